//! Jet-pipe electropneumatic actuator of the Utah/MIT Dextrous Hand (P.D. Henri, 1994).

pub mod fmi2;
pub mod fmu_exports;
pub mod variables;

/// The model behind the exported FMI symbols in [`fmu_exports`].
pub type ExportedModel = fmi2::testing::DummyModel; // replaced by the actuator at merge
