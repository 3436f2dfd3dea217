"""A second importer of the FMI 3.0 archive: FMU Manipulation Toolbox's container runtime (PyPI
`fmu-manipulation-toolbox` 2.0, pinned in requirements.txt; its `container.so`, C, BSD-2-Clause,
ships in the wheel), on the inputs of the tolerance sweep that reach every regime
(`tolerance_sweep.SIGNALS`, 0.2 s each, held every 0.1 ms).

The toolbox wraps FMUs into a container FMU whose own library imports them: a Co-Simulation FMU
through fmi3DoStep, a Model Exchange FMU through its own loop (fmi3InstantiateModelExchange,
fmi3SetContinuousStates, fmi3GetContinuousStateDerivatives, fmi3GetEventIndicators,
fmi3CompletedIntegratorStep, fmi3EnterEventMode and fmi3UpdateDiscreteStates), integrated with a
fixed-step RK4 (`container.solver` = 1) at the container's step, state events located by
bisection. The toolbox embeds a dual archive in Co-Simulation, so Model Exchange is run on a copy
of the archive whose model description lacks its <CoSimulation> element. FMPy only steps the
container (an FMI 3.0 Co-Simulation FMU, every 0.1 ms): every call into the actuator's library
comes from the container's code.

Model Exchange at a 10 us step must follow FMPy's Co-Simulation of the archive within 0.02 N RMS
at the 1 ms instants (the bar of test_fmipp.py and the FMPy sweep; RK4 measured 4.4e-4 N on the
full steps, 1.2e-4 N and 1.3e-5 N on the moving stopper with and without the volumes and the
mount, 1e-7 N or less elsewhere; at a 100 us step the full steps miss it, 0.066 N). The
container sets its inputs in continuous-time mode, never in event mode: the moving stopper
follows because the chambers' states are their air, which a stopper moved there leaves as it is
(src/fmu/model_exchange.rs; when the states were the pressures, the volumes moved without the
compression and the force parted from Co-Simulation's by 170 N RMS).
Co-Simulation through the container must give FMPy's Co-Simulation to rounding, the moving stopper
included. Last, FMI++ (scripts/fmipp.sh) steps the same Model Exchange container built with an
FMI 2.0 interface: no call of FMPy's anywhere in that chain.
"""

from __future__ import annotations

import re
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmu_manipulation_toolbox.assembly import AssemblyNode

import tolerance_sweep as ts
from test_tolerance_sweep import archive_path, reference

try:
    import fmipp
except ImportError:  # reported by the test that uses it
    fmipp = None

T_END = 0.2
HOLD = ts.HOLD
RMS_LIMIT_N = 0.02
ME_STEP = 1e-5  # s: the container's RK4 step (ten per input hold)
RK4 = 1  # container.solver: 0 Euler, 1 RK4
EVERY = int(round(1e-3 / HOLD))
# As test_fmipp.py's, with the moving stopper also on the volumes and the mount.
ME_CASES = ["slow_sine", "full_steps", "moving_stopper", "volumes_and_mount", "moving_stopper_volumes",
            "measured_preset", "transducers"]
CS_CASES = ["full_steps", "moving_stopper", "measured_preset"]


def model_exchange_only(archive: Path, copy: Path) -> Path:
    """`archive` with the <CoSimulation> element of its model description left out."""
    with zipfile.ZipFile(archive) as zin, zipfile.ZipFile(copy, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename == "modelDescription.xml":
                text, n = re.subn(r"\s*<CoSimulation\b[^>]*/>", "", data.decode("utf-8"))
                assert n == 1, f"{archive}: {n} <CoSimulation/> elements"
                assert "<ModelExchange" in text
                data = text.encode("utf-8")
            zout.writestr(item, data)
    return copy


def container(folder: Path, embedded: Path, name: str, step: float, fmi_version: int) -> Path:
    """The container FMU `name` around `embedded` (in `folder`), its inputs, outputs and the
    embedded FMU's parameters exposed, the parameters as "<embedded stem>.<name>"."""
    node = AssemblyNode(name, step_size=step, auto_parameter=True)
    node.add_fmu(embedded.name)
    node.make_fmu(folder, fmi_version=fmi_version)
    path = folder / name
    assert path.is_file(), f"the toolbox wrote no {path}"
    return path


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fmucontainer")
    model_exchange_only(archive_path("fmi3"), folder / "me.fmu")
    (folder / "cs.fmu").write_bytes(archive_path("fmi3").read_bytes())
    return folder


def description(path: Path) -> str:
    with zipfile.ZipFile(path) as z:
        return z.read("modelDescription.xml").decode("utf-8")


@pytest.fixture(scope="module")
def me_container(folder):
    path = container(folder, folder / "me.fmu", "container_me.fmu", ME_STEP, 3)
    # The solver's selector is there only when an FMU is embedded in Model Exchange.
    assert 'name="container.solver"' in description(path)
    return fmpy.extract(str(path), str(folder / "container_me"))


@pytest.fixture(scope="module")
def cs_container(folder):
    path = container(folder, folder / "cs.fmu", "container_cs.fmu", HOLD, 3)
    assert 'name="container.solver"' not in description(path)
    return fmpy.extract(str(path), str(folder / "container_cs"))


def through_container(unzipdir, prefix, name, extra=None):
    """F_act at the 1 ms instants, FMPy stepping the container every 0.1 ms on the held inputs
    (as `tolerance_sweep.co_simulation` steps the archive for the reference)."""
    start = {f"{prefix}.{k}": v for k, v in ts.start_values(name).items()}
    start.update(extra or {})
    held = ts.signal(name, T_END, HOLD, hold=True)
    result = fmpy.simulate_fmu(unzipdir, fmi_type="CoSimulation", stop_time=T_END, input=held,
                               output_interval=HOLD, start_values=start, output=["F_act"])
    assert result["time"][-1] == pytest.approx(T_END, abs=1e-9), f"{name}: stopped at {result['time'][-1]} s"
    return result[::EVERY]


def rms(a, b):
    return float(np.sqrt(np.mean((np.asarray(a) - np.asarray(b)) ** 2)))


@pytest.mark.parametrize("name", ME_CASES)
def test_container_model_exchange_reaches_the_end_and_follows_co_simulation(me_container, name):
    cs = reference("fmi3", name)
    me = through_container(me_container, "me", name, {"container.solver": RK4})
    assert len(me) == len(cs)
    assert np.allclose(me["time"], cs["time"], atol=1e-9, rtol=0)
    error = rms(me["F_act"], cs["F_act"])
    print(f"{name}, the container's FMI 3.0 Model Exchange (RK4, {ME_STEP:g} s) against FMPy's "
          f"Co-Simulation: F_act RMS {error:.2e} N")
    assert error <= RMS_LIMIT_N


@pytest.mark.parametrize("name", CS_CASES)
def test_container_co_simulation_gives_what_fmpy_gives(cs_container, name):
    cs = reference("fmi3", name)
    mine = through_container(cs_container, "cs", name)
    error = rms(mine["F_act"], cs["F_act"])
    print(f"{name}, the container's FMI 3.0 Co-Simulation against FMPy's: F_act RMS {error:.2e} N")
    # The same library, inputs, steps and tolerance: the same numbers but for rounding
    # (measured 2e-13 N).
    assert error <= 1e-9 * float(np.abs(cs["F_act"]).max())


@pytest.fixture(scope="module")
def fmipp_uri(folder):
    if fmipp is None:
        pytest.fail("fmipp is not installed: run `bash scripts/fmipp.sh` (the test command does)", pytrace=False)
    path = container(folder, folder / "me.fmu", "container_me2.fmu", ME_STEP, 2)
    (folder / "fmipp").mkdir()
    return fmipp.extractFMU(str(path), str(folder / "fmipp"))


@pytest.mark.parametrize("name", ["full_steps", "measured_preset"])
def test_fmipp_steps_the_model_exchange_container(fmipp_uri, name):
    """FMI++ steps an FMI 2.0 container of the Model Exchange copy: FMI++ calls the container,
    the container calls the FMU's FMI 3.0 Model Exchange, FMPy calls nothing."""
    fmu = fmipp.FMUCoSimulationV2(fmipp_uri, "container_me2", False, 1e-6)
    assert fmu.instantiate("container", 0.0, False, False) == fmipp.statusOK
    assert fmu.setIntegerValue("container.solver", RK4) == fmipp.statusOK
    for variable, value in ts.start_values(name).items():
        assert fmu.setRealValue(f"me.{variable}", float(value)) == fmipp.statusOK, variable
    law = ts.SIGNALS[name]
    v, x = law(0.0, T_END)
    fmu.setRealValue("v_DA", v)
    fmu.setRealValue("x_s", x)
    assert fmu.initialize(0.0, True, T_END) == fmipp.statusOK
    force = []
    for k in range(int(round(T_END / HOLD))):
        if k % EVERY == 0:
            force.append(fmu.getRealValue("F_act"))
        v, x = law(k * HOLD, T_END)
        assert fmu.setRealValue("v_DA", v) == fmipp.statusOK
        assert fmu.setRealValue("x_s", x) == fmipp.statusOK
        status = fmu.doStep(k * HOLD, HOLD, True)
        assert status == fmipp.statusOK, f"{name}: doStep at {k * HOLD} s gave {status}"
    force.append(fmu.getRealValue("F_act"))
    cs = reference("fmi3", name)["F_act"]
    assert len(force) == len(cs)
    error = rms(force, cs)
    print(f"{name}, FMI++ stepping the container's FMI 3.0 Model Exchange against FMPy's Co-Simulation: "
          f"F_act RMS {error:.2e} N")
    assert error <= RMS_LIMIT_N
