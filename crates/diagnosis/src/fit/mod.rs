//! Fitting a candidate: bounded Gauss–Newton on the training blocks through the model's
//! sensitivities, searches (`search.rs`) for the terms with none, held-out scores.

pub mod calibrate;
pub(crate) mod localize;
pub(crate) mod normal;
pub(crate) mod oscillation;
pub(crate) mod refit;
pub mod scored;
pub(crate) mod screen;
pub(crate) mod search;

use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::candidates::Filter;
use crate::candidates::Mechanism;
use crate::candidates::Modulation;
use crate::candidates::Regressor;
use crate::candidates::Term;
use crate::fit::search::{golden, search_from_grid};
use crate::input::blocks::Block;
use crate::input::recording::Recording;
use crate::input::stopper_motion::stopper_acceleration;
use crate::input::stopper_motion::stopper_velocity;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::current_driver;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::physics::sensors::{Channel, SensorLaw};

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
                    Block::Settling => {}
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

    /// A second-order filter on a measured channel (its natural frequency, then its damping
    /// ratio as a shape): it acts on the channel exactly, so it is applied to the base
    /// prediction, with no replay. A search of the damping's logarithm, and for
    /// each damping of the frequency's; the filter stays off unless it lowers the misfit.
    fn fit_second_order(
        &self,
        candidate: &Candidate,
        channel: usize,
        iterations: usize,
        base_replay: &Replay,
    ) -> Result<Fit, String> {
        let [frequency, damping] = match candidate.terms.as_slice() {
            [f, d] if d.mechanism == Mechanism::Shape => [f, d],
            _ => return Err("a second-order filter is its frequency and its damping".to_string()),
        };
        let (steps, outer_steps, grid) = if iterations <= 1 {
            (COARSE_GOLDEN_STEPS, FIRST_PASS_OUTER_STEPS, COARSE_GRID)
        } else {
            (GOLDEN_STEPS, GOLDEN_STEPS, FINE_GRID)
        };
        let base = Prediction::of_replay(base_replay);
        let filtered = |f: f64, z: f64| {
            let mut y = base.clone();
            y[channel] = Filter::SecondOrder(z).apply(&self.recording.time, &base[channel], f);
            y
        };
        let cost = |y: &[Vec<f64>; CHANNELS]| self.errors(y).0.iter().sum::<f64>();
        let on_scale = |t: &Term, u: f64| t.lower * (t.upper / t.lower).powf(u);
        let best_frequency =
            |z: f64| search_from_grid(grid, steps, &mut |u| cost(&filtered(on_scale(frequency, u), z)));
        let (u_damping, _) = search_from_grid(grid, outer_steps, &mut |u| best_frequency(on_scale(damping, u)).1);
        let z = on_scale(damping, u_damping);
        let f = on_scale(frequency, best_frequency(z).0);
        let on = filtered(f, z);
        let (values, prediction) = if cost(&on) < cost(&base) {
            (vec![f, z], on)
        } else {
            (vec![frequency.neutral, damping.neutral], base)
        };
        let (train, heldout) = self.errors(&prediction);
        Ok(Fit {
            candidate: candidate.clone(),
            values,
            prediction,
            train,
            heldout,
            replays: 0,
        })
    }

    /// A searched term followed by parameters that only act once it is on (an orifice and the
    /// volume behind it): the search with the parameters at their starts, then Gauss–Newton on
    /// all of them from there, the searched term now a parameter. A first pass (one
    /// iteration: the ranking of every candidate) searches coarser. It still takes its one
    /// Gauss–Newton step: the volume can matter more than the orifice (a wide orifice in front
    /// of a line acts as a volume added to the chamber), and without the step such a candidate
    /// would rank below the ones that mimic it and never be refined.
    fn fit_search_then_refine(
        &self,
        candidate: &Candidate,
        iterations: usize,
        base_replay: &Replay,
    ) -> Result<Fit, String> {
        let (first, rest) = candidate.terms.split_first().ok_or("a candidate without terms")?;
        let mut settings = candidate.settings.clone();
        settings.extend(rest.iter().filter_map(|t| {
            t.mechanism
                .model_parameter()
                .map(|name| (name, t.mechanism.model_value(t.neutral)))
        }));
        let searched = Candidate {
            terms: vec![first.clone()],
            settings,
            ..candidate.clone()
        };
        let first_pass = iterations <= 1;
        let found = self.fit_search(
            &searched,
            base_replay,
            if first_pass { COARSE_GOLDEN_STEPS } else { GOLDEN_STEPS },
        )?;
        let neutral: Vec<f64> = candidate.terms.iter().map(|t| t.neutral).collect();
        if found.values[0] == first.neutral {
            // Nothing the search could find: the candidate stays off, and so do the parameters
            // that act only behind it.
            let mut values = neutral;
            for (value, term) in values.iter_mut().zip(&candidate.terms).skip(1) {
                if let Some(name) = term.mechanism.model_parameter() {
                    // (in the term's own unit: a corner's time constant)
                    *value = term.mechanism.model_value(parameter_value(self.base, name));
                }
            }
            return Ok(Fit {
                candidate: candidate.clone(),
                values,
                ..found
            });
        }
        let name = first
            .mechanism
            .model_parameter()
            .ok_or("a searched term without a parameter")?;
        let mut refined = candidate.clone();
        // A one-sided limit may lie near 0 V: its step is a fiftieth of a volt, not of it.
        let step = if is_one_sided_command_limit(&first.mechanism) {
            0.02
        } else {
            0.02 * found.values[0]
        };
        refined.terms[0] = Term {
            mechanism: Mechanism::Parameter(name),
            neutral: found.values[0],
            step,
            ..first.clone()
        };
        // A searched model parameter's prediction at what the search found is the replay
        // with the other terms at their starts: the refinement's first point. (A filter on
        // an output is searched on the base replay, not through the model.)
        let (start_replay, replayed) = if matches!(first.mechanism, Mechanism::OutputFilter { .. }) {
            let start: Vec<f64> = refined.terms.iter().map(|t| t.neutral).collect();
            (self.replay(&refined, &start)?, 1)
        } else {
            let [force, p1, p2] = found.prediction;
            let searched = Replay {
                force,
                p1,
                p2,
                ..Replay::default()
            };
            (searched, 0)
        };
        let none = |_: &'static str| None;
        let fit = self.fit(&refined, iterations, &start_replay, &none)?;
        Ok(Fit {
            candidate: candidate.clone(),
            replays: fit.replays + found.replays + replayed,
            ..fit
        })
    }

    fn fit_search(&self, candidate: &Candidate, base_replay: &Replay, golden_steps: usize) -> Result<Fit, String> {
        let p = self.base;
        let term = &candidate.terms[0];
        if term.mechanism == Mechanism::Searched("command_quantum") {
            return self.fit_quantiser(candidate, base_replay, golden_steps);
        }
        // A limit beyond every command the fits train on changes nothing they see: the search
        // spans the training rows' commands, or a flat stretch of misfit above them takes a
        // search away from a limit that clips only the highest training level.
        let commands: Vec<f64> = self
            .recording
            .v_da
            .iter()
            .zip(self.blocks)
            .filter(|(_, b)| **b == Block::Training)
            .map(|(v, _)| *v)
            .collect();
        let (low, high) = commands
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
        let (lower, upper, logarithmic) = match term.mechanism {
            // A symmetric limit is one only where it clips both sides of what the fits train
            // on; clipping one side, it is the one-sided limit, which claims nothing about the
            // other (where a closed loop may drive the command hard in held-out rows).
            Mechanism::CurrentLimit => {
                let at = |v: f64| current_driver::static_current(p.k_cd, p.i_offset, v);
                let (i_low, i_high) = (at(low).min(at(high)), at(low).max(at(high)));
                let largest = i_low.abs().max(i_high.abs());
                (0.2 * largest, both_sides_clipped_below(i_low, i_high), false)
            }
            Mechanism::CommandLimit => {
                let largest = low.abs().max(high.abs());
                (0.2 * largest, both_sides_clipped_below(low, high), false)
            }
            // A one-sided limit anywhere in the upper or lower four fifths of the commands
            // trained on: it clips at least a fifth of their span.
            Mechanism::Searched(name) if is_one_sided_command_limit(&term.mechanism) => {
                let span = high - low;
                if name == "command_upper_limit" {
                    (low + 0.2 * span, high, false)
                } else {
                    (low, high - 0.2 * span, false)
                }
            }
            // Above the recording's Nyquist frequency the command's filter reads as a delay of
            // 2ζ/ω, which the delay candidate is; and there each step is cut into pieces
            // (`CommandStage::pieces_over`), which makes its replays the slowest of the pass.
            Mechanism::Searched("command_filter_frequency") => {
                (term.lower, term.upper.min(0.5 * self.recording.sample_rate()), true)
            }
            _ => (term.lower, term.upper, true),
        };
        let base = Prediction::of_replay(base_replay);
        // (an empty range, or one of NaN where the training rows hold no command)
        if upper.partial_cmp(&lower) != Some(std::cmp::Ordering::Greater) {
            let (train, heldout) = self.errors(&base);
            return Ok(Fit {
                candidate: candidate.clone(),
                values: vec![term.neutral],
                prediction: base,
                train,
                heldout,
                replays: 0,
            });
        }
        let mut replays = 0;
        // The prediction at the lowest cost so far: the search ends on it, and it is not
        // replayed again.
        let mut lowest: Option<(f64, f64, [Vec<f64>; CHANNELS])> = None;
        let mut evaluate = |value: f64| -> (f64, Option<[Vec<f64>; CHANNELS]>) {
            if let Some((at, cost, y)) = &lowest {
                if *at == value {
                    return (*cost, Some(y.clone()));
                }
            }
            let prediction = match term.mechanism {
                Mechanism::OutputFilter { channel, filter } => {
                    match self.lag_read_by_the_model(channel, filter, value, golden_steps >= GOLDEN_STEPS) {
                        Some(name) => {
                            replays += 1;
                            let mut p = self.base.clone();
                            set_parameter(&mut p, name, value)
                                .ok()
                                .and_then(|_| Actuator::new(p).ok())
                                .and_then(|model| replay_fast(&model, self.recording, self.recording.len()).ok())
                                .map(|r| Prediction::of_replay(&r))
                        }
                        None => {
                            let mut out = base.clone();
                            out[channel] = filter.apply(&self.recording.time, &base[channel], value);
                            Some(out)
                        }
                    }
                }
                _ => {
                    replays += 1;
                    self.replay(candidate, &[value]).ok().map(|r| Prediction::of_replay(&r))
                }
            };
            match prediction {
                Some(y) => {
                    let cost: f64 = self.errors(&y).0.iter().sum();
                    if lowest.as_ref().map_or(true, |(_, c, _)| cost < *c) {
                        lowest = Some((value, cost, y.clone()));
                    }
                    (cost, Some(y))
                }
                None => (f64::INFINITY, None),
            }
        };
        let to_value = |u: f64| {
            if logarithmic {
                lower * (upper / lower).powf(u)
            } else {
                lower + (upper - lower) * u
            }
        };
        let grid = if golden_steps >= GOLDEN_STEPS {
            FINE_GRID
        } else {
            COARSE_GRID
        };
        let (u, _) = search_from_grid(grid, golden_steps, &mut |u| evaluate(to_value(u)).0);
        let best = to_value(u);
        let (cost, prediction) = evaluate(best);
        let (values, prediction) = match prediction {
            Some(y) if cost < self.errors(&base).0.iter().sum::<f64>() => (vec![best], y),
            _ => (vec![term.neutral], base),
        };
        let (train, heldout) = self.errors(&prediction);
        Ok(Fit {
            candidate: candidate.clone(),
            values,
            prediction,
            train,
            heldout,
            replays,
        })
    }
}

impl Problem<'_> {
    /// The command quantiser ([`crate::candidates::quantiser`]): the leading periods of the residual in
    /// the command, each under the four conventions, and the steps of coarser converters
    /// over the logger's span, rounding and truncating, are tried in the model; the best is
    /// polished within 3 % by a golden-section search. The first pass, which only ranks the
    /// candidates, tries rounding alone. The origin and the threshold the fit takes are its
    /// candidate's settings.
    fn fit_quantiser(&self, candidate: &Candidate, base_replay: &Replay, golden_steps: usize) -> Result<Fit, String> {
        let base = Prediction::of_replay(base_replay);
        let residual: Vec<f64> = self
            .recording
            .force
            .iter()
            .zip(&base_replay.force)
            .map(|(m, y)| m - y)
            .collect();
        let training: Vec<bool> = self.blocks.iter().map(|b| *b == Block::Training).collect();
        let settled = |origin: f64, threshold: f64| Candidate {
            settings: candidate
                .settings
                .iter()
                .filter(|(name, _)| !name.starts_with("command_quantum_"))
                .copied()
                .chain([
                    ("command_quantum_origin", origin),
                    ("command_quantum_threshold", threshold),
                ])
                .collect(),
            ..candidate.clone()
        };
        let mut replays = 0;
        let mut best = (
            self.errors(&base).0.iter().sum::<f64>(),
            candidate.clone(),
            candidate.terms[0].neutral,
            base,
        );
        let mut trial =
            |best: &mut (f64, Candidate, f64, [Vec<f64>; CHANNELS]), q: f64, origin: f64, threshold: f64| {
                let tried = settled(origin, threshold);
                replays += 1;
                let Ok(replay) = self.replay(&tried, &[q]) else {
                    return f64::INFINITY;
                };
                let y = Prediction::of_replay(&replay);
                let cost: f64 = self.errors(&y).0.iter().sum();
                if cost < best.0 {
                    *best = (cost, tried, q, y);
                }
                cost
            };
        let first_pass = golden_steps < GOLDEN_STEPS;
        for q in crate::candidates::quantiser::leading_steps(
            &self.recording.time,
            &self.recording.v_da,
            &residual,
            &training,
        ) {
            for (origin, threshold) in crate::candidates::quantiser::conventions(q) {
                if !(first_pass && threshold == 1.0) {
                    trial(&mut best, q, origin, threshold);
                }
            }
        }
        for q in crate::candidates::quantiser::converter_steps(&self.recording.v_da) {
            for threshold in [0.5, 1.0] {
                if !(first_pass && threshold == 1.0) {
                    trial(&mut best, q, 0.0, threshold);
                }
            }
        }
        if best.2 > 0.0 {
            let (q, settings) = (best.2, best.1.settings.clone());
            let get = |name: &str| settings.iter().find(|(n, _)| *n == name).map_or(0.0, |s| s.1);
            let (origin, threshold) = (get("command_quantum_origin"), get("command_quantum_threshold"));
            // A grid half a step off 0 V stays half a step off as the step changes.
            let origin_in_steps = origin / q;
            let mut polish = |u: f64| {
                let q = q * (0.97 + 0.06 * u);
                trial(&mut best, q, origin_in_steps * q, threshold)
            };
            // The first pass only ranks the candidates: a few steps do for that.
            let steps = if first_pass { 4 } else { COARSE_GOLDEN_STEPS };
            golden(0.0, 1.0, steps, &mut polish);
        }
        let (_, candidate, q, prediction) = best;
        let (train, heldout) = self.errors(&prediction);
        Ok(Fit {
            candidate,
            values: vec![q],
            prediction,
            train,
            heldout,
            replays,
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

/// The largest symmetric limit that clips both ends of a range from `low` to `high`: the
/// smaller of their magnitudes, or 0 when the range lies on one side of zero.
fn both_sides_clipped_below(low: f64, high: f64) -> f64 {
    if low < 0.0 && high > 0.0 {
        (-low).min(high)
    } else {
        0.0
    }
}

/// Whether `mechanism` is the command's upper or lower limit, searched over the commands
/// recorded on a linear scale.
fn is_one_sided_command_limit(mechanism: &Mechanism) -> bool {
    matches!(
        mechanism,
        Mechanism::Searched("command_upper_limit" | "command_lower_limit")
    )
}

impl Problem<'_> {
    /// The model parameter through which a lag of `value` seconds on `channel` is searched,
    /// where it is searched through the model rather than on the samples: where the
    /// model's transducer reads the quantity between samples ([`SensorLaw::parts_over`]), and
    /// the base model's transducer there neither lags nor filters. On the samples the
    /// quantity is a chord from each to the next; a force that a closed loop at 250 Hz drove
    /// by 7 N from sample to sample read a 0.53 ms lag as anything but one (the force sensor's
    /// lag explained less than a command delay, which was named), where the model's lag
    /// follows the force it computes between them. Only the refining pass (`refining`)
    /// searches so: a transducer recorded in up to 16 parts of each sample makes
    /// each replay the slowest of a round, and in the first pass, over every candidate of
    /// every round, it more than doubled the test cases' time.
    pub(crate) fn lag_read_by_the_model(
        &self,
        channel: usize,
        filter: Filter,
        value: f64,
        refining: bool,
    ) -> Option<&'static str> {
        if filter != Filter::Lag || !refining {
            return None;
        }
        let time = &self.recording.time;
        let n = time.len();
        if n < 2 {
            return None;
        }
        let interval = (time[n - 1] - time[0]) / (n - 1) as f64;
        let law = SensorLaw::of(self.base, Channel::ALL[channel]);
        let fresh = law.lag <= 0.0 && law.filter_frequency <= 0.0;
        let lagged = SensorLaw { lag: value, ..law };
        if fresh && lagged.parts_over(interval) > 1 {
            filter.sensor_parameter(channel)
        } else {
            None
        }
    }
}

#[cfg(test)]
#[path = "fit_tests.rs"]
mod tests;
