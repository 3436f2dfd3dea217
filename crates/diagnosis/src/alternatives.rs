//! A search that does not lock in: after a named effect has earned its name at a place, the
//! simpler terms at that place are tried again in the replayed model, and one that does
//! better on the held-out blocks (its parameters' penalty counted) replaces it. A
//! supply pressure set 30 kPa low is explained by the line resistance of the named
//! `supply_pressure_drop` to within 10 noise floors, and by a plain `P_s` to the noise.

use super::*;

/// What the judgement of a replayed model needs from its round.
pub(crate) struct Check<'a> {
    pub cx: &'a Context<'a>,
    pub problem: &'a Problem<'a>,
    /// Held-out samples.
    pub count: f64,
    /// The round's held-out force RMS error before the addition, N.
    pub force_before: f64,
}

impl Check<'_> {
    /// The model with `params` replayed: its held-out misfit (all channels, in noise floors
    /// squared) and its held-out force RMS error.
    fn judge(&self, params: &Parameters, replays: &mut usize) -> Result<(f64, f64), String> {
        let with = replay_fast(&Actuator::new(params.clone())?, self.cx.recording, self.cx.n)?;
        *replays += 1;
        let (_, heldout) = self
            .problem
            .errors(&[with.force.clone(), with.p1.clone(), with.p2.clone()]);
        let force = rms_where(
            &difference(&self.cx.recording.force, &with.force),
            &self.cx.training,
            false,
        );
        Ok((heldout.iter().sum(), force))
    }
}

/// The simplest term at the named effect's place that, replayed, leaves a held-out misfit
/// plus its parameters' penalty below the named effect's: that term, as discovered, with
/// the parameters that carry it. Only terms with no more parameters than the named effect
/// are tried, best first, at most [`DISCOVERY_TRIALS`].
pub(crate) fn simpler_than_named(
    check: &Check,
    found: &Localization,
    params: &Parameters,
    named: &Scored,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(DiscoveredTerm, Parameters)>, String> {
    let place = named.fit.candidate.location;
    let count = check.count;
    let penalty = discovery_penalty_per_term(count);
    let named_terms = used_terms(named);
    let mut alternatives: Vec<&Scored> = found
        .candidates
        .iter()
        .filter(|s| s.fit.candidate.location == place && s.fit.candidate.named.is_none())
        .filter(|s| s.explained >= LOCATED_SHARE && used_terms(s) <= named_terms)
        .collect();
    if alternatives.is_empty() {
        return Ok(None);
    }
    alternatives.sort_by(|a, b| discovery_penalised(a, count).total_cmp(&discovery_penalised(b, count)));
    let name = named.fit.candidate.named.expect("a named candidate");
    let mut with_named = params.clone();
    if apply_named(&mut with_named, named).is_err() {
        return Ok(None);
    }
    let (named_misfit, named_force) = check.judge(&with_named, replays)?;
    let named_score = named_misfit + named_terms * penalty;
    for s in alternatives.into_iter().take(DISCOVERY_TRIALS) {
        let candidate = &s.fit.candidate;
        let Some(set) = discover::model_terms(candidate, &s.fit.values, params, check.problem) else {
            continue;
        };
        let mut trial = params.clone();
        if set.iter().any(|(n, v)| set_parameter(&mut trial, n, *v).is_err()) || trial.validate().is_err() {
            continue;
        }
        let (misfit, force) = check.judge(&trial, replays)?;
        let score = misfit + used_terms(s) * penalty;
        progress(&format!(
            "  instead of {name}: {} leaves {misfit:.0} held out against its {named_misfit:.0} (noise floors squared), force {force:.4} against {named_force:.4} N",
            candidate.label
        ));
        if score < named_score && force <= named_force {
            progress(&format!(
                "adding a {} at the {} instead of {name}",
                candidate.label, place
            ));
            let before = check.force_before;
            let term = DiscoveredTerm {
                location: place,
                family: crate::curves::family(candidate.family, &set),
                candidate: candidate.label,
                reading: discover::reading(candidate.label, place, candidate.family, &set, params),
                parameters: set,
                heldout_before: before,
                heldout_after: force,
                share: 1.0 - (force / before).powi(2),
                pressures_heldout: None,
            };
            return Ok(Some((term, trial)));
        }
    }
    Ok(None)
}
