//! The fits of the terms with no sensitivity to solve for: a friction's speed scale, a second
//! order filter, a limit, a delay, a quantiser, searched (`search.rs`) and then refined.

use super::{
    Fit, Prediction, Problem, COARSE_GOLDEN_STEPS, COARSE_GRID, FINE_GRID, FIRST_PASS_OUTER_STEPS, GOLDEN_STEPS,
};
use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::candidates::Filter;
use crate::candidates::Mechanism;
use crate::candidates::Term;
use crate::fit::search::{golden, search_from_grid};
use crate::input::blocks::Block;
use crate::replay::replay_fast;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::current_driver;
use jetpipe_model::physics::sensors::{Channel, SensorLaw};

impl Problem<'_> {
    /// A second-order filter on a measured channel (its natural frequency, then its damping
    /// ratio as a shape): it acts on the channel exactly, so it is applied to the base
    /// prediction, with no replay. A search of the damping's logarithm, and for
    /// each damping of the frequency's; the filter stays off unless it lowers the misfit.
    pub(super) fn fit_second_order(
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
    pub(super) fn fit_search_then_refine(
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

    pub(super) fn fit_search(
        &self,
        candidate: &Candidate,
        base_replay: &Replay,
        golden_steps: usize,
    ) -> Result<Fit, String> {
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
    pub(super) fn fit_quantiser(
        &self,
        candidate: &Candidate,
        base_replay: &Replay,
        golden_steps: usize,
    ) -> Result<Fit, String> {
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
