//! The actuator's tests: the Jacobian, the mass flows and the rates' fast paths against the
//! general ones, the chambers' leaks, the discharge curve, the outputs, the extra force's
//! product slots, the extra flow slots.

use super::*;

#[test]
fn jacobian_matches_finite_differences_of_the_whole_model() {
    let model = Actuator::new(Parameters::default()).unwrap();
    let u = Inputs {
        v_da: 2.5,
        x_s: 0.054,
        x_s_rate: 0.01,
        plays: None,
    };
    let y = State::from([0.09, 2.1e-4, 0.03, -20.0, 4.0e5, 1.7e5]);
    let f = model.derivatives(&y, &u);
    let analytic = model.jacobian(&y, &u, &f);
    let numeric = crate::integrator::finite_difference_jacobian(|yy| model.derivatives(yy, &u), &y, &f);
    for r in 0..N_STATES {
        for c in 0..N_STATES {
            let (a, n) = (analytic[(r, c)], numeric[(r, c)]);
            assert!(
                (a - n).abs() <= 1e-4 * n.abs().max(1e-6 * analytic.row(r).amax()),
                "J[{r},{c}] {a} vs {n}"
            );
        }
    }
}

#[test]
fn mass_flows_balance_when_the_chambers_are_sealed() {
    let p = Parameters {
        c_d: 0.0,
        c_db_a_lpp: 0.0,
        c_dm_a_lpp: 0.0,
        ..Parameters::default()
    };
    let model = Actuator::new(p).unwrap();
    let f = model.mass_flows(3e-4, 4e5, 2e5);
    assert_eq!((f.net_1(), f.net_2()), (0.0, 0.0));
}

/// Jet pipe positions across and beyond the ports, and pressures from below P_r to
/// above P_s, both orders of P1 and P2, equal pressures, choked and unchoked flows.
fn rate_samples() -> Vec<(f64, f64, f64, f64, f64)> {
    let mut samples = vec![];
    for x_jp in [-0.4e-3, -0.11e-3, -2e-5, 0.0, 1e-6, 0.05e-3, 0.2e-3, 0.6e-3] {
        for (p1, p2) in [
            (5.8e5, 2.8e5),
            (2.8e5, 5.8e5),
            (3.3e5, 3.3e5),
            (1.2e5, 6.9e5),
            (1.0e5, 1.01e5),
        ] {
            for (x_s, x_s_rate) in [(0.054, 0.0), (0.047, -0.02), (0.066, 0.03)] {
                samples.push((x_jp, p1, p2, x_s, x_s_rate));
            }
        }
    }
    samples
}

#[test]
fn the_thesis_rates_are_the_general_paths_to_the_last_bit() {
    let with_factors = Parameters {
        supply_area_scale_1: 1.07,
        return_area_scale_2: 0.93,
        dead_volume_1: 2e-6,
        heat_transfer_fraction: 0.4,
        ..Parameters::default()
    };
    for params in [Parameters::default(), with_factors] {
        let model = Actuator::new(params).unwrap();
        assert_eq!(model.rate_terms(), RateTerms::Thesis);
        for (x_jp, p1, p2, x_s, x_s_rate) in rate_samples() {
            let areas = model.areas(x_jp);
            let thesis = model.thesis_pressure_rates(&areas, p1, p2, x_s, x_s_rate);
            let general = model.extended_pressure_rates(&areas, p1, p2, x_s, x_s_rate);
            assert_eq!(
                (thesis.0.to_bits(), thesis.1.to_bits()),
                (general.0.to_bits(), general.1.to_bits()),
                "x_jp {x_jp}, P1 {p1}, P2 {p2}, x_s {x_s}, rate {x_s_rate}"
            );
            assert_eq!(model.pressure_rates_through(&areas, p1, p2, x_s, x_s_rate), thesis);
        }
    }
}

#[test]
fn a_vent_a_restriction_or_a_compliant_stopper_takes_the_general_rates() {
    type Setter = fn(&mut Parameters);
    let terms: [(&str, Setter); 11] = [
        ("chamber_vent_2", |p| p.chamber_vent_2 = 2e-9),
        ("extra_flow_1_coefficient", |p| p.extra_flows[0].coefficient = 1e-6),
        ("extra_inflow_2", |p| p.extra_inflow_2 = -1e-6),
        ("chamber_supply_leak_1", |p| p.chamber_supply_leak_1 = 2e-9),
        ("chamber_laminar_vent_2", |p| p.chamber_laminar_vent_2 = 1e-11),
        ("chamber_laminar_supply_leak_1", |p| {
            p.chamber_laminar_supply_leak_1 = 1e-11
        }),
        ("chamber_laminar_cross_leak", |p| p.chamber_laminar_cross_leak = 1e-11),
        ("discharge_curve", |p| {
            p.discharge_curve = super::super::static_curve::StaticCurve::through(&[0.2, 1.0], &[0.8, 0.6])
        }),
        ("supply_resistance", |p| p.supply_resistance = 3e8),
        ("port_restriction_area_1", |p| p.port_restriction_area_1 = 0.2e-6),
        ("stopper_compliance", |p| p.stopper_compliance = 1e-5),
    ];
    let thesis = Actuator::new(Parameters::default()).unwrap();
    for (name, set) in terms {
        let mut params = Parameters::default();
        set(&mut params);
        let model = Actuator::new(params).unwrap();
        assert_eq!(model.rate_terms(), RateTerms::Extended, "{name}");
        // The term acts: the rates differ from the thesis model's somewhere.
        let differs = rate_samples().into_iter().any(|(x_jp, p1, p2, x_s, x_s_rate)| {
            model.pressure_rates(x_jp, p1, p2, x_s, x_s_rate) != thesis.pressure_rates(x_jp, p1, p2, x_s, x_s_rate)
        });
        assert!(differs, "{name} changes no rate");
    }
}

#[test]
fn with_the_discharge_curve_each_valve_orifice_flows_with_c_d_at_its_own_pressure_ratio() {
    use super::super::static_curve::StaticCurve;
    // C_d rising from 0.6 at equal pressures to 0.8 at a ratio of 0.2 and below.
    let mut params = Parameters {
        supply_area_scale_2: 1.1,
        ..Parameters::default()
    };
    params.discharge_curve = StaticCurve::through(&[0.2, 1.0], &[0.8, 0.6]);
    let model = Actuator::new(params.clone()).unwrap();
    let cd = |ratio: f64| if ratio <= 0.2 { 0.8 } else { 0.8 - 0.25 * (ratio - 0.2) };
    let k = params.flow_constants();
    let (x_jp, p1, p2) = (0.03e-3, 420e3, 250e3);
    let a = model.areas(x_jp);
    let flows = model.mass_flows(x_jp, p1, p2);
    let expected = [
        (
            flows.supply_1,
            mass_flow(&k, cd(p1 / params.p_s) * a.supply_1, params.p_s, p1),
        ),
        (
            flows.return_1,
            mass_flow(&k, cd(params.p_r / p1) * a.return_1, p1, params.p_r),
        ),
        (
            flows.supply_2,
            mass_flow(&k, 1.1 * cd(p2 / params.p_s) * a.supply_2, params.p_s, p2),
        ),
        (
            flows.return_2,
            mass_flow(&k, cd(params.p_r / p2) * a.return_2, p2, params.p_r),
        ),
    ];
    for (i, (got, want)) in expected.into_iter().enumerate() {
        assert!(want != 0.0 || got == 0.0);
        assert!(
            (got - want).abs() <= 1e-12 * want.abs(),
            "orifice {i}: {got} against {want}"
        );
    }
    // A flat curve at the thesis's C_d is the thesis model, to rounding.
    let mut flat = Parameters::default();
    flat.discharge_curve = StaticCurve::through(&[0.0, 1.0], &[flat.c_d, flat.c_d]);
    let (flat, thesis) = (
        Actuator::new(flat).unwrap(),
        Actuator::new(Parameters::default()).unwrap(),
    );
    for (x_jp, p1, p2, x_s, x_s_rate) in rate_samples() {
        let (a, b) = flat.pressure_rates(x_jp, p1, p2, x_s, x_s_rate);
        let (c, d) = thesis.pressure_rates(x_jp, p1, p2, x_s, x_s_rate);
        assert!((a - c).abs() <= 1e-9 * c.abs().max(1.0) && (b - d).abs() <= 1e-9 * d.abs().max(1.0));
    }
}

#[test]
fn a_chambers_leaks_are_orifices_and_laminar_paths_to_the_return_from_the_supply_and_to_the_other_chamber() {
    let params = Parameters {
        chamber_vent_1: 3e-9,
        chamber_laminar_vent_1: 2e-11,
        chamber_supply_leak_1: 1e-9,
        chamber_supply_leak_2: 4e-9,
        chamber_laminar_supply_leak_2: 5e-12,
        chamber_laminar_cross_leak: 3e-11,
        ..Parameters::default()
    };
    let k = params.flow_constants();
    let model = Actuator::new(params.clone()).unwrap();
    let (p1, p2) = (380e3, 210e3);
    let flows = model.mass_flows(0.02e-3, p1, p2);
    let lost_1 = mass_flow(&k, 3e-9, p1, params.p_r) + 2e-11 * (p1 - params.p_r) - mass_flow(&k, 1e-9, params.p_s, p1);
    let lost_2 = -mass_flow(&k, 4e-9, params.p_s, p2) - 5e-12 * (params.p_s - p2);
    assert!(
        (flows.vent_1 - lost_1).abs() <= 1e-15 * lost_1.abs(),
        "{} against {lost_1}",
        flows.vent_1
    );
    assert!(
        (flows.vent_2 - lost_2).abs() <= 1e-15 * lost_2.abs(),
        "{} against {lost_2}",
        flows.vent_2
    );
    // The supply leak brings air in, the laminar path takes it out in proportion.
    assert!(lost_2 < 0.0 && 2e-11 * (p1 - params.p_r) > 0.0);
    let thesis = Actuator::new(Parameters::default())
        .unwrap()
        .mass_flows(0.02e-3, p1, p2);
    assert_eq!((thesis.vent_1, thesis.vent_2), (0.0, 0.0));
    let across = thesis.leakage + 3e-11 * (p1 - p2); // (2.23) beside the laminar path between the chambers
    let off = (flows.leakage - across).abs();
    assert!(off <= 1e-15 * across, "leakage {} against {across}", flows.leakage);
}

#[test]
fn a_discharge_curve_outside_its_range_is_refused_naming_the_knot() {
    use crate::variables::vr;
    let mut params = Parameters::default();
    params.set(vr::DISCHARGE_CURVE_KNOTS, 2.0).unwrap();
    params.set(vr::DISCHARGE_CURVE_X + 1, 1.0).unwrap();
    let e = params.set(vr::DISCHARGE_CURVE_Y, 1.3).unwrap_err();
    assert!(e.contains("discharge_curve_y_1") && e.contains("1.3"), "{e}");
    let e = params.set(vr::DISCHARGE_CURVE_X, -0.1).unwrap_err();
    assert!(e.contains("discharge_curve_x_1") && e.contains("-0.1"), "{e}");
}

#[test]
fn the_thesis_outputs_are_the_general_paths_to_the_last_bit() {
    let model = Actuator::new(Parameters::default()).unwrap();
    assert!(model.thesis_outputs);
    let mut general = model.clone();
    general.thesis_outputs = false;
    for (x_jp, p1, p2, x_s, stopper_velocity) in rate_samples() {
        let mut y = State::zeros();
        y[index::CURRENT] = 0.13;
        y[index::JET_POSITION] = x_jp;
        y[index::P1] = p1;
        y[index::P2] = p2;
        for time in [0.0, 3.7] {
            let (a, b) = (
                model.outputs_at(&y, x_s, stopper_velocity, time),
                general.outputs_at(&y, x_s, stopper_velocity, time),
            );
            let bits = |o: &Outputs| {
                [o.f_act, o.f_meas, o.p1_meas, o.p2_meas, o.p1, o.p2, o.current, o.x_jp].map(f64::to_bits)
            };
            assert_eq!(bits(&a), bits(&b), "{y:?} at x_s {x_s}");
        }
    }
    // Any friction or transducer term leaves the thesis outputs.
    for params in [
        Parameters {
            friction_coulomb: 1.5,
            ..Parameters::default()
        },
        Parameters {
            p2_sensor_offset: 300.0,
            ..Parameters::default()
        },
        Parameters {
            force_sensor_lag: 1e-3,
            ..Parameters::default()
        },
    ] {
        assert!(!Actuator::new(params).unwrap().thesis_outputs);
    }
}

#[test]
fn an_extra_flow_of_p1_less_p2_into_chamber_2_changes_chamber_2s_inflow_alone() {
    use super::super::extra_flow::FlowSlot;
    let c = 3.1e-6; // kg/s per bar of P1 − P2
    let mut params = Parameters::default();
    params.extra_flows[1] = FlowSlot {
        chamber: 2.0,
        signal: 1.0,
        coefficient: c,
    };
    let model = Actuator::new(params).unwrap();
    let thesis = Actuator::new(Parameters::default()).unwrap();
    for (x_jp, p1, p2) in [(0.02e-3, 380e3, 210e3), (-0.05e-3, 150e3, 460e3), (0.0, 300e3, 300e3)] {
        let with = model.mass_flows(x_jp, p1, p2);
        let without = thesis.mass_flows(x_jp, p1, p2);
        let added = c * (p1 - p2) / 1e5;
        let change_2 = with.net_2() - without.net_2();
        assert!(
            (change_2 - added).abs() <= 1e-12 * without.net_2().abs().max(added.abs()),
            "chamber 2 gains {change_2} kg/s against {added} at P1 {p1}, P2 {p2}"
        );
        assert_eq!(with.net_1(), without.net_1(), "chamber 1 at P1 {p1}, P2 {p2}");
        assert_eq!(with.leakage, without.leakage);
    }
    // Mass is not conserved between the chambers: their net flows' sum changes by the flow.
    let (p1, p2) = (400e3, 200e3);
    let sum = |f: MassFlows| f.net_1() + f.net_2();
    let gained = sum(model.mass_flows(0.0, p1, p2)) - sum(thesis.mass_flows(0.0, p1, p2));
    assert!((gained - 2.0 * c).abs() < 1e-12 * 2.0 * c + 1e-18, "{gained}");
}

#[test]
fn the_extra_flow_slots_are_off_by_default_and_leave_the_thesis_model_unchanged() {
    let params = Parameters::default();
    assert!(params.extra_flows.iter().all(|slot| slot.coefficient == 0.0));
    let model = Actuator::new(params.clone()).unwrap();
    assert_eq!(model.rate_terms(), RateTerms::Thesis);
    // A slot with a chamber and a signal but no coefficient is still off.
    let mut set_up = params;
    set_up.extra_flows[0].chamber = 2.0;
    set_up.extra_flows[0].signal = 4.0;
    let idle = Actuator::new(set_up).unwrap();
    assert_eq!(idle.rate_terms(), RateTerms::Thesis);
    for (x_jp, p1, p2, x_s, x_s_rate) in rate_samples() {
        assert_eq!(
            idle.pressure_rates(x_jp, p1, p2, x_s, x_s_rate),
            model.pressure_rates(x_jp, p1, p2, x_s, x_s_rate)
        );
    }
}

#[test]
fn the_pressures_are_found_again_from_their_values_at_the_reference_volumes() {
    let rigid = Parameters::default();
    let compliant = Parameters {
        stopper_compliance: 2e-4,
        ..Parameters::default()
    };
    let lagging = Parameters {
        stopper_compliance: 2e-4,
        stopper_mount_lag: 5e-3,
        ..Parameters::default()
    };
    let x_s = 0.054;
    // P1 − P2 of 3 bar lies above the spring floor (0.13 bar at 54 mm), −1 bar on it.
    for (name, params) in [("rigid", rigid), ("compliant", compliant), ("lagging", lagging)] {
        let model = Actuator::new(params).unwrap();
        let reference = model.cylinder.volumes(0.061);
        for (p1, p2, mount) in [
            (4.5e5_f64, 1.5e5_f64, 2.9e5_f64),
            (1.5e5, 2.5e5, 0.2e5),
            (6.0e5, 1.0e5, 5.0e5),
        ] {
            let (v1, v2) = model.chamber_volumes(p1, p2, mount, x_s);
            let n = model.polytropic_exponent;
            let at_reference = [
                chambers::pressure_after_volume_jump(n, p1, v1, reference.0),
                chambers::pressure_after_volume_jump(n, p2, v2, reference.1),
            ];
            let found = model.pressures_from_reference(at_reference, reference, mount, x_s);
            for (f, p) in found.iter().zip([p1, p2]) {
                assert!((f - p).abs() <= 1e-9 * p, "{name}: {found:?} for {:?}", [p1, p2]);
            }
        }
        if name != "rigid" {
            let moved = model.chamber_volumes(4.5e5, 1.5e5, 2.9e5, x_s);
            assert!(
                (moved.0 - model.cylinder.volumes(x_s).0).abs() > 1e-8,
                "{name}: the piston moved"
            );
        }
    }
}

#[test]
fn a_stopper_jump_conserves_each_chambers_air_with_the_piston_where_the_pressures_put_it() {
    for lag in [0.0, 5e-3] {
        let model = Actuator::new(Parameters {
            stopper_compliance: 2e-4,
            stopper_mount_lag: lag,
            ..Parameters::default()
        })
        .unwrap();
        let (p1, p2, mount) = (4.5e5, 1.5e5, 2.9e5);
        let [q1, q2] = model.pressures_after_stopper_jump(p1, p2, mount, 0.054, 0.070);
        let n = model.polytropic_exponent;
        let before = model.chamber_volumes(p1, p2, mount, 0.054);
        let after = model.chamber_volumes(q1, q2, mount, 0.070);
        let air = |p: f64, v: f64| p * v.powf(n);
        assert!(
            (air(q1, after.0) / air(p1, before.0) - 1.0).abs() < 1e-12,
            "lag {lag}: chamber 1"
        );
        assert!(
            (air(q2, after.1) / air(p2, before.1) - 1.0).abs() < 1e-12,
            "lag {lag}: chamber 2"
        );
        assert!(q1 < p1 && q2 > p2, "lag {lag}: chamber 1 grows, chamber 2 shrinks");
    }
}
