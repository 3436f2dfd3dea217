//! [`fmi2_cosimulation_exports!`]: the exported `fmi2*` symbols of the FMI 2.0 Co-Simulation
//! layer for any [`crate::model::CoSimModel`], for the crates that put a model on the layer
//! (`fmus/` in the workspace).
//!
//! The actuator's `crates/fmu/src/fmu_exports.rs` stays literal because cbindgen reads it to
//! write the C header whose compilation against the standard `fmi2Functions.h` proves the
//! signatures. This macro must therefore emit exactly the same signatures: the test
//! `macro_signatures_are_the_literal_exports` (crates/fmu/tests/exports.rs) compares the two
//! texts, so an edit to one without the other fails.
//!
//! Invoke it once per cdylib; a second invocation, or the actuator's own symbols in the same
//! library or test (any crate that links `crates/fmu`), would give duplicate `fmi2*`
//! definitions.

/// Emit the 34 `#[no_mangle] extern "C" fn fmi2*` functions of FMI 2.0 Co-Simulation as
/// forwarders to [`crate::api`] instantiated for `$model` (a type implementing
/// [`crate::model::CoSimModel`]).
///
/// ```ignore
/// fmi2::fmi2_cosimulation_exports!(crate::fmu::TendonFmu);
/// ```
#[macro_export]
macro_rules! fmi2_cosimulation_exports {
    ($model:ty) => {
        // ---- Common functions ----------------------------------------------------------------

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub extern "C" fn fmi2GetTypesPlatform() -> *const ::std::os::raw::c_char {
            $crate::api::get_types_platform()
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub extern "C" fn fmi2GetVersion() -> *const ::std::os::raw::c_char {
            $crate::api::get_version()
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetDebugLogging(
            c: $crate::types::fmi2Component,
            loggingOn: $crate::types::fmi2Boolean,
            nCategories: usize,
            categories: *const $crate::types::fmi2String,
        ) -> $crate::types::fmi2Status {
            $crate::api::set_debug_logging::<$model>(c, loggingOn, nCategories, categories)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2Instantiate(
            instanceName: $crate::types::fmi2String,
            fmuType: $crate::types::fmi2Type,
            fmuGUID: $crate::types::fmi2String,
            fmuResourceLocation: $crate::types::fmi2String,
            functions: *const $crate::types::fmi2CallbackFunctions,
            visible: $crate::types::fmi2Boolean,
            loggingOn: $crate::types::fmi2Boolean,
        ) -> $crate::types::fmi2Component {
            $crate::api::instantiate::<$model>(
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
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2FreeInstance(c: $crate::types::fmi2Component) {
            $crate::api::free_instance::<$model>(c);
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetupExperiment(
            c: $crate::types::fmi2Component,
            toleranceDefined: $crate::types::fmi2Boolean,
            tolerance: $crate::types::fmi2Real,
            startTime: $crate::types::fmi2Real,
            stopTimeDefined: $crate::types::fmi2Boolean,
            stopTime: $crate::types::fmi2Real,
        ) -> $crate::types::fmi2Status {
            $crate::api::setup_experiment::<$model>(
                c,
                toleranceDefined,
                tolerance,
                startTime,
                stopTimeDefined,
                stopTime,
            )
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2EnterInitializationMode(
            c: $crate::types::fmi2Component,
        ) -> $crate::types::fmi2Status {
            $crate::api::enter_initialization_mode::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2ExitInitializationMode(
            c: $crate::types::fmi2Component,
        ) -> $crate::types::fmi2Status {
            $crate::api::exit_initialization_mode::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2Terminate(c: $crate::types::fmi2Component) -> $crate::types::fmi2Status {
            $crate::api::terminate::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2Reset(c: $crate::types::fmi2Component) -> $crate::types::fmi2Status {
            $crate::api::reset::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetReal(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::types::fmi2Real,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_real::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetInteger(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::types::fmi2Integer,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_integer::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetBoolean(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::types::fmi2Boolean,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_boolean::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetString(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::types::fmi2String,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_string::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetReal(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::types::fmi2Real,
        ) -> $crate::types::fmi2Status {
            $crate::api::set_real::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetInteger(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::types::fmi2Integer,
        ) -> $crate::types::fmi2Status {
            $crate::api::set_integer::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetBoolean(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::types::fmi2Boolean,
        ) -> $crate::types::fmi2Status {
            $crate::api::set_boolean::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetString(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::types::fmi2String,
        ) -> $crate::types::fmi2Status {
            $crate::api::set_string::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetFMUstate(
            c: $crate::types::fmi2Component,
            FMUstate: *mut $crate::types::fmi2FMUstate,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_fmu_state::<$model>(c, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetFMUstate(
            c: $crate::types::fmi2Component,
            FMUstate: $crate::types::fmi2FMUstate,
        ) -> $crate::types::fmi2Status {
            $crate::api::set_fmu_state::<$model>(c, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2FreeFMUstate(
            c: $crate::types::fmi2Component,
            FMUstate: *mut $crate::types::fmi2FMUstate,
        ) -> $crate::types::fmi2Status {
            $crate::api::free_fmu_state::<$model>(c, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
            c: $crate::types::fmi2Component,
            FMUstate: $crate::types::fmi2FMUstate,
            size: *mut usize,
        ) -> $crate::types::fmi2Status {
            $crate::api::serialized_fmu_state_size::<$model>(c, FMUstate, size)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SerializeFMUstate(
            c: $crate::types::fmi2Component,
            FMUstate: $crate::types::fmi2FMUstate,
            serializedState: *mut $crate::types::fmi2Byte,
            size: usize,
        ) -> $crate::types::fmi2Status {
            $crate::api::serialize_fmu_state::<$model>(c, FMUstate, serializedState, size)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
            c: $crate::types::fmi2Component,
            serializedState: *const $crate::types::fmi2Byte,
            size: usize,
            FMUstate: *mut $crate::types::fmi2FMUstate,
        ) -> $crate::types::fmi2Status {
            $crate::api::deserialize_fmu_state::<$model>(c, serializedState, size, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
            c: $crate::types::fmi2Component,
            vUnknown_ref: *const $crate::types::fmi2ValueReference,
            nUnknown: usize,
            vKnown_ref: *const $crate::types::fmi2ValueReference,
            nKnown: usize,
            dvKnown: *const $crate::types::fmi2Real,
            dvUnknown: *mut $crate::types::fmi2Real,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_directional_derivative::<$model>(
                c,
                vUnknown_ref,
                nUnknown,
                vKnown_ref,
                nKnown,
                dvKnown,
                dvUnknown,
            )
        }

        // ---- Co-Simulation functions ---------------------------------------------------------

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            order: *const $crate::types::fmi2Integer,
            value: *const $crate::types::fmi2Real,
        ) -> $crate::types::fmi2Status {
            $crate::api::set_real_input_derivatives::<$model>(c, vr, nvr, order, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
            c: $crate::types::fmi2Component,
            vr: *const $crate::types::fmi2ValueReference,
            nvr: usize,
            order: *const $crate::types::fmi2Integer,
            value: *mut $crate::types::fmi2Real,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_real_output_derivatives::<$model>(c, vr, nvr, order, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2DoStep(
            c: $crate::types::fmi2Component,
            currentCommunicationPoint: $crate::types::fmi2Real,
            communicationStepSize: $crate::types::fmi2Real,
            noSetFMUStatePriorToCurrentPoint: $crate::types::fmi2Boolean,
        ) -> $crate::types::fmi2Status {
            $crate::api::do_step::<$model>(
                c,
                currentCommunicationPoint,
                communicationStepSize,
                noSetFMUStatePriorToCurrentPoint,
            )
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2CancelStep(c: $crate::types::fmi2Component) -> $crate::types::fmi2Status {
            $crate::api::cancel_step::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetStatus(
            c: $crate::types::fmi2Component,
            s: $crate::types::fmi2StatusKind,
            value: *mut $crate::types::fmi2Status,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetRealStatus(
            c: $crate::types::fmi2Component,
            s: $crate::types::fmi2StatusKind,
            value: *mut $crate::types::fmi2Real,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_real_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetIntegerStatus(
            c: $crate::types::fmi2Component,
            s: $crate::types::fmi2StatusKind,
            value: *mut $crate::types::fmi2Integer,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_integer_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetBooleanStatus(
            c: $crate::types::fmi2Component,
            s: $crate::types::fmi2StatusKind,
            value: *mut $crate::types::fmi2Boolean,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_boolean_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetStringStatus(
            c: $crate::types::fmi2Component,
            s: $crate::types::fmi2StatusKind,
            value: *mut $crate::types::fmi2String,
        ) -> $crate::types::fmi2Status {
            $crate::api::get_string_status::<$model>(c, s, value)
        }
    };
}
