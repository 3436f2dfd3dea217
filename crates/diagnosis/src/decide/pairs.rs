//! A compound of two departures within reach. One term at one place can stand in for two
//! at two places: without pressure channels, a supply set 30 kPa low together with the
//! receivers 0.1 mm off the jet pipe's null was taken for a force sensor's cubic curve (four
//! parameters, 5.4 noise floors left), which then locked the search in. So when no single
//! candidate leaves the force within its noise, the best candidate of each of the leading
//! places is fitted in pairs with each other's, jointly (one Gauss–Newton step from the
//! shared sensitivities, the best pair refined), and a pair that, replayed, leaves a
//! penalised held-out misfit below the best single candidate's is added as two discovered
//! terms.

use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::candidates::Mechanism;
use crate::context::Context;
use crate::decide::additions::DiscoveredTerm;
use crate::fit::localize::discovery_penalised;
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::heldout_count;
use crate::fit::localize::WantedSensitivities;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Fit;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::parallel::parallel_map;
use crate::policy::worth_adding;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::policy::LEADING_PAIRS;
use crate::policy::LOCATED_SHARE;
use crate::policy::PAIRED_PLACES;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use crate::vocabulary::Place;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// Gauss–Newton iterations of every pair's fit: the first from the shared sensitivities,
/// the second from fresh ones (one step ranked a current driver's offset above the
/// receivers' null, which fits a supply set low and the null better).
const PAIR_ITERATIONS: usize = 2;
/// Gauss–Newton iterations of the best pair's refinement.
const PAIR_REFINE_ITERATIONS: usize = 4;

/// Whether a candidate can be fitted jointly with another by Gauss–Newton: every term a
/// constant, a modulated constant or a regressor on a channel, at most two of them.
pub(crate) fn pairable(c: &Candidate) -> bool {
    c.settings.is_empty()
        && c.terms.len() <= 2
        && c.terms.iter().all(|t| {
            matches!(
                t.mechanism,
                Mechanism::Parameter(_) | Mechanism::Modulated { .. } | Mechanism::Output { .. }
            )
        })
}

/// A trial model replayed and scored on the held-out blocks, as an addition of several terms
/// is judged (a pair, or a term with the earlier ones refitted beside it).
pub(crate) struct Replayed {
    /// Held-out misfit, every channel in its noise floors squared.
    pub misfit: f64,
    /// Held-out force RMS error, N.
    pub after: f64,
    before_total: f64,
    worse_pressures: bool,
    /// Held-out misfit per channel, in its noise floors squared.
    pub heldout: [f64; CHANNELS],
}

impl Replayed {
    pub(crate) fn judge(
        cx: &Context,
        problem: &Problem,
        trial: &Parameters,
        heldout_before: &[f64; CHANNELS],
        replays: &mut usize,
    ) -> Result<Self, String> {
        let count = heldout_count(&cx.blocks) as f64;
        let with = replay_fast(&Actuator::new(trial.clone())?, cx.recording, cx.n)?;
        *replays += 1;
        let (_, heldout) = problem.errors(&[with.force.clone(), with.p1.clone(), with.p2.clone()]);
        Ok(Self {
            misfit: heldout.iter().sum(),
            after: rms_where(
                &difference(&cx.recording.force, &with.force),
                &cx.blocks,
                Block::HeldOut,
            ),
            before_total: heldout_before.iter().sum(),
            worse_pressures: (1..CHANNELS)
                .any(|c| problem.weights[c] > 0.0 && heldout[c] > 1.05 * heldout_before[c] + count * 0.01),
            heldout,
        })
    }

    /// Whether the addition is kept: its penalised misfit below the best single candidate's,
    /// its penalty earned, the force error down as [`worth_adding`] asks, no pressure worse.
    pub(crate) fn earns(&self, penalty: f64, single_score: f64, force_before: f64, noise: f64) -> bool {
        self.misfit + penalty < single_score
            && self.before_total - self.misfit > penalty
            && worth_adding(force_before, self.after, noise, false)
            && !self.worse_pressures
    }
}

/// One candidate with the terms of `a`, then those of `b`.
pub(crate) fn joined(a: &Candidate, b: &Candidate) -> Candidate {
    Candidate {
        terms: a.terms.iter().chain(&b.terms).cloned().collect(),
        named: None,
        settings: vec![],
        ..a.clone()
    }
}

/// Sensitivities at the current point of every constant the candidates vary.
pub(crate) fn wanted_for(candidates: &[&Candidate], params: &Parameters) -> WantedSensitivities {
    let mut wanted = WantedSensitivities::default();
    for c in candidates {
        wanted.add_constants_of(&c.terms);
    }
    for c in candidates {
        for t in &c.terms {
            if let Mechanism::Modulated { parameter, .. } = t.mechanism {
                wanted.add(parameter, (1e-3 * parameter_value(params, parameter).abs()).max(1e-12));
            }
        }
    }
    wanted
}

/// The best pair of candidates at two places, added as two discovered terms, with the
/// parameters that carry them; `None` when a single candidate explains the force or no pair
/// does better than the best single one.
#[allow(clippy::too_many_arguments)]
pub(crate) fn best_pair(
    cx: &Context,
    problem: &Problem,
    found: &Localization,
    params: &Parameters,
    current: &Replay,
    heldout_before: &[f64; CHANNELS],
    force_before: f64,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(Vec<DiscoveredTerm>, Parameters)>, String> {
    let count = heldout_count(&cx.blocks) as f64;
    let penalty = discovery_penalty_per_term(count);
    let Some(single) = found.candidates.first() else {
        return Ok(None);
    };
    if single.force_heldout_rms <= EXPLAINED_WITHIN_NOISE * cx.noise || single.explained < LOCATED_SHARE {
        return Ok(None);
    }
    let single_score = discovery_penalised(single, count);
    // The best pairable candidate of each leading place, by its penalised held-out misfit
    // (so the simpler of two that explain alike).
    let mut ranked: Vec<&Scored> = found.candidates.iter().collect();
    ranked.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    // Per place the best two: a pair's members need not be what fits best alone (a softer
    // static curve alone, the receivers' null in a pair).
    let mut members: Vec<&Scored> = vec![];
    let mut places: Vec<Place> = vec![];
    for s in ranked {
        let c = &s.fit.candidate;
        if c.named.is_some() || !pairable(c) {
            continue;
        }
        if !places.contains(&c.location) {
            if places.len() >= PAIRED_PLACES {
                continue;
            }
            places.push(c.location);
            members.push(s);
        } else {
            let at_place: Vec<&&Scored> = members
                .iter()
                .filter(|m| m.fit.candidate.location == c.location)
                .collect();
            if at_place.len() == 1 {
                members.push(s);
            }
        }
    }
    if places.len() < 2 {
        return Ok(None);
    }
    let mut pairs: Vec<(usize, usize)> = vec![];
    for i in 0..members.len() {
        for j in i + 1..members.len() {
            if members[i].fit.candidate.location != members[j].fit.candidate.location {
                pairs.push((i, j));
            }
        }
    }
    let candidates: Vec<&Candidate> = members.iter().map(|m| &m.fit.candidate).collect();
    let wanted = wanted_for(&candidates, params);
    progress(&format!(
        "no single candidate explains the force: {} pairs of the best candidates at {} places",
        pairs.len(),
        members.len()
    ));
    let jobs = cx.options.jobs;
    *replays += wanted.len();
    let sensitivities = wanted.taken(problem, current, jobs, "pairs", &None);
    let shared = |name: &'static str| sensitivities.get(name);
    // Every pair from the shared sensitivities, the leading pairs again with fresh ones.
    let first: Vec<Option<Fit>> = parallel_map(&pairs, jobs, |&(i, j)| {
        let pair = joined(&members[i].fit.candidate, &members[j].fit.candidate);
        problem
            .fit(&pair, 1, current, &shared)
            .ok()
            .map(Fit::without_prediction)
    });
    *replays += first.iter().flatten().map(|f| f.replays).sum::<usize>();
    let score = |f: &Fit| {
        let used = f
            .values
            .iter()
            .zip(&f.candidate.terms)
            .filter(|(v, t)| **v != t.neutral)
            .count() as f64;
        f.heldout_total() + used * penalty
    };
    let mut order: Vec<usize> = (0..pairs.len()).filter(|&k| first[k].is_some()).collect();
    order.sort_by(|&a, &b| score(first[a].as_ref().expect("kept")).total_cmp(&score(first[b].as_ref().expect("kept"))));
    order.truncate(LEADING_PAIRS);
    let again: Vec<Option<Fit>> = parallel_map(&order, jobs, |&k| {
        let (i, j) = pairs[k];
        let pair = joined(&members[i].fit.candidate, &members[j].fit.candidate);
        problem
            .fit(&pair, PAIR_ITERATIONS, current, &shared)
            .ok()
            .map(Fit::without_prediction)
    });
    *replays += again.iter().flatten().map(|f| f.replays).sum::<usize>();
    let mut fits: Vec<Option<Fit>> = vec![None; pairs.len()];
    for (&k, f) in order.iter().zip(again) {
        fits[k] = match (f, first[k].clone()) {
            (Some(f), Some(g)) if g.train_total() < f.train_total() => Some(g),
            (f, g) => f.or(g),
        };
    }
    for &k in &order {
        let (i, j) = pairs[k];
        if let Some(f) = &fits[k] {
            progress(&format!(
                "    {} + {}: {:.0}",
                members[i].fit.candidate.label,
                members[j].fit.candidate.label,
                score(f)
            ));
        }
    }
    let Some((k, _)) = fits
        .iter()
        .enumerate()
        .filter_map(|(k, f)| f.as_ref().map(|f| (k, score(f))))
        .min_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return Ok(None);
    };
    let (i, j) = pairs[k];
    let (mut a, mut b) = (&members[i].fit.candidate, &members[j].fit.candidate);
    let mut best_fit = fits[k].clone().expect("scored");
    // The simplest adequate pair: each side replaced by a candidate at its place with fewer
    // terms, when the pair's penalised held-out misfit is no larger (a plain supply pressure
    // rather than its drift).
    for side in 0..2 {
        let (this, other) = if side == 0 { (a, b) } else { (b, a) };
        let simpler: Vec<&Candidate> = found
            .candidates
            .iter()
            .map(|s| &s.fit.candidate)
            .filter(|c| c.location == this.location && c.named.is_none() && pairable(c))
            .filter(|c| c.terms.len() < this.terms.len())
            .collect();
        for c in simpler {
            let pair = if side == 0 { joined(c, other) } else { joined(other, c) };
            let Ok(f) = problem
                .fit(&pair, PAIR_ITERATIONS, current, &shared)
                .map(Fit::without_prediction)
            else {
                continue;
            };
            *replays += f.replays;
            if score(&f) <= score(&best_fit) {
                progress(&format!(
                    "  the {} does as well as the {} in the pair",
                    c.label, this.label
                ));
                best_fit = f;
                if side == 0 {
                    a = c;
                } else {
                    b = c;
                }
                break;
            }
        }
    }
    progress(&format!(
        "  best pair: the {} ({}) with the {} ({}), penalised held-out misfit {:.0} against the best single candidate's {single_score:.0}",
        a.label,
        a.location,
        b.label,
        b.location,
        score(&best_fit)
    ));
    problem.set_jobs(jobs);
    let refined = problem
        .fit(&joined(a, b), PAIR_REFINE_ITERATIONS, current, &shared)
        .map(Fit::without_prediction);
    problem.set_jobs(1);
    let fit = match (refined, Some(best_fit)) {
        (Ok(r), Some(f)) if r.train_total() < f.train_total() => r,
        (_, Some(f)) => f,
        (Ok(r), None) => r,
        (Err(e), None) => return Err(e),
    };
    *replays += fit.replays;
    let (va, vb) = fit.values.split_at(a.terms.len());
    let (Some(set_a), Some(set_b)) = (
        crate::decide::discover::model_terms(a, va, params, problem),
        crate::decide::discover::model_terms(b, vb, params, problem),
    ) else {
        progress("  the FMU has no parameters for the pair");
        return Ok(None);
    };
    if set_a.iter().any(|(n, _)| set_b.iter().any(|(m, _)| m == n)) {
        return Ok(None);
    }
    let mut trial = params.clone();
    if set_a
        .iter()
        .chain(&set_b)
        .any(|(n, v)| set_parameter(&mut trial, n, *v).is_err())
        || trial.validate().is_err()
    {
        return Ok(None);
    }
    let used = (set_a.len() + set_b.len()).min(a.terms.len() + b.terms.len()) as f64;
    let judged = Replayed::judge(cx, problem, &trial, heldout_before, replays)?;
    progress(&format!(
        "  the pair in the model: force held-out {force_before:.4} -> {:.4} N, misfit {:.0} + penalty {:.0} against {single_score:.0}",
        judged.after,
        judged.misfit,
        used * penalty
    ));
    if !judged.earns(used * penalty, single_score, force_before, cx.noise) {
        return Ok(None);
    }
    let (misfit, after) = (judged.misfit, judged.after);
    // Each member must earn its own penalty: the other alone (as fitted alone, replayed)
    // leaves more than the pair by more than this member's parameters' penalty. Otherwise
    // one term with a passenger would be added where the single term does.
    for (this, other, other_set) in [(a, b, &set_b), (b, a, &set_a)] {
        let Some(alone) = found.candidates.iter().find(|s| s.fit.candidate.label == other.label) else {
            return Ok(None);
        };
        let Some(set) = crate::decide::discover::model_terms(other, &alone.fit.values, params, problem) else {
            return Ok(None);
        };
        let mut single = params.clone();
        if set.iter().any(|(n, v)| set_parameter(&mut single, n, *v).is_err()) || single.validate().is_err() {
            return Ok(None);
        }
        let (misfit_alone, _) = crate::decide::alternatives::judge(cx, problem, &single, replays)?;
        let own = (used - other_set.len() as f64).max(1.0);
        progress(&format!(
            "  the {} alone leaves {misfit_alone:.0}: the {} earns {:.0} against its penalty {:.0}",
            other.label,
            this.label,
            misfit_alone - misfit,
            own * penalty
        ));
        if misfit_alone - misfit <= own * penalty {
            return Ok(None);
        }
    }
    progress(&format!(
        "adding the {} at the {} and the {} at the {} together",
        a.label, a.location, b.label, b.location
    ));
    Ok(Some((
        vec![
            DiscoveredTerm::fitted(a, set_a, params, force_before, after),
            DiscoveredTerm::fitted(b, set_b, params, force_before, after),
        ],
        trial,
    )))
}
