//! A search that does not lock in (`alternatives.rs`, `pairs.rs`, `eliminate.rs`), on
//! mechanisms the synthetic bench writes with its own integrator: a compound of two
//! departures at two places, a stopper position logged 1 mm off, a compliant stopper mount
//! with a 1 ms lag and a gas temperature drifting 20 K (explained with T_drift). Short
//! recordings (20 s at 250 or 500 Hz), two protocols each, with and without pressures.

use super::diagnose;
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::Diagnosis;
use jetpipe_model::physics::parameters::Parameters;
use synthetic_bench::{
    generate_protocol_with, BenchEffects, BenchParams, CommandProtocol, ProtocolSpec, StopperMotion, UndeclaredEffects,
};

use super::{names, value_reference};

fn diagnosed(label: &str, spec: &ProtocolSpec, undeclared: UndeclaredEffects) -> Diagnosis {
    diagnosed_with(label, &BenchParams::default(), spec, undeclared)
}

pub(super) fn diagnosed_with(
    label: &str,
    plant: &BenchParams,
    spec: &ProtocolSpec,
    undeclared: UndeclaredEffects,
) -> Diagnosis {
    let effects = BenchEffects {
        undeclared,
        ..BenchEffects::default()
    };
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-{}-{label}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    generate_protocol_with(plant, spec, &effects)
        .unwrap()
        .write_csv(&path)
        .unwrap();
    let recording = Recording::read(&path, &Parameters::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
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

pub(super) fn spec(
    command: CommandProtocol,
    stopper: StopperMotion,
    sample_rate: f64,
    pressures: bool,
) -> ProtocolSpec {
    ProtocolSpec {
        command,
        stopper,
        sample_rate,
        duration: 20.0,
        pressures,
        seed: 5,
        ..ProtocolSpec::default()
    }
}

fn moves() -> StopperMotion {
    StopperMotion::Moves { speed: 0.02 }
}

pub(super) fn fixed() -> StopperMotion {
    StopperMotion::Fixed { position: 0.054 }
}

pub(super) fn get(d: &Diagnosis, name: &str) -> f64 {
    d.parameters.get(value_reference(name)).unwrap()
}

/// The receivers 0.1 mm off the jet pipe's null and a supply set 30 kPa low: found as both,
/// each at its place, not as one term elsewhere that stands in for the two.
fn compound_found(label: &str, spec: &ProtocolSpec) {
    let truth = BenchParams::default().p_supply - 30e3;
    let plant = BenchParams {
        p_supply: truth,
        ..BenchParams::default()
    };
    let d = diagnosed_with(
        label,
        &plant,
        spec,
        UndeclaredEffects {
            receiver_offset: 1e-5,
            ..UndeclaredEffects::default()
        },
    );
    assert!(names(&d).is_empty(), "{label}: named {:?}", names(&d));
    let places: Vec<(&str, &str)> = d
        .discovered
        .iter()
        .map(|t| (t.location.as_str(), t.family.as_str()))
        .collect();
    assert!(
        places.contains(&("supply", "parameter_offset")) && places.contains(&("jet_pipe", "parameter_offset")),
        "{label}: {places:?}"
    );
    let supply = get(&d, "P_s");
    assert!((supply - truth).abs() < 3e3, "{label}: P_s = {supply} against {truth}");
    let null = get(&d, "x_jp_offset") - Parameters::default().x_jp_offset;
    assert!((null - 1e-5).abs() < 0.2e-5, "{label}: x_jp_offset moved by {null}");
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
#[ignore = "a broad case (about 3e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_supply_set_low_with_the_receivers_off_the_null_is_found_as_both_under_ramps_at_500_hz_without_pressures() {
    compound_found("compound-ramps", &spec(CommandProtocol::Ramps, moves(), 500.0, false));
}

#[test]
#[ignore = "the slowest of the compound's cases (65 s wall under load); scripts/bench_protocols.sh runs the compound under every protocol"]
fn a_supply_set_low_with_the_receivers_off_the_null_is_found_as_both_under_a_staircase_at_250_hz_with_pressures() {
    compound_found(
        "compound-staircase",
        &spec(CommandProtocol::Staircase, fixed(), 250.0, true),
    );
}

/// The logged stopper position 1 mm beyond the true one: at the chambers, as the support
/// length L_sup 1 mm longer (within 20 %), the force explained.
fn stopper_offset_found(label: &str, spec: &ProtocolSpec) {
    let d = diagnosed(
        label,
        spec,
        UndeclaredEffects {
            stopper_position_offset: 1e-3,
            ..UndeclaredEffects::default()
        },
    );
    assert!(names(&d).is_empty(), "{label}: named {:?}", names(&d));
    let first = d
        .discovered
        .first()
        .unwrap_or_else(|| panic!("{label}: nothing discovered ({})", d.summary()[0]));
    assert_eq!(
        (first.location.as_str(), first.family.as_str()),
        ("chambers", "parameter_offset"),
        "{}",
        first.reading
    );
    let shift = get(&d, "L_sup") - Parameters::default().l_sup;
    assert!((shift - 1e-3).abs() < 0.2e-3, "{label}: L_sup moved by {shift} m");
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
#[ignore = "a broad case (about 2e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_stopper_position_logged_one_millimetre_off_is_placed_at_the_chambers_under_a_staircase_at_500_hz_with_pressures() {
    stopper_offset_found(
        "stopper-offset-staircase",
        &spec(CommandProtocol::Staircase, fixed(), 500.0, true),
    );
}

#[test]
#[ignore = "a broad case (about 15 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_stopper_position_logged_one_millimetre_off_is_placed_at_the_chambers_under_ramps_at_250_hz_without_pressures() {
    stopper_offset_found(
        "stopper-offset-ramps",
        &spec(CommandProtocol::Ramps, moves(), 250.0, false),
    );
}

/// A compliant stopper mount (2e4 N/m) with a 1 ms lag: at the mechanics as a compliance,
/// the compliance within 5 % of 1/k, the force explained; where the protocol shows the lag
/// (`lag_shows`), the mount's lag within 25 % of 1 ms.
fn compliant_mount_found(label: &str, spec: &ProtocolSpec, lag_shows: bool) {
    let d = diagnosed(
        label,
        spec,
        UndeclaredEffects {
            contact_stiffness: 2e4,
            contact_lag: 1e-3,
            ..UndeclaredEffects::default()
        },
    );
    assert!(names(&d).is_empty(), "{label}: named {:?}", names(&d));
    let first = d
        .discovered
        .first()
        .unwrap_or_else(|| panic!("{label}: nothing discovered ({})", d.summary()[0]));
    assert_eq!(
        (first.location.as_str(), first.family.as_str()),
        ("mechanics", "compliance"),
        "{}",
        first.reading
    );
    let compliance = get(&d, "stopper_compliance");
    assert!(
        (compliance - 5e-5).abs() < 0.05 * 5e-5,
        "{label}: compliance {compliance}"
    );
    if lag_shows {
        let lag = get(&d, "stopper_mount_lag");
        assert!((lag - 1e-3).abs() < 0.25e-3, "{label}: lag {lag} s");
    }
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
#[ignore = "a broad case (about 18 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_compliant_stopper_mount_with_a_one_millisecond_lag_is_explained_with_its_lag_under_a_shaken_stopper_at_500_hz() {
    compliant_mount_found(
        "mount-shaken",
        &spec(
            CommandProtocol::Staircase,
            StopperMotion::Sine {
                centre: 0.054,
                amplitude: 0.004,
                frequency: 2.5,
            },
            500.0,
            true,
        ),
        true,
    );
}

#[test]
fn a_compliant_stopper_mount_with_a_one_millisecond_lag_is_explained_under_ramps_at_250_hz_without_pressures() {
    // Slow ramps sampled at 250 Hz hardly show a 1 ms lag: the plain compliance explains the
    // force (1.0 noise floor), and the simpler term wins.
    compliant_mount_found(
        "mount-ramps",
        &spec(CommandProtocol::Ramps, moves(), 250.0, false),
        false,
    );
}

/// The gas temperature rising 20 K over the recording (1 K/s over 20 s): at the chambers as
/// a drift, carried by the FMU parameter T_drift within 15 % of 1 K/s from T within 1 K of
/// its start, nothing named, and the force explained (held-out error within 1.5 noise floors).
fn temperature_drift_found(label: &str, spec: &ProtocolSpec) {
    let rise = 20.0;
    let d = diagnosed(
        label,
        spec,
        UndeclaredEffects {
            gas_temperature_drift: rise,
            ..UndeclaredEffects::default()
        },
    );
    assert!(names(&d).is_empty(), "{label}: named {:?}", names(&d));
    let first = d
        .discovered
        .first()
        .unwrap_or_else(|| panic!("{label}: nothing discovered ({})", d.summary()[0]));
    assert_eq!(
        (first.location.as_str(), first.family.as_str()),
        ("chambers", "drift"),
        "{}",
        first.reading
    );
    let (drift, start) = (get(&d, "T_drift"), get(&d, "T"));
    let truth = rise / spec.duration;
    println!(
        "{label}: held-out after {:.3} noise floors (before {:.3}); T_drift = {drift} K/s, T = {start} K",
        d.after.heldout_rms / d.noise_floor,
        d.before.heldout_rms / d.noise_floor,
    );
    assert!(
        (drift - truth).abs() < 0.15 * truth,
        "{label}: T_drift = {drift} K/s against {truth}"
    );
    let thesis = Parameters::default().temperature;
    assert!((start - thesis).abs() < 1.0, "{label}: T = {start} K against {thesis}");
    assert!(
        d.after.heldout_rms <= 1.5 * d.noise_floor,
        "{label}: {}",
        d.summary()[0]
    );
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
fn a_gas_temperature_drifting_twenty_kelvin_is_found_at_the_chambers_and_explained_with_t_drift_under_a_staircase_at_500_hz(
) {
    temperature_drift_found(
        "gas-drift-staircase",
        &spec(CommandProtocol::Staircase, fixed(), 500.0, true),
    );
}

#[test]
#[ignore = "a broad case (about 13 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_gas_temperature_drifting_twenty_kelvin_is_found_at_the_chambers_and_explained_with_t_drift_under_a_slow_sine_at_250_hz(
) {
    temperature_drift_found("gas-drift-sine", &spec(CommandProtocol::Sine, fixed(), 250.0, true));
}

/// The same drift under a staircase at 250 Hz with the stopper shaken and pressures four
/// times noisier than the bench's (600 Pa): the pressures stay within their noise, but the
/// force's departure (about 0.1 N) would move a pressure by some 250 Pa, which they could
/// not show, so the places upstream stay in the search (before, only the mechanics and the
/// force sensor were fitted, and nothing was found: 2.4 noise floors, unexplained).
#[test]
#[ignore = "a broad case (about 1e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_gas_temperature_drift_is_found_at_the_chambers_when_the_pressures_are_too_noisy_to_show_it() {
    let shaken = StopperMotion::Sine {
        centre: 0.05,
        amplitude: 0.006,
        frequency: 0.7,
    };
    temperature_drift_found(
        "gas-drift-noisy-pressures",
        &ProtocolSpec {
            pressure_noise: 600.0,
            ..spec(CommandProtocol::Staircase, shaken, 250.0, true)
        },
    );
}

/// The force sensor's offset and gain (named) beside a 2.3 ms command delay, under a PRBS:
/// once the offset and gain are fitted, the delay leaves 20 noise floors, and a richer curve
/// of the force sensor that takes a sliver of the delay's misfit beat the named effect by
/// its penalty and replaced it (a cubic curve, the named effect never given). A richer term
/// must now close a fifth of the way to the noise; the named effect stays.
#[test]
#[ignore = "a broad case (about 5e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_sensor_offset_and_gain_beside_a_command_delay_stays_the_named_effect_not_a_richer_curve() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Prbs,
        stopper: StopperMotion::Moves { speed: 0.1 },
        sample_rate: 500.0,
        duration: 20.0,
        force_noise: 0.09,
        pressures: true,
        seed: 4,
        ..ProtocolSpec::default()
    };
    let (gain, offset) = (0.971, -0.494);
    let effects = BenchEffects {
        command_delay: 2.27e-3,
        force_sensor_gain: gain,
        force_sensor_offset: offset,
        ..BenchEffects::default()
    };
    let recording = super::protocols::recorded("offset-gain-beside-delay", &spec, &effects);
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!("offset and gain beside a delay: {}", d.summary().join(" | "));
    assert!(names(&d).contains(&"sensor_offset_gain"), "{}", d.summary().join(" | "));
    assert!(
        d.discovered.iter().all(|t| t.location.as_str() != "force_sensor"),
        "{}",
        d.summary().join(" | ")
    );
    assert!(
        (d.parameters.force_sensor_gain - gain).abs() < 0.01 * gain,
        "{}",
        d.parameters.force_sensor_gain
    );
    assert!(
        (d.parameters.force_sensor_offset - offset).abs() < 0.05,
        "{}",
        d.parameters.force_sensor_offset
    );
}
