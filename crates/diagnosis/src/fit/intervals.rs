//! How sure the amounts added are: a 95 % interval on each, taken once at the end on the
//! final model, so that nothing the decision did depends on it.
//!
//! The interval is the fit's curvature on the training blocks: the residual variance times
//! (JᵀJ)⁻¹, J the final replay's sensitivities to every amount at once (each channel weighted
//! by its noise floor), so each interval holds the others free. Residuals of a model that
//! does not explain everything, and of a transducer's lag, are autocorrelated, and JᵀJ then
//! counts more independent samples than there are: each amount's variance is multiplied by
//! the integrated autocorrelation time of its influence series (the sample's contribution to
//! the Gauss–Newton step), 1 + 2 Σρ up to the first lag where ρ ≤ 0, which is n over the
//! effective sample size. That is checked against the held-out blocks: the same influences
//! summed block by block over the held-out residual (which no fit has seen) give a variance
//! from the spread between blocks, with whatever correlation a block holds. Where that is
//! larger than the curvature's by more than the blocks' own scatter allows (its 97.5 %
//! chi-square point) and there are four blocks or more, the interval is the held-out blocks'
//! one, with Student's t on as many degrees of freedom as blocks.
//!
//! The fits score candidates on the fixed-step replay, held within a tenth of a noise floor of
//! the error-controlled one. Against n samples that tenth is not small: a departure of 0.1
//! floors that leans on an amount's sensitivity moves its least-squares value by up to
//! 0.1 √n standard errors (9 at 7,500 samples), beyond any interval from the noise. So the
//! residual here is the error-controlled replay's, and each interval carries the
//! Gauss–Newton step from the fitted value to that replay's least squares on the training
//! blocks ([`Interval::step`]), which the conclusion takes before the interval is reported.

use crate::candidates::declared_bounds;
use crate::candidates::parameter_value;
use crate::fit::Problem;
use crate::fit::Sensitivity;
use crate::input::blocks::Block;
use crate::replay::replay_fast;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// The standard normal's 97.5 % point: a two-sided 95 % interval.
const Z_975: f64 = 1.959_963_985;
/// The relative step of the finite differences: the one the joint refit takes.
const RELATIVE_STEP: f64 = 1e-3;
/// The longest lag, in samples, of an autocorrelation summed: a 2 s block's at 1 kHz.
const MOST_LAGS: usize = 2000;
/// The fewest held-out blocks whose spread may replace the curvature's interval. A variance
/// from B blocks has B degrees of freedom: from two, its 95 % range spans a factor of 150, and
/// the 2.5 % of amounts whose check fails by chance would get intervals four times too wide
/// (Student's t on 2 degrees is 4.3). With fewer, the check is reported and not applied.
const FEWEST_BLOCKS_TO_WIDEN: usize = 4;

/// Where an interval came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntervalMethod {
    /// The curvature of the training fit, with the effective sample size; the held-out blocks
    /// agree with it (or there were too few to tell).
    Curvature,
    /// The spread over the held-out blocks, wider than the curvature's by more than chance.
    HeldOutBlocks,
}

impl IntervalMethod {
    pub fn as_str(self) -> &'static str {
        match self {
            IntervalMethod::Curvature => "curvature",
            IntervalMethod::HeldOutBlocks => "heldout_blocks",
        }
    }
}

/// A 95 % interval on one amount.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub low: f64,
    pub high: f64,
    pub method: IntervalMethod,
    /// The held-out blocks' standard error over the curvature's (with the effective sample
    /// size); `None` with fewer than two held-out blocks.
    pub heldout_ratio: Option<f64>,
    /// The Gauss–Newton step of this amount, all amounts moving together, from its value to
    /// the least squares of the residual given on the training blocks; `low` and `high` are
    /// around the value before the step.
    pub step: f64,
}

impl Interval {
    /// The same interval around the value moved by `shift`.
    pub fn shifted(self, shift: f64) -> Interval {
        Interval {
            low: self.low + shift,
            high: self.high + shift,
            ..self
        }
    }
}

/// Whether `name` is an amount with an interval: a curve's knot count and abscissae and a
/// modulation's constant, signal, frequency and knot count are its grid or its choice, held
/// where the search put them (the others' intervals are given that choice).
pub(crate) fn has_interval(name: &str) -> bool {
    crate::fit::refit::refittable(name)
}

/// The 95 % interval of each of `names` in the model `params` on the problem's recording
/// and blocks (`problem.base` must be `params`), in the order given; `None` for an amount
/// without one ([`has_interval`]), one at zero with a default of zero (no scale for its
/// step), one the replay does not see, or when the model refuses the moved value. The
/// residual is `accurate`'s, the error-controlled replay of `params` at the problem's rows,
/// when given, else the fixed-step replay's. Also the replays taken (one, and one per amount).
pub(crate) fn intervals(
    problem: &Problem,
    params: &Parameters,
    names: &[&'static str],
    accurate: Option<&Replay>,
    jobs: usize,
) -> Result<(Vec<Option<Interval>>, usize), String> {
    let recording = problem.recording;
    let at = replay_fast(&Actuator::new(params.clone())?, recording, recording.len())?;
    let residual_of = accurate.unwrap_or(&at);
    let thesis = Parameters::default();
    let steps: Vec<Option<f64>> = names
        .iter()
        .map(|&name| {
            let value = parameter_value(params, name);
            let scale = value.abs().max(parameter_value(&thesis, name).abs());
            if !has_interval(name) || scale == 0.0 {
                return None;
            }
            let step = RELATIVE_STEP * scale;
            // Forward unless that leaves the declared range.
            Some(if value + step <= declared_bounds(name).1 {
                step
            } else {
                -step
            })
        })
        .collect();
    let wanted: Vec<(usize, f64)> = steps
        .iter()
        .enumerate()
        .filter_map(|(j, s)| s.map(|s| (j, s)))
        .collect();
    let columns: Vec<Option<Sensitivity>> = crate::parallel::parallel_map(&wanted, jobs, |&(j, step)| {
        let value = parameter_value(params, names[j]);
        problem.sensitivity_to(&[(names[j], value + step)], step, &at)
    });
    let replays = 1 + wanted.len();
    let measured_residual: [Vec<f64>; CHANNELS] = std::array::from_fn(|c| {
        if problem.weights[c] == 0.0 {
            return vec![];
        }
        let modelled = [&residual_of.force, &residual_of.p1, &residual_of.p2][c];
        problem.measured[c]
            .iter()
            .zip(modelled)
            .map(|(m, y)| problem.weights[c] * (m - y))
            .collect()
    });
    let mut out = vec![None; names.len()];
    let usable: Vec<(usize, Sensitivity)> = wanted
        .iter()
        .zip(columns)
        .filter_map(|(&(j, _), c)| c.map(|c| (j, c)))
        .collect();
    let weighted: Vec<[Vec<f64>; CHANNELS]> = usable
        .iter()
        .map(|(_, column)| {
            std::array::from_fn(|c| {
                if problem.weights[c] == 0.0 || column[c].is_empty() {
                    return vec![];
                }
                column[c].iter().map(|v| problem.weights[c] * f64::from(*v)).collect()
            })
        })
        .collect();
    let values: Vec<f64> = usable.iter().map(|(j, _)| parameter_value(params, names[*j])).collect();
    let estimated = linearised_intervals(&weighted, &measured_residual, problem.blocks, &values);
    for ((j, _), interval) in usable.iter().zip(estimated) {
        out[*j] = interval.map(|i| {
            let (lower, upper) = declared_bounds(names[*j]);
            Interval {
                low: i.low.max(lower),
                high: i.high.min(upper),
                ..i
            }
        });
    }
    Ok((out, replays))
}

/// The intervals of amounts at `values` from their weighted sensitivity columns `columns[a][c]`
/// (an empty channel for one not measured) and the weighted residual of each channel
/// (`residual[c]`, empty where not measured): the account in the module's head. `None` for an
/// amount whose columns are zero on the training samples, or all when the curvature is
/// singular.
pub(crate) fn linearised_intervals(
    columns: &[[Vec<f64>; CHANNELS]],
    residual: &[Vec<f64>; CHANNELS],
    blocks: &[Block],
    values: &[f64],
) -> Vec<Option<Interval>> {
    let p = columns.len();
    let at = |a: usize, c: usize, k: usize| columns[a][c].get(k).copied().unwrap_or(0.0);
    let measured: Vec<usize> = (0..CHANNELS).filter(|&c| !residual[c].is_empty()).collect();
    // The curvature and the gradient on the training samples.
    let mut curvature = nalgebra::DMatrix::<f64>::zeros(p, p);
    let mut gradient = vec![0.0; p];
    let mut terms = 0usize;
    for (k, _) in blocks.iter().enumerate().filter(|(_, b)| **b == Block::Training) {
        for &c in &measured {
            terms += 1;
            for a in 0..p {
                let ja = at(a, c, k);
                if ja == 0.0 {
                    continue;
                }
                gradient[a] += ja * residual[c][k];
                for b in a..p {
                    curvature[(a, b)] += ja * at(b, c, k);
                }
            }
        }
    }
    for a in 0..p {
        for b in 0..a {
            curvature[(a, b)] = curvature[(b, a)];
        }
    }
    // An amount the training samples do not see has no interval; the others are taken
    // without it.
    let seen: Vec<usize> = (0..p).filter(|&a| curvature[(a, a)] > 0.0).collect();
    let mut out = vec![None; p];
    if seen.is_empty() || terms <= seen.len() {
        return out;
    }
    let reduced = nalgebra::DMatrix::from_fn(seen.len(), seen.len(), |i, j| curvature[(seen[i], seen[j])]);
    let Some(inverse) = reduced.try_inverse() else {
        return out;
    };
    // The Gauss–Newton step, and the residual it leaves (linearised), from which the
    // variance and the influences are taken: a residual that still holds the step's share
    // would count it as noise, once in the variance and again in every block's spread.
    let step: Vec<f64> = (0..seen.len())
        .map(|i| (0..seen.len()).map(|j| inverse[(i, j)] * gradient[seen[j]]).sum())
        .collect();
    let residual: [Vec<f64>; CHANNELS] = std::array::from_fn(|c| {
        residual[c]
            .iter()
            .enumerate()
            .map(|(k, r)| r - seen.iter().zip(&step).map(|(&a, s)| at(a, c, k) * s).sum::<f64>())
            .collect()
    });
    let sum_squares: f64 = blocks
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == Block::Training)
        .map(|(k, _)| measured.iter().map(|&c| residual[c][k] * residual[c][k]).sum::<f64>())
        .sum();
    let variance = sum_squares / (terms - seen.len()) as f64;
    // Each sample's influence on the step: (JᵀJ)⁻¹ times its gradient.
    let influence = |k: usize| -> Vec<f64> {
        let gradient: Vec<f64> = seen
            .iter()
            .map(|&a| measured.iter().map(|&c| at(a, c, k) * residual[c][k]).sum())
            .collect();
        (0..seen.len())
            .map(|i| (0..seen.len()).map(|j| inverse[(i, j)] * gradient[j]).sum())
            .collect()
    };
    let runs = |kind: Block| -> Vec<Vec<Vec<f64>>> {
        let mut runs: Vec<Vec<Vec<f64>>> = vec![];
        let mut open = false;
        for (k, b) in blocks.iter().enumerate() {
            if *b == kind {
                if !open {
                    runs.push(vec![]);
                    open = true;
                }
                runs.last_mut().expect("a run").push(influence(k));
            } else {
                open = false;
            }
        }
        runs
    };
    let training = runs(Block::Training);
    let heldout = runs(Block::HeldOut);
    let training_samples: usize = training.iter().map(Vec::len).sum();
    let heldout_samples: usize = heldout.iter().map(Vec::len).sum();
    for (i, &a) in seen.iter().enumerate() {
        let curvature_variance = variance * inverse[(i, i)];
        if !(curvature_variance.is_finite() && curvature_variance > 0.0) {
            continue;
        }
        let series: Vec<Vec<f64>> = training.iter().map(|run| run.iter().map(|u| u[i]).collect()).collect();
        let variance_curvature = curvature_variance * autocorrelation_time(&series);
        // The held-out blocks: each block's summed influence is one draw of what a block
        // adds to the estimate; their sum of squares, scaled to the training's size.
        let blocks = heldout.len();
        let heldout_ratio = (blocks >= 2 && heldout_samples > 0).then(|| {
            let spread: f64 = heldout
                .iter()
                .map(|run| run.iter().map(|u| u[i]).sum::<f64>().powi(2))
                .sum::<f64>()
                * training_samples as f64
                / heldout_samples as f64;
            (spread / variance_curvature).sqrt()
        });
        let (half_width, method) = match heldout_ratio {
            Some(ratio)
                if blocks >= FEWEST_BLOCKS_TO_WIDEN
                    && ratio * ratio > chi_square_975(blocks as f64) / blocks as f64 =>
            {
                (
                    student_t_975(blocks as f64) * ratio * variance_curvature.sqrt(),
                    IntervalMethod::HeldOutBlocks,
                )
            }
            _ => (Z_975 * variance_curvature.sqrt(), IntervalMethod::Curvature),
        };
        out[a] = Some(Interval {
            low: values[a] - half_width,
            high: values[a] + half_width,
            method,
            heldout_ratio,
            step: step[i],
        });
    }
    out
}

/// The integrated autocorrelation time of a series cut into runs (lags within a run only):
/// 1 + 2 Σρ(lag) from lag 1 up to the first lag where ρ ≤ 0 (beyond it the sum is noise),
/// at most [`MOST_LAGS`]; at least 1, as a series no more independent than white noise is
/// not taken as more.
pub(crate) fn autocorrelation_time(runs: &[Vec<f64>]) -> f64 {
    let total: usize = runs.iter().map(Vec::len).sum();
    if total < 2 {
        return 1.0;
    }
    let mean = runs.iter().flatten().sum::<f64>() / total as f64;
    let lagged = |lag: usize| -> f64 {
        runs.iter()
            .map(|run| {
                (lag..run.len())
                    .map(|k| (run[k] - mean) * (run[k - lag] - mean))
                    .sum::<f64>()
            })
            .sum()
    };
    let zero = lagged(0);
    if zero <= 0.0 {
        return 1.0;
    }
    let longest = runs
        .iter()
        .map(Vec::len)
        .max()
        .unwrap_or(0)
        .saturating_sub(1)
        .min(MOST_LAGS);
    let mut sum = 0.0;
    for lag in 1..=longest {
        let rho = lagged(lag) / zero;
        if rho <= 0.0 {
            break;
        }
        sum += rho;
    }
    (1.0 + 2.0 * sum).max(1.0)
}

/// The chi-square distribution's 97.5 % point on `dof` degrees of freedom (Wilson and
/// Hilferty's cube-root approximation: within 1 % from 3 degrees on).
fn chi_square_975(dof: f64) -> f64 {
    let a = 2.0 / (9.0 * dof);
    dof * (1.0 - a + Z_975 * a.sqrt()).powi(3)
}

/// Student's t distribution's 97.5 % point on `dof` degrees of freedom (the Cornish–Fisher
/// expansion to 1/dof³: 2.77 against 2.776 at 4 degrees).
fn student_t_975(dof: f64) -> f64 {
    let z = Z_975;
    let (z3, z5, z7) = (z.powi(3), z.powi(5), z.powi(7));
    z + (z3 + z) / (4.0 * dof)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * dof.powi(2))
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * dof.powi(3))
}

#[cfg(test)]
#[path = "intervals_tests.rs"]
mod tests;
