//! A generic FMI 2.0 Co-Simulation layer: C ABI, state machine, logging, FMU state.
//! It knows nothing about the model behind it: see [`model::CoSimModel`].

pub mod api;
pub mod fmu_state;
pub mod instance;
pub mod model;
pub mod model_description;
pub mod state;
pub mod testing;
pub mod types;
#[cfg(test)]
mod tests;
