//! The per-step cost of the modulation slots: a 1 kHz replay (`FixedStep`) and the
//! error-controlled `Simulation::step` of 2 s of a stepped command, with the slots off, with a
//! slot on the supply pressure by P1 (constants only), on k_cd by P1 (the propagator rebuilt
//! every step) and on the force sensor's gain by F_act (the outputs formed with it).
//!
//! `cargo run --release -p jetpipe-model --example modulation_cost`

use std::time::Instant;

use jetpipe_model::physics::modulation::{ModulationSignal, Slot};
use jetpipe_model::variables::vr;
use jetpipe_model::{Actuator, FixedStep, Parameters, Simulation};

const SAMPLES: usize = 2000;

fn command(k: usize) -> f64 {
    [1.0, 4.0, -2.0, 0.5, 6.0][(k / 100) % 5]
}

fn per_step(p: &Parameters, fixed: bool) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let model = Actuator::new(p.clone()).unwrap();
        if fixed {
            let mut run = FixedStep::at_equilibrium(model, 1.0, 0.054, 0.0).unwrap().unwrap();
            let begun = Instant::now();
            for k in 0..SAMPLES {
                run.set_command(command(k)).unwrap();
                run.step_to((k + 1) as f64 * 1e-3, 0.054).unwrap();
            }
            best = best.min(begun.elapsed().as_secs_f64());
        } else {
            let mut run = Simulation::at_equilibrium(model, 1.0, 0.054, 0.0, 1e-6).unwrap();
            let begun = Instant::now();
            let mut force = 0.0;
            for k in 0..SAMPLES {
                run.set_command(command(k)).unwrap();
                run.step(1e-3).unwrap();
                force += run.outputs().f_meas;
            }
            best = best.min(begun.elapsed().as_secs_f64());
            assert!(force.is_finite());
        }
    }
    best / SAMPLES as f64 * 1e6
}

fn main() {
    let slot = |constant: u32, signal, x: &[f64], y: &[f64]| Parameters {
        modulation: [Slot::through(constant, signal, x, y), Slot::default()],
        ..Parameters::default()
    };
    let cases = [
        ("slots off", Parameters::default()),
        (
            "P_s by P1",
            slot(vr::P_S, ModulationSignal::P1, &[2e5, 6e5], &[0.0, -3e4]),
        ),
        (
            "k_cd by P1",
            slot(vr::K_CD, ModulationSignal::P1, &[2e5, 6e5], &[0.0, 0.004]),
        ),
        (
            "force_sensor_gain by F_act",
            slot(
                vr::FORCE_SENSOR_GAIN,
                ModulationSignal::Force,
                &[0.0, 100.0],
                &[0.0, 0.02],
            ),
        ),
    ];
    println!(
        "{:<28} {:>16} {:>22}",
        "case", "FixedStep µs/step", "Simulation::step µs/step"
    );
    for (name, p) in &cases {
        println!("{name:<28} {:>16.2} {:>22.2}", per_step(p, true), per_step(p, false));
    }
}
