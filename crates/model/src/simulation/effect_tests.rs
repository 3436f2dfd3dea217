//! Runs of a [`Simulation`] with the effects on: each changes what it should, and the gas
//! volumes behind restrictions behave as their quasi-static limits say.

use super::tests::{thesis_model, with};
use super::*;
use crate::physics::parameters::Parameters;
use crate::physics::restrictions::PRESSURES_WITH_VOLUMES;

/// Force after holding `v` for `hold` seconds, having come from `from`.
fn settled_force(model: &Actuator, from: f64, v: f64, hold: f64) -> f64 {
    let mut sim = Simulation::at_equilibrium(model.clone(), from, 0.054, 0.0, 1e-6).unwrap();
    // a slow ramp so hysteresis sees a monotone sweep
    for k in 1..=100 {
        sim.set_command(from + (v - from) * k as f64 / 100.0).unwrap();
        sim.step(0.01).unwrap();
    }
    sim.step(hold).unwrap();
    sim.outputs().f_act
}

#[test]
fn effects_are_off_by_default_and_each_changes_what_it_should() {
    let thesis = thesis_model();
    // jet_pipe_hysteresis: at the same command the force is higher coming down than
    // going up (the tip lags the command by the play widths).
    let hysteretic = with(|p| p.hysteresis_width = 0.16e-3);
    let up = settled_force(&hysteretic, -4.0, 0.5, 2.0);
    let down = settled_force(&hysteretic, 6.0, 0.5, 2.0);
    let plain_up = settled_force(&thesis, -4.0, 0.5, 2.0);
    let plain_down = settled_force(&thesis, 6.0, 0.5, 2.0);
    // (the plain model is still settling from opposite sides: allow a tenth of the loop)
    assert!(
        (plain_up - plain_down).abs() < 0.1 * (down - up),
        "hysteresis without the effect: {plain_up} {plain_down}"
    );
    assert!(down - up > 1.0, "hysteresis loop: up {up} N, down {down} N");
    // supply_pressure_drop lowers the saturated force; dead_volume does not change statics.
    let full = settled_force(&thesis, 0.0, 10.0, 2.0);
    let dropped = settled_force(&with(|p| p.supply_resistance = 3e8), 0.0, 10.0, 2.0);
    assert!(dropped < full - 1.0, "supply drop: {dropped} vs {full}");
    let dead = with(|p| {
        p.dead_volume_1 = 3e-6;
        p.dead_volume_2 = 3e-6;
    });
    assert!((settled_force(&dead, 0.0, 2.5, 3.0) - settled_force(&thesis, 0.0, 2.5, 3.0)).abs() < 1e-3);
    // dead_volume and heat_transfer slow the pressure response to a command step.
    let response = |model: &Actuator| {
        let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-6).unwrap();
        let start = sim.outputs().f_act;
        sim.set_command(2.5).unwrap();
        sim.step(0.05).unwrap();
        sim.outputs().f_act - start
    };
    let base = response(&thesis);
    assert!(
        response(&dead) < 0.9 * base,
        "dead volume: {} vs {base}",
        response(&dead)
    );
    let isothermal = with(|p| p.heat_transfer_fraction = 1.0);
    assert!(
        response(&isothermal) < 0.9 * base,
        "heat transfer: {} vs {base}",
        response(&isothermal)
    );
    // transport_delay: nothing happens until the delay has passed.
    let delayed = with(|p| p.command_delay = 0.02);
    let mut sim = Simulation::at_equilibrium(delayed, 1.0, 0.054, 0.0, 1e-6).unwrap();
    let i0 = sim.outputs().current;
    sim.set_command(2.5).unwrap();
    for _ in 0..19 {
        sim.step(0.001).unwrap();
    }
    assert!(
        (sim.outputs().current - i0).abs() < 1e-12,
        "current moved before the delay"
    );
    sim.step(0.005).unwrap();
    assert!(
        sim.outputs().current > i0 + 0.05,
        "current did not follow after the delay"
    );
    // piston_friction: the rod force drops by F_c while the stopper extends.
    let friction = with(|p| p.friction_coulomb = 1.5);
    let run = |model: Actuator| {
        let mut sim = Simulation::at_equilibrium(model, 2.5, 0.054, 0.0, 1e-6).unwrap();
        sim.set_stopper_rate(0.01).unwrap();
        sim.step(0.01).unwrap();
        sim.outputs().f_act
    };
    assert!((run(thesis.clone()) - run(friction) - 1.5).abs() < 1e-9);
    // sensor_offset_gain
    let sensor = with(|p| {
        p.force_sensor_offset = 0.7;
        p.force_sensor_gain = 1.02;
    });
    let y = Simulation::at_equilibrium(sensor, 2.5, 0.054, 0.0, 1e-6)
        .unwrap()
        .outputs();
    assert!((y.f_meas - (0.7 + 1.02 * y.f_act)).abs() < 1e-12);
    let y = Simulation::at_equilibrium(thesis, 2.5, 0.054, 0.0, 1e-6)
        .unwrap()
        .outputs();
    assert_eq!(y.f_meas, y.f_act);
}

/// 0.3 s of command steps at 1 kHz, the forces and the volumes' pressures at each sample.
fn stepped_run(model: &Actuator) -> (Vec<f64>, Vec<[f64; node::COUNT]>) {
    let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-8).unwrap();
    let (mut forces, mut nodes) = (vec![], vec![]);
    for k in 0..300 {
        sim.set_command(if (k / 50) % 2 == 0 { 4.0 } else { 1.0 }).unwrap();
        sim.step(1e-3).unwrap();
        forces.push(sim.outputs().f_act);
        nodes.push(sim.node_pressures());
    }
    (forces, nodes)
}

fn worst_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// A volume behind a restriction, shrunk to a thousandth of a cubic millimetre, fills in
/// microseconds: the run must follow the quasi-static restriction's, which takes no volume
/// and finds the pressure behind it as a root at every evaluation.
#[test]
fn a_vanishing_volume_behind_a_restriction_gives_the_restriction_alone() {
    type Setter = fn(&mut Parameters, f64);
    let cases: [(&str, Setter); 3] = [
        ("port line behind an orifice", |p, v| {
            p.port_restriction_area_1 = 0.2e-6;
            p.port_line_volume_1 = v;
        }),
        ("supply plenum behind a resistance", |p, v| {
            p.supply_resistance = 3e8;
            p.supply_plenum_volume = v;
        }),
        ("return plenum behind a vent orifice", |p, v| {
            p.return_vent_area = 0.35e-6;
            p.return_plenum_volume = v;
        }),
    ];
    let (thesis, _) = stepped_run(&thesis_model());
    for (name, set) in cases {
        let (quasi_static, _) = stepped_run(&with(|p| set(p, 0.0)));
        let (tiny, _) = stepped_run(&with(|p| set(p, 1e-12)));
        let (sizeable, _) = stepped_run(&with(|p| set(p, 3e-6)));
        let effect = worst_difference(&quasi_static, &thesis);
        assert!(
            effect > 0.3,
            "{name}: the restriction moves the force by {effect} N only"
        );
        let gap = worst_difference(&tiny, &quasi_static);
        assert!(
            gap < 1e-3 * effect,
            "{name}: {gap} N from the quasi-static run (effect {effect} N)"
        );
        let volume_effect = worst_difference(&sizeable, &quasi_static);
        assert!(
            volume_effect > 0.05,
            "{name}: 3 cm3 moves the force by {volume_effect} N only"
        );
    }
}

#[test]
fn with_volumes_the_equilibrium_balances_every_flow_and_stays_put() {
    let model = with(|p| {
        p.supply_restriction_area = 0.25e-6;
        p.supply_plenum_volume = 2e-6;
        p.return_resistance = 1e8;
        p.return_plenum_volume = 1e-6;
        p.port_restriction_area_2 = 0.3e-6;
        p.port_line_volume_2 = 3e-6;
    });
    for v in [-3.0, 1.0, 2.5, 8.0] {
        let mut sim = Simulation::at_equilibrium(model.clone(), v, 0.06, 0.0, 1e-8).unwrap();
        let mut pressures = [0.0; PRESSURES_WITH_VOLUMES];
        pressures[0] = sim.state[index::P1];
        pressures[1] = sim.state[index::P2];
        pressures[2..2 + node::COUNT].copy_from_slice(&sim.node_pressures());
        let rates =
            model.pressure_rates_with_volumes(&model.areas(sim.state[index::JET_POSITION]), &pressures, 0.06, 0.0);
        // A pascal per second at most: far below a millisecond's change of 1 Pa.
        assert!(rates.iter().all(|r| r.abs() < 1.0), "v = {v}: {rates:?}");
        let p = &model.params;
        let nodes = sim.node_pressures();
        assert!(
            nodes[node::SUPPLY] < p.p_s && nodes[node::SUPPLY] > p.p_r,
            "v = {v}: {nodes:?}"
        );
        assert!(
            nodes[node::RETURN] > p.p_r && nodes[node::RETURN] < p.p_s,
            "v = {v}: {nodes:?}"
        );
        let before = sim.outputs();
        sim.step(0.5).unwrap();
        let after = sim.outputs();
        assert!(
            (after.f_act - before.f_act).abs() < 1e-6,
            "v = {v}: {before:?} -> {after:?}"
        );
        assert!(worst_difference(&sim.node_pressures(), &nodes) < 1e-3, "v = {v}");
    }
}

/// The volumes change how the pressures get there, not where they settle: the static force
/// is the quasi-static restriction's, and a command step reaches it later.
#[test]
fn a_line_volume_keeps_the_static_force_and_slows_the_step() {
    let alone = with(|p| p.port_restriction_area_1 = 0.2e-6);
    let with_line = with(|p| {
        p.port_restriction_area_1 = 0.2e-6;
        p.port_line_volume_1 = 3e-6;
    });
    let settled = |model: &Actuator| {
        Simulation::at_equilibrium(model.clone(), 2.5, 0.054, 0.0, 1e-8)
            .unwrap()
            .outputs()
            .f_act
    };
    assert!((settled(&alone) - settled(&with_line)).abs() < 1e-6);
    let response = |model: &Actuator| {
        let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-8).unwrap();
        let start = sim.outputs().f_act;
        sim.set_command(2.5).unwrap();
        sim.step(0.01).unwrap();
        sim.outputs().f_act - start
    };
    assert!(
        response(&with_line) < 0.9 * response(&alone),
        "{} vs {}",
        response(&with_line),
        response(&alone)
    );
}

/// A stopper shaken 10 mm at 2.5 Hz about 54 mm under a 2.5 V command, sampled at `rate` Hz:
/// the outputs at each sample from a simulation stepped once per sample, the stopper moving
/// linearly between samples and its rate on to the next sample set before the outputs are
/// read (as the diagnosis replays a recording), with the times and positions.
fn shaken(model: &Actuator, rate: f64, samples: usize) -> (Vec<Outputs>, Vec<f64>, Vec<f64>) {
    let w = 2.0 * std::f64::consts::PI * 2.5;
    let h = 1.0 / rate;
    let time: Vec<f64> = (0..samples).map(|k| k as f64 * h).collect();
    let x: Vec<f64> = time.iter().map(|t| 0.054 + 0.01 * (w * t).sin()).collect();
    let mut sim = Simulation::at_equilibrium(model.clone(), 2.5, x[0], 0.0, 1e-6).unwrap();
    let mut out = vec![];
    for k in 0..samples {
        if k + 1 < samples {
            sim.set_stopper_rate((x[k + 1] - x[k]) / h).unwrap();
        }
        out.push(sim.outputs());
        if k + 1 < samples {
            sim.step(h).unwrap();
            sim.land_stopper_at(x[k + 1]);
        }
    }
    (out, time, x)
}

#[test]
fn the_extra_force_adds_each_library_term_to_the_measured_force_as_the_diagnosis_forms_it() {
    use crate::physics::extra_force;
    let (c_a, c_q, c_s, c_d) = (-0.1, -300.0, -2e-6, 3e-6);
    let on = with(|p| {
        p.extra_force_acceleration = c_a;
        p.extra_force_velocity_squared = c_q;
        p.extra_force_sign_pressure = c_s;
        p.extra_force_pressure_difference = c_d;
    });
    for rate in [1000.0, 250.0] {
        let (plain, time, x) = shaken(&thesis_model(), rate, (0.8 * rate) as usize);
        let (extra, _, _) = shaken(&on, rate, time.len());
        // The columns the diagnosis builds from the recorded positions alone.
        let acceleration = extra_force::stopper_accelerations(&time, &x);
        let velocity = extra_force::stopper_velocities(&time, &x);
        let p_r = on.params.p_r;
        let mut largest = 0.0f64;
        for k in 1..time.len() {
            let (a, b) = (&plain[k], &extra[k]);
            // The extra force changes no pressure: it acts on the piston held by the stopper.
            assert_eq!((a.p1, a.p2), (b.p1, b.p2));
            let v = velocity[k];
            let expected = c_a * acceleration[k]
                + c_q * v * v.abs()
                + c_s * (v / 1e-3).tanh() * (a.p1 + a.p2 - 2.0 * p_r)
                + c_d * (a.p1 - a.p2);
            assert!(
                (b.f_meas - a.f_meas - expected).abs() < 1e-9 * (1.0 + a.f_meas.abs()),
                "{rate} Hz, sample {k}: {} against {expected}",
                b.f_meas - a.f_meas
            );
            largest = largest.max(expected.abs());
        }
        assert!(largest > 0.5, "the terms are felt: {largest} N");
    }
}

#[test]
fn with_the_extra_force_off_the_outputs_are_the_thesis_models_bits_and_a_snapshot_carries_the_stoppers_motion() {
    // Every library coefficient zero but the sign's speed scale changed: the same bits.
    let filter_only = with(|p| p.extra_force_sign_velocity = 0.02);
    let (plain, _, _) = shaken(&thesis_model(), 1000.0, 300);
    let (other, _, _) = shaken(&filter_only, 1000.0, 300);
    for (a, b) in plain.iter().zip(&other) {
        assert_eq!(a.f_meas.to_bits(), b.f_meas.to_bits());
        assert_eq!(a.p1.to_bits(), b.p1.to_bits());
    }
    // With the mass on, a simulation restored from a snapshot mid-motion goes on as the
    // original does, to the bit.
    let mass = with(|p| p.extra_force_acceleration = -0.2);
    let w = 2.0 * std::f64::consts::PI * 2.5;
    let mut sim = Simulation::at_equilibrium(mass.clone(), 2.5, 0.054, 0.0, 1e-6).unwrap();
    let rate = |k: usize| 0.01 * w * (w * k as f64 * 1e-3).cos();
    for k in 0..100 {
        sim.set_stopper_rate(rate(k)).unwrap();
        sim.step(1e-3).unwrap();
    }
    let values = sim.snapshot().to_values();
    let mut copy = Simulation::restore(mass, &SimulationSnapshot::from_values(&values).unwrap()).unwrap();
    for k in 100..150 {
        for s in [&mut sim, &mut copy] {
            s.set_stopper_rate(rate(k)).unwrap();
            s.step(1e-3).unwrap();
        }
        assert_eq!(
            sim.outputs().f_meas.to_bits(),
            copy.outputs().f_meas.to_bits(),
            "step {k}"
        );
    }
}

/// Every output of a stepped run with the command moving, bit for bit.
fn output_bits(model: &Actuator) -> Vec<u64> {
    let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-6).unwrap();
    let mut bits = vec![];
    for k in 1..=200 {
        sim.set_command(1.0 + 3.0 * (k as f64 * 0.05).sin()).unwrap();
        sim.step(1e-3).unwrap();
        let y = sim.outputs();
        for v in [y.f_act, y.f_meas, y.p1, y.p2, y.p1_meas, y.p2_meas, y.current, y.x_jp] {
            bits.push(v.to_bits());
        }
    }
    bits
}

#[test]
fn a_static_curve_off_leaves_every_output_bit_identical_and_on_reads_through_its_knots() {
    use crate::physics::static_curve::StaticCurve;
    let thesis = thesis_model();
    // Knots written but not in use (knots = 0): the thesis's outputs, bit for bit.
    let written = with(|p| {
        for curve in [
            &mut p.command_curve,
            &mut p.force_sensor_curve,
            &mut p.p1_sensor_curve,
            &mut p.p2_sensor_curve,
        ] {
            *curve = StaticCurve::through(&[-1.0, 0.0, 1.0], &[0.0, 0.0, 5.0]);
            curve.knots = 0.0;
        }
    });
    assert_eq!(output_bits(&written), output_bits(&thesis));
    // A force sensor that saturates at 20 N, pressure transducers that clip at 4 bar.
    let saturating = with(|p| {
        p.force_sensor_curve = StaticCurve::through(&[0.0, 20.0, 30.0], &[0.0, 20.0, 20.0]);
        p.p1_sensor_curve = StaticCurve::through(&[1e5, 4e5, 5e5], &[1e5, 4e5, 4e5]);
    });
    for v in [1.0, 6.0] {
        let y = Simulation::at_equilibrium(saturating.clone(), v, 0.054, 0.0, 1e-6)
            .unwrap()
            .outputs();
        assert_eq!(y.f_meas, y.f_act.min(20.0), "at {v} V: F_act {}", y.f_act);
        assert!((y.p1_meas - y.p1.min(4e5)).abs() < 1e-6, "at {v} V: P1 {}", y.p1);
        assert_eq!(y.p2_meas, y.p2);
    }
    // A dead zone of ±0.5 V in the command: inside it the actuator sits where 0 V puts it.
    let dead = with(|p| p.command_curve = StaticCurve::through(&[-10.0, -0.5, 0.5, 10.0], &[-9.5, 0.0, 0.0, 9.5]));
    let at = |model: &Actuator, v: f64| {
        Simulation::at_equilibrium(model.clone(), v, 0.054, 0.0, 1e-6)
            .unwrap()
            .outputs()
            .f_act
    };
    assert_eq!(at(&dead, 0.4), at(&thesis, 0.0));
    assert!((at(&dead, 3.0) - at(&thesis, 2.5)).abs() < 1e-9);
}

/// The chambers of a held stopper under a held command, the current and the jet pipe at rest
/// from the start: only the pressures move, and by (2.20)–(2.21) every mass flow scales as
/// 1/√T and (2.29)'s R T ṁ as √T. A gas temperature T(t) so runs the constant-T trajectory on
/// the clock τ = ∫ √(T(s)/T) ds. A simulation with T_drift holds T at its mid-step value over
/// each step h, so after each step it must be where the thesis model is after steps of
/// h √(T(t + h/2)/T): an independent account of the drift, from the scaling alone.
#[test]
fn a_drifting_gas_temperature_runs_the_chambers_on_the_clock_of_the_square_root_of_the_temperature() {
    let (drift, t0, h, v, x_s) = (3.0, 10.0, 1e-3, 2.5, 0.054);
    let thesis = thesis_model();
    let drifting = with(|p| p.t_drift = drift);
    let started = |model: &Actuator, time: f64| {
        // The pressures half-way between P_r and P_s, far from their balance.
        let state = equilibrium_of_electromechanics(model, v);
        Simulation::from_state(model.clone(), state, v, x_s, time, 1e-10)
    };
    let t_gas = thesis.params.temperature;
    let mut warm = started(&drifting, t0);
    let mut scaled = started(&thesis, 0.0);
    let mut plain = started(&thesis, 0.0);
    let (mut worst, mut apart) = (0.0_f64, 0.0_f64);
    for k in 0..150 {
        let mid = t0 + (k as f64 + 0.5) * h;
        warm.step(h).unwrap();
        scaled.step(h * ((t_gas + drift * mid) / t_gas).sqrt()).unwrap();
        plain.step(h).unwrap();
        for i in [index::P1, index::P2] {
            worst = worst.max((warm.state[i] - scaled.state[i]).abs());
            apart = apart.max((warm.state[i] - plain.state[i]).abs());
        }
    }
    println!("warm against the rescaled thesis run: {worst} Pa; against the plain one: {apart} Pa");
    // 30 K warmer by t0: the chambers run 5 % faster than the thesis's, by kPa in the transient.
    assert!(apart > 1e3, "the drift moved the pressures by {apart} Pa at most");
    assert!(worst < 0.01, "{worst} Pa from the rescaled clock");
    assert_eq!(warm.model.params, drifting.params);
    assert_eq!(warm.model.flow, drifting.flow);
}

#[test]
fn a_step_that_would_take_the_drifting_gas_temperature_below_zero_kelvin_is_refused_by_name() {
    // T = 293.15 K − 10 K/s · t: 3.15 K at t = 29 s, −1.85 K at the next step's middle.
    let model = with(|p| p.t_drift = -10.0);
    let mut sim = Simulation::at_equilibrium(model, 2.5, 0.054, 29.0, 1e-6).unwrap();
    match sim.step(1.0) {
        Err(StepFailure::InvalidRequest(e)) => {
            assert!(
                e.contains("T_drift = -10 K/s") && e.contains("must be in (0, 1000] K"),
                "{e}"
            )
        }
        other => panic!("a gas temperature of -1.85 K was not refused: {other:?}"),
    }
}

/// Commands stepped every 20 ms with the stopper shaken, the force at each millisecond.
fn forces_under_steps_and_a_shaken_stopper(model: &Actuator) -> Vec<f64> {
    let w = 2.0 * std::f64::consts::PI * 2.5;
    let mut sim = Simulation::at_equilibrium(model.clone(), 2.0, 0.054, 0.0, 1e-8).unwrap();
    let mut forces = vec![];
    for k in 0..300 {
        let t = k as f64 * 1e-3;
        if k % 20 == 0 {
            sim.set_command(if (k / 20) % 2 == 0 { 5.0 } else { -1.0 }).unwrap();
        }
        sim.set_stopper_rate(0.01 * w * (w * t).cos()).unwrap();
        sim.step(1e-3).unwrap();
        forces.push(sim.outputs().f_act);
    }
    forces
}

#[test]
fn a_stopper_mount_with_a_vanishing_lag_is_the_quasi_static_compliance() {
    let rigid = forces_under_steps_and_a_shaken_stopper(&thesis_model());
    let compliant = forces_under_steps_and_a_shaken_stopper(&with(|p| p.stopper_compliance = 5e-5));
    let lagging = forces_under_steps_and_a_shaken_stopper(&with(|p| {
        p.stopper_compliance = 5e-5;
        p.stopper_mount_lag = 1e-6;
    }));
    let slow = forces_under_steps_and_a_shaken_stopper(&with(|p| {
        p.stopper_compliance = 5e-5;
        p.stopper_mount_lag = 3e-3;
    }));
    let effect = worst_difference(&compliant, &rigid);
    assert!(effect > 1.0, "the compliance moves the force by {effect} N only");
    // A microsecond's lag against the pressures' milliseconds: the quasi-static law (its own
    // closed form) to a thousandth of the compliance's effect.
    let near = worst_difference(&lagging, &compliant);
    assert!(near < 1e-3 * effect, "{near} N against the compliance's {effect} N");
    let lagged = worst_difference(&slow, &compliant);
    assert!(lagged > 0.05 * effect, "a 3 ms lag moves the force by {lagged} N only");
}

#[test]
fn a_lagging_mounts_state_follows_the_pressure_difference_through_its_lag_and_rests_on_it() {
    let tau = 2e-3;
    let model = with(|p| {
        p.stopper_compliance = 5e-5;
        p.stopper_mount_lag = tau;
    });
    let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-9).unwrap();
    let difference = |sim: &Simulation| model.mount_load(sim.state[index::P1], sim.state[index::P2], 0.054);
    let rested = sim.stopper_mount_state().unwrap();
    assert!(
        (rested - difference(&sim)).abs() < 1e-6 * difference(&sim).abs(),
        "{rested}"
    );
    sim.step(0.2).unwrap();
    assert!((sim.stopper_mount_state().unwrap() - rested).abs() < 1.0);
    // After a command step, q̇ = (F/A_p − q)/τ integrated exactly for F/A_p linear between
    // samples every 10 µs: an oracle apart from the integrator's.
    sim.set_command(4.0).unwrap();
    let h = 1e-5;
    let mut q = sim.stopper_mount_state().unwrap();
    let mut before = difference(&sim);
    let decay = (-h / tau).exp();
    let mut worst: f64 = 0.0;
    for _ in 0..2000 {
        sim.step(h).unwrap();
        let now = difference(&sim);
        q = decay * q + (1.0 - decay) * before + (1.0 - tau * (1.0 - decay) / h) * (now - before);
        before = now;
        worst = worst.max((sim.stopper_mount_state().unwrap() - q).abs());
    }
    let swing = (difference(&sim) - rested).abs();
    assert!(swing > 1e4, "the step moves ΔP by {swing} Pa only");
    assert!(worst < 1e-4 * swing, "{worst} Pa off, against a swing of {swing} Pa");
    assert!(Simulation::at_equilibrium(thesis_model(), 1.0, 0.054, 0.0, 1e-6)
        .unwrap()
        .stopper_mount_state()
        .is_none());
}

#[test]
fn the_extra_force_products_add_their_formula_to_the_measured_force_and_bad_codes_are_refused() {
    use crate::physics::extra_force::{self, ProductSlot};
    // Slot 1: 0.7 N × (x_s − 54 mm)/10 mm × a/(1 m/s²); slot 3: −0.3 N × (P2 − P_r)/1 bar ×
    // tanh(v / 1 mm/s); slot 2 off.
    let slots = [
        ProductSlot {
            first: 1.0,
            second: 4.0,
            origin: 0.054,
            coefficient: 0.7,
        },
        ProductSlot::default(),
        ProductSlot {
            first: 7.0,
            second: 3.0,
            origin: 0.0,
            coefficient: -0.3,
        },
    ];
    let on = with(|p| p.extra_force_products = slots);
    assert!(on.reads_stopper_motion);
    for rate in [1000.0, 250.0] {
        let (plain, time, x) = shaken(&thesis_model(), rate, (0.8 * rate) as usize);
        let (extra, _, _) = shaken(&on, rate, time.len());
        let acceleration = extra_force::stopper_accelerations(&time, &x);
        let velocity = extra_force::stopper_velocities(&time, &x);
        let p_r = on.params.p_r;
        let mut largest = 0.0f64;
        for k in 1..time.len() {
            let (a, b) = (&plain[k], &extra[k]);
            assert_eq!((a.p1, a.p2), (b.p1, b.p2));
            let expected =
                0.7 * (x[k] - 0.054) / 0.01 * acceleration[k] - 0.3 * (a.p2 - p_r) / 1e5 * (velocity[k] / 1e-3).tanh();
            assert!(
                (b.f_meas - a.f_meas - expected).abs() < 1e-9 * (1.0 + a.f_meas.abs()),
                "{rate} Hz, sample {k}: {} against {expected}",
                b.f_meas - a.f_meas
            );
            largest = largest.max(expected.abs());
        }
        assert!(largest > 0.5, "the products are felt: {largest} N");
    }
    // A code that is no signal is refused when the model is built, naming the variable, the
    // value and the limit; beyond the row's limits the setter refuses it.
    let mut p = Parameters::default();
    p.set(crate::variables::vr::EXTRA_FORCE_PRODUCT_2_FIRST + 1, 2.5)
        .unwrap();
    let e = Actuator::new(p.clone()).unwrap_err();
    assert!(
        e.starts_with("extra_force_product_2_second = 2.5 is invalid: must be a whole number from 0 to 7"),
        "{e}"
    );
    let e = p
        .set(crate::variables::vr::EXTRA_FORCE_PRODUCT_3_FIRST, 8.0)
        .unwrap_err();
    assert!(
        e.contains("extra_force_product_3_first") && e.contains('8') && e.contains('7'),
        "{e}"
    );
}

#[test]
fn a_transducer_faster_than_the_communication_step_reads_the_same_at_coarse_and_fine_steps() {
    // A 1 ms force-sensor lag stepped at 8 ms and at 0.1 ms after a command step: at the
    // coarse points the readings agree with the fine run's, where a memory recorded only at
    // the 8 ms points would read the force's rise as a chord between them.
    let model = with(|p| p.force_sensor_lag = 1e-3);
    let run = |step: f64, points: usize| -> Vec<f64> {
        let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-8).unwrap();
        sim.set_command(6.0).unwrap();
        let mut out = vec![];
        for k in 1..=points {
            sim.step(step).unwrap();
            if k % ((8e-3 / step).round() as usize) == 0 {
                out.push(sim.outputs().f_meas);
            }
        }
        out
    };
    let coarse = run(8e-3, 10);
    let fine = run(1e-4, 800);
    let rise = fine.last().unwrap() - fine[0];
    assert!(rise > 5.0, "the force rose by {rise} N");
    for (k, (c, f)) in coarse.iter().zip(&fine).enumerate() {
        assert!(
            (c - f).abs() < 2e-3 * rise,
            "at {} ms: {c} N against {f} N",
            8 * (k + 1)
        );
    }
}

#[test]
fn a_transducer_slower_than_the_communication_step_reads_the_force_within_it_not_its_chord() {
    // A 10 ms force-sensor lag under a command that switches every 4 ms (a PRBS at 250 Hz):
    // stepped at 4 ms, its readings agree with those of a run stepped at 0.1 ms with the
    // same held commands, where one chord of the force over each 4 ms step reached the lag
    // early.
    let model = with(|p| p.force_sensor_lag = 10e-3);
    let commands = [6.0, -2.0, 4.0, 4.0, -5.0, 1.0, 7.0, -3.0, -3.0, 2.0, 5.0, -6.0];
    let run = |step: f64| -> Vec<f64> {
        let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-8).unwrap();
        let per_sample = (4e-3 / step).round() as usize;
        let mut out = vec![];
        for &v in &commands {
            sim.set_command(v).unwrap();
            for _ in 0..per_sample {
                sim.step(step).unwrap();
            }
            out.push(sim.outputs().f_meas);
        }
        out
    };
    let (coarse, fine) = (run(4e-3), run(1e-4));
    let span = fine.iter().cloned().fold(f64::MIN, f64::max) - fine.iter().cloned().fold(f64::MAX, f64::min);
    assert!(span > 3.0, "the reading moved over {span} N");
    for (k, (c, f)) in coarse.iter().zip(&fine).enumerate() {
        assert!(
            (c - f).abs() < 2e-3 * span,
            "at {} ms: {c} N against {f} N",
            4 * (k + 1)
        );
    }
}

#[test]
fn a_stopper_acceleration_given_as_an_input_is_what_the_mass_force_reads_at_once_and_along_its_rate() {
    // A moving mass of 0.2 kg (extra_force_acceleration = -0.2) with the acceleration taken
    // whole from the input: the force departs from the plain model's by -0.2 a_s, a_s as set
    // (read at once, before any step) and as its rate carried it over a step; the pressures
    // do not change. With the share at 0 the input is not read.
    let on = with(|p| {
        p.extra_force_acceleration = -0.2;
        p.stopper_acceleration_input_share = 1.0;
    });
    let mut plain = Simulation::at_equilibrium(thesis_model(), 2.0, 0.054, 0.0, 1e-8).unwrap();
    let mut sim = Simulation::at_equilibrium(on, 2.0, 0.054, 0.0, 1e-8).unwrap();
    sim.set_stopper_acceleration(3.0).unwrap();
    let departure = sim.outputs().f_meas - plain.outputs().f_meas;
    assert!((departure + 0.6).abs() < 1e-9, "{departure} N against -0.6 N");
    sim.set_stopper_acceleration_rate(-500.0).unwrap();
    for s in [&mut plain, &mut sim] {
        s.set_command(4.0).unwrap();
        s.step(2e-3).unwrap();
    }
    assert!((sim.stopper_acceleration_input() - 2.0).abs() < 1e-12);
    let (a, b) = (plain.outputs(), sim.outputs());
    assert_eq!((a.p1, a.p2), (b.p1, b.p2));
    assert!(
        (b.f_meas - a.f_meas + 0.4).abs() < 1e-9,
        "{} N against -0.4 N",
        b.f_meas - a.f_meas
    );
    // The rate lasted one step.
    for s in [&mut plain, &mut sim] {
        s.step(2e-3).unwrap();
    }
    assert!((sim.stopper_acceleration_input() - 2.0).abs() < 1e-12);
    let off = with(|p| p.extra_force_acceleration = -0.2);
    let mut unread = Simulation::at_equilibrium(off, 2.0, 0.054, 0.0, 1e-8).unwrap();
    let before = unread.outputs().f_meas;
    unread.set_stopper_acceleration(3.0).unwrap();
    assert_eq!(unread.outputs().f_meas, before);
    let e = sim.set_stopper_acceleration(2e4).unwrap_err();
    assert!(e.starts_with("a_s = 20000 m/s2 is invalid"), "{e}");
}

#[test]
fn a_friction_reads_the_velocity_the_positions_make_not_a_smoothed_acceleration_input() {
    // A stopper at rest with an acceleration input of 50 m/s², as an acceleration smoothed
    // over a few samples shows just before a ramp starts: carried half a 2 ms step, it would
    // make 50 mm/s of velocity and switch a 2 N friction fully on while nothing moves.
    let friction = |share: f64| {
        with(|p| {
            p.friction_coulomb = 2.0;
            p.friction_velocity = 2e-4;
            p.stopper_acceleration_input_share = share;
        })
    };
    let mut unread = Simulation::at_equilibrium(friction(0.0), 2.0, 0.054, 0.0, 1e-8).unwrap();
    let mut read = Simulation::at_equilibrium(friction(1.0), 2.0, 0.054, 0.0, 1e-8).unwrap();
    for s in [&mut unread, &mut read] {
        s.set_command(4.0).unwrap();
        s.step(2e-3).unwrap();
    }
    read.set_stopper_acceleration(50.0).unwrap();
    let (a, b) = (unread.outputs(), read.outputs());
    assert_eq!((a.p1, a.p2), (b.p1, b.p2));
    assert!(
        (b.f_meas - a.f_meas).abs() < 1e-9,
        "{} N against {} N",
        b.f_meas,
        a.f_meas
    );
}
