//! The FMI 3.0 calls that take or make an instance, generic over the model: what is the same
//! as in FMI 2.0 (the handle checks, `catch_unwind`, the per-variable checks, the setters and
//! getters, logging, the FMU-state calls) is the layer of crate `fmi2` run with this version's
//! table ([`crate::state::Function`]); what FMI 3.0 adds or names differently is here.
//!
//! As in FMI 2.0, every function that takes an instance returns fmi3Error for a NULL, freed or
//! foreign instance without reading its memory, catches panics (the instance becomes `fatal`,
//! the call returns fmi3Fatal), and answers an illegal call in the state machine with
//! fmi3Error and "fmi3Xxx: illegal call in state yyy". An instance made by `fmi2Instantiate`
//! is refused by every `fmi3*` call and the other way round.
//!
//! # Safety
//! All functions are `unsafe`: the pointers must satisfy the FMI 3.0 standard (arrays of the
//! given lengths, an instance returned by an `fmi3Instantiate*` of the same model).

use std::ffi::CStr;
use std::os::raw::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};

use fmi2::api::{check_get_in, drop_payload, get_values, guarded, in_slice, out_slice, panic_message, set_values};
use fmi2::fmu_state_calls as fs;
use fmi2::instance::{call_log_message, Instance, CAT_DISCARD, CAT_ERROR};
use fmi2::model::{CoSimModel, ModelExchangeModel, StepError, VarType};
use fmi2::state::{Interface, State, Version};
use fmi2::types::fmi2String;

use crate::model_description::time_value_reference;
use crate::state::Function;
use crate::types::*;

pub fn get_version() -> *const c_char {
    VERSION.as_ptr()
}

/// The instantiation token: the GUID of the model's FMI 2.0 description (a hash of the whole
/// variable table and interface), so both archives of one build name the same model.
pub fn instantiation_token<M: CoSimModel>() -> &'static str {
    M::info().guid()
}

/// The shared part of the `fmi3Instantiate*` functions: checks, then a boxed, registered
/// instance (NULL, after logging when there is a logger, on any problem or panic).
unsafe fn instantiate<M: CoSimModel>(
    fname: &str,
    instance_name: fmi3String,
    token: fmi3String,
    interface: Interface,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
    refusal: Option<String>,
) -> fmi3Instance {
    let result = catch_unwind(AssertUnwindSafe(|| {
        let log = |msg: &str| call_log_message(log_message, environment, fmi3Error, CAT_ERROR, msg);
        if instance_name.is_null() {
            log(&format!("{fname}: instanceName is NULL"));
            return std::ptr::null_mut();
        }
        if let Some(why) = &refusal {
            log(&format!("{fname}: {why}"));
            return std::ptr::null_mut();
        }
        if interface == Interface::ModelExchange && M::info().model_exchange.is_none() {
            log(&format!("{fname}: this FMU has no Model Exchange interface"));
            return std::ptr::null_mut();
        }
        let expected = instantiation_token::<M>();
        let got = if token.is_null() {
            "NULL".to_owned()
        } else {
            CStr::from_ptr(token).to_string_lossy().into_owned()
        };
        if got != expected {
            log(&format!(
                "{fname}: instantiationToken mismatch: expected {expected}, got {got}"
            ));
            return std::ptr::null_mut();
        }
        let name = CStr::from_ptr(instance_name).to_string_lossy();
        let mut instance = Instance::new_fmi3(M::instantiate(), &name, environment, log_message, logging_on != 0);
        instance.interface = interface;
        if interface == Interface::ModelExchange {
            instance.model.use_model_exchange();
        }
        instance.into_component()
    }));
    match result {
        Ok(c) => c,
        Err(payload) => {
            let message = format!("{fname}: panic in the FMU: {}", panic_message(&*payload));
            drop_payload(payload);
            let _ = catch_unwind(AssertUnwindSafe(|| {
                call_log_message(log_message, environment, fmi3Fatal, "logStatusFatal", &message)
            }));
            std::ptr::null_mut()
        }
    }
}

/// `fmi3InstantiateModelExchange`.
///
/// # Safety
/// Strings NUL-terminated or NULL; `log_message` and `environment` as the standard says.
pub unsafe fn instantiate_model_exchange<M: CoSimModel>(
    instance_name: fmi3String,
    token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
) -> fmi3Instance {
    instantiate::<M>(
        "fmi3InstantiateModelExchange",
        instance_name,
        token,
        Interface::ModelExchange,
        logging_on,
        environment,
        log_message,
        None,
    )
}

/// `fmi3InstantiateCoSimulation`: without event mode (`hasEventMode="false"`), intermediate
/// update or early return; `eventModeUsed` true or required intermediate variables are refused.
///
/// # Safety
/// As [`instantiate_model_exchange`]; `required` holds `n_required` value references.
pub unsafe fn instantiate_co_simulation<M: CoSimModel>(
    instance_name: fmi3String,
    token: fmi3String,
    _resource_path: fmi3String,
    _visible: fmi3Boolean,
    logging_on: fmi3Boolean,
    event_mode_used: fmi3Boolean,
    _early_return_allowed: fmi3Boolean,
    _required: *const fmi3ValueReference,
    n_required: usize,
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
    _intermediate_update: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let refusal = if event_mode_used != 0 {
        Some("eventModeUsed = true, but this FMU's Co-Simulation has no event mode (hasEventMode=\"false\")".to_owned())
    } else if n_required > 0 {
        Some(format!(
            "nRequiredIntermediateVariables = {n_required}, but this FMU provides no intermediate update"
        ))
    } else {
        None
    };
    instantiate::<M>(
        "fmi3InstantiateCoSimulation",
        instance_name,
        token,
        Interface::CoSimulation,
        logging_on,
        environment,
        log_message,
        refusal,
    )
}

/// `fmi3InstantiateScheduledExecution`: not offered; logs why and returns NULL.
///
/// # Safety
/// As [`instantiate_model_exchange`].
pub unsafe fn instantiate_scheduled_execution(
    environment: fmi3InstanceEnvironment,
    log_message: fmi3LogMessageCallback,
) -> fmi3Instance {
    let _ = catch_unwind(AssertUnwindSafe(|| {
        call_log_message(
            log_message,
            environment,
            fmi3Error,
            CAT_ERROR,
            "fmi3InstantiateScheduledExecution: this FMU offers Co-Simulation and Model Exchange, not Scheduled Execution",
        )
    }));
    std::ptr::null_mut()
}

/// `fmi3FreeInstance`: NULL is a no-op; a dead or foreign handle is left alone.
///
/// # Safety
/// `c` NULL or from an `fmi3Instantiate*` of `M`.
pub unsafe fn free_instance<M: CoSimModel>(c: fmi3Instance) {
    fmi2::api::free_instance_as::<M, _>(c, Function::FreeInstance);
}

/// # Safety
/// `categories` holds `n_categories` strings.
pub unsafe fn set_debug_logging<M: CoSimModel>(
    c: fmi3Instance,
    logging_on: fmi3Boolean,
    n_categories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    fmi2::api::set_debug_logging_as::<M, _>(
        c,
        Function::SetDebugLogging,
        logging_on != 0,
        n_categories,
        categories as *const fmi2String,
    )
}

/// `fmi3EnterInitializationMode`: FMI 2.0's `fmi2SetupExperiment` and
/// `fmi2EnterInitializationMode` in one call.
///
/// # Safety
/// See the module documentation.
pub unsafe fn enter_initialization_mode<M: CoSimModel>(
    c: fmi3Instance,
    tolerance_defined: fmi3Boolean,
    tolerance: fmi3Float64,
    start_time: fmi3Float64,
    stop_time_defined: fmi3Boolean,
    stop_time: fmi3Float64,
) -> fmi3Status {
    guarded::<M, _>(c, Function::EnterInitializationMode, |inst| {
        const F: &str = "fmi3EnterInitializationMode";
        if !start_time.is_finite() {
            return inst.error(format!("{F}: startTime = {start_time} is not finite"));
        }
        let stop = (stop_time_defined != 0).then_some(stop_time);
        if let Some(stop) = stop {
            if stop.is_nan() || stop < start_time {
                return inst.error(format!("{F}: stopTime = {stop} is before startTime = {start_time}"));
            }
        }
        let tol = (tolerance_defined != 0).then_some(tolerance);
        if let Some(tol) = tol {
            if !(tol.is_finite() && tol > 0.0) {
                return inst.error(format!("{F}: tolerance = {tol} must be finite and > 0"));
            }
        }
        let result = inst
            .model
            .setup_experiment(tol, start_time, stop)
            .and_then(|()| inst.model.enter_initialization());
        match result {
            Ok(()) => {
                inst.state = State::InitializationMode;
                fmi3OK
            }
            Err(m) => inst.error(format!("{F}: {m}")),
        }
    })
}

/// `fmi3ExitInitializationMode`: a Co-Simulation instance goes to `stepMode`, a Model
/// Exchange one to `eventMode`.
///
/// # Safety
/// See the module documentation.
pub unsafe fn exit_initialization_mode<M: CoSimModel>(c: fmi3Instance) -> fmi3Status {
    guarded::<M, _>(c, Function::ExitInitializationMode, |inst| {
        match inst.model.exit_initialization() {
            Ok(()) => {
                inst.state = match inst.interface {
                    Interface::CoSimulation => State::StepComplete,
                    Interface::ModelExchange => State::EventMode,
                };
                fmi3OK
            }
            Err(m) => inst.error(format!("fmi3ExitInitializationMode: {m}")),
        }
    })
}

/// # Safety
/// See the module documentation.
pub unsafe fn terminate<M: CoSimModel>(c: fmi3Instance) -> fmi3Status {
    guarded::<M, _>(c, Function::Terminate, |inst| {
        inst.state = State::Terminated;
        fmi3OK
    })
}

/// `fmi3Reset`: back to `instantiated` with every start value.
///
/// # Safety
/// See the module documentation.
pub unsafe fn reset<M: CoSimModel>(c: fmi3Instance) -> fmi3Status {
    guarded::<M, _>(c, Function::Reset, |inst| {
        inst.model.reset();
        if inst.interface == Interface::ModelExchange {
            inst.model.use_model_exchange();
        }
        inst.state = State::Instantiated;
        inst.last_successful_time = None;
        fmi3OK
    })
}

// ------------------------------------------------------------------------------------
// Getters and setters
// ------------------------------------------------------------------------------------

/// A variable of the FMI 3.0 description that is not a row of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Extra {
    /// The independent variable `time`.
    Time,
    /// Event indicator `k` (from 0) of Model Exchange.
    Indicator(usize),
}

/// The number of event indicators (0 without Model Exchange).
pub fn event_indicator_count<M: CoSimModel>() -> usize {
    M::info().model_exchange.map_or(0, |me| me.event_indicators)
}

/// Which extra variable `vr` is, if it is one (see [`crate::model_description`]).
fn extra_variable<M: CoSimModel>(vr: u32) -> Option<Extra> {
    let k = vr.checked_sub(time_value_reference(M::info()))? as usize;
    match k {
        0 => Some(Extra::Time),
        k if k <= event_indicator_count::<M>() => Some(Extra::Indicator(k - 1)),
        _ => None,
    }
}

/// FMI 3.0 gives arrays `nValues` beside `nValueReferences`; the model's variables are all
/// scalars, so the two must be equal. The error of a call in which they are not.
unsafe fn count_mismatch<M: CoSimModel>(c: fmi3Instance, f: Function, nvr: usize, n_values: usize) -> fmi3Status {
    guarded::<M, _>(c, f, |inst| {
        inst.error(format!(
            "{}: nValues = {n_values}, but the {nvr} value references name {nvr} scalar values (this FMU has no array variables)",
            f.name()
        ))
    })
}

/// `fmi3GetFloat64`: the table's Real variables, and the event indicators as variables.
///
/// # Safety
/// `vr` holds `nvr` references, `values` `n_values` values.
pub unsafe fn get_float64<M: ModelExchangeModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3Float64,
    n_values: usize,
) -> fmi3Status {
    if nvr != n_values {
        return count_mismatch::<M>(c, Function::GetFloat64, nvr, n_values);
    }
    let any_extra = !vr.is_null()
        && std::slice::from_raw_parts(vr, nvr)
            .iter()
            .any(|&r| extra_variable::<M>(r).is_some());
    if !any_extra {
        return get_values::<M, f64, _>(c, Function::GetFloat64, VarType::Real, vr, nvr, values, |m, r| {
            m.get_real(r)
        });
    }
    guarded::<M, _>(c, Function::GetFloat64, |inst| {
        const F: &str = "fmi3GetFloat64";
        let vrs = match in_slice(inst, F, "valueReferences[]", vr, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        let out = match out_slice(inst, F, "values[]", values, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        let mut indicators: Option<Vec<f64>> = None;
        for (&r, slot) in vrs.iter().zip(out.iter_mut()) {
            match extra_variable::<M>(r) {
                Some(Extra::Time) => *slot = inst.model.time(),
                Some(Extra::Indicator(k)) => {
                    if inst.state == State::Instantiated {
                        return inst.error(format!(
                            "{F}: event_indicator_{} (value reference {r}) has no value in state instantiated",
                            k + 1
                        ));
                    }
                    if indicators.is_none() {
                        let mut z = vec![0.0; event_indicator_count::<M>()];
                        if let Err(m) = inst.model.event_indicators(&mut z) {
                            return inst.error(format!("{F}: {m}"));
                        }
                        indicators = Some(z);
                    }
                    *slot = indicators.as_ref().map_or(0.0, |z| z[k]);
                }
                None => {
                    let checked = inst
                        .variable(F, r, VarType::Real)
                        .and_then(|v| check_get_in(F, v, inst.state, Version::Fmi3));
                    if let Err(m) = checked {
                        return inst.error(m);
                    }
                    match inst.model.get_real(r) {
                        Ok(x) => *slot = x,
                        Err(m) => return inst.error(format!("{F}: {m}")),
                    }
                }
            }
        }
        fmi3OK
    })
}

/// # Safety
/// `vr` holds `nvr` references, `values` `n_values` values.
pub unsafe fn set_float64<M: CoSimModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3Float64,
    n_values: usize,
) -> fmi3Status {
    if nvr != n_values {
        return count_mismatch::<M>(c, Function::SetFloat64, nvr, n_values);
    }
    set_values::<M, f64, _>(c, Function::SetFloat64, VarType::Real, vr, nvr, values, |m, r, x| {
        m.set_real(r, x)
    })
}

/// # Safety
/// `vr` holds `nvr` references, `values` `n_values` values.
pub unsafe fn get_int32<M: CoSimModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3Int32,
    n_values: usize,
) -> fmi3Status {
    if nvr != n_values {
        return count_mismatch::<M>(c, Function::GetInt32, nvr, n_values);
    }
    get_values::<M, i32, _>(c, Function::GetInt32, VarType::Integer, vr, nvr, values, |m, r| {
        m.get_integer(r)
    })
}

/// # Safety
/// `vr` holds `nvr` references, `values` `n_values` values.
pub unsafe fn set_int32<M: CoSimModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3Int32,
    n_values: usize,
) -> fmi3Status {
    if nvr != n_values {
        return count_mismatch::<M>(c, Function::SetInt32, nvr, n_values);
    }
    set_values::<M, i32, _>(c, Function::SetInt32, VarType::Integer, vr, nvr, values, |m, r, x| {
        m.set_integer(r, x)
    })
}

/// # Safety
/// `vr` holds `nvr` references, `values` `n_values` values.
pub unsafe fn get_boolean<M: CoSimModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    if nvr != n_values {
        return count_mismatch::<M>(c, Function::GetBoolean, nvr, n_values);
    }
    get_values::<M, u8, _>(c, Function::GetBoolean, VarType::Boolean, vr, nvr, values, |m, r| {
        m.get_boolean(r).map(u8::from)
    })
}

/// # Safety
/// `vr` holds `nvr` references, `values` `n_values` values.
pub unsafe fn set_boolean<M: CoSimModel>(
    c: fmi3Instance,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const fmi3Boolean,
    n_values: usize,
) -> fmi3Status {
    if nvr != n_values {
        return count_mismatch::<M>(c, Function::SetBoolean, nvr, n_values);
    }
    set_values::<M, u8, _>(c, Function::SetBoolean, VarType::Boolean, vr, nvr, values, |m, r, x| {
        m.set_boolean(r, x != 0)
    })
}

/// A getter or setter of a type the model has no variable of (`Float32`, `Int8`, ...,
/// `String`, `Binary`, `Clock`): no value reference is fine, any other is an error that
/// names the variable's real type.
///
/// # Safety
/// `vr` holds `nvr` references.
pub unsafe fn no_variables_of_type<M: CoSimModel>(
    c: fmi3Instance,
    f: Function,
    type_name: &str,
    vr: *const fmi3ValueReference,
    nvr: usize,
) -> fmi3Status {
    guarded::<M, _>(c, f, |inst| {
        let fname = f.name();
        let vrs = match in_slice(inst, fname, "valueReferences[]", vr, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        match vrs.first() {
            None => fmi3OK,
            Some(&r) => {
                let m = match M::info().variables.iter().find(|v| v.value_reference == r) {
                    Some(v) => format!(
                        "{fname}: value reference {r} ({}) is a {} variable, not {type_name}",
                        v.name,
                        v.var_type.name_in(Version::Fmi3)
                    ),
                    None if extra_variable::<M>(r).is_some() => {
                        format!("{fname}: value reference {r} is a Float64 variable, not {type_name}")
                    }
                    None => format!("{fname}: unknown value reference {r} (this FMU has no {type_name} variables)"),
                };
                inst.error(m)
            }
        }
    })
}

/// A call this FMU does not support (directional derivatives, variable dependencies, clocks,
/// configuration mode, ...): fmi3Error with `why`, in every state the table allows it.
///
/// # Safety
/// See the module documentation.
pub unsafe fn unsupported<M: CoSimModel>(c: fmi3Instance, f: Function, why: &str) -> fmi3Status {
    guarded::<M, _>(c, f, |inst| inst.error(format!("{}: {why}", f.name())))
}

// ------------------------------------------------------------------------------------
// FMU state: the layer's calls, with this version's table
// ------------------------------------------------------------------------------------

/// # Safety
/// `state` points to NULL or to an FMU state of this FMU.
pub unsafe fn get_fmu_state<M: CoSimModel>(c: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    fs::get_fmu_state_as::<M, _>(c, Function::GetFMUState, state)
}

/// # Safety
/// `state` is an FMU state of this FMU.
pub unsafe fn set_fmu_state<M: CoSimModel>(c: fmi3Instance, state: fmi3FMUState) -> fmi3Status {
    fs::set_fmu_state_as::<M, _>(c, Function::SetFMUState, state)
}

/// # Safety
/// `state` is NULL or points to NULL or to an FMU state of this FMU.
pub unsafe fn free_fmu_state<M: CoSimModel>(c: fmi3Instance, state: *mut fmi3FMUState) -> fmi3Status {
    fs::free_fmu_state_as::<M, _>(c, Function::FreeFMUState, state)
}

/// # Safety
/// `size` is writable.
pub unsafe fn serialized_fmu_state_size<M: CoSimModel>(
    c: fmi3Instance,
    state: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    fs::serialized_fmu_state_size_as::<M, _>(c, Function::SerializedFMUStateSize, state, size)
}

/// # Safety
/// `bytes` holds `size` bytes.
pub unsafe fn serialize_fmu_state<M: CoSimModel>(
    c: fmi3Instance,
    state: fmi3FMUState,
    bytes: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    fs::serialize_fmu_state_as::<M, _>(c, Function::SerializeFMUState, state, bytes as *mut _, size)
}

/// # Safety
/// `bytes` holds `size` bytes; `state` points to NULL or to an FMU state.
pub unsafe fn deserialize_fmu_state<M: CoSimModel>(
    c: fmi3Instance,
    bytes: *const fmi3Byte,
    size: usize,
    state: *mut fmi3FMUState,
) -> fmi3Status {
    fs::deserialize_fmu_state_as::<M, _>(c, Function::DeserializeFMUState, bytes as *const _, size, state)
}

// ------------------------------------------------------------------------------------
// Co-Simulation
// ------------------------------------------------------------------------------------

/// `fmi3DoStep`: the checks of FMI 2.0's `fmi2DoStep` (step finite and > 0, the current
/// communication point the FMU's time), then `CoSimModel::do_step`. Never asks for event
/// handling or termination, never returns early; `lastSuccessfulTime` is the FMU's time after
/// the call. A step the integrator cannot complete is fmi3Discard (state `stepDiscarded`).
///
/// # Safety
/// The four output pointers are writable.
pub unsafe fn do_step<M: CoSimModel>(
    c: fmi3Instance,
    current: fmi3Float64,
    h: fmi3Float64,
    _no_set_fmu_state_prior: fmi3Boolean,
    event_handling_needed: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    early_return: *mut fmi3Boolean,
    last_successful_time: *mut fmi3Float64,
) -> fmi3Status {
    guarded::<M, _>(c, Function::DoStep, |inst| {
        const F: &str = "fmi3DoStep";
        if event_handling_needed.is_null()
            || terminate_simulation.is_null()
            || early_return.is_null()
            || last_successful_time.is_null()
        {
            return inst.error(format!(
                "{F}: eventHandlingNeeded, terminateSimulation, earlyReturn or lastSuccessfulTime is NULL"
            ));
        }
        if !(h.is_finite() && h > 0.0) {
            return inst.error(format!("{F}: communicationStepSize = {h:e} must be finite and > 0"));
        }
        let t = inst.model.time();
        let tol = 1e-9 * t.abs().max(1.0);
        if !current.is_finite() || (current - t).abs() > tol {
            return inst.error(format!(
                "{F}: currentCommunicationPoint = {current:?} does not match the FMU's time {t:?} (tolerance {tol:e})"
            ));
        }
        if t + h <= t {
            return inst.error(format!(
                "{F}: communicationStepSize = {h:e} is below the resolution of the time {t:?}: the step would not advance it"
            ));
        }
        *event_handling_needed = fmi3False;
        *terminate_simulation = fmi3False;
        *early_return = fmi3False;
        match inst.model.do_step(current, h) {
            Ok(()) => {
                inst.last_successful_time = None;
                *last_successful_time = inst.model.time();
                fmi3OK
            }
            Err(StepError::Discard {
                message,
                last_successful_time: reached,
            }) => {
                inst.state = State::StepFailed;
                inst.last_successful_time = Some(reached);
                *last_successful_time = reached;
                inst.log(
                    fmi3Discard,
                    CAT_DISCARD,
                    &format!("{F}: step from t = {current:?} by {h:e} discarded, last successful time {reached:?}: {message}"),
                );
                fmi3Discard
            }
            Err(StepError::Error(m)) => inst.error(format!("{F}: {m}")),
        }
    })
}

/// `fmi3UpdateDiscreteStates` (Model Exchange's event iteration; a Co-Simulation instance
/// has no event mode): the model's events need no iteration.
///
/// # Safety
/// The six output pointers are writable.
pub unsafe fn update_discrete_states<M: ModelExchangeModel>(
    c: fmi3Instance,
    discrete_states_need_update: *mut fmi3Boolean,
    terminate_simulation: *mut fmi3Boolean,
    nominals_changed: *mut fmi3Boolean,
    values_changed: *mut fmi3Boolean,
    next_event_time_defined: *mut fmi3Boolean,
    next_event_time: *mut fmi3Float64,
) -> fmi3Status {
    guarded::<M, _>(c, Function::UpdateDiscreteStates, |inst| {
        const F: &str = "fmi3UpdateDiscreteStates";
        let outputs = [
            discrete_states_need_update,
            terminate_simulation,
            nominals_changed,
            values_changed,
            next_event_time_defined,
        ];
        if outputs.iter().any(|p| p.is_null()) || next_event_time.is_null() {
            return inst.error(format!("{F}: an output argument is NULL"));
        }
        match inst.model.new_discrete_states() {
            Ok(update) => {
                *discrete_states_need_update = fmi3False;
                *terminate_simulation = u8::from(update.terminate_simulation);
                *nominals_changed = u8::from(update.nominals_of_continuous_states_changed);
                *values_changed = u8::from(update.values_of_continuous_states_changed);
                *next_event_time_defined = u8::from(update.next_event_time.is_some());
                *next_event_time = update.next_event_time.unwrap_or(0.0);
                fmi3OK
            }
            Err(m) => inst.error(format!("{F}: {m}")),
        }
    })
}
