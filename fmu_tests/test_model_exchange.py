"""FMI 2.0 Model Exchange in the same archive as Co-Simulation (issue 44): FMPy integrates the
actuator's derivatives with CVODE and follows the Co-Simulation step, the archive declares both
interfaces with one binary, and the effects Model Exchange does not have are refused by name.

The comparisons sample both runs at the same instants with the same convention: FMPy's
Co-Simulation records an output at an input change before the new input acts, so Model
Exchange's value there is taken before the event (its run records both sides of each event).
"""

from __future__ import annotations

import math
import zipfile

import fmpy
import numpy as np
import pytest
from fmpy.fmi2 import FMU2Model
from fmpy.validation import validate_fmu

import scenarios
from jetpipe_fmu import LogRecorder, _ALLOCATE, _FREE, _LOGGER, _lock, _registry, vr_map

ME_TOLERANCE = 1e-8
RMS_LIMIT_N = 0.005  # a tenth of a bench's force noise (issue 44)
OUTPUTS = ["F_act", "P1", "P2", "i", "x_jp"]


def chirp_signal(t_end=2.0, f0=1.0, f1=100.0, sample=1e-3):
    """v_DA sweeping from f0 to f1 Hz (linear chirp) about 0.5 V with 3 V amplitude, across the
    jet pipe's centre (x_abs = 0 near -1.2 V); held for `sample` s (a zero-order hold, as a D/A
    converter gives it), the stopper still."""
    dtype = [("time", np.float64), ("v_DA", np.float64), ("x_s", np.float64)]
    n = int(round(t_end / sample))

    def v(k):
        t = k * sample
        return 0.5 + 3.0 * math.sin(2 * math.pi * (f0 * t + (f1 - f0) * t * t / (2 * t_end)))

    rows = [(0.0, v(0), 0.054)]
    for k in range(1, n):
        t = k * sample
        rows.append((t, v(k - 1), 0.054))
        rows.append((t, v(k), 0.054))
    rows.append((t_end, v(n - 1), 0.054))
    return np.array(rows, dtype=dtype)


def co_simulation(fmu_path, signal, t_end, interval):
    return fmpy.simulate_fmu(str(fmu_path), fmi_type="CoSimulation", stop_time=t_end, input=signal,
                             output_interval=interval, output=OUTPUTS)


def model_exchange(fmu_path, signal, t_end, interval, start_values=None):
    return fmpy.simulate_fmu(str(fmu_path), fmi_type="ModelExchange", stop_time=t_end, input=signal,
                             output_interval=interval, relative_tolerance=ME_TOLERANCE, output=OUTPUTS,
                             record_events=True, start_values=start_values or {})


def before_events(me, times):
    """The rows of `me` at `times`, the first of each instant (the value before its event).
    An instant is matched within 1 ns, as `tolerance_sweep.before_events` does: where CVODE
    finds a root a few 1e-11 s before an output instant, FMPy records its rows there and none
    at the instant itself (seen at 1.829 s with the measured preset at 1e-8, and with the
    same archive built before the lags and filters became states at 1.997 s at 1e-6)."""
    idx = np.searchsorted(me["time"], times - 1e-9, side="left")
    assert np.allclose(me["time"][idx], times, atol=1e-9, rtol=0)
    return me[idx]


def force_rms(cs, me):
    me_at = before_events(me, cs["time"])
    return float(np.sqrt(np.mean((cs["F_act"] - me_at["F_act"]) ** 2)))


def test_the_archive_declares_both_interfaces_with_one_binary_per_platform(fmu_path, model_description):
    md = model_description
    assert md.modelExchange is not None and md.coSimulation is not None
    assert md.modelExchange.modelIdentifier == md.coSimulation.modelIdentifier == "JetPipeActuator"
    assert md.modelExchange.canGetAndSetFMUstate and md.modelExchange.canSerializeFMUstate
    assert md.numberOfContinuousStates == 31
    assert md.numberOfEventIndicators == 8
    # the hysteresis memory is advanced after each step
    assert md.modelExchange.needsCompletedIntegratorStep  # (FMPy: not completedIntegratorStepNotNeeded)
    states = [d.variable.derivative.name for d in md.derivatives]
    assert states == ["i", "x_jp", "x_jp_velocity", "x_jp_acceleration", "P1_at_mid_stroke", "P2_at_mid_stroke", "p_supply_plenum",
                      "p_return_plenum", "p_port_line_1", "p_port_line_2", "stopper_mount_load",
                      # the command stage's and the transducers' lags and filters
                      "command_lagged", "command_filtered", "command_filtered_rate", "F_meas_lagged", "F_meas_filtered", "F_meas_filtered_rate", "P1_meas_lagged", "P1_meas_filtered", "P1_meas_filtered_rate", "P2_meas_lagged", "P2_meas_filtered", "P2_meas_filtered_rate",
                      "command_delay_pade_1", "command_delay_pade_2", "command_delay_pade_3", "command_delay_pade_4", "command_delay_pade_5", "command_delay_pade_6", "command_delay_pade_7", "command_delay_pade_8"]
    with zipfile.ZipFile(fmu_path) as z:
        binaries = [n for n in z.namelist() if n.startswith("binaries/") and not n.endswith("/")]
    platforms = [n.split("/")[1] for n in binaries]
    assert len(platforms) == len(set(platforms)), binaries


def test_fmpy_validates_the_archive_with_both_interfaces(fmu_path):
    problems = validate_fmu(str(fmu_path))
    assert problems == [], "\n".join(problems)


def test_model_exchange_follows_the_standard_scenario_within_five_millinewtons_rms_of_co_simulation(fmu_path):
    signal = scenarios.input_signal()
    cs = co_simulation(fmu_path, signal, scenarios.T_END, 1e-3)
    me = model_exchange(fmu_path, signal, scenarios.T_END, 1e-3)
    rms = force_rms(cs, me)
    print(f"standard scenario: F_act RMS difference ME - CS = {rms:.3e} N")
    assert rms < RMS_LIMIT_N
    me_at = before_events(me, cs["time"])
    for name in ("P1", "P2"):
        assert np.max(np.abs(cs[name] - me_at[name])) < 50.0, name


def test_model_exchange_follows_a_chirp_within_five_millinewtons_rms_of_co_simulation(fmu_path):
    signal = chirp_signal()
    cs = co_simulation(fmu_path, signal, 2.0, 1e-4)
    me = model_exchange(fmu_path, signal, 2.0, 1e-4)
    rms = force_rms(cs, me)
    print(f"chirp 1-100 Hz: F_act RMS difference ME - CS = {rms:.3e} N")
    assert rms < RMS_LIMIT_N
    # the chirp drives the jet pipe across its centre, a tangency of the orifice geometry
    x_abs = cs["x_jp"] + 0.099e-3
    assert x_abs.min() < 0 < x_abs.max()


def make_model(unzipdir, model_description, name):
    """An FMU2Model (Model Exchange) whose log messages land in `.log`."""
    from ctypes import byref
    from fmpy.fmi2 import fmi2CallbackFunctions
    from fmpy.logging import addLoggerProxy

    fmu = FMU2Model(guid=model_description.guid, unzipDirectory=str(unzipdir),
                    modelIdentifier=model_description.modelExchange.modelIdentifier, instanceName=name)
    env_id = 0x4D45 + id(fmu) % 100000
    rec = LogRecorder()
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = _LOGGER
    callbacks.allocateMemory = _ALLOCATE
    callbacks.freeMemory = _FREE
    callbacks.componentEnvironment = env_id
    addLoggerProxy(byref(callbacks))
    with _lock:
        _registry[env_id] = rec
    fmu.log = rec
    fmu.instantiate(callbacks=callbacks, loggingOn=True)
    return fmu


@pytest.mark.parametrize("parameter, value, effect", [
    ("current_slew_limit", 2.0, "slew limit"),
    ("p1_sensor_delay", 1e-3, "transducers"),
])
def test_an_effect_that_is_not_an_ode_is_refused_in_model_exchange_by_name_and_runs_in_co_simulation(
        unzipdir, model_description, fmu_path, parameter, value, effect):
    vrs = vr_map(model_description)
    fmu = make_model(unzipdir, model_description, f"refuse_{parameter}")
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        with pytest.raises(Exception):
            fmu.setReal([vrs[parameter]], [value])
        text = fmu.log.text()
        assert effect in text and parameter in text and "Model Exchange does not have" in text, text
        assert "use the Co-Simulation interface" in text
    finally:
        fmu.freeInstance()
    with pytest.raises(Exception):
        model_exchange(fmu_path, scenarios.input_signal()[:5], 0.01, 1e-3, start_values={parameter: value})
    r = fmpy.simulate_fmu(str(fmu_path), fmi_type="CoSimulation", stop_time=0.05, output_interval=1e-3,
                          start_values={parameter: value, "v_DA": 2.5})
    assert np.all(np.isfinite(r["F_act"]))


def test_the_transport_delay_without_pade_sections_is_refused_when_initialisation_ends_naming_the_option(
        unzipdir, model_description):
    """Taken when set (an importer sets the parameters in the model description's order, the
    delay before `command_delay_pade_sections`), refused when initialisation ends."""
    vrs = vr_map(model_description)
    fmu = make_model(unzipdir, model_description, "refuse_command_delay")
    try:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([vrs["command_delay"]], [2e-3])
        with pytest.raises(Exception):
            fmu.exitInitializationMode()
        text = fmu.log.text()
        assert "transport_delay" in text and "is not an ODE" in text and "command_delay_pade_sections" in text, text
    finally:
        fmu.freeInstance()


# Broad: test_model_exchange_hysteresis.py runs the preset through reversals and steps.
@pytest.mark.broad
def test_the_thesis_measured_preset_with_its_hysteresis_runs_in_model_exchange(fmu_path):
    """The whole preset: its fitted terms (flow constants, dead volume, vent) and its Bouc-Wen
    hysteresis, whose memory Model Exchange advances where the current reverses
    (fmu_tests/test_model_exchange_hysteresis.py has the reversals)."""
    import json
    from pathlib import Path
    preset = json.loads((Path(__file__).resolve().parent.parent / "presets" / "thesis_measured.json").read_text())
    assert preset["hysteresis_width"] > 0
    signal = scenarios.input_signal()[:401]  # the first 2 s
    cs = fmpy.simulate_fmu(str(fmu_path), fmi_type="CoSimulation", stop_time=2.0, input=signal,
                           output_interval=1e-3, output=OUTPUTS, start_values=preset)
    me = model_exchange(fmu_path, signal, 2.0, 1e-3, start_values=preset)
    rms = force_rms(cs, me)
    print(f"thesis_measured, standard scenario 2 s: F_act RMS ME - CS = {rms:.3e} N")
    assert rms < RMS_LIMIT_N


def test_gas_volumes_behind_restrictions_and_a_lagging_mount_are_states_that_follow_co_simulation(fmu_path):
    """The ODE effects beyond (4.1) are states of Model Exchange: a supply plenum and a port
    line behind restrictions, a compliant stopper on a lagging mount."""
    volumes = {
        "supply_restriction_area": 2e-6, "supply_plenum_volume": 5e-6,
        "port_restriction_area_1": 0.5e-6, "port_line_volume_1": 1e-6,
        "stopper_compliance": 2e-5, "stopper_mount_lag": 2e-3,
    }
    signal = scenarios.input_signal()[:401]  # the first 2 s
    cs = fmpy.simulate_fmu(str(fmu_path), fmi_type="CoSimulation", stop_time=2.0, input=signal,
                           output_interval=1e-3, output=OUTPUTS, start_values=volumes)
    me = model_exchange(fmu_path, signal, 2.0, 1e-3, start_values=volumes)
    rms = force_rms(cs, me)
    print(f"gas volumes and a lagging mount, standard scenario 2 s: F_act RMS ME - CS = {rms:.3e} N")
    assert rms < RMS_LIMIT_N
