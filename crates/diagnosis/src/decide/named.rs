//! A named effect earns its name only when the residual carries its own signature, not
//! merely because fitting it lowers the error. Each test returns whether the signature
//! is there and a sentence with the numbers it rests on.

use crate::input::blocks::Block;
use crate::input::recording::Recording;
use crate::input::stopper_motion::stopper_velocity;
use crate::replay::signals::command_direction;
use crate::replay::signature::BINS;

/// What a signature test found.
pub struct SignatureTest {
    pub present: bool,
    pub sentence: String,
}

/// Held-out RMS of `residual − fit` for least squares on `columns` over the training samples.
fn heldout_rms_after(residual: &[f64], columns: &[Vec<f64>], blocks: &[Block]) -> f64 {
    let m = columns.len();
    let mut ata = nalgebra::DMatrix::<f64>::zeros(m, m);
    let mut atb = nalgebra::DVector::<f64>::zeros(m);
    for k in 0..residual.len() {
        if blocks[k] != Block::Training {
            continue;
        }
        for a in 0..m {
            atb[a] += columns[a][k] * residual[k];
            for b in 0..m {
                ata[(a, b)] += columns[a][k] * columns[b][k];
            }
        }
    }
    let x = ata.lu().solve(&atb).unwrap_or_else(|| nalgebra::DVector::zeros(m));
    let (mut sum, mut n) = (0.0, 0usize);
    for k in 0..residual.len() {
        if blocks[k] != Block::HeldOut {
            continue;
        }
        let fit: f64 = (0..m).map(|a| x[a] * columns[a][k]).sum();
        sum += (residual[k] - fit).powi(2);
        n += 1;
    }
    (sum / n.max(1) as f64).sqrt()
}

/// A sensor offset and gain leave the force and what the pressures (or, without them,
/// the model) say disagreeing as an affine map: a smooth curve must not do much better.
pub fn sensor_is_affine(residual: &[f64], reference: &[f64], blocks: &[Block], noise: f64) -> SignatureTest {
    let ones = vec![1.0; reference.len()];
    let squares: Vec<f64> = reference.iter().map(|f| f * f).collect();
    let cubes: Vec<f64> = reference.iter().map(|f| f * f * f).collect();
    let affine = heldout_rms_after(residual, &[ones.clone(), reference.to_vec()], blocks);
    let curve = heldout_rms_after(residual, &[ones, reference.to_vec(), squares, cubes], blocks);
    let present = affine <= 2.0 * noise || affine - curve <= noise;
    SignatureTest {
        present,
        sentence: format!(
            "an affine map of the force leaves {affine:.4} N held out and a cubic {curve:.4} N (noise {noise:.4} N): {}",
            if present {
                "the disagreement is affine, as an offset and a gain make it"
            } else {
                "the disagreement is curved, which an offset and a gain cannot make"
            }
        ),
    }
}

/// Friction opposes the stopper's motion: while it moves, the residual is negative moving
/// out and positive moving in, and sign(dx_s/dt) explains a good part of it.
pub fn friction_changes_sign(residual: &[f64], recording: &Recording, noise: f64) -> SignatureTest {
    let v = stopper_velocity(recording);
    let (mut sum_out, mut n_out, mut sum_in, mut n_in) = (0.0, 0usize, 0.0, 0usize);
    let mut moving = vec![];
    for (k, &speed) in v.iter().enumerate() {
        if speed > 1e-9 {
            sum_out += residual[k];
            n_out += 1;
            moving.push(k);
        } else if speed < -1e-9 {
            sum_in += residual[k];
            n_in += 1;
            moving.push(k);
        }
    }
    if n_out < 100 || n_in < 100 {
        return SignatureTest {
            present: false,
            sentence: "the stopper hardly moves, so friction cannot show".to_string(),
        };
    }
    let (out, into) = (sum_out / n_out as f64, sum_in / n_in as f64);
    let mean = moving.iter().map(|&k| residual[k]).sum::<f64>() / moving.len() as f64;
    let total: f64 = moving.iter().map(|&k| (residual[k] - mean).powi(2)).sum();
    let between = n_out as f64 * (out - mean).powi(2) + n_in as f64 * (into - mean).powi(2);
    let share = if total > 0.0 { between / total } else { 0.0 };
    let present = out < 0.0 && into > 0.0 && 0.5 * (into - out) > noise && share > 0.3;
    SignatureTest {
        present,
        sentence: format!(
            "while the stopper moves the residual averages {out:+.4} N moving out and {into:+.4} N moving in, and the direction of motion explains {:.0} % of its variance there",
            100.0 * share
        ),
    }
}

/// The mean of `signal` while the command rises less its mean while the command falls, in
/// each bin of command level both directions visit for at least 200 samples: the loop a
/// signal draws against the command. The bins are quantiles of the command while it moves,
/// not equal widths of its whole range: a recording that sweeps both ways over a narrow
/// band (a multisine about a mean) and crosses the rest once (ramps between levels) shows
/// its loop in that band, which equal widths of the whole range would give two bins.
fn rising_less_falling(signal: &[f64], recording: &Recording) -> Vec<Option<f64>> {
    let direction = command_direction(&recording.v_da);
    let mut moving: Vec<f64> = recording
        .v_da
        .iter()
        .zip(&direction)
        .filter(|(_, d)| **d != 0.0)
        .map(|(v, _)| *v)
        .collect();
    if moving.is_empty() {
        return vec![];
    }
    moving.sort_by(|a, b| a.total_cmp(b));
    let edges: Vec<f64> = (1..BINS).map(|b| moving[b * moving.len() / BINS]).collect();
    let mut sums = vec![[0.0f64; 4]; BINS];
    for (k, &value) in signal.iter().enumerate() {
        let bin = edges.partition_point(|edge| *edge <= recording.v_da[k]);
        if direction[k] > 0.0 {
            sums[bin][0] += value;
            sums[bin][1] += 1.0;
        } else if direction[k] < 0.0 {
            sums[bin][2] += value;
            sums[bin][3] += 1.0;
        }
    }
    sums.iter()
        .map(|s| (s[1] >= 200.0 && s[3] >= 200.0).then(|| s[0] / s[1] - s[2] / s[3]))
        .collect()
}

/// Hysteresis after f3 draws a loop against the command: at equal command the force differs
/// while the command rises from while it falls. Which way depends on how fast the command
/// moves: followed quasi-statically the force is lower while rising; under a command faster
/// than the chambers (a chirp to 20 Hz) the force lags by more than a quarter period and the
/// loop turns over. So the residual's loop is held against the loop the fitted effect draws
/// (`effect`, the fitted model's force less the current one): the same way bin after bin of
/// command level, and by more than twice the noise on average.
pub fn loop_with_command_direction(
    residual: &[f64],
    effect: &[f64],
    recording: &Recording,
    noise: f64,
) -> SignatureTest {
    let pairs: Vec<(f64, f64)> = rising_less_falling(residual, recording)
        .into_iter()
        .zip(rising_less_falling(effect, recording))
        .filter_map(|(r, e)| Some((r?, e?)))
        .collect();
    if pairs.len() < 3 {
        return branch_gap_at_held_levels(residual, effect, recording, noise);
    }
    // The residual's gap counted positive where it runs the way the effect's does.
    let aligned: Vec<f64> = pairs.iter().map(|(r, e)| r * e.signum()).collect();
    let same_way = aligned.iter().filter(|g| **g > 0.0).count();
    let mean_gap = aligned.iter().sum::<f64>() / aligned.len() as f64;
    let effect_lower_rising = pairs.iter().filter(|(_, e)| *e < 0.0).count();
    let present = 3 * same_way >= 2 * aligned.len() && mean_gap > 2.0 * noise;
    SignatureTest {
        present,
        sentence: format!(
            "at equal command the residual differs between rising and falling commands the way the fitted hysteresis makes it in {same_way} of {} command bins, by {mean_gap:.4} N on average (the hysteresis lowers the force while the command rises in {effect_lower_rising} of them)",
            aligned.len(),
        ),
    }
}

/// The gap between the branches, rising less falling, with a cubic in the command taken
/// out, over the samples after the command's first move, and the share of the branch's
/// variance the cubic leaves (how far the branch is told apart from the level).
fn branch_gap(signal: &[f64], recording: &Recording, direction: &[f64]) -> Option<(f64, f64)> {
    let samples: Vec<usize> = (0..signal.len()).filter(|&k| direction[k] != 0.0).collect();
    if samples.len() < 400 {
        return None;
    }
    let row = |k: usize| {
        let v = recording.v_da[k];
        [1.0, v, v * v, v * v * v, direction[k]]
    };
    let mut ata = nalgebra::Matrix5::<f64>::zeros();
    let mut atb = nalgebra::Vector5::<f64>::zeros();
    for &k in &samples {
        let x = nalgebra::Vector5::from(row(k));
        ata += x * x.transpose();
        atb += x * signal[k];
    }
    let inverse = ata.try_inverse()?;
    let coefficients = inverse * atb;
    // 1 / (A^T A)^-1 [4,4] is the branch's sum of squares left after the cubic.
    let n = samples.len() as f64;
    let mean_direction = samples.iter().map(|&k| direction[k]).sum::<f64>() / n;
    let direction_variance = samples
        .iter()
        .map(|&k| (direction[k] - mean_direction).powi(2))
        .sum::<f64>();
    let distinct = if inverse[(4, 4)] > 0.0 && direction_variance > 0.0 {
        1.0 / inverse[(4, 4)] / direction_variance
    } else {
        0.0
    };
    Some((2.0 * coefficients[4], distinct))
}

/// A command held at levels (a staircase, a slow PRBS) meets few command bins both ways, but
/// the hysteresis still draws its loop: each held level sits on the branch of the command's
/// last move, which a staircase reaches from below at some levels and from above at others.
/// The branch's step is read with a cubic in the command taken out; it counts only where
/// the levels reached each way interleave enough that the cubic leaves at least a fifth of
/// the branch's variance, and the residual's step must run the fitted hysteresis's way, by
/// more than twice the noise and within a factor two of the effect's.
fn branch_gap_at_held_levels(residual: &[f64], effect: &[f64], recording: &Recording, noise: f64) -> SignatureTest {
    let direction = command_direction(&recording.v_da);
    let (Some((gap, distinct)), Some((effect_gap, _))) = (
        branch_gap(residual, recording, &direction),
        branch_gap(effect, recording, &direction),
    ) else {
        return SignatureTest {
            present: false,
            sentence: "the command hardly moves, so no loop can show".to_string(),
        };
    };
    if distinct < 0.2 {
        return SignatureTest {
            present: false,
            sentence: format!(
                "the command does not sweep both ways over enough of its range to show a loop, and the levels it reaches rising and falling do not interleave enough to tell the branch from the level ({:.0} % of the branch's variance is left beside a cubic in the command)",
                100.0 * distinct
            ),
        };
    }
    let aligned = gap * effect_gap.signum();
    let ratio = if effect_gap != 0.0 { gap / effect_gap } else { 0.0 };
    let present = aligned > 2.0 * noise && (0.5..=2.0).contains(&ratio);
    SignatureTest {
        present,
        sentence: format!(
            "the command is mostly held, so few levels are met both ways; over the levels it reaches rising and falling, with a cubic in the command taken out, the residual is {gap:+.4} N higher on the rising branch and the fitted hysteresis makes it {effect_gap:+.4} N"
        ),
    }
}

/// Whether a named effect has a signature test of its own here (the others pass by default).
pub fn has_signature_test(name: &str) -> bool {
    matches!(name, "sensor_offset_gain" | "piston_friction" | "jet_pipe_hysteresis")
}

#[cfg(test)]
mod tests {
    use super::{branch_gap_at_held_levels, loop_with_command_direction};
    use crate::input::recording::Recording;

    /// A triangle command from 0 to 10 V, 2 s a period, for 20 s at 1 kHz.
    fn triangle() -> Recording {
        let n = 20_000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let v_da = time
            .iter()
            .map(|t| {
                let phase = t % 2.0;
                if phase < 1.0 {
                    10.0 * phase
                } else {
                    10.0 * (2.0 - phase)
                }
            })
            .collect();
        Recording::of(time, v_da, vec![0.06; n], vec![0.0; n])
    }

    #[test]
    fn a_loop_is_the_hysteresis_signature_when_it_turns_the_way_the_fitted_hysteresis_turns_it_either_way() {
        let recording = triangle();
        let rising: Vec<f64> = (1..recording.v_da.len())
            .map(|k| recording.v_da[k] - recording.v_da[k - 1])
            .chain([0.0])
            .map(|dv| dv.signum())
            .collect();
        let noise = 0.05;
        // A loop 0.5 N high while the command rises (as under a command faster than the
        // chambers), and a fitted hysteresis that draws it so: present.
        let higher_rising: Vec<f64> = rising.iter().map(|s| 0.25 * s).collect();
        assert!(loop_with_command_direction(&higher_rising, &higher_rising, &recording, noise).present);
        // The quasi-static loop, lower while rising: present with an effect that turns that way.
        let lower_rising: Vec<f64> = higher_rising.iter().map(|x| -x).collect();
        assert!(loop_with_command_direction(&lower_rising, &lower_rising, &recording, noise).present);
        // A residual whose loop runs against the fitted one's: absent.
        let against = loop_with_command_direction(&lower_rising, &higher_rising, &recording, noise);
        assert!(!against.present, "{}", against.sentence);
        // A loop within twice the noise: absent.
        let small: Vec<f64> = higher_rising.iter().map(|x| 0.1 * x).collect();
        assert!(!loop_with_command_direction(&small, &higher_rising, &recording, noise).present);
        // A drift in time draws no loop against the command: absent.
        let drift: Vec<f64> = recording.time.iter().map(|t| 0.05 * t).collect();
        assert!(!loop_with_command_direction(&drift, &higher_rising, &recording, noise).present);
    }

    #[test]
    fn a_loop_drawn_in_a_narrow_band_the_command_sweeps_both_ways_shows_though_ramps_cross_the_rest_once() {
        // Ramps up from 0 to 10 V in 5 s, a fall to 5 V, then a 1 Hz sine of ±0.8 V about
        // 5 V for 20 s, at 1 kHz: equal widths of the whole range would give the sine two
        // bins of 1 V, too few to show a loop.
        let n = 25_000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let v_da: Vec<f64> = time
            .iter()
            .map(|&t| {
                if t < 5.0 {
                    2.0 * t
                } else {
                    5.0 + 0.8 * (2.0 * std::f64::consts::PI * (t - 5.0)).sin()
                }
            })
            .collect();
        let mut recording = triangle();
        recording.time = time;
        recording.v_da = v_da;
        recording.x_s = vec![0.06; n];
        recording.force = vec![0.0; n];
        let direction = crate::replay::signals::command_direction(&recording.v_da);
        let loop_in_sine: Vec<f64> = (0..n)
            .map(|k| if k >= 5_000 { 0.25 * direction[k] } else { 0.0 })
            .collect();
        let test = loop_with_command_direction(&loop_in_sine, &loop_in_sine, &recording, 0.05);
        assert!(test.present, "{}", test.sentence);
    }

    #[test]
    fn a_staircase_held_at_levels_reached_from_below_and_above_shows_the_loop_on_the_branch_of_the_last_move() {
        // Sixteen levels held 1 s each at 1 kHz, zigzagging up and then down so that levels
        // reached from below and from above interleave.
        let levels = [
            1.0, 3.0, 2.0, 5.0, 4.0, 7.0, 6.0, 9.0, 8.0, 6.5, 7.5, 4.5, 5.5, 2.5, 3.5, 0.5,
        ];
        let n = 1000 * levels.len();
        let mut recording = triangle();
        recording.time = (0..n).map(|k| k as f64 * 1e-3).collect();
        recording.v_da = (0..n).map(|k| levels[k / 1000]).collect();
        recording.x_s = vec![0.06; n];
        recording.force = vec![0.0; n];
        let direction = crate::replay::signals::command_direction(&recording.v_da);
        let noise = 0.05;
        let lower_rising: Vec<f64> = direction.iter().map(|d| -0.25 * d).collect();
        let test = branch_gap_at_held_levels(&lower_rising, &lower_rising, &recording, noise);
        assert!(test.present, "{}", test.sentence);
        // Against the fitted hysteresis's way, or a fitted loop four times the residual's: absent.
        let higher_rising: Vec<f64> = lower_rising.iter().map(|x| -x).collect();
        assert!(!branch_gap_at_held_levels(&lower_rising, &higher_rising, &recording, noise).present);
        let four_times: Vec<f64> = lower_rising.iter().map(|x| 4.0 * x).collect();
        assert!(!branch_gap_at_held_levels(&lower_rising, &four_times, &recording, noise).present);
        // A curve in the command level (a kink, as a dead zone's), or a drift in time, is no
        // loop: absent.
        let curve: Vec<f64> = recording.v_da.iter().map(|v| 0.3 * (v - 5.0).max(0.0)).collect();
        assert!(!branch_gap_at_held_levels(&curve, &lower_rising, &recording, noise).present);
        let drift: Vec<f64> = recording.time.iter().map(|t| 0.05 * t).collect();
        assert!(!branch_gap_at_held_levels(&drift, &lower_rising, &recording, noise).present);
        // A staircase that only climbs cannot tell the branch from the level: absent.
        let climbing: Vec<f64> = (0..n).map(|k| 0.5 * (k / 1000) as f64).collect();
        recording.v_da = climbing;
        let test = branch_gap_at_held_levels(&lower_rising, &lower_rising, &recording, noise);
        assert!(!test.present, "{}", test.sentence);
    }
}
