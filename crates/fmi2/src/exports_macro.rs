//! [`fmi2_cosimulation_exports!`]: the exported `fmi2*` symbols of the FMI 2.0 Co-Simulation
//! layer for any [`crate::model::CoSimModel`], for the crates that put a model on the layer
//! (`fmus/` in the workspace).
//!
//! The actuator's `src/fmu_exports.rs` stays literal because cbindgen reads it to
//! write the C header whose compilation against the standard `fmi2Functions.h` proves the
//! signatures. This macro must therefore emit exactly the same signatures:
//! `tests::macro_signatures_are_the_literal_exports` compares the two texts (only as text:
//! this crate does not depend on the actuator's), so an edit to one without the other fails.
//!
//! Invoke it once per cdylib; a second invocation, or the actuator's own symbols in the same
//! library or test (any crate that links the FMU crate), would give duplicate `fmi2*`
//! definitions.

/// Emit the 34 `#[no_mangle] extern "C" fn fmi2*` functions of FMI 2.0 Co-Simulation as
/// forwarders to [`crate::api`] instantiated for `$model` (a type implementing
/// [`crate::model::CoSimModel`]). The expansion names them `$crate::fmi2::api` and
/// `$crate::fmi2::types` (see `crate::fmi2`).
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
            $crate::fmi2::api::get_types_platform()
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub extern "C" fn fmi2GetVersion() -> *const ::std::os::raw::c_char {
            $crate::fmi2::api::get_version()
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetDebugLogging(
            c: $crate::fmi2::types::fmi2Component,
            loggingOn: $crate::fmi2::types::fmi2Boolean,
            nCategories: usize,
            categories: *const $crate::fmi2::types::fmi2String,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::set_debug_logging::<$model>(c, loggingOn, nCategories, categories)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2Instantiate(
            instanceName: $crate::fmi2::types::fmi2String,
            fmuType: $crate::fmi2::types::fmi2Type,
            fmuGUID: $crate::fmi2::types::fmi2String,
            fmuResourceLocation: $crate::fmi2::types::fmi2String,
            functions: *const $crate::fmi2::types::fmi2CallbackFunctions,
            visible: $crate::fmi2::types::fmi2Boolean,
            loggingOn: $crate::fmi2::types::fmi2Boolean,
        ) -> $crate::fmi2::types::fmi2Component {
            $crate::fmi2::api::instantiate::<$model>(
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
        pub unsafe extern "C" fn fmi2FreeInstance(c: $crate::fmi2::types::fmi2Component) {
            $crate::fmi2::api::free_instance::<$model>(c);
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetupExperiment(
            c: $crate::fmi2::types::fmi2Component,
            toleranceDefined: $crate::fmi2::types::fmi2Boolean,
            tolerance: $crate::fmi2::types::fmi2Real,
            startTime: $crate::fmi2::types::fmi2Real,
            stopTimeDefined: $crate::fmi2::types::fmi2Boolean,
            stopTime: $crate::fmi2::types::fmi2Real,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::setup_experiment::<$model>(
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
            c: $crate::fmi2::types::fmi2Component,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::enter_initialization_mode::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2ExitInitializationMode(
            c: $crate::fmi2::types::fmi2Component,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::exit_initialization_mode::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2Terminate(
            c: $crate::fmi2::types::fmi2Component,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::terminate::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2Reset(c: $crate::fmi2::types::fmi2Component) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::reset::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetReal(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::fmi2::types::fmi2Real,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_real::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetInteger(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::fmi2::types::fmi2Integer,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_integer::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetBoolean(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::fmi2::types::fmi2Boolean,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_boolean::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetString(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *mut $crate::fmi2::types::fmi2String,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_string::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetReal(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::fmi2::types::fmi2Real,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::set_real::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetInteger(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::fmi2::types::fmi2Integer,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::set_integer::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetBoolean(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::fmi2::types::fmi2Boolean,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::set_boolean::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetString(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            value: *const $crate::fmi2::types::fmi2String,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::set_string::<$model>(c, vr, nvr, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetFMUstate(
            c: $crate::fmi2::types::fmi2Component,
            FMUstate: *mut $crate::fmi2::types::fmi2FMUstate,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_fmu_state::<$model>(c, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SetFMUstate(
            c: $crate::fmi2::types::fmi2Component,
            FMUstate: $crate::fmi2::types::fmi2FMUstate,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::set_fmu_state::<$model>(c, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2FreeFMUstate(
            c: $crate::fmi2::types::fmi2Component,
            FMUstate: *mut $crate::fmi2::types::fmi2FMUstate,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::free_fmu_state::<$model>(c, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
            c: $crate::fmi2::types::fmi2Component,
            FMUstate: $crate::fmi2::types::fmi2FMUstate,
            size: *mut usize,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::serialized_fmu_state_size::<$model>(c, FMUstate, size)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2SerializeFMUstate(
            c: $crate::fmi2::types::fmi2Component,
            FMUstate: $crate::fmi2::types::fmi2FMUstate,
            serializedState: *mut $crate::fmi2::types::fmi2Byte,
            size: usize,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::serialize_fmu_state::<$model>(c, FMUstate, serializedState, size)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
            c: $crate::fmi2::types::fmi2Component,
            serializedState: *const $crate::fmi2::types::fmi2Byte,
            size: usize,
            FMUstate: *mut $crate::fmi2::types::fmi2FMUstate,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::deserialize_fmu_state::<$model>(c, serializedState, size, FMUstate)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
            c: $crate::fmi2::types::fmi2Component,
            vUnknown_ref: *const $crate::fmi2::types::fmi2ValueReference,
            nUnknown: usize,
            vKnown_ref: *const $crate::fmi2::types::fmi2ValueReference,
            nKnown: usize,
            dvKnown: *const $crate::fmi2::types::fmi2Real,
            dvUnknown: *mut $crate::fmi2::types::fmi2Real,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_directional_derivative::<$model>(
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
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            order: *const $crate::fmi2::types::fmi2Integer,
            value: *const $crate::fmi2::types::fmi2Real,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::set_real_input_derivatives::<$model>(c, vr, nvr, order, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
            c: $crate::fmi2::types::fmi2Component,
            vr: *const $crate::fmi2::types::fmi2ValueReference,
            nvr: usize,
            order: *const $crate::fmi2::types::fmi2Integer,
            value: *mut $crate::fmi2::types::fmi2Real,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_real_output_derivatives::<$model>(c, vr, nvr, order, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2DoStep(
            c: $crate::fmi2::types::fmi2Component,
            currentCommunicationPoint: $crate::fmi2::types::fmi2Real,
            communicationStepSize: $crate::fmi2::types::fmi2Real,
            noSetFMUStatePriorToCurrentPoint: $crate::fmi2::types::fmi2Boolean,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::do_step::<$model>(
                c,
                currentCommunicationPoint,
                communicationStepSize,
                noSetFMUStatePriorToCurrentPoint,
            )
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2CancelStep(
            c: $crate::fmi2::types::fmi2Component,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::cancel_step::<$model>(c)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetStatus(
            c: $crate::fmi2::types::fmi2Component,
            s: $crate::fmi2::types::fmi2StatusKind,
            value: *mut $crate::fmi2::types::fmi2Status,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetRealStatus(
            c: $crate::fmi2::types::fmi2Component,
            s: $crate::fmi2::types::fmi2StatusKind,
            value: *mut $crate::fmi2::types::fmi2Real,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_real_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetIntegerStatus(
            c: $crate::fmi2::types::fmi2Component,
            s: $crate::fmi2::types::fmi2StatusKind,
            value: *mut $crate::fmi2::types::fmi2Integer,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_integer_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetBooleanStatus(
            c: $crate::fmi2::types::fmi2Component,
            s: $crate::fmi2::types::fmi2StatusKind,
            value: *mut $crate::fmi2::types::fmi2Boolean,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_boolean_status::<$model>(c, s, value)
        }

        #[no_mangle]
        #[allow(non_snake_case, clippy::missing_safety_doc)]
        pub unsafe extern "C" fn fmi2GetStringStatus(
            c: $crate::fmi2::types::fmi2Component,
            s: $crate::fmi2::types::fmi2StatusKind,
            value: *mut $crate::fmi2::types::fmi2String,
        ) -> $crate::fmi2::types::fmi2Status {
            $crate::fmi2::api::get_string_status::<$model>(c, s, value)
        }
    };
}

#[cfg(test)]
mod tests {
    /// The exported items of `text` (from the first `#[no_mangle]` after `begin` up to `stop`), with the
    /// paths the macro needs and the formatting removed, so the two files compare as code.
    fn exported_items(text: &str, begin: &str, stop: &str) -> Vec<String> {
        let from = text.find(begin).expect("no begin marker");
        let start = from + text[from..].find("#[no_mangle]").expect("no exported item");
        let end = text[start..].find(stop).map_or(text.len(), |i| start + i);
        let code: String = text[start..end]
            .lines()
            .filter(|l| !l.trim_start().starts_with("//") && !l.trim_start().starts_with("#[allow("))
            .collect::<Vec<_>>()
            .join("\n")
            .replace("$crate::fmi2::types::", "")
            .replace("$crate::fmi2::", "")
            .replace("::std::os::raw::", "")
            .replace("$model", "ExportedModel")
            .split_whitespace()
            .collect();
        code.replace(",)", ")")
            .split("#[no_mangle]")
            .filter(|item| !item.is_empty())
            .map(|item| item.trim_end_matches(['}', ';']).to_string())
            .collect()
    }

    #[test]
    fn macro_signatures_are_the_literal_exports() {
        let literal = exported_items(
            include_str!("../../../src/fmu_exports.rs"),
            "use crate::ExportedModel;",
            "// ---- Model Exchange",
        );
        let generated = exported_items(include_str!("exports_macro.rs"), "macro_rules!", "\n    };\n}");
        assert_eq!(
            literal.len(),
            34,
            "src/fmu_exports.rs should export the 34 FMI 2.0 Co-Simulation functions before its Model Exchange ones"
        );
        assert_eq!(
            literal.len(),
            generated.len(),
            "the macro and src/fmu_exports.rs export different counts"
        );
        for (a, b) in literal.iter().zip(&generated) {
            assert_eq!(a, b, "the macro's item differs from src/fmu_exports.rs");
        }
    }
}
