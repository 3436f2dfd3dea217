//! Steps 3–5 of the crate's account, repeated: replay the current model, localize the
//! departure, and add the named effect that earns its name there, or else a discovered
//! term that the replay confirms.

use crate::candidates::catalogue;
use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::context::Context;
use crate::decide::additions::AddedEffect;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::findings::curve_corners_across_unvisited;
use crate::decide::findings::nameable;
use crate::decide::findings::pressures_gain;
use crate::decide::findings::sync_earlier;
use crate::decide::findings::Findings;
use crate::decide::findings::Round;
use crate::decide::findings::Stage;
use crate::decide::findings::{carried_alike, same_term};
use crate::decide::named_effect::apply_named;
use crate::fit::localize::discovery_penalised;
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::heldout_count;
use crate::fit::localize::localize;
use crate::fit::localize::used_terms;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::policy::worth_adding;
use crate::policy::DISCOVERY_TRIALS;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::policy::LOCATED_SHARE;
use crate::policy::MAX_EFFECTS;
use crate::policy::REFINE_ITERATIONS;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::signals::ChainSignals;
use crate::replay::signals::CHANNELS;
use crate::replay::signals::CHANNEL_NAMES;
use crate::replay::signals::FORCE;
use crate::replay::Replay;
use crate::verdict::signature::Signature;
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
        let cx: &Context = cx;
        let problem = Problem::new(cx.recording, &f.params, &cx.blocks, cx.channel_noise);
        let Some(r) = replay_round(cx, &problem, &f, round, replays, progress)? else {
            progress("every channel is within its noise on the held-out blocks");
            f.localization = None;
            break;
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
        let added = if round < MAX_EFFECTS {
            find_addition(cx, &r, &problem, &found, &f, replays, progress)?
        } else {
            None
        };
        // What was added is a hypothesis, not a lock: a simpler term at its place that does
        // as well on the held-out blocks replaces it (a supply set low is its plain pressure,
        // not a line resistance), and so does a richer one that does better than a named
        // effect by its penalty.
        let check = crate::decide::alternatives::Check {
            cx,
            problem: &problem,
            count: r.count,
            force_before: r.force_before,
        };
        let added = match added {
            Some(Addition::Named(s, sentence)) => {
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
                    crate::decide::alternatives::alternative_at_place(&check, &found, &f.params, &a, replays, progress)?
                } else {
                    None
                };
                match simpler {
                    Some((term, trial)) => Some(Addition::Discovered(term, Box::new(trial), None)),
                    None => Some(Addition::Named(s, sentence)),
                }
            }
            Some(Addition::Discovered(term, trial, Some(s))) => {
                let a = crate::decide::alternatives::Added {
                    scored: &s,
                    with: &trial,
                    named: false,
                    measured_shape: false,
                };
                match crate::decide::alternatives::alternative_at_place(
                    &check, &found, &f.params, &a, replays, progress,
                )? {
                    Some((simpler, with)) => Some(Addition::Discovered(simpler, Box::new(with), None)),
                    None => match crate::decide::alternatives::simpler_elsewhere(
                        &check, &found, &f.params, &a, &r.current, replays, progress,
                    )? {
                        Some((simpler, with)) => Some(Addition::Discovered(simpler, Box::new(with), None)),
                        None => Some(Addition::Discovered(term, trial, Some(s))),
                    },
                }
            }
            other => other,
        };
        // A term put in another's place is tied to the places that one was.
        let added = match added {
            Some(Addition::Discovered(mut term, trial, s))
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
                Some(Addition::Discovered(term, trial, s))
            }
            other => other,
        };
        match added {
            Some(Addition::Discovered(term, trial, _)) => {
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
            Some(Addition::Pair(terms, trial)) => {
                // No terms: the earlier additions refitted beside a candidate that stayed off.
                if !terms.is_empty() {
                    f.discovered.extend(terms);
                    f.newest = Some((false, f.discovered.len() - 1));
                }
                f.params = *trial;
                // A term added beside the earlier ones moved their constants.
                sync_earlier(&mut f);
            }
            Some(Addition::Named(s, sentence)) => {
                let effect = add_effect(cx, &mut f.params, &r, &found, s, sentence, progress)?;
                f.effects.push(effect);
                f.newest = Some((true, f.effects.len() - 1));
            }
            Some(Addition::NamedWithTerm(s, sentence, term, trial)) => {
                let effect = add_effect(cx, &mut f.params, &r, &found, *s, sentence, progress)?;
                f.effects.push(effect);
                f.discovered.push(term);
                f.newest = Some((false, f.discovered.len() - 1));
                f.params = *trial;
            }
            None => {
                f.localization = Some(found);
                break;
            }
        }
        // Each addition was fitted with those before it held. Refitting them together now,
        // not only at the end, lets the next round start from where they explain most: a
        // discovered restriction fitted while friction was still missing leaves the pressures
        // a few noise floors off, and the next round would fit every upstream candidate again
        // for that.
        if let Some(refit) = crate::decide::joint_refit::refit_jointly(cx, &mut f, replays, progress)? {
            f.joint_refit = Some(refit);
        }
        // What a later addition has made redundant goes (`eliminate.rs`).
        if crate::decide::eliminate::drop_redundant(cx, &mut f, replays, progress)? {
            if let Some(refit) = crate::decide::joint_refit::refit_jointly(cx, &mut f, replays, progress)? {
                f.joint_refit = Some(refit);
            }
        }
        f.stages.push(Stage::of(&f));
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

/// A departure of this many noise floors of a channel lifts the channel's held-out misfit,
/// noise and departure together, to [`EXPLAINED_WITHIN_NOISE`]: √(1 + 1.118²) = 1.5.
const PRESSURES_SHOW_FROM: f64 = 1.118;

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
    let line = crate::verdict::signature::spectrum(&recording.time, &force_residual);
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
                crate::verdict::signature::polished_line(&recording.time, &force_residual, l.hz, sample_rate / n as f64)
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
        .filter(|c| !pressures_agree || matches!(c.location, "mechanics" | "force_sensor"))
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

/// Whether a candidate may be added as a discovered term, which claims no name: one outside
/// the named effects, or a named effect whose name this round cannot give (see [`nameable`]).
/// A term may be found first and the named effect after it: beside chamber leaks found in a
/// first round, the dead volumes explained 98 % of the second and could be neither named nor
/// added, and 12 noise floors stayed.
fn unclaimed(s: &Scored, discovered: &[DiscoveredTerm]) -> bool {
    s.fit.candidate.named.is_none() || !nameable(s, discovered)
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
    if place != "unknown" {
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
    let downstream_of_elsewhere = !matches!(place, "mechanics" | "force_sensor");
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
    if place != "unknown" {
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

/// No named effect fits: the place's own best candidates that the FMU can carry, each kept
/// only if the model with it (replayed, not predicted) is better on the held-out blocks by
/// more than a noise floor and by more than its parameters' BIC penalty, and no pressure
/// channel gets worse.
fn discover_term(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    found: &Localization,
    params: &Parameters,
    earlier: &[DiscoveredTerm],
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(DiscoveredTerm, Parameters, Scored)>, String> {
    let (recording, count, force_before, noise) = (cx.recording, r.count, r.force_before, cx.noise);
    // The located place's candidates first, then those of the places that explain nearly as
    // much: where the recording cannot tell places apart (a short lag anywhere before the jet
    // pipe reads as a delay under a slow sine) and the located place has no term to keep, the
    // best of the others is tried. Up to DISCOVERY_TRIALS of each.
    let tied = found.alternatives();
    let unnamed_at = |place: &str| -> Vec<&Scored> {
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
            .any(|s| s.force_heldout_rms <= crate::candidates::modulation::WRITTEN_ADEQUATE_WITHIN * noise);
        let behind = |s: &Scored| {
            crate::candidates::modulation::is_modulation(&s.fit.candidate)
                && (written_adequate
                    || written_best <= crate::candidates::modulation::WRITTEN_FIRST_WITHIN * s.fit.heldout_total())
        };
        at.sort_by(|a, b| {
            behind(a)
                .cmp(&behind(b))
                .then(discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)))
        });
        at.truncate(DISCOVERY_TRIALS);
        at
    };
    let mut others: Vec<&Scored> = tied.iter().flat_map(|place| unnamed_at(place)).collect();
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
    let before_total: f64 = r.heldout.iter().sum();
    let training_before = rms_where(
        &difference(&recording.force, &r.current.force),
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
        let penalty = used_terms(s) * discovery_penalty_per_term(count);
        let worse_pressures =
            (1..CHANNELS).any(|c| problem.weights[c] > 0.0 && s.fit.heldout[c] > 1.05 * r.heldout[c] + count * 0.01);
        if worse_pressures || before_total - s.fit.heldout_total() < penalty {
            progress(&format!(
                "  {label}: not better than its parameters' penalty, or worse in a pressure"
            ));
            continue;
        }
        if crate::candidates::modulation::is_modulation(&s.fit.candidate)
            && crate::candidates::modulation::is_flat(&s.fit.values)
        {
            progress(&format!(
                "  {label}: the same change at every knot, a constant's own candidate carries it"
            ));
            continue;
        }
        let Some(mut set) = crate::decide::discover::model_terms(&s.fit.candidate, &s.fit.values, params, problem)
        else {
            progress(&format!("  {label}: the FMU has no parameters for it"));
            continue;
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
            continue;
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
        let pressures = if s.fit.candidate.location == "pressure_sensors" || (!force_ok && cx.pressure_noise.is_some())
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
                family: crate::candidates::curves::family(candidate.family, &set),
                candidate: candidate.label,
                reading: with_undecided(
                    crate::decide::discover::reading(
                        candidate.label,
                        candidate.location,
                        candidate.family,
                        &set,
                        params,
                    ),
                    found.undecided_beside(candidate.location, cx.pressure_noise.is_some()),
                ),
                parameters: set,
                heldout_before: force_before,
                heldout_after: after,
                share: 1.0 - (after / force_before).powi(2),
                pressures_heldout: pressures,
                tied_locations: found.tied_with(candidate.location),
            };
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
    }
    // A written term wins over a modulation that does not do clearly better in the model.
    Ok(match (written_best, modulation) {
        (Some(w), Some(m)) if w.0.heldout_after > written_instead_bar(m.0.heldout_after, noise) => Some(m),
        (Some(w), _) => Some(w),
        (None, m) => m,
    })
}

/// The held-out force error (N) at or below which a written term is taken instead of a
/// modulation that leaves `modulation_after`: within [`WRITTEN_INSTEAD_WITHIN`] of it, or
/// within the verdict's bar.
fn written_instead_bar(modulation_after: f64, noise: f64) -> f64 {
    (EXPLAINED_WITHIN_NOISE * noise).max(WRITTEN_INSTEAD_WITHIN * modulation_after)
}

/// A written term that earns its place but leaves more than the verdict's bar ends the
/// trials only when no later trial's fit promises to leave at most this share of its
/// held-out force error: a current driver's gain, as good as tied with the jet pipe, is
/// tried after the jet pipe's curve that leaves 7 noise floors.
const PROMISE_BEYOND_WRITTEN: f64 = 0.5;

/// Whether a term earns its place on a departure that the training blocks hold more of than
/// the held-out ones (a command saturating near the top of a slow sine whose peaks fell in
/// training blocks: 16 noise floors there, 3.7 held out). It must lower the training error by
/// [`TRAINING_GAIN_IN_NOISE`] floors of RMS, which no fit of a few parameters takes from
/// noise, and the held-out error as a refit must ([`worth_adding`]): by a tenth, and by a
/// noise floor squared of its mean square.
fn shown_mostly_where_fitted(heldout_before: f64, heldout_after: f64, training_gain: f64, noise: f64) -> bool {
    training_gain >= TRAINING_GAIN_IN_NOISE * noise && worth_adding(heldout_before, heldout_after, noise, true)
}

/// See [`shown_mostly_where_fitted`].
const TRAINING_GAIN_IN_NOISE: f64 = 3.0;

/// A written term that does within this factor of a modulation's held-out force error in the
/// model (or within the verdict's bar) is added instead of it.
const WRITTEN_INSTEAD_WITHIN: f64 = 1.1;

/// Whether `term` is a static function of the command at a place of its path, its ties (if
/// any) among those places: the places the path makes alike replace them.
fn is_along_the_command_path(term: &DiscoveredTerm) -> bool {
    use crate::candidates::command_path::{acts_alike_along_the_command_path, COMMAND_PATH};
    COMMAND_PATH.contains(&term.location)
        && acts_alike_along_the_command_path(&term.parameters)
        && term.tied_locations.iter().all(|l| COMMAND_PATH.contains(l))
}

/// A discovered term's `reading` (one sentence) with the places it cannot be told apart from.
fn with_undecided(reading: String, undecided: Option<String>) -> String {
    match undecided {
        Some(clause) => format!("{}; {clause}.", reading.trim_end_matches('.')),
        None => reading,
    }
}

/// The command's curve `set` refitted with its interior knots free
/// (`crate::candidates::curves::command_curve_with_free_knots`), made non-decreasing again, kept when the
/// model with it fits the training samples better than with `set`.
fn command_curve_knots_freed(
    cx: &Context,
    problem: &Problem,
    params: &Parameters,
    set: Vec<(&'static str, f64)>,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Vec<(&'static str, f64)> {
    let Some(free) = crate::candidates::curves::command_curve_with_free_knots(&set) else {
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
    crate::candidates::curves::monotone_command(&mut freed);
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

/// A pressure transducer's term leaves the force as it is: it is judged on the pressures,
/// by the same rule in their noise, and must leave the force no worse. When it passes, the
/// held-out RMS of each pressure before and after, Pa.
fn pressures_judgement(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    with: &Replay,
    after: f64,
    progress: &mut dyn FnMut(&str),
    label: &str,
) -> Option<([f64; 2], [f64; 2])> {
    let recording = cx.recording;
    let (_, replayed) = problem.errors(&[with.force.clone(), with.p1.clone(), with.p2.clone()]);
    let in_noise = |h: &[f64; CHANNELS]| ((h[1] + h[2]) / r.count).sqrt();
    progress(&format!(
        "  {label}: in the model, pressures held-out {:.2} -> {:.2} noise floors",
        in_noise(&r.heldout),
        in_noise(&replayed)
    ));
    let rms_pa = |series: [&[f64]; 2]| {
        let measured = [recording.p1.as_deref(), recording.p2.as_deref()];
        [0, 1].map(|c| {
            measured[c].map_or(0.0, |m| {
                rms_where(&difference(m, series[c]), &cx.blocks, Block::HeldOut)
            })
        })
    };
    let better = pressures_gain(&r.heldout, &replayed, r.count) && after <= r.force_before + 0.05 * cx.noise;
    better.then(|| (rms_pa([&r.current.p1, &r.current.p2]), rms_pa([&with.p1, &with.p2])))
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
    })
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

    #[test]
    fn a_refit_that_takes_two_noise_floors_to_one_and_a_half_is_worth_adding_and_a_new_term_must_take_a_whole_floor_unless_it_closes_the_last_mile(
    ) {
        // In noise floors. A refit of a term already added: 2.0 → 1.4 removes 2.0 of the mean square's 4.0.
        assert!(worth_adding(2.0, 1.4, 1.0, true));
        // A new term must take a whole noise floor of the RMS…
        assert!(!worth_adding(3.0, 2.2, 1.0, false));
        assert!(!worth_adding(2.0, 1.6, 1.0, false));
        assert!(worth_adding(2.0, 0.9, 1.0, false));
        // …but below 2.5 floors, one that brings the force within 1.5 needs a floor squared
        // of the mean square.
        assert!(worth_adding(2.0, 1.4, 1.0, false));
        assert!(worth_adding(1.72, 1.18, 1.0, false));
        assert!(!worth_adding(1.6, 1.4, 1.0, false));
        assert!(!worth_adding(2.6, 1.7, 1.0, false));
        // 1.2 → 1.0: a fifth of the RMS but under half a noise floor squared.
        assert!(!worth_adding(1.2, 1.0, 1.0, true));
        // 10 → 9.5: 19 noise floors squared of mean square, but 5 % of the error.
        assert!(!worth_adding(10.0, 9.5, 1.0, true));
        assert!(!worth_adding(2.0, 2.1, 1.0, true));
    }

    fn term(candidate: &'static str, parameters: Vec<(&'static str, f64)>) -> DiscoveredTerm {
        DiscoveredTerm {
            location: "mechanics",
            family: "extra_force",
            candidate,
            parameters,
            reading: String::new(),
            heldout_before: 1.0,
            heldout_after: 0.5,
            share: 0.75,
            pressures_heldout: None,
            tied_locations: vec![],
        }
    }

    #[test]
    fn a_named_effect_without_a_signature_test_is_tried_as_a_term_once_a_term_is_in_and_one_with_a_test_never() {
        use crate::decide::named_rivals::tests::scored;
        let dead_volumes = scored("dead volumes", "chambers", Some("dead_volume"), 0.98);
        let friction = scored("piston friction", "mechanics", Some("piston_friction"), 0.9);
        let leak = scored("chamber leaks to the return", "chambers", None, 0.8);
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
