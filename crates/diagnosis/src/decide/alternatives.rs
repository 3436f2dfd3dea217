//! A search that does not lock in: after anything has been added at a place (a named
//! effect or a discovered term), the other terms at that place with no more parameters are
//! tried again in the replayed model, and the simplest that is adequate on the held-out
//! blocks (its parameters' penalty counted) takes its place. A supply pressure set 30 kPa
//! low is explained by the line resistance of the named `supply_pressure_drop` to within 10
//! noise floors, and by a plain `P_s` to the noise. A named effect also competes with the
//! general terms at its place that have more parameters: one whose penalised misfit is
//! lower by a further penalty replaces it (a second-order filter at the command, which the
//! named `transport_delay` followed to within 4.4 noise floors).

use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::context::Context;
use crate::decide::additions::DiscoveredTerm;
use crate::fit::localize::discovery_penalised;
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::used_terms;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Fit;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::policy::DISCOVERY_TRIALS;
use crate::policy::ELSEWHERE_TRIALS;
use crate::policy::EQUAL_SHARE_OF_GAP;
use crate::policy::FLEXIBLE_TERMS;
use crate::policy::LOCATED_SHARE;
use crate::policy::RICHER_SHARE_OF_GAP;
use crate::policy::SIMPLE_TERMS;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::Replay;
use crate::vocabulary::Place;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// What the judgement of a replayed model needs from its round.
pub(crate) struct Check<'a> {
    pub cx: &'a Context<'a>,
    pub problem: &'a Problem<'a>,
    /// Held-out samples.
    pub count: f64,
    /// The round's held-out force RMS error before the addition, N.
    pub force_before: f64,
}

impl Check<'_> {
    /// The model with `params` replayed: its held-out misfit (all channels, in noise floors
    /// squared) and its held-out force RMS error.
    pub(crate) fn judge(&self, params: &Parameters, replays: &mut usize) -> Result<(f64, f64), String> {
        judge(self.cx, self.problem, params, replays)
    }

    /// A fitted candidate's `values` set in the model `params` and replayed: the parameters
    /// that carry it, the model with it, its held-out misfit and its held-out force error.
    /// `None` when the values cannot be set or the model is not valid with them.
    #[allow(clippy::type_complexity)]
    fn replayed(
        &self,
        candidate: &Candidate,
        values: &[f64],
        params: &Parameters,
        replays: &mut usize,
    ) -> Result<Option<(Vec<(&'static str, f64)>, Parameters, f64, f64)>, String> {
        let Some(set) = crate::decide::discover::model_terms(candidate, values, params, self.problem) else {
            return Ok(None);
        };
        let mut trial = params.clone();
        if set.iter().any(|(n, v)| set_parameter(&mut trial, n, *v).is_err()) || trial.validate().is_err() {
            return Ok(None);
        }
        let (misfit, force) = self.judge(&trial, replays)?;
        Ok(Some((set, trial, misfit, force)))
    }

    /// The candidate, carried by `set`, as a discovered term that leaves `force` held out.
    fn discovered(
        &self,
        candidate: &Candidate,
        set: Vec<(&'static str, f64)>,
        params: &Parameters,
        force: f64,
    ) -> DiscoveredTerm {
        DiscoveredTerm::fitted(candidate, set, params, self.force_before, force)
    }
}

/// The model with `params` replayed: its held-out misfit (all channels, in noise floors
/// squared, weighted as `problem` weighs them) and its held-out force RMS error, N.
pub(crate) fn judge(
    cx: &Context,
    problem: &Problem,
    params: &Parameters,
    replays: &mut usize,
) -> Result<(f64, f64), String> {
    let with = replay_fast(&Actuator::new(params.clone())?, cx.recording, cx.n)?;
    *replays += 1;
    let (_, heldout) = problem.errors(&[with.force.clone(), with.p1.clone(), with.p2.clone()]);
    let force = rms_where(
        &difference(&cx.recording.force, &with.force),
        &cx.blocks,
        Block::HeldOut,
    );
    Ok((heldout.iter().sum(), force))
}

/// What was added at a place, as the alternatives are judged against it.
pub(crate) struct Added<'a> {
    /// Its fitted candidate.
    pub scored: &'a Scored,
    /// The model with it.
    pub with: &'a Parameters,
    /// A named effect (its alternatives may have as many parameters as it, or more when they
    /// do better by a penalty) or a discovered term (one with as many must do strictly
    /// better).
    pub named: bool,
    /// The named effect's shape was measured apart from the model: a force sensor's offset
    /// and gain against the force the pressures make, where a cubic did no better than the
    /// affine map. A richer term at its place then gains only by taking a sliver of a
    /// departure elsewhere (a force sensor curve took 37 % of the way to the noise beside a
    /// torque-motor gain stepping with P1 − P2, and displaced the true offset and gain), so
    /// none is tried.
    pub measured_shape: bool,
}

/// The simplest other term at the place of what was added that, replayed, leaves a
/// held-out misfit plus its parameters' penalty no larger than the addition's, and a
/// held-out force error no larger (within a twentieth of the noise floor when it has fewer
/// parameters): that term, as discovered, with the parameters that carry it. The candidates
/// with no more parameters than the addition are tried (after a named effect, those with
/// more too, which must leave a penalised misfit lower by a further penalty and a smaller
/// force error; one as rich as it or a discovered term must leave a penalised misfit lower
/// by a penalty, and after a named effect also close a share of the way to the noise), best first by their penalised held-out misfit, at most
/// [`DISCOVERY_TRIALS`]; among those adequate, the [`simplest`].
pub(crate) fn alternative_at_place(
    check: &Check,
    found: &Localization,
    params: &Parameters,
    added: &Added,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(DiscoveredTerm, Parameters)>, String> {
    let scored = added.scored;
    let place = scored.fit.candidate.location;
    let count = check.count;
    let penalty = discovery_penalty_per_term(count);
    let added_terms = used_terms(scored);
    let mut alternatives: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.location == place && s.fit.candidate.named.is_none())
        .filter(|s| s.fit.candidate.label != scored.fit.candidate.label)
        .filter(|s| s.explained >= LOCATED_SHARE && used_terms(s) > 0.0)
        .filter(|s| used_terms(s) <= added_terms || (added.named && !added.measured_shape))
        // A modulation can take any shape: it is no simpler form of a written term, and it
        // replaces only another modulation.
        .filter(|s| {
            !crate::candidates::modulation::is_modulation(&s.fit.candidate)
                || crate::candidates::modulation::is_modulation(&scored.fit.candidate)
        })
        .collect();
    if alternatives.is_empty() {
        return Ok(None);
    }
    alternatives.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    let name = scored.fit.candidate.named.unwrap_or(scored.fit.candidate.label);
    let (added_misfit, added_force) = check.judge(added.with, replays)?;
    let added_score = added_misfit + added_terms * penalty;
    let noise = check.cx.noise;
    // (terms, score, term, parameters) of each adequate alternative.
    let mut adequate: Vec<(f64, f64, DiscoveredTerm, Parameters)> = vec![];
    for s in alternatives.into_iter().take(DISCOVERY_TRIALS) {
        let candidate = &s.fit.candidate;
        let Some((set, trial, misfit, force)) = check.replayed(candidate, &s.fit.values, params, replays)? else {
            continue;
        };
        let terms = used_terms(s);
        let score = misfit + terms * penalty;
        progress(&format!(
            "  instead of {name}: {} leaves {misfit:.0} held out against its {added_misfit:.0} (noise floors squared), force {force:.4} against {added_force:.4} N",
            candidate.label
        ));
        let ok = if terms < added_terms {
            score <= added_score && force <= added_force + 0.05 * noise
        } else if terms > added_terms {
            // While another departure dominates what the named effect leaves, a richer term
            // at its place gains by taking a sliver of that departure: it must take a real
            // share of the way to the noise.
            let gap = (added_force - noise).max(0.0);
            let taken = added_force - force >= RICHER_SHARE_OF_GAP * gap;
            score < added_score - penalty && force < added_force && taken
        } else if added.named {
            // As close as the two come while another departure is still to be found, the
            // named effect stays: an unnamed term as rich as it replaces it by a penalty and
            // a share of the way to the noise (a seal friction growing with the pressures
            // matched a smooth friction to 0.1 % beside a force sensor lag).
            let gap = (added_force - noise).max(0.0);
            let taken = added_force - force >= EQUAL_SHARE_OF_GAP * gap
                || added_misfit - misfit >= EQUAL_SHARE_OF_GAP * added_misfit;
            score < added_score - penalty && force <= added_force && taken
        } else {
            // a discovered term must be beaten by its penalty
            score < added_score - penalty && force <= added_force
        };
        if !ok {
            continue;
        }
        adequate.push((terms, score, check.discovered(candidate, set, params, force), trial));
    }
    Ok(simplest(adequate, penalty, name, progress))
}

/// Their linearisations: a jet pipe's travel 30 % short comes to within the noise in three.
const ELSEWHERE_ITERATIONS: usize = 4;

/// After a flexible addition (a static curve), the simplest term at another place of the
/// chain that, refitted and replayed, does as well on the held-out blocks: that term, as
/// discovered, with the parameters that carry it. A curve at the command reshapes everything
/// downstream of it, so one Gauss–Newton step from its identity already takes it to a jet
/// pipe whose travel is 30 % short, where the travel's own constant, a step from its neutral
/// value, is still part of the way; refitted, the constant explains as much with two
/// parameters against the curve's eight. Candidates with at most [`SIMPLE_TERMS`] parameters
/// that explained at least [`LOCATED_SHARE`] in the first pass, the best of each place and
/// none searched, are refitted from their neutral values with [`ELSEWHERE_ITERATIONS`]
/// linearisations, best first, at most [`ELSEWHERE_TRIALS`]; one is adequate when its misfit
/// plus its parameters' penalty is no larger than the curve's and its held-out force error no
/// larger by a twentieth of the noise floor.
pub(crate) fn simpler_elsewhere(
    check: &Check,
    found: &Localization,
    params: &Parameters,
    added: &Added,
    current: &Replay,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(DiscoveredTerm, Parameters)>, String> {
    let scored = added.scored;
    let added_terms = used_terms(scored);
    if added.named || added_terms < FLEXIBLE_TERMS {
        return Ok(None);
    }
    let place = scored.fit.candidate.location;
    let count = check.count;
    let penalty = discovery_penalty_per_term(count);
    let mut others: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.location != place && s.fit.candidate.named.is_none())
        .filter(|s| s.fit.candidate.settings.is_empty())
        // A searched term (a limit, a filter, a friction's shape) was searched in the first
        // pass too: it is not behind for having been linearised once.
        .filter(|s| s.fit.candidate.terms.iter().all(|t| !t.mechanism.is_searched()))
        .filter(|s| s.explained >= LOCATED_SHARE && s.fit.candidate.terms.len() as f64 <= SIMPLE_TERMS)
        .collect();
    if others.is_empty() {
        return Ok(None);
    }
    others.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    // One step from neutral ranks the constants by how far a linearisation reaches, not by
    // where the departure is (a large one lets any gain along the chain take most of it):
    // the best of each place is refitted, not the best few of one place.
    let mut places: Vec<Place> = vec![];
    others.retain(|s| {
        let new_place = !places.contains(&s.fit.candidate.location);
        if new_place {
            places.push(s.fit.candidate.location);
        }
        new_place
    });
    others.truncate(ELSEWHERE_TRIALS);
    let name = scored.fit.candidate.label;
    progress(&format!(
        "the {name} has {added_terms} parameters: {} simpler terms at other places refitted",
        others.len()
    ));
    let (added_misfit, added_force) = check.judge(added.with, replays)?;
    let added_score = added_misfit + added_terms * penalty;
    let refits: Vec<Option<Fit>> = crate::parallel::parallel_map(&others, check.cx.options.jobs, |s| {
        check
            .problem
            .fit(&s.fit.candidate, ELSEWHERE_ITERATIONS, current, &|_| None)
            .ok()
            .map(Fit::without_prediction)
    });
    let noise = check.cx.noise;
    // (terms, score, term, parameters) of each adequate term.
    let mut adequate: Vec<(f64, f64, DiscoveredTerm, Parameters)> = vec![];
    for fit in refits.into_iter().flatten() {
        *replays += fit.replays;
        let candidate = &fit.candidate;
        let Some((set, trial, misfit, force)) = check.replayed(candidate, &fit.values, params, replays)? else {
            continue;
        };
        let terms = crate::fit::localize::terms_used(&fit);
        let score = misfit + terms * penalty;
        progress(&format!(
            "  instead of the {name}: the {} at the {} leaves {misfit:.0} held out against its {added_misfit:.0} (noise floors squared), force {force:.4} against {added_force:.4} N",
            candidate.label, candidate.location
        ));
        if terms == 0.0 || score > added_score || force > added_force + 0.05 * noise {
            continue;
        }
        adequate.push((terms, score, check.discovered(candidate, set, params, force), trial));
    }
    Ok(simplest(adequate, penalty, &format!("the {name}"), progress))
}

/// Of the adequate terms (their parameters, penalised misfit, term and model), the
/// [`simplest_index`].
fn simplest(
    mut adequate: Vec<(f64, f64, DiscoveredTerm, Parameters)>,
    penalty: f64,
    instead_of: &str,
    progress: &mut dyn FnMut(&str),
) -> Option<(DiscoveredTerm, Parameters)> {
    let sizes: Vec<(f64, f64)> = adequate.iter().map(|a| (a.0, a.1)).collect();
    let (_, _, term, trial) = adequate.swap_remove(simplest_index(&sizes, penalty)?);
    progress(&format!(
        "adding a {} at the {} instead of {instead_of}",
        term.candidate, term.location
    ));
    Some((term, trial))
}

/// Of terms given as (parameters, penalised misfit), the one with the fewest parameters among
/// those whose penalised misfit is within one `penalty` of the smallest, then the smallest
/// penalised misfit. A simpler term is preferred only where the held-out blocks do not tell
/// it from the best: a command lag left four times the misfit of the command's second-order
/// filter that had written the recording, and was taken for having one parameter fewer.
fn simplest_index(terms: &[(f64, f64)], penalty: f64) -> Option<usize> {
    let lowest = terms.iter().map(|t| t.1).fold(f64::INFINITY, f64::min);
    (0..terms.len())
        .filter(|&i| terms[i].1 <= lowest + penalty)
        .min_by(|&i, &j| {
            terms[i]
                .0
                .total_cmp(&terms[j].0)
                .then(terms[i].1.total_cmp(&terms[j].1))
        })
}

#[cfg(test)]
mod tests {
    use super::simplest_index;

    #[test]
    fn a_simpler_term_wins_only_where_the_held_out_blocks_do_not_tell_it_from_the_best() {
        // Penalised misfits in noise floors squared, a penalty of 9 per parameter.
        assert_eq!(simplest_index(&[(1.0, 22615.0), (2.0, 5606.0)], 9.0), Some(1));
        assert_eq!(simplest_index(&[(2.0, 5606.0), (1.0, 5610.0)], 9.0), Some(1));
        assert_eq!(
            simplest_index(&[(2.0, 5606.0), (1.0, 5620.0), (3.0, 5600.0)], 9.0),
            Some(0)
        );
        assert_eq!(simplest_index(&[], 9.0), None);
    }
}
