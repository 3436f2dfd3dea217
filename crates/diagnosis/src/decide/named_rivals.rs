//! Two named effects that one round could hardly tell apart. A round names the effect
//! that explains most of its place with the fewest parameters, judged beside whatever that
//! round has not found yet; a departure found later can favour the other. Without pressure
//! channels, heat exchange in the chambers explained 96.9 % of the first round's misfit and
//! the dead volumes 96.6 %, beside a command curve that a later round found: the one with
//! fewer parameters was named, and the truth was the other. So once every round is done,
//! each named effect's rivals (named effects at its place within [`RIVAL_SHARE_GAP`] of
//! its share when it was named) are fitted in its place with every other addition
//! refitted beside them: a rival better by more than one penalty takes its place; one
//! within a penalty either way leaves the two tied, which the report says.

use crate::candidates::catalogue;
use crate::candidates::parameter_value;
use crate::candidates::without_addition;
use crate::candidates::Candidate;
use crate::context::Context;
use crate::decide::additions::AddedEffect;
use crate::decide::findings::Findings;
use crate::decide::named_instead::{best_named_fit, refitted_beside};
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::heldout_count;
use crate::fit::scored::Scored;
use crate::fit::Problem;
use crate::policy::MOST_RIVALS;
use crate::policy::RIVAL_SHARE_GAP;
use crate::vocabulary::Place;
use jetpipe_model::physics::parameters::Parameters;

/// The named effects at `place` other than `name` whose share of the round's held-out misfit
/// is within [`RIVAL_SHARE_GAP`] of `explained`, most first.
pub(crate) fn rivals_of(
    name: &'static str,
    place: Place,
    explained: f64,
    candidates: &[Scored],
) -> Vec<(&'static str, f64)> {
    let mut rivals: Vec<(&'static str, f64)> = vec![];
    for s in candidates.iter().filter(|s| s.fit.candidate.location == place) {
        let Some(other) = s.fit.candidate.named else {
            continue;
        };
        if other == name || s.explained < explained - RIVAL_SHARE_GAP {
            continue;
        }
        match rivals.iter_mut().find(|(n, _)| *n == other) {
            Some(r) => r.1 = r.1.max(s.explained),
            None => rivals.push((other, s.explained)),
        }
    }
    rivals.sort_by(|a, b| b.1.total_cmp(&a.1));
    rivals.truncate(MOST_RIVALS);
    rivals
}

/// Try every named effect's rivals in its place; a rival that does better by more than a
/// penalty replaces it. Whether any was replaced.
pub(crate) fn settle_rivals(
    cx: &Context,
    f: &mut Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<bool, String> {
    let mut replaced = false;
    for k in 0..f.effects.len() {
        if f.effects[k].rivals.is_empty() {
            continue;
        }
        match rival_in_place_of(cx, f, k, replays, progress)? {
            Settled::Replaced(effect, params) => {
                progress(&format!("{} instead of the {}", effect.name, f.effects[k].name));
                f.params = *params;
                f.effects[k] = effect;
                crate::decide::findings::sync_earlier(f);
                replaced = true;
            }
            Settled::Tied(rival, sentence) => {
                let effect = &mut f.effects[k];
                effect.tied_effects = vec![effect.name, rival];
                effect.evidence = format!("{} {sentence}", effect.evidence);
            }
            Settled::Kept => {}
        }
    }
    Ok(replaced)
}

enum Settled {
    /// The rival, as added, and the model with it and every other addition refitted.
    Replaced(AddedEffect, Box<Parameters>),
    /// The rival the recording cannot tell from the named effect, and a sentence saying so.
    Tied(&'static str, String),
    Kept,
}

fn rival_in_place_of(
    cx: &Context,
    f: &Findings,
    k: usize,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Settled, String> {
    let effect = &f.effects[k];
    let rivals: Vec<Candidate> = catalogue(
        &f.params,
        cx.pressure_noise.is_some(),
        None,
        &crate::candidates::curves::CurveKnots::default(),
    )
    .into_iter()
    .filter(|c| c.location == effect.location)
    .filter(|c| {
        c.named.map_or(false, |n| {
            effect.rivals.iter().any(|(r, _)| *r == n) && !f.effects.iter().any(|e| e.name == n)
        })
    })
    .collect();
    if rivals.is_empty() {
        return Ok(Settled::Kept);
    }
    let without = match without_addition(&f.params, &f.start, &effect.parameters) {
        Ok(without) => without,
        Err(why) => {
            progress(&format!(
                "{}'s rivals not tried: the model without it is refused ({why})",
                effect.name
            ));
            return Ok(Settled::Kept);
        }
    };
    let penalty = discovery_penalty_per_term(heldout_count(&cx.blocks) as f64);
    let problem = Problem::new(cx.recording, &without, &cx.blocks, cx.channel_noise);
    let (own_misfit, own_force) = crate::decide::alternatives::judge(cx, &problem, &f.params, replays)?;
    let own_terms = effect
        .parameters
        .iter()
        .filter(|(name, value)| *value != parameter_value(&f.start, name))
        .count() as f64;
    let own_score = own_misfit + own_terms * penalty;
    let others = refitted_beside(f, |_| true, |e| !std::ptr::eq(e, effect), &without);
    let against = format!(
        "in place of {}, every addition refitted: {{misfit}} held out + penalty {{penalty}} against {own_misfit:.0} + {:.0} (noise floors squared), force {{force}} against {own_force:.4} N",
        effect.name,
        own_terms * penalty
    );
    progress(&format!("{}'s rivals at the {}", effect.name, effect.location));
    let Some(fit) = best_named_fit(cx, &without, &others, &rivals, &against, replays, progress)? else {
        return Ok(Settled::Kept);
    };
    let (score, force) = (fit.score, fit.force);
    let rival = fit.scored.fit.candidate.named.expect("a named candidate");
    let share_then = effect.rivals.iter().find(|(r, _)| *r == rival).map_or(0.0, |r| r.1);
    if score > own_score - penalty || force > own_force {
        if score <= own_score + penalty {
            let sentence = format!(
                "This recording does not tell it from {rival}: with every other addition refitted, {rival} in its place leaves the held-out force error at {force:.4} N against {own_force:.4} N, within one penalty on the held-out misfit."
            );
            return Ok(Settled::Tied(rival, sentence));
        }
        return Ok(Settled::Kept);
    }
    let (test, parameters) = fit.signature(cx, replays)?;
    if !test.present {
        progress(&format!("  {rival}: its signature is absent"));
        return Ok(Settled::Kept);
    }
    let values: Vec<String> = parameters.iter().map(|(n, v)| format!("{n} = {v:.4e}")).collect();
    let evidence = format!(
        "Named {} first, which the round that found it could hardly tell from {rival} ({rival} explained {:.1} % of that round's held-out misfit); with every later addition in and refitted beside it, {rival} ({}) leaves the held-out force error at {force:.4} N against {own_force:.4} N with {} (noise floor {:.4} N){}.",
        effect.name,
        100.0 * share_then,
        values.join(", "),
        effect.name,
        cx.noise,
        if test.sentence.is_empty() {
            String::new()
        } else {
            format!("; {}", test.sentence)
        },
    );
    Ok(Settled::Replaced(
        AddedEffect {
            name: rival,
            location: effect.location,
            parameters,
            evidence,
            heldout_before: effect.heldout_before,
            heldout_after: force,
            share: 1.0 - (force / effect.heldout_before).powi(2),
            remainder_follows: String::new(),
            rivals: vec![],
            tied_effects: vec![],
            intervals: vec![],
            // The rival stands at the same place, which won by as much.
            margin: effect.margin,
        },
        Box::new(fit.params),
    ))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::fit::Fit;
    use crate::replay::signals::CHANNELS;
    use crate::vocabulary::Family;

    /// A candidate's score with no fit behind it: its label, place, named effect and share.
    pub(crate) fn scored(label: &'static str, location: Place, named: Option<&'static str>, explained: f64) -> Scored {
        Scored {
            fit: Fit {
                candidate: Candidate {
                    label,
                    location,
                    family: Family::ParameterOffset,
                    named,
                    terms: vec![],
                    settings: vec![],
                },
                values: vec![],
                prediction: [vec![], vec![], vec![]],
                train: [0.0; CHANNELS],
                heldout: [0.0; CHANNELS],
                replays: 0,
            },
            explained,
            force_heldout_rms: 0.0,
        }
    }

    #[test]
    fn a_rival_is_a_named_effect_at_the_same_place_within_five_points_of_the_share_and_each_is_listed_once() {
        let candidates = vec![
            scored("heat exchange", Place::Chambers, Some("heat_transfer"), 0.969),
            scored("dead volumes", Place::Chambers, Some("dead_volume"), 0.966),
            scored("dead volumes, one chamber", Place::Chambers, Some("dead_volume"), 0.930),
            scored("gas temperature drift", Place::Chambers, None, 0.975),
            scored("chamber 1 leak", Place::Chambers, Some("leak_at_the_place"), 0.910),
            scored("supply restriction", Place::Supply, Some("supply_pressure_drop"), 0.968),
        ];
        let rivals = rivals_of("heat_transfer", Place::Chambers, 0.969, &candidates);
        assert_eq!(rivals, vec![("dead_volume", 0.966)]);
        // Named the other way round, the heat exchange is the rival.
        let rivals = rivals_of("dead_volume", Place::Chambers, 0.966, &candidates);
        assert_eq!(rivals, vec![("heat_transfer", 0.969)]);
        // A named effect far ahead has none.
        assert!(rivals_of("heat_transfer", Place::Chambers, 1.02, &candidates).is_empty());
    }
}
