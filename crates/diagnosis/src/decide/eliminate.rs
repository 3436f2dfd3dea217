//! The other half of a search that does not lock in: an effect or term added in an early
//! round may be made redundant by a later one (a named effect standing in for part of what a
//! later term explains exactly). After each addition every earlier one is taken out of the
//! model in turn, its parameters back at their values before the rounds; one whose removal
//! raises the held-out misfit (all channels, in noise floors squared) by less than its
//! parameters' discovery penalty, and the held-out force error by less than a tenth of the
//! noise floor, goes (backward elimination, the least missed first, one at a time).
//!
//! Once the search has ended and everything has been refitted together, each addition's
//! errors and share are recomputed from that joint fit: its held-out force error with
//! everything else and without it.

use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::context::Context;
use crate::decide::findings::Findings;
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::heldout_count;
use crate::fit::Problem;
use crate::policy::REDUNDANT_WITHIN_NOISE;
use jetpipe_model::physics::parameters::Parameters;

/// One addition of the findings: a named effect (`true`) or a discovered term, by index.
pub(crate) type Which = (bool, usize);

pub(crate) fn additions(f: &Findings) -> Vec<Which> {
    (0..f.effects.len())
        .map(|k| (true, k))
        .chain((0..f.discovered.len()).map(|k| (false, k)))
        .collect()
}

fn parameters_of(f: &Findings, which: Which) -> &[(&'static str, f64)] {
    match which {
        (true, k) => &f.effects[k].parameters,
        (false, k) => &f.discovered[k].parameters,
    }
}

pub(crate) fn label_of(f: &Findings, which: Which) -> &'static str {
    match which {
        (true, k) => f.effects[k].name,
        (false, k) => f.discovered[k].candidate,
    }
}

/// Take one addition out of the findings' lists (its parameters stay as they are).
pub(crate) fn remove(f: &mut Findings, which: Which) {
    match which {
        (true, k) => {
            f.effects.remove(k);
        }
        (false, k) => {
            f.discovered.remove(k);
        }
    }
}

/// The findings' model without one addition: its parameters that no other addition sets go
/// back to their values before the rounds. `None` when that model is not valid.
pub(crate) fn without(f: &Findings, which: Which) -> Option<(Parameters, usize)> {
    let others: Vec<&'static str> = additions(f)
        .into_iter()
        .filter(|w| *w != which)
        .flat_map(|w| parameters_of(f, w).iter().map(|(n, _)| *n))
        .collect();
    let mut trial = f.params.clone();
    let mut reset = 0;
    for (name, _) in parameters_of(f, which) {
        if others.contains(name) {
            continue;
        }
        set_parameter(&mut trial, name, parameter_value(&f.start, name)).ok()?;
        reset += 1;
    }
    if which.0 && f.effects[which.1].name == "piston_friction" {
        trial.friction_velocity = f.start.friction_velocity;
    }
    trial.validate().ok()?;
    Some((trial, reset))
}

/// Remove the additions that a later one has made redundant (see the module's account).
/// Whether any was removed.
pub(crate) fn drop_redundant(
    cx: &Context,
    f: &mut Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<bool, String> {
    let mut removed_any = false;
    loop {
        let all = additions(f);
        if all.len() < 2 {
            return Ok(removed_any);
        }
        let problem = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
        let count = heldout_count(&cx.blocks) as f64;
        let penalty = discovery_penalty_per_term(count);
        let (misfit, force) = crate::decide::alternatives::judge(cx, &problem, &f.params, replays)?;
        // The newest addition has just earned its place.
        let newest = f.newest;
        let mut least: Option<(f64, Which)> = None;
        for which in all.into_iter().filter(|w| Some(*w) != newest) {
            let Some((trial, reset)) = without(f, which) else {
                continue;
            };
            if reset == 0 {
                continue;
            }
            let (misfit_without, force_without) = crate::decide::alternatives::judge(cx, &problem, &trial, replays)?;
            let rise = misfit_without - misfit;
            progress(&format!(
                "  without the {}: held-out misfit {misfit:.0} -> {misfit_without:.0} (noise floors squared, penalty {:.0}), force {force:.4} -> {force_without:.4} N",
                label_of(f, which),
                reset as f64 * penalty
            ));
            let redundant = rise < reset as f64 * penalty && force_without - force < REDUNDANT_WITHIN_NOISE * cx.noise;
            if redundant && least.map_or(true, |(r, _)| rise < r) {
                least = Some((rise, which));
            }
        }
        let Some((_, which)) = least else {
            return Ok(removed_any);
        };
        let (trial, _) = without(f, which).expect("judged above");
        progress(&format!(
            "the {} is redundant after what was added later: removed",
            label_of(f, which)
        ));
        f.params = trial;
        remove(f, which);
        if let Some((named, k)) = f.newest {
            if named == which.0 && k > which.1 {
                f.newest = Some((named, k - 1));
            }
        }
        removed_any = true;
    }
}

/// After the joint refit: each addition's held-out force error before (everything else
/// in) and after (everything in), and its share of the mean square, from the jointly
/// refitted model.
pub(crate) fn attribute_from_joint_fit(
    cx: &Context,
    f: &mut Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<(), String> {
    let all = additions(f);
    if all.len() < 2 {
        return Ok(());
    }
    let problem = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
    let (_, after) = crate::decide::alternatives::judge(cx, &problem, &f.params, replays)?;
    progress("each addition's share, from the joint fit");
    for which in all {
        let Some((trial, _)) = without(f, which) else {
            continue;
        };
        let (_, before) = crate::decide::alternatives::judge(cx, &problem, &trial, replays)?;
        let share = if before > 0.0 {
            1.0 - (after / before).powi(2)
        } else {
            0.0
        };
        progress(&format!(
            "  {}: held-out force error {before:.4} N without it, {after:.4} N with it",
            label_of(f, which)
        ));
        match which {
            (true, k) => {
                let e = &mut f.effects[k];
                e.heldout_before = before;
                e.heldout_after = after;
                e.share = share;
            }
            (false, k) => {
                let d = &mut f.discovered[k];
                d.heldout_before = before;
                d.heldout_after = after;
                d.share = share;
            }
        }
    }
    Ok(())
}
