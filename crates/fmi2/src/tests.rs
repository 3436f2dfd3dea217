//! Unit tests of the generic layer, driven through `api` with the dummy model.
#![allow(non_upper_case_globals)]

use std::cell::RefCell;
use std::ffi::{CStr, CString};
use std::os::raw::c_char;
use std::ptr::{null, null_mut};

use super::api::{self, illegal_call_message};
use super::fmu_state::{crc32, Snapshot, FORMAT_VERSION, STATE_MAGIC};
use super::instance::Instance;
use super::model::{CoSimModel, ModelInfo};
use super::model_description::{format_double, try_model_description_xml, validate_model_info};
use super::model_exchange as me;
use super::state::{Function, State};
use super::testing::*;
use super::types::*;

type M = DummyModel;

/// What the test logger received: (status, category, format, first variadic argument).
type LogRecord = (fmi2Status, String, String, String);

/// A logger written in Rust. Rust cannot define a variadic function on stable, so this
/// takes exactly the one string argument the layer always passes after `"%s"` and is
/// called through the variadic pointer type: sound in practice on the two ABIs below,
/// where a variadic pointer argument travels exactly like a named one.
#[cfg(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64")))]
unsafe extern "C" fn test_logger(
    env: fmi2ComponentEnvironment,
    _name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    arg: *const c_char,
) {
    let sink = &*(env as *const RefCell<Vec<LogRecord>>);
    let s = |p: *const c_char| CStr::from_ptr(p).to_string_lossy().into_owned();
    sink.borrow_mut().push((status, s(category), s(format), s(arg)));
}

fn callbacks(sink: &RefCell<Vec<LogRecord>>) -> fmi2CallbackFunctions {
    #[cfg(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64")))]
    let logger: fmi2CallbackLogger = Some(unsafe {
        std::mem::transmute::<
            unsafe extern "C" fn(
                fmi2ComponentEnvironment,
                fmi2String,
                fmi2Status,
                fmi2String,
                fmi2String,
                *const c_char,
            ),
            unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String, ...),
        >(test_logger)
    });
    #[cfg(not(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64"))))]
    let logger: fmi2CallbackLogger = None;
    fmi2CallbackFunctions {
        logger,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: sink as *const _ as *mut _,
    }
}

fn guid() -> CString {
    CString::new(M::info().guid()).unwrap()
}

unsafe fn new_instance(sink: &RefCell<Vec<LogRecord>>, logging_on: bool) -> fmi2Component {
    let cb = callbacks(sink);
    let c = api::instantiate::<M>(
        c"inst".as_ptr(),
        fmi2CoSimulation,
        guid().as_ptr(),
        null(),
        &cb,
        fmi2False,
        logging_on as fmi2Boolean,
    );
    assert!(!c.is_null());
    c
}

unsafe fn inst<'a>(c: fmi2Component) -> &'a mut Instance<M> {
    &mut *(c as *mut Instance<M>)
}

unsafe fn initialize(c: fmi2Component) {
    assert_eq!(api::setup_experiment::<M>(c, 0, 0.0, 0.0, 0, 0.0), fmi2OK);
    assert_eq!(api::enter_initialization_mode::<M>(c), fmi2OK);
    assert_eq!(api::exit_initialization_mode::<M>(c), fmi2OK);
    assert_eq!(inst(c).state, State::StepComplete);
}

unsafe fn set_r(c: fmi2Component, vr: u32, x: f64) -> fmi2Status {
    api::set_real::<M>(c, &vr, 1, &x)
}

unsafe fn get_r(c: fmi2Component, vr: u32) -> (fmi2Status, f64) {
    let mut x = f64::NAN;
    (api::get_real::<M>(c, &vr, 1, &mut x), x)
}

fn last_error(c: fmi2Component) -> String {
    unsafe { inst(c).last_error.clone().unwrap_or_default() }
}

fn boxed_snapshot() -> fmi2FMUstate {
    Snapshot::new::<M>(State::StepComplete, M::instantiate().serialize()).into_raw()
}

/// Call `f` with harmless, valid arguments.
unsafe fn call(f: Function, c: fmi2Component) -> fmi2Status {
    let mut r = 0.0;
    let mut i = 0;
    let mut b = 0;
    let mut s: fmi2String = null();
    let mut st: fmi2Status = 0;
    let mut size = 0usize;
    let mut fs: fmi2FMUstate = null_mut();
    match f {
        Function::SetDebugLogging => api::set_debug_logging::<M>(c, 1, 0, null()),
        Function::FreeInstance => api::free_instance::<M>(c),
        Function::SetupExperiment => api::setup_experiment::<M>(c, 0, 0.0, 0.0, 0, 0.0),
        Function::EnterInitializationMode => api::enter_initialization_mode::<M>(c),
        Function::ExitInitializationMode => api::exit_initialization_mode::<M>(c),
        Function::Terminate => api::terminate::<M>(c),
        Function::Reset => api::reset::<M>(c),
        Function::GetReal => api::get_real::<M>(c, &VR_TAU, 1, &mut r),
        Function::GetInteger => api::get_integer::<M>(c, &VR_N_SUB, 1, &mut i),
        Function::GetBoolean => api::get_boolean::<M>(c, &VR_FROZEN, 1, &mut b),
        Function::GetString => api::get_string::<M>(c, null(), 0, &mut s),
        Function::SetReal => api::set_real::<M>(c, &VR_TAU, 1, &2.0),
        Function::SetInteger => api::set_integer::<M>(c, &VR_N_SUB, 1, &3),
        Function::SetBoolean => api::set_boolean::<M>(c, &VR_FROZEN, 1, &1),
        Function::SetString => api::set_string::<M>(c, null(), 0, null()),
        Function::GetFMUstate => api::get_fmu_state::<M>(c, &mut fs),
        Function::SetFMUstate => api::set_fmu_state::<M>(c, boxed_snapshot()),
        Function::FreeFMUstate => {
            fs = boxed_snapshot();
            api::free_fmu_state::<M>(c, &mut fs)
        }
        Function::SerializedFMUstateSize => api::serialized_fmu_state_size::<M>(c, boxed_snapshot(), &mut size),
        Function::SerializeFMUstate => {
            let snap = boxed_snapshot();
            let mut buf = (*(snap as *const Snapshot)).to_bytes();
            api::serialize_fmu_state::<M>(c, snap, buf.as_mut_ptr() as *mut fmi2Byte, buf.len())
        }
        Function::DeSerializeFMUstate => {
            let bytes = (*(boxed_snapshot() as *const Snapshot)).to_bytes();
            api::deserialize_fmu_state::<M>(c, bytes.as_ptr() as *const fmi2Byte, bytes.len(), &mut fs)
        }
        Function::GetDirectionalDerivative => api::get_directional_derivative::<M>(c, &VR_Y, 1, &VR_U, 1, &1.0, &mut r),
        Function::SetRealInputDerivatives => api::set_real_input_derivatives::<M>(c, &VR_U, 1, &1, &0.5),
        Function::GetRealOutputDerivatives => api::get_real_output_derivatives::<M>(c, &VR_Y, 1, &1, &mut r),
        Function::DoStep => api::do_step::<M>(c, 0.0, 0.1, 1),
        Function::CancelStep => api::cancel_step::<M>(c),
        Function::GetStatus => api::get_status::<M>(c, fmi2DoStepStatus, &mut st),
        Function::GetRealStatus => api::get_real_status::<M>(c, fmi2LastSuccessfulTime, &mut r),
        Function::GetIntegerStatus => api::get_integer_status::<M>(c, fmi2DoStepStatus, &mut i),
        Function::GetBooleanStatus => api::get_boolean_status::<M>(c, fmi2Terminated, &mut b),
        Function::GetStringStatus => api::get_string_status::<M>(c, fmi2PendingStatus, &mut s),
        Function::EnterEventMode => me::enter_event_mode::<M>(c),
        Function::NewDiscreteStates => {
            let mut info = fmi2EventInfo::default();
            me::new_discrete_states::<M>(c, &mut info)
        }
        Function::EnterContinuousTimeMode => me::enter_continuous_time_mode::<M>(c),
        Function::CompletedIntegratorStep => me::completed_integrator_step::<M>(c, 1, &mut b, &mut i),
        Function::SetTime => me::set_time::<M>(c, 0.5),
        Function::SetContinuousStates => me::set_continuous_states::<M>(c, null(), 0),
        Function::GetDerivatives => me::get_derivatives::<M>(c, null_mut(), 0),
        Function::GetEventIndicators => me::get_event_indicators::<M>(c, null_mut(), 0),
        Function::GetContinuousStates => me::get_continuous_states::<M>(c, null_mut(), 0),
        Function::GetNominalsOfContinuousStates => me::get_nominals_of_continuous_states::<M>(c, null_mut(), 0),
    }
}

#[test]
fn state_machine_every_function_in_every_state() {
    let sink = RefCell::new(Vec::new());
    for f in Function::all() {
        for s in State::ALL {
            unsafe {
                let c = new_instance(&sink, false);
                inst(c).state = s;
                // an instance in a state of one interface only is of that interface
                let interface = s.interface().unwrap_or(super::state::Interface::CoSimulation);
                inst(c).interface = interface;
                inst(c).last_error = None;
                let status = call(f, c);
                if f.legal(s, interface) {
                    assert_ne!(status, fmi2Fatal, "{f:?} in {s:?}");
                    if f == Function::FreeInstance {
                        assert_eq!(status, fmi2OK);
                        continue;
                    }
                    let e = last_error(c);
                    assert!(!e.contains("illegal call"), "{f:?} in {s:?}: {e}");
                } else {
                    assert_eq!(status, fmi2Error, "{f:?} in {s:?}");
                    assert_eq!(inst(c).state, s, "{f:?} changed the state");
                    let e = last_error(c);
                    assert_eq!(e, api::illegal_call_message_for(f, s, interface));
                    assert!(e.contains(f.name()) && e.contains(s.name()), "{e}");
                }
                assert_eq!(api::free_instance::<M>(c), fmi2OK);
            }
        }
    }
}

#[test]
fn null_and_dead_instances_are_errors_for_every_function() {
    // a readable block without the magic number: what a freed instance typically is
    let fake = Box::into_raw(Box::new([0u64; 64])) as fmi2Component;
    for f in Function::all() {
        unsafe {
            let expected = if f == Function::FreeInstance { fmi2OK } else { fmi2Error };
            assert_eq!(call(f, null_mut()), expected, "{f:?} on NULL");
            assert_eq!(call(f, fake), fmi2Error, "{f:?} on a dead instance");
        }
    }
    unsafe { drop(Box::from_raw(fake as *mut [u64; 64])) };
}

#[test]
fn variables_found_by_the_table_of_rows_are_those_the_search_finds() {
    use super::model::{VarType, Variable};
    let instance = Instance::new(M::instantiate(), "rows", None, false);
    let largest = M::info().variables.iter().map(|v| v.value_reference).max().unwrap();
    for vr in (0..=largest + 2).chain([u32::MAX]) {
        for ty in [VarType::Real, VarType::Integer, VarType::Boolean] {
            let by_rows = instance.variable("f", vr, ty).map(|v| v as *const Variable);
            let by_search = api::lookup::<M>("f", vr, ty).map(|v| v as *const Variable);
            assert_eq!(by_rows, by_search, "vr {vr} {ty:?}");
        }
    }
}

#[test]
fn a_freed_instance_is_not_live_though_it_was_the_last_one_found() {
    use super::instance::{is_registered_handle, HandleKind};
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        // Found live: it is now the instance of the last call, checked without the lock.
        assert!(Instance::<M>::is_live(c));
        assert!(is_registered_handle(c, HandleKind::Instance));
        assert_eq!(api::free_instance::<M>(c), fmi2OK);
        // The registry alone answers: the freed memory is not read.
        assert!(!is_registered_handle(c, HandleKind::Instance));
        assert!(!Instance::<M>::is_live(c));
    }
}

#[test]
fn free_clears_the_magic() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        assert!(Instance::<M>::is_live(c));
        inst(c).kill();
        assert!(!Instance::<M>::is_live(c));
        assert_eq!(api::terminate::<M>(c), fmi2Error);
        assert_eq!(api::free_instance::<M>(c), fmi2Error); // leaks the instance on purpose
        assert_eq!(api::free_instance::<M>(null_mut()), fmi2OK);
    }
}

#[test]
fn instantiate_rejects_bad_arguments() {
    let sink = RefCell::new(Vec::new());
    let cb = callbacks(&sink);
    unsafe {
        let g = guid();
        let inst = |name: fmi2String, ty, guid: fmi2String, cb: *const fmi2CallbackFunctions| {
            api::instantiate::<M>(name, ty, guid, null(), cb, 0, 0)
        };
        assert!(inst(c"a".as_ptr(), fmi2CoSimulation, c"{wrong}".as_ptr(), &cb).is_null());
        assert!(inst(c"a".as_ptr(), fmi2ModelExchange, g.as_ptr(), &cb).is_null());
        assert!(inst(c"a".as_ptr(), 7, g.as_ptr(), &cb).is_null());
        assert!(inst(c"a".as_ptr(), fmi2CoSimulation, null(), &cb).is_null());
        assert!(inst(null(), fmi2CoSimulation, g.as_ptr(), &cb).is_null());
        assert!(inst(c"a".as_ptr(), fmi2CoSimulation, g.as_ptr(), null()).is_null());
        let no_logger = fmi2CallbackFunctions { logger: None, ..cb };
        assert!(inst(c"a".as_ptr(), fmi2CoSimulation, c"{wrong}".as_ptr(), &no_logger).is_null());
        // two live instances at once
        let a = inst(c"a".as_ptr(), fmi2CoSimulation, g.as_ptr(), &no_logger);
        let b = inst(c"b".as_ptr(), fmi2CoSimulation, g.as_ptr(), &no_logger);
        assert!(!a.is_null() && !b.is_null() && a != b);
        assert_eq!(set_r(a, VR_TAU, 5.0), fmi2OK);
        assert_eq!(get_r(b, VR_TAU), (fmi2OK, 1.0));
        api::free_instance::<M>(a);
        api::free_instance::<M>(b);
    }
    #[cfg(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        let log = sink.borrow();
        assert_eq!(log.len(), 5, "{log:?}"); // NULL functions and no logger: nothing to call
        assert!(log
            .iter()
            .all(|r| r.0 == fmi2Error && r.1 == "logStatusError" && r.2 == "%s"));
        assert_eq!(
            log[0].3,
            format!(
                "fmi2Instantiate: GUID mismatch: expected {}, got {{wrong}}",
                M::info().guid()
            )
        );
        assert!(log[1].3.contains("fmi2ModelExchange"), "{}", log[1].3);
        assert!(log[4].3.contains("instanceName is NULL"));
    }
}

#[test]
fn logger_gets_percent_s_and_filtering_follows_logging_on() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        // a '%' in the message must not be interpreted by the importer
        inst(c).log(fmi2OK, "logEvents", "100% info");
        inst(c).log(fmi2Warning, "logStatusWarning", "warn");
        assert!(inst(c).captured.is_empty());
        inst(c).log(fmi2Error, "logStatusError", "error %d %s");
        inst(c).log(fmi2Discard, "logStatusDiscard", "discard");
        assert_eq!(inst(c).captured.len(), 2);

        // unknown category: fmi2Error, nothing changes
        let cats = [c"logEvents".as_ptr(), c"nope".as_ptr()];
        assert_eq!(api::set_debug_logging::<M>(c, 1, 2, cats.as_ptr()), fmi2Error);
        assert!(
            last_error(c).contains("unknown log category \"nope\""),
            "{}",
            last_error(c)
        );
        assert!(!inst(c).should_log(fmi2OK, "logEvents"));
        assert_eq!(api::set_debug_logging::<M>(c, 1, 1, cats.as_ptr()), fmi2OK);
        assert!(inst(c).should_log(fmi2OK, "logEvents"));
        assert!(!inst(c).should_log(fmi2OK, "logStatusWarning"));
        assert_eq!(api::set_debug_logging::<M>(c, 1, 0, null()), fmi2OK);
        assert!(inst(c).should_log(fmi2OK, "logStatusWarning"));
        assert_eq!(api::set_debug_logging::<M>(c, 0, 0, null()), fmi2OK);
        assert!(!inst(c).should_log(fmi2OK, "logEvents"));
        assert_eq!(api::set_debug_logging::<M>(c, 1, 1, null()), fmi2Error);
        api::free_instance::<M>(c);
    }
    #[cfg(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64")))]
    {
        let log = sink.borrow();
        assert_eq!(
            log[0],
            (fmi2Error, "logStatusError".into(), "%s".into(), "error %d %s".into())
        );
        assert_eq!(log[1].0, fmi2Discard);
        assert!(log.iter().all(|r| r.2 == "%s"));
    }
}

#[test]
fn simulation_lifecycle() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        assert_eq!(get_r(c, VR_TAU), (fmi2OK, 1.0)); // parameters readable when instantiated
        assert_eq!(get_r(c, VR_Y).0, fmi2Error); // outputs not
        assert!(last_error(c).contains("y (value reference 2)"), "{}", last_error(c));
        assert_eq!(set_r(c, VR_TAU, 0.5), fmi2OK);
        assert_eq!(set_r(c, VR_U, 1.0), fmi2OK);
        initialize(c);
        let h = 0.1;
        for k in 0..10 {
            assert_eq!(api::do_step::<M>(c, k as f64 * h, h, 1), fmi2OK);
        }
        let (st, y) = get_r(c, VR_Y);
        assert_eq!(st, fmi2OK);
        assert!((y - (1.0 - (-1.0f64 / 0.5).exp())).abs() < 1e-6, "{y}");
        let mut t = 0.0;
        assert_eq!(api::get_real_status::<M>(c, fmi2LastSuccessfulTime, &mut t), fmi2OK);
        assert!((t - 1.0).abs() < 1e-12);
        let mut b = 7;
        assert_eq!(api::get_boolean_status::<M>(c, fmi2Terminated, &mut b), fmi2OK);
        assert_eq!(b, fmi2False);
        let mut st = 0;
        assert_eq!(api::get_status::<M>(c, fmi2DoStepStatus, &mut st), fmi2Discard);
        assert_eq!(api::get_status::<M>(c, 99, &mut st), fmi2Error);
        assert_eq!(
            api::get_real_status::<M>(c, fmi2LastSuccessfulTime, null_mut()),
            fmi2Error
        );
        assert_eq!(api::terminate::<M>(c), fmi2OK);
        assert_eq!(inst(c).state, State::Terminated);
        assert_eq!(get_r(c, VR_Y), (fmi2OK, y));
        assert_eq!(api::reset::<M>(c), fmi2OK);
        assert_eq!(inst(c).state, State::Instantiated);
        assert_eq!(inst(c).model, M::instantiate());
        api::free_instance::<M>(c);
    }
}

#[test]
fn do_step_checks_arguments_and_maps_step_errors() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        initialize(c);
        for h in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(api::do_step::<M>(c, 0.0, h, 0), fmi2Error, "h = {h}");
            assert!(last_error(c).contains("communicationStepSize"), "{}", last_error(c));
        }
        assert_eq!(api::do_step::<M>(c, 0.5, 0.1, 0), fmi2Error);
        assert!(
            last_error(c).contains("0.5") && last_error(c).contains("time 0.0"),
            "{}",
            last_error(c)
        );
        assert_eq!(api::do_step::<M>(c, 1e-12, 0.1, 0), fmi2OK); // within tolerance
        assert_eq!(api::do_step::<M>(c, 0.1, 2000.0, 0), fmi2Error); // StepError::Error
        assert!(last_error(c).contains("too long"));
        assert_eq!(inst(c).state, State::StepComplete);

        assert_eq!(set_r(c, VR_U, 2e6), fmi2OK);
        assert_eq!(api::do_step::<M>(c, 0.1, 0.1, 0), fmi2Discard);
        assert_eq!(inst(c).captured.last().unwrap().0, fmi2Discard);
        assert_eq!(inst(c).state, State::StepFailed);
        let t1 = 0.1 + 1e-12; // the FMU follows the importer's communication points
        assert_eq!(inst(c).last_successful_time, Some(t1));
        let log = &inst(c).captured;
        assert!(log.last().unwrap().2.contains("too large"), "{log:?}");
        let mut t = 0.0;
        assert_eq!(api::get_real_status::<M>(c, fmi2LastSuccessfulTime, &mut t), fmi2OK);
        assert_eq!(t, t1);
        assert_eq!(api::do_step::<M>(c, t1, 0.1, 0), fmi2Error); // illegal in stepFailed
        assert_eq!(last_error(c), illegal_call_message(Function::DoStep, State::StepFailed));
        assert_eq!(get_r(c, VR_Y).0, fmi2OK);
        assert_eq!(api::terminate::<M>(c), fmi2OK);
        assert_eq!(api::cancel_step::<M>(c), fmi2Error);
        api::free_instance::<M>(c);
    }
}

#[test]
fn setters_and_getters_check_the_variable_table() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        assert_eq!(set_r(c, VR_Y, 1.0), fmi2Error);
        assert!(
            last_error(c).contains("y (value reference 2) is an output"),
            "{}",
            last_error(c)
        );
        assert_eq!(set_r(c, 999, 1.0), fmi2Error);
        assert!(last_error(c).contains("unknown value reference 999"));
        assert_eq!(set_r(c, VR_N_SUB, 1.0), fmi2Error);
        assert!(last_error(c).contains("value reference 12 (n_sub) is a Integer variable, not Real"));
        assert_eq!(set_r(c, VR_TAU, 0.0), fmi2Error); // model rejects
        assert!(last_error(c).contains("fmi2SetReal: tau = 0"), "{}", last_error(c));
        assert_eq!(set_r(c, VR_TAU, f64::NAN), fmi2Error);
        assert_eq!(api::set_integer::<M>(c, &VR_N_SUB, 1, &0), fmi2Error);
        assert_eq!(api::set_integer::<M>(c, &VR_N_SUB, 1, &8), fmi2OK);
        assert_eq!(api::set_boolean::<M>(c, &VR_FROZEN, 1, &5), fmi2OK); // nonzero is true
        let mut b = 0;
        assert_eq!(api::get_boolean::<M>(c, &VR_FROZEN, 1, &mut b), fmi2OK);
        assert_eq!(b, fmi2True);
        // all VRs are checked before any value is written
        let vrs = [VR_TAU, VR_Y];
        assert_eq!(api::set_real::<M>(c, vrs.as_ptr(), 2, [3.0, 3.0].as_ptr()), fmi2Error);
        assert_eq!(get_r(c, VR_TAU), (fmi2OK, 1.0));
        // NULL arrays
        let mut x = 0.0;
        assert_eq!(api::set_real::<M>(c, null(), 1, &1.0), fmi2Error);
        assert!(last_error(c).contains("vr[] is NULL"));
        assert_eq!(api::get_real::<M>(c, &VR_TAU, 1, null_mut()), fmi2Error);
        assert!(last_error(c).contains("value[] is NULL"));
        assert_eq!(api::get_real::<M>(c, null(), 0, null_mut()), fmi2OK);
        assert_eq!(api::set_real_input_derivatives::<M>(c, &VR_U, 1, null(), &x), fmi2Error);
        // strings
        let mut s: fmi2String = null();
        assert_eq!(api::get_string::<M>(c, &VR_U, 1, &mut s), fmi2Error);
        assert!(last_error(c).contains("not String"));
        assert_eq!(api::set_string::<M>(c, &77, 1, &c"x".as_ptr()), fmi2Error);
        // input derivatives: inputs only, order >= 1
        assert_eq!(api::set_real_input_derivatives::<M>(c, &VR_TAU, 1, &1, &1.0), fmi2Error);
        assert!(last_error(c).contains("not an input"));
        assert_eq!(api::set_real_input_derivatives::<M>(c, &VR_U, 1, &0, &1.0), fmi2Error);

        initialize(c);
        assert_eq!(set_r(c, VR_Y0, 1.0), fmi2Error); // fixed parameter after initialization
        assert!(last_error(c).contains("fixed parameter and cannot be set in state stepComplete"));
        assert_eq!(api::set_integer::<M>(c, &VR_N_SUB, 1, &2), fmi2Error);
        assert_eq!(set_r(c, VR_TAU, 2.0), fmi2OK); // tunable
        assert_eq!(set_r(c, VR_U, 1.0), fmi2OK); // input
        assert_eq!(api::get_real::<M>(c, &VR_Y, 1, &mut x), fmi2OK);
        assert_eq!(api::set_boolean::<M>(c, &VR_FROZEN, 1, &0), fmi2OK);
        assert_eq!(api::set_real_input_derivatives::<M>(c, &VR_U, 1, &1, &2.0), fmi2OK);
        assert_eq!(inst(c).model.du, 2.0);
        assert_eq!(api::do_step::<M>(c, 0.0, 0.5, 0), fmi2OK);
        assert!((get_r(c, VR_U).1 - 2.0).abs() < 1e-12);
        let mut d = 0.0;
        assert_eq!(
            api::get_directional_derivative::<M>(c, &VR_Y, 1, &VR_U, 1, &1.0, &mut d),
            fmi2Error
        );
        assert!(last_error(c).contains("not supported"));
        assert_eq!(
            api::get_real_output_derivatives::<M>(c, &VR_Y, 1, &1, &mut d),
            fmi2Error
        );
        api::free_instance::<M>(c);
    }
}

#[test]
fn panics_are_caught_and_make_the_instance_fatal() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        assert_eq!(set_r(c, VR_U, PANIC_VALUE), fmi2Fatal);
        assert_eq!(inst(c).state, State::Fatal);
        let (status, _, msg) = inst(c).captured.last().unwrap().clone();
        assert_eq!(status, fmi2Fatal);
        assert!(
            msg.contains("fmi2SetReal: panic in the FMU: dummy model asked to panic"),
            "{msg}"
        );
        assert_eq!(get_r(c, VR_TAU).0, fmi2Error);
        assert_eq!(last_error(c), illegal_call_message(Function::GetReal, State::Fatal));
        assert_eq!(api::free_instance::<M>(c), fmi2OK);
    }
    #[cfg(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64")))]
    assert!(sink
        .borrow()
        .iter()
        .any(|r| r.0 == fmi2Fatal && r.3.contains("asked to panic")));
}

#[test]
fn fmu_state_get_set_free() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        assert_eq!(set_r(c, VR_U, 1.0), fmi2OK);
        initialize(c);
        assert_eq!(api::do_step::<M>(c, 0.0, 0.5, 0), fmi2OK);
        let mut fs: fmi2FMUstate = null_mut();
        assert_eq!(api::get_fmu_state::<M>(c, &mut fs), fmi2OK);
        assert!(!fs.is_null());
        let saved = inst(c).model.clone();
        assert_eq!(api::do_step::<M>(c, 0.5, 0.5, 0), fmi2OK);
        assert_eq!(api::terminate::<M>(c), fmi2OK);
        assert_eq!(api::set_fmu_state::<M>(c, fs), fmi2OK);
        assert_eq!(inst(c).model, saved);
        assert_eq!(inst(c).state, State::StepComplete);
        // getting into an existing state overwrites it in place
        let before = fs;
        assert_eq!(api::do_step::<M>(c, 0.5, 0.25, 0), fmi2OK);
        assert_eq!(api::get_fmu_state::<M>(c, &mut fs), fmi2OK);
        assert_eq!(fs, before);
        assert_eq!((*(fs as *const Snapshot)).model_bytes, inst(c).model.serialize());
        assert_eq!(api::free_fmu_state::<M>(c, &mut fs), fmi2OK);
        assert!(fs.is_null());
        assert_eq!(api::free_fmu_state::<M>(c, &mut fs), fmi2OK); // NULL: no-op
        assert_eq!(api::free_fmu_state::<M>(c, null_mut()), fmi2OK);
        let fake = Box::into_raw(Box::new([0u64; 8])) as fmi2FMUstate;
        assert_eq!(api::set_fmu_state::<M>(c, fake), fmi2Error);
        assert_eq!(api::set_fmu_state::<M>(c, null_mut()), fmi2Error);
        assert_eq!(api::get_fmu_state::<M>(c, null_mut()), fmi2Error);
        let mut fake_slot = fake;
        assert_eq!(api::get_fmu_state::<M>(c, &mut fake_slot), fmi2Error);
        drop(Box::from_raw(fake as *mut [u64; 8]));
        api::free_instance::<M>(c);
    }
}

/// Serialize a state from one instance, free it, and restore it into a new instance from
/// the bytes alone (what a process restart would do).
#[test]
fn serialized_state_round_trip() {
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        assert_eq!(set_r(c, VR_U, 1.0), fmi2OK);
        initialize(c);
        assert_eq!(api::do_step::<M>(c, 0.0, 0.3, 0), fmi2OK);
        let mut fs: fmi2FMUstate = null_mut();
        assert_eq!(api::get_fmu_state::<M>(c, &mut fs), fmi2OK);
        let mut size = 0;
        assert_eq!(api::serialized_fmu_state_size::<M>(c, fs, &mut size), fmi2OK);
        let mut bytes = vec![0u8; size];
        assert_eq!(
            api::serialize_fmu_state::<M>(c, fs, bytes.as_mut_ptr() as *mut fmi2Byte, size - 1),
            fmi2Error
        );
        assert_eq!(
            api::serialize_fmu_state::<M>(c, fs, bytes.as_mut_ptr() as *mut fmi2Byte, size),
            fmi2OK
        );
        let saved = inst(c).model.clone();
        assert_eq!(api::free_fmu_state::<M>(c, &mut fs), fmi2OK);
        api::free_instance::<M>(c);

        let d = new_instance(&sink, false);
        let mut fs2: fmi2FMUstate = null_mut();
        assert_eq!(
            api::deserialize_fmu_state::<M>(d, bytes.as_ptr() as *const fmi2Byte, size, &mut fs2),
            fmi2OK
        );
        assert_eq!(api::set_fmu_state::<M>(d, fs2), fmi2OK);
        assert_eq!(inst(d).model, saved);
        assert_eq!(inst(d).state, State::StepComplete);
        assert_eq!(api::do_step::<M>(d, 0.3, 0.1, 0), fmi2OK);
        assert_eq!(api::free_fmu_state::<M>(d, &mut fs2), fmi2OK);
        api::free_instance::<M>(d);
    }
}

fn good_bytes() -> Vec<u8> {
    let mut m = M::instantiate();
    m.y = 0.25;
    Snapshot::new::<M>(State::StepComplete, m.serialize()).to_bytes()
}

/// Rebuild the byte image with its fields changed and a valid checksum.
fn forge(magic: &[u8], version: u32, guid: &str, state: u8, model: &[u8]) -> Vec<u8> {
    let mut b = magic.to_vec();
    b.extend_from_slice(&version.to_le_bytes());
    b.extend_from_slice(&(guid.len() as u32).to_le_bytes());
    b.extend_from_slice(guid.as_bytes());
    b.push(state);
    b.extend_from_slice(&(model.len() as u64).to_le_bytes());
    b.extend_from_slice(model);
    let crc = crc32(&b);
    b.extend_from_slice(&crc.to_le_bytes());
    b
}

#[test]
fn serialized_state_rejects_corrupted_foreign_and_truncated_bytes() {
    let good = good_bytes();
    let model = M::instantiate().serialize();
    let g = M::info().guid();
    assert!(Snapshot::from_bytes::<M>(&good).is_ok());
    assert_eq!(
        forge(STATE_MAGIC, FORMAT_VERSION, g, 3, &{
            let mut m = M::instantiate();
            m.y = 0.25;
            m.serialize()
        }),
        good
    );

    let err = |b: &[u8]| Snapshot::from_bytes::<M>(b).err().expect("must be rejected");
    assert!(err(&forge(b"NOTASTAT", 1, g, 3, &model)).contains("wrong magic"));
    assert!(err(&forge(STATE_MAGIC, 2, g, 3, &model)).contains("format version 2"));
    let e = err(&forge(STATE_MAGIC, 1, "{other-fmu}", 3, &model));
    assert!(e.contains("GUID mismatch") && e.contains("{other-fmu}"), "{e}");
    assert!(err(&forge(STATE_MAGIC, 1, g, 0, &model)).contains("invalid layer state"));
    assert!(err(&forge(STATE_MAGIC, 1, g, 8, &model)).contains("fatal"));
    assert!(err(&forge(STATE_MAGIC, 1, g, 3, &model[..10])).contains("rejected by the model"));
    // every single-bit flip in the body is caught (by the checksum or an earlier check)
    for i in 0..good.len() {
        let mut b = good.clone();
        b[i] ^= 0x10;
        let e = err(&b);
        if i >= 8 + 4 + 4 + g.len() + 1 + 8 && i < good.len() - 4 {
            assert!(e.contains("checksum mismatch"), "byte {i}: {e}");
        }
    }
    for n in 0..good.len() {
        let e = err(&good[..n]);
        assert!(e.contains("truncated") || e.contains("wrong magic"), "{n}: {e}");
    }
    let mut long = good.clone();
    long.push(0);
    assert!(err(&long).contains("trailing"));

    // and through the API: fmi2Error with the reason logged
    let sink = RefCell::new(Vec::new());
    unsafe {
        let c = new_instance(&sink, false);
        let mut fs: fmi2FMUstate = null_mut();
        let bad = forge(STATE_MAGIC, 1, "{other-fmu}", 3, &model);
        assert_eq!(
            api::deserialize_fmu_state::<M>(c, bad.as_ptr() as *const fmi2Byte, bad.len(), &mut fs),
            fmi2Error
        );
        assert!(fs.is_null());
        assert!(last_error(c).starts_with("fmi2DeSerializeFMUstate: serialized FMU state of another FMU"));
        assert_eq!(api::deserialize_fmu_state::<M>(c, null(), 0, &mut fs), fmi2Error);
        assert!(last_error(c).contains("truncated"));
        assert_eq!(api::deserialize_fmu_state::<M>(c, null(), 5, &mut fs), fmi2Error);
        api::free_instance::<M>(c);
    }
}

#[test]
fn model_description_lists_every_variable() {
    let xml = try_model_description_xml(M::info()).unwrap();
    assert!(xml.contains(r#"fmiVersion="2.0""#));
    assert!(xml.contains(&format!(r#"guid="{}""#, M::info().guid())));
    assert!(xml.contains(r#"canInterpolateInputs="true""#));
    assert!(xml.contains(r#"<ScalarVariable name="u" valueReference="1" description="input &lt;u&gt; &amp; &quot;target&quot;" causality="input" variability="continuous">"#));
    assert!(xml.contains(r#"<Real unit="1" start="0.0"/>"#));
    assert!(xml.contains(r#"<Real unit="s" start="1.0" min="1e-6"/>"#), "{xml}");
    assert!(xml.contains(r#"<Integer start="4" min="1" max="1000"/>"#));
    assert!(xml.contains(r#"<Boolean start="false"/>"#));
    assert!(xml.contains("<Outputs>\n      <Unknown index=\"2\"/>\n    </Outputs>"));
    assert!(xml.contains("<InitialUnknowns>\n      <Unknown index=\"2\"/>\n    </InitialUnknowns>"));
    for v in M::info().variables {
        assert_eq!(
            xml.matches(&format!(r#"name="{}" valueReference="{}""#, v.name, v.value_reference))
                .count(),
            1
        );
    }
    let vrs = xml.matches("valueReference=").count();
    assert_eq!(vrs, M::info().variables.len());
}

#[test]
fn sha1_and_uuid_v5_match_the_standards_vectors() {
    use super::model_description::{sha1, uuid_v5};
    let hex = |b: &[u8]| b.iter().map(|x| format!("{x:02x}")).collect::<String>();
    // FIPS 180 examples.
    assert_eq!(hex(&sha1(b"abc")), "a9993e364706816aba3e25717850c26c9cd0d89d");
    assert_eq!(hex(&sha1(b"")), "da39a3ee5e6b4b0d3255bfef95601890afd80709");
    assert_eq!(
        hex(&sha1(b"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")),
        "84983e441c3bd26ebaae4aa1f95129e5e54670f1"
    );
    // Python: uuid.uuid5(uuid.NAMESPACE_DNS, "python.org")
    let dns = [
        0x6b, 0xa7, 0xb8, 0x10, 0x9d, 0xad, 0x11, 0xd1, 0x80, 0xb4, 0x00, 0xc0, 0x4f, 0xd4, 0x30, 0xc8,
    ];
    assert_eq!(uuid_v5(&dns, b"python.org"), "886313e1-3b8a-5372-9b90-0c9aee199e5d");
}

#[test]
fn guid_is_a_uuid_of_the_description_and_follows_its_content() {
    let a = M::info().guid();
    assert_eq!(a.len(), 38, "{a}");
    assert!(
        a.starts_with('{') && a.ends_with('}') && a.as_bytes()[15] == b'5',
        "{a}"
    );
    assert_eq!(a, M::info().guid(), "computed once and kept");
    let other = ModelInfo {
        description: "another description",
        ..clone_info(M::info())
    };
    assert_ne!(other.guid(), a);
    assert_eq!(clone_info(M::info()).guid(), a, "the same content gives the same GUID");
}

#[test]
fn model_structure_lists_declared_dependencies() {
    use super::model::{DependencyKind, OutputDependencies};
    static DEPS: [OutputDependencies; 1] = [OutputDependencies {
        output: 2,
        step: &[(1, DependencyKind::Constant)],
        initial: Some(&[(11, DependencyKind::Dependent), (1, DependencyKind::Dependent)]),
    }];
    let info = ModelInfo {
        dependencies: &DEPS,
        ..clone_info(M::info())
    };
    let xml = try_model_description_xml(&info).unwrap();
    let index = |vr: u32| {
        M::info()
            .variables
            .iter()
            .position(|v| v.value_reference == vr)
            .unwrap()
            + 1
    };
    let (u, y0) = (index(1), index(11));
    assert!(
        xml.contains(&format!(
            r#"<Outputs>
      <Unknown index="{}" dependencies="{u}" dependenciesKind="constant"/>"#,
            index(2)
        )),
        "{xml}"
    );
    let (first, second) = if u < y0 { (u, y0) } else { (y0, u) };
    assert!(xml.contains(&format!(
        r#"<InitialUnknowns>
      <Unknown index="{}" dependencies="{first} {second}" dependenciesKind="dependent dependent"/>"#,
        index(2)
    )));
    // A dependency of an output on an output is refused.
    static BAD: [OutputDependencies; 1] = [OutputDependencies {
        output: 2,
        step: &[(2, DependencyKind::Dependent)],
        initial: None,
    }];
    let info = ModelInfo {
        dependencies: &BAD,
        ..clone_info(M::info())
    };
    assert!(validate_model_info(&info)
        .unwrap_err()
        .iter()
        .any(|p| p.contains("is not one of [Input]")));
}

#[test]
fn model_description_rejects_a_broken_table() {
    use super::model::Variable;
    static DUP: [Variable; 3] = [
        DUMMY_VARIABLES[0],
        DUMMY_VARIABLES[1],
        Variable {
            name: "u2",
            ..DUMMY_VARIABLES[0]
        },
    ];
    let info = ModelInfo {
        variables: &DUP,
        ..clone_info(M::info())
    };
    let problems = validate_model_info(&info).unwrap_err();
    assert!(
        problems.iter().any(|p| p.contains("duplicate value reference 1")),
        "{problems:?}"
    );
    static DUPNAME: [Variable; 2] = [
        DUMMY_VARIABLES[0],
        Variable {
            value_reference: 77,
            ..DUMMY_VARIABLES[0]
        },
    ];
    let info = ModelInfo {
        variables: &DUPNAME,
        ..clone_info(M::info())
    };
    assert!(validate_model_info(&info)
        .unwrap_err()
        .iter()
        .any(|p| p.contains("duplicate variable name")));
    let r = std::panic::catch_unwind(|| {
        super::model_description::model_description_xml(&ModelInfo {
            variables: &DUPNAME,
            ..clone_info(M::info())
        })
    });
    assert!(r.is_err());
}

#[test]
fn doubles_round_trip_as_xs_double() {
    for x in [
        652925.0,
        0.1,
        1e-7,
        -4.75e-8,
        1e300,
        5e-324,
        0.0,
        -0.0,
        293.15,
        1.0 / 3.0,
    ] {
        let s = format_double(x);
        assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        assert!(!s.contains("inf") && !s.contains('+'), "{s}");
    }
    assert_eq!(format_double(652925.0), "652925.0");
    assert_eq!(format_double(f64::INFINITY), "INF");
    assert_eq!(format_double(f64::NEG_INFINITY), "-INF");
}
