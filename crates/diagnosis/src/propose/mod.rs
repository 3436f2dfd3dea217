//! Stage 7, what to record next (`jetpipe propose`): from a report that ties places or leaves
//! a remainder, a protocol (the command and the stopper position) that a bench can play and
//! on which the leading explanations of the recording differ most.
//!
//! 1. [`explanations`]: the rivals, read from the report: its own model, and the best
//!    first-round candidate at each tied place and at the next places of the ranking, each
//!    on the report's model without its additions.
//! 2. [`protocol`]: what a bench can play (±10 V, the stopper within 35–90 mm at most
//!    200 mm/s) as segments of steps, sines, chirps or ramps with the stopper held or swinging.
//! 3. [`design`]: segment after segment, the one of a few random draws after which the two
//!    closest explanations differ most, each explanation simulated by the model from where
//!    the segments before left it; the differences in the noise floors the report measured.

pub mod design;
pub mod explanations;
pub mod protocol;

pub use design::{propose, Proposal, ProposeOptions};

#[cfg(test)]
mod tests;
