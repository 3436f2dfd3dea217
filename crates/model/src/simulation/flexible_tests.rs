//! The plain constants `extra_force_offset`, `extra_inflow_1` and `extra_inflow_2` against the
//! slots that already add the same terms (a product slot of codes 0 × 0, an extra flow slot
//! of code 0), over recording-like runs of a [`Simulation`].

use super::*;
use crate::physics::extra_flow::{FlowSlot, FADE_PRESSURE};
use crate::physics::extra_force::ProductSlot;
use crate::physics::parameters::Parameters;

/// The command of a recording-like run at 1 kHz: steps, a ramp and a sine.
pub(super) fn command(k: usize) -> f64 {
    match k {
        0..=59 => 1.0,
        60..=139 => 4.5,
        140..=219 => -2.0 + 0.06 * (k - 140) as f64,
        _ => 2.5 + 1.5 * (2.0 * std::f64::consts::PI * 7.0 * k as f64 * 1e-3).sin(),
    }
}

/// The stopper of the run: a 4 Hz sine of ±5 mm about 54 mm, moving linearly between samples.
pub(super) fn stopper(k: usize) -> f64 {
    0.054 + 0.005 * (2.0 * std::f64::consts::PI * 4.0 * k as f64 * 1e-3).sin()
}

/// The readings of every output after each of `samples` steps of 1 ms of a run from the
/// equilibrium of the first inputs: F_act, F_meas, P1, P2, P1_meas, P2_meas, i, x_jp.
pub(super) fn recording(p: &Parameters, samples: usize) -> Vec<[f64; 8]> {
    let model = Actuator::new(p.clone()).unwrap();
    let mut sim = Simulation::at_equilibrium(model, command(0), stopper(0), 0.0, 1e-8).unwrap();
    (0..samples)
        .map(|k| {
            sim.set_command(command(k)).unwrap();
            sim.set_stopper_rate((stopper(k + 1) - sim.x_s()) / 1e-3).unwrap();
            sim.step(1e-3).unwrap();
            sim.land_stopper_at(stopper(k + 1));
            let y = sim.outputs();
            [y.f_act, y.f_meas, y.p1, y.p2, y.p1_meas, y.p2_meas, y.current, y.x_jp]
        })
        .collect()
}

/// The largest difference of each output between two runs, relative to the output's largest
/// magnitude over the first.
pub(super) fn relative_gap(a: &[[f64; 8]], b: &[[f64; 8]]) -> f64 {
    assert_eq!(a.len(), b.len());
    let mut worst = 0.0_f64;
    for c in 0..8 {
        let scale = a.iter().fold(0.0_f64, |m, r| m.max(r[c].abs())).max(1e-300);
        for (ra, rb) in a.iter().zip(b) {
            worst = worst.max((ra[c] - rb[c]).abs() / scale);
        }
    }
    worst
}

#[test]
fn extra_force_offset_gives_the_outputs_of_a_product_slot_of_codes_0_by_0() {
    for c in [2.75, -13.0] {
        let offset = Parameters {
            extra_force_offset: c,
            ..Parameters::default()
        };
        let mut product = Parameters::default();
        product.extra_force_products[1] = ProductSlot {
            first: 0.0,
            second: 0.0,
            origin: 0.0,
            coefficient: c,
        };
        let (a, b) = (recording(&offset, 300), recording(&product, 300));
        let gap = relative_gap(&a, &b);
        assert!(gap <= 1e-12, "c = {c} N: {gap}");
        // The offset acts: the force moves by c where it is above the spring's (§2.7, where
        // the pressures set it), by less where the spring holds it; the pressures do not move.
        let thesis = recording(&Parameters::default(), 300);
        let mut moved_by_c = 0;
        for (r, t) in a.iter().zip(&thesis) {
            let shift = r[0] - t[0];
            assert!(shift.abs() <= c.abs() + 1e-9, "{} against {}", r[0], t[0]);
            moved_by_c += usize::from((shift - c).abs() < 1e-9);
            assert_eq!(r[2], t[2]);
        }
        assert!(moved_by_c > 150, "c = {c} N: the force moved by c at {moved_by_c} samples");
    }
}

#[test]
fn extra_inflow_gives_the_outputs_of_an_extra_flow_slot_of_code_0_in_its_chamber() {
    for (chamber, c) in [(1, 2e-5), (2, -1.5e-5)] {
        let mut constant = Parameters::default();
        if chamber == 1 {
            constant.extra_inflow_1 = c;
        } else {
            constant.extra_inflow_2 = c;
        }
        let mut slot = Parameters::default();
        slot.extra_flows[2] = FlowSlot {
            chamber: chamber as f64,
            signal: 0.0,
            coefficient: c,
        };
        let (a, b) = (recording(&constant, 300), recording(&slot, 300));
        let gap = relative_gap(&a, &b);
        assert!(gap <= 1e-12, "chamber {chamber}, {c} kg/s: {gap}");
        let thesis = recording(&Parameters::default(), 300);
        assert!(relative_gap(&a, &thesis) > 1e-4, "chamber {chamber}: the inflow changes nothing");
        // The rates, with the outflow's fade near vacuum, to the last bit.
        let (with_constant, with_slot) = (Actuator::new(constant).unwrap(), Actuator::new(slot).unwrap());
        for (p1, p2) in [(4e5, 3e5), (0.4 * FADE_PRESSURE, 0.3 * FADE_PRESSURE), (-1.0, 2e5)] {
            let rates = |m: &Actuator| {
                let (a, b) = m.pressure_rates(0.02e-3, p1, p2, 0.054, 0.01);
                (a.to_bits(), b.to_bits())
            };
            assert_eq!(rates(&with_constant), rates(&with_slot), "P1 {p1}, P2 {p2}");
        }
    }
}
