"""A second importer, FMI++ (`fmipp`, AIT's C++ library, built by scripts/fmipp.sh), runs the
FMI 2.0 archive in Model Exchange and in Co-Simulation (issue 80), on the inputs of the
tolerance sweep that reach every regime (`tolerance_sweep.SIGNALS`, 0.2 s each, held every
0.1 ms).

Its Model Exchange integrates with its own variable-step solvers (Boost.Odeint's
Dormand-Prince and Rosenbrock; FMI++ sets their tolerances to 1e-6 and its Python interface
does not change them), locates the FMU's state events itself and calls its event updates: a
code path the FMU has not met in FMPy. Each run must reach the end and follow FMPy's
Co-Simulation of the same held inputs within 0.02 N RMS at the 1 ms instants, the bar of the
FMPy sweep. Its Co-Simulation must give FMPy's Co-Simulation: the same library and inputs
through another importer's calls.

FMI++ imports FMI 1.0 and 2.0 only: the 3.0 archive's importers are FMPy and the C importer
(test_c_driver.py, test_fmi3.py).
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

import tolerance_sweep as ts
from test_tolerance_sweep import archive_path, reference

try:
    import fmipp
except ImportError:  # reported by the fixture below, with the way to install it
    fmipp = None

T_END = 0.2
HOLD = ts.HOLD
RMS_LIMIT_N = 0.02
MODEL = "JetPipeActuator"
# The sweep's inputs, a regime each: a slow sine; full-scale steps (the chambers to the supply
# and the return, the leakage reversing, the force on and off the spring floor); the stopper
# moved through the spring floor with a chamber above the supply; the gas volumes and the
# lagging mount; the measured preset with its hysteresis (a discrete memory moved at events);
# the transducers' lags and filters (states of their own).
CASES = ["slow_sine", "full_steps", "moving_stopper", "volumes_and_mount", "measured_preset", "transducers"]


@pytest.fixture(scope="module")
def uri(tmp_path_factory):
    if fmipp is None:
        pytest.fail("fmipp is not installed: run `bash scripts/fmipp.sh` (the test command does)", pytrace=False)
    folder = tmp_path_factory.mktemp("fmipp")
    shutil.copy(archive_path("fmi2"), folder / "archive.fmu")
    return fmipp.extractFMU(str(folder / "archive.fmu"), str(folder))


def held_inputs(name):
    """The input law of `name` at each 0.1 ms hold, as `tolerance_sweep.signal` holds it."""
    law = ts.SIGNALS[name]
    n = int(round(T_END / HOLD))
    return [law(k * HOLD, T_END) for k in range(n)]


def set_start_values(fmu, name):
    for variable, value in ts.start_values(name).items():
        if variable == "command_delay_pade_sections":
            status = fmu.setIntegerValue(variable, int(value))
        else:
            status = fmu.setRealValue(variable, float(value))
        assert status == fmipp.statusOK, f"{name}: setting {variable} = {value} gave status {status}"


def force_every_millisecond(fmu, name, advance):
    """F_act at the 1 ms instants, each read before the input of that instant is set (as FMPy's
    Co-Simulation records it), the inputs set at each hold and `advance(t, t_next)` between."""
    inputs = held_inputs(name)
    every = int(round(1e-3 / HOLD))
    force = []
    for k, (v, x) in enumerate(inputs):
        if k % every == 0:
            force.append(fmu.getRealValue("F_act"))
        assert fmu.setRealValue("v_DA", v) == fmipp.statusOK
        assert fmu.setRealValue("x_s", x) == fmipp.statusOK
        advance(k * HOLD, (k + 1) * HOLD)
    force.append(fmu.getRealValue("F_act"))
    return np.array(force)


def model_exchange(uri, name, integrator):
    fmu = fmipp.FMUModelExchangeV2(uri, MODEL, False, False, 1e-6, getattr(fmipp, f"integrator{integrator}"))
    assert fmu.instantiate("me") == fmipp.statusOK
    set_start_values(fmu, name)
    v, x = ts.SIGNALS[name](0.0, T_END)
    fmu.setRealValue("v_DA", v)
    fmu.setRealValue("x_s", x)
    assert fmu.initialize() == fmipp.statusOK, f"{name}: initialize gave {fmu.getLastStatus()}"
    calls = [0]

    def advance(t, t_next):
        while fmu.getTime() < t_next - 1e-12:
            fmu.integrate(t_next, HOLD)
            calls[0] += 1
            assert fmu.getLastStatus() == fmipp.statusOK, f"{name}: status {fmu.getLastStatus()} at {fmu.getTime()} s"
            assert calls[0] < 100 * T_END / HOLD, f"{name}: stuck at {fmu.getTime()} s"

    force = force_every_millisecond(fmu, name, advance)
    assert fmu.getTime() == pytest.approx(T_END, abs=1e-9)
    return force


def co_simulation(uri, name):
    # FMI++ hands its time resolution to fmi2SetupExperiment as the tolerance: 1e-6, the FMU's
    # default, which FMPy leaves it at.
    fmu = fmipp.FMUCoSimulationV2(uri, MODEL, False, 1e-6)
    assert fmu.instantiate("cs", 0.0, False, False) == fmipp.statusOK
    set_start_values(fmu, name)
    v, x = ts.SIGNALS[name](0.0, T_END)
    fmu.setRealValue("v_DA", v)
    fmu.setRealValue("x_s", x)
    assert fmu.initialize(0.0, True, T_END) == fmipp.statusOK

    def advance(t, t_next):
        status = fmu.doStep(t, t_next - t, True)
        assert status == fmipp.statusOK, f"{name}: doStep at {t} s gave {status}"

    return force_every_millisecond(fmu, name, advance)


def rms(a, b):
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


@pytest.mark.parametrize("name", CASES)
def test_fmipp_model_exchange_reaches_the_end_and_follows_co_simulation(uri, name):
    cs = reference("fmi2", name)["F_act"]
    for integrator in ("DP", "RO") if name == "full_steps" else ("DP",):
        me = model_exchange(uri, name, integrator)
        assert len(me) == len(cs)
        error = rms(me, cs)
        print(f"{name}, FMI++ Model Exchange ({integrator}) against FMPy's Co-Simulation: F_act RMS {error:.2e} N")
        assert error <= RMS_LIMIT_N


@pytest.mark.parametrize("name", ["full_steps", "measured_preset"])
def test_fmipp_co_simulation_gives_what_fmpy_gives(uri, name):
    cs = reference("fmi2", name)["F_act"]
    mine = co_simulation(uri, name)
    error = rms(mine, cs)
    print(f"{name}, FMI++ against FMPy's Co-Simulation: F_act RMS {error:.2e} N")
    # The same library, inputs and tolerance: the same numbers but for rounding (1e-9 of the
    # force; the full steps differ by 1e-9 N, where the importers' communication times may
    # round apart).
    assert error <= 1e-9 * float(np.abs(cs).max())
