//! Screening flexible surfaces: each place's constant's sensitivity times a grid's bilinear
//! basis at one or two signals (each read directly or low-passed), least squares on the
//! training blocks with a small penalty on the grid's second differences, scored on the
//! held-out ones. The surfaces and their slots are [`crate::candidates::flexible`]'s.

use crate::candidates::flexible::{
    low_passed, quantile_knots, signals, Axis, Surface, KNOTS_ALONE, KNOTS_PAIRED, LAGS,
};
use crate::candidates::modulation::hats;
use crate::fit::normal::Normal;
use crate::fit::{Problem, Sensitivity};
use crate::input::blocks::Block;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use crate::vocabulary::Place;
use jetpipe_model::physics::modulation::ModulationSignal;

/// The signals of one screen's surfaces of two: the best this many single signals of a
/// constant, paired.
const PAIRED_FROM: usize = 4;

/// The weight of the second differences of the grid's values against the data: a fraction of
/// the mean diagonal of the normal matrix, so that it smooths where data are thin and yields
/// where they are many.
const SMOOTHING: f64 = 1e-3;

/// The bilinear basis of a grid at one sample: the product of each axis's hats, axis 1
/// slowest, into `out` (length the product of the axes' knot counts).
fn basis(knots: &[Vec<f64>], at: &[f64], scratch: &mut [Vec<f64>], out: &mut [f64]) {
    for (a, k) in knots.iter().enumerate() {
        hats(k, at[a], &mut scratch[a]);
    }
    match knots.len() {
        1 => out.copy_from_slice(&scratch[0]),
        _ => {
            let m = knots[1].len();
            for (i, p) in scratch[0].iter().enumerate() {
                for (j, q) in scratch[1].iter().enumerate() {
                    out[i * m + j] = p * q;
                }
            }
        }
    }
}

/// The rows of the grid's second differences along each axis, for the smoothing.
fn second_differences(shape: &[usize]) -> Vec<Vec<f64>> {
    let size: usize = shape.iter().product();
    let index = |i: usize, j: usize| if shape.len() == 1 { i } else { i * shape[1] + j };
    let (n1, n2) = (shape[0], *shape.get(1).unwrap_or(&1));
    let mut rows = vec![];
    for i in 0..n1 {
        for j in 0..n2 {
            if i + 2 < n1 {
                let mut r = vec![0.0; size];
                r[index(i, j)] = 1.0;
                r[index(i + 1, j)] = -2.0;
                r[index(i + 2, j)] = 1.0;
                rows.push(r);
            }
            if j + 2 < n2 {
                let mut r = vec![0.0; size];
                r[index(i, j)] = 1.0;
                r[index(i, j + 1)] = -2.0;
                r[index(i, j + 2)] = 1.0;
                rows.push(r);
            }
        }
    }
    rows
}

/// Screen one surface: the sensitivity times the grid's basis, least squares on the training
/// blocks with the smoothing, scored on the held-out ones. Returns the values and the
/// held-out sum of squares.
pub fn screen_surface(
    problem: &Problem,
    residual: &[Vec<f64>; CHANNELS],
    sensitivity: &Sensitivity,
    axes_values: &[&[f64]],
    knots: &[Vec<f64>],
) -> Option<(Vec<f64>, f64)> {
    let shape: Vec<usize> = knots.iter().map(Vec::len).collect();
    let size: usize = shape.iter().product();
    let mut normal = Normal::new(size);
    let mut scratch: Vec<Vec<f64>> = shape.iter().map(|&n| vec![0.0; n]).collect();
    let mut phi = vec![0.0; size];
    let mut row = vec![0.0; size];
    let mut at = vec![0.0; knots.len()];
    let mut diagonal = 0.0;
    for (k, &block) in problem.blocks.iter().enumerate() {
        if !block.is_used() {
            continue;
        }
        for (a, values) in axes_values.iter().enumerate() {
            at[a] = values[k];
        }
        basis(knots, &at, &mut scratch, &mut phi);
        for c in 0..CHANNELS {
            if residual[c].is_empty() || sensitivity[c].is_empty() {
                continue;
            }
            let s = problem.weights[c] * f64::from(sensitivity[c][k]);
            if s == 0.0 {
                continue;
            }
            for j in 0..size {
                row[j] = s * phi[j];
            }
            if block == Block::Training {
                diagonal += row.iter().map(|r| r * r).sum::<f64>();
            }
            normal.add(block, &row, residual[c][k]);
        }
    }
    if diagonal.is_nan() || diagonal <= 0.0 {
        return None;
    }
    let weight = (SMOOTHING * diagonal / size as f64).sqrt();
    for r in second_differences(&shape) {
        let scaled: Vec<f64> = r.iter().map(|v| v * weight).collect();
        normal.add(Block::Training, &scaled, 0.0);
    }
    let identity: Vec<Vec<f64>> = (0..size)
        .map(|i| (0..size).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    normal.solve_in(&identity)
}

/// Every surface worth fitting through the model, best first: for each place's constant, its
/// surfaces of one signal (every signal at every lag of [`LAGS`]) and of two (pairs of the
/// best `PAIRED_FROM` (4) signals of one), each kept where it beats a constant shift of the
/// constant by its penalty; at most `most`, one per constant. `sensitivities` are the
/// constants' (one replay each, made by the caller), `penalty` what each coefficient must
/// earn, in noise floors squared.
pub fn screen(
    problem: &Problem,
    replay: &Replay,
    sensitivities: &[(Place, &'static str, Sensitivity)],
    penalty: f64,
    most: usize,
    jobs: usize,
) -> Vec<Surface> {
    let residual = crate::fit::screen::residuals(problem, replay);
    let time = &problem.recording.time;
    let axes: Vec<Axis> = signals()
        .flat_map(|signal| LAGS.iter().map(move |&lag| Axis { signal, lag }))
        .filter(|a| a.lag == 0.0 || a.signal != ModulationSignal::Time)
        .collect();
    let values_of = |axis: &Axis| {
        low_passed(
            time,
            &crate::fit::screen::signal_values(axis.signal, problem, replay),
            axis.lag,
        )
    };
    // Each axis once, against every constant: the axis's values are the memory that counts.
    let alone: Vec<Vec<Option<Surface>>> = crate::parallel::parallel_map(&axes, jobs, |axis| {
        let values = values_of(axis);
        let Some(knots) = quantile_knots(&values, problem.blocks, KNOTS_ALONE) else {
            return vec![];
        };
        sensitivities
            .iter()
            .map(|(place, constant, sensitivity)| {
                let (y, ss) = screen_surface(
                    problem,
                    &residual,
                    sensitivity,
                    &[&values],
                    std::slice::from_ref(&knots),
                )?;
                let (_, shift_ss) = screen_surface(problem, &residual, sensitivity, &[&values], &[vec![0.0]])
                    .unwrap_or((vec![], f64::INFINITY));
                let penalised = ss + penalty * knots.len() as f64;
                (penalised < shift_ss + penalty).then(|| Surface {
                    place: *place,
                    constant,
                    axes: vec![*axis],
                    knots: vec![knots.clone()],
                    values: y,
                    penalised,
                })
            })
            .collect()
    });
    let mut found: Vec<Surface> = alone.into_iter().flatten().flatten().collect();
    found.sort_by(|a, b| a.penalised.total_cmp(&b.penalised));
    // Pairs of each constant's best signals (one lag per signal).
    let mut pairs: Vec<(usize, Axis, Axis)> = vec![];
    for (c, (_, constant, _)) in sensitivities.iter().enumerate() {
        let mut best: Vec<Axis> = vec![];
        for s in found.iter().filter(|s| s.constant == *constant) {
            if best.len() < PAIRED_FROM && !best.iter().any(|a| a.signal == s.axes[0].signal) {
                best.push(s.axes[0]);
            }
        }
        for i in 0..best.len() {
            for j in i + 1..best.len() {
                pairs.push((c, best[i], best[j]));
            }
        }
        // The best signal beside every other one read directly: the leading few often carry
        // one piece of information (the command, the current and the jet's position), and the
        // second factor is then none of them.
        if let Some(&first) = best.first() {
            for signal in signals().filter(|&s| !best.iter().any(|a| a.signal == s)) {
                pairs.push((c, first, Axis { signal, lag: 0.0 }));
            }
        }
    }
    let paired: Vec<Option<Surface>> = crate::parallel::parallel_map(&pairs, jobs, |&(c, a, b)| {
        let (place, constant, sensitivity) = &sensitivities[c];
        let (va, vb) = (values_of(&a), values_of(&b));
        let knots = vec![
            quantile_knots(&va, problem.blocks, KNOTS_PAIRED)?,
            quantile_knots(&vb, problem.blocks, KNOTS_PAIRED)?,
        ];
        let (y, ss) = screen_surface(problem, &residual, sensitivity, &[&va, &vb], &knots)?;
        Some(Surface {
            place: *place,
            constant,
            axes: vec![a, b],
            penalised: ss + penalty * (knots[0].len() * knots[1].len()) as f64,
            knots,
            values: y,
        })
    });
    found.extend(paired.into_iter().flatten());
    found.sort_by(|a, b| a.penalised.total_cmp(&b.penalised));
    let mut kept: Vec<Surface> = vec![];
    for s in found {
        if kept.len() < most && !kept.iter().any(|k| k.constant == s.constant) {
            kept.push(s);
        }
    }
    // The low-passes between the grid's: each kept surface's lags scaled by the factors of
    // [`LAG_REFINEMENTS`], one axis at a time, the best kept.
    crate::parallel::parallel_map(&kept, jobs, |surface| {
        let mut best = surface.clone();
        for a in 0..surface.axes.len() {
            if surface.axes[a].lag == 0.0 {
                continue;
            }
            let start = best.clone();
            for factor in LAG_REFINEMENTS {
                let mut axes = start.axes.clone();
                axes[a].lag *= factor;
                let values: Vec<Vec<f64>> = axes.iter().map(values_of).collect();
                let slices: Vec<&[f64]> = values.iter().map(Vec::as_slice).collect();
                let count = if axes.len() == 1 { KNOTS_ALONE } else { KNOTS_PAIRED };
                let Some(knots) = values
                    .iter()
                    .map(|v| quantile_knots(v, problem.blocks, count))
                    .collect::<Option<Vec<_>>>()
                else {
                    continue;
                };
                let sensitivity = &sensitivities
                    .iter()
                    .find(|(_, c, _)| *c == surface.constant)
                    .expect("a kept surface's constant was screened")
                    .2;
                let Some((y, ss)) = screen_surface(problem, &residual, sensitivity, &slices, &knots) else {
                    continue;
                };
                let size: usize = knots.iter().map(Vec::len).product();
                let penalised = ss + penalty * size as f64;
                if penalised < best.penalised {
                    best = Surface {
                        axes,
                        knots,
                        values: y,
                        penalised,
                        ..surface.clone()
                    };
                }
            }
        }
        best
    })
}

/// The factors a kept surface's low-passes are scaled by, between the screen's grid of lags.
const LAG_REFINEMENTS: [f64; 6] = [0.5, 0.6, 0.75, 1.3, 1.6, 2.0];

#[cfg(test)]
mod tests {
    use super::*;
    use jetpipe_model::physics::parameters::Parameters;

    #[test]
    fn a_surface_of_two_signals_is_screened_as_that_surface_where_one_signal_alone_leaves_most_of_it() {
        let n = 40_000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let a: Vec<f64> = time.iter().map(|t| (0.37 * t).sin()).collect();
        let b: Vec<f64> = time.iter().map(|t| (1.13 * t + 0.4).sin()).collect();
        // A product of the two, which no function of one alone holds.
        let truth: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.5 * x * y).collect();
        let blocks = Block::alternating(n, 2000);
        let recording = crate::input::recording::Recording {
            fast_replay: crate::input::recording::FastReplayMethod {
                step: 1e-3,
                third_order: false,
            },
            ..crate::input::recording::Recording::of(time.clone(), vec![0.0; n], vec![0.06; n], truth.clone())
        };
        let base = Parameters::default();
        let problem = Problem::new(&recording, &base, &blocks, [0.01, 0.0, 0.0]);
        let residual: [Vec<f64>; CHANNELS] = [truth.iter().map(|r| r / 0.01).collect(), vec![], vec![]];
        let sensitivity: Sensitivity = std::sync::Arc::new([vec![1.0f32; n], vec![], vec![]]);
        let ka = quantile_knots(&a, &blocks, KNOTS_PAIRED).unwrap();
        let kb = quantile_knots(&b, &blocks, KNOTS_PAIRED).unwrap();
        let heldout_ss: f64 = residual[0]
            .iter()
            .zip(&blocks)
            .filter(|(_, b)| **b == Block::HeldOut)
            .map(|(r, _)| r * r)
            .sum();
        let (_, alone) = screen_surface(
            &problem,
            &residual,
            &sensitivity,
            &[&a],
            &[quantile_knots(&a, &blocks, KNOTS_ALONE).unwrap()],
        )
        .unwrap();
        let (values, paired) =
            screen_surface(&problem, &residual, &sensitivity, &[&a, &b], &[ka.clone(), kb.clone()]).unwrap();
        assert!(
            alone > 0.8 * heldout_ss,
            "one signal alone left {alone} of {heldout_ss}"
        );
        assert!(paired < 0.05 * heldout_ss, "the surface left {paired} of {heldout_ss}");
        // At the grid's corners the surface is the product's sign.
        let corner = |i: usize, j: usize| values[i * kb.len() + j];
        assert!(corner(0, 0) > 0.0 && corner(ka.len() - 1, kb.len() - 1) > 0.0);
        assert!(corner(0, kb.len() - 1) < 0.0 && corner(ka.len() - 1, 0) < 0.0);
    }
}
