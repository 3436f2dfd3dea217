//! Step 6: the final accurate replays, the verdict and the tests of the residual.

use crate::candidates::declared_bounds;
use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::context::Context;
use crate::fit::calibrate::Calibrated;
use crate::fit::scored::Localization;
use crate::input::blocks::Block;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::policy::NEGLIGIBLE_SHARE_OF_NOISE;
use crate::replay::errors::errors;
use crate::replay::errors::Errors;
use crate::replay::replay;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms;
use crate::replay::signals::ChainSignals;
use crate::replay::signature::Signature;
use crate::replay::Replay;
use crate::verdict::diagnosis::Diagnosis;
use crate::verdict::diagnosis::Unexplained;
use crate::verdict::split::PressureSplit;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;
use serde_json::json;

/// A discovered term whose constants all stand at the model's defaults (a compliance
/// refitted to its bound of 0) is not in the model: what the round that added it gained came
/// from the constants refitted beside it. It is not reported.
fn drop_terms_at_defaults(found: &mut crate::decide::findings::Findings, progress: &mut dyn FnMut(&str)) {
    let params = &found.params;
    found.discovered.retain(|d| {
        let off = !d.parameters.is_empty()
            && d.parameters
                .iter()
                .all(|(name, _)| parameter_value(params, name) == parameter_value(&Parameters::default(), name));
        if off {
            progress(&format!("  {} stands at its defaults: not reported", d.candidate));
        }
        !off
    });
}

/// A model's error-controlled replay of every sample, and its errors.
type AccurateReplay<'a> = dyn Fn(&Parameters) -> Result<(Replay, Errors), String> + 'a;

/// How sure each amount added is: its 95 % interval at the final model
/// ([`crate::fit::intervals`]), from that model's error-controlled replay `after` (of every
/// sample of `cx.full`) on the fits' rows and blocks. Taken after every decision, which none
/// of them reads, and not counted in the report's replays. The amounts first take the
/// intervals' Gauss–Newton step to the error-controlled replay's least squares
/// ([`move_to_least_squares`]). A model the moved values refuse leaves the intervals out, with
/// a line of progress, rather than the report.
fn settle_and_set_intervals(
    cx: &Context,
    found: &mut crate::decide::findings::Findings,
    (after, after_errors): (&mut Replay, &mut Errors),
    before_errors: &Errors,
    replay_accurately: &AccurateReplay,
    progress: &mut dyn FnMut(&str),
) {
    let mut names: Vec<&'static str> = vec![];
    for (name, _) in found
        .effects
        .iter()
        .flat_map(|e| e.parameters.iter())
        .chain(found.discovered.iter().flat_map(|d| d.parameters.iter()))
    {
        if !names.contains(name) {
            names.push(name);
        }
    }
    if names.is_empty() {
        return;
    }
    progress(&format!(
        "95 % intervals of the {} amount{} added",
        names.len(),
        if names.len() == 1 { "" } else { "s" }
    ));
    // (the model the intervals are taken at; `found` may move from it below)
    let at = found.params.clone();
    let problem = crate::fit::Problem::new(cx.recording, &at, &cx.blocks, cx.channel_noise);
    let accurate = at_fitted_rows(cx, after);
    let mut intervals = match crate::fit::intervals::intervals(&problem, &at, &names, Some(&accurate), cx.options.jobs)
    {
        Ok((intervals, _)) => intervals,
        Err(why) => {
            progress(&format!("  no intervals: {why}"));
            return;
        }
    };
    let mut steps = Steps {
        names: &names,
        intervals: &mut intervals,
        problem: &problem,
        accurate: &accurate,
    };
    move_to_least_squares(
        cx,
        found,
        &mut steps,
        (after, after_errors),
        before_errors,
        replay_accurately,
        progress,
    );
    let of = |name: &str| names.iter().position(|n| *n == name).and_then(|k| intervals[k]);
    for e in found.effects.iter_mut() {
        e.intervals = e.parameters.iter().map(|(name, _)| of(name)).collect();
    }
    for d in found.discovered.iter_mut() {
        d.intervals = d.parameters.iter().map(|(name, _)| of(name)).collect();
    }
}

/// An error-controlled replay at the rows the fits saw.
fn at_fitted_rows(cx: &Context, replay: &Replay) -> Replay {
    match cx.recording.full_rate.as_ref() {
        Some(f) => replay.at_rows(&f.rows),
        None => replay.clone(),
    }
}

/// The amounts, their intervals (each with its Gauss–Newton step), the fits' problem and the
/// error-controlled replay of the model at the fitted rows.
struct Steps<'a> {
    names: &'a [&'static str],
    intervals: &'a mut [Option<crate::fit::intervals::Interval>],
    problem: &'a crate::fit::Problem<'a>,
    accurate: &'a Replay,
}

/// The amounts moved by their intervals' Gauss–Newton steps to the error-controlled replay's
/// least squares on the training blocks (the fits' fixed-step replay leans them by up to
/// several standard errors). Kept when the weighted training misfit falls, the held-out force
/// error does not grow by more than [`NEGLIGIBLE_SHARE_OF_NOISE`] of a noise floor, and the
/// moved model is not worse than the starting model (`before_errors`) by the rule of
/// [`crate::decide::withdraw::worse_than_start`], which the withdrawal before it applied;
/// then `found`'s values, the intervals' centres, `after` and `after_errors` are the moved
/// model's.
fn move_to_least_squares(
    cx: &Context,
    found: &mut crate::decide::findings::Findings,
    steps: &mut Steps<'_>,
    (after, after_errors): (&mut Replay, &mut Errors),
    before_errors: &Errors,
    replay_accurately: &AccurateReplay,
    progress: &mut dyn FnMut(&str),
) {
    let mut settled = found.params.clone();
    for (name, interval) in steps.names.iter().zip(steps.intervals.iter()) {
        if let Some(i) = interval {
            let (lower, upper) = declared_bounds(name);
            let value = (parameter_value(&settled, name) + i.step).clamp(lower, upper);
            if set_parameter(&mut settled, name, value).is_err() {
                return;
            }
        }
    }
    if settled == found.params {
        return;
    }
    let misfit_before = training_misfit(steps.problem, steps.accurate);
    let (moved, moved_errors) = match replay_accurately(&settled) {
        Ok(replayed) => replayed,
        Err(why) => {
            progress(&format!(
                "  the step to the error-controlled replay's least squares was refused: {why}"
            ));
            return;
        }
    };
    let taken = training_misfit(steps.problem, &at_fitted_rows(cx, &moved)) < misfit_before
        && moved_errors.heldout_rms <= after_errors.heldout_rms + NEGLIGIBLE_SHARE_OF_NOISE * cx.noise
        && !crate::decide::withdraw::worse_than_start(&moved_errors, before_errors, cx.noise);
    if !taken {
        progress("  the step to the error-controlled replay's least squares did not lower the misfit within the errors allowed: not taken");
        return;
    }
    let moves: Vec<String> = steps
        .names
        .iter()
        .zip(steps.intervals.iter_mut())
        .filter_map(|(name, interval)| {
            let (from, to) = (parameter_value(&found.params, name), parameter_value(&settled, name));
            *interval = interval.map(|i| i.shifted(to - from));
            (to != from).then(|| format!("{name} {from:.6e} → {to:.6e}"))
        })
        .collect();
    progress(&format!(
        "  the amounts moved to the error-controlled replay's least squares ({}): held-out force error {:.5} → {:.5} N",
        moves.join(", "),
        after_errors.heldout_rms,
        moved_errors.heldout_rms
    ));
    found.params = settled;
    for e in found.effects.iter_mut() {
        for (name, value) in e.parameters.iter_mut() {
            *value = parameter_value(&found.params, name);
        }
    }
    for d in found.discovered.iter_mut() {
        for (name, value) in d.parameters.iter_mut() {
            *value = parameter_value(&found.params, name);
        }
    }
    (*after, *after_errors) = (moved, moved_errors);
}

/// The misfit the fits minimise, on the training blocks: the sum of squares of each measured
/// channel's residual in its noise floors.
fn training_misfit(problem: &crate::fit::Problem, replay: &Replay) -> f64 {
    let modelled = [&replay.force, &replay.p1, &replay.p2];
    (0..crate::replay::signals::CHANNELS)
        .filter(|&c| problem.weights[c] != 0.0)
        .map(|c| {
            problem.measured[c]
                .iter()
                .zip(modelled[c])
                .zip(problem.blocks)
                .filter(|(_, &b)| b == Block::Training)
                .map(|((m, y), _)| (problem.weights[c] * (m - y)).powi(2))
                .sum::<f64>()
        })
        .sum()
}

/// The final accurate replay, the verdict (step 6) and the tests of the residual; `start` is
/// the starting model, its accurate replay and the check of the fits' replay against it.
pub(crate) fn conclude(
    cx: &Context,
    start: (Actuator, Replay, crate::replay::agreement::FastReplayCheck),
    mut found: crate::decide::findings::Findings,
    mut joint_refit: Option<(f64, f64)>,
    mut input_checks: Vec<String>,
    calibrated: Vec<Calibrated>,
    glitches: Vec<crate::input::glitches::Glitch>,
    replays: usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    let (full, noise) = (cx.full, cx.noise);
    // A model without a force on the stopper's motion reads no acceleration.
    let start_share = start.0.params.stopper_acceleration_input_share;
    for params in std::iter::once(&mut found.params).chain(found.stages.iter_mut().map(|s| &mut s.params)) {
        if !Actuator::new(params.clone())?.reads_stopper_motion {
            params.stopper_acceleration_input_share = start_share;
        }
    }
    // The reported figures come from the accurate, error-controlled replay of every sample.
    progress("final replays with the error-controlled integrator");
    let (before_model, before, fast_replay) = start;
    let n = full.len();
    let thinned = cx.recording.full_rate.as_ref().map(|f| f.rows.as_slice());
    let full_blocks = match thinned {
        Some(_) => crate::input::blocks::blocks(&full.time, &full.x_s, cx.settled_from, &cx.set_aside),
        None => cx.blocks.clone(),
    };
    let blocks = &full_blocks;
    let replay_accurately = |params: &Parameters| -> Result<(Replay, Errors), String> {
        let with = replay(&Actuator::new(params.clone())?, full, 1e-5, n)?;
        let e = errors(&with, full, blocks);
        Ok((with, e))
    };
    let (mut after, mut after_errors) = replay_accurately(&found.params)?;
    let before_errors = errors(&before, full, blocks);
    let withdrawn = crate::decide::withdraw::withdraw_if_worse(
        &mut found,
        &before_model.params,
        &before_errors,
        &after_errors,
        noise,
        &mut |params: &Parameters| {
            progress("  an earlier round's model replayed with the error-controlled integrator");
            replay_accurately(params)
        },
    )?;
    let withdrawn = withdrawn.map(|(w, kept)| {
        progress(&format!(
            "the accurate replay finds the model with every addition worse than the starting model (held-out {:.4} against {:.4} N, whole {:.4} against {:.4} N): {} withdrawn{}",
            w.heldout_with,
            before_errors.heldout_rms,
            w.whole_with,
            before_errors.rms,
            w.names.join(" and "),
            if w.kept.is_empty() { String::new() } else { format!(", {} kept", w.kept.join(" and ")) }
        ));
        joint_refit = found.joint_refit;
        (after, after_errors) = kept.unwrap_or_else(|| (before.clone(), before_errors));
        w
    });
    drop_terms_at_defaults(&mut found, progress);
    settle_and_set_intervals(
        cx,
        &mut found,
        (&mut after, &mut after_errors),
        &before_errors,
        &replay_accurately,
        progress,
    );
    let final_model = Actuator::new(found.params.clone())?;
    let after = after;
    // The additions were scored on the fixed-step replay, checked against the accurate one
    // on the starting model only: a term that follows a signal switching at every sample can
    // part them again.
    let fast_replay_final = if found.params != before_model.params {
        let fast = replay_fast(&final_model, full, n)?;
        let departure = rms(&difference(&fast.force, &after.force));
        let ratio = departure / noise;
        if ratio > crate::replay::agreement::AGREEMENT_WITHIN_NOISE {
            let sentence = format!(
                "The fits' fixed-step replay ({}{} ms steps) of the final model departs from its error-controlled replay by {departure:.4} N of force ({ratio:.2} noise floors), more than the {} noise floor it was held to on the starting model: the additions were scored on a replay that parts from the accurate one; every error reported is the accurate replay's",
                if fast_replay.third_order { "third-order, " } else { "" },
                fast_replay.step * 1e3,
                crate::replay::agreement::AGREEMENT_WITHIN_NOISE
            );
            progress(&sentence);
            input_checks.push(sentence);
        }
        Some((departure, ratio))
    } else {
        None
    };
    let split = cx
        .pressure_noise
        .and_then(|pn| crate::verdict::split::pressure_split(&final_model, full, &after, noise, pn, blocks));
    // What the remainder follows, on the fits' rows.
    let after_at_rows = thinned.map(|rows| after.at_rows(rows));
    let after_rows = after_at_rows.as_ref().unwrap_or(&after);
    let recording = cx.recording;
    let chain = ChainSignals::new(&final_model, recording, after_rows);
    let remainder = Signature::of(
        &recording.time,
        &difference(&recording.force, &after_rows.force),
        &chain,
        "N",
    );
    let unexplained = what_stays_unexplained(
        cx,
        &found.localization,
        after_rows,
        &after_errors,
        split.as_ref(),
        &chain,
        &remainder,
    );
    let heldout_residual: Vec<f64> = full
        .force
        .iter()
        .zip(&after.force)
        .zip(blocks)
        .filter(|(_, &b)| b == Block::HeldOut)
        .map(|((f, a), _)| f - a)
        .collect();
    let (ljung_box, lag1) = whiteness(&heldout_residual, 20);
    let residual_tests = json!({
        "whiteness": {"lag1_autocorrelation": lag1, "ljung_box_q20": ljung_box, "white_at_5_percent": ljung_box < 31.41},
        "signature": remainder.to_json("N"),
    });
    Ok(Diagnosis {
        samples: n,
        noise_floor: noise,
        pressure_noise: cx.pressure_noise,
        input_checks,
        glitches,
        before: before_errors,
        after: after_errors,
        settling: cx.settled_from - full.time[0],
        calibrated,
        effects: found.effects,
        discovered: found.discovered,
        joint_refit,
        candidates: found.first_candidates,
        localization: found.localization,
        pressure_split: split,
        unexplained,
        residual_tests,
        parameters: found.params,
        before_force: before.force,
        after_force: after.force,
        replays,
        withdrawn,
        fast_replay,
        fast_replay_final,
        start_pressures: crate::replay::start_pressures(&final_model, full),
        stopper_positions: cx.stopper_positions,
        acceleration_window: if final_model.params.stopper_acceleration_input_share > 0.0 {
            full.acceleration_window
        } else {
            0.0
        },
    })
}

/// Explained when the held-out force error is within its noise; otherwise, or when the
/// pressures depart while the force does not, the remainder: its place and signature.
fn what_stays_unexplained(
    cx: &Context,
    localization: &Option<Localization>,
    after: &Replay,
    after_errors: &Errors,
    split: Option<&PressureSplit>,
    chain: &ChainSignals,
    remainder: &Signature,
) -> Option<Unexplained> {
    let noise = cx.noise;
    let explained = after_errors.heldout_rms <= EXPLAINED_WITHIN_NOISE * noise;
    // Every measured channel counts: pressures that depart while the force does not (a
    // pressure transducer, say) leave a remainder too, with its place and signature.
    if explained && !crate::verdict::split::pressures_off(split, cx.pressure_noise, after_errors.pressure_rms) {
        return None;
    }
    let (mut location, mut family, mut alternatives) = match localization {
        Some(l) => (l.location, l.family, l.alternatives()),
        None => (Place::Unknown, Family::Unknown, vec![]),
    };
    let share_at = |place: Place| {
        localization
            .as_ref()
            .and_then(|l| l.by_location.iter().find(|(p, _, _)| *p == place))
            .map_or(0.0, |(_, e, _)| *e)
    };
    // Pressures at their noise and a force that does not agree with them place the departure
    // after the pressures, in the mechanics or the force sensor, though no candidate there
    // explains a good part of it: both are named, the better candidates' place first.
    let after_the_pressures =
        location == Place::Unknown && split.map_or(false, PressureSplit::departure_after_the_pressures);
    if after_the_pressures {
        let (first, second) = if share_at(Place::ForceSensor) > share_at(Place::Mechanics) {
            (Place::ForceSensor, Place::Mechanics)
        } else {
            (Place::Mechanics, Place::ForceSensor)
        };
        (location, family, alternatives) = (first, Family::Unknown, vec![second]);
    }
    let ratio = after_errors.heldout_rms / noise.max(1e-12);
    let place = if location == Place::Unknown {
        "no candidate place in the chain explains a good part of it".to_string()
    } else if after_the_pressures {
        format!(
            "the pressures agree with the model's and the force does not agree with them, so the model departs in the {location} or the {} (the pressure channels tell these two apart from the rest of the chain but not from each other), where no candidate explains a good part of it (the best there: {:.0} % and {:.0} % of the held-out misfit)",
            alternatives[0],
            100.0 * share_at(location),
            100.0 * share_at(alternatives[0])
        )
    } else {
        let share = localization
            .as_ref()
            .and_then(|l| l.best_at(location))
            .map_or(0.0, |s| s.explained);
        format!(
            "the model departs most likely at the {location} ({family}: a correction there explains {:.0} % of the held-out misfit){}",
            100.0 * share,
            if alternatives.is_empty() {
                String::new()
            } else {
                format!(", though the {} explain nearly as much", alternatives.iter().map(|p| p.as_str()).collect::<Vec<_>>().join(" and the "))
            }
        )
    };
    let (sentence, signature) = if explained {
        let noise_pa = cx
            .pressure_noise
            .expect("pressures depart only where the recording has them");
        let whole = after_errors
            .pressure_rms
            .expect("pressures depart only where the recording has them");
        let whole_ratio = [whole[0] / noise_pa[0].max(1e-9), whole[1] / noise_pa[1].max(1e-9)];
        let worse = split.map_or(
            usize::from(whole_ratio[1] > whole_ratio[0]),
            PressureSplit::worse_chamber,
        );
        let recording = cx.recording;
        let measured = if worse == 0 { &recording.p1 } else { &recording.p2 };
        let modelled = if worse == 0 { &after.p1 } else { &after.p2 };
        let residual = difference(measured.as_ref().expect("pressures"), modelled);
        let signature = Signature::of(&recording.time, &residual, chain, "Pa");
        let figures = match split {
            Some(s) => format!(
                "by {:.0} and {:.0} Pa RMS after the start ({:.1}× and {:.1}× their noise; {:.1}× and {:.1}× over the whole recording)",
                s.pressure_rms[0],
                s.pressure_rms[1],
                s.pressure_ratio[0],
                s.pressure_ratio[1],
                s.whole_pressure_ratio[0],
                s.whole_pressure_ratio[1],
            ),
            None => format!(
                "by {:.0} and {:.0} Pa RMS over the whole recording ({:.1}× and {:.1}× their noise)",
                whole[0], whole[1], whole_ratio[0], whole_ratio[1],
            ),
        };
        (
            format!(
                "The force is explained to within its noise ({:.4} N held out, {ratio:.1}× the noise floor), but the pressures depart from the model's {figures}; {place}. Chamber {}: {}",
                after_errors.heldout_rms,
                worse + 1,
                signature.sentence
            ),
            signature,
        )
    } else {
        (
            format!(
                "A held-out force error of {:.4} N ({ratio:.1}× the noise floor) stays; {place}. {}",
                after_errors.heldout_rms, remainder.sentence
            ),
            remainder.clone(),
        )
    };
    Some(Unexplained {
        rms: after_errors.heldout_rms,
        ratio_to_noise: ratio,
        location,
        family,
        alternatives,
        sentence,
        signature,
    })
}

/// Ljung–Box statistic of the first `lags` autocorrelations, and the lag-1 autocorrelation.
fn whiteness(residual: &[f64], lags: usize) -> (f64, f64) {
    let n = residual.len();
    if n <= lags + 1 {
        return (0.0, 0.0);
    }
    let mean = residual.iter().sum::<f64>() / n as f64;
    let c0: f64 = residual.iter().map(|r| (r - mean).powi(2)).sum::<f64>();
    if c0 == 0.0 {
        return (0.0, 0.0);
    }
    let mut q = 0.0;
    let mut first = 0.0;
    for lag in 1..=lags {
        let c: f64 = (lag..n)
            .map(|k| (residual[k] - mean) * (residual[k - lag] - mean))
            .sum();
        let rho = c / c0;
        if lag == 1 {
            first = rho;
        }
        q += rho * rho / (n - lag) as f64;
    }
    (n as f64 * (n as f64 + 2.0) * q, first)
}
