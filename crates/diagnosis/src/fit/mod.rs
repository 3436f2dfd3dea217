//! Fitting a candidate: bounded Gauss–Newton on the training blocks through the model's
//! sensitivities, searches (`search.rs`) for the terms with none, held-out scores.

pub mod calibrate;
pub(crate) mod flexible_screen;
pub mod intervals;
pub(crate) mod localize;
pub(crate) mod normal;
pub(crate) mod oscillation;
pub(crate) mod refit;
pub mod scored;
pub(crate) mod screen;
pub(crate) mod search;
mod searched;

use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::candidates::Filter;
use crate::candidates::Mechanism;
use crate::candidates::Modulation;
use crate::candidates::Regressor;
use crate::candidates::Term;
use crate::fit::search::search_from_grid;
use crate::input::blocks::Block;
use crate::input::recording::Recording;
use crate::input::stopper_motion::stopper_acceleration;
use crate::input::stopper_motion::stopper_velocity;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// The precision of a searched term, in golden-section steps: its bracket shrinks to
/// 0.618^16 = 5e-4 of its range (a thousandth of a decade over three), or, for the first
/// pass's ranking, to 0.618^10 = 8e-3 (6 % in value over three decades; a limit's range is
/// linear, 0.8 % of it). The leaders' refinement and a discovered term's trial search to the
/// finer bracket.
const GOLDEN_STEPS: usize = 16;
const COARSE_GOLDEN_STEPS: usize = 10;
/// The first pass's steps of the outer search of two nested ones (a friction's second speed
/// scale, a second-order filter's damping): 0.618^7 = 3 % of the range, as each of its
/// points costs a whole inner search.
const FIRST_PASS_OUTER_STEPS: usize = 7;
/// Points of the grid a search starts from (Brent's search then runs between the best
/// point's neighbours): the first pass's ranking and the shape searches, then the leaders'
/// refinement.
const COARSE_GRID: usize = 5;
const FINE_GRID: usize = 9;
/// Steps along a Gauss–Newton direction tried on the true model, each half the last.
const LINE_SEARCH_STEPS: usize = 4;
/// The dampings λ a damped fit tries, in turn, when no step along the Gauss–Newton
/// direction lowers the misfit.
const MARQUARDT_DAMPINGS: [f64; 4] = [0.01, 0.1, 1.0, 100.0];

/// The fixed part of a fitting problem: the recording, the base model, the blocks and
/// the channels' weights.
pub struct Problem<'a> {
    pub recording: &'a Recording,
    pub base: &'a Parameters,
    /// Which samples are fitted and which held out.
    pub blocks: &'a [Block],
    /// 1/noise floor of each channel (0 for a channel the recording lacks).
    pub weights: [f64; CHANNELS],
    pub measured: [&'a [f64]; CHANNELS],
    velocity: Vec<f64>,
    /// The stopper acceleration as the model forms it.
    acceleration: Vec<f64>,
    /// The stopper's mean position, where the position regressor vanishes.
    pub mean_position: f64,
    /// The middle and the span of the recording's time, for the ramp regressor.
    pub t_mid: f64,
    pub t_span: f64,
    /// Threads for the finite-difference replays of one Gauss–Newton step (1 while the
    /// candidates themselves are spread over the threads).
    pub jobs: std::sync::atomic::AtomicUsize,
}

impl<'a> Problem<'a> {
    pub fn new(recording: &'a Recording, base: &'a Parameters, blocks: &'a [Block], noise: [f64; CHANNELS]) -> Self {
        let empty: &[f64] = &[];
        let measured = [
            recording.force.as_slice(),
            recording.p1.as_deref().unwrap_or(empty),
            recording.p2.as_deref().unwrap_or(empty),
        ];
        let mut weights = [0.0; CHANNELS];
        for c in 0..CHANNELS {
            if !measured[c].is_empty() && noise[c] > 0.0 {
                weights[c] = 1.0 / noise[c];
            }
        }
        let n = recording.len();
        let (t0, t1) = (recording.time[0], recording.time[n - 1]);
        Self {
            recording,
            base,
            blocks,
            weights,
            measured,
            velocity: stopper_velocity(recording),
            acceleration: stopper_acceleration(recording),
            mean_position: recording.x_s.iter().sum::<f64>() / n as f64,
            t_mid: 0.5 * (t0 + t1),
            t_span: (t1 - t0).max(1e-9),
            jobs: std::sync::atomic::AtomicUsize::new(1),
        }
    }

    /// Spread each Gauss–Newton step's finite-difference replays over `jobs` threads.
    pub fn set_jobs(&self, jobs: usize) {
        self.jobs.store(jobs.max(1), std::sync::atomic::Ordering::Relaxed);
    }

    /// Model outputs with the nonlinear terms at `values` (linear terms are added by
    /// [`Self::predict`]).
    fn replay(&self, candidate: &Candidate, values: &[f64]) -> Result<Replay, String> {
        let mut p = self.base.clone();
        for &(name, value) in &candidate.settings {
            set_parameter(&mut p, name, value)?;
        }
        for (term, &value) in candidate.terms.iter().zip(values) {
            if let Some(name) = term.mechanism.model_parameter() {
                set_parameter(&mut p, name, term.mechanism.model_value(value))?;
            }
        }
        replay_fast(&Actuator::new(p)?, self.recording, self.recording.len())
    }

    fn regressor(&self, regressor: Regressor, r: &Replay, own: &[f64], floor: &[bool], k: usize) -> f64 {
        let t = self.recording.time[k];
        let v = self.velocity[k];
        let set_by_pressures = !floor[k];
        match regressor {
            Regressor::One => 1.0,
            Regressor::Own => own[k],
            Regressor::OwnSquared => own[k] * own[k],
            Regressor::OwnCubed => own[k] * own[k] * own[k],
            Regressor::Friction if set_by_pressures && v.abs() > 1e-9 => -v.signum(),
            Regressor::SmoothFriction(vc) if set_by_pressures => {
                -jetpipe_model::physics::effects::friction_force(1.0, vc, 0.0, 0.0, v)
            }
            Regressor::Stribeck(vc, vs) if set_by_pressures => {
                -jetpipe_model::physics::effects::friction_force(0.0, vc, 1.0, vs, v)
            }
            Regressor::Viscous if set_by_pressures => -v,
            Regressor::Position if set_by_pressures => -(self.recording.x_s[k] - self.mean_position),
            Regressor::Acceleration if set_by_pressures => self.acceleration[k],
            Regressor::VelocitySquared if set_by_pressures => v * v.abs(),
            Regressor::SignPressure(ve) if set_by_pressures => {
                let p = self.base;
                let ve = if ve > 0.0 { ve } else { p.extra_force_sign_velocity };
                jetpipe_model::physics::extra_force::signals(v, ve, r.p1[k], r.p2[k], p.p_r)[1]
            }
            Regressor::Product { first, second, origin } if set_by_pressures => {
                use jetpipe_model::physics::extra_force::{MechanicsSignals, ProductSlot};
                let slot = ProductSlot {
                    first: f64::from(first.code()),
                    second: f64::from(second.code()),
                    origin,
                    coefficient: 1.0,
                };
                slot.regressor(&MechanicsSignals {
                    x_s: self.recording.x_s[k],
                    velocity: v,
                    acceleration: self.acceleration[k],
                    sign_velocity: self.base.extra_force_sign_velocity,
                    p1: r.p1[k],
                    p2: r.p2[k],
                    p_r: self.base.p_r,
                })
            }
            Regressor::Friction
            | Regressor::Product { .. }
            | Regressor::SmoothFriction(_)
            | Regressor::Stribeck(..)
            | Regressor::Viscous
            | Regressor::Position
            | Regressor::Acceleration
            | Regressor::VelocitySquared
            | Regressor::SignPressure(_) => 0.0,
            Regressor::Ramp => (t - self.t_mid) / self.t_span,
            Regressor::Sine(f) => (2.0 * std::f64::consts::PI * f * t).sin(),
            Regressor::Cosine(f) => (2.0 * std::f64::consts::PI * f * t).cos(),
            Regressor::Segment { lo, hi, below, above } => {
                crate::candidates::curves::segment(own[k], lo, hi, below, above)
            }
        }
    }
}

fn modulation_at(m: Modulation, t: f64, t_mid: f64, t_span: f64) -> f64 {
    match m {
        Modulation::Ramp => (t - t_mid) / t_span,
        Modulation::Sine(f) => (2.0 * std::f64::consts::PI * f * t).sin(),
        Modulation::Cosine(f) => (2.0 * std::f64::consts::PI * f * t).cos(),
    }
}

/// A candidate fitted: its values, what it predicts, and its errors.
#[derive(Clone, Debug)]
pub struct Fit {
    pub candidate: Candidate,
    pub values: Vec<f64>,
    pub prediction: [Vec<f64>; CHANNELS],
    /// Weighted sums of squares per channel on the training and held-out samples.
    pub train: [f64; CHANNELS],
    pub heldout: [f64; CHANNELS],
    pub replays: usize,
}

impl Fit {
    /// The fit without its predicted series, for a caller that keeps only its values and
    /// misfits (a pair among fifty held at once: 2.4 MB each at 100,000 rows).
    pub fn without_prediction(mut self) -> Fit {
        self.prediction = [Vec::new(), Vec::new(), Vec::new()];
        self
    }

    pub fn train_total(&self) -> f64 {
        self.train.iter().sum()
    }
    pub fn heldout_total(&self) -> f64 {
        self.heldout.iter().sum()
    }
}

/// Sensitivities of the model's outputs to the nonlinear terms, shared by candidates that
/// start from the same point. Single precision: a finite difference of two replays carries
/// the integrator's relative error (1e-6 and more) in its lowest digits, so 24 bits lose
/// nothing a Gauss–Newton step can use, and the thirty-odd shared columns of a long
/// recording take half the memory (72 MB in double precision at 100,000 rows). Shared, not
/// copied: the screen and the fits read the same columns (copies of the shared ones were
/// 41 MB of a 600 s recording's peak).
pub type Sensitivity = std::sync::Arc<[Vec<f32>; CHANNELS]>;

/// A column of a [`Sensitivity`] from one in double precision.
fn single(column: Vec<f64>) -> Vec<f32> {
    column.into_iter().map(|v| v as f32).collect()
}

/// A column of a [`Sensitivity`] by finite difference: (`moved` − `at`) / `step`.
fn divided_difference(moved: &[f64], at: &[f64], step: f64) -> Vec<f32> {
    moved.iter().zip(at).map(|(x, y)| ((x - y) / step) as f32).collect()
}

/// Everything needed at one point of a candidate's terms.
struct Point<'r> {
    values: Vec<f64>,
    /// Shared, not copied, between the points of a fit that differ only in linear terms, and
    /// the base replay borrowed: every candidate of the first pass starts from it.
    replay: std::sync::Arc<std::borrow::Cow<'r, Replay>>,
}

impl Problem<'_> {
    /// Predictions of the measured channels for a candidate at `values`, from a replay at
    /// those values and the sensitivities of modulated parameters.
    fn predict(&self, terms: &[Term], point: &Point, sensitivities: &[Option<Sensitivity>]) -> [Vec<f64>; CHANNELS] {
        self.predict_at(terms, &point.values, &point.replay, sensitivities)
    }

    /// [`Problem::predict`] at `values` from `replay`, a replay at the values of the nonlinear
    /// terms.
    fn predict_at(
        &self,
        terms: &[Term],
        values: &[f64],
        r: &Replay,
        sensitivities: &[Option<Sensitivity>],
    ) -> [Vec<f64>; CHANNELS] {
        let mut out = [r.force.clone(), r.p1.clone(), r.p2.clone()];
        let n = self.recording.len();
        let mut floor: Option<Vec<bool>> = None;
        for (j, (term, &value)) in terms.iter().zip(values).enumerate() {
            if value == 0.0 {
                continue;
            }
            match term.mechanism {
                Mechanism::Output { channel, regressor } => {
                    let own = [&r.force, &r.p1, &r.p2][channel];
                    let floor = floor.get_or_insert_with(|| self.floor(r));
                    for k in 0..n {
                        out[channel][k] += value * self.regressor(regressor, r, own, floor, k);
                    }
                }
                Mechanism::Modulated { modulation, .. } => {
                    if let Some(s) = &sensitivities[j] {
                        for c in 0..CHANNELS {
                            if s[c].is_empty() {
                                continue;
                            }
                            for k in 0..n {
                                let m = modulation_at(modulation, self.recording.time[k], self.t_mid, self.t_span);
                                out[c][k] += value * f64::from(s[c][k]) * m;
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        out
    }

    /// A regressor's column over the recording, with the replay `r` (for the tests).
    #[cfg(test)]
    pub(crate) fn column(&self, regressor: Regressor, r: &Replay) -> Vec<f64> {
        let floor = self.floor(r);
        (0..self.recording.len())
            .map(|k| self.regressor(regressor, r, &r.force, &floor, k))
            .collect()
    }

    /// Samples where the spring floor, not the pressures, sets the modelled force.
    fn floor(&self, r: &Replay) -> Vec<bool> {
        let p = &self.base;
        let area = std::f64::consts::PI * p.d_cyl * p.d_cyl / 4.0;
        (0..self.recording.len())
            .map(|k| {
                let spring = jetpipe_model::physics::piston::spring_force(
                    p.k_spring,
                    p.l_spring0,
                    p.l_s,
                    p.l_p,
                    self.recording.x_s[k],
                );
                area * (r.p1[k] - r.p2[k]) <= spring
            })
            .collect()
    }

    /// Weighted sums of squares per channel, training and held-out.
    pub fn errors(&self, prediction: &[Vec<f64>; CHANNELS]) -> ([f64; CHANNELS], [f64; CHANNELS]) {
        let mut train = [0.0; CHANNELS];
        let mut heldout = [0.0; CHANNELS];
        for c in 0..CHANNELS {
            let w = self.weights[c];
            if w == 0.0 {
                continue;
            }
            for (k, (&m, &y)) in self.measured[c].iter().zip(&prediction[c]).enumerate() {
                let e = w * (m - y);
                match self.blocks[k] {
                    Block::Training => train[c] += e * e,
                    Block::HeldOut => heldout[c] += e * e,
                    Block::Settling | Block::SetAside => {}
                }
            }
        }
        (train, heldout)
    }

    /// Sensitivity of the outputs to one parameter at a point of the base model.
    pub fn sensitivity(&self, name: &'static str, step: f64, at: &Replay) -> Option<Sensitivity> {
        let value = parameter_value(self.base, name);
        self.sensitivity_to(&[(name, value + step)], step, at)
    }

    /// The outputs' change, divided by `step`, when the base model takes `settings` (a
    /// parameter moved by `step`, or a modulation slot filled with an increment of that
    /// size).
    pub fn sensitivity_to(&self, settings: &[(&'static str, f64)], step: f64, at: &Replay) -> Option<Sensitivity> {
        let mut p = self.base.clone();
        for &(name, value) in settings {
            set_parameter(&mut p, name, value).ok()?;
        }
        let model = Actuator::new(p).ok()?;
        let moved = replay_fast(&model, self.recording, self.recording.len()).ok()?;
        Some(std::sync::Arc::new([
            divided_difference(&moved.force, &at.force, step),
            divided_difference(&moved.p1, &at.p1, step),
            divided_difference(&moved.p2, &at.p2, step),
        ]))
    }

    /// Fit a candidate: bounded Gauss–Newton from its neutral values, at most `iterations`
    /// linearisations. `start` may give the base replay and the sensitivities to the
    /// candidate's nonlinear terms at the neutral point (shared between candidates).
    pub fn fit(
        &self,
        candidate: &Candidate,
        iterations: usize,
        base_replay: &Replay,
        shared: &dyn Fn(&'static str) -> Option<Sensitivity>,
    ) -> Result<Fit, String> {
        self.fit_with(candidate, iterations, base_replay, shared, false)
    }

    /// [`Problem::fit`] for a candidate whose Gauss–Newton step may overshoot far from its
    /// start (a curve's knot abscissae, whose sensitivities change where a corner crosses the
    /// data): when no step along the Gauss–Newton direction lowers the misfit, steps damped in
    /// Marquardt's way (the normal matrix's diagonal scaled by 1 + λ, λ from 0.01 to 100) are
    /// tried from the same columns, one replay each, before the fit stops.
    pub fn fit_damped(
        &self,
        candidate: &Candidate,
        iterations: usize,
        base_replay: &Replay,
        shared: &dyn Fn(&'static str) -> Option<Sensitivity>,
    ) -> Result<Fit, String> {
        self.fit_with(candidate, iterations, base_replay, shared, true)
    }

    fn fit_with(
        &self,
        candidate: &Candidate,
        iterations: usize,
        base_replay: &Replay,
        shared: &dyn Fn(&'static str) -> Option<Sensitivity>,
        damped: bool,
    ) -> Result<Fit, String> {
        let terms = &candidate.terms;
        if let Some(Mechanism::OutputFilter {
            channel,
            filter: Filter::SecondOrder(_),
        }) = terms.first().map(|t| t.mechanism)
        {
            return self.fit_second_order(candidate, channel, iterations, base_replay);
        }
        if terms.iter().any(|t| t.mechanism == Mechanism::Shape) {
            return self.fit_shape(candidate, base_replay, iterations <= 1);
        }
        if terms.iter().any(|t| t.mechanism.is_searched()) {
            if terms.len() > 1 {
                return self.fit_search_then_refine(candidate, iterations, base_replay);
            }
            // The first pass only ranks the candidates: a coarser search does for that.
            let steps = if iterations <= 1 {
                COARSE_GOLDEN_STEPS
            } else {
                GOLDEN_STEPS
            };
            return self.fit_search(candidate, base_replay, steps);
        }
        // Sensitivities of the modulated parameters (at the base point: first order).
        let modulated: Vec<Option<Sensitivity>> = terms
            .iter()
            .map(|t| match t.mechanism {
                Mechanism::Modulated { parameter, .. } => shared(parameter),
                _ => None,
            })
            .collect();
        let mut point = Point {
            values: terms.iter().map(|t| t.neutral).collect(),
            replay: std::sync::Arc::new(std::borrow::Cow::Borrowed(base_replay)),
        };
        let mut replays = 0;
        let mut prediction = self.predict(terms, &point, &modulated);
        let (mut train, _) = self.errors(&prediction);
        for iteration in 0..iterations.max(1) {
            // Columns: nonlinear terms by finite differences (shared ones at the start), their
            // replays spread over the threads; `known` ends up holding both kinds.
            let mut known: Vec<Option<Sensitivity>> = terms
                .iter()
                .map(|term| match term.mechanism {
                    Mechanism::Parameter(name) if iteration == 0 && candidate.settings.is_empty() => shared(name),
                    _ => None,
                })
                .collect();
            let differenced: Vec<(usize, f64)> = terms
                .iter()
                .enumerate()
                .filter(|(j, term)| {
                    known[*j].is_none()
                        && matches!(
                            term.mechanism,
                            Mechanism::Parameter(_)
                                | Mechanism::TimeConstantOf(_)
                                | Mechanism::CommandLag
                                | Mechanism::InputCubic
                        )
                })
                .map(|(j, term)| {
                    let step = if point.values[j] + term.step <= term.upper {
                        term.step
                    } else {
                        -term.step
                    };
                    (j, step)
                })
                .collect();
            let jobs = self.jobs.load(std::sync::atomic::Ordering::Relaxed);
            let moved_replays = crate::parallel::parallel_map(&differenced, jobs, |&(j, step)| {
                let mut moved = point.values.clone();
                moved[j] += step;
                self.replay(candidate, &moved).ok().map(|r| {
                    std::sync::Arc::new([
                        divided_difference(&r.force, &point.replay.force, step),
                        divided_difference(&r.p1, &point.replay.p1, step),
                        divided_difference(&r.p2, &point.replay.p2, step),
                    ])
                })
            });
            replays += differenced.len();
            for (&(j, _), column) in differenced.iter().zip(moved_replays) {
                known[j] = column;
            }
            let mut columns: Vec<Sensitivity> = Vec::with_capacity(terms.len());
            for (j, term) in terms.iter().enumerate() {
                let column = match term.mechanism {
                    _ if known[j].is_some() => known[j].take(),
                    Mechanism::Output { .. } | Mechanism::Modulated { .. } => {
                        let mut unit = point.values.clone();
                        unit.iter_mut().zip(terms).for_each(|(v, t)| {
                            if t.mechanism.is_linear() {
                                *v = 0.0
                            }
                        });
                        unit[j] = 1.0;
                        let with = self.predict_at(terms, &unit, &point.replay, &modulated);
                        Some(std::sync::Arc::new([
                            single(difference(&with[0], &point.replay.force)),
                            single(difference(&with[1], &point.replay.p1)),
                            single(difference(&with[2], &point.replay.p2)),
                        ]))
                    }
                    _ => None,
                };
                columns.push(column.unwrap_or_else(|| std::sync::Arc::new([vec![], vec![], vec![]])));
            }
            let step = self.solve(terms, &point.values, &columns, &prediction, 0.0);
            // Line search on the true model; then, for a damped fit, Marquardt's steps.
            let mut accepted = false;
            let mut alpha = 1.0;
            let mut step = step;
            let tries = if damped {
                LINE_SEARCH_STEPS + MARQUARDT_DAMPINGS.len()
            } else {
                LINE_SEARCH_STEPS
            };
            for attempt in 0..tries {
                if attempt >= LINE_SEARCH_STEPS {
                    step = self.solve(
                        terms,
                        &point.values,
                        &columns,
                        &prediction,
                        MARQUARDT_DAMPINGS[attempt - LINE_SEARCH_STEPS],
                    );
                    alpha = 1.0;
                }
                let values: Vec<f64> = point
                    .values
                    .iter()
                    .zip(&step)
                    .zip(terms)
                    .map(|((v, s), t)| (v + alpha * s).clamp(t.lower, t.upper))
                    .collect();
                let nonlinear_moved = terms
                    .iter()
                    .zip(values.iter().zip(&point.values))
                    .any(|(t, (a, b))| !t.mechanism.is_linear() && a != b);
                let replay = if nonlinear_moved {
                    replays += 1;
                    match self.replay(candidate, &values) {
                        Ok(r) => std::sync::Arc::new(std::borrow::Cow::Owned(r)),
                        Err(_) => {
                            alpha *= 0.5;
                            continue;
                        }
                    }
                } else {
                    point.replay.clone()
                };
                let trial = Point { values, replay };
                let trial_prediction = self.predict(terms, &trial, &modulated);
                let (trial_train, _) = self.errors(&trial_prediction);
                if trial_train.iter().sum::<f64>() < train.iter().sum::<f64>() {
                    point = trial;
                    prediction = trial_prediction;
                    train = trial_train;
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            if !accepted || terms.iter().all(|t| t.mechanism.is_linear()) {
                break;
            }
        }
        let (train, heldout) = self.errors(&prediction);
        Ok(Fit {
            candidate: candidate.clone(),
            values: point.values,
            prediction,
            train,
            heldout,
            replays,
        })
    }

    /// Bounded linear least squares for the step of every term, on the training samples.
    fn solve(
        &self,
        terms: &[Term],
        values: &[f64],
        columns: &[Sensitivity],
        prediction: &[Vec<f64>; CHANNELS],
        damping: f64,
    ) -> Vec<f64> {
        let m = terms.len();
        let usable: Vec<bool> = columns.iter().map(|c| c.iter().any(|ch| !ch.is_empty())).collect();
        let mut ata = vec![vec![0.0; m]; m];
        let mut atb = vec![0.0; m];
        for c in 0..CHANNELS {
            let w2 = self.weights[c] * self.weights[c];
            if w2 == 0.0 {
                continue;
            }
            for k in 0..self.recording.len() {
                if self.blocks[k] != Block::Training {
                    continue;
                }
                let r = self.measured[c][k] - prediction[c][k];
                for a in 0..m {
                    let ja = if usable[a] && !columns[a][c].is_empty() {
                        f64::from(columns[a][c][k])
                    } else {
                        0.0
                    };
                    if ja == 0.0 {
                        continue;
                    }
                    atb[a] += w2 * ja * r;
                    for b in a..m {
                        let jb = if usable[b] && !columns[b][c].is_empty() {
                            f64::from(columns[b][c][k])
                        } else {
                            0.0
                        };
                        ata[a][b] += w2 * ja * jb;
                    }
                }
            }
        }
        for a in 0..m {
            for b in 0..a {
                ata[a][b] = ata[b][a];
            }
            ata[a][a] *= 1.0 + damping;
        }
        let lower: Vec<f64> = terms.iter().zip(values).map(|(t, v)| t.lower - v).collect();
        let upper: Vec<f64> = terms.iter().zip(values).map(|(t, v)| t.upper - v).collect();
        bounded_least_squares(&ata, &atb, &usable, &lower, &upper)
    }

    /// A transform with one coefficient whose sensitivity vanishes where it is off (a
    /// limit does nothing until it clips, a slew limit until the command jumps) or that
    /// acts on a measured channel exactly (a delay, a lag, a play): a search on the
    /// coefficient ([`search_from_grid`]), on a logarithmic scale where it spans decades.
    /// A candidate whose regressors share one or two shape parameters (a friction's speed
    /// scales): a search of their logarithms (the second outside the first),
    /// the linear amplitudes solved at each trial point. The first pass, which only ranks
    /// the candidates, searches to a coarser bracket.
    fn fit_shape(&self, candidate: &Candidate, base_replay: &Replay, first_pass: bool) -> Result<Fit, String> {
        let shapes: Vec<usize> = (0..candidate.terms.len())
            .filter(|&k| candidate.terms[k].mechanism == Mechanism::Shape)
            .collect();
        let range = |k: usize| (candidate.terms[shapes[k]].lower, candidate.terms[shapes[k]].upper);
        let value_of = |k: usize, u: f64| {
            let (lower, upper) = range(k);
            lower * (upper / lower).powf(u)
        };
        let shaped = |vc: f64, vs: f64| -> Candidate {
            let mut c = candidate.clone();
            c.terms.retain(|t| t.mechanism != Mechanism::Shape);
            for t in c.terms.iter_mut() {
                if let Mechanism::Output { channel, regressor } = t.mechanism {
                    let regressor = match regressor {
                        Regressor::SmoothFriction(_) => Regressor::SmoothFriction(vc),
                        Regressor::Stribeck(..) => Regressor::Stribeck(vc, vs),
                        Regressor::SignPressure(_) => Regressor::SignPressure(vc),
                        other => other,
                    };
                    t.mechanism = Mechanism::Output { channel, regressor };
                }
            }
            c
        };
        let none = |_: &'static str| None;
        let fit_at = |vc: f64, vs: f64| self.fit(&shaped(vc, vs), 1, base_replay, &none).ok();
        let cost = |fit: &Option<Fit>| fit.as_ref().map_or(f64::INFINITY, |f| f.train_total());
        // The best u in [0, 1] of the cost, and its cost.
        let search = |iterations: usize, f: &dyn Fn(f64) -> f64| -> (f64, f64) {
            search_from_grid(COARSE_GRID, iterations, &mut |u| f(u))
        };
        let (inner_steps, outer_steps) = if first_pass {
            (COARSE_GOLDEN_STEPS, FIRST_PASS_OUTER_STEPS)
        } else {
            (14, 10)
        };
        let inner = |vs: f64| search(inner_steps, &|u| cost(&fit_at(value_of(0, u), vs)));
        let (vc, vs) = if shapes.len() >= 2 {
            let (u_s, _) = search(outer_steps, &|u| inner(value_of(1, u)).1);
            let vs = value_of(1, u_s);
            (value_of(0, inner(vs).0), vs)
        } else {
            (value_of(0, inner(0.0).0), 0.0)
        };
        let fit = fit_at(vc, vs).ok_or("the shaped fit failed")?;
        let mut values = fit.values.clone();
        values.insert(shapes[0], vc);
        if shapes.len() >= 2 {
            values.insert(shapes[1], vs);
        }
        Ok(Fit {
            candidate: candidate.clone(),
            values,
            ..fit
        })
    }
}

struct Prediction;

impl Prediction {
    fn of_replay(r: &Replay) -> [Vec<f64>; CHANNELS] {
        [r.force.clone(), r.p1.clone(), r.p2.clone()]
    }
}

/// min |A x − b|² given the normal equations (ata, atb), with lower ≤ x ≤ upper and the
/// unusable unknowns at 0: solve the free unknowns, clamp those that leave their bounds,
/// and solve again for the rest (at most once per unknown).
fn bounded_least_squares(ata: &[Vec<f64>], atb: &[f64], usable: &[bool], lower: &[f64], upper: &[f64]) -> Vec<f64> {
    let m = atb.len();
    let mut x = vec![0.0; m];
    // A term that moves nothing on the training samples (a knot inside a flat stretch of its
    // curve) gets no step: its column of zeros would make the system singular, and the solve
    // would give every term a NaN.
    let mut fixed: Vec<bool> = usable
        .iter()
        .enumerate()
        .map(|(a, &u)| !u || ata[a][a] <= 0.0)
        .collect();
    for _ in 0..=m {
        let free: Vec<usize> = (0..m).filter(|&j| !fixed[j]).collect();
        if free.is_empty() {
            return x;
        }
        let mut a = nalgebra::DMatrix::<f64>::zeros(free.len(), free.len());
        let mut b = nalgebra::DVector::<f64>::zeros(free.len());
        for (i, &fi) in free.iter().enumerate() {
            b[i] = atb[fi] - (0..m).filter(|&j| fixed[j]).map(|j| ata[fi][j] * x[j]).sum::<f64>();
            for (j, &fj) in free.iter().enumerate() {
                a[(i, j)] = ata[fi][fj];
            }
            // A whisker of ridge keeps nearly collinear columns solvable.
            a[(i, i)] += 1e-10 * ata[fi][fi].max(1e-300);
        }
        let Some(solution) = a.lu().solve(&b) else { return x };
        let mut clamped = false;
        for (i, &fi) in free.iter().enumerate() {
            x[fi] = solution[i];
            if !(lower[fi]..=upper[fi]).contains(&x[fi]) {
                x[fi] = x[fi].clamp(lower[fi], upper[fi]);
                fixed[fi] = true;
                clamped = true;
            }
        }
        if !clamped {
            return x;
        }
    }
    x
}

#[cfg(test)]
#[path = "fit_tests.rs"]
mod tests;
