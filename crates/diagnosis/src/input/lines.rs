//! Sharp spectral lines anywhere up to the Nyquist frequency: a mains pick-up on a sensor, a
//! compressor's ripple. The residual's spectrum on a logarithmic grid ([`crate::replay::signature`])
//! steps over a line narrower than its 6 % spacing; here the whole spectrum is read from a
//! Hann-windowed FFT, a line is a bin that stands far above its neighbourhood, and its
//! frequency is interpolated between bins (Gaussian interpolation, exact for a Gaussian
//! peak and within a few hundredths of a bin for the Hann window's), then placed to a small
//! fraction of 1/span by a Goertzel search.
//!
//! A line that the inputs carry (a sine or multisine command, a shaken stopper) is the
//! plant's response to them, not a disturbance: such frequencies are skipped.

use rustfft::{num_complex::Complex, FftPlanner};

/// A line's power over the median of its neighbourhood, below which it is not a line. A
/// pure sine of amplitude A over white noise σ, N samples, stands N A² / (6 σ²) above the
/// noise's mean bin in the Hann window's spectrum (at worst 0.7 of that between two bins),
/// so a 0.1 N pick-up over 0.05 N of noise stands out by about 5 000 over 7 500 samples;
/// a broad-band residual's bins stand within a factor 10 of their neighbours.
pub const LINE_PROMINENCE: f64 = 1000.0;
/// An input carries a line at a frequency when its bin stands this far above its
/// neighbourhood (the inputs are noiseless, a lower bar than the residual's).
const INPUT_PROMINENCE: f64 = 100.0;
/// Half width of the neighbourhood, bins; the line's own bins (±`LINE_HALF_WIDTH`) are left
/// out of its median.
const NEIGHBOURHOOD: usize = 64;
const LINE_HALF_WIDTH: usize = 3;

/// A spectral line of a residual.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    pub hz: f64,
    /// Its power over the median of its neighbourhood.
    pub prominence: f64,
    /// Amplitude of the sinusoid, in the residual's unit.
    pub amplitude: f64,
}

/// Power spectrum of the mean-removed, Hann-windowed `x` in bins of `sample_rate / len`.
fn hann_power(x: &[f64]) -> Vec<f64> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let mut buffer: Vec<Complex<f64>> = x
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * k as f64 / n as f64).cos();
            Complex::new((v - mean) * w, 0.0)
        })
        .collect();
    FftPlanner::new().plan_fft_forward(n).process(&mut buffer);
    buffer[..n / 2 + 1].iter().map(|c| c.norm_sqr()).collect()
}

/// The bin's power over the median of its neighbourhood (its own bins left out).
fn prominence(power: &[f64], k: usize) -> f64 {
    let lo = k.saturating_sub(NEIGHBOURHOOD);
    let hi = (k + NEIGHBOURHOOD).min(power.len() - 1);
    let mut around: Vec<f64> = (lo..=hi)
        .filter(|&j| j + LINE_HALF_WIDTH < k || j > k + LINE_HALF_WIDTH)
        .map(|j| power[j])
        .collect();
    if around.is_empty() {
        return 0.0;
    }
    let mid = around.len() / 2;
    let median = *around.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
    power[k] / median.max(1e-300)
}

fn is_local_peak(power: &[f64], k: usize) -> bool {
    k > 0 && k + 1 < power.len() && power[k] >= power[k - 1] && power[k] >= power[k + 1]
}

/// Power of `x` at frequency `f` (Goertzel), per sample squared.
pub(crate) fn power_at(x: &[f64], f: f64, sample_rate: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * f / sample_rate;
    let c = 2.0 * w.cos();
    let (mut s1, mut s2) = (0.0, 0.0);
    for &v in x {
        let s = v + c * s1 - s2;
        s2 = s1;
        s1 = s;
    }
    (s1 * s1 + s2 * s2 - c * s1 * s2) / (x.len() as f64).powi(2)
}

/// The most prominent line of `residual` (sampled at `sample_rate`, Hz) between two cycles
/// over the recording and the Nyquist frequency; `None` when no bin stands
/// [`LINE_PROMINENCE`] above its neighbourhood. A line that one of `inputs` carries is
/// skipped when `response` (the model's output whose residual this is; empty for none)
/// carries it too at a tenth of the residual's amplitude or more: a departure in how the
/// plant answers an input line changes that answer by a fraction of it. A residual line ten
/// times the model's own answer is no such departure: under force tracking the controller
/// feeds a sensor's pick-up back into the command, and the plant's few hertz of bandwidth
/// all but remove it from the force.
pub fn strongest_line(residual: &[f64], sample_rate: f64, inputs: &[&[f64]], response: &[f64]) -> Option<Line> {
    strongest_line_above(residual, sample_rate, inputs, response, 0.0)
}

/// [`strongest_line`] at `from_hz` or above.
pub fn strongest_line_above(
    residual: &[f64],
    sample_rate: f64,
    inputs: &[&[f64]],
    response: &[f64],
    from_hz: f64,
) -> Option<Line> {
    let n = residual.len();
    if n < 4 * NEIGHBOURHOOD {
        return None;
    }
    let power = hann_power(residual);
    assert!(
        inputs.iter().all(|x| x.len() == n),
        "the inputs and the residual differ in length"
    );
    let input_power: Vec<Vec<f64>> = inputs.iter().map(|x| hann_power(x)).collect();
    let response_power = (response.len() == n).then(|| hann_power(response));
    let answered_by_the_model = |k: usize| response_power.as_ref().map_or(true, |r| r[k] >= 0.01 * power[k]);
    let bin_hz = sample_rate / n as f64;
    let lowest = ((from_hz / bin_hz).ceil() as usize).max(2);
    let carried_by_inputs = |k: usize| {
        input_power.iter().any(|p| {
            (k.saturating_sub(2)..=(k + 2).min(p.len() - 1)).any(|j| p[j] > 0.0 && prominence(p, j) > INPUT_PROMINENCE)
        })
    };
    let (k, prominence_of_peak) = (lowest..power.len() - 1)
        .filter(|&k| is_local_peak(&power, k))
        .map(|k| (k, prominence(&power, k)))
        .filter(|&(_, p)| p > LINE_PROMINENCE)
        .filter(|&(k, _)| !(carried_by_inputs(k) && answered_by_the_model(k)))
        .max_by(|a, b| (power[a.0]).total_cmp(&power[b.0]))?;
    // Gaussian interpolation on the log powers of the peak and its neighbours.
    let (a, b, c) = (power[k - 1].ln(), power[k].ln(), power[k + 1].ln());
    let denominator = a - 2.0 * b + c;
    let offset = if denominator < 0.0 {
        (0.5 * (a - c) / denominator).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let estimate = (k as f64 + offset) * bin_hz;
    // Polish to a small fraction of 1/span, within half a bin of the estimate.
    let mean = residual.iter().sum::<f64>() / n as f64;
    let centred: Vec<f64> = residual.iter().map(|r| r - mean).collect();
    let steps = 40;
    let (hz, line_power) = (0..=steps)
        .map(|j| estimate + bin_hz * (j as f64 / steps as f64 - 0.5))
        .map(|f| (f, power_at(&centred, f, sample_rate)))
        .fold((estimate, power_at(&centred, estimate, sample_rate)), |best, (f, p)| {
            if p > best.1 {
                (f, p)
            } else {
                best
            }
        });
    Some(Line {
        hz,
        prominence: prominence_of_peak,
        amplitude: 2.0 * line_power.sqrt(),
    })
}

/// `x` less its sharp lines that second differences would count as noise (at most
/// `max_lines`, each fitted by least squares as a sine and a cosine at its frequency): a
/// mains pick-up at a quarter of the sampling rate has second differences as large as the
/// noise's. Only lines above a fiftieth of the sampling rate are sought: below it a line's
/// second differences are less than 2.4·10⁻⁴ of its power, and the lines there are the
/// plant's response to its inputs.
pub fn without_lines(x: &[f64], sample_rate: f64, max_lines: usize) -> Vec<f64> {
    let mut out = x.to_vec();
    for _ in 0..max_lines {
        let Some(line) = strongest_line_above(&out, sample_rate, &[], &[], sample_rate / 50.0) else {
            break;
        };
        let w = 2.0 * std::f64::consts::PI * line.hz / sample_rate;
        let (mut ss, mut sc, mut cc, mut xs, mut xc) = (0.0, 0.0, 0.0, 0.0, 0.0);
        let mean = out.iter().sum::<f64>() / out.len() as f64;
        for (k, v) in out.iter().enumerate() {
            let (s, c) = (w * k as f64).sin_cos();
            ss += s * s;
            sc += s * c;
            cc += c * c;
            xs += (v - mean) * s;
            xc += (v - mean) * c;
        }
        let det = ss * cc - sc * sc;
        if det.abs() < 1e-12 * (ss * cc).max(1e-300) {
            break;
        }
        let (a, b) = ((xs * cc - xc * sc) / det, (xc * ss - xs * sc) / det);
        for (k, v) in out.iter_mut().enumerate() {
            let (s, c) = (w * k as f64).sin_cos();
            *v -= a * s + b * c;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Deterministic white noise (xorshift, Box–Muller) of standard deviation `sigma`.
    fn noise(n: usize, sigma: f64, seed: u64) -> Vec<f64> {
        let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
        let mut uniform = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| sigma * (-2.0 * uniform().ln()).sqrt() * (2.0 * PI * uniform()).cos())
            .collect()
    }

    #[test]
    fn a_fifty_hertz_pickup_between_bins_is_found_to_a_thousandth_with_its_amplitude() {
        for (rate, seconds) in [(250.0, 30.0), (1000.0, 40.0), (2000.0, 20.0)] {
            let n = (rate * seconds) as usize;
            let hz = 50.0 + 0.37 / seconds; // between two bins
            let x: Vec<f64> = noise(n, 0.05, 3)
                .iter()
                .enumerate()
                .map(|(k, e)| e + 0.1 * (2.0 * PI * hz * k as f64 / rate + 0.4).sin())
                .collect();
            let line = strongest_line(&x, rate, &[], &[]).expect("a line");
            assert!(
                (line.hz - hz).abs() < 1e-3 * hz,
                "{} Hz against {hz} at {rate} Hz",
                line.hz
            );
            assert!((line.amplitude - 0.1).abs() < 0.01, "amplitude {}", line.amplitude);
        }
    }

    #[test]
    fn removing_a_pickup_at_a_quarter_of_the_sampling_rate_restores_the_noise_floor() {
        let (rate, n) = (250.0, 15_000);
        let noise_only = noise(n, 0.08, 13);
        let x: Vec<f64> = noise_only
            .iter()
            .enumerate()
            .map(|(k, e)| {
                e + 5.0 * (2.0 * PI * 0.3 * k as f64 / rate).sin()
                    + 0.3 * (2.0 * PI * 60.0 * k as f64 / rate + 1.0).sin()
            })
            .collect();
        let with_line = crate::input::noise::noise_floor(&x);
        let without = crate::input::noise::noise_floor(&without_lines(&x, rate, 3));
        assert!(with_line > 0.15, "{with_line}");
        assert!((without - 0.08).abs() < 0.006, "{without}");
        // the slow sine is signal, not a line of the second differences: it stays
        let kept = without_lines(&x, rate, 3);
        let slow: f64 = kept
            .iter()
            .enumerate()
            .map(|(k, v)| v * (2.0 * PI * 0.3 * k as f64 / rate).sin())
            .sum::<f64>()
            * 2.0
            / n as f64;
        assert!((slow - 5.0).abs() < 0.05, "{slow}");
    }

    #[test]
    fn a_line_near_nyquist_is_found() {
        let (rate, n) = (500.0, 20_000);
        let x: Vec<f64> = noise(n, 0.05, 5)
            .iter()
            .enumerate()
            .map(|(k, e)| e + 0.2 * (2.0 * PI * 231.3 * k as f64 / rate).cos())
            .collect();
        let line = strongest_line(&x, rate, &[], &[]).expect("a line");
        assert!((line.hz - 231.3).abs() < 0.01, "{}", line.hz);
    }

    #[test]
    fn white_noise_and_a_broad_band_residual_have_no_line() {
        let n = 40_000;
        assert_eq!(strongest_line(&noise(n, 0.05, 7), 1000.0, &[], &[]), None);
        // a low-passed random walk: broad-band, large, no line
        let mut level = 0.0;
        let walk: Vec<f64> = noise(n, 1.0, 9)
            .iter()
            .map(|e| {
                level = 0.995 * level + e;
                level
            })
            .collect();
        assert_eq!(strongest_line(&walk, 1000.0, &[], &[]), None);
    }

    #[test]
    fn a_line_the_command_carries_is_the_plants_response_not_a_disturbance() {
        let (rate, n) = (1000.0, 30_000);
        let command: Vec<f64> = (0..n)
            .map(|k| 2.5 + 3.0 * (2.0 * PI * 0.7 * k as f64 / rate).sin())
            .collect();
        // the model answers the command's line with 8 N/V; the plant with 10 % more
        let response: Vec<f64> = command.iter().map(|v| 8.0 * (v - 2.5)).collect();
        let residual: Vec<f64> = noise(n, 0.05, 11)
            .iter()
            .zip(&response)
            .map(|(e, f)| e + 0.1 * f)
            .collect();
        assert!(strongest_line(&residual, rate, &[], &[]).is_some());
        assert_eq!(strongest_line(&residual, rate, &[&command], &response), None);
    }

    #[test]
    fn a_pickup_fed_back_into_the_command_is_still_a_disturbance() {
        let (rate, n) = (500.0, 15_000);
        let at = |k: usize, hz: f64| (2.0 * PI * hz * k as f64 / rate).sin();
        // a controller's command: a slow sine and a trace of the 50 Hz pick-up it read
        let command: Vec<f64> = (0..n).map(|k| 2.5 + 3.0 * at(k, 0.7) + 0.004 * at(k, 50.0)).collect();
        // the model passes the slow sine and all but removes 50 Hz
        let response: Vec<f64> = (0..n).map(|k| 24.0 * at(k, 0.7) + 1e-4 * at(k, 50.0)).collect();
        let residual: Vec<f64> = noise(n, 0.05, 17)
            .iter()
            .enumerate()
            .map(|(k, e)| e + 0.2 * at(k, 50.0))
            .collect();
        let line = strongest_line(&residual, rate, &[&command], &response).expect("the pick-up");
        assert!((line.hz - 50.0).abs() < 0.01, "{}", line.hz);
    }
}
