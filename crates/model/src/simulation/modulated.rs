//! The modulation and flexible slots ([`crate::physics::modulation`],
//! [`crate::physics::flexible`]) in a simulation: the signals at a sample, the slots'
//! constants held over a step (with the propagator rebuilt when they are the current driver's
//! or the jet pipe's) and released after it, the flexible slots' lags advanced after it, and
//! the outputs at a sample with the constants at its signals.

use super::Simulation;
use crate::electromechanics::ElectromechanicalPropagator;
use crate::physics::actuator::{index, Actuator, Outputs, State};
use crate::physics::flexible::{self, FLEXIBLE_SLOTS};
use crate::physics::modulation::{self, Held, Signals};

/// What [`Simulation::hold_modulated`] changed, for [`Simulation::release_modulated`].
pub(super) struct HeldModulation {
    constants: Held,
    /// The simulation's own propagator, when the step has one of its own, and the
    /// constants of the step's.
    propagator: Option<(Option<ElectromechanicalPropagator>, [f64; 9])>,
}

/// A propagator and the current driver's and jet pipe's constants it was built from.
#[derive(Clone, Debug)]
pub(super) struct PropagatorOf {
    constants: [f64; 9],
    propagator: ElectromechanicalPropagator,
}

/// The constants [`ElectromechanicalPropagator::new`] reads that a slot may modulate.
fn electromechanical_constants(p: &crate::physics::parameters::Parameters) -> [f64; 9] {
    [
        p.k_cd, p.i_offset, p.omega_cd, p.k_m, p.omega_1, p.omega_2, p.zeta_2, p.x_jp_sat, p.f_jp_sat,
    ]
}

/// The signals of the chain at a sample: `state`, the command, the stopper and its motion as
/// the outputs there read them, and the force F_act of the nominal constants (formed only
/// when a slot follows it).
#[allow(clippy::too_many_arguments)]
pub(super) fn signals_at(
    model: &Actuator,
    state: &State,
    v_da: f64,
    x_s: f64,
    stopper_velocity: f64,
    stopper_acceleration: f64,
    time: f64,
) -> Signals {
    let f_act = if modulation::follows_the_force(&model.params) {
        model
            .outputs_in_motion(state, x_s, stopper_velocity, stopper_acceleration, time)
            .f_act
    } else {
        0.0
    };
    Signals {
        lagged: None,
        time,
        v_da,
        current: state[index::CURRENT],
        x_jp: state[index::JET_POSITION],
        x_s,
        stopper_velocity,
        f_act,
        p1: state[index::P1],
        p2: state[index::P2],
    }
}

/// [`Actuator::outputs_in_motion`] with the slots' constants at the sample's signals, the
/// flexible slots' lagged ones `lagged` (the raw signals for `None`): the nominal outputs when
/// no slot modulates a constant the outputs read, or when the constants at these signals are
/// refused, which a step from here reports.
#[allow(clippy::too_many_arguments)]
pub(super) fn outputs_in_motion(
    model: &Actuator,
    state: &State,
    x_s: f64,
    stopper_velocity: f64,
    stopper_acceleration: f64,
    time: f64,
    v_da: f64,
    lagged: Option<[[f64; 2]; FLEXIBLE_SLOTS]>,
) -> Outputs {
    if modulation::modulates_outputs(&model.params) {
        let mut signals = signals_at(model, state, v_da, x_s, stopper_velocity, stopper_acceleration, time);
        signals.lagged = lagged;
        if let Ok(at) = modulation::model_at(model, &signals) {
            return at.outputs_in_motion(state, x_s, stopper_velocity, stopper_acceleration, time);
        }
    }
    model.outputs_in_motion(state, x_s, stopper_velocity, stopper_acceleration, time)
}

impl Simulation {
    /// The signals at the last sample, the time signals at `time`, with the flexible slots'
    /// lag state where they lag.
    pub(super) fn modulation_signals(&self, time: f64) -> Signals {
        let mut signals = signals_at(
            &self.model,
            &self.state,
            self.v_da,
            self.x_s,
            self.stopper_velocity_at_sample(),
            self.acceleration_read(),
            time,
        );
        signals.lagged = self.lags();
        signals
    }

    /// The flexible slots' lag state, when one lags.
    fn lags(&self) -> Option<[[f64; 2]; FLEXIBLE_SLOTS]> {
        self.plan.lagged.then_some(self.flexible_lags)
    }

    /// After a completed step of `step` seconds that started at the signals `start` (the time
    /// signals at the step's start), with the model's constants nominal again: the flexible
    /// slots' lags advanced to the signals at the new sample, as the outputs there read them.
    pub(super) fn advance_lags(&mut self, step: f64, start: &Signals) {
        if self.plan.lagged {
            let end = self.modulation_signals(self.time);
            flexible::advance_lags(&self.model.params, &mut self.flexible_lags, step, start, &end);
        }
    }

    /// The slots' constants set at `signals` for a step, with the propagator of those
    /// constants when they are the current driver's or the jet pipe's.
    pub(super) fn hold_modulated(&mut self, signals: &Signals) -> Result<HeldModulation, String> {
        let constants = modulation::apply(&mut self.model, signals)?;
        let propagator = if self.propagator.is_some() && modulation::modulates_electromechanics(&self.model.params) {
            // The last step's when its constants are these (a signal beyond the end knots, a
            // constant increment): building one costs about three fixed steps.
            let key = electromechanical_constants(&self.model.params);
            let kept = self
                .modulated_propagator
                .take()
                .filter(|kept| kept.constants == key)
                .map(|kept| kept.propagator);
            match kept.or_else(|| ElectromechanicalPropagator::new(&self.model.params)) {
                Some(rebuilt) => Some((self.propagator.replace(rebuilt), key)),
                None => {
                    modulation::restore(&mut self.model, constants);
                    return Err(format!(
                        "the modulation slots give the jet pipe no modal form at t = {} s (zeta_2 >= 1)",
                        signals.time
                    ));
                }
            }
        } else {
            None
        };
        if self.plan.moving_piston {
            self.carry_air_to_held_piston_place();
        }
        self.chamber_rates_at_end = None;
        self.slots_held = true;
        Ok(HeldModulation { constants, propagator })
    }

    /// The chambers' pressures after the piston moves from the stopper's offset L_sup the last
    /// step held to the one the model holds now: the same jump as the stopper's by the
    /// difference, the air in each chamber conserved
    /// ([`Actuator::pressures_after_stopper_jump`]; L_sup larger is the stopper nearer, the
    /// piston's position x_s − L_p − L_s − L_sup).
    fn carry_air_to_held_piston_place(&mut self) {
        let now = self.model.cylinder.l_sup;
        let before = std::mem::replace(&mut self.held_piston_place, now);
        if before == now {
            return;
        }
        let (p1, p2) = (self.state[index::P1], self.state[index::P2]);
        let mount = self.stopper_mount_state().unwrap_or(0.0);
        // With the offset now, the stopper at x_s + (now − before) puts the piston where the
        // offset before put it at x_s.
        let [p1, p2] = self
            .model
            .pressures_after_stopper_jump(p1, p2, mount, self.x_s + (now - before), self.x_s);
        self.state[index::P1] = p1;
        self.state[index::P2] = p2;
    }

    /// Undo [`Self::hold_modulated`].
    pub(super) fn release_modulated(&mut self, held: HeldModulation) {
        modulation::restore(&mut self.model, held.constants);
        self.slots_held = false;
        if let Some((own, constants)) = held.propagator {
            if let Some(propagator) = std::mem::replace(&mut self.propagator, own) {
                self.modulated_propagator = Some(PropagatorOf { constants, propagator });
            }
        }
        self.chamber_rates_at_end = None;
    }

    /// The outputs at the last sample (the transducers' static readings), with the slots'
    /// constants at its signals; within a step, with those the step holds.
    pub(super) fn outputs_at_sample(&self) -> Outputs {
        let (velocity, acceleration) = (self.stopper_velocity_at_sample(), self.acceleration_read());
        if !self.plan.modulated_outputs || self.slots_held {
            return self
                .model
                .outputs_in_motion(&self.state, self.x_s, velocity, acceleration, self.time);
        }
        outputs_in_motion(
            &self.model,
            &self.state,
            self.x_s,
            velocity,
            acceleration,
            self.time,
            self.v_da,
            self.lags(),
        )
    }
}
