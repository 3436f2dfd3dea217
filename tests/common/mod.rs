//! Shared by the robustness tests (issue 5): a recording logger for the exported
//! `fmi2*` functions, instance helpers, a tiny deterministic PRNG and size knobs.
#![allow(dead_code)]

use std::ffi::{CStr, CString};
use std::os::raw::c_char;
use std::ptr::{null, null_mut};
use std::sync::Mutex;

use fmi2::instance::Instance;
use fmi2::model::CoSimModel;
use fmi2::state::State;
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::vr;
use jetpipe::ExportedModel;

/// The five outputs.
pub const OUTPUTS: [u32; 5] = [vr::F_ACT, vr::P1, vr::P2, vr::I, vr::X_JP];

/// What the logger received: (status, category, format, message).
#[derive(Clone, Debug)]
pub struct LogRecord {
    pub status: fmi2Status,
    pub category: String,
    pub format: String,
    pub message: String,
}

/// Where one instance's messages go (the `componentEnvironment`).
#[derive(Default)]
pub struct Sink(pub Mutex<Vec<LogRecord>>);

impl Sink {
    pub fn len(&self) -> usize {
        self.0.lock().unwrap().len()
    }
    pub fn since(&self, n: usize) -> Vec<LogRecord> {
        self.0.lock().unwrap()[n..].to_vec()
    }
    pub fn clear(&self) {
        self.0.lock().unwrap().clear()
    }
}

/// A logger written in Rust, called through the variadic pointer type. The layer always
/// calls it as `logger(env, name, status, category, "%s", message)`; on x86_64 and aarch64
/// Linux a variadic pointer argument travels exactly like a named one (as in
/// src/fmi2/tests.rs).
#[cfg(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64")))]
unsafe extern "C" fn recording_logger(
    env: fmi2ComponentEnvironment,
    _name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    format: fmi2String,
    arg: *const c_char,
) {
    if env.is_null() {
        return;
    }
    let sink = &*(env as *const Sink);
    let s = |p: *const c_char| {
        if p.is_null() {
            "<NULL>".to_owned()
        } else {
            CStr::from_ptr(p).to_string_lossy().into_owned()
        }
    };
    sink.0.lock().unwrap().push(LogRecord {
        status,
        category: s(category),
        format: s(format),
        message: s(arg),
    });
}

pub fn logger_available() -> bool {
    cfg!(all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64")
    ))
}

pub fn callbacks(sink: &Sink) -> fmi2CallbackFunctions {
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
        >(recording_logger)
    });
    #[cfg(not(all(target_os = "linux", any(target_arch = "x86_64", target_arch = "aarch64"))))]
    let logger: fmi2CallbackLogger = None;
    fmi2CallbackFunctions {
        logger,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: sink as *const Sink as *mut _,
    }
}

pub fn guid() -> CString {
    CString::new(ExportedModel::info().guid()).unwrap()
}

/// A new instance logging into `sink` (which must outlive it).
pub unsafe fn instantiate(sink: &Sink, name: &str) -> fmi2Component {
    let cb = callbacks(sink);
    let name = CString::new(name).unwrap();
    let c = fmi2Instantiate(
        name.as_ptr(),
        fmi2CoSimulation,
        guid().as_ptr(),
        null(),
        &cb,
        fmi2False,
        fmi2False,
    );
    assert!(!c.is_null(), "fmi2Instantiate returned NULL");
    c
}

/// A new Model Exchange instance logging into `sink` (which must outlive it).
pub unsafe fn instantiate_model_exchange(sink: &Sink, name: &str) -> fmi2Component {
    let cb = callbacks(sink);
    let name = CString::new(name).unwrap();
    let c = fmi2Instantiate(
        name.as_ptr(),
        fmi2ModelExchange,
        guid().as_ptr(),
        null(),
        &cb,
        fmi2False,
        fmi2False,
    );
    assert!(!c.is_null(), "fmi2Instantiate(fmi2ModelExchange) returned NULL");
    c
}

/// Setup, initialisation with the given inputs and Real parameters, exit.
pub unsafe fn initialise(c: fmi2Component, tolerance: Option<f64>, params: &[(u32, f64)], v_da: f64, x_s: f64) {
    let (defined, tol) = tolerance.map_or((fmi2False, 0.0), |t| (fmi2True, t));
    assert_eq!(fmi2SetupExperiment(c, defined, tol, 0.0, fmi2False, 0.0), fmi2OK);
    assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
    for &(r, x) in params {
        assert_eq!(fmi2SetReal(c, &r, 1, &x), fmi2OK, "parameter vr {r} = {x}");
    }
    set_inputs(c, v_da, x_s);
    assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
}

pub unsafe fn set_inputs(c: fmi2Component, v_da: f64, x_s: f64) {
    let vrs = [vr::V_DA, vr::X_S];
    let xs = [v_da, x_s];
    assert_eq!(
        fmi2SetReal(c, vrs.as_ptr(), 2, xs.as_ptr()),
        fmi2OK,
        "v_DA = {v_da}, x_s = {x_s}"
    );
}

pub unsafe fn get_reals(c: fmi2Component, vrs: &[u32]) -> (fmi2Status, Vec<f64>) {
    let mut out = vec![f64::NAN; vrs.len()];
    let s = fmi2GetReal(c, vrs.as_ptr(), vrs.len(), out.as_mut_ptr());
    (s, out)
}

pub unsafe fn outputs(c: fmi2Component) -> [f64; 5] {
    let (s, y) = get_reals(c, &OUTPUTS);
    assert_eq!(s, fmi2OK);
    [y[0], y[1], y[2], y[3], y[4]]
}

/// The layer's view of an instance (read-only peek, for cross-checking a mirror).
pub unsafe fn layer_state(c: fmi2Component) -> State {
    (*(c as *const Instance<ExportedModel>)).state
}

pub unsafe fn model_time(c: fmi2Component) -> f64 {
    (*(c as *const Instance<ExportedModel>)).model.time()
}

pub fn free(c: fmi2Component) {
    unsafe { fmi2FreeInstance(c) }
}

pub fn null_component() -> fmi2Component {
    null_mut()
}

/// SplitMix64: tiny, deterministic, good enough to generate call sequences.
#[derive(Clone)]
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    pub fn chance(&mut self, p: f64) -> bool {
        self.unit() < p
    }
    pub fn pick<'a, T>(&mut self, xs: &'a [T]) -> &'a T {
        &xs[self.below(xs.len())]
    }
    /// Log-uniform in [lo, hi].
    pub fn log_range(&mut self, lo: f64, hi: f64) -> f64 {
        (lo.ln() + (hi.ln() - lo.ln()) * self.unit()).exp()
    }
}

/// An environment variable as a number, or the default (the bounded CI form).
pub fn env_or<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}
