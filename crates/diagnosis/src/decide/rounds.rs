//! Steps 3–5 of the crate's account, repeated: replay the current model, localize the
//! departure, and add the named effect that earns its name there, or else a discovered
//! term that the replay confirms.

use crate::candidates::catalogue;
use crate::candidates::Candidate;
use crate::context::Context;
use crate::decide::additions::AddedEffect;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::findings::same_term;
use crate::decide::findings::sync_earlier;
use crate::decide::findings::Findings;
use crate::decide::findings::Round;
use crate::decide::findings::Stage;
use crate::decide::named_effect::apply_named;
use crate::decide::new_term::{discover_term, is_along_the_command_path, with_undecided};
use crate::fit::localize::heldout_count;
use crate::fit::localize::localize;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::policy::PRESSURES_SHOW_FROM;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::signals::ChainSignals;
use crate::replay::signals::CHANNELS;
use crate::replay::signals::CHANNEL_NAMES;
use crate::replay::signals::FORCE;
use crate::replay::signature::Signature;
use crate::replay::Replay;
use crate::vocabulary::Place;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// What a round adds to the model.
enum Addition {
    /// A named effect with its signature's sentence.
    Named(Scored, String),
    /// A discovered term with the parameters that carry it, and its fitted candidate.
    Discovered(DiscoveredTerm, Box<Parameters>, Option<Box<Scored>>),
    /// Two discovered terms at two places, fitted together (`pairs.rs`).
    Pair(Vec<DiscoveredTerm>, Box<Parameters>),
    /// A named effect and a term beside it, fitted together (`named_places.rs`).
    NamedWithTerm(Box<Scored>, String, DiscoveredTerm, Box<Parameters>),
}

/// How a round ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum RoundEnd {
    /// Every channel is within its noise held out.
    WithinNoise,
    /// Nothing earned a place (or `may_add` was false): the findings' localization is the
    /// remainder's.
    NothingAdded,
    /// An addition was made, the additions refitted together and the redundant removed.
    Added,
}

/// One round (steps 3–5): replay the findings' model, localize what departs, and add what
/// earns its place there when `may_add`; then refit every addition together and remove
/// what the new one made redundant. Read as propose → check → commit → refit.
pub(crate) fn one_round(
    cx: &Context,
    f: &mut Findings,
    round: usize,
    may_add: bool,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<RoundEnd, String> {
    let problem = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
    let Some(r) = replay_round(cx, &problem, f, round, replays, progress)? else {
        progress("every channel is within its noise on the held-out blocks");
        f.localization = None;
        return Ok(RoundEnd::WithinNoise);
    };

    // Every round fits every place again: an effect added on the force side of the
    // piston leaves the pressures as they were but not the force, and scores kept from
    // the round before judged a command delay beside a friction on the force the
    // friction had left (68 % where it explained all).
    let screen = crate::fit::screen::Screen {
        periodic_hz: r.periodic,
    };
    let (found, used) = localize(&problem, &r.current, &r.candidates, cx.options, Some(screen), progress);
    *replays += used;
    if round == 0 {
        f.first_candidates = found.candidates.clone();
    }
    let proposed = if may_add {
        find_addition(cx, &r, &problem, &found, f, replays, progress)?
    } else {
        None
    };
    let Some(proposed) = proposed else {
        f.localization = Some(found);
        return Ok(RoundEnd::NothingAdded);
    };
    let checked = simpler_in_its_place(cx, &r, &problem, &found, f, proposed, replays, progress)?;
    let checked = tied_where_it_stands(cx, &found, checked);
    commit(cx, f, &r, &found, checked, progress)?;
    refit_after_addition(cx, f, replays, progress)?;
    f.stages.push(Stage::of(f));
    Ok(RoundEnd::Added)
}

/// What was added is a hypothesis, not a lock: a simpler term at its place that does as
/// well on the held-out blocks replaces it (a supply set low is its plain pressure, not a
/// line resistance), and so does a richer one that does better than a named effect by its
/// penalty.
#[allow(clippy::too_many_arguments)]
fn simpler_in_its_place(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    found: &Localization,
    f: &Findings,
    added: Addition,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Addition, String> {
    let check = crate::decide::alternatives::Check {
        cx,
        problem,
        count: r.count,
        force_before: r.force_before,
    };
    Ok(match added {
        Addition::Named(s, sentence) => {
            let mut with = f.params.clone();
            let simpler = if apply_named(&mut with, &s).is_ok() {
                let a = crate::decide::alternatives::Added {
                    scored: &s,
                    with: &with,
                    named: true,
                    measured_shape: s.fit.candidate.named == Some("sensor_offset_gain")
                        && cx.recording.p1.is_some()
                        && cx.recording.p2.is_some(),
                };
                crate::decide::alternatives::alternative_at_place(&check, found, &f.params, &a, replays, progress)?
            } else {
                None
            };
            match simpler {
                Some((term, trial)) => Addition::Discovered(term, Box::new(trial), None),
                None => Addition::Named(s, sentence),
            }
        }
        Addition::Discovered(term, trial, Some(s)) => {
            let a = crate::decide::alternatives::Added {
                scored: &s,
                with: &trial,
                named: false,
                measured_shape: false,
            };
            match crate::decide::alternatives::alternative_at_place(&check, found, &f.params, &a, replays, progress)? {
                Some((simpler, with)) => Addition::Discovered(simpler, Box::new(with), None),
                None => match crate::decide::alternatives::simpler_elsewhere(
                    &check, found, &f.params, &a, &r.current, replays, progress,
                )? {
                    Some((simpler, with)) => Addition::Discovered(simpler, Box::new(with), None),
                    None => Addition::Discovered(term, trial, Some(s)),
                },
            }
        }
        other => other,
    })
}

/// A term put in another's place is tied to the places that one was; one along the command
/// path is tied to every place a static function of the command acts alike at.
fn tied_where_it_stands(cx: &Context, found: &Localization, added: Addition) -> Addition {
    match added {
        Addition::Discovered(mut term, trial, s)
            if term.tied_locations.is_empty() || is_along_the_command_path(&term) =>
        {
            // Ties already given (by the fit that added it) are in its reading already.
            let mut undecided = None;
            if term.tied_locations.is_empty() {
                term.tied_locations = found.tied_with(term.location);
                undecided = found.undecided_beside(term.location, cx.pressure_noise.is_some());
            }
            if is_along_the_command_path(&term) {
                term.tied_locations = crate::candidates::command_path::tied_along_the_command_path(term.location);
                undecided = Some(
                    "a static function of the command (a curve, an offset, a gain or a limit) acts alike at the command, in the current driver and at the torque motor, which a command slower than the driver does not tell apart".to_string(),
                );
            }
            term.reading = with_undecided(std::mem::take(&mut term.reading), undecided);
            Addition::Discovered(term, trial, s)
        }
        other => other,
    }
}

/// The addition into the findings, with the margin by which each new addition's place won.
fn commit(
    cx: &Context,
    f: &mut Findings,
    r: &Round,
    found: &Localization,
    added: Addition,
    progress: &mut dyn FnMut(&str),
) -> Result<(), String> {
    let earlier = (f.effects.len(), f.discovered.len());
    // Two terms added as a pair were judged together, against no single place: their
    // places get no margin.
    let paired = matches!(added, Addition::Pair(..));
    match added {
        Addition::Discovered(term, trial, _) => {
            match f.discovered.iter().position(|d| same_term(d, &term)) {
                // The same candidate with the same parameters again: a refit of the earlier
                // term (its first fit, through a linear regressor, left a viscous friction
                // 2 % short), reported as one term with its new values.
                Some(k) => {
                    progress(&format!("the {} again: one term, refitted", term.candidate));
                    let earlier = &mut f.discovered[k];
                    earlier.parameters = term.parameters;
                    earlier.heldout_after = term.heldout_after;
                    earlier.share = 1.0 - (earlier.heldout_after / earlier.heldout_before).powi(2);
                    earlier.reading = crate::decide::discover::reading(
                        earlier.candidate,
                        earlier.location,
                        earlier.family,
                        &earlier.parameters,
                        &f.start,
                    );
                    earlier.pressures_heldout = term.pressures_heldout.or(earlier.pressures_heldout);
                    f.newest = Some((false, k));
                }
                None => {
                    f.discovered.push(term);
                    f.newest = Some((false, f.discovered.len() - 1));
                }
            }
            f.params = *trial;
        }
        Addition::Pair(terms, trial) => {
            // No terms: the earlier additions refitted beside a candidate that stayed off.
            if !terms.is_empty() {
                f.discovered.extend(terms);
                f.newest = Some((false, f.discovered.len() - 1));
            }
            f.params = *trial;
            // A term added beside the earlier ones moved their constants.
            sync_earlier(f);
        }
        Addition::Named(s, sentence) => {
            let effect = add_effect(cx, &mut f.params, r, found, s, sentence, progress)?;
            f.effects.push(effect);
            f.newest = Some((true, f.effects.len() - 1));
        }
        Addition::NamedWithTerm(s, sentence, term, trial) => {
            let effect = add_effect(cx, &mut f.params, r, found, *s, sentence, progress)?;
            f.effects.push(effect);
            f.discovered.push(term);
            f.newest = Some((false, f.discovered.len() - 1));
            f.params = *trial;
        }
    }
    // How clearly the place of each addition this round made won in its localization.
    for (place, margin) in f.effects[earlier.0..]
        .iter_mut()
        .map(|e| (e.location, &mut e.margin))
        .chain(
            f.discovered[earlier.1..]
                .iter_mut()
                .map(|d| (d.location, &mut d.margin)),
        )
    {
        *margin = if paired { None } else { found.margin(place) };
    }
    Ok(())
}

/// After an addition: a sinusoid's frequency moved through the model, every addition
/// refitted together, and what the new one made redundant removed.
fn refit_after_addition(
    cx: &Context,
    f: &mut Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<(), String> {
    // A sinusoid's frequency, held by the fits at the spectral line's, moved through the
    // model where another leaves less (`frequency.rs`).
    crate::decide::frequency::polish_frequency(cx, f, replays, progress)?;
    // Each addition was fitted with those before it held. Refitting them together now,
    // not only at the end, lets the next round start from where they explain most: a
    // discovered restriction fitted while friction was still missing leaves the pressures
    // a few noise floors off, and the next round would fit every upstream candidate again
    // for that.
    if let Some(refit) = crate::decide::joint_refit::refit_jointly(cx, f, replays, progress)? {
        f.joint_refit = Some(refit);
    }
    // What a later addition has made redundant goes (`eliminate.rs`).
    if crate::decide::eliminate::drop_redundant(cx, f, replays, progress)? {
        if let Some(refit) = crate::decide::joint_refit::refit_jointly(cx, f, replays, progress)? {
            f.joint_refit = Some(refit);
        }
    }
    Ok(())
}

/// Replay the current model; `None` when every channel is within its noise held out.
fn replay_round(
    cx: &Context,
    problem: &Problem,
    f: &Findings,
    round: usize,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<Round>, String> {
    let recording = cx.recording;
    let model = Actuator::new(f.params.clone())?;
    let current = replay_fast(&model, recording, cx.n)?;
    *replays += 1;
    let prediction = [current.force.clone(), current.p1.clone(), current.p2.clone()];
    let (_, heldout) = problem.errors(&prediction);
    let count = heldout_count(&cx.blocks) as f64;
    let misfit: Vec<f64> = (0..CHANNELS)
        .filter(|&c| problem.weights[c] > 0.0)
        .map(|c| (heldout[c] / count).sqrt())
        .collect();
    if misfit.iter().all(|m| *m <= EXPLAINED_WITHIN_NOISE) {
        return Ok(None);
    }
    let force_residual = difference(&recording.force, &current.force);
    let line = crate::replay::signature::spectrum(&recording.time, &force_residual);
    // A line on the logarithmic grid of the signature, else a sharp line anywhere up to the
    // Nyquist frequency that the inputs do not carry (`lines.rs`).
    let periodic = (line.peak_over_median > 100.0 && line.low_share < 0.5 && line.peak_hz > 0.2)
        .then_some(line.peak_hz)
        .or_else(|| {
            let n = force_residual.len();
            let sample_rate = recording.sample_rate();
            let inputs = [&recording.v_da[..n], &recording.x_s[..n]];
            // Placed again at the samples' own times: the fits' stretches have gaps.
            crate::input::lines::strongest_line(&force_residual, sample_rate, &inputs, &current.force[..n]).map(|l| {
                crate::replay::signature::polished_line(&recording.time, &force_residual, l.hz, sample_rate / n as f64)
            })
        });
    // Pressures within their noise: nothing upstream of the piston departs by more
    // than they can show, and only the mechanics and the force sensor are fitted. They can
    // show it only where it is large enough: a departure upstream moves the force by
    // A_p (Δp1 − Δp2), so one pressure departs by at least half the force's departure
    // over A_p, and that must lift its channel above the limit. Noisy pressures (600 Pa of
    // noise against a force departure of 0.1 N, at least 250 Pa in one pressure) tell
    // nothing, and every place stays in the search.
    let force_departure = ((heldout[FORCE] / count) - 1.0).max(0.0).sqrt() * cx.channel_noise[FORCE];
    let pressure_shown = force_departure / (2.0 * model.piston_area);
    let pressures_could_show = pressure_shown >= PRESSURES_SHOW_FROM * cx.channel_noise[1].max(cx.channel_noise[2]);
    let pressures_agree = problem.weights[1] > 0.0
        && problem.weights[2] > 0.0
        && pressures_could_show
        && (1..CHANNELS).all(|c| (heldout[c] / count).sqrt() <= EXPLAINED_WITHIN_NOISE);
    let knots = curve_knots(cx, problem, &current);
    let candidates: Vec<Candidate> = catalogue(&f.params, cx.pressure_noise.is_some(), periodic, &knots)
        .into_iter()
        .chain(crate::candidates::products::candidates(
            &f.params,
            problem.mean_position,
        ))
        .filter(|c| !f.effects.iter().any(|e| Some(e.name) == c.named))
        .filter(|c| !pressures_agree || matches!(c.location, Place::Mechanics | Place::ForceSensor))
        .collect();
    progress(&format!(
        "round {}: held-out misfit {} noise floors",
        round + 1,
        misfit
            .iter()
            .zip(CHANNEL_NAMES)
            .map(|(m, name)| format!("{name} {m:.1}"))
            .collect::<Vec<_>>()
            .join(", ")
    ));
    let force_before = rms_where(&force_residual, &cx.blocks, Block::HeldOut);
    Ok(Some(Round {
        model,
        current,
        heldout,
        count,
        force_before,
        pressures_agree,
        candidates,
        periodic,
    }))
}

/// Where the static curves' knots go ([`crate::candidates::curves`]): on each measured channel against
/// the model's reading of it; on the command against the force's residual through its
/// sensitivity to a constant shift of the command (a shift of i_offset by k_cd per volt:
/// the driver is linear), one replay.
fn curve_knots(cx: &Context, problem: &Problem, current: &Replay) -> crate::candidates::curves::CurveKnots {
    let modelled = [&current.force, &current.p1, &current.p2];
    let mut knots = crate::candidates::curves::CurveKnots::default();
    for c in 0..CHANNELS {
        if problem.weights[c] > 0.0 {
            knots.channels[c] = crate::candidates::curves::placed_knots(
                modelled[c],
                problem.measured[c],
                &cx.blocks,
                crate::candidates::curves::SENSOR_KNOTS,
            );
        }
    }
    let k_cd = problem.base.k_cd;
    if let Some(s) = problem.sensitivity("i_offset", 1e-3, current) {
        let per_volt: Vec<f64> = s[FORCE].iter().map(|&x| f64::from(x) * k_cd).collect();
        let residual = difference(&cx.recording.force, &current.force);
        knots.command = crate::candidates::curves::placed_command_knots(
            &cx.recording.v_da[..cx.n],
            &residual,
            &per_volt,
            &cx.blocks,
            crate::candidates::curves::COMMAND_KNOTS,
        );
    }
    knots
}

/// The round's addition, in the order of preference: a named effect at the located place,
/// one downstream of the pressures, a discovered term at the located place.
fn find_addition(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    found: &Localization,
    f: &Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<Addition>, String> {
    let place = found.location;
    let mut halves = vec![];
    if place != Place::Unknown {
        if let Some((s, sentence)) =
            crate::decide::named_places::named_at_place(cx, r, problem, found, &f.discovered, &mut halves, progress)
        {
            return Ok(Some(Addition::Named(s, sentence)));
        }
    }
    // The downstream pass finds a second effect behind a larger one upstream. Located at the
    // mechanics or the force sensor, the departure is not upstream: the named effects there
    // were judged at the place, and judged again on the force against the pressures, one of
    // them would stand in for a term there that also moves the pressures (a bore narrowing
    // over the recording was read as the force sensor's offset and gain, leaving 6.9 noise
    // floors, where the bore varying with time leaves 1.0).
    let downstream_of_elsewhere = !matches!(place, Place::Mechanics | Place::ForceSensor);
    let downstream = if !r.pressures_agree && downstream_of_elsewhere {
        crate::decide::named_places::downstream(cx, r, &f.params, replays, progress)
    } else {
        None
    };
    if let Some(d) = &downstream {
        if let Some((s, sentence)) =
            crate::decide::named_places::named_downstream(cx, r, &f.params, &f.discovered, d, replays, progress)?
        {
            return Ok(Some(Addition::Named(s, sentence)));
        }
    }
    if !halves.is_empty() {
        if let Some((s, sentence, term, trial)) =
            crate::decide::named_places::named_with_term(cx, problem, found, &f.params, r, halves, replays, progress)?
        {
            return Ok(Some(Addition::NamedWithTerm(
                Box::new(s),
                sentence,
                term,
                Box::new(trial),
            )));
        }
    }
    if let Some((terms, trial)) = crate::decide::pairs::best_pair(
        cx,
        problem,
        found,
        &f.params,
        &r.current,
        &r.heldout,
        r.force_before,
        replays,
        progress,
    )? {
        return Ok(Some(Addition::Pair(terms, Box::new(trial))));
    }
    if place != Place::Unknown {
        if let Some((term, trial, s)) =
            discover_term(cx, r, problem, found, &f.params, &f.discovered, replays, progress)?
        {
            return Ok(Some(Addition::Discovered(term, Box::new(trial), Some(Box::new(s)))));
        }
    }
    if let Some((term, trial)) = crate::decide::beside::best_beside_earlier(
        cx,
        problem,
        found,
        f,
        &r.current,
        &r.heldout,
        r.force_before,
        replays,
        progress,
    )? {
        return Ok(Some(Addition::Pair(term.into_iter().collect(), Box::new(trial))));
    }
    if let Some(d) = &downstream {
        if let Some((term, trial)) =
            crate::decide::named_places::discovered_downstream(cx, r, problem, &f.params, d, replays, progress)?
        {
            // Added as a pair's terms are: its ties are its own side's, not the round's.
            return Ok(Some(Addition::Pair(vec![term], Box::new(trial))));
        }
    }
    Ok(None)
}

/// Add the named effect to the model and write down its evidence.
fn add_effect(
    cx: &Context,
    params: &mut Parameters,
    r: &Round,
    found: &Localization,
    s: Scored,
    signature_sentence: String,
    progress: &mut dyn FnMut(&str),
) -> Result<AddedEffect, String> {
    let (force_before, noise) = (r.force_before, cx.noise);
    let place = s.fit.candidate.location;
    let downstream = place != found.location;
    let place_share = if downstream {
        s.explained
    } else {
        found.best_at(found.location).map_or(0.0, |s| s.explained)
    };
    let name = s.fit.candidate.named.expect("a named candidate");
    let set = apply_named(params, &s)?;
    let remainder = difference(&cx.recording.force, &s.fit.prediction[FORCE]);
    let chain = ChainSignals::new(&r.model, cx.recording, &r.current);
    let follows = Signature::of(&cx.recording.time, &remainder, &chain, "N");
    let top = follows.follows.first();
    let share = 1.0 - (s.force_heldout_rms / force_before).powi(2);
    let values: Vec<String> = set.iter().map(|(n, v)| format!("{n} = {v:.4e}")).collect();
    let evidence = format!(
        "Of the places in the chain, the {place} explains the most of the held-out misfit{} ({:.1} %), and {name} {:.1} % of it{}. Fitted on the training blocks ({}), it lowers the held-out force error from {force_before:.4} N to {:.4} N (noise floor {noise:.4} N), {:.1} % of its mean square.",
        if downstream { " of the force against the pressures" } else { "" },
        100.0 * place_share,
        100.0 * s.explained,
        if signature_sentence.is_empty() {
            String::new()
        } else {
            format!("; {signature_sentence}")
        },
        values.join(", "),
        s.force_heldout_rms,
        100.0 * share
    );
    let evidence = match found.undecided_beside(found.location, cx.pressure_noise.is_some()) {
        Some(clause) if !downstream => format!("{evidence} Beside it, {clause}."),
        _ => evidence,
    };
    progress(&format!("adding {name}"));
    Ok(AddedEffect {
        name,
        location: place,
        parameters: set,
        evidence,
        heldout_before: force_before,
        heldout_after: s.force_heldout_rms,
        share,
        remainder_follows: top
            .map(|f| format!("{} (η² = {:.2})", f.signal, f.eta_squared))
            .unwrap_or_default(),
        rivals: if downstream {
            vec![]
        } else {
            crate::decide::named_rivals::rivals_of(name, place, s.explained, &found.candidates)
        },
        tied_effects: vec![],
        intervals: vec![],
        margin: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decide::findings::{nameable, unclaimed};
    use crate::vocabulary::Family;

    fn term(candidate: &'static str, parameters: Vec<(&'static str, f64)>) -> DiscoveredTerm {
        DiscoveredTerm {
            location: Place::Mechanics,
            family: Family::ExtraForce,
            candidate,
            parameters,
            reading: String::new(),
            heldout_before: 1.0,
            heldout_after: 0.5,
            share: 0.75,
            pressures_heldout: None,
            tied_locations: vec![],
            intervals: vec![],
            margin: None,
            flexible: None,
        }
    }

    #[test]
    fn a_named_effect_without_a_signature_test_is_tried_as_a_term_once_a_term_is_in_and_one_with_a_test_never() {
        use crate::decide::named_rivals::tests::scored;
        let dead_volumes = scored("dead volumes", Place::Chambers, Some("dead_volume"), 0.98);
        let friction = scored("piston friction", Place::Mechanics, Some("piston_friction"), 0.9);
        let leak = scored("chamber leaks to the return", Place::Chambers, None, 0.8);
        let earlier = vec![term("chamber leaks to the return", vec![("chamber_vent_1", 4.5e-9)])];
        // Before any term: the dead volumes are a name to try, not a term.
        assert!(nameable(&dead_volumes, &[]) && !unclaimed(&dead_volumes, &[]));
        // After one: no longer a name, so a term.
        assert!(!nameable(&dead_volumes, &earlier) && unclaimed(&dead_volumes, &earlier));
        // Friction has its own signature test: always a name to try, never a term.
        assert!(nameable(&friction, &earlier) && !unclaimed(&friction, &earlier));
        assert!(unclaimed(&leak, &[]) && unclaimed(&leak, &earlier));
    }

    #[test]
    fn the_same_candidate_on_the_same_parameters_is_one_term_whatever_their_values() {
        let a = term("viscous friction", vec![("viscous_friction", 58.96)]);
        assert!(same_term(
            &a,
            &term("viscous friction", vec![("viscous_friction", 60.23)])
        ));
        assert!(!same_term(
            &a,
            &term("quadratic damping", vec![("viscous_friction", 60.23)])
        ));
        assert!(!same_term(
            &a,
            &term(
                "viscous friction",
                vec![("viscous_friction", 60.23), ("extra_force_acceleration", -0.1)]
            )
        ));
    }
}
