//! The actuator behind the generic FMI layer: maps the variable table onto the physics
//! and the simulation driver. No FFI types here. Model Exchange: the private module
//! `model_exchange`.

mod model_exchange;

use crate::variables::{me_vr, vr, CONTINUOUS_STATES, UNITS, VARIABLES};
use fmi2::model::{
    CoSimModel, DependencyKind, Extent, GuidCache, ModelExchangeInfo, ModelInfo, OutputDependencies, StepError,
};
use fmi2::state_bytes::StateFormat;
use jetpipe_model::physics::actuator::{index, Actuator};
use jetpipe_model::physics::parameters::{variable_name, Parameters};
use jetpipe_model::simulation::{Simulation, SimulationSnapshot, StepFailure, DEFAULT_RELATIVE_TOLERANCE};

pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logEvents", "initialisation, resets and state restores"),
    ("logStatusWarning", "messages with status fmi2Warning"),
    ("logStatusDiscard", "messages with status fmi2Discard"),
    ("logStatusError", "messages with status fmi2Error"),
    ("logStatusFatal", "messages with status fmi2Fatal"),
    ("logAll", "every message"),
];

pub use jetpipe_model::variables::V_DA_RANGE;

/// `min`, `max` and `nominal` of the model description. Parameters: the bounds that
/// `Parameters::set` enforces (FMI has no open bounds, so "> 0" is `min="0"`) and the
/// default's magnitude as nominal. `x_s`: the stopper range of the default geometry (the
/// run-time check uses the geometry actually set). `v_DA`: the D/A range.
pub fn extent(value_reference: u32) -> Extent {
    let defaults = Parameters::default();
    let scale = |x: f64| if x != 0.0 && x.is_finite() { Some(x.abs()) } else { None };
    match value_reference {
        vr::V_DA => Extent {
            min: Some(V_DA_RANGE.0),
            max: Some(V_DA_RANGE.1),
            nominal: Some(V_DA_RANGE.1),
        },
        vr::X_S => {
            let (lo, hi) = defaults.cylinder().stopper_range();
            Extent {
                min: Some(lo),
                max: Some(hi),
                nominal: scale(start(vr::X_S)),
            }
        }
        vr::A_S => {
            let v = &jetpipe_model::variables::row(vr::A_S).expect("a_s has a row").variable;
            Extent {
                min: v.min,
                max: v.max,
                nominal: Some(1.0),
            }
        }
        vr::P1 | vr::P2 => Extent {
            min: Some(0.0),
            max: None,
            nominal: scale(defaults.p_s),
        },
        vr::I => Extent {
            min: None,
            max: None,
            nominal: scale(defaults.k_cd * V_DA_RANGE.1),
        },
        vr::X_JP => Extent {
            min: None,
            max: None,
            nominal: scale(defaults.x_jp_sat),
        },
        vr::F_ACT | vr::F_MEAS => Extent {
            min: None,
            max: None,
            nominal: Some(100.0),
        },
        vr::P1_MEAS | vr::P2_MEAS => Extent {
            min: None,
            max: None,
            nominal: scale(defaults.p_s),
        },
        vr::P1_START | vr::P2_START => Extent {
            min: Some(0.0),
            max: None,
            nominal: scale(start(value_reference)),
        },
        _ => match Parameters::declared_range(value_reference) {
            Some((min, max)) => Extent {
                min,
                max,
                nominal: scale(start(value_reference)),
            },
            None => Extent::default(),
        },
    }
}

const DEPENDS: DependencyKind = DependencyKind::Dependent;

/// `<ModelStructure>`: a new x_s moves the stopper at once (the chamber pressures jump,
/// conserving the air), so the pressures and forces depend on it directly; a new v_DA acts
/// only through the current's dynamics, during the next step. After initialisation the
/// current and the jet pipe are at the static values of v_DA; the pressures and forces
/// depend on everything.
pub const DEPENDENCIES: &[OutputDependencies] = &[
    OutputDependencies {
        output: vr::F_ACT,
        step: &[(vr::X_S, DEPENDS), (vr::A_S, DEPENDS)],
        initial: None,
    },
    OutputDependencies {
        output: vr::F_MEAS,
        step: &[(vr::X_S, DEPENDS), (vr::A_S, DEPENDS)],
        initial: None,
    },
    OutputDependencies {
        output: vr::P1,
        step: &[(vr::X_S, DEPENDS)],
        initial: None,
    },
    OutputDependencies {
        output: vr::P2,
        step: &[(vr::X_S, DEPENDS)],
        initial: None,
    },
    OutputDependencies {
        output: vr::P1_MEAS,
        step: &[(vr::X_S, DEPENDS)],
        initial: None,
    },
    OutputDependencies {
        output: vr::P2_MEAS,
        step: &[(vr::X_S, DEPENDS)],
        initial: None,
    },
    OutputDependencies {
        output: vr::I,
        step: &[],
        initial: Some(&[
            (vr::V_DA, DEPENDS),
            (vr::K_CD, DEPENDS),
            (vr::I_OFFSET, DEPENDS),
            (vr::COMMAND_LIMIT, DEPENDS),
            (vr::CURRENT_LIMIT, DEPENDS),
            (vr::F3_INPUT_CUBIC, DEPENDS),
        ]),
    },
    OutputDependencies {
        output: vr::X_JP,
        step: &[],
        initial: Some(&[
            (vr::V_DA, DEPENDS),
            (vr::K_CD, DEPENDS),
            (vr::I_OFFSET, DEPENDS),
            (vr::COMMAND_LIMIT, DEPENDS),
            (vr::CURRENT_LIMIT, DEPENDS),
            (vr::F3_INPUT_CUBIC, DEPENDS),
            (vr::K_M, DEPENDS),
            (vr::X_JP_SAT, DEPENDS),
            (vr::F_JP_SAT, DEPENDS),
        ]),
    },
];

pub static MODEL_INFO: ModelInfo = ModelInfo {
    model_name: "JetPipeActuator",
    model_identifier: "JetPipeActuator",
    description: "Jet-pipe electropneumatic actuator of the Utah/MIT Dextrous Hand (P.D. Henri, 1994): current driver, third-order jet pipe, orifice flows, leaky piston, two chambers with a moving stopper",
    author: "jetpipe project",
    version: env!("CARGO_PKG_VERSION"),
    generation_tool: concat!("jetpipe ", env!("CARGO_PKG_VERSION")),
    default_start_time: 0.0,
    default_stop_time: 10.0,
    default_tolerance: DEFAULT_RELATIVE_TOLERANCE,
    default_step_size: 1e-3,
    log_categories: LOG_CATEGORIES,
    units: UNITS,
    variables: VARIABLES,
    can_interpolate_inputs: true,
    extent,
    dependencies: DEPENDENCIES,
    model_exchange: Some(&MODEL_EXCHANGE),
    guid_cache: GuidCache::new(),
};

/// Model Exchange: the thirty-one states (the six of (4.1), the volumes' pressures and the
/// mount's load, the command stage's and the transducers' lags and filters, the transport
/// delay's Padé chain), the event indicators and the hysteresis memory of the private module
/// `model_exchange`.
// The state vector of `model_exchange` is the model description's.
const _: () = assert!(model_exchange::STATES == CONTINUOUS_STATES.len());

pub static MODEL_EXCHANGE: ModelExchangeInfo = ModelExchangeInfo {
    states: &CONTINUOUS_STATES,
    event_indicators: model_exchange::EVENT_INDICATORS,
    // the hysteresis memory is advanced after each accepted step (model_exchange's text)
    needs_completed_integrator_step: true,
};

/// How far past an end of the D/A range, in units of the end's last place, a command is still
/// that end: an importer's linear interpolation between two samples at +10 V gives
/// 10.000000000000002 V (one place past) at some instants, which is the end, not a wrong value.
const COMMAND_ROUNDING_PLACES: f64 = 4.0;

/// v_DA within the D/A range, a rounding past an end taken as that end; the message names the
/// variable, the value and the range.
fn checked_command(v_da: f64) -> Result<f64, String> {
    let (lo, hi) = V_DA_RANGE;
    let rounding = |end: f64| COMMAND_ROUNDING_PLACES * f64::EPSILON * end.abs();
    if (lo..=hi).contains(&v_da) {
        Ok(v_da)
    } else if v_da > hi && v_da - hi <= rounding(hi) {
        Ok(hi)
    } else if v_da < lo && lo - v_da <= rounding(lo) {
        Ok(lo)
    } else {
        Err(format!(
            "v_DA = {v_da} V is invalid: must be finite and within the D/A range [{lo}, {hi}] V"
        ))
    }
}

/// One FMU instance: parameters and inputs until initialisation, then a simulation.
#[derive(Clone, Debug)]
pub struct ActuatorFmu {
    params: Parameters,
    v_da: f64,
    x_s: f64,
    v_da_rate: f64,
    x_s_rate: f64,
    /// The stopper acceleration input and its rate, until initialisation ends.
    a_s: f64,
    a_s_rate: f64,
    start_at_equilibrium: bool,
    p1_start: f64,
    p2_start: f64,
    tolerance: f64,
    start_time: f64,
    simulation: Option<Simulation>,
    /// The last x_s set before initialisation ended that was inside the cylinder (the table's
    /// start at first): where the stopper starts if the last x_s set was not.
    x_s_valid: f64,
    /// Made for Model Exchange ([`CoSimModel::use_model_exchange`]).
    model_exchange: bool,
    /// A Model Exchange instance after initialisation (then `simulation` stays `None`).
    me: Option<model_exchange::MeState>,
    /// `command_delay_pade_sections`: the transport delay as a Padé chain in Model Exchange
    /// (0: refused there; Co-Simulation keeps its exact delay).
    pade_sections: f64,
}

fn start(value_reference: u32) -> f64 {
    jetpipe_model::physics::parameters::table_start(value_reference)
}

impl ActuatorFmu {
    /// The state the simulation would start from with the current settings.
    fn initial_simulation(&self) -> Result<Simulation, String> {
        let model = Actuator::new(self.params.clone())?;
        model.params.check_stopper(self.x_s)?;
        let mut simulation = if self.start_at_equilibrium {
            Simulation::at_equilibrium(model, self.v_da, self.x_s, self.start_time, self.tolerance)?
        } else {
            Simulation::at_pressures(
                model,
                self.v_da,
                self.x_s,
                self.start_time,
                self.tolerance,
                [self.p1_start, self.p2_start],
            )?
        };
        simulation.set_command_rate(self.v_da_rate)?;
        simulation.set_stopper_rate(self.x_s_rate)?;
        simulation.set_stopper_acceleration(self.a_s)?;
        simulation.set_stopper_acceleration_rate(self.a_s_rate)?;
        Ok(simulation)
    }

    pub fn simulation(&self) -> Option<&Simulation> {
        self.simulation.as_ref()
    }

    /// [`CoSimModel::get_real`] for any variable, before and after initialisation.
    #[cold]
    #[inline(never)]
    fn get_real_otherwise(&self, value_reference: u32) -> Result<f64, String> {
        if value_reference == me_vr::COMMAND_DELAY_PADE_SECTIONS {
            return Ok(self.pade_sections);
        }
        if let Some(x) = self.me_real(value_reference) {
            return Ok(x);
        }
        if (me_vr::FIRST..=me_vr::LAST).contains(&value_reference) {
            let computed;
            let simulation = match &self.simulation {
                Some(s) => s,
                None => {
                    computed = self.initial_simulation()?;
                    &computed
                }
            };
            let memory = simulation.hysteresis_memory();
            let filters = model_exchange::filters_of(simulation);
            let command = model_exchange::seen_command(&simulation.model().params, simulation.v_da(), &filters);
            let at = model_exchange::At {
                model: simulation.model(),
                x: simulation.state(),
                nodes: &model_exchange::nodes_of(simulation),
                filters: &filters,
                chain: &[command; model_exchange::PADE_SECTIONS],
                sections: 0,
                v_da: simulation.v_da(),
                x_s: simulation.x_s(),
                scale: model_exchange::AirScale::at(simulation.model(), simulation.x_s()),
                time: simulation.time(),
                memory: memory.as_ref(),
            };
            return model_exchange::state_variable(&at, value_reference)
                .ok_or_else(|| format!("no Real variable with value reference {value_reference}"));
        }
        match value_reference {
            vr::V_DA => Ok(self.simulation.as_ref().map_or(self.v_da, Simulation::v_da)),
            vr::X_S => Ok(self.simulation.as_ref().map_or(self.x_s, Simulation::x_s)),
            vr::A_S => Ok(self
                .simulation
                .as_ref()
                .map_or(self.a_s, Simulation::stopper_acceleration_input)),
            vr::F_ACT | vr::F_MEAS | vr::P1 | vr::P2 | vr::P1_MEAS | vr::P2_MEAS | vr::I | vr::X_JP => {
                let computed;
                let simulation = match &self.simulation {
                    Some(s) => s,
                    None => {
                        computed = self.initial_simulation()?;
                        &computed
                    }
                };
                // The states among the outputs are read as they are: an importer asks for the
                // outputs one value reference at a time, and the others cost a force each.
                let state = simulation.state();
                Ok(match value_reference {
                    vr::P1 => state[index::P1],
                    vr::P2 => state[index::P2],
                    vr::I => state[index::CURRENT],
                    vr::X_JP => state[index::JET_POSITION],
                    _ => {
                        let y = simulation.outputs();
                        match value_reference {
                            vr::F_ACT => y.f_act,
                            vr::F_MEAS => y.f_meas,
                            vr::P1_MEAS => y.p1_meas,
                            _ => y.p2_meas,
                        }
                    }
                })
            }
            vr::P1_START => Ok(self.p1_start),
            vr::P2_START => Ok(self.p2_start),
            _ => self
                .params
                .get(value_reference)
                .ok_or_else(|| format!("no Real variable with value reference {value_reference}")),
        }
    }
}

impl CoSimModel for ActuatorFmu {
    fn info() -> &'static ModelInfo {
        &MODEL_INFO
    }

    fn instantiate() -> Self {
        Self {
            params: Parameters::default(),
            v_da: start(vr::V_DA),
            x_s: start(vr::X_S),
            v_da_rate: 0.0,
            x_s_rate: 0.0,
            a_s: start(vr::A_S),
            a_s_rate: 0.0,
            start_at_equilibrium: start(vr::START_AT_EQUILIBRIUM) != 0.0,
            p1_start: start(vr::P1_START),
            p2_start: start(vr::P2_START),
            tolerance: DEFAULT_RELATIVE_TOLERANCE,
            start_time: 0.0,
            simulation: None,
            x_s_valid: start(vr::X_S),
            model_exchange: false,
            me: None,
            pade_sections: 0.0,
        }
    }

    fn use_model_exchange(&mut self) {
        self.model_exchange = true;
    }

    /// The inputs and outputs of a simulation at once (an importer reads them every step);
    /// everything else, and everything before initialisation ends, from
    /// `ActuatorFmu::get_real_otherwise`.
    #[inline]
    fn get_real(&self, value_reference: u32) -> Result<f64, String> {
        let simulation = match &self.simulation {
            Some(simulation) => simulation,
            None => return self.get_real_otherwise(value_reference),
        };
        let state = simulation.state();
        Ok(match value_reference {
            vr::P1 => state[index::P1],
            vr::P2 => state[index::P2],
            vr::I => state[index::CURRENT],
            vr::X_JP => state[index::JET_POSITION],
            vr::F_ACT => simulation.outputs().f_act,
            vr::V_DA => simulation.v_da(),
            vr::X_S => simulation.x_s(),
            _ => return self.get_real_otherwise(value_reference),
        })
    }

    fn set_real(&mut self, value_reference: u32, value: f64) -> Result<(), String> {
        match value_reference {
            vr::V_DA => {
                let value = checked_command(value)?;
                match &mut self.simulation {
                    Some(s) => s.set_command(value),
                    None => {
                        self.v_da = value;
                        Ok(())
                    }
                }
            }
            vr::X_S => match &mut self.simulation {
                Some(s) => {
                    s.set_stopper(value)?;
                    self.x_s = value;
                    Ok(())
                }
                // Before initialisation ends, a master may start its connectors at 0 and
                // propagate the other FMUs' outputs only afterwards: any finite value is taken,
                // and checked when initialisation ends and at each step.
                None if value.is_finite() && self.me.is_some() => self.move_stopper_model_exchange(value),
                None if value.is_finite() => {
                    self.x_s = value;
                    if self.params.check_stopper(value).is_ok() {
                        self.x_s_valid = value;
                    }
                    Ok(())
                }
                None => Err(format!("x_s = {value} m is invalid: must be finite")),
            },
            vr::A_S => match &mut self.simulation {
                Some(s) => s.set_stopper_acceleration(value),
                None => {
                    jetpipe_model::variables::check(value_reference, value)?;
                    self.a_s = value;
                    Ok(())
                }
            },
            me_vr::COMMAND_DELAY_PADE_SECTIONS => {
                self.pade_sections = model_exchange::check_pade_sections(value)?;
                Ok(())
            }
            vr::P1_START | vr::P2_START => {
                jetpipe_model::variables::check(value_reference, value)?;
                if value_reference == vr::P1_START {
                    self.p1_start = value;
                } else {
                    self.p2_start = value;
                }
                Ok(())
            }
            _ => {
                if self.model_exchange {
                    model_exchange::refused_setting(value_reference, value)?;
                }
                self.params.set(value_reference, value)
            }
        }
    }

    fn get_boolean(&self, value_reference: u32) -> Result<bool, String> {
        match value_reference {
            vr::START_AT_EQUILIBRIUM => Ok(self.start_at_equilibrium),
            _ => Err(format!("no Boolean variable with value reference {value_reference}")),
        }
    }

    fn set_boolean(&mut self, value_reference: u32, value: bool) -> Result<(), String> {
        match value_reference {
            vr::START_AT_EQUILIBRIUM => {
                self.start_at_equilibrium = value;
                Ok(())
            }
            _ => Err(format!("no Boolean variable with value reference {value_reference}")),
        }
    }

    fn setup_experiment(
        &mut self,
        tolerance: Option<f64>,
        start_time: f64,
        _stop_time: Option<f64>,
    ) -> Result<(), String> {
        if let Some(t) = tolerance {
            if !(t.is_finite() && t > 0.0 && t < 1.0) {
                return Err(format!("tolerance = {t} is invalid: must be in (0, 1)"));
            }
            // Below 1e-12 the error estimate is rounding noise.
            self.tolerance = t.max(1e-12);
        }
        if !start_time.is_finite() {
            return Err(format!("startTime = {start_time} s is invalid: must be finite"));
        }
        self.start_time = start_time;
        Ok(())
    }

    /// With an x_s outside the cylinder (a master that set its connectors to 0 and propagates
    /// outputs only with the first step), the stopper starts at the last valid x_s set (or the
    /// start value), and the first step is refused unless a valid x_s has been set by then.
    fn exit_initialization(&mut self) -> Result<(), String> {
        if self.model_exchange {
            return self.exit_initialization_model_exchange();
        }
        let simulation = match self.params.check_stopper(self.x_s) {
            Ok(()) => self.initial_simulation()?,
            Err(e) => {
                let mut fallback = self.clone();
                fallback.x_s = self.x_s_valid;
                fallback.params.check_stopper(fallback.x_s).map_err(|_| e)?;
                fallback.initial_simulation()?
            }
        };
        self.simulation = Some(simulation);
        Ok(())
    }

    fn set_real_input_derivative(&mut self, value_reference: u32, order: i32, value: f64) -> Result<(), String> {
        if order != 1 {
            return Err(format!(
                "input derivative of order {order} for {} is not supported: only order 1",
                variable_name(value_reference)
            ));
        }
        match (value_reference, &mut self.simulation) {
            (vr::V_DA, Some(s)) => s.set_command_rate(value),
            (vr::X_S, Some(s)) => s.set_stopper_rate(value),
            (vr::A_S, Some(s)) => s.set_stopper_acceleration_rate(value),
            (vr::V_DA | vr::X_S | vr::A_S, None) if !value.is_finite() => Err(format!(
                "der({}) = {value} is invalid: must be finite",
                variable_name(value_reference)
            )),
            (vr::V_DA, None) => {
                self.v_da_rate = value;
                Ok(())
            }
            (vr::X_S, None) => {
                self.x_s_rate = value;
                Ok(())
            }
            (vr::A_S, None) => {
                self.a_s_rate = value;
                Ok(())
            }
            _ => Err(format!("value reference {value_reference} is not an input")),
        }
    }

    fn do_step(&mut self, _current_time: f64, step_size: f64) -> Result<(), StepError> {
        // An x_s set before initialisation ended and never corrected (see exit_initialization).
        if self.simulation.is_some() {
            if let Err(e) = self.params.check_stopper(self.x_s) {
                return Err(StepError::Error(format!(
                    "{e} (the x_s set during initialisation; set a valid x_s before the first step)"
                )));
            }
        }
        let simulation = self
            .simulation
            .as_mut()
            .ok_or_else(|| StepError::Error("the model is not initialised".to_string()))?;
        simulation.step(step_size).map_err(|failure| match failure {
            StepFailure::InvalidRequest(message) => StepError::Error(message),
            StepFailure::Integration { message, time } => StepError::Discard {
                message,
                last_successful_time: time,
            },
        })
    }

    fn time(&self) -> f64 {
        match &self.simulation {
            Some(simulation) => simulation.time(),
            None => self.me_time().unwrap_or(self.start_time),
        }
    }

    fn serialize(&self) -> Vec<u8> {
        let mut w = STATE_FORMAT.writer();
        for &value_reference in Parameters::VALUE_REFERENCES {
            w.f64(self.params.get(value_reference).unwrap_or(f64::NAN));
        }
        for v in [
            self.v_da,
            self.x_s,
            self.v_da_rate,
            self.x_s_rate,
            self.a_s,
            self.a_s_rate,
            self.p1_start,
            self.p2_start,
            self.tolerance,
            self.start_time,
        ] {
            w.f64(v);
        }
        w.bool(self.start_at_equilibrium);
        self.serialize_model_exchange(&mut w);
        match &self.simulation {
            None => w.bool(false),
            Some(s) => {
                w.bool(true);
                w.f64s(&s.snapshot().to_values());
            }
        }
        w.into_bytes()
    }

    fn deserialize(&mut self, bytes: &[u8]) -> Result<(), String> {
        let mut r = STATE_FORMAT.reader(bytes)?;
        let mut restored = Self::instantiate();
        for &value_reference in Parameters::VALUE_REFERENCES {
            restored.params.set(value_reference, r.f64()?)?;
        }
        restored.v_da = r.f64()?;
        restored.x_s = r.f64()?;
        restored.v_da_rate = r.f64()?;
        restored.x_s_rate = r.f64()?;
        restored.a_s = r.f64()?;
        restored.a_s_rate = r.f64()?;
        restored.p1_start = r.f64()?;
        restored.p2_start = r.f64()?;
        restored.tolerance = r.f64()?;
        restored.start_time = r.f64()?;
        restored.start_at_equilibrium = r.bool("startAtEquilibrium")?;
        Self::deserialize_model_exchange(&mut r, &mut restored)?;
        if r.bool("initialised")? {
            let model = Actuator::new(restored.params.clone())?;
            let values = r.f64s_at_most(MAX_SIMULATION_VALUES, "simulation values")?;
            let snapshot = SimulationSnapshot::from_values(&values)?;
            restored.simulation = Some(Simulation::restore(model, &snapshot)?);
        }
        r.finish()?;
        *self = restored;
        Ok(())
    }
}

/// The header of the actuator's state bytes (the layer's byte format, as the other FMUs'),
/// then the parameters, the inputs and settings of the instance, and, once initialised, the
/// simulation's snapshot as one counted array (`SimulationSnapshot::to_values`). Version 3:
/// the snapshot replaced the simulation's fields written one by one; version 4: the
/// restrictions' parameters and the pressures of the gas volumes behind them; version 5: the
/// interface and the Model Exchange state; version 6: the modulation slots' parameters;
/// version 7: the laminar chamber leaks and the extra force's product slots; version 8: the
/// extra flow slots; version 9: the stopper acceleration input; version 10: Model Exchange's
/// hysteresis memory; version 11: Model Exchange's states of the lags, filters and Padé chain
/// and `command_delay_pade_sections`; version 12: the plain constants `extra_force_offset`,
/// `extra_inflow_1`, `extra_inflow_2`, the flexible slots' parameters and, in the snapshot
/// (its layout 10), their lags; version 13: Model Exchange's chamber states are their air at
/// mid-stroke; version 14: in the snapshot (its layout 11), the stopper's offset the last step
/// held.
const STATE_FORMAT: StateFormat =
    fmi2::state_format!(magic: b"JetPipeActuatorState", version: 14, model: "JetPipeActuator");

/// Far more numbers than a simulation's snapshot holds (about 60 and the past commands: three
/// for each communication step within the transport delay, 3e5 for a 0.1 s delay stepped
/// every microsecond), so that a corrupted count is refused with its own message.
const MAX_SIMULATION_VALUES: usize = 1 << 24;

#[cfg(test)]
mod tests {
    use super::*;

    fn initialised() -> ActuatorFmu {
        let mut fmu = ActuatorFmu::instantiate();
        fmu.setup_experiment(Some(1e-6), 0.0, None).unwrap();
        fmu.set_real(vr::V_DA, 2.5).unwrap();
        fmu.exit_initialization().unwrap();
        fmu
    }

    #[test]
    fn serialized_state_continues_bit_identically() {
        let mut a = initialised();
        a.do_step(0.0, 0.05).unwrap();
        let bytes = a.serialize();
        let mut b = ActuatorFmu::instantiate();
        b.deserialize(&bytes).unwrap();
        for fmu in [&mut a, &mut b] {
            fmu.set_real(vr::V_DA, 6.0).unwrap();
            fmu.do_step(0.05, 0.05).unwrap();
        }
        for value_reference in [vr::F_ACT, vr::P1, vr::P2, vr::I, vr::X_JP] {
            assert_eq!(
                a.get_real(value_reference).unwrap().to_bits(),
                b.get_real(value_reference).unwrap().to_bits()
            );
        }
    }

    #[test]
    fn corrupted_or_foreign_states_are_rejected_and_leave_the_instance_unchanged() {
        let mut fmu = initialised();
        let bytes = fmu.serialize();
        let before = fmu.get_real(vr::F_ACT).unwrap();
        let mut truncated = bytes.clone();
        truncated.truncate(bytes.len() - 3);
        assert!(fmu.deserialize(&truncated).unwrap_err().contains("truncated"));
        let mut foreign = bytes.clone();
        foreign[0] ^= 0xff;
        assert!(fmu.deserialize(&foreign).is_err());
        let mut longer = bytes.clone();
        longer.push(0);
        assert!(fmu.deserialize(&longer).unwrap_err().contains("trailing"));
        assert_eq!(fmu.get_real(vr::F_ACT).unwrap(), before);
    }

    #[test]
    fn states_of_another_format_or_with_a_malformed_snapshot_are_refused_with_the_reason() {
        let mut fmu = initialised();
        fmu.do_step(0.0, 0.01).unwrap();
        let bytes = fmu.serialize();
        let before = fmu.serialize();
        let mut older = bytes.clone();
        let at = STATE_FORMAT.magic.len();
        older[at..at + 4].copy_from_slice(&2u32.to_le_bytes());
        let e = fmu.deserialize(&older).unwrap_err();
        assert!(e.contains("format version 2 is not supported"), "{e}");
        // The last number is the snapshot's count of chamber 2 transducer values (none here).
        let mut malformed = bytes.clone();
        let n = malformed.len();
        malformed[n - 8..].copy_from_slice(&0.5f64.to_le_bytes());
        let e = fmu.deserialize(&malformed).unwrap_err();
        assert!(e.contains("transducer value count is 0.5"), "{e}");
        assert_eq!(fmu.serialize(), before);
    }

    #[test]
    fn a_command_one_rounding_past_the_d_a_range_is_its_end_and_a_nanovolt_past_is_refused() {
        let (lo, hi) = V_DA_RANGE;
        for (end, past) in [(hi, 10.000000000000002), (lo, -10.000000000000002)] {
            assert!(past != end, "the rounding is past the end");
            let mut fmu = ActuatorFmu::instantiate();
            fmu.set_real(vr::V_DA, past).unwrap();
            assert_eq!(fmu.get_real(vr::V_DA).unwrap(), end);
            fmu.exit_initialization().unwrap();
            fmu.set_real(vr::V_DA, past).unwrap();
            assert_eq!(fmu.get_real(vr::V_DA).unwrap(), end);
            let beyond = end + end.signum() * 1e-9;
            let message = fmu.set_real(vr::V_DA, beyond).unwrap_err();
            assert!(message.contains("v_DA") && message.contains("D/A range"), "{message}");
        }
    }

    #[test]
    fn outputs_before_initialisation_are_the_equilibrium() {
        let mut fmu = ActuatorFmu::instantiate();
        fmu.set_real(vr::V_DA, 2.5).unwrap();
        let early = fmu.get_real(vr::F_ACT).unwrap();
        fmu.exit_initialization().unwrap();
        assert_eq!(early, fmu.get_real(vr::F_ACT).unwrap());
        assert!(early > 10.0 && early < 112.0, "{early}");
    }

    #[test]
    fn declared_dependencies_are_what_perturbations_show() {
        // With a moving mass that reads the stopper acceleration input, which the forces then
        // follow at once; at the start values it is not read.
        let settings = [
            (vr::EXTRA_FORCE_ACCELERATION, -0.2),
            (vr::STOPPER_ACCELERATION_INPUT_SHARE, 1.0),
        ];
        let report = fmi2::structure_check::check_dependencies_with::<ActuatorFmu>(1e-3, &settings);
        assert!(report.problems.is_empty(), "{:#?}", report.problems);
        // Only the stopper acts within a step, on the pressures and the forces, and its
        // acceleration on the forces.
        let mut pairs = report.step_pairs.clone();
        pairs.sort();
        assert_eq!(
            pairs,
            vec![
                ("F_act", "a_s"),
                ("F_act", "x_s"),
                ("F_meas", "a_s"),
                ("F_meas", "x_s"),
                ("P1", "x_s"),
                ("P1_meas", "x_s"),
                ("P2", "x_s"),
                ("P2_meas", "x_s")
            ]
        );
        // Nothing is skipped but what validate() refuses when set alone: a deadband wider than
        // the (zero) hysteresis width, each gas volume without its restriction, each static
        // curve's knot count (five curves), a whole number that a small perturbation cannot be,
        // and each modulation slot's constant, signal code and knot count (two slots), which
        // are whole numbers too, as the extra force product slots' two signal codes (three
        // slots), the extra flow slots' chamber and signal code (three slots) and each flexible
        // slot's constant, two signal codes and two knot counts (two slots).
        let refused_alone = |message: &String| {
            message.starts_with("hysteresis_deadband = ")
                || (message.contains("_curve_knots = ") && message.contains("must be 0 (off) or a whole number"))
                || (message.starts_with("modulation_")
                    && ["_parameter = ", "_signal = ", "_knots = "]
                        .iter()
                        .any(|field| message.contains(field))
                    && message.contains("is invalid: must be"))
                || (message.starts_with("extra_force_product_")
                    && ["_first = ", "_second = "].iter().any(|field| message.contains(field))
                    && message.contains("is invalid: must be a whole number"))
                || (message.starts_with("flexible_")
                    && [
                        "_parameter = ",
                        "_signal_1 = ",
                        "_signal_2 = ",
                        "_knots_1 = ",
                        "_knots_2 = ",
                    ]
                    .iter()
                    .any(|field| message.contains(field))
                    && message.contains("is invalid: must be"))
                || (message.starts_with("extra_flow_")
                    && ["_chamber = ", "_signal = "]
                        .iter()
                        .any(|field| message.contains(field))
                    && message.contains("is invalid: must be"))
                || [
                    "supply_plenum_volume",
                    "return_plenum_volume",
                    "port_line_volume_1",
                    "port_line_volume_2",
                ]
                .iter()
                .any(|name| {
                    message.starts_with(&format!("{name} = ")) && message.contains("invalid without a restriction")
                })
        };
        assert!(report.skipped.len() <= 38, "{:#?}", report.skipped);
        assert!(report.skipped.iter().all(refused_alone), "{:#?}", report.skipped);
    }

    /// Every declared min/max is what the FMU enforces: a value just outside is refused
    /// with a message that names the variable and the value, and a value just inside (or
    /// on a closed bound) is taken.
    #[test]
    fn declared_bounds_are_the_enforced_ones() {
        let info = ActuatorFmu::info();
        let mut checked = 0;
        for v in info.variables {
            if v.var_type != fmi2::model::VarType::Real || v.causality == fmi2::model::Causality::Output {
                continue;
            }
            let e = info.extent_of(v);
            for (bound, outward) in [(e.min, -1.0), (e.max, 1.0)] {
                let Some(b) = bound else { continue };
                let step = 1e-9 * b.abs().max(1e-3);
                let outside = b + outward * step;
                let inside = b - outward * step;
                let mut fmu = ActuatorFmu::instantiate();
                fmu.setup_experiment(None, 0.0, None).unwrap();
                // Refused when set, when initialisation ends, or (x_s) at the first step.
                let refused = fmu
                    .set_real(v.value_reference, outside)
                    .and_then(|_| fmu.exit_initialization())
                    .and_then(|_| {
                        fmu.do_step(0.0, 1e-3).map_err(|e| match e {
                            StepError::Error(m) | StepError::Discard { message: m, .. } => m,
                        })
                    });
                let message = refused.expect_err(&format!("{} = {outside} was taken", v.name));
                assert!(
                    message.contains(v.name)
                        && (message.contains(&format!("{outside}"))
                            || message.contains(&jetpipe_model::variables::number(outside))),
                    "{message}"
                );
                let mut fmu = ActuatorFmu::instantiate();
                fmu.set_real(v.value_reference, inside)
                    .unwrap_or_else(|e| panic!("{} = {inside} refused: {e}", v.name));
                checked += 1;
            }
        }
        assert!(checked >= 30, "{checked}");
    }

    #[test]
    fn nominals_are_positive_and_ranges_hold_the_defaults() {
        let info = ActuatorFmu::info();
        fmi2::model_description::validate_model_info(info).unwrap();
        let x_s = info.variables.iter().find(|v| v.value_reference == vr::X_S).unwrap();
        let e = info.extent_of(x_s);
        // The default geometry: the stopper between the support and the piston's travel.
        assert!(
            (e.min.unwrap() - 0.026).abs() < 1e-12 && (e.max.unwrap() - 0.096).abs() < 1e-12,
            "{e:?}"
        );
    }

    /// A master may start its connectors at 0 before initialisation and propagate the other
    /// FMUs' outputs only afterwards: x_s = 0 is taken then; the stopper starts at the last
    /// valid x_s, and a step is refused, with the message of a step-time x_s, until a valid
    /// x_s has been set.
    #[test]
    fn stopper_checked_when_initialisation_ends_and_at_each_step() {
        let mut fmu = ActuatorFmu::instantiate();
        fmu.setup_experiment(None, 0.0, None).unwrap();
        fmu.enter_initialization().unwrap();
        fmu.set_real(vr::X_S, 0.0).unwrap();
        fmu.set_real(vr::X_S, 0.05).unwrap();
        fmu.exit_initialization().unwrap();
        assert_eq!(fmu.get_real(vr::X_S).unwrap(), 0.05);
        let during_steps = fmu.set_real(vr::X_S, 0.0).unwrap_err();
        assert!(
            during_steps.contains("x_s = 0 m") && during_steps.contains("0.026"),
            "{during_steps}"
        );

        // Connectors started at 0: initialised at the last valid x_s (here the start, 0.054).
        let mut reference = ActuatorFmu::instantiate();
        reference.set_real(vr::V_DA, 2.0).unwrap();
        reference.exit_initialization().unwrap();
        let mut fmu = ActuatorFmu::instantiate();
        fmu.enter_initialization().unwrap();
        fmu.set_real(vr::V_DA, 2.0).unwrap();
        fmu.set_real(vr::X_S, 0.0).unwrap();
        fmu.exit_initialization().unwrap();
        assert_eq!(
            fmu.get_real(vr::F_ACT).unwrap().to_bits(),
            reference.get_real(vr::F_ACT).unwrap().to_bits()
        );
        let StepError::Error(refused) = fmu.do_step(0.0, 1e-3).unwrap_err() else {
            panic!("not an error")
        };
        assert!(refused.starts_with(&during_steps), "{refused}");
        assert_eq!(fmu.time(), 0.0, "nothing was stepped");
        // Propagated before the first step: the step runs, as from that x_s at once.
        fmu.set_real(vr::X_S, 0.055).unwrap();
        reference.set_real(vr::X_S, 0.055).unwrap();
        fmu.do_step(0.0, 1e-3).unwrap();
        reference.do_step(0.0, 1e-3).unwrap();
        assert_eq!(
            fmu.get_real(vr::F_ACT).unwrap().to_bits(),
            reference.get_real(vr::F_ACT).unwrap().to_bits()
        );
        assert!(fmu.set_real(vr::X_S, f64::NAN).unwrap_err().contains("x_s = NaN"));
    }

    #[test]
    fn v_da_outside_the_d_a_range_is_refused() {
        let mut fmu = initialised();
        let e = fmu.set_real(vr::V_DA, 10.5).unwrap_err();
        assert!(e.contains("v_DA = 10.5 V") && e.contains("[-10, 10]"), "{e}");
        fmu.set_real(vr::V_DA, -10.0).unwrap();
    }
}
