//! The crate root of the win64 build of the actuator FMU: the modules of `src/` that the FMU
//! needs (no command line, packaging, plots, sweeps or diagnosis), compiled by
//! `scripts/build_win64.sh` with Debian's rustc and its Windows standard library.

#[path = "../../src/compat.rs"]
pub mod compat;
#[path = "../../src/electromechanics/mod.rs"]
pub mod electromechanics;
#[path = "../../src/fmi2/mod.rs"]
pub mod fmi2;
#[path = "../../src/fmu.rs"]
pub mod fmu;
#[path = "../../src/fmu_exports.rs"]
pub mod fmu_exports;
#[path = "../../src/integrator.rs"]
pub mod integrator;
#[path = "../../src/physics/mod.rs"]
pub mod physics;
#[path = "../../src/polynomial.rs"]
pub mod polynomial;
#[path = "../../src/scenario.rs"]
pub mod scenario;
#[path = "../../src/simulation/mod.rs"]
pub mod simulation;
#[path = "../../src/variables.rs"]
pub mod variables;

/// The model behind the exported FMI symbols in `fmu_exports`.
pub type ExportedModel = fmu::ActuatorFmu;
