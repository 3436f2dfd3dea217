//! Issue 44, call orders of Model Exchange: every FMI 2.0 function in every state of the
//! Model Exchange state machine, through the exported symbols, in generated sequences on an
//! instance made with fmi2ModelExchange (and the Model Exchange calls on a Co-Simulation
//! instance, from the Co-Simulation fuzz in `main.rs`, through [`call`]).
//!
//! A mirror of the state machine predicts each status from the legality table
//! (`Function::legal` for Model Exchange) and the arguments; after every call:
//! * an illegal call -> fmi2Error and "fmi2Xxx: illegal call in state yyy";
//! * a legal call -> the predicted status, never fmi2Fatal, an fmi2Error with a message naming
//!   the function;
//! * the layer's state is the mirror's; in the running states the continuous states, the
//!   derivatives and the event indicators are finite.
//!
//! The `error` state is entered by restoring a serialized FMU state whose layer-state code was
//! rewritten. Bounded like the Co-Simulation fuzz: JETPIPE_FUZZ_SEQUENCES (default 100, a
//! quarter of them here) sequences of JETPIPE_FUZZ_CALLS (default 400) calls.

use std::collections::BTreeSet;
use std::ptr::{null, null_mut};

use super::common::*;
use super::{recode, ALL_FUNCTIONS};
use fmi2::state::{Function, Interface, State};
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::vr;

const NX: usize = 31;
const NZ: usize = 8;

/// The states a Model Exchange instance reaches.
const REACHABLE: [State; 6] = [
    State::Instantiated,
    State::InitializationMode,
    State::EventMode,
    State::ContinuousTimeMode,
    State::Terminated,
    State::Error,
];

/// One call of a Model Exchange function `f` with valid (right lengths, writable arrays, states
/// as read) or invalid arguments (a wrong length, NULL, NaN, a negative pressure).
pub unsafe fn call(c: fmi2Component, f: Function, valid: bool) -> (String, fmi2Status) {
    let mut x = [0.0; NX];
    let mut z = [0.0; NZ];
    match f {
        Function::SetTime => {
            let t = if valid { 0.25 } else { f64::NAN };
            (format!("fmi2SetTime({t})"), fmi2SetTime(c, t))
        }
        Function::SetContinuousStates => {
            if fmi2GetContinuousStates(c, x.as_mut_ptr(), NX) != fmi2OK {
                x = [0.0; NX];
                x[..11].copy_from_slice(&[0.1, 1e-4, 0.0, 0.0, 3e5, 2e5, 6e5, 1e5, 3e5, 2e5, 1e5]);
            }
            if valid {
                x[4] *= 1.0 + 1e-6;
                (
                    "fmi2SetContinuousStates(x)".into(),
                    fmi2SetContinuousStates(c, x.as_ptr(), NX),
                )
            } else {
                match x[0].to_bits() % 4 {
                    0 => (
                        "fmi2SetContinuousStates(nx 5)".into(),
                        fmi2SetContinuousStates(c, x.as_ptr(), 5),
                    ),
                    1 => (
                        "fmi2SetContinuousStates(NULL)".into(),
                        fmi2SetContinuousStates(c, null(), NX),
                    ),
                    2 => {
                        x[1] = f64::NAN;
                        (
                            "fmi2SetContinuousStates(NaN)".into(),
                            fmi2SetContinuousStates(c, x.as_ptr(), NX),
                        )
                    }
                    _ => {
                        x[5] = -1.0;
                        (
                            "fmi2SetContinuousStates(P2 < 0)".into(),
                            fmi2SetContinuousStates(c, x.as_ptr(), NX),
                        )
                    }
                }
            }
        }
        Function::GetDerivatives | Function::GetContinuousStates | Function::GetNominalsOfContinuousStates => {
            let get = match f {
                Function::GetDerivatives => fmi2GetDerivatives,
                Function::GetContinuousStates => fmi2GetContinuousStates,
                _ => fmi2GetNominalsOfContinuousStates,
            };
            if valid {
                (format!("{}(nx {NX})", f.name()), get(c, x.as_mut_ptr(), NX))
            } else if x.as_ptr() as usize % 16 == 0 {
                (format!("{}(nx {NZ})", f.name()), get(c, z.as_mut_ptr(), NZ))
            } else {
                (format!("{}(NULL)", f.name()), get(c, null_mut(), NX))
            }
        }
        Function::GetEventIndicators => {
            if valid {
                (
                    "fmi2GetEventIndicators(ni 8)".into(),
                    fmi2GetEventIndicators(c, z.as_mut_ptr(), NZ),
                )
            } else {
                (
                    "fmi2GetEventIndicators(ni 31)".into(),
                    fmi2GetEventIndicators(c, x.as_mut_ptr(), NX),
                )
            }
        }
        Function::EnterEventMode => ("fmi2EnterEventMode".into(), fmi2EnterEventMode(c)),
        Function::EnterContinuousTimeMode => ("fmi2EnterContinuousTimeMode".into(), fmi2EnterContinuousTimeMode(c)),
        Function::NewDiscreteStates => {
            let mut info = fmi2EventInfo::default();
            if valid {
                (
                    "fmi2NewDiscreteStates(&info)".into(),
                    fmi2NewDiscreteStates(c, &mut info),
                )
            } else {
                (
                    "fmi2NewDiscreteStates(NULL)".into(),
                    fmi2NewDiscreteStates(c, null_mut()),
                )
            }
        }
        Function::CompletedIntegratorStep => {
            let (mut enter, mut terminate) = (7, 7);
            if valid {
                let s = fmi2CompletedIntegratorStep(c, fmi2True, &mut enter, &mut terminate);
                if s == fmi2OK {
                    assert_eq!((enter, terminate), (fmi2False, fmi2False));
                }
                ("fmi2CompletedIntegratorStep".into(), s)
            } else {
                (
                    "fmi2CompletedIntegratorStep(NULL, NULL)".into(),
                    fmi2CompletedIntegratorStep(c, fmi2True, null_mut(), null_mut()),
                )
            }
        }
        _ => panic!("{f:?} is not a Model Exchange function"),
    }
}

struct MeFuzz {
    rng: Rng,
    sink: Box<Sink>,
    c: fmi2Component,
    mirror: State,
    snapshots: Vec<(fmi2FMUstate, State)>,
    blob: Option<Vec<u8>>,
    covered: BTreeSet<(&'static str, &'static str)>,
    trace: Vec<String>,
    calls: u64,
}

impl MeFuzz {
    fn new(seed: u64) -> Self {
        let sink = Box::new(Sink::default());
        let c = unsafe { instantiate_model_exchange(&sink, "me fuzz") };
        MeFuzz {
            rng: Rng(seed),
            sink,
            c,
            mirror: State::Instantiated,
            snapshots: Vec::new(),
            blob: None,
            covered: BTreeSet::new(),
            trace: Vec::new(),
            calls: 0,
        }
    }

    fn fail(&self, what: String) -> ! {
        let start = self.trace.len().saturating_sub(25);
        panic!(
            "{what}\nlast calls (oldest first):\n  {}",
            self.trace[start..].join("\n  ")
        );
    }

    /// Check a call against the table and the prediction `ok` (whether a legal call
    /// succeeds), and move the mirror to `next` when it did.
    fn check(&mut self, f: Function, desc: String, status: fmi2Status, ok: bool, from: usize, next: Option<State>) {
        self.calls += 1;
        let legal = f.legal(self.mirror, Interface::ModelExchange);
        let messages = self.sink.since(from);
        self.trace
            .push(format!("[{}] {desc} -> {}", self.mirror.name(), status_name(status)));
        self.covered.insert((f.name(), self.mirror.name()));
        let has = |s: fmi2Status, needle: &str| messages.iter().any(|m| m.status == s && m.message.contains(needle));
        if status == fmi2Fatal {
            self.fail(format!("{desc}: fmi2Fatal"));
        }
        if !legal {
            let needle = format!("{}: illegal call in state {}", f.name(), self.mirror.name());
            if status != fmi2Error || (logger_available() && !has(fmi2Error, &needle)) {
                self.fail(format!("{desc}: illegal, got {} and {messages:?}", status_name(status)));
            }
        } else {
            let expected = if ok { fmi2OK } else { fmi2Error };
            if status != expected {
                self.fail(format!(
                    "{desc}: expected {}, got {}: {messages:?}",
                    status_name(expected),
                    status_name(status)
                ));
            }
            if status == fmi2Error && logger_available() && !has(fmi2Error, f.name()) {
                self.fail(format!(
                    "{desc}: fmi2Error without a message naming {}: {messages:?}",
                    f.name()
                ));
            }
            if status == fmi2OK {
                if let Some(next) = next {
                    self.mirror = next;
                }
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
        if matches!(self.mirror, State::EventMode | State::ContinuousTimeMode) {
            let mut x = [f64::NAN; NX];
            let mut dx = [f64::NAN; NX];
            let mut z = [f64::NAN; NZ];
            let statuses = unsafe {
                [
                    fmi2GetContinuousStates(self.c, x.as_mut_ptr(), NX),
                    fmi2GetDerivatives(self.c, dx.as_mut_ptr(), NX),
                    fmi2GetEventIndicators(self.c, z.as_mut_ptr(), NZ),
                ]
            };
            let finite = x.iter().chain(&dx).chain(&z).all(|v| v.is_finite());
            if statuses.iter().any(|&s| s != fmi2OK) || !finite {
                self.fail(format!("{desc}: after it {statuses:?} x {x:?} dx {dx:?} z {z:?}"));
            }
        }
    }

    unsafe fn op(&mut self, f: Function, valid: bool) {
        let c = self.c;
        let from = self.sink.len();
        let st = self.mirror;
        match f {
            Function::FreeInstance => {
                fmi2FreeInstance(c);
                self.covered.insert((f.name(), st.name()));
                self.sink.clear();
                self.c = instantiate_model_exchange(&self.sink, "me fuzz");
                self.mirror = State::Instantiated;
                self.trace
                    .push("fmi2FreeInstance, fmi2Instantiate(fmi2ModelExchange)".into());
            }
            Function::SetupExperiment => {
                let t0 = if valid { 0.0 } else { f64::NAN };
                let s = fmi2SetupExperiment(c, fmi2False, 0.0, t0, fmi2False, 0.0);
                self.check(f, format!("fmi2SetupExperiment(start {t0})"), s, valid, from, None);
            }
            Function::EnterInitializationMode => {
                let s = fmi2EnterInitializationMode(c);
                self.check(f, f.name().into(), s, true, from, Some(State::InitializationMode));
            }
            Function::ExitInitializationMode => {
                let s = fmi2ExitInitializationMode(c);
                self.check(f, f.name().into(), s, true, from, Some(State::EventMode));
            }
            Function::Terminate => {
                let s = fmi2Terminate(c);
                self.check(f, f.name().into(), s, true, from, Some(State::Terminated));
            }
            Function::Reset => {
                let s = fmi2Reset(c);
                self.check(f, f.name().into(), s, true, from, Some(State::Instantiated));
            }
            Function::EnterEventMode => {
                let (desc, s) = call(c, f, valid);
                self.check(f, desc, s, true, from, Some(State::EventMode));
            }
            Function::EnterContinuousTimeMode => {
                let (desc, s) = call(c, f, valid);
                self.check(f, desc, s, true, from, Some(State::ContinuousTimeMode));
            }
            Function::SetTime
            | Function::SetContinuousStates
            | Function::GetDerivatives
            | Function::GetEventIndicators
            | Function::GetContinuousStates
            | Function::GetNominalsOfContinuousStates
            | Function::NewDiscreteStates
            | Function::CompletedIntegratorStep => {
                let (desc, s) = call(c, f, valid);
                self.check(f, desc, s, valid, from, None);
            }
            Function::GetReal => {
                let outputs = st != State::Instantiated;
                let vrs = if valid && outputs {
                    OUTPUTS.to_vec()
                } else {
                    vec![vr::V_DA, vr::X_S, vr::P_S]
                };
                let vrs = if valid { vrs } else { vec![9999] };
                let (s, _) = get_reals(c, &vrs);
                self.check(f, format!("fmi2GetReal({vrs:?})"), s, valid, from, None);
            }
            Function::SetReal => {
                let (r, x) = if !valid {
                    (vr::V_DA, 11.0)
                } else if self.rng.chance(0.5) {
                    (vr::V_DA, self.rng.range(-10.0, 10.0))
                } else {
                    (vr::X_S, self.rng.range(0.04, 0.07))
                };
                let s = fmi2SetReal(c, &r, 1, &x);
                self.check(f, format!("fmi2SetReal(vr {r} = {x})"), s, valid, from, None);
            }
            Function::GetInteger
            | Function::SetInteger
            | Function::GetBoolean
            | Function::SetBoolean
            | Function::GetString
            | Function::SetString => {
                let r = [vr::V_DA];
                let mut i = [0 as fmi2Integer; 1];
                let mut sv: [fmi2String; 1] = [null()];
                let (n, pv) = if valid { (0usize, null()) } else { (1usize, r.as_ptr()) };
                let s = match f {
                    Function::GetInteger => fmi2GetInteger(c, pv, n, i.as_mut_ptr()),
                    Function::SetInteger => fmi2SetInteger(c, pv, n, i.as_ptr()),
                    Function::GetBoolean => fmi2GetBoolean(c, pv, n, i.as_mut_ptr()),
                    Function::SetBoolean => fmi2SetBoolean(c, pv, n, i.as_ptr()),
                    Function::GetString => fmi2GetString(c, pv, n, sv.as_mut_ptr()),
                    _ => fmi2SetString(c, pv, n, sv.as_ptr()),
                };
                self.check(f, format!("{}(nvr {n})", f.name()), s, valid, from, None);
            }
            Function::GetFMUstate => {
                let mut p: fmi2FMUstate = null_mut();
                let s = fmi2GetFMUstate(c, &mut p);
                self.check(f, f.name().into(), s, true, from, None);
                if s == fmi2OK {
                    self.snapshots.push((p, st));
                    self.serialize(p);
                }
            }
            Function::SetFMUstate => {
                if valid && !self.snapshots.is_empty() {
                    let (p, holds) = *self.rng.pick(&self.snapshots);
                    let s = fmi2SetFMUstate(c, p);
                    self.check(
                        f,
                        format!("fmi2SetFMUstate(a state in {})", holds.name()),
                        s,
                        true,
                        from,
                        Some(holds),
                    );
                } else {
                    let s = fmi2SetFMUstate(c, null_mut());
                    self.check(f, "fmi2SetFMUstate(NULL)".into(), s, false, from, None);
                }
            }
            Function::FreeFMUstate => {
                let mut p = self.snapshots.pop().map_or(null_mut(), |(p, _)| p);
                let s = fmi2FreeFMUstate(c, &mut p);
                self.check(f, f.name().into(), s, true, from, None);
            }
            Function::SerializedFMUstateSize | Function::SerializeFMUstate => {
                let mut size = 0usize;
                let mut buf = [0 as fmi2Byte; 8];
                let s = if f == Function::SerializedFMUstateSize {
                    fmi2SerializedFMUstateSize(c, null_mut(), &mut size)
                } else {
                    fmi2SerializeFMUstate(c, null_mut(), buf.as_mut_ptr(), 8)
                };
                self.check(f, format!("{}(NULL state)", f.name()), s, false, from, None);
            }
            Function::DeSerializeFMUstate => {
                // the error state, through a serialized state whose layer state is rewritten
                let crafted = match (&self.blob, valid) {
                    (Some(blob), true) => recode(blob, State::Error.code() | fmi2::fmu_state::MODEL_EXCHANGE_BIT),
                    _ => b"not an FMU state".to_vec(),
                };
                let mut q: fmi2FMUstate = null_mut();
                let s = fmi2DeSerializeFMUstate(c, crafted.as_ptr() as *const fmi2Byte, crafted.len(), &mut q);
                let ok = valid && self.blob.is_some();
                self.check(f, format!("fmi2DeSerializeFMUstate(valid {ok})"), s, ok, from, None);
                if s == fmi2OK {
                    self.snapshots.push((q, State::Error));
                }
            }
            // Co-Simulation calls (and fmi2GetDirectionalDerivative, never provided): errors
            _ => {
                let mut r = 0.0;
                let mut status = 0;
                let s = match f {
                    Function::DoStep => fmi2DoStep(c, 0.0, 1e-3, fmi2True),
                    Function::CancelStep => fmi2CancelStep(c),
                    Function::GetStatus => fmi2GetStatus(c, fmi2DoStepStatus, &mut status),
                    Function::GetRealStatus => fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &mut r),
                    Function::SetRealInputDerivatives => fmi2SetRealInputDerivatives(c, &vr::V_DA, 1, &1, &0.5),
                    Function::GetRealOutputDerivatives => fmi2GetRealOutputDerivatives(c, &vr::F_ACT, 1, &1, &mut r),
                    Function::GetDirectionalDerivative => {
                        fmi2GetDirectionalDerivative(c, &vr::F_ACT, 1, &vr::V_DA, 1, &1.0, &mut r)
                    }
                    Function::SetDebugLogging => fmi2SetDebugLogging(c, fmi2True, 0, null()),
                    Function::GetIntegerStatus => fmi2GetIntegerStatus(c, fmi2DoStepStatus, &mut status),
                    Function::GetBooleanStatus => fmi2GetBooleanStatus(c, fmi2Terminated, &mut status),
                    _ => fmi2GetStringStatus(c, fmi2PendingStatus, &mut null()),
                };
                let ok = f == Function::SetDebugLogging;
                self.check(f, f.name().into(), s, ok, from, None);
            }
        }
    }

    /// Keep the bytes of an FMU state taken in a running state (for the crafted error state).
    unsafe fn serialize(&mut self, p: fmi2FMUstate) {
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(self.c, p, &mut size), fmi2OK);
        let mut buf = vec![0 as fmi2Byte; size];
        assert_eq!(fmi2SerializeFMUstate(self.c, p, buf.as_mut_ptr(), size), fmi2OK);
        self.blob = Some(buf.iter().map(|&b| b as u8).collect());
    }

    fn finish(mut self) -> BTreeSet<(&'static str, &'static str)> {
        unsafe {
            for (mut p, _) in std::mem::take(&mut self.snapshots) {
                assert_eq!(fmi2FreeFMUstate(self.c, &mut p), fmi2OK);
            }
            fmi2FreeInstance(self.c);
        }
        std::mem::take(&mut self.covered)
    }
}

/// Random Model Exchange call sequences on instances made for Model Exchange: each call's
/// status is the legality table's and the arguments', the layer's state is the state
/// machine's, and the states, derivatives and event indicators stay finite; every function
/// meets every reachable state.
#[test]
fn model_exchange_call_sequences_follow_the_state_machine_and_never_crash() {
    let sequences: u64 = env_or("JETPIPE_FUZZ_SEQUENCES", 100u64).div_ceil(4);
    let calls: u64 = env_or("JETPIPE_FUZZ_CALLS", 400u64);
    let seed0: u64 = env_or("JETPIPE_FUZZ_SEED", 0x4D45_F022u64);
    let mut covered = BTreeSet::new();
    let mut total = 0;
    for k in 0..sequences {
        let mut fz = MeFuzz::new(seed0 + k);
        for _ in 0..calls {
            // bias towards the calls that move through the state machine
            let f = if fz.rng.chance(0.3) {
                *fz.rng.pick(&[
                    Function::EnterInitializationMode,
                    Function::ExitInitializationMode,
                    Function::EnterEventMode,
                    Function::EnterContinuousTimeMode,
                    Function::SetContinuousStates,
                    Function::SetTime,
                    Function::GetFMUstate,
                    Function::DeSerializeFMUstate,
                ])
            } else {
                *fz.rng.pick(&ALL_FUNCTIONS)
            };
            if f == Function::FreeInstance && !fz.rng.chance(0.1) {
                continue;
            }
            let valid = fz.rng.chance(0.7);
            unsafe { fz.op(f, valid) };
        }
        total += fz.calls;
        covered.extend(fz.finish());
    }
    println!(
        "model exchange call fuzz: {sequences} sequences, {total} calls, {} (function, state) pairs",
        covered.len()
    );
    let missing: Vec<String> = REACHABLE
        .iter()
        .flat_map(|s| ALL_FUNCTIONS.iter().map(move |f| (*f, *s)))
        .filter(|(f, s)| *f != Function::FreeInstance && !covered.contains(&(f.name(), s.name())))
        .map(|(f, s)| format!("{} in {}", f.name(), s.name()))
        .collect();
    assert!(missing.is_empty() || sequences < 20, "never exercised: {missing:?}");
}
