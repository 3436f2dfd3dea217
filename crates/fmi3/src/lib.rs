//! FMI 3.0 Co-Simulation and Model Exchange on the generic FMI layer of crate `fmi2`.
//!
//! One layer, two versions: the model implements the same traits
//! ([`fmi2::model::CoSimModel`], [`fmi2::model::ModelExchangeModel`]) with the same variable
//! table ([`fmi2::model::ModelInfo`]) for both. What the versions share is the layer's, run
//! with this version's table of functions ([`state::Function`], an [`fmi2::state::Call`]):
//! instances and their registry of live handles, `catch_unwind`, the per-variable checks,
//! the getters' and setters' loops, logging, the FMU-state calls and their byte format (which
//! records the version), the Model Exchange calls. What FMI 3.0 adds or changes is here:
//!
//! * [`types`]: the C types of the FMI 3.0 headers;
//! * [`state`]: the legality table of FMI 3.0's state machines;
//! * [`api`]: instantiation (`fmi3InstantiateCoSimulation`, `fmi3InstantiateModelExchange`),
//!   `fmi3EnterInitializationMode` (with the experiment's setup), the typed getters and
//!   setters, `fmi3DoStep`, `fmi3UpdateDiscreteStates`, the calls the FMU does not support;
//! * [`model_exchange`]: the Model Exchange calls;
//! * [`model_description`]: the FMI 3.0 `modelDescription.xml`.
//!
//! Another version would be a crate like this one: its C types, its table, the calls whose
//! signatures differ, its model description. A model gets the FMI 3.0 symbols by forwarding
//! each `fmi3*` C function to the generic function here (the actuator's crate writes them out
//! in `src/fmu3_exports.rs`, so that cbindgen can read them).
//!
//! # Known limits
//! Co-Simulation without event mode, intermediate update or early return; no clocks, no
//! structural parameters, no array variables, no directional or adjoint derivatives, no
//! Scheduled Execution: each such call answers fmi3Error with a message that says so.

pub mod api;
pub mod model_description;
pub mod model_exchange;
pub mod state;
pub mod types;

#[cfg(test)]
mod tests;
