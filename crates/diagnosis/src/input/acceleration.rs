//! The stopper acceleration the replays give the model (its input a_s, taken whole with
//! `stopper_acceleration_input_share` = 1), formed from the recording's positions centred
//! on each sample.
//!
//! The model, stepped from sample to sample, forms the acceleration as the second
//! difference of the positions over one sampling interval. Positions are logged to a
//! micrometre, and that rounding over an interval h is 1 µm / h²: 1 m/s² at 1 kHz and
//! 16 m/s² at 4 kHz, against a few m/s² of a shaken stopper. A force that follows the
//! acceleration (a moving mass) is then fitted to noise. Here the acceleration at t is the
//! second difference over a half-width T,
//!
//! a(t) = (x(t + T) − 2 x(t) + x(t − T)) / T²,
//!
//! x linear between the samples: the mean of the acceleration under a triangle of
//! half-width T, centred (no lag), its rounding 1 µm / T² (0.0025 m/s² at 20 ms). Near the
//! recording's ends T shrinks to the time there is; at the first and last samples a = 0.
//! T is chosen among [`WINDOWS`] by which best carries the starting model's force residual
//! ([`crate::input::stopper_motion::choose_window`]); the report gives it, so the FMU can be fed the same.

/// The half-widths (s) the diagnosis chooses among: a doubling grid from a few samples at
/// 1 kHz to the length of a slow stopper's ramp.
pub const WINDOWS: [f64; 4] = [5e-3, 10e-3, 20e-3, 40e-3];

/// The position at time `t` of a motion sampled at `time`, `x_s`, linear between samples
/// (`hint`: a sample at or before `t`, moved to the one that starts its interval).
fn position_at(time: &[f64], x_s: &[f64], t: f64, hint: &mut usize) -> f64 {
    let n = time.len();
    while *hint + 1 < n && time[*hint + 1] <= t {
        *hint += 1;
    }
    while *hint > 0 && time[*hint] > t {
        *hint -= 1;
    }
    let k = *hint;
    if k + 1 >= n {
        return x_s[n - 1];
    }
    let share = ((t - time[k]) / (time[k + 1] - time[k])).clamp(0.0, 1.0);
    x_s[k] + share * (x_s[k + 1] - x_s[k])
}

/// The acceleration at each sample of a motion sampled at `time` (s) and `x_s` (m), over the
/// half-width `window` (s), shrunk near the ends (see the module's formula).
pub fn smoothed_accelerations(time: &[f64], x_s: &[f64], window: f64) -> Vec<f64> {
    let n = time.len();
    let (first, last) = match (time.first(), time.last()) {
        (Some(&a), Some(&b)) => (a, b),
        _ => return vec![],
    };
    let (mut before, mut after) = (0, 0);
    (0..n)
        .map(|k| {
            let t = time[k];
            let half = window.min(t - first).min(last - t);
            if half.is_nan() || half <= 0.0 {
                return 0.0;
            }
            let x_before = position_at(time, x_s, t - half, &mut before);
            let x_after = position_at(time, x_s, t + half, &mut after);
            (x_after - 2.0 * x_s[k] + x_before) / (half * half)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steady_acceleration_is_read_exactly_and_a_sine_within_its_smoothing() {
        let time: Vec<f64> = (0..2001).map(|k| k as f64 * 1e-3).collect();
        let steady: Vec<f64> = time.iter().map(|t| 0.05 + 0.5 * 1.5 * t * t).collect();
        let a = smoothed_accelerations(&time, &steady, 0.02);
        for k in 1..time.len() - 1 {
            assert!((a[k] - 1.5).abs() < 1e-6, "sample {k}: {}", a[k]);
        }
        assert_eq!((a[0], a[2000]), (0.0, 0.0));
        // A 2.5 Hz, 10 mm shake: the triangle passes a sine of frequency ω times
        // sinc²(ω T / 2), 0.9918 at T = 20 ms.
        let w = 2.0 * std::f64::consts::PI * 2.5;
        let shake: Vec<f64> = time.iter().map(|t| 0.06 + 0.01 * (w * t).sin()).collect();
        let a = smoothed_accelerations(&time, &shake, 0.02);
        for k in 40..1960 {
            let exact = -0.01 * w * w * (w * time[k]).sin();
            assert!(
                (a[k] - exact).abs() < 0.0085 * 0.01 * w * w,
                "sample {k}: {} against {exact}",
                a[k]
            );
        }
    }

    #[test]
    fn positions_rounded_to_a_micrometre_leave_little_rounding_in_the_smoothed_acceleration() {
        // At 4 kHz a second difference of positions rounded to 1 µm is rounded to 16 m/s²;
        // over 20 ms it is 1 µm / (20 ms)² = 0.0025 m/s² at most, and the motion's own
        // 1.5 m/s² comes through.
        let time: Vec<f64> = (0..8001).map(|k| k as f64 * 2.5e-4).collect();
        let x: Vec<f64> = time
            .iter()
            .map(|t| ((0.05 + 0.75 * t * t) * 1e6).round() / 1e6)
            .collect();
        let a = smoothed_accelerations(&time, &x, 0.02);
        for k in 80..7920 {
            assert!((a[k] - 1.5).abs() < 0.01, "sample {k}: {}", a[k]);
        }
        let raw = jetpipe_model::physics::extra_force::stopper_accelerations(&time, &x);
        let spread = raw[80..7920].iter().map(|a| (a - 1.5).abs()).fold(0.0, f64::max);
        assert!(spread > 5.0, "the raw second difference's rounding: {spread} m/s²");
    }
}
