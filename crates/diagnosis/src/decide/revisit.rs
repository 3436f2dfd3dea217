//! Each addition again, with every other one in (backfitting). A round fits its candidates
//! beside what the earlier rounds added and beside whatever no round has found yet: with two
//! departures at once, the first round's candidates each take a share of both, and the one
//! that wins may be a stand-in that the joint refits only polish. So once the rounds stop with
//! a channel above its bar, each addition in turn is taken out (its parameters back at their
//! start values, as in `eliminate.rs`) and its round is run again from the model with every
//! other addition in, where the departure it was meant for stands alone. What that round adds
//! replaces the addition when the findings' held-out misfit, with the discovery penalty for
//! each parameter that departs from its start value, falls by more than one penalty.
//!
//! A revisit costs a round, the most costly step of a diagnosis: the earliest
//! [`REVISITED`] additions are revisited, those fitted beside the most that was still
//! unfound, and where the remainder sits is localized once after the last replacement.

use crate::candidates::parameter_value;
use crate::context::Context;
use crate::decide::eliminate::{additions, label_of, remove, without};
use crate::decide::findings::Findings;
use crate::decide::rounds::{one_round, RoundEnd};
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::heldout_count;
use crate::fit::Problem;
use crate::policy::MAX_EFFECTS;
use crate::policy::REVISITED;

/// The findings' held-out misfit (every channel, in noise floors squared) with the discovery
/// penalty for each of their parameters that departs from its start value, and the held-out
/// force error.
fn penalised(cx: &Context, f: &Findings, replays: &mut usize) -> Result<(f64, f64), String> {
    let problem = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
    let (misfit, force) = crate::decide::alternatives::judge(cx, &problem, &f.params, replays)?;
    let mut names: Vec<&'static str> = f
        .effects
        .iter()
        .flat_map(|e| e.parameters.iter())
        .chain(f.discovered.iter().flat_map(|d| d.parameters.iter()))
        .map(|(name, _)| *name)
        .filter(|name| parameter_value(&f.params, name) != parameter_value(&f.start, name))
        .collect();
    names.sort_unstable();
    names.dedup();
    let penalty = discovery_penalty_per_term(heldout_count(&cx.blocks) as f64);
    Ok((misfit + names.len() as f64 * penalty, force))
}

/// The findings' additions, as (named, label), in the order the rounds added them: by the
/// first stage that holds each.
fn in_the_order_added(f: &Findings) -> Vec<(bool, &'static str)> {
    let mut order: Vec<(bool, &'static str)> = vec![];
    let stages = f.stages.iter().map(|s| (&s.effects, &s.discovered));
    for (effects, discovered) in stages.chain(std::iter::once((&f.effects, &f.discovered))) {
        let labels = effects
            .iter()
            .map(|e| (true, e.name))
            .chain(discovered.iter().map(|d| (false, d.candidate)));
        for label in labels {
            if !order.contains(&label) {
                order.push(label);
            }
        }
    }
    let now: Vec<(bool, &'static str)> = additions(f).into_iter().map(|w| (w.0, label_of(f, w))).collect();
    order.retain(|label| now.contains(label));
    order
}

/// Revisit the earliest [`REVISITED`] additions once each, earliest first (see the module's
/// account). Whether any was replaced; the findings are changed only by a replacement, made
/// whole.
pub(crate) fn revisit(
    cx: &Context,
    f: &mut Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<bool, String> {
    if f.localization.is_none() || additions(f).len() < 2 {
        return Ok(false);
    }
    let penalty = discovery_penalty_per_term(heldout_count(&cx.blocks) as f64);
    let (mut score, mut force) = penalised(cx, f, replays)?;
    let mut order = in_the_order_added(f);
    order.truncate(REVISITED);
    let mut replaced = false;
    for (named, label) in order {
        let Some(which) = additions(f)
            .into_iter()
            .find(|&w| w.0 == named && label_of(f, w) == label)
        else {
            continue;
        };
        let Some((params, _)) = without(f, which) else {
            continue;
        };
        progress(&format!(
            "revisiting the {label}: its round again with every other addition in"
        ));
        let mut trial = f.clone();
        trial.params = params;
        remove(&mut trial, which);
        trial.newest = None;
        trial.localization = None;
        let round = f.stages.len().clamp(1, MAX_EFFECTS - 1);
        if one_round(cx, &mut trial, round, true, replays, progress)? != RoundEnd::Added {
            progress(&format!("  nothing earns the {label}'s place: it stays"));
            continue;
        }
        let (trial_score, trial_force) = penalised(cx, &trial, replays)?;
        let now: Vec<&'static str> = additions(&trial).into_iter().map(|w| label_of(&trial, w)).collect();
        progress(&format!(
            "  with {}: penalised held-out misfit {trial_score:.0} against {score:.0} (noise floors squared, penalty {penalty:.0}), force {trial_force:.4} against {force:.4} N",
            now.join(", ")
        ));
        if trial_score < score - penalty {
            progress(&format!("  the {label} is replaced"));
            *f = trial;
            (score, force) = (trial_score, trial_force);
            replaced = true;
        }
    }
    if replaced {
        // Where the remainder now sits (nowhere, within the noise) is a round's to say.
        one_round(cx, f, MAX_EFFECTS, false, replays, progress)?;
    }
    Ok(replaced)
}
