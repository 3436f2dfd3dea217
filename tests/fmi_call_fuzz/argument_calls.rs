//! The calls of the fuzzer whose arguments take more than a few lines to build: fmi2SetReal
//! with valid and invalid values, fmi2DeSerializeFMUstate with crafted and corrupted states,
//! the status queries, and every function on a NULL or freed instance.

use super::*;

impl Fuzz {
    pub(super) unsafe fn op_set_real(&mut self, valid: bool, early: bool, settable_input: bool) {
        let f = Function::SetReal;
        let c = self.c;
        let m = self.mark();
        if valid {
            let kind = self.rng.below(4);
            let (vrs, xs, e): (Vec<u32>, Vec<f64>, Expect) = match kind {
                0 | 1 => (
                    vec![vr::V_DA, vr::X_S, vr::A_S],
                    vec![
                        self.rng.range(-10.0, 10.0),
                        self.rng.range(0.03, 0.09),
                        self.rng.range(-50.0, 50.0),
                    ],
                    if settable_input { Expect::Ok } else { Expect::Error },
                ),
                2 => {
                    let (r, scale) = *self.rng.pick(&[
                        (vr::P_S, 0.1),
                        (vr::K_SPRING, 0.5),
                        (vr::C_D, 0.2),
                        (vr::P1_START, 0.5),
                        (vr::T_GAS, 0.1),
                    ]);
                    let start = VARIABLES.iter().find(|v| v.value_reference == r).unwrap().start;
                    let x = start * self.rng.range(1.0 - scale, 1.0 + scale);
                    (vec![r], vec![x], if early { Expect::Ok } else { Expect::Error })
                }
                _ => (vec![], vec![], Expect::Ok),
            };
            let (pv, px) = if vrs.is_empty() {
                (null(), null())
            } else {
                (vrs.as_ptr(), xs.as_ptr())
            };
            let s = fmi2SetReal(c, pv, vrs.len(), px);
            self.check(f, format!("fmi2SetReal({vrs:?} = {xs:?})"), s, e, m, None);
            return;
        }
        // invalid: the value must not be applied
        let (r, x) = *self.rng.pick(&[
            (vr::V_DA, f64::NAN),
            (vr::V_DA, f64::INFINITY),
            (vr::V_DA, f64::NEG_INFINITY),
            (vr::X_S, f64::NAN),
            (vr::X_S, 0.0),
            (vr::X_S, 0.026),
            (vr::X_S, 0.096),
            (vr::X_S, -1.0),
            (vr::X_S, 1e300),
            (vr::P_S, f64::NAN),
            (vr::P_S, -1.0),
            (vr::P_S, 0.0),
            (vr::GAMMA, 1.0),
            (vr::D_CYL, 0.0),
            (vr::C_D, -0.1),
            (vr::T_GAS, f64::INFINITY),
            (vr::F_ACT, 1.0),
            (vr::P1, 1e5),
            (vr::START_AT_EQUILIBRIUM, 1.0),
            (vr::A_S, f64::NAN),
            (vr::A_S, 2e4),
            (4, 1.0),
            (9999, 1.0),
            (u32::MAX, 1.0),
        ]);
        // Before initialisation ends, a finite x_s outside the cylinder is taken (a master may
        // start its connectors at 0) and checked by fmi2ExitInitializationMode: only NaN is
        // refused at once there.
        let (r, x) = if early && r == vr::X_S && x.is_finite() {
            (r, f64::NAN)
        } else {
            (r, x)
        };
        let known = VARIABLES
            .iter()
            .any(|v| v.value_reference == r && v.var_type == fmi2::model::VarType::Real);
        let before = if known { self.readback(r) } else { f64::NAN };
        let (d, s) = match self.rng.below(6) {
            0 => ("fmi2SetReal(vr NULL, 1)".to_string(), fmi2SetReal(c, null(), 1, &x)),
            1 => ("fmi2SetReal(value NULL, 1)".to_string(), fmi2SetReal(c, &r, 1, null())),
            _ => (format!("fmi2SetReal([{r}] = {x})"), fmi2SetReal(c, &r, 1, &x)),
        };
        self.check(f, d.clone(), s, Expect::Error, m, None);
        if known {
            let after = self.readback(r);
            if after.to_bits() != before.to_bits() {
                self.fail(format!("{d}: rejected but the value changed from {before} to {after}"));
            }
        }
    }

    pub(super) unsafe fn op_deserialize(&mut self, valid: bool) {
        let f = Function::DeSerializeFMUstate;
        let c = self.c;
        let m = self.mark();
        let mut p: fmi2FMUstate = null_mut();
        if self.blobs.is_empty() {
            let junk = [1 as fmi2Byte; 40];
            let s = fmi2DeSerializeFMUstate(c, junk.as_ptr(), junk.len(), &mut p);
            self.check(f, "fmi2DeSerializeFMUstate(junk)".into(), s, Expect::Error, m, None);
            return;
        }
        let (blob, held) = self.rng.pick(&self.blobs).clone();
        // states whose model was initialised can take any layer-state code
        let initialised = !matches!(held, State::Instantiated | State::InitializationMode);
        let (desc, bytes, expect, holds): (String, Vec<u8>, Expect, State) = if valid {
            if initialised && self.rng.chance(0.6) {
                // mostly the states that no ordinary call sequence reaches
                let target = *self.rng.pick(&[
                    State::StepFailed,
                    State::StepCanceled,
                    State::Error,
                    State::Error,
                    State::Terminated,
                    State::Instantiated,
                    State::InitializationMode,
                    State::StepComplete,
                ]);
                (
                    format!("fmi2DeSerializeFMUstate(recoded to {})", target.name()),
                    recode(&blob, target.code()),
                    Expect::Ok,
                    target,
                )
            } else {
                ("fmi2DeSerializeFMUstate(valid)".into(), blob.clone(), Expect::Ok, held)
            }
        } else {
            let mut b = blob.clone();
            let what = match self.rng.below(8) {
                0 => {
                    let i = self.rng.below(b.len());
                    b[i] ^= 1 << self.rng.below(8);
                    format!("bit flipped at {i}")
                }
                1 => {
                    let i = self.rng.below(b.len());
                    b[i] = b[i].wrapping_add(1 + self.rng.below(255) as u8);
                    format!("byte changed at {i}")
                }
                2 => {
                    let n = self.rng.below(b.len());
                    b.truncate(n);
                    format!("truncated to {n}")
                }
                3 => {
                    b.push(0);
                    "one byte appended".into()
                }
                4 => {
                    b = recode(&blob, *self.rng.pick(&[0u8, 8, 9, 255]));
                    "layer-state code invalid or fatal".into()
                }
                5 => {
                    b = with_model_version(&blob, "0.0.9");
                    "other model version".into()
                }
                6 => {
                    for x in b.iter_mut() {
                        *x = self.rng.next_u64() as u8;
                    }
                    "random bytes".into()
                }
                _ => {
                    b.clear();
                    "zero length".into()
                }
            };
            (format!("fmi2DeSerializeFMUstate({what})"), b, Expect::Error, held)
        };
        let ptr = if bytes.is_empty() {
            null()
        } else {
            bytes.as_ptr() as *const fmi2Byte
        };
        let s = fmi2DeSerializeFMUstate(c, ptr, bytes.len(), &mut p);
        if s == fmi2OK {
            self.add_state(p, holds);
        } else if !p.is_null() {
            self.fail(format!("{desc}: rejected but the FMU state pointer was set"));
        }
        self.check(f, desc, s, expect, m, None);
    }

    pub(super) unsafe fn op_status(&mut self, f: Function, valid: bool) {
        let c = self.c;
        let m = self.mark();
        let kind = if valid {
            *self.rng.pick(&[
                fmi2DoStepStatus,
                fmi2PendingStatus,
                fmi2LastSuccessfulTime,
                fmi2Terminated,
            ])
        } else {
            *self.rng.pick(&[-1, 4, 99])
        };
        let null_value = !valid && self.rng.chance(0.3);
        let mut st: fmi2Status = -1;
        let mut r = f64::NAN;
        let mut i: fmi2Integer = -1;
        let mut b: fmi2Boolean = -1;
        let mut sv: fmi2String = null();
        let s = match (f, null_value) {
            (Function::GetStatus, false) => fmi2GetStatus(c, kind, &mut st),
            (Function::GetStatus, true) => fmi2GetStatus(c, kind, null_mut()),
            (Function::GetRealStatus, false) => fmi2GetRealStatus(c, kind, &mut r),
            (Function::GetRealStatus, true) => fmi2GetRealStatus(c, kind, null_mut()),
            (Function::GetIntegerStatus, false) => fmi2GetIntegerStatus(c, kind, &mut i),
            (Function::GetIntegerStatus, true) => fmi2GetIntegerStatus(c, kind, null_mut()),
            (Function::GetBooleanStatus, false) => fmi2GetBooleanStatus(c, kind, &mut b),
            (Function::GetBooleanStatus, true) => fmi2GetBooleanStatus(c, kind, null_mut()),
            (_, false) => fmi2GetStringStatus(c, kind, &mut sv),
            (_, true) => fmi2GetStringStatus(c, kind, null_mut()),
        };
        let e = if !valid {
            Expect::Error
        } else {
            match (f, kind) {
                (Function::GetRealStatus, fmi2LastSuccessfulTime) | (Function::GetBooleanStatus, fmi2Terminated) => {
                    Expect::Ok
                }
                _ => Expect::Discard,
            }
        };
        if s == fmi2OK && f == Function::GetRealStatus && r != self.time() {
            self.fail(format!(
                "fmi2LastSuccessfulTime {r} but the model time is {}",
                self.time()
            ));
        }
        if s == fmi2OK && f == Function::GetBooleanStatus && b != fmi2False {
            self.fail(format!("fmi2Terminated = {b}"));
        }
        self.check(
            f,
            format!("{}(kind {kind}{})", f.name(), if null_value { ", NULL" } else { "" }),
            s,
            e,
            m,
            None,
        );
    }

    /// Every function with a NULL instance: fmi2Error (fmi2FreeInstance: a no-op).
    pub(super) unsafe fn null_instance_calls(&mut self) {
        let n = null_mut();
        let r = vr::V_DA;
        let mut x = 0.0;
        let mut i = 0;
        let mut p: fmi2FMUstate = null_mut();
        let mut size = 0usize;
        let o = 1;
        let results = [
            fmi2SetDebugLogging(n, 1, 0, null()),
            fmi2SetupExperiment(n, 0, 0.0, 0.0, 0, 0.0),
            fmi2EnterInitializationMode(n),
            fmi2ExitInitializationMode(n),
            fmi2Terminate(n),
            fmi2Reset(n),
            fmi2GetReal(n, &r, 1, &mut x),
            fmi2GetInteger(n, &r, 1, &mut i),
            fmi2GetBoolean(n, &r, 1, &mut i),
            fmi2GetString(n, null(), 0, null_mut()),
            fmi2SetReal(n, &r, 1, &x),
            fmi2SetInteger(n, &r, 1, &i),
            fmi2SetBoolean(n, &r, 1, &i),
            fmi2SetString(n, null(), 0, null()),
            fmi2GetFMUstate(n, &mut p),
            fmi2SetFMUstate(n, null_mut()),
            fmi2FreeFMUstate(n, &mut p),
            fmi2SerializedFMUstateSize(n, null_mut(), &mut size),
            fmi2SerializeFMUstate(n, null_mut(), null_mut(), 0),
            fmi2DeSerializeFMUstate(n, null(), 0, &mut p),
            fmi2GetDirectionalDerivative(n, null(), 0, null(), 0, null(), null_mut()),
            fmi2SetRealInputDerivatives(n, &r, 1, &o, &x),
            fmi2GetRealOutputDerivatives(n, &r, 1, &o, &mut x),
            fmi2DoStep(n, 0.0, 1e-3, 1),
            fmi2CancelStep(n),
            fmi2GetStatus(n, fmi2DoStepStatus, &mut i),
            fmi2GetRealStatus(n, fmi2LastSuccessfulTime, &mut x),
            fmi2GetIntegerStatus(n, fmi2DoStepStatus, &mut i),
            fmi2GetBooleanStatus(n, fmi2Terminated, &mut i),
            fmi2GetStringStatus(n, fmi2DoStepStatus, null_mut()),
        ];
        fmi2FreeInstance(n);
        for (k, s) in results.iter().enumerate() {
            if *s != fmi2Error {
                self.fail(format!("call #{k} with a NULL instance returned {}", status_name(*s)));
            }
        }
        if !p.is_null() {
            self.fail("a call with a NULL instance wrote an FMU state".into());
        }
        self.calls += results.len() as u64 + 1;
    }
}
