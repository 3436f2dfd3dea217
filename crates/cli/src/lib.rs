//! The library parts of the `jetpipe` command-line tool (`src/bin/jetpipe.rs`):
//!
//! * [`sweep`]: parameter sweeps of the standard scenario over all cores (`jetpipe sweep`);
//! * [`plots`]: the figures of a diagnosis (`jetpipe diagnose --plots`, and its pages);
//! * [`html_report`]: a diagnosis's self-contained HTML page, and a batch's index;
//! * [`batch`]: `jetpipe diagnose --out DIR` on many recordings over `--jobs` cores;
//! * [`output`]: result files written whole, and never over anything but a regular file;
//! * [`proposal`]: `jetpipe propose`'s JSON and page beside its protocol.
//!
//! The model is crate `jetpipe-model`, the FMU `jetpipe-fmu` (library `jetpipe`), its archive
//! `jetpipe-packaging`, the diagnosis `jetpipe-diagnosis`.

pub mod batch;
pub mod html_report;
pub mod output;
pub mod plots;
pub mod proposal;
pub mod sweep;
