//! Jet-pipe electropneumatic actuator of the Utah/MIT Dextrous Hand (P.D. Henri, 1994).
//!
//! * [`physics`]: the thesis model, one module per physical part, equations cited by number;
//! * [`integrator`]: the error-controlled integrators (SDIRK4; Dormand–Prince 5(4) for the
//!   non-stiff stretches, handing over to SDIRK4), independent of the physics;
//! * [`simulation`]: stepping between communication points (FMU, CLI and tests share it);
//! * [`fmi2`]: the generic FMI 2.0 Co-Simulation layer, which knows nothing of pneumatics;
//! * [`fmu`]: the actuator behind that layer; `fmu_exports`: the exported `fmi2*` symbols
//!   (feature `actuator-exports`, on by default);
//! * [`fmi2_cosimulation_exports!`]: the same symbols for any other model, for crates that
//!   put another FMU on this layer (`fmus/` in the workspace);
//! * [`variables`]: the table of FMU variables from which the model description comes;
//! * [`sweep`]: parameter sweeps of the standard scenario over all cores (`jetpipe sweep`).

pub mod compat;
pub mod diagnosis;
pub mod electromechanics;
pub mod fmi2;
mod fmi2_exports_macro;
pub mod fmu;
/// Off only for crates that export another model's symbols (see the `actuator-exports`
/// feature in Cargo.toml): a cdylib built on jetpipe's rlib would otherwise carry these too.
#[cfg(feature = "actuator-exports")]
pub mod fmu_exports;
pub mod integrator;
pub mod linearization;
pub mod packaging;
pub mod physics;
pub mod plots;
pub mod polynomial;
pub mod recording;
pub mod replay;
pub mod scenario;
pub mod simulation;
pub mod sweep;
pub mod synthetic_bench;
pub mod variables;

/// The model behind the exported FMI symbols in `fmu_exports`.
pub type ExportedModel = fmu::ActuatorFmu;
