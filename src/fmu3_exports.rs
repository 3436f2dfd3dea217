//! The exported FMI 3.0 symbols, Co-Simulation and Model Exchange, beside the FMI 2.0 ones of
//! [`crate::fmu_exports`] in the same library (the names differ). Each is a thin forwarder to
//! the generic implementation in [`fmi3::api`] or [`fmi3::model_exchange`], instantiated for
//! [`crate::ExportedModel`]. Written out literally (no macros) so that cbindgen can read this
//! file (`build.rs` writes `target/include/jetpipe_fmi3.h`).
#![allow(non_snake_case, clippy::missing_safety_doc)]

use crate::ExportedModel;
use fmi3::state::Function;
use fmi3::types::{
    fmi3Binary, fmi3Boolean, fmi3Byte, fmi3Clock, fmi3ClockUpdateCallback, fmi3DependencyKind, fmi3FMUState,
    fmi3Float32, fmi3Float64, fmi3Instance, fmi3InstanceEnvironment, fmi3Int16, fmi3Int32, fmi3Int64, fmi3Int8,
    fmi3IntermediateUpdateCallback, fmi3IntervalQualifier, fmi3LockPreemptionCallback, fmi3LogMessageCallback,
    fmi3Status, fmi3String, fmi3UInt16, fmi3UInt32, fmi3UInt64, fmi3UInt8, fmi3UnlockPreemptionCallback,
    fmi3ValueReference,
};
use fmi3::{api, model_exchange as me};
use std::os::raw::c_char;

#[no_mangle]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    api::get_version()
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    api::set_debug_logging::<ExportedModel>(instance, loggingOn, nCategories, categories)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    api::instantiate_model_exchange::<ExportedModel>(
        instanceName,
        instantiationToken,
        resourcePath,
        visible,
        loggingOn,
        instanceEnvironment,
        logMessage,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    earlyReturnAllowed: fmi3Boolean,
    requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    api::instantiate_co_simulation::<ExportedModel>(
        instanceName,
        instantiationToken,
        resourcePath,
        visible,
        loggingOn,
        eventModeUsed,
        earlyReturnAllowed,
        requiredIntermediateVariables,
        nRequiredIntermediateVariables,
        instanceEnvironment,
        logMessage,
        intermediateUpdate,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _instanceName: fmi3String,
    _instantiationToken: fmi3String,
    _resourcePath: fmi3String,
    _visible: fmi3Boolean,
    _loggingOn: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _clockUpdate: fmi3ClockUpdateCallback,
    _lockPreemption: fmi3LockPreemptionCallback,
    _unlockPreemption: fmi3UnlockPreemptionCallback,
) -> fmi3Instance {
    api::instantiate_scheduled_execution(instanceEnvironment, logMessage)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    api::free_instance::<ExportedModel>(instance);
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    toleranceDefined: fmi3Boolean,
    tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    api::enter_initialization_mode::<ExportedModel>(
        instance,
        toleranceDefined,
        tolerance,
        startTime,
        stopTimeDefined,
        stopTime,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    api::exit_initialization_mode::<ExportedModel>(instance)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterEventMode(instance: fmi3Instance) -> fmi3Status {
    me::enter_event_mode::<ExportedModel>(instance)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    api::terminate::<ExportedModel>(instance)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    api::reset::<ExportedModel>(instance)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3Float32,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetFloat32,
        "Float32",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3Float32,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetFloat32,
        "Float32",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    api::get_float64::<ExportedModel>(instance, valueReferences, nValueReferences, values, nValues)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFloat64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    api::set_float64::<ExportedModel>(instance, valueReferences, nValueReferences, values, nValues)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3Int8,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::GetInt8, "Int8", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3Int8,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::SetInt8, "Int8", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3UInt8,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::GetUInt8, "UInt8", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt8(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3UInt8,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::SetUInt8, "UInt8", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3Int16,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::GetInt16, "Int16", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3Int16,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::SetInt16, "Int16", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3UInt16,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetUInt16,
        "UInt16",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt16(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3UInt16,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetUInt16,
        "UInt16",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    api::get_int32::<ExportedModel>(instance, valueReferences, nValueReferences, values, nValues)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Int32,
    nValues: usize,
) -> fmi3Status {
    api::set_int32::<ExportedModel>(instance, valueReferences, nValueReferences, values, nValues)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3UInt32,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetUInt32,
        "UInt32",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt32(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3UInt32,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetUInt32,
        "UInt32",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3Int64,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::GetInt64, "Int64", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3Int64,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::SetInt64, "Int64", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3UInt64,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetUInt64,
        "UInt64",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetUInt64(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3UInt64,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetUInt64,
        "UInt64",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    api::get_boolean::<ExportedModel>(instance, valueReferences, nValueReferences, values, nValues)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBoolean(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3Boolean,
    nValues: usize,
) -> fmi3Status {
    api::set_boolean::<ExportedModel>(instance, valueReferences, nValueReferences, values, nValues)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3String,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetString,
        "String",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetString(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3String,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetString,
        "String",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *mut usize,
    _values: *mut fmi3Binary,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetBinary,
        "Binary",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetBinary(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *const usize,
    _values: *const fmi3Binary,
    _nValues: usize,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetBinary,
        "Binary",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *mut fmi3Clock,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::GetClock, "Clock", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetClock(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _values: *const fmi3Clock,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(instance, Function::SetClock, "Clock", valueReferences, nValueReferences)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfVariableDependencies(
    instance: fmi3Instance,
    _valueReference: fmi3ValueReference,
    _nDependencies: *mut usize,
) -> fmi3Status {
    api::unsupported::<ExportedModel>(instance, Function::GetNumberOfVariableDependencies, "not supported (providesPerElementDependencies=\"false\": the model description's dependencies are the dependencies)")
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetVariableDependencies(
    instance: fmi3Instance,
    _dependent: fmi3ValueReference,
    _elementIndicesOfDependent: *mut usize,
    _independents: *mut fmi3ValueReference,
    _elementIndicesOfIndependents: *mut usize,
    _dependencyKinds: *mut fmi3DependencyKind,
    _nDependencies: usize,
) -> fmi3Status {
    api::unsupported::<ExportedModel>(instance, Function::GetVariableDependencies, "not supported (providesPerElementDependencies=\"false\": the model description's dependencies are the dependencies)")
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetFMUState(instance: fmi3Instance, FMUState: *mut fmi3FMUState) -> fmi3Status {
    api::get_fmu_state::<ExportedModel>(instance, FMUState)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetFMUState(instance: fmi3Instance, FMUState: fmi3FMUState) -> fmi3Status {
    api::set_fmu_state::<ExportedModel>(instance, FMUState)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3FreeFMUState(instance: fmi3Instance, FMUState: *mut fmi3FMUState) -> fmi3Status {
    api::free_fmu_state::<ExportedModel>(instance, FMUState)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    api::serialized_fmu_state_size::<ExportedModel>(instance, FMUState, size)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    api::serialize_fmu_state::<ExportedModel>(instance, FMUState, serializedState, size)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    api::deserialize_fmu_state::<ExportedModel>(instance, serializedState, size, FMUState)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    _unknowns: *const fmi3ValueReference,
    _nUnknowns: usize,
    _knowns: *const fmi3ValueReference,
    _nKnowns: usize,
    _seed: *const fmi3Float64,
    _nSeed: usize,
    _sensitivity: *mut fmi3Float64,
    _nSensitivity: usize,
) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::GetDirectionalDerivative,
        "not supported (providesDirectionalDerivatives=\"false\")",
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    instance: fmi3Instance,
    _unknowns: *const fmi3ValueReference,
    _nUnknowns: usize,
    _knowns: *const fmi3ValueReference,
    _nKnowns: usize,
    _seed: *const fmi3Float64,
    _nSeed: usize,
    _sensitivity: *mut fmi3Float64,
    _nSensitivity: usize,
) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::GetAdjointDerivative,
        "not supported (providesAdjointDerivatives=\"false\")",
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::EnterConfigurationMode,
        "this FMU has no structural parameters and so no configuration mode",
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::ExitConfigurationMode,
        "this FMU has no configuration mode",
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _intervals: *mut fmi3Float64,
    _qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetIntervalDecimal,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetIntervalFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _counters: *mut fmi3UInt64,
    _resolutions: *mut fmi3UInt64,
    _qualifiers: *mut fmi3IntervalQualifier,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetIntervalFraction,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _shifts: *mut fmi3Float64,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetShiftDecimal,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetShiftFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _counters: *mut fmi3UInt64,
    _resolutions: *mut fmi3UInt64,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::GetShiftFraction,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _intervals: *const fmi3Float64,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetIntervalDecimal,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetIntervalFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _counters: *const fmi3UInt64,
    _resolutions: *const fmi3UInt64,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetIntervalFraction,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftDecimal(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _shifts: *const fmi3Float64,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetShiftDecimal,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetShiftFraction(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _counters: *const fmi3UInt64,
    _resolutions: *const fmi3UInt64,
) -> fmi3Status {
    api::no_variables_of_type::<ExportedModel>(
        instance,
        Function::SetShiftFraction,
        "Clock",
        valueReferences,
        nValueReferences,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EvaluateDiscreteStates(instance: fmi3Instance) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::EvaluateDiscreteStates,
        "not supported (providesEvaluateDiscreteStates=\"false\"; the model has no discrete states)",
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3UpdateDiscreteStates(
    instance: fmi3Instance,
    discreteStatesNeedUpdate: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    nominalsOfContinuousStatesChanged: *mut fmi3Boolean,
    valuesOfContinuousStatesChanged: *mut fmi3Boolean,
    nextEventTimeDefined: *mut fmi3Boolean,
    nextEventTime: *mut fmi3Float64,
) -> fmi3Status {
    api::update_discrete_states::<ExportedModel>(
        instance,
        discreteStatesNeedUpdate,
        terminateSimulation,
        nominalsOfContinuousStatesChanged,
        valuesOfContinuousStatesChanged,
        nextEventTimeDefined,
        nextEventTime,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterContinuousTimeMode(instance: fmi3Instance) -> fmi3Status {
    me::enter_continuous_time_mode::<ExportedModel>(instance)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3CompletedIntegratorStep(
    instance: fmi3Instance,
    noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    enterEventMode: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
) -> fmi3Status {
    me::completed_integrator_step::<ExportedModel>(
        instance,
        noSetFMUStatePriorToCurrentPoint,
        enterEventMode,
        terminateSimulation,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetTime(instance: fmi3Instance, time: fmi3Float64) -> fmi3Status {
    me::set_time::<ExportedModel>(instance, time)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3SetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *const fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me::set_continuous_states::<ExportedModel>(instance, continuousStates, nContinuousStates)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStateDerivatives(
    instance: fmi3Instance,
    derivatives: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me::get_continuous_state_derivatives::<ExportedModel>(instance, derivatives, nContinuousStates)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetEventIndicators(
    instance: fmi3Instance,
    eventIndicators: *mut fmi3Float64,
    nEventIndicators: usize,
) -> fmi3Status {
    me::get_event_indicators::<ExportedModel>(instance, eventIndicators, nEventIndicators)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetContinuousStates(
    instance: fmi3Instance,
    continuousStates: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me::get_continuous_states::<ExportedModel>(instance, continuousStates, nContinuousStates)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNominalsOfContinuousStates(
    instance: fmi3Instance,
    nominals: *mut fmi3Float64,
    nContinuousStates: usize,
) -> fmi3Status {
    me::get_nominals_of_continuous_states::<ExportedModel>(instance, nominals, nContinuousStates)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfEventIndicators(
    instance: fmi3Instance,
    nEventIndicators: *mut usize,
) -> fmi3Status {
    me::get_number_of_event_indicators::<ExportedModel>(instance, nEventIndicators)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetNumberOfContinuousStates(
    instance: fmi3Instance,
    nContinuousStates: *mut usize,
) -> fmi3Status {
    me::get_number_of_continuous_states::<ExportedModel>(instance, nContinuousStates)
}

#[no_mangle]
pub unsafe extern "C" fn fmi3EnterStepMode(instance: fmi3Instance) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::EnterStepMode,
        "this FMU's Co-Simulation has no event mode to leave",
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    _valueReferences: *const fmi3ValueReference,
    _nValueReferences: usize,
    _orders: *const fmi3Int32,
    _values: *mut fmi3Float64,
    _nValues: usize,
) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::GetOutputDerivatives,
        "not supported (maxOutputDerivativeOrder=\"0\")",
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    api::do_step::<ExportedModel>(
        instance,
        currentCommunicationPoint,
        communicationStepSize,
        noSetFMUStatePriorToCurrentPoint,
        eventHandlingNeeded,
        terminateSimulation,
        earlyReturn,
        lastSuccessfulTime,
    )
}

#[no_mangle]
pub unsafe extern "C" fn fmi3ActivateModelPartition(
    instance: fmi3Instance,
    _clockReference: fmi3ValueReference,
    _activationTime: fmi3Float64,
) -> fmi3Status {
    api::unsupported::<ExportedModel>(
        instance,
        Function::ActivateModelPartition,
        "this FMU has no Scheduled Execution",
    )
}
