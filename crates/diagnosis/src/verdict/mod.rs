//! Stage 6, the verdict: the final accurate replays, the pressure split, the residual's
//! signature, and the report.

pub(crate) mod conclude;
pub mod diagnosis;
pub mod joint;
pub(crate) mod report;
pub(crate) mod split;
