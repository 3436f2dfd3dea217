//! Never a worse model: additions the accurate replay finds worse than the starting model
//! are taken out again, the latest first.

use crate::decide::findings;
use crate::policy::EARLIER_ROUNDS_TRIED;
use crate::policy::NEGLIGIBLE_SHARE_OF_NOISE;
use jetpipe_model::physics::parameters::Parameters;

use crate::replay::errors::Errors;

/// Additions taken out because, replayed accurately, they made the force error larger than
/// the starting model's, held out or over the whole recording.
#[derive(Clone, Debug)]
pub struct Withdrawn {
    /// The named effects and discovered terms taken out, by name.
    pub names: Vec<&'static str>,
    /// The force RMS errors of the model with every addition, N: held out, then over the
    /// whole recording.
    pub heldout_with: f64,
    pub whole_with: f64,
    /// The earlier additions that stay, as a round fitted them before the ones taken out
    /// (empty: the model reported is the starting model).
    pub kept: Vec<&'static str>,
}

/// A model's replay with its errors.
pub(crate) type Replayed<R> = (R, Errors);

/// What was withdrawn and, when an earlier round's model stays, its replay.
pub(crate) type Withdrawal<R> = (Withdrawn, Option<Replayed<R>>);

fn names(
    effects: &[crate::decide::additions::AddedEffect],
    discovered: &[crate::decide::additions::DiscoveredTerm],
) -> Vec<&'static str> {
    effects
        .iter()
        .map(|e| e.name)
        .chain(discovered.iter().map(|d| d.candidate))
        .collect()
}

/// Whether a model with errors `e` is worse than the starting model's `before`, held out or
/// over the whole recording, by more than [`NEGLIGIBLE_SHARE_OF_NOISE`] of the force's `noise`
/// floor: the rule no reported model breaks.
pub(crate) fn worse_than_start(e: &Errors, before: &Errors, noise: f64) -> bool {
    let negligible = NEGLIGIBLE_SHARE_OF_NOISE * noise;
    e.heldout_rms > before.heldout_rms + negligible || e.rms > before.rms + negligible
}

/// The search scores its additions on the fast replay; the accurate one decides. When it
/// finds the model with them worse than the model the diagnosis started from (`start`), held
/// out or over the whole recording, by more than [`NEGLIGIBLE_SHARE_OF_NOISE`] of the force's
/// `noise` floor, the additions are taken out the latest first: the models earlier rounds
/// left (`found.stages`, up to [`EARLIER_ROUNDS_TRIED`] of them) are replayed accurately by
/// `replay_accurately`, and the latest that is not worse than the start is kept, with its
/// replay; when none is, `found` is the starting model again.
pub(crate) fn withdraw_if_worse<R>(
    found: &mut findings::Findings,
    start: &Parameters,
    before: &Errors,
    after: &Errors,
    noise: f64,
    replay_accurately: &mut dyn FnMut(&Parameters) -> Result<Replayed<R>, String>,
) -> Result<Option<Withdrawal<R>>, String> {
    let worse = |e: &Errors| worse_than_start(e, before, noise);
    if !worse(after) {
        return Ok(None);
    }
    let every = names(&found.effects, &found.discovered);
    let earlier: Vec<findings::Stage> = found
        .stages
        .iter()
        .rev()
        .filter(|s| !(s.effects.is_empty() && s.discovered.is_empty()) && s.params != found.params)
        .take(EARLIER_ROUNDS_TRIED)
        .cloned()
        .collect();
    for stage in earlier {
        let (with, errors) = replay_accurately(&stage.params)?;
        if worse(&errors) {
            continue;
        }
        let kept = names(&stage.effects, &stage.discovered);
        found.params = stage.params;
        found.effects = stage.effects;
        found.discovered = stage.discovered;
        found.joint_refit = stage.joint_refit;
        found.newest = None;
        return Ok(Some((
            Withdrawn {
                names: every.into_iter().filter(|n| !kept.contains(n)).collect(),
                heldout_with: after.heldout_rms,
                whole_with: after.rms,
                kept,
            },
            Some((with, errors)),
        )));
    }
    found.effects.clear();
    found.discovered.clear();
    found.newest = None;
    found.joint_refit = None;
    found.params = start.clone();
    Ok(Some((
        Withdrawn {
            names: every,
            heldout_with: after.heldout_rms,
            whole_with: after.rms,
            kept: vec![],
        },
        None,
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decide::additions::AddedEffect;
    use crate::decide::additions::DiscoveredTerm;
    use crate::vocabulary::{Family, Place};
    use std::cell::Cell;

    fn errors(heldout_rms: f64, rms: f64) -> Errors {
        Errors {
            rms,
            nrmse: 0.0,
            train_rms: heldout_rms,
            heldout_rms,
            pressure_rms: None,
        }
    }

    /// Findings with one named effect, added in a first round at an offset of 0.7 N, and one
    /// discovered term added in a second, beside which the offset was refitted to 0.72 N.
    fn findings(start: &Parameters) -> findings::Findings {
        let mut params = start.clone();
        params.force_sensor_offset = 0.72;
        let mut first = start.clone();
        first.force_sensor_offset = 0.7;
        let effects = vec![AddedEffect {
            name: "sensor_offset_gain",
            location: Place::ForceSensor,
            parameters: vec![("force_sensor_offset", 0.7)],
            evidence: String::new(),
            heldout_before: 0.3,
            heldout_after: 0.1,
            share: 0.9,
            remainder_follows: String::new(),
            rivals: vec![],
            tied_effects: vec![],
            intervals: vec![],
            margin: None,
        }];
        findings::Findings {
            params,
            stages: vec![findings::Stage {
                params: first,
                effects: effects.clone(),
                discovered: vec![],
                joint_refit: None,
            }],
            effects,
            discovered: vec![DiscoveredTerm {
                location: Place::JetPipe,
                family: Family::Dynamics,
                candidate: "jet pipe extra lag",
                parameters: vec![],
                reading: String::new(),
                heldout_before: 0.1,
                heldout_after: 0.09,
                share: 0.2,
                pressures_heldout: None,
                tied_locations: vec![],
                intervals: vec![],
                margin: None,
                flexible: None,
            }],
            first_candidates: vec![],
            localization: None,
            joint_refit: Some((0.1, 0.09)),
            start: start.clone(),
            newest: Some((false, 0)),
        }
    }

    /// An accurate replay that finds `first_round`'s errors for the first round's model and
    /// counts its calls.
    fn replayed(
        first_round: Errors,
        calls: &Cell<usize>,
    ) -> impl FnMut(&Parameters) -> Result<((), Errors), String> + '_ {
        move |p: &Parameters| {
            calls.set(calls.get() + 1);
            assert_eq!(p.force_sensor_offset, 0.7, "only the first round's model is replayed");
            Ok(((), first_round))
        }
    }

    /// The diagnosis started at 0.3 N held out and 0.4 N whole; its final model is at
    /// `after`, its first round's model at `first_round`. Returns what was withdrawn, how many
    /// accurate replays ran and the findings left.
    fn withdrawn_when(first_round: Errors, after: Errors) -> (Option<Withdrawal<()>>, usize, findings::Findings) {
        let start = Parameters::default();
        let mut found = findings(&start);
        let calls = Cell::new(0);
        let mut replay = replayed(first_round, &calls);
        let out = withdraw_if_worse(&mut found, &start, &errors(0.3, 0.4), &after, 0.05, &mut replay).unwrap();
        (out, calls.get(), found)
    }

    #[test]
    fn additions_that_lower_both_errors_stay_and_nothing_is_replayed_again() {
        let (out, calls, found) = withdrawn_when(errors(0.2, 0.3), errors(0.1, 0.2));
        assert!(out.is_none());
        assert_eq!(calls, 0);
        assert_eq!((found.effects.len(), found.discovered.len()), (1, 1));
        assert_eq!(found.params.force_sensor_offset, 0.72);
    }

    #[test]
    fn when_the_latest_addition_makes_the_model_worse_the_earlier_rounds_model_is_kept() {
        let (out, calls, found) = withdrawn_when(errors(0.2, 0.3), errors(0.31, 0.2));
        let (withdrawn, kept) = out.unwrap();
        assert_eq!(calls, 1);
        assert_eq!(withdrawn.names, ["jet pipe extra lag"]);
        assert_eq!(withdrawn.kept, ["sensor_offset_gain"]);
        assert_eq!((withdrawn.heldout_with, withdrawn.whole_with), (0.31, 0.2));
        assert_eq!(kept.unwrap().1, errors(0.2, 0.3));
        assert_eq!((found.effects.len(), found.discovered.len()), (1, 0));
        assert_eq!(found.params.force_sensor_offset, 0.7);
        assert!(found.joint_refit.is_none() && found.newest.is_none());
    }

    #[test]
    fn when_every_rounds_model_is_worse_every_addition_is_withdrawn_and_the_start_comes_back() {
        // The first round's model is worse over the whole recording.
        let (out, calls, found) = withdrawn_when(errors(0.2, 0.45), errors(0.31, 0.2));
        let (withdrawn, kept) = out.unwrap();
        assert_eq!(calls, 1);
        assert!(kept.is_none() && withdrawn.kept.is_empty());
        assert_eq!(withdrawn.names, ["sensor_offset_gain", "jet pipe extra lag"]);
        assert!(found.effects.is_empty() && found.discovered.is_empty());
        assert_eq!(found.params, Parameters::default());
        assert!(found.joint_refit.is_none() && found.newest.is_none());
    }

    #[test]
    fn additions_that_make_only_the_whole_recording_worse_are_withdrawn_too() {
        let (out, _, found) = withdrawn_when(errors(0.3, 0.41), errors(0.1, 0.41));
        assert!(out.is_some());
        assert!(found.effects.is_empty());
    }

    #[test]
    fn a_force_error_larger_by_a_thousandth_of_the_noise_or_less_is_not_worse() {
        let start = Parameters::default();
        let mut found = findings(&start);
        let calls = Cell::new(0);
        let mut replay = replayed(errors(0.3, 0.41), &calls);
        // 0.05 N of noise: up to 5e-5 N is negligible, 6e-5 N is not.
        let near = withdraw_if_worse(
            &mut found,
            &start,
            &errors(0.3, 0.4),
            &errors(0.30004, 0.40004),
            0.05,
            &mut replay,
        );
        assert!(near.unwrap().is_none());
        assert_eq!(found.effects.len(), 1);
        let beyond = withdraw_if_worse(
            &mut found,
            &start,
            &errors(0.3, 0.4),
            &errors(0.3, 0.40006),
            0.05,
            &mut replay,
        );
        assert!(beyond.unwrap().is_some());
    }
}
