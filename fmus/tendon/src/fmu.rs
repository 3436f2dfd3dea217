//! The tendon behind jetpipe's generic FMI layer. No FFI types here.

use fmi2::model::{CoSimModel, ModelInfo, OutputDependencies, StepError};
use fmi2::state_bytes::StateFormat;
use fmu_common::Values;

use crate::physics::{JointEnd, Parameters, State};
use crate::variables::{vr, UNITS, VARIABLES};

pub static MODEL_INFO: ModelInfo = fmu_common::model_info! {
    name: "Tendon",
    description: "Tendon of a 2N tendon drive (Utah/MIT Dextrous Hand): rod mass at the actuator end, elastic tendon that goes slack instead of pushing, capstan friction of the pulleys; outputs the actuator's stopper position",
    units: UNITS,
    variables: VARIABLES,
    dependencies: DEPENDENCIES,
};

/// `<ModelStructure>`: every output comes from the state at the end of the last step (no direct feedthrough);
/// after initialisation it is the static rest state of the inputs, which depends on all of them.
pub const DEPENDENCIES: &[OutputDependencies] = &[
    OutputDependencies {
        output: vr::T,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::T_ROD,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::X_S,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::V_ROD,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::STRETCH,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::SLACK_TIME,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::SLACK,
        step: &[],
        initial: None,
    },
];

#[derive(Clone, Debug)]
pub struct TendonFmu {
    values: Values,
    start_time: f64,
    /// Parameters and state from initialisation on.
    running: Option<(Parameters, State)>,
}

impl TendonFmu {
    pub fn parameters(&self) -> Result<Parameters, String> {
        let v = |r| self.values.get(r);
        let p = Parameters {
            m_rod: v(vr::M_ROD),
            c_rod: v(vr::C_ROD),
            k: v(vr::K),
            c: v(vr::C),
            capstan: v(vr::CAPSTAN),
            v_friction: v(vr::V_FRICTION),
            x_s0: v(vr::X_S0),
            x_s_min: v(vr::X_S_MIN),
            x_s_max: v(vr::X_S_MAX),
            max_substep: v(vr::MAX_SUBSTEP),
        };
        p.check()?;
        Ok(p)
    }

    fn joint_end(&self) -> JointEnd {
        JointEnd {
            x: self.values.get(vr::X_JOINT),
            v: self.values.get(vr::V_JOINT),
        }
    }

    fn initial(&self) -> Result<(Parameters, State), String> {
        let p = self.parameters()?;
        let s = State::equilibrium(&p, self.values.get(vr::F_ACT), self.joint_end());
        Ok((p, s))
    }

    pub fn state(&self) -> Option<&State> {
        self.running.as_ref().map(|(_, s)| s)
    }
}

impl CoSimModel for TendonFmu {
    fn info() -> &'static ModelInfo {
        &MODEL_INFO
    }

    fn instantiate() -> Self {
        Self {
            values: Values::starts(VARIABLES),
            start_time: 0.0,
            running: None,
        }
    }

    fn get_real(&self, value_reference: u32) -> Result<f64, String> {
        let (p, s) = match value_reference {
            vr::T | vr::T_ROD | vr::X_S | vr::V_ROD | vr::STRETCH | vr::SLACK_TIME => match &self.running {
                Some((p, s)) => (p.clone(), s.clone()),
                // Initialisation mode: the outputs of the state the step would start from.
                None => self.initial()?,
            },
            _ => return self.values.try_get(value_reference),
        };
        let y = s.outputs(&p);
        Ok(match value_reference {
            vr::T => y.tension,
            vr::T_ROD => y.rod_tension,
            vr::X_S => y.x_s,
            vr::V_ROD => y.v_rod,
            vr::STRETCH => y.stretch,
            _ => s.slack_time,
        })
    }

    fn set_real(&mut self, value_reference: u32, value: f64) -> Result<(), String> {
        self.values.set(value_reference, value)
    }

    fn get_boolean(&self, value_reference: u32) -> Result<bool, String> {
        if value_reference != vr::SLACK {
            return Err(format!("no Boolean variable with value reference {value_reference}"));
        }
        let (p, s) = match &self.running {
            Some((p, s)) => (p.clone(), s.clone()),
            None => self.initial()?,
        };
        Ok(s.outputs(&p).slack)
    }

    fn setup_experiment(&mut self, _tolerance: Option<f64>, start_time: f64, _stop: Option<f64>) -> Result<(), String> {
        self.start_time = fmu_common::checked_start_time(start_time)?;
        Ok(())
    }

    fn exit_initialization(&mut self) -> Result<(), String> {
        self.running = Some(self.initial()?);
        Ok(())
    }

    fn do_step(&mut self, _current_time: f64, step_size: f64) -> Result<(), StepError> {
        let f_act = self.values.get(vr::F_ACT);
        let joint = self.joint_end();
        let (p, s) = fmu_common::initialised(&mut self.running)?;
        fmu_common::step_or_restore(s, |s| s.step(p, f_act, joint, step_size))
    }

    fn time(&self) -> f64 {
        self.start_time + self.running.as_ref().map_or(0.0, |(_, s)| s.elapsed)
    }

    fn serialize(&self) -> Vec<u8> {
        let mut w = STATE_FORMAT.writer();
        w.f64s(self.values.as_slice());
        w.f64(self.start_time);
        w.optional_f64s(
            self.running
                .as_ref()
                .map(|(_, s)| [s.x_a, s.v_a, s.joint.x, s.joint.v, s.slack_time, s.elapsed]),
        );
        w.0
    }

    fn deserialize(&mut self, bytes: &[u8]) -> Result<(), String> {
        let mut r = STATE_FORMAT.reader(bytes)?;
        let mut restored = Self::instantiate();
        restored.values.restore(&r.f64s()?)?;
        restored.start_time = r.f64()?;
        if let Some([x_a, v_a, x_j, v_j, slack_time, elapsed]) = r.optional_f64s("tendon")? {
            let p = restored.parameters()?;
            let s = State {
                x_a,
                v_a,
                joint: JointEnd { x: x_j, v: v_j },
                slack_time,
                elapsed,
            };
            restored.running = Some((p, s));
        }
        r.finish()?;
        *self = restored;
        Ok(())
    }
}

const STATE_FORMAT: StateFormat = fmi2::state_format!(magic: b"TendonState", version: 1, model: "Tendon");

#[cfg(test)]
mod tests {
    use super::*;

    fmu_common::interface_tests! {
        model: TendonFmu,
        info: MODEL_INFO,
        dir: "fmus/tendon",
        checked_in: include_str!("../modelDescription.xml"),
        vrs: [
            vr::F_ACT, vr::X_JOINT, vr::V_JOINT,
            vr::T, vr::T_ROD, vr::X_S, vr::V_ROD, vr::STRETCH, vr::SLACK_TIME, vr::SLACK,
            vr::M_ROD, vr::C_ROD, vr::K, vr::C, vr::CAPSTAN, vr::V_FRICTION, vr::X_S0, vr::X_S_MIN, vr::X_S_MAX,
            vr::MAX_SUBSTEP,
        ],
    }

    fn initialised(f_act: f64) -> TendonFmu {
        let mut fmu = TendonFmu::instantiate();
        fmu.set_real(vr::F_ACT, f_act).unwrap();
        fmu.exit_initialization().unwrap();
        fmu
    }

    #[test]
    fn starts_at_equilibrium_with_its_inputs() {
        let fmu = initialised(25.0);
        assert!((fmu.get_real(vr::T).unwrap() - 25.0).abs() < 1e-9);
        assert!((fmu.get_real(vr::X_S).unwrap() - (0.054 + 25.0 / 2e4)).abs() < 1e-12);
        assert!(!fmu.get_boolean(vr::SLACK).unwrap());
    }

    #[test]
    fn bad_values_are_rejected_with_the_name_and_not_applied() {
        let mut fmu = initialised(25.0);
        let e = fmu.set_real(vr::F_ACT, f64::NAN).unwrap_err();
        assert!(e.contains("F_act") && e.contains("NaN"), "{e}");
        assert_eq!(fmu.get_real(vr::F_ACT).unwrap(), 25.0);
        let mut fresh = TendonFmu::instantiate();
        let e = fresh.set_real(vr::X_S_MAX, 0.2).unwrap_err();
        assert!(e.contains("x_s_max = 0.2 m"), "{e}");
        fresh.set_real(vr::X_S0, 0.095).unwrap();
        let e = fresh.exit_initialization().unwrap_err();
        assert!(e.contains("x_s0 = 0.095 m"), "{e}");
    }

    #[test]
    fn serialized_state_continues_bit_identically_and_corruption_is_rejected() {
        let mut a = initialised(25.0);
        a.set_real(vr::F_ACT, 40.0).unwrap();
        a.do_step(0.0, 1e-3).unwrap();
        let bytes = a.serialize();
        let mut b = TendonFmu::instantiate();
        b.deserialize(&bytes).unwrap();
        for fmu in [&mut a, &mut b] {
            fmu.set_real(vr::V_JOINT, 0.01).unwrap();
            fmu.do_step(1e-3, 1e-3).unwrap();
        }
        for r in [vr::T, vr::X_S, vr::V_ROD, vr::SLACK_TIME] {
            assert_eq!(a.get_real(r).unwrap().to_bits(), b.get_real(r).unwrap().to_bits());
        }
        assert_eq!(a.time(), b.time());
        let before = b.get_real(vr::X_S).unwrap();
        assert!(b.deserialize(&bytes[..bytes.len() - 1]).is_err());
        let mut foreign = bytes.clone();
        foreign[0] ^= 0xff;
        assert!(b.deserialize(&foreign).is_err());
        assert_eq!(b.get_real(vr::X_S).unwrap(), before);
    }
}
