//! The finger joint behind jetpipe's generic FMI layer. No FFI types here.

use fmi2::model::{CoSimModel, DependencyKind, ModelInfo, OutputDependencies, StepError};
use fmi2::state_bytes::StateFormat;
use fmu_common::Values;

use crate::physics::{Inputs, Parameters, State};
use crate::variables::{vr, UNITS, VARIABLES};

pub static MODEL_INFO: ModelInfo = fmu_common::model_info! {
    name: "FingerJoint",
    description: "One-degree finger joint pulled by two antagonistic tendons over a pulley (2N drive, Utah/MIT Dextrous Hand): inertia, damping, joint stops; outputs the tendon excursions",
    units: UNITS,
    variables: VARIABLES,
    dependencies: DEPENDENCIES,
};

/// `<ModelStructure>`: the state's outputs change only in a step; `tau_tendons` is
/// r·(T_flexor − T_extensor) of the inputs at once (linear, its factor the fixed parameter r).
pub const DEPENDENCIES: &[OutputDependencies] = &[
    OutputDependencies {
        output: vr::THETA,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::OMEGA,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::X_FLEXOR,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::V_FLEXOR,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::X_EXTENSOR,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::V_EXTENSOR,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::TAU_LIMIT,
        step: &[],
        initial: None,
    },
    OutputDependencies {
        output: vr::TAU_TENDONS,
        step: &[
            (vr::T_FLEXOR, DependencyKind::Fixed),
            (vr::T_EXTENSOR, DependencyKind::Fixed),
        ],
        // FMI 2.0 allows only "dependent" and "constant" among InitialUnknowns.
        initial: Some(&[
            (vr::T_FLEXOR, DependencyKind::Dependent),
            (vr::T_EXTENSOR, DependencyKind::Dependent),
            (vr::R, DependencyKind::Dependent),
        ]),
    },
];

#[derive(Clone, Debug)]
pub struct FingerJointFmu {
    values: Values,
    start_time: f64,
    running: Option<(Parameters, State)>,
}

impl FingerJointFmu {
    pub fn parameters(&self) -> Result<Parameters, String> {
        let v = |r| self.values.get(r);
        let p = Parameters {
            inertia: v(vr::J),
            damping: v(vr::B),
            radius: v(vr::R),
            theta_min: v(vr::THETA_MIN),
            theta_max: v(vr::THETA_MAX),
            k_limit: v(vr::K_LIMIT),
            c_limit: v(vr::C_LIMIT),
            max_substep: v(vr::MAX_SUBSTEP),
        };
        p.check()?;
        Ok(p)
    }

    fn inputs(&self) -> Inputs {
        Inputs {
            t_flexor: self.values.get(vr::T_FLEXOR),
            t_extensor: self.values.get(vr::T_EXTENSOR),
            tau_ext: self.values.get(vr::TAU_EXT),
        }
    }

    fn initial(&self) -> Result<(Parameters, State), String> {
        let p = self.parameters()?;
        let s = State {
            theta: self.values.get(vr::THETA_START),
            omega: self.values.get(vr::OMEGA_START),
            elapsed: 0.0,
        };
        Ok((p, s))
    }
}

impl CoSimModel for FingerJointFmu {
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
            vr::THETA..=vr::TAU_LIMIT => match &self.running {
                Some((p, s)) => (p.clone(), s.clone()),
                None => self.initial()?,
            },
            _ => return self.values.try_get(value_reference),
        };
        let r = p.radius;
        Ok(match value_reference {
            vr::THETA => s.theta,
            vr::OMEGA => s.omega,
            vr::X_FLEXOR => r * s.theta,
            vr::V_FLEXOR => r * s.omega,
            vr::X_EXTENSOR => -r * s.theta,
            vr::V_EXTENSOR => -r * s.omega,
            vr::TAU_TENDONS => self.inputs().tendon_torque(&p),
            _ => p.limit_torque(s.theta, s.omega),
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
        Ok(())
    }

    fn do_step(&mut self, _current_time: f64, step_size: f64) -> Result<(), StepError> {
        let u = self.inputs();
        let (p, s) = fmu_common::initialised(&mut self.running)?;
        fmu_common::step_or_restore(s, |s| s.step(p, u, step_size))
    }

    fn time(&self) -> f64 {
        self.start_time + self.running.as_ref().map_or(0.0, |(_, s)| s.elapsed)
    }

    fn serialize(&self) -> Vec<u8> {
        let mut w = STATE_FORMAT.writer();
        w.f64s(self.values.as_slice());
        w.f64(self.start_time);
        w.optional_f64s(self.running.as_ref().map(|(_, s)| [s.theta, s.omega, s.elapsed]));
        w.0
    }

    fn deserialize(&mut self, bytes: &[u8]) -> Result<(), String> {
        let mut r = STATE_FORMAT.reader(bytes)?;
        let mut restored = Self::instantiate();
        restored.values.restore(&r.f64s()?)?;
        restored.start_time = r.f64()?;
        if let Some([theta, omega, elapsed]) = r.optional_f64s("joint")? {
            let p = restored.parameters()?;
            restored.running = Some((p, State { theta, omega, elapsed }));
        }
        r.finish()?;
        *self = restored;
        Ok(())
    }
}

const STATE_FORMAT: StateFormat = fmi2::state_format!(magic: b"FingerJointState", version: 1, model: "FingerJoint");

#[cfg(test)]
mod tests {
    use super::*;

    fmu_common::interface_tests! {
        model: FingerJointFmu,
        info: MODEL_INFO,
        dir: "fmus/finger_joint",
        checked_in: include_str!("../modelDescription.xml"),
        vrs: [
            vr::T_FLEXOR, vr::T_EXTENSOR, vr::TAU_EXT,
            vr::THETA, vr::OMEGA, vr::X_FLEXOR, vr::V_FLEXOR, vr::X_EXTENSOR, vr::V_EXTENSOR, vr::TAU_TENDONS,
            vr::TAU_LIMIT,
            vr::J, vr::B, vr::R, vr::THETA_MIN, vr::THETA_MAX, vr::K_LIMIT, vr::C_LIMIT, vr::THETA_START,
            vr::OMEGA_START, vr::MAX_SUBSTEP,
        ],
    }

    #[test]
    fn outputs_are_the_tendon_excursions() {
        let mut fmu = FingerJointFmu::instantiate();
        fmu.set_real(vr::THETA_START, 0.5).unwrap();
        fmu.set_real(vr::OMEGA_START, -2.0).unwrap();
        fmu.set_real(vr::T_FLEXOR, 30.0).unwrap();
        fmu.set_real(vr::T_EXTENSOR, 20.0).unwrap();
        fmu.exit_initialization().unwrap();
        assert!((fmu.get_real(vr::X_FLEXOR).unwrap() - 0.005).abs() < 1e-15);
        assert!((fmu.get_real(vr::X_EXTENSOR).unwrap() + 0.005).abs() < 1e-15);
        assert!((fmu.get_real(vr::V_FLEXOR).unwrap() + 0.02).abs() < 1e-15);
        assert!((fmu.get_real(vr::V_EXTENSOR).unwrap() - 0.02).abs() < 1e-15);
        assert!((fmu.get_real(vr::TAU_TENDONS).unwrap() - 0.1).abs() < 1e-15);
        for r in [vr::TAU_EXT, vr::K_LIMIT, vr::C_LIMIT, vr::B] {
            assert!(fmu.get_real(r).is_ok());
        }
    }

    #[test]
    fn bad_values_are_rejected_with_the_name_and_not_applied() {
        let mut fmu = FingerJointFmu::instantiate();
        let e = fmu.set_real(vr::T_FLEXOR, f64::INFINITY).unwrap_err();
        assert!(e.contains("T_flexor") && e.contains("inf"), "{e}");
        let e = fmu.set_real(vr::J, -1.0).unwrap_err();
        assert!(e.contains("J = -1 kg.m2"), "{e}");
        assert_eq!(fmu.get_real(vr::J).unwrap(), 2.0e-4);
        fmu.set_real(vr::THETA_MAX, -1.0).unwrap();
        let e = fmu.exit_initialization().unwrap_err();
        assert!(e.contains("theta_min") && e.contains("theta_max = -1 rad"), "{e}");
    }

    #[test]
    fn serialized_state_continues_bit_identically() {
        let mut a = FingerJointFmu::instantiate();
        a.exit_initialization().unwrap();
        a.set_real(vr::T_FLEXOR, 30.0).unwrap();
        a.do_step(0.0, 1e-3).unwrap();
        let bytes = a.serialize();
        let mut b = FingerJointFmu::instantiate();
        b.deserialize(&bytes).unwrap();
        for fmu in [&mut a, &mut b] {
            fmu.do_step(1e-3, 1e-3).unwrap();
        }
        assert_eq!(
            a.get_real(vr::THETA).unwrap().to_bits(),
            b.get_real(vr::THETA).unwrap().to_bits()
        );
        assert!(b.deserialize(&bytes[..10]).is_err());
    }
}
