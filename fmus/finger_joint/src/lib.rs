//! A one-degree finger joint pulled by two antagonistic tendons (the 2N arrangement of the
//! Utah/MIT Dextrous Hand) as an FMI 2.0 Co-Simulation FMU (`FingerJoint`), on jetpipe's
//! generic FMI layer.
//!
//! * [`physics`]: inertia, damping, joint limits, pulley, implicit integrator (plain Rust);
//! * [`variables`]: the variable table;
//! * [`fmu`]: the model behind the layer; the `fmi2*` symbols come from
//!   `fmi2::fmi2_cosimulation_exports!` below.

pub mod fmu;
pub mod physics;
pub mod variables;

#[cfg(feature = "exports")]
fmi2::fmi2_cosimulation_exports!(crate::fmu::FingerJointFmu);
