//! One tendon of a 2N tendon drive (Utah/MIT Dextrous Hand) as an FMI 2.0 Co-Simulation FMU
//! (`Tendon`), on jetpipe's generic FMI layer.
//!
//! * [`physics`]: the rod node, the elastic tendon that goes slack, the capstan friction of
//!   the pulleys, and the implicit integrator (plain Rust);
//! * [`variables`]: the variable table (model description, getters and setters);
//! * [`fmu`]: the model behind the layer; the `fmi2*` symbols come from
//!   `fmi2::fmi2_cosimulation_exports!` below.

pub mod fmu;
pub mod physics;
pub mod variables;

#[cfg(feature = "exports")]
fmi2::fmi2_cosimulation_exports!(crate::fmu::TendonFmu);
