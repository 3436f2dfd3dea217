//! A running simulation's memory as a plain value: what a caller (the FMU's state, a
//! checkpoint) keeps to continue the simulation later, bit for bit, without reading the
//! simulation's fields.
//!
//! Everything that carries memory from one step to the next is in it: time, state, inputs
//! and their rates, the integrators' step sizes, the hysteresis plays, the commands of the
//! recent past (transport delay), the command stage and the transducers' filters, the flexible
//! slots' lags, the work counters.
//! What is derived from the model (the jet pipe's propagator) is built again on restore, and
//! the chambers' rates kept from the last step are left out: they are a memo, the results
//! are the same to the last bit without them.
//!
//! [`SimulationSnapshot::to_values`] flattens a snapshot into numbers for a byte codec that
//! knows only `f64` arrays; [`SimulationSnapshot::from_values`] checks their shape.

use super::{ChamberMethod, CommandChange, Method, Simulation, StepPlan};
use crate::integrator::{Sdirk4, Statistics};
use crate::physics::actuator::{Actuator, State, N_STATES};
use crate::physics::command_stage::{self, CommandStage};
use crate::physics::effects::PLAY_OPERATORS;
use crate::physics::extra_force::StopperMotion;
use crate::physics::flexible::FLEXIBLE_SLOTS;
use crate::physics::restrictions::node;
use crate::physics::sensors::SensorMemory;

/// A simulation's memory between two steps: see the module's documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationSnapshot {
    time: f64,
    state: [f64; N_STATES],
    nodes: [f64; node::STATES],
    v_da: f64,
    x_s: f64,
    v_da_rate: f64,
    x_s_rate: f64,
    relative_tolerance: f64,
    method: Method,
    chamber_method: ChamberMethod,
    integrator: Sdirk4,
    chamber_integrator: Sdirk4,
    statistics: Statistics,
    input_changed: bool,
    step_after_change: f64,
    plays: [f64; PLAY_OPERATORS],
    command_history: Vec<CommandChange>,
    stopper_velocity: f64,
    next_stopper_rate: Option<f64>,
    stopper_turned_before: bool,
    x_s_at_last_step: f64,
    stopper_motion: StopperMotion,
    stopper_acceleration: f64,
    acceleration_input: f64,
    acceleration_input_rate: f64,
    command_stage: CommandStage,
    transducers: [Option<SensorMemory>; 3],
    flexible_lags: [[f64; 2]; FLEXIBLE_SLOTS],
    held_piston_place: f64,
}

/// The first of [`SimulationSnapshot::to_values`]: a reader of another layout refuses the
/// numbers instead of misreading them. Raise it whenever the layout changes.
/// Layout 10: the flexible slots' lags; 11: the stopper's offset the last step held.
pub const SNAPSHOT_LAYOUT: f64 = 11.0;

/// Numbers before the two counted lists: the layout, 26 scalars, the state, the volumes'
/// pressures, the plays, the command stage ([`command_stage::VALUES`]), the flexible slots'
/// lags, the stopper's offset the last step held and the six work counters as two halves each.
const FIXED_VALUES: usize =
    1 + 26 + N_STATES + node::STATES + PLAY_OPERATORS + command_stage::VALUES + LAGS + 1 + 2 * STATISTICS;
const STATISTICS: usize = 6;
/// The flexible slots' lag states: two axes per slot.
const LAGS: usize = 2 * FLEXIBLE_SLOTS;

impl Simulation {
    /// The simulation's memory, to continue it later with [`Simulation::restore`].
    pub fn snapshot(&self) -> SimulationSnapshot {
        let mut state = [0.0; N_STATES];
        state.copy_from_slice(self.state.as_slice());
        SimulationSnapshot {
            time: self.time,
            state,
            nodes: self.nodes,
            v_da: self.v_da,
            x_s: self.x_s,
            v_da_rate: self.v_da_rate,
            x_s_rate: self.x_s_rate,
            relative_tolerance: self.relative_tolerance,
            method: self.method,
            chamber_method: self.chamber_method,
            integrator: self.integrator,
            chamber_integrator: self.chamber_integrator,
            statistics: self.statistics,
            input_changed: self.input_changed,
            step_after_change: self.step_after_change,
            plays: self.plays,
            command_history: self.command_history.clone(),
            stopper_velocity: self.stopper_velocity,
            next_stopper_rate: self.next_stopper_rate,
            stopper_turned_before: self.stopper_turned_before,
            x_s_at_last_step: self.x_s_at_last_step,
            stopper_motion: self.stopper_motion,
            stopper_acceleration: self.stopper_acceleration,
            acceleration_input: self.acceleration_input,
            acceleration_input_rate: self.acceleration_input_rate,
            command_stage: self.command_stage,
            transducers: self.transducers.clone(),
            flexible_lags: self.flexible_lags,
            held_piston_place: self.held_piston_place,
        }
    }

    /// The simulation of `model` that `snapshot` was taken of, which continues as that one
    /// would have. `model` must be the one the snapshot's simulation ran (the caller keeps its
    /// parameters); the stopper position is checked against its cylinder.
    pub fn restore(model: Actuator, snapshot: &SimulationSnapshot) -> Result<Simulation, String> {
        let s = snapshot;
        model.params.check_stopper(s.x_s)?;
        // From the state, for what is derived from the model (the propagator and with it
        // whether the split method can run); then the memory over what it started.
        let mut sim = Simulation::from_state(model, State::from(s.state), s.v_da, s.x_s, s.time, s.relative_tolerance);
        if sim.propagator.is_some() {
            sim.method = s.method;
        }
        sim.chamber_method = s.chamber_method;
        sim.nodes = s.nodes;
        sim.v_da_rate = s.v_da_rate;
        sim.x_s_rate = s.x_s_rate;
        sim.integrator = s.integrator;
        sim.chamber_integrator = s.chamber_integrator;
        sim.statistics = s.statistics;
        sim.input_changed = s.input_changed;
        sim.step_after_change = s.step_after_change;
        sim.plays = s.plays;
        sim.command_history = s.command_history.clone();
        sim.stopper_velocity = s.stopper_velocity;
        sim.next_stopper_rate = s.next_stopper_rate;
        sim.stopper_turned_before = s.stopper_turned_before;
        sim.x_s_at_last_step = s.x_s_at_last_step;
        sim.stopper_motion = s.stopper_motion;
        sim.stopper_acceleration = s.stopper_acceleration;
        sim.acceleration_input = s.acceleration_input;
        sim.acceleration_input_rate = s.acceleration_input_rate;
        sim.command_stage = s.command_stage;
        sim.transducers = s.transducers.clone();
        sim.flexible_lags = s.flexible_lags;
        sim.held_piston_place = s.held_piston_place;
        sim.plan = StepPlan::of(&sim.model, &sim.transducers);
        Ok(sim)
    }
}

impl SimulationSnapshot {
    /// The simulated time the snapshot was taken at.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The snapshot as numbers, for a codec of `f64` arrays; [`Self::from_values`] reads them.
    ///
    /// Layout: [`SNAPSHOT_LAYOUT`]; time, v_DA, x_s, der(v_DA), der(x_s), relative tolerance,
    /// method (0 split, 1 monolithic), chamber method (0 non-stiff first, 1 Dormand–Prince
    /// only, 2 SDIRK4), the two integrators' next, largest and first step sizes, input changed
    /// (0 or 1), the step after a change, stopper velocity, x_s at the last step, the stopper
    /// velocity over the step before the last and that step's length, and the stopper
    /// acceleration they gave, the acceleration input a_s and its rate; the state;
    /// the pressures of the gas volumes behind restrictions (supply, return, line 1, line 2); the
    /// plays; the command stage (time, held, lagged, filtered and its rate); the flexible slots'
    /// lag states (slot 1's two axes, then slot 2's); the stopper's offset L_sup the last step
    /// held; the work counters (steps, rejected,
    /// right-hand sides, Jacobians, Newton failures, stiff hand-overs), each as its low then
    /// its high 32 bits, since an `f64` holds integers exactly only up to 2^53; then the
    /// number of past commands and their (time, v_DA, rate); then for each transducer (force,
    /// chamber 1, chamber 2) the number of its filter's values (0 when it does not filter) and
    /// the values. Every number is carried bit for bit.
    pub fn to_values(&self) -> Vec<f64> {
        let sensors = self
            .transducers
            .clone()
            .map(|memory| memory.as_ref().map(SensorMemory::to_values).unwrap_or_default());
        let sensor_values: usize = sensors.iter().map(Vec::len).sum();
        let mut v = Vec::with_capacity(FIXED_VALUES + 4 + 3 * self.command_history.len() + sensor_values);
        v.push(SNAPSHOT_LAYOUT);
        v.extend_from_slice(&[
            self.time,
            self.v_da,
            self.x_s,
            self.v_da_rate,
            self.x_s_rate,
            self.relative_tolerance,
            method_code(self.method),
            chamber_method_code(self.chamber_method),
            self.integrator.next_step,
            self.integrator.max_step,
            self.integrator.first_step,
            self.chamber_integrator.next_step,
            self.chamber_integrator.max_step,
            self.chamber_integrator.first_step,
            if self.input_changed { 1.0 } else { 0.0 },
            self.step_after_change,
            self.stopper_velocity,
            self.x_s_at_last_step,
            self.stopper_motion.velocity,
            self.stopper_motion.interval,
            self.stopper_acceleration,
            self.acceleration_input,
            self.acceleration_input_rate,
            if self.next_stopper_rate.is_some() { 1.0 } else { 0.0 },
            self.next_stopper_rate.unwrap_or(0.0),
            if self.stopper_turned_before { 1.0 } else { 0.0 },
        ]);
        v.extend_from_slice(&self.state);
        v.extend_from_slice(&self.nodes);
        v.extend_from_slice(&self.plays);
        v.extend_from_slice(&self.command_stage.to_values());
        for lags in &self.flexible_lags {
            v.extend_from_slice(lags);
        }
        v.push(self.held_piston_place);
        for count in statistics_counts(&self.statistics) {
            v.push((count & 0xffff_ffff) as f64);
            v.push((count >> 32) as f64);
        }
        v.push(self.command_history.len() as f64);
        for change in &self.command_history {
            v.extend_from_slice(&[change.time, change.v_da, change.rate]);
        }
        for sensor in &sensors {
            v.push(sensor.len() as f64);
            v.extend_from_slice(sensor);
        }
        v
    }

    /// What [`Self::to_values`] wrote, its layout and shape checked: the layout number, the
    /// length against the two counts, the codes, flags and counts (finite whole numbers in
    /// range), and the numbers a step computes with (finite; the largest step sizes may be
    /// infinite, the oldest past command's time is −∞).
    pub fn from_values(values: &[f64]) -> Result<Self, String> {
        if values.first() != Some(&SNAPSHOT_LAYOUT) {
            return Err(match values.first() {
                None => "the simulation snapshot holds no values".to_string(),
                Some(layout) => format!(
                    "simulation snapshot layout {layout} is not supported (this model reads layout {SNAPSHOT_LAYOUT})"
                ),
            });
        }
        if values.len() < FIXED_VALUES + 4 {
            return Err(format!(
                "the simulation snapshot holds {} values, fewer than the {} of its fixed part",
                values.len(),
                FIXED_VALUES + 4
            ));
        }
        let mut at = 1;
        let mut next = |n: usize| {
            let slice = &values[at..at + n];
            at += n;
            slice
        };
        let scalars = next(26);
        let [time, v_da, x_s, v_da_rate, x_s_rate, relative_tolerance, method, chamber_method, next_step, max_step, first_step, chamber_next_step, chamber_max_step, chamber_first_step, input_changed, step_after_change, stopper_velocity, x_s_at_last_step, motion_velocity, motion_interval, stopper_acceleration, acceleration_input, acceleration_input_rate, next_rate_set, next_rate, turned_before]: [f64; 26] =
            scalars.try_into().expect("26 values");
        let mut state = [0.0; N_STATES];
        state.copy_from_slice(next(N_STATES));
        let mut nodes = [0.0; node::STATES];
        nodes.copy_from_slice(next(node::STATES));
        let mut plays = [0.0; PLAY_OPERATORS];
        plays.copy_from_slice(next(PLAY_OPERATORS));
        let stage: [f64; command_stage::VALUES] = next(command_stage::VALUES)
            .try_into()
            .expect("the command stage's values");
        let lag_values = next(LAGS);
        let mut flexible_lags = [[0.0; 2]; FLEXIBLE_SLOTS];
        for (k, lags) in flexible_lags.iter_mut().enumerate() {
            lags.copy_from_slice(&lag_values[2 * k..2 * k + 2]);
        }
        let held_piston_place = next(1)[0];
        let halves = next(2 * STATISTICS);
        let mut counts = [0u64; STATISTICS];
        for (k, count) in counts.iter_mut().enumerate() {
            let low = whole_number(halves[2 * k], u32::MAX as usize, "work counter half")?;
            let high = whole_number(halves[2 * k + 1], u32::MAX as usize, "work counter half")?;
            *count = (low as u64) | ((high as u64) << 32);
        }
        let rest = &values[at..];
        // At least the three transducers' counts follow the past commands.
        let changes = whole_number(rest[0], (rest.len() - 4) / 3, "past command count")?;
        let (history, mut rest) = rest[1..].split_at(3 * changes);
        let mut transducers = [None, None, None];
        let mut sensor_values: Vec<f64> = vec![];
        for (k, memory) in transducers.iter_mut().enumerate() {
            let later_counts = 2 - k;
            let count = whole_number(rest[0], rest.len() - 1 - later_counts, "transducer value count")?;
            let (sensor, after) = rest[1..].split_at(count);
            if !sensor.is_empty() {
                *memory = Some(SensorMemory::from_values(sensor).ok_or_else(|| {
                    format!(
                        "the simulation snapshot's transducer {k} memory is malformed ({} values)",
                        sensor.len()
                    )
                })?);
            }
            sensor_values.extend_from_slice(sensor);
            rest = after;
        }
        if !rest.is_empty() {
            return Err(format!(
                "the simulation snapshot holds {} values, {} more than its counts account for",
                values.len(),
                rest.len()
            ));
        }
        let sensor = &sensor_values[..];
        let command_history: Vec<CommandChange> = history
            .chunks(3)
            .map(|c| CommandChange {
                time: c[0],
                v_da: c[1],
                rate: c[2],
            })
            .collect();

        let numbers = [
            time,
            v_da,
            x_s,
            v_da_rate,
            x_s_rate,
            relative_tolerance,
            next_step,
            first_step,
            chamber_next_step,
            chamber_first_step,
            step_after_change,
            stopper_velocity,
            x_s_at_last_step,
            motion_velocity,
            motion_interval,
            stopper_acceleration,
            acceleration_input,
            acceleration_input_rate,
            next_rate,
        ];
        let finite = numbers
            .iter()
            .chain(&state)
            .chain(&nodes)
            .chain(&stage)
            .chain(lag_values)
            .chain(std::iter::once(&held_piston_place))
            .chain(sensor)
            .all(|v| v.is_finite())
            && command_history.iter().all(|c| c.v_da.is_finite() && c.rate.is_finite())
            // The step caps may be unlimited; the oldest past command is from −∞.
            && !max_step.is_nan()
            && !chamber_max_step.is_nan()
            && command_history.iter().all(|c| !c.time.is_nan() && c.time != f64::INFINITY);
        if !finite {
            return Err("the simulation snapshot holds non-finite values".to_string());
        }
        if relative_tolerance <= 0.0 {
            return Err(format!(
                "the simulation snapshot's relative tolerance {relative_tolerance} is not positive"
            ));
        }
        Ok(Self {
            time,
            state,
            nodes,
            v_da,
            x_s,
            v_da_rate,
            x_s_rate,
            relative_tolerance,
            method: match whole_number(method, 1, "method code")? {
                0 => Method::Split,
                _ => Method::Monolithic,
            },
            chamber_method: match whole_number(chamber_method, 2, "chamber method code")? {
                0 => ChamberMethod::NonStiffFirst,
                1 => ChamberMethod::DormandPrinceOnly,
                _ => ChamberMethod::Sdirk4,
            },
            integrator: Sdirk4 {
                next_step,
                max_step,
                first_step,
            },
            chamber_integrator: Sdirk4 {
                next_step: chamber_next_step,
                max_step: chamber_max_step,
                first_step: chamber_first_step,
            },
            statistics: Statistics {
                steps: counts[0],
                rejected: counts[1],
                rhs_evaluations: counts[2],
                jacobians: counts[3],
                newton_failures: counts[4],
                stiff_handovers: counts[5],
            },
            input_changed: whole_number(input_changed, 1, "input-changed flag")? == 1,
            step_after_change,
            plays,
            command_history,
            stopper_velocity,
            next_stopper_rate: (whole_number(next_rate_set, 1, "next stopper rate flag")? == 1).then_some(next_rate),
            stopper_turned_before: whole_number(turned_before, 1, "stopper turn flag")? == 1,
            x_s_at_last_step,
            stopper_motion: StopperMotion {
                velocity: motion_velocity,
                interval: motion_interval,
            },
            stopper_acceleration,
            acceleration_input,
            acceleration_input_rate,
            command_stage: CommandStage::from_values(stage),
            transducers,
            flexible_lags,
            held_piston_place,
        })
    }
}

fn method_code(method: Method) -> f64 {
    match method {
        Method::Split => 0.0,
        Method::Monolithic => 1.0,
    }
}

fn chamber_method_code(method: ChamberMethod) -> f64 {
    match method {
        ChamberMethod::NonStiffFirst => 0.0,
        ChamberMethod::DormandPrinceOnly => 1.0,
        ChamberMethod::Sdirk4 => 2.0,
    }
}

fn statistics_counts(s: &Statistics) -> [u64; STATISTICS] {
    [
        s.steps,
        s.rejected,
        s.rhs_evaluations,
        s.jacobians,
        s.newton_failures,
        s.stiff_handovers,
    ]
}

/// `value` as a count, code or flag: a whole number from 0 to `max`; `what` names it.
fn whole_number(value: f64, max: usize, what: &str) -> Result<usize, String> {
    if value.is_finite() && value >= 0.0 && value.fract() == 0.0 && value <= max as f64 {
        Ok(value as usize)
    } else {
        Err(format!(
            "the simulation snapshot's {what} is {value}: must be a whole number from 0 to {max}"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{thesis_model, with};
    use super::*;
    use crate::physics::actuator::Outputs;
    use crate::physics::parameters::Parameters;

    fn model(change: impl Fn(&mut Parameters)) -> Actuator {
        let mut p = Parameters::default();
        change(&mut p);
        Actuator::new(p).unwrap()
    }

    /// Memory in every effect that carries some from step to step: the hysteresis plays, the
    /// transport delay's past commands, the force and chamber 1 transducers' lags, the friction's stopper
    /// velocity (and, from `drive`, a command rate).
    fn with_memory() -> Actuator {
        model(|p| {
            p.hysteresis_width = 0.16e-3;
            p.command_delay = 0.004;
            p.force_sensor_lag = 0.003;
            p.p1_sensor_lag = 0.002;
            p.friction_coulomb = 1.5;
        })
    }

    /// The rest of it: the command stage (a lag and a second-order filter), the force and chamber 2 transducers' delays, a
    /// varying supply feeding a plenum, a port line's volume.
    fn with_staged_memory() -> Actuator {
        model(|p| {
            p.supply_resistance = 2e8;
            p.supply_plenum_volume = 2e-6;
            p.port_restriction_area_1 = 0.2e-6;
            p.port_line_volume_1 = 3e-6;
            p.command_lag = 0.002;
            p.command_filter_frequency = 80.0;
            p.command_filter_damping = 0.5;
            p.force_sensor_delay = 0.002;
            p.p2_sensor_delay = 0.003;
            p.supply_ripple_sine = 2e4;
            p.supply_ripple_frequency = 50.0;
        })
    }

    /// Step `k`'s inputs: a sine command with a rate on every third step, a stopper that
    /// moves on some steps and jumps on others.
    fn drive(sim: &mut Simulation, k: usize) {
        let t = k as f64 * 1e-3;
        sim.set_command(2.5 + 3.0 * (40.0 * t).sin()).unwrap();
        if k % 3 == 0 {
            sim.set_command_rate(-150.0).unwrap();
        }
        if k % 17 == 5 {
            sim.set_stopper(0.05 + 0.004 * (k % 3) as f64).unwrap();
        }
        // (on the step before the snapshot too, so that it holds a stopper velocity)
        if k % 11 == 5 {
            sim.set_stopper_rate(0.2).unwrap();
        }
        sim.step(1e-3).unwrap();
    }

    fn bits(y: &Outputs) -> [u64; 6] {
        [y.f_act, y.p1, y.p2, y.current, y.x_jp, y.f_meas].map(f64::to_bits)
    }

    #[test]
    fn a_snapshot_taken_mid_run_continues_bit_identically_in_a_new_simulation() {
        let lagging_mount = with(|p| {
            p.stopper_compliance = 5e-5;
            p.stopper_mount_lag = 1e-3;
        });
        for model in [with_memory(), with_staged_memory(), thesis_model(), lagging_mount] {
            let mut original = Simulation::at_equilibrium(model.clone(), 1.0, 0.054, 0.0, 1e-6).unwrap();
            for k in 0..50 {
                drive(&mut original, k);
            }
            // Mid-run, with inputs set for the next step: they are memory too.
            original.set_command(7.0).unwrap();
            original.set_command_rate(30.0).unwrap();
            original.set_stopper(0.052).unwrap();
            let snapshot = original.snapshot();
            assert!(snapshot.command_history.len() > 1 || model.params.command_delay == 0.0);
            let mut restored = Simulation::restore(model.clone(), &snapshot).unwrap();
            let mut decoded =
                Simulation::restore(model, &SimulationSnapshot::from_values(&snapshot.to_values()).unwrap()).unwrap();
            let restored_as_taken = [restored.snapshot(), decoded.snapshot()];
            for k in 50..150 {
                let mut outputs = vec![];
                for sim in [&mut original, &mut restored, &mut decoded] {
                    if k > 50 {
                        drive(sim, k);
                    } else {
                        sim.step(1e-3).unwrap();
                    }
                    outputs.push(bits(&sim.outputs()));
                }
                assert_eq!(outputs[0], outputs[1], "restored, step {k}");
                assert_eq!(outputs[0], outputs[2], "decoded, step {k}");
            }
            // The outputs first, as a user sees them; then all of the memory.
            assert_eq!(restored_as_taken, [snapshot.clone(), snapshot]);
            assert_eq!(original.snapshot(), restored.snapshot());
            assert_eq!(original.snapshot(), decoded.snapshot());
        }
    }

    #[test]
    fn values_round_trip_every_field_and_work_counters_beyond_2_to_the_53() {
        let mut sim = Simulation::at_equilibrium(with_memory(), 1.0, 0.054, 0.0, 1e-6).unwrap();
        for k in 0..20 {
            drive(&mut sim, k);
        }
        sim.method = Method::Monolithic;
        sim.chamber_method = ChamberMethod::DormandPrinceOnly;
        sim.input_changed = true;
        sim.statistics.steps = (1 << 53) + 1;
        sim.statistics.stiff_handovers = u64::MAX;
        let snapshot = sim.snapshot();
        let values = snapshot.to_values();
        assert_eq!(values[0], SNAPSHOT_LAYOUT);
        let back = SimulationSnapshot::from_values(&values).unwrap();
        assert_eq!(back, snapshot);
        assert_eq!(back.statistics.steps, (1 << 53) + 1);
        assert_eq!(back.statistics.stiff_handovers, u64::MAX);
        assert_eq!(
            back.to_values().iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            values.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
    }

    #[test]
    fn from_values_refuses_wrong_lengths_and_malformed_counts_with_a_clear_message() {
        let mut sim = Simulation::at_equilibrium(with_memory(), 1.0, 0.054, 0.0, 1e-6).unwrap();
        for k in 0..20 {
            drive(&mut sim, k);
        }
        let values = sim.snapshot().to_values();
        let refused = |v: &[f64]| SimulationSnapshot::from_values(v).unwrap_err();
        let history_count = FIXED_VALUES;
        let changes = values[history_count] as usize;
        let sensor_count = history_count + 1 + 3 * changes;

        assert!(refused(&[]).contains("holds no values"));
        let mut other = values.clone();
        other[0] = SNAPSHOT_LAYOUT + 1.0;
        assert!(refused(&other).contains(&format!("layout {} is not supported", SNAPSHOT_LAYOUT + 1.0)));
        assert!(refused(&values[..FIXED_VALUES]).contains("fewer than the"));
        // One number too few or too many: the counts no longer match the length.
        let e = refused(&values[..values.len() - 1]);
        assert!(e.contains("transducer value count"), "{e}");
        let mut longer = values.clone();
        longer.push(0.0);
        assert!(refused(&longer).contains("1 more than its counts account for"));
        for bad in [f64::NAN, f64::INFINITY, -1.0, 0.5, 1e9] {
            let mut v = values.clone();
            v[history_count] = bad;
            let e = refused(&v);
            assert!(
                e.contains("past command count") && e.contains("whole number"),
                "{bad}: {e}"
            );
            let mut v = values.clone();
            v[sensor_count] = bad;
            assert!(refused(&v).contains("transducer value count"), "{bad}");
        }
        let mut v = values.clone();
        v[7] = 3.0;
        assert!(refused(&v).contains("method code is 3"));
        let mut v = values.clone();
        v[1] = f64::NAN;
        assert!(refused(&v).contains("non-finite"));
        let mut v = values.clone();
        v[FIXED_VALUES - 1] = 2f64.powi(32);
        assert!(refused(&v).contains("work counter half"));
    }

    #[test]
    fn restore_refuses_a_stopper_outside_the_models_cylinder() {
        let sim = Simulation::at_equilibrium(thesis_model(), 1.0, 0.054, 0.0, 1e-6).unwrap();
        let mut values = sim.snapshot().to_values();
        values[3] = 0.2;
        let snapshot = SimulationSnapshot::from_values(&values).unwrap();
        let e = Simulation::restore(thesis_model(), &snapshot).unwrap_err();
        assert!(e.contains("x_s") && e.contains("0.2"), "{e}");
    }
}
