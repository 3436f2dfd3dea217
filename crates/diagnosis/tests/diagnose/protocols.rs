//! `jetpipe diagnose` on recordings made under other protocols than the bench's
//! (`synthetic_bench::protocols`): each general discovery piece on at least two protocols,
//! and at two sampling rates where the rate matters. The truths are the synthetic bench's,
//! written by its own integrator.

use super::diagnose;
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::Diagnosis;
use jetpipe_model::physics::parameters::Parameters;
use synthetic_bench::{
    generate_protocol, BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion, UndeclaredEffects,
};

use super::{names, value_reference};

/// The recording of `effects` under `spec`, through the CSV file the generator writes.
pub(crate) fn recorded(label: &str, spec: &ProtocolSpec, effects: &BenchEffects) -> Recording {
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-{}-{label}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    generate_protocol(spec, effects).unwrap().write_csv(&path).unwrap();
    let recording = Recording::read(&path, &Parameters::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    recording
}

/// The diagnosis of that recording, printed with its time.
pub(crate) fn diagnosed(label: &str, spec: &ProtocolSpec, effects: &BenchEffects) -> Diagnosis {
    let recording = recorded(label, spec, effects);
    let started = std::time::Instant::now();
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!(
        "{label} ({}): {} in {:.1} s; {}",
        spec.label(),
        d.verdict(),
        started.elapsed().as_secs_f64(),
        d.summary().join(" | ")
    );
    d
}

fn pickup(amplitude: f64, frequency: f64) -> BenchEffects {
    BenchEffects {
        undeclared: UndeclaredEffects {
            force_sensor_pickup_amplitude: amplitude,
            force_sensor_pickup_frequency: frequency,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    }
}

/// A pick-up of `amplitude` N at `frequency` Hz on the force, a sin(2π f t + 1): discovered
/// at the force sensor as periodic, its frequency within 0.05 % and its amplitude within
/// 10 %, the force explained, nothing named.
fn pickup_found(label: &str, spec: &ProtocolSpec, amplitude: f64, frequency: f64) {
    let d = diagnosed(label, spec, &pickup(amplitude, frequency));
    assert!(names(&d).is_empty(), "{label}: named {:?}", names(&d));
    let found = d
        .discovered
        .first()
        .unwrap_or_else(|| panic!("{label}: nothing discovered ({})", d.summary()[0]));
    assert_eq!(
        (found.location.as_str(), found.family.as_str()),
        ("force_sensor", "periodic"),
        "{}",
        found.reading
    );
    let get = |name: &str| d.parameters.get(value_reference(name)).unwrap();
    let fitted_hz = get("force_sensor_ripple_frequency");
    assert!(
        (fitted_hz - frequency).abs() < 5e-4 * frequency,
        "{label}: {fitted_hz} Hz"
    );
    // a sin(ωt + 1) = a cos 1 sin ωt + a sin 1 cos ωt
    let (sine, cosine) = (get("force_sensor_ripple_sine"), get("force_sensor_ripple_cosine"));
    let fitted_amplitude = sine.hypot(cosine);
    assert!(
        (fitted_amplitude - amplitude).abs() < 0.1 * amplitude,
        "{label}: amplitude {fitted_amplitude}"
    );
    assert!(
        (cosine.atan2(sine) - 1.0).abs() < 0.1,
        "{label}: phase {}",
        cosine.atan2(sine)
    );
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
#[ignore = "a broad case (about 29 s of CPU); scripts/bench_cases.sh runs every case"]
fn a_fifty_hertz_pickup_under_a_multisine_at_one_kilohertz_without_pressures_is_discovered() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        sample_rate: 1000.0,
        duration: 40.0,
        pressures: false,
        seed: 3,
        ..ProtocolSpec::default()
    };
    pickup_found("pickup-multisine", &spec, 0.2, 50.0);
}

#[test]
#[ignore = "60,000 samples; the pick-up under every protocol is scripts/bench_protocols.sh's, the test command keeps 1 kHz, 500 Hz and 250 Hz"]
fn a_fifty_hertz_pickup_under_a_prbs_at_two_kilohertz_with_a_shaken_stopper_is_discovered() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Prbs,
        stopper: StopperMotion::Sine {
            centre: 0.054,
            amplitude: 0.004,
            frequency: 2.5,
        },
        sample_rate: 2000.0,
        duration: 30.0,
        force_noise: 0.03,
        seed: 5,
        ..ProtocolSpec::default()
    };
    pickup_found("pickup-prbs", &spec, 0.2, 50.0);
}

#[test]
fn a_sixty_hertz_pickup_under_a_staircase_at_250_hertz_is_discovered() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        sample_rate: 250.0,
        duration: 60.0,
        force_noise: 0.08,
        seed: 8,
        ..ProtocolSpec::default()
    };
    pickup_found("pickup-staircase", &spec, 0.3, 60.0);
}

/// The supply 30 kPa below the thesis's: the plain supply pressure discovered (within
/// 2 kPa of the truth), not the named line resistance, and the force explained.
fn supply_set_low_found(label: &str, spec: &ProtocolSpec) {
    let truth = synthetic_bench::BenchParams::default().p_supply - 30e3;
    let params = synthetic_bench::BenchParams {
        p_supply: truth,
        ..synthetic_bench::BenchParams::default()
    };
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-{}-{label}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    synthetic_bench::generate_protocol_with(&params, spec, &BenchEffects::default())
        .unwrap()
        .write_csv(&path)
        .unwrap();
    let recording = Recording::read(&path, &Parameters::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!(
        "{label} ({}): {}; {}",
        spec.label(),
        d.verdict(),
        d.summary().join(" | ")
    );
    assert!(names(&d).is_empty(), "{label}: named {:?}", names(&d));
    let found = d.discovered.first().expect("a discovered term");
    assert_eq!(
        (found.location.as_str(), found.family.as_str()),
        ("supply", "parameter_offset"),
        "{}",
        found.reading
    );
    let p_s = d.parameters.get(value_reference("P_s")).unwrap();
    assert!((p_s - truth).abs() < 2e3, "{label}: P_s = {p_s}, truth {truth}");
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
#[ignore = "60,000 samples; the supply set low under every protocol is scripts/bench_protocols.sh's, the test command keeps the ramps at 500 Hz"]
fn a_supply_set_low_under_a_staircase_with_pressures_is_its_plain_pressure_not_a_line_resistance() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        duration: 60.0,
        seed: 6,
        ..ProtocolSpec::default()
    };
    supply_set_low_found("supply-low-staircase", &spec);
}

#[test]
#[ignore = "a broad case (about 21 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_supply_set_low_under_ramps_at_500_hertz_without_pressures_is_its_plain_pressure() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Ramps,
        sample_rate: 500.0,
        duration: 40.0,
        pressures: false,
        seed: 9,
        ..ProtocolSpec::default()
    };
    supply_set_low_found("supply-low-ramps", &spec);
}

#[test]
#[ignore = "a broad case (about 12 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn clean_recordings_under_three_other_protocols_get_nothing() {
    let specs = [
        ProtocolSpec {
            command: CommandProtocol::ForceTracking,
            sample_rate: 500.0,
            duration: 30.0,
            force_noise: 0.08,
            seed: 5,
            ..ProtocolSpec::default()
        },
        ProtocolSpec {
            command: CommandProtocol::Multisine,
            stopper: StopperMotion::Moves { speed: 0.02 },
            duration: 30.0,
            pressures: false,
            seed: 5,
            ..ProtocolSpec::default()
        },
        ProtocolSpec {
            command: CommandProtocol::Sine,
            sample_rate: 250.0,
            duration: 30.0,
            seed: 5,
            ..ProtocolSpec::default()
        },
    ];
    for (k, spec) in specs.iter().enumerate() {
        let d = diagnosed(&format!("clean-{k}"), spec, &BenchEffects::default());
        assert!(
            d.effects.is_empty() && d.discovered.is_empty(),
            "{}: {}",
            spec.label(),
            d.summary().join(" | ")
        );
        assert_eq!(d.verdict(), "explained", "{}: {}", spec.label(), d.summary()[0]);
    }
}

#[test]
#[ignore = "a broad case (about 1e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_fifty_hertz_pickup_under_force_tracking_that_feeds_it_back_into_the_command_is_discovered() {
    let spec = ProtocolSpec {
        command: CommandProtocol::ForceTracking,
        sample_rate: 500.0,
        duration: 30.0,
        force_noise: 0.08,
        seed: 5,
        ..ProtocolSpec::default()
    };
    pickup_found("pickup-tracking", &spec, 0.2, 50.0);
}

/// Under force tracking the controller starts from 2.5 V and the first command logged is
/// another, so the bench does not start where a replay does: the stretch in which that
/// shows is neither fitted nor scored. Trained on it, an offset and gain of the force sensor
/// came out at 1.029 for 1.02 and a 10 ms lag was not found (4.4 and 6.4 noise floors left).
#[test]
fn under_force_tracking_the_start_is_left_out_and_a_force_sensors_offset_gain_and_lag_are_found_with_their_values() {
    let spec = ProtocolSpec {
        command: CommandProtocol::ForceTracking,
        sample_rate: 500.0,
        duration: 20.0,
        force_noise: 0.08,
        seed: 6,
        ..ProtocolSpec::default()
    };
    let offset_gain = BenchEffects {
        force_sensor_offset: 0.7,
        force_sensor_gain: 1.02,
        ..BenchEffects::default()
    };
    let d = diagnosed("tracking-offset-gain", &spec, &offset_gain);
    assert!(
        d.settling > 0.5 && d.settling <= 5.0,
        "settling {} s of a 20 s recording",
        d.settling
    );
    assert_eq!(names(&d), ["sensor_offset_gain"], "{}", d.summary().join(" | "));
    let get = |name: &str| d.parameters.get(value_reference(name)).unwrap();
    assert!(
        (get("force_sensor_offset") - 0.7).abs() < 0.05,
        "offset {}",
        get("force_sensor_offset")
    );
    assert!(
        (get("force_sensor_gain") - 1.02).abs() < 0.003,
        "gain {}",
        get("force_sensor_gain")
    );
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);

    let lag = UndeclaredEffects {
        force_sensor_lag: 0.01,
        ..UndeclaredEffects::default()
    };
    let fitted = discovered_and_explained(
        "tracking-sensor-lag",
        &spec,
        lag,
        ("force_sensor", "dynamics"),
        "force_sensor_lag",
    );
    assert!((fitted - 0.01).abs() < 0.001, "lag {fitted} s");
}

/// At 250 Hz a force sensor's half-millisecond lag acts within a sample, and under a PRBS the
/// force rises within one: read on the samples, where the force is a chord from each to the
/// next, the lag's search missed it and a transport delay was named in its place (1.1 noise
/// floors); searched through the model, whose transducer follows the force between samples,
/// the lag is found.
#[test]
#[ignore = "a broad case (about 2e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_half_millisecond_force_sensor_lag_under_a_prbs_at_250_hertz_is_found_with_its_value() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Prbs,
        sample_rate: 250.0,
        duration: 20.0,
        force_noise: 0.03,
        pressures: false,
        seed: 11,
        ..ProtocolSpec::default()
    };
    let lag = UndeclaredEffects {
        force_sensor_lag: 0.5e-3,
        ..UndeclaredEffects::default()
    };
    let fitted = discovered_and_explained(
        "prbs-250-half-millisecond-lag",
        &spec,
        lag,
        ("force_sensor", "dynamics"),
        "force_sensor_lag",
    );
    assert!((fitted / 0.5e-3 - 1.0).abs() < 0.1, "lag {fitted} s");
}

/// Diagnose `undeclared` under `spec`: the first term discovered is at `place` (location,
/// family), the force is explained; the fitted value of `parameter`.
fn discovered_and_explained(
    label: &str,
    spec: &ProtocolSpec,
    undeclared: UndeclaredEffects,
    place: (&str, &str),
    parameter: &str,
) -> f64 {
    explained_at(label, spec, undeclared, place)
        .get(value_reference(parameter))
        .unwrap()
}

/// [`discovered_and_explained`]'s diagnosis: the model it ends with.
fn explained_at(label: &str, spec: &ProtocolSpec, undeclared: UndeclaredEffects, place: (&str, &str)) -> Parameters {
    let effects = BenchEffects {
        undeclared,
        ..BenchEffects::default()
    };
    let d = diagnosed(label, spec, &effects);
    let found = d
        .discovered
        .first()
        .unwrap_or_else(|| panic!("{label}: nothing discovered: {}", d.summary()[0]));
    assert_eq!(
        (found.location.as_str(), found.family.as_str()),
        place,
        "{label}: {}",
        found.reading
    );
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
    d.parameters
}

/// An extra 15 ms lag after the jet pipe's static curve, in series with its 1.03 ms corner
/// (974 rad/s): one lag of their summed time constants, 16.0 ms, is 62.4 rad/s. The corner
/// is searched on a logarithmic scale; one Gauss–Newton step from 974 rad/s, where the
/// force barely moves with it, left it behind a current slew limit (7.3 noise floors).
#[test]
#[ignore = "a broad case (about 16 s of wall time two at a time); scripts/bench_cases.sh runs every case"]
fn a_fifteen_millisecond_jet_pipe_lag_under_a_staircase_is_found_as_the_jet_pipes_corner_at_the_summed_time_constant() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        sample_rate: 1000.0,
        duration: 20.0,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let lag = UndeclaredEffects {
        jet_pipe_lag: 15e-3,
        ..UndeclaredEffects::default()
    };
    let corner = discovered_and_explained(
        "staircase-jet-pipe-lag",
        &spec,
        lag,
        ("jet_pipe", "dynamics"),
        "omega_1",
    );
    let summed = 1.0 / (15e-3 + 1.0 / 973.9);
    assert!(
        (corner / summed - 1.0).abs() < 0.1,
        "omega_1 {corner} rad/s against {summed}"
    );
}

/// The same lag under a multisine at 1 kHz without pressures: the summed corner leaves two
/// noise floors there (the two lags differ by about 6° of phase at 20 Hz), and no candidate of
/// the next round, fitted with the corner held, takes the thesis's corner back. Fitted with
/// the corner free beside it, a second term at the jet pipe does, and the corner returns to
/// the extra lag's own, 1/15 ms.
#[test]
#[ignore = "a broad case (about 4e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn an_extra_jet_pipe_lag_under_a_multisine_without_pressures_is_explained_with_the_corner_refitted_beside_a_second_term(
) {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        sample_rate: 1000.0,
        duration: 20.0,
        pressures: false,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let lag = UndeclaredEffects {
        jet_pipe_lag: 15e-3,
        ..UndeclaredEffects::default()
    };
    let corner = discovered_and_explained(
        "multisine-jet-pipe-lag",
        &spec,
        lag,
        ("jet_pipe", "dynamics"),
        "omega_1",
    );
    assert!(
        (corner * 15e-3 - 1.0).abs() < 0.05,
        "omega_1 {corner} rad/s against {}",
        1.0 / 15e-3
    );
}

/// A leak from the supply into chamber 2 (an orifice of C_d·A 0.01 mm², a worn seat) under a
/// staircase at 1 kHz with pressures: one of the chambers' leak library, found with its area.
#[test]
#[ignore = "a broad case (about 2e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_leak_from_the_supply_into_chamber_2_under_a_staircase_is_an_extra_flow_of_the_chambers_with_its_area() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        sample_rate: 1000.0,
        duration: 20.0,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let leak = UndeclaredEffects {
        supply_leak_2: 1e-8,
        ..UndeclaredEffects::default()
    };
    let area = discovered_and_explained(
        "staircase-supply-leak",
        &spec,
        leak,
        ("chambers", "extra_flow"),
        "chamber_supply_leak_2",
    );
    assert!((area / 1e-8 - 1.0).abs() < 0.05, "C_d·A {area} m²");
}

/// A laminar leak from chamber 1 to atmosphere (3e-11 kg/(s·Pa), about 9 mg/s at 3 bar) under
/// a multisine at 500 Hz without pressures: the orifice law to the return left 1.51 noise
/// floors; the laminar member of the library explains it.
#[test]
#[ignore = "a broad case (about 17 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_laminar_leak_from_chamber_1_under_a_multisine_without_pressures_is_a_laminar_extra_flow_of_the_chambers() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        sample_rate: 500.0,
        duration: 20.0,
        pressures: false,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let leak = UndeclaredEffects {
        laminar_leak_1: 3e-11,
        ..UndeclaredEffects::default()
    };
    let conductance = discovered_and_explained(
        "multisine-laminar-leak",
        &spec,
        leak,
        ("chambers", "extra_flow"),
        "chamber_laminar_vent_1",
    );
    assert!((conductance / 3e-11 - 1.0).abs() < 0.05, "{conductance} kg/(s·Pa)");
}

/// A laminar leak from the supply into chamber 2 (4e-12 kg/(s·Pa), about 1.2 mg/s at 3 bar of
/// difference, a porous seal) under a staircase at 1 kHz with pressures: the held-out force
/// error is 8.6 noise floors before (0.43 N); the laminar member of the library from the
/// supply explains it, found with its conductance.
#[test]
#[ignore = "a broad case (about 2e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_laminar_leak_from_the_supply_into_chamber_2_under_a_staircase_is_a_laminar_extra_flow_of_the_chambers() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        sample_rate: 1000.0,
        duration: 20.0,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let leak = UndeclaredEffects {
        laminar_supply_leak_2: 4e-12,
        ..UndeclaredEffects::default()
    };
    let conductance = discovered_and_explained(
        "staircase-laminar-supply-leak",
        &spec,
        leak,
        ("chambers", "extra_flow"),
        "chamber_laminar_supply_leak_2",
    );
    assert!((conductance / 4e-12 - 1.0).abs() < 0.05, "{conductance} kg/(s·Pa)");
}

/// A laminar leak between the chambers (4e-12 kg/(s·Pa), about 1.2 mg/s at 3 bar of
/// difference, a scored bore) under a multisine at 500 Hz without pressures: the held-out
/// force error is 11.6 noise floors before (0.56 N); the laminar member of the library
/// between the chambers, beside the leakage past the piston, explains it, found with its
/// conductance.
#[test]
#[ignore = "a broad case (about 15 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_laminar_leak_between_the_chambers_under_a_multisine_without_pressures_is_a_laminar_extra_flow_of_the_chambers() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        sample_rate: 500.0,
        duration: 20.0,
        pressures: false,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let leak = UndeclaredEffects {
        laminar_cross_leak: 4e-12,
        ..UndeclaredEffects::default()
    };
    let conductance = discovered_and_explained(
        "multisine-laminar-cross-leak",
        &spec,
        leak,
        ("chambers", "extra_flow"),
        "chamber_laminar_cross_leak",
    );
    assert!((conductance / 4e-12 - 1.0).abs() < 0.05, "{conductance} kg/(s·Pa)");
}

/// A second-order low-pass filter on a reading (an amplifier's anti-aliasing filter) of
/// `frequency` Hz and damping `damping`, integrated by the bench with its plant: found at
/// `place` as a second-order filter, the force explained, the frequency within 5 % and the
/// damping within 10 %.
fn second_order_filter_found(
    label: &str,
    spec: &ProtocolSpec,
    undeclared: UndeclaredEffects,
    place: (&str, &str),
    prefix: &str,
    (frequency, damping): (f64, f64),
) {
    let model = explained_at(label, spec, undeclared, place);
    let at = |name: String| model.get(value_reference(&name)).unwrap();
    let (fitted, d) = (
        at(format!("{prefix}_filter_frequency")),
        at(format!("{prefix}_filter_damping")),
    );
    assert!(
        (fitted / frequency - 1.0).abs() < 0.05,
        "{label}: {fitted} Hz against {frequency}"
    );
    assert!(
        (d / damping - 1.0).abs() < 0.1,
        "{label}: damping {d} against {damping}"
    );
}

/// A 40 Hz filter of damping 0.5 on the force sensor under a multisine at 1 kHz without
/// pressures (19 noise floors before): not a lag, a second-order filter.
#[test]
#[ignore = "a broad case (about 26 s of wall time two at a time); scripts/bench_cases.sh runs every case"]
fn a_ringing_second_order_filter_on_the_force_sensor_under_a_multisine_is_found_with_its_frequency_and_damping() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        sample_rate: 1000.0,
        duration: 20.0,
        pressures: false,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let filter = UndeclaredEffects {
        force_sensor_filter_frequency: 40.0,
        force_sensor_filter_damping: 0.5,
        ..UndeclaredEffects::default()
    };
    second_order_filter_found(
        "multisine-force-filter",
        &spec,
        filter,
        ("force_sensor", "dynamics"),
        "force_sensor",
        (40.0, 0.5),
    );
}

/// A critically damped 30 Hz filter on the chamber 1 transducer under a staircase at 250 Hz
/// with pressures: found at the pressure sensors.
#[test]
#[ignore = "a broad case (about 2e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_critically_damped_filter_on_a_pressure_transducer_under_a_staircase_at_250_hertz_is_found_at_the_pressure_sensors()
{
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        sample_rate: 250.0,
        duration: 20.0,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let filter = UndeclaredEffects {
        pressure_sensor_filter_1: 30.0,
        pressure_sensor_filter_damping_1: 1.0,
        ..UndeclaredEffects::default()
    };
    second_order_filter_found(
        "staircase-pressure-filter",
        &spec,
        filter,
        ("pressure_sensors", "dynamics"),
        "p1_sensor",
        (30.0, 1.0),
    );
}

/// A 30 Hz filter of damping 0.6 between the D/A and the current driver (a reconstruction
/// filter) under a multisine at 1 kHz without pressures: found at the command as a
/// second-order filter, not as a lag or a delay.
#[test]
#[ignore = "a broad case (about 3e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_second_order_filter_on_the_command_under_a_multisine_is_found_at_the_command_with_its_frequency_and_damping() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        sample_rate: 1000.0,
        duration: 20.0,
        pressures: false,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let filter = UndeclaredEffects {
        command_filter_frequency: 30.0,
        command_filter_damping: 0.6,
        ..UndeclaredEffects::default()
    };
    second_order_filter_found(
        "multisine-command-filter",
        &spec,
        filter,
        ("command", "dynamics"),
        "command",
        (30.0, 0.6),
    );
}

/// A closed loop: the controller computes the command from the logged force, so the command
/// carries the force's noise and answers every departure, and the departure the hysteresis
/// makes in the force is partly undone by the command. The jet-pipe hysteresis is still named,
/// with its width, and nothing else is added, at two rates.
#[test]
#[ignore = "a broad case (about 6e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn the_jet_pipe_hysteresis_is_named_under_force_tracking_that_answers_it() {
    let effects = BenchEffects {
        hysteresis_width: 0.12e-3,
        ..BenchEffects::default()
    };
    for (sample_rate, seed) in [(500.0, 11), (1000.0, 12)] {
        let spec = ProtocolSpec {
            command: CommandProtocol::ForceTracking,
            sample_rate,
            duration: 30.0,
            force_noise: 0.08,
            seed,
            ..ProtocolSpec::default()
        };
        let label = format!("hysteresis-tracking-{sample_rate}");
        let d = diagnosed(&label, &spec, &effects);
        assert_eq!(
            names(&d),
            ["jet_pipe_hysteresis"],
            "{label}: {}",
            d.summary().join(" | ")
        );
        assert!(d.discovered.is_empty(), "{label}: {}", d.summary().join(" | "));
        assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
        let width = d.parameters.get(value_reference("hysteresis_width")).unwrap();
        assert!((width - 0.12e-3).abs() < 0.012e-3, "{label}: width {width} m");
    }
}
