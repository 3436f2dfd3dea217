//! Jet-pipe electropneumatic actuator of the Utah/MIT Dextrous Hand (P.D. Henri, 1994): the
//! model, in plain Rust (no FFI types; builds with Rust 1.63, nalgebra and smallvec only, as
//! `scripts/build_win64.sh` does).
//!
//! * [`physics`]: the thesis model, one module per physical part, equations cited by number;
//! * [`electromechanics`]: the current driver and jet pipe propagated exactly over a step;
//! * [`integrator`]: the error-controlled integrators (SDIRK4; Dormand–Prince 5(4) for the
//!   non-stiff stretches, handing over to SDIRK4), independent of the physics;
//! * [`simulation`]: stepping between communication points (FMU, CLI and tests share it);
//! * [`variables`]: the table of the actuator's variables (name, value reference, unit, start,
//!   limits, thesis reference), from which the FMU's model description comes (`crates/fmu`);
//! * [`polynomial`], [`scenario`], [`compat`]: piecewise polynomials for the hot functions,
//!   the standard scenario's inputs, what Rust 1.63's standard library lacks.

pub mod compat;
pub mod electromechanics;
pub mod integrator;
pub mod physics;
pub mod polynomial;
pub mod scenario;
pub mod simulation;
pub mod variable;
pub mod variables;
