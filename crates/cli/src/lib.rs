//! The library parts of the `jetpipe` command-line tool (`src/bin/jetpipe.rs`):
//!
//! * [`sweep`]: parameter sweeps of the standard scenario over all cores (`jetpipe sweep`);
//! * [`linearization`]: the linear model about an equilibrium, its poles and zeros
//!   (`jetpipe linearize`);
//! * [`plots`]: the figures of `jetpipe diagnose --plots`.
//!
//! The model is crate `jetpipe-model`, the FMU `jetpipe-fmu` (library `jetpipe`), its archive
//! `jetpipe-packaging`, the diagnosis `jetpipe-diagnosis`.

pub mod linearization;
pub mod plots;
pub mod sweep;
