//! Issue 44, call orders of FMI 3.0: every exported `fmi3*` function that takes an instance, in
//! generated sequences on instances made by `fmi3InstantiateCoSimulation` and
//! `fmi3InstantiateModelExchange`, with valid and invalid arguments (NULL arrays, wrong lengths,
//! NaN, a wrong time, value references of other types or none), and now and then an `fmi2*` call
//! on the FMI 3.0 instance.
//!
//! A mirror of the state machine predicts each call's legality from `fmi3::state`'s table; after
//! every call:
//! * an illegal call -> fmi3Error and "fmi3Xxx: illegal call in state yyy" (FMI 3.0's names);
//! * a legal call -> never fmi3Fatal; fmi3OK for the calls that cannot fail with valid arguments,
//!   fmi3Error for the calls the FMU does not support and for invalid arguments; every fmi3Error
//!   and fmi3Discard with a message of that status that names the function;
//! * an `fmi2*` call -> fmi2Error, "the instance was made by fmi3Instantiate", the state unchanged;
//! * the layer's state is the mirror's.
//!
//! Bounded like the FMI 2.0 fuzz: JETPIPE_FUZZ_SEQUENCES (default 100, a quarter of them here) of
//! JETPIPE_FUZZ_CALLS (default 400) calls; JETPIPE_FUZZ_SEED picks the first seed.

use std::ffi::{CStr, CString};
use std::os::raw::{c_char, c_int, c_void};
use std::ptr::{null, null_mut};
use std::sync::Mutex;

use super::common::*;
use fmi2::state::{Call, Interface, State, Version};
use fmi3::state::Function;
use fmi3::types::*;
use jetpipe::fmu3_exports::*;
use jetpipe::variables::vr;

const NX: usize = 31;
const NZ: usize = 8;

/// One instance's messages: (status, message).
#[derive(Default)]
pub struct Sink3(pub Mutex<Vec<(c_int, String)>>);

impl Sink3 {
    fn len(&self) -> usize {
        self.0.lock().unwrap().len()
    }
    fn since(&self, n: usize) -> Vec<(c_int, String)> {
        self.0.lock().unwrap()[n..].to_vec()
    }
}

unsafe extern "C" fn log3(env: *mut c_void, status: c_int, _category: *const c_char, message: *const c_char) {
    if env.is_null() {
        return;
    }
    let sink = &*(env as *const Sink3);
    let text = if message.is_null() {
        "<NULL>".to_owned()
    } else {
        CStr::from_ptr(message).to_string_lossy().into_owned()
    };
    sink.0.lock().unwrap().push((status, text));
}

/// A new FMI 3.0 instance of `interface`, logging into `sink`.
pub unsafe fn instantiate3(sink: &Sink3, interface: Interface) -> fmi3Instance {
    let name = CString::new("fuzz3").unwrap();
    let token = guid();
    let env = sink as *const Sink3 as *mut c_void;
    let c = match interface {
        Interface::CoSimulation => fmi3InstantiateCoSimulation(
            name.as_ptr(),
            token.as_ptr(),
            null(),
            0,
            0,
            0,
            0,
            null(),
            0,
            env,
            Some(log3),
            None,
        ),
        Interface::ModelExchange => {
            fmi3InstantiateModelExchange(name.as_ptr(), token.as_ptr(), null(), 0, 0, env, Some(log3))
        }
    };
    assert!(!c.is_null(), "fmi3Instantiate* returned NULL");
    c
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Expect {
    Ok,
    Error,
    Any,
}

/// The functions the FMU does not support: fmi3Error wherever the table allows them.
fn unsupported(f: Function) -> bool {
    use Function::*;
    matches!(
        f,
        GetNumberOfVariableDependencies
            | GetVariableDependencies
            | GetDirectionalDerivative
            | GetAdjointDerivative
            | EnterConfigurationMode
            | ExitConfigurationMode
            | EvaluateDiscreteStates
            | GetOutputDerivatives
            | EnterStepMode
            | ActivateModelPartition
    )
}

/// One call of `f` with valid or invalid arguments; what to expect of a legal call.
unsafe fn call(c: fmi3Instance, f: Function, valid: bool, state: State) -> (String, fmi3Status, Expect) {
    use Function::*;
    let mut x = [0.0f64; NX];
    let mut z = [0.0f64; NZ];
    let mut b = [0u8; 6];
    let mut t = 0.0f64;
    let mut n = 0usize;
    let ok_if = |v: bool| if v { Expect::Ok } else { Expect::Error };
    let outputs = [vr::F_ACT, vr::P1, vr::P2];
    let v_da = [vr::V_DA];
    let readable_outputs = state != State::Instantiated;
    match f {
        SetDebugLogging => (
            "fmi3SetDebugLogging".into(),
            fmi3SetDebugLogging(c, 1, 0, null()),
            Expect::Ok,
        ),
        FreeInstance => unreachable!("freed at the end of a sequence"),
        EnterInitializationMode => {
            let tol = if valid { 1e-6 } else { -1.0 };
            (
                format!("fmi3EnterInitializationMode(tol {tol})"),
                fmi3EnterInitializationMode(c, 1, tol, 0.0, 0, 0.0),
                ok_if(valid),
            )
        }
        ExitInitializationMode => (
            "fmi3ExitInitializationMode".into(),
            fmi3ExitInitializationMode(c),
            Expect::Ok,
        ),
        EnterEventMode => ("fmi3EnterEventMode".into(), fmi3EnterEventMode(c), Expect::Ok),
        Terminate => ("fmi3Terminate".into(), fmi3Terminate(c), Expect::Ok),
        Reset => ("fmi3Reset".into(), fmi3Reset(c), Expect::Ok),
        GetFloat64 => {
            let (p, nv) = if valid { (outputs.as_ptr(), 3) } else { (null(), 3) };
            let expect = if valid { ok_if(readable_outputs) } else { Expect::Error };
            (
                "fmi3GetFloat64(outputs)".into(),
                fmi3GetFloat64(c, p, 3, x.as_mut_ptr(), nv),
                expect,
            )
        }
        SetFloat64 => {
            let value = [if valid { 3.0 } else { f64::NAN }];
            (
                format!("fmi3SetFloat64(v_DA = {})", value[0]),
                fmi3SetFloat64(c, v_da.as_ptr(), 1, value.as_ptr(), 1),
                ok_if(valid),
            )
        }
        GetBoolean | SetBoolean => {
            let r = [vr::START_AT_EQUILIBRIUM];
            let s = if f == GetBoolean {
                fmi3GetBoolean(c, r.as_ptr(), 1, b.as_mut_ptr(), if valid { 1 } else { 2 })
            } else {
                b[0] = 1;
                fmi3SetBoolean(c, r.as_ptr(), 1, b.as_ptr(), if valid { 1 } else { 2 })
            };
            let settable = f == GetBoolean || matches!(state, State::Instantiated | State::InitializationMode);
            (
                format!("{}(start_at_equilibrium)", f.name()),
                s,
                ok_if(valid && settable),
            )
        }
        GetInt32 | SetInt32 | GetFloat32 | SetFloat32 | GetInt8 | SetInt8 | GetUInt8 | SetUInt8 | GetInt16
        | SetInt16 | GetUInt16 | SetUInt16 | GetUInt32 | SetUInt32 | GetInt64 | SetInt64 | GetUInt64 | SetUInt64
        | GetString | SetString | GetBinary | SetBinary | GetClock | SetClock | GetIntervalDecimal
        | GetIntervalFraction | GetShiftDecimal | GetShiftFraction | SetIntervalDecimal | SetIntervalFraction
        | SetShiftDecimal | SetShiftFraction => {
            // the model has no variable of these types: none asked is fine, v_DA is an error
            let nvr = usize::from(!valid);
            let mut buffer = [0u64; 4];
            let p = buffer.as_mut_ptr();
            let s = match f {
                GetInt32 => fmi3GetInt32(c, v_da.as_ptr(), nvr, p as *mut i32, nvr),
                SetInt32 => fmi3SetInt32(c, v_da.as_ptr(), nvr, p as *const i32, nvr),
                GetFloat32 => fmi3GetFloat32(c, v_da.as_ptr(), nvr, p as *mut f32, nvr),
                SetFloat32 => fmi3SetFloat32(c, v_da.as_ptr(), nvr, p as *const f32, nvr),
                GetInt8 => fmi3GetInt8(c, v_da.as_ptr(), nvr, p as *mut i8, nvr),
                SetInt8 => fmi3SetInt8(c, v_da.as_ptr(), nvr, p as *const i8, nvr),
                GetUInt8 => fmi3GetUInt8(c, v_da.as_ptr(), nvr, p as *mut u8, nvr),
                SetUInt8 => fmi3SetUInt8(c, v_da.as_ptr(), nvr, p as *const u8, nvr),
                GetInt16 => fmi3GetInt16(c, v_da.as_ptr(), nvr, p as *mut i16, nvr),
                SetInt16 => fmi3SetInt16(c, v_da.as_ptr(), nvr, p as *const i16, nvr),
                GetUInt16 => fmi3GetUInt16(c, v_da.as_ptr(), nvr, p as *mut u16, nvr),
                SetUInt16 => fmi3SetUInt16(c, v_da.as_ptr(), nvr, p as *const u16, nvr),
                GetUInt32 => fmi3GetUInt32(c, v_da.as_ptr(), nvr, p as *mut u32, nvr),
                SetUInt32 => fmi3SetUInt32(c, v_da.as_ptr(), nvr, p as *const u32, nvr),
                GetInt64 => fmi3GetInt64(c, v_da.as_ptr(), nvr, p as *mut i64, nvr),
                SetInt64 => fmi3SetInt64(c, v_da.as_ptr(), nvr, p as *const i64, nvr),
                GetUInt64 => fmi3GetUInt64(c, v_da.as_ptr(), nvr, p, nvr),
                SetUInt64 => fmi3SetUInt64(c, v_da.as_ptr(), nvr, p as *const u64, nvr),
                GetString => fmi3GetString(c, v_da.as_ptr(), nvr, p as *mut fmi3String, nvr),
                SetString => fmi3SetString(c, v_da.as_ptr(), nvr, p as *const fmi3String, nvr),
                GetBinary => fmi3GetBinary(c, v_da.as_ptr(), nvr, null_mut(), null_mut(), nvr),
                SetBinary => fmi3SetBinary(c, v_da.as_ptr(), nvr, null(), null(), nvr),
                GetClock => fmi3GetClock(c, v_da.as_ptr(), nvr, p as *mut u8),
                SetClock => fmi3SetClock(c, v_da.as_ptr(), nvr, p as *const u8),
                GetIntervalDecimal => fmi3GetIntervalDecimal(c, v_da.as_ptr(), nvr, null_mut(), null_mut()),
                GetIntervalFraction => {
                    fmi3GetIntervalFraction(c, v_da.as_ptr(), nvr, null_mut(), null_mut(), null_mut())
                }
                GetShiftDecimal => fmi3GetShiftDecimal(c, v_da.as_ptr(), nvr, null_mut()),
                GetShiftFraction => fmi3GetShiftFraction(c, v_da.as_ptr(), nvr, null_mut(), null_mut()),
                SetIntervalDecimal => fmi3SetIntervalDecimal(c, v_da.as_ptr(), nvr, null()),
                SetIntervalFraction => fmi3SetIntervalFraction(c, v_da.as_ptr(), nvr, null(), null()),
                SetShiftDecimal => fmi3SetShiftDecimal(c, v_da.as_ptr(), nvr, null()),
                _ => fmi3SetShiftFraction(c, v_da.as_ptr(), nvr, null(), null()),
            };
            (format!("{}(nvr = {nvr})", f.name()), s, ok_if(valid))
        }
        GetNumberOfVariableDependencies => (
            f.name().into(),
            fmi3GetNumberOfVariableDependencies(c, vr::F_ACT, &mut n),
            Expect::Error,
        ),
        GetVariableDependencies => (
            f.name().into(),
            fmi3GetVariableDependencies(c, vr::F_ACT, null_mut(), null_mut(), null_mut(), null_mut(), 0),
            Expect::Error,
        ),
        GetFMUState | SetFMUState | FreeFMUState | SerializedFMUStateSize | SerializeFMUState | DeserializeFMUState => {
            // a whole round trip; the legality of `f` is what the mirror checks
            let mut s: fmi3FMUState = null_mut();
            let status = match f {
                GetFMUState => fmi3GetFMUState(c, if valid { &mut s } else { null_mut() }),
                SetFMUState => fmi3SetFMUState(c, null_mut()),
                FreeFMUState => fmi3FreeFMUState(c, &mut s),
                SerializedFMUStateSize => fmi3SerializedFMUStateSize(c, null_mut(), &mut n),
                SerializeFMUState => fmi3SerializeFMUState(c, null_mut(), b.as_mut_ptr(), 0),
                _ => fmi3DeserializeFMUState(c, b.as_ptr(), if valid { 0 } else { 6 }, &mut s),
            };
            let expect = match f {
                GetFMUState => ok_if(valid),
                FreeFMUState => Expect::Ok,
                _ => Expect::Error,
            };
            if !s.is_null() {
                let mut size = 0usize;
                assert_eq!(fmi3SerializedFMUStateSize(c, s, &mut size), fmi3OK);
                let mut bytes = vec![0u8; size];
                assert_eq!(fmi3SerializeFMUState(c, s, bytes.as_mut_ptr(), size), fmi3OK);
                let mut back: fmi3FMUState = null_mut();
                assert_eq!(fmi3DeserializeFMUState(c, bytes.as_ptr(), size, &mut back), fmi3OK);
                assert_eq!(fmi3SetFMUState(c, back), fmi3OK, "restoring the state just taken");
                assert_eq!(fmi3FreeFMUState(c, &mut back), fmi3OK);
                assert_eq!(fmi3FreeFMUState(c, &mut s), fmi3OK);
            }
            (format!("{}(valid {valid})", f.name()), status, expect)
        }
        GetDirectionalDerivative | GetAdjointDerivative => {
            let s = if f == GetDirectionalDerivative {
                fmi3GetDirectionalDerivative(c, null(), 0, null(), 0, null(), 0, null_mut(), 0)
            } else {
                fmi3GetAdjointDerivative(c, null(), 0, null(), 0, null(), 0, null_mut(), 0)
            };
            (f.name().into(), s, Expect::Error)
        }
        EnterConfigurationMode => (f.name().into(), fmi3EnterConfigurationMode(c), Expect::Error),
        ExitConfigurationMode => (f.name().into(), fmi3ExitConfigurationMode(c), Expect::Error),
        EvaluateDiscreteStates => (f.name().into(), fmi3EvaluateDiscreteStates(c), Expect::Error),
        UpdateDiscreteStates => {
            let p = b.as_mut_ptr();
            let last = if valid { &mut t as *mut f64 } else { null_mut() };
            let s = fmi3UpdateDiscreteStates(c, p, p.add(1), p.add(2), p.add(3), p.add(4), last);
            (f.name().into(), s, ok_if(valid))
        }
        EnterContinuousTimeMode => (f.name().into(), fmi3EnterContinuousTimeMode(c), Expect::Ok),
        CompletedIntegratorStep => {
            let p = b.as_mut_ptr();
            let s = fmi3CompletedIntegratorStep(c, 1, p, if valid { p.add(1) } else { null_mut() });
            (f.name().into(), s, ok_if(valid))
        }
        SetTime => {
            let time = if valid { model_time(c) + 1e-4 } else { f64::INFINITY };
            (format!("fmi3SetTime({time})"), fmi3SetTime(c, time), ok_if(valid))
        }
        SetContinuousStates => {
            let read = fmi3GetContinuousStates(c, x.as_mut_ptr(), NX) == fmi3OK;
            let s = fmi3SetContinuousStates(c, x.as_ptr(), if valid { NX } else { NX - 1 });
            (f.name().into(), s, ok_if(valid && read))
        }
        GetContinuousStateDerivatives | GetContinuousStates | GetNominalsOfContinuousStates => {
            let nx = if valid { NX } else { NX + 1 };
            let mut big = [0.0; NX + 1];
            let s = match f {
                GetContinuousStateDerivatives => fmi3GetContinuousStateDerivatives(c, big.as_mut_ptr(), nx),
                GetContinuousStates => fmi3GetContinuousStates(c, big.as_mut_ptr(), nx),
                _ => fmi3GetNominalsOfContinuousStates(c, big.as_mut_ptr(), nx),
            };
            if s == fmi3OK {
                assert!(big[..NX].iter().all(|v| v.is_finite()), "{}: {big:?}", f.name());
            }
            (format!("{}(nx {nx})", f.name()), s, ok_if(valid))
        }
        GetEventIndicators => {
            let s = fmi3GetEventIndicators(c, z.as_mut_ptr(), if valid { NZ } else { 0 });
            (f.name().into(), s, ok_if(valid))
        }
        GetNumberOfEventIndicators | GetNumberOfContinuousStates => {
            let s = if f == GetNumberOfEventIndicators {
                fmi3GetNumberOfEventIndicators(c, if valid { &mut n } else { null_mut() })
            } else {
                fmi3GetNumberOfContinuousStates(c, if valid { &mut n } else { null_mut() })
            };
            if s == fmi3OK {
                assert_eq!(n, if f == GetNumberOfEventIndicators { NZ } else { NX });
            }
            (f.name().into(), s, ok_if(valid))
        }
        EnterStepMode => (f.name().into(), fmi3EnterStepMode(c), Expect::Error),
        GetOutputDerivatives => (
            f.name().into(),
            fmi3GetOutputDerivatives(c, null(), 0, null(), null_mut(), 0),
            Expect::Error,
        ),
        DoStep => {
            let now = model_time(c);
            let current = if valid { now } else { now + 1.0 };
            let p = b.as_mut_ptr();
            let s = fmi3DoStep(c, current, 1e-3, 1, p, p.add(1), p.add(2), &mut t);
            if s == fmi3OK {
                assert_eq!(&b[..3], &[0, 0, 0]);
                assert!((t - (now + 1e-3)).abs() < 1e-12, "lastSuccessfulTime {t}");
            }
            (
                format!("fmi3DoStep({current})"),
                s,
                if valid { Expect::Any } else { Expect::Error },
            )
        }
        ActivateModelPartition => (f.name().into(), fmi3ActivateModelPartition(c, 0, 0.0), Expect::Error),
    }
}

/// The state after a successful call of `f` from `state`.
fn next_state(f: Function, state: State, interface: Interface) -> State {
    use Function::*;
    match f {
        EnterInitializationMode => State::InitializationMode,
        ExitInitializationMode => match interface {
            Interface::CoSimulation => State::StepComplete,
            Interface::ModelExchange => State::EventMode,
        },
        EnterEventMode => State::EventMode,
        EnterContinuousTimeMode => State::ContinuousTimeMode,
        Terminate => State::Terminated,
        Reset => State::Instantiated,
        _ => state,
    }
}

/// Runs one sequence; returns the number of calls that were legal.
fn run_sequence(seed: u64, calls: usize, interface: Interface) -> usize {
    let mut rng = Rng(seed);
    let sink = Sink3::default();
    let functions: Vec<Function> = Function::all().filter(|&f| f != Function::FreeInstance).collect();
    let mut legal_calls = 0;
    unsafe {
        let c = instantiate3(&sink, interface);
        let mut state = State::Instantiated;
        assert_eq!(fmi3SetFloat64(c, [vr::V_DA].as_ptr(), 1, [2.5].as_ptr(), 1), fmi3OK);
        for k in 0..calls {
            // bias towards the calls that move the state machine on
            let f = if rng.chance(0.3) {
                *rng.pick(&[
                    Function::EnterInitializationMode,
                    Function::ExitInitializationMode,
                    Function::DoStep,
                    Function::EnterEventMode,
                    Function::EnterContinuousTimeMode,
                    Function::UpdateDiscreteStates,
                    Function::SetTime,
                    Function::GetFloat64,
                ])
            } else if rng.chance(0.02) {
                Function::Reset
            } else {
                *rng.pick(&functions)
            };
            let valid = rng.chance(0.8);
            let before = sink.len();
            let (what, status, expect) = call(c, f, valid, state);
            let context = format!(
                "seed {seed}, call {k}: {what} in {} ({})",
                state.name_in(Version::Fmi3),
                interface.name()
            );
            let messages = sink.since(before);
            assert_ne!(status, fmi3Fatal, "{context}: fmi3Fatal; {messages:?}");
            if !Call::legal(f, state, interface) {
                assert_eq!(status, fmi3Error, "{context}: an illegal call");
                let wanted = format!("{}: illegal call in state {}", f.name(), state.name_in(Version::Fmi3));
                assert!(
                    messages.iter().any(|(s, m)| *s == fmi3Error && m.starts_with(&wanted)),
                    "{context}: {messages:?}"
                );
            } else {
                legal_calls += 1;
                let unsupported_call = unsupported(f);
                match (expect, unsupported_call) {
                    (_, true) | (Expect::Error, _) => assert_eq!(status, fmi3Error, "{context}: {messages:?}"),
                    (Expect::Ok, false) => assert_eq!(status, fmi3OK, "{context}: {messages:?}"),
                    (Expect::Any, false) => {}
                }
                if status == fmi3Error || status == fmi3Discard {
                    assert!(
                        messages.iter().any(|(s, m)| *s == status && m.starts_with(f.name())),
                        "{context}: no message naming the call: {messages:?}"
                    );
                }
                if status == fmi3OK {
                    state = next_state(f, state, interface);
                } else if status == fmi3Discard {
                    state = State::StepFailed;
                }
            }
            if rng.chance(0.02) {
                // an FMI 2.0 call on the FMI 3.0 instance
                let before = sink.len();
                let s = jetpipe::fmu_exports::fmi2Terminate(c);
                assert_eq!(
                    s,
                    fmi2::types::fmi2Error,
                    "{context}: fmi2Terminate on an FMI 3.0 instance"
                );
                let m = sink.since(before);
                assert!(
                    m.iter()
                        .any(|(_, m)| m.contains("the instance was made by fmi3Instantiate")),
                    "{context}: {m:?}"
                );
            }
            assert_eq!(
                layer_state(c),
                state,
                "{context}: the layer's state is not the mirror's"
            );
        }
        fmi3FreeInstance(c);
        // a freed instance is refused without being read
        assert_eq!(fmi3Terminate(c), fmi3Error);
        fmi3FreeInstance(c);
    }
    legal_calls
}

#[test]
fn generated_fmi3_call_sequences_follow_the_fmi3_state_table() {
    let sequences: u64 = env_or("JETPIPE_FUZZ_SEQUENCES", 100u64).div_ceil(4).max(2);
    let calls: usize = env_or("JETPIPE_FUZZ_CALLS", 400);
    let seed0: u64 = env_or("JETPIPE_FUZZ_SEED", 0x4649_3300u64);
    let mut legal = 0;
    let mut total = 0;
    for k in 0..sequences {
        for interface in [Interface::CoSimulation, Interface::ModelExchange] {
            legal += run_sequence(
                seed0 + 2 * k + (interface == Interface::ModelExchange) as u64,
                calls,
                interface,
            );
            total += calls;
        }
    }
    println!("FMI 3.0 call fuzz: {total} calls, {legal} legal, from seed {seed0:#x}");
    assert!(
        legal > total / 4,
        "too few legal calls ({legal} of {total}) to exercise the FMU"
    );
}

#[test]
fn every_fmi3_function_is_tried_in_every_reachable_state_of_both_interfaces() {
    let sink = Sink3::default();
    let mut tried = 0;
    for interface in [Interface::CoSimulation, Interface::ModelExchange] {
        let path: &[Function] = match interface {
            Interface::CoSimulation => &[
                Function::EnterInitializationMode,
                Function::ExitInitializationMode,
                Function::Terminate,
            ],
            Interface::ModelExchange => &[
                Function::EnterInitializationMode,
                Function::ExitInitializationMode,
                Function::EnterContinuousTimeMode,
                Function::Terminate,
            ],
        };
        for depth in 0..=path.len() {
            for f in Function::all().filter(|&f| f != Function::FreeInstance) {
                unsafe {
                    let c = instantiate3(&sink, interface);
                    let mut state = State::Instantiated;
                    for &g in &path[..depth] {
                        let (_, s, _) = call(c, g, true, state);
                        assert_eq!(s, fmi3OK, "{} on the way", g.name());
                        state = next_state(g, state, interface);
                    }
                    let before = sink.len();
                    let (what, status, _) = call(c, f, true, state);
                    assert_ne!(status, fmi3Fatal, "{what}");
                    if !Call::legal(f, state, interface) {
                        assert_eq!(status, fmi3Error, "{what} in {state:?}");
                        assert!(sink
                            .since(before)
                            .iter()
                            .any(|(_, m)| m.contains("illegal call in state")));
                    }
                    tried += 1;
                    fmi3FreeInstance(c);
                }
            }
        }
    }
    assert!(tried > 500, "{tried}");
}
