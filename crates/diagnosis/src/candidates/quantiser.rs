//! A command quantiser: a D/A of fewer bits than the logged command puts the command the
//! current driver sees on levels o + k q (`command_quantum`, `command_quantum_origin`,
//! `command_quantum_threshold`). The misfit as a function of the step q has a minimum at
//! every spacing the recorded commands happen to fit, so q is not found by a golden-section
//! search. It is read from the residual instead: the quantisation error is a sawtooth of
//! period q in the command, which a force that follows the command quasi-statically carries.
//! The strongest periods are then tried in the model with the two usual conventions
//! (rounding and truncation) and the two grids (a level at 0 V, or half a step off it).

/// Periods tried in the model.
pub(crate) const STEP_TRIALS: usize = 3;
/// Samples the periodogram reads at most (evenly spread): 20 000 give a period's power to a
/// few per cent.
const PERIODOGRAM_SAMPLES: usize = 20_000;
/// The smallest step, in resolutions of the logged command: a step of one or two of them
/// is the logger's own.
const SMALLEST_STEP_IN_RESOLUTIONS: f64 = 4.0;
/// The smallest step, as a share of the commands' span: a finer converter's error is a
/// thousandth of the command.
const SMALLEST_STEP_IN_SPANS: f64 = 1e-3;
/// The largest step, as a share of the commands' span: four levels at least.
const LARGEST_STEP_IN_SPANS: f64 = 0.25;
/// How long the force takes to follow the command (the current driver, the jet pipe and the
/// chambers), s: a sawtooth the command sweeps through faster is averaged away.
const RESPONSE_TIME: f64 = 0.02;
/// Periods closer than this ratio are one peak.
const SAME_PEAK: f64 = 1.05;

/// The steps of converters with fewer bits over the logger's own span: the logged command's
/// resolution times 4, 8, ..., up to the largest step (a quarter of the commands' span).
/// Rounding onto levels through 0 V and truncation are tried at each.
pub(crate) fn converter_steps(v: &[f64]) -> Vec<f64> {
    let (low, high) = v
        .iter()
        .filter(|x| x.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| (l.min(x), h.max(x)));
    let logged = resolution(v);
    let largest = LARGEST_STEP_IN_SPANS * (high - low);
    let smallest = SMALLEST_STEP_IN_SPANS * (high - low);
    if !(logged.is_finite() && logged > 0.0) {
        return vec![];
    }
    (2..16)
        .map(|k| logged * f64::from(1u32 << k))
        .filter(|&q| q >= smallest && q <= largest)
        .collect()
}

/// The quantiser's (origin, threshold) pairs tried at each step q: rounding and truncation,
/// on a grid through 0 V and on one half a step off it.
pub(crate) fn conventions(q: f64) -> [(f64, f64); 4] {
    [(0.0, 0.5), (0.0, 1.0), (0.5 * q, 0.5), (0.5 * q, 1.0)]
}

/// The steps q whose sawtooth in the command `v` (at times `time`) the `residual` holds
/// most of, strongest first, at most [`STEP_TRIALS`]; only the samples where `used` is true
/// are read. Empty when the commands span too few levels of their own resolution to hold a
/// coarser grid.
pub(crate) fn leading_steps(time: &[f64], v: &[f64], residual: &[f64], used: &[bool]) -> Vec<f64> {
    let mut out: Vec<f64> = vec![];
    for (q, _) in peaks(time, v, residual, used) {
        if out.iter().all(|&o| (q / o).max(o / q) > SAME_PEAK) {
            out.push(q);
        }
        if out.len() == STEP_TRIALS {
            break;
        }
    }
    out
}

/// The periodogram's local maxima (period, mean square of its line), strongest first. A
/// sample counts for a step q as far as the force can follow its sawtooth there: with the
/// weight 1/(1 + (τ |dv/dt| / q)²), τ = [`RESPONSE_TIME`], set for each octave of q by its
/// lowest step. A command sweeping through the levels faster leaves the force their mean.
fn peaks(time: &[f64], v: &[f64], residual: &[f64], used: &[bool]) -> Vec<(f64, f64)> {
    let n = v.len().min(residual.len()).min(used.len()).min(time.len());
    let picked: Vec<usize> = (0..n)
        .filter(|&k| used[k] && v[k].is_finite() && residual[k].is_finite())
        .collect();
    let stride = (picked.len() / PERIODOGRAM_SAMPLES).max(1);
    let picked: Vec<usize> = picked.into_iter().step_by(stride).collect();
    if picked.len() < 16 {
        return vec![];
    }
    let xs: Vec<f64> = picked.iter().map(|&k| v[k]).collect();
    let ys = without_smooth_trend(&xs, &picked.iter().map(|&k| residual[k]).collect::<Vec<_>>());
    let rates: Vec<f64> = picked
        .iter()
        .map(|&k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            let dt = time[b] - time[a];
            if dt > 0.0 {
                (v[b] - v[a]) / dt
            } else {
                0.0
            }
        })
        .collect();
    let (low, high) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &x| (l.min(x), h.max(x)));
    let span = high - low;
    let logged = resolution(&xs);
    let smallest = (SMALLEST_STEP_IN_RESOLUTIONS * logged).max(SMALLEST_STEP_IN_SPANS * span);
    let largest = LARGEST_STEP_IN_SPANS * span;
    if !(smallest > 0.0 && smallest < largest) {
        return vec![];
    }
    // The weighted residual summed over bins of the command no wider than the logger's
    // resolution (or an eighth of the smallest step): the lines are sums over the bins.
    let width = logged.min(smallest / 8.0);
    let mut periods = vec![];
    let mut power = vec![];
    let mut octave = smallest;
    while octave <= largest {
        // The force follows the command late, so a sawtooth crossed rising and one crossed
        // falling are out of phase in it: each direction (and a still command) is a line of
        // its own, and their powers add.
        let mut groups = [(); 3].map(|_| std::collections::BTreeMap::<i64, (f64, f64, f64)>::new());
        let mut total = 0.0;
        for ((&x, &y), &rate) in xs.iter().zip(&ys).zip(&rates) {
            let w = 1.0 / (1.0 + (RESPONSE_TIME * rate / octave).powi(2));
            let group = if rate.abs() * RESPONSE_TIME < 0.05 * octave {
                0
            } else if rate > 0.0 {
                1
            } else {
                2
            };
            let bin = groups[group]
                .entry(((x - low) / width).round() as i64)
                .or_insert((0.0, 0.0, 0.0));
            *bin = (bin.0 + w * x, bin.1 + w * y, bin.2 + w);
            total += w;
        }
        let lines: Vec<(Vec<f64>, Vec<f64>)> = groups
            .iter()
            .map(|bins| bins.values().filter(|b| b.2 > 0.0).map(|&(x, y, w)| (x / w, y)).unzip())
            .collect();
        // A peak at period q is about q/span wide (relative): a quarter of that apart.
        let mut q = octave;
        while q < 2.0 * octave && q <= largest {
            periods.push(q);
            let summed: f64 = lines.iter().map(|(centres, sums)| line_power(centres, sums, q)).sum();
            power.push(summed / (total * total).max(1e-300));
            q *= 1.0 + 0.25 * q / span;
        }
        octave *= 2.0;
    }
    let mut peaks: Vec<(f64, f64)> = (1..periods.len().saturating_sub(1))
        .filter(|&i| power[i] >= power[i - 1] && power[i] >= power[i + 1])
        .map(|i| {
            // The vertex of the parabola through the peak and its neighbours.
            let (a, b, c) = (power[i - 1], power[i], power[i + 1]);
            let (qa, qb, qc) = (periods[i - 1], periods[i], periods[i + 1]);
            let curvature = a - 2.0 * b + c;
            let shift = if curvature < 0.0 {
                (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
            } else {
                0.0
            };
            (qb + shift * if shift < 0.0 { qb - qa } else { qc - qb }, b)
        })
        .collect();
    peaks.sort_by(|a, b| b.1.total_cmp(&a.1));
    peaks
}

/// The quantiser in words, with its parameters, when `set` switches it on.
pub(crate) fn reading(set: &[(&'static str, f64)]) -> Option<String> {
    let get = |name: &str| set.iter().find(|(n, _)| *n == name).map(|s| s.1);
    let q = get("command_quantum").filter(|&q| q > 0.0)?;
    let origin = get("command_quantum_origin").unwrap_or(0.0);
    let threshold = get("command_quantum_threshold").unwrap_or(0.5);
    let way = if threshold == 0.5 {
        "rounded to the nearest level".to_string()
    } else if threshold == 1.0 {
        "truncated to the level below".to_string()
    } else {
        format!("taking the next level from {:.0} % of the way to it", 100.0 * threshold)
    };
    Some(format!(
        "The command the current driver sees takes only levels {q:.4} V apart ({:.0} levels over the D/A's \
         20 V), through {origin:.4} V, each command {way}: command_quantum = {q:.4e} V, \
         command_quantum_origin = {origin:.4e} V, command_quantum_threshold = {threshold}.",
        20.0 / q
    ))
}

/// The smallest positive spacing between distinct commands (the logger's resolution).
fn resolution(xs: &[f64]) -> f64 {
    let mut sorted: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|&d| d > 1e-9)
        .fold(f64::INFINITY, f64::min)
}

/// `ys` less its least-squares quadratic in `xs`: a smooth static misfit is no period.
fn without_smooth_trend(xs: &[f64], ys: &[f64]) -> Vec<f64> {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    let scale = xs.iter().map(|x| (x - mean).abs()).fold(0.0, f64::max).max(1e-12);
    let basis = |x: f64| {
        let u = (x - mean) / scale;
        [1.0, u, u * u]
    };
    let mut ata = [[0.0; 3]; 3];
    let mut atb = [0.0; 3];
    for (&x, &y) in xs.iter().zip(ys) {
        let b = basis(x);
        for i in 0..3 {
            atb[i] += b[i] * y;
            for j in 0..3 {
                ata[i][j] += b[i] * b[j];
            }
        }
    }
    let c = solve3(ata, atb).unwrap_or([0.0; 3]);
    xs.iter()
        .zip(ys)
        .map(|(&x, &y)| {
            let b = basis(x);
            y - c[0] * b[0] - c[1] * b[1] - c[2] * b[2]
        })
        .collect()
}

fn solve3(mut a: [[f64; 3]; 3], mut b: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let pivot = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        b.swap(col, pivot);
        for row in col + 1..3 {
            let f = a[row][col] / a[col][col];
            for k in col..3 {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; 3];
    for row in (0..3).rev() {
        let s: f64 = (row + 1..3).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    Some(x)
}

/// |Σ y e^{2πi x/q}|²: n² times the mean square of the line at period q of n samples.
fn line_power(xs: &[f64], ys: &[f64], q: f64) -> f64 {
    let w = 2.0 * std::f64::consts::PI / q;
    let (mut s, mut c) = (0.0, 0.0);
    for (&x, &y) in xs.iter().zip(ys) {
        let (sin, cos) = (w * x).sin_cos();
        s += y * sin;
        c += y * cos;
    }
    s * s + c * c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(n: usize) -> Vec<f64> {
        (0..n).map(|k| k as f64 * 1e-3).collect()
    }

    /// A slow sine of the command on the 12-bit logger's grid, and the quantisation error of
    /// a converter of step `q` rounding onto levels through `origin`, seen through a gain.
    fn sawtooth(q: f64, origin: f64) -> (Vec<f64>, Vec<f64>) {
        let logged = 20.0 / 4096.0;
        let v: Vec<f64> = (0..20_000)
            .map(|k| {
                let v = 4.0 + 3.5 * (k as f64 * 2e-4).sin();
                (v / logged).round() * logged
            })
            .collect();
        let r = v
            .iter()
            .enumerate()
            .map(|(k, &v)| {
                let error = origin + q * ((v - origin) / q).round() - v;
                // A gain error and a little noise the period must stand out of.
                2.0 * error + 0.05 * v + 0.02 * ((k * 7919) % 101) as f64 / 101.0
            })
            .collect();
        (v, r)
    }

    #[test]
    fn a_sawtooth_of_the_command_is_read_at_its_period() {
        for (q, origin) in [(0.3125, 0.0), (0.6, 0.1), (0.078, 0.0)] {
            let (v, r) = sawtooth(q, origin);
            let steps = leading_steps(&times(v.len()), &v, &r, &vec![true; v.len()]);
            assert!((steps[0] / q - 1.0).abs() < 0.01, "q = {q} V read as {steps:?}");
        }
    }

    #[test]
    fn a_smooth_static_misfit_holds_no_period_beside_a_sawtooth() {
        let (v, with) = sawtooth(0.3125, 0.0);
        let smooth: Vec<f64> = v.iter().map(|v| 0.05 * v + 0.01 * v * v).collect();
        let used = vec![true; v.len()];
        let strongest = |r: &[f64]| peaks(&times(v.len()), &v, r, &used).first().map_or(0.0, |p| p.1);
        assert!(strongest(&smooth) < 1e-3 * strongest(&with));
    }

    #[test]
    fn a_twelve_bit_log_of_commands_over_a_few_volts_gives_the_coarser_converters_steps() {
        let (v, _) = sawtooth(0.3125, 0.0);
        let steps = converter_steps(&v);
        // 20/4096 V times 4 .. 256: the 10- to 4-bit converters over ±10 V whose step is
        // within a quarter of the 7 V the commands span.
        let expected: Vec<f64> = (2..=8).map(|k| 20.0 / 4096.0 * f64::from(1u32 << k)).collect();
        assert_eq!(steps, expected);
    }

    #[test]
    fn commands_on_a_few_logger_steps_hold_no_coarser_grid() {
        let v: Vec<f64> = (0..100).map(|k| 1.0 + 0.005 * (k % 3) as f64).collect();
        let r = vec![0.0; 100];
        assert!(leading_steps(&times(100), &v, &r, &[true; 100]).is_empty());
    }
}
