//! `jetpipe diagnose` on recordings with an undeclared effect, written by the independent
//! generator of `synthetic_bench` (another integrator, and other forms of the effects:
//! Bouc–Wen hysteresis for the play-operator candidate, a Stribeck curve for Coulomb
//! friction, line volumes, a supply plenum, chamber temperature states), with the bench's
//! noise and quantisation. Each case: the right effects are named, nothing is added to a
//! recording that has none, and the error after is near the noise floor.
//!
//! The full protocol (80 s) runs for every case; set JETPIPE_DIAGNOSE_CASES to a comma
//! list of case names to run a subset.

use super::diagnose;
use jetpipe_diagnosis::Diagnosis;
use jetpipe_model::physics::parameters::Parameters;
use synthetic_bench::{generate, BenchEffects};

use super::{generated, names};

fn run(name: &str, effects: BenchEffects, seed: u64) -> Diagnosis {
    let rows = generate(&effects, seed, 80.0);
    let recording = generated(&format!("synthetic-{name}"), &rows, &Parameters::default());
    let started = std::time::Instant::now();
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    let named: Vec<String> = d
        .effects
        .iter()
        .map(|f| {
            format!(
                "{} {:?}",
                f.name,
                f.parameters
                    .iter()
                    .map(|(n, v)| format!("{n}={v:.4e}"))
                    .collect::<Vec<_>>()
            )
        })
        .collect();
    println!(
        "{name}: noise {:.4} N, before {:.4} N (held-out {:.4}), after {:.4} N (held-out {:.4}), effects {named:?}, {:.1} s",
        d.noise_floor,
        d.before.rms,
        d.before.heldout_rms,
        d.after.rms,
        d.after.heldout_rms,
        started.elapsed().as_secs_f64()
    );
    d
}

fn selected(name: &str) -> bool {
    match std::env::var("JETPIPE_DIAGNOSE_CASES") {
        Ok(list) => list.split(',').any(|c| c.trim() == name),
        Err(_) => true,
    }
}

#[test]
fn a_recording_without_effects_gets_none() {
    if !selected("null") {
        return;
    }
    let d = run("null", BenchEffects::default(), 101);
    assert!(
        d.effects.is_empty(),
        "added {:?} to a recording without effects",
        names(&d)
    );
    assert!(
        d.after.heldout_rms < 1.3 * d.noise_floor,
        "{} vs noise {}",
        d.after.heldout_rms,
        d.noise_floor
    );
}

/// One effect alone: it must be named first and explain most of the error; with
/// `near_noise`, the held-out error after must be within that many noise floors.
fn single(name: &str, expected: &str, effects: BenchEffects, seed: u64, near_noise: Option<f64>) {
    if !selected(name) {
        return;
    }
    let d = run(name, effects, seed);
    assert_eq!(
        names(&d).first().copied(),
        Some(expected),
        "{name}: named {:?}",
        names(&d)
    );
    if let Some(factor) = near_noise {
        assert!(
            d.after.heldout_rms < factor * d.noise_floor,
            "{name}: held-out error after {:.4} N is not within {factor} x the noise floor {:.4} N",
            d.after.heldout_rms,
            d.noise_floor
        );
    }
    assert!(d.after.heldout_rms < 0.4 * d.before.heldout_rms);
}

// Where the generator's form of an effect is the model's (sensor, delay, added volume,
// between-isothermal-and-adiabatic chambers, the Bouc–Wen hysteresis) the residual must come
// down to the noise. Where the forms differ, part of the error stays: a Stribeck curve with
// its own speed scales and a viscous term the named law lacks, read at the velocity of the
// averaged stopper positions' last interval, half a sample early (measured 1.76 noise floors;
// the bound for named effects is 2). The supply plenum is the model's supply orifice
// with a plenum, but the generator's orifice is sized from its resistance and its plenum may be
// enlarged, so it is held to the bound for named effects, 2.

#[test]
#[ignore = "a broad case (about 21 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn sensor_offset_and_gain() {
    let effects = BenchEffects {
        force_sensor_offset: 1.0,
        force_sensor_gain: 1.03,
        ..Default::default()
    };
    single("sensor", "sensor_offset_gain", effects, 102, Some(1.3));
}

#[test]
#[ignore = "a broad case (about 57 s of CPU); scripts/bench_cases.sh runs every case"]
fn command_delay() {
    single(
        "delay",
        "transport_delay",
        BenchEffects {
            command_delay: 0.008,
            ..Default::default()
        },
        103,
        Some(1.3),
    );
}

#[test]
#[ignore = "a broad case (about 15 s of wall time two at a time); scripts/bench_cases.sh runs every case"]
fn piston_friction_with_a_stribeck_curve() {
    single(
        "friction",
        "piston_friction",
        BenchEffects {
            friction_coulomb: 2.0,
            ..Default::default()
        },
        104,
        Some(2.0),
    );
}

#[test]
#[ignore = "a broad case (about 62 s of CPU); scripts/bench_cases.sh runs every case"]
fn smooth_jet_pipe_hysteresis_is_found_with_the_generators_bouc_wen_constants() {
    if !selected("hysteresis") {
        return;
    }
    let effects = BenchEffects {
        hysteresis_width: 0.16e-3,
        ..Default::default()
    };
    let d = run("hysteresis", effects, 105);
    assert_eq!(names(&d), ["jet_pipe_hysteresis"]);
    assert!(
        d.after.heldout_rms < 1.5 * d.noise_floor,
        "{} vs {}",
        d.after.heldout_rms,
        d.noise_floor
    );
    // The generator's law (synthetic_bench.rs): n = 1, A = 0.5, β = 0.75/w, γ = 0.25/w, so
    // a = β/(β + γ) = 0.75, and a falling approach before the recording (start −1).
    let truth = [
        ("hysteresis_width", 0.16e-3),
        ("hysteresis_exponent", 1.0),
        ("hysteresis_gain", 0.5),
        ("hysteresis_beta_share", 0.75),
        ("hysteresis_start", -1.0),
    ];
    let fitted = &d.effects[0].parameters;
    for (name, value) in truth {
        let found = fitted.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
        let found = found.unwrap_or_else(|| panic!("{name} not fitted: {fitted:?}"));
        assert!(
            (found - value).abs() < 0.05 * value.abs(),
            "{name} = {found}, truth {value}"
        );
    }
}

#[test]
#[ignore = "a broad case (about 43 s of CPU); scripts/bench_cases.sh runs every case"]
fn dead_volume_as_line_volumes() {
    let effects = BenchEffects {
        dead_volume_1: 5e-6,
        dead_volume_2: 5e-6,
        ..Default::default()
    };
    single("dead_volume", "dead_volume", effects, 106, Some(1.5));
}

#[test]
#[ignore = "a broad case (about 9e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn supply_pressure_drop_through_a_plenum() {
    single(
        "supply",
        "supply_pressure_drop",
        BenchEffects {
            supply_resistance: 5e8,
            ..Default::default()
        },
        107,
        Some(2.0),
    );
}

#[test]
#[ignore = "a broad case (about 34 s of CPU); scripts/bench_cases.sh runs every case"]
fn heat_transfer_with_chamber_temperatures() {
    single(
        "heat",
        "heat_transfer",
        BenchEffects {
            heat_transfer: 1.0,
            ..Default::default()
        },
        108,
        Some(1.5),
    );
}

#[test]
#[ignore = "a broad case (about 107 s of CPU); scripts/bench_cases.sh runs every case"]
fn two_effects_at_once() {
    if !selected("two") {
        return;
    }
    let effects = BenchEffects {
        hysteresis_width: 0.12e-3,
        friction_coulomb: 2.0,
        ..Default::default()
    };
    let d = run("two", effects, 109);
    let found = names(&d);
    assert!(
        found.contains(&"jet_pipe_hysteresis") && found.contains(&"piston_friction"),
        "named {found:?}"
    );
    assert!(d.after.heldout_rms < 0.35 * d.before.heldout_rms);
    assert!(
        d.after.heldout_rms < 2.0 * d.noise_floor,
        "held-out error after {:.4} N against the noise floor {:.4} N",
        d.after.heldout_rms,
        d.noise_floor
    );
}

#[test]
#[ignore = "a broad case (about 2e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn calibration_re_identifies_the_static_parameters() {
    // Start the diagnosis from a wrong discharge coefficient and jet pipe offset; with
    // --calibrate it must find the generator's values again (§3.3.1's identification).
    if !selected("calibrate") {
        return;
    }
    let wrong = Parameters {
        c_d: 0.60,
        x_jp_offset: 0.07e-3,
        ..Parameters::default()
    };
    let rows = generate(&BenchEffects::default(), 110, 80.0);
    let recording = generated("synthetic-calibrate", &rows, &wrong);
    let d = diagnose(&recording, &wrong, true, &mut |line| println!("{line}")).unwrap();
    let value = |name: &str| d.calibrated.iter().find(|c| c.name == name).map(|c| c.value).unwrap();
    println!(
        "calibrated: {:?}; after {:.4} N, noise {:.4} N",
        d.calibrated, d.after.rms, d.noise_floor
    );
    assert!((value("C_d") - 0.696).abs() < 0.02, "C_d = {}", value("C_d"));
    assert!(
        (value("x_jp_offset") - 0.099e-3).abs() < 0.01e-3,
        "x_jp_offset = {}",
        value("x_jp_offset")
    );
    assert!(d.effects.is_empty(), "added {:?}", names(&d));
}
