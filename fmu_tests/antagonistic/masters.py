"""dist/AntagonisticJoint.ssp in three SSP masters that this project did not write, each as its
users would run it, with the joint angle recorded after every 1 ms step:

* FMPy's `simulate_ssp` (fixed-step Jacobi), with the start values the .ssp binds;
* OSP's libcosim through `libcosimpy` (`CosimExecution.from_ssp_file`, fixed step);
* FMU Manipulation Toolbox's FMU container built from the .ssp (its `Assembly`, as `fmucontainer`
  does, with the components' start values), run by FMPy's `simulate_fmu`.

The system steps its reference by itself (the controller's `theta_step` at `t_step`, set in the
parameter set), so no master has to drive an input.

Each function returns (t, theta): the times of the outputs (after each step) and joint.theta.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]
STEP_SIZE = 1e-3


def default_ssp() -> Path:
    env = os.environ.get("JETPIPE_SSP")
    return Path(env) if env else REPO / "dist" / "AntagonisticJoint.ssp"


def ssp_parameters(ssp: Path) -> dict[str, float]:
    """The start values the .ssp binds on its components: {"component.variable": value}."""
    sys.path.insert(0, str(HERE))
    import ssp_sim  # noqa: E402

    return {p.name: float(p.value) for p in ssp_sim.parameter_set(ssp).parameters}


def run_fmpy(ssp: Path, stop_time: float):
    sys.path.insert(0, str(HERE))
    import ssp_sim  # noqa: E402

    result, _ = ssp_sim.simulate(None, stop_time, ssp=ssp)
    return ssp_sim.output_time(result), np.asarray(result["joint.theta"])


def run_libcosim(ssp: Path, stop_time: float):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.WARNING)
    with tempfile.TemporaryDirectory() as tmp:
        # libcosim reads an SSP from its folder (SystemStructure.ssd and what it refers to).
        with zipfile.ZipFile(ssp) as zf:
            zf.extractall(tmp)
        execution = CosimExecution.from_ssp_file(tmp, step_size=int(round(STEP_SIZE * 1e9)))
        observer = CosimObserver.create_last_value()
        execution.add_observer(observer)
        joint = execution.slave_index_from_instance_name("joint")
        refs = {v.name.decode(): v.reference for v in execution.slave_variables(joint)}
        n = int(round(stop_time / STEP_SIZE))
        t, theta = np.empty(n), np.empty(n)
        for k in range(n):
            assert execution.step(), f"libcosim step {k} failed"
            t[k] = (k + 1) * STEP_SIZE
            theta[k] = observer.last_real_values(joint, [refs["theta"]])[0]
        execution.stop()
    return t, theta


def build_container(ssp: Path, out_dir: Path, bindings=None) -> Path:
    """The container FMU of the .ssp, built in `out_dir` by FMU Manipulation Toolbox's
    `Assembly` (what `fmucontainer -container <ssp>:<step>` runs). Its SSP reader (marked alpha
    in 2.0) takes the systems, components and connections only, so each component's start
    values are handed to the container through the toolbox's `add_start_value` (only those named
    in `bindings`, "component.variable", if given)."""
    from fmu_manipulation_toolbox.assembly import Assembly, SSDParser

    shutil.copy(ssp, out_dir / ssp.name)
    assembly = Assembly(ssp.name, default_step_size=STEP_SIZE, fmu_directory=out_dir)
    # The toolbox's own names of the components' FMUs (instances of one FMU get -1, -2, ...).
    with zipfile.ZipFile(out_dir / ssp.name) as zin:
        parser = SSDParser(zin, ssp.with_suffix(".dir").name)
        parser.parse("SystemStructure.ssd")
    for name, value in ssp_parameters(ssp).items():
        if bindings is not None and name not in bindings:
            continue
        component, variable = name.split(".", 1)
        assembly.root.add_start_value(parser.fmu_filenames[component], variable, repr(value))
    assembly.make_fmu()
    fmu = out_dir / ssp.with_suffix(".fmu").name
    if not fmu.is_file():
        raise RuntimeError(f"the container {fmu} was not written")
    return fmu


def run_container(ssp: Path, stop_time: float, bindings=None):
    import fmpy

    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_container(ssp, Path(tmp), bindings)
        result = fmpy.simulate_fmu(
            str(fmu), stop_time=stop_time, step_size=STEP_SIZE, output_interval=STEP_SIZE,
            output=["fingerjoint.theta"],
        )
    # FMPy records the start and then the values after each step.
    return np.asarray(result["time"][1:]), np.asarray(result["fingerjoint.theta"][1:])
