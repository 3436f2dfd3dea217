//! The state a simulation starts from: the electromechanics at their static values and the
//! chamber pressures at which both net mass flows vanish (§3.3.1), found by a
//! pseudo-transient run polished by Newton's method, which converges from any start.

use nalgebra::SVector;

use super::monolithic::StepSystem;
use crate::integrator::{Sdirk4, Statistics, Tolerances};
use crate::physics::actuator::{index, Actuator, State};
use crate::physics::command_stage;
use crate::physics::current_driver;
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

/// [`equilibrium`] with the constants that vary in time at their values at `time`.
pub fn equilibrium_at(model: &Actuator, v_da: f64, x_s: f64, time: f64) -> Result<State, String> {
    if !time_varying::varies(&model.params) {
        return equilibrium(model, v_da, x_s);
    }
    let mut at = model.clone();
    time_varying::set_at(&mut at.params, &model.params, time)?;
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
