//! A new term with the earlier additions refitted beside it. Each round fits its candidates
//! with what was added before held, so an addition that took up part of a second departure
//! locks that part in: an extra jet pipe lag in series with the thesis's corner was fitted
//! as one slower corner (the two lags as one), and then no single candidate of the next
//! round could take the thesis's corner back (2.0 noise floors left, the best candidate 47 %
//! of them). When neither one candidate nor a pair explains the force, the leading
//! candidates that Gauss–Newton can fit are fitted again with the earlier additions'
//! constants free beside them; one that, replayed, earns its penalty on the held-out blocks
//! and does better than the best candidate alone is added, with the earlier constants as
//! that fit left them. These fits are damped in Marquardt's way: the earlier constants can
//! be nearly collinear (a supply line resistance beside a supply pressure that varies with a
//! pressure), and there the plain Gauss–Newton step overshoots, every shortened step is
//! refused, and all the fits ended where they began (a command lag beside them was left at
//! zero and 5.1 noise floors stayed; damped, it took 5.1 to 2.8).

use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::candidates::Candidate;
use crate::candidates::Mechanism;
use crate::context::Context;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::findings::Findings;
use crate::decide::pairs::joined;
use crate::fit::localize::{discovery_penalised, discovery_penalty_per_term, heldout_count, WantedSensitivities};
use crate::fit::refit::joint_candidate;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Fit;
use crate::fit::Problem;
use crate::parallel::parallel_map;
use crate::policy::BESIDE_MEMBERS;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use jetpipe_model::physics::parameters::Parameters;

/// Gauss–Newton iterations of each fit beside the earlier additions.
const ITERATIONS: usize = 3;

/// Whether every term of a candidate is fitted by Gauss–Newton (a constant, a corner as its
/// time constant, a lag on the command, a regressor): at most two, and no search.
fn fitted_by_gauss_newton(c: &Candidate) -> bool {
    c.named.is_none()
        && c.settings.is_empty()
        && c.terms.len() <= 2
        && c.terms.iter().all(|t| {
            matches!(
                t.mechanism,
                Mechanism::Parameter(_)
                    | Mechanism::TimeConstantOf(_)
                    | Mechanism::CommandLag
                    | Mechanism::Modulated { .. }
                    | Mechanism::Output { .. }
            )
        })
}

/// The constants of the additions so far, as they stand in `params` (a curve's knots are
/// its grid, not amounts to refit).
pub(crate) fn earlier_constants(f: &Findings) -> Vec<&'static str> {
    let mut names: Vec<&'static str> = vec![];
    for (name, _) in f
        .effects
        .iter()
        .flat_map(|e| e.parameters.iter())
        .chain(f.discovered.iter().flat_map(|d| d.parameters.iter()))
    {
        if parameter_value(&f.params, name) != 0.0 && crate::fit::refit::refittable(name) && !names.contains(name) {
            names.push(name);
        }
    }
    names
}

/// The best candidate of the round with the earlier additions refitted beside it: its term,
/// and the parameters with both. `None` when nothing was added before, the force is within
/// its noise, or no such fit earns its penalty.
#[allow(clippy::too_many_arguments)]
pub(crate) fn best_beside_earlier(
    cx: &Context,
    problem: &Problem,
    found: &Localization,
    f: &Findings,
    current: &Replay,
    heldout_before: &[f64; CHANNELS],
    force_before: f64,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(Option<DiscoveredTerm>, Parameters)>, String> {
    let params = &f.params;
    let earlier = earlier_constants(f);
    if earlier.is_empty() {
        return Ok(None);
    }
    let Some(single) = found.candidates.first() else {
        return Ok(None);
    };
    if force_before <= EXPLAINED_WITHIN_NOISE * cx.noise {
        return Ok(None);
    }
    let count = heldout_count(&cx.blocks) as f64;
    let penalty = discovery_penalty_per_term(count);
    let single_score = discovery_penalised(single, count);
    let mut ranked: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| fitted_by_gauss_newton(&s.fit.candidate))
        .filter(|s| {
            // A candidate on an earlier constant is that constant refitted, not a new term.
            s.fit
                .candidate
                .terms
                .iter()
                .all(|t| t.mechanism.model_parameter().map_or(true, |n| !earlier.contains(&n)))
        })
        .collect();
    ranked.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    ranked.truncate(BESIDE_MEMBERS);
    if ranked.is_empty() {
        return Ok(None);
    }
    progress(&format!(
        "the {} leading candidates with the {} constants added before refitted beside them",
        ranked.len(),
        earlier.len()
    ));
    let earlier_terms = joint_candidate(params, &earlier);
    let mut wanted = WantedSensitivities::default();
    wanted.add_constants_of(&earlier_terms.terms);
    for s in &ranked {
        wanted.add_constants_of(&s.fit.candidate.terms);
    }
    let jobs = cx.options.jobs;
    *replays += wanted.len();
    let sensitivities = wanted.taken(problem, current, jobs, "beside", &None);
    let shared = |name: &'static str| sensitivities.get(name);
    let fits: Vec<Option<Fit>> = parallel_map(&ranked, jobs, |s| {
        problem
            .fit_damped(&joined(&s.fit.candidate, &earlier_terms), ITERATIONS, current, &shared)
            .ok()
            .map(Fit::without_prediction)
    });
    *replays += fits.iter().flatten().map(|f| f.replays).sum::<usize>();
    // Only the new term pays a penalty: the earlier constants have paid theirs.
    let own_terms = |s: &Scored, fit: &Fit| {
        fit.values
            .iter()
            .zip(&fit.candidate.terms)
            .take(s.fit.candidate.terms.len())
            .filter(|(v, t)| **v != t.neutral)
            .count() as f64
    };
    let score = |s: &Scored, fit: &Fit| fit.heldout_total() + own_terms(s, fit) * penalty;
    for (s, fit) in ranked.iter().zip(&fits) {
        if let Some(fit) = fit {
            progress(&format!("    {}: {:.0}", s.fit.candidate.label, score(s, fit)));
        }
    }
    let Some((s, fit)) = ranked
        .iter()
        .zip(&fits)
        .filter_map(|(s, fit)| fit.as_ref().map(|fit| (*s, fit)))
        .min_by(|a, b| score(a.0, a.1).total_cmp(&score(b.0, b.1)))
    else {
        return Ok(None);
    };
    let candidate = &s.fit.candidate;
    let (own, refitted) = fit.values.split_at(candidate.terms.len());
    let Some(set) = crate::decide::discover::model_terms(candidate, own, params, problem) else {
        progress("  the FMU has no parameters for it");
        return Ok(None);
    };
    if set.iter().any(|(n, _)| earlier.contains(n)) {
        return Ok(None);
    }
    let mut trial = params.clone();
    if earlier
        .iter()
        .zip(refitted)
        .map(|(n, v)| (*n, *v))
        .chain(set.iter().copied())
        .any(|(n, v)| set_parameter(&mut trial, n, v).is_err())
        || trial.validate().is_err()
    {
        return Ok(None);
    }
    let used = own
        .iter()
        .zip(&candidate.terms)
        .filter(|(v, t)| **v != t.neutral)
        .count() as f64;
    let judged = crate::decide::pairs::Replayed::judge(cx, problem, &trial, heldout_before, replays)?;
    progress(&format!(
        "  the {} with the earlier constants refitted, in the model: force held-out {force_before:.4} -> {:.4} N, misfit {:.0} + penalty {:.0} against {:.0} before and the best candidate's {single_score:.0}",
        candidate.label,
        judged.after,
        judged.misfit,
        used * penalty,
        heldout_before.iter().sum::<f64>()
    ));
    if !judged.earns(used * penalty, single_score, force_before, cx.noise) {
        return Ok(None);
    }
    let after = judged.after;
    if used == 0.0 {
        // The new term stayed off: what was gained is the earlier additions' refit alone, and
        // they report it, not a term of zero size.
        progress(&format!(
            "the earlier additions refitted (the {} stays off)",
            candidate.label
        ));
        return Ok(Some((None, trial)));
    }
    progress(&format!(
        "adding a {} at the {}, the earlier additions refitted beside it",
        candidate.label, candidate.location
    ));
    let term = DiscoveredTerm::fitted(candidate, set, params, force_before, after);
    Ok(Some((Some(term), trial)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn candidate(terms: Vec<Mechanism>) -> Candidate {
        Candidate::of_mechanisms(terms)
    }

    #[test]
    fn a_corner_or_a_constant_is_refitted_beside_the_earlier_ones_and_a_search_is_not() {
        assert!(fitted_by_gauss_newton(&candidate(vec![Mechanism::TimeConstantOf(
            "omega_cd"
        )])));
        assert!(fitted_by_gauss_newton(&candidate(vec![
            Mechanism::Parameter("omega_2"),
            Mechanism::Parameter("zeta_2")
        ])));
        assert!(!fitted_by_gauss_newton(&candidate(vec![Mechanism::Searched(
            "command_filter_frequency"
        )])));
        assert!(!fitted_by_gauss_newton(&candidate(vec![Mechanism::CommandLimit])));
        assert!(!fitted_by_gauss_newton(&candidate(vec![
            Mechanism::Parameter("a"),
            Mechanism::Parameter("b"),
            Mechanism::Parameter("c")
        ])));
    }
}
