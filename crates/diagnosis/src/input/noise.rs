//! Sensor noise of a recorded channel, from its second differences.
//!
//! For white noise of standard deviation σ, the second difference x(k+1) − 2x(k) + x(k−1)
//! has variance 6σ². The mean square of the second differences is taken over short
//! windows, and a low quantile over the windows is kept: a window where the signal itself
//! curves (a step, a fast chirp, a stopper shaken at 2 Hz sampled at 250 Hz) only lifts its
//! own mean square, and where the signal curves in most windows a median is lifted with
//! them, while the quietest tenth still holds the noise alone. A quantile of mean squares
//! does not jump between the few values a quantised channel's second differences take
//! (the median of the single differences did: 0.046 or 0.055 N on 0.050 N of noise).

use crate::statistics::correlation;

/// Second differences per window.
pub const WINDOW: usize = 64;

/// The quantile of the windows' mean squares kept.
const QUANTILE: f64 = 0.1;

/// Windows needed for [`QUANTILE`]; with fewer, the median.
const WINDOWS_FOR_QUANTILE: usize = 30;

/// The quantile of a window's mean square over its mean for Gaussian white noise: the mean
/// square of 64 second differences has about ν = 33 effective degrees of freedom (adjacent
/// second differences correlate by −2/3 and 1/6), and by Wilson–Hilferty the quantile p of
/// χ²(ν)/ν is (1 − 2/(9ν) + z_p √(2/(9ν)))³: 0.980 for the median (z = 0),
/// 0.700 for the tenth (z = −1.2816).
fn quantile_over_mean(z: f64) -> f64 {
    let nu: f64 = 33.0;
    let a = 2.0 / (9.0 * nu);
    (1.0 - a + z * a.sqrt()).powi(3)
}

/// Estimated standard deviation of the noise of `x` (sampled at a regular rate).
pub fn noise_floor(x: &[f64]) -> f64 {
    if x.len() < 3 {
        return 0.0;
    }
    let second: Vec<f64> = x.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
    let windows: Vec<&[f64]> = second.chunks_exact(WINDOW).collect();
    if windows.len() < 3 {
        // Too short for windows: the mean square of all of them.
        let mean = second.iter().map(|d| d * d).sum::<f64>() / second.len() as f64;
        return (mean / 6.0).sqrt();
    }
    let mean_square = |c: &&[f64]| c.iter().map(|d| d * d).sum::<f64>() / WINDOW as f64;
    // A window where the channel stands still for half its samples (a reading held at its
    // rail, a channel rounded coarser than its noise) carries no noise to measure: such
    // windows are left out while three others remain.
    let moving: Vec<f64> = windows
        .iter()
        .filter(|c| 2 * c.iter().filter(|d| **d == 0.0).count() <= WINDOW)
        .map(mean_square)
        .collect();
    let mut squares = if moving.len() >= 3 {
        moving
    } else {
        windows.iter().map(mean_square).collect()
    };
    let (rank, z) = if squares.len() >= WINDOWS_FOR_QUANTILE {
        ((QUANTILE * squares.len() as f64) as usize, -1.2816)
    } else {
        (squares.len() / 2, 0.0)
    };
    let kept = *squares.select_nth_unstable_by(rank, |a, b| a.total_cmp(b)).1;
    (kept / quantile_over_mean(z) / 6.0).sqrt()
}

/// Windows either side whose lower quartile gives a window's local noise level.
const LEVEL_NEIGHBOURS: usize = 5;

/// The third smallest of eleven mean squares of 64 fourth differences of white noise, over
/// their mean ([`local_levels`]).
const LOWER_QUARTILE_OVER_MEAN: f64 = 0.78;

/// The local noise level of `x` (σ) in each window of [`WINDOW`] samples: from its fourth
/// differences (variance 70 σ² for white noise), which a signal slow against the sampling
/// leaves nearly alone, the lower quartile over the window and `LEVEL_NEIGHBOURS` either
/// side, so that what lifts up to two thirds of them (a step and the transient after it, a
/// model departing at each step) lifts no level. The mean square of 64 fourth differences
/// has about 24 degrees of freedom (adjacent ones correlate by −0.8, 0.4, −0.11), and the
/// third of eleven such, by Wilson–Hilferty, lies at 0.78 of its mean: the level is divided
/// by that. Empty when `x` is too short for five windows.
pub fn local_levels(x: &[f64]) -> Vec<f64> {
    if x.len() < 5 * WINDOW + 4 {
        return vec![];
    }
    let fourth: Vec<f64> = x
        .windows(5)
        .map(|w| w[4] - 4.0 * w[3] + 6.0 * w[2] - 4.0 * w[1] + w[0])
        .collect();
    let squares: Vec<f64> = fourth
        .chunks_exact(WINDOW)
        .map(|c| c.iter().map(|d| d * d).sum::<f64>() / (70.0 * WINDOW as f64))
        .collect();
    (0..squares.len())
        .map(|w| {
            let from = w.saturating_sub(LEVEL_NEIGHBOURS);
            let to = (w + LEVEL_NEIGHBOURS + 1).min(squares.len());
            let mut around = squares[from..to].to_vec();
            let rank = around.len() / 4;
            (*around.select_nth_unstable_by(rank, |a, b| a.total_cmp(b)).1 / LOWER_QUARTILE_OVER_MEAN).sqrt()
        })
        .collect()
}

/// Noise whose level is not steady: the local level's tenth and ninetieth percentiles over
/// the windows, its RMS over the recording (the noise a model without error leaves), and
/// whether it follows the channel's level or wanders in time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VaryingNoise {
    pub lowest: f64,
    pub highest: f64,
    pub rms: f64,
    pub follows_level: bool,
}

/// How the noise of `x` (a channel, or its departure from a model) varies, when its local
/// level's ninetieth percentile is more than [`crate::policy::NOISE_VARIES`] times its tenth;
/// `None` for noise of a steady level. `level` is the channel itself, whose size the noise
/// may follow; `command` the recorded command, whose activity (its mean step from sample to
/// sample over each window) a level that rises and falls with is the actuator answering the
/// command faster than the model does, not noise (a loop closed on the logged force at the
/// sampling rate feeds the force's noise back, and the actuator's answer to it lifts the
/// force's fourth differences wherever the loop is closed).
pub fn varying(x: &[f64], level: &[f64], command: &[f64]) -> Option<VaryingNoise> {
    let levels = local_levels(x);
    if levels.len() < 10 {
        return None;
    }
    let mut sorted = levels.clone();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q).round() as usize];
    let (lowest, highest) = (at(0.1), at(0.9));
    if highest.is_nan() || highest <= crate::policy::NOISE_VARIES * lowest {
        return None;
    }
    let rms = (levels.iter().map(|l| l * l).sum::<f64>() / levels.len() as f64).sqrt();
    let magnitude: Vec<f64> = level
        .chunks_exact(WINDOW)
        .take(levels.len())
        .map(|c| c.iter().map(|v| v.abs()).sum::<f64>() / WINDOW as f64)
        .collect();
    let activity: Vec<f64> = command
        .chunks_exact(WINDOW)
        .take(levels.len())
        .map(|c| c.windows(2).map(|w| (w[1] - w[0]).abs()).sum::<f64>() / (WINDOW - 1) as f64)
        .collect();
    let follows = crate::policy::NOISE_FOLLOWS_CORRELATION;
    if correlation(&levels[..activity.len()], &activity) > follows {
        return None;
    }
    let follows_level = correlation(&levels[..magnitude.len()], &magnitude) > follows;
    // Noise that wanders does so slowly: most of its level's variance stays in a mean over
    // a few seconds. A level that changes from window to window is a signal's activity.
    if !follows_level && slow_share(&levels) < SLOW_SHARE {
        return None;
    }
    Some(VaryingNoise {
        lowest,
        highest,
        rms,
        follows_level,
    })
}

/// Windows either side of the running mean that keeps a wandering level.
const WANDER_WINDOWS: usize = 16;

/// The share of a level's variance a wander keeps in its running mean.
const SLOW_SHARE: f64 = 0.6;

/// The variance of the running mean over [`WANDER_WINDOWS`] either side, over the variance.
fn slow_share(levels: &[f64]) -> f64 {
    let n = levels.len();
    let mean = levels.iter().sum::<f64>() / n as f64;
    let variance = levels.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / n as f64;
    if variance <= 0.0 {
        return 0.0;
    }
    let smooth: Vec<f64> = (0..n)
        .map(|w| {
            let (a, b) = (w.saturating_sub(WANDER_WINDOWS), (w + WANDER_WINDOWS + 1).min(n));
            levels[a..b].iter().sum::<f64>() / (b - a) as f64
        })
        .collect();
    smooth.iter().map(|s| (s - mean).powi(2)).sum::<f64>() / n as f64 / variance
}

/// The step to which `x` is quantised, if it looks quantised: the largest of the smallest
/// step between samples (the one at the first percentile) and its whole fractions down to a
/// tenth of which nine in ten of the nonzero steps are whole multiples, or else the smallest
/// step when half of them are.
pub fn quantisation_step(x: &[f64]) -> Option<f64> {
    let mut steps: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).filter(|d| *d > 0.0).collect();
    if steps.len() < 100 {
        return None;
    }
    steps.sort_by(|a, b| a.total_cmp(b));
    let smallest = steps[steps.len() / 100];
    if smallest <= 0.0 {
        return None;
    }
    let multiples = |step: f64| {
        steps
            .iter()
            .filter(|d| {
                let m = *d / step;
                (m - m.round()).abs() < 0.02
            })
            .count()
    };
    // A steady motion logged to a step moves by a few steps between samples (7 and 8 µm
    // at 14.6 mm/s and 2 kHz): the step divides the smallest one.
    if let Some(step) = (1..=10)
        .map(|d| smallest / d as f64)
        .find(|&step| 10 * multiples(step) >= 9 * steps.len())
    {
        return Some(step);
    }
    (2 * multiples(smallest) >= steps.len()).then_some(smallest)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Deterministic standard normal samples (Box–Muller on an LCG).
    pub(crate) fn normals(seed: u64, n: usize) -> Vec<f64> {
        let mut state = seed;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| {
                let (a, b) = (uniform(), uniform());
                (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
            })
            .collect()
    }

    fn bench_like(seed: u64, sigma: f64, lsb: f64) -> Vec<f64> {
        normals(seed, 80_000)
            .into_iter()
            .enumerate()
            .map(|(k, e)| {
                let t = k as f64 * 1e-3;
                let f = 45.0 + 30.0 * (0.3 * t).sin() + sigma * e;
                if lsb > 0.0 {
                    (f / lsb).round() * lsb
                } else {
                    f
                }
            })
            .collect()
    }

    #[test]
    fn noise_floor_of_white_noise_is_its_sigma() {
        for seed in 1..=10 {
            let sigma = noise_floor(&bench_like(seed, 0.05, 0.0));
            assert!((sigma - 0.05).abs() < 0.05 * 0.03, "seed {seed}: {sigma}");
        }
    }

    #[test]
    fn noise_floor_of_quantised_noise_is_steady_across_seeds() {
        // The bench's force channel: 16 bits over ±500 N, 0.05 N of noise. The floor is
        // the noise plus the rounding's own lsb²/12, and must not jump with the seed.
        let lsb = 1000.0 / 65536.0;
        let expected = (0.05f64.powi(2) + lsb * lsb / 12.0).sqrt();
        let floors: Vec<f64> = (1..=20).map(|seed| noise_floor(&bench_like(seed, 0.05, lsb))).collect();
        let (lo, hi) = floors
            .iter()
            .fold((f64::INFINITY, 0f64), |(a, b), &f| (a.min(f), b.max(f)));
        assert!(
            lo > 0.97 * expected && hi < 1.03 * expected,
            "floors {lo}..{hi}, expected {expected}"
        );
    }

    #[test]
    fn a_step_in_the_signal_does_not_raise_the_floor() {
        let mut x = bench_like(3, 0.05, 0.0);
        for v in x.iter_mut().skip(40_000) {
            *v += 20.0;
        }
        let sigma = noise_floor(&x);
        assert!((sigma - 0.05).abs() < 0.05 * 0.03, "{sigma}");
    }

    /// A recording thinned for the fits is its stretches joined end to end: the signal
    /// jumps at every joint, which moves only the few windows across one.
    #[test]
    fn stretches_joined_with_jumps_keep_the_floor_of_their_noise() {
        let mut x = bench_like(7, 0.05, 0.0);
        for (k, v) in x.iter_mut().enumerate() {
            // twenty joints, 4,000 samples apart, each with a jump of up to 30 N
            *v += 30.0 * ((k / 4_000) as f64 * 1.7).sin();
        }
        let sigma = noise_floor(&x);
        assert!((sigma - 0.05).abs() < 0.05 * 0.03, "{sigma}");
    }

    /// Sampled at 250 Hz, a multisine up to 40 Hz curves between every three samples: over
    /// three fifths of the recording it lifts the second differences' mean square above the
    /// noise's in every window, and a median over the windows reads it. The tenth of all
    /// windows is then the quarter of the 39 quiet ones, whose mean square is 0.79 of the
    /// noise's against the tenth's 0.70: the floor reads 6 % high, ± 3 % for one standard
    /// deviation of that quantile over 39 windows.
    #[test]
    fn a_signal_that_curves_at_the_sampling_scale_over_most_of_the_recording_leaves_the_floor_at_the_noise() {
        let rate = 250.0;
        let x: Vec<f64> = normals(11, 6_250)
            .into_iter()
            .enumerate()
            .map(|(k, e)| {
                let t = k as f64 / rate;
                let fast = if t < 15.0 {
                    (1..=8)
                        .map(|j| 0.4 * (2.0 * std::f64::consts::PI * 5.0 * j as f64 * t + j as f64).sin())
                        .sum::<f64>()
                } else {
                    0.0
                };
                40.0 + fast + 0.04 * e
            })
            .collect();
        // The median over the windows, as the floor was once taken, reads the signal.
        let median_window = {
            let second: Vec<f64> = x.windows(3).map(|w| w[2] - 2.0 * w[1] + w[0]).collect();
            let mut squares: Vec<f64> = second
                .chunks_exact(WINDOW)
                .map(|c| c.iter().map(|d| d * d).sum::<f64>() / WINDOW as f64)
                .collect();
            let mid = squares.len() / 2;
            (*squares.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1 / 0.98 / 6.0).sqrt()
        };
        assert!(median_window > 2.0 * 0.04, "{median_window}");
        let sigma = noise_floor(&x);
        assert!((sigma / 0.04 - 1.06).abs() < 0.09, "{sigma}");
    }

    /// A force reading held at its rail for half the recording: the windows where it stands
    /// still carry no noise, and the floor is that of the rest.
    #[test]
    fn a_reading_held_at_its_rail_for_half_the_recording_keeps_the_floor_of_the_rest() {
        let mut x = bench_like(9, 0.05, 0.0);
        for v in x.iter_mut().skip(40_000) {
            *v = 85.0;
        }
        let sigma = noise_floor(&x);
        assert!((sigma - 0.05).abs() < 0.05 * 0.05, "{sigma}");
    }

    #[test]
    fn white_noise_of_one_level_under_a_slow_signal_does_not_vary() {
        for seed in 1..=10 {
            for lsb in [0.0, 0.0153] {
                let x = bench_like(seed, 0.05, lsb);
                assert_eq!(varying(&x, &x, &x), None, "seed {seed}, lsb {lsb}");
            }
        }
    }

    #[test]
    fn noise_growing_with_the_level_or_wandering_in_time_varies_and_says_which() {
        let e = normals(3, 80_000);
        let level: Vec<f64> = (0..80_000)
            .map(|k| 45.0 + 30.0 * (0.3 * k as f64 * 1e-3).sin())
            .collect();
        let growing: Vec<f64> = level.iter().zip(&e).map(|(l, e)| l + 0.004 * l * e).collect();
        let still = vec![5.0; growing.len()];
        let v = varying(&growing, &growing, &still).expect("varies");
        assert!(v.follows_level);
        let truth = (level.iter().map(|l| (0.004 * l).powi(2)).sum::<f64>() / level.len() as f64).sqrt();
        assert!((v.rms / truth - 1.0).abs() < 0.1, "{} against {truth}", v.rms);
        assert!(v.lowest < 0.004 * 25.0 && v.highest > 0.004 * 65.0, "{v:?}");

        let wandering: Vec<f64> = level
            .iter()
            .zip(&e)
            .enumerate()
            .map(|(k, (l, e))| l + 0.05 * (1.0 + 0.8 * (2.0 * std::f64::consts::PI * k as f64 * 1e-3 / 7.0).sin()) * e)
            .collect();
        let v = varying(&wandering, &wandering, &still).expect("varies");
        assert!(!v.follows_level, "{v:?}");
        let truth = 0.05 * (1.0f64 + 0.32).sqrt();
        assert!((v.rms / truth - 1.0).abs() < 0.1, "{} against {truth}", v.rms);
    }

    #[test]
    fn a_level_that_rises_where_the_command_is_busy_is_the_actuator_answering_it_and_not_noise() {
        // Four seconds of a command stepping every sample (a loop closed on the logged force)
        // and four of a held command, in turn: where the command is busy the force carries
        // three times the sensor's fourth differences.
        let e = normals(4, 80_000);
        let busy = |k: usize| (k / 4000) % 2 == 0;
        let command: Vec<f64> = (0..80_000)
            .map(|k| if busy(k) { 5.0 + 0.1 * e[(k * 7) % 80_000] } else { 5.0 })
            .collect();
        let force: Vec<f64> = (0..80_000)
            .map(|k| 40.0 + if busy(k) { 0.15 } else { 0.05 } * e[k])
            .collect();
        assert_eq!(varying(&force, &force, &command), None);
        // The same force beside a command that is busy throughout varies (in time).
        let steady_busy: Vec<f64> = (0..80_000).map(|k| 5.0 + 0.1 * e[(k * 7) % 80_000]).collect();
        assert!(varying(&force, &force, &steady_busy).is_some());
    }

    #[test]
    fn quantisation_step_is_found_on_a_quantised_channel_only() {
        let lsb = 1000.0 / 65536.0;
        let q = quantisation_step(&bench_like(5, 0.05, lsb)).unwrap();
        assert!((q - lsb).abs() < 1e-9, "{q}");
        assert_eq!(quantisation_step(&bench_like(5, 0.05, 0.0)), None);
    }

    #[test]
    fn a_steady_motion_logged_to_a_micrometre_has_a_micrometre_step_though_it_moves_seven_or_eight_between_samples() {
        let x: Vec<f64> = (0..400).map(|k| (0.05e6 + 7.3 * k as f64).round() * 1e-6).collect();
        let q = quantisation_step(&x).unwrap();
        assert!((q - 1e-6).abs() < 1e-12, "{q}");
    }
}
