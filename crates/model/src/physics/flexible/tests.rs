//! The flexible slots' law, lag and refusals, against the modulation slots and closed forms.
//! Simulations with them are in `simulation/flexible_tests.rs`.

use super::*;
use crate::physics::modulation::Slot;

fn with_slot(slot: FlexibleSlot) -> Parameters {
    let mut p = Parameters::default();
    p.flexible[0] = slot;
    p
}

/// A slot on `parameter` over a grid: axis 1 `signal_1` at `x1`, axis 2 `signal_2` at `x2`,
/// the increments `y(i, j)` at the nodes.
fn grid(
    parameter: u32,
    (signal_1, x1): (ModulationSignal, &[f64]),
    (signal_2, x2): (ModulationSignal, &[f64]),
    y: impl Fn(usize, usize) -> f64,
) -> FlexibleSlot {
    let mut s = FlexibleSlot {
        parameter: parameter as f64,
        signals: [signal_1.code() as f64, signal_2.code() as f64],
        knots: [x1.len() as f64, x2.len() as f64],
        ..FlexibleSlot::default()
    };
    s.x[0][..x1.len()].copy_from_slice(x1);
    s.x[1][..x2.len()].copy_from_slice(x2);
    for i in 0..x1.len() {
        for j in 0..x2.len().max(1) {
            s.y[i][j] = y(i, j);
        }
    }
    s
}

#[test]
fn one_signal_gives_the_modulation_slots_increment_to_the_last_bit() {
    let (x, y) = ([-3.0, -1.0, 0.5, 2.0, 7.0], [0.2, -0.1, 0.4, 0.45, -0.3]);
    for n in 1..=5 {
        let modulation = Slot::through(vr::C_D, ModulationSignal::Command, &x[..n], &y[..n]);
        let flexible = FlexibleSlot::through(vr::C_D, ModulationSignal::Command, &x[..n], &y[..n]);
        for k in 0..=200 {
            let s = -5.0 + 0.07 * k as f64;
            assert_eq!(
                flexible.increment(s, 123.0).to_bits(),
                modulation.increment(s).to_bits(),
                "{n} knots at {s}"
            );
        }
    }
}

#[test]
fn a_grid_interpolates_a_product_exactly_within_its_cells_and_holds_its_edges_beyond() {
    // Bilinear interpolation reproduces u1 u2 at every point of a cell (it is bilinear), so
    // on a grid of y_ij = x1_i x2_j the increment is u1 u2 inside and the edge's beyond.
    let (x1, x2) = ([-2.0, -0.5, 1.0, 3.0], [0.0, 1.0, 4.0]);
    let slot = grid(
        vr::K_SPRING,
        (ModulationSignal::Command, &x1),
        (ModulationSignal::P1, &x2),
        |i, j| x1[i] * x2[j],
    );
    for (u1, u2) in [(-1.3, 0.25), (0.0, 2.5), (2.9, 3.99), (-2.0, 4.0), (1.0, 1.0)] {
        let inc = slot.increment(u1, u2);
        assert!(
            (inc - u1 * u2).abs() < 1e-14 * (1.0 + (u1 * u2).abs()),
            "({u1}, {u2}): {inc}"
        );
    }
    // Beyond the end knots: held at the edge (u clamped to the grid).
    assert_eq!(slot.increment(10.0, 2.0), slot.increment(3.0, 2.0));
    assert_eq!(slot.increment(-10.0, -7.0), slot.increment(-2.0, 0.0));
    assert!((slot.increment(5.0, 9.0) - 12.0).abs() < 1e-14);
    // A separable grid is the sum of its two axes' piecewise-linear functions.
    let (a, b) = ([0.3, -0.2, 0.1, 0.0], [1.0, -1.0, 0.5]);
    let separable = grid(
        vr::K_SPRING,
        (ModulationSignal::Command, &x1),
        (ModulationSignal::P1, &x2),
        |i, j| a[i] + b[j],
    );
    let (sa, sb) = (
        Slot::through(vr::K_SPRING, ModulationSignal::Command, &x1, &a),
        Slot::through(vr::K_SPRING, ModulationSignal::P1, &x2, &b),
    );
    for k in 0..50 {
        let (u1, u2) = (-3.0 + 0.13 * k as f64, -0.5 + 0.11 * k as f64);
        let sum = sa.increment(u1) + sb.increment(u2);
        assert!((separable.increment(u1, u2) - sum).abs() < 1e-15, "({u1}, {u2})");
    }
    // One knot on axis 2 (or none): the column y_i_1 alone, whatever signal 2 reads.
    let mut one_column = separable;
    one_column.knots[1] = 1.0;
    let column = |u1: f64| sa.increment(u1) + b[0];
    assert!((one_column.increment(0.2, 1e6) - column(0.2)).abs() < 1e-15);
    one_column.knots[1] = 0.0;
    assert!((one_column.increment(0.2, -1e6) - column(0.2)).abs() < 1e-15);
}

#[test]
fn the_lag_of_a_held_signal_is_the_exact_first_order_response_and_of_a_ramp_within_its_bound() {
    let tau = 0.02;
    let mut slot = FlexibleSlot::through(vr::EXTRA_FORCE_OFFSET, ModulationSignal::Command, &[0.0], &[0.0]);
    slot.lags[0] = tau;
    let p = with_slot(slot);
    let at = |v_da: f64| Signals {
        v_da,
        ..Signals::default()
    };
    // From 1 V, the command held at 4 V: u = 4 − 3 e^(−t/τ) at every step's end.
    let mut lags = initial_lags(&p, &at(1.0));
    assert_eq!(lags[0][0], 1.0);
    let h = 1e-3;
    for k in 1..=100 {
        advance_lags(&p, &mut lags, h, &at(4.0), &at(4.0));
        let exact = 4.0 - 3.0 * (-(k as f64) * h / tau).exp();
        assert!(
            (lags[0][0] - exact).abs() < 1e-13,
            "step {k}: {} against {exact}",
            lags[0][0]
        );
    }
    // A ramp s = r t from rest: the exact response is r (t − τ (1 − e^(−t/τ))); the trapezoid
    // of each step's ends is off by r h³/(12 τ²) per step to leading order, which the lag's
    // decay accumulates to at most r h²/(12 τ).
    let r = 50.0;
    let mut lags = initial_lags(&p, &at(0.0));
    let bound = r * h * h / (12.0 * tau);
    let mut worst = 0.0_f64;
    for k in 1..=200 {
        let (t0, t1) = ((k - 1) as f64 * h, k as f64 * h);
        advance_lags(&p, &mut lags, h, &at(r * t0), &at(r * t1));
        let exact = r * (t1 - tau * (1.0 - (-t1 / tau).exp()));
        worst = worst.max((lags[0][0] - exact).abs());
    }
    assert!(worst <= 1.01 * bound, "{worst} against the bound {bound}");
    assert!(
        worst >= 0.9 * bound,
        "{worst}: the bound {bound} is not the discretisation's"
    );
    // An axis without lag, a slot that is off: nothing to follow.
    let mut unlagged = p.clone();
    unlagged.flexible[0].lags[0] = 0.0;
    assert!(!lags_on(&unlagged));
    let mut same = [[7.0, 8.0]; FLEXIBLE_SLOTS];
    advance_lags(&unlagged, &mut same, h, &at(1.0), &at(2.0));
    assert_eq!(same, [[7.0, 8.0]; FLEXIBLE_SLOTS]);
}

#[test]
fn a_lagged_axis_reads_the_lag_state_and_an_unlagged_one_the_signal() {
    let mut slot = grid(
        vr::K_SPRING,
        (ModulationSignal::Command, &[0.0, 10.0]),
        (ModulationSignal::P1, &[0.0, 1e6]),
        |i, j| 10.0 * i as f64 + 5.0 * j as f64,
    );
    slot.lags = [0.01, 0.0];
    let mut p = Parameters::default();
    p.flexible[1] = slot;
    let raw = Signals {
        v_da: 5.0,
        p1: 4e5,
        ..Signals::default()
    };
    let lagged = Signals {
        lagged: Some([[0.0, 0.0], [2.0, 9e5]]),
        ..raw
    };
    // Raw: 5 + 2; lagged on axis 1 alone: 2 + 2 (slot 2 reads the second pair).
    assert!((slot.increment_at(1, &raw) - 7.0).abs() < 1e-12);
    assert!((slot.increment_at(1, &lagged) - 4.0).abs() < 1e-12);
    assert!(lags_on(&p));
}

#[test]
fn each_variable_of_a_slot_is_its_named_field() {
    for k in 0..FLEXIBLE_SLOTS {
        let base = vr::FLEXIBLE_1_PARAMETER + k as u32 * vr::FLEXIBLE_STRIDE;
        let mut names = vec![
            "parameter".to_string(),
            "signal_1".into(),
            "signal_2".into(),
            "frequency".into(),
            "lag_1".into(),
            "lag_2".into(),
            "knots_1".into(),
            "knots_2".into(),
        ];
        names.extend((1..=5).map(|i| format!("x1_{i}")));
        names.extend((1..=5).map(|j| format!("x2_{j}")));
        for i in 1..=5 {
            names.extend((1..=5).map(|j| format!("y_{i}_{j}")));
        }
        assert_eq!(names.len(), SLOT_VARIABLES);
        for (offset, name) in names.iter().enumerate() {
            let r = base + offset as u32;
            assert_eq!(variable_name(r), format!("flexible_{}_{name}", k + 1));
            let mut p = Parameters::default();
            // Within every row's limits (the knot counts' [0, 5] the narrowest).
            let value = 0.25 + 0.01 * offset as f64;
            p.set(r, value).unwrap();
            let slot = &p.flexible[k];
            let field = match offset {
                0 => slot.parameter,
                1 | 2 => slot.signals[offset - 1],
                3 => slot.frequency,
                4 | 5 => slot.lags[offset - 4],
                6 | 7 => slot.knots[offset - 6],
                8..=12 => slot.x[0][offset - 8],
                13..=17 => slot.x[1][offset - 13],
                _ => {
                    let (i, j) = ((offset - 18) / 5, (offset - 18) % 5);
                    slot.y[i][j]
                }
            };
            assert_eq!(field, value, "{name}");
            assert!(Parameters::VALUE_REFERENCES.contains(&r), "{name}");
        }
        assert!(Parameters::default().get(base + SLOT_VARIABLES as u32).is_none());
    }
    assert_eq!(vr::FLEXIBLE_1_Y + 5 + 2, 825);
    assert_eq!(variable_name(825), "flexible_1_y_2_3");
}

#[test]
fn the_targets_are_the_modulatable_constants_and_the_three_plain_ones() {
    assert_eq!(FLEXIBLE_TARGETS.len(), MODULATABLE.len() + 3);
    for r in MODULATABLE.iter().chain(&[780, 781, 782]) {
        assert!(FLEXIBLE_TARGETS.contains(r), "{}", variable_name(*r));
    }
    assert!(!MODULATABLE.contains(&vr::EXTRA_FORCE_OFFSET));
}

/// The error `validate` gives `slot` (in slot 1), which must say each of `parts`.
fn refused(slot: FlexibleSlot, parts: &[&str]) {
    let e = with_slot(slot).validate().unwrap_err();
    for part in parts {
        assert!(e.contains(part), "{part:?} not in: {e}");
    }
}

#[test]
fn validation_refuses_bad_codes_targets_knots_and_grid_values_naming_variable_value_and_limit() {
    let good = grid(
        vr::C_D,
        (ModulationSignal::StopperPosition, &[0.05, 0.055, 0.06]),
        (ModulationSignal::Command, &[-1.0, 2.0, 5.0]),
        |i, j| 0.01 * (i as f64 - j as f64),
    );
    assert!(with_slot(good).validate().is_ok());
    let mut p = with_slot(good);
    p.flexible[1] = good;
    assert!(p.validate().is_ok(), "both slots on");

    let mut s = good;
    s.signals[0] = 2.5;
    refused(
        s,
        &["flexible_1_signal_1 = 2.5 is invalid", "whole number from 0 to 13"],
    );
    let mut s = good;
    s.knots[1] = 1.5;
    refused(s, &["flexible_1_knots_2 = 1.5 is invalid", "whole number from 0 to 5"]);
    let mut s = good;
    s.parameter = vr::GAMMA as f64;
    refused(
        s,
        &[
            "flexible_1_parameter = 103 is invalid",
            "must be 0 (off) or the value reference",
            "extra_force_offset (780)",
        ],
    );
    let mut s = good;
    s.parameter = vr::C_D as f64 + 0.5;
    refused(s, &["flexible_1_parameter = 131.5 is invalid"]);
    let mut s = good;
    s.x[1][2] = 1.0;
    refused(
        s,
        &["flexible_1_x2_3 = 1 V is invalid: must exceed flexible_1_x2_2 = 2 V"],
    );
    let mut s = good;
    s.x[0][1] = 0.05;
    refused(
        s,
        &["flexible_1_x1_2 = 0.05 m is invalid: must exceed flexible_1_x1_1 = 0.05 m"],
    );
    // C_d = 0.696 plus 0.4 at node (2, 3) leaves (0, 1].
    let mut s = good;
    s.y[1][2] = 0.4;
    refused(
        s,
        &[
            "flexible_1_y_2_3 = 0.4 takes C_d from 0.696 to 1.096 at node (2, 3)",
            "x_s = 0.055 m, v_DA = 5 V",
            "C_d = 1.096 is invalid: must be in (0, 1]",
        ],
    );
    // A constraint between constants: P_r above P_s at a node.
    let p_r = grid(
        vr::P_R,
        (ModulationSignal::P1, &[1e5, 3e5]),
        (ModulationSignal::None, &[]),
        |i, _| if i == 1 { 6e5 } else { 0.0 },
    );
    refused(
        p_r,
        &[
            "flexible_1_y_2_1 = 600000 takes P_r from 101325 to 701325",
            "must be >= P_r",
        ],
    );
    // A node's value is checked only where the grid uses it.
    let mut s = good;
    s.y[4][4] = 5.0;
    s.y[2][3] = -5.0;
    assert!(with_slot(s).validate().is_ok());
    // Off: its knots and increments are not read.
    let mut s = good;
    s.parameter = 0.0;
    s.y[0][0] = 1e6;
    s.x[0][1] = -1.0;
    assert!(with_slot(s).validate().is_ok());
}

#[test]
fn model_exchange_is_refused_by_name_and_sent_to_co_simulation() {
    assert!(refuse_in_model_exchange(&Parameters::default()).is_ok());
    let mut p = Parameters::default();
    p.flexible[1] = FlexibleSlot::through(vr::EXTRA_INFLOW_1, ModulationSignal::P1, &[1e5], &[1e-6]);
    let e = refuse_in_model_exchange(&p).unwrap_err();
    assert!(
        e.starts_with("flexible_2_parameter = 781 (extra_inflow_1) switches on a flexible slot")
            && e.contains("Co-Simulation"),
        "{e}"
    );
}
