//! The modulation slots: their parameters and refusals, and simulations with them against
//! the model with the constant set by hand, against the time-varying constants, and against a
//! current driver stepped here by hand.

use super::*;
use crate::physics::actuator::index;
use crate::simulation::{equilibrium_at, FixedStep, Simulation};

fn with_slot(slot: Slot) -> Parameters {
    Parameters {
        modulation: [slot, Slot::default()],
        ..Parameters::default()
    }
}

/// The command of the runs below: steps and a ramp over 0.3 s, a sample each millisecond.
fn command(k: usize) -> f64 {
    match k {
        0..=49 => 1.0,
        50..=149 => 4.0,
        150..=249 => -2.0 + 0.05 * (k - 150) as f64,
        _ => 0.5,
    }
}

/// (time, F_meas, P1, P2, i) at each sample of a 0.3 s run at 1 kHz of the error-controlled
/// simulation, the stopper moving sinusoidally by ±5 mm.
fn run(p: &Parameters) -> Vec<[f64; 5]> {
    let model = Actuator::new(p.clone()).unwrap();
    let mut sim = Simulation::at_equilibrium(model, command(0), 0.054, 0.0, 1e-8).unwrap();
    let mut out = Vec::new();
    for k in 0..300 {
        sim.set_command(command(k)).unwrap();
        let t_next = (k + 1) as f64 * 1e-3;
        let x_next = 0.054 + 0.005 * (2.0 * std::f64::consts::PI * 5.0 * t_next).sin();
        sim.set_stopper_rate((x_next - sim.x_s()) / 1e-3).unwrap();
        sim.step(1e-3).unwrap();
        sim.land_stopper_at(x_next);
        let y = sim.outputs();
        out.push([sim.time(), y.f_meas, y.p1, y.p2, y.current]);
    }
    out
}

/// The same samples through the fixed-step replay.
fn replay(p: &Parameters) -> Vec<[f64; 5]> {
    let model = Actuator::new(p.clone()).unwrap();
    let mut fixed = FixedStep::at_equilibrium(model, command(0), 0.054, 0.0)
        .unwrap()
        .unwrap();
    let mut out = Vec::new();
    for k in 0..300 {
        fixed.set_command(command(k)).unwrap();
        let t_next = (k + 1) as f64 * 1e-3;
        let x_next = 0.054 + 0.005 * (2.0 * std::f64::consts::PI * 5.0 * t_next).sin();
        fixed.step_to(t_next, x_next).unwrap();
        let y = fixed.outputs();
        out.push([t_next, y.f_meas, y.p1, y.p2, y.current]);
    }
    out
}

/// The largest difference of each column, relative to the column's largest magnitude.
fn relative_gap(a: &[[f64; 5]], b: &[[f64; 5]]) -> f64 {
    let mut worst = 0.0_f64;
    for c in 1..5 {
        let scale = a.iter().fold(0.0_f64, |m, r| m.max(r[c].abs())).max(1e-12);
        for (ra, rb) in a.iter().zip(b) {
            worst = worst.max((ra[c] - rb[c]).abs() / scale);
        }
    }
    worst
}

#[test]
fn the_signal_codes_run_from_0_to_13_in_the_order_of_the_interface_with_si_units() {
    let expected = [
        ("none", "1"),
        ("t", "s"),
        ("v_DA", "V"),
        ("i", "A"),
        ("x_jp", "m"),
        ("x_s", "m"),
        ("stopper velocity", "m/s"),
        ("sign of the stopper velocity", "1"),
        ("F_act", "N"),
        ("P1", "Pa"),
        ("P2", "Pa"),
        ("P1 - P2", "Pa"),
        ("sin(2 pi f t)", "1"),
        ("cos(2 pi f t)", "1"),
    ];
    for (code, (signal, (name, unit))) in ModulationSignal::ALL.iter().zip(expected).enumerate() {
        assert_eq!(signal.code(), code as u32);
        assert_eq!((signal.name(), signal.unit()), (name, unit));
        assert_eq!(ModulationSignal::from_code(code as f64), Some(*signal));
    }
    assert_eq!(ModulationSignal::from_code(14.0), None);
    assert_eq!(ModulationSignal::from_code(2.5), None);
    let s = Signals {
        time: 0.125,
        p1: 4e5,
        p2: 1.5e5,
        stopper_velocity: -1e-3,
        ..Signals::default()
    };
    assert_eq!(ModulationSignal::PressureDifference.value(&s, 0.0), 2.5e5);
    assert!((ModulationSignal::StopperVelocitySign.value(&s, 0.0) - (-1.0_f64).tanh()).abs() < 1e-15);
    // 2 Hz at 0.125 s: a quarter turn.
    assert!((ModulationSignal::Sine.value(&s, 2.0) - 1.0).abs() < 1e-15);
    assert!(ModulationSignal::Cosine.value(&s, 2.0).abs() < 1e-15);
}

#[test]
fn the_increment_is_linear_between_knots_and_held_beyond_the_first_and_last() {
    let slot = Slot::through(vr::P_S, ModulationSignal::P1, &[1e5, 2e5, 4e5], &[10.0, 30.0, -10.0]);
    assert_eq!(slot.increment(0.0), 10.0);
    assert_eq!(slot.increment(1e5), 10.0);
    assert_eq!(slot.increment(1.5e5), 20.0);
    assert_eq!(slot.increment(3e5), 10.0);
    assert_eq!(slot.increment(4e5), -10.0);
    assert_eq!(slot.increment(9e5), -10.0);
    let one = Slot::through(vr::P_S, ModulationSignal::Time, &[7.0], &[-500.0]);
    for s in [-1e6, 0.0, 7.0, 1e6] {
        assert_eq!(one.increment(s), -500.0, "one knot is a constant increment");
    }
    assert!(!Slot::default().is_on());
    assert!(!Slot { knots: 0.0, ..one }.is_on(), "no knot in use: off");
}

#[test]
fn the_slots_description_names_every_modulatable_constant_with_its_value_reference() {
    let row = crate::variables::VARIABLES
        .iter()
        .find(|v| v.name == "modulation_1_parameter")
        .unwrap();
    for &constant in MODULATABLE {
        let name = crate::variables::VARIABLES
            .iter()
            .find(|v| v.value_reference == constant)
            .unwrap()
            .name;
        let listed = if name.contains("area_scale") {
            row.description.contains("supply/return area scales 400-403")
        } else {
            row.description.contains(&format!("{name} {constant}"))
        };
        assert!(listed, "{name} ({constant}) is not in: {}", row.description);
    }
}

#[test]
fn every_variable_of_both_slots_is_a_parameter_of_the_table_that_sets_its_own_field() {
    let names: Vec<&str> = value_references().map(variable_name).collect();
    assert_eq!(names.len(), 56);
    assert_eq!(names[0], "modulation_1_parameter");
    assert_eq!(names[15], "modulation_1_x_12");
    assert_eq!(names[27], "modulation_1_y_12");
    assert_eq!(names[28], "modulation_2_parameter");
    assert_eq!(names[29], "modulation_2_signal");
    assert_eq!(names[30], "modulation_2_frequency");
    assert_eq!(names[31], "modulation_2_knots");
    assert_eq!(names[32], "modulation_2_x_1");
    assert_eq!(names[44], "modulation_2_y_1");
    for (j, r) in value_references().enumerate() {
        assert!(Parameters::VALUE_REFERENCES.contains(&r), "{}", names[j]);
        let mut p = Parameters::default();
        // A value every field accepts, told apart from every other field's.
        let value = if j % 28 == 0 {
            vr::K_CD as f64
        } else {
            (j % 28).min(12) as f64
        };
        p.set(r, value).unwrap_or_else(|e| panic!("{}: {e}", names[j]));
        assert_eq!(p.get(r), Some(value));
        let changed: Vec<u32> = value_references()
            .filter(|&other| p.get(other) != Parameters::default().get(other))
            .collect();
        assert_eq!(changed, vec![r], "{} sets only itself", names[j]);
    }
}

#[test]
fn a_constant_that_is_not_modulatable_is_refused_naming_the_slot_the_value_and_what_is_allowed() {
    let refused = |value_reference: u32, value: f64| {
        let mut p = Parameters::default();
        // Taken within the row's limits; refused when the model is built.
        p.set(value_reference, value).unwrap();
        let e = p.validate().unwrap_err();
        assert_eq!(check_setting(value_reference, value).unwrap_err(), e);
        assert!(Actuator::new(p).is_err());
        e
    };
    let e = refused(vr::MODULATION_2_PARAMETER, vr::GAMMA as f64);
    assert!(
        e.starts_with(
            "modulation_2_parameter = 103 is invalid: must be 0 (off) or the value reference of a modulatable constant"
        ),
        "{e}"
    );
    assert!(e.contains("k_cd (110)") && e.contains("p2_sensor_gain (511)"), "{e}");
    let e = refused(vr::MODULATION_1_PARAMETER, vr::K_CD as f64 + 0.5);
    assert!(e.starts_with("modulation_1_parameter = 110.5 is invalid"), "{e}");
    let e = refused(vr::MODULATION_1_SIGNAL, 2.5);
    assert!(
        e.starts_with("modulation_1_signal = 2.5 is invalid") && e.contains("8 F_act (N)"),
        "{e}"
    );
    let e = refused(vr::MODULATION_2_KNOTS, 1.5);
    assert!(e.starts_with("modulation_2_knots = 1.5 is invalid"), "{e}");
    let mut p = Parameters::default();
    assert!(p.set(vr::MODULATION_1_SIGNAL, 14.0).is_err(), "beyond the row's limits");
    assert!(p.set(vr::MODULATION_1_KNOTS, 13.0).is_err());
    assert!(p.set(vr::MODULATION_1_PARAMETER, 1001.0).is_err());
    assert_eq!(p, Parameters::default(), "a refused setting changes nothing");
    for &constant in MODULATABLE {
        assert!(check_setting(vr::MODULATION_1_PARAMETER, constant as f64).is_ok());
    }
}

#[test]
fn knots_that_do_not_increase_are_refused_naming_the_slot_the_knot_and_the_values() {
    let p = with_slot(Slot::through(
        vr::K_CD,
        ModulationSignal::P1,
        &[1e5, 3e5, 3e5],
        &[0.0, 0.0, 0.0],
    ));
    let e = p.validate().unwrap_err();
    assert!(
        e.starts_with("modulation_1_x_3 = 300000 Pa is invalid: must exceed modulation_1_x_2 = 300000 Pa"),
        "{e}"
    );
    assert!(Actuator::new(p).is_err());
}

#[test]
fn a_knot_that_takes_the_constant_outside_its_limits_is_refused_naming_the_knot_the_value_and_the_limit() {
    let nominal = Parameters::default().c_d;
    let p = with_slot(Slot::through(
        vr::C_D,
        ModulationSignal::Command,
        &[-5.0, 0.0, 5.0],
        &[0.0, 0.1, 1.0],
    ));
    let e = p.validate().unwrap_err();
    assert!(e.starts_with("modulation_1_y_3 = 1 takes C_d from "), "{e}");
    assert!(e.contains(&format!("to {}", number(nominal + 1.0))), "{e}");
    assert!(
        e.contains("at knot 3 (v_DA = 5 V)") && e.contains("must be in (0, 1]"),
        "{e}"
    );
    // A constraint between constants: the supply below the return pressure at a knot.
    let q = with_slot(Slot::through(vr::P_R, ModulationSignal::Time, &[0.0, 1.0], &[0.0, 6e5]));
    let e = q.validate().unwrap_err();
    assert!(
        e.starts_with("modulation_1_y_2 = 600000 takes P_r") && e.contains("must be >= P_r"),
        "{e}"
    );
    // zeta_2 at 1 or above leaves the jet pipe no modal form.
    let z = with_slot(Slot::through(vr::ZETA_2, ModulationSignal::Time, &[0.0], &[2.0]));
    assert!(z.validate().unwrap_err().contains("zeta_2 must stay below 1"));
}

#[test]
fn a_slot_whose_increments_are_zero_changes_no_bit_of_the_outputs() {
    let thesis = run(&Parameters::default());
    for constant in [vr::P_S, vr::K_CD, vr::C_D, vr::FORCE_SENSOR_GAIN] {
        let p = with_slot(Slot::through(constant, ModulationSignal::P1, &[2e5, 4e5], &[0.0, 0.0]));
        let modulated = run(&p);
        for (a, b) in thesis.iter().zip(&modulated) {
            assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits), "{}", variable_name(constant));
        }
    }
}

#[test]
fn a_slot_with_one_knot_equals_the_model_with_the_constant_set_to_its_value_plus_the_increment() {
    let cases: [(u32, f64); 11] = [
        (vr::K_CD, 0.004),
        (vr::OMEGA_2, -150.0),
        (vr::P_S, -4e4),
        (vr::T_GAS, 25.0),
        (vr::RETURN_AREA_SCALE_2, 0.2),
        (vr::FORCE_SENSOR_GAIN, 0.05),
        (vr::FRICTION_COULOMB, 1.5),
        (vr::K_SPRING, 300.0),
        // Half chamber 1's volume at mid-stroke, and chamber 2's.
        (vr::DEAD_VOLUME_1, 2e-6),
        (vr::DEAD_VOLUME_2, 2e-6),
        // A bore 2 % wider: the piston's area 4 % larger, in the force and both volumes.
        (vr::D_CYL, 3.175e-4),
    ];
    for (constant, delta) in cases {
        let slotted = with_slot(Slot::through(
            constant,
            ModulationSignal::StopperPosition,
            &[0.05],
            &[delta],
        ));
        let mut by_hand = Parameters::default();
        by_hand.set(constant, by_hand.get(constant).unwrap() + delta).unwrap();
        let name = variable_name(constant);
        let (a, b) = (run(&slotted), run(&by_hand));
        assert!(relative_gap(&a, &b) < 1e-9, "{name}: {}", relative_gap(&a, &b));
        let (c, d) = (replay(&slotted), replay(&by_hand));
        assert!(
            relative_gap(&c, &d) < 1e-12,
            "{name} replayed: {}",
            relative_gap(&c, &d)
        );
        // And the slot does change the run (the comparison could fail).
        assert!(
            relative_gap(&a, &run(&Parameters::default())) > 1e-6,
            "{name} changed nothing"
        );
    }
}

#[test]
fn a_slot_on_the_supply_pressure_linear_in_time_equals_the_supply_drift() {
    let drift = -2e5; // Pa/s: 60 kPa over the run
    let slotted = with_slot(Slot::through(
        vr::P_S,
        ModulationSignal::Time,
        &[0.0, 1.0],
        &[0.0, drift],
    ));
    let drifting = Parameters {
        supply_drift: drift,
        ..Parameters::default()
    };
    let (a, b) = (run(&slotted), run(&drifting));
    assert!(relative_gap(&a, &b) < 1e-9, "{}", relative_gap(&a, &b));
    let (c, d) = (replay(&slotted), replay(&drifting));
    assert!(relative_gap(&c, &d) < 1e-12, "{}", relative_gap(&c, &d));
    assert!(relative_gap(&a, &run(&Parameters::default())) > 1e-4);
}

#[test]
fn a_slot_on_k_cd_by_p1_steps_the_current_as_a_driver_stepped_by_hand_with_k_cd_at_the_step_start() {
    let slot = Slot::through(
        vr::K_CD,
        ModulationSignal::P1,
        &[5.2e5, 5.6e5, 6e5],
        &[-0.004, 0.002, 0.006],
    );
    let p = with_slot(slot);
    let model = Actuator::new(p.clone()).unwrap();
    let mut sim = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-8).unwrap();
    let mut fixed = FixedStep::at_equilibrium(model, 1.0, 0.054, 0.0).unwrap().unwrap();
    let h = 1e-3;
    let mut worst = 0.0_f64;
    let mut spread = (f64::INFINITY, f64::NEG_INFINITY);
    // The closed form of di/dt = ω_cd (k_cd v + i_offset − i) over a held command, k_cd read
    // off the knots by hand at the P1 of the step's start.
    let by_hand = |state: &crate::physics::actuator::State, v: f64| {
        let (i0, p1) = (state[index::CURRENT], state[index::P1]);
        let k_cd = p.k_cd
            + if p1 <= 5.2e5 {
                -0.004
            } else if p1 <= 5.6e5 {
                -0.004 + (p1 - 5.2e5) / 4e4 * 0.006
            } else if p1 <= 6e5 {
                0.002 + (p1 - 5.6e5) / 4e4 * 0.004
            } else {
                0.006
            };
        let target = k_cd * v + p.i_offset;
        (target + (i0 - target) * (-p.omega_cd * h).exp(), p1)
    };
    for k in 0..300 {
        let v = command(k);
        let (expected, p1) = by_hand(sim.state(), v);
        let (expected_fixed, _) = by_hand(fixed.simulation().state(), v);
        sim.set_command(v).unwrap();
        sim.step(h).unwrap();
        fixed.set_command(v).unwrap();
        fixed.step_to((k + 1) as f64 * h, 0.054).unwrap();
        worst = worst.max((sim.outputs().current - expected).abs());
        worst = worst.max((fixed.outputs().current - expected_fixed).abs());
        spread = (spread.0.min(p1), spread.1.max(p1));
    }
    assert!(worst < 1e-12, "{worst} A");
    assert!(spread.0 < 5.2e5 && spread.1 > 6e5, "P1 crossed every knot: {spread:?}");
}

#[test]
fn the_equilibrium_with_i_offset_modulated_by_the_jet_position_is_its_own_signals_fixed_point() {
    let slot = Slot::through(
        vr::I_OFFSET,
        ModulationSignal::JetPosition,
        &[-1e-4, 1e-4],
        &[-0.01, 0.01],
    );
    let p = with_slot(slot);
    let model = Actuator::new(p.clone()).unwrap();
    let v = 2.0;
    let state = equilibrium_at(&model, v, 0.054, 0.0).unwrap();
    let (current, x_jp) = (state[index::CURRENT], state[index::JET_POSITION]);
    let increment = slot.increment(x_jp);
    assert!(
        increment.abs() > 1e-3,
        "the slot acts here: {increment} A at x_jp = {x_jp} m"
    );
    // The equilibrium's own signals give the increment used: the static current of (2.3)
    // with i_offset plus that increment, and the jet pipe where f3 puts it.
    assert!(
        (current - (p.k_cd * v + p.i_offset + increment)).abs() < 1e-12,
        "{current}"
    );
    let at = Actuator::new(Parameters {
        i_offset: p.i_offset + increment,
        ..Parameters::default()
    })
    .unwrap();
    assert!((x_jp - at.static_jet_position(current)).abs() < 1e-15, "{x_jp}");
    // It differs from the nominal equilibrium, and a simulation started there stays put.
    let nominal = equilibrium_at(&Actuator::new(Parameters::default()).unwrap(), v, 0.054, 0.0).unwrap();
    assert!((nominal[index::CURRENT] - current).abs() > 1e-3);
    let mut sim = Simulation::at_equilibrium(model, v, 0.054, 0.0, 1e-8).unwrap();
    let start = sim.outputs();
    for _ in 0..50 {
        sim.step(1e-3).unwrap();
    }
    let end = sim.outputs();
    assert!(
        (end.current - start.current).abs() < 1e-12,
        "{} A",
        end.current - start.current
    );
    assert!((end.p1 - start.p1).abs() < 1.0, "{} Pa", end.p1 - start.p1);
}

#[test]
fn a_slot_on_friction_switches_the_friction_on_and_acts_where_its_knots_say() {
    // Coulomb friction of 3 N between 52 and 56 mm of stopper position, none elsewhere.
    let slot = Slot::through(
        vr::FRICTION_COULOMB,
        ModulationSignal::StopperPosition,
        &[0.0515, 0.052, 0.056, 0.0565],
        &[0.0, 3.0, 3.0, 0.0],
    );
    let p = Parameters {
        friction_velocity: 1e-3,
        ..with_slot(slot)
    };
    let model = Actuator::new(p.clone()).unwrap();
    assert!(
        model.reads_stopper_motion,
        "friction by a slot forms the stopper's motion"
    );
    assert!(!Actuator::new(Parameters::default()).unwrap().reads_stopper_motion);
    let plain = run(&Parameters {
        friction_velocity: 1e-3,
        ..Parameters::default()
    });
    let modulated = run(&p);
    let x = |t: f64| 0.054 + 0.005 * (2.0 * std::f64::consts::PI * 5.0 * t).sin();
    let (mut inside, mut outside) = (0.0_f64, 0.0_f64);
    for (a, b) in plain.iter().zip(&modulated) {
        let gap = (a[1] - b[1]).abs();
        if (0.0525..0.0555).contains(&x(a[0])) {
            inside = inside.max(gap);
        } else if !(0.0510..0.0570).contains(&x(a[0])) {
            outside = outside.max(gap);
        }
    }
    assert!(inside > 2.0, "the friction acts inside: {inside} N");
    assert_eq!(outside, 0.0, "and nowhere beyond its knots");
}

#[test]
fn a_transducer_gain_modulated_by_the_pressure_reads_with_the_gain_at_the_sample() {
    let slot = Slot::through(vr::P1_SENSOR_GAIN, ModulationSignal::P1, &[1e5, 6e5], &[0.0, 0.05]);
    let model = Actuator::new(with_slot(slot)).unwrap();
    let mut sim = Simulation::at_equilibrium(model, 1.0, 0.054, 0.0, 1e-8).unwrap();
    let mut checked = 0;
    for k in 0..200 {
        sim.set_command(command(k)).unwrap();
        sim.step(1e-3).unwrap();
        let y = sim.outputs();
        let gain = 1.0 + 0.05 * ((y.p1 - 1e5) / 5e5).clamp(0.0, 1.0);
        assert!(
            (y.p1_meas - gain * y.p1).abs() < 1e-6,
            "{} vs {}",
            y.p1_meas,
            gain * y.p1
        );
        checked += usize::from(gain > 1.01);
    }
    assert!(checked > 10, "the gain moved from 1 at {checked} samples");
}

#[test]
fn model_exchange_and_the_linearisation_are_told_which_slot_they_refuse() {
    assert!(refuse_in_model_exchange(&Parameters::default()).is_ok());
    let mut p = Parameters::default();
    p.modulation[1] = Slot::through(vr::P_S, ModulationSignal::Time, &[0.0], &[1.0]);
    let e = refuse_in_model_exchange(&p).unwrap_err();
    assert!(
        e.starts_with("modulation_2_parameter = 100 (P_s) switches on a modulation slot"),
        "{e}"
    );
    let e = crate::linearize(&Actuator::new(p).unwrap(), 2.0, 0.054).unwrap_err();
    assert!(
        e.starts_with("modulation_2_parameter = 100: the linearisation does not carry"),
        "{e}"
    );
    assert!(crate::linearize(&Actuator::new(Parameters::default()).unwrap(), 2.0, 0.054).is_ok());
}

#[test]
fn an_effective_area_error_modulated_by_the_pressure_difference_adds_its_force_and_leaves_the_pressures() {
    let slot = Slot::through(
        vr::EXTRA_FORCE_PRESSURE_DIFFERENCE,
        ModulationSignal::PressureDifference,
        &[-3e5, 3e5],
        &[-1e-5, 1e-5],
    );
    let with = run(&with_slot(slot));
    let without = run(&Parameters::default());
    let p = Parameters::default();
    let (mut largest, mut checked) = (0.0_f64, 0);
    for (a, b) in with.iter().zip(&without) {
        assert_eq!((a[2], a[3]), (b[2], b[3]), "the pressures are the thesis model's");
        // Where the spring's floor holds the force (§2.7) the area error does not show.
        let x_s = 0.054 + 0.005 * (2.0 * std::f64::consts::PI * 5.0 * a[0]).sin();
        let floor = crate::physics::piston::spring_force(p.k_spring, p.l_spring0, p.l_s, p.l_p, x_s);
        if a[1].min(b[1]) < floor + 0.1 {
            continue;
        }
        let difference = a[2] - a[3];
        let area_error = 1e-5 * (difference / 3e5).clamp(-1.0, 1.0);
        let added = a[1] - b[1];
        assert!(
            (added - area_error * difference).abs() < 1e-9 * b[1].abs().max(1.0),
            "{added} N against {} N at {:?} and {:?}",
            area_error * difference,
            a,
            b
        );
        largest = largest.max(added.abs());
        checked += 1;
    }
    assert!(checked > 150, "{checked} of 300 samples above the spring's floor");
    assert!(largest > 0.1, "the slot moved the force by {largest} N");
}

/// Chamber 1's and 2's pressures at each sample of 0.3 s of the command of [`command`], the
/// stopper moving from `from` to `to` at a constant rate, stepped every `step` seconds by the
/// error-controlled simulation or the fixed-step replay.
fn chamber_pressures(p: Parameters, from: f64, to: f64, step: f64, replayed: bool) -> Vec<[f64; 2]> {
    let model = Actuator::new(p).unwrap();
    let steps = (0.3 / step).round() as usize;
    let position = |k: usize| from + (to - from) * k as f64 / steps as f64;
    let command_at = |k: usize| command((k as f64 * step * 1e3) as usize);
    let mut out = Vec::new();
    if replayed {
        let mut fixed = FixedStep::at_equilibrium(model, command(0), from, 0.0)
            .unwrap()
            .unwrap();
        for k in 0..steps {
            fixed.set_command(command_at(k)).unwrap();
            fixed.step_to((k + 1) as f64 * step, position(k + 1)).unwrap();
            let y = fixed.outputs();
            out.push([y.p1, y.p2]);
        }
    } else {
        let mut sim = Simulation::at_equilibrium(model, command(0), from, 0.0, 1e-8).unwrap();
        for k in 0..steps {
            sim.set_command(command_at(k)).unwrap();
            sim.set_stopper_rate((position(k + 1) - sim.x_s()) / step).unwrap();
            sim.step(step).unwrap();
            sim.land_stopper_at(position(k + 1));
            let y = sim.outputs();
            out.push([y.p1, y.p2]);
        }
    }
    out
}

/// The largest difference of two runs' pressures (Pa), over the samples of the coarser (every
/// `every`-th of `fine`).
fn largest_pressure_gap(coarse: &[[f64; 2]], fine: &[[f64; 2]], every: usize) -> f64 {
    coarse
        .iter()
        .enumerate()
        .flat_map(|(k, c)| {
            let f = fine[(k + 1) * every - 1];
            [(c[0] - f[0]).abs(), (c[1] - f[1]).abs()]
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_stopper_offset_that_a_slot_moves_with_the_stopper_keeps_the_piston_and_both_chambers_as_at_rest() {
    // The stopper moves 8 mm and the slot takes its offset L_sup 8 mm further: the piston,
    // at x_s − L_p − L_s − L_sup, stays where it was, and so must the chambers' pressures. The
    // slot's changes have to move the piston back and carry the air in the chambers exactly
    // as the stopper's motion moves it forth.
    let (from, to) = (0.050, 0.058);
    let slotted = with_slot(Slot::through(
        vr::L_SUP,
        ModulationSignal::StopperPosition,
        &[from, to],
        &[0.0, to - from],
    ));
    for replayed in [false, true] {
        let at_rest = chamber_pressures(Parameters::default(), from, from, 1e-4, replayed);
        let moved = chamber_pressures(Parameters::default(), from, to, 1e-4, replayed);
        let coarse = chamber_pressures(slotted.clone(), from, to, 1e-3, replayed);
        let fine = chamber_pressures(slotted.clone(), from, to, 1e-4, replayed);
        let motion = largest_pressure_gap(&moved, &at_rest, 1);
        let (gap_coarse, gap_fine) = (
            largest_pressure_gap(&coarse, &at_rest, 10),
            largest_pressure_gap(&fine, &at_rest, 1),
        );
        // The stopper's motion alone moves the pressures by tens of kilopascals…
        assert!(
            motion > 2e4,
            "replayed {replayed}: the motion moves them by only {motion} Pa"
        );
        // …the slot undoes it to within what a step's lag leaves (the slot moves the piston
        // at the steps' starts, the stopper within them), which falls as the step does.
        assert!(
            gap_fine < 0.01 * motion,
            "replayed {replayed}: {gap_fine} Pa of {motion}"
        );
        assert!(
            gap_fine < 0.3 * gap_coarse,
            "replayed {replayed}: {gap_fine} Pa at 0.1 ms steps, {gap_coarse} Pa at 1 ms"
        );
    }
}

#[test]
fn a_stopper_offset_falling_with_p1_minus_p2_by_the_compliance_times_the_area_is_the_compliant_stopper() {
    // A compliant stopper lets the piston c A_p max(P1 − P2, floor) beyond it, continuously
    // within a step (its own terms in the pressures' rates); a slot on L_sup that falls by
    // c A_p per pascal of P1 − P2 above the floor moves it there from step to step.
    let x_s = 0.054;
    let compliance = 2e-5;
    let compliant = Parameters {
        stopper_compliance: compliance,
        ..Parameters::default()
    };
    let model = Actuator::new(compliant.clone()).unwrap();
    let area = model.piston_area;
    let floor = model.spring_force(x_s) / area;
    let slotted = with_slot(Slot::through(
        vr::L_SUP,
        ModulationSignal::PressureDifference,
        &[floor, floor + 1e6],
        &[-compliance * area * floor, -compliance * area * (floor + 1e6)],
    ));
    for replayed in [false, true] {
        let reference = chamber_pressures(compliant.clone(), x_s, x_s, 1e-4, replayed);
        let rigid = chamber_pressures(Parameters::default(), x_s, x_s, 1e-4, replayed);
        let coarse = chamber_pressures(slotted.clone(), x_s, x_s, 1e-3, replayed);
        let fine = chamber_pressures(slotted.clone(), x_s, x_s, 1e-4, replayed);
        let compliance_moves = largest_pressure_gap(&rigid, &reference, 1);
        let (gap_coarse, gap_fine) = (
            largest_pressure_gap(&coarse, &reference, 10),
            largest_pressure_gap(&fine, &reference, 1),
        );
        assert!(
            compliance_moves > 1e4,
            "replayed {replayed}: the compliance moves the pressures by only {compliance_moves} Pa"
        );
        assert!(
            gap_fine < 0.02 * compliance_moves,
            "replayed {replayed}: {gap_fine} Pa of {compliance_moves}"
        );
        assert!(
            gap_fine < 0.3 * gap_coarse,
            "replayed {replayed}: {gap_fine} Pa at 0.1 ms steps, {gap_coarse} Pa at 1 ms"
        );
    }
}
