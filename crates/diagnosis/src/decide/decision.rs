//! The decide stage from end to end: rounds until every channel is within its noise or
//! nothing earns a place (`rounds.rs`), each early addition revisited with the others in
//! (`revisit.rs`), second opinions on the names (`named_rivals.rs`, `named_instead.rs`), and
//! each addition's share of the error from the joint fit (`eliminate.rs`).

use crate::context::Context;
use crate::decide::findings::{Findings, Stage};
use crate::decide::rounds::{one_round, RoundEnd};
use crate::policy::MAX_EFFECTS;
use jetpipe_model::physics::parameters::Parameters;

pub(crate) fn run_rounds(
    cx: &mut Context,
    params: Parameters,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Findings, String> {
    let mut f = Findings {
        start: params.clone(),
        newest: None,
        params,
        effects: vec![],
        discovered: vec![],
        first_candidates: vec![],
        localization: None,
        joint_refit: None,
        stages: vec![],
    };
    for round in 0..=MAX_EFFECTS {
        if round > 0 {
            cx.lower_noise_to_departure(&f.params, replays, progress)?;
        }
        if one_round(cx, &mut f, round, round < MAX_EFFECTS, replays, progress)? != RoundEnd::Added {
            break;
        }
    }
    let cx: &Context = cx;
    // A revisit the model refuses leaves the findings as they were (each replacement is made
    // whole or not at all).
    if let Err(why) = crate::decide::revisit::revisit(cx, &mut f, replays, progress) {
        progress(&format!("the revisit of the additions stopped: {why}"));
    }
    let renamed = second_opinion(
        crate::decide::named_rivals::settle_rivals(cx, &mut f, replays, progress),
        progress,
    );
    let instead = second_opinion(
        crate::decide::named_instead::named_instead_of_discovered(cx, &mut f, replays, progress),
        progress,
    );
    if instead || renamed {
        // The last joint refit was of the additions before the names changed.
        f.joint_refit = None;
        // The last round's findings are these now: going back to it keeps the name.
        let stage = Stage::of(&f);
        match f.stages.last_mut() {
            Some(last) => *last = stage,
            None => f.stages.push(stage),
        }
    }
    crate::decide::eliminate::attribute_from_joint_fit(cx, &mut f, replays, progress)?;
    Ok(f)
}
/// Whether a second opinion on the names may have changed any. One the model refuses stops
/// there, the findings as they stand (each replacement is made whole or not at all), rather
/// than leave the user without a report; it counts as a change, so the last stage is taken
/// from the findings again.
fn second_opinion(outcome: Result<bool, String>, progress: &mut dyn FnMut(&str)) -> bool {
    outcome.unwrap_or_else(|why| {
        progress(&format!("the names' second opinion stopped: {why}"));
        true
    })
}
