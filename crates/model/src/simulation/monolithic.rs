//! The whole actuator model as one system of six states for the SDIRK4 integrator, with
//! the inputs linear in time over the step: the monolithic method (kept for comparison and
//! for a jet pipe without a modal form) and the equilibrium's pseudo-transient run.

use crate::integrator::OdeSystem;
use crate::physics::actuator::{Actuator, Inputs, Jacobian, State, N_STATES};
use crate::physics::effects::PLAY_OPERATORS;

/// The actuator model over one step, with inputs linear in time from `t0`.
pub(super) struct StepSystem<'a> {
    pub(super) model: &'a Actuator,
    pub(super) t0: f64,
    pub(super) v_da: f64,
    pub(super) v_da_rate: f64,
    pub(super) x_s: f64,
    pub(super) x_s_rate: f64,
    pub(super) plays: Option<[f64; PLAY_OPERATORS]>,
}

impl StepSystem<'_> {
    pub(super) fn inputs(&self, t: f64) -> Inputs {
        let dt = t - self.t0;
        Inputs {
            v_da: self.v_da + self.v_da_rate * dt,
            x_s: self.x_s + self.x_s_rate * dt,
            x_s_rate: self.x_s_rate,
            plays: self.plays,
        }
    }
}

impl OdeSystem<N_STATES> for StepSystem<'_> {
    fn rhs(&self, t: f64, y: &State) -> State {
        self.model.derivatives(y, &self.inputs(t))
    }
    fn jacobian(&self, t: f64, y: &State, f_y: &State) -> Jacobian {
        self.model.jacobian(y, &self.inputs(t), f_y)
    }
}
