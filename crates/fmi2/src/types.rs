//! The C types of the FMI 2.0 standard headers (`fmi2TypesPlatform.h`,
//! `fmi2FunctionTypes.h`), spelled as in the headers.
//!
//! C enums (`fmi2Status`, `fmi2Type`, `fmi2StatusKind`) are `c_int` aliases with
//! constants rather than Rust enums: an importer may pass any integer, and an
//! out-of-range value in a Rust enum would be undefined behaviour.
#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use std::os::raw::{c_char, c_int, c_uint, c_void};

pub type fmi2Component = *mut c_void;
pub type fmi2ComponentEnvironment = *mut c_void;
pub type fmi2FMUstate = *mut c_void;
pub type fmi2ValueReference = c_uint;
pub type fmi2Real = f64;
pub type fmi2Integer = c_int;
pub type fmi2Boolean = c_int;
pub type fmi2Char = c_char;
pub type fmi2String = *const fmi2Char;
pub type fmi2Byte = c_char;

pub const fmi2True: fmi2Boolean = 1;
pub const fmi2False: fmi2Boolean = 0;

/// `fmi2Status` (a C enum).
pub type fmi2Status = c_int;
pub const fmi2OK: fmi2Status = 0;
pub const fmi2Warning: fmi2Status = 1;
pub const fmi2Discard: fmi2Status = 2;
pub const fmi2Error: fmi2Status = 3;
pub const fmi2Fatal: fmi2Status = 4;
pub const fmi2Pending: fmi2Status = 5;

/// `fmi2Type` (a C enum).
pub type fmi2Type = c_int;
pub const fmi2ModelExchange: fmi2Type = 0;
pub const fmi2CoSimulation: fmi2Type = 1;

/// `fmi2StatusKind` (a C enum).
pub type fmi2StatusKind = c_int;
pub const fmi2DoStepStatus: fmi2StatusKind = 0;
pub const fmi2PendingStatus: fmi2StatusKind = 1;
pub const fmi2LastSuccessfulTime: fmi2StatusKind = 2;
pub const fmi2Terminated: fmi2StatusKind = 3;

/// `fmi2CallbackLogger`: variadic; the layer always passes `"%s"` and one string.
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        componentEnvironment: fmi2ComponentEnvironment,
        instanceName: fmi2String,
        status: fmi2Status,
        category: fmi2String,
        message: fmi2String,
        ...
    ),
>;
pub type fmi2CallbackAllocateMemory = Option<unsafe extern "C" fn(nobj: usize, size: usize) -> *mut c_void>;
pub type fmi2CallbackFreeMemory = Option<unsafe extern "C" fn(obj: *mut c_void)>;
pub type fmi2StepFinished =
    Option<unsafe extern "C" fn(componentEnvironment: fmi2ComponentEnvironment, status: fmi2Status)>;

/// `fmi2CallbackFunctions`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct fmi2CallbackFunctions {
    pub logger: fmi2CallbackLogger,
    pub allocateMemory: fmi2CallbackAllocateMemory,
    pub freeMemory: fmi2CallbackFreeMemory,
    pub stepFinished: fmi2StepFinished,
    pub componentEnvironment: fmi2ComponentEnvironment,
}

/// `fmi2EventInfo` (Model Exchange).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct fmi2EventInfo {
    pub newDiscreteStatesNeeded: fmi2Boolean,
    pub terminateSimulation: fmi2Boolean,
    pub nominalsOfContinuousStatesChanged: fmi2Boolean,
    pub valuesOfContinuousStatesChanged: fmi2Boolean,
    pub nextEventTimeDefined: fmi2Boolean,
    pub nextEventTime: fmi2Real,
}

/// `fmi2TypesPlatform`.
// Byte strings, not c"" literals: the win64 build compiles with rustc 1.63.
// SAFETY: one NUL, at the end.
pub const TYPES_PLATFORM: &std::ffi::CStr = unsafe { std::ffi::CStr::from_bytes_with_nul_unchecked(b"default\0") };
/// `fmi2Version`.
// SAFETY: one NUL, at the end.
pub const VERSION: &std::ffi::CStr = unsafe { std::ffi::CStr::from_bytes_with_nul_unchecked(b"2.0\0") };

/// A readable name of a status, for log messages.
pub fn status_name(s: fmi2Status) -> &'static str {
    match s {
        fmi2OK => "fmi2OK",
        fmi2Warning => "fmi2Warning",
        fmi2Discard => "fmi2Discard",
        fmi2Error => "fmi2Error",
        fmi2Fatal => "fmi2Fatal",
        fmi2Pending => "fmi2Pending",
        _ => "invalid fmi2Status",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::{align_of, size_of};

    #[test]
    fn layout_matches_the_header() {
        // five pointer-sized members, no padding
        assert_eq!(size_of::<fmi2CallbackFunctions>(), 5 * size_of::<*mut c_void>());
        assert_eq!(align_of::<fmi2CallbackFunctions>(), align_of::<*mut c_void>());
        assert_eq!(size_of::<fmi2CallbackLogger>(), size_of::<*mut c_void>());
        assert_eq!(size_of::<fmi2Status>(), 4);
        assert_eq!(size_of::<fmi2ValueReference>(), 4);
        assert_eq!(size_of::<fmi2Byte>(), 1);
        // five ints, padding to the double's alignment, the double
        assert_eq!(size_of::<fmi2EventInfo>(), 32);
    }
}
