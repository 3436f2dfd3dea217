"""The antagonistic joint (issue 7): the Tendon, FingerJoint and JointController FMUs on their own,
then dist/AntagonisticJoint.ssp (two JetPipeActuator instances, two tendons, the joint and the
controller) through FMPy's SSP master: step, 2 Hz sine, tendons never slack, joint position
bandwidth near the 8 Hz reported for the Utah/MIT hand (thesis §1.1.1).

Build what it needs with
    cargo run --release --bin jetpipe -- package
    cargo run --release -p antagonistic -- package
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
import fmpy
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2Error
from fmpy.ssp.ssd import read_ssd
from fmpy.validation import validate_fmu

from jetpipe_fmu import make_slave, mentions_value, release, vr_map

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
DIST = REPO / "dist"
sys.path.insert(0, str(HERE / "antagonistic"))

import ssp_sim  # noqa: E402

# model identifier -> crate folder
MODELS = {"Tendon": "tendon", "FingerJoint": "finger_joint", "JointController": "joint_controller"}
BUILD = "cargo run --release -p antagonistic -- package"

FMI2_CS_FUNCTIONS = sorted(
    """fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
    fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset
    fmi2GetReal fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean
    fmi2SetString fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize
    fmi2SerializeFMUstate fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative fmi2SetRealInputDerivatives
    fmi2GetRealOutputDerivatives fmi2DoStep fmi2CancelStep fmi2GetStatus fmi2GetRealStatus
    fmi2GetIntegerStatus fmi2GetBooleanStatus fmi2GetStringStatus""".split()
)


def need(path: Path) -> Path:
    if not path.is_file():
        pytest.fail(f"{path} not found: build it with `{BUILD}`", pytrace=False)
    return path


@pytest.fixture(scope="module", params=sorted(MODELS))
def model(request, tmp_path_factory):
    """(identifier, fmu path, unzip dir, model description) of each new FMU."""
    path = need(DIST / f"{request.param}.fmu")
    unzipdir = Path(fmpy.extract(str(path), str(tmp_path_factory.mktemp(request.param))))
    return request.param, path, unzipdir, fmpy.read_model_description(str(path))


@pytest.fixture(scope="module")
def ssp() -> Path:
    return need(DIST / "AntagonisticJoint.ssp")


# ---- the three FMUs ----------------------------------------------------------------------


def test_validate_fmu(model):
    name, path, _, _ = model
    problems = validate_fmu(str(path))
    assert problems == [], f"{name}: " + "\n".join(problems)


def test_model_description_is_the_checked_copy(model):
    name, path, _, md = model
    with zipfile.ZipFile(path) as z:
        packaged = z.read("modelDescription.xml").decode()
    checked = (REPO / "fmus" / MODELS[name] / "modelDescription.xml").read_text()
    assert packaged == checked, f"{name}: the packaged model description is not fmus/{MODELS[name]}/modelDescription.xml"
    assert md.fmiVersion == "2.0" and md.coSimulation.modelIdentifier == name
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate
    for v in md.modelVariables:
        assert v.description, f"{name}.{v.name} has no description"
        if v.type == "Real":
            assert v.unit, f"{name}.{v.name} has no unit"


def test_library_exports_its_own_fmi2_functions_only(model):
    """The library must carry exactly one set of the 34 functions, and they must be this model's:
    jetpipe's own exported symbols (src/fmu_exports.rs, the actuator's) must not have come along
    with its rlib. If they had, the GUID check would be the actuator's."""
    name, _, unzipdir, md = model
    library = unzipdir / "binaries" / "linux64" / f"{name}.so"
    nm = shutil.which("nm")
    if nm is not None:
        out = subprocess.run([nm, "-D", "--defined-only", str(library)], capture_output=True, text=True, check=True)
        exported = sorted(line.split()[-1] for line in out.stdout.splitlines() if line.split()[-1].startswith("fmi2"))
        assert exported == FMI2_CS_FUNCTIONS
    fmu = make_slave(unzipdir, md)  # raises if fmi2Instantiate rejects the model's own GUID
    release(fmu)
    with pytest.raises(Exception):
        make_slave(unzipdir, md, guid="{5b0c7f0e-3d2a-4c1e-9a57-jetpipe-0001}")  # the actuator's GUID


# (model, input, bad value) and (model, parameter, bad value, expected text)
BAD_INPUTS = {"Tendon": "F_act", "FingerJoint": "T_flexor", "JointController": "theta_ref"}
BAD_PARAMETERS = {
    "Tendon": ("k", -2.0e4, "k = -20000 N/m"),
    "FingerJoint": ("J", -1.0, "J = -1 kg.m2"),
    "JointController": ("k_feedforward", 2.0, "k_feedforward = 2"),
}
# a parameter value valid on its own that contradicts another: rejected at initialisation
BAD_RELATIONS = {
    "Tendon": ("x_s0", 0.095, "x_s0 = 0.095 m"),
    "FingerJoint": ("theta_max", -1.0, "theta_max = -1 rad"),
    "JointController": ("T_min", 30.0, "T_min = 30 N"),
}


@pytest.mark.parametrize("bad", [float("nan"), float("inf")], ids=["nan", "inf"])
def test_bad_input_is_rejected_with_a_message_naming_it(model, bad):
    name, _, unzipdir, md = model
    vrs = vr_map(md)
    fmu = make_slave(unzipdir, md)
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(0.0, 1e-3)
        variable = BAD_INPUTS[name]
        before = fmu.getReal([vrs[variable]])[0]
        n = len(fmu.log)
        with pytest.raises(FMICallException) as info:
            fmu.setReal([vrs[variable]], [bad])
        assert info.value.status == fmi2Error
        text = " | ".join(m.message for m in fmu.log.since(n) if m.status >= fmi2Error)
        assert variable in text and mentions_value(text, bad), text
        print(f"{name}: {text}")
        assert fmu.getReal([vrs[variable]])[0] == before, "the rejected value was applied"
        fmu.doStep(1e-3, 1e-3)  # still usable
    finally:
        release(fmu)


def test_bad_parameters_are_rejected_with_a_message_naming_them(model):
    name, _, unzipdir, md = model
    vrs = vr_map(md)
    parameter, value, needle = BAD_PARAMETERS[name]
    fmu = make_slave(unzipdir, md)
    try:
        n = len(fmu.log)
        with pytest.raises(FMICallException):
            fmu.setReal([vrs[parameter]], [value])
        text = " | ".join(m.message for m in fmu.log.since(n))
        assert needle in text, text
        parameter, value, needle = BAD_RELATIONS[name]
        fmu.setReal([vrs[parameter]], [value])
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        n = len(fmu.log)
        with pytest.raises(FMICallException):
            fmu.exitInitializationMode()
        text = " | ".join(m.message for m in fmu.log.since(n))
        assert needle in text, text
        print(f"{name}: {text}")
    finally:
        release(fmu)


def test_tendon_goes_slack_instead_of_pushing(tmp_path):
    """Through the C API: a tendon whose joint end is pulled 5 mm towards an actuator that does not
    pull carries no tension and reports it, and its stopper output stays in the cylinder."""
    path = need(DIST / "Tendon.fmu")
    md = fmpy.read_model_description(str(path))
    vrs = vr_map(md)
    fmu = make_slave(Path(fmpy.extract(str(path), str(tmp_path))), md)
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([vrs["F_act"]], [20.0])
        fmu.exitInitializationMode()
        assert fmu.getReal([vrs["T"]])[0] == pytest.approx(20.0)
        fmu.setReal([vrs["F_act"], vrs["x_joint"]], [0.0, 5e-3])
        for k in range(20):
            fmu.doStep(k * 1e-3, 1e-3)
        t, x_s, slack_time = fmu.getReal([vrs["T"], vrs["x_s"], vrs["slack_time"]])
        assert t == 0.0 and fmu.getBoolean([vrs["slack"]])[0]
        assert slack_time > 0.015
        assert 0.026 < x_s < 0.096
    finally:
        release(fmu)


# ---- the system ----------------------------------------------------------------------------


def test_ssd_is_valid_and_wires_the_2n_drive(ssp):
    ssd = read_ssd(str(ssp))  # validates against FMPy's bundled SSP 1.0 schema
    components = {c.name: c.source for c in ssd.system.elements}
    assert components == {
        "controller": "resources/JointController.fmu",
        "actuator_flexor": "resources/JetPipeActuator.fmu",
        "actuator_extensor": "resources/JetPipeActuator.fmu",
        "tendon_flexor": "resources/Tendon.fmu",
        "tendon_extensor": "resources/Tendon.fmu",
        "joint": "resources/FingerJoint.fmu",
    }
    wires = {(c.startElement, c.startConnector, c.endElement, c.endConnector) for c in ssd.system.connections}
    for side in ("flexor", "extensor"):
        assert (f"tendon_{side}", "x_s", f"actuator_{side}", "x_s") in wires
        assert (f"actuator_{side}", "F_act", f"tendon_{side}", "F_act") in wires
        assert ("joint", f"x_{side}", f"tendon_{side}", "x_joint") in wires
        assert (f"tendon_{side}", "T", "joint", f"T_{side}") in wires
    names = {p.name for p in ssp_sim.parameter_set(ssp).parameters}
    assert {"controller.Kp", "tendon_flexor.k", "joint.J", "actuator_extensor.x_s"} <= names


def assert_never_slack(result, label):
    t_min = min(result["tendon_flexor.T"].min(), result["tendon_extensor.T"].min())
    slack = max(result["tendon_flexor.slack_time"][-1], result["tendon_extensor.slack_time"][-1])
    print(f"{label}: minimum tendon tension {t_min:.2f} N, time slack {slack:.4f} s")
    assert t_min > 0.0, f"{label}: a tendon went slack (minimum tension {t_min} N)"
    assert slack == 0.0, f"{label}: a tendon was slack for {slack} s between communication points"
    return t_min


T_STEP, THETA_STEP = 0.2, 0.5


@pytest.fixture(scope="module")
def step_run(ssp):
    ref = lambda t: 0.0 if t < T_STEP else THETA_STEP  # noqa: E731
    return ssp_sim.simulate(ref, 1.2, ssp=ssp)


def test_step_response(step_run):
    result, seconds = step_run
    t = ssp_sim.output_time(result)
    # The controller sees the reference one step late (FMPy passes system inputs on after the step).
    m = ssp_sim.step_metrics(t, result["joint.theta"], T_STEP + ssp_sim.STEP_SIZE, 0.0, THETA_STEP)
    print(
        f"step 0 -> {THETA_STEP} rad: overshoot {m['overshoot_pct']:.1f} %, rise (10-90 %) {m['rise_s'] * 1e3:.0f} ms, "
        f"5 % settling {m['settling_s'] * 1e3:.0f} ms, final error {m['final_error_rad'] * 1e3:.1f} mrad "
        f"({seconds:.2f} s wall for 1.2 s)"
    )
    assert abs(m["final_error_rad"]) < 0.01
    assert m["overshoot_pct"] < 20.0
    assert m["rise_s"] < 0.1 and m["settling_s"] < 0.6
    before = t < T_STEP
    assert np.max(np.abs(result["joint.theta"][before])) < 1e-3, "the joint moved before the step: not at rest"
    assert_never_slack(result, "step")


@pytest.fixture(scope="module")
def sine_run(ssp):
    return ssp_sim.frequency_point(2.0, amplitude=0.3, ssp=ssp, settle=0.5, periods=2)


def test_2hz_sine_tracking(sine_run):
    gain, phase, result, seconds = sine_run
    print(f"2 Hz, 0.3 rad: amplitude ratio {gain:.3f} ({20 * np.log10(gain):+.2f} dB), phase {phase:.1f} deg "
          f"({seconds:.2f} s wall)")
    assert 0.85 < gain < 1.2
    assert -45.0 < phase < 0.0
    assert_never_slack(result, "2 Hz sine")


FREQUENCIES = [1.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0]


@pytest.fixture(scope="module")
def frequency_response(ssp):
    return [ssp_sim.frequency_point(f, amplitude=0.1, ssp=ssp) for f in FREQUENCIES]


def test_joint_position_bandwidth_is_near_8_hz(frequency_response):
    gains = [g for g, _, _, _ in frequency_response]
    print("f (Hz)   |theta/theta_ref| (dB)   phase (deg)   min tension (N)")
    for f, (g, p, r, _) in zip(FREQUENCIES, frequency_response):
        t_min = min(r["tendon_flexor.T"].min(), r["tendon_extensor.T"].min())
        print(f"{f:6.1f}   {20 * np.log10(g):+8.2f}               {p:7.1f}       {t_min:6.2f}")
    bw = ssp_sim.bandwidth(FREQUENCIES, gains)
    wall = sum(s for _, _, _, s in frequency_response)
    print(f"joint position bandwidth (-3 dB, 0.1 rad): {bw:.2f} Hz (Utah/MIT hand: 8 Hz, thesis §1.1.1); "
          f"{wall:.1f} s wall")
    assert bw is not None and 6.0 <= bw <= 10.0
    assert 0.8 < gains[0] < 1.3, "no tracking at 1 Hz"
    for f, (_, _, r, _) in zip(FREQUENCIES, frequency_response):
        assert_never_slack(r, f"{f} Hz")
