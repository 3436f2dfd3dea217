//! Stepping the actuator between communication points: the one driver used by the FMU,
//! the command-line tool and the tests.
//!
//! Inputs are held over a step, or move linearly when a first-order derivative is given
//! for the step. A stopper position set without a derivative is a jump at the
//! communication point: the air in each chamber is conserved and the pressures follow
//! the exact no-flow limit of (2.29), P V^γ = const, so no spike comes from differencing.
//!
//! This file holds [`Simulation`] and its stepping: inputs, command segments, the choice
//! between the split and the monolithic method, and the integrators' hand-overs. What a step
//! integrates lives apart: `chambers` (the two pressures driven by the jet pipe's exact
//! trajectory, for the split method), `monolithic` (all six states) and `equilibrium` (the
//! state a simulation starts from).

mod chambers;
mod equilibrium;
mod fixed_step;
mod monolithic;
mod snapshot;

pub use equilibrium::{balance_with_volumes, equilibrium, equilibrium_at, equilibrium_of_electromechanics};
pub use fixed_step::FixedStep;
pub use snapshot::{SimulationSnapshot, SNAPSHOT_LAYOUT};

use nalgebra::{Const, DimMin, SVector};

use self::chambers::ChamberSystem;
use self::monolithic::StepSystem;
use crate::electromechanics::{ElectromechanicalPropagator, ElectromechanicalState, Trajectory};
use crate::integrator::{ExplicitPair, IntegrationFailure, OdeSystem, Sdirk4, Statistics, Tolerances};
use crate::physics::actuator::{index, Actuator, Outputs, State, N_STATES};
use crate::physics::chambers::pressure_after_volume_jump;
use crate::physics::command_stage::{self, CommandStage};
use crate::physics::effects::PLAY_OPERATORS;
use crate::physics::restrictions::{node, PRESSURES_WITH_VOLUMES};
use crate::physics::sensors::{Channel, SensorLaw, SensorMemory};
use crate::physics::time_varying;

/// The default relative tolerance (also the model description's default experiment).
pub const DEFAULT_RELATIVE_TOLERANCE: f64 = 1e-6;

/// The integrators keep each step's local error below this fraction of the relative
/// tolerance. Global errors exceed local ones, most where chamber pressures cross (the
/// √Δp flow law is steep there); a tenth holds the standard scenario's global force error
/// well below the tolerance times the force (7e-6 N at 1e-6, measured against a 1e-10 run).
pub const LOCAL_ERROR_FRACTION: f64 = 0.1;

/// How a step is integrated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Current driver and jet pipe propagated exactly (the private `electromechanics`); only
    /// the two chamber pressures are integrated, with error control on them.
    Split,
    /// All six states with the SDIRK4 integrator (kept for comparison, and used when the
    /// jet pipe has no modal form, e.g. ζ2 ≥ 1).
    Monolithic,
}

/// How the split method integrates the two chamber pressures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChamberMethod {
    /// Dormand–Prince 5(4) while the chambers are not stiff (Verner's 6(5) for a ringing
    /// stretch longer than Dormand–Prince's quarter-period cap and at most a period), SDIRK4 from where
    /// they become so to the end of the communication step. The chambers' own time constants
    /// are 3 ms and slower in the standard scenarios, so this is the default: no Newton
    /// iterations.
    NonStiffFirst,
    /// [`ChamberMethod::NonStiffFirst`] with Dormand–Prince for every explicit step, capped at
    /// a quarter of the ringing period while the jet pipe rings (the default until Verner's
    /// pair took the stretches the cap cuts in two; kept for comparison).
    DormandPrinceOnly,
    /// SDIRK4 throughout (kept for comparison).
    Sdirk4,
}

/// Why a step failed.
#[derive(Clone, Debug, PartialEq)]
pub enum StepFailure {
    /// The request is invalid; nothing changed.
    InvalidRequest(String),
    /// The integrator gave up; the simulation holds the last accepted state at `time`.
    Integration { message: String, time: f64 },
}

/// A running simulation of one actuator.
#[derive(Clone, Debug)]
pub struct Simulation {
    model: Actuator,
    time: f64,
    state: State,
    v_da: f64,
    x_s: f64,
    /// First-order input derivatives for the next step only (cleared after it).
    v_da_rate: f64,
    x_s_rate: f64,
    relative_tolerance: f64,
    method: Method,
    chamber_method: ChamberMethod,
    /// Step-size memory of the six-state integrator (monolithic method).
    integrator: Sdirk4,
    /// Step-size memory of the chamber integrator (split method).
    chamber_integrator: Sdirk4,
    statistics: Statistics,
    /// An input changed since the last step (the jet pipe will move and ring).
    input_changed: bool,
    /// First chamber step size that was accepted after the last input change: where the
    /// next step after a change starts, instead of the long steps that suit the end of a
    /// quiet interval.
    step_after_change: f64,
    /// Play operators of the jet_pipe_hysteresis effect (when it is off, f3's output at the
    /// start, and not followed).
    plays: [f64; PLAY_OPERATORS],
    /// Commands of the recent past, for the transport_delay effect.
    command_history: Vec<CommandChange>,
    /// Mean stopper velocity over the last step (for piston friction).
    stopper_velocity: f64,
    x_s_at_last_step: f64,
    /// The command stage's memory (see [`crate::physics::command_stage`]).
    command_stage: CommandStage,
    /// The transducers' memories, in the order of [`Channel::ALL`], for those that filter
    /// (see [`crate::physics::sensors`]).
    transducers: [Option<SensorMemory>; 3],
    propagator: Option<ElectromechanicalPropagator>,
    /// The pressures of the gas volumes behind restrictions, in the order of
    /// [`crate::physics::restrictions::node`] (followed only for the places with a volume).
    nodes: [f64; node::COUNT],
    /// The chambers' pressure rates at the end of the last split step, with what they are a
    /// function of: when the next step starts from the same jet pipe position, pressures and
    /// stopper motion, they are its rates at the start and are not evaluated again.
    chamber_rates_at_end: Option<ChamberRatesAtEnd>,
}

/// See [`Simulation::chamber_rates_at_end`].
#[derive(Clone, Copy, Debug, PartialEq)]
struct ChamberRatesAtEnd {
    x_jp: f64,
    pressures: SVector<f64, 2>,
    x_s: f64,
    x_s_rate: f64,
    rates: SVector<f64, 2>,
}

/// From `time` on, the command was `v_da` + `rate`·(t − `time`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandChange {
    pub time: f64,
    pub v_da: f64,
    pub rate: f64,
}

impl Simulation {
    /// A simulation at rest at the equilibrium of the given inputs.
    pub fn at_equilibrium(
        model: Actuator,
        v_da: f64,
        x_s: f64,
        time: f64,
        relative_tolerance: f64,
    ) -> Result<Self, String> {
        check_finite("v_DA", v_da, "V")?;
        model.params.check_stopper(x_s)?;
        let state = equilibrium_at(&model, v_da, x_s, time)?;
        if !model.restrictions.has_volumes() {
            return Ok(Self::from_state(model, state, v_da, x_s, time, relative_tolerance));
        }
        let (state, nodes) = balance_with_volumes(&model, &state, x_s, time)?;
        let mut simulation = Self::from_state(model, state, v_da, x_s, time, relative_tolerance);
        if simulation.propagator.is_none() {
            return Err(volumes_need_the_split_method(&simulation.model));
        }
        simulation.nodes = nodes;
        Ok(simulation)
    }

    /// A simulation from a given state.
    pub fn from_state(model: Actuator, state: State, v_da: f64, x_s: f64, time: f64, relative_tolerance: f64) -> Self {
        let propagator = ElectromechanicalPropagator::new(&model.params);
        let plays = model.initial_hysteresis_memory(state[index::CURRENT]);
        let command_stage = CommandStage::at_rest(&model.params, time, v_da);
        let readings = model.outputs_at(&state, x_s, 0.0, time).readings();
        let transducers = [0, 1, 2].map(|k| {
            SensorLaw::of(&model.params, Channel::ALL[k])
                .filters()
                .then(|| SensorMemory::at_rest(time, readings[k]))
        });
        // What the driver has seen since long before (the delay line's past): the command
        // through the stage, as every later entry of the line is.
        let seen_before = command_stage.current(&model.params);
        let nodes = if model.restrictions.any() {
            model
                .network_flows(
                    &model.areas(state[index::JET_POSITION]),
                    state[index::P1],
                    state[index::P2],
                    None,
                )
                .node_pressures
        } else {
            [0.0; node::COUNT]
        };
        Self {
            nodes,
            model,
            time,
            state,
            v_da,
            x_s,
            v_da_rate: 0.0,
            x_s_rate: 0.0,
            relative_tolerance,
            method: if propagator.is_some() {
                Method::Split
            } else {
                Method::Monolithic
            },
            chamber_method: ChamberMethod::NonStiffFirst,
            integrator: Sdirk4::default(),
            chamber_integrator: Sdirk4::default(),
            statistics: Statistics::default(),
            input_changed: false,
            step_after_change: 1e-5,
            plays,
            command_history: vec![CommandChange {
                time: f64::NEG_INFINITY,
                v_da: seen_before,
                rate: 0.0,
            }],
            stopper_velocity: 0.0,
            x_s_at_last_step: x_s,
            command_stage,
            transducers,
            propagator,
            chamber_rates_at_end: None,
        }
    }

    /// The simulated time, s.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The six states (see [`index`]).
    pub fn state(&self) -> &State {
        &self.state
    }

    /// The pressures behind the restrictions, Pa, in the order of
    /// [`crate::physics::restrictions::node`]: the state where the place has a volume, the
    /// quasi-static pressure where it has a restriction alone, and where it has none the
    /// pressure the valve sees there (P_s, P_r, the chamber's).
    pub fn node_pressures(&self) -> [f64; node::COUNT] {
        let x_jp = self.state[index::JET_POSITION];
        self.model
            .network_flows(
                &self.model.areas(x_jp),
                self.state[index::P1],
                self.state[index::P2],
                Some(&self.nodes),
            )
            .node_pressures
    }

    /// The command v_DA, V: as set, or where its ramp ended (the driver may see another
    /// through the command stage and the transport delay).
    pub fn v_da(&self) -> f64 {
        self.v_da
    }

    /// The stopper position, m.
    pub fn x_s(&self) -> f64 {
        self.x_s
    }

    pub fn relative_tolerance(&self) -> f64 {
        self.relative_tolerance
    }

    pub fn model(&self) -> &Actuator {
        &self.model
    }

    /// The integrators' work so far.
    pub fn statistics(&self) -> Statistics {
        self.statistics
    }

    /// For comparisons with the six-state integrator. Without the jet pipe's modal form
    /// (ζ2 ≥ 1) the split method is not available and a step integrates all six states anyway.
    pub fn set_method(&mut self, method: Method) {
        self.method = method;
    }

    /// For comparisons of the chamber integrators; the default suits every scenario.
    pub fn set_chamber_method(&mut self, method: ChamberMethod) {
        self.chamber_method = method;
    }

    /// Puts the stopper at `x_s` without the air-conserving jump of [`Self::set_stopper`]: for
    /// a caller that moved it with a rate over the step and lands it on the position it
    /// meant, a rounding error away.
    pub fn land_stopper_at(&mut self, x_s: f64) {
        self.x_s = x_s;
    }

    pub fn outputs(&self) -> Outputs {
        let mut y = self
            .model
            .outputs_at(&self.state, self.x_s, self.stopper_velocity, self.time);
        for ((memory, reading), channel) in self.transducers.iter().zip(y.readings_mut()).zip(Channel::ALL) {
            if let Some(memory) = memory {
                *reading = memory.output(&SensorLaw::of(&self.model.params, channel), self.time, *reading);
            }
        }
        y
    }

    pub fn set_command(&mut self, v_da: f64) -> Result<(), String> {
        check_finite("v_DA", v_da, "V")?;
        self.input_changed |= v_da != self.v_da;
        self.v_da = v_da;
        Ok(())
    }

    /// Move the stopper instantly, conserving the air in each chamber.
    pub fn set_stopper(&mut self, x_s: f64) -> Result<(), String> {
        self.model.params.check_stopper(x_s)?;
        if x_s != self.x_s {
            let gamma = self.model.polytropic_exponent;
            let (v1_before, v2_before) = self.model.cylinder.volumes(self.x_s);
            let (v1_after, v2_after) = self.model.cylinder.volumes(x_s);
            self.state[index::P1] = pressure_after_volume_jump(gamma, self.state[index::P1], v1_before, v1_after);
            self.state[index::P2] = pressure_after_volume_jump(gamma, self.state[index::P2], v2_before, v2_after);
            self.x_s = x_s;
            self.input_changed = true;
        }
        Ok(())
    }

    pub fn set_command_rate(&mut self, rate: f64) -> Result<(), String> {
        check_finite("der(v_DA)", rate, "V/s")?;
        self.v_da_rate = rate;
        Ok(())
    }

    pub fn set_stopper_rate(&mut self, rate: f64) -> Result<(), String> {
        check_finite("der(x_s)", rate, "m/s")?;
        self.x_s_rate = rate;
        Ok(())
    }

    fn local_tolerance(&self) -> f64 {
        LOCAL_ERROR_FRACTION * self.relative_tolerance
    }

    pub fn tolerances(&self) -> Tolerances<N_STATES> {
        Tolerances {
            relative: self.local_tolerance(),
            absolute: self.model.state_scales() * self.local_tolerance(),
        }
    }

    /// How long into a step of length `step` the jet pipe's ringing still moves the
    /// pressures by more than a hundredth of the tolerance (0 if never; the whole step,
    /// without asking, if it is no longer than a ringing period and the default method
    /// integrates it). The pressure rates at the start come from `system`, which
    /// keeps them for the integrator's first stage.
    fn ringing_until<const N: usize>(&self, system: &ChamberSystem<N>, trajectory: &Trajectory, step: f64) -> f64 {
        let after_current_transient = step.min(5.0 / self.model.params.omega_cd);
        let amplitude = trajectory
            .ringing_amplitude(0.0)
            .max(trajectory.ringing_amplitude(after_current_transient));
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
        if !time_varying::varies(&self.model.params) {
            return self.step_with_constants_held(step);
        }
        // The varying constants at mid-step, held over the step; the chambers' rates kept
        // from the last step were for the old values.
        let nominal = self.model.params.clone();
        if step.is_finite() && step > 0.0 {
            time_varying::set_at(&mut self.model.params, &nominal, self.time + 0.5 * step)
                .map_err(StepFailure::InvalidRequest)?;
        }
        self.chamber_rates_at_end = None;
        let result = self.step_with_constants_held(step);
        self.model.params = nominal;
        self.chamber_rates_at_end = None;
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
        let t_end = self.time + step;
        let segments = self.seen_command_segments(step);
        for (duration, v, v_rate) in segments {
            self.advance(duration, v, v_rate).map_err(|failure| {
                self.v_da_rate = 0.0;
                self.x_s_rate = 0.0;
                failure
            })?;
        }
        self.time = t_end;
        self.x_s = x_s_end;
        self.v_da += self.v_da_rate * step;
        self.v_da_rate = 0.0;
        self.x_s_rate = 0.0;
        self.input_changed = false;
        self.stopper_velocity = (self.x_s - self.x_s_at_last_step) / step;
        self.x_s_at_last_step = self.x_s;
        if self.transducers.iter().any(Option::is_some) {
            let mut y = self
                .model
                .outputs_at(&self.state, self.x_s, self.stopper_velocity, self.time);
            self.record_transducers(&mut y);
        }
        Ok(())
    }

    /// Record the transducers' static readings in `y` (at the simulation's time) in the
    /// memories of those that filter, and put their filtered readings in `y`.
    fn record_transducers(&mut self, y: &mut Outputs) {
        for ((memory, reading), channel) in self.transducers.iter_mut().zip(y.readings_mut()).zip(Channel::ALL) {
            if let Some(memory) = memory {
                *reading = memory.record(&SensorLaw::of(&self.model.params, channel), self.time, *reading);
            }
        }
    }

    /// The command the current driver sees over the next `step`, through the command stage
    /// and the delay line, as [`Self::command_segments`] pieces; shared by the
    /// error-controlled and the fixed steps.
    fn seen_command_segments(&mut self, step: f64) -> smallvec::SmallVec<[(f64, f64, f64); 2]> {
        // The command stage holds what the driver sees over the step (a command ramp
        // reaches it at the next communication point).
        let applied = self.v_da;
        let staged = command_stage::is_active(&self.model.params);
        if staged {
            let before = self.command_stage.current(&self.model.params);
            let seen = self.command_stage.next(&self.model.params, self.time, applied);
            self.input_changed |= seen != before;
            self.v_da = seen;
        }
        let rate = self.v_da_rate;
        if staged {
            self.v_da_rate = 0.0;
        }
        let segments = self.command_segments(step);
        self.v_da = applied;
        self.v_da_rate = rate;
        segments
    }

    /// The command the current driver sees over the next `step`: v_DA itself, or (with the
    /// transport_delay effect) v_DA as it was `command_delay` earlier, as (duration,
    /// value at the segment's start, rate) pieces.
    fn command_segments(&mut self, step: f64) -> smallvec::SmallVec<[(f64, f64, f64); 2]> {
        let delay = self.model.params.command_delay;
        if delay == 0.0 {
            return smallvec::smallvec![(step, self.v_da, self.v_da_rate)];
        }
        self.command_history.push(CommandChange {
            time: self.time,
            v_da: self.v_da,
            rate: self.v_da_rate,
        });
        let (from, to) = (self.time - delay, self.time + step - delay);
        // Forget what no later step can see.
        while self.command_history.len() > 1 && self.command_history[1].time <= from {
            self.command_history.remove(0);
        }
        let mut segments: smallvec::SmallVec<[(f64, f64, f64); 2]> = smallvec::SmallVec::new();
        let mut start = from;
        for (k, change) in self.command_history.iter().enumerate() {
            let end = self.command_history.get(k + 1).map_or(to, |next| next.time.min(to));
            if end <= start {
                continue;
            }
            let value = if change.rate == 0.0 {
                change.v_da
            } else {
                change.v_da + change.rate * (start - change.time)
            };
            segments.push((end - start, value, change.rate));
            start = end;
            if start >= to {
                break;
            }
        }
        // Rounding can leave the pieces a hair short of the step: give it to the last.
        let covered: f64 = segments.iter().map(|s| s.0).sum();
        if let Some(last) = segments.last_mut() {
            last.0 += step - covered;
        }
        segments
    }

    /// Integrate `duration` seconds with the command `v` + `v_rate`·s seen by the current
    /// driver; the stopper moves at `x_s_rate`.
    fn advance(&mut self, duration: f64, v: f64, v_rate: f64) -> Result<(), StepFailure> {
        let outcome = match (self.method, &self.propagator) {
            (Method::Split, Some(_)) => self.split_step(duration, v, v_rate),
            _ if self.model.restrictions.has_volumes() => {
                return Err(StepFailure::InvalidRequest(volumes_need_the_split_method(&self.model)))
            }
            _ => self.monolithic_step(duration, v, v_rate),
        };
        self.settle(outcome, duration)
    }

    /// The split method's step: the jet pipe's exact trajectory drives the chambers, whose
    /// two pressures alone are integrated.
    fn split_step(&mut self, duration: f64, v: f64, v_rate: f64) -> Result<State, IntegrationFailure<N_STATES>> {
        if self.model.restrictions.has_volumes() {
            self.split_step_over::<PRESSURES_WITH_VOLUMES>(duration, v, v_rate)
        } else {
            self.split_step_over::<2>(duration, v, v_rate)
        }
    }

    /// The pressures the split method integrates: P1 and P2, then the volumes' (N = 6).
    fn pressures<const N: usize>(&self) -> SVector<f64, N> {
        SVector::<f64, N>::from_fn(|i, _| match i {
            0 => self.state[index::P1],
            1 => self.state[index::P2],
            _ => self.nodes[i - 2],
        })
    }

    /// [`Self::split_step`] with N integrated pressures.
    fn split_step_over<const N: usize>(
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
        let system = ChamberSystem::<N>::new(
            &self.model,
            &trajectory,
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
        if self.model.hysteresis.is_active() {
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
        if self.model.hysteresis.is_active() {
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
    fn electromechanical_state(&self) -> ElectromechanicalState {
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
fn integrate_chambers<const N: usize>(
    integrator: &mut Sdirk4,
    statistics: &mut Statistics,
    method: ChamberMethod,
    system: &ChamberSystem<N>,
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
fn keep_nodes<const N: usize>(nodes: &mut [f64; node::COUNT], p: &SVector<f64, N>) {
    for i in 2..N {
        nodes[i - 2] = p[i];
    }
}

/// Why a model with gas volumes cannot take a monolithic step.
fn volumes_need_the_split_method(model: &Actuator) -> String {
    let p = &model.params;
    format!(
        "the gas volumes behind restrictions (supply_plenum_volume = {} m3, return_plenum_volume = {} m3, port_line_volume_1 = {} m3, port_line_volume_2 = {} m3) are integrated by the split method only, which needs a jet pipe with two distinct eigenvalues (zeta_2 = {} must be < 1)",
        p.supply_plenum_volume, p.return_plenum_volume, p.port_line_volume_1, p.port_line_volume_2, p.zeta_2
    )
}

fn check_finite(name: &str, value: f64, unit: &str) -> Result<(), String> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(format!("{name} = {value} {unit} is invalid: must be finite"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::parameters::Parameters;

    pub(super) fn thesis_model() -> Actuator {
        Actuator::new(Parameters::default()).unwrap()
    }
    #[test]
    fn sealed_chambers_conserve_air_when_the_stopper_moves() {
        let p = Parameters {
            c_d: 0.0,
            c_db_a_lpp: 0.0,
            c_dm_a_lpp: 0.0,
            ..Parameters::default()
        };
        let model = Actuator::new(p).unwrap();
        let mut state = equilibrium(&thesis_model(), 2.5, 0.054).unwrap();
        state[index::P1] = 4e5;
        state[index::P2] = 2e5;
        let mut sim = Simulation::from_state(model.clone(), state, 2.5, 0.054, 0.0, 1e-8);
        let invariant = |s: &Simulation| {
            let (v1, v2) = s.model.cylinder.volumes(s.x_s);
            (s.state[index::P1] * v1.powf(1.4), s.state[index::P2] * v2.powf(1.4))
        };
        let start = invariant(&sim);
        // Linear motion over a step (input derivative), then a jump, then back.
        sim.set_stopper_rate(0.2).unwrap();
        sim.step(0.05).unwrap();
        assert!((sim.x_s - 0.064).abs() < 1e-15);
        let moved = invariant(&sim);
        sim.set_stopper(0.040).unwrap();
        let jumped = invariant(&sim);
        for (a, b) in [(start, moved), (start, jumped)] {
            assert!(
                (a.0 - b.0).abs() < 1e-7 * a.0 && (a.1 - b.1).abs() < 1e-7 * a.1,
                "{a:?} vs {b:?}"
            );
        }
        sim.set_stopper(0.054).unwrap();
        assert!((sim.state[index::P1] - 4e5).abs() < 1e-7 * 4e5 && (sim.state[index::P2] - 2e5).abs() < 1e-7 * 2e5);
    }

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

    fn with(change: impl Fn(&mut Parameters)) -> Actuator {
        let mut p = Parameters::default();
        change(&mut p);
        Actuator::new(p).unwrap()
    }

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
            pressures[2..].copy_from_slice(&sim.node_pressures());
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

    #[test]
    fn bad_requests_name_the_variable_and_value() {
        let mut sim = Simulation::at_equilibrium(thesis_model(), 2.5, 0.054, 0.0, 1e-6).unwrap();
        let e = sim.set_command(f64::NAN).unwrap_err();
        assert!(e.contains("v_DA") && e.contains("NaN"), "{e}");
        let e = sim.set_stopper(0.1).unwrap_err();
        assert!(e.contains("x_s") && e.contains("0.1"), "{e}");
        match sim.step(-1e-3) {
            Err(StepFailure::InvalidRequest(e)) => assert!(e.contains("-0.001"), "{e}"),
            other => panic!("{other:?}"),
        }
        sim.set_stopper_rate(1.0).unwrap();
        assert!(matches!(sim.step(0.1), Err(StepFailure::InvalidRequest(_))));
        assert_eq!(sim.time, 0.0);
    }
}
