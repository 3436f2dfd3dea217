//! Stepping the actuator between communication points: the one driver used by the FMU,
//! the command-line tool and the tests.
//!
//! Inputs are held over a step, or move linearly when a first-order derivative is given
//! for the step. A stopper position set without a derivative is a jump at the
//! communication point: the air in each chamber is conserved and the pressures follow
//! the exact no-flow limit of (2.29), P V^γ = const, so no spike comes from differencing.
//!
//! This file holds [`Simulation`], its construction and its inputs. `stepping` advances it: the
//! choice between the split and the monolithic method, and the integrators' hand-overs;
//! `commands` gives the command the current driver sees over a step (command stage, transport
//! delay). What a step integrates lives apart: `chambers` (the two pressures driven by the jet
//! pipe's exact trajectory, for the split method), `monolithic` (all six states) and
//! `equilibrium` (the state a simulation starts from).

mod chambers;
mod commands;
#[cfg(test)]
mod effect_tests;
mod equilibrium;
mod fixed_step;
#[cfg(test)]
mod flexible_tests;
mod modulated;
mod monolithic;
mod snapshot;
mod stepping;

pub use commands::CommandChange;

pub use equilibrium::{
    balance_with_volumes, equilibrium, equilibrium_at, equilibrium_of_electromechanics, modulated_equilibrium,
};
pub use fixed_step::FixedStep;
pub use snapshot::{SimulationSnapshot, SNAPSHOT_LAYOUT};

use nalgebra::SVector;

use self::stepping::volumes_need_the_split_method;
use crate::electromechanics::ElectromechanicalPropagator;
use crate::integrator::{Sdirk4, Statistics, Tolerances};
use crate::physics::actuator::{index, Actuator, Outputs, State, N_STATES};
use crate::physics::command_stage::{self, CommandStage};
use crate::physics::effects::PLAY_OPERATORS;
use crate::physics::extra_force::{self, StopperMotion};
use crate::physics::flexible::{self, FLEXIBLE_SLOTS};
use crate::physics::modulation;
use crate::physics::restrictions::node;
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
    /// Mean stopper velocity over the last step.
    stopper_velocity: f64,
    /// The stopper's rate over the coming step, once set for it (der(x_s)): the outputs at
    /// the sample then read the velocity between the two intervals
    /// ([`crate::physics::extra_force::velocity_between_intervals`]).
    next_stopper_rate: Option<f64>,
    /// The motion turned at the last sample but one ([`crate::physics::extra_force::turns_at_sample`]):
    /// its corner lay within the last step.
    stopper_turned_before: bool,
    x_s_at_last_step: f64,
    /// The stopper's motion over the last step, from which the acceleration and the velocity
    /// at the sample that the forces on the piston read are formed
    /// ([`crate::physics::extra_force`]; followed only when such a force is on), and the
    /// acceleration at the end of the last step (0 when off).
    stopper_motion: StopperMotion,
    stopper_acceleration: f64,
    /// The stopper acceleration input (a_s) and its rate over the next step: read by the
    /// forces as far as `stopper_acceleration_input_share` says ([`Self::acceleration_read`]).
    acceleration_input: f64,
    acceleration_input_rate: f64,
    /// The command stage's memory (see [`crate::physics::command_stage`]).
    command_stage: CommandStage,
    /// The transducers' memories, in the order of [`Channel::ALL`], for those that filter
    /// (see [`crate::physics::sensors`]).
    transducers: [Option<SensorMemory>; 3],
    propagator: Option<ElectromechanicalPropagator>,
    /// The pressures of the gas volumes behind restrictions, in the order of
    /// [`crate::physics::restrictions::node`] (followed only for the places with a volume),
    /// then the lagging stopper mount's state (followed only when it lags).
    nodes: [f64; node::STATES],
    /// The chambers' pressure rates at the end of the last split step, with what they are a
    /// function of: when the next step starts from the same jet pipe position, pressures and
    /// stopper motion, they are its rates at the start and are not evaluated again.
    chamber_rates_at_end: Option<ChamberRatesAtEnd>,
    /// The split method's table of the orifice areas at an explicit step's stages, lent to
    /// each step's chamber system (it holds nothing from one step to the next).
    stage_areas: std::cell::RefCell<chambers::StageAreas>,
    /// Which of a step's optional stages the model has, decided once from its parameters.
    plan: StepPlan,
    /// The propagator of the last step whose modulation slots changed the current driver's or
    /// the jet pipe's constants, kept for the next step with the same constants.
    modulated_propagator: Option<modulated::PropagatorOf>,
    /// Whether the slots' constants are set in `model` for a step: the readings within it
    /// take them as they are rather than setting them a second time.
    slots_held: bool,
    /// The flexible slots' low-passed signals at the last sample, per slot and axis
    /// ([`crate::physics::flexible`]; followed only where a slot lags).
    flexible_lags: [[f64; 2]; FLEXIBLE_SLOTS],
    /// The stopper's offset L_sup the last step held, or where the slots put it at the starting
    /// state: where the next step holds another, the piston moves and the chambers' air is
    /// carried across the change ([`modulation::moves_the_piston`]).
    held_piston_place: f64,
}

/// The optional stages of a step, decided once when a simulation is built from its model (its
/// parameters do not change after: the constants that vary in time are set and reset
/// around each step, and do not change which stages are live), so that the thesis model's
/// step does not test for each effect that is off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct StepPlan {
    /// Constants vary in time ([`crate::physics::time_varying`]).
    varying_constants: bool,
    /// A modulation slot is on ([`crate::physics::modulation`]): its constant is held over
    /// each step at the signals at the step's start. A slot on a friction or a transducer's
    /// term switches that on in the model (the stopper's motion is then formed, the outputs'
    /// general law used), as the constant away from its default would.
    modulated: bool,
    /// A slot modulates a constant the outputs read: they are formed with it at the sample's
    /// signals.
    modulated_outputs: bool,
    /// A flexible slot low-passes a signal: its lag state is advanced after each step.
    lagged: bool,
    /// The command reaches the driver through the command stage or the transport delay.
    command_path: bool,
    /// A transducer filters its reading (and so has a memory, which records the reading after
    /// each step).
    filtering_transducers: bool,
    /// A slot moves the piston (L_sup): the chambers' air is carried across each change.
    moving_piston: bool,
    /// The hysteresis operator has a memory to follow.
    hysteresis: bool,
    /// A force follows the stopper's velocity or acceleration at the sample, formed from the
    /// steps' motions.
    stopper_acceleration: bool,
    /// Something is recorded after each step: a transducer's memory or the stopper's motion.
    after_step: bool,
}

impl StepPlan {
    fn of(model: &Actuator, transducers: &[Option<SensorMemory>; 3]) -> Self {
        let p = &model.params;
        StepPlan {
            varying_constants: time_varying::varies(p),
            modulated: modulation::any_on(p),
            modulated_outputs: modulation::modulates_outputs(p),
            lagged: flexible::lags_on(p),
            command_path: command_stage::is_active(p) || p.command_delay != 0.0,
            filtering_transducers: transducers.iter().any(Option::is_some),
            moving_piston: modulation::moves_the_piston(p),
            hysteresis: model.hysteresis.is_active(),
            stopper_acceleration: model.reads_stopper_motion,
            after_step: transducers.iter().any(Option::is_some) || model.reads_stopper_motion,
        }
    }
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
        if !model.has_volume_states() {
            return Ok(Self::from_state(model, state, v_da, x_s, time, relative_tolerance));
        }
        // With the slots' constants at the equilibrium's signals (the drifts then added).
        let at = match modulation::any_on(&model.params) {
            true => modulation::model_at(
                &model,
                &modulated::signals_at(&model, &state, v_da, x_s, 0.0, 0.0, time),
            )?,
            false => model.clone(),
        };
        let (state, nodes) = balance_with_volumes(&at, &state, x_s, time)?;
        let mut simulation = Self::from_state(model, state, v_da, x_s, time, relative_tolerance);
        if simulation.propagator.is_none() {
            return Err(volumes_need_the_split_method(&simulation.model));
        }
        simulation.nodes = nodes;
        Ok(simulation)
    }

    /// A simulation at the equilibrium of the given inputs except for the chamber pressures,
    /// which are `pressures` (Pa): a bench that had not settled when its recording began, as
    /// its transducers read it. The current and the jet pipe, whose time constants are
    /// milliseconds, start at their equilibrium, and so do the volumes behind restrictions,
    /// which follow the chambers within their own short time constants. Where the inputs have
    /// no equilibrium, the current and the jet pipe start at their static values alone.
    pub fn at_pressures(
        model: Actuator,
        v_da: f64,
        x_s: f64,
        time: f64,
        relative_tolerance: f64,
        pressures: [f64; 2],
    ) -> Result<Self, String> {
        for (name, p) in [("P1_start", pressures[0]), ("P2_start", pressures[1])] {
            if !(p.is_finite() && p > 0.0) {
                return Err(format!("{name} = {p} Pa is invalid: must be above 0 Pa"));
            }
        }
        let (state, nodes) = match Self::at_equilibrium(model.clone(), v_da, x_s, time, relative_tolerance) {
            Ok(settled) => (settled.state, Some(settled.nodes)),
            Err(_) => {
                check_finite("v_DA", v_da, "V")?;
                model.params.check_stopper(x_s)?;
                (equilibrium_of_electromechanics(&model, v_da), None)
            }
        };
        let mut state = state;
        state[index::P1] = pressures[0];
        state[index::P2] = pressures[1];
        let mut simulation = Self::from_state(model, state, v_da, x_s, time, relative_tolerance);
        if let Some(nodes) = nodes.filter(|_| simulation.model.has_volume_states()) {
            simulation.nodes = nodes;
        }
        Ok(simulation)
    }

    /// A simulation from a given state.
    pub fn from_state(model: Actuator, state: State, v_da: f64, x_s: f64, time: f64, relative_tolerance: f64) -> Self {
        let propagator = ElectromechanicalPropagator::new(&model.params);
        let plays = model.initial_hysteresis_memory(state[index::CURRENT]);
        let command_stage = CommandStage::at_rest(&model.params, time, v_da);
        let readings = modulated::outputs_in_motion(&model, &state, x_s, 0.0, 0.0, time, v_da, None).readings();
        // The lags start settled at the signals of the starting state (the steady state).
        let flexible_lags = if flexible::any_on(&model.params) {
            let signals = modulated::signals_at(&model, &state, v_da, x_s, 0.0, 0.0, time);
            flexible::initial_lags(&model.params, &signals)
        } else {
            [[0.0; 2]; FLEXIBLE_SLOTS]
        };
        let transducers = [0, 1, 2].map(|k| {
            SensorLaw::of(&model.params, Channel::ALL[k])
                .filters()
                .then(|| SensorMemory::at_rest(time, readings[k]))
        });
        // What the driver has seen since long before (the delay line's past): the command
        // through the stage, as every later entry of the line is.
        let seen_before = command_stage.current(&model.params);
        let plan = StepPlan::of(&model, &transducers);
        let held_piston_place = if plan.moving_piston {
            let signals = modulated::signals_at(&model, &state, v_da, x_s, 0.0, 0.0, time);
            modulation::model_at(&model, &signals).map_or(model.cylinder.l_sup, |at| at.cylinder.l_sup)
        } else {
            model.cylinder.l_sup
        };
        let mut nodes = [0.0; node::STATES];
        if model.restrictions.any() {
            let places = model
                .network_flows(
                    &model.areas(state[index::JET_POSITION]),
                    state[index::P1],
                    state[index::P2],
                    None,
                )
                .node_pressures;
            nodes[..node::COUNT].copy_from_slice(&places);
        }
        if model.mount_lags() {
            nodes[node::MOUNT] = model.mount_load(state[index::P1], state[index::P2], x_s);
        }
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
            next_stopper_rate: None,
            stopper_turned_before: false,
            x_s_at_last_step: x_s,
            stopper_motion: StopperMotion::at_rest(),
            stopper_acceleration: 0.0,
            acceleration_input: 0.0,
            acceleration_input_rate: 0.0,
            command_stage,
            transducers,
            propagator,
            chamber_rates_at_end: None,
            stage_areas: std::cell::RefCell::new(chambers::StageAreas::default()),
            plan,
            modulated_propagator: None,
            slots_held: false,
            flexible_lags,
            held_piston_place,
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
                Some(&self.restriction_nodes()),
            )
            .node_pressures
    }

    /// The pressure difference the lagging stopper mount has followed, Pa
    /// ([`node::MOUNT`]), when it lags.
    pub fn stopper_mount_state(&self) -> Option<f64> {
        self.model.mount_lags().then(|| self.nodes[node::MOUNT])
    }

    /// The first [`node::COUNT`] of the nodes: the places' pressures.
    fn restriction_nodes(&self) -> [f64; node::COUNT] {
        let mut places = [0.0; node::COUNT];
        places.copy_from_slice(&self.nodes[..node::COUNT]);
        places
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

    /// The jet_pipe_hysteresis operator's memory (its plays, or the Bouc–Wen law's input and
    /// output where it was last advanced), when the effect is on: what Model Exchange starts
    /// its own from.
    pub fn hysteresis_memory(&self) -> Option<[f64; PLAY_OPERATORS]> {
        self.model.hysteresis.is_active().then_some(self.plays)
    }

    /// The command stage's lag output, second-order filter output and its rate at the last
    /// communication point ([`CommandStage::dynamic_states`]): what Model Exchange starts
    /// its states of them from.
    pub fn command_dynamics(&self) -> [f64; 3] {
        self.command_stage.dynamic_states()
    }

    /// The same for the transducer of `channel`, when it has a memory (a delay, lag, filter
    /// or play; `None` when it reads its static reading).
    pub fn transducer_dynamics(&self, channel: Channel) -> Option<[f64; 3]> {
        let k = Channel::ALL.iter().position(|&c| c == channel)?;
        self.transducers[k].as_ref().map(SensorMemory::dynamic_states)
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

    /// The stopper acceleration the forces read: the share `stopper_acceleration_input_share`
    /// of the input a_s, the rest formed from the positions (the last two steps' motions).
    /// A master that knows the acceleration (a finger model; the diagnosis, which smooths a
    /// recording's positions centred on each sample) gives it whole: formed from positions
    /// rounded to a micrometre, a second difference at 4 kHz carries 16 m/s² of rounding.
    pub(super) fn acceleration_read(&self) -> f64 {
        let share = self.model.params.stopper_acceleration_input_share;
        if share == 0.0 {
            self.stopper_acceleration
        } else {
            share * self.acceleration_input + (1.0 - share) * self.stopper_acceleration
        }
    }

    /// The stopper velocity the forces read at the last sample: between the last step's
    /// motion and the coming one once its rate is set, else at the sample from the last two
    /// steps' motions, where a force reads it ([`extra_force::velocity_at_sample`]).
    /// The positions, linear between samples, are the motion: the velocity is carried to the
    /// sample with the acceleration they form, not with the input a_s, which a master may
    /// smooth over several samples and which would then switch a friction on before a ramp
    /// starts.
    pub(super) fn stopper_velocity_at_sample(&self) -> f64 {
        if self.plan.stopper_acceleration {
            match self.next_stopper_rate {
                Some(next) => extra_force::velocity_between_intervals(
                    self.stopper_velocity,
                    self.stopper_acceleration * self.stopper_motion.interval,
                    next,
                    self.stopper_turned_before,
                ),
                None => extra_force::velocity_at_sample(
                    self.stopper_velocity,
                    self.stopper_motion.interval,
                    self.stopper_acceleration,
                ),
            }
        } else {
            self.stopper_velocity
        }
    }

    pub fn outputs(&self) -> Outputs {
        let mut y = self.outputs_at_sample();
        if !self.plan.filtering_transducers {
            return y;
        }
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

    /// Move the stopper instantly, conserving the air in each chamber (with the piston where a
    /// compliant stopper or a lagging mount puts it).
    pub fn set_stopper(&mut self, x_s: f64) -> Result<(), String> {
        self.model.params.check_stopper(x_s)?;
        if x_s != self.x_s {
            let (p1, p2) = (self.state[index::P1], self.state[index::P2]);
            let mount = self.stopper_mount_state().unwrap_or(0.0);
            let [p1, p2] = self.model.pressures_after_stopper_jump(p1, p2, mount, self.x_s, x_s);
            self.state[index::P1] = p1;
            self.state[index::P2] = p2;
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

    /// Whether the stopper turns at this sample into a step at `rate`, remembered over the
    /// step ([`Self::stopper_turned_before`]); called as the step starts.
    pub(super) fn note_stopper_turn(&mut self, rate: f64) {
        self.stopper_turned_before = self.plan.stopper_acceleration
            && extra_force::turns_at_sample(
                self.stopper_velocity,
                self.stopper_acceleration * self.stopper_motion.interval,
                rate,
            );
    }

    pub fn set_stopper_rate(&mut self, rate: f64) -> Result<(), String> {
        check_finite("der(x_s)", rate, "m/s")?;
        self.x_s_rate = rate;
        self.next_stopper_rate = Some(rate);
        Ok(())
    }

    /// The stopper acceleration input a_s (m/s²), read at once by the outputs, as the share
    /// `stopper_acceleration_input_share` of the acceleration the forces read (the rest is
    /// formed from the positions).
    pub fn set_stopper_acceleration(&mut self, a_s: f64) -> Result<(), String> {
        crate::variables::check(crate::variables::vr::A_S, a_s)?;
        self.acceleration_input = a_s;
        Ok(())
    }

    /// The rate of the stopper acceleration input over the next step (m/s³): it moves
    /// linearly to a_s + rate · step, as x_s does with its rate.
    pub fn set_stopper_acceleration_rate(&mut self, rate: f64) -> Result<(), String> {
        check_finite("der(a_s)", rate, "m/s3")?;
        self.acceleration_input_rate = rate;
        Ok(())
    }

    pub fn stopper_acceleration_input(&self) -> f64 {
        self.acceleration_input
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

    pub(super) fn with(change: impl Fn(&mut Parameters)) -> Actuator {
        let mut p = Parameters::default();
        change(&mut p);
        Actuator::new(p).unwrap()
    }

    #[test]
    fn a_start_at_given_pressures_keeps_them_and_the_electromechanics_equilibrium_and_then_settles() {
        let model = thesis_model();
        let settled = Simulation::at_equilibrium(model.clone(), 2.5, 0.054, 0.0, 1e-8).unwrap();
        let same = Simulation::at_pressures(
            model.clone(),
            2.5,
            0.054,
            0.0,
            1e-8,
            [settled.state[index::P1], settled.state[index::P2]],
        )
        .unwrap();
        assert_eq!(same.state, settled.state);
        let mut apart = Simulation::at_pressures(model.clone(), 2.5, 0.054, 0.0, 1e-8, [4.0e5, 2.0e5]).unwrap();
        assert_eq!((apart.state[index::P1], apart.state[index::P2]), (4.0e5, 2.0e5));
        assert_eq!(apart.state[index::CURRENT], settled.state[index::CURRENT]);
        assert_eq!(apart.state[index::JET_POSITION], settled.state[index::JET_POSITION]);
        // Held at the same inputs, the chambers go to the equilibrium's pressures.
        for _ in 0..40 {
            apart.step(0.25).unwrap();
        }
        for k in [index::P1, index::P2] {
            assert!(
                (apart.state[k] - settled.state[k]).abs() < 1.0,
                "{} against {}",
                apart.state[k],
                settled.state[k]
            );
        }
        let error = Simulation::at_pressures(model, 2.5, 0.054, 0.0, 1e-8, [0.0, 2.0e5])
            .err()
            .unwrap();
        assert!(error.contains("P1_start = 0 Pa"), "{error}");
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
