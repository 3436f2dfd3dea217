//! A generic FMI 2.0 Co-Simulation layer: C ABI, state machine, logging, FMU state.
//! It knows nothing about the model behind it: see [`model::CoSimModel`].

pub mod model;
