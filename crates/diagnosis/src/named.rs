//! A named effect earns its name only when the residual carries its own signature, not
//! merely because fitting it lowers the error. Each test returns whether the signature
//! is there and a sentence with the numbers it rests on.

use super::signals::{command_direction, stopper_velocity};
use super::signature::BINS;
use crate::blocks::Block;
use crate::recording::Recording;

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

/// Hysteresis after f3: at equal command the force is lower while the command rises than
/// while it falls, bin after bin of command level.
pub fn loop_with_command_direction(residual: &[f64], recording: &Recording, noise: f64) -> SignatureTest {
    let direction = command_direction(&recording.v_da);
    let (lo, hi) = recording
        .v_da
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let width = (hi - lo).max(1e-9) / BINS as f64;
    let mut sums = vec![[0.0f64; 4]; BINS];
    for k in 0..residual.len() {
        let bin = (((recording.v_da[k] - lo) / width) as usize).min(BINS - 1);
        if direction[k] > 0.0 {
            sums[bin][0] += residual[k];
            sums[bin][1] += 1.0;
        } else if direction[k] < 0.0 {
            sums[bin][2] += residual[k];
            sums[bin][3] += 1.0;
        }
    }
    let gaps: Vec<f64> = sums
        .iter()
        .filter(|s| s[1] >= 200.0 && s[3] >= 200.0)
        .map(|s| s[0] / s[1] - s[2] / s[3])
        .collect();
    if gaps.len() < 3 {
        return SignatureTest {
            present: false,
            sentence: "the command does not sweep both ways over enough of its range to show a loop".to_string(),
        };
    }
    let lower_rising = gaps.iter().filter(|g| **g < 0.0).count();
    let mean_gap = gaps.iter().sum::<f64>() / gaps.len() as f64;
    let present = 3 * lower_rising >= 2 * gaps.len() && -mean_gap > 2.0 * noise;
    SignatureTest {
        present,
        sentence: format!(
            "at equal command the residual is lower while the command rises than while it falls in {lower_rising} of {} command bins, by {:.4} N on average",
            gaps.len(),
            -mean_gap
        ),
    }
}

/// Whether a named effect has a signature test of its own here (the others pass by default).
pub fn has_signature_test(name: &str) -> bool {
    matches!(name, "sensor_offset_gain" | "piston_friction" | "jet_pipe_hysteresis")
}
