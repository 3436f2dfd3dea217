//! Step 5: the named effect that earns its name at the located place, or downstream of a
//! larger departure upstream, and what each takes of what it could take.

use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::context::Context;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::findings::{nameable, pressures_gain, Round};
use crate::decide::named_effect::apply_named;
use crate::decide::named_effect::force_through_mechanics;
use crate::decide::named_effect::named_signature;
use crate::fit::localize::discovery_penalised;
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::localize;
use crate::fit::localize::penalised;
use crate::fit::localize::used_terms;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Fit;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::parallel::parallel_map;
use crate::policy::worth_adding;
use crate::policy::DISCOVERY_TRIALS;
use crate::policy::ELSEWHERE_BESIDE_NAMED;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::policy::LOCATED_SHARE;
use crate::policy::NAMED_MIN_SHARE;
use crate::policy::NAMED_SHARE_OF_PLACE;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::signals::CHANNELS;
use crate::replay::signals::FORCE;
use crate::vocabulary::Place;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// The best named effect at the located place that earns its name (step 5), judged on the
/// fitted prediction.
pub(crate) fn named_at_place(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    found: &Localization,
    discovered: &[DiscoveredTerm],
    halves: &mut Vec<Half>,
    progress: &mut dyn FnMut(&str),
) -> Option<(Scored, String)> {
    let (place, count, force_before, noise) = (found.location, r.count, r.force_before, cx.noise);
    // Against the written candidates: a modulation can take any shape, a named effect's too.
    let place_share = found
        .candidates
        .iter()
        .filter(|s| {
            s.fit.candidate.location == place && !crate::candidates::modulation::is_modulation(&s.fit.candidate)
        })
        .map(|s| s.explained)
        .fold(0.0, f64::max);
    // Where only a modulation located the place (no written candidate there explains as
    // much as one elsewhere), a named effect must stand on its own: explain as much as the
    // best written candidate anywhere (a supply varying with the pressure difference located
    // a supply set low with the receivers off the null at the supply, where a named supply
    // restriction at 87 % stood in for the pair).
    let written_anywhere = found
        .candidates
        .iter()
        .filter(|s| !crate::candidates::modulation::is_modulation(&s.fit.candidate))
        .map(|s| s.explained)
        .fold(0.0, f64::max);
    let named_floor = if place_share < written_anywhere
        && found.best_at(place).map_or(false, |s| {
            crate::candidates::modulation::is_modulation(&s.fit.candidate)
        }) {
        written_anywhere
    } else {
        0.0
    };
    let mut named: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.location == place)
        .filter(|s| nameable(s, discovered))
        .collect();
    named.sort_by(|a, b| penalised(a, count).total_cmp(&penalised(b, count)));
    for s in named {
        let name = s.fit.candidate.named.expect("filtered on named");
        let gain = force_before - s.force_heldout_rms;
        let worse_pressures =
            (1..CHANNELS).any(|c| problem.weights[c] > 0.0 && s.fit.heldout[c] > 1.05 * r.heldout[c] + count * 0.01);
        let share_ok = s.explained >= NAMED_SHARE_OF_PLACE * place_share
            && share_of_reach(&r.heldout, &s.fit.heldout, &problem.weights, count) >= NAMED_MIN_SHARE
            && s.explained >= named_floor;
        let gain_ok = worth_adding(force_before, force_before - gain, noise, false)
            || pressures_gain(&r.heldout, &s.fit.heldout, count) && s.force_heldout_rms <= force_before + 0.05 * noise;
        let test = named_signature(
            name,
            cx.recording,
            &r.model,
            &r.current,
            &s.fit.prediction[FORCE],
            &cx.blocks,
            noise,
            cx.mechanical_noise,
        );
        progress(&format!(
            "  {name}: explains {:.1} % (its place {:.1} %), force held-out {force_before:.4} -> {:.4} N, signature {}",
            100.0 * s.explained,
            100.0 * place_share,
            s.force_heldout_rms,
            if test.present { "present" } else { "absent" }
        ));
        if !test.sentence.is_empty() {
            progress(&format!("    {}", test.sentence));
        }
        if share_ok && gain_ok && !worse_pressures && test.present {
            return Some((s.clone(), test.sentence));
        }
        let reach = share_of_reach(&r.heldout, &s.fit.heldout, &problem.weights, count);
        if gain_ok && test.present && (worse_pressures || reach < NAMED_MIN_SHARE) {
            let shortfall = if worse_pressures {
                "makes a pressure worse".to_string()
            } else {
                format!(
                    "takes {:.0} % of what the channels it moves hold above their noise",
                    100.0 * reach
                )
            };
            progress(&format!("    alone it {shortfall}: it may be half of the departure"));
            halves.push(Half {
                scored: s.clone(),
                sentence: test.sentence,
                shortfall,
            });
        }
    }
    None
}

/// A named effect whose signature shows and that lowers the force error, but that alone
/// makes a pressure worse or takes too little of the misfit: the other half may be a term.
pub(crate) struct Half {
    scored: Scored,
    sentence: String,
    shortfall: String,
}

/// A named effect with a term beside it, fitted together: dead volumes beside an extra flow
/// out of chamber 1 each alone made chamber 2's pressure worse (the flow is the other half of
/// the pressures' departure) and nothing was added, 21.9 noise floors left. Each such named
/// effect is fitted jointly with every written candidate at its place and the leading ones
/// elsewhere; the best pair, replayed, must leave every channel within 1.5 noise floors and
/// do better than the best single candidate by its penalty with no pressure worse, and each
/// half must earn its own penalty against the other alone. Returns the named effect with its values from the pair and the sentence that says
/// so, the term, and the parameters with both.
#[allow(clippy::too_many_arguments)]
pub(crate) fn named_with_term(
    cx: &Context,
    problem: &Problem,
    found: &Localization,
    params: &Parameters,
    r: &Round,
    halves: Vec<Half>,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(Scored, String, DiscoveredTerm, Parameters)>, String> {
    let count = r.count;
    let penalty = discovery_penalty_per_term(count);
    let Some(single) = found.candidates.first() else {
        return Ok(None);
    };
    let single_score = discovery_penalised(single, count);
    let mut written: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.named.is_none() && crate::decide::pairs::pairable(&s.fit.candidate))
        .collect();
    written.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    let places: Vec<Place> = halves.iter().map(|h| h.scored.fit.candidate.location).collect();
    let mut elsewhere = 0;
    let ranked: Vec<&Scored> = written
        .into_iter()
        .filter(|s| {
            let here = places.contains(&s.fit.candidate.location);
            elsewhere += usize::from(!here);
            here || elsewhere <= ELSEWHERE_BESIDE_NAMED
        })
        .collect();
    if ranked.is_empty() || halves.is_empty() {
        return Ok(None);
    }
    let pairs: Vec<(usize, usize)> = (0..halves.len())
        .flat_map(|h| (0..ranked.len()).map(move |m| (h, m)))
        .collect();
    let candidates: Vec<&Candidate> = halves
        .iter()
        .map(|h| &h.scored.fit.candidate)
        .chain(ranked.iter().map(|s| &s.fit.candidate))
        .collect();
    let wanted = crate::decide::pairs::wanted_for(&candidates, params);
    let jobs = cx.options.jobs;
    *replays += wanted.len();
    progress(&format!(
        "{} named effects that may be half of the departure, each with {} written candidates",
        halves.len(),
        ranked.len()
    ));
    let sensitivities = wanted.taken(problem, &r.current, jobs, "named pairs", &None);
    let shared = |name: &'static str| sensitivities.get(name);
    let fits: Vec<Option<Fit>> = parallel_map(&pairs, jobs, |&(h, m)| {
        let pair = crate::decide::pairs::joined(&halves[h].scored.fit.candidate, &ranked[m].fit.candidate);
        problem
            .fit(&pair, PAIR_ITERATIONS, &r.current, &shared)
            .ok()
            .map(Fit::without_prediction)
    });
    *replays += fits.iter().flatten().map(|f| f.replays).sum::<usize>();
    let score = |f: &Fit| f.heldout_total() + f.values.len() as f64 * penalty;
    let Some((k, fit)) = fits
        .iter()
        .enumerate()
        .filter_map(|(k, f)| f.as_ref().map(|f| (k, f)))
        .min_by(|a, b| score(a.1).total_cmp(&score(b.1)))
    else {
        return Ok(None);
    };
    let (h, m) = pairs[k];
    let half = halves.into_iter().nth(h).expect("a pair's half");
    let named = &half.scored.fit.candidate;
    let member = &ranked[m].fit.candidate;
    let name = named.named.expect("a named candidate");
    progress(&format!(
        "  {name} with the {} ({}) beside it: penalised held-out misfit {:.0} against the best single candidate's {single_score:.0}",
        member.label,
        member.location,
        score(fit)
    ));
    let (named_values, member_values) = fit.values.split_at(named.terms.len());
    let mut with_named = half.scored.clone();
    with_named.fit.values = named_values.to_vec();
    let mut trial = params.clone();
    if apply_named(&mut trial, &with_named).is_err() {
        return Ok(None);
    }
    let Some(set) = crate::decide::discover::model_terms(member, member_values, params, problem) else {
        return Ok(None);
    };
    if set.iter().any(|(n, v)| set_parameter(&mut trial, n, *v).is_err()) || trial.validate().is_err() {
        return Ok(None);
    }
    let used = fit.values.len() as f64;
    let judged = crate::decide::pairs::Replayed::judge(cx, problem, &trial, &r.heldout, replays)?;
    progress(&format!(
        "  the two in the model: force held-out {:.4} -> {:.4} N, misfit {:.0} + penalty {:.0} against {single_score:.0}",
        r.force_before,
        judged.after,
        judged.misfit,
        used * penalty
    ));
    // A name that alone falls short is claimed only where its other half closes the
    // departure: beside a remainder, the term may be a passenger of the named effect (a gas
    // temperature 2.5 % low rode in beside a friction that a force sensor's filter, found
    // next, left at the noise by itself).
    let within = (0..CHANNELS)
        .filter(|&c| problem.weights[c] > 0.0)
        .all(|c| judged.heldout[c] <= EXPLAINED_WITHIN_NOISE.powi(2) * count);
    if !within || !judged.earns(used * penalty, single_score, r.force_before, cx.noise) {
        return Ok(None);
    }
    // Each half earns its own penalty against the other alone.
    let mut named_alone = params.clone();
    let mut term_alone = params.clone();
    let Some(term_set) = crate::decide::discover::model_terms(member, &ranked[m].fit.values, params, problem) else {
        return Ok(None);
    };
    if apply_named(&mut named_alone, &half.scored).is_err()
        || term_set
            .iter()
            .any(|(n, v)| set_parameter(&mut term_alone, n, *v).is_err())
        || named_alone.validate().is_err()
        || term_alone.validate().is_err()
    {
        return Ok(None);
    }
    for (alone, other, own) in [
        (&named_alone, name, member.terms.len()),
        (&term_alone, member.label, named.terms.len()),
    ] {
        let (misfit_alone, _) = crate::decide::alternatives::judge(cx, problem, alone, replays)?;
        progress(&format!(
            "  the {other} alone leaves {misfit_alone:.0}: the other earns {:.0} against its penalty {:.0}",
            misfit_alone - judged.misfit,
            own as f64 * penalty
        ));
        if misfit_alone - judged.misfit <= own as f64 * penalty {
            return Ok(None);
        }
    }
    progress(&format!(
        "adding {name} with the {} at the {} beside it",
        member.label, member.location
    ));
    let term = DiscoveredTerm::fitted(member, set, params, r.force_before, judged.after);
    let sentence = format!(
        "{}alone it {}, and fitted together with the {} at the {} beside it (the other half of the departure) the held-out force error goes to {:.4} N",
        if half.sentence.is_empty() { String::new() } else { format!("{}; ", half.sentence) },
        half.shortfall,
        member.label, member.location, judged.after
    );
    with_named.force_heldout_rms = judged.after;
    Ok(Some((with_named, sentence, term, trial)))
}

/// Gauss–Newton iterations of each named effect and term fitted together.
const PAIR_ITERATIONS: usize = 2;

/// The share that a candidate leaving the held-out misfit `after` (per channel, noise
/// floors squared summed over `count` samples) takes of what it could take from `before`:
/// the misfit above the noise (one floor squared a sample) of the channels it moves. Where a
/// departure left for a later round is a few noise floors, the noise is half the misfit or
/// more (a command delay of 0.5 ms beside a friction took 92 % of what was above the noise,
/// 52 % of the misfit); a friction does not move the pressures, where a transducer's delay
/// held a third of the misfit beside it.
pub(crate) fn share_of_reach(
    before: &[f64; CHANNELS],
    after: &[f64; CHANNELS],
    weights: &[f64; CHANNELS],
    count: f64,
) -> f64 {
    let moved = |c: usize| weights[c] > 0.0 && (after[c] - before[c]).abs() > 1e-6 * before[c];
    let (mut above_noise, mut taken) = (0.0, 0.0);
    for c in (0..CHANNELS).filter(|&c| moved(c)) {
        above_noise += (before[c] - count).max(0.0);
        taken += before[c] - after[c];
    }
    if above_noise <= 0.0 {
        return 0.0;
    }
    (taken / above_noise).min(1.0)
}

/// The force against the measured pressures (the force the mechanics make of them) and where
/// the mechanics' and the force sensor's candidates place its departure: a second effect
/// there shows even while a larger one upstream dominates the misfit.
pub(crate) struct Downstream<'a> {
    problem: Problem<'a>,
    /// Held-out misfit of the force against the pressures, per channel (force only).
    misfit: [f64; CHANNELS],
    side: Localization,
}

/// [`Downstream`] of the round, when the force departs from the pressures beyond the noise.
/// (With the pressures within their noise the round's candidates were these already.)
pub(crate) fn downstream<'a>(
    cx: &'a Context,
    r: &Round,
    params: &'a Parameters,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Option<Downstream<'a>> {
    let through = force_through_mechanics(&r.model, cx.recording)?;
    let problem = Problem::new(cx.recording, params, &cx.blocks, [cx.mechanical_noise, 0.0, 0.0]);
    let (_, misfit) = problem.errors(&[through.force.clone(), vec![], vec![]]);
    if (misfit[FORCE] / r.count).sqrt() <= EXPLAINED_WITHIN_NOISE {
        return None;
    }
    let near: Vec<Candidate> = r
        .candidates
        .iter()
        .filter(|c| matches!(c.location, Place::Mechanics | Place::ForceSensor))
        .cloned()
        .collect();
    progress("the force departs from the pressures too: the mechanics and the force sensor on their own");
    let (side, used) = localize(&problem, &through, &near, cx.options, None, progress);
    *replays += used;
    Some(Downstream { problem, misfit, side })
}

/// The named effect at the mechanics or the force sensor that earns its name on the force
/// against the pressures. Judged on the replay.
pub(crate) fn named_downstream(
    cx: &Context,
    r: &Round,
    params: &Parameters,
    discovered: &[DiscoveredTerm],
    d: &Downstream,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(Scored, String)>, String> {
    let (recording, count, force_before, noise) = (cx.recording, r.count, r.force_before, cx.noise);
    let side = &d.side;
    let side_share = side.best_at(side.location).map_or(0.0, |s| s.explained);
    let mut named: Vec<&Scored> = side
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.location == side.location)
        .filter(|s| nameable(s, discovered))
        .collect();
    named.sort_by(|a, b| penalised(a, count).total_cmp(&penalised(b, count)));
    for s in named {
        let name = s.fit.candidate.named.expect("filtered on named");
        let mut trial = params.clone();
        if apply_named(&mut trial, s).is_err() {
            continue;
        }
        let with = replay_fast(&Actuator::new(trial)?, recording, cx.n)?;
        *replays += 1;
        let after = rms_where(&difference(&recording.force, &with.force), &cx.blocks, Block::HeldOut);
        let gain = force_before - after;
        let share_ok = s.explained >= NAMED_SHARE_OF_PLACE * side_share
            && share_of_reach(&d.misfit, &s.fit.heldout, &d.problem.weights, count) >= NAMED_MIN_SHARE;
        let gain_ok = worth_adding(force_before, force_before - gain, noise, false);
        let test = named_signature(
            name,
            recording,
            &r.model,
            &r.current,
            &with.force,
            &cx.blocks,
            noise,
            cx.mechanical_noise,
        );
        progress(&format!(
            "  {name}: explains {:.1} % of the force against the pressures, force held-out {force_before:.4} -> {after:.4} N, signature {}",
            100.0 * s.explained,
            if test.present { "present" } else { "absent" }
        ));
        if share_ok && gain_ok && test.present {
            let mut s = s.clone();
            s.force_heldout_rms = after;
            s.fit.prediction[FORCE] = with.force;
            return Ok(Some((s, test.sentence)));
        }
    }
    Ok(None)
}

/// A term outside the named effects at the mechanics or the force sensor, fitted on the force
/// against the pressures, where nothing else was added this round: a transducer's curve
/// beside a larger departure upstream that no candidate there explains alone (beside dead
/// volumes, a force transducer saturating at 105 N explained 97 % of the force against the
/// pressures and 42 % of the whole misfit, and nothing was added). Kept as every discovered
/// term is: the model with it replayed, the held-out misfit lower by more than its
/// parameters' penalty, the force error down, no pressure worse.
#[allow(clippy::too_many_arguments)]
pub(crate) fn discovered_downstream(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    params: &Parameters,
    d: &Downstream,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(DiscoveredTerm, Parameters)>, String> {
    let side = &d.side;
    if side.location == Place::Unknown {
        return Ok(None);
    }
    let mut unnamed: Vec<&Scored> = side
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.location == side.location && s.fit.candidate.named.is_none())
        .filter(|s| s.explained >= LOCATED_SHARE)
        .collect();
    unnamed.sort_by(|a, b| discovery_penalised(a, r.count).total_cmp(&discovery_penalised(b, r.count)));
    unnamed.truncate(DISCOVERY_TRIALS);
    let penalty_per_term = discovery_penalty_per_term(r.count);
    for s in unnamed {
        let candidate = &s.fit.candidate;
        let Some(mut set) = crate::decide::discover::model_terms(candidate, &s.fit.values, params, &d.problem) else {
            continue;
        };
        crate::decide::findings::curve_corners_across_unvisited(cx, r, problem, params, candidate, &mut set);
        let mut trial = params.clone();
        if set.iter().any(|(n, v)| set_parameter(&mut trial, n, *v).is_err()) || trial.validate().is_err() {
            continue;
        }
        let judged = crate::decide::pairs::Replayed::judge(cx, problem, &trial, &r.heldout, replays)?;
        progress(&format!(
            "  {} ({}), fitted on the force against the pressures: force held-out {:.4} -> {:.4} N",
            candidate.label, candidate.location, r.force_before, judged.after
        ));
        if !judged.earns(
            used_terms(s) * penalty_per_term,
            f64::INFINITY,
            r.force_before,
            cx.noise,
        ) {
            continue;
        }
        progress(&format!(
            "adding the {} at the {}, found on the force against the pressures",
            candidate.label, candidate.location
        ));
        let mut term = DiscoveredTerm::fitted(candidate, set, params, r.force_before, judged.after);
        // Its ties are those of the force against the pressures: the whole misfit's places
        // are upstream of them, not alternatives to it.
        term.tied_locations = side.tied_with(candidate.location);
        let undecided = side
            .undecided_beside(candidate.location, true)
            .map_or(String::new(), |clause| format!("; {clause}"));
        term.reading = format!(
            "{}; found on the force against the measured pressures, beside a departure upstream of them{undecided}.",
            term.reading.trim_end_matches('.')
        );
        return Ok(Some((term, trial)));
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_named_share_counts_what_is_above_the_noise_in_the_channels_the_candidate_moves() {
        let (all, count) = ([1.0; CHANNELS], 1000.0);
        // 1.5 floors of force and 1.4 of each pressure: half of it is noise. Taking the
        // channels to their noise takes all that could be taken, half the misfit.
        let before = [2250.0, 1960.0, 1960.0];
        assert!((share_of_reach(&before, &[1000.0; CHANNELS], &all, count) - 1.0).abs() < 1e-12);
        let halfway = [1625.0, 1480.0, 1480.0];
        assert!((share_of_reach(&before, &halfway, &all, count) - 0.5).abs() < 1e-12);
        // A force-side term leaves the pressures exactly: their departure is not its to take.
        let before = [4000.0, 3000.0, 1000.0];
        assert!((share_of_reach(&before, &[1000.0, 3000.0, 1000.0], &all, count) - 1.0).abs() < 1e-12);
        assert!((share_of_reach(&before, &[2500.0, 3000.0, 1000.0], &all, count) - 0.5).abs() < 1e-12);
        // Nothing above the noise: nothing to take.
        assert_eq!(share_of_reach(&[900.0; CHANNELS], &[800.0; CHANNELS], &all, count), 0.0);
    }
}
