//! The C types of the FMI 3.0 standard headers (`fmi3PlatformTypes.h`,
//! `fmi3FunctionTypes.h`), spelled as in the headers.
//!
//! `fmi3Boolean` and `fmi3Clock` are C `bool`s; they are received as bytes (`u8`, the same
//! ABI) so that an importer passing a byte other than 0 or 1 is not undefined behaviour.
//! C enums (`fmi3Status`, `fmi3DependencyKind`, `fmi3IntervalQualifier`) are `c_int` aliases.
#![allow(non_camel_case_types, non_upper_case_globals, non_snake_case)]

use std::os::raw::{c_char, c_int, c_void};

pub type fmi3Instance = *mut c_void;
pub type fmi3InstanceEnvironment = *mut c_void;
pub type fmi3FMUState = *mut c_void;
pub type fmi3ValueReference = u32;
pub type fmi3Float32 = f32;
pub type fmi3Float64 = f64;
pub type fmi3Int8 = i8;
pub type fmi3UInt8 = u8;
pub type fmi3Int16 = i16;
pub type fmi3UInt16 = u16;
pub type fmi3Int32 = i32;
pub type fmi3UInt32 = u32;
pub type fmi3Int64 = i64;
pub type fmi3UInt64 = u64;
pub type fmi3Boolean = u8;
pub type fmi3Char = c_char;
pub type fmi3String = *const fmi3Char;
pub type fmi3Byte = u8;
pub type fmi3Binary = *const fmi3Byte;
pub type fmi3Clock = u8;

pub const fmi3True: fmi3Boolean = 1;
pub const fmi3False: fmi3Boolean = 0;

/// `fmi3Status` (a C enum; the same numbering as `fmi2Status` without `fmi2Pending`).
pub type fmi3Status = c_int;
pub const fmi3OK: fmi3Status = 0;
pub const fmi3Warning: fmi3Status = 1;
pub const fmi3Discard: fmi3Status = 2;
pub const fmi3Error: fmi3Status = 3;
pub const fmi3Fatal: fmi3Status = 4;

/// `fmi3DependencyKind` (a C enum).
pub type fmi3DependencyKind = c_int;
/// `fmi3IntervalQualifier` (a C enum).
pub type fmi3IntervalQualifier = c_int;

/// `fmi3LogMessageCallback`.
pub type fmi3LogMessageCallback = fmi2::instance::LogMessageCallback;
/// `fmi3IntermediateUpdateCallback` (never called: `providesIntermediateUpdate="false"`).
pub type fmi3IntermediateUpdateCallback = Option<
    unsafe extern "C" fn(
        instance_environment: fmi3InstanceEnvironment,
        intermediate_update_time: fmi3Float64,
        intermediate_variable_set_requested: fmi3Boolean,
        intermediate_variable_get_allowed: fmi3Boolean,
        intermediate_step_finished: fmi3Boolean,
        can_return_early: fmi3Boolean,
        early_return_requested: *mut fmi3Boolean,
        early_return_time: *mut fmi3Float64,
    ),
>;
/// `fmi3ClockUpdateCallback` (Scheduled Execution, which this layer does not offer).
pub type fmi3ClockUpdateCallback = Option<unsafe extern "C" fn(instance_environment: fmi3InstanceEnvironment)>;
/// `fmi3LockPreemptionCallback`.
pub type fmi3LockPreemptionCallback = Option<unsafe extern "C" fn()>;
/// `fmi3UnlockPreemptionCallback`.
pub type fmi3UnlockPreemptionCallback = Option<unsafe extern "C" fn()>;

/// `fmi3Version`.
// Byte strings, not c"" literals: the win64 build compiles with rustc 1.63.
// SAFETY: one NUL, at the end.
pub const VERSION: &std::ffi::CStr = unsafe { std::ffi::CStr::from_bytes_with_nul_unchecked(b"3.0\0") };

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::size_of;

    #[test]
    fn the_types_have_the_sizes_of_the_header() {
        assert_eq!(size_of::<fmi3Boolean>(), size_of::<bool>());
        assert_eq!(size_of::<fmi3Status>(), 4);
        assert_eq!(size_of::<fmi3ValueReference>(), 4);
        assert_eq!(size_of::<fmi3LogMessageCallback>(), size_of::<*mut c_void>());
        assert_eq!(fmi3Fatal, fmi2::types::fmi2Fatal);
        assert_eq!(fmi3Discard, fmi2::types::fmi2Discard);
    }
}
