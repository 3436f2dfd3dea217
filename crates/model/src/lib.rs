//! Jet-pipe electropneumatic actuator of the Utah/MIT Dextrous Hand (P.D. Henri, 1994): the
//! model, in plain Rust (no FFI types; builds with Rust 1.63, nalgebra and smallvec only, as
//! `scripts/build_win64.sh` does).
//!
//! What an embedding program needs is at the crate's root:
//!
//! * [`Parameters`] (every constant, set by name or value reference through the table's
//!   checks) and [`Actuator`], the model they make;
//! * [`Simulation`]: inputs (`set_command`, `set_stopper`, their rates), `step`, [`Outputs`],
//!   and [`SimulationSnapshot`] to continue a run later; [`equilibrium`] for a start at rest;
//! * [`linearize`]: the linear model about an equilibrium, its poles and zeros (§4.2.2);
//! * [`VARIABLES`]: the table of the FMU's variables (name, unit, start, limits, meaning).
//!
//! ```
//! use jetpipe_model::{Actuator, Parameters, Simulation};
//! let model = Actuator::new(Parameters::default()).unwrap();
//! let mut sim = Simulation::at_equilibrium(model, 2.5, 0.054, 0.0, 1e-6).unwrap();
//! sim.set_command(3.0).unwrap();
//! sim.step(1e-3).unwrap();
//! assert!(sim.outputs().f_act > 0.0);
//! ```
//!
//! The modules behind it:
//!
//! * [`physics`]: the thesis model, one module per physical part, equations cited by number;
//! * [`simulation`]: stepping between communication points (FMU, CLI and tests share it),
//!   and the fixed-step replay of a recording the diagnosis fits with;
//! * [`linearization`]: the linear model of §4.2.2;
//! * [`variables`]: the table of the actuator's variables (name, value reference, unit, start,
//!   limits, thesis reference), from which the FMU's model description comes (the root package, `src/`);
//! * [`scenario`]: the standard scenario's inputs.
//!
//! Private: the exact propagation of the current driver and jet pipe over a step
//! (`electromechanics`), the integrators (`integrator`: SDIRK4, Dormand–Prince 5(4), ROS2),
//! piecewise polynomials for the hot functions (`polynomial`) and what Rust 1.63's standard
//! library lacks (`compat`).

mod compat;
mod electromechanics;
mod integrator;
pub mod linearization;
pub mod physics;
mod polynomial;
pub mod scenario;
pub mod simulation;
pub mod variable;
pub mod variables;

pub use integrator::Statistics;
pub use linearization::{command_for_force, linearize, LinearModel, OperatingPoint};
pub use physics::actuator::{Actuator, Outputs};
pub use physics::parameters::Parameters;
pub use simulation::{equilibrium, FixedStep, Simulation, SimulationSnapshot, StepFailure};
pub use variables::VARIABLES;
