//! A dummy model for the layer's tests (and for building the FMU before the physics is
//! merged): a first-order lag `y' = (u(t) - y) / tau`, integrated with `n_sub` RK4
//! substeps per communication step, with a linearly interpolated input when an input
//! derivative is set.
//!
//! Magic behaviour for tests: setting `u` to [`PANIC_VALUE`] panics; a step with
//! `|u| > 1e6` is discarded; a step longer than 1000 s is an error.

use super::model::{Causality, CoSimModel, ModelInfo, StepError, UnitDefinition, VarType, Variability, Variable};

pub const VR_U: u32 = 1;
pub const VR_Y: u32 = 2;
pub const VR_TAU: u32 = 10;
pub const VR_Y0: u32 = 11;
pub const VR_N_SUB: u32 = 12;
pub const VR_FROZEN: u32 = 13;

/// Setting `u` to this value panics (to test that panics are caught).
pub const PANIC_VALUE: f64 = -12345.678;

#[allow(clippy::too_many_arguments)]
const fn var(
    name: &'static str,
    value_reference: u32,
    var_type: VarType,
    causality: Causality,
    variability: Variability,
    unit: Option<&'static str>,
    start: f64,
    description: &'static str,
) -> Variable {
    Variable {
        name,
        value_reference,
        var_type,
        causality,
        variability,
        unit,
        start,
        min: None,
        max: None,
        description,
    }
}

pub static DUMMY_VARIABLES: [Variable; 6] = [
    var(
        "u",
        VR_U,
        VarType::Real,
        Causality::Input,
        Variability::Continuous,
        Some("1"),
        0.0,
        "input <u> & \"target\"",
    ),
    var(
        "y",
        VR_Y,
        VarType::Real,
        Causality::Output,
        Variability::Continuous,
        Some("1"),
        0.0,
        "output, lags u",
    ),
    Variable {
        min: Some(1e-6),
        ..var(
            "tau",
            VR_TAU,
            VarType::Real,
            Causality::Parameter,
            Variability::Tunable,
            Some("s"),
            1.0,
            "time constant",
        )
    },
    var(
        "y0",
        VR_Y0,
        VarType::Real,
        Causality::Parameter,
        Variability::Fixed,
        Some("1"),
        0.0,
        "initial output",
    ),
    Variable {
        min: Some(1.0),
        max: Some(1000.0),
        ..var(
            "n_sub",
            VR_N_SUB,
            VarType::Integer,
            Causality::Parameter,
            Variability::Fixed,
            None,
            4.0,
            "RK4 substeps per step",
        )
    },
    var(
        "frozen",
        VR_FROZEN,
        VarType::Boolean,
        Causality::Parameter,
        Variability::Tunable,
        None,
        0.0,
        "hold y constant",
    ),
];

pub static DUMMY_INFO: ModelInfo = ModelInfo {
    model_name: "DummyLag",
    model_identifier: "jetpipe",
    description: "First-order lag used to test the generic FMI 2.0 layer",
    author: "jetpipe FMI layer",
    version: "0.1.0",
    generation_tool: "jetpipe (Rust)",
    default_start_time: 0.0,
    default_stop_time: 10.0,
    default_tolerance: 1e-6,
    default_step_size: 1e-3,
    log_categories: &[
        ("logEvents", "Log events"),
        ("logStatusWarning", "Log messages with status fmi2Warning"),
        ("logStatusDiscard", "Log messages with status fmi2Discard"),
        ("logStatusError", "Log messages with status fmi2Error"),
        ("logStatusFatal", "Log messages with status fmi2Fatal"),
        ("logCalls", "Log calls of FMI functions"),
    ],
    units: &[
        UnitDefinition {
            name: "1",
            kg: 0,
            m: 0,
            s: 0,
            a: 0,
            k: 0,
        },
        UnitDefinition {
            name: "s",
            kg: 0,
            m: 0,
            s: 1,
            a: 0,
            k: 0,
        },
    ],
    variables: &DUMMY_VARIABLES,
    can_interpolate_inputs: true,
    extent: super::model::no_extent,
    dependencies: &[],
    model_exchange: None,
    guid_cache: super::model::GuidCache::new(),
};

#[derive(Clone, Debug, PartialEq)]
pub struct DummyModel {
    pub time: f64,
    pub y: f64,
    pub u: f64,
    pub du: f64,
    pub tau: f64,
    pub y0: f64,
    pub n_sub: i32,
    pub frozen: bool,
}

const DUMMY_BYTES_VERSION: u8 = 1;
const DUMMY_BYTES_LEN: usize = 1 + 6 * 8 + 4 + 1;

impl CoSimModel for DummyModel {
    fn info() -> &'static ModelInfo {
        &DUMMY_INFO
    }

    fn instantiate() -> Self {
        DummyModel {
            time: 0.0,
            y: 0.0,
            u: 0.0,
            du: 0.0,
            tau: 1.0,
            y0: 0.0,
            n_sub: 4,
            frozen: false,
        }
    }

    fn get_real(&self, vr: u32) -> Result<f64, String> {
        match vr {
            VR_U => Ok(self.u),
            VR_Y => Ok(self.y),
            VR_TAU => Ok(self.tau),
            VR_Y0 => Ok(self.y0),
            _ => Err(format!("no Real variable with value reference {vr}")),
        }
    }

    fn set_real(&mut self, vr: u32, value: f64) -> Result<(), String> {
        if value == PANIC_VALUE {
            panic!("dummy model asked to panic (value {value} for value reference {vr})");
        }
        if !value.is_finite() {
            return Err(format!("value reference {vr}: value {value} is not finite"));
        }
        match vr {
            VR_U => {
                self.u = value;
                self.du = 0.0;
            }
            VR_TAU if value < 1e-6 => return Err(format!("tau = {value} must be >= 1e-6 s")),
            VR_TAU => self.tau = value,
            VR_Y0 => self.y0 = value,
            _ => return Err(format!("Real variable with value reference {vr} cannot be set")),
        }
        Ok(())
    }

    fn get_integer(&self, vr: u32) -> Result<i32, String> {
        match vr {
            VR_N_SUB => Ok(self.n_sub),
            _ => Err(format!("no Integer variable with value reference {vr}")),
        }
    }

    fn set_integer(&mut self, vr: u32, value: i32) -> Result<(), String> {
        match vr {
            VR_N_SUB if (1..=1000).contains(&value) => {
                self.n_sub = value;
                Ok(())
            }
            VR_N_SUB => Err(format!("n_sub = {value} must be in 1..=1000")),
            _ => Err(format!("no Integer variable with value reference {vr}")),
        }
    }

    fn get_boolean(&self, vr: u32) -> Result<bool, String> {
        match vr {
            VR_FROZEN => Ok(self.frozen),
            _ => Err(format!("no Boolean variable with value reference {vr}")),
        }
    }

    fn set_boolean(&mut self, vr: u32, value: bool) -> Result<(), String> {
        match vr {
            VR_FROZEN => {
                self.frozen = value;
                Ok(())
            }
            _ => Err(format!("no Boolean variable with value reference {vr}")),
        }
    }

    fn setup_experiment(&mut self, _tolerance: Option<f64>, start_time: f64, _stop: Option<f64>) -> Result<(), String> {
        self.time = start_time;
        Ok(())
    }

    fn exit_initialization(&mut self) -> Result<(), String> {
        self.y = self.y0;
        Ok(())
    }

    fn set_real_input_derivative(&mut self, vr: u32, order: i32, value: f64) -> Result<(), String> {
        match (vr, order) {
            (VR_U, 1) => {
                self.du = value;
                Ok(())
            }
            _ => Err(format!(
                "input derivative of order {order} for value reference {vr} not supported"
            )),
        }
    }

    fn do_step(&mut self, current_time: f64, step_size: f64) -> Result<(), StepError> {
        if step_size > 1000.0 {
            return Err(StepError::Error(format!("step size {step_size} s is too long")));
        }
        if self.u.abs() > 1e6 {
            return Err(StepError::Discard {
                message: format!("input u = {} is too large", self.u),
                last_successful_time: self.time,
            });
        }
        if !self.frozen {
            let n = self.n_sub.max(1);
            let h = step_size / n as f64;
            let (u0, du, tau) = (self.u, self.du, self.tau);
            let f = |t: f64, y: f64| (u0 + du * (t - current_time) - y) / tau;
            let mut y = self.y;
            for i in 0..n {
                let t = current_time + i as f64 * h;
                let k1 = f(t, y);
                let k2 = f(t + h / 2.0, y + h / 2.0 * k1);
                let k3 = f(t + h / 2.0, y + h / 2.0 * k2);
                let k4 = f(t + h, y + h * k3);
                y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            }
            self.y = y;
            self.u += du * step_size;
        }
        self.time = current_time + step_size;
        Ok(())
    }

    fn time(&self) -> f64 {
        self.time
    }

    fn serialize(&self) -> Vec<u8> {
        let mut b = vec![DUMMY_BYTES_VERSION];
        for x in [self.time, self.y, self.u, self.du, self.tau, self.y0] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b.extend_from_slice(&self.n_sub.to_le_bytes());
        b.push(self.frozen as u8);
        b
    }

    fn deserialize(&mut self, bytes: &[u8]) -> Result<(), String> {
        if bytes.len() != DUMMY_BYTES_LEN {
            return Err(format!(
                "dummy model state must be {DUMMY_BYTES_LEN} bytes, got {}",
                bytes.len()
            ));
        }
        if bytes[0] != DUMMY_BYTES_VERSION {
            return Err(format!("dummy model state version {} unsupported", bytes[0]));
        }
        let f = |i: usize| f64::from_le_bytes(bytes[1 + 8 * i..9 + 8 * i].try_into().unwrap());
        let n_sub = i32::from_le_bytes(bytes[49..53].try_into().unwrap());
        let frozen = match bytes[53] {
            0 => false,
            1 => true,
            b => return Err(format!("dummy model state: invalid boolean byte {b}")),
        };
        *self = DummyModel {
            time: f(0),
            y: f(1),
            u: f(2),
            du: f(3),
            tau: f(4),
            y0: f(5),
            n_sub,
            frozen,
        };
        Ok(())
    }
}

/// A copy of `i` (a `ModelInfo` holds its GUID cache, so it is not `Clone`), for tests that
/// change some fields: `ModelInfo { variables: ..., ..clone_info(M::info()) }`.
pub fn clone_info(i: &ModelInfo) -> ModelInfo {
    ModelInfo {
        model_name: i.model_name,
        model_identifier: i.model_identifier,
        description: i.description,
        author: i.author,
        version: i.version,
        generation_tool: i.generation_tool,
        default_start_time: i.default_start_time,
        default_stop_time: i.default_stop_time,
        default_tolerance: i.default_tolerance,
        default_step_size: i.default_step_size,
        log_categories: i.log_categories,
        units: i.units,
        variables: i.variables,
        can_interpolate_inputs: i.can_interpolate_inputs,
        extent: i.extent,
        dependencies: i.dependencies,
        model_exchange: i.model_exchange,
        guid_cache: super::model::GuidCache::new(),
    }
}

/// The lag's Model Exchange calls, ẏ = (u − y)/τ, for the layer's tests of the Model Exchange
/// functions in every state. `DUMMY_INFO` declares no Model Exchange (so `fmi2Instantiate`
/// refuses fmi2ModelExchange and the arrays have no element): the tests reach these calls by
/// putting an instance in the Model Exchange states.
impl super::model::ModelExchangeModel for DummyModel {
    fn set_time(&mut self, time: f64) -> Result<(), String> {
        self.time = time;
        Ok(())
    }

    fn continuous_states(&self, x: &mut [f64]) -> Result<(), String> {
        x.iter_mut().for_each(|v| *v = self.y);
        Ok(())
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        if let Some(&y) = x.first() {
            self.y = y;
        }
        Ok(())
    }

    fn derivatives(&self, dx: &mut [f64]) -> Result<(), String> {
        dx.iter_mut().for_each(|v| *v = (self.u - self.y) / self.tau);
        Ok(())
    }

    fn event_indicators(&self, z: &mut [f64]) -> Result<(), String> {
        z.iter_mut().for_each(|v| *v = self.u - self.y);
        Ok(())
    }

    fn nominals(&self, nominals: &mut [f64]) {
        nominals.iter_mut().for_each(|v| *v = 1.0);
    }

    fn new_discrete_states(&mut self) -> Result<super::model::EventUpdate, String> {
        Ok(super::model::EventUpdate::default())
    }
}
