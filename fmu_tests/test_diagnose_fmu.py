"""The diagnosis's FMU start values reproduce its reported error through the FMU.

A recording with a named effect, or with an undeclared one that the diagnosis discovers,
comes from the independent generator (benchgen); `jetpipe diagnose` adds the effect or the
term and reports `fmu_start_values`. Setting those on the packaged FMU and replaying the
recording through FMPy (command held between samples, the stopper moving linearly via
fmi2SetRealInputDerivatives between the smoothed positions the report's `stopper_positions`
names) must give the reported `after` error within 5 %.
"""

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from jetpipe_fmu import initialize, make_slave, release

ROOT = Path(__file__).resolve().parent.parent
BIN = ROOT / "target" / "release"


def stopper_positions(x, residual_limit):
    """The report's `stopper_positions`: where it gives a
    `stopper_positions_smoothing_residual_limit_m2` (1 kHz and faster), x_s smoothed over
    samples k-3..k+3 with the weights (-2, 3, 6, 7, 6, 3, -2)/21 at each sample whose seven
    positions leave at most that sum of squares about their least-squares quadratic, the
    recorded positions elsewhere and at the first and last three samples; else (None) x_s as
    recorded."""
    x = np.asarray(x, dtype=float)
    if residual_limit is None:
        return x.copy()
    weights = np.array([-2.0, 3.0, 6.0, 7.0, 6.0, 3.0, -2.0]) / 21.0
    i = np.arange(-3.0, 4.0)
    basis = np.vstack([np.ones(7), i, i * i]).T
    out = x.copy()
    for k in range(3, len(x) - 3):
        d = x[k - 3:k + 4] - x[k]
        _, residual, _, _ = np.linalg.lstsq(basis, d, rcond=None)
        if residual.size and residual[0] > residual_limit:
            continue
        out[k] = x[k] + np.sum(weights * d)
    return out


def stopper_accelerations(t, x, half_width):
    """The report's `stopper_acceleration_input` recipe: (x(t+T) - 2 x(t) + x(t-T)) / T^2, x
    linear between samples, T shrunk to the time left near the ends, 0 at the first and last."""
    t, x = np.asarray(t, dtype=float), np.asarray(x, dtype=float)
    half = np.minimum(half_width, np.minimum(t - t[0], t[-1] - t))
    a = np.zeros_like(x)
    inner = half > 0
    h = half[inner]
    a[inner] = (np.interp(t[inner] + h, t, x) - 2.0 * x[inner] + np.interp(t[inner] - h, t, x)) / (h * h)
    return a


def replay_through_fmu(unzipdir, model_description, vrs, recording, start_values, smoothing, outputs=("F_meas",),
                       acceleration=None):
    """The FMU's `outputs` at every sample of the recording (one array, or a tuple of them),
    the stopper driven with the positions the diagnosis replays (`smoothing`: the report's
    `stopper_positions_smoothing_residual_limit_m2`) and, where the report's `stopper_acceleration_input`
    (`acceleration`) says so, its acceleration fed to the input a_s."""
    fmu = make_slave(unzipdir, model_description)
    t, v, x = recording["time_s"], recording["v_da_V"], stopper_positions(recording["x_s_m"], smoothing)
    a = None if acceleration is None else stopper_accelerations(t, x, acceleration["half_width_s"])
    try:
        # The report's start values are Reals but for start_at_equilibrium, a Boolean (false
        # where the replays started the chambers at the pressures first read).
        reals = {n: value for n, value in start_values.items() if not isinstance(value, bool)}
        booleans = {n: value for n, value in start_values.items() if isinstance(value, bool)}
        initialize(fmu, vrs, inputs=(v[0], x[0]), parameters=reals, booleans=booleans)
        read = np.empty((len(outputs), len(t)))
        vr_v, vr_x, vr_a, vr_out = [vrs["v_DA"]], [vrs["x_s"]], [vrs["a_s"]], [vrs[name] for name in outputs]
        if a is not None:
            fmu.setReal(vr_a, [a[0]])
        for k in range(len(t)):
            # The stopper's motion on to the next sample is set before the outputs at this
            # one are read: they read the velocity between the two intervals, as the
            # diagnosis's replays do.
            if k + 1 < len(t):
                fmu.setRealInputDerivatives(vr_x, [1], [(x[k + 1] - x[k]) / (t[k + 1] - t[k])])
            read[:, k] = fmu.getReal(vr_out)
            if k + 1 == len(t):
                break
            dt = t[k + 1] - t[k]
            fmu.setReal(vr_v, [v[k]])
            if a is not None:
                fmu.setRealInputDerivatives(vr_a, [1], [(a[k + 1] - a[k]) / dt])
            fmu.doStep(currentCommunicationPoint=t[k], communicationStepSize=dt)
        return read[0] if len(outputs) == 1 else tuple(read)
    finally:
        release(fmu)


needs_binaries = pytest.mark.skipif(
    not (BIN / "benchgen").exists() or not (BIN / "jetpipe").exists(),
    reason="needs target/release/benchgen and jetpipe (cargo test --release builds them)")


def generated_and_diagnosed(tmp_path, name, *benchgen_args):
    """A recording from the independent generator and `jetpipe diagnose`'s report on it."""
    recording_path = tmp_path / f"{name}.csv"
    subprocess.run([str(BIN / "benchgen"), "--out", str(recording_path), *benchgen_args],
                   check=True, capture_output=True)
    report_path = tmp_path / "report.json"
    subprocess.run([str(BIN / "jetpipe"), "diagnose", str(recording_path), "--report", str(report_path)],
                   check=True, capture_output=True)
    recording = np.genfromtxt(recording_path, delimiter=",", names=True)
    return recording, json.loads(report_path.read_text())


def force_errors_through_fmu(unzipdir, model_description, vrs, recording, report, name):
    """The force's RMS error with the report's start values through the FMU, the one the
    report gives after, and the one before."""
    force = replay_through_fmu(unzipdir, model_description, vrs, recording, report["fmu_start_values"], report["stopper_positions_smoothing_residual_limit_m2"], acceleration=report.get("stopper_acceleration_input"))
    rms = float(np.sqrt(np.mean((recording["force_N"] - force) ** 2)))
    reported, before = report["after"]["force_rms_N"], report["before"]["force_rms_N"]
    print(f"{name}: after error reported {reported:.5f} N, FMU replay {rms:.5f} N; before {before:.4f} N")
    return rms, reported, before


# Broad: crates/cli/tests/diagnosis_through_fmu.rs drives the FMU as a report says on a friction.
@needs_binaries
@pytest.mark.broad
def test_fmu_start_values_reproduce_the_after_error(unzipdir, model_description, vrs, tmp_path):
    recording, report = generated_and_diagnosed(tmp_path, "friction", "--seed", "31", "--friction-coulomb", "2.5")
    assert [e["name"] for e in report["effects"]][:1] == ["piston_friction"], report["effects"]
    force = replay_through_fmu(unzipdir, model_description, vrs, recording, report["fmu_start_values"], report["stopper_positions_smoothing_residual_limit_m2"], acceleration=report.get("stopper_acceleration_input"))
    rms = float(np.sqrt(np.mean((recording["force_N"] - force) ** 2)))
    reported = report["after"]["force_rms_N"]
    print(f"after error: reported {reported:.5f} N, FMU replay {rms:.5f} N; before {report['before']['force_rms_N']:.4f} N")
    assert abs(rms - reported) <= 0.05 * reported


# A term in the command stage (a rate limit between communication points), one in the
# force sensor (a lag of its reading) and a port line's volume behind an orifice (a pressure
# state of its own): each has a memory the FMU keeps between steps.
@needs_binaries
@pytest.mark.parametrize("mechanism,parameter,duration", [pytest.param("current_slew_limit", "current_slew_limit", 80,
                                                                       marks=pytest.mark.broad),
                                                          ("force_sensor_lag", "force_sensor_lag", 20),
                                                          pytest.param("port_1_restriction", "port_line_volume_1", 40,
                                                                       marks=pytest.mark.broad)])
def test_fmu_start_values_of_a_discovered_term_reproduce_the_after_error(
        unzipdir, model_description, vrs, tmp_path, mechanism, parameter, duration):
    recording, report = generated_and_diagnosed(tmp_path, mechanism, "--seed", "41", "--duration", str(duration),
                                                "--undeclared", mechanism)
    assert report["effects"] == [], report["effects"]
    assert parameter in report["discovered"][0]["parameters"], report["discovered"]
    assert parameter in report["fmu_start_values"], report["fmu_start_values"]
    rms, reported, before = force_errors_through_fmu(unzipdir, model_description, vrs, recording, report, mechanism)
    assert rms < 0.5 * before
    assert abs(rms - reported) <= 0.05 * reported


# The Bouc–Wen law of jet_pipe_hysteresis, with the loop's starting state: its memory is the
# FMU state's hysteresis array, and the step's closed form (a parabola per step) must give
# through the FMU what the diagnosis's fast replay gave.
@needs_binaries
def test_fmu_start_values_of_a_bouc_wen_hysteresis_reproduce_the_after_error(
        unzipdir, model_description, vrs, tmp_path):
    # The protocol's first 40 s hold both branches and the minor loops that tell the laws apart.
    recording, report = generated_and_diagnosed(tmp_path, "hysteresis", "--seed", "105", "--duration", "40",
                                                "--hysteresis-width", "0.16e-3")
    assert [e["name"] for e in report["effects"]] == ["jet_pipe_hysteresis"], report["effects"]
    start_values = report["fmu_start_values"]
    assert start_values.get("hysteresis_exponent", 0) > 0, start_values
    assert start_values.get("hysteresis_start", 0) < -0.5, start_values
    force = replay_through_fmu(unzipdir, model_description, vrs, recording, start_values, report["stopper_positions_smoothing_residual_limit_m2"], acceleration=report.get("stopper_acceleration_input"))
    rms = float(np.sqrt(np.mean((recording["force_N"] - force) ** 2)))
    reported = report["after"]["force_rms_N"]
    print(f"after error: reported {reported:.5f} N, FMU replay {rms:.5f} N; before {report['before']['force_rms_N']:.4f} N")
    assert abs(rms - reported) <= 0.05 * reported


# A pressure transducer's terms act on P1_meas and P2_meas alone: the report's pressure errors
# after must come back through the FMU's transducer outputs, a delay's memory included.
@needs_binaries
@pytest.mark.parametrize("mechanism,parameter", [("p1_sensor_offset", "p1_sensor_offset"),
                                                 pytest.param("p2_sensor_delay", "p2_sensor_delay",
                                                              marks=pytest.mark.broad)])
def test_fmu_start_values_of_a_pressure_transducer_reproduce_the_pressure_errors_after(
        unzipdir, model_description, vrs, tmp_path, mechanism, parameter):
    recording, report = generated_and_diagnosed(tmp_path, mechanism, "--seed", "43", "--duration", "40",
                                                "--undeclared", mechanism)
    assert report["effects"] == [], report["effects"]
    assert parameter in report["discovered"][0]["parameters"], report["discovered"]
    assert report["discovered"][0]["location"] == "pressure_sensors", report["discovered"]
    p1, p2 = replay_through_fmu(unzipdir, model_description, vrs, recording, report["fmu_start_values"], report["stopper_positions_smoothing_residual_limit_m2"],
                                outputs=("P1_meas", "P2_meas"), acceleration=report.get("stopper_acceleration_input"))
    through_fmu = [float(np.sqrt(np.mean((recording[c] - p) ** 2))) for c, p in (("p1_Pa", p1), ("p2_Pa", p2))]
    reported = report["after"]["pressure_rms_Pa"]
    before = report["before"]["pressure_rms_Pa"]
    print(f"{mechanism}: pressure errors after reported {reported}, FMU replay {through_fmu}; before {before}")
    for c in range(2):
        assert abs(through_fmu[c] - reported[c]) <= 0.05 * reported[c]
    assert max(through_fmu) < 0.5 * max(before)


# An extra force on the piston from the library of local signals: a mass moving with the
# stopper, whose acceleration the FMU forms from its communication steps as the diagnosis
# forms it from the samples; and a seal friction growing with the chambers' pressures.
@needs_binaries
@pytest.mark.parametrize("name,args,parameter", [
    ("moving_mass", ("--moving-mass", "0.1", "--stopper", "moves:0.2"), "extra_force_acceleration"),
    pytest.param("seal_friction", ("--seal-pressure-friction", "1e-6", "--stopper", "moves:0.05"),
                 "extra_force_sign_pressure", marks=pytest.mark.broad),
])
def test_fmu_start_values_of_an_extra_force_on_the_piston_reproduce_the_after_error(
        unzipdir, model_description, vrs, tmp_path, name, args, parameter):
    recording, report = generated_and_diagnosed(tmp_path, name, "--protocol", "staircase", "--duration", "20",
                                                "--seed", "5", "--force-noise", "0.03", *args)
    assert report["discovered"][0]["location"] == "mechanics", report["discovered"]
    assert parameter in report["fmu_start_values"], report["fmu_start_values"]
    # A force on the stopper's motion reads the acceleration the report says how to form.
    assert report["fmu_start_values"]["stopper_acceleration_input_share"] == 1.0
    assert report["stopper_acceleration_input"]["half_width_s"] > 0
    force = replay_through_fmu(unzipdir, model_description, vrs, recording, report["fmu_start_values"], report["stopper_positions_smoothing_residual_limit_m2"], acceleration=report.get("stopper_acceleration_input"))
    rms = float(np.sqrt(np.mean((recording["force_N"] - force) ** 2)))
    reported = report["after"]["force_rms_N"]
    print(f"{name}: after error reported {reported:.5f} N, FMU replay {rms:.5f} N; "
          f"before {report['before']['force_rms_N']:.4f} N")
    assert rms < 0.5 * report["before"]["force_rms_N"]
    assert abs(rms - reported) <= 0.05 * reported
# A static curve (piecewise linear through its knots) on the force sensor and on a pressure
# transducer, found under another protocol than the bench's: the report's knots, set on the
# FMU, give its errors after.
@needs_binaries
@pytest.mark.parametrize("name,options,prefix,outputs", [
    ("force_saturation", ("--protocol", "staircase", "--force-sensor-saturation", "40"),
     "force_sensor_curve", ("F_meas",)),
    pytest.param("p1_saturation", ("--protocol", "ramps", "--sample-rate", "500", "--pressure-sensor-saturation", "450000"),
                 "p1_sensor_curve", ("P1_meas", "P2_meas"), marks=pytest.mark.broad),
])
def test_fmu_start_values_of_a_static_curve_reproduce_the_errors_after(
        unzipdir, model_description, vrs, tmp_path, name, options, prefix, outputs):
    recording, report = generated_and_diagnosed(tmp_path, name, "--seed", "5", "--duration", "20", *options)
    assert report["effects"] == [], report["effects"]
    start_values = report["fmu_start_values"]
    assert start_values.get(f"{prefix}_knots", 0) >= 3, start_values
    assert report["discovered"][0]["family"] == "limit", report["discovered"]
    read = replay_through_fmu(unzipdir, model_description, vrs, recording, start_values, report["stopper_positions_smoothing_residual_limit_m2"], outputs=outputs, acceleration=report.get("stopper_acceleration_input"))
    if outputs == ("F_meas",):
        rms = float(np.sqrt(np.mean((recording["force_N"] - read) ** 2)))
        reported = report["after"]["force_rms_N"]
        print(f"{name}: after error reported {reported:.5f} N, FMU replay {rms:.5f} N")
        assert abs(rms - reported) <= 0.1 * reported
    else:
        through_fmu = [float(np.sqrt(np.mean((recording[c] - p) ** 2))) for c, p in zip(("p1_Pa", "p2_Pa"), read)]
        reported = report["after"]["pressure_rms_Pa"]
        print(f"{name}: pressure errors after reported {reported}, FMU replay {through_fmu}")
        for c in range(2):
            assert abs(through_fmu[c] - reported[c]) <= 0.1 * reported[c]


# The general classes added at the valve, in the chambers' balances, at the force sensor and
# at the stopper's mount: the discharge coefficient as a curve of the pressure ratio, a leak
# from the supply into a chamber, a second-order filter on the reading (the FMU filters at its
# communication points), a compliant mount that lags (its state in the FMU's).
@needs_binaries
@pytest.mark.parametrize("name, options, parameter", [
    ("force_filter", ("--protocol", "sine", "--sample-rate", "250", "--force-sensor-filter", "25"),
     "force_sensor_filter_frequency"),
    ("mount_lag", ("--protocol", "staircase", "--sample-rate", "500", "--contact-stiffness", "2e4",
                   "--contact-lag", "1e-3"), "stopper_mount_lag"),
    pytest.param("discharge_rise", ("--protocol", "multisine", "--sample-rate", "500", "--no-pressures",
                                    "--discharge-ratio-rise", "0.3"), "discharge_curve_y_2", marks=pytest.mark.broad),
    pytest.param("supply_leak", ("--protocol", "staircase", "--sample-rate", "500", "--supply-leak-2", "1e-8"),
                 "chamber_supply_leak_2", marks=pytest.mark.broad),
])
def test_fmu_start_values_of_a_general_class_at_the_valve_chambers_sensor_or_mount_reproduce_the_after_error(
        unzipdir, model_description, vrs, tmp_path, name, options, parameter):
    recording, report = generated_and_diagnosed(tmp_path, name, "--seed", "5", "--duration", "20", *options)
    assert report["effects"] == [], report["effects"]
    assert parameter in report["fmu_start_values"], report["fmu_start_values"]
    rms, reported, before = force_errors_through_fmu(unzipdir, model_description, vrs, recording, report, name)
    assert rms < 0.1 * before
    assert abs(rms - reported) <= 0.1 * reported
