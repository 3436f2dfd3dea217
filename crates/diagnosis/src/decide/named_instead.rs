//! A discovered term where a named effect can stand. Each round fits its candidates with what
//! was added before held, so an earlier addition fitted while a named effect was still off
//! carries part of that effect, and in the next round the named effect falls short of its
//! share: a term of the same place with no name takes the round, and the joint refit then
//! brings both to the noise (a force sensor's 50 Hz filter, fitted first at 34 Hz beside an
//! unseen smooth friction, left the friction 73 % of the next round, and a force in the
//! position times the velocity's sign took it). After the rounds, each discovered term at a
//! place with a named effect of its family that has its own signature test (and on the force
//! side of the piston, any such effect there) is tried as that effect
//! instead: the term goes back to its start values, the named effect is fitted in its place,
//! every addition is refitted beside it, and where the held-out misfit with the named
//! parameters' penalty is within one penalty of the term's and the effect's signature shows,
//! the named effect replaces the term: a name is the simpler reading of the same departure.
//! It does so only where the named effect brings the force to the noise, and the pressures
//! the recording has: beside a remainder in any channel, the term may be standing in for part
//! of it, and a name would claim what it cannot show.

use crate::candidates::catalogue;
use crate::candidates::parameter_value;
use crate::candidates::without_addition;
use crate::candidates::Candidate;
use crate::context::Context;
use crate::decide::additions::AddedEffect;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::findings::Findings;
use crate::decide::named_effect::apply_named;
use crate::decide::named_effect::named_signature;
use crate::fit::localize::discovery_penalty_per_term;
use crate::fit::localize::heldout_count;
use crate::fit::localize::terms_used;
use crate::fit::refit::refittable;
use crate::fit::scored::Scored;
use crate::fit::Problem;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::replay::replay_fast;
use crate::replay::Replay;
use crate::vocabulary::Place;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// Whether a place is on the force side of the piston, where a force the stopper's motion
/// sets reads the same whether it acts on the piston or is added by the sensor: a smooth
/// friction was found as the force sensor's offset varying with the stopper velocity.
fn force_side(place: Place) -> bool {
    matches!(place, Place::Mechanics | Place::ForceSensor)
}

/// Gauss–Newton iterations of the named effect's fit in the term's place.
const ITERATIONS: usize = 3;

/// Replace, one by one, the discovered terms that a named effect at their place does as well
/// as. Whether any was replaced.
pub(crate) fn named_instead_of_discovered(
    cx: &Context,
    f: &mut Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<bool, String> {
    let mut replaced = false;
    let mut k = 0;
    while k < f.discovered.len() {
        if let Some((effect, params)) = named_in_place_of(cx, f, k, replays, progress)? {
            let term = f.discovered.remove(k);
            progress(&format!(
                "{} instead of the {} at the {}",
                effect.name, term.candidate, term.location
            ));
            f.params = params;
            f.effects.push(effect);
            f.newest = Some((true, f.effects.len() - 1));
            crate::decide::findings::sync_earlier(f);
            replaced = true;
        } else {
            k += 1;
        }
    }
    Ok(replaced)
}

/// The named effect, as added, and the parameters with it and every other addition
/// refitted, that replaces the discovered term `k`; `None` when none does as well.
fn named_in_place_of(
    cx: &Context,
    f: &Findings,
    k: usize,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(AddedEffect, Parameters)>, String> {
    let term = &f.discovered[k];
    let place = term.location;
    let named: Vec<Candidate> = catalogue(
        &f.params,
        cx.pressure_noise.is_some(),
        None,
        &crate::candidates::curves::CurveKnots::default(),
    )
    .into_iter()
    .filter(|c| c.location == place && c.family == term.family || force_side(place) && force_side(c.location))
    .filter(|c| {
        c.named.map_or(false, |n| {
            crate::decide::named::has_signature_test(n) && !f.effects.iter().any(|e| e.name == n)
        })
    })
    .collect();
    if named.is_empty() {
        return Ok(None);
    }
    let without = match without_addition(&f.params, &f.start, &term.parameters) {
        Ok(without) => without,
        Err(why) => {
            progress(&format!(
                "named effects in place of the {} not tried: the model without it is refused ({why})",
                term.candidate
            ));
            return Ok(None);
        }
    };
    let count = heldout_count(&cx.blocks) as f64;
    let penalty = discovery_penalty_per_term(count);
    let (term_misfit, term_force) = crate::decide::alternatives::judge(
        cx,
        &Problem::new(cx.recording, &without, &cx.blocks, cx.channel_noise),
        &f.params,
        replays,
    )?;
    let term_terms = term
        .parameters
        .iter()
        .filter(|(name, value)| *value != parameter_value(&f.start, name))
        .count() as f64;
    let term_score = term_misfit + term_terms * penalty;
    let others = refitted_beside(f, |d| !std::ptr::eq(d, term), |_| true, &without);
    let against = format!(
        "in place of the {}, every addition refitted: {{misfit}} held out + penalty {{penalty}} against {term_misfit:.0} + {:.0} (noise floors squared), force {{force}} against {term_force:.4} N",
        term.candidate,
        term_terms * penalty
    );
    let Some(fit) = best_named_fit(cx, &without, &others, &named, &against, replays, progress)? else {
        return Ok(None);
    };
    let (score, force) = (fit.score, fit.force);
    if score > term_score + penalty || force > term_force + 0.05 * cx.noise {
        return Ok(None);
    }
    // A name claims the mechanism. While a remainder above the noise stays, the term may be
    // a stand-in for part of what remains, and a named effect fitted in its place takes on
    // the stand-in's evidence: without pressures, a 0.79 ms force sensor delay beside a
    // supply restriction left a force sensor curve standing in for the restriction at 2.1
    // noise floors, and the sensor's offset and gain in its place read it as a gain of 0.98.
    if force > EXPLAINED_WITHIN_NOISE * cx.noise {
        progress(&format!(
            "  {}: not named in the {}'s place while {force:.4} N stays, above {EXPLAINED_WITHIN_NOISE} noise floors",
            fit.scored.fit.candidate.named.unwrap_or(fit.scored.fit.candidate.label),
            term.candidate
        ));
        return Ok(None);
    }
    // So does a remainder in the pressures: a force-side term in the pressures' remainder
    // took its place beside laminar leaks standing in for a turbulent flow between the
    // chambers (pressures 1.7 noise floors off held out), and the sensor's offset and gain
    // fitted there, 1.4 mN and 1e-5, were named.
    if let Some(ratio) = pressures_off_held_out(cx, &fit.params, replays)? {
        progress(&format!(
            "  {}: not named in the {}'s place while a pressure stays {ratio:.2} noise floors off held out",
            fit.scored.fit.candidate.named.unwrap_or(fit.scored.fit.candidate.label),
            term.candidate
        ));
        return Ok(None);
    }
    let name = fit.scored.fit.candidate.named.expect("a named candidate");
    let (test, parameters) = fit.signature(cx, replays)?;
    if !test.present {
        progress(&format!("  {name}: its signature is absent"));
        return Ok(None);
    }
    let values: Vec<String> = parameters.iter().map(|(n, v)| format!("{n} = {v:.4e}")).collect();
    let before = term.heldout_before;
    let evidence = format!(
        "Found first as the term \"{}\" at the {place}, while another addition still carried part of it; in its place, with every addition refitted beside it, {name} ({}) leaves the held-out force error at {force:.4} N against the term's {term_force:.4} N (noise floor {:.4} N){}.",
        term.candidate,
        values.join(", "),
        cx.noise,
        if test.sentence.is_empty() {
            String::new()
        } else {
            format!("; {}", test.sentence)
        },
    );
    Ok(Some((
        AddedEffect {
            name,
            location: place,
            parameters,
            evidence,
            heldout_before: before,
            heldout_after: force,
            share: 1.0 - (force / before).powi(2),
            remainder_follows: String::new(),
            rivals: vec![],
            tied_effects: vec![],
            intervals: vec![],
            // The effect stands at the term's place, which won by as much.
            margin: term.margin,
        },
        fit.params,
    )))
}

/// The held-out RMS error of the pressure further from the model `params`', in its noise
/// floors, where it is above [`EXPLAINED_WITHIN_NOISE`]; `None` where both are within it or
/// the recording has no pressures.
fn pressures_off_held_out(cx: &Context, params: &Parameters, replays: &mut usize) -> Result<Option<f64>, String> {
    if cx.pressure_noise.is_none() {
        return Ok(None);
    }
    let problem = Problem::new(cx.recording, params, &cx.blocks, cx.channel_noise);
    let with = replay_fast(&Actuator::new(params.clone())?, cx.recording, cx.n)?;
    *replays += 1;
    let (_, heldout) = problem.errors(&[with.force, with.p1, with.p2]);
    let count = heldout_count(&cx.blocks) as f64;
    let worst = (1..heldout.len())
        .filter(|&c| problem.weights[c] > 0.0)
        .map(|c| (heldout[c] / count).sqrt())
        .fold(0.0, f64::max);
    Ok((worst > EXPLAINED_WITHIN_NOISE).then_some(worst))
}

/// The refittable parameters of every addition but those `keep_term` / `keep_effect` leave
/// out, that are set in `without`.
pub(crate) fn refitted_beside(
    f: &Findings,
    keep_term: impl Fn(&DiscoveredTerm) -> bool,
    keep_effect: impl Fn(&AddedEffect) -> bool,
    without: &Parameters,
) -> Vec<&'static str> {
    f.effects
        .iter()
        .filter(|e| keep_effect(e))
        .flat_map(|e| e.parameters.iter())
        .chain(
            f.discovered
                .iter()
                .filter(|d| keep_term(d))
                .flat_map(|d| d.parameters.iter()),
        )
        .map(|(name, _)| *name)
        .filter(|name| parameter_value(without, name) != 0.0 && refittable(name))
        .collect()
}

/// A named effect fitted in the place of something taken out of the model.
pub(crate) struct NamedFit {
    /// Held-out misfit (noise floors squared) plus the penalty of the terms it uses.
    pub score: f64,
    /// Held-out force RMS, N.
    pub force: f64,
    pub scored: Scored,
    /// The model parameters that carry it.
    pub carried: Vec<&'static str>,
    /// The model with it and every other addition refitted.
    pub params: Parameters,
    /// The model it was fitted into, and its replay.
    pub without_model: Actuator,
    pub without_replay: Replay,
}

impl NamedFit {
    /// The named effect's signature in the residual of the model it was fitted into, and
    /// the model parameters that carry it as `apply_named` set them (a sensor's offset and
    /// gain are fitted as errors of the values it had).
    #[allow(clippy::type_complexity)]
    pub(crate) fn signature(
        &self,
        cx: &Context,
        replays: &mut usize,
    ) -> Result<(crate::decide::named::SignatureTest, Vec<(&'static str, f64)>), String> {
        let name = self.scored.fit.candidate.named.expect("a named candidate");
        let with = replay_fast(&Actuator::new(self.params.clone())?, cx.recording, cx.n)?;
        *replays += 1;
        let test = named_signature(
            name,
            cx.recording,
            &self.without_model,
            &self.without_replay,
            &with.force,
            &cx.blocks,
            cx.noise,
            cx.mechanical_noise,
        );
        let parameters = self
            .carried
            .iter()
            .map(|name| (*name, parameter_value(&self.params, name)))
            .collect();
        Ok((test, parameters))
    }
}

/// The best of the `named` candidates fitted into `without` (the model with what they would
/// replace taken out), each with the parameters `others` refitted beside it. `against`
/// completes the progress line, with `{misfit}`, `{penalty}` and `{force}` filled in.
pub(crate) fn best_named_fit(
    cx: &Context,
    without: &Parameters,
    others: &[&'static str],
    named: &[Candidate],
    against: &str,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<NamedFit>, String> {
    let (recording, n) = (cx.recording, cx.n);
    let model = Actuator::new(without.clone())?;
    let current = replay_fast(&model, recording, n)?;
    *replays += 1;
    let problem = Problem::new(recording, without, &cx.blocks, cx.channel_noise);
    problem.set_jobs(cx.options.jobs);
    let penalty = discovery_penalty_per_term(heldout_count(&cx.blocks) as f64);
    let sensitivity = |name: &'static str| {
        let step = named
            .iter()
            .flat_map(|c| c.terms.iter())
            .find(|t| t.name == name)
            .map_or(0.0, |t| t.step);
        problem.sensitivity(name, step, &current)
    };
    let mut best: Option<(f64, f64, Scored, Vec<&'static str>, Parameters)> = None;
    for candidate in named {
        let Ok(fit) = problem.fit(candidate, ITERATIONS, &current, &sensitivity) else {
            continue;
        };
        *replays += fit.replays;
        let used = terms_used(&fit);
        if used == 0.0 {
            continue;
        }
        let scored = Scored {
            fit,
            explained: 0.0,
            force_heldout_rms: 0.0,
        };
        let mut trial = without.clone();
        let Ok(set) = apply_named(&mut trial, &scored) else {
            continue;
        };
        if trial.validate().is_err() {
            continue;
        }
        let mut names = others.to_vec();
        names.extend(set.iter().map(|(name, _)| *name).filter(|name| refittable(name)));
        let trial = match crate::fit::refit::refit_constants(cx, &trial, &names, replays)? {
            Some((refitted, before, after)) if after < before => refitted,
            _ => trial,
        };
        let (misfit, force) = crate::decide::alternatives::judge(cx, &problem, &trial, replays)?;
        let score = misfit + used * penalty;
        progress(&format!(
            "  {} ({}) {}",
            candidate.named.unwrap_or(candidate.label),
            candidate.label,
            against
                .replace("{misfit}", &format!("{misfit:.0}"))
                .replace("{penalty}", &format!("{:.0}", used * penalty))
                .replace("{force}", &format!("{force:.4}"))
        ));
        if best.as_ref().map_or(true, |b| score < b.0) {
            let carried = set.iter().map(|(name, _)| *name).collect();
            best = Some((score, force, scored, carried, trial));
        }
    }
    Ok(best.map(|(score, force, scored, carried, params)| NamedFit {
        score,
        force,
        scored,
        carried,
        params,
        without_model: model,
        without_replay: current,
    }))
}
