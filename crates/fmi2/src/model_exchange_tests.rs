//! The layer's Model Exchange: the legality table's rows, the interface in the messages,
//! instantiation, FMU states across interfaces, and the model description's elements.

use std::ffi::CString;
use std::ptr::null;

use super::api::{self, illegal_call_message};
use super::instance::Instance;
use super::model::{
    Causality, CoSimModel, ContinuousState, ModelExchangeInfo, ModelInfo, VarType, Variability, Variable,
};
use super::model_description::{try_model_description_xml, validate_model_info};
use super::state::{Function, Interface, State};
use super::testing::*;
use super::types::*;

type M = DummyModel;

const ME_FUNCTIONS: [Function; 10] = [
    Function::EnterEventMode,
    Function::NewDiscreteStates,
    Function::EnterContinuousTimeMode,
    Function::CompletedIntegratorStep,
    Function::SetTime,
    Function::SetContinuousStates,
    Function::GetDerivatives,
    Function::GetEventIndicators,
    Function::GetContinuousStates,
    Function::GetNominalsOfContinuousStates,
];

#[test]
fn the_model_exchange_rows_are_those_of_the_fmi_2_state_machine() {
    use Function::*;
    use State::*;
    let legal = |f: Function| -> Vec<State> { State::ALL.into_iter().filter(|&s| f.allowed_in(s)).collect() };
    assert_eq!(legal(SetTime), vec![EventMode, ContinuousTimeMode]);
    assert_eq!(legal(EnterEventMode), vec![EventMode, ContinuousTimeMode]);
    assert_eq!(legal(NewDiscreteStates), vec![EventMode]);
    assert_eq!(legal(EnterContinuousTimeMode), vec![EventMode]);
    assert_eq!(legal(SetContinuousStates), vec![ContinuousTimeMode]);
    assert_eq!(legal(CompletedIntegratorStep), vec![ContinuousTimeMode]);
    for f in [GetDerivatives, GetEventIndicators, GetContinuousStates] {
        assert_eq!(
            legal(f),
            vec![InitializationMode, Terminated, Error, EventMode, ContinuousTimeMode],
            "{f:?}"
        );
    }
    assert_eq!(
        legal(GetNominalsOfContinuousStates),
        vec![Instantiated, Terminated, Error, EventMode, ContinuousTimeMode]
    );
    // Common functions in the Model Exchange states.
    for f in [
        GetReal,
        SetReal,
        Terminate,
        GetFMUstate,
        SetFMUstate,
        Reset,
        FreeInstance,
    ] {
        assert!(f.allowed_in(EventMode) && f.allowed_in(ContinuousTimeMode), "{f:?}");
    }
    assert!(!EnterInitializationMode.allowed_in(EventMode));
}

#[test]
fn every_function_of_one_interface_is_illegal_in_the_states_of_the_other() {
    for f in Function::all() {
        for s in State::ALL {
            if let (Some(wanted), Some(current)) = (f.interface(), s.interface()) {
                if wanted != current {
                    assert!(!f.allowed_in(s), "{f:?} legal in {s:?}");
                    let m = illegal_call_message(f, s);
                    assert!(
                        m.contains(&format!("is a {} function", wanted.name()))
                            && m.contains(&format!("instantiated for {}", current.name())),
                        "{m}"
                    );
                }
            }
        }
    }
    assert_eq!(
        ME_FUNCTIONS.len(),
        Function::all()
            .filter(|f| f.interface() == Some(Interface::ModelExchange))
            .count()
    );
}

#[test]
fn inputs_and_tunable_parameters_are_settable_in_event_mode_and_inputs_in_continuous_time_mode() {
    let u = DUMMY_VARIABLES.iter().find(|v| v.value_reference == VR_U).unwrap();
    let tau = DUMMY_VARIABLES.iter().find(|v| v.value_reference == VR_TAU).unwrap();
    let y0 = DUMMY_VARIABLES.iter().find(|v| v.value_reference == VR_Y0).unwrap();
    assert!(api::check_set("f", u, State::EventMode).is_ok());
    assert!(api::check_set("f", u, State::ContinuousTimeMode).is_ok());
    assert!(api::check_set("f", tau, State::EventMode).is_ok());
    let e = api::check_set("f", tau, State::ContinuousTimeMode).unwrap_err();
    assert!(e.contains("tau") && e.contains("continuousTimeMode"), "{e}");
    assert!(api::check_set("f", y0, State::EventMode).is_err());
}

#[test]
fn a_model_without_model_exchange_refuses_to_be_instantiated_for_it_with_the_reason() {
    let sink = std::cell::RefCell::new(Vec::<(fmi2Status, String)>::new());
    let guid = CString::new(M::info().guid()).unwrap();
    let cb = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: &sink as *const _ as *mut _,
    };
    let c = unsafe {
        api::instantiate::<M>(
            CString::new("me").unwrap().as_ptr(),
            fmi2ModelExchange,
            guid.as_ptr(),
            null(),
            &cb,
            fmi2False,
            fmi2False,
        )
    };
    assert!(c.is_null());
}

#[test]
fn an_fmu_state_of_one_interface_is_refused_by_an_instance_of_the_other() {
    let mut instance = Instance::new(M::instantiate(), "me", None, false);
    instance.interface = Interface::ModelExchange;
    instance.state = State::EventMode;
    let c = instance.into_component();
    unsafe {
        let snapshot =
            super::fmu_state::Snapshot::new::<M>(State::Instantiated, M::instantiate().serialize()).into_raw();
        assert_eq!(api::set_fmu_state::<M>(c, snapshot), fmi2Error);
        let inst = &*(c as *const Instance<M>);
        let e = inst.last_error.clone().unwrap();
        assert!(
            e.contains("Co-Simulation instance (state instantiated); this instance is for Model Exchange"),
            "{e}"
        );
        assert_eq!(inst.state, State::EventMode);
        let mut s = snapshot;
        assert_eq!(api::free_fmu_state::<M>(c, &mut s), fmi2OK);
        assert_eq!(api::free_instance::<M>(c), fmi2OK);
    }
}

const fn real(name: &'static str, vr: u32, causality: Causality, variability: Variability) -> Variable {
    Variable {
        name,
        value_reference: vr,
        var_type: VarType::Real,
        causality,
        variability,
        unit: None,
        start: 0.0,
        min: None,
        max: None,
        description: "",
    }
}

static LAG_VARIABLES: [Variable; 4] = [
    real("u", 1, Causality::Input, Variability::Continuous),
    real("y", 2, Causality::Output, Variability::Continuous),
    real("der(y)", 3, Causality::Local, Variability::Continuous),
    real("tau", 4, Causality::Parameter, Variability::Fixed),
];

static LAG_ME: ModelExchangeInfo = ModelExchangeInfo {
    states: &[ContinuousState {
        state: 2,
        derivative: 3,
    }],
    event_indicators: 2,
    needs_completed_integrator_step: false,
};

#[test]
fn the_model_description_of_a_model_with_model_exchange_has_its_elements_in_the_schemas_order() {
    let info = ModelInfo {
        variables: &LAG_VARIABLES,
        model_exchange: Some(&LAG_ME),
        units: &[],
        ..clone_info(M::info())
    };
    let xml = try_model_description_xml(&info).unwrap();
    assert!(xml.contains(r#"numberOfEventIndicators="2""#));
    let me = xml.find("<ModelExchange modelIdentifier=").unwrap();
    let cs = xml.find("<CoSimulation modelIdentifier=").unwrap();
    assert!(me < cs);
    assert!(xml.contains(r#"<Real derivative="2"/>"#), "{xml}");
    let outputs = xml.find("<Outputs>").unwrap();
    let derivatives = xml.find("<Derivatives>").unwrap();
    let initial = xml.find("<InitialUnknowns>").unwrap();
    assert!(outputs < derivatives && derivatives < initial, "{xml}");
    assert!(xml[derivatives..initial].contains(r#"<Unknown index="3"/>"#));
    // the state and its derivative are initial unknowns
    assert!(
        xml[initial..].contains(r#"<Unknown index="2""#)
            && xml[initial..]
                .contains(r#"<Unknown index="3" dependencies="1 4" dependenciesKind="dependent dependent"/>"#)
    );
    // without Model Exchange: none of it, and no event indicators
    let cs_only = try_model_description_xml(M::info()).unwrap();
    assert!(!cs_only.contains("<ModelExchange") && !cs_only.contains("<Derivatives>"));
    assert!(cs_only.contains(r#"numberOfEventIndicators="0""#));
}

#[test]
fn a_model_that_updates_a_memory_after_each_step_asks_for_the_completed_integrator_step() {
    static STEPPED: ModelExchangeInfo = ModelExchangeInfo {
        needs_completed_integrator_step: true,
        ..LAG_ME
    };
    let with = |me: &'static ModelExchangeInfo| {
        try_model_description_xml(&ModelInfo {
            variables: &LAG_VARIABLES,
            model_exchange: Some(me),
            units: &[],
            ..clone_info(M::info())
        })
        .unwrap()
    };
    assert!(with(&LAG_ME).contains(r#"completedIntegratorStepNotNeeded="true""#));
    assert!(with(&STEPPED).contains(r#"completedIntegratorStepNotNeeded="false""#));
}

#[test]
fn a_state_that_is_not_a_continuous_real_output_or_local_is_a_problem_of_the_table() {
    static BAD: ModelExchangeInfo = ModelExchangeInfo {
        states: &[
            ContinuousState {
                state: 4,
                derivative: 3,
            },
            ContinuousState {
                state: 2,
                derivative: 99,
            },
        ],
        event_indicators: 0,
        needs_completed_integrator_step: false,
    };
    let info = ModelInfo {
        variables: &LAG_VARIABLES,
        model_exchange: Some(&BAD),
        units: &[],
        ..clone_info(M::info())
    };
    let problems = validate_model_info(&info).unwrap_err();
    assert!(problems.iter().any(|p| p.contains("value reference 4")), "{problems:?}");
    assert!(
        problems.iter().any(|p| p.contains("value reference 99")),
        "{problems:?}"
    );
}

#[test]
fn a_function_of_the_other_interface_is_illegal_also_in_the_states_both_interfaces_share() {
    let mut instance = Instance::new(M::instantiate(), "cs", None, false);
    instance.state = State::InitializationMode;
    let c = instance.into_component();
    unsafe {
        let mut dx = [0.0; 1];
        assert_eq!(
            super::model_exchange::get_derivatives::<M>(c, dx.as_mut_ptr(), 0),
            fmi2Error
        );
        let inst = &mut *(c as *mut Instance<M>);
        let e = inst.last_error.take().unwrap();
        assert_eq!(
            e,
            "fmi2GetDerivatives: illegal call in state initializationMode (fmi2GetDerivatives is a Model Exchange function; this instance was instantiated for Co-Simulation)"
        );
        inst.interface = Interface::ModelExchange;
        assert_eq!(api::set_real_input_derivatives::<M>(c, &VR_U, 1, &1, &0.5), fmi2Error);
        let e = (*(c as *mut Instance<M>)).last_error.take().unwrap();
        assert!(
            e.contains("is a Co-Simulation function; this instance was instantiated for Model Exchange"),
            "{e}"
        );
        assert_eq!(
            super::model_exchange::get_derivatives::<M>(c, dx.as_mut_ptr(), 0),
            fmi2OK
        );
        assert_eq!(api::free_instance::<M>(c), fmi2OK);
    }
}

#[test]
fn the_interface_of_an_fmu_state_survives_its_bytes_and_a_state_of_the_other_interface_is_refused() {
    use super::fmu_state::{Snapshot, MODEL_EXCHANGE_BIT};
    let me = Snapshot::new::<M>(State::ContinuousTimeMode, M::instantiate().serialize())
        .of_interface(Interface::ModelExchange);
    let bytes = me.to_bytes();
    let back = Snapshot::from_bytes::<M>(&bytes).unwrap();
    assert_eq!(
        (back.state, back.interface),
        (State::ContinuousTimeMode, Interface::ModelExchange)
    );
    // a Co-Simulation state's bytes are those of the layer before Model Exchange
    let cs = Snapshot::new::<M>(State::StepComplete, M::instantiate().serialize()).to_bytes();
    let at = 16 + u32::from_le_bytes(cs[12..16].try_into().unwrap()) as usize;
    assert_eq!(cs[at], State::StepComplete.code());
    // eventMode without the bit: a Co-Simulation instance cannot be in it
    let mut crafted = cs.clone();
    crafted[at] = State::EventMode.code();
    let n = crafted.len();
    let crc = super::fmu_state::crc32(&crafted[..n - 4]);
    crafted[n - 4..].copy_from_slice(&crc.to_le_bytes());
    let e = Snapshot::from_bytes::<M>(&crafted).err().unwrap();
    assert!(e.contains("state eventMode of a Co-Simulation instance"), "{e}");
    assert_eq!(bytes[at] & MODEL_EXCHANGE_BIT, MODEL_EXCHANGE_BIT);
}
