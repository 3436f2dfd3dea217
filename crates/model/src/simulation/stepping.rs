//! Advancing a [`Simulation`] by a communication step: the constants that vary in time held at
//! mid-step, the pieces of the command the driver sees, and for each piece the split method
//! (the jet pipe's exact trajectory driving the integrated chamber pressures) or the
//! monolithic one (all six states), then the end state or the failure kept.

use nalgebra::{Const, DimMin, SVector};

use super::chambers::{ChamberSystem, ExtendedLaw, PressureLaw, ThesisLaw, VolumesLaw};
use super::monolithic::StepSystem;
use super::{ChamberMethod, ChamberRatesAtEnd, Method, Simulation, StepFailure};
use crate::electromechanics::{ElectromechanicalState, Trajectory};
use crate::integrator::{ExplicitPair, IntegrationFailure, OdeSystem, Sdirk4, Statistics, Tolerances};
use crate::physics::actuator::{index, Actuator, Outputs, RateTerms, State, N_STATES};
use crate::physics::effects::PLAY_OPERATORS;
use crate::physics::modulation::Signals;
use crate::physics::restrictions::{node, PRESSURES_WITH_VOLUMES};
use crate::physics::sensors::{Channel, SensorLaw};
use crate::physics::time_varying;

impl Simulation {
    /// How long into a step of length `step` the jet pipe's ringing still moves the
    /// pressures by more than a hundredth of the tolerance (0 if never; the whole step,
    /// without asking, if it is no longer than a ringing period and the default method
    /// integrates it). The pressure rates at the start come from `system`, which
    /// keeps them for the integrator's first stage.
    fn ringing_until<const N: usize, L: PressureLaw<N>>(
        &self,
        system: &ChamberSystem<N, L>,
        trajectory: &Trajectory,
        step: f64,
    ) -> f64 {
        let after_current_transient = step.min(5.0 / self.model.params.omega_cd);
        let amplitude = trajectory.ringing_amplitude_at_start_or(after_current_transient);
        if amplitude == 0.0 {
            return 0.0;
        }
        let (decay, period) = trajectory.ringing_decay_and_period();
        // A step of at most a period goes to Verner's pair, whose estimate holds whether or
        // not the ringing matters (see `advance`): cheaper than working out whether it does,
        // which costs the rates at a second jet pipe position.
        if self.chamber_method == ChamberMethod::NonStiffFirst && step <= period {
            return step;
        }
        let (x_jp, p1, p2) = (
            self.state[index::JET_POSITION],
            self.state[index::P1],
            self.state[index::P2],
        );
        let h = 1e-7;
        // The system's rates at the start are at the trajectory's x(0), which is x_jp to
        // rounding (an ulp, some 1e-13 of h).
        let pressures = self.pressures::<N>();
        let start = system.rhs(0.0, &pressures);
        let moved = system.rates(&self.model.areas(x_jp + h), 0.0, &pressures);
        let sensitivity = ((moved - start) / h).amax();
        // Pressure ripple ≈ ∂Ṗ/∂x · amplitude / ω_d.
        let ripple = sensitivity * amplitude * period / (2.0 * std::f64::consts::PI);
        let allowed = 0.01 * self.local_tolerance() * (self.model.state_scales()[index::P1] + p1.abs().max(p2.abs()));
        if ripple <= allowed {
            return 0.0;
        }
        let excess = ripple / allowed;
        // ln(excess) ≥ decay·step, so the ringing outlasts the step, whenever
        // excess·(1 − decay·step) ≥ 1 (e^y ≤ 1/(1 − y) for 0 ≤ y < 1): the usual answer
        // for a command that moves every step, without a call to `ln`.
        let decay_over_step = decay * step;
        if decay_over_step < 1.0 && excess * (1.0 - decay_over_step) >= 1.0 {
            return step;
        }
        (excess.ln() / decay).min(step)
    }

    /// Advance by `step` seconds.
    pub fn step(&mut self, step: f64) -> Result<(), StepFailure> {
        if self.plan.modulated {
            return self.step_modulated(step);
        }
        if !self.plan.varying_constants {
            return self.step_with_constants_held(step);
        }
        // The varying constants at mid-step, held over the step; the chambers' rates kept
        // from the last step were for the old values.
        let nominal = self.model.params.clone();
        if step.is_finite() && step > 0.0 {
            time_varying::set_model_at(&mut self.model, &nominal, self.time + 0.5 * step)
                .map_err(StepFailure::InvalidRequest)?;
        }
        self.chamber_rates_at_end = None;
        let result = self.step_with_constants_held(step);
        time_varying::reset_model(&mut self.model, &nominal);
        self.model.params = nominal;
        self.chamber_rates_at_end = None;
        result
    }

    /// [`Self::step`] with modulation or flexible slots: the signals at the step's start (the
    /// time signals at mid-step), the drifting constants at mid-step, the slots' increments
    /// added to them, all held over the step and restored after it; then the flexible slots'
    /// lags advanced over the completed step.
    fn step_modulated(&mut self, step: f64) -> Result<(), StepFailure> {
        if !(step.is_finite() && step > 0.0) {
            return self.step_with_constants_held(step);
        }
        let mid = self.time + 0.5 * step;
        let signals = self.modulation_signals(mid);
        let start = Signals {
            time: self.time,
            ..signals
        };
        let nominal = self.plan.varying_constants.then(|| self.model.params.clone());
        let mut held = Ok(None);
        if let Some(nominal) = &nominal {
            held = time_varying::set_model_at(&mut self.model, nominal, mid).map(|_| None);
        }
        if held.is_ok() {
            held = self.hold_modulated(&signals).map(Some);
        }
        let result = match held {
            Ok(held) => {
                self.chamber_rates_at_end = None;
                let result = self.step_with_constants_held(step);
                if let Some(held) = held {
                    self.release_modulated(held);
                }
                result
            }
            Err(e) => Err(StepFailure::InvalidRequest(e)),
        };
        if let Some(nominal) = nominal {
            time_varying::reset_model(&mut self.model, &nominal);
            self.model.params = nominal;
        }
        self.chamber_rates_at_end = None;
        if result.is_ok() {
            self.advance_lags(step, &start);
            // The readings at the new sample take the slots' constants at its signals, as
            // the outputs there do; the step, which held those at its start, left them.
            if self.plan.after_step && self.plan.filtering_transducers {
                self.record_transducers_at_sample();
            }
        }
        result
    }

    fn step_with_constants_held(&mut self, step: f64) -> Result<(), StepFailure> {
        if !(step.is_finite() && step > 0.0) {
            return Err(StepFailure::InvalidRequest(format!(
                "communicationStepSize = {step} s is invalid: must be finite and > 0"
            )));
        }
        let x_s_end = self.x_s + self.x_s_rate * step;
        if self.x_s_rate != 0.0 {
            self.model.params.check_stopper(x_s_end).map_err(|e| {
                StepFailure::InvalidRequest(format!(
                    "with der(x_s) = {} m/s the stopper would leave the cylinder during the step: {e}",
                    self.x_s_rate
                ))
            })?;
        }
        // Inside the step the stopper moves at its rate; the rate is the past step's after it.
        self.note_stopper_turn(self.x_s_rate);
        self.next_stopper_rate = None;
        let t_end = self.time + step;
        let segments = if self.plan.command_path {
            self.seen_command_segments(step)
        } else {
            // Without a command stage or delay the driver sees v_DA itself, in one piece.
            smallvec::smallvec![(step, self.v_da, self.v_da_rate)]
        };
        let parts = self.transducer_parts(step);
        if parts <= 1 {
            for (duration, v, v_rate) in segments {
                self.advance_or_drop_the_rates(duration, v, v_rate)?;
            }
        } else {
            self.advance_recording_transducers(step, parts, &segments)?;
        }
        self.time = t_end;
        self.x_s = x_s_end;
        self.v_da += self.v_da_rate * step;
        self.v_da_rate = 0.0;
        self.x_s_rate = 0.0;
        self.acceleration_input += self.acceleration_input_rate * step;
        self.acceleration_input_rate = 0.0;
        self.input_changed = false;
        self.stopper_velocity = (self.x_s - self.x_s_at_last_step) / step;
        if self.plan.after_step {
            self.record_after_step(step);
        }
        self.x_s_at_last_step = self.x_s;
        Ok(())
    }

    /// After a step of `step` seconds that moved the stopper linearly from
    /// `x_s_at_last_step` to `x_s`: form the stopper acceleration and record the transducers'
    /// readings, for those of the two the model has; with the slots' constants held, the
    /// readings wait for [`Self::step_modulated`] to release them.
    pub(super) fn record_after_step(&mut self, step: f64) {
        if self.plan.stopper_acceleration {
            self.stopper_acceleration = self.stopper_motion.advance(self.stopper_velocity, step);
        }
        if self.plan.filtering_transducers && !self.slots_held {
            self.record_transducers_at_sample();
        }
    }

    /// Record the transducers' readings at the simulation's time, a communication point.
    fn record_transducers_at_sample(&mut self) {
        let mut y = self.outputs_at_sample();
        self.record_transducers(&mut y, true);
    }

    /// [`Self::advance`]; on a failure the input derivatives are dropped.
    fn advance_or_drop_the_rates(&mut self, duration: f64, v: f64, v_rate: f64) -> Result<(), StepFailure> {
        self.advance(duration, v, v_rate).map_err(|failure| {
            self.v_da_rate = 0.0;
            self.x_s_rate = 0.0;
            self.acceleration_input_rate = 0.0;
            failure
        })
    }

    /// How many equal parts a step of `step` seconds is recorded in by the transducers that
    /// lag or filter: the most any of them asks for ([`SensorLaw::parts_over`]).
    pub(super) fn transducer_parts(&self, step: f64) -> usize {
        if !self.plan.filtering_transducers {
            return 1;
        }
        Channel::ALL
            .iter()
            .zip(&self.transducers)
            .filter(|(_, memory)| memory.is_some())
            .map(|(&channel, _)| SensorLaw::of(&self.model.params, channel).parts_over(step))
            .max()
            .unwrap_or(1)
    }

    /// Advance over the step's command `segments` (which span `step` seconds), recording the
    /// transducers at the ends of `parts` equal parts of it but the last (which the step's
    /// end records), the stopper at its place there and moving at the step's rate.
    fn advance_recording_transducers(
        &mut self,
        step: f64,
        parts: usize,
        segments: &[(f64, f64, f64)],
    ) -> Result<(), StepFailure> {
        let part = step / parts as f64;
        let slack = 1e-9 * step;
        // The forces the transducers read within the step take the step's own velocity; the
        // last interval's is back for the step's end, failed or not.
        let velocity = std::mem::replace(&mut self.stopper_velocity, self.x_s_rate);
        let acceleration_input = self.acceleration_input;
        let (mut elapsed, mut next_record) = (0.0, part);
        let mut result = Ok(());
        'segments: for &(duration, v, v_rate) in segments {
            let mut done = 0.0;
            while duration - done > slack {
                let piece = if duration - done <= next_record - elapsed + slack {
                    duration - done
                } else {
                    next_record - elapsed
                };
                result = self.advance_or_drop_the_rates(piece, v + v_rate * done, v_rate);
                if result.is_err() {
                    break 'segments;
                }
                done += piece;
                elapsed += piece;
                if elapsed >= next_record - slack && next_record < step - slack {
                    self.acceleration_input = acceleration_input + self.acceleration_input_rate * elapsed;
                    let mut y = self.outputs_at_sample();
                    self.record_transducers(&mut y, false);
                    next_record += part;
                }
            }
        }
        self.stopper_velocity = velocity;
        self.acceleration_input = acceleration_input;
        result
    }

    /// Record the transducers' static readings in `y` (at the simulation's time) in the
    /// memories of those that filter, and put their filtered readings in `y`. Inside a step
    /// (`at_communication_point` false) the delays do not keep the reading: they interpolate
    /// between communication points.
    pub(super) fn record_transducers(&mut self, y: &mut Outputs, at_communication_point: bool) {
        for ((memory, reading), channel) in self.transducers.iter_mut().zip(y.readings_mut()).zip(Channel::ALL) {
            if let Some(memory) = memory {
                let law = SensorLaw::of(&self.model.params, channel);
                *reading = if at_communication_point {
                    memory.record(&law, self.time, *reading)
                } else {
                    memory.record_between(&law, self.time, *reading)
                };
            }
        }
    }

    /// Integrate `duration` seconds with the command `v` + `v_rate`·s seen by the current
    /// driver; the stopper moves at `x_s_rate`.
    fn advance(&mut self, duration: f64, v: f64, v_rate: f64) -> Result<(), StepFailure> {
        let outcome = match (self.method, &self.propagator) {
            (Method::Split, Some(_)) => self.split_step(duration, v, v_rate),
            _ if self.model.has_volume_states() => {
                return Err(StepFailure::InvalidRequest(volumes_need_the_split_method(&self.model)))
            }
            _ => self.monolithic_step(duration, v, v_rate),
        };
        self.settle(outcome, duration)
    }

    /// The split method's step: the jet pipe's exact trajectory drives the chambers, whose
    /// two pressures alone are integrated.
    fn split_step(&mut self, duration: f64, v: f64, v_rate: f64) -> Result<State, IntegrationFailure<N_STATES>> {
        if self.model.has_volume_states() {
            return self.split_step_over::<PRESSURES_WITH_VOLUMES, VolumesLaw>(duration, v, v_rate);
        }
        match self.model.rate_terms() {
            RateTerms::Thesis => self.split_step_over::<2, ThesisLaw>(duration, v, v_rate),
            RateTerms::Extended => self.split_step_over::<2, ExtendedLaw>(duration, v, v_rate),
        }
    }

    /// The pressures the split method integrates: P1 and P2, then the volumes' (N = 6).
    pub(super) fn pressures<const N: usize>(&self) -> SVector<f64, N> {
        SVector::<f64, N>::from_fn(|i, _| match i {
            0 => self.state[index::P1],
            1 => self.state[index::P2],
            _ => self.nodes[i - 2],
        })
    }

    /// [`Self::split_step`] with N integrated pressures.
    fn split_step_over<const N: usize, L: PressureLaw<N>>(
        &mut self,
        duration: f64,
        v: f64,
        v_rate: f64,
    ) -> Result<State, IntegrationFailure<N_STATES>>
    where
        Const<N>: DimMin<Const<N>, Output = Const<N>>,
    {
        let t0 = self.time;
        let propagator = self.propagator.as_ref().expect("the split method has a propagator");
        let trajectory = propagator.trajectory(&self.electromechanical_state(), v, v_rate, &self.plays);
        let pressures = self.pressures::<N>();
        let start_position = self.state[index::JET_POSITION];
        // The rates kept from the last step are the chambers' alone.
        let known_rates = self.known_chamber_rates().filter(|_| N == 2).map(|end| {
            (
                SVector::<f64, N>::from_fn(|i, _| end.pressures[i]),
                SVector::<f64, N>::from_fn(|i, _| end.rates[i]),
            )
        });
        let system = ChamberSystem::<N, L>::new(
            &self.model,
            &trajectory,
            &self.stage_areas,
            duration,
            start_position,
            known_rates,
            self.x_s,
            self.x_s_rate,
        );
        let scale = self.model.state_scales();
        let tolerances = Tolerances {
            relative: self.local_tolerance(),
            absolute: SVector::<f64, N>::repeat(scale[index::P1] * self.local_tolerance()),
        };
        let combine = |s: f64, p: SVector<f64, N>| {
            let em = trajectory.state(s);
            State::from([em.current, em.position, em.velocity, em.acceleration, p[0], p[1]])
        };
        let ringing_until = self.ringing_until(&system, &trajectory, duration);
        let changed = self.input_changed || v_rate != 0.0 || self.x_s_rate != 0.0;
        if changed {
            self.chamber_integrator.next_step = self.chamber_integrator.next_step.min(2.0 * self.step_after_change);
        }
        let result = integrate_chambers(
            &mut self.chamber_integrator,
            &mut self.statistics,
            self.chamber_method,
            &system,
            &tolerances,
            pressures,
            duration,
            ringing_until,
        );
        if changed {
            self.step_after_change = self.chamber_integrator.first_step;
        }
        if self.plan.hysteresis {
            let reached = match &result {
                Ok(_) => duration,
                Err(f) => f.time,
            };
            let plays = trajectory.plays_at(reached);
            if plays.iter().all(|p| p.is_finite()) {
                self.plays = plays;
            }
        }
        self.chamber_rates_at_end = None;
        match result {
            Ok(p) => {
                let mut end = combine(duration, p);
                // The position the chambers' last stage saw (the trajectory's own value at
                // the end agrees to rounding): with it the state is the last stage's, and its
                // rates are the next step's at its start.
                if let Some((x_jp, pressures, rates)) = system.end_rates.get().filter(|(_, q, _)| *q == p) {
                    end[index::JET_POSITION] = x_jp;
                    if N == 2 {
                        self.chamber_rates_at_end = Some(ChamberRatesAtEnd {
                            x_jp,
                            pressures: SVector::<f64, 2>::new(pressures[0], pressures[1]),
                            x_s: self.x_s + self.x_s_rate * duration,
                            x_s_rate: self.x_s_rate,
                            rates: SVector::<f64, 2>::new(rates[0], rates[1]),
                        });
                    }
                }
                keep_nodes(&mut self.nodes, &p);
                Ok(end)
            }
            Err(f) if f.state.iter().all(|v| v.is_finite()) => {
                keep_nodes(&mut self.nodes, &f.state);
                Err(IntegrationFailure {
                    message: f.message,
                    time: t0 + f.time,
                    state: combine(f.time, f.state),
                })
            }
            Err(f) => Err(IntegrationFailure {
                message: f.message,
                time: t0 + f.time,
                state: combine(f.time, f.state),
            }),
        }
    }

    /// The monolithic method's step: all six states integrated together.
    fn monolithic_step(&mut self, duration: f64, v: f64, v_rate: f64) -> Result<State, IntegrationFailure<N_STATES>> {
        let t0 = self.time;
        let system = StepSystem {
            model: &self.model,
            t0,
            v_da: v,
            v_da_rate: v_rate,
            x_s: self.x_s,
            x_s_rate: self.x_s_rate,
            plays: self.hysteresis_plays(),
        };
        let tolerances = self.tolerances();
        let result = self.integrator.integrate(
            &system,
            t0,
            self.state,
            t0 + duration,
            &tolerances,
            &mut self.statistics,
        );
        if self.plan.hysteresis {
            // Plays follow the static position monotonically within the step.
            let y = match &result {
                Ok(y) => *y,
                Err(f) => f.state,
            };
            let x_bar = self.model.static_jet_position(y[index::CURRENT]);
            self.model.hysteresis.advance(&mut self.plays, x_bar);
        }
        result
    }

    /// Take a step's end state, or on a failure its last accepted one with the inputs moved
    /// on as far.
    fn settle(
        &mut self,
        outcome: Result<State, IntegrationFailure<N_STATES>>,
        duration: f64,
    ) -> Result<(), StepFailure> {
        match outcome {
            Ok(y) => {
                self.state = y;
                self.time += duration;
                self.x_s += self.x_s_rate * duration;
                Ok(())
            }
            Err(failure) if failure.state.iter().all(|v| v.is_finite()) => {
                let elapsed = failure.time - self.time;
                self.state = failure.state;
                self.v_da += self.v_da_rate * elapsed;
                self.x_s += self.x_s_rate * elapsed;
                self.time = failure.time;
                Err(StepFailure::Integration {
                    message: format!("at t = {} s: {}", failure.time, failure.message),
                    time: failure.time,
                })
            }
            // Never keep a non-finite state: stay where the step started.
            Err(failure) => Err(StepFailure::Integration {
                message: failure.message,
                time: self.time,
            }),
        }
    }

    /// The chambers' rates at the last step's end when the next step starts where they
    /// were taken: same jet pipe position, pressures and stopper motion.
    fn known_chamber_rates(&self) -> Option<ChamberRatesAtEnd> {
        self.chamber_rates_at_end.filter(|end| {
            end.x_jp == self.state[index::JET_POSITION]
                && end.pressures == SVector::<f64, 2>::new(self.state[index::P1], self.state[index::P2])
                && end.x_s == self.x_s
                && end.x_s_rate == self.x_s_rate
        })
    }

    /// The current driver's and jet pipe's part of the state.
    pub(super) fn electromechanical_state(&self) -> ElectromechanicalState {
        ElectromechanicalState {
            current: self.state[index::CURRENT],
            position: self.state[index::JET_POSITION],
            velocity: self.state[index::JET_VELOCITY],
            acceleration: self.state[index::JET_ACCELERATION],
        }
    }

    fn hysteresis_plays(&self) -> Option<[f64; PLAY_OPERATORS]> {
        self.model.hysteresis.is_active().then_some(self.plays)
    }
}

/// Integrate the chambers over a step of `duration`. While the jet pipe rings (until
/// `ringing_until`), the explicit pairs' steps are capped by its period.
#[allow(clippy::too_many_arguments)]
fn integrate_chambers<const N: usize, L: PressureLaw<N>>(
    integrator: &mut Sdirk4,
    statistics: &mut Statistics,
    method: ChamberMethod,
    system: &ChamberSystem<N, L>,
    tolerances: &Tolerances<N>,
    pressures: SVector<f64, N>,
    duration: f64,
    ringing_until: f64,
) -> Result<SVector<f64, N>, IntegrationFailure<N>>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    let integrate = |integrator: &mut Sdirk4,
                     pair: ExplicitPair,
                     from: f64,
                     p: SVector<f64, N>,
                     to: f64,
                     statistics: &mut Statistics| match method {
        ChamberMethod::NonStiffFirst | ChamberMethod::DormandPrinceOnly => {
            integrator.integrate_nonstiff_first(pair, system, from, p, to, tolerances, statistics)
        }
        ChamberMethod::Sdirk4 => integrator.integrate(system, from, p, to, tolerances, statistics),
    };
    if ringing_until > 0.0 {
        // While the jet pipe rings enough to matter, Dormand–Prince's steps stay below a
        // quarter of its period: a longer step samples the 295 Hz forcing too sparsely for its
        // embedded estimate to notice what it misses. Verner's estimate holds up to a whole
        // period, so a ringing stretch longer than the cap and at most a period takes Verner's
        // steps, as long as its error allows: the chirp's 1 ms inputs (0.85 ms and the rest
        // under the cap) take one, 8 right-hand sides, not 12; the closed loop's 2 ms about
        // two, where the current's transient sets the size.
        let (_, period) = system.trajectory.ringing_decay_and_period();
        let quarter = 0.25 * period;
        let (pair, cap) =
            if method == ChamberMethod::NonStiffFirst && ringing_until > quarter && ringing_until <= 4.0 * quarter {
                (ExplicitPair::Verner, period)
            } else {
                (ExplicitPair::DormandPrince, quarter)
            };
        let unlimited = integrator.max_step;
        integrator.max_step = cap.min(unlimited);
        let first = integrate(integrator, pair, 0.0, pressures, ringing_until, statistics);
        integrator.max_step = unlimited;
        match first {
            Ok(p) if ringing_until < duration => integrate(
                integrator,
                ExplicitPair::DormandPrince,
                ringing_until,
                p,
                duration,
                statistics,
            ),
            other => other,
        }
    } else {
        integrate(
            integrator,
            ExplicitPair::DormandPrince,
            0.0,
            pressures,
            duration,
            statistics,
        )
    }
}

/// Keep the volumes' pressures of an integrated pressure vector (entries 2.. of N = 6).
pub(super) fn keep_nodes<const N: usize>(nodes: &mut [f64; node::STATES], p: &SVector<f64, N>) {
    for i in 2..N {
        nodes[i - 2] = p[i];
    }
}

/// Why a model with gas volumes or a lagging stopper mount cannot take a monolithic step.
pub(super) fn volumes_need_the_split_method(model: &Actuator) -> String {
    let p = &model.params;
    format!(
        "the gas volumes behind restrictions (supply_plenum_volume = {} m3, return_plenum_volume = {} m3, port_line_volume_1 = {} m3, port_line_volume_2 = {} m3) and the stopper mount's lag (stopper_mount_lag = {} s) are integrated by the split method only, which needs a jet pipe with two distinct eigenvalues (zeta_2 = {} must be < 1)",
        p.supply_plenum_volume, p.return_plenum_volume, p.port_line_volume_1, p.port_line_volume_2, p.stopper_mount_lag, p.zeta_2
    )
}

#[cfg(test)]
mod tests {
    use super::super::tests::{thesis_model, with};
    use super::*;
    use crate::simulation::DEFAULT_RELATIVE_TOLERANCE;

    #[test]
    fn results_do_not_depend_on_the_communication_step() {
        let model = thesis_model();
        let command = |t: f64| 2.5 + 3.0 * (2.0 * std::f64::consts::PI * 0.3 * t).sin();
        let run = |substeps: usize| {
            let mut sim =
                Simulation::at_equilibrium(model.clone(), command(0.0), 0.054, 0.0, DEFAULT_RELATIVE_TOLERANCE)
                    .unwrap();
            let mut forces = vec![];
            for k in 0..100 {
                sim.set_command(command(0.01 * k as f64)).unwrap();
                for _ in 0..substeps {
                    sim.step(0.01 / substeps as f64).unwrap();
                }
                forces.push(sim.outputs().f_act);
            }
            forces
        };
        let coarse = run(1);
        let fine = run(100);
        let worst = coarse.iter().zip(&fine).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(worst < 1e-4, "max |ΔF| = {worst} N");
    }

    #[test]
    fn split_and_monolithic_methods_agree() {
        // The exact jet pipe propagation plus chamber integration against the six-state
        // SDIRK4 on the same inputs, including big command jumps and stopper motion, with
        // and without the hysteresis operator (closed-form and quadrature paths).
        for model in [thesis_model(), with(|p| p.hysteresis_width = 0.16e-3)] {
            let run = |method: Method| {
                let mut sim = Simulation::at_equilibrium(model.clone(), 0.0, 0.054, 0.0, 1e-8).unwrap();
                sim.method = method;
                let mut forces = vec![];
                for k in 0..60 {
                    let (v, x) = crate::scenario::standard_inputs(k);
                    sim.set_command(if k % 20 == 10 { 10.0 } else { v }).unwrap();
                    sim.set_stopper(x).unwrap();
                    sim.set_stopper_rate(if k % 7 == 3 { 0.05 } else { 0.0 }).unwrap();
                    sim.step(0.01).unwrap();
                    forces.push((sim.outputs().f_act, sim.state[index::JET_POSITION]));
                }
                forces
            };
            let split = run(Method::Split);
            let monolithic = run(Method::Monolithic);
            for (k, (a, b)) in split.iter().zip(&monolithic).enumerate() {
                assert!((a.0 - b.0).abs() < 1e-5, "sample {k}: F {} vs {}", a.0, b.0);
                assert!((a.1 - b.1).abs() < 1e-10, "sample {k}: x_jp {} vs {}", a.1, b.1);
            }
        }
    }

    /// Runs 0.6 s of the standard inputs with commands jumping to ±10 V every 0.1 s (the jet
    /// pipe then swings across tangencies of the orifice geometry) with a chamber method.
    fn forces_with(chamber_method: ChamberMethod, relative_tolerance: f64) -> (Vec<f64>, Statistics) {
        let mut sim = Simulation::at_equilibrium(thesis_model(), 2.5, 0.054, 0.0, relative_tolerance).unwrap();
        sim.chamber_method = chamber_method;
        let mut forces = vec![];
        for k in 0..60 {
            let (v, x) = crate::scenario::standard_inputs(k);
            let v = match k % 20 {
                5 => 10.0,
                15 => -10.0,
                _ => v,
            };
            sim.set_command(v).unwrap();
            sim.set_stopper(x).unwrap();
            sim.step(0.01).unwrap();
            forces.push(sim.outputs().f_act);
        }
        (forces, sim.statistics)
    }

    #[test]
    fn explicit_chamber_steps_match_sdirk4_without_its_newton_iterations() {
        let (reference, _) = forces_with(ChamberMethod::Sdirk4, 1e-10);
        for rtol in [1e-6, 1e-8] {
            let (explicit, work) = forces_with(ChamberMethod::NonStiffFirst, rtol);
            let (implicit, implicit_work) = forces_with(ChamberMethod::Sdirk4, rtol);
            let error = |f: &[f64]| f.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
            // The tolerance times the force scale (up to ~70 N here).
            assert!(
                error(&explicit) < 100.0 * rtol,
                "rtol {rtol}: explicit error {}",
                error(&explicit)
            );
            assert!(
                error(&implicit) < 100.0 * rtol,
                "rtol {rtol}: SDIRK4 error {}",
                error(&implicit)
            );
            assert_eq!(work.jacobians, 0, "{work:?}");
            assert_eq!(work.stiff_handovers, 0, "{work:?}");
            assert!(
                work.rhs_evaluations < implicit_work.rhs_evaluations,
                "{work:?} vs {implicit_work:?}"
            );
        }
    }

    /// The chirp's situation: inputs held for 1 ms, each re-exciting the ringing. Dormand–
    /// Prince's cap (0.85 ms) cuts each into two steps; one Verner step takes it, with fewer
    /// right-hand sides and a smaller error (here 8.3e-3 against 1.4e-2 Pa).
    #[test]
    fn ringing_millisecond_inputs_take_one_verner_step_each() {
        let run = |method: ChamberMethod, relative_tolerance: f64| {
            let mut sim = Simulation::at_equilibrium(thesis_model(), 2.5, 0.054, 0.0, relative_tolerance).unwrap();
            sim.chamber_method = method;
            let mut pressures = vec![];
            for k in 0..200 {
                let v = 2.5 + 1.5 * (2.0 * std::f64::consts::PI * 15.0 * k as f64 * 1e-3).sin();
                sim.set_command(v).unwrap();
                sim.step(1e-3).unwrap();
                pressures.push([sim.state[index::P1], sim.state[index::P2]]);
            }
            (pressures, sim.statistics)
        };
        let (reference, _) = run(ChamberMethod::NonStiffFirst, 1e-10);
        let error = |p: &[[f64; 2]]| {
            p.iter()
                .zip(&reference)
                .map(|(a, b)| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()))
                .fold(0.0, f64::max)
        };
        let (verner, verner_work) = run(ChamberMethod::NonStiffFirst, 1e-6);
        let (capped, capped_work) = run(ChamberMethod::DormandPrinceOnly, 1e-6);
        // A few inputs (where the sine turns, the ringing matters for less than the cap)
        // stay with Dormand–Prince: 224 steps here, against 410.
        assert!(verner_work.steps < 240, "{verner_work:?}");
        assert!(capped_work.steps >= 400, "{capped_work:?}");
        assert!(
            verner_work.rhs_evaluations * 5 < capped_work.rhs_evaluations * 4,
            "{verner_work:?} vs {capped_work:?}"
        );
        let (e_verner, e_capped) = (error(&verner), error(&capped));
        assert!(e_verner < 0.75 * e_capped, "Verner {e_verner} Pa, capped {e_capped} Pa");
        assert!(e_verner < 0.1, "{e_verner} Pa");
    }

    #[test]
    fn rates_at_a_step_end_are_the_next_steps_rates_at_its_start() {
        // Held stopper, then a moving one, then a jump: a millisecond chirp-like command.
        let run = |forget: bool| {
            let mut sim = Simulation::at_equilibrium(thesis_model(), 2.5, 0.054, 0.0, 1e-6).unwrap();
            let mut states = vec![];
            let mut reused = 0;
            for k in 0..60 {
                sim.set_command(2.5 + 1.5 * (k as f64 * 0.3).sin()).unwrap();
                if (20..30).contains(&k) {
                    sim.set_stopper_rate(0.05).unwrap();
                }
                if k == 40 {
                    sim.set_stopper(0.05).unwrap();
                }
                if forget {
                    sim.chamber_rates_at_end = None;
                }
                reused += usize::from(sim.known_chamber_rates().is_some());
                sim.step(1e-3).unwrap();
                states.push(sim.state);
                let end = sim.chamber_rates_at_end.expect("every step ends with its last stage");
                // What was kept is the rate function at what it is keyed on, and that key is
                // the state the step ended in.
                let (a, b) =
                    sim.model
                        .pressure_rates(end.x_jp, end.pressures[0], end.pressures[1], end.x_s, end.x_s_rate);
                assert_eq!(end.rates, SVector::<f64, 2>::new(a, b));
                assert_eq!(end.x_jp, sim.state[index::JET_POSITION]);
                assert_eq!(
                    end.pressures,
                    SVector::<f64, 2>::new(sim.state[index::P1], sim.state[index::P2])
                );
                assert_eq!(end.x_s, sim.x_s);
            }
            (states, reused)
        };
        let (with, reused) = run(false);
        let (without, none) = run(true);
        // A memo: the results are the same to the last bit.
        assert_eq!(with, without);
        assert_eq!(none, 0);
        // Every step but the first reuses them, except where the stopper starts moving
        // (step 20), stops (30) and jumps (40).
        assert_eq!(reused, 56);
    }

    #[test]
    fn stiff_chambers_are_handed_over_to_sdirk4() {
        // The stopper a hair from the top: chamber 1 is nearly empty, and its pressure time
        // constant far below the step the jet pipe allows.
        let model = thesis_model();
        let (lo, hi) = model.params.cylinder().stopper_range();
        let x_s = lo + 1e-5 * (hi - lo);
        let run = |method: ChamberMethod, rtol: f64| {
            let mut sim = Simulation::at_equilibrium(model.clone(), 2.5, x_s, 0.0, rtol).unwrap();
            sim.chamber_method = method;
            for k in 0..20 {
                sim.set_command(if k % 2 == 0 { 4.0 } else { 1.0 }).unwrap();
                sim.step(0.01).unwrap();
            }
            (sim.state[index::P1], sim.state[index::P2], sim.statistics)
        };
        let (p1, p2, work) = run(ChamberMethod::NonStiffFirst, 1e-6);
        let (q1, q2, _) = run(ChamberMethod::Sdirk4, 1e-10);
        assert!(work.stiff_handovers > 0, "{work:?}");
        assert!(
            (p1 - q1).abs() < 1e-5 * q1 && (p2 - q2).abs() < 1e-5 * q2,
            "{p1} {p2} vs {q1} {q2}"
        );
    }

    #[test]
    fn the_monolithic_method_refuses_volumes_by_name() {
        let model = with(|p| {
            p.supply_resistance = 3e8;
            p.supply_plenum_volume = 2e-6;
        });
        let mut sim = Simulation::at_equilibrium(model, 2.5, 0.054, 0.0, 1e-6).unwrap();
        sim.set_method(Method::Monolithic);
        match sim.step(1e-3) {
            Err(StepFailure::InvalidRequest(e)) => {
                assert!(
                    e.contains("supply_plenum_volume = 0.000002") && e.contains("split"),
                    "{e}"
                )
            }
            other => panic!("{other:?}"),
        }
        let without_modal_form = with(|p| {
            p.zeta_2 = 1.5;
            p.port_resistance_2 = 1e8;
            p.port_line_volume_2 = 1e-6;
        });
        let e = Simulation::at_equilibrium(without_modal_form, 2.5, 0.054, 0.0, 1e-6).unwrap_err();
        assert!(
            e.contains("port_line_volume_2 = 0.000001") && e.contains("zeta_2 = 1.5"),
            "{e}"
        );
    }
}
