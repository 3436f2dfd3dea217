//! How long the model's starting state shows in its outputs on a recording: the stretch at the
//! start that is neither fitted nor scored ([`crate::input::blocks`]).

use crate::input::recording::Recording;
use crate::policy::BLOCK_SECONDS;
use crate::replay::{replay_fast_from, Start};
use jetpipe_model::physics::actuator::Actuator;

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
    use crate::input::blocks::tests::recording_of;
    use jetpipe_model::physics::parameters::Parameters;

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
