//! The state a simulation starts from: the electromechanics at their static values and the
//! chamber pressures at which both net mass flows vanish (§3.3.1), found by a
//! pseudo-transient run polished by Newton's method, which converges from any start.

use nalgebra::{DMatrix, DVector, SVector};

use super::monolithic::StepSystem;
use crate::integrator::{Sdirk4, Statistics, Tolerances};
use crate::physics::actuator::{index, Actuator, State};
use crate::physics::command_stage;
use crate::physics::current_driver;
use crate::physics::modulation::{self, ALL_SLOTS};
use crate::physics::restrictions::{node, PRESSURES_WITH_VOLUMES};
use crate::physics::time_varying;

/// The current at its static value and the jet pipe at rest at f3 of it; the pressures
/// are set half-way between return and supply.
pub fn equilibrium_of_electromechanics(model: &Actuator, v_da: f64) -> State {
    let p = &model.params;
    let seen = command_stage::static_map(p, v_da);
    let current = current_driver::static_current(p.k_cd, p.i_offset, seen);
    let x_jp = model.initial_jet_input(current);
    let mid = 0.5 * (p.p_s + p.p_r);
    State::from([current, x_jp, 0.0, 0.0, mid, mid])
}

/// [`equilibrium`] with the constants that vary in time at their values at `time`, and the
/// modulation slots' constants at the equilibrium's own signals ([`modulated_equilibrium`]).
pub fn equilibrium_at(model: &Actuator, v_da: f64, x_s: f64, time: f64) -> Result<State, String> {
    if modulation::any_on(&model.params) {
        return modulated_equilibrium(model, v_da, x_s, time).map(|(state, _)| state);
    }
    if !time_varying::varies(&model.params) {
        return equilibrium(model, v_da, x_s);
    }
    let mut at = model.clone();
    time_varying::set_model_at(&mut at, &model.params, time)?;
    equilibrium(&at, v_da, x_s)
}

/// The equilibrium state for constant inputs: the current at its static value, the jet
/// pipe at rest at f3 of it, and chamber pressures at which both net mass flows vanish.
///
/// The pressures come from a pseudo-transient run of the chamber equations (robust from
/// any start) polished by Newton's method on the two net flows.
pub fn equilibrium(model: &Actuator, v_da: f64, x_s: f64) -> Result<State, String> {
    let p = &model.params;
    let mut y = equilibrium_of_electromechanics(model, v_da);
    let x_jp = y[index::JET_POSITION];
    let rates = |p1: f64, p2: f64| {
        let (a, b) = model.pressure_rates(x_jp, p1, p2, x_s, 0.0);
        SVector::<f64, 2>::new(a, b)
    };
    let system = StepSystem {
        model,
        t0: 0.0,
        v_da: command_stage::static_map(p, v_da),
        v_da_rate: 0.0,
        x_s,
        x_s_rate: 0.0,
        // Held where hysteresis_start puts it (the command stays, so the memory does).
        plays: (model.hysteresis.is_active() && p.hysteresis_start != 0.0)
            .then(|| model.initial_hysteresis_memory(y[index::CURRENT])),
    };
    let tolerances = Tolerances {
        relative: 1e-8,
        absolute: model.state_scales() * 1e-8,
    };
    let mut integrator = Sdirk4::default();
    let mut statistics = Statistics::default();
    let pressure_scale = p.p_s.max(p.p_r);
    let mut t = 0.0;
    for _ in 0..400 {
        y = integrator
            .integrate(&system, t, y, t + 0.5, &tolerances, &mut statistics)
            .map_err(|f| {
                format!(
                    "could not find the equilibrium for v_DA = {v_da} V, x_s = {x_s} m: {}",
                    f.message
                )
            })?;
        t += 0.5;
        let r = rates(y[index::P1], y[index::P2]);
        // Settled to where Newton converges quadratically: < 1 Pa of drift per 10 ms.
        if r.amax() < 1e-4 * pressure_scale {
            break;
        }
    }
    let mut pressures = SVector::<f64, 2>::new(y[index::P1], y[index::P2]);
    for _ in 0..50 {
        let r = rates(pressures[0], pressures[1]);
        if r.amax() == 0.0 {
            break;
        }
        let jac = crate::integrator::finite_difference_jacobian(|q| rates(q[0], q[1]), &pressures, &r);
        let delta = match jac.lu().solve(&(-r)) {
            Some(delta) => delta,
            None => break,
        };
        // Never jump further than a tenth of the supply pressure in one iteration.
        let limit = 0.1 * pressure_scale;
        let delta = if delta.amax() > limit {
            delta * (limit / delta.amax())
        } else {
            delta
        };
        let trial = pressures + delta;
        if rates(trial[0], trial[1]).amax() >= r.amax() && delta.amax() < 1e-9 * pressure_scale {
            break;
        }
        pressures = trial;
        if delta.amax() < 1e-12 * pressure_scale {
            break;
        }
    }
    y[index::P1] = pressures[0];
    y[index::P2] = pressures[1];
    let residual = rates(pressures[0], pressures[1]).amax();
    if !residual.is_finite() || residual > 1e-3 * pressure_scale {
        return Err(format!(
            "could not find the equilibrium for v_DA = {v_da} V, x_s = {x_s} m: pressures still change by {residual} Pa/s"
        ));
    }
    Ok(y)
}

/// The chamber pressures of `state` and the volumes' pressures at which every net flow of the
/// network with its volumes vanishes ([`Actuator::pressure_rates_with_volumes`]), at the
/// constants' values at `time`. [`equilibrium`] balances the chambers with the pressures
/// behind the restrictions found one place at a time; that is close, and Newton's method on
/// all the pressures together takes it the rest of the way.
pub fn balance_with_volumes(
    model: &Actuator,
    state: &State,
    x_s: f64,
    time: f64,
) -> Result<(State, [f64; node::STATES]), String> {
    let held;
    let model = if time_varying::varies(&model.params) {
        let mut at = model.clone();
        time_varying::set_model_at(&mut at, &model.params, time)?;
        held = at;
        &held
    } else {
        model
    };
    let areas = model.areas(state[index::JET_POSITION]);
    let quasi_static = model
        .network_flows(&areas, state[index::P1], state[index::P2], None)
        .node_pressures;
    let mount = 2 + node::MOUNT;
    let active: Vec<usize> = (0..PRESSURES_WITH_VOLUMES)
        .filter(|&i| {
            i < 2 || (i == mount && model.mount_lags()) || (i < mount && model.restrictions.places[i - 2].has_volume())
        })
        .collect();
    let mut all = [0.0; PRESSURES_WITH_VOLUMES];
    all[0] = state[index::P1];
    all[1] = state[index::P2];
    all[2..mount].copy_from_slice(&quasi_static);
    if model.mount_lags() {
        all[mount] = model.mount_load(state[index::P1], state[index::P2], x_s);
    }
    let residual = |all: &[f64; PRESSURES_WITH_VOLUMES]| {
        let rates = model.pressure_rates_with_volumes(&areas, all, x_s, 0.0);
        DVector::from_iterator(active.len(), active.iter().map(|&i| rates[i]))
    };
    let scale = model.params.p_s.max(model.params.p_r);
    let mut r = residual(&all);
    for _ in 0..50 {
        if r.amax() == 0.0 {
            break;
        }
        let mut jac = DMatrix::<f64>::zeros(active.len(), active.len());
        for (c, &i) in active.iter().enumerate() {
            let mut moved = all;
            let h = 1e-7 * moved[i].abs().max(1e3);
            moved[i] += h;
            jac.set_column(c, &((residual(&moved) - &r) / h));
        }
        let delta = match jac.lu().solve(&(-&r)) {
            Some(delta) => delta,
            None => break,
        };
        // Halve the step until the imbalance falls: the start is close, but the orifice
        // law's root makes the rates steep where a restriction's pressures meet.
        let mut fraction = 1.0;
        let mut improved = None;
        for _ in 0..30 {
            let mut trial = all;
            for (k, &i) in active.iter().enumerate() {
                trial[i] += fraction * delta[k];
            }
            let r_trial = residual(&trial);
            if r_trial.amax() < r.amax() {
                improved = Some((trial, r_trial));
                break;
            }
            fraction *= 0.5;
        }
        match improved {
            Some((trial, r_trial)) => {
                let moved = (fraction * delta.amax()).abs();
                all = trial;
                r = r_trial;
                if moved < 1e-12 * scale {
                    break;
                }
            }
            None => break,
        }
    }
    let balanced = r.amax() <= 1e-3 * scale;
    if !balanced {
        return Err(format!(
            "could not balance the gas volumes behind the restrictions with the chambers at x_s = {x_s} m: pressures still change by {} Pa/s",
            r.amax()
        ));
    }
    let mut balanced = *state;
    balanced[index::P1] = all[0];
    balanced[index::P2] = all[1];
    let mut nodes = [0.0; node::STATES];
    nodes.copy_from_slice(&all[2..]);
    Ok((balanced, nodes))
}

/// The most equilibria [`modulated_equilibrium`] computes.
const MODULATED_EQUILIBRIUM_ROUNDS: usize = 50;

/// The equilibrium with the modulation and flexible slots' constants at the equilibrium's own
/// signals (time `time`, the stopper at rest; a lag has settled there, at the signal itself),
/// and the model with the constants there. A fixed point: the equilibrium of the nominal
/// constants, the slots' increments at its signals, the equilibrium again with the constants
/// so modulated, until the increments at the equilibrium's signals are those it was computed
/// with (to 1e-9 of the constant's scale, its nominal value plus its largest increment). The
/// constants that vary in time are at their values at `time`, the increments added to them.
/// An error names the slots when the increments do not settle (a modulation so steep that it
/// has no equilibrium, or several).
pub fn modulated_equilibrium(model: &Actuator, v_da: f64, x_s: f64, time: f64) -> Result<(State, Actuator), String> {
    let mut base = model.clone();
    if time_varying::varies(&model.params) {
        time_varying::set_model_at(&mut base, &model.params, time)?;
    }
    let p = &model.params;
    let constants = modulation::constants(p);
    let largest = modulation::largest_increments(p);
    let mut scales = [0.0; ALL_SLOTS];
    for k in 0..ALL_SLOTS {
        let nominal = base.params.get(constants[k]).unwrap_or(0.0).abs();
        scales[k] = 1e-9 * (nominal + largest[k]).max(f64::MIN_POSITIVE);
    }
    let mut state = equilibrium(&base, v_da, x_s)?;
    let mut at = base.clone();
    let mut used = [0.0; ALL_SLOTS];
    for _ in 0..MODULATED_EQUILIBRIUM_ROUNDS {
        let signals = super::modulated::signals_at(&base, &state, v_da, x_s, 0.0, 0.0, time);
        let next = modulation::increments(p, &signals);
        if (0..ALL_SLOTS).all(|k| (next[k] - used[k]).abs() <= scales[k]) {
            return Ok((state, at));
        }
        at = modulation::model_at(&base, &signals)?;
        state = equilibrium(&at, v_da, x_s)?;
        used = next;
    }
    Err(format!(
        "could not find the equilibrium for v_DA = {v_da} V, x_s = {x_s} m with the modulation and flexible slots (modulation_1_parameter = {}, modulation_2_parameter = {}, flexible_1_parameter = {}, flexible_2_parameter = {}): the increments at the equilibrium's signals did not settle in {MODULATED_EQUILIBRIUM_ROUNDS} rounds",
        p.modulation[0].parameter, p.modulation[1].parameter, p.flexible[0].parameter, p.flexible[1].parameter
    ))
}

#[cfg(test)]
mod tests {
    use super::super::tests::thesis_model;
    use super::super::Simulation;
    use super::*;

    #[test]
    fn equilibrium_has_zero_net_flow_and_stays_put() {
        let model = thesis_model();
        for v in [-4.0, 0.0, 1.0, 2.5, 10.0] {
            let mut sim = Simulation::at_equilibrium(model.clone(), v, 0.054, 0.0, 1e-8).unwrap();
            let flows = model.mass_flows(
                sim.state[index::JET_POSITION],
                sim.state[index::P1],
                sim.state[index::P2],
            );
            assert!(
                flows.net_1().abs() < 1e-12 && flows.net_2().abs() < 1e-12,
                "v = {v}: {flows:?}"
            );
            let before = sim.outputs();
            sim.step(1.0).unwrap();
            let after = sim.outputs();
            assert!(
                (after.f_act - before.f_act).abs() < 1e-6 * before.f_act.abs().max(1.0),
                "v = {v}: {before:?} -> {after:?}"
            );
            let p = &model.params;
            assert!(after.p1 >= p.p_r - 1.0 && after.p1 <= p.p_s + 1.0);
            assert!(after.p2 >= p.p_r - 1.0 && after.p2 <= p.p_s + 1.0);
        }
    }

    #[test]
    fn static_force_is_independent_of_stopper_position() {
        // §3.3.1: at equilibrium both net flows vanish, which fixes P1 and P2 independently
        // of the volumes.
        let model = thesis_model();
        for v in [0.5, 2.5, 6.0] {
            let f: Vec<f64> = [0.040, 0.054, 0.070]
                .iter()
                .map(|&x| {
                    Simulation::at_equilibrium(model.clone(), v, x, 0.0, 1e-8)
                        .unwrap()
                        .outputs()
                        .f_act
                })
                .collect();
            assert!(
                (f[0] - f[1]).abs() < 1e-6 && (f[2] - f[1]).abs() < 1e-6,
                "v = {v}: {f:?}"
            );
        }
    }
}
