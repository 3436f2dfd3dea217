//! The generated modulation class screened against the residual: for each modulatable
//! constant and each signal of the chain, the constant's sensitivity times a piecewise-linear
//! function of the signal fitted to what the model leaves, the leading pairs kept, and a
//! screened pair turned into a candidate and fitted to first order.

use crate::candidates::interned;
use crate::candidates::modulation::family_of;
use crate::candidates::modulation::free_slots;
use crate::candidates::modulation::hats;
use crate::candidates::modulation::modulatable;
use crate::candidates::modulation::place_of;
use crate::candidates::modulation::sensitivity_step;
use crate::candidates::modulation::slot_parameter;
use crate::candidates::modulation::value_reference;
use crate::candidates::modulation::Follows;
use crate::candidates::parameter_value;
use crate::candidates::unit_of;
use crate::candidates::Candidate;
use crate::candidates::Mechanism;
use crate::candidates::Term;
use crate::fit::normal::Normal;
use crate::fit::oscillation;
use crate::fit::Fit;
use crate::fit::Problem;
use crate::fit::Sensitivity;
use crate::input::blocks::Block;
use crate::input::stopper_motion::stopper_velocity;
use crate::replay::signals::CHANNELS;
use crate::replay::signals::FORCE;
use crate::replay::signals::P1;
use crate::replay::signals::P2;
use crate::replay::Replay;
use jetpipe_model::physics::modulation::{ModulationSignal, MAX_KNOTS, SIGN_VELOCITY};
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::variables::VARIABLES;

/// Knots of the fine fit over a signal, at evenly spaced quantiles of it in the recording
/// (over time: evenly in time); the shape the model carries is simplified from it to at most
/// [`MAX_KNOTS`] of them.
const FINE_KNOTS: usize = 25;

/// The quantiles of the first and last fine knots: a little inside the range, so that a few
/// outlying samples do not stretch the shape.
const END_QUANTILE: f64 = 0.01;

/// The most modulation candidates a round fits through the model.
pub const MOST_CANDIDATES: usize = 4;

/// …of which at most this many modulate the same constant…
const MOST_PER_CONSTANT: usize = 2;

/// …and at most this many follow the same signal. The screen is first order: it reads an
/// increment as acting at once, so a shape that switches faster than the chambers answer
/// (the sign of the stopper's velocity) is under-scored against a smoother one of the
/// same signal family, and only a fit through the model tells them apart; four constants
/// of the current driver and jet pipe on one signal would leave it nothing to compare.
const MOST_PER_SIGNAL: usize = 2;

/// What a round asks the localization to screen: every modulation, with the residual's
/// spectral line if it has one.
#[derive(Clone, Copy, Debug)]
pub struct Screen {
    pub periodic_hz: Option<f64>,
}

/// One constant against one signal, screened.
#[derive(Clone, Debug)]
pub struct Screened {
    pub constant: &'static str,
    pub follows: Follows,
    /// The knots' signal values (for a periodic modulation: −1 and 1 of the sine, then of
    /// the cosine) and the first-order increments of the constant there.
    pub knots: Vec<f64>,
    pub increments: Vec<f64>,
    /// Held-out weighted sum of squares after, plus the penalty of its knots.
    pub penalised: f64,
}

/// The signal's value at every sample, from the recording and the current model's replay.
pub(crate) fn signal_values(signal: ModulationSignal, problem: &Problem, replay: &Replay) -> Vec<f64> {
    let recording = problem.recording;
    match signal {
        ModulationSignal::Time => recording.time.clone(),
        ModulationSignal::Command => recording.v_da.clone(),
        ModulationSignal::Current => replay.current.clone(),
        ModulationSignal::JetPosition => replay.x_jp.clone(),
        ModulationSignal::StopperPosition => recording.x_s.clone(),
        ModulationSignal::StopperVelocity => stopper_velocity(recording),
        ModulationSignal::StopperVelocitySign => stopper_velocity(recording)
            .iter()
            .map(|v| (v / SIGN_VELOCITY).tanh())
            .collect(),
        ModulationSignal::Force => replay.force.clone(),
        ModulationSignal::P1 => replay.p1.clone(),
        ModulationSignal::P2 => replay.p2.clone(),
        ModulationSignal::PressureDifference => replay.p1.iter().zip(&replay.p2).map(|(a, b)| a - b).collect(),
        ModulationSignal::None | ModulationSignal::Sine | ModulationSignal::Cosine => vec![],
    }
}

/// Knots at the quantiles of the signal over the fitted samples, strictly increasing
/// (fewer where the signal takes few values); `None` when it hardly moves.
fn knots_of(values: &[f64], blocks: &[Block], signal: ModulationSignal) -> Option<Vec<f64>> {
    if signal == ModulationSignal::StopperVelocitySign {
        return Some(vec![-1.0, 1.0]);
    }
    if signal == ModulationSignal::Time {
        // Evenly in time: a slow wander has no quantiles to follow.
        let first = values.iter().zip(blocks).find(|(_, b)| b.is_used())?.0;
        let last = values.last()?;
        let knots: Vec<f64> = (0..FINE_KNOTS)
            .map(|j| first + (last - first) * j as f64 / (FINE_KNOTS - 1) as f64)
            .collect();
        return (last > first).then_some(knots);
    }
    let mut kept: Vec<f64> = values
        .iter()
        .zip(blocks)
        .filter(|(v, b)| b.is_used() && v.is_finite())
        .map(|(v, _)| *v)
        .collect();
    if kept.len() < 10 {
        return None;
    }
    kept.sort_by(|a, b| a.total_cmp(b));
    let at = |q: f64| kept[((kept.len() - 1) as f64 * q).round() as usize];
    let span = at(1.0 - END_QUANTILE) - at(END_QUANTILE);
    if span.is_nan() || span <= 1e-12 * at(0.5).abs().max(1e-300) {
        return None;
    }
    let mut knots: Vec<f64> = vec![];
    for j in 0..FINE_KNOTS {
        let q = END_QUANTILE + (1.0 - 2.0 * END_QUANTILE) * j as f64 / (FINE_KNOTS - 1) as f64;
        let x = at(q);
        if knots.last().map_or(true, |&last| x > last + 1e-3 * span) {
            knots.push(x);
        }
    }
    (knots.len() >= 2).then_some(knots)
}

/// The knots (indices into the fine `x`) of the simplest polylines through the fine fit
/// (`x`, `y`), with 2 to [`MAX_KNOTS`] knots: the ends, then one by one the fine knot that
/// departs most from the polyline so far.
fn simplified(x: &[f64], y: &[f64]) -> Vec<Vec<usize>> {
    let last = x.len() - 1;
    let mut chosen = vec![0, last];
    let mut shapes = vec![chosen.clone()];
    while chosen.len() < MAX_KNOTS.min(x.len()) {
        let xs: Vec<f64> = chosen.iter().map(|&i| x[i]).collect();
        let mut phi = vec![0.0; chosen.len()];
        let worst = (0..x.len())
            .filter(|i| !chosen.contains(i))
            .map(|i| {
                hats(&xs, x[i], &mut phi);
                let at: f64 = phi.iter().zip(&chosen).map(|(p, &j)| p * y[j]).sum();
                (i, (y[i] - at).abs())
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        let Some((i, _)) = worst else {
            break;
        };
        chosen.push(i);
        chosen.sort_unstable();
        shapes.push(chosen.clone());
    }
    shapes
}

/// The weighted residual of each measured channel against `replay`.
pub(crate) fn residuals(problem: &Problem, replay: &Replay) -> [Vec<f64>; CHANNELS] {
    let modelled = [&replay.force, &replay.p1, &replay.p2];
    let mut out: [Vec<f64>; CHANNELS] = [vec![], vec![], vec![]];
    for c in 0..CHANNELS {
        let w = problem.weights[c];
        if w > 0.0 {
            out[c] = problem.measured[c]
                .iter()
                .zip(modelled[c])
                .map(|(m, y)| w * (m - y))
                .collect();
        }
    }
    out
}

/// Screen one constant against one signal: the best of a constant shift, a straight line
/// between the end knots and the full shape, with `penalty` per knot; `None` when the
/// constant shift is best (a plain constant, which other candidates fit).
fn screen_pair(
    problem: &Problem,
    residual: &[Vec<f64>; CHANNELS],
    sensitivity: &Sensitivity,
    values: &[f64],
    knots: &[f64],
    penalty: f64,
) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let size = knots.len();
    let mut normal = Normal::new(size);
    let mut phi = vec![0.0; size];
    let mut row = vec![0.0; size];
    for (k, &block) in problem.blocks.iter().enumerate() {
        if !block.is_used() {
            continue;
        }
        hats(knots, values[k], &mut phi);
        for c in 0..CHANNELS {
            if residual[c].is_empty() || sensitivity[c].is_empty() {
                continue;
            }
            let s = problem.weights[c] * f64::from(sensitivity[c][k]);
            for j in 0..size {
                row[j] = s * phi[j];
            }
            normal.add(block, &row, residual[c][k]);
        }
    }
    let constant: Vec<Vec<f64>> = (0..size).map(|_| vec![1.0]).collect();
    let (_, constant_ss) = normal.solve_in(&constant)?;
    let full: Vec<Vec<f64>> = (0..size)
        .map(|i| (0..size).map(|j| if i == j { 1.0 } else { 0.0 }).collect())
        .collect();
    let (fine, _) = normal.solve_in(&full)?;
    let mut best: Option<(Vec<f64>, Vec<f64>, f64)> = None;
    for shape in simplified(knots, &fine) {
        // The coarse hats on the fine knots: a polyline over a subset of the knots is one over
        // all of them.
        let coarse: Vec<f64> = shape.iter().map(|&i| knots[i]).collect();
        let mut phi = vec![0.0; coarse.len()];
        let map: Vec<Vec<f64>> = knots
            .iter()
            .map(|&x| {
                hats(&coarse, x, &mut phi);
                phi.clone()
            })
            .collect();
        let Some((y, ss)) = normal.solve_in(&map) else {
            continue;
        };
        let scored = ss + penalty * coarse.len() as f64;
        if scored < constant_ss + penalty && best.as_ref().map_or(true, |b| scored < b.2) {
            best = Some((coarse, y, scored));
        }
    }
    best
}

/// Screen every modulatable constant whose sensitivity `shared` holds against every signal
/// (and the spectral line `periodic_hz`), best first, at most [`MOST_CANDIDATES`].
/// A sinusoid is screened on the model's answers to it (two replays a constant and a line),
/// counted in the second value returned.
pub fn screen(
    problem: &Problem,
    replay: &Replay,
    shared: &dyn Fn(&'static str) -> Option<Sensitivity>,
    catalogue: &[Candidate],
    periodic_hz: Option<f64>,
    penalty: f64,
    jobs: usize,
) -> (Vec<Screened>, usize) {
    let residual = residuals(problem, replay);
    let periodic_hz = periodic_hz.filter(|hz| !oscillation::carried_by_inputs(problem, *hz));
    let mut signals: Vec<(ModulationSignal, Vec<f64>, Vec<f64>)> = vec![];
    for signal in ModulationSignal::ALL {
        if matches!(
            signal,
            ModulationSignal::None | ModulationSignal::Sine | ModulationSignal::Cosine
        ) {
            continue;
        }
        let values = signal_values(signal, problem, replay);
        if let Some(knots) = knots_of(&values, problem.blocks, signal) {
            signals.push((signal, values, knots));
        }
    }
    let constants: Vec<(&'static str, Sensitivity)> = modulatable()
        .into_iter()
        .filter_map(|name| shared(name).map(|s| (name, s)))
        .collect();
    // Each constant's own line: the spectral peak of its increment traced window by window
    // (a sinusoid that modulates a constant shows in the residual at the sum and difference
    // of its frequency with the signals', and in the trace at its own).
    let lines: Vec<Option<f64>> = crate::parallel::parallel_map(&constants, jobs, |(_, sensitivity)| {
        oscillation::traced_line(problem, &residual, sensitivity)
    });
    let answered = std::sync::atomic::AtomicUsize::new(0);
    let pairs: Vec<(usize, usize)> = (0..constants.len())
        .flat_map(|c| (0..signals.len() + 2).map(move |s| (c, s)))
        .collect();
    let screened: Vec<Option<Screened>> = crate::parallel::parallel_map(&pairs, jobs, |&(c, s)| {
        let (constant, sensitivity) = &constants[c];
        if s >= signals.len() {
            let hz = if s == signals.len() { periodic_hz? } else { lines[c]? };
            let step = sensitivity_step(constant, problem.base, catalogue);
            let answers = oscillation::responses(problem, replay, constant, step, hz)?;
            answered.fetch_add(2, std::sync::atomic::Ordering::Relaxed);
            return oscillation::screen_periodic(problem, &residual, sensitivity, &answers, penalty).map(
                |(knots, y, scored)| Screened {
                    constant,
                    follows: Follows::Periodic(hz),
                    knots,
                    increments: y,
                    penalised: scored,
                },
            );
        }
        let (signal, values, knots) = &signals[s];
        screen_pair(problem, &residual, sensitivity, values, knots, penalty).map(|(knots, y, scored)| Screened {
            constant,
            follows: Follows::Signal(*signal),
            knots,
            increments: y,
            penalised: scored,
        })
    });
    (leading(screened.into_iter().flatten().collect()), answered.into_inner())
}

/// The best screened pairs, at most [`MOST_CANDIDATES`], [`MOST_PER_CONSTANT`] of a constant
/// and [`MOST_PER_SIGNAL`] of a signal, and one of each constant against each signal.
fn leading(mut all: Vec<Screened>) -> Vec<Screened> {
    all.sort_by(|a, b| a.penalised.total_cmp(&b.penalised));
    let mut kept: Vec<Screened> = vec![];
    for s in all {
        if kept.len() >= MOST_CANDIDATES {
            break;
        }
        let same_constant = kept.iter().filter(|k| k.constant == s.constant).count();
        let same_signal = kept.iter().filter(|k| k.follows.kind() == s.follows.kind()).count();
        // The residual's spectral line and a constant's own traced line are often one line
        // read twice: a second sinusoid of the same constant would take the place of another
        // constant's.
        let repeated = kept
            .iter()
            .any(|k| k.constant == s.constant && k.follows.kind() == s.follows.kind());
        if same_constant < MOST_PER_CONSTANT && same_signal < MOST_PER_SIGNAL && !repeated {
            kept.push(s);
        }
    }
    kept
}

/// A screened modulation as a candidate whose knot values are model parameters, in the
/// free slots of `params`; `None` without a free slot.
pub fn candidate(s: &Screened, params: &Parameters, catalogue: &[Candidate]) -> Option<Candidate> {
    if !VARIABLES.iter().any(|v| v.name == "modulation_1_parameter") {
        return None;
    }
    let free = free_slots(params);
    let location = place_of(s.constant);
    let family = family_of(s.constant, location, s.follows);
    let nominal = parameter_value(params, s.constant);
    let (lower, upper) = crate::candidates::declared_bounds(s.constant);
    let scale = sensitivity_step(s.constant, params, catalogue);
    let term = |slot: usize, j: usize| Term {
        name: slot_parameter(slot, &format!("y_{j}")),
        unit: unit_of(s.constant),
        mechanism: Mechanism::Parameter(slot_parameter(slot, &format!("y_{j}"))),
        neutral: 0.0,
        step: scale,
        lower: lower - nominal,
        upper: upper - nominal,
    };
    let mut settings: Vec<(&'static str, f64)> = vec![];
    let mut terms = vec![];
    let slots: Vec<(usize, ModulationSignal, f64, &[f64])> = match s.follows {
        Follows::Signal(signal) => vec![(*free.first()?, signal, 0.0, &s.knots[..])],
        Follows::Periodic(hz) => {
            if free.len() < 2 {
                return None;
            }
            vec![
                (free[0], ModulationSignal::Sine, hz, &s.knots[..2]),
                (free[1], ModulationSignal::Cosine, hz, &s.knots[2..]),
            ]
        }
    };
    for (slot, signal, hz, knots) in slots {
        settings.push((slot_parameter(slot, "parameter"), value_reference(s.constant)));
        settings.push((slot_parameter(slot, "signal"), f64::from(signal.code())));
        settings.push((slot_parameter(slot, "frequency"), hz));
        settings.push((slot_parameter(slot, "knots"), knots.len() as f64));
        for (j, &x) in knots.iter().enumerate() {
            settings.push((slot_parameter(slot, &format!("x_{}", j + 1)), x));
            terms.push(term(slot, j + 1));
        }
    }
    let what = s.follows.to_string();
    Some(Candidate {
        label: interned(format!("{} varying with {what}", s.constant)),
        location,
        family,
        named: None,
        terms,
        settings,
    })
}

/// The first-order fit of a screened modulation as a candidate's [`Fit`]: its values, its
/// prediction and its errors, for the ranking with the other candidates.
pub fn first_order_fit(
    problem: &Problem,
    replay: &Replay,
    screened: &Screened,
    candidate: Candidate,
    sensitivity: &Sensitivity,
) -> Fit {
    let mut prediction = [replay.force.clone(), replay.p1.clone(), replay.p2.clone()];
    let n = problem.recording.len();
    // Within the constant's declared limits at every knot (a friction cannot go negative).
    let values: Vec<f64> = screened
        .increments
        .iter()
        .zip(&candidate.terms)
        .map(|(y, t)| y.clamp(t.lower, t.upper))
        .collect();
    let mut replays = 0;
    match screened.follows {
        Follows::Signal(signal) => {
            let signal_at = signal_values(signal, problem, replay);
            let mut phi = vec![0.0; screened.knots.len()];
            let increments: Vec<f64> = (0..n)
                .map(|k| {
                    hats(&screened.knots, signal_at[k], &mut phi);
                    phi.iter().zip(&values).map(|(p, y)| p * y).sum()
                })
                .collect();
            for c in [FORCE, P1, P2] {
                if sensitivity[c].is_empty() || prediction[c].is_empty() {
                    continue;
                }
                for k in 0..n {
                    prediction[c][k] += f64::from(sensitivity[c][k]) * increments[k];
                }
            }
        }
        // The model's answers, as the screen read them, replayed again: the screen keeps no
        // answers, whose series for every constant would be the diagnosis's peak of memory.
        // Without them (no replay), no claim.
        Follows::Periodic(hz) => {
            let step = candidate.terms[0].step;
            if let Some(answers) = oscillation::responses(problem, replay, screened.constant, step, hz) {
                replays = 2;
                for c in [FORCE, P1, P2] {
                    if answers[0][c].is_empty() || prediction[c].is_empty() {
                        continue;
                    }
                    for k in 0..n {
                        prediction[c][k] +=
                            values[0] * f64::from(answers[0][c][k]) + values[1] * f64::from(answers[1][c][k]);
                    }
                }
            }
        }
    }
    let (train, heldout) = problem.errors(&prediction);
    // The slots' knot values: for a periodic modulation, ∓ the amplitude at −1 and +1.
    let fitted = match screened.follows {
        Follows::Signal(_) => values,
        Follows::Periodic(_) => vec![-values[0], values[0], -values[1], values[1]],
    };
    Fit {
        candidate,
        values: fitted,
        prediction,
        train,
        heldout,
        replays,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_residual_that_is_a_sensitivity_times_a_band_of_a_signal_is_screened_as_that_band() {
        let (recording, blocks, sensitivity, x_s) = banded();
        let base = Parameters::default();
        let problem = Problem::new(&recording, &base, &blocks, [0.05, 0.0, 0.0]);
        let residual = residuals(&problem, &silent_replay(recording.len()));
        let knots = knots_of(&x_s, &blocks, ModulationSignal::StopperPosition).unwrap();
        let (xs, ys, _) =
            screen_pair(&problem, &residual, &sensitivity, &x_s, &knots, 10.0).expect("a band beats a constant");
        assert!(xs.len() <= MAX_KNOTS && xs.len() >= 3, "{xs:?}");
        let mut phi = vec![0.0; xs.len()];
        for (x, want) in [(0.055, 0.0), (0.0595, 0.0), (0.064, 2.0), (0.067, 2.0), (0.0615, 1.0)] {
            hats(&xs, x, &mut phi);
            let got: f64 = phi.iter().zip(&ys).map(|(p, y)| p * y).sum();
            assert!(
                (got - want).abs() < 0.15,
                "at {x} m: {got}, the band's {want} ({xs:?}, {ys:?})"
            );
        }
        // Against time the same residual is no band: a constant does as well, or a shape of
        // time leaves far more than the band does.
        let (_, _, band_score) = screen_pair(&problem, &residual, &sensitivity, &x_s, &knots, 10.0).unwrap();
        let time_knots = knots_of(&recording.time, &blocks, ModulationSignal::Time).unwrap();
        if let Some((_, _, time_score)) =
            screen_pair(&problem, &residual, &sensitivity, &recording.time, &time_knots, 10.0)
        {
            assert!(
                time_score > 10.0 * band_score,
                "time {time_score} against the band's {band_score}"
            );
        }
    }

    #[test]
    fn the_leading_modulations_follow_more_than_one_signal_though_one_signal_screens_best_for_every_constant() {
        let pair = |constant: &'static str, signal: ModulationSignal, penalised: f64| Screened {
            constant,
            follows: Follows::Signal(signal),
            knots: vec![-1.0, 1.0],
            increments: vec![0.0, 0.0],
            penalised,
        };
        let velocity = ModulationSignal::StopperVelocity;
        let sign = ModulationSignal::StopperVelocitySign;
        let all = vec![
            pair("k_m", velocity, 3.0),
            pair("i_offset", velocity, 1.0),
            pair("k_cd", velocity, 2.0),
            pair("F_jp_sat", velocity, 4.0),
            pair("i_offset", sign, 5.0),
            pair("k_cd", sign, 6.0),
            pair("i_offset", ModulationSignal::Force, 7.0),
        ];
        let sinusoid = |constant: &'static str, hz: f64, penalised: f64| Screened {
            follows: Follows::Periodic(hz),
            ..pair(constant, velocity, penalised)
        };
        let kept: Vec<(&str, Follows)> = leading(all).iter().map(|s| (s.constant, s.follows)).collect();
        assert_eq!(
            kept,
            vec![
                ("i_offset", Follows::Signal(velocity)),
                ("k_cd", Follows::Signal(velocity)),
                ("i_offset", Follows::Signal(sign)),
                ("k_cd", Follows::Signal(sign)),
            ]
        );
        // One line read twice (from the residual and from the constant's trace) is one
        // candidate.
        let lines = vec![
            sinusoid("x_jp_sat", 9.060, 1.0),
            sinusoid("x_jp_sat", 9.061, 1.1),
            sinusoid("k_m", 9.060, 2.0),
            pair("force_sensor_offset", ModulationSignal::Force, 3.0),
        ];
        let kept: Vec<(&str, Follows)> = leading(lines).iter().map(|s| (s.constant, s.follows)).collect();
        assert_eq!(
            kept,
            vec![
                ("x_jp_sat", Follows::Periodic(9.060)),
                ("k_m", Follows::Periodic(9.060)),
                ("force_sensor_offset", Follows::Signal(ModulationSignal::Force)),
            ]
        );
    }

    #[test]
    fn the_simplest_polylines_add_the_knot_that_departs_most() {
        let x: Vec<f64> = (0..9).map(f64::from).collect();
        let y = [0.0, 0.0, 0.0, 0.0, 3.0, 3.0, 3.0, 3.0, 3.0];
        let shapes = simplified(&x, &y);
        assert_eq!(shapes[0], vec![0, 8]);
        // The step's corners come next: at 3 (the line through the ends passes 1.125 there) or 4.
        assert!(shapes[2].contains(&3) && shapes[2].contains(&4), "{shapes:?}");
        // From two knots to every fine one.
        assert_eq!(shapes.len(), MAX_KNOTS.min(x.len()) - 1);
    }

    #[test]
    fn a_constant_wandering_in_time_through_seven_turns_is_screened_with_all_seven() {
        // The banded recording's sensitivity times a wander of ±1 with seven turns over
        // its 20 s: a polyline needs a knot at each turn and the ends, nine in all.
        let (mut recording, blocks, sensitivity, x_s) = banded();
        let band = |x: f64| (2.0 * (x - 0.060) / 0.003).clamp(0.0, 2.0);
        let wander: Vec<f64> = recording
            .time
            .iter()
            .map(|t| (2.0 * std::f64::consts::PI * 3.5 * t / 20.0).sin())
            .collect();
        // The band taken out again and the wander put in, the noise kept.
        for (k, f) in recording.force.iter_mut().enumerate() {
            *f += f64::from(sensitivity[FORCE][k]) * (wander[k] - band(x_s[k]));
        }
        let base = Parameters::default();
        let problem = Problem::new(&recording, &base, &blocks, [0.05, 0.0, 0.0]);
        let residual = residuals(&problem, &silent_replay(recording.len()));
        let knots = knots_of(&recording.time, &blocks, ModulationSignal::Time).unwrap();
        let (xs, ys, _) = screen_pair(&problem, &residual, &sensitivity, &recording.time, &knots, 10.0)
            .expect("a wander beats a constant");
        let mut phi = vec![0.0; xs.len()];
        let misfit: f64 = recording
            .time
            .iter()
            .zip(&wander)
            .map(|(&t, w)| {
                hats(&xs, t, &mut phi);
                let got: f64 = phi.iter().zip(&ys).map(|(p, y)| p * y).sum();
                (got - w).powi(2)
            })
            .sum::<f64>()
            / wander.len() as f64;
        // Straight between the fine knots nearest its turns, the shape departs from the sine
        // by about a sixth of its swing; with six knots, four turns at most, by half of it.
        let turns = ys.windows(3).filter(|w| (w[1] - w[0]) * (w[2] - w[1]) < 0.0).count();
        assert_eq!(turns, 7, "{xs:?} {ys:?}");
        assert!(
            misfit.sqrt() < 0.2,
            "the shape departs from the wander by {} RMS over {} knots ({xs:?})",
            misfit.sqrt(),
            xs.len()
        );
    }

    /// A recording whose force residual is a sensitivity times a band of the stopper's
    /// position (0 below 60 mm, 2 above 63 mm, linear between), with noise.
    /// A replay whose every signal is zero: the residual is the recording itself.
    fn silent_replay(n: usize) -> Replay {
        let zero = vec![0.0; n];
        Replay {
            force: zero.clone(),
            p1: zero.clone(),
            p2: zero.clone(),
            current: zero.clone(),
            x_jp: zero,
            steps: 0,
        }
    }

    fn banded() -> (crate::input::recording::Recording, Vec<Block>, Sensitivity, Vec<f64>) {
        let n = 20_000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let x_s: Vec<f64> = time
            .iter()
            .map(|t| 0.06 + 0.008 * (2.0 * std::f64::consts::PI * 0.3 * t).sin())
            .collect();
        let sensitivity_force: Vec<f32> = time.iter().map(|t| (1.0 + 0.5 * (7.0 * t).sin()) as f32).collect();
        let band = |x: f64| (2.0 * (x - 0.060) / 0.003).clamp(0.0, 2.0);
        // A deterministic noise of 0.05 N RMS.
        let mut state = 12345u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.05 * 12f64.sqrt()
        };
        let force: Vec<f64> = (0..n)
            .map(|k| f64::from(sensitivity_force[k]) * band(x_s[k]) + noise())
            .collect();
        let recording = crate::input::recording::Recording {
            fast_replay: crate::input::recording::FastReplayMethod {
                step: 1e-3,
                third_order: false,
            },
            ..crate::input::recording::Recording::of(time, vec![0.0; n], x_s.clone(), force)
        };
        let blocks = Block::alternating(n, 2000);
        (
            recording,
            blocks,
            std::sync::Arc::new([sensitivity_force, vec![], vec![]]),
            x_s,
        )
    }
}
