//! The library parts of the `jetpipe` command-line tool (`src/bin/jetpipe.rs`):
//!
//! * [`sweep`]: parameter sweeps of the standard scenario over all cores (`jetpipe sweep`);
//! * [`plots`]: the figures of `jetpipe diagnose --plots`.
//!
//! The model is crate `jetpipe-model`, the FMU `jetpipe-fmu` (library `jetpipe`), its archive
//! `jetpipe-packaging`, the diagnosis `jetpipe-diagnosis`.

pub mod plots;
pub mod sweep;
