//! The exported C symbols forward to the generic layer for `jetpipe::ExportedModel`.
//! Model-agnostic: uses only `ExportedModel::info()` (GUID, default step size), so it
//! also runs after the merge against the actuator.

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};

use fmi2::model::CoSimModel;
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::ExportedModel;

#[test]
fn exported_symbols_drive_a_simulation() {
    unsafe {
        assert_eq!(CStr::from_ptr(fmi2GetVersion()), c"2.0");
        assert_eq!(CStr::from_ptr(fmi2GetTypesPlatform()), c"default");
        let cb = fmi2CallbackFunctions {
            logger: None,
            allocateMemory: None,
            freeMemory: None,
            stepFinished: None,
            componentEnvironment: null_mut(),
        };
        let guid = CString::new(ExportedModel::info().guid()).unwrap();
        assert!(fmi2Instantiate(c"x".as_ptr(), fmi2CoSimulation, c"{nope}".as_ptr(), null(), &cb, 0, 0).is_null());
        let c = fmi2Instantiate(c"x".as_ptr(), fmi2CoSimulation, guid.as_ptr(), null(), &cb, 0, 0);
        assert!(!c.is_null());
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 1, 1.0), fmi2OK);
        assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let h = ExportedModel::info().default_step_size;
        for k in 0..10 {
            assert_eq!(fmi2DoStep(c, k as f64 * h, h, 1), fmi2OK);
        }
        let mut t = 0.0;
        assert_eq!(fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut t), fmi2OK);
        assert!((t - 10.0 * h).abs() < 1e-12);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut st), fmi2OK);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(c, st, &mut size), fmi2OK);
        let mut bytes = vec![0 as fmi2Byte; size];
        assert_eq!(fmi2SerializeFMUstate(c, st, bytes.as_mut_ptr(), size), fmi2OK);
        let mut st2: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut st2), fmi2OK);
        assert_eq!(fmi2SetFMUstate(c, st2), fmi2OK);
        assert_eq!(fmi2FreeFMUstate(c, &mut st), fmi2OK);
        assert_eq!(fmi2FreeFMUstate(c, &mut st2), fmi2OK);
        assert_eq!(fmi2CancelStep(c), fmi2Error);
        assert_eq!(fmi2Terminate(c), fmi2OK);
        assert_eq!(fmi2Reset(c), fmi2OK);
        fmi2FreeInstance(c);
        fmi2FreeInstance(null_mut());
        assert_eq!(fmi2DoStep(null_mut(), 0.0, 1.0, 0), fmi2Error);
    }
}
