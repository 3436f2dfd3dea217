"""presets/thesis_measured.json in Model Exchange (issue 80): its Bouc-Wen jet-pipe hysteresis
is a memory that the FMU advances where the coil current reverses (event indicator z7), at
every event and after every completed integrator step, and its right-hand side is the law
Co-Simulation integrates. FMPy's CVODE at relative tolerances 1e-4 to 1e-10, both archives,
follows Co-Simulation within the input hold (0.02 N RMS, inputs every 0.1 ms) on a command
that reverses many times: a 20 Hz sine with ±1 V steps every 30 ms (`measured_preset`),
held as a D/A converter holds it (an input event every 0.1 ms); and the sine alone set at the
time of each right-hand side (`measured_preset_sine`, no input event: every reversal is a
root of z7).
"""

from __future__ import annotations

import numpy as np
import pytest

import tolerance_sweep as ts
from test_tolerance_sweep import RMS_LIMIT_N, T_END, archive_path, reference


def current_reversals(cs) -> int:
    """The coil current's turning points in Co-Simulation's 0.1 ms samples."""
    di = np.diff(cs["i"])
    di = di[di != 0.0]
    return int(np.count_nonzero(np.sign(di[1:]) != np.sign(di[:-1])))


def run(archive, name, law, rtol):
    inputs = None if law else ts.signal(name, T_END, ts.HOLD, hold=True)
    me, error, work, wall = ts.model_exchange(archive_path(archive), inputs, T_END, rtol,
                                              start=ts.start_values(name),
                                              law=ts.delayed(ts.SIGNALS[name]) if law else None)
    assert me is not None, f"{archive} {name} rtol {rtol:g}: {error}"
    assert me["time"][-1] == pytest.approx(T_END, abs=1e-9)
    rms = ts.force_rms(reference(archive, name), me)
    print(f"{archive} {name} {'smooth' if law else 'held'} rtol {rtol:g}: F_act RMS ME - CS {rms:.2e} N, "
          f"{work.steps / T_END:.0f} steps/s, {work.rhs / T_END:.0f} RHS/s, {work.restarts} restarts, {wall:.1f} s")
    return rms, work


@pytest.mark.parametrize("archive", ["fmi2", "fmi3"])
@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8, 1e-10])
def test_the_measured_preset_in_model_exchange_follows_co_simulation_through_reversals_and_steps(archive, rtol):
    rms, work = run(archive, "measured_preset", False, rtol)
    assert rms <= RMS_LIMIT_N
    assert work.restarts >= T_END / ts.HOLD - 1  # an input event at each sample


@pytest.mark.parametrize("archive, rtol", [("fmi2", 1e-10), ("fmi3", 1e-6)])
def test_with_a_smooth_command_model_exchange_stops_at_every_reversal_of_the_current_and_follows_co_simulation(
        archive, rtol):
    """No input event: CVODE restarts only at roots of the event indicators, and z7 has one at
    each turning point of the current, where the memory moves to the loop's other branch."""
    rms, work = run(archive, "measured_preset_sine", True, rtol)
    reversals = current_reversals(ts.co_simulation(archive_path(archive),
                                                   ts.signal("measured_preset_sine", T_END, ts.HOLD, hold=True),
                                                   T_END, ts.HOLD, ts.start_values("measured_preset_sine")))
    assert reversals >= 7  # a 20 Hz sine for 0.2 s
    assert work.restarts >= reversals
    assert rms <= RMS_LIMIT_N


def test_the_preset_s_hysteresis_moves_the_force_by_far_more_than_the_agreement_asked_for():
    """Co-Simulation with and without the preset's hysteresis differ by over 50 times the 0.02 N:
    a Model Exchange run that lost the memory would fail the tests above."""
    name = "measured_preset"
    held = ts.signal(name, T_END, ts.HOLD, hold=True)
    without = {k: v for k, v in ts.start_values(name).items() if not k.startswith("hysteresis")}
    plain = ts.co_simulation(archive_path("fmi2"), held, T_END, ts.HOLD, without)[:: int(round(1e-3 / ts.HOLD))]
    with_it = reference("fmi2", name)
    rms = float(np.sqrt(np.mean((with_it["F_act"] - plain["F_act"]) ** 2)))
    print(f"F_act RMS, Co-Simulation with - without the preset's hysteresis: {rms:.2f} N")
    assert rms > 50 * RMS_LIMIT_N
