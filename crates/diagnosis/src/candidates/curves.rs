//! The static-curve class: at the command, the force sensor and each pressure transducer, a
//! piecewise linear curve (the model's `*_curve_*` parameters,
//! `jetpipe_model::physics::static_curve`) fitted through the model, competing with the
//! named effects and the other terms at its place.
//!
//! * **Where the knots go.** At quantiles of the signal at that place over the recording
//!   (the model's reading of the channel, or the logged command), so every segment holds
//!   data. On a measured channel the reading is linear in the knot values, so each trial
//!   placement is a linear least-squares solve on the training samples, without a replay:
//!   from the two ends of the range, knots are added one at a time at the 1/64 quantile
//!   that lowers the misfit most, then moved one at a time between their neighbours (a
//!   grid, then golden-section steps; two sweeps), which puts knots on a saturation's or a
//!   dead zone's corners. The command's curve acts before the dynamics;
//!   knots are placed the same way on the force's residual against the model's
//!   sensitivity to a constant shift of the command (the departure c(v) − v seen through
//!   the model to first order, exact where the command is held), then its values are
//!   fitted by Gauss–Newton through the model itself (one replay per knot value and
//!   iteration). It is always among the candidates refined after the first pass when that
//!   pass finds it worth refining. Before it is judged, its interior knots' abscissae are
//!   freed and fitted through the model with the values
//!   ([`crate::candidates::command_curve::command_curve_with_free_knots`]): the proxy puts a dead zone's corners a little off
//!   where the model needs them (a ±0.4 V dead zone under a sine at 500 Hz: 1.36 N of force
//!   left on the training blocks with the proxy's knots, 0.049 N with them freed, the noise
//!   floor 0.049 N).
//! * **Unvisited stretches.** Where the training samples cover less than half of the
//!   stretch between two knots of a channel's curve, the stretch's upper knot moves to where
//!   its neighbours' lines meet, unless the held-out samples there fit the chord better
//!   ([`corners_across_unvisited`]).
//! * **Monotone.** A transducer's reading and the command the driver sees do not fall as
//!   their input rises: on a channel the curve is fitted as an offset and non-negative
//!   increments over the segments (bounded least squares); the command's knot values are
//!   made non-decreasing (adjacent violators pooled to their mean) before the curve enters
//!   the model, whose replay then judges it.
//! * **Reading.** From the fitted curve: a flat end is a saturation (family `limit`), a
//!   flat stretch inside a dead zone, otherwise the largest departure from the identity and
//!   where it is.

use crate::candidates::{Candidate, Mechanism, Regressor, Term};
use crate::input::blocks::Block;
use crate::replay::signals::{CHANNELS, FORCE, P1, P2};
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::physics::static_curve::{StaticCurve, MAX_KNOTS};
use jetpipe_model::variables::VARIABLES;

/// Knots of a curve on a measured channel.
pub const SENSOR_KNOTS: usize = 8;
/// Knots of the command's curve (each a replay per Gauss–Newton iteration).
pub const COMMAND_KNOTS: usize = 8;
/// A segment whose slope is below this share of the identity's is flat.
pub(crate) const FLAT: f64 = 0.1;

/// The knots' starting abscissae at each place: the command (V), then the channels' readings.
#[derive(Clone, Debug, Default)]
pub struct CurveKnots {
    pub command: Vec<f64>,
    pub channels: [Vec<f64>; CHANNELS],
}

/// The place of a channel's curve: its parameters' prefix and the reading's words.
fn channel_prefix(channel: usize) -> &'static str {
    match channel {
        FORCE => "force_sensor_curve",
        P1 => "p1_sensor_curve",
        _ => "p2_sensor_curve",
    }
}

/// The name of a variable of the table, as the table's own `&'static str`.
pub fn variable_name(name: &str) -> &'static str {
    VARIABLES
        .iter()
        .find(|v| v.name == name)
        .map(|v| v.name)
        .unwrap_or_else(|| panic!("{name} is not a variable of the model"))
}

/// Names of a curve's offset and increments on a channel (report names, not parameters).
const INCREMENTS: [[&str; SENSOR_KNOTS]; CHANNELS] = [
    [
        "force_sensor_curve_offset",
        "force_sensor_curve_rise_1",
        "force_sensor_curve_rise_2",
        "force_sensor_curve_rise_3",
        "force_sensor_curve_rise_4",
        "force_sensor_curve_rise_5",
        "force_sensor_curve_rise_6",
        "force_sensor_curve_rise_7",
    ],
    [
        "p1_sensor_curve_offset",
        "p1_sensor_curve_rise_1",
        "p1_sensor_curve_rise_2",
        "p1_sensor_curve_rise_3",
        "p1_sensor_curve_rise_4",
        "p1_sensor_curve_rise_5",
        "p1_sensor_curve_rise_6",
        "p1_sensor_curve_rise_7",
    ],
    [
        "p2_sensor_curve_offset",
        "p2_sensor_curve_rise_1",
        "p2_sensor_curve_rise_2",
        "p2_sensor_curve_rise_3",
        "p2_sensor_curve_rise_4",
        "p2_sensor_curve_rise_5",
        "p2_sensor_curve_rise_6",
        "p2_sensor_curve_rise_7",
    ],
];

/// The share of a segment [lo, hi] that `v` has risen through: 0 below, 1 above, the end
/// segments continued (`below`, `above`).
pub fn segment(v: f64, lo: f64, hi: f64, below: bool, above: bool) -> f64 {
    let mut u = (v - lo) / (hi - lo);
    if !below {
        u = u.max(0.0);
    }
    if !above {
        u = u.min(1.0);
    }
    u
}

/// Quantiles 0, 1/(n−1), …, 1 of `values`, with knots closer than a hundredth of the range
/// merged; empty when fewer than three remain.
pub fn quantile_knots(values: &[f64], n: usize) -> Vec<f64> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if sorted.len() < 2 * n {
        return vec![];
    }
    sorted.sort_by(f64::total_cmp);
    let (lo, hi) = (sorted[0], sorted[sorted.len() - 1]);
    let gap = 0.01 * (hi - lo);
    if gap <= 0.0 {
        return vec![];
    }
    let mut knots: Vec<f64> = vec![];
    for j in 0..n {
        let x = sorted[((sorted.len() - 1) * j) / (n - 1)];
        match knots.last() {
            Some(&last) if x - last < gap => {
                if j == n - 1 {
                    *knots.last_mut().expect("not empty") = x.max(last);
                }
            }
            _ => knots.push(x),
        }
    }
    if knots.len() < 3 {
        return vec![];
    }
    knots
}

/// Sum of squares of `y` − `scale` × (the best curve through `knots` of `x`): least squares
/// on the offset and the segments, a whisker of ridge. (`scale` 1 fits the reading itself;
/// the command's curve fits a residual through a sensitivity.)
fn misfit(knots: &[f64], x: &[f64], y: &[f64], scale: &[f64]) -> f64 {
    let m = knots.len();
    let basis = |v: f64, s: f64, out: &mut [f64]| {
        out[0] = s;
        for j in 1..m {
            out[j] = s * segment(v, knots[j - 1], knots[j], j == 1, j == m - 1);
        }
    };
    let mut ata = nalgebra::DMatrix::<f64>::zeros(m, m);
    let mut atb = nalgebra::DVector::<f64>::zeros(m);
    let mut row = vec![0.0; m];
    for ((&v, &w), &s) in x.iter().zip(y).zip(scale) {
        basis(v, s, &mut row);
        for a in 0..m {
            atb[a] += row[a] * w;
            for b in a..m {
                ata[(a, b)] += row[a] * row[b];
            }
        }
    }
    for a in 0..m {
        for b in 0..a {
            ata[(a, b)] = ata[(b, a)];
        }
        ata[(a, a)] += 1e-10 * ata[(a, a)].max(1e-300);
    }
    let Some(c) = ata.lu().solve(&atb) else {
        return f64::INFINITY;
    };
    x.iter()
        .zip(y)
        .zip(scale)
        .map(|((&v, &w), &s)| {
            basis(v, s, &mut row);
            let e = w - row.iter().zip(c.iter()).map(|(a, b)| a * b).sum::<f64>();
            e * e
        })
        .sum()
}

/// A stretch of the signal's range that no training sample visits, wider than this share of
/// the range, offers its two edges as knots.
pub const GAP_EDGE_SHARE: f64 = 0.05;

/// The samples on either side of each stretch of `values` wider than `width` that holds
/// none. The 1/64 quantiles hold no knot at a visited stretch's end when few samples lie
/// near it: a force sensor saturating at 40 N under force tracking, whose training samples
/// read up to 26.7 N and then only above 89.7 N, got its knot at 41 N, and the chord from
/// 17.4 N to it, fitted to the samples up to 26.7 N, read the level 0.08 N high and left
/// 1.85 noise floors. With a knot at the edge, the stretch beyond is unvisited and takes
/// its neighbours' corner ([`corners_across_unvisited`]).
fn gap_edges(values: &[f64], width: f64) -> Vec<f64> {
    let mut sorted: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    sorted
        .windows(2)
        .filter(|w| w[1] - w[0] > width)
        .flat_map(|w| [w[0], w[1]])
        .collect()
}

/// Knots for a curve taking the model's reading `own` to the measured `measured` on the
/// training samples: the ends of `own`'s range, knots added one at a time at whichever of
/// its 1/64 quantiles lowers the least-squares misfit most, then each interior knot moved
/// between its neighbours to where the curve fits best (two sweeps). At most 5000 samples
/// are used, evenly spread.
pub fn placed_knots(own: &[f64], measured: &[f64], blocks: &[Block], n: usize) -> Vec<f64> {
    let ones = vec![1.0; own.len()];
    placed(own, measured, &ones, blocks, n)
}

/// Knots for the command's curve: `residual` (the measured force minus the model's) taken
/// as `sensitivity` (of the force to a constant shift of the command, N/V) times a curve's
/// departure from the identity at the command `v_da`.
pub fn placed_command_knots(
    v_da: &[f64],
    residual: &[f64],
    sensitivity: &[f64],
    blocks: &[Block],
    n: usize,
) -> Vec<f64> {
    placed(v_da, residual, sensitivity, blocks, n)
}

fn placed(x_all: &[f64], y_all: &[f64], s_all: &[f64], blocks: &[Block], n: usize) -> Vec<f64> {
    let picked: Vec<usize> = (0..x_all.len().min(y_all.len()).min(s_all.len()))
        .filter(|&k| {
            blocks[k] == Block::Training && x_all[k].is_finite() && y_all[k].is_finite() && s_all[k].is_finite()
        })
        .collect();
    let stride = (picked.len() / 5000).max(1);
    let x: Vec<f64> = picked.iter().step_by(stride).map(|&k| x_all[k]).collect();
    let y: Vec<f64> = picked.iter().step_by(stride).map(|&k| y_all[k]).collect();
    let s: Vec<f64> = picked.iter().step_by(stride).map(|&k| s_all[k]).collect();
    // The ends, then knots added one at a time where they lower the misfit most, from
    // the 1/64 quantiles of the signal: a curve's corners (a dead zone's two, a
    // saturation's one) are found first.
    let mut grid = quantile_knots(&x, 65);
    if grid.len() < 3 {
        return vec![];
    }
    let (first, last) = (grid[0], grid[grid.len() - 1]);
    let gap = 0.01 * (last - first);
    grid.extend(gap_edges(&x, GAP_EDGE_SHARE * (last - first)));
    grid.sort_by(f64::total_cmp);
    grid.dedup();
    let mut knots = vec![first, last];
    while knots.len() < n {
        let best = grid
            .iter()
            .filter(|&&g| knots.iter().all(|k| (k - g).abs() >= gap))
            .map(|&g| {
                let mut trial = knots.clone();
                trial.push(g);
                trial.sort_by(f64::total_cmp);
                (g, misfit(&trial, &x, &y, &s))
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((g, _)) => {
                knots.push(g);
                knots.sort_by(f64::total_cmp);
            }
            None => break,
        }
    }
    if knots.len() < 3 {
        return vec![];
    }
    let phi = (5f64.sqrt() - 1.0) / 2.0;
    for _sweep in 0..2 {
        for j in 1..knots.len() - 1 {
            let (lo, hi) = (knots[j - 1] + gap, knots[j + 1] - gap);
            let cost = |v: f64| {
                let mut trial = knots.clone();
                trial[j] = v;
                misfit(&trial, &x, &y, &s)
            };
            // A grid first (the cost may have several minima between the neighbours),
            // then golden-section steps around the best point of the grid.
            let at_start = cost(knots[j]);
            const GRID: usize = 16;
            let grid: Vec<(f64, f64)> = (0..=GRID)
                .map(|g| {
                    let v = lo + (hi - lo) * g as f64 / GRID as f64;
                    (v, cost(v))
                })
                .collect();
            let g = (0..=GRID)
                .min_by(|&a, &b| grid[a].1.total_cmp(&grid[b].1))
                .expect("a grid");
            let (mut a, mut b) = (grid[g.saturating_sub(1)].0, grid[(g + 1).min(GRID)].0);
            let mut c = b - phi * (b - a);
            let mut d = a + phi * (b - a);
            let (mut fc, mut fd) = (cost(c), cost(d));
            for _ in 0..12 {
                if fc < fd {
                    b = d;
                    d = c;
                    fd = fc;
                    c = b - phi * (b - a);
                    fc = cost(c);
                } else {
                    a = c;
                    c = d;
                    fc = fd;
                    d = a + phi * (b - a);
                    fd = cost(d);
                }
            }
            let (best, f) = [(c, fc), (d, fd), grid[g]]
                .into_iter()
                .min_by(|p, q| p.1.total_cmp(&q.1))
                .expect("three points");
            if f < at_start {
                knots[j] = best;
            }
        }
    }
    knots
}

/// The curve candidate on a measured channel: an offset and one increment per segment of
/// the knots `x` (non-negative: the curve does not fall).
fn channel_terms(channel: usize, x: &[f64], unit: &'static str) -> Vec<Term> {
    let names = &INCREMENTS[channel];
    let typical = (x[x.len() - 1] - x[0]) / (x.len() - 1) as f64;
    let mut terms = vec![Term {
        name: names[0],
        unit,
        mechanism: Mechanism::Output {
            channel,
            regressor: Regressor::One,
        },
        neutral: 0.0,
        step: 1e-3 * typical,
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
    }];
    for j in 1..x.len() {
        terms.push(Term {
            name: names[j],
            unit,
            mechanism: Mechanism::Output {
                channel,
                regressor: Regressor::Segment {
                    lo: x[j - 1],
                    hi: x[j],
                    below: j == 1,
                    above: j == x.len() - 1,
                },
            },
            neutral: 0.0,
            step: 1e-3 * typical,
            lower: -(x[j] - x[j - 1]),
            upper: f64::INFINITY,
        });
    }
    terms
}

/// The command's curve: its knot values as model parameters, from the identity at the
/// knots `x`.
fn command_terms(x: &[f64]) -> (Vec<Term>, Vec<(&'static str, f64)>) {
    let n = x.len();
    let mut settings = vec![(variable_name("command_curve_knots"), n as f64)];
    let mut terms = vec![];
    for k in 0..n {
        let xn = variable_name(&format!("command_curve_x_{}", k + 1));
        let yn = variable_name(&format!("command_curve_y_{}", k + 1));
        settings.push((xn, x[k]));
        settings.push((yn, x[k]));
        terms.push(command_value_term(k, x[k]));
    }
    (terms, settings)
}

/// The term of the command curve's knot `k` (from 0) value, starting at `start`.
pub(crate) fn command_value_term(k: usize, start: f64) -> Term {
    let name = variable_name(&format!("command_curve_y_{}", k + 1));
    Term {
        name,
        unit: "V",
        mechanism: Mechanism::Parameter(name),
        neutral: start,
        step: 0.02,
        lower: -100.0,
        upper: 100.0,
    }
}

/// Whether a candidate is the command's curve.
pub fn is_command_curve(candidate: &Candidate) -> bool {
    candidate.settings.iter().any(|(n, _)| *n == "command_curve_knots")
}

/// The static-curve candidates at the places the knots allow, where the model `base` has no
/// curve yet (a second curve there would replace the first, not add to it).
pub fn candidates(base: &Parameters, knots: &CurveKnots, has_pressures: bool) -> Vec<Candidate> {
    let free = [
        !base.force_sensor_curve.is_on(),
        !base.p1_sensor_curve.is_on(),
        !base.p2_sensor_curve.is_on(),
    ];
    let mut list = vec![];
    let c = |label, location, terms, settings| Candidate {
        label,
        location,
        family: Family::Nonlinearity,
        named: None,
        terms,
        settings,
    };
    if knots.command.len() >= 3 && !base.command_curve.is_on() {
        let (terms, settings) = command_terms(&knots.command);
        list.push(c("command static curve", Place::Command, terms, settings));
    }
    if knots.channels[FORCE].len() >= 3 && free[FORCE] {
        let terms = channel_terms(FORCE, &knots.channels[FORCE], "N");
        list.push(c("force sensor static curve", Place::ForceSensor, terms, vec![]));
    }
    if has_pressures {
        let one = |ch: usize| {
            (knots.channels[ch].len() >= 3 && free[ch]).then(|| channel_terms(ch, &knots.channels[ch], "Pa"))
        };
        if let Some(t) = one(P1) {
            list.push(c(
                "chamber 1 pressure sensor static curve",
                Place::PressureSensors,
                t,
                vec![],
            ));
        }
        if let Some(t) = one(P2) {
            list.push(c(
                "chamber 2 pressure sensor static curve",
                Place::PressureSensors,
                t,
                vec![],
            ));
        }
        if let (Some(mut a), Some(b)) = (one(P1), one(P2)) {
            a.extend(b);
            list.push(c("pressure sensor static curves", Place::PressureSensors, a, vec![]));
        }
    }
    list
}

/// Whether a candidate is a curve on a measured channel.
pub fn is_channel_curve(candidate: &Candidate) -> bool {
    candidate.terms.iter().any(|t| {
        matches!(
            t.mechanism,
            Mechanism::Output {
                regressor: Regressor::Segment { .. },
                ..
            }
        )
    })
}

/// The FMU parameters of a fitted channel curve, composed with the transducer the model
/// has (an offset and a gain: the new reading c(o + g y) is a curve of y through the
/// knots (x − o)/g); `None` when the transducer has more than that (a curve, a polynomial,
/// a drift, a pick-up or a filter), which a curve could not carry exactly.
pub fn channel_model_terms(
    candidate: &Candidate,
    values: &[f64],
    base: &Parameters,
) -> Option<Vec<(&'static str, f64)>> {
    let mut set = vec![];
    for channel in [FORCE, P1, P2] {
        let mine: Vec<(&Term, f64)> = candidate
            .terms
            .iter()
            .zip(values)
            .filter(|(t, _)| matches!(t.mechanism, Mechanism::Output { channel: c, .. } if c == channel))
            .map(|(t, &v)| (t, v))
            .collect();
        if mine.is_empty() {
            continue;
        }
        let mut offset = 0.0;
        let mut knots: Vec<f64> = vec![];
        let mut rises: Vec<f64> = vec![];
        for (t, v) in &mine {
            match t.mechanism {
                Mechanism::Output {
                    regressor: Regressor::One,
                    ..
                } => offset += v,
                Mechanism::Output {
                    regressor: Regressor::Segment { lo, hi, .. },
                    ..
                } => {
                    if knots.is_empty() {
                        knots.push(lo);
                    }
                    knots.push(hi);
                    rises.push(hi - lo + v);
                }
                _ => return None,
            }
        }
        if knots.len() < 2 || knots.len() > MAX_KNOTS {
            return None;
        }
        let (o, g) = match channel {
            FORCE => {
                let p = base;
                let plain = p.force_sensor_quadratic == 0.0
                    && p.force_sensor_cubic == 0.0
                    && p.force_sensor_drift == 0.0
                    && p.force_sensor_ripple_sine == 0.0
                    && p.force_sensor_ripple_cosine == 0.0
                    && p.force_sensor_delay == 0.0
                    && p.force_sensor_lag == 0.0
                    && p.force_sensor_filter_frequency == 0.0
                    && p.force_sensor_play == 0.0
                    && !p.force_sensor_curve.is_on();
                if !plain {
                    return None;
                }
                (p.force_sensor_offset, p.force_sensor_gain)
            }
            P1 => {
                let p = base;
                if p.p1_sensor_drift != 0.0
                    || p.p1_sensor_delay != 0.0
                    || p.p1_sensor_lag != 0.0
                    || p.p1_sensor_filter_frequency != 0.0
                    || p.p1_sensor_curve.is_on()
                {
                    return None;
                }
                (p.p1_sensor_offset, p.p1_sensor_gain)
            }
            _ => {
                let p = base;
                if p.p2_sensor_drift != 0.0
                    || p.p2_sensor_delay != 0.0
                    || p.p2_sensor_lag != 0.0
                    || p.p2_sensor_filter_frequency != 0.0
                    || p.p2_sensor_curve.is_on()
                {
                    return None;
                }
                (p.p2_sensor_offset, p.p2_sensor_gain)
            }
        };
        let prefix = channel_prefix(channel);
        let (off_name, gain_name) = match channel {
            FORCE => ("force_sensor_offset", "force_sensor_gain"),
            P1 => ("p1_sensor_offset", "p1_sensor_gain"),
            _ => ("p2_sensor_offset", "p2_sensor_gain"),
        };
        set.push((variable_name(off_name), 0.0));
        set.push((variable_name(gain_name), 1.0));
        set.push((variable_name(&format!("{prefix}_knots")), knots.len() as f64));
        let mut y = knots[0] + offset;
        for (k, &x) in knots.iter().enumerate() {
            if k > 0 {
                y += rises[k - 1];
            }
            set.push((variable_name(&format!("{prefix}_x_{}", k + 1)), (x - o) / g));
            set.push((variable_name(&format!("{prefix}_y_{}", k + 1)), y));
        }
    }
    (!set.is_empty()).then_some(set)
}

/// A stretch between two knots of a channel's curve that the training samples visit over
/// less than this share of its width is decided by its ends alone: the chord between them is
/// a slope that no sample supports.
pub const VISITED_SHARE: f64 = 0.5;

/// Each channel curve in `set` with its chords across stretches the training samples leave
/// unvisited ([`VISITED_SHARE`]) replaced by the corner where the lines of the stretches on
/// either side meet: the curve keeps the shape the data show on each side up to where they
/// cross, instead of a slope of its own. A transducer saturating at 450 kPa under force
/// tracking, whose training blocks hold the model's P1 up to 437 kPa and then only above
/// 470 kPa, got a chord from 431 to 470 kPa that read the held-out blocks' rise into the
/// saturation 14 noise floors off. Each side's line is the secant over up to two segments
/// (one short segment's slope is noisy). The held-out samples over the stretch and the next
/// one choose between the corner and the chord (the corner when none lie there).
///
/// `quantities` holds the model's reading of each channel in the curve's coordinates, at
/// every sample; `measured`, the recording's (empty for a channel it lacks).
pub fn corners_across_unvisited(
    set: &mut Vec<(&'static str, f64)>,
    quantities: [&[f64]; CHANNELS],
    measured: [&[f64]; CHANNELS],
    blocks: &[Block],
) {
    for channel in [FORCE, P1, P2] {
        let prefix = channel_prefix(channel);
        let get = |set: &[(&'static str, f64)], name: &str| set.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
        let Some(n) = get(set, &format!("{prefix}_knots")) else {
            continue;
        };
        let n = n as usize;
        let (q, m) = (quantities[channel], measured[channel]);
        if n < 4 || q.is_empty() || m.len() != q.len() {
            continue;
        }
        let (Some(x), Some(y)): (Option<Vec<f64>>, Option<Vec<f64>>) = (
            (1..=n).map(|k| get(set, &format!("{prefix}_x_{k}"))).collect(),
            (1..=n).map(|k| get(set, &format!("{prefix}_y_{k}"))).collect(),
        ) else {
            continue;
        };
        let samples = |which: Block| -> Vec<(f64, f64)> {
            (0..q.len())
                .filter(|&k| blocks[k] == which && q[k].is_finite() && m[k].is_finite())
                .map(|k| (q[k], m[k]))
                .collect()
        };
        let (x, y, changed) = cornered(x, y, &samples(Block::Training), &samples(Block::HeldOut));
        if !changed {
            continue;
        }
        for (name, value) in set.iter_mut() {
            for (k, (&xk, &yk)) in x.iter().zip(&y).enumerate() {
                if *name == format!("{prefix}_x_{}", k + 1) {
                    *value = xk;
                } else if *name == format!("{prefix}_y_{}", k + 1) {
                    *value = yk;
                }
            }
        }
    }
}

/// The knots `x`, `y` with every chord across a stretch that `training` (quantity,
/// measured) visits over less than [`VISITED_SHARE`] of its width replaced by its
/// neighbours' corner (the stretch's upper knot moved there), unless `held_out` fits the
/// chord better; and whether any was.
fn cornered(
    mut x: Vec<f64>,
    mut y: Vec<f64>,
    training: &[(f64, f64)],
    held_out: &[(f64, f64)],
) -> (Vec<f64>, Vec<f64>, bool) {
    let mut changed = false;
    let mut j = 1;
    while j + 2 < x.len() {
        let inside: Vec<(f64, f64)> = training
            .iter()
            .copied()
            .filter(|&(q, _)| q >= x[j] && q <= x[j + 1])
            .collect();
        let (lo, hi) = inside
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &(q, _)| {
                (a.min(q), b.max(q))
            });
        let seen = if inside.is_empty() { 0.0 } else { hi - lo };
        if seen >= VISITED_SHARE * (x[j + 1] - x[j]) {
            j += 1;
            continue;
        }
        let back = j.saturating_sub(2);
        let ahead = (j + 3).min(x.len() - 1);
        let left = (y[j] - y[back]) / (x[j] - x[back]);
        let right = (y[ahead] - y[j + 1]) / (x[ahead] - x[j + 1]);
        let corner = (y[j + 1] - y[j] + left * x[j] - right * x[j + 1]) / (left - right);
        if !(corner > x[j] && corner < x[j + 1]) {
            j += 1;
            continue;
        }
        let at_corner = y[j] + left * (corner - x[j]);
        let chord = StaticCurve::through(&x, &y);
        let mut cx = x.clone();
        let mut cy = y.clone();
        cx[j + 1] = corner;
        cy[j + 1] = at_corner;
        let bent = StaticCurve::through(&cx, &cy);
        let (from, to) = (x[j], x[j + 2]);
        let misfit = |c: &StaticCurve| {
            held_out
                .iter()
                .filter(|&&(q, _)| q >= from && q <= to)
                .map(|&(q, m)| (m - c.at(q)).powi(2))
                .sum::<f64>()
        };
        if misfit(&bent) <= misfit(&chord) {
            x = cx;
            y = cy;
            changed = true;
        }
        j += 1;
    }
    (x, y, changed)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reading that follows its quantity to 40 and stays there, fitted with a chord from
    /// (26, 26) to (41.5, 40) because no training sample lies between 27 and 85.
    fn chord_across_a_saturation() -> (Vec<f64>, Vec<f64>, Vec<(f64, f64)>) {
        let x = vec![8.0, 17.0, 26.0, 41.5, 90.0];
        let y = vec![8.0, 17.0, 26.0, 40.0, 40.0];
        let training: Vec<(f64, f64)> = (0..400)
            .map(|k| {
                let q = if k < 200 {
                    8.0 + 19.0 * k as f64 / 199.0
                } else {
                    85.0 + 5.0 * (k - 200) as f64 / 199.0
                };
                (q, q.min(40.0))
            })
            .collect();
        (x, y, training)
    }

    #[test]
    fn a_chord_across_a_stretch_no_training_sample_visits_becomes_its_neighbours_corner_when_the_held_out_samples_agree(
    ) {
        let (x, y, training) = chord_across_a_saturation();
        let held_out: Vec<(f64, f64)> = (0..100)
            .map(|k| 27.0 + 0.2 * k as f64)
            .map(|q| (q, q.min(40.0)))
            .collect();
        let (x2, y2, changed) = cornered(x, y, &training, &held_out);
        assert!(changed);
        let curve = StaticCurve::through(&x2, &y2);
        // The identity up to the corner at 40, flat beyond it.
        for q in [30.0, 35.0, 39.5, 45.0, 60.0] {
            assert!(
                (curve.at(q) - q.min(40.0)).abs() < 0.05,
                "{q}: {} ({x2:?}, {y2:?})",
                curve.at(q)
            );
        }
    }

    #[test]
    fn held_out_samples_that_follow_the_chord_keep_it() {
        let (x, y, training) = chord_across_a_saturation();
        let chord = StaticCurve::through(&x, &y);
        let held_out: Vec<(f64, f64)> = (0..100)
            .map(|k| 27.0 + 0.2 * k as f64)
            .map(|q| (q, chord.at(q)))
            .collect();
        let (x2, y2, changed) = cornered(x.clone(), y.clone(), &training, &held_out);
        assert!(!changed);
        assert_eq!((x2, y2), (x, y));
    }

    #[test]
    fn a_stretch_the_training_samples_cover_keeps_its_chord() {
        let (x, y, _) = chord_across_a_saturation();
        let training: Vec<(f64, f64)> = (0..400)
            .map(|k| 8.0 + 82.0 * k as f64 / 399.0)
            .map(|q| (q, q.min(40.0)))
            .collect();
        let held_out: Vec<(f64, f64)> = (0..100)
            .map(|k| 27.0 + 0.2 * k as f64)
            .map(|q| (q, q.min(40.0)))
            .collect();
        assert!(!cornered(x, y, &training, &held_out).2);
    }

    #[test]
    fn knots_placed_on_a_saturated_reading_put_one_on_its_corner() {
        // A reading that follows its quantity to 85 and stays there; the quantity 0..100.
        let x: Vec<f64> = (0..4000).map(|k| 100.0 * k as f64 / 3999.0).collect();
        let y: Vec<f64> = x.iter().map(|v| v.min(85.0)).collect();
        let knots = placed_knots(&x, &y, &vec![Block::Training; x.len()], SENSOR_KNOTS);
        assert!(
            knots.iter().any(|k| (k - 85.0).abs() < 0.2),
            "no knot at the corner: {knots:?}"
        );
    }
}
