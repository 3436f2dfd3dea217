//! Refits of what was added: together after the rounds, or a few constants at a time.

use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::candidates::Mechanism;
use crate::candidates::Term;
use crate::context::Context;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// Whether an added parameter is an amount a refit may move: a curve's knot count and
/// abscissae are its grid, and a modulation slot's constant, signal, frequency and knot
/// count say what varies with what (its knots' abscissae move: a band of friction 60–66 mm
/// wide, first placed at the signal's quantiles, was refitted from 2.5 noise floors to 1.2).
/// A flexible slot's grid values move; its constant, signals, lags and knots stay.
pub(crate) fn refittable(name: &str) -> bool {
    if name.starts_with("modulation_") {
        return name.contains("_y_") || name.contains("_x_");
    }
    // A flexible slot's grid values; its signals, lags and knots say what the surface is over.
    if name.starts_with("flexible_") {
        return name.contains("_y_");
    }
    !name.ends_with("_curve_knots") && !name.contains("_curve_x_")
}

/// The added parameters as one candidate, starting from their current values.
pub(crate) fn joint_candidate(params: &Parameters, names: &[&'static str]) -> Candidate {
    let terms: Vec<Term> = names
        .iter()
        .map(|&name| {
            let value = parameter_value(params, name);
            let (lower, upper) = crate::candidates::declared_bounds(name);
            Term {
                name,
                unit: crate::candidates::unit_of(name),
                mechanism: Mechanism::Parameter(name),
                neutral: value,
                step: 1e-3 * value.abs(),
                lower,
                upper,
            }
        })
        .collect();
    Candidate {
        label: "joint refit",
        location: Place::Unplaced,
        family: Family::Unclassified,
        named: None,
        terms,
        settings: vec![],
    }
}

/// The constants `names` of `params` refitted together (three Gauss–Newton iterations from
/// where they stand): the parameters with them, and the held-out force error before and
/// after, N. `None` when the fit fails or its values are not a valid model.
pub(crate) fn refit_constants(
    cx: &Context,
    params: &Parameters,
    names: &[&'static str],
    replays: &mut usize,
) -> Result<Option<(Parameters, f64, f64)>, String> {
    let (recording, n) = (cx.recording, cx.n);
    let problem = Problem::new(recording, params, &cx.blocks, cx.channel_noise);
    problem.set_jobs(cx.options.jobs);
    let candidate = joint_candidate(params, names);
    let current = replay_fast(&Actuator::new(params.clone())?, recording, n)?;
    let before_joint = rms_where(
        &difference(&recording.force, &current.force),
        &cx.blocks,
        Block::HeldOut,
    );
    let step_of = |name: &'static str| candidate.terms.iter().find(|t| t.name == name).map_or(0.0, |t| t.step);
    let sensitivities = |name: &'static str| problem.sensitivity(name, step_of(name), &current);
    let Ok(fit) = problem.fit(&candidate, 3, &current, &sensitivities) else {
        return Ok(None);
    };
    *replays += fit.replays + names.len();
    let mut trial = params.clone();
    // The command the driver sees does not fall as the logged one rises, after the refit as
    // when the curve was first fitted.
    let mut refitted: Vec<(&'static str, f64)> = names.iter().copied().zip(fit.values.iter().copied()).collect();
    crate::candidates::command_curve::monotone_command(&mut refitted);
    let valid = refitted
        .iter()
        .all(|(name, value)| set_parameter(&mut trial, name, *value).is_ok())
        && trial.validate().is_ok();
    if !valid {
        return Ok(None);
    }
    let with = replay_fast(&Actuator::new(trial.clone())?, recording, n)?;
    *replays += 1;
    let after_joint = rms_where(&difference(&recording.force, &with.force), &cx.blocks, Block::HeldOut);
    Ok(Some((trial, before_joint, after_joint)))
}
