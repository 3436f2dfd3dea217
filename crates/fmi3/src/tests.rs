//! Unit tests of the FMI 3.0 layer, through `api` with the layer's dummy model (Co-Simulation
//! only) and its Model Exchange form.

use std::ffi::{CStr, CString};
use std::os::raw::{c_char, c_int, c_void};
use std::ptr::{null, null_mut};
use std::sync::Mutex;

use fmi2::model::ModelInfo;
use fmi2::state::{Call, Interface, State, Version};
use fmi2::testing::*;

use crate::api;
use crate::model_description::{model_description_xml, time_value_reference};
use crate::state::{Function, TABLE};
use crate::types::*;

type M = DummyModel;

#[derive(Default)]
struct Sink(Mutex<Vec<(c_int, String, String)>>);

unsafe extern "C" fn log(env: *mut c_void, status: c_int, category: *const c_char, message: *const c_char) {
    let sink = &*(env as *const Sink);
    let s = |p: *const c_char| CStr::from_ptr(p).to_string_lossy().into_owned();
    sink.0.lock().unwrap().push((status, s(category), s(message)));
}

impl Sink {
    fn last(&self) -> String {
        self.0.lock().unwrap().last().map(|m| m.2.clone()).unwrap_or_default()
    }
}

unsafe fn cs(sink: &Sink) -> fmi3Instance {
    let name = CString::new("dummy").unwrap();
    let token = CString::new(api::instantiation_token::<M>()).unwrap();
    api::instantiate_co_simulation::<M>(
        name.as_ptr(),
        token.as_ptr(),
        null(),
        0,
        0,
        0,
        0,
        null(),
        0,
        sink as *const Sink as *mut c_void,
        Some(log),
        None,
    )
}

#[test]
fn a_co_simulation_instance_steps_through_the_fmi3_calls_and_logs_through_the_fmi3_callback() {
    let sink = Sink::default();
    unsafe {
        let c = cs(&sink);
        assert!(!c.is_null());
        let u = [VR_U];
        assert_eq!(api::set_float64::<M>(c, u.as_ptr(), 1, [1.0].as_ptr(), 1), fmi3OK);
        assert_eq!(api::enter_initialization_mode::<M>(c, 1, 1e-6, 0.0, 0, 0.0), fmi3OK);
        assert_eq!(api::exit_initialization_mode::<M>(c), fmi3OK);
        let (mut e, mut t, mut r, mut last) = (9u8, 9u8, 9u8, 0.0);
        assert_eq!(
            api::do_step::<M>(c, 0.0, 0.5, 1, &mut e, &mut t, &mut r, &mut last),
            fmi3OK
        );
        assert_eq!((e, t, r, last), (0, 0, 0, 0.5));
        let mut y = [0.0];
        assert_eq!(api::get_float64::<M>(c, [VR_Y].as_ptr(), 1, y.as_mut_ptr(), 1), fmi3OK);
        assert!(y[0] > 0.3 && y[0] < 0.5, "{}", y[0]); // 1 - exp(-0.5) = 0.39
        let time = [time_value_reference(&DUMMY_INFO)];
        assert_eq!(api::get_float64::<M>(c, time.as_ptr(), 1, y.as_mut_ptr(), 1), fmi3OK);
        assert_eq!(y[0], 0.5);
        // a wrong time: an error that names the call, through fmi3LogMessageCallback
        assert_eq!(
            api::do_step::<M>(c, 0.0, 0.5, 1, &mut e, &mut t, &mut r, &mut last),
            fmi3Error
        );
        let (status, category, message) = sink.0.lock().unwrap().last().cloned().unwrap();
        assert_eq!((status, category.as_str()), (fmi3Error, "logStatusError"));
        assert!(
            message.starts_with("fmi3DoStep: currentCommunicationPoint"),
            "{message}"
        );
        api::free_instance::<M>(c);
    }
}

#[test]
fn scalar_getters_and_setters_refuse_a_count_of_values_other_than_of_references() {
    let sink = Sink::default();
    unsafe {
        let c = cs(&sink);
        let mut y = [0.0; 2];
        assert_eq!(
            api::get_float64::<M>(c, [VR_U].as_ptr(), 1, y.as_mut_ptr(), 2),
            fmi3Error
        );
        assert!(sink.last().contains("nValues = 2"), "{}", sink.last());
        let mut b = [7u8];
        assert_eq!(
            api::get_boolean::<M>(c, [VR_FROZEN].as_ptr(), 1, b.as_mut_ptr(), 1),
            fmi3OK
        );
        assert_eq!(b[0], 0);
        let mut i = [0i32];
        assert_eq!(
            api::get_int32::<M>(c, [VR_N_SUB].as_ptr(), 1, i.as_mut_ptr(), 1),
            fmi3OK
        );
        assert_eq!(i[0], 4);
        assert_eq!(api::get_int32::<M>(c, [VR_U].as_ptr(), 1, i.as_mut_ptr(), 1), fmi3Error);
        assert!(
            sink.last().contains("is a Float64 variable, not Int32"),
            "{}",
            sink.last()
        );
        assert_eq!(
            api::no_variables_of_type::<M>(c, Function::GetUInt16, "UInt16", [VR_TAU].as_ptr(), 1),
            fmi3Error
        );
        assert!(
            sink.last().contains("(tau) is a Float64 variable, not UInt16"),
            "{}",
            sink.last()
        );
        assert_eq!(
            api::no_variables_of_type::<M>(c, Function::GetUInt16, "UInt16", null(), 0),
            fmi3OK
        );
        api::free_instance::<M>(c);
    }
}

#[test]
fn an_instance_of_one_version_is_refused_by_the_calls_of_the_other() {
    let sink = Sink::default();
    unsafe {
        let c = cs(&sink);
        assert_eq!(fmi2::api::terminate::<M>(c), fmi2::types::fmi2Error);
        assert!(
            sink.last()
                .starts_with("fmi2Terminate: the instance was made by fmi3Instantiate"),
            "{}",
            sink.last()
        );
        let two = fmi2::api::instantiate::<M>(
            CString::new("two").unwrap().as_ptr(),
            fmi2::types::fmi2CoSimulation,
            CString::new(DUMMY_INFO.guid()).unwrap().as_ptr(),
            null(),
            &fmi2::types::fmi2CallbackFunctions {
                logger: None,
                allocateMemory: None,
                freeMemory: None,
                stepFinished: None,
                componentEnvironment: null_mut(),
            },
            0,
            0,
        );
        assert!(!two.is_null());
        assert_eq!(api::terminate::<M>(two), fmi3Error);
        let inst = &*(two as *const fmi2::instance::Instance<M>);
        assert!(inst
            .last_error
            .as_deref()
            .unwrap_or("")
            .starts_with("fmi3Terminate: the instance was made by fmi2"));
        // an FMU state of the FMI 3.0 instance is refused by the FMI 2.0 one
        let mut s: fmi3FMUState = null_mut();
        assert_eq!(api::get_fmu_state::<M>(c, &mut s), fmi3OK);
        assert_eq!(fmi2::api::set_fmu_state::<M>(two, s), fmi2::types::fmi2Error);
        let message = inst.last_error.clone().unwrap_or_default();
        assert!(message.contains("Co-Simulation instance of FMI 3.0"), "{message}");
        assert_eq!(api::free_fmu_state::<M>(c, &mut s), fmi3OK);
        fmi2::api::free_instance::<M>(two);
        api::free_instance::<M>(c);
    }
}

#[test]
fn a_model_without_model_exchange_gives_no_model_exchange_instance_and_says_why() {
    let sink = Sink::default();
    unsafe {
        let name = CString::new("me").unwrap();
        let token = CString::new(api::instantiation_token::<M>()).unwrap();
        let env = &sink as *const Sink as *mut c_void;
        let c = api::instantiate_model_exchange::<M>(name.as_ptr(), token.as_ptr(), null(), 0, 0, env, Some(log));
        assert!(c.is_null());
        assert!(sink.last().contains("no Model Exchange interface"), "{}", sink.last());
        let bad = CString::new("{not the token}").unwrap();
        let c = api::instantiate_model_exchange::<M>(name.as_ptr(), bad.as_ptr(), null(), 0, 0, env, Some(log));
        assert!(c.is_null());
    }
}

#[test]
fn every_illegal_call_message_names_the_call_and_the_fmi3_state() {
    for &(f, name, _) in TABLE {
        for s in State::ALL {
            for i in [Interface::CoSimulation, Interface::ModelExchange] {
                if !Call::legal(f, s, i) {
                    let m = Call::illegal_call_message(f, s, i);
                    let wanted = format!("{name}: illegal call in state {}", s.name_in(Version::Fmi3));
                    assert!(m.starts_with(&wanted), "{m}");
                    assert!(!m.contains("stepComplete") && !m.contains("stepFailed"), "{m}");
                }
            }
        }
    }
}

fn with_model_exchange() -> ModelInfo {
    static ME: fmi2::model::ModelExchangeInfo = fmi2::model::ModelExchangeInfo {
        states: &[],
        event_indicators: 2,
        needs_completed_integrator_step: false,
    };
    let mut info = clone_info(&DUMMY_INFO);
    info.model_exchange = Some(&ME);
    info
}

#[test]
fn the_description_has_an_independent_time_and_the_event_indicators_as_variables() {
    let xml = model_description_xml(&DUMMY_INFO);
    let t = time_value_reference(&DUMMY_INFO);
    assert!(
        xml.contains(&format!(r#"name="time" valueReference="{t}" causality="independent""#)),
        "{xml}"
    );
    assert!(xml.contains(&format!(r#"instantiationToken="{}""#, DUMMY_INFO.guid())));
    assert!(!xml.contains("<ModelExchange") && !xml.contains("<EventIndicator"));
    assert!(xml.contains(r#"<Int32 name="n_sub""#) && xml.contains(r#"<Boolean name="frozen""#));
    assert_eq!(xml.matches("<Output ").count(), 1);
    let info = with_model_exchange();
    let xml = model_description_xml(&info);
    assert!(xml.contains("<ModelExchange"));
    assert!(xml.contains(r#"needsCompletedIntegratorStep="false""#));
    for k in 1..=2 {
        let vr = t + k;
        assert!(
            xml.contains(&format!(r#"name="event_indicator_{k}" valueReference="{vr}""#)),
            "{xml}"
        );
        assert!(
            xml.contains(&format!(r#"<EventIndicator valueReference="{vr}"/>"#)),
            "{xml}"
        );
    }
}

#[test]
fn a_model_that_updates_a_memory_after_each_step_says_it_needs_the_completed_integrator_step() {
    static STEPPED: fmi2::model::ModelExchangeInfo = fmi2::model::ModelExchangeInfo {
        states: &[],
        event_indicators: 1,
        needs_completed_integrator_step: true,
    };
    let mut info = clone_info(&DUMMY_INFO);
    info.model_exchange = Some(&STEPPED);
    assert!(model_description_xml(&info).contains(r#"needsCompletedIntegratorStep="true""#));
}
