"""FMI 3.0 Co-Simulation and Model Exchange (issue 44): dist/JetPipeActuator-fmi3.fmu, from the same
model, variable table and binary as the FMI 2.0 archive.

FMPy simulates both 3.0 interfaces against the 2.0 Co-Simulation FMU (Co-Simulation must agree to
1e-9 N, Model Exchange with CVODE at a relative tolerance of 1e-8 within 0.005 N RMS), the archives
pass `fmpy validate`, the FMI 3.0 schema and FMU Manipulation Toolbox's checker, illegal calls are
errors that name the call and the state, and FMU states round-trip.

The archive is taken from $JETPIPE_FMU3 or dist/JetPipeActuator-fmi3.fmu (`bash scripts/package.sh`).
"""

from __future__ import annotations

import ctypes
import json
import os
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy.validation import validate_fmu

import scenarios
from jetpipe_fmu import default_fmu_path
from test_model_exchange import OUTPUTS, RMS_LIMIT_N, ME_TOLERANCE, before_events, chirp_signal, force_rms

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
FMPY_DIR = Path(fmpy.__file__).resolve().parent
SCHEMA = FMPY_DIR / "schema" / "fmi3" / "fmi3ModelDescription.xsd"
CS_LIMIT_N = 1e-9  # 3.0 Co-Simulation against 2.0 Co-Simulation (issue 44)


@pytest.fixture(scope="module")
def fmu3_path() -> Path:
    env = os.environ.get("JETPIPE_FMU3")
    path = Path(env) if env else REPO / "dist" / "JetPipeActuator-fmi3.fmu"
    if not path.is_file():
        pytest.fail(f"{path} not found (build it with `bash scripts/package.sh`)", pytrace=False)
    return path.resolve()


@pytest.fixture(scope="module")
def fmu2_path() -> Path:
    env = os.environ.get("JETPIPE_FMU")
    return Path(env).resolve() if env else default_fmu_path()


@pytest.fixture(scope="module")
def md3(fmu3_path):
    return fmpy.read_model_description(str(fmu3_path))


@pytest.fixture(scope="module")
def unzip3(fmu3_path, tmp_path_factory) -> Path:
    return Path(fmpy.extract(str(fmu3_path), str(tmp_path_factory.mktemp("fmu3"))))


def simulate(path, fmi_type, signal, t_end, interval, start_values=None):
    extra = {"relative_tolerance": ME_TOLERANCE, "record_events": True} if fmi_type == "ModelExchange" else {}
    return fmpy.simulate_fmu(str(path), fmi_type=fmi_type, stop_time=t_end, input=signal, output_interval=interval,
                             output=OUTPUTS, start_values=start_values or {}, **extra)


def preset(without_hysteresis=False):
    values = json.loads((REPO / "presets" / "thesis_measured.json").read_text())
    if without_hysteresis:
        values = {k: v for k, v in values.items() if not k.startswith("hysteresis")}
    return values


class Log:
    """A logMessage callback that keeps (status, category, message)."""

    def __init__(self):
        self.messages = []

    def __call__(self, env, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))

    def last(self):
        return self.messages[-1][2] if self.messages else ""


def make(unzip3, md3, kind, name):
    cls = FMU3Slave if kind == "cs" else FMU3Model
    fmu = cls(guid=md3.guid, unzipDirectory=str(unzip3), modelIdentifier=md3.coSimulation.modelIdentifier,
              instanceName=name)
    log = Log()
    fmu.instantiate(loggingOn=False, logMessage=log)
    fmu.log = log
    return fmu


def vr3(md3):
    return {v.name: v.valueReference for v in md3.modelVariables}


# ---- the archive and its description ----------------------------------------------------------


def test_the_fmi3_archive_carries_the_same_binary_as_the_fmi2_archive_under_the_fmi3_platform_names(fmu3_path, fmu2_path):
    with zipfile.ZipFile(fmu3_path) as z3, zipfile.ZipFile(fmu2_path) as z2:
        names3 = [n for n in z3.namelist() if n.startswith("binaries/") and not n.endswith("/")]
        assert "binaries/x86_64-linux/JetPipeActuator.so" in names3
        assert all(n.split("/")[1] in ("x86_64-linux", "x86_64-windows") for n in names3), names3
        assert z3.read("binaries/x86_64-linux/JetPipeActuator.so") == z2.read("binaries/linux64/JetPipeActuator.so")
        if "binaries/win64/JetPipeActuator.dll" in z2.namelist():
            assert z3.read("binaries/x86_64-windows/JetPipeActuator.dll") == z2.read("binaries/win64/JetPipeActuator.dll")
        text = z3.read("modelDescription.xml").decode()
    assert 'fmiVersion="3.0"' in text
    assert text == (REPO / "modelDescription-fmi3.xml").read_text(), "the archive's description is not the checked-in one"


def test_the_fmi3_description_declares_both_interfaces_the_states_the_event_indicators_and_units(md3, fmu2_path):
    md2 = fmpy.read_model_description(str(fmu2_path))
    assert md3.fmiVersion == "3.0"
    assert md3.guid == md2.guid  # the instantiation token is the 2.0 GUID
    assert md3.coSimulation is not None and md3.modelExchange is not None
    assert [d.variable.name for d in md3.derivatives] == [d.variable.name for d in md2.derivatives]
    assert len(md3.eventIndicators) == md2.numberOfEventIndicators == 8
    assert md3.modelExchange.needsCompletedIntegratorStep  # the hysteresis memory is advanced there
    by_name2 = {v.name: v for v in md2.modelVariables}
    for v in md3.modelVariables:
        if v.name in by_name2:
            w = by_name2[v.name]
            assert (v.causality, v.variability, v.unit, v.start) == (w.causality, w.variability, w.unit, w.start), v.name
            assert v.type == {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}[w.type], v.name
    assert sorted(u.name for u in md3.unitDefinitions) == sorted(u.name for u in md2.unitDefinitions)
    assert {u.variable.name for u in md3.outputs} == {u.variable.name for u in md2.outputs}


def test_fmpy_validates_both_archives(fmu3_path, fmu2_path):
    for path in (fmu3_path, fmu2_path):
        problems = validate_fmu(str(path))
        assert problems == [], f"{path.name}:\n" + "\n".join(problems)


def test_the_fmi3_schema_validates_the_fmi3_description(fmu3_path):
    from lxml import etree
    schema = etree.XMLSchema(etree.parse(str(SCHEMA)))
    with zipfile.ZipFile(fmu3_path) as z:
        doc = etree.fromstring(z.read("modelDescription.xml"))
    assert schema.validate(doc), str(schema.error_log)


def test_fmu_manipulation_toolbox_reads_both_archives(fmu3_path, fmu2_path):
    fmutool = Path(sys.executable).with_name("fmutool")
    for path, version in ((fmu3_path, "FMI-3.0"), (fmu2_path, "FMI-2.0")):
        proc = subprocess.run([str(fmutool), "-input", str(path), "-check"], capture_output=True, text=True, timeout=300)
        text = proc.stdout + proc.stderr
        assert proc.returncode == 0, f"{path.name}: exit {proc.returncode}\n{text}"
        assert f"compliant with {version}" in text and "No semantic error" in text, f"{path.name}:\n{text}"
        assert "ERROR" not in text, f"{path.name}:\n{text}"


def test_the_generated_fmi3_header_compiles_with_the_standard_fmi3_functions_header(tmp_path):
    gcc = shutil.which("gcc")
    header = REPO / "target" / "include" / "jetpipe_fmi3.h"
    if gcc is None or not header.is_file():
        pytest.skip("gcc or target/include/jetpipe_fmi3.h missing")
    tu = tmp_path / "check_header3.c"
    tu.write_text('#include "fmi3Functions.h"\n#include "jetpipe_fmi3.h"\nint main(void) { return 0; }\n')
    cmd = [gcc, "-std=c99", "-Wall", "-Werror", "-fsyntax-only", f"-I{FMPY_DIR / 'c-code'}", f"-I{header.parent}", str(tu)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"the generated header conflicts with fmi3Functions.h:\n{proc.stderr}"
    assert header.read_text().count("fmi3Status fmi3") >= 60


# ---- simulations against FMI 2.0 Co-Simulation -------------------------------------------------


def test_fmi3_co_simulation_follows_fmi2_co_simulation_in_the_standard_scenario_within_1e_9_newton(fmu3_path, fmu2_path):
    signal = scenarios.input_signal()
    cs2 = simulate(fmu2_path, "CoSimulation", signal, scenarios.T_END, 1e-3)
    cs3 = simulate(fmu3_path, "CoSimulation", signal, scenarios.T_END, 1e-3)
    assert np.array_equal(cs2["time"], cs3["time"])
    diff = float(np.max(np.abs(cs3["F_act"] - cs2["F_act"])))
    print(f"standard scenario: max |F_act 3.0 CS - 2.0 CS| = {diff:.3e} N")
    assert diff <= CS_LIMIT_N
    assert np.ptp(cs3["F_act"]) > 10.0  # the scenario moves the force


def test_fmi3_co_simulation_follows_fmi2_co_simulation_in_a_chirp_within_1e_9_newton(fmu3_path, fmu2_path):
    signal = chirp_signal()
    cs2 = simulate(fmu2_path, "CoSimulation", signal, 2.0, 1e-4)
    cs3 = simulate(fmu3_path, "CoSimulation", signal, 2.0, 1e-4)
    diff = float(np.max(np.abs(cs3["F_act"] - cs2["F_act"])))
    print(f"chirp 1-100 Hz: max |F_act 3.0 CS - 2.0 CS| = {diff:.3e} N")
    assert diff <= CS_LIMIT_N


# Broad: test_tolerance_sweep.py runs FMI 3.0 Model Exchange on steps, sines, a chirp and a
# moving stopper against Co-Simulation.
@pytest.mark.broad
def test_fmi3_model_exchange_follows_fmi2_co_simulation_in_the_standard_scenario_within_five_millinewtons_rms(fmu3_path, fmu2_path):
    signal = scenarios.input_signal()
    cs2 = simulate(fmu2_path, "CoSimulation", signal, scenarios.T_END, 1e-3)
    me3 = simulate(fmu3_path, "ModelExchange", signal, scenarios.T_END, 1e-3)
    rms = force_rms(cs2, me3)
    print(f"standard scenario: F_act RMS 3.0 ME - 2.0 CS = {rms:.3e} N")
    assert rms < RMS_LIMIT_N


# Broad: test_tolerance_sweep.py runs FMI 3.0 Model Exchange on a chirp at two tolerances.
@pytest.mark.broad
def test_fmi3_model_exchange_follows_fmi2_co_simulation_in_a_chirp_within_five_millinewtons_rms(fmu3_path, fmu2_path):
    signal = chirp_signal()
    cs2 = simulate(fmu2_path, "CoSimulation", signal, 2.0, 1e-4)
    me3 = simulate(fmu3_path, "ModelExchange", signal, 2.0, 1e-4)
    rms = force_rms(cs2, me3)
    print(f"chirp 1-100 Hz: F_act RMS 3.0 ME - 2.0 CS = {rms:.3e} N")
    assert rms < RMS_LIMIT_N


def test_with_the_measured_preset_fmi3_co_simulation_follows_fmi2_within_1e_9_newton(fmu3_path, fmu2_path):
    signal = scenarios.input_signal()[:401]  # the first 2 s
    values = preset()
    assert any(k.startswith("hysteresis") for k in values)
    cs2 = simulate(fmu2_path, "CoSimulation", signal, 2.0, 1e-3, values)
    cs3 = simulate(fmu3_path, "CoSimulation", signal, 2.0, 1e-3, values)
    plain = simulate(fmu2_path, "CoSimulation", signal, 2.0, 1e-3)
    diff = float(np.max(np.abs(cs3["F_act"] - cs2["F_act"])))
    print(f"thesis_measured, standard scenario 2 s: max |F_act 3.0 CS - 2.0 CS| = {diff:.3e} N")
    assert diff <= CS_LIMIT_N
    assert np.max(np.abs(cs3["F_act"] - plain["F_act"])) > 0.1  # the preset is on


# Broad: test_model_exchange_hysteresis.py runs the preset in FMI 3.0 Model Exchange.
@pytest.mark.broad
def test_with_the_measured_preset_and_its_hysteresis_fmi3_model_exchange_follows_fmi2_co_simulation(fmu3_path, fmu2_path):
    signal = scenarios.input_signal()[:401]
    values = preset()
    assert values["hysteresis_width"] > 0
    cs2 = simulate(fmu2_path, "CoSimulation", signal, 2.0, 1e-3, values)
    me3 = simulate(fmu3_path, "ModelExchange", signal, 2.0, 1e-3, values)
    rms = force_rms(cs2, me3)
    print(f"thesis_measured, 2 s: F_act RMS 3.0 ME - 2.0 CS = {rms:.3e} N")
    assert rms < RMS_LIMIT_N


def test_the_transport_delay_is_refused_in_fmi3_model_exchange_by_name(unzip3, md3):
    vrs = vr3(md3)
    fmu = make(unzip3, md3, "me", "delay")
    try:
        fmu.enterInitializationMode()
        fmu.setFloat64([vrs["command_delay"]], [2e-3])  # refused when initialisation ends
        with pytest.raises(Exception):
            fmu.exitInitializationMode()
        text = fmu.log.last()
        assert "transport_delay" in text and "command_delay_pade_sections" in text and "Co-Simulation" in text, text
        assert text.startswith("fmi3ExitInitializationMode"), text
    finally:
        fmu.freeInstance()


# ---- the calls ---------------------------------------------------------------------------------


def test_an_fmi3_instance_runs_model_exchange_calls_and_its_event_indicator_variables_match(unzip3, md3):
    vrs = vr3(md3)
    fmu = make(unzip3, md3, "me", "me_calls")
    try:
        nx = fmu.getNumberOfContinuousStates()
        nz = fmu.getNumberOfEventIndicators()
        assert (nx, nz) == (31, 8)
        fmu.setFloat64([vrs["v_DA"]], [2.5])
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()
        flags = fmu.updateDiscreteStates()
        assert not flags[0]  # discreteStatesNeedUpdate
        fmu.enterContinuousTimeMode()
        x, dx, z = (ctypes.c_double * nx)(), (ctypes.c_double * nx)(), (ctypes.c_double * nz)()
        fmu.getContinuousStates(x, nx)
        fmu.getContinuousStateDerivatives(dx, nx)
        fmu.getEventIndicators(z, nz)
        x, dx, z = list(x), list(dx), list(z)
        assert np.all(np.isfinite(x)) and np.all(np.isfinite(dx))
        assert max(abs(v) for v in dx[:6]) < 1e-3 * max(1.0, max(abs(v) for v in x))  # at equilibrium
        indicators = [vrs[f"event_indicator_{k + 1}"] for k in range(nz)]
        assert list(fmu.getFloat64(indicators)) == list(z)
        assert fmu.getFloat64([vrs["time"]])[0] == 0.0
        fmu.setTime(1e-3)
        x2 = list(x)
        x2[4] += 1000.0  # P1 up by 1 kPa
        fmu.setContinuousStates((ctypes.c_double * nx)(*x2), nx)
        assert fmu.getFloat64([vrs["P1_at_mid_stroke"]])[0] == x2[4]
        enter_event, terminate = fmu.completedIntegratorStep()
        assert not enter_event and not terminate
        fmu.terminate()
    finally:
        fmu.freeInstance()


@pytest.mark.parametrize("call, expected", [
    (lambda f, v: f.doStep(0.0, 1e-3), "fmi3DoStep: illegal call in state instantiated"),
    (lambda f, v: f.exitInitializationMode(), "fmi3ExitInitializationMode: illegal call in state instantiated"),
    (lambda f, v: f.enterStepMode(), "fmi3EnterStepMode: illegal call in state instantiated"),
    (lambda f, v: f.getFloat32([v["v_DA"]]), "fmi3GetFloat32: value reference"),
    (lambda f, v: f.getFloat64([v["F_act"]]), "has no value in state instantiated"),
    (lambda f, v: f.setFloat64([v["F_act"]], [1.0]), "is an output and cannot be set"),
    (lambda f, v: f.setFloat64([v["v_DA"]], [11.0]), "v_DA"),
    (lambda f, v: f.getDirectionalDerivative([v["F_act"]], [v["v_DA"]], [1.0]),
     "fmi3GetDirectionalDerivative: illegal call in state instantiated"),
    (lambda f, v: f.enterConfigurationMode(), "no structural parameters"),
])
def test_an_illegal_or_unsupported_fmi3_call_is_an_error_that_names_the_call(unzip3, md3, call, expected):
    vrs = vr3(md3)
    fmu = make(unzip3, md3, "cs", "misuse")
    try:
        with pytest.raises(Exception):
            call(fmu, vrs)
        assert expected in fmu.log.last(), fmu.log.last()
        assert fmu.log.messages[-1][0] == 3  # fmi3Error
        # the instance still works
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.doStep(0.0, 1e-3)
    finally:
        fmu.freeInstance()


def test_in_step_mode_model_exchange_calls_and_enter_step_mode_are_errors_that_say_why(unzip3, md3):
    fmu = make(unzip3, md3, "cs", "step_mode")
    try:
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        derivatives = fmu.dll.fmi3GetContinuousStateDerivatives
        derivatives.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_double), ctypes.c_size_t]
        derivatives.restype = ctypes.c_int
        assert derivatives(fmu.component, (ctypes.c_double * 31)(), 31) == 3
        assert "fmi3GetContinuousStateDerivatives: illegal call in state stepMode" in fmu.log.last()
        assert "is a Model Exchange function" in fmu.log.last()
        with pytest.raises(Exception):
            fmu.enterStepMode()
        assert "hasEventMode" in fmu.log.last(), fmu.log.last()
        with pytest.raises(Exception):
            fmu.getDirectionalDerivative([vr3(md3)["F_act"]], [vr3(md3)["v_DA"]], [1.0])
        assert "fmi3GetDirectionalDerivative: not supported" in fmu.log.last(), fmu.log.last()
        with pytest.raises(Exception):
            fmu.doStep(0.5, 1e-3)
        assert "does not match the FMU's time" in fmu.log.last()
        fmu.doStep(0.0, 1e-3)
    finally:
        fmu.freeInstance()


def test_an_fmi2_call_on_an_fmi3_instance_is_an_error_and_leaves_it_usable(unzip3, md3):
    fmu = make(unzip3, md3, "cs", "cross")
    try:
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmi2DoStep = fmu.dll.fmi2DoStep
        fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
        fmi2DoStep.restype = ctypes.c_int
        assert fmi2DoStep(fmu.component, 0.0, 1e-3, 1) == 3
        assert "fmi2DoStep: the instance was made by fmi3Instantiate" in fmu.log.last(), fmu.log.last()
        fmu.doStep(0.0, 1e-3)
    finally:
        fmu.freeInstance()


def test_a_wrong_instantiation_token_or_event_mode_gives_no_instance_and_says_why(unzip3, md3):
    fmu = FMU3Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=str(unzip3),
                    modelIdentifier="JetPipeActuator", instanceName="token")
    log = Log()
    with pytest.raises(Exception):
        fmu.instantiate(logMessage=log)
    assert "instantiationToken mismatch" in log.last(), log.last()
    fmu = FMU3Slave(guid=md3.guid, unzipDirectory=str(unzip3), modelIdentifier="JetPipeActuator", instanceName="ev")
    log = Log()
    with pytest.raises(Exception):
        fmu.instantiate(eventModeUsed=True, logMessage=log)
    assert "hasEventMode" in log.last(), log.last()


def test_an_fmi3_fmu_state_round_trips_through_its_bytes_and_is_refused_by_the_other_interface(unzip3, md3):
    vrs = vr3(md3)
    fmu = make(unzip3, md3, "cs", "state")
    me = make(unzip3, md3, "me", "state_me")
    try:
        fmu.setFloat64([vrs["v_DA"]], [2.5])
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        fmu.setFloat64([vrs["v_DA"]], [6.0])
        state = fmu.getFMUState()
        data = fmu.serializeFMUState(state)
        first = []
        t = 0.0
        for _ in range(20):
            fmu.doStep(t, 1e-3)
            t += 1e-3
            first.append(fmu.getFloat64([vrs["F_act"]])[0])
        restored = fmu.deserializeFMUState(data)
        fmu.setFMUState(restored)
        again = []
        t = 0.0
        for _ in range(20):
            fmu.doStep(t, 1e-3)
            t += 1e-3
            again.append(fmu.getFloat64([vrs["F_act"]])[0])
        assert again == first and first[-1] != first[0]
        with pytest.raises(Exception):
            me.setFMUState(state)
        assert "taken from a Co-Simulation instance" in me.log.last(), me.log.last()
        fmu.freeFMUState(state)
        fmu.freeFMUState(restored)
    finally:
        fmu.freeInstance()
        me.freeInstance()
