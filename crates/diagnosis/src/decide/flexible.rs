//! The last resort of the rounds: where the readable terms leave a channel above its bar, a
//! flexible term ([`crate::candidates::flexible`]) at the place whose surface fits best, one
//! slot at a time, while a channel stays above its bar and the term earns its coefficients on
//! the held-out blocks. A readable candidate of the last localization whose held-out misfit
//! is within [`READABLE_WINS_WITHIN`] of the flexible term's wins: no flexible term then.

use crate::candidates::flexible::{self, free_slots, Surface, TARGETS};
use crate::candidates::set_parameter;
use crate::context::Context;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::findings::{Findings, Stage};
use crate::fit::localize::{discovery_penalty_per_term, heldout_count, terms_used};
use crate::fit::{Fit, Problem, Sensitivity};
use crate::input::blocks::Block;
use crate::policy::{EXPLAINED_WITHIN_NOISE, FLEXIBLE_FITTED, FLEXIBLE_ITERATIONS, READABLE_WINS_WITHIN};
use crate::replay::replay_fast;
use crate::replay::signals::{difference, rms_where, CHANNELS, FORCE, P1, P2};
use crate::replay::Replay;
use crate::vocabulary::Place;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// The held-out misfit of each measured channel, in noise floors (RMS over the held-out
/// samples), of a prediction.
fn misfits(problem: &Problem, prediction: &[Vec<f64>; CHANNELS], count: f64) -> Vec<f64> {
    let (_, heldout) = problem.errors(prediction);
    (0..CHANNELS)
        .filter(|&c| problem.weights[c] > 0.0)
        .map(|c| (heldout[c] / count).sqrt())
        .collect()
}

/// Add flexible terms while a channel stays above its bar and one earns its place.
pub(crate) fn close_with_flexible(
    cx: &Context,
    f: &mut Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<(), String> {
    let count = heldout_count(&cx.blocks) as f64;
    if count == 0.0 {
        return Ok(());
    }
    let unexplained = {
        let problem = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
        let current = replay_fast(&Actuator::new(f.params.clone())?, cx.recording, cx.n)?;
        *replays += 1;
        let prediction = [current.force.clone(), current.p1.clone(), current.p2.clone()];
        misfits(&problem, &prediction, count)
            .iter()
            .any(|m| *m > EXPLAINED_WITHIN_NOISE)
    };
    // Once a flexible term replaced the discovered terms, the last localization's readable
    // candidates were fitted to another model: their misfits no longer compare.
    let mut localization_stale = false;
    if unexplained {
        localization_stale = in_place_of_discovered(cx, f, count, replays, progress)?;
    }
    while let Some(&slot) = free_slots(&f.params).first() {
        let problem = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
        let current = replay_fast(&Actuator::new(f.params.clone())?, cx.recording, cx.n)?;
        *replays += 1;
        let prediction = [current.force.clone(), current.p1.clone(), current.p2.clone()];
        let before = misfits(&problem, &prediction, count);
        if before.iter().all(|m| *m <= EXPLAINED_WITHIN_NOISE) {
            break;
        }
        progress(&format!(
            "a flexible term, where the readable ones leave {} noise floors",
            before.iter().map(|m| format!("{m:.2}")).collect::<Vec<_>>().join(", ")
        ));
        let Some((fit, surface)) = best_surface(cx, &problem, &current, slot, count, replays, progress)? else {
            progress("  no flexible term earns its coefficients");
            break;
        };
        let after = misfits(&problem, &fit.prediction, count);
        let flexible_rms = (fit.heldout_total() / count).sqrt();
        let readable = nearest_readable(f, surface.place).filter(|_| !localization_stale);
        if let Some((label, readable_total)) = readable {
            let readable_rms = (readable_total / count).sqrt();
            if readable_rms <= READABLE_WINS_WITHIN * flexible_rms {
                progress(&format!(
                    "  the {label} leaves {readable_rms:.2} noise floors against the flexible term's {flexible_rms:.2}: the readable form stands"
                ));
                break;
            }
        }
        let (term, trial) = flexible_term(cx, &f.params, &fit, &current, readable, count)?;
        progress(&format!(
            "  added: the {} ({} noise floors after)",
            fit.candidate.label,
            after.iter().map(|m| format!("{m:.2}")).collect::<Vec<_>>().join(", ")
        ));
        f.discovered.push(term);
        f.newest = Some((false, f.discovered.len() - 1));
        f.params = trial;
        f.stages.push(Stage::of(f));
    }
    Ok(())
}

/// The fitted flexible `fit` as a discovered term on `base` (whose replay is `current`), and
/// the parameters with it.
fn flexible_term(
    cx: &Context,
    base: &Parameters,
    fit: &Fit,
    current: &Replay,
    readable: Option<(&'static str, f64)>,
    count: f64,
) -> Result<(DiscoveredTerm, Parameters), String> {
    let flexible_rms = (fit.heldout_total() / count).sqrt();
    let mut trial = base.clone();
    let mut set: Vec<(&'static str, f64)> = fit.candidate.settings.clone();
    set.extend(fit.candidate.terms.iter().zip(&fit.values).map(|(t, v)| (t.name, *v)));
    for &(name, value) in &set {
        set_parameter(&mut trial, name, value)?;
    }
    trial.validate()?;
    let force_before = rms_where(
        &difference(&cx.recording.force, &current.force),
        &cx.blocks,
        Block::HeldOut,
    );
    let force_after = rms_where(
        &difference(&cx.recording.force, &fit.prediction[FORCE]),
        &cx.blocks,
        Block::HeldOut,
    );
    let mut term = DiscoveredTerm::fitted(&fit.candidate, set, base, force_before, force_after);
    if let (Some(p1), Some(p2)) = (&cx.recording.p1, &cx.recording.p2) {
        let rms =
            |measured: &[f64], modelled: &[f64]| rms_where(&difference(measured, modelled), &cx.blocks, Block::HeldOut);
        term.pressures_heldout = Some((
            [rms(p1, &current.p1), rms(p2, &current.p2)],
            [rms(p1, &fit.prediction[P1]), rms(p2, &fit.prediction[P2])],
        ));
    }
    term.flexible = Some(flexible::Nearest {
        readable: readable.map(|(label, total)| (label, (total / count).sqrt())),
        flexible_noise_floors: flexible_rms,
    });
    Ok((term, trial))
}

/// A flexible term in place of every discovered term: fitted to what they were added for, on
/// the model without them (named effects kept), and taken when its penalised held-out misfit
/// is below the discovered terms' (each amount they fitted charged the same penalty). A
/// readable term fitted first may take a share of a departure that one surface holds whole, and
/// a surface fitted beside it only the leftover's.
fn in_place_of_discovered(
    cx: &Context,
    f: &mut Findings,
    count: f64,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<bool, String> {
    if f.discovered.is_empty() {
        return Ok(false);
    }
    let added: Vec<(&'static str, f64)> = f.discovered.iter().flat_map(|d| d.parameters.iter().copied()).collect();
    let Ok(without) = crate::candidates::without_addition(&f.params, &f.start, &added) else {
        return Ok(false);
    };
    let Some(&slot) = free_slots(&without).first() else {
        return Ok(false);
    };
    let penalty = discovery_penalty_per_term(count);
    let amounts = added
        .iter()
        .filter(|(name, _)| crate::fit::refit::refittable(name))
        .count() as f64;
    let now = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
    let current = replay_fast(&Actuator::new(f.params.clone())?, cx.recording, cx.n)?;
    let (_, heldout) = now.errors(&[current.force.clone(), current.p1.clone(), current.p2.clone()]);
    let discovered_penalised = heldout.iter().sum::<f64>() + amounts * penalty;
    let problem = Problem::new(cx.recording, &without, &cx.blocks, cx.channel_noise);
    let bare = replay_fast(&Actuator::new(without.clone())?, cx.recording, cx.n)?;
    *replays += 2;
    progress("a flexible term in place of the discovered terms");
    let Some((fit, surface)) = best_surface(cx, &problem, &bare, slot, count, replays, progress)? else {
        return Ok(false);
    };
    let penalised = fit.heldout_total() + terms_used(&fit) * penalty;
    if penalised >= discovered_penalised {
        progress(&format!(
            "  the discovered terms stand: {discovered_penalised:.0} against {penalised:.0} (noise floors squared, with penalties)"
        ));
        return Ok(false);
    }
    let readable = nearest_readable(f, surface.place);
    let (term, trial) = flexible_term(cx, &without, &fit, &bare, readable, count)?;
    progress(&format!(
        "  the {} replaces {}: {penalised:.0} against {discovered_penalised:.0} (noise floors squared, with penalties)",
        fit.candidate.label,
        f.discovered
            .iter()
            .map(|d| d.candidate)
            .collect::<Vec<_>>()
            .join(" and ")
    ));
    f.discovered = vec![term];
    f.newest = Some((false, 0));
    f.params = trial;
    f.joint_refit = None;
    f.stages.push(Stage::of(f));
    Ok(true)
}

/// The best readable candidate of the last localization, at `place` or anywhere, with its
/// held-out misfit (noise floors squared, summed over the samples and channels).
fn nearest_readable(f: &Findings, place: Place) -> Option<(&'static str, f64)> {
    let l = f.localization.as_ref()?;
    let best = l
        .best_at(place)
        .or_else(|| l.candidates.iter().max_by(|a, b| a.explained.total_cmp(&b.explained)))?;
    Some((best.fit.candidate.label, best.fit.heldout_total()))
}

/// Screen every place's surfaces, fit the leading ones through the model, and keep the one
/// with the lowest penalised held-out misfit if it beats the current model's.
fn best_surface(
    cx: &Context,
    problem: &Problem,
    current: &Replay,
    slot: usize,
    count: f64,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(Fit, Surface)>, String> {
    let with_pressures = cx.recording.p1.is_some() && cx.recording.p2.is_some();
    let targets: Vec<(Place, &'static str)> = TARGETS
        .iter()
        .filter_map(|name| jetpipe_model::variables::VARIABLES.iter().find(|v| v.name == *name))
        .map(|v| (crate::candidates::modulation::place_of(v.name), v.name))
        .filter(|(place, _)| with_pressures || *place != Place::PressureSensors)
        .collect();
    let jobs = cx.options.jobs;
    let sensitivities: Vec<Option<(Place, &'static str, Sensitivity)>> =
        crate::parallel::parallel_map(&targets, jobs, |&(place, name)| {
            let step = crate::candidates::modulation::sensitivity_step(name, problem.base, &[]);
            problem.sensitivity(name, step, current).map(|s| (place, name, s))
        });
    *replays += targets.len();
    let sensitivities: Vec<(Place, &'static str, Sensitivity)> = sensitivities.into_iter().flatten().collect();
    let penalty = discovery_penalty_per_term(count);
    let surfaces =
        crate::fit::flexible_screen::screen(problem, current, &sensitivities, penalty, FLEXIBLE_FITTED, jobs);
    let start_total: f64 = {
        let (_, heldout) = problem.errors(&[current.force.clone(), current.p1.clone(), current.p2.clone()]);
        heldout.iter().sum()
    };
    problem.set_jobs(jobs);
    let mut best: Option<(Fit, Surface, f64)> = None;
    for surface in surfaces {
        let candidate = flexible::candidate(&surface, slot, problem.base, &[]);
        let fit = match problem.fit(&candidate, FLEXIBLE_ITERATIONS, current, &|_| None) {
            Ok(fit) => fit,
            Err(_) => continue,
        };
        *replays += fit.replays;
        let penalised = fit.heldout_total() + terms_used(&fit) * penalty;
        progress(&format!(
            "  the {}: screened {:.0}, fitted {:.0} + penalty {:.0} against {:.0} (noise floors squared)",
            candidate.label,
            surface.penalised,
            fit.heldout_total(),
            terms_used(&fit) * penalty,
            start_total
        ));
        if penalised < start_total && best.as_ref().map_or(true, |b| penalised < b.2) {
            best = Some((fit, surface, penalised));
        }
    }
    Ok(best.map(|(fit, surface, _)| (fit, surface)))
}
