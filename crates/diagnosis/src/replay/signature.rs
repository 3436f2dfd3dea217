//! What a residual looks like: where in time it lives, which signals along the chain it
//! follows (binned conditional means, so a dependence need not be linear), its spectrum
//! and its trend.

use serde_json::{json, Value};

use crate::replay::signals::{rms, ChainSignals};
use crate::statistics::correlation;

/// Quantile bins of a signal for its conditional means.
pub const BINS: usize = 10;

/// How much of a residual's variance the conditional means of `signal` explain (the
/// correlation ratio η²), with the bin means. Bins are quantiles of the signal; a signal
/// with fewer distinct values gets as many bins as it has values.
pub fn conditional_means(residual: &[f64], signal: &[f64]) -> (f64, Vec<(f64, f64, usize)>) {
    let n = residual.len();
    if n < 2 * BINS {
        return (0.0, vec![]);
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| signal[a].total_cmp(&signal[b]));
    let mean = residual.iter().sum::<f64>() / n as f64;
    let total: f64 = residual.iter().map(|r| (r - mean) * (r - mean)).sum();
    if total == 0.0 {
        return (0.0, vec![]);
    }
    let mut bins: Vec<(f64, f64, usize)> = vec![];
    let mut start = 0;
    while start < n {
        let mut end = ((bins.len() + 1) * n / BINS).max(start + 1).min(n);
        // Keep equal signal values in one bin.
        while end < n && signal[order[end]] == signal[order[end - 1]] {
            end += 1;
        }
        let members = &order[start..end];
        let r_mean = members.iter().map(|&k| residual[k]).sum::<f64>() / members.len() as f64;
        let s_mean = members.iter().map(|&k| signal[k]).sum::<f64>() / members.len() as f64;
        bins.push((s_mean, r_mean, members.len()));
        start = end;
    }
    let between: f64 = bins.iter().map(|(_, m, c)| *c as f64 * (m - mean) * (m - mean)).sum();
    (between / total, bins)
}

/// Power of `x` sampled at `time` at frequency `f`, per sample squared: |Σ x e^(−iωt)|² / n²,
/// Goertzel's figure for a series without gaps. The phasor turns by one step's rotation
/// from sample to sample and is formed afresh after a gap.
pub fn power_at_times(time: &[f64], x: &[f64], f: f64) -> f64 {
    let n = x.len().min(time.len());
    if n == 0 {
        return 0.0;
    }
    let w = 2.0 * std::f64::consts::PI * f;
    let step = if n > 1 { time[1] - time[0] } else { 0.0 };
    let (turn_re, turn_im) = ((w * step).cos(), -(w * step).sin());
    let (mut re, mut im) = ((w * time[0]).cos(), -(w * time[0]).sin());
    let (mut sum_re, mut sum_im) = (0.0, 0.0);
    for k in 0..n {
        if k > 0 {
            let interval = time[k] - time[k - 1];
            if (interval - step).abs() <= 1e-9 * step.abs().max(1e-12) {
                let next = re * turn_re - im * turn_im;
                im = re * turn_im + im * turn_re;
                re = next;
            } else {
                re = (w * time[k]).cos();
                im = -(w * time[k]).sin();
            }
        }
        sum_re += x[k] * re;
        sum_im += x[k] * im;
    }
    (sum_re * sum_re + sum_im * sum_im) / (n as f64).powi(2)
}

/// The frequency within `half_width` (Hz) of `estimate` where `x` sampled at `time` has the
/// most power, placed to a twentieth of 1/span ([`power_at_times`]).
pub fn polished_line(time: &[f64], x: &[f64], estimate: f64, half_width: f64) -> f64 {
    let n = x.len().min(time.len());
    if n < 2 {
        return estimate;
    }
    let mean = x[..n].iter().sum::<f64>() / n as f64;
    let centred: Vec<f64> = x[..n].iter().map(|v| v - mean).collect();
    let span = (time[n - 1] - time[0]).max(1e-9);
    let steps = ((2.0 * half_width * span / 0.05).ceil() as usize).clamp(2, 4000);
    (0..=steps)
        .map(|k| estimate - half_width + 2.0 * half_width * k as f64 / steps as f64)
        .filter(|f| *f > 0.0)
        .map(|f| (f, power_at_times(&time[..n], &centred, f)))
        .fold(
            (estimate, power_at_times(&time[..n], &centred, estimate)),
            |best, (f, p)| {
                if p > best.1 {
                    (f, p)
                } else {
                    best
                }
            },
        )
        .0
}

/// The residual's spectrum on a logarithmic grid: the frequency of its largest line, how
/// far that line stands above the median of the grid, and the share of the power below
/// 0.5 Hz.
pub struct Spectrum {
    pub peak_hz: f64,
    pub peak_over_median: f64,
    pub low_share: f64,
}

pub fn spectrum(time: &[f64], residual: &[f64]) -> Spectrum {
    let n = residual.len();
    let time = &time[..n];
    let sample_rate = crate::input::recording::sample_rate(time);
    // The stretches of a recording thinned for the fits are read at their own times: joined
    // end to end they would break a line's phase at every gap and move its peak.
    let span = time[n - 1] - time[0];
    let mean = residual.iter().sum::<f64>() / n as f64;
    let centred: Vec<f64> = residual.iter().map(|r| r - mean).collect();
    let lowest = (2.0 / span).max(0.02);
    let highest = 0.45 * sample_rate;
    let points = 160;
    let grid: Vec<f64> = (0..points)
        .map(|k| lowest * (highest / lowest).powf(k as f64 / (points - 1) as f64))
        .collect();
    let powers: Vec<f64> = grid.iter().map(|&f| power_at_times(time, &centred, f)).collect();
    let mut sorted = powers.clone();
    sorted.sort_by(|a, b| a.total_cmp(b));
    let median = sorted[points / 2].max(1e-300);
    let (peak, &peak_power) = powers
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .expect("a grid of frequencies");
    // The grid is 6 % coarse; a line used as a regressor over the whole recording must be
    // placed to a small fraction of 1/span, so search its neighbourhood finely.
    let (from, to) = (grid[peak.saturating_sub(1)], grid[(peak + 1).min(points - 1)]);
    let fine_step = 0.05 / span.max(1e-9);
    let fine = ((to - from) / fine_step).ceil().clamp(1.0, 4000.0) as usize;
    let (peak_hz, peak_power) = (0..=fine)
        .map(|k| from + (to - from) * k as f64 / fine as f64)
        .map(|f| (f, power_at_times(time, &centred, f)))
        .fold(
            (grid[peak], peak_power),
            |best, (f, p)| if p > best.1 { (f, p) } else { best },
        );
    // Share of power below 0.5 Hz, from a moving average over 1 s (a low-pass).
    let window = (sample_rate as usize).max(1);
    let mut low = vec![0.0; n];
    let mut acc = 0.0;
    for k in 0..n {
        acc += centred[k];
        if k >= window {
            acc -= centred[k - window];
        }
        low[k] = acc / (k + 1).min(window) as f64;
    }
    let total: f64 = centred.iter().map(|r| r * r).sum::<f64>().max(1e-300);
    Spectrum {
        peak_hz,
        peak_over_median: peak_power / median,
        low_share: (low.iter().map(|r| r * r).sum::<f64>() / total).min(1.0),
    }
}

/// Straight-line trend of the residual in time: slope and the share of variance it explains.
pub fn trend(time: &[f64], residual: &[f64]) -> (f64, f64) {
    let r = correlation(time, residual);
    let n = time.len() as f64;
    let (mt, mr) = (time.iter().sum::<f64>() / n, residual.iter().sum::<f64>() / n);
    let (mut stt, mut str_) = (0.0, 0.0);
    for (t, x) in time.iter().zip(residual) {
        stt += (t - mt) * (t - mt);
        str_ += (t - mt) * (x - mr);
    }
    (if stt > 0.0 { str_ / stt } else { 0.0 }, r * r)
}

/// The bench protocol's segments when the recording follows it (0–80 s), otherwise
/// consecutive 10 s windows.
pub fn segments(time: &[f64]) -> Vec<(String, f64, f64)> {
    let (t0, t1) = (time[0], time[time.len() - 1]);
    if t0.abs() < 0.01 && (t1 - 80.0).abs() < 0.5 {
        return vec![
            ("A (major loop)".to_string(), 0.0, 20.0),
            ("B (nested reversals)".to_string(), 20.0, 35.0),
            ("C (chirp)".to_string(), 35.0, 50.0),
            ("D (steps)".to_string(), 50.0, 60.0),
            ("E (stopper motion)".to_string(), 60.0, t1 + 1e-9),
        ];
    }
    let mut out = vec![];
    let mut from = t0;
    while from < t1 {
        let to = (from + 10.0).min(t1 + 1e-9);
        out.push((format!("{from:.0}-{to:.0} s"), from, to));
        from = to;
    }
    out
}

/// One signal's share of the residual.
#[derive(Clone, Debug)]
pub struct Follows {
    pub signal: &'static str,
    pub eta_squared: f64,
    pub correlation: f64,
}

/// The residual's signature: numbers and one sentence.
#[derive(Clone, Debug)]
pub struct Signature {
    pub rms: f64,
    pub by_segment: Vec<(String, f64)>,
    pub follows: Vec<Follows>,
    pub peak_hz: f64,
    pub peak_over_median: f64,
    pub low_share: f64,
    pub trend_per_s: f64,
    pub trend_share: f64,
    pub sentence: String,
}

impl Signature {
    pub fn of(time: &[f64], residual: &[f64], signals: &ChainSignals, unit: &str) -> Self {
        let by_segment: Vec<(String, f64)> = segments(time)
            .into_iter()
            .map(|(name, a, b)| {
                let inside: Vec<f64> = time
                    .iter()
                    .zip(residual)
                    .filter(|(t, _)| **t >= a && **t < b)
                    .map(|(_, r)| *r)
                    .collect();
                (name, rms(&inside))
            })
            .collect();
        let mut follows: Vec<Follows> = signals
            .names
            .iter()
            .zip(&signals.values)
            .map(|(name, values)| Follows {
                signal: name,
                eta_squared: conditional_means(residual, values).0,
                correlation: correlation(residual, values),
            })
            .collect();
        follows.sort_by(|a, b| b.eta_squared.total_cmp(&a.eta_squared));
        let s = spectrum(time, residual);
        let (trend_per_s, trend_share) = trend(time, residual);
        let total = rms(residual);
        let worst = by_segment
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .cloned()
            .unwrap_or_default();
        let top: Vec<String> = follows
            .iter()
            .take(2)
            .map(|f| format!("{} (η² = {:.2})", f.signal, f.eta_squared))
            .collect();
        let spectral = if s.peak_over_median > 100.0 && s.low_share < 0.5 {
            format!(
                "a spectral line at {:.2} Hz stands {:.0}× above the median",
                s.peak_hz, s.peak_over_median
            )
        } else {
            format!("{:.0} % of its power lies below 0.5 Hz", 100.0 * s.low_share)
        };
        let sentence = format!(
            "RMS {total:.4} {unit}, largest in segment {} ({:.4} {unit}); its binned means follow {}; {spectral}; a straight line in time explains {:.0} % of it.",
            worst.0,
            worst.1,
            top.join(" and "),
            100.0 * trend_share
        );
        Self {
            rms: total,
            by_segment,
            follows,
            peak_hz: s.peak_hz,
            peak_over_median: s.peak_over_median,
            low_share: s.low_share,
            trend_per_s,
            trend_share,
            sentence,
        }
    }

    pub fn to_json(&self, unit: &str) -> Value {
        json!({
            "rms": self.rms,
            "unit": unit,
            "by_segment": self.by_segment.iter().map(|(n, r)| json!({"segment": n, "rms": r})).collect::<Vec<_>>(),
            "follows": self.follows.iter().take(6).map(|f| json!({
                "signal": f.signal,
                "eta_squared": f.eta_squared,
                "correlation": f.correlation,
            })).collect::<Vec<_>>(),
            "spectrum": {
                "peak_hz": self.peak_hz,
                "peak_over_median": self.peak_over_median,
                "share_below_0_5_hz": self.low_share,
            },
            "trend": {"slope_per_s": self.trend_per_s, "share_of_variance": self.trend_share},
            "sentence": self.sentence,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conditional_means_see_a_dependence_that_correlation_misses() {
        // r = s² on a symmetric s: correlation 0, η² near 1.
        let s: Vec<f64> = (0..2000).map(|k| -1.0 + k as f64 / 1000.0).collect();
        let r: Vec<f64> = s.iter().map(|x| x * x).collect();
        let (eta, bins) = conditional_means(&r, &s);
        assert!(correlation(&r, &s).abs() < 0.01);
        assert!(eta > 0.95, "{eta}");
        assert_eq!(bins.len(), BINS);
        // And nothing where the residual ignores the signal.
        let flat = vec![1.0; 2000];
        assert_eq!(conditional_means(&flat, &s).0, 0.0);
    }

    #[test]
    fn the_spectrum_finds_a_line_and_the_trend_a_ramp() {
        let t: Vec<f64> = (0..20_000).map(|k| k as f64 * 1e-3).collect();
        let line: Vec<f64> = t.iter().map(|t| (2.0 * std::f64::consts::PI * 7.0 * t).sin()).collect();
        let s = spectrum(&t, &line);
        assert!((s.peak_hz - 7.0).abs() < 0.01, "{}", s.peak_hz);
        assert!(s.peak_over_median > 100.0 && s.low_share < 0.05);
        let ramp: Vec<f64> = t.iter().map(|t| 0.1 * t).collect();
        let (slope, share) = trend(&t, &ramp);
        assert!((slope - 0.1).abs() < 1e-9 && share > 0.999);
    }

    /// Stretches of 4 s, every second one kept over 48 s at 2 kHz, as the fits thin a long
    /// recording, of a 38.807 Hz line whose amplitude wanders slowly, with noise.
    fn stretched_line() -> (Vec<f64>, Vec<f64>) {
        let (mut t, mut x) = (vec![], vec![]);
        let mut state = 12345_u64;
        for k in 0..96_000 {
            let time = k as f64 / 2000.0;
            if (time / 4.0) as usize % 2 == 1 {
                continue;
            }
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let uniform = (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
            let envelope = 1.0 + 0.5 * (0.3 * time).sin();
            t.push(time);
            x.push(envelope * (2.0 * std::f64::consts::PI * 38.807 * time + 1.0).sin() + 0.3 * uniform);
        }
        (t, x)
    }

    #[test]
    fn a_line_in_stretches_with_gaps_is_placed_at_its_frequency_over_the_whole_span() {
        let (t, x) = stretched_line();
        let s = spectrum(&t, &x);
        // A twentieth of 1/span is 0.001 Hz; joined end to end the stretches span 24 s.
        assert!((s.peak_hz - 38.807).abs() < 0.002, "{}", s.peak_hz);
        let polished = polished_line(&t, &x, 38.86, 0.1);
        assert!((polished - 38.807).abs() < 0.002, "{polished}");
    }

    #[test]
    fn the_power_at_the_samples_times_is_goertzels_without_gaps() {
        let t: Vec<f64> = (0..5000).map(|k| k as f64 * 1e-3).collect();
        let x: Vec<f64> = t
            .iter()
            .map(|t| (2.0 * std::f64::consts::PI * 7.3 * t).cos() + 0.2)
            .collect();
        for f in [0.5, 7.0, 7.3, 123.4] {
            let (timed, goertzel) = (power_at_times(&t, &x, f), crate::input::lines::power_at(&x, f, 1000.0));
            assert!(
                (timed - goertzel).abs() <= 1e-9 * goertzel.max(1e-12),
                "{f} Hz: {timed} against {goertzel}"
            );
        }
    }
}
