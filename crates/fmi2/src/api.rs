//! The FMI 2.0 Co-Simulation functions, generic over the model. The exported C symbols
//! (`fmi2_cosimulation_exports!`, or a model crate's literal forwarders) forward to these.
//!
//! Every function that takes an instance:
//! * returns fmi2Error for a NULL, freed or foreign instance: the handle is looked up in
//!   the registry of live handles before anything is dereferenced (see
//!   [`Instance::is_live`]); there is no logger to report it to;
//! * runs its whole body inside `catch_unwind`: a panic is logged with its message, the
//!   instance goes to the `fatal` state and the call returns fmi2Fatal;
//! * checks the call against [`state::TABLE`](super::state::TABLE): an illegal call logs
//!   "fmi2Xxx: illegal call in state yyy" and returns fmi2Error, state unchanged.
//!
//! Other errors (bad arguments, model rejections) return fmi2Error with a logged message
//! and leave the state unchanged (the model contract guarantees nothing was changed,
//! except that a setter call stops at the first value the model rejects).
//!
//! # Safety
//! All functions are `unsafe`: the pointers must satisfy the FMI 2.0 standard (arrays
//! of `nvr` elements, a component returned by [`instantiate`] for the same model, ...).

#![allow(non_upper_case_globals)] // the FMI constants are spelled as in the headers

use std::any::Any;
use std::ffi::{CStr, CString};
use std::fmt::Write;
use std::os::raw::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};

use super::instance::*;
use super::model::{Causality, CoSimModel, StepError, VarType, Variability, Variable};
use super::state::{Call, Function, Interface, State, Version};
use super::types::*;

/// The text of a panic's payload.
pub fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "panic with a non-string payload".to_owned()
    }
}

/// Drop a panic payload without letting a panic in its destructor escape.
pub fn drop_payload(payload: Box<dyn Any + Send>) {
    if let Err(again) = catch_unwind(AssertUnwindSafe(move || drop(payload))) {
        std::mem::forget(again);
    }
}

/// The illegal-call message for `f` in state `s` of an instance of `interface`.
pub fn illegal_call_message_for(f: Function, s: State, interface: Interface) -> String {
    match f.interface() {
        Some(wanted) if wanted != interface && f.allowed_in(s) => format!(
            "{}: illegal call in state {} ({} is a {} function; this instance was instantiated for {})",
            f.name(),
            s.name(),
            f.name(),
            wanted.name(),
            interface.name()
        ),
        _ => illegal_call_message(f, s),
    }
}

/// The illegal-call message for `f` in state `s`.
pub fn illegal_call_message(f: Function, s: State) -> String {
    let mut m = format!("{}: illegal call in state {}", f.name(), s.name());
    if f == Function::CancelStep {
        m.push_str(
            " (fmi2CancelStep is only legal while an asynchronous fmi2DoStep is pending; this FMU steps synchronously)",
        );
    }
    if let (Some(wanted), Some(current)) = (f.interface(), s.interface()) {
        if wanted != current {
            let _ = write!(
                m,
                " ({} is a {} function; this instance was instantiated for {})",
                f.name(),
                wanted.name(),
                current.name()
            );
        }
    }
    m
}

/// Run `body` on the instance behind `c` after the null, magic, version and state checks,
/// with panics caught (see the module documentation). `f` is a function of either version's
/// table ([`Call`]): the FMI 3.0 layer runs its calls through here too.
///
/// # Safety
/// `c` must be NULL or a handle given to the importer (see [`Instance::is_live`]).
pub unsafe fn guarded<M: CoSimModel, F: Call>(
    c: fmi2Component,
    f: F,
    body: impl FnOnce(&mut Instance<M>) -> fmi2Status,
) -> fmi2Status {
    if !Instance::<M>::is_live(c) {
        return fmi2Error;
    }
    let result = catch_unwind(AssertUnwindSafe(|| {
        let inst = &mut *(c as *mut Instance<M>);
        if inst.version != f.version() {
            return inst.error(format!(
                "{}: the instance was made by {}Instantiate*, not by this version's",
                f.name(),
                inst.version.prefix()
            ));
        }
        if !f.legal(inst.state, inst.interface) {
            return inst.error(f.illegal_call_message(inst.state, inst.interface));
        }
        // call tracing only for models that declare the "logCalls" category
        if inst.logs_calls() {
            inst.log(fmi2OK, CAT_CALLS, f.name());
        }
        body(inst)
    }));
    match result {
        Ok(status) => status,
        Err(payload) => {
            let message = format!("{}: panic in the FMU: {}", f.name(), panic_message(&*payload));
            drop_payload(payload);
            if let Err(p) = catch_unwind(AssertUnwindSafe(|| {
                let inst = &mut *(c as *mut Instance<M>);
                inst.state = State::Fatal;
                inst.log(fmi2Fatal, CAT_FATAL, &message);
            })) {
                std::mem::forget(p);
            }
            fmi2Fatal
        }
    }
}

/// `p[..n]` as a slice; NULL with `n > 0` is an error (NULL with `n == 0` is fine).
///
/// # Safety
/// `p` must be NULL or hold `n` elements.
#[inline]
pub unsafe fn in_slice<'a, T, M: CoSimModel>(
    inst: &mut Instance<M>,
    fname: &str,
    what: &str,
    p: *const T,
    n: usize,
) -> Result<&'a [T], fmi2Status> {
    if n == 0 {
        Ok(&[])
    } else if p.is_null() {
        Err(inst.error(format!("{fname}: {what} is NULL but nvr = {n}")))
    } else {
        Ok(std::slice::from_raw_parts(p, n))
    }
}

/// `p[..n]` as a mutable slice; NULL with `n > 0` is an error.
///
/// # Safety
/// `p` must be NULL or hold `n` elements.
#[inline]
pub unsafe fn out_slice<'a, T, M: CoSimModel>(
    inst: &mut Instance<M>,
    fname: &str,
    what: &str,
    p: *mut T,
    n: usize,
) -> Result<&'a mut [T], fmi2Status> {
    if n == 0 {
        Ok(&mut [])
    } else if p.is_null() {
        Err(inst.error(format!("{fname}: {what} is NULL but nvr = {n}")))
    } else {
        Ok(std::slice::from_raw_parts_mut(p, n))
    }
}

/// The variable with value reference `vr` and type `ty`, or a message naming the VR.
#[inline]
pub fn lookup<M: CoSimModel>(fname: &str, vr: u32, ty: VarType) -> Result<&'static Variable, String> {
    lookup_in::<M>(fname, vr, ty, Version::Fmi2)
}

/// [`lookup`] with the types named as `version` names them.
pub fn lookup_in<M: CoSimModel>(
    fname: &str,
    vr: u32,
    ty: VarType,
    version: Version,
) -> Result<&'static Variable, String> {
    let vars = M::info().variables;
    if let Some(v) = vars.iter().find(|v| v.value_reference == vr && v.var_type == ty) {
        return Ok(v);
    }
    match vars.iter().find(|v| v.value_reference == vr) {
        Some(v) => Err(format!(
            "{fname}: value reference {vr} ({}) is a {} variable, not {}",
            v.name,
            v.var_type.name_in(version),
            ty.name_in(version)
        )),
        None => Err(format!("{fname}: unknown value reference {vr}")),
    }
}

/// Whether `v` may be read in `state`: in `instantiated` only parameters and inputs.
#[inline]
pub fn check_get(fname: &str, v: &Variable, state: State) -> Result<(), String> {
    check_get_in(fname, v, state, Version::Fmi2)
}

/// [`check_get`] with the state named as `version` names it.
#[inline]
pub fn check_get_in(fname: &str, v: &Variable, state: State, version: Version) -> Result<(), String> {
    if state == State::Instantiated && !matches!(v.causality, Causality::Parameter | Causality::Input) {
        return Err(format!(
            "{fname}: {} (value reference {}) is an {} and has no value in state {}",
            v.name,
            v.value_reference,
            v.causality.name(),
            state.name_in(version)
        ));
    }
    Ok(())
}

/// Whether `v` may be set in `state`: no outputs or locals; fixed parameters only in
/// `instantiated` and `initializationMode`; tunable parameters and inputs also in
/// `stepComplete` and (Model Exchange) `eventMode`; inputs also in `continuousTimeMode`.
#[inline]
pub fn check_set(fname: &str, v: &Variable, state: State) -> Result<(), String> {
    check_set_in(fname, v, state, Version::Fmi2)
}

/// [`check_set`] with the state named as `version` names it.
#[inline]
pub fn check_set_in(fname: &str, v: &Variable, state: State, version: Version) -> Result<(), String> {
    let early = matches!(state, State::Instantiated | State::InitializationMode);
    let ok = match (v.causality, v.variability) {
        (Causality::Output | Causality::Local, _) => {
            return Err(format!(
                "{fname}: {} (value reference {}) is an {} and cannot be set",
                v.name,
                v.value_reference,
                v.causality.name()
            ))
        }
        (Causality::Parameter, Variability::Tunable) => {
            early || matches!(state, State::StepComplete | State::EventMode)
        }
        (Causality::Input, _) => {
            early
                || matches!(
                    state,
                    State::StepComplete | State::EventMode | State::ContinuousTimeMode
                )
        }
        (Causality::Parameter, _) => early,
    };
    if ok {
        Ok(())
    } else {
        Err(format!(
            "{fname}: {} (value reference {}) is a {} {} and cannot be set in state {}",
            v.name,
            v.value_reference,
            v.variability.name(),
            v.causality.name(),
            state.name_in(version)
        ))
    }
}

// ------------------------------------------------------------------------------------
// Functions without an instance
// ------------------------------------------------------------------------------------

pub fn get_types_platform() -> *const c_char {
    TYPES_PLATFORM.as_ptr()
}

pub fn get_version() -> *const c_char {
    VERSION.as_ptr()
}

/// `fmi2Instantiate`. Returns NULL (after logging, when a logger is available) for a
/// NULL `functions`, a NULL instance name, a type other than fmi2CoSimulation (or
/// fmi2ModelExchange for a model with [`crate::model::ModelInfo::model_exchange`]), or a
/// GUID other than `M::info().guid()`.
///
/// # Safety
/// Pointers as in the FMI 2.0 standard (NUL-terminated strings or NULL).
pub unsafe fn instantiate<M: CoSimModel>(
    instance_name: fmi2String,
    fmu_type: fmi2Type,
    guid: fmi2String,
    _resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    let result = catch_unwind(AssertUnwindSafe(|| {
        if functions.is_null() {
            return std::ptr::null_mut();
        }
        let callbacks = *functions;
        let name = if instance_name.is_null() {
            None
        } else {
            Some(CStr::from_ptr(instance_name).to_string_lossy().into_owned())
        };
        let log = |msg: &str| {
            let n = to_cstring(name.as_deref().unwrap_or(""));
            call_logger(
                callbacks.logger,
                callbacks.componentEnvironment,
                &n,
                fmi2Error,
                CAT_ERROR,
                msg,
            );
        };
        let name = match name.as_deref() {
            Some(name) => name,
            None => {
                log("fmi2Instantiate: instanceName is NULL");
                return std::ptr::null_mut();
            }
        };
        let model_exchange = fmu_type == fmi2ModelExchange && M::info().model_exchange.is_some();
        if fmu_type != fmi2CoSimulation && !model_exchange {
            let what = if fmu_type == fmi2ModelExchange {
                "fmi2ModelExchange".to_owned()
            } else {
                format!("{fmu_type}")
            };
            log(&format!(
                "fmi2Instantiate: fmuType {what} is not supported: this FMU supports only fmi2CoSimulation"
            ));
            return std::ptr::null_mut();
        }
        let expected = M::info().guid();
        if guid.is_null() {
            log(&format!(
                "fmi2Instantiate: GUID mismatch: expected {expected}, got NULL"
            ));
            return std::ptr::null_mut();
        }
        let got = CStr::from_ptr(guid).to_string_lossy();
        if got != expected {
            log(&format!(
                "fmi2Instantiate: GUID mismatch: expected {expected}, got {got}"
            ));
            return std::ptr::null_mut();
        }
        let mut instance = Instance::new(M::instantiate(), name, Some(&callbacks), logging_on != 0);
        if model_exchange {
            instance.interface = Interface::ModelExchange;
            instance.model.use_model_exchange();
        }
        instance.into_component()
    }));
    match result {
        Ok(c) => c,
        Err(payload) => {
            // nothing was allocated that survives; best effort to tell the importer
            let message = format!("fmi2Instantiate: panic in the FMU: {}", panic_message(&*payload));
            drop_payload(payload);
            if !functions.is_null() {
                let _ = catch_unwind(AssertUnwindSafe(|| {
                    let cb = *functions;
                    call_logger(
                        cb.logger,
                        cb.componentEnvironment,
                        &CString::default(),
                        fmi2Fatal,
                        CAT_FATAL,
                        &message,
                    );
                }));
            }
            std::ptr::null_mut()
        }
    }
}

/// `fmi2FreeInstance`. NULL is a no-op (fmi2OK). A pointer that is not a live instance
/// (already freed, or never one) returns fmi2Error without touching it; the exported
/// `void` function drops the status.
///
/// # Safety
/// `c` must be NULL or come from [`instantiate`] for `M`; see [`Instance::is_live`].
pub unsafe fn free_instance<M: CoSimModel>(c: fmi2Component) -> fmi2Status {
    free_instance_as::<M, _>(c, Function::FreeInstance)
}

/// [`free_instance`] for either version's table of functions.
///
/// # Safety
/// See [`free_instance`].
pub unsafe fn free_instance_as<M: CoSimModel, K: Call>(c: fmi2Component, call: K) -> fmi2Status {
    if c.is_null() {
        return fmi2OK;
    }
    guarded::<M, K>(c, call, |inst| {
        inst.kill();
        unregister_handle(c, HandleKind::Instance);
        drop(Box::from_raw(inst as *mut Instance<M>));
        fmi2OK
    })
}

// ------------------------------------------------------------------------------------
// Logging, experiment setup, initialization, termination
// ------------------------------------------------------------------------------------

/// `fmi2SetDebugLogging`: `n_categories == 0` switches every category; otherwise only
/// the listed ones (which must be in `M::info().log_categories`, else fmi2Error and
/// nothing changes).
///
/// # Safety
/// `categories` must hold `n_categories` strings.
pub unsafe fn set_debug_logging<M: CoSimModel>(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n_categories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    set_debug_logging_as::<M, _>(c, Function::SetDebugLogging, logging_on != 0, n_categories, categories)
}

/// [`set_debug_logging`] for either version's table of functions.
///
/// # Safety
/// See [`set_debug_logging`].
pub unsafe fn set_debug_logging_as<M: CoSimModel, K: Call>(
    c: fmi2Component,
    call: K,
    on: bool,
    n_categories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    guarded::<M, K>(c, call, |inst| {
        let fname = call.name();
        let cats = match in_slice(inst, fname, "categories[]", categories, n_categories) {
            Ok(s) => s,
            Err(s) => return s,
        };
        let known = M::info().log_categories;
        let mut indices = Vec::with_capacity(cats.len());
        for &cat in cats {
            if cat.is_null() {
                return inst.error(format!("{fname}: a category is NULL"));
            }
            let cat = CStr::from_ptr(cat).to_string_lossy();
            match known.iter().position(|(name, _)| *name == cat) {
                Some(i) => indices.push(i),
                None => {
                    let list: Vec<&str> = known.iter().map(|(n, _)| *n).collect();
                    return inst.error(format!(
                        "{fname}: unknown log category \"{cat}\" (known: {})",
                        list.join(", ")
                    ));
                }
            }
        }
        if indices.is_empty() {
            inst.logging_on = on;
            inst.categories_enabled.iter_mut().for_each(|e| *e = on);
        } else {
            for i in indices {
                inst.categories_enabled[i] = on;
            }
            inst.logging_on = inst.categories_enabled.iter().any(|&e| e);
        }
        fmi2OK
    })
}

/// `fmi2SetupExperiment` → `CoSimModel::setup_experiment`.
///
/// # Safety
/// See the module documentation.
pub unsafe fn setup_experiment<M: CoSimModel>(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: fmi2Real,
    start_time: fmi2Real,
    stop_time_defined: fmi2Boolean,
    stop_time: fmi2Real,
) -> fmi2Status {
    guarded::<M, _>(c, Function::SetupExperiment, |inst| {
        const F: &str = "fmi2SetupExperiment";
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
        match inst.model.setup_experiment(tol, start_time, stop) {
            Ok(()) => fmi2OK,
            Err(m) => inst.error(format!("{F}: {m}")),
        }
    })
}

/// # Safety
/// See the module documentation.
pub unsafe fn enter_initialization_mode<M: CoSimModel>(c: fmi2Component) -> fmi2Status {
    guarded::<M, _>(c, Function::EnterInitializationMode, |inst| {
        match inst.model.enter_initialization() {
            Ok(()) => {
                inst.state = State::InitializationMode;
                fmi2OK
            }
            Err(m) => inst.error(format!("fmi2EnterInitializationMode: {m}")),
        }
    })
}

/// # Safety
/// See the module documentation.
pub unsafe fn exit_initialization_mode<M: CoSimModel>(c: fmi2Component) -> fmi2Status {
    guarded::<M, _>(c, Function::ExitInitializationMode, |inst| {
        match inst.model.exit_initialization() {
            Ok(()) => {
                inst.state = match inst.interface {
                    Interface::CoSimulation => State::StepComplete,
                    Interface::ModelExchange => State::EventMode,
                };
                fmi2OK
            }
            Err(m) => inst.error(format!("fmi2ExitInitializationMode: {m}")),
        }
    })
}

/// # Safety
/// See the module documentation.
pub unsafe fn terminate<M: CoSimModel>(c: fmi2Component) -> fmi2Status {
    guarded::<M, _>(c, Function::Terminate, |inst| {
        inst.state = State::Terminated;
        fmi2OK
    })
}

/// `fmi2Reset`: `CoSimModel::reset`, back to `instantiated`.
///
/// # Safety
/// See the module documentation.
pub unsafe fn reset<M: CoSimModel>(c: fmi2Component) -> fmi2Status {
    guarded::<M, _>(c, Function::Reset, |inst| {
        inst.model.reset();
        if inst.interface == Interface::ModelExchange {
            inst.model.use_model_exchange();
        }
        inst.state = State::Instantiated;
        inst.last_successful_time = None;
        fmi2OK
    })
}

// ------------------------------------------------------------------------------------
// Getters and setters
// ------------------------------------------------------------------------------------

/// Shared body of the getters of both versions: check every VR, then read each value.
///
/// # Safety
/// `vr` and `value` hold `nvr` elements.
pub unsafe fn get_values<M: CoSimModel, T, K: Call>(
    c: fmi2Component,
    f: K,
    ty: VarType,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut T,
    read: impl Fn(&M, u32) -> Result<T, String>,
) -> fmi2Status {
    guarded::<M, K>(c, f, |inst| {
        let fname = f.name();
        let vrs = match in_slice(inst, fname, "vr[]", vr, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        let values = match out_slice(inst, fname, "value[]", value, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        // Only in `instantiated` does what a variable is limit whether it may be read.
        let restricted = inst.state == State::Instantiated;
        for (&r, slot) in vrs.iter().zip(values.iter_mut()) {
            if restricted || inst.tabled_variable(r, ty).is_none() {
                let checked = inst
                    .variable(fname, r, ty)
                    .and_then(|v| check_get_in(fname, v, inst.state, inst.version));
                if let Err(m) = checked {
                    return inst.error(m);
                }
            }
            match read(&inst.model, r) {
                Ok(x) => *slot = x,
                Err(m) => return inst.error(format!("{fname}: {m}")),
            }
        }
        fmi2OK
    })
}

/// Shared body of the setters of both versions: check every VR first, then write each value.
///
/// # Safety
/// `vr` and `value` hold `nvr` elements.
pub unsafe fn set_values<M: CoSimModel, T: Copy, K: Call>(
    c: fmi2Component,
    f: K,
    ty: VarType,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const T,
    write: impl Fn(&mut M, u32, T) -> Result<(), String>,
) -> fmi2Status {
    guarded::<M, K>(c, f, |inst| {
        let fname = f.name();
        let vrs = match in_slice(inst, fname, "vr[]", vr, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        let values = match in_slice(inst, fname, "value[]", value, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        for &r in vrs {
            if let Err(m) = inst
                .variable(fname, r, ty)
                .and_then(|v| check_set_in(fname, v, inst.state, inst.version))
            {
                return inst.error(m);
            }
        }
        for (&r, &x) in vrs.iter().zip(values) {
            if let Err(m) = write(&mut inst.model, r, x) {
                return inst.error(format!("{fname}: {m}"));
            }
        }
        fmi2OK
    })
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn get_real<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    get_values::<M, f64, _>(c, Function::GetReal, VarType::Real, vr, nvr, value, |m, r| {
        m.get_real(r)
    })
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn get_integer<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    get_values::<M, fmi2Integer, _>(c, Function::GetInteger, VarType::Integer, vr, nvr, value, |m, r| {
        m.get_integer(r)
    })
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn get_boolean<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    get_values::<M, fmi2Boolean, _>(c, Function::GetBoolean, VarType::Boolean, vr, nvr, value, |m, r| {
        m.get_boolean(r).map(|b| if b { fmi2True } else { fmi2False })
    })
}

/// There are no String variables: `nvr == 0` is fine, anything else an error.
///
/// # Safety
/// `vr` and `value` hold `nvr` elements.
pub unsafe fn no_strings<M: CoSimModel, T, K: Call>(
    c: fmi2Component,
    f: K,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const T,
) -> fmi2Status {
    guarded::<M, K>(c, f, |inst| {
        let fname = f.name();
        let vrs = match in_slice(inst, fname, "vr[]", vr, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        if let Err(s) = in_slice(inst, fname, "value[]", value, nvr) {
            return s;
        }
        match vrs.first() {
            None => fmi2OK,
            Some(&r) => {
                let m = match M::info().variables.iter().find(|v| v.value_reference == r) {
                    Some(v) => format!(
                        "{fname}: value reference {r} ({}) is a {} variable, not String",
                        v.name,
                        v.var_type.name()
                    ),
                    None => format!("{fname}: unknown value reference {r} (this FMU has no String variables)"),
                };
                inst.error(m)
            }
        }
    })
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn get_string<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    no_strings::<M, fmi2String, _>(c, Function::GetString, vr, nvr, value)
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn set_real<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    set_values::<M, f64, _>(c, Function::SetReal, VarType::Real, vr, nvr, value, |m, r, x| {
        m.set_real(r, x)
    })
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn set_integer<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    set_values::<M, fmi2Integer, _>(c, Function::SetInteger, VarType::Integer, vr, nvr, value, |m, r, x| {
        m.set_integer(r, x)
    })
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn set_boolean<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    set_values::<M, fmi2Boolean, _>(c, Function::SetBoolean, VarType::Boolean, vr, nvr, value, |m, r, x| {
        m.set_boolean(r, x != fmi2False)
    })
}

/// # Safety
/// `vr` and `value` must hold `nvr` elements.
pub unsafe fn set_string<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    no_strings::<M, fmi2String, _>(c, Function::SetString, vr, nvr, value)
}

// ------------------------------------------------------------------------------------
// FMU state: see `crate::fmu_state_calls`
// ------------------------------------------------------------------------------------

pub use super::fmu_state_calls::{
    deserialize_fmu_state, free_fmu_state, get_fmu_state, serialize_fmu_state, serialized_fmu_state_size, set_fmu_state,
};

// ------------------------------------------------------------------------------------
// Derivatives
// ------------------------------------------------------------------------------------

/// Not supported (`providesDirectionalDerivative="false"`): fmi2Error.
///
/// # Safety
/// See the module documentation.
pub unsafe fn get_directional_derivative<M: CoSimModel>(
    c: fmi2Component,
    _v_unknown_ref: *const fmi2ValueReference,
    _n_unknown: usize,
    _v_known_ref: *const fmi2ValueReference,
    _n_known: usize,
    _dv_known: *const fmi2Real,
    _dv_unknown: *mut fmi2Real,
) -> fmi2Status {
    guarded::<M, _>(c, Function::GetDirectionalDerivative, |inst| {
        inst.error("fmi2GetDirectionalDerivative: not supported (providesDirectionalDerivative=\"false\")")
    })
}

/// `fmi2SetRealInputDerivatives` → `CoSimModel::set_real_input_derivative` per element;
/// only for Real inputs, order >= 1, and only if `canInterpolateInputs`.
///
/// # Safety
/// `vr`, `order` and `value` must hold `nvr` elements.
pub unsafe fn set_real_input_derivatives<M: CoSimModel>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    guarded::<M, _>(c, Function::SetRealInputDerivatives, |inst| {
        const F: &str = "fmi2SetRealInputDerivatives";
        let vrs = match in_slice(inst, F, "vr[]", vr, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        let orders = match in_slice(inst, F, "order[]", order, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        let values = match in_slice(inst, F, "value[]", value, nvr) {
            Ok(s) => s,
            Err(s) => return s,
        };
        if nvr > 0 && !M::info().can_interpolate_inputs {
            return inst.error(format!(
                "{F}: this FMU cannot interpolate inputs (canInterpolateInputs=\"false\")"
            ));
        }
        for (&r, &o) in vrs.iter().zip(orders) {
            let v = match lookup::<M>(F, r, VarType::Real) {
                Ok(v) => v,
                Err(m) => return inst.error(m),
            };
            if v.causality != Causality::Input {
                return inst.error(format!("{F}: {} (value reference {r}) is not an input", v.name));
            }
            if o < 1 {
                return inst.error(format!(
                    "{F}: order {o} for {} (value reference {r}) must be >= 1",
                    v.name
                ));
            }
        }
        for ((&r, &o), &x) in vrs.iter().zip(orders).zip(values) {
            if let Err(m) = inst.model.set_real_input_derivative(r, o, x) {
                return inst.error(format!("{F}: {m}"));
            }
        }
        fmi2OK
    })
}

/// Not supported (`maxOutputDerivativeOrder="0"`): fmi2Error.
///
/// # Safety
/// See the module documentation.
pub unsafe fn get_real_output_derivatives<M: CoSimModel>(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    guarded::<M, _>(c, Function::GetRealOutputDerivatives, |inst| {
        inst.error("fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder=\"0\")")
    })
}

// ------------------------------------------------------------------------------------
// Stepping and status
// ------------------------------------------------------------------------------------

/// `fmi2DoStep`: checks the step size (finite, > 0) and that `current` equals the
/// model's time within `1e-9 * max(1, |t|)`, then `CoSimModel::do_step`.
/// `StepError::Discard` → fmi2Discard and `stepFailed`; `StepError::Error` → fmi2Error.
///
/// # Safety
/// See the module documentation.
pub unsafe fn do_step<M: CoSimModel>(
    c: fmi2Component,
    current: fmi2Real,
    h: fmi2Real,
    _no_set_prior: fmi2Boolean,
) -> fmi2Status {
    guarded::<M, _>(c, Function::DoStep, |inst| {
        const F: &str = "fmi2DoStep";
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
        match inst.model.do_step(current, h) {
            Ok(()) => {
                inst.last_successful_time = None;
                fmi2OK
            }
            Err(StepError::Discard {
                message,
                last_successful_time,
            }) => {
                inst.state = State::StepFailed;
                inst.last_successful_time = Some(last_successful_time);
                inst.log(
                    fmi2Discard,
                    CAT_DISCARD,
                    &format!(
                        "{F}: step from t = {current:?} by {h:e} discarded, last successful time {last_successful_time:?}: {message}"
                    ),
                );
                fmi2Discard
            }
            Err(StepError::Error(m)) => inst.error(format!("{F}: {m}")),
        }
    })
}

/// # Safety
/// See the module documentation.
pub unsafe fn cancel_step<M: CoSimModel>(c: fmi2Component) -> fmi2Status {
    // illegal in every state (see the table); the body is never reached
    guarded::<M, _>(c, Function::CancelStep, |inst| {
        inst.error("fmi2CancelStep: no asynchronous step to cancel")
    })
}

fn status_kind_name(s: fmi2StatusKind) -> Option<&'static str> {
    match s {
        fmi2DoStepStatus => Some("fmi2DoStepStatus"),
        fmi2PendingStatus => Some("fmi2PendingStatus"),
        fmi2LastSuccessfulTime => Some("fmi2LastSuccessfulTime"),
        fmi2Terminated => Some("fmi2Terminated"),
        _ => None,
    }
}

/// Shared body of the status getters: `answer` gives the value for the kinds it
/// supports; other valid kinds → fmi2Discard with a message, invalid kinds → fmi2Error.
unsafe fn get_status_of<M: CoSimModel, T>(
    c: fmi2Component,
    f: Function,
    kind: fmi2StatusKind,
    value: *mut T,
    answer: impl FnOnce(&Instance<M>, fmi2StatusKind) -> Option<T>,
) -> fmi2Status {
    guarded::<M, _>(c, f, |inst| {
        let fname = f.name();
        let kind_name = match status_kind_name(kind) {
            Some(kind_name) => kind_name,
            None => return inst.error(format!("{fname}: invalid fmi2StatusKind {kind}")),
        };
        if value.is_null() {
            return inst.error(format!("{fname}: value is NULL"));
        }
        match answer(inst, kind) {
            Some(x) => {
                *value = x;
                fmi2OK
            }
            None => {
                inst.log(
                    fmi2Discard,
                    CAT_DISCARD,
                    &format!("{fname}: {kind_name} is not available from this function (this FMU steps synchronously)"),
                );
                fmi2Discard
            }
        }
    })
}

/// # Safety
/// `value` must be writable.
pub unsafe fn get_status<M: CoSimModel>(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Status) -> fmi2Status {
    get_status_of::<M, fmi2Status>(c, Function::GetStatus, s, value, |_, _| None)
}

/// `fmi2LastSuccessfulTime` → `CoSimModel::time`.
///
/// # Safety
/// `value` must be writable.
pub unsafe fn get_real_status<M: CoSimModel>(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Real) -> fmi2Status {
    get_status_of::<M, fmi2Real>(c, Function::GetRealStatus, s, value, |inst, k| {
        (k == fmi2LastSuccessfulTime).then(|| inst.model.time())
    })
}

/// # Safety
/// `value` must be writable.
pub unsafe fn get_integer_status<M: CoSimModel>(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    get_status_of::<M, fmi2Integer>(c, Function::GetIntegerStatus, s, value, |_, _| None)
}

/// `fmi2Terminated` → fmi2False (the FMU never asks to stop the simulation).
///
/// # Safety
/// `value` must be writable.
pub unsafe fn get_boolean_status<M: CoSimModel>(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    get_status_of::<M, fmi2Boolean>(c, Function::GetBooleanStatus, s, value, |_, k| {
        (k == fmi2Terminated).then_some(fmi2False)
    })
}

/// # Safety
/// `value` must be writable.
pub unsafe fn get_string_status<M: CoSimModel>(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    get_status_of::<M, fmi2String>(c, Function::GetStringStatus, s, value, |_, _| None)
}
