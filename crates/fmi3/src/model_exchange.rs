//! The FMI 3.0 Model Exchange calls: FMI 2.0's (crate `fmi2`'s `model_exchange`) run with this
//! version's table, and what FMI 3.0 adds (`fmi3GetNumberOf*`, `fmi3CompletedIntegratorStep`'s
//! boolean outputs). Conventions as in [`crate::api`].
//!
//! # Safety
//! All functions are `unsafe`: the pointers must satisfy the FMI 3.0 standard.

use fmi2::api::guarded;
use fmi2::model::ModelExchangeModel;
use fmi2::model_exchange as me;

use crate::state::Function;
use crate::types::*;

/// # Safety
/// See the module documentation.
pub unsafe fn set_time<M: ModelExchangeModel>(c: fmi3Instance, time: fmi3Float64) -> fmi3Status {
    me::set_time_as::<M, _>(c, Function::SetTime, time)
}

/// # Safety
/// `x` holds `nx` values.
pub unsafe fn set_continuous_states<M: ModelExchangeModel>(
    c: fmi3Instance,
    x: *const fmi3Float64,
    nx: usize,
) -> fmi3Status {
    me::set_continuous_states_as::<M, _>(c, Function::SetContinuousStates, x, nx)
}

/// # Safety
/// `x` holds `nx` values.
pub unsafe fn get_continuous_states<M: ModelExchangeModel>(
    c: fmi3Instance,
    x: *mut fmi3Float64,
    nx: usize,
) -> fmi3Status {
    me::get_continuous_states_as::<M, _>(c, Function::GetContinuousStates, x, nx)
}

/// `fmi3GetContinuousStateDerivatives`: the model's right-hand side.
///
/// # Safety
/// `dx` holds `nx` values.
pub unsafe fn get_continuous_state_derivatives<M: ModelExchangeModel>(
    c: fmi3Instance,
    dx: *mut fmi3Float64,
    nx: usize,
) -> fmi3Status {
    me::get_derivatives_as::<M, _>(c, Function::GetContinuousStateDerivatives, dx, nx)
}

/// # Safety
/// `z` holds `nz` values.
pub unsafe fn get_event_indicators<M: ModelExchangeModel>(
    c: fmi3Instance,
    z: *mut fmi3Float64,
    nz: usize,
) -> fmi3Status {
    me::get_event_indicators_as::<M, _>(c, Function::GetEventIndicators, z, nz)
}

/// # Safety
/// `nominals` holds `nx` values.
pub unsafe fn get_nominals_of_continuous_states<M: ModelExchangeModel>(
    c: fmi3Instance,
    nominals: *mut fmi3Float64,
    nx: usize,
) -> fmi3Status {
    me::get_nominals_of_continuous_states_as::<M, _>(c, Function::GetNominalsOfContinuousStates, nominals, nx)
}

/// # Safety
/// See the module documentation.
pub unsafe fn enter_event_mode<M: ModelExchangeModel>(c: fmi3Instance) -> fmi3Status {
    me::enter_event_mode_as::<M, _>(c, Function::EnterEventMode)
}

/// # Safety
/// See the module documentation.
pub unsafe fn enter_continuous_time_mode<M: ModelExchangeModel>(c: fmi3Instance) -> fmi3Status {
    me::enter_continuous_time_mode_as::<M, _>(c, Function::EnterContinuousTimeMode)
}

/// `fmi3GetNumberOfContinuousStates` and `fmi3GetNumberOfEventIndicators`: what the model
/// description declares.
unsafe fn get_number<M: ModelExchangeModel>(c: fmi3Instance, f: Function, n: *mut usize, value: usize) -> fmi3Status {
    guarded::<M, _>(c, f, |inst| {
        if n.is_null() {
            return inst.error(format!("{}: the output argument is NULL", f.name()));
        }
        *n = value;
        fmi3OK
    })
}

/// # Safety
/// `n` is writable.
pub unsafe fn get_number_of_continuous_states<M: ModelExchangeModel>(c: fmi3Instance, n: *mut usize) -> fmi3Status {
    let value = me::me_info::<M>().states.len();
    get_number::<M>(c, Function::GetNumberOfContinuousStates, n, value)
}

/// # Safety
/// `n` is writable.
pub unsafe fn get_number_of_event_indicators<M: ModelExchangeModel>(c: fmi3Instance, n: *mut usize) -> fmi3Status {
    let value = me::me_info::<M>().event_indicators;
    get_number::<M>(c, Function::GetNumberOfEventIndicators, n, value)
}

/// `fmi3CompletedIntegratorStep`: the model's update after an accepted step
/// ([`ModelExchangeModel::completed_integrator_step`]); never asks for an event.
///
/// # Safety
/// `enter_event_mode` and `terminate_simulation` are writable.
pub unsafe fn completed_integrator_step<M: ModelExchangeModel>(
    c: fmi3Instance,
    _no_set_fmu_state_prior: fmi3Boolean,
    enter_event_mode: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
) -> fmi3Status {
    guarded::<M, _>(c, Function::CompletedIntegratorStep, |inst| {
        const F: &str = "fmi3CompletedIntegratorStep";
        if enter_event_mode.is_null() || terminate_simulation.is_null() {
            return inst.error(format!("{F}: enterEventMode or terminateSimulation is NULL"));
        }
        match inst.model.completed_integrator_step() {
            Ok(terminate) => {
                *enter_event_mode = fmi3False;
                *terminate_simulation = u8::from(terminate);
                fmi3OK
            }
            Err(m) => inst.error(format!("{F}: {m}")),
        }
    })
}
