//! What the three small FMUs of the antagonistic joint (`Tendon`, `FingerJoint`,
//! `JointController`) share on top of the generic FMI layer (crate `fmi2`): a value store
//! driven by the variable table (range checks with messages that name the variable), a
//! monotone scalar solver for their implicit integrators, and what their `ModelInfo`,
//! `CoSimModel` impls and interface tests would otherwise each repeat. No FFI types here.
//! (The byte format of their FMU states is the layer's `fmi2::state_bytes`, shared with the
//! actuator; the interface page of their archives is `jetpipe_packaging::documentation_page`,
//! as the actuator's.)

pub mod solve;
pub mod testing;
pub mod units;
pub mod values;

pub use values::Values;

// For `model_info!`, so that its expansion does not depend on the caller's imports.
#[doc(hidden)]
pub use fmi2 as __fmi2;

use fmi2::model::StepError;

/// The `ModelInfo` of one of these models, from what tells them apart; the author, default
/// experiment, log categories and the lack of input interpolation are the same for all. A macro,
/// not a function, so that `version` and `generation_tool` are the calling crate's.
#[macro_export]
macro_rules! model_info {
    (
        name: $name:expr,
        description: $description:expr,
        units: $units:expr,
        variables: $variables:expr,
        dependencies: $dependencies:expr $(,)?
    ) => {
        $crate::__fmi2::model::ModelInfo {
            model_name: $name,
            model_identifier: $name,
            description: $description,
            author: "jetpipe project",
            version: env!("CARGO_PKG_VERSION"),
            generation_tool: concat!("jetpipe ", env!("CARGO_PKG_NAME"), " ", env!("CARGO_PKG_VERSION")),
            default_start_time: 0.0,
            default_stop_time: 1.0,
            default_tolerance: 1e-6,
            default_step_size: 1e-3,
            log_categories: $crate::LOG_CATEGORIES,
            units: $units,
            variables: $variables,
            can_interpolate_inputs: false,
            extent: {
                fn extent(value_reference: u32) -> $crate::__fmi2::model::Extent {
                    $crate::nominal_from_start($variables, value_reference)
                }
                extent
            },
            dependencies: $dependencies,
            model_exchange: None,
            guid_cache: $crate::__fmi2::model::GuidCache::new(),
        }
    };
}

/// The extent these models declare beyond their table rows' min/max: a nominal, the magnitude
/// of the start value, for every Real parameter and input whose start is not 0.
pub fn nominal_from_start(variables: &[fmi2::model::Variable], value_reference: u32) -> fmi2::model::Extent {
    use fmi2::model::{Causality, Extent, VarType};
    let nominal = variables
        .iter()
        .find(|v| v.value_reference == value_reference)
        .filter(|v| v.var_type == VarType::Real && matches!(v.causality, Causality::Parameter | Causality::Input))
        .map(|v| v.start.abs())
        .filter(|n| n.is_finite() && *n > 0.0);
    Extent {
        nominal,
        ..Extent::default()
    }
}

/// `fmi2SetupExperiment`'s start time, for the models' `setup_experiment`.
pub fn checked_start_time(start_time: f64) -> Result<f64, String> {
    if !start_time.is_finite() {
        return Err(format!("startTime = {start_time} s is invalid: must be finite"));
    }
    Ok(start_time)
}

/// The state a model has from initialisation on, for `do_step`.
pub fn initialised<T>(running: &mut Option<T>) -> Result<&mut T, StepError> {
    running
        .as_mut()
        .ok_or_else(|| StepError::Error("the model is not initialised".to_string()))
}

/// Runs `step` on `state` and puts the state back if it fails: `fmi2Error` promises that
/// nothing was changed.
pub fn step_or_restore<S: Clone>(
    state: &mut S,
    step: impl FnOnce(&mut S) -> Result<(), String>,
) -> Result<(), StepError> {
    let before = state.clone();
    if let Err(message) = step(state) {
        *state = before;
        return Err(StepError::Error(message));
    }
    Ok(())
}

/// The six log categories every model of this workspace declares (the layer's own).
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logEvents", "initialisation, resets and state restores"),
    ("logStatusWarning", "messages with status fmi2Warning"),
    ("logStatusDiscard", "messages with status fmi2Discard"),
    ("logStatusError", "messages with status fmi2Error"),
    ("logStatusFatal", "messages with status fmi2Fatal"),
    ("logAll", "every message"),
];
