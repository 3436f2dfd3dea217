//! Recording-like runs of a [`Simulation`] with the plain constants `extra_force_offset`,
//! `extra_inflow_1` and `extra_inflow_2` and with the flexible slots, against what already adds
//! the same terms: a product slot of codes 0 × 0, an extra flow slot of code 0, modulation
//! slots through the same knots; a lagged slot against the analytic lag response; snapshots
//! with a lag state.

use super::*;
use crate::physics::extra_flow::{FlowSlot, FADE_PRESSURE};
use crate::physics::extra_force::ProductSlot;
use crate::physics::flexible::FlexibleSlot;
use crate::physics::modulation::{ModulationSignal, Slot};
use crate::physics::parameters::Parameters;
use crate::variables::vr;

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
        assert!(
            moved_by_c > 150,
            "c = {c} N: the force moved by c at {moved_by_c} samples"
        );
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
        assert!(
            relative_gap(&a, &thesis) > 1e-4,
            "chamber {chamber}: the inflow changes nothing"
        );
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

/// The readings of the same run through the fixed-step replay (the diagnosis's).
fn replay(p: &Parameters, samples: usize) -> Vec<[f64; 8]> {
    let model = Actuator::new(p.clone()).unwrap();
    let mut fixed = FixedStep::at_equilibrium(model, command(0), stopper(0), 0.0)
        .unwrap()
        .unwrap();
    (0..samples)
        .map(|k| {
            fixed.set_command(command(k)).unwrap();
            fixed.step_to((k + 1) as f64 * 1e-3, stopper(k + 1)).unwrap();
            let y = fixed.outputs();
            [y.f_act, y.f_meas, y.p1, y.p2, y.p1_meas, y.p2_meas, y.current, y.x_jp]
        })
        .collect()
}

#[test]
fn a_flexible_slot_of_one_signal_without_lag_gives_the_outputs_of_a_modulation_slot_through_the_same_knots() {
    let cases = [
        // A flow constant on the stopper position.
        (
            vr::C_D,
            ModulationSignal::StopperPosition,
            vec![0.05, 0.054, 0.058],
            vec![-0.05, 0.02, 0.06],
        ),
        // A transducer offset on the command, past the end knots at both ends of the run.
        (
            vr::P1_SENSOR_OFFSET,
            ModulationSignal::Command,
            vec![-1.0, 1.5, 3.0, 4.0],
            vec![-2e3, 5e3, 1e3, 8e3],
        ),
    ];
    let thesis = recording(&Parameters::default(), 300);
    for (constant, signal, x, y) in cases {
        let mut modulated = Parameters::default();
        modulated.modulation[1] = Slot::through(constant, signal, &x, &y);
        let mut flexible = Parameters::default();
        flexible.flexible[0] = FlexibleSlot::through(constant, signal, &x, &y);
        let name = crate::physics::parameters::variable_name(constant);
        let (a, b) = (recording(&modulated, 300), recording(&flexible, 300));
        let gap = relative_gap(&a, &b);
        assert!(gap <= 1e-12, "{name}: {gap}");
        assert!(relative_gap(&a, &thesis) > 1e-4, "{name}: the slot changes nothing");
        let gap = relative_gap(&replay(&modulated, 300), &replay(&flexible, 300));
        assert!(gap <= 1e-12, "{name}, fixed steps: {gap}");
    }
}

#[test]
fn a_two_signal_slot_with_separable_increments_gives_the_outputs_of_two_modulation_slots_on_its_constant() {
    // y_ij = a_i + b_j on C_d, a over x_s and b over v_DA: the two modulation slots a and b.
    let (x1, a) = ([0.05, 0.054, 0.058], [-0.04, 0.01, 0.05]);
    let (x2, b) = ([-2.0, 0.0, 2.0, 4.0], [0.03, -0.02, 0.04, 0.0]);
    let two = Parameters {
        modulation: [
            Slot::through(vr::C_D, ModulationSignal::StopperPosition, &x1, &a),
            Slot::through(vr::C_D, ModulationSignal::Command, &x2, &b),
        ],
        ..Parameters::default()
    };
    let mut grid = FlexibleSlot::through(vr::C_D, ModulationSignal::StopperPosition, &x1, &[0.0; 3]);
    grid.signals[1] = ModulationSignal::Command.code() as f64;
    grid.knots[1] = 4.0;
    grid.x[1][..4].copy_from_slice(&x2);
    for i in 0..3 {
        for j in 0..4 {
            grid.y[i][j] = a[i] + b[j];
        }
    }
    let mut flexible = Parameters::default();
    flexible.flexible[1] = grid;
    let (expected, got) = (recording(&two, 300), recording(&flexible, 300));
    let gap = relative_gap(&expected, &got);
    assert!(gap <= 1e-12, "{gap}");
    // Each axis acts: b alone is another run.
    let mut one = Parameters::default();
    one.modulation[0] = two.modulation[0];
    assert!(relative_gap(&expected, &recording(&one, 300)) > 1e-4);
}

/// The force F_act after each of the steps of 1 ms at the commands `commands` (their rates
/// `rates` over the step) from the equilibrium at the first command, the stopper held.
fn forces(p: &Parameters, commands: &[(f64, f64)]) -> Vec<f64> {
    let model = Actuator::new(p.clone()).unwrap();
    let mut sim = Simulation::at_equilibrium(model, commands[0].0, 0.054, 0.0, 1e-8).unwrap();
    commands
        .iter()
        .map(|&(v, rate)| {
            sim.set_command(v).unwrap();
            sim.set_command_rate(rate).unwrap();
            sim.step(1e-3).unwrap();
            sim.outputs().f_act
        })
        .collect()
}

#[test]
fn a_lagged_slot_on_extra_force_offset_adds_the_analytic_lag_response_to_the_command() {
    // The increment c' u of the command's low-pass u (τ = 20 ms), c' = 0.4 N/V: the force the
    // slot adds is F_act less the thesis model's, since the offset moves no pressure.
    let (tau, gain, h) = (0.02, 0.4, 1e-3);
    let mut slot = FlexibleSlot::through(
        vr::EXTRA_FORCE_OFFSET,
        ModulationSignal::Command,
        &[-10.0, 10.0],
        &[-4.0, 4.0],
    );
    slot.lags[0] = tau;
    let mut p = Parameters::default();
    p.flexible[0] = slot;
    // A step from 1 V to 4.5 V held over each step: the lag's update is the exact response of a
    // held signal, u = 4.5 − 3.5 e^(−t/τ), so the bound is rounding (1e-12 N here).
    let step: Vec<(f64, f64)> = (0..150).map(|k| (if k == 0 { 1.0 } else { 4.5 }, 0.0)).collect();
    let (with, thesis_step) = (forces(&p, &step), forces(&Parameters::default(), &step));
    for k in 1..150 {
        let t = k as f64 * h;
        let c = gain * 3.5;
        let expected = gain * 1.0 + c * (1.0 - (-t / tau).exp());
        let added = with[k] - thesis_step[k];
        assert!(
            (added - expected).abs() < 1e-12,
            "t = {t} s: {added} N against {expected} N"
        );
    }
    // A ramp of r = 40 V/s from 1 V: u lags it by the exact response's r (t − τ(1 − e^(−t/τ)))
    // to within r h²/(12 τ) (the trapezoid of each step's ends: see physics::flexible's tests).
    let r = 40.0;
    let ramp: Vec<(f64, f64)> = (0..100).map(|k| (1.0 + r * k as f64 * h, r)).collect();
    let (with, without) = (forces(&p, &ramp), forces(&Parameters::default(), &ramp));
    let bound = gain * r * h * h / (12.0 * tau);
    for k in 0..100 {
        let t = (k + 1) as f64 * h;
        let expected = gain * (1.0 + r * (t - tau * (1.0 - (-t / tau).exp())));
        let added = with[k] - without[k];
        assert!(
            (added - expected).abs() <= 1.01 * bound + 1e-12,
            "t = {t} s: {added} N against {expected} N (bound {bound} N)"
        );
    }
    // Without the lag, the raw command: a different force from the first step on.
    let mut raw = p.clone();
    raw.flexible[0].lags[0] = 0.0;
    let unlagged = forces(&raw, &step);
    let added = unlagged[1] - thesis_step[1];
    assert!((added - gain * 4.5).abs() < 1e-12, "{added} N");
}

/// A 2-D slot on C_d with a lag on each axis (command and P1 − P2).
fn with_lagged_grid() -> Parameters {
    let mut slot = FlexibleSlot::through(vr::C_D, ModulationSignal::Command, &[0.0, 3.0, 6.0], &[0.0; 3]);
    slot.signals[1] = ModulationSignal::PressureDifference.code() as f64;
    slot.knots[1] = 2.0;
    slot.x[1][..2].copy_from_slice(&[-2e5, 2e5]);
    slot.lags = [0.015, 0.004];
    for i in 0..3 {
        for j in 0..2 {
            slot.y[i][j] = 0.05 * i as f64 - 0.04 * j as f64;
        }
    }
    let mut p = Parameters::default();
    p.flexible[1] = slot;
    p.force_sensor_offset = 0.1;
    p
}

#[test]
fn a_snapshot_mid_run_continues_bit_for_bit_with_a_lagged_slot_and_carries_its_lag_state() {
    let model = Actuator::new(with_lagged_grid()).unwrap();
    let mut original = Simulation::at_equilibrium(model.clone(), command(0), stopper(0), 0.0, 1e-6).unwrap();
    let drive = |sim: &mut Simulation, k: usize| {
        sim.set_command(command(k)).unwrap();
        sim.set_stopper_rate((stopper(k + 1) - sim.x_s()) / 1e-3).unwrap();
        sim.step(1e-3).unwrap();
        sim.land_stopper_at(stopper(k + 1));
        let y = sim.outputs();
        [y.f_act, y.f_meas, y.p1, y.p2].map(f64::to_bits)
    };
    for k in 0..70 {
        drive(&mut original, k);
    }
    let snapshot = original.snapshot();
    let values = snapshot.to_values();
    let mut decoded = Simulation::restore(model.clone(), &SimulationSnapshot::from_values(&values).unwrap()).unwrap();
    // The lag state moved from its start, so that carrying it matters.
    let lags = original.flexible_lags[1];
    let settled = Simulation::at_equilibrium(model.clone(), command(0), stopper(0), 0.0, 1e-6).unwrap();
    assert!(lags != settled.flexible_lags[1], "{lags:?}");
    // The same snapshot with the lag state of the start.
    let position = values.iter().position(|v| v.to_bits() == lags[0].to_bits()).unwrap();
    assert_eq!(values[position + 1].to_bits(), lags[1].to_bits());
    let mut forgetful_values = values.clone();
    forgetful_values[position] = settled.flexible_lags[1][0];
    forgetful_values[position + 1] = settled.flexible_lags[1][1];
    let mut forgetful =
        Simulation::restore(model, &SimulationSnapshot::from_values(&forgetful_values).unwrap()).unwrap();
    let mut differs = false;
    for k in 70..200 {
        let expected = drive(&mut original, k);
        assert_eq!(drive(&mut decoded, k), expected, "step {k}");
        differs |= drive(&mut forgetful, k) != expected;
    }
    assert_eq!(original.snapshot(), decoded.snapshot());
    assert!(differs, "the lag state changed nothing");
}

#[test]
fn a_slot_on_a_lagging_or_filtering_transducers_offset_reads_as_the_same_offset_set_directly() {
    // Each transducer's memory records the reading once a step, with the slot's increment
    // set once: a constant increment of the offset gives the readings of that offset.
    type Case = (u32, fn(&mut Parameters, f64), fn(&mut Parameters), usize);
    let cases: [Case; 4] = [
        (
            vr::P1_SENSOR_OFFSET,
            |p, c| p.p1_sensor_offset += c,
            |p| p.p1_sensor_lag = 1e-3,
            4,
        ),
        (
            vr::P2_SENSOR_OFFSET,
            |p, c| p.p2_sensor_offset += c,
            |p| p.p2_sensor_lag = 4e-3,
            5,
        ),
        (
            vr::FORCE_SENSOR_OFFSET,
            |p, c| p.force_sensor_offset += c,
            |p| {
                p.force_sensor_filter_frequency = 150.0;
                p.force_sensor_filter_damping = 0.6;
            },
            1,
        ),
        (
            vr::P1_SENSOR_OFFSET,
            |p, c| p.p1_sensor_offset += c,
            |p| p.p1_sensor_delay = 2.5e-3,
            4,
        ),
    ];
    for (constant, add, filter, channel) in cases {
        let increment = if channel == 1 { 0.75 } else { 1000.0 };
        let mut direct = Parameters::default();
        filter(&mut direct);
        let mut slotted = direct.clone();
        add(&mut direct, increment);
        slotted.modulation[0] = Slot::through(
            constant,
            ModulationSignal::Command,
            &[-10.0, 10.0],
            &[increment, increment],
        );
        let (a, b) = (recording(&direct, 300), recording(&slotted, 300));
        let worst = a
            .iter()
            .zip(&b)
            .map(|(x, y)| (x[channel] - y[channel]).abs())
            .fold(0.0, f64::max);
        assert!(worst <= 1e-9 * increment, "vr {constant}: {worst}");
        // The increment acts, once.
        let mut plain = direct.clone();
        add(&mut plain, -increment);
        let settled = recording(&plain, 300);
        let moved = b[299][channel] - settled[299][channel];
        assert!(
            (moved - increment).abs() <= 1e-6 * increment,
            "vr {constant}: moved by {moved}"
        );
    }
}
