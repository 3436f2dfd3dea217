//! The exported FMI 2.0 symbols, Co-Simulation and Model Exchange. Each is a thin forwarder
//! to the generic implementation in [`fmi2::api`] or [`fmi2::model_exchange`], instantiated
//! for [`crate::ExportedModel`].
//! Written out literally (no macros) so that cbindgen can read this file.
#![allow(non_snake_case, clippy::missing_safety_doc)]

use crate::ExportedModel;
use fmi2::types::{
    fmi2Boolean, fmi2Byte, fmi2CallbackFunctions, fmi2Component, fmi2EventInfo, fmi2FMUstate, fmi2Integer, fmi2Real,
    fmi2Status, fmi2StatusKind, fmi2String, fmi2Type, fmi2ValueReference,
};
use fmi2::{api, model_exchange as me};
use std::os::raw::c_char;

// ---- Common functions ----------------------------------------------------------------

#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    api::get_types_platform()
}

#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    api::get_version()
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    api::set_debug_logging::<ExportedModel>(c, loggingOn, nCategories, categories)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    api::instantiate::<ExportedModel>(
        instanceName,
        fmuType,
        fmuGUID,
        fmuResourceLocation,
        functions,
        visible,
        loggingOn,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    api::free_instance::<ExportedModel>(c);
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    api::setup_experiment::<ExportedModel>(c, toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    api::enter_initialization_mode::<ExportedModel>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    api::exit_initialization_mode::<ExportedModel>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    api::terminate::<ExportedModel>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    api::reset::<ExportedModel>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    api::get_real::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    api::get_integer::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    api::get_boolean::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    api::get_string::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    api::set_real::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    api::set_integer::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    api::set_boolean::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    api::set_string::<ExportedModel>(c, vr, nvr, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    api::get_fmu_state::<ExportedModel>(c, FMUstate)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    api::set_fmu_state::<ExportedModel>(c, FMUstate)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: fmi2Component, FMUstate: *mut fmi2FMUstate) -> fmi2Status {
    api::free_fmu_state::<ExportedModel>(c, FMUstate)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    api::serialized_fmu_state_size::<ExportedModel>(c, FMUstate, size)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    api::serialize_fmu_state::<ExportedModel>(c, FMUstate, serializedState, size)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    api::deserialize_fmu_state::<ExportedModel>(c, serializedState, size, FMUstate)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    api::get_directional_derivative::<ExportedModel>(c, vUnknown_ref, nUnknown, vKnown_ref, nKnown, dvKnown, dvUnknown)
}

// ---- Co-Simulation functions ---------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    api::set_real_input_derivatives::<ExportedModel>(c, vr, nvr, order, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    api::get_real_output_derivatives::<ExportedModel>(c, vr, nvr, order, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    api::do_step::<ExportedModel>(
        c,
        currentCommunicationPoint,
        communicationStepSize,
        noSetFMUStatePriorToCurrentPoint,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    api::cancel_step::<ExportedModel>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Status) -> fmi2Status {
    api::get_status::<ExportedModel>(c, s, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: fmi2Component, s: fmi2StatusKind, value: *mut fmi2Real) -> fmi2Status {
    api::get_real_status::<ExportedModel>(c, s, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Integer,
) -> fmi2Status {
    api::get_integer_status::<ExportedModel>(c, s, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    api::get_boolean_status::<ExportedModel>(c, s, value)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2String,
) -> fmi2Status {
    api::get_string_status::<ExportedModel>(c, s, value)
}

// ---- Model Exchange ----------------------------------------------------------------

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterEventMode(c: fmi2Component) -> fmi2Status {
    me::enter_event_mode::<ExportedModel>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2NewDiscreteStates(c: fmi2Component, fmi2eventInfo: *mut fmi2EventInfo) -> fmi2Status {
    me::new_discrete_states::<ExportedModel>(c, fmi2eventInfo)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2EnterContinuousTimeMode(c: fmi2Component) -> fmi2Status {
    me::enter_continuous_time_mode::<ExportedModel>(c)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2CompletedIntegratorStep(
    c: fmi2Component,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
    enterEventMode: *mut fmi2Boolean,
    terminateSimulation: *mut fmi2Boolean,
) -> fmi2Status {
    me::completed_integrator_step::<ExportedModel>(
        c,
        noSetFMUStatePriorToCurrentPoint,
        enterEventMode,
        terminateSimulation,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetTime(c: fmi2Component, time: fmi2Real) -> fmi2Status {
    me::set_time::<ExportedModel>(c, time)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2SetContinuousStates(c: fmi2Component, x: *const fmi2Real, nx: usize) -> fmi2Status {
    me::set_continuous_states::<ExportedModel>(c, x, nx)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetDerivatives(c: fmi2Component, derivatives: *mut fmi2Real, nx: usize) -> fmi2Status {
    me::get_derivatives::<ExportedModel>(c, derivatives, nx)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetEventIndicators(
    c: fmi2Component,
    eventIndicators: *mut fmi2Real,
    ni: usize,
) -> fmi2Status {
    me::get_event_indicators::<ExportedModel>(c, eventIndicators, ni)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetContinuousStates(c: fmi2Component, x: *mut fmi2Real, nx: usize) -> fmi2Status {
    me::get_continuous_states::<ExportedModel>(c, x, nx)
}

#[no_mangle]
pub unsafe extern "C" fn fmi2GetNominalsOfContinuousStates(
    c: fmi2Component,
    x_nominal: *mut fmi2Real,
    nx: usize,
) -> fmi2Status {
    me::get_nominals_of_continuous_states::<ExportedModel>(c, x_nominal, nx)
}
