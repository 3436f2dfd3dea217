//! A discovered term at the located place, when no named effect fits there: the place's best
//! candidates that the FMU can carry, each replayed and kept only where it earns its place,
//! and a written term preferred to a generated one that does barely better.

use crate::candidates::set_parameter;
use crate::context::Context;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::findings::carried_alike;
use crate::decide::findings::curve_corners_across_unvisited;
use crate::decide::findings::pressures_judgement;
use crate::decide::findings::unclaimed;
use crate::decide::findings::Round;
use crate::fit::localize::discovery_penalised;
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::used_terms;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::policy::worth_adding;
use crate::policy::DISCOVERY_TRIALS;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::policy::LOCATED_SHARE;
use crate::policy::PROMISE_BEYOND_WRITTEN;
use crate::policy::REFINE_ITERATIONS;
use crate::policy::TRAINING_GAIN_IN_NOISE;
use crate::policy::WRITTEN_INSTEAD_WITHIN;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use crate::vocabulary::Place;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// No named effect fits: the place's own best candidates that the FMU can carry, each kept
/// only if the model with it (replayed, not predicted) is better on the held-out blocks by
/// more than a noise floor and by more than its parameters' BIC penalty, and no pressure
/// channel gets worse.
pub(crate) fn discover_term(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    found: &Localization,
    params: &Parameters,
    earlier: &[DiscoveredTerm],
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(DiscoveredTerm, Parameters, Scored)>, String> {
    let (count, noise) = (r.count, cx.noise);
    let at_place = trial_order(found, earlier, count, noise);
    let before_total: f64 = r.heldout.iter().sum();
    let training_before = rms_where(
        &difference(&cx.recording.force, &r.current.force),
        &cx.blocks,
        Block::Training,
    );
    let mut modulation: Option<(DiscoveredTerm, Parameters, Scored)> = None;
    let mut written_best: Option<(DiscoveredTerm, Parameters, Scored)> = None;
    for s in at_place {
        let label = s.fit.candidate.label;
        if let Some((w, _, _)) = &written_best {
            if s.force_heldout_rms > PROMISE_BEYOND_WRITTEN * w.heldout_after {
                continue;
            }
        }
        let judged = Judged {
            before_total,
            training_before,
        };
        let Some((term, trial)) = in_the_model(cx, r, problem, found, params, earlier, s, judged, replays, progress)?
        else {
            continue;
        };
        let after = term.heldout_after;
        let candidate = &s.fit.candidate;
        let is_modulation = crate::candidates::modulation::is_modulation(candidate);
        match &modulation {
            None if is_modulation => {
                progress(&format!(
                    "  {label}: kept unless a written candidate does nearly as well in the model"
                ));
                modulation = Some((term, trial, s.clone()));
            }
            None if after <= EXPLAINED_WITHIN_NOISE * noise => return Ok(Some((term, trial, s.clone()))),
            None => {
                if written_best.as_ref().map_or(true, |(w, _, _)| after < w.heldout_after) {
                    progress(&format!(
                        "  {label}: kept unless a later trial, promising half of what it leaves, does better in the model"
                    ));
                    written_best = Some((term, trial, s.clone()));
                }
            }
            Some((kept, _, _)) if !is_modulation => {
                if after <= written_instead_bar(kept.heldout_after, noise) {
                    progress(&format!(
                        "  {label} instead of the {}: nearly as good and written",
                        kept.candidate
                    ));
                    return Ok(Some((term, trial, s.clone())));
                }
            }
            Some(_) => {}
        }
    }
    // A written term wins over a modulation that does not do clearly better in the model.
    Ok(match (written_best, modulation) {
        (Some(w), Some(m)) if w.0.heldout_after > written_instead_bar(m.0.heldout_after, noise) => Some(m),
        (Some(w), _) => Some(w),
        (None, m) => m,
    })
}

/// The order in which the located place's candidates are tried in the model: its own first,
/// then those of the places that explain nearly as much, then its written candidates that
/// the trials leave out, then the earlier terms' own candidates.
fn trial_order<'a>(found: &'a Localization, earlier: &[DiscoveredTerm], count: f64, noise: f64) -> Vec<&'a Scored> {
    // The located place's candidates first, then those of the places that explain nearly as
    // much: where the recording cannot tell places apart (a short lag anywhere before the jet
    // pipe reads as a delay under a slow sine) and the located place has no term to keep, the
    // best of the others is tried. Up to DISCOVERY_TRIALS of each.
    let tied = found.alternatives();
    let unnamed_at = |place: Place| -> Vec<&Scored> {
        let mut at: Vec<&Scored> = found
            .candidates
            .iter()
            .filter(|s| s.fit.candidate.location == place && unclaimed(s, earlier))
            .filter(|s| s.explained >= LOCATED_SHARE)
            .collect();
        // A modulation goes behind the written candidates at its place that leave nearly as
        // little, or that are adequate on their own (the force within the verdict's bar).
        let written: Vec<&&Scored> = at
            .iter()
            .filter(|s| !crate::candidates::modulation::is_modulation(&s.fit.candidate))
            .collect();
        let written_best = written
            .iter()
            .map(|s| s.fit.heldout_total())
            .fold(f64::INFINITY, f64::min);
        let written_adequate = written
            .iter()
            .any(|s| s.force_heldout_rms <= crate::policy::WRITTEN_ADEQUATE_WITHIN * noise);
        let behind = |s: &Scored| {
            crate::candidates::modulation::is_modulation(&s.fit.candidate)
                && (written_adequate || written_best <= crate::policy::WRITTEN_FIRST_WITHIN * s.fit.heldout_total())
        };
        at.sort_by(|a, b| {
            behind(a)
                .cmp(&behind(b))
                .then(discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)))
        });
        at.truncate(DISCOVERY_TRIALS);
        at
    };
    let mut others: Vec<&Scored> = tied.iter().flat_map(|&place| unnamed_at(place)).collect();
    others.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    others.truncate(DISCOVERY_TRIALS);
    let mut at_place: Vec<&Scored> = unnamed_at(found.location).into_iter().chain(others).collect();
    // The written candidates at the place that the trials leave out, last: a modulation that
    // earns its place is added only when none of them does nearly as well in the model.
    let mut written: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.location == found.location && unclaimed(s, earlier))
        .filter(|s| s.explained >= LOCATED_SHARE && !crate::candidates::modulation::is_modulation(&s.fit.candidate))
        .filter(|s| !at_place.iter().any(|a| a.fit.candidate == s.fit.candidate))
        .collect();
    written.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    written.truncate(DISCOVERY_TRIALS);
    at_place.extend(written);
    // The earlier terms' own candidates, wherever the round located: their refit may be what
    // is left (a quadratic damping fitted 1 % short leaves 1.6 noise floors at 250 Hz).
    let refits: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| earlier.iter().any(|d| d.candidate == s.fit.candidate.label))
        .filter(|s| s.explained >= LOCATED_SHARE)
        .filter(|s| !at_place.iter().any(|a| a.fit.candidate == s.fit.candidate))
        .collect();
    at_place.extend(refits);
    at_place
}

/// The misfits a trial is judged against: the round's held-out total and its force's
/// training error.
#[derive(Clone, Copy)]
struct Judged {
    before_total: f64,
    training_before: f64,
}

/// One candidate put in the model: the term it adds and the parameters that carry it, when
/// it earns its penalty, keeps the pressures, fits the model's limits and, replayed, is worth
/// adding on the force or on the pressures.
#[allow(clippy::too_many_arguments)]
fn in_the_model(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    found: &Localization,
    params: &Parameters,
    earlier: &[DiscoveredTerm],
    s: &Scored,
    judged: Judged,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(DiscoveredTerm, Parameters)>, String> {
    let (recording, count, force_before, noise) = (cx.recording, r.count, r.force_before, cx.noise);
    let Judged {
        before_total,
        training_before,
    } = judged;
    let label = s.fit.candidate.label;
    let penalty = used_terms(s) * discovery_penalty_per_term(count);
    let worse_pressures =
        (1..CHANNELS).any(|c| problem.weights[c] > 0.0 && s.fit.heldout[c] > 1.05 * r.heldout[c] + count * 0.01);
    if worse_pressures || before_total - s.fit.heldout_total() < penalty {
        progress(&format!(
            "  {label}: not better than its parameters' penalty, or worse in a pressure"
        ));
        return Ok(None);
    }
    if crate::candidates::modulation::is_modulation(&s.fit.candidate)
        && crate::candidates::modulation::is_flat(&s.fit.values)
    {
        progress(&format!(
            "  {label}: the same change at every knot, a constant's own candidate carries it"
        ));
        return Ok(None);
    }
    let Some(mut set) = crate::decide::discover::model_terms(&s.fit.candidate, &s.fit.values, params, problem) else {
        progress(&format!("  {label}: the FMU has no parameters for it"));
        return Ok(None);
    };
    if crate::candidates::curves::is_command_curve(&s.fit.candidate) {
        set = command_curve_knots_freed(cx, problem, params, set, replays, progress);
    }
    curve_corners_across_unvisited(cx, r, problem, params, &s.fit.candidate, &mut set);
    let mut trial = params.clone();
    if set
        .iter()
        .any(|(name, value)| set_parameter(&mut trial, name, *value).is_err())
        || trial.validate().is_err()
    {
        progress(&format!("  {label}: its parameters are outside the model's limits"));
        return Ok(None);
    }
    let with = replay_fast(&Actuator::new(trial.clone())?, recording, cx.n)?;
    *replays += 1;
    let residual = difference(&recording.force, &with.force);
    let after = rms_where(&residual, &cx.blocks, Block::HeldOut);
    progress(&format!(
        "  {label}: in the model, force held-out {force_before:.4} -> {after:.4} N"
    ));
    let refines = earlier.iter().any(|d| carried_alike(d, label, &set));
    let training_after = rms_where(&residual, &cx.blocks, Block::Training);
    let force_ok = worth_adding(force_before, after, noise, refines)
        || shown_mostly_where_fitted(force_before, after, training_before - training_after, noise);
    // A term on the pressure transducers is judged on the pressures; so is one upstream
    // of the piston whose departure shows in the pressures more than in the force (a
    // stopper position 1 mm off leaves 2 noise floors in the force, 9 in the pressures).
    let pressures = if s.fit.candidate.location == Place::PressureSensors || (!force_ok && cx.pressure_noise.is_some())
    {
        pressures_judgement(cx, r, problem, &with, after, progress, label)
    } else {
        None
    };
    if pressures.is_some() || force_ok {
        let candidate = &s.fit.candidate;
        progress(&format!("adding a {} at the {}", candidate.label, candidate.location));
        let term = DiscoveredTerm {
            location: candidate.location,
            family: crate::candidates::curve_reading::family(candidate.family, &set),
            candidate: candidate.label,
            reading: with_undecided(
                crate::decide::discover::reading(candidate.label, candidate.location, candidate.family, &set, params),
                found.undecided_beside(candidate.location, cx.pressure_noise.is_some()),
            ),
            parameters: set,
            heldout_before: force_before,
            heldout_after: after,
            share: 1.0 - (after / force_before).powi(2),
            pressures_heldout: pressures,
            tied_locations: found.tied_with(candidate.location),
            intervals: vec![],
            margin: None,
            flexible: None,
        };
        return Ok(Some((term, trial)));
    }
    Ok(None)
}

/// The held-out force error (N) at or below which a written term is taken instead of a
/// modulation that leaves `modulation_after`: within [`WRITTEN_INSTEAD_WITHIN`] of it, or
/// within the verdict's bar.
pub(crate) fn written_instead_bar(modulation_after: f64, noise: f64) -> f64 {
    (EXPLAINED_WITHIN_NOISE * noise).max(WRITTEN_INSTEAD_WITHIN * modulation_after)
}

/// Whether a term earns its place on a departure that the training blocks hold more of than
/// the held-out ones (a command saturating near the top of a slow sine whose peaks fell in
/// training blocks: 16 noise floors there, 3.7 held out). It must lower the training error by
/// [`TRAINING_GAIN_IN_NOISE`] floors of RMS, which no fit of a few parameters takes from
/// noise, and the held-out error as a refit must ([`worth_adding`]): by a tenth, and by a
/// noise floor squared of its mean square.
pub(crate) fn shown_mostly_where_fitted(
    heldout_before: f64,
    heldout_after: f64,
    training_gain: f64,
    noise: f64,
) -> bool {
    training_gain >= TRAINING_GAIN_IN_NOISE * noise && worth_adding(heldout_before, heldout_after, noise, true)
}

/// Whether `term` is a static function of the command at a place of its path, its ties (if
/// any) among those places: the places the path makes alike replace them.
pub(crate) fn is_along_the_command_path(term: &DiscoveredTerm) -> bool {
    use crate::candidates::command_path::{acts_alike_along_the_command_path, COMMAND_PATH};
    COMMAND_PATH.contains(&term.location)
        && acts_alike_along_the_command_path(&term.parameters)
        && term.tied_locations.iter().all(|l| COMMAND_PATH.contains(l))
}

/// A discovered term's `reading` (one sentence) with the places it cannot be told apart from.
pub(crate) fn with_undecided(reading: String, undecided: Option<String>) -> String {
    match undecided {
        Some(clause) => format!("{}; {clause}.", reading.trim_end_matches('.')),
        None => reading,
    }
}

/// The command's curve `set` refitted with its interior knots free
/// (`crate::candidates::command_curve::command_curve_with_free_knots`), made non-decreasing again, kept when the
/// model with it fits the training samples better than with `set`.
pub(crate) fn command_curve_knots_freed(
    cx: &Context,
    problem: &Problem,
    params: &Parameters,
    set: Vec<(&'static str, f64)>,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Vec<(&'static str, f64)> {
    let Some(free) = crate::candidates::command_curve::command_curve_with_free_knots(&set) else {
        return set;
    };
    let replayed = |values: &[(&'static str, f64)]| -> Result<Replay, String> {
        let mut p = params.clone();
        for &(name, value) in values {
            set_parameter(&mut p, name, value)?;
        }
        replay_fast(&Actuator::new(p)?, cx.recording, cx.n)
    };
    let training_rms = |r: &Replay| rms_where(&difference(&cx.recording.force, &r.force), &cx.blocks, Block::Training);
    // A set the model refuses is left for the caller's checks to turn down.
    let Ok(start) = replayed(&set) else {
        return set;
    };
    *replays += 1;
    let Ok(fit) = problem.fit_damped(&free, REFINE_ITERATIONS, &start, &|_| None) else {
        return set;
    };
    *replays += fit.replays;
    let mut freed = set.clone();
    for (term, &value) in free.terms.iter().zip(&fit.values) {
        if let Some(entry) = freed.iter_mut().find(|(n, _)| *n == term.name) {
            entry.1 = value;
        }
    }
    crate::candidates::command_curve::monotone_command(&mut freed);
    let Ok(with) = replayed(&freed) else {
        return set;
    };
    *replays += 1;
    let (before, after) = (training_rms(&start), training_rms(&with));
    progress(&format!(
        "  command static curve, its knots freed: force on the training blocks {before:.4} -> {after:.4} N"
    ));
    let (chosen, replay) = if after < before { (freed, with) } else { (set, start) };
    // Stretches of commands no training block holds are joined from their neighbours' lines
    // where the held-out blocks agree.
    let mut training: Vec<f64> = (0..cx.recording.v_da.len())
        .filter(|&k| cx.blocks[k] == Block::Training && cx.recording.v_da[k].is_finite())
        .map(|k| cx.recording.v_da[k])
        .collect();
    training.sort_by(f64::total_cmp);
    let heldout_rms = |r: &Replay| rms_where(&difference(&cx.recording.force, &r.force), &cx.blocks, Block::HeldOut);
    let (joined, tried) = crate::candidates::command_gaps::joined_where_held_out_agrees(
        chosen.clone(),
        &training,
        heldout_rms(&replay),
        &mut |values| replayed(values).ok().map(|r| heldout_rms(&r)),
    );
    *replays += tried;
    if joined != chosen {
        progress("  command static curve: a stretch no training command holds joined from its neighbours' lines");
    }
    joined
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_term_that_takes_many_floors_off_the_training_blocks_needs_less_of_the_held_out_ones() {
        // In noise floors: a saturation met mostly in the training blocks, 3.7 → 3.0 held out
        // (0.7 of RMS, 4.7 of mean square) and 13 taken off the training blocks' RMS.
        assert!(!worth_adding(3.7, 3.0, 1.0, false));
        assert!(shown_mostly_where_fitted(3.7, 3.0, 13.0, 1.0));
        // Two floors off the training blocks could be a fit to their noise and the
        // reconstruction between samples: the held-out bar stays.
        assert!(!shown_mostly_where_fitted(3.7, 3.0, 2.0, 1.0));
        // Held out, it must still take a tenth and a floor squared of the mean square.
        assert!(!shown_mostly_where_fitted(3.7, 3.5, 13.0, 1.0));
        assert!(!shown_mostly_where_fitted(1.3, 1.0, 13.0, 1.0));
    }
}
