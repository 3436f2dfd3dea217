//! The FMI 2.0 Model Exchange functions, generic over a [`ModelExchangeModel`]. The exported
//! C symbols of a model with Model Exchange forward to these (the actuator's crate writes
//! them out literally in its `fmu_exports`).
//!
//! They follow the conventions of [`crate::api`]: a NULL, freed or foreign instance is an
//! fmi2Error without its memory being read, a panic is caught (the instance becomes `fatal`),
//! an illegal call in the state machine ([`crate::state::TABLE`]) logs
//! "fmi2Xxx: illegal call in state yyy" and returns fmi2Error, and a bad argument (a NULL
//! array, a length other than the model description's) or a model rejection logs its message
//! and returns fmi2Error with nothing changed.
//!
//! # Safety
//! All functions are `unsafe`: the pointers must satisfy the FMI 2.0 standard (arrays of the
//! given lengths, a component returned by [`crate::api::instantiate`] for the same model).

use super::api::{guarded, in_slice, out_slice};
use super::instance::Instance;
use super::model::{CoSimModel, ModelExchangeInfo, ModelExchangeModel};
use super::state::{Call, Function, State};
use super::types::*;

/// What [`crate::model::ModelInfo::model_exchange`] declares (a model without it never gets a
/// Model Exchange instance, so the empty description is only a fallback).
pub fn me_info<M: CoSimModel>() -> &'static ModelExchangeInfo {
    static NONE: ModelExchangeInfo = ModelExchangeInfo {
        states: &[],
        event_indicators: 0,
        needs_completed_integrator_step: false,
    };
    M::info().model_exchange.unwrap_or(&NONE)
}

/// The error of an array whose length is not the model description's.
fn length_error<M: CoSimModel>(
    inst: &mut Instance<M>,
    fname: &str,
    what: &str,
    given: usize,
    declared: usize,
) -> fmi2Status {
    inst.error(format!(
        "{fname}: {what} = {given}, but the model description declares {declared}"
    ))
}

/// `fmi2SetTime`: a finite time, not before the last one set (the importer's solver may step
/// back within a step, but not before an event it has handled).
///
/// # Safety
/// See the module documentation.
pub unsafe fn set_time_as<M: ModelExchangeModel, K: Call>(c: fmi2Component, call: K, time: fmi2Real) -> fmi2Status {
    guarded::<M, _>(c, call, |inst| {
        let fname = call.name();
        if !time.is_finite() {
            return inst.error(format!("{fname}: time = {time} is not finite"));
        }
        match inst.model.set_time(time) {
            Ok(()) => fmi2OK,
            Err(m) => inst.error(format!("{fname}: {m}")),
        }
    })
}

/// `fmi2SetContinuousStates`: `nx` must be the number of states.
///
/// # Safety
/// `x` must hold `nx` values.
pub unsafe fn set_continuous_states_as<M: ModelExchangeModel, K: Call>(
    c: fmi2Component,
    call: K,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    guarded::<M, _>(c, call, |inst| {
        let fname = call.name();
        let declared = me_info::<M>().states.len();
        if nx != declared {
            return length_error(inst, fname, "nx", nx, declared);
        }
        let values = match in_slice(inst, fname, "x[]", x, nx) {
            Ok(s) => s,
            Err(s) => return s,
        };
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return inst.error(format!("{fname}: x[{k}] = {} is not finite", values[k]));
        }
        match inst.model.set_continuous_states(values) {
            Ok(()) => fmi2OK,
            Err(m) => inst.error(format!("{fname}: {m}")),
        }
    })
}

/// The getters of states, derivatives, event indicators and nominals: check the length
/// against `declared` and the pointer, then let `read` fill the array.
///
/// # Safety
/// `p` holds `n` values.
pub unsafe fn get_array<M: ModelExchangeModel, K: Call>(
    c: fmi2Component,
    f: K,
    what: &str,
    p: *mut fmi2Real,
    n: usize,
    declared: usize,
    read: impl FnOnce(&mut M, &mut [f64]) -> Result<(), String>,
) -> fmi2Status {
    guarded::<M, _>(c, f, |inst| {
        let fname = f.name();
        if n != declared {
            return length_error(inst, fname, what, n, declared);
        }
        let values = match out_slice(inst, fname, "the array", p, n) {
            Ok(s) => s,
            Err(s) => return s,
        };
        match read(&mut inst.model, values) {
            Ok(()) => fmi2OK,
            Err(m) => inst.error(format!("{fname}: {m}")),
        }
    })
}

/// # Safety
/// `x` must hold `nx` values.
pub unsafe fn get_continuous_states_as<M: ModelExchangeModel, K: Call>(
    c: fmi2Component,
    call: K,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let declared = me_info::<M>().states.len();
    get_array::<M, K>(c, call, "nx", x, nx, declared, |m, x| m.continuous_states(x))
}

/// # Safety
/// `dx` must hold `nx` values.
pub unsafe fn get_derivatives_as<M: ModelExchangeModel, K: Call>(
    c: fmi2Component,
    call: K,
    dx: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let declared = me_info::<M>().states.len();
    get_array::<M, K>(c, call, "nx", dx, nx, declared, |m, dx| m.derivatives(dx))
}

/// # Safety
/// `z` must hold `nz` values.
pub unsafe fn get_event_indicators_as<M: ModelExchangeModel, K: Call>(
    c: fmi2Component,
    call: K,
    z: *mut fmi2Real,
    nz: usize,
) -> fmi2Status {
    let declared = me_info::<M>().event_indicators;
    get_array::<M, K>(c, call, "ni", z, nz, declared, |m, z| m.event_indicators(z))
}

/// # Safety
/// `nominals` must hold `nx` values.
pub unsafe fn get_nominals_of_continuous_states_as<M: ModelExchangeModel, K: Call>(
    c: fmi2Component,
    call: K,
    nominals: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    let declared = me_info::<M>().states.len();
    get_array::<M, K>(c, call, "nx", nominals, nx, declared, |m, n| {
        m.nominals(n);
        Ok(())
    })
}

/// `fmi2EnterEventMode`: from `continuousTimeMode` (or again in `eventMode`).
///
/// # Safety
/// See the module documentation.
pub unsafe fn enter_event_mode_as<M: ModelExchangeModel, K: Call>(c: fmi2Component, call: K) -> fmi2Status {
    guarded::<M, _>(c, call, |inst| match inst.model.enter_event_mode() {
        Ok(()) => {
            inst.state = State::EventMode;
            fmi2OK
        }
        Err(m) => inst.error(format!("{}: {m}", call.name())),
    })
}

/// `fmi2NewDiscreteStates`: one event iteration; the model's events need no iteration, so
/// `newDiscreteStatesNeeded` is always false.
///
/// # Safety
/// `event_info` must be writable.
pub unsafe fn new_discrete_states<M: ModelExchangeModel>(
    c: fmi2Component,
    event_info: *mut fmi2EventInfo,
) -> fmi2Status {
    guarded::<M, _>(c, Function::NewDiscreteStates, |inst| {
        const F: &str = "fmi2NewDiscreteStates";
        if event_info.is_null() {
            return inst.error(format!("{F}: eventInfo is NULL"));
        }
        match inst.model.new_discrete_states() {
            Ok(update) => {
                let b = |x: bool| if x { fmi2True } else { fmi2False };
                *event_info = fmi2EventInfo {
                    newDiscreteStatesNeeded: fmi2False,
                    terminateSimulation: b(update.terminate_simulation),
                    nominalsOfContinuousStatesChanged: b(update.nominals_of_continuous_states_changed),
                    valuesOfContinuousStatesChanged: b(update.values_of_continuous_states_changed),
                    nextEventTimeDefined: b(update.next_event_time.is_some()),
                    nextEventTime: update.next_event_time.unwrap_or(0.0),
                };
                fmi2OK
            }
            Err(m) => inst.error(format!("{F}: {m}")),
        }
    })
}

/// `fmi2EnterContinuousTimeMode`.
///
/// # Safety
/// See the module documentation.
pub unsafe fn enter_continuous_time_mode_as<M: ModelExchangeModel, K: Call>(c: fmi2Component, call: K) -> fmi2Status {
    guarded::<M, _>(c, call, |inst| {
        inst.state = State::ContinuousTimeMode;
        fmi2OK
    })
}

/// `fmi2CompletedIntegratorStep`: the model's update after an accepted step
/// ([`ModelExchangeModel::completed_integrator_step`]); never asks for an event.
///
/// # Safety
/// `enter_event_mode` and `terminate_simulation` must be writable.
pub unsafe fn completed_integrator_step<M: ModelExchangeModel>(
    c: fmi2Component,
    _no_set_fmu_state_prior: fmi2Boolean,
    enter_event_mode: *mut fmi2Boolean,
    terminate_simulation: *mut fmi2Boolean,
) -> fmi2Status {
    guarded::<M, _>(c, Function::CompletedIntegratorStep, |inst| {
        const F: &str = "fmi2CompletedIntegratorStep";
        if enter_event_mode.is_null() || terminate_simulation.is_null() {
            return inst.error(format!("{F}: enterEventMode or terminateSimulation is NULL"));
        }
        match inst.model.completed_integrator_step() {
            Ok(terminate) => {
                *enter_event_mode = fmi2False;
                *terminate_simulation = if terminate { fmi2True } else { fmi2False };
                fmi2OK
            }
            Err(m) => inst.error(format!("{F}: {m}")),
        }
    })
}

/// [`set_time_as`] for FMI 2.0's `fmi2SetTime`.
///
/// # Safety
/// See [`set_time_as`].
pub unsafe fn set_time<M: ModelExchangeModel>(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    set_time_as::<M, _>(c, Function::SetTime, time)
}

/// [`set_continuous_states_as`] for FMI 2.0's `fmi2SetContinuousStates`.
///
/// # Safety
/// See [`set_continuous_states_as`].
pub unsafe fn set_continuous_states<M: ModelExchangeModel>(
    c: fmi2Component,
    x: *const fmi2Real,
    nx: usize,
) -> fmi2Status {
    set_continuous_states_as::<M, _>(c, Function::SetContinuousStates, x, nx)
}

/// [`get_continuous_states_as`] for FMI 2.0's `fmi2GetContinuousStates`.
///
/// # Safety
/// See [`get_continuous_states_as`].
pub unsafe fn get_continuous_states<M: ModelExchangeModel>(
    c: fmi2Component,
    x: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    get_continuous_states_as::<M, _>(c, Function::GetContinuousStates, x, nx)
}

/// [`get_derivatives_as`] for FMI 2.0's `fmi2GetDerivatives`.
///
/// # Safety
/// See [`get_derivatives_as`].
pub unsafe fn get_derivatives<M: ModelExchangeModel>(c: fmi2Component, dx: *mut fmi2Real, nx: usize) -> fmi2Status {
    get_derivatives_as::<M, _>(c, Function::GetDerivatives, dx, nx)
}

/// [`get_event_indicators_as`] for FMI 2.0's `fmi2GetEventIndicators`.
///
/// # Safety
/// See [`get_event_indicators_as`].
pub unsafe fn get_event_indicators<M: ModelExchangeModel>(c: fmi2Component, z: *mut fmi2Real, nz: usize) -> fmi2Status {
    get_event_indicators_as::<M, _>(c, Function::GetEventIndicators, z, nz)
}

/// [`get_nominals_of_continuous_states_as`] for FMI 2.0's `fmi2GetNominalsOfContinuousStates`.
///
/// # Safety
/// See [`get_nominals_of_continuous_states_as`].
pub unsafe fn get_nominals_of_continuous_states<M: ModelExchangeModel>(
    c: fmi2Component,
    nominals: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    get_nominals_of_continuous_states_as::<M, _>(c, Function::GetNominalsOfContinuousStates, nominals, nx)
}

/// [`enter_event_mode_as`] for FMI 2.0's `fmi2EnterEventMode`.
///
/// # Safety
/// See [`enter_event_mode_as`].
pub unsafe fn enter_event_mode<M: ModelExchangeModel>(c: fmi2Component) -> fmi2Status {
    enter_event_mode_as::<M, _>(c, Function::EnterEventMode)
}

/// [`enter_continuous_time_mode_as`] for FMI 2.0's `fmi2EnterContinuousTimeMode`.
///
/// # Safety
/// See [`enter_continuous_time_mode_as`].
pub unsafe fn enter_continuous_time_mode<M: ModelExchangeModel>(c: fmi2Component) -> fmi2Status {
    enter_continuous_time_mode_as::<M, _>(c, Function::EnterContinuousTimeMode)
}
