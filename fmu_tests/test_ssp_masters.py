"""dist/AntagonisticJoint.ssp in three SSP masters this project did not write (issue 21): FMPy's
`simulate_ssp`, OSP's libcosim (`libcosimpy`) and FMU Manipulation Toolbox's container, each at
1 ms steps with the start values the .ssp binds on its components. The system steps its own
reference (the controller's theta_step at t_step), so the three runs are the same scenario; the
joint angle must agree within 1e-3 rad at every step.

Two masters need something the .ssp cannot give them. FMPy's `simulate_ssp` hands 0.0 to every
connected input in the first step, which the actuator refuses as x_s; its run goes through
`ssp_sim`, which starts the connectors at the FMUs' values after initialisation (a test below
shows the unpatched run stopping there and only there). The container's SSP reader takes
components and connections only: the start values the .ssp binds are handed over with the
toolbox's `add_start_value` (`masters.build_container`).

Build what it needs with
    bash scripts/package.sh
    cargo run --release -p antagonistic -- package
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "antagonistic"))

import masters  # noqa: E402

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}
MASTERS = {"FMPy": masters.run_fmpy, "libcosim": masters.run_libcosim, "container": masters.run_container}


@pytest.fixture(scope="module")
def ssp() -> Path:
    path = masters.default_ssp()
    if not path.is_file():
        pytest.fail(f"{path} not found (see this module's doc)", pytrace=False)
    return path


@pytest.fixture(scope="module")
def scenario(ssp):
    p = masters.ssp_parameters(ssp)
    return p["controller.theta_step"], p["controller.t_step"]


@pytest.fixture(scope="module")
def runs(ssp, scenario):
    _, t_step = scenario
    stop = t_step + 1.0
    n = int(round(stop / masters.STEP_SIZE))
    out = {}
    for name, run in MASTERS.items():
        t, theta = run(ssp, stop)
        assert len(t) >= n, f"{name}: {len(t)} steps, expected {n}"
        assert np.allclose(t[:n], masters.STEP_SIZE * np.arange(1, n + 1)), f"{name}: output times"
        out[name] = (t[:n], theta[:n])
    return out


def test_the_ssd_has_nothing_libcosim_rejects_and_binds_start_values(ssp):
    with zipfile.ZipFile(ssp) as zf:
        root = ET.fromstring(zf.read("SystemStructure.ssd"))
    system = root.find("ssd:System", NS)
    assert system.find("ssd:Connectors", NS) is None, "system-level connectors (libcosim takes none)"
    for c in system.iterfind("ssd:Connections/ssd:Connection", NS):
        assert c.get("startElement") and c.get("endElement"), c.attrib
    fed = {(c.get("endElement"), c.get("endConnector")) for c in system.iterfind("ssd:Connections/ssd:Connection", NS)}
    for component in system.iterfind("ssd:Elements/ssd:Component", NS):
        name = component.get("name")
        starts = {
            p.get("name")
            for p in component.iterfind(
                "ssd:ParameterBindings/ssd:ParameterBinding/ssd:ParameterValues/ssv:ParameterSet/ssv:Parameters/ssv:Parameter", NS
            )
        }
        inputs = {c.get("name") for c in component.iterfind("ssd:Connectors/ssd:Connector", NS) if c.get("kind") == "input"}
        assert inputs <= starts, f"{name}: connected inputs without a start value: {sorted(inputs - starts)}"
        assert all((name, i) in fed for i in inputs)


def test_fmpy_unpatched_hands_zero_to_the_stoppers_and_the_actuator_refuses_it(ssp, capfd, tmp_path, monkeypatch):
    """Why `ssp_sim` changes FMPy's master (`connectors_start_at_fmu_values`), and that this is
    the only reason. FMPy 0.3.32's `simulate_ssp` sets every connector to 0.0 before it
    instantiates the FMUs, never reads an output after initialisation, and applies the
    connections only after every component has stepped: in the first step every connected input
    gets 0.0, whatever the .ssd says (start values, bindings, order). The actuator must refuse
    x_s = 0 m (outside its cylinder), so the unpatched run stops there. If this test fails
    because the run succeeds, FMPy has changed: drop the patch from ssp_sim."""
    import fmpy.ssp.simulation as ssp_simulation
    from fmpy.fmi1 import FMICallException

    import ssp_sim  # noqa: E402

    for name in ("instantiate_fmu", "do_step", "simulate_ssp"):
        assert getattr(ssp_simulation, name).__module__ == "fmpy.ssp.simulation", f"{name} is patched"
    # FMPy leaves its extracted .ssp and FMUs behind when a run raises: extract them here.
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    with pytest.raises(FMICallException, match="fmi2SetReal failed"):
        ssp_simulation.simulate_ssp(str(ssp), stop_time=2 * masters.STEP_SIZE, step_size=masters.STEP_SIZE,
                                    parameter_set=ssp_sim.parameter_set(ssp))
    # FMPy's log lines look different once another test has changed its logger: match the message.
    log = capfd.readouterr().out
    errors = [line for line in log.splitlines() if "error" in line.lower()]
    assert len(errors) == 1, log
    assert "fmi2SetReal: x_s = 0 m is outside the cylinder: both chamber volumes must be positive" in errors[0], log


def test_joint_step_response_is_the_same_in_three_masters(runs, scenario):
    theta_step, t_step = scenario
    for name, (t, theta) in runs.items():
        before = t < t_step
        final = np.mean(theta[t > t[-1] - 0.1])
        print(f"{name}: |theta| before the step {np.max(np.abs(theta[before])):.2e} rad, peak {theta.max():.4f} rad, "
              f"final {final:.4f} rad")
        assert np.max(np.abs(theta[before])) < 1e-3, f"{name}: the joint moved before the step"
        assert abs(final - theta_step) < 0.02 and theta.max() < 1.2 * theta_step, name
    names = list(runs)
    worst = 0.0
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            d = float(np.max(np.abs(runs[a][1] - runs[b][1])))
            print(f"max |theta_{a} - theta_{b}| = {d:.2e} rad")
            worst = max(worst, d)
    assert worst < 1e-3


def test_the_container_needs_only_the_reference_step_from_the_bindings(ssp, scenario, runs):
    """The container's SSP reader drops the bindings. Handed only the reference step (the other
    bindings are the FMUs' defaults or input start values), it still agrees with the other two
    masters within 1e-3 rad; handed nothing, it runs the FMUs' defaults, where nothing moves."""
    _, t_step = scenario
    n = len(runs["FMPy"][0])
    stop = n * masters.STEP_SIZE
    _, theta = masters.run_container(ssp, stop, {"controller.theta_step", "controller.t_step"})
    for name in ("FMPy", "libcosim"):
        d = float(np.max(np.abs(theta[:n] - runs[name][1])))
        print(f"max |theta_{name} - theta_container(reference step only)| = {d:.2e} rad")
        assert d < 1e-3, name
    _, theta = masters.run_container(ssp, t_step + 0.1, set())
    assert np.max(np.abs(theta)) == 0.0


def test_fmutool_check_is_clean_for_every_fmu(ssp):
    fmutool = Path(sys.executable).with_name("fmutool")
    dist = ssp.parent
    for name in ("JetPipeActuator", "Tendon", "FingerJoint", "JointController"):
        proc = subprocess.run([str(fmutool), "-input", str(dist / f"{name}.fmu"), "-check"],
                              capture_output=True, text=True, timeout=300)
        text = proc.stdout + proc.stderr
        assert proc.returncode == 0, f"{name}: exit {proc.returncode}\n{text}"
        assert "No semantic error" in text and "compliant with FMI-2.0" in text, f"{name}:\n{text}"
        assert "ERROR" not in text, f"{name}:\n{text}"
