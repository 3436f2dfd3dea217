//! The jet-pipe actuator (crate `jetpipe-model`) as an FMU, Co-Simulation and Model Exchange,
//! FMI 2.0 on the generic layer of crate `fmi2` and FMI 3.0 on crate `fmi3`. Built as
//! `libjetpipe.so` (cdylib) with both versions' symbols, packaged by `jetpipe package` as
//! `JetPipeActuator.fmu` (FMI 2.0) and `JetPipeActuator-fmi3.fmu` (FMI 3.0).
//!
//! * [`fmu`]: `ActuatorFmu`, the actuator behind the layer (`CoSimModel`), with the model
//!   description's extents and dependencies;
//! * [`fmu_exports`]: the exported `fmi2*` symbols, written out literally so that `build.rs`
//!   (cbindgen) can read them. Every binary that links this crate carries them, so a crate
//!   that exports another model's symbols (`fmi2::fmi2_cosimulation_exports!`) cannot link it
//!   into the same library or test: `fmus/antagonistic`, which links the actuator next to the
//!   other models, takes theirs without their `exports` feature;
//! * [`fmu3_exports`]: the exported `fmi3*` symbols, likewise (`build.rs` writes their header);
//! * [`variables`]: the model's variable table as FMI variables, and the units of the model
//!   description.

pub mod fmu;
pub mod fmu3_exports;
pub mod fmu_exports;
pub mod variables;

/// The model behind the exported FMI symbols in `fmu_exports`.
pub type ExportedModel = fmu::ActuatorFmu;
