//! The joint controller behind jetpipe's generic FMI layer. No FFI types here.

use fmi2::model::{CoSimModel, ModelInfo, OutputDependencies, StepError};
use fmi2::state_bytes::StateFormat;
use fmu_common::Values;

use crate::control::{Commands, Controller, Gains, Measurements};
use crate::variables::{vr, UNITS, VARIABLES};

pub static MODEL_INFO: ModelInfo = fmu_common::model_info! {
    name: "JointController",
    description: "Antagonistic joint position controller with co-contraction (Jacobsen et al.) for two jet-pipe actuators: PID on the angle, tension distribution keeping both tendons above T_min, force loops with inverse static feedforward; sampled at the communication step",
    units: UNITS,
    variables: VARIABLES,
    dependencies: DEPENDENCIES,
};

/// `<ModelStructure>`: the controller samples its inputs once per step, so no output follows a new input
/// before the next step; after initialisation the outputs depend on all inputs and parameters.
pub const DEPENDENCIES: &[OutputDependencies] = &[
    OutputDependencies {
        output: vr::V_DA_FLEXOR,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::V_DA_EXTENSOR,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::T_FLEXOR_REF,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::T_EXTENSOR_REF,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::TAU_REF,
        step: &[],
        initial: None,
    },
];

#[derive(Clone, Debug)]
pub struct JointControllerFmu {
    values: Values,
    start_time: f64,
    elapsed: f64,
    /// Gains, memory and the commands held since the last sample, from initialisation on.
    running: Option<(Gains, Controller, Commands)>,
}

impl JointControllerFmu {
    pub fn gains(&self) -> Result<Gains, String> {
        let v = |r| self.values.get(r);
        let g = Gains {
            radius: v(vr::R),
            t_co: v(vr::T_CO),
            t_min: v(vr::T_MIN),
            t_max: v(vr::T_MAX),
            kp: v(vr::KP),
            ki: v(vr::KI),
            kd: v(vr::KD),
            tau_i_max: v(vr::TAU_I_MAX),
            k_force: v(vr::K_F),
            k_feedforward: v(vr::K_FF),
            v_min: v(vr::V_MIN),
            v_max: v(vr::V_MAX),
        };
        g.check()?;
        Ok(g)
    }

    /// The reference at the controller's own time: theta_ref plus theta_step from t_step on
    /// (with half a nanosecond of slack for a time summed from steps).
    fn reference(&self) -> f64 {
        let t = self.start_time + self.elapsed;
        let stepped = t >= self.values.get(vr::T_STEP) - 0.5e-9;
        self.values.get(vr::THETA_REF) + if stepped { self.values.get(vr::THETA_STEP) } else { 0.0 }
    }

    fn measurements(&self) -> Measurements {
        Measurements {
            theta_ref: self.reference(),
            theta: self.values.get(vr::THETA),
            omega: self.values.get(vr::OMEGA),
            f_flexor: self.values.get(vr::F_FLEXOR),
            f_extensor: self.values.get(vr::F_EXTENSOR),
        }
    }

    /// The first sample, taken at initialisation (no integration yet).
    fn initial(&self) -> Result<(Gains, Controller, Commands), String> {
        let g = self.gains()?;
        let mut c = Controller::default();
        let u = c.update(&g, &self.measurements(), 0.0);
        Ok((g, c, u))
    }
}

impl CoSimModel for JointControllerFmu {
    fn info() -> &'static ModelInfo {
        &MODEL_INFO
    }

    fn instantiate() -> Self {
        Self {
            values: Values::starts(VARIABLES),
            start_time: 0.0,
            elapsed: 0.0,
            running: None,
        }
    }

    fn get_real(&self, value_reference: u32) -> Result<f64, String> {
        let u = match value_reference {
            vr::V_DA_FLEXOR..=vr::TAU_REF => match &self.running {
                Some((_, _, u)) => *u,
                None => self.initial()?.2,
            },
            _ => return self.values.try_get(value_reference),
        };
        Ok(match value_reference {
            vr::V_DA_FLEXOR => u.v_flexor,
            vr::V_DA_EXTENSOR => u.v_extensor,
            vr::T_FLEXOR_REF => u.t_flexor,
            vr::T_EXTENSOR_REF => u.t_extensor,
            _ => u.tau,
        })
    }

    fn set_real(&mut self, value_reference: u32, value: f64) -> Result<(), String> {
        self.values.set(value_reference, value)
    }

    fn setup_experiment(&mut self, _tolerance: Option<f64>, start_time: f64, _stop: Option<f64>) -> Result<(), String> {
        self.start_time = fmu_common::checked_start_time(start_time)?;
        Ok(())
    }

    fn exit_initialization(&mut self) -> Result<(), String> {
        self.running = Some(self.initial()?);
        self.elapsed = 0.0;
        Ok(())
    }

    fn do_step(&mut self, _current_time: f64, step_size: f64) -> Result<(), StepError> {
        let m = self.measurements();
        let (g, c, u) = fmu_common::initialised(&mut self.running)?;
        *u = c.update(g, &m, step_size);
        self.elapsed += step_size;
        Ok(())
    }

    fn time(&self) -> f64 {
        self.start_time + self.elapsed
    }

    fn serialize(&self) -> Vec<u8> {
        let mut w = STATE_FORMAT.writer();
        w.f64s(self.values.as_slice());
        w.f64(self.start_time);
        w.f64(self.elapsed);
        w.optional_f64s(
            self.running
                .as_ref()
                .map(|(_, c, u)| [c.integral, u.tau, u.t_flexor, u.t_extensor, u.v_flexor, u.v_extensor]),
        );
        w.0
    }

    fn deserialize(&mut self, bytes: &[u8]) -> Result<(), String> {
        let mut r = STATE_FORMAT.reader(bytes)?;
        let mut restored = Self::instantiate();
        restored.values.restore(&r.f64s()?)?;
        restored.start_time = r.f64()?;
        restored.elapsed = r.f64()?;
        if let Some([integral, tau, t_flexor, t_extensor, v_flexor, v_extensor]) = r.optional_f64s("controller")? {
            let g = restored.gains()?;
            let u = Commands {
                tau,
                t_flexor,
                t_extensor,
                v_flexor,
                v_extensor,
            };
            restored.running = Some((g, Controller { integral }, u));
        }
        r.finish()?;
        *self = restored;
        Ok(())
    }
}

const STATE_FORMAT: StateFormat =
    fmi2::state_format!(magic: b"JointControllerState", version: 1, model: "JointController");

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::static_command;

    fmu_common::interface_tests! {
        model: JointControllerFmu,
        info: MODEL_INFO,
        dir: "fmus/joint_controller",
        checked_in: include_str!("../modelDescription.xml"),
        vrs: [
            vr::THETA_REF, vr::THETA, vr::OMEGA, vr::F_FLEXOR, vr::F_EXTENSOR,
            vr::V_DA_FLEXOR, vr::V_DA_EXTENSOR, vr::T_FLEXOR_REF, vr::T_EXTENSOR_REF, vr::TAU_REF,
            vr::R, vr::T_CO, vr::T_MIN, vr::T_MAX, vr::KP, vr::KI, vr::KD, vr::TAU_I_MAX, vr::K_F, vr::K_FF,
            vr::V_MIN, vr::V_MAX, vr::THETA_STEP, vr::T_STEP,
        ],
    }

    #[test]
    fn initial_outputs_are_the_static_co_contraction() {
        let mut fmu = JointControllerFmu::instantiate();
        fmu.exit_initialization().unwrap();
        let v = fmu.get_real(vr::V_DA_FLEXOR).unwrap();
        assert!((v - static_command(25.0)).abs() < 1e-12);
        assert_eq!(v, fmu.get_real(vr::V_DA_EXTENSOR).unwrap());
        assert_eq!(fmu.get_real(vr::T_FLEXOR_REF).unwrap(), 25.0);
    }

    #[test]
    fn outputs_are_held_until_the_next_sample() {
        let mut fmu = JointControllerFmu::instantiate();
        fmu.exit_initialization().unwrap();
        let before = fmu.get_real(vr::V_DA_FLEXOR).unwrap();
        fmu.set_real(vr::THETA_REF, 0.5).unwrap();
        assert_eq!(fmu.get_real(vr::V_DA_FLEXOR).unwrap(), before);
        fmu.do_step(0.0, 1e-3).unwrap();
        assert!(fmu.get_real(vr::V_DA_FLEXOR).unwrap() > before);
        assert!(fmu.get_real(vr::TAU_REF).unwrap() > 0.0);
    }

    #[test]
    fn bad_values_are_rejected_with_the_name() {
        let mut fmu = JointControllerFmu::instantiate();
        let e = fmu.set_real(vr::THETA_REF, f64::NAN).unwrap_err();
        assert!(e.contains("theta_ref") && e.contains("NaN"), "{e}");
        let e = fmu.set_real(vr::K_FF, 2.0).unwrap_err();
        assert!(e.contains("k_feedforward = 2"), "{e}");
        fmu.set_real(vr::T_MIN, 0.0).unwrap();
        let e = fmu.exit_initialization().unwrap_err();
        assert!(e.contains("T_min = 0 N"), "{e}");
    }

    #[test]
    fn serialized_state_continues_bit_identically() {
        let mut a = JointControllerFmu::instantiate();
        a.exit_initialization().unwrap();
        a.set_real(vr::THETA_REF, 0.3).unwrap();
        a.do_step(0.0, 1e-3).unwrap();
        let bytes = a.serialize();
        let mut b = JointControllerFmu::instantiate();
        b.deserialize(&bytes).unwrap();
        for fmu in [&mut a, &mut b] {
            fmu.do_step(1e-3, 1e-3).unwrap();
        }
        assert_eq!(
            a.get_real(vr::V_DA_FLEXOR).unwrap().to_bits(),
            b.get_real(vr::V_DA_FLEXOR).unwrap().to_bits()
        );
        assert!(b.deserialize(&bytes[..bytes.len() - 2]).is_err());
    }

    /// theta_step acts exactly like a theta_ref that steps at t_step: from the first step that
    /// starts at t_step on (t summed from 1 ms steps), and not before.
    #[test]
    fn the_reference_step_is_theta_ref_stepping_at_t_step() {
        let mut stepped = JointControllerFmu::instantiate();
        stepped.set_real(vr::THETA_STEP, 0.5).unwrap();
        stepped.set_real(vr::T_STEP, 0.01).unwrap();
        stepped.exit_initialization().unwrap();
        let mut driven = JointControllerFmu::instantiate();
        driven.exit_initialization().unwrap();
        let mut t = 0.0;
        for k in 0..20 {
            if k == 10 {
                driven.set_real(vr::THETA_REF, 0.5).unwrap();
            }
            stepped.do_step(t, 1e-3).unwrap();
            driven.do_step(t, 1e-3).unwrap();
            t += 1e-3;
            let (a, b) = (
                stepped.get_real(vr::TAU_REF).unwrap(),
                driven.get_real(vr::TAU_REF).unwrap(),
            );
            assert_eq!(a, b, "step {k}");
            assert_eq!(a > 0.0, k >= 10, "step {k}: tau_ref {a}");
        }
    }
}
