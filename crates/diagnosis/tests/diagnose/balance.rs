//! The extra term in the piston's force balance, picked from a library of local signals:
//! mechanisms that no candidate was written for before it (a mass moving with the stopper,
//! quadratic damping, a seal friction growing with the pressure), each written by the
//! synthetic bench's own integrator with the stopper moving, under three protocols, at two
//! sampling rates, with and without the pressure channels. Each must be discovered at the
//! mechanics as an extra force of its own kind, with its coefficient near the bench's, and
//! the force explained (held-out error within 1.5 noise floors).

use jetpipe_diagnosis::recording::Recording;
use jetpipe_diagnosis::{diagnose, Diagnosis};
use jetpipe_model::physics::parameters::Parameters;
use synthetic_bench::{
    generate_protocol, BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion, UndeclaredEffects,
};

use super::{names, value_reference};

fn diagnosed(label: &str, spec: &ProtocolSpec, undeclared: UndeclaredEffects) -> Diagnosis {
    let effects = BenchEffects {
        undeclared,
        ..BenchEffects::default()
    };
    let dir = std::env::temp_dir().join(format!("jetpipe-diagnose-{}-{label}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    generate_protocol(spec, &effects).unwrap().write_csv(&path).unwrap();
    let recording = Recording::read(&path, &Parameters::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let started = std::time::Instant::now();
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!(
        "{label} ({}): {} in {:.1} s, held-out after {:.2} noise floors; {}",
        spec.label(),
        d.verdict(),
        started.elapsed().as_secs_f64(),
        d.after.heldout_rms / d.noise_floor,
        d.summary().join(" | ")
    );
    d
}

/// 20 s with 0.03 N of force noise, the stopper as given.
fn spec(command: CommandProtocol, stopper: StopperMotion, sample_rate: f64, pressures: bool) -> ProtocolSpec {
    ProtocolSpec {
        command,
        stopper,
        sample_rate,
        duration: 20.0,
        force_noise: 0.03,
        pressures,
        seed: 5,
        ..ProtocolSpec::default()
    }
}

/// The first thing added is the candidate `candidate` at the mechanics, an extra force, its
/// FMU parameter `parameter` within `tolerance` (relative) of `truth`; nothing named; the
/// force explained.
fn discovered_as(d: &Diagnosis, label: &str, candidate: &str, parameter: &str, truth: f64, tolerance: f64) {
    assert!(names(d).is_empty(), "{label}: named {:?}", names(d));
    let found = d
        .discovered
        .first()
        .unwrap_or_else(|| panic!("{label}: nothing discovered ({})", d.summary()[0]));
    assert_eq!(
        (found.location, found.family, found.candidate),
        ("mechanics", "extra_force", candidate),
        "{label}: {}",
        found.reading
    );
    let fitted = d.parameters.get(value_reference(parameter)).unwrap();
    assert!(
        (fitted / truth - 1.0).abs() < tolerance,
        "{label}: {parameter} = {fitted}, the bench's {truth}"
    );
    assert_eq!(d.verdict(), "explained", "{label}: {}", d.summary()[0]);
    assert!(d.after.heldout_rms <= 1.5 * d.noise_floor);
}

const MOVES: StopperMotion = StopperMotion::Moves { speed: 0.2 };
const SLOW_MOVES: StopperMotion = StopperMotion::Moves { speed: 0.05 };

fn moving_mass(kg: f64) -> UndeclaredEffects {
    UndeclaredEffects {
        moving_mass: kg,
        ..UndeclaredEffects::default()
    }
}

fn quadratic_damping(coefficient: f64) -> UndeclaredEffects {
    UndeclaredEffects {
        quadratic_damping: coefficient,
        ..UndeclaredEffects::default()
    }
}

fn seal_friction(coefficient: f64) -> UndeclaredEffects {
    UndeclaredEffects {
        seal_pressure_friction: coefficient,
        ..UndeclaredEffects::default()
    }
}

// A mass moving with the stopper: the reading loses m a. A shaken stopper's acceleration is
// −ω² times its displacement, which a spring on the position reads as well, so the stopper
// moves between positions (half-cosine profiles). The model's acceleration, the second
// difference of the smoothed positions one sample late, misses the profile's jumps by a few
// samples, so the mass is fitted within 10 %.

#[test]
fn a_mass_moving_with_the_stopper_under_a_staircase_at_one_kilohertz_is_a_moving_mass() {
    let d = diagnosed(
        "mass-staircase",
        &spec(CommandProtocol::Staircase, MOVES, 1000.0, true),
        moving_mass(0.1),
    );
    discovered_as(
        &d,
        "mass-staircase",
        "moving mass",
        "extra_force_acceleration",
        -0.1,
        0.1,
    );
    assert!(
        d.discovered[0].reading.contains("a moving mass of"),
        "{}",
        d.discovered[0].reading
    );
}

#[test]
fn a_mass_moving_with_the_stopper_under_a_slow_sine_at_two_kilohertz_is_a_moving_mass() {
    let d = diagnosed(
        "mass-sine",
        &spec(CommandProtocol::Sine, MOVES, 2000.0, true),
        moving_mass(0.1),
    );
    discovered_as(&d, "mass-sine", "moving mass", "extra_force_acceleration", -0.1, 0.1);
}

#[test]
#[ignore = "40 s of fitting every place without pressures; scripts/bench_protocols.sh runs it"]
fn a_mass_moving_with_the_stopper_under_a_multisine_without_pressures_is_a_moving_mass() {
    let d = diagnosed(
        "mass-multisine",
        &spec(CommandProtocol::Multisine, MOVES, 1000.0, false),
        moving_mass(0.1),
    );
    discovered_as(
        &d,
        "mass-multisine",
        "moving mass",
        "extra_force_acceleration",
        -0.1,
        0.1,
    );
}

// Quadratic damping q v|v|, 300 N·s²/m²: 3 N at 0.1 m/s.

#[test]
fn quadratic_damping_under_a_staircase_at_one_kilohertz_is_quadratic_not_viscous() {
    let d = diagnosed(
        "quadratic-staircase",
        &spec(
            CommandProtocol::Staircase,
            StopperMotion::Moves { speed: 0.1 },
            1000.0,
            true,
        ),
        quadratic_damping(300.0),
    );
    discovered_as(
        &d,
        "quadratic-staircase",
        "quadratic damping",
        "extra_force_velocity_squared",
        -300.0,
        0.05,
    );
}

#[test]
fn quadratic_damping_under_ramps_at_five_hundred_hertz_is_quadratic_damping() {
    let d = diagnosed(
        "quadratic-ramps",
        &spec(CommandProtocol::Ramps, StopperMotion::Moves { speed: 0.1 }, 500.0, true),
        quadratic_damping(300.0),
    );
    discovered_as(
        &d,
        "quadratic-ramps",
        "quadratic damping",
        "extra_force_velocity_squared",
        -300.0,
        0.05,
    );
}

#[test]
fn quadratic_damping_under_a_multisine_with_a_shaken_stopper_at_250_hertz_without_pressures_is_found() {
    let shaken = StopperMotion::Sine {
        centre: 0.054,
        amplitude: 0.01,
        frequency: 2.5,
    };
    let d = diagnosed(
        "quadratic-multisine",
        &spec(CommandProtocol::Multisine, shaken, 250.0, false),
        quadratic_damping(300.0),
    );
    discovered_as(
        &d,
        "quadratic-multisine",
        "quadratic damping",
        "extra_force_velocity_squared",
        -300.0,
        0.1,
    );
}

// A seal friction μ (P1 + P2 − 2 P_r) tanh(v / 0.2 mm/s), μ = 1e-6 m²: 0.5 N at 5 bar above
// the return, changing with the command's pressures; the named piston_friction competes.

#[test]
fn a_seal_friction_growing_with_the_pressure_under_a_staircase_at_one_kilohertz_is_found() {
    let d = diagnosed(
        "seal-staircase",
        &spec(CommandProtocol::Staircase, SLOW_MOVES, 1000.0, true),
        seal_friction(1e-6),
    );
    discovered_as(
        &d,
        "seal-staircase",
        "seal friction growing with the pressure",
        "extra_force_sign_pressure",
        -1e-6,
        0.05,
    );
}

#[test]
fn a_seal_friction_growing_with_the_pressure_under_ramps_at_five_hundred_hertz_is_found() {
    let d = diagnosed(
        "seal-ramps",
        &spec(CommandProtocol::Ramps, SLOW_MOVES, 500.0, true),
        seal_friction(1e-6),
    );
    discovered_as(
        &d,
        "seal-ramps",
        "seal friction growing with the pressure",
        "extra_force_sign_pressure",
        -1e-6,
        0.05,
    );
}

#[test]
fn a_seal_friction_growing_with_the_pressure_under_a_slow_sine_at_250_hertz_without_pressures_is_found() {
    let d = diagnosed(
        "seal-sine",
        &spec(CommandProtocol::Sine, SLOW_MOVES, 250.0, false),
        seal_friction(1e-6),
    );
    discovered_as(
        &d,
        "seal-sine",
        "seal friction growing with the pressure",
        "extra_force_sign_pressure",
        -1e-6,
        0.05,
    );
}
