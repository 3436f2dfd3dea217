//! A generic FMI 2.0 layer, Co-Simulation and (for a model that has it) Model Exchange: C ABI, state machine, logging, FMU state.
//! It knows nothing about the model behind it: see [`model::CoSimModel`].
//!
//! It is also the common part of the FMI 3.0 layer (crate `fmi3`): the model traits and the
//! variable table, instances and the registry of live handles, [`api::guarded`] (run with
//! either version's table of functions, a [`state::Call`]), the per-variable checks, the
//! getters' and setters' loops, the FMU-state calls and bytes, the Model Exchange calls
//! (`*_as` with the version's function). An instance records its [`state::Version`] and is
//! refused by the other version's calls.
//!
//! # Using it
//! * Implement [`model::CoSimModel`] (variable table in a [`model::ModelInfo`]).
//! * Export the `fmi2*` C symbols as forwarders to [`api`] instantiated for the type: with
//!   [`fmi2_cosimulation_exports!`] in the model's cdylib crate (the actuator's crate,
//!   the root package of the repository, writes the same forwarders out literally for cbindgen).
//! * Write `modelDescription.xml` with
//!   [`model_description::model_description_xml`]`(M::info())` (panics on a broken
//!   table; [`model_description::try_model_description_xml`] returns the problems).
//!
//! # Modules
//! * [`types`]: the C types of the FMI 2.0 headers.
//! * [`state`]: the state machine and the table of legal calls per state.
//! * [`instance`]: one FMU instance, logging (always `"%s"` + the text; fmi2Discard,
//!   fmi2Error and fmi2Fatal are always passed to the logger, other statuses only when
//!   logging is on for their category).
//! * [`api`]: one generic function per FMI call (argument checks, `catch_unwind`).
//! * [`model_exchange`]: the Model Exchange calls, for a model that implements
//!   [`model::ModelExchangeModel`] and declares [`model::ModelInfo::model_exchange`].
//! * [`fmu_state`]: FMU-state snapshots and their checksummed byte format (which records the
//!   FMI version and the interface of the instance).
//! * [`fmu_state_calls`]: get, set, free and (de)serialize FMU states, for either version.
//! * [`state_bytes`]: the byte format of a model's own state inside it (magic, versions,
//!   little-endian numbers), with [`state_format!`].
//! * [`model_description`]: the XML generator and table validation.
//! * [`testing`]: a dummy first-order-lag model for tests.
//! * [`fmi2_cosimulation_exports!`]: the exported `fmi2*` symbols for a model.
//!
//! # Known limits
//! * Instances and FMU states are recorded in a process-wide registry of live handles
//!   (a mutex-protected set of addresses, locked only for the look-up): a NULL, freed or
//!   foreign handle (a double `fmi2FreeInstance`, a use after free) is an fmi2Error
//!   without its memory being read. The only case not caught: a freed address that the
//!   allocator has meanwhile given to a new instance (or FMU state) is that new one.
//! * Only synchronous stepping: `fmi2CancelStep` is always an illegal call, the
//!   `stepInProgress` state does not exist, `fmi2GetStatus` answers fmi2Discard.
//! * After a panic the instance is `fatal`; only `fmi2FreeInstance` is accepted. Other
//!   instances are unaffected (there is no shared state). The default Rust panic hook
//!   still prints the panic to stderr.
//! * Argument and model errors return fmi2Error but do not move the instance to the
//!   `error` state (the model contract says nothing was changed); a multi-value setter
//!   stops at the first value the model rejects, earlier values stay set.

pub mod api;
mod exports_macro;
pub mod fmu_state;
pub mod fmu_state_calls;
pub mod instance;
pub mod model;
pub mod model_description;
pub mod model_exchange;
pub mod state;
pub mod state_bytes;
pub mod structure_check;
pub mod testing;
pub mod types;

#[cfg(test)]
mod model_exchange_tests;
#[cfg(test)]
mod tests;

/// The paths `fmi2_cosimulation_exports!` expands to, `$crate::fmi2::api` and
/// `$crate::fmi2::types`: those of the time this layer was the module `fmi2` of the jetpipe
/// crate, kept so that the macro's text did not change when the layer became a crate.
#[doc(hidden)]
pub mod fmi2 {
    pub use crate::{api, types};
}
