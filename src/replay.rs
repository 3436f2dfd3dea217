//! Replaying a recording's inputs through the model: the command held between samples,
//! the stopper moving linearly between samples (MODEL.md, "Measured data").

use crate::physics::actuator::{Actuator, Outputs};
use crate::recording::Recording;
use crate::simulation::{Simulation, StepFailure};

/// The model's outputs at every sample of a recording.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Replay {
    /// The force the bench's sensor would read (`F_meas`).
    pub force: Vec<f64>,
    pub p1: Vec<f64>,
    pub p2: Vec<f64>,
    pub current: Vec<f64>,
    /// Jet pipe tip position relative to its rest position.
    pub x_jp: Vec<f64>,
    /// Work done, for progress and benchmarks.
    pub steps: u64,
}

impl Replay {
    fn with_capacity(n: usize) -> Self {
        Self {
            force: Vec::with_capacity(n),
            p1: Vec::with_capacity(n),
            p2: Vec::with_capacity(n),
            current: Vec::with_capacity(n),
            x_jp: Vec::with_capacity(n),
            steps: 0,
        }
    }

    fn record(&mut self, y: &Outputs) {
        self.force.push(y.f_meas);
        self.p1.push(y.p1);
        self.p2.push(y.p2);
        self.current.push(y.current);
        self.x_jp.push(y.x_jp);
    }
}

/// Simulate `recording` from the equilibrium of its first sample (the bench holds the
/// first command before t = 0). Samples in `0..end` only.
pub fn replay(model: &Actuator, recording: &Recording, tolerance: f64, end: usize) -> Result<Replay, String> {
    let n = end.min(recording.len());
    let mut sim = Simulation::at_equilibrium(
        model.clone(),
        recording.v_da[0],
        recording.x_s[0],
        recording.time[0],
        tolerance,
    )?;
    let mut out = Replay::with_capacity(n);
    for k in 0..n {
        let y = sim.outputs();
        out.record(&y);
        if k + 1 == n {
            break;
        }
        let dt = recording.time[k + 1] - recording.time[k];
        sim.set_command(recording.v_da[k])?;
        sim.set_stopper_rate((recording.x_s[k + 1] - recording.x_s[k]) / dt)?;
        sim.step(dt).map_err(|e| match e {
            StepFailure::InvalidRequest(m) => format!("sample {}: {m}", k + 1),
            StepFailure::Integration { message, time } => format!("sample {} (t = {time} s): {message}", k + 1),
        })?;
        // Land exactly on the recorded stopper position (no drift from rounding).
        sim.x_s = recording.x_s[k + 1];
    }
    out.steps = sim.statistics.steps;
    Ok(out)
}

/// The chamber Jacobian of the fast replay is refreshed every this many steps.
const JACOBIAN_REUSE: u64 = 8;

/// A cheaper replay for fitting: one two-stage Rosenbrock step (ROS2, L-stable, order 2;
/// Verwer et al. 1999) of the chamber pressures per sample interval, with the current
/// driver and jet pipe still propagated exactly. No error control: the sample period
/// (1 ms on the bench) is far below the chambers' time constants, and the accurate
/// replay checks the final figures. Falls back to [`replay`] when the jet pipe has no
/// modal form.
pub fn replay_fast(model: &Actuator, recording: &Recording, end: usize) -> Result<Replay, String> {
    use crate::electromechanics::{ElectromechanicalPropagator, ElectromechanicalState};
    use crate::physics::actuator::{index, State};
    use crate::physics::effects::PLAY_OPERATORS;
    use nalgebra::{Matrix2, Vector2};

    let Some(propagator) = ElectromechanicalPropagator::new(&model.params) else {
        return replay(model, recording, 1e-5, end);
    };
    let n = end.min(recording.len());
    let t = &recording.time;
    let y0 = crate::simulation::equilibrium(model, recording.v_da[0], recording.x_s[0])?;
    let mut em = ElectromechanicalState {
        current: y0[index::CURRENT],
        position: y0[index::JET_POSITION],
        velocity: y0[index::JET_VELOCITY],
        acceleration: y0[index::JET_ACCELERATION],
    };
    let mut pressures = Vector2::new(y0[index::P1], y0[index::P2]);
    let mut plays = [model.static_jet_position(em.current); PLAY_OPERATORS];
    let mut velocity = 0.0;
    let delay = model.params.command_delay;
    let gamma = 1.0 + std::f64::consts::FRAC_1_SQRT_2;
    let mut out = Replay::with_capacity(n);
    // Index of the sample whose held command the current driver sees at time `at`.
    let seen = |at: f64, hint: usize| -> usize {
        let mut j = hint;
        while j + 1 < recording.len() && t[j + 1] <= at {
            j += 1;
        }
        j
    };
    let mut source = 0usize;
    let mut jac = Matrix2::zeros();
    let mut w = Matrix2::identity();
    let mut last_h = f64::NAN;
    for k in 0..n {
        let x_s = recording.x_s[k];
        let state = State::from([
            em.current,
            em.position,
            em.velocity,
            em.acceleration,
            pressures[0],
            pressures[1],
        ]);
        let y = model.outputs(&state, x_s, velocity);
        out.record(&y);
        if k + 1 == n {
            break;
        }
        let (t0, t1) = (t[k], t[k + 1]);
        let rate = (recording.x_s[k + 1] - x_s) / (t1 - t0);
        let mut a = t0;
        while a < t1 {
            source = seen(a - delay, source);
            // The delayed command switches when the next sample's time plus the delay comes.
            let b = if delay > 0.0 && source + 1 < recording.len() {
                (t[source + 1] + delay).min(t1)
            } else {
                t1
            };
            let b = if b <= a { t1 } else { b };
            let v = if delay > 0.0 && a - delay < t[0] {
                recording.v_da[0]
            } else {
                recording.v_da[source]
            };
            let trajectory = propagator.trajectory(&em, v, 0.0, &plays);
            let h = b - a;
            let rates = |x_jp: f64, s: f64, p: &Vector2<f64>| {
                let (d1, d2) = model.pressure_rates(x_jp, p[0], p[1], x_s + rate * (a + s - t0), rate);
                Vector2::new(d1, d2)
            };
            let f = |s: f64, p: &Vector2<f64>| rates(trajectory.position(s), s, p);
            let f0 = rates(em.position, 0.0, &pressures);
            let eps = 1e-7 * h;
            let f_t = (f(eps, &pressures) - f0) / eps;
            // The Jacobian changes slowly: refresh it every few steps.
            if out.steps % JACOBIAN_REUSE == 0 || h != last_h {
                for c in 0..2 {
                    let mut q = pressures;
                    let dp = 1e-6 * q[c].abs().max(1e3);
                    q[c] += dp;
                    jac.set_column(c, &((rates(em.position, 0.0, &q) - f0) / dp));
                }
                w = (Matrix2::identity() - jac * (gamma * h))
                    .try_inverse()
                    .ok_or("singular chamber Jacobian")?;
                last_h = h;
            }
            let k1 = w * (f0 + f_t * (gamma * h));
            let k2 = w * (f(h, &(pressures + k1 * h)) - k1 * 2.0 - f_t * (gamma * h));
            pressures += k1 * (1.5 * h) + k2 * (0.5 * h);
            em = trajectory.state(h);
            plays = trajectory.plays_at(h);
            out.steps += 1;
            a = b;
        }
        velocity = rate;
    }
    Ok(out)
}
