//! Issue 5, call orders: every FMI 2.0 CS function in every state of the state machine,
//! through the exported `fmi2*` symbols, in generated call sequences.
//!
//! A deterministic generator (SplitMix64, seed printed) drives one instance through random
//! calls with valid and invalid arguments (NULL pointers, unknown value references,
//! zero-length arrays, NaN, wrong sizes, corrupted and crafted FMU states, freed handles).
//! A mirror of the state machine predicts each status from the legality table
//! (`fmi2::state`) and the arguments; after every call the test checks:
//! * illegal call -> fmi2Error and the message "fmi2Xxx: illegal call in state yyy";
//! * legal call -> the predicted status (OK / Error / Discard), never fmi2Fatal;
//! * every fmi2Error / fmi2Discard comes with a logged message of that status that names
//!   the function, always with the format "%s";
//! * the layer's state equals the mirror; a rejected value was not applied;
//! * in readable states every output is finite.
//!
//! States other than those reachable by ordinary calls (stepFailed, stepCanceled, error)
//! are entered by restoring a serialized FMU state whose layer-state code was rewritten
//! (with a valid checksum): so every function is tried in every state but `fatal` (which
//! only a panic reaches; the layer's unit tests cover it with a panicking dummy model).
//!
//! Bounded for CI: JETPIPE_FUZZ_SEQUENCES (default 100) sequences of JETPIPE_FUZZ_CALLS
//! (default 400) calls; JETPIPE_FUZZ_SEED picks the first seed.

#![allow(non_upper_case_globals)]

mod argument_calls;
#[path = "../common/mod.rs"]
mod common;
mod fmi3;
mod model_exchange;

use std::collections::BTreeMap;
use std::ffi::CString;
use std::os::raw::c_char;
use std::ptr::{null, null_mut};
use std::time::Instant;

/// Status counts per (call, state).
type Tally = BTreeMap<(&'static str, &'static str), [u32; 5]>;

use common::*;
use fmi2::fmu_state::crc32;
use fmi2::state::{Function, Interface, State};
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::{vr, VARIABLES};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Expect {
    Ok,
    Error,
    Discard,
    OkOrDiscard,
}

const REACHABLE: [State; 7] = [
    State::Instantiated,
    State::InitializationMode,
    State::StepComplete,
    State::StepFailed,
    State::StepCanceled,
    State::Terminated,
    State::Error,
];

const ALL_FUNCTIONS: [Function; 41] = [
    Function::SetDebugLogging,
    Function::FreeInstance,
    Function::SetupExperiment,
    Function::EnterInitializationMode,
    Function::ExitInitializationMode,
    Function::Terminate,
    Function::Reset,
    Function::GetReal,
    Function::GetInteger,
    Function::GetBoolean,
    Function::GetString,
    Function::SetReal,
    Function::SetInteger,
    Function::SetBoolean,
    Function::SetString,
    Function::GetFMUstate,
    Function::SetFMUstate,
    Function::FreeFMUstate,
    Function::SerializedFMUstateSize,
    Function::SerializeFMUstate,
    Function::DeSerializeFMUstate,
    Function::GetDirectionalDerivative,
    Function::SetRealInputDerivatives,
    Function::GetRealOutputDerivatives,
    Function::DoStep,
    Function::CancelStep,
    Function::GetStatus,
    Function::GetRealStatus,
    Function::GetIntegerStatus,
    Function::GetBooleanStatus,
    Function::GetStringStatus,
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

/// Byte offset of the layer-state code in a serialized FMU state (see fmu_state.rs).
fn code_offset(blob: &[u8]) -> usize {
    16 + u32::from_le_bytes(blob[12..16].try_into().unwrap()) as usize
}

fn fix_crc(b: &mut [u8]) {
    let n = b.len();
    let crc = crc32(&b[..n - 4]);
    b[n - 4..].copy_from_slice(&crc.to_le_bytes());
}

/// The blob with another layer-state code and a valid checksum.
fn recode(blob: &[u8], code: u8) -> Vec<u8> {
    let mut b = blob.to_vec();
    b[code_offset(blob)] = code;
    fix_crc(&mut b);
    b
}

/// The blob with the model-version string inside the model bytes replaced (counts and
/// checksum fixed): what a state written by another version of the model looks like.
pub fn with_model_version(blob: &[u8], version: &str) -> Vec<u8> {
    let at = code_offset(blob) + 1;
    let n = u64::from_le_bytes(blob[at..at + 8].try_into().unwrap()) as usize;
    let model = &blob[at + 8..at + 8 + n];
    // model bytes: 20-byte magic, u32 format, u32 length + version string, rest
    let vlen = u32::from_le_bytes(model[24..28].try_into().unwrap()) as usize;
    let mut m = model[..24].to_vec();
    m.extend_from_slice(&(version.len() as u32).to_le_bytes());
    m.extend_from_slice(version.as_bytes());
    m.extend_from_slice(&model[28 + vlen..]);
    let mut b = blob[..at].to_vec();
    b.extend_from_slice(&(m.len() as u64).to_le_bytes());
    b.extend_from_slice(&m);
    b.extend_from_slice(&[0; 4]);
    fix_crc(&mut b);
    b
}

struct Fuzz {
    rng: Rng,
    sink: Box<Sink>,
    c: fmi2Component,
    mirror: State,
    /// Live FMU states and the layer state each holds.
    states: Vec<(fmi2FMUstate, State)>,
    /// Freed FMU-state pointers (never dereferenced by a correct layer).
    stale_states: Vec<fmi2FMUstate>,
    /// Serialized states and the layer state each holds.
    blobs: Vec<(Vec<u8>, State)>,
    trace: Vec<String>,
    /// (function, state) -> [legal calls, illegal calls, OK, Error, Discard]
    coverage: BTreeMap<(&'static str, &'static str), [u32; 5]>,
    calls: u64,
    steps: u64,
}

impl Fuzz {
    fn new(seed: u64) -> Self {
        let sink = Box::new(Sink::default());
        let c = unsafe { instantiate(&sink, "fuzz") };
        Fuzz {
            rng: Rng(seed),
            sink,
            c,
            mirror: State::Instantiated,
            states: Vec::new(),
            stale_states: Vec::new(),
            blobs: Vec::new(),
            trace: Vec::new(),
            coverage: BTreeMap::new(),
            calls: 0,
            steps: 0,
        }
    }

    fn fail(&self, what: String) -> ! {
        let tail: Vec<&String> = self
            .trace
            .iter()
            .rev()
            .take(25)
            .collect::<Vec<_>>()
            .into_iter()
            .rev()
            .collect();
        panic!(
            "{what}\nlast calls (oldest first):\n  {}",
            tail.iter().map(|s| s.as_str()).collect::<Vec<_>>().join("\n  ")
        );
    }

    /// Check a call's status against the mirror, the prediction and the log; move the mirror.
    fn check(
        &mut self,
        f: Function,
        desc: String,
        status: fmi2Status,
        expect: Expect,
        logged_from: usize,
        on_ok: Option<State>,
    ) {
        self.calls += 1;
        let legal = f.legal(self.mirror, Interface::CoSimulation);
        let msgs = self.sink.since(logged_from);
        self.trace
            .push(format!("[{}] {desc} -> {}", self.mirror.name(), status_name(status)));
        let cov = self.coverage.entry((f.name(), self.mirror.name())).or_default();
        cov[if legal { 0 } else { 1 }] += 1;
        match status {
            fmi2OK => cov[2] += 1,
            fmi2Error => cov[3] += 1,
            fmi2Discard => cov[4] += 1,
            _ => {}
        }
        for m in &msgs {
            if m.format != "%s" {
                self.fail(format!("{desc}: logger called with format {:?}", m.format));
            }
        }
        let has = |s: fmi2Status, needle: &str| msgs.iter().any(|m| m.status == s && m.message.contains(needle));
        if !legal {
            if status != fmi2Error {
                self.fail(format!(
                    "{desc}: illegal in state {} but returned {}",
                    self.mirror.name(),
                    status_name(status)
                ));
            }
            let needle = format!("{}: illegal call in state {}", f.name(), self.mirror.name());
            if logger_available() && !has(fmi2Error, &needle) {
                self.fail(format!("{desc}: no message {needle:?}; got {msgs:?}"));
            }
        } else {
            let ok = match expect {
                Expect::Ok => status == fmi2OK,
                Expect::Error => status == fmi2Error,
                Expect::Discard => status == fmi2Discard,
                Expect::OkOrDiscard => status == fmi2OK || status == fmi2Discard,
            };
            if !ok {
                self.fail(format!(
                    "{desc}: expected {expect:?} in state {}, got {}; messages: {msgs:?}",
                    self.mirror.name(),
                    status_name(status)
                ));
            }
            if logger_available() && (status == fmi2Error || status == fmi2Discard) && !has(status, f.name()) {
                self.fail(format!(
                    "{desc}: {} without a message naming {}; got {msgs:?}",
                    status_name(status),
                    f.name()
                ));
            }
            if status == fmi2OK {
                if let Some(s) = on_ok {
                    self.mirror = s;
                }
            }
            if status == fmi2Discard && f == Function::DoStep {
                self.mirror = State::StepFailed;
            }
        }
        let layer = unsafe { layer_state(self.c) };
        if layer != self.mirror {
            self.fail(format!(
                "{desc}: layer state {} but mirror {}",
                layer.name(),
                self.mirror.name()
            ));
        }
        // outputs stay finite whenever they can be read
        // (in initializationMode each read solves the equilibrium, ~5 ms: only sometimes)
        let check_outputs = match self.mirror {
            State::Instantiated => false,
            State::InitializationMode => self.rng.chance(0.05),
            _ => true,
        };
        if check_outputs && f != Function::GetReal {
            let (s, y) = unsafe { get_reals(self.c, &OUTPUTS) };
            if s != fmi2OK || !y.iter().all(|v| v.is_finite()) {
                self.fail(format!("{desc}: outputs after the call: {} {y:?}", status_name(s)));
            }
        }
    }

    /// A new live FMU state; its address may be that of a freed one (the allocator reuses it).
    fn add_state(&mut self, p: fmi2FMUstate, holds: State) {
        self.stale_states.retain(|&q| q != p);
        self.states.push((p, holds));
    }

    fn mark(&self) -> usize {
        self.sink.len()
    }

    fn time(&self) -> f64 {
        unsafe { model_time(self.c) }
    }

    fn readback(&self, r: u32) -> f64 {
        let mut x = f64::NAN;
        unsafe { fmi2GetReal(self.c, &r, 1, &mut x) };
        x
    }

    /// One call of `f`; `valid` asks for arguments that should be accepted (some kinds of
    /// call are errors whatever the arguments, e.g. fmi2GetDirectionalDerivative).
    unsafe fn op(&mut self, f: Function, valid: bool) {
        let c = self.c;
        let m = self.mark();
        let st = self.mirror;
        let early = matches!(st, State::Instantiated | State::InitializationMode);
        let settable_input = early || st == State::StepComplete;
        match f {
            Function::SetDebugLogging => {
                let log_all = CString::new("logAll").unwrap();
                let bogus = CString::new("noSuchCategory").unwrap();
                let cats: [*const c_char; 1] = [log_all.as_ptr()];
                let bad: [*const c_char; 1] = [bogus.as_ptr()];
                let nulls: [*const c_char; 1] = [null()];
                let (desc, s, e) = if valid {
                    match self.rng.below(3) {
                        0 => (
                            "fmi2SetDebugLogging(on, 0, NULL)",
                            fmi2SetDebugLogging(c, 1, 0, null()),
                            Expect::Ok,
                        ),
                        1 => (
                            "fmi2SetDebugLogging(off, 0, NULL)",
                            fmi2SetDebugLogging(c, 0, 0, null()),
                            Expect::Ok,
                        ),
                        _ => (
                            "fmi2SetDebugLogging(on, [logAll])",
                            fmi2SetDebugLogging(c, 1, 1, cats.as_ptr()),
                            Expect::Ok,
                        ),
                    }
                } else {
                    match self.rng.below(3) {
                        0 => (
                            "fmi2SetDebugLogging(on, [unknown])",
                            fmi2SetDebugLogging(c, 1, 1, bad.as_ptr()),
                            Expect::Error,
                        ),
                        1 => (
                            "fmi2SetDebugLogging(on, 2, NULL)",
                            fmi2SetDebugLogging(c, 1, 2, null()),
                            Expect::Error,
                        ),
                        _ => (
                            "fmi2SetDebugLogging(on, [NULL])",
                            fmi2SetDebugLogging(c, 1, 1, nulls.as_ptr()),
                            Expect::Error,
                        ),
                    }
                };
                self.check(f, desc.into(), s, e, m, None);
            }
            Function::FreeInstance => {
                // free, then probe the dead handle before anything can reuse its address
                fmi2FreeInstance(c);
                self.calls += 1;
                self.trace.push(format!("[{}] fmi2FreeInstance", st.name()));
                let r = vr::V_DA;
                let mut x = 0.0;
                for (name, s) in [
                    ("fmi2DoStep(dead)", fmi2DoStep(c, 0.0, 1e-3, 1)),
                    ("fmi2GetReal(dead)", fmi2GetReal(c, &r, 1, &mut x)),
                    ("fmi2Reset(dead)", fmi2Reset(c)),
                    ("fmi2Terminate(dead)", fmi2Terminate(c)),
                ] {
                    if s != fmi2Error {
                        self.fail(format!("{name} on a freed instance returned {}", status_name(s)));
                    }
                }
                fmi2FreeInstance(c); // repeated: must be harmless
                fmi2FreeInstance(c);
                self.sink.clear();
                self.c = instantiate(&self.sink, "fuzz");
                self.mirror = State::Instantiated;
                self.trace.push("fmi2Instantiate".into());
            }
            Function::SetupExperiment => {
                let start = *self.rng.pick(&[0.0, 0.0, 1.5]);
                let (desc, s, e) = if valid {
                    if self.rng.chance(0.5) {
                        (
                            format!("fmi2SetupExperiment(tol 1e-6, start {start})"),
                            fmi2SetupExperiment(c, 1, 1e-6, start, 1, start + 10.0),
                            Expect::Ok,
                        )
                    } else {
                        (
                            format!("fmi2SetupExperiment(no tol, start {start})"),
                            fmi2SetupExperiment(c, 0, 0.0, start, 0, 0.0),
                            Expect::Ok,
                        )
                    }
                } else {
                    let (tol, t0, stop) = *self.rng.pick(&[
                        (f64::NAN, 0.0, 1.0),
                        (-1e-6, 0.0, 1.0),
                        (2.0, 0.0, 1.0),
                        (f64::INFINITY, 0.0, 1.0),
                        (1e-6, f64::NAN, 1.0),
                        (1e-6, f64::NEG_INFINITY, 1.0),
                        (1e-6, 1.0, 0.5),
                        (1e-6, 0.0, f64::NAN),
                    ]);
                    (
                        format!("fmi2SetupExperiment(tol {tol}, start {t0}, stop {stop})"),
                        fmi2SetupExperiment(c, 1, tol, t0, 1, stop),
                        Expect::Error,
                    )
                };
                self.check(f, desc, s, e, m, None);
            }
            Function::EnterInitializationMode => {
                let s = fmi2EnterInitializationMode(c);
                self.check(
                    f,
                    "fmi2EnterInitializationMode".into(),
                    s,
                    Expect::Ok,
                    m,
                    Some(State::InitializationMode),
                );
            }
            Function::ExitInitializationMode => {
                let s = fmi2ExitInitializationMode(c);
                self.check(
                    f,
                    "fmi2ExitInitializationMode".into(),
                    s,
                    Expect::Ok,
                    m,
                    Some(State::StepComplete),
                );
            }
            Function::Terminate => {
                let s = fmi2Terminate(c);
                self.check(f, "fmi2Terminate".into(), s, Expect::Ok, m, Some(State::Terminated));
            }
            Function::Reset => {
                let s = fmi2Reset(c);
                self.check(f, "fmi2Reset".into(), s, Expect::Ok, m, Some(State::Instantiated));
            }
            Function::GetReal => {
                let readable_outputs = st != State::Instantiated;
                let inputs_params = [vr::V_DA, vr::X_S, vr::P_S, vr::C_D, vr::K_SPRING, vr::P1_START];
                if valid {
                    let (vrs, e): (Vec<u32>, Expect) = if self.rng.chance(0.5) {
                        (inputs_params.to_vec(), Expect::Ok)
                    } else if self.rng.chance(0.2) {
                        (vec![], Expect::Ok)
                    } else {
                        (
                            OUTPUTS.to_vec(),
                            if readable_outputs { Expect::Ok } else { Expect::Error },
                        )
                    };
                    let mut out = vec![f64::NAN; vrs.len()];
                    let (pv, po) = if vrs.is_empty() {
                        (null(), null_mut())
                    } else {
                        (vrs.as_ptr(), out.as_mut_ptr())
                    };
                    let s = fmi2GetReal(c, pv, vrs.len(), po);
                    if s == fmi2OK && !out.iter().all(|v| v.is_finite()) {
                        self.fail(format!("fmi2GetReal({vrs:?}) gave non-finite values {out:?}"));
                    }
                    self.check(f, format!("fmi2GetReal({vrs:?})"), s, e, m, None);
                } else {
                    let mut out = [0.0f64; 2];
                    let unknown = [*self.rng.pick(&[0u32, 4, 99, 203, 9999, u32::MAX]), vr::V_DA];
                    let boolean = [vr::START_AT_EQUILIBRIUM];
                    let (desc, s) = match self.rng.below(4) {
                        0 => (
                            "fmi2GetReal(unknown vr)".to_string(),
                            fmi2GetReal(c, unknown.as_ptr(), 2, out.as_mut_ptr()),
                        ),
                        1 => (
                            "fmi2GetReal(vr NULL, 2)".into(),
                            fmi2GetReal(c, null(), 2, out.as_mut_ptr()),
                        ),
                        2 => (
                            "fmi2GetReal(value NULL)".into(),
                            fmi2GetReal(c, inputs_params.as_ptr(), 2, null_mut()),
                        ),
                        _ => (
                            "fmi2GetReal(Boolean vr)".into(),
                            fmi2GetReal(c, boolean.as_ptr(), 1, out.as_mut_ptr()),
                        ),
                    };
                    self.check(f, desc, s, Expect::Error, m, None);
                }
            }
            Function::GetInteger | Function::SetInteger | Function::GetString | Function::SetString => {
                // no Integer or String variables: only zero-length calls succeed
                let r = [vr::V_DA];
                let mut i = [0 as fmi2Integer; 1];
                let mut sv: [fmi2String; 1] = [null()];
                let (n, pv) = if valid { (0usize, null()) } else { (1usize, r.as_ptr()) };
                let s = match f {
                    Function::GetInteger => fmi2GetInteger(c, pv, n, i.as_mut_ptr()),
                    Function::SetInteger => fmi2SetInteger(c, pv, n, i.as_ptr()),
                    Function::GetString => fmi2GetString(c, pv, n, sv.as_mut_ptr()),
                    _ => fmi2SetString(c, pv, n, sv.as_ptr()),
                };
                self.check(
                    f,
                    format!("{}(nvr {n})", f.name()),
                    s,
                    if valid { Expect::Ok } else { Expect::Error },
                    m,
                    None,
                );
            }
            Function::GetBoolean => {
                let r = if valid {
                    vr::START_AT_EQUILIBRIUM
                } else {
                    *self.rng.pick(&[vr::V_DA, 9999])
                };
                let mut b = -1;
                let s = fmi2GetBoolean(c, &r, 1, &mut b);
                if s == fmi2OK && b != 0 && b != 1 {
                    self.fail(format!("fmi2GetBoolean gave {b}"));
                }
                self.check(
                    f,
                    format!("fmi2GetBoolean([{r}])"),
                    s,
                    if valid { Expect::Ok } else { Expect::Error },
                    m,
                    None,
                );
            }
            Function::SetBoolean => {
                let r = if valid { vr::START_AT_EQUILIBRIUM } else { vr::V_DA };
                let x: fmi2Boolean = *self.rng.pick(&[0, 1, 1, 7]);
                let s = fmi2SetBoolean(c, &r, 1, &x);
                let e = if valid && early { Expect::Ok } else { Expect::Error };
                self.check(f, format!("fmi2SetBoolean([{r}] = {x})"), s, e, m, None);
            }
            Function::SetReal => self.op_set_real(valid, early, settable_input),
            Function::GetFMUstate => {
                let k = self.rng.below(4);
                if valid && (k < 2 || self.states.is_empty()) {
                    let mut p: fmi2FMUstate = null_mut();
                    let s = fmi2GetFMUstate(c, &mut p);
                    self.check(f, "fmi2GetFMUstate(&NULL)".into(), s, Expect::Ok, m, None);
                    self.add_state(p, st);
                } else if valid {
                    let i = self.rng.below(self.states.len());
                    let mut p = self.states[i].0;
                    let s = fmi2GetFMUstate(c, &mut p);
                    if p != self.states[i].0 {
                        self.fail("fmi2GetFMUstate into an existing state moved it".into());
                    }
                    self.check(f, "fmi2GetFMUstate(&existing)".into(), s, Expect::Ok, m, None);
                    self.states[i].1 = st;
                } else if k % 2 == 0 || self.stale_states.is_empty() {
                    let s = fmi2GetFMUstate(c, null_mut());
                    self.check(f, "fmi2GetFMUstate(NULL)".into(), s, Expect::Error, m, None);
                } else {
                    let mut p = *self.rng.pick(&self.stale_states);
                    let s = fmi2GetFMUstate(c, &mut p);
                    self.check(f, "fmi2GetFMUstate(&freed)".into(), s, Expect::Error, m, None);
                }
            }
            Function::SetFMUstate => {
                if valid && !self.states.is_empty() {
                    // often the newest state (e.g. one just deserialized)
                    let (p, held) = if self.rng.chance(0.5) {
                        *self.states.last().unwrap()
                    } else {
                        *self.rng.pick(&self.states)
                    };
                    let s = fmi2SetFMUstate(c, p);
                    self.check(
                        f,
                        format!("fmi2SetFMUstate(live, holds {})", held.name()),
                        s,
                        Expect::Ok,
                        m,
                        Some(held),
                    );
                } else {
                    let mut junk = [0x5a5a_5a5a_5a5a_5a5au64; 8];
                    let p = match self.rng.below(3) {
                        0 => null_mut(),
                        1 => junk.as_mut_ptr() as fmi2FMUstate,
                        _ => self.stale_states.last().copied().unwrap_or(null_mut()),
                    };
                    let s = fmi2SetFMUstate(c, p);
                    self.check(f, "fmi2SetFMUstate(NULL/junk/freed)".into(), s, Expect::Error, m, None);
                }
            }
            Function::FreeFMUstate => {
                if valid && !self.states.is_empty() {
                    let i = self.rng.below(self.states.len());
                    let (mut p, _) = self.states.swap_remove(i);
                    let old = p;
                    let s = fmi2FreeFMUstate(c, &mut p);
                    if s == fmi2OK {
                        if !p.is_null() {
                            self.fail("fmi2FreeFMUstate did not set the pointer to NULL".into());
                        }
                        self.stale_states.push(old);
                    } else {
                        self.states.push((old, st)); // still live
                    }
                    self.check(f, "fmi2FreeFMUstate(live)".into(), s, Expect::Ok, m, None);
                } else if valid {
                    let mut p: fmi2FMUstate = null_mut();
                    let s = if self.rng.chance(0.5) {
                        fmi2FreeFMUstate(c, &mut p)
                    } else {
                        fmi2FreeFMUstate(c, null_mut())
                    };
                    self.check(f, "fmi2FreeFMUstate(NULL)".into(), s, Expect::Ok, m, None);
                } else {
                    let mut junk = [0u64; 8];
                    let mut p = self
                        .stale_states
                        .last()
                        .copied()
                        .unwrap_or(junk.as_mut_ptr() as fmi2FMUstate);
                    let before = p;
                    let s = fmi2FreeFMUstate(c, &mut p);
                    if p != before {
                        self.fail("a rejected fmi2FreeFMUstate changed the pointer".into());
                    }
                    self.check(f, "fmi2FreeFMUstate(&freed or junk)".into(), s, Expect::Error, m, None);
                }
            }
            Function::SerializedFMUstateSize => {
                let mut size = 0usize;
                if valid && !self.states.is_empty() {
                    let p = self.rng.pick(&self.states).0;
                    let s = fmi2SerializedFMUstateSize(c, p, &mut size);
                    if s == fmi2OK && size == 0 {
                        self.fail("serialized size 0".into());
                    }
                    self.check(f, "fmi2SerializedFMUstateSize(live)".into(), s, Expect::Ok, m, None);
                } else {
                    let p = self.states.first().map_or(null_mut(), |x| x.0);
                    let (d, s) = if self.rng.chance(0.5) || p.is_null() {
                        (
                            "fmi2SerializedFMUstateSize(NULL state)",
                            fmi2SerializedFMUstateSize(c, null_mut(), &mut size),
                        )
                    } else {
                        (
                            "fmi2SerializedFMUstateSize(size NULL)",
                            fmi2SerializedFMUstateSize(c, p, null_mut()),
                        )
                    };
                    self.check(f, d.into(), s, Expect::Error, m, None);
                }
            }
            Function::SerializeFMUstate => {
                if self.states.is_empty() {
                    let mut buf = [0 as fmi2Byte; 16];
                    let s = fmi2SerializeFMUstate(c, null_mut(), buf.as_mut_ptr(), 16);
                    self.check(f, "fmi2SerializeFMUstate(NULL state)".into(), s, Expect::Error, m, None);
                    return;
                }
                let (p, held) = *self.rng.pick(&self.states);
                let mut size = 0usize;
                if fmi2SerializedFMUstateSize(c, p, &mut size) != fmi2OK {
                    size = 64; // illegal in this state: any size
                }
                let mut buf = vec![0 as fmi2Byte; size + 1];
                let (d, s, e) = if valid {
                    (
                        "fmi2SerializeFMUstate(size ok)",
                        fmi2SerializeFMUstate(c, p, buf.as_mut_ptr(), size),
                        Expect::Ok,
                    )
                } else if self.rng.chance(0.5) {
                    (
                        "fmi2SerializeFMUstate(size + 1)",
                        fmi2SerializeFMUstate(c, p, buf.as_mut_ptr(), size + 1),
                        Expect::Error,
                    )
                } else {
                    (
                        "fmi2SerializeFMUstate(bytes NULL)",
                        fmi2SerializeFMUstate(c, p, null_mut(), size),
                        Expect::Error,
                    )
                };
                if s == fmi2OK {
                    let blob: Vec<u8> = buf[..size].iter().map(|&b| b as u8).collect();
                    self.blobs.push((blob, held));
                    if self.blobs.len() > 8 {
                        self.blobs.remove(0);
                    }
                }
                self.check(f, d.into(), s, e, m, None);
            }
            Function::DeSerializeFMUstate => self.op_deserialize(valid),
            Function::GetDirectionalDerivative => {
                let u = [vr::F_ACT];
                let k = [vr::V_DA];
                let dk = [1.0];
                let mut du = [0.0];
                let s = fmi2GetDirectionalDerivative(c, u.as_ptr(), 1, k.as_ptr(), 1, dk.as_ptr(), du.as_mut_ptr());
                self.check(f, "fmi2GetDirectionalDerivative".into(), s, Expect::Error, m, None);
            }
            Function::SetRealInputDerivatives => {
                if valid {
                    let (r, x) = if self.rng.chance(0.5) {
                        (vr::X_S, self.rng.range(-1e-3, 1e-3))
                    } else {
                        (vr::V_DA, self.rng.range(-10.0, 10.0))
                    };
                    let o: fmi2Integer = 1;
                    let (d, s) = if self.rng.chance(0.2) {
                        (
                            "fmi2SetRealInputDerivatives(nvr 0)".to_string(),
                            fmi2SetRealInputDerivatives(c, null(), 0, null(), null()),
                        )
                    } else {
                        (
                            format!("fmi2SetRealInputDerivatives([{r}], 1, {x})"),
                            fmi2SetRealInputDerivatives(c, &r, 1, &o, &x),
                        )
                    };
                    self.check(f, d, s, Expect::Ok, m, None);
                } else {
                    let (r, o, x) = *self.rng.pick(&[
                        (vr::X_S, 0, 0.0),
                        (vr::X_S, 2, 0.0),
                        (vr::X_S, -1, 0.0),
                        (vr::F_ACT, 1, 0.0),
                        (vr::P_S, 1, 0.0),
                        (9999, 1, 0.0),
                        (vr::V_DA, 1, f64::NAN),
                        (vr::X_S, 1, f64::INFINITY),
                    ]);
                    let s = if self.rng.chance(0.1) {
                        fmi2SetRealInputDerivatives(c, &r, 1, null(), &x)
                    } else {
                        fmi2SetRealInputDerivatives(c, &r, 1, &o, &x)
                    };
                    self.check(
                        f,
                        format!("fmi2SetRealInputDerivatives([{r}], {o}, {x})"),
                        s,
                        Expect::Error,
                        m,
                        None,
                    );
                }
            }
            Function::GetRealOutputDerivatives => {
                let r = [vr::F_ACT];
                let o = [1];
                let mut x = [0.0];
                let s = fmi2GetRealOutputDerivatives(c, r.as_ptr(), 1, o.as_ptr(), x.as_mut_ptr());
                self.check(f, "fmi2GetRealOutputDerivatives".into(), s, Expect::Error, m, None);
            }
            Function::DoStep => {
                let t = self.time();
                if valid {
                    let h = self.rng.log_range(1e-7, 0.05);
                    let s = fmi2DoStep(c, t, h, self.rng.below(2) as fmi2Boolean);
                    if s == fmi2OK {
                        self.steps += 1;
                        let t1 = self.time();
                        if t1 != t + h {
                            self.fail(format!("fmi2DoStep({t}, {h}) ended at {t1}"));
                        }
                    }
                    self.check(f, format!("fmi2DoStep({t}, {h:e})"), s, Expect::OkOrDiscard, m, None);
                } else {
                    let (cur, h) = *self.rng.pick(&[
                        (t, 0.0),
                        (t, -1e-3),
                        (t, f64::NAN),
                        (t, f64::INFINITY),
                        (t + 1.0, 1e-3),
                        (t - 1e-3, 1e-3),
                        (f64::NAN, 1e-3),
                    ]);
                    let s = fmi2DoStep(c, cur, h, 1);
                    self.check(f, format!("fmi2DoStep({cur}, {h})"), s, Expect::Error, m, None);
                    if self.time() != t {
                        self.fail(format!(
                            "a rejected fmi2DoStep moved the time from {t} to {}",
                            self.time()
                        ));
                    }
                }
            }
            Function::CancelStep => {
                let s = fmi2CancelStep(c);
                self.check(f, "fmi2CancelStep".into(), s, Expect::Error, m, None);
            }
            Function::GetStatus
            | Function::GetRealStatus
            | Function::GetIntegerStatus
            | Function::GetBooleanStatus
            | Function::GetStringStatus => self.op_status(f, valid),
            // Model Exchange calls: illegal for a Co-Simulation instance in every state
            _ => {
                let (desc, s) = model_exchange::call(c, f, valid);
                self.check(f, desc, s, Expect::Error, m, None);
            }
        }
    }

    /// Free every FMU state and the instance (nothing may leak: see fmu_tests/test_memory.py).
    fn finish(mut self) -> (Tally, u64, u64) {
        unsafe {
            for (mut p, _) in std::mem::take(&mut self.states) {
                let s = fmi2FreeFMUstate(self.c, &mut p);
                // fmi2FreeFMUstate is legal in every state but fatal
                assert_eq!(s, fmi2OK, "fmi2FreeFMUstate at the end");
            }
            fmi2FreeInstance(self.c);
        }
        (self.coverage, self.calls, self.steps)
    }

    /// A random function, weighted towards progress through the state machine.
    fn random_function(&mut self) -> Function {
        // linger in the states that only a restored FMU state reaches
        let rare = matches!(self.mirror, State::StepFailed | State::StepCanceled | State::Error);
        if self.rng.chance(if rare { 0.05 } else { 0.35 }) {
            *self.rng.pick(&[
                Function::SetupExperiment,
                Function::EnterInitializationMode,
                Function::ExitInitializationMode,
                Function::DoStep,
                Function::DoStep,
                Function::DoStep,
                Function::SetReal,
                Function::SetFMUstate,
                Function::DeSerializeFMUstate,
                Function::SerializeFMUstate,
                Function::GetFMUstate,
            ])
        } else if self.rng.chance(0.01) {
            Function::FreeInstance
        } else {
            if rare && self.rng.chance(0.5) {
                // rare states are brief: spend them on calls this sequence has not made there
                let state = self.mirror.name();
                let untried: Vec<Function> = ALL_FUNCTIONS
                    .iter()
                    .copied()
                    .filter(|f| *f != Function::FreeInstance && !self.coverage.contains_key(&(f.name(), state)))
                    .collect();
                if !untried.is_empty() {
                    return *self.rng.pick(&untried);
                }
            }
            let f = *self.rng.pick(&ALL_FUNCTIONS);
            if f == Function::FreeInstance || (f == Function::Reset && self.rng.chance(0.4)) {
                Function::DoStep
            } else {
                f
            }
        }
    }
}

#[test]
fn generated_call_sequences_follow_the_state_table() {
    let sequences: u64 = env_or("JETPIPE_FUZZ_SEQUENCES", 100);
    let calls_per: usize = env_or("JETPIPE_FUZZ_CALLS", 400);
    let seed0: u64 = env_or("JETPIPE_FUZZ_SEED", 0x5EED_0005);
    let started = Instant::now();
    let mut coverage: BTreeMap<(&'static str, &'static str), [u32; 5]> = BTreeMap::new();
    let (mut calls, mut steps) = (0u64, 0u64);
    for k in 0..sequences {
        let seed = seed0.wrapping_add(k);
        let mut fz = Fuzz::new(seed);
        for n in 0..calls_per {
            let f = fz.random_function();
            let valid = fz.rng.chance(0.7);
            unsafe { fz.op(f, valid) };
            if n % 50 == 0 {
                unsafe { fz.null_instance_calls() };
            }
        }
        let (cov, c, s) = fz.finish();
        for (key, v) in cov {
            let e = coverage.entry(key).or_default();
            for i in 0..5 {
                e[i] += v[i];
            }
        }
        calls += c;
        steps += s;
    }
    let pairs = coverage.len();
    let legal: u32 = coverage.values().map(|v| v[0]).sum();
    let illegal: u32 = coverage.values().map(|v| v[1]).sum();
    let (ok, err, disc): (u32, u32, u32) = coverage
        .values()
        .fold((0, 0, 0), |a, v| (a.0 + v[2], a.1 + v[3], a.2 + v[4]));
    println!(
        "call fuzz: {sequences} sequences x {calls_per} calls from seed {seed0:#x}: {calls} calls ({legal} legal, {illegal} illegal; \
         {ok} OK, {err} Error, {disc} Discard), {steps} successful steps, {pairs} (function, state) pairs, {:.1} s",
        started.elapsed().as_secs_f64()
    );
    // every function (but fmi2FreeInstance, exercised separately) in every reachable state
    let mut missing = Vec::new();
    for s in REACHABLE {
        for f in ALL_FUNCTIONS {
            if f != Function::FreeInstance && !coverage.contains_key(&(f.name(), s.name())) {
                missing.push(format!("{} in {}", f.name(), s.name()));
            }
        }
    }
    assert!(
        missing.is_empty() || sequences < 20,
        "never exercised: {missing:?} (raise JETPIPE_FUZZ_SEQUENCES)"
    );
}

/// Deterministic complement: each function, with valid and with invalid arguments, in each
/// reachable state, on a fresh instance brought into that state.
#[test]
fn every_function_in_every_state() {
    let mut n = 0;
    for s in REACHABLE {
        for f in ALL_FUNCTIONS {
            for valid in [true, false] {
                for seed in 0..3u64 {
                    let mut fz = Fuzz::new(seed * 7919 + n);
                    unsafe { bring_to(&mut fz, s) };
                    assert_eq!(fz.mirror, s);
                    unsafe { fz.op(f, valid) };
                    fz.finish();
                    n += 1;
                }
            }
        }
    }
    println!("every function in every state: {n} cases");
}

/// Drive a fresh harness into state `s` (through a recoded FMU state when no ordinary call
/// sequence leads there).
unsafe fn bring_to(fz: &mut Fuzz, s: State) {
    let c = fz.c;
    if s == State::Instantiated {
        return;
    }
    assert_eq!(fmi2SetupExperiment(c, 1, 1e-6, 0.0, 0, 0.0), fmi2OK);
    assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
    fz.mirror = State::InitializationMode;
    if s == State::InitializationMode {
        return;
    }
    set_inputs(c, 2.5, 0.054);
    assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
    assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), fmi2OK);
    fz.mirror = State::StepComplete;
    // keep a live state and a blob for the FMU-state functions
    let mut p: fmi2FMUstate = null_mut();
    assert_eq!(fmi2GetFMUstate(c, &mut p), fmi2OK);
    let mut size = 0;
    assert_eq!(fmi2SerializedFMUstateSize(c, p, &mut size), fmi2OK);
    let mut buf = vec![0 as fmi2Byte; size];
    assert_eq!(fmi2SerializeFMUstate(c, p, buf.as_mut_ptr(), size), fmi2OK);
    let blob: Vec<u8> = buf.iter().map(|&b| b as u8).collect();
    fz.states.push((p, State::StepComplete));
    fz.blobs.push((blob.clone(), State::StepComplete));
    if s == State::StepComplete {
        return;
    }
    if s == State::Terminated {
        assert_eq!(fmi2Terminate(c), fmi2OK);
        fz.mirror = s;
        return;
    }
    let crafted = recode(&blob, s.code());
    let mut q: fmi2FMUstate = null_mut();
    assert_eq!(
        fmi2DeSerializeFMUstate(c, crafted.as_ptr() as *const fmi2Byte, crafted.len(), &mut q),
        fmi2OK
    );
    assert_eq!(fmi2SetFMUstate(c, q), fmi2OK);
    assert_eq!(fmi2FreeFMUstate(c, &mut q), fmi2OK);
    fz.mirror = s;
    assert_eq!(layer_state(c), s);
}

/// A double fmi2FreeInstance and calls on a freed instance are errors without a crash,
/// and (under Valgrind, see fmu_tests/test_memory.py) without reading freed memory.
#[test]
fn repeated_free_and_use_after_free_are_rejected() {
    let sink = Sink::default();
    unsafe {
        for _ in 0..100 {
            let c = instantiate(&sink, "twice");
            let mut p: fmi2FMUstate = null_mut();
            assert_eq!(fmi2GetFMUstate(c, &mut p), fmi2OK);
            let copy = p;
            assert_eq!(fmi2FreeFMUstate(c, &mut p), fmi2OK);
            assert!(p.is_null());
            let mut again = copy;
            assert_eq!(fmi2FreeFMUstate(c, &mut again), fmi2Error, "freeing an FMU state twice");
            assert_eq!(fmi2SetFMUstate(c, copy), fmi2Error, "restoring a freed FMU state");
            fmi2FreeInstance(c);
            fmi2FreeInstance(c);
            assert_eq!(fmi2Reset(c), fmi2Error);
            assert_eq!(fmi2EnterInitializationMode(c), fmi2Error);
            let mut x = 0.0;
            assert_eq!(fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut x), fmi2Error);
        }
    }
}
