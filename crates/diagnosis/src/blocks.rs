//! Which samples the fits train on and which score them: alternate blocks of
//! [`BLOCK_SECONDS`], after a first stretch in which the model's
//! unknown starting state still shows.
//!
//! A replay starts from the equilibrium of the first recorded command, as if the bench had
//! held it before the recording began. A bench that was already running (a controller
//! acting, a command changing) was not there: until the chambers have forgotten where they
//! started, the model and the recording differ by a transient that no correction of the
//! model explains, and a fit that trains on it bends every term towards it. How long the
//! starting state matters is the model's to say: it is replayed from the equilibria of the
//! lowest and the highest command of the first block (a bench running before the recording
//! began was most likely doing what it does in its first seconds), and the samples until
//! every channel of those replays agrees with the first one within 0.3 of its noise are
//! neither fitted nor scored.

use crate::recording::Recording;
use crate::replay::{replay_fast_from, Start};
use crate::BLOCK_SECONDS;
use jetpipe_model::physics::actuator::Actuator;

/// What a sample is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// Fitted on.
    Training,
    /// Scored on, never fitted.
    HeldOut,
    /// Before the model's starting state has faded: neither.
    Settling,
}

/// Training samples are those in even-numbered blocks counted from the first sample,
/// held-out ones those in odd-numbered blocks; those before `settled_from` (s) are settling.
pub fn blocks(time: &[f64], settled_from: f64) -> Vec<Block> {
    let t0 = time.first().copied().unwrap_or(0.0);
    time.iter()
        .map(|&t| {
            if t < settled_from {
                Block::Settling
            } else if ((t - t0) / BLOCK_SECONDS).floor() as i64 % 2 == 0 {
                Block::Training
            } else {
                Block::HeldOut
            }
        })
        .collect()
}

/// How many samples are `which`.
pub fn count(blocks: &[Block], which: Block) -> usize {
    blocks.iter().filter(|&&b| b == which).count()
}

/// Replays from another starting state must agree with the first replay within this
/// fraction of each channel's noise floor: what is left adds at most a tenth to the noise's
/// mean square, 5 % to its RMS. (A tenth of the floor would cost a 20 s recording under
/// force tracking a quarter of its samples: the chambers' common pressure forgets its start
/// slowly, 0.3 of the floor about 3.7 s after the start and 0.1 of it after 5 s.)
pub const SETTLED_WITHIN_NOISE: f64 = 0.3;
/// The settling stretch is looked for in at most this share of the recording…
pub const MOST_OF_THE_SPAN: f64 = 0.25;
/// …and in at most this many seconds.
pub const LONGEST_SETTLING: f64 = 10.0;

/// The time (s) from which `model`'s starting state no longer shows in its outputs on
/// `recording`, to within [`SETTLED_WITHIN_NOISE`] of each channel's floor in `noise`
/// (force, p1, p2; 0 for a channel not weighed), the start taken to lie among the
/// equilibria of the first block's commands. At most a quarter of the recording or
/// [`LONGEST_SETTLING`] in. The replays start at those equilibria even where the recording's
/// pressures give the chambers' start: what the transducers do not read (the jet pipe's
/// hysteresis memory, say) stays unknown for as long as such a start shows.
pub fn settling_time(model: &Actuator, recording: &Recording, noise: [f64; 3]) -> Result<f64, String> {
    let time = &recording.time;
    let t0 = time[0];
    let span = time[time.len() - 1] - t0;
    let horizon = t0 + (MOST_OF_THE_SPAN * span).min(LONGEST_SETTLING);
    let end = time.partition_point(|&t| t <= horizon).max(1);
    let first_block = time.partition_point(|&t| t < t0 + BLOCK_SECONDS);
    let (lowest, highest) = recording.v_da[..first_block.max(1)]
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let first = replay_fast_from(model, recording, end, Start::AtEquilibrium(recording.v_da[0]))?;
    let mut last_apart: Option<usize> = None;
    for held in [lowest, highest] {
        if held == recording.v_da[0] {
            continue;
        }
        let other = replay_fast_from(model, recording, end, Start::AtEquilibrium(held))?;
        let channels = [
            (&first.force, &other.force),
            (&first.p1, &other.p1),
            (&first.p2, &other.p2),
        ];
        for (c, (a, b)) in channels.into_iter().enumerate() {
            if noise[c] <= 0.0 {
                continue;
            }
            let limit = SETTLED_WITHIN_NOISE * noise[c];
            if let Some(k) = (0..end)
                .rev()
                .find(|&k| (a[k] - b[k]).abs() > limit || !(a[k] - b[k]).is_finite())
            {
                last_apart = Some(last_apart.map_or(k, |l: usize| l.max(k)));
            }
        }
    }
    Ok(match last_apart {
        None => t0,
        Some(k) if k + 1 >= end => horizon,
        Some(k) => time[k + 1],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use jetpipe_model::physics::parameters::Parameters;

    fn recording_of(commands: impl Fn(f64) -> f64, seconds: f64) -> Recording {
        let n = (seconds * 1000.0) as usize;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let v_da: Vec<f64> = time.iter().map(|&t| commands(t)).collect();
        Recording {
            x_s: vec![0.054; n],
            force: vec![0.0; n],
            p1: None,
            p2: None,
            time,
            v_da,
            full_rate: None,
            fast_replay_step: crate::replay::MAX_FAST_STEP,
            acceleration_window: 0.0,
        }
    }

    #[test]
    fn samples_before_the_settling_time_are_neither_fitted_nor_scored() {
        let time: Vec<f64> = (0..1000).map(|k| k as f64 * 0.01).collect();
        let b = blocks(&time, 0.5);
        assert!(b[..50].iter().all(|&x| x == Block::Settling));
        assert!(b[50..200].iter().all(|&x| x == Block::Training));
        assert!(b[200..400].iter().all(|&x| x == Block::HeldOut));
        assert!(b[400..600].iter().all(|&x| x == Block::Training));
        assert_eq!(count(&b, Block::HeldOut), 400);
    }

    #[test]
    fn the_starting_state_fades_within_the_chambers_time_constants_and_not_at_once() {
        let model = Actuator::new(Parameters::default()).unwrap();
        let recording = recording_of(|t| if (1.0..1.5).contains(&t) { 6.0 } else { 1.0 }, 20.0);
        let settled = settling_time(&model, &recording, [0.05, 0.0, 0.0]).unwrap();
        // The first block's commands span 1–6 V; a start from the equilibrium of 6 V while
        // 1 V is held relaxes through the chambers (tens of ms), not in one sample, and
        // within a few seconds.
        assert!(settled > 0.02 && settled < 4.0, "settled from {settled} s");
        // A coarser noise floor forgives more of the transient.
        let coarse = settling_time(&model, &recording, [5.0, 0.0, 0.0]).unwrap();
        assert!(coarse < settled, "{coarse} against {settled}");
    }

    #[test]
    fn a_recording_whose_command_never_changes_has_nothing_to_settle() {
        let model = Actuator::new(Parameters::default()).unwrap();
        let recording = recording_of(|_| 2.0, 10.0);
        assert_eq!(settling_time(&model, &recording, [0.05, 0.0, 0.0]).unwrap(), 0.0);
    }
}
