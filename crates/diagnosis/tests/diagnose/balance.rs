//! The extra term in the piston's force balance, picked from a library of local signals:
//! mechanisms that no candidate was written for before it (a mass moving with the stopper,
//! quadratic damping, a seal friction growing with the pressure), each written by the
//! synthetic bench's own integrator with the stopper moving, under three protocols, at two
//! sampling rates, with and without the pressure channels. Each must be discovered at the
//! mechanics as an extra force of its own kind, with its coefficient near the bench's, and
//! the force explained (held-out error within 1.5 noise floors).

use super::diagnose;
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::Diagnosis;
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
        (found.location.as_str(), found.family.as_str(), found.candidate),
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

pub(crate) fn moving_mass(kg: f64) -> UndeclaredEffects {
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

// One move of the stopper, 26 mm in 82 ms inside the held-out block 2–4 s: what follows its
// motion shows in that move alone, and the fits see it only because a short move is cut in
// pieces fitted and scored in turn.
#[test]
#[ignore = "a broad case (about 1e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_mass_moving_with_the_stopper_in_its_one_move_inside_a_held_out_block_is_a_moving_mass() {
    let once = StopperMotion::Move {
        at: 2.6,
        to: 0.08,
        speed: 0.5,
    };
    let d = diagnosed(
        "mass-once",
        &spec(CommandProtocol::Staircase, once, 1000.0, true),
        moving_mass(0.1),
    );
    // In a move one way the sign of the velocity is +1 wherever the acceleration is not
    // small, so a force on sign(v)·a is the moving mass's as well: either, within 10 %.
    let found = d.discovered.first().expect("nothing discovered");
    let parameter = match found.candidate {
        "moving mass" => "extra_force_acceleration",
        "extra force ∝ sign(v)·a" => "extra_force_product_1_coefficient",
        other => panic!("mass-once: {other} ({})", found.reading),
    };
    discovered_as(&d, "mass-once", found.candidate, parameter, -0.1, 0.1);
}

#[test]
#[ignore = "a broad case (about 9 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
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
#[ignore = "a broad case (about 9e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
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
#[ignore = "a broad case (about 5e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
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
#[ignore = "a broad case (about 46 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
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
#[ignore = "a broad case (about 2e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
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
#[ignore = "a broad case (about 1e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
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
#[ignore = "a broad case (about 11 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
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

// The generated products of the mechanics' signals ([`jetpipe_diagnosis::candidates::products`]): forces
// written by the bench's own plant, each found as its own product in the model's slots.

/// A friction growing along the bore and turning with the motion: 75 N/m × (x_s − 54 mm) ×
/// tanh(v / 1 mm/s), about 0.5 N rms with the stopper moving: the slot's coefficient is
/// 0.75 N per 10 mm, its origin (with the slot of the sign alone) 54 mm. The stopper moves at
/// 50 mm/s, as for the seal friction: the sign turns over 1 mm/s, within the first few
/// milliseconds of a move, where the velocity the model forms from the samples (exact to
/// second order in the interval) misses the bench's own by a share of that speed. Moves at
/// 0.2 m/s sampled at 1 kHz found the product (0.99 N per 10 mm against 1, origin 54.0 mm)
/// but left 1.75 noise floors; at 2 kHz 1.23.
#[test]
fn a_force_on_the_position_times_the_sign_under_a_multisine_at_one_kilohertz_is_that_product() {
    let label = "position-sign-multisine";
    let d = diagnosed(
        label,
        &spec(CommandProtocol::Multisine, SLOW_MOVES, 1000.0, true),
        UndeclaredEffects {
            position_sign_force: 75.0,
            position_sign_origin: 0.054,
            ..UndeclaredEffects::default()
        },
    );
    discovered_as(
        &d,
        label,
        "extra force ∝ (x_s − x0)·sign(v)",
        "extra_force_product_1_coefficient",
        0.75,
        0.05,
    );
    let get = |name: &str| d.parameters.get(value_reference(name)).unwrap();
    // c₁ (x_s − x̄)/10 mm + c₂ = c₁ (x_s − x₀)/10 mm with x₀ = x̄ − 10 mm × c₂/c₁.
    let (c1, c2) = (
        get("extra_force_product_1_coefficient"),
        get("extra_force_product_2_coefficient"),
    );
    let x0 = get("extra_force_product_1_origin") - 0.01 * c2 / c1;
    println!(
        "{label}: c₁ = {c1} N per 10 mm, x₀ = {:.2} mm; {}",
        x0 * 1e3,
        d.discovered[0].reading
    );
    assert!((x0 - 0.054).abs() < 0.5e-3, "{label}: x₀ = {x0} m");
    assert!(
        d.discovered[0].reading.contains("the sign of the stopper velocity"),
        "{}",
        d.discovered[0].reading
    );
}

/// Chamber 1's pressure on an annulus the thesis leaves out: 1e-6 m² × (P1 − P_r), the slot's
/// coefficient 0.1 N per bar, about 0.45 N rms; no pressure channels.
#[test]
#[ignore = "a broad case (about 23 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_force_on_chamber_1s_pressure_under_a_multisine_at_500_hertz_without_pressures_is_that_product() {
    let label = "chamber-1-pressure-multisine";
    let d = diagnosed(
        label,
        &spec(CommandProtocol::Multisine, MOVES, 500.0, false),
        UndeclaredEffects {
            chamber_1_pressure_force: 1e-6,
            ..UndeclaredEffects::default()
        },
    );
    discovered_as(
        &d,
        label,
        "extra force ∝ (P1 − P_r)",
        "extra_force_product_1_coefficient",
        0.1,
        0.05,
    );
}
