//! The joint position controller of an antagonistic (2N) tendon-driven joint, with
//! co-contraction, for two jet-pipe actuators, as an FMI 2.0 Co-Simulation FMU
//! (`JointController`) on jetpipe's generic FMI layer.
//!
//! * [`control`]: the control law (plain Rust): PID on the joint angle, the tension
//!   distribution with co-contraction, and per actuator a force loop with the inverse
//!   static force map as feedforward;
//! * [`variables`]: the variable table;
//! * [`fmu`]: the model behind the layer; the `fmi2*` symbols come from
//!   `fmi2::fmi2_cosimulation_exports!` below.

pub mod control;
pub mod fmu;
pub mod variables;

#[cfg(feature = "exports")]
fmi2::fmi2_cosimulation_exports!(crate::fmu::JointControllerFmu);
