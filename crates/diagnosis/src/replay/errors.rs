//! The force errors of a replay against the recording: over the whole, on the training and
//! on the held-out blocks, and each pressure's; the glitches set aside are left out of each.

use crate::input::blocks::Block;
use crate::replay::signals::difference;
use crate::replay::signals::rms_kept;
use crate::replay::signals::rms_where;
use crate::replay::Recording;
use crate::replay::Replay;

/// Errors of a force trace against the recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    pub rms: f64,
    pub nrmse: f64,
    pub train_rms: f64,
    pub heldout_rms: f64,
    /// RMS of each measured pressure minus the model's reading of it, Pa, over the whole
    /// recording (when it has pressure channels).
    pub pressure_rms: Option<[f64; 2]>,
}

pub(crate) fn errors(model: &Replay, recording: &Recording, blocks: &[Block]) -> Errors {
    let residual = difference(&recording.force, &model.force);
    let (lo, hi) = recording
        .force
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &f| (a.min(f), b.max(f)));
    let total = rms_kept(&residual, blocks);
    Errors {
        rms: total,
        nrmse: if hi > lo { total / (hi - lo) } else { 0.0 },
        train_rms: rms_where(&residual, blocks, Block::Training),
        heldout_rms: rms_where(&residual, blocks, Block::HeldOut),
        pressure_rms: match (&recording.p1, &recording.p2) {
            (Some(p1), Some(p2)) => Some([
                rms_kept(&difference(p1, &model.p1), blocks),
                rms_kept(&difference(p2, &model.p2), blocks),
            ]),
            _ => None,
        },
    }
}
