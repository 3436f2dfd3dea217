//! Diagnosis of a bench recording: where does the thesis model depart from it, what kind
//! of departure is it, and is it one of the named effects? The folders are the method's
//! stages, in the order a recording goes through them ([`diagnose`] runs them):
//!
//! 1. [`input`]: read and check the recording, measure each channel's noise floor and
//!    spectral lines, and cut it into training and held-out blocks; several recordings of one
//!    actuator are joined into one ([`diagnose_joint`]).
//! 2. [`replay`]: run the recording's inputs through the model (crate `jetpipe-model`), check
//!    the fits' fixed-step replay against the error-controlled one, and form the signals
//!    along the chain that a residual may follow.
//! 3. [`candidates`]: every correction the diagnosis may add, place by place: the written
//!    catalogue and the generated classes (static curves, a constant varying with a signal,
//!    products of the mechanics' signals, extra flows, quantisers).
//! 4. [`fit`]: fit each candidate through the model on the training blocks, score it on the
//!    held-out blocks with its penalty, and rank the places of the chain (optionally after
//!    the static calibration of `--calibrate`).
//! 5. [`decide`]: rounds of localization and addition: a named effect where the residual
//!    carries its signature, a discovered term otherwise; alternatives, compounds,
//!    elimination, and withdrawal of anything that leaves a worse model.
//! 6. [`verdict`]: the final accurate replays, the verdict and the remainder's signature,
//!    the report, and for a joint diagnosis each recording under the joint model.
//! 7. [`propose`]: from a report, what to record next: a protocol on which its leading
//!    explanations differ most (`jetpipe propose`).
//!
//! Beside the stages: [`policy`] states every threshold and precedence rule once,
//! [`statistics`] the small statistics every stage uses,
//! `context.rs` (its `Context`) is what every stage reads, and the result types live in the stage that
//! produces them and are re-exported here.

pub mod candidates;
pub mod decide;
pub mod fit;
pub mod input;
pub mod propose;
pub mod replay;
pub mod verdict;

mod context;
mod diagnose;
mod parallel;
pub mod policy;
pub mod statistics;
pub mod vocabulary;

pub use context::{Options, ProgressBars};
pub use decide::additions::{AddedEffect, DiscoveredTerm};
pub use decide::withdraw::Withdrawn;
pub use diagnose::{diagnose, diagnose_joint, diagnose_owned, diagnose_with};
pub use fit::scored::{Localization, Scored};
pub use replay::errors::Errors;
pub use verdict::diagnosis::{Diagnosis, Unexplained};
pub use verdict::joint::JointDiagnosis;
pub use verdict::split::PressureSplit;
