//! Diagnosis of a bench recording: where does the thesis model depart from it, and is
//! the departure one of the named effects?
//!
//! 1. Check the file (units, length, sampling) and estimate each channel's noise floor.
//! 2. Optionally re-identify what the thesis identified from static loops (`--calibrate`).
//! 3. Replay the recording's inputs through the model. With pressure channels, split the
//!    residual: the force against A_p (p1 − p2) speaks of the mechanics and the force
//!    sensor, the pressures against the model's of everything upstream.
//! 4. Fit every candidate correction ([`corrections`]) on the training blocks of all
//!    channels and score it on the held-out blocks; the place in the chain whose best
//!    candidate explains most of the held-out misfit is where the model departs.
//! 5. A named effect is added only when it is a candidate at that place, explains most of
//!    what that place can explain, lowers the force error by more than the noise
//!    ([`worth_adding`]), makes no
//!    channel worse, and the residual carries its own signature (`named.rs`). Repeat.
//! 6. Verdict: explained when the held-out force error after is within 1.5 noise floors;
//!    otherwise the remainder, where it sits in the chain and its signature.
//!
//! The recordings themselves are [`recording`]; [`replay`](mod@replay) runs their inputs
//! through the model (crate `jetpipe-model`).

pub mod acceleration;
pub mod agreement;
mod alternatives;
mod beside;
pub mod blocks;
pub mod calibrate;
pub mod checks;
pub mod command_gaps;
pub mod command_path;
mod conclude;
pub mod corrections;
pub mod curves;
pub mod discharge;
mod discover;
mod eliminate;
pub mod extra_flows;
pub mod lines;
mod localize;
pub mod modulation;
mod named;
mod named_instead;
mod named_places;
mod named_rivals;
pub mod noise;
mod oscillation;
mod pairs;
pub mod products;
mod quantiser;
pub mod recording;
pub mod replay;
mod report;
mod rounds;
pub mod signals;
pub mod signature;
mod split;
mod withdraw;

mod context;
mod diagnose;
mod named_effect;
pub mod policy;
mod refit;
pub mod results;

pub use context::*;
pub use diagnose::*;
pub(crate) use named_effect::*;
pub use policy::*;
pub(crate) use refit::*;
pub use results::*;
