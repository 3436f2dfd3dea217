//! The static-curve class (`jetpipe_diagnosis::candidates::curves`) on recordings of the synthetic
//! bench's own mechanisms, which it writes with its own code: a force sensor that
//! saturates, a pressure transducer that saturates or reads a quadratic curve, and a dead
//! zone in the command. Short recordings (20 s at 250–1000 Hz) under several protocols, two
//! or more sampling rates, with and without pressures; broader sweeps are rows of
//! `scripts/bench_protocols.sh`.

use super::diagnose;
use jetpipe_diagnosis::{Diagnosis, DiscoveredTerm};
use jetpipe_model::physics::parameters::Parameters;
use synthetic_bench::{BenchEffects, CommandProtocol, ProtocolSpec, UndeclaredEffects};

use super::names;
use super::protocols::recorded;

fn diagnosed(label: &str, spec: &ProtocolSpec, effects: &BenchEffects) -> Diagnosis {
    let recording = recorded(label, spec, effects);
    let started = std::time::Instant::now();
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!(
        "{label} ({}): {} in {:.1} s, held-out after {:.2}× the noise; {}",
        spec.label(),
        d.verdict(),
        started.elapsed().as_secs_f64(),
        d.after.heldout_rms / d.noise_floor,
        d.summary().join(" | ")
    );
    d
}

fn undeclared(u: UndeclaredEffects) -> BenchEffects {
    BenchEffects {
        undeclared: u,
        ..BenchEffects::default()
    }
}

fn spec(command: CommandProtocol, sample_rate: f64, pressures: bool) -> ProtocolSpec {
    ProtocolSpec {
        command,
        sample_rate,
        duration: 20.0,
        pressures,
        seed: 5,
        ..ProtocolSpec::default()
    }
}

/// The one discovered term, nothing named, at `location` in `family`.
fn only_term<'a>(label: &str, d: &'a Diagnosis, location: &str, family: &str) -> &'a DiscoveredTerm {
    assert!(names(d).is_empty(), "{label}: named {:?}", names(d));
    assert_eq!(d.discovered.len(), 1, "{label}: {}", d.summary().join(" | "));
    let term = &d.discovered[0];
    assert_eq!(
        (term.location.as_str(), term.family.as_str()),
        (location, family),
        "{label}: {}",
        term.reading
    );
    term
}

/// The number that follows `words` in a reading.
fn reading_number(reading: &str, words: &str) -> f64 {
    let at = reading
        .find(words)
        .unwrap_or_else(|| panic!("no \"{words}\" in: {reading}"));
    let after = &reading[at + words.len()..];
    let end = after
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .unwrap_or(after.len());
    after[..end]
        .parse()
        .unwrap_or_else(|_| panic!("no number after \"{words}\" in: {reading}"))
}

/// A force sensor that reads at most `limit` N: a static curve at the force sensor, flat
/// above the limit (family `limit`), its reading naming the level, the force explained.
fn force_saturation_found(label: &str, spec: &ProtocolSpec, limit: f64) {
    let d = diagnosed(
        label,
        spec,
        &undeclared(UndeclaredEffects {
            force_sensor_saturation: limit,
            ..UndeclaredEffects::default()
        }),
    );
    let term = only_term(label, &d, "force_sensor", "limit");
    let level = reading_number(&term.reading, "the force sensor saturates at ");
    assert!((level - limit).abs() < 0.1, "{label}: {}", term.reading);
    let curve = &d.parameters.force_sensor_curve;
    assert!(curve.is_on(), "{label}: the curve is off");
    // Flat above the limit, the identity well below it.
    assert!(
        (curve.at(limit + 30.0) - limit).abs() < 0.05,
        "{label}: {}",
        curve.at(limit + 30.0)
    );
    assert!(
        (curve.at(0.5 * limit) - 0.5 * limit).abs() < 0.1,
        "{label}: {}",
        curve.at(0.5 * limit)
    );
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
fn a_force_sensor_that_saturates_under_a_staircase_at_one_kilohertz_is_a_static_curve_flat_at_the_limit() {
    force_saturation_found(
        "saturation-staircase",
        &spec(CommandProtocol::Staircase, 1000.0, true),
        40.0,
    );
}

#[test]
#[ignore = "a broad case (about 22 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_force_sensor_that_saturates_under_a_multisine_at_500_hertz_without_pressures_is_a_static_curve_flat_at_the_limit()
{
    force_saturation_found(
        "saturation-multisine",
        &spec(CommandProtocol::Multisine, 500.0, false),
        25.0,
    );
}

#[test]
#[ignore = "a broad case (about 1e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_force_sensor_that_saturates_under_ramps_at_250_hertz_is_a_static_curve_flat_at_the_limit() {
    force_saturation_found("saturation-ramps", &spec(CommandProtocol::Ramps, 250.0, true), 50.0);
}

#[test]
#[ignore = "a broad case (about 1e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn an_offset_and_a_gain_of_the_force_sensor_stay_an_offset_and_a_gain_not_a_curve() {
    let effects = BenchEffects {
        force_sensor_offset: 0.7,
        force_sensor_gain: 1.02,
        ..BenchEffects::default()
    };
    // (Without pressures too in scripts/bench_protocols.sh: 36 s here, over this file's budget.)
    let (label, spec) = ("offset-gain-staircase", spec(CommandProtocol::Staircase, 1000.0, true));
    {
        let d = diagnosed(label, &spec, &effects);
        assert_eq!(
            names(&d),
            vec!["sensor_offset_gain"],
            "{label}: {}",
            d.summary().join(" | ")
        );
        assert!(d.discovered.is_empty(), "{label}: {}", d.summary().join(" | "));
        assert!(!d.parameters.force_sensor_curve.is_on());
        assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
    }
}

/// The pressures after the term, held out, within 1.5 noise floors each.
fn pressures_explained(label: &str, d: &Diagnosis, term: &DiscoveredTerm) {
    let (_, after) = term.pressures_heldout.expect("a pressure term's pressures");
    let noise = d.pressure_noise.expect("pressure noise floors");
    for c in 0..2 {
        assert!(
            after[c] <= 1.5 * noise[c],
            "{label}: P{} held out {:.0} Pa, noise {:.0} Pa",
            c + 1,
            after[c],
            noise[c]
        );
    }
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
#[ignore = "a broad case (about 50 s of wall time two at a time; its kind has other cases here: a transducer's curve, a saturating sensor); scripts/bench_cases.sh runs every case"]
fn a_chamber_1_transducer_whose_range_ends_at_450_kilopascals_is_a_static_curve_flat_there_under_two_protocols() {
    let effects = undeclared(UndeclaredEffects {
        pressure_sensor_saturation_1: 450e3,
        ..UndeclaredEffects::default()
    });
    for (label, spec) in [
        ("p1-saturation-staircase", spec(CommandProtocol::Staircase, 250.0, true)),
        ("p1-saturation-ramps", spec(CommandProtocol::Ramps, 500.0, true)),
    ] {
        let d = diagnosed(label, &spec, &effects);
        let term = only_term(label, &d, "pressure_sensors", "limit");
        let level = reading_number(&term.reading, "the chamber 1 pressure transducer saturates at ");
        assert!((level - 450.0).abs() < 0.5, "{label}: {} (kPa)", term.reading);
        let curve = &d.parameters.p1_sensor_curve;
        assert!((curve.at(560e3) - 450e3).abs() < 500.0, "{label}: {}", curve.at(560e3));
        assert!(!d.parameters.p2_sensor_curve.is_on(), "{label}: a curve on P2 too");
        pressures_explained(label, &d, term);
    }
}

#[test]
fn a_chamber_2_transducer_with_a_quadratic_curve_is_a_static_curve_that_follows_it_under_a_sine() {
    let q = 5e-8;
    let label = "p2-quadratic-sine";
    let d = diagnosed(
        label,
        &spec(CommandProtocol::Sine, 250.0, true),
        &undeclared(UndeclaredEffects {
            pressure_sensor_quadratic_2: q,
            ..UndeclaredEffects::default()
        }),
    );
    let term = only_term(label, &d, "pressure_sensors", "nonlinearity");
    let curve = &d.parameters.p2_sensor_curve;
    // Within the knots' range the curve is the transducer's, to a few per cent of the bend.
    let (lo, hi) = (curve.x[0], curve.x[curve.len() - 1]);
    for share in [0.25, 0.5, 0.75] {
        let p = lo + share * (hi - lo);
        let gauge = p - 101_325.0;
        let truth = p + q * gauge * gauge;
        assert!(
            (curve.at(p) - truth).abs() < 0.05 * q * gauge * gauge + 300.0,
            "{label}: at {p:.0} Pa reads {:.0}, truth {truth:.0}",
            curve.at(p)
        );
    }
    pressures_explained(label, &d, term);
}

/// A dead zone of ±0.4 V in the D/A output the driver sees, found at the command, read as a
/// dead zone of about ±0.4 V, the curve flat inside it and the identity shifted by 0.4 V
/// outside, the force explained.
fn dead_zone_found(label: &str, spec: &ProtocolSpec) {
    let effects = undeclared(UndeclaredEffects {
        command_dead_zone: 0.4,
        ..UndeclaredEffects::default()
    });
    let command = recorded(label, spec, &effects).v_da;
    let lowest = command.iter().cloned().fold(f64::INFINITY, f64::min);
    let highest = command.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let d = diagnosed(label, spec, &effects);
    let term = only_term(label, &d, "command", "nonlinearity");
    let half = reading_number(&term.reading, "the command has a dead zone of ±");
    assert!((half - 0.4).abs() < 0.05, "{label}: {}", term.reading);
    let curve = &d.parameters.command_curve;
    assert!(curve.at(0.1).abs() < 0.05, "{label}: {}", curve.at(0.1));
    // Within the commands recorded (the sine spans −1.5 to 6.5 V): beyond them the curve
    // continues its end segment, which the recording does not decide (a knot 0.14 V from
    // the sine's lowest point gave a slope of 1.14 there, −2.83 V at −3 V).
    for v in [-3.0, 0.8 * lowest, 3.0, 0.8 * highest] {
        if v < lowest || v > highest {
            continue;
        }
        let truth = if v.abs() <= 0.4 { 0.0 } else { v - 0.4 * v.signum() };
        assert!((curve.at(v) - truth).abs() < 0.05, "{label}: at {v} V {}", curve.at(v));
    }
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}

#[test]
#[ignore = "a broad case (about 4e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_dead_zone_in_the_command_under_a_sine_at_500_hertz_is_a_static_curve_at_the_command_read_as_a_dead_zone() {
    dead_zone_found("dead-zone-sine", &spec(CommandProtocol::Sine, 500.0, true));
}

#[test]
#[ignore = "a broad case (about 25 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_dead_zone_in_the_command_under_a_multisine_at_250_hertz_without_pressures_is_a_static_curve_at_the_command() {
    dead_zone_found("dead-zone-multisine", &spec(CommandProtocol::Multisine, 250.0, false));
}

/// Under force tracking the controller winds up against a sensor that reads at most 40 N
/// and the chamber 1 transducer whose range ends at 450 kPa: the training blocks hold the
/// model's reading below the corner and well beyond it, the held-out blocks the rise between.
/// The curve's stretch across the corner is its neighbours' corner, not a chord (1.79 noise
/// floors of force and 14 of P1 were left with the chord).
#[test]
#[ignore = "a broad case (about 28 s of wall time two at a time); scripts/bench_cases.sh runs every case"]
fn saturations_whose_corner_only_the_held_out_blocks_cross_under_force_tracking_are_cornered_where_the_reading_meets_the_limit(
) {
    let tracking = ProtocolSpec {
        command: CommandProtocol::ForceTracking,
        sample_rate: 500.0,
        duration: 20.0,
        force_noise: 0.08,
        seed: 5,
        ..ProtocolSpec::default()
    };
    force_saturation_found("saturation-tracking", &tracking, 40.0);
    let label = "p1-saturation-tracking";
    let d = diagnosed(
        label,
        &tracking,
        &undeclared(UndeclaredEffects {
            pressure_sensor_saturation_1: 450e3,
            ..UndeclaredEffects::default()
        }),
    );
    let term = only_term(label, &d, "pressure_sensors", "limit");
    let curve = &d.parameters.p1_sensor_curve;
    for p in [440e3, 445e3, 455e3, 500e3] {
        assert!(
            (curve.at(p) - p.min(450e3)).abs() < 1e3,
            "{label}: {p} reads {}",
            curve.at(p)
        );
    }
    pressures_explained(label, &d, term);
}

/// The valve orifices' C_d rising as the flow chokes, C_d (1 + 0.3 (1 − r)²) at the pressure
/// ratio r (0.696 at equal pressures, 0.90 at r = 0): discovered at the valve as the
/// discharge coefficient's curve of the ratio, the force explained, and the curve within
/// 2 % of the truth over the ratios the orifices work at.
fn discharge_curve_found(label: &str, spec: &ProtocolSpec) {
    let d = diagnosed(
        label,
        spec,
        &undeclared(UndeclaredEffects {
            discharge_ratio_rise: 0.3,
            ..UndeclaredEffects::default()
        }),
    );
    let term = only_term(label, &d, "valve", "nonlinearity");
    assert!(term.reading.contains("as the flow chokes"), "{label}: {}", term.reading);
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
    let c_d = Parameters::default().c_d;
    for r in [0.25, 0.5, 0.75] {
        let truth = c_d * (1.0 + 0.3 * (1.0 - r) * (1.0 - r));
        let fitted = d.parameters.discharge_curve.at(r);
        assert!(
            (fitted / truth - 1.0).abs() < 0.02,
            "{label}: C_d {fitted} at r = {r} against {truth}"
        );
    }
}

#[test]
fn a_discharge_coefficient_rising_as_the_flow_chokes_under_a_staircase_at_1_kilohertz_is_a_curve_of_the_pressure_ratio_at_the_valve(
) {
    discharge_curve_found("discharge-staircase", &spec(CommandProtocol::Staircase, 1000.0, true));
}

#[test]
#[ignore = "a broad case (about 21 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_discharge_coefficient_rising_as_the_flow_chokes_under_a_multisine_at_500_hertz_without_pressures_is_a_curve_of_the_pressure_ratio_at_the_valve(
) {
    discharge_curve_found("discharge-multisine", &spec(CommandProtocol::Multisine, 500.0, false));
}

/// Dead volumes (1.2 cm³ each) beside a force sensor saturating at 89.5 N, near the top of the
/// force's range, under ramps at 250 Hz with the stopper shaken. Alone, the dead volumes take
/// two thirds of what the channels hold above their noise and are not named, no pair closes
/// the departure, and nothing was added. On the force against the measured pressures the
/// force sensor's curve explains nearly all: it is added from there, flat within 0.2 N of the
/// limit, the dead volumes in the next round, each within 5 %, and the recording explained.
#[test]
#[ignore = "a broad case (about 6e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_force_sensor_saturating_beside_dead_volumes_is_found_on_the_force_against_the_pressures_then_the_dead_volumes() {
    let label = "saturation-beside-dead-volumes";
    let effects = BenchEffects {
        dead_volume_1: 1.2e-6,
        dead_volume_2: 1.2e-6,
        ..undeclared(UndeclaredEffects {
            force_sensor_saturation: 89.5,
            ..UndeclaredEffects::default()
        })
    };
    let spec = ProtocolSpec {
        stopper: synthetic_bench::StopperMotion::Sine {
            centre: 0.06,
            amplitude: 0.003,
            frequency: 1.2,
        },
        duration: 30.0,
        seed: 7,
        ..spec(CommandProtocol::Ramps, 250.0, true)
    };
    let d = diagnosed(label, &spec, &effects);
    let limit = d
        .discovered
        .iter()
        .find(|t| (t.location.as_str(), t.family.as_str()) == ("force_sensor", "limit"))
        .unwrap_or_else(|| panic!("{label}: no limit at the force sensor: {}", d.summary().join(" | ")));
    let level = reading_number(&limit.reading, "the force sensor saturates at ");
    assert!((level - 89.5).abs() < 0.2, "{label}: {}", limit.reading);
    for name in ["dead_volume_1", "dead_volume_2"] {
        let value = d.parameters.get(super::value_reference(name)).unwrap();
        assert!((value / 1.2e-6 - 1.0).abs() < 0.05, "{label}: {name} = {value}");
    }
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
}
