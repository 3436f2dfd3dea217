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

use crate::policy::BLOCK_SECONDS;

/// What a sample is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// Fitted on.
    Training,
    /// Scored on, never fitted.
    HeldOut,
    /// Before the model's starting state has faded: neither.
    Settling,
    /// A glitch of the recording ([`crate::input::glitches`]): neither, and left out of
    /// every error reported.
    SetAside,
}

impl Block {
    /// Whether the sample is fitted on or scored on.
    pub fn is_used(self) -> bool {
        matches!(self, Block::Training | Block::HeldOut)
    }

    /// `n` samples in alternate training and held-out blocks of `length` samples, training
    /// first: the blocks of the unit tests' recordings.
    #[cfg(test)]
    pub(crate) fn alternating(n: usize, length: usize) -> Vec<Block> {
        (0..n)
            .map(|k| {
                if (k / length) % 2 == 0 {
                    Block::Training
                } else {
                    Block::HeldOut
                }
            })
            .collect()
    }
}

/// Training samples are those in even-numbered blocks counted from the first sample,
/// held-out ones those in odd-numbered blocks; those before `settled_from` (s) are settling.
/// A short move of the stopper (`x_s`, m) is cut finer: see [`short_stopper_moves`]. Samples
/// within the `set_aside` spans (s, inclusive) are set aside.
pub fn blocks(time: &[f64], x_s: &[f64], settled_from: f64, set_aside: &[(f64, f64)]) -> Vec<Block> {
    let t0 = time.first().copied().unwrap_or(0.0);
    let mut blocks: Vec<Block> = time
        .iter()
        .map(|&t| {
            if t < settled_from {
                Block::Settling
            } else if ((t - t0) / BLOCK_SECONDS).floor() as i64 % 2 == 0 {
                Block::Training
            } else {
                Block::HeldOut
            }
        })
        .collect();
    for (start, end) in short_stopper_moves(time, x_s) {
        let from = start - MOVE_MARGIN_SECONDS;
        for k in time.partition_point(|&t| t < from)..time.partition_point(|&t| t <= end + MOVE_MARGIN_SECONDS) {
            if blocks[k] != Block::Settling {
                blocks[k] = if ((time[k] - from) / MOVE_PIECE_SECONDS).floor() as i64 % 2 == 0 {
                    Block::Training
                } else {
                    Block::HeldOut
                };
            }
        }
    }
    for &(from, to) in set_aside {
        let (first, end) = (time.partition_point(|&t| t < from), time.partition_point(|&t| t <= to));
        for block in &mut blocks[first..end] {
            *block = Block::SetAside;
        }
    }
    blocks
}

/// A stopper that rests and moves a few times shows whatever follows its motion (a force
/// with its acceleration or velocity) in those moves alone, mostly where it starts and stops.
/// Left in the blocks of [`BLOCK_SECONDS`], a recording with one move has it all in a
/// training block or all in a held-out one: the fits never see it, or the score never does.
/// So a move shorter than [`SHORT_MOVE_SECONDS`] and the [`MOVE_MARGIN_SECONDS`] either side
/// of it are cut in pieces of [`MOVE_PIECE_SECONDS`], fitted and scored in turn.
pub const SHORT_MOVE_SECONDS: f64 = 1.0;
/// What follows a stop (the force's response, a smoothed acceleration) lasts tens of ms.
pub const MOVE_MARGIN_SECONDS: f64 = 0.05;
/// Four pieces to a start or a stop that lasts 40 ms.
pub const MOVE_PIECE_SECONDS: f64 = 0.01;
/// A move is one when the stopper goes further than this (m): a position that only toggles
/// by its last logged digit is at rest.
pub const SMALLEST_MOVE: f64 = 1e-4;

/// The stopper's short moves, (first, last) time (s) at which it moves: runs of samples at
/// which the position changes, joined across gaps under [`MOVE_MARGIN_SECONDS`], shorter
/// than [`SHORT_MOVE_SECONDS`] and spanning more than [`SMALLEST_MOVE`]. A stopper moving
/// all along (shaken, or a noisy position) has none.
pub fn short_stopper_moves(time: &[f64], x_s: &[f64]) -> Vec<(f64, f64)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for k in 1..time.len().min(x_s.len()) {
        if x_s[k] == x_s[k - 1] {
            continue;
        }
        match runs.last_mut() {
            Some(run) if time[k - 1] - time[run.1] < MOVE_MARGIN_SECONDS => run.1 = k,
            _ => runs.push((k - 1, k)),
        }
    }
    runs.into_iter()
        .filter(|&(a, b)| time[b] - time[a] < SHORT_MOVE_SECONDS)
        .filter(|&(a, b)| {
            let (low, high) = x_s[a..=b]
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| (l.min(x), h.max(x)));
            high - low > SMALLEST_MOVE
        })
        .map(|(a, b)| (time[a], time[b]))
        .collect()
}

/// How many samples are `which`.
pub fn count(blocks: &[Block], which: Block) -> usize {
    blocks.iter().filter(|&&b| b == which).count()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::input::recording::Recording;

    pub(crate) fn recording_of(commands: impl Fn(f64) -> f64, seconds: f64) -> Recording {
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
            fast_replay: crate::input::recording::FastReplayMethod::default(),
            acceleration_window: 0.0,
            repeated_rows: vec![],
        }
    }

    #[test]
    fn samples_before_the_settling_time_are_neither_fitted_nor_scored() {
        let time: Vec<f64> = (0..1000).map(|k| k as f64 * 0.01).collect();
        let b = blocks(&time, &vec![0.05; time.len()], 0.5, &[]);
        assert!(b[..50].iter().all(|&x| x == Block::Settling));
        assert!(b[50..200].iter().all(|&x| x == Block::Training));
        assert!(b[200..400].iter().all(|&x| x == Block::HeldOut));
        assert!(b[400..600].iter().all(|&x| x == Block::Training));
        assert_eq!(count(&b, Block::HeldOut), 400);
    }

    #[test]
    fn a_short_stopper_move_inside_one_block_is_both_fitted_and_scored() {
        // 1 kHz, 10 s; the stopper rests at 67 mm, ramps to 76 mm over 2.4–2.7 s (inside the
        // held-out block 2–4 s) and rests again.
        let time: Vec<f64> = (0..10_000).map(|k| k as f64 * 1e-3).collect();
        let x_s: Vec<f64> = time
            .iter()
            .map(|&t| 0.067 + 0.009 * ((t - 2.4) / 0.3).clamp(0.0, 1.0))
            .collect();
        assert_eq!(short_stopper_moves(&time, &x_s).len(), 1);
        let b = blocks(&time, &x_s, 0.0, &[]);
        let within = |from: f64, to: f64, which: Block| {
            (0..time.len())
                .filter(|&k| time[k] >= from && time[k] <= to && b[k] == which)
                .count()
        };
        // The stop at 2.7 s and the start at 2.4 s each have pieces of both kinds.
        for at in [2.4, 2.7] {
            assert!(
                within(at - 0.02, at + 0.02, Block::Training) >= 10,
                "training near {at} s"
            );
            assert!(
                within(at - 0.02, at + 0.02, Block::HeldOut) >= 10,
                "held out near {at} s"
            );
        }
        // Away from the move the blocks of 2 s stay.
        assert!(within(2.0, 2.3, Block::Training) == 0 && within(2.8, 3.99, Block::Training) == 0);
        assert!(within(0.0, 1.99, Block::HeldOut) == 0);
    }

    #[test]
    fn a_stopper_at_rest_moving_all_along_or_toggling_its_last_digit_keeps_the_plain_blocks() {
        let time: Vec<f64> = (0..10_000).map(|k| k as f64 * 1e-3).collect();
        let plain = blocks(&time, &vec![0.05; time.len()], 0.0, &[]);
        let shaken: Vec<f64> = time.iter().map(|&t| 0.05 + 0.005 * (6.0 * t).sin()).collect();
        let toggling: Vec<f64> = (0..time.len()).map(|k| 0.05 + 1e-6 * (k / 7 % 2) as f64).collect();
        // A single long move (3 s) is already split by the blocks.
        let long_move: Vec<f64> = time
            .iter()
            .map(|&t| 0.05 + 0.01 * ((t - 3.0) / 3.0).clamp(0.0, 1.0))
            .collect();
        for x_s in [shaken, toggling, long_move] {
            assert!(short_stopper_moves(&time, &x_s).is_empty());
            assert_eq!(blocks(&time, &x_s, 0.0, &[]), plain);
        }
    }

    #[test]
    fn samples_within_a_glitch_span_are_set_aside_and_no_others() {
        let time: Vec<f64> = (0..10_000).map(|k| k as f64 * 1e-3).collect();
        let x_s = vec![0.05; time.len()];
        let plain = blocks(&time, &x_s, 0.5, &[]);
        let marked = blocks(&time, &x_s, 0.5, &[(3.0, 3.0), (6.1, 6.1795)]);
        for (k, (&p, &m)) in plain.iter().zip(&marked).enumerate() {
            let inside = k == 3000 || (6100..=6179).contains(&k);
            assert_eq!(m, if inside { Block::SetAside } else { p }, "sample {k}");
        }
    }
}
