//! Step 4 of the crate's account: fit every candidate, score it on the held-out blocks
//! and rank the places of the chain; the penalties by which simpler candidates win.

use crate::candidates::Candidate;
use crate::candidates::Mechanism;
use crate::candidates::Term;
use crate::context::Options;
use crate::context::ProgressBars;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Fit;
use crate::fit::Problem;
use crate::fit::Sensitivity;
use crate::input::blocks::count;
use crate::input::blocks::Block;
use crate::parallel::parallel_map_shown;
use crate::policy::LOCATED_SHARE;
use crate::policy::MIN_MEAN_SQUARE_GAIN_PER_TERM;
use crate::policy::REFINED;
use crate::policy::REFINE_ITERATIONS;
use crate::policy::WORTH_REFINING;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::signals::FORCE;
use crate::replay::Replay;
use crate::vocabulary::{Family, Place};

/// How many of a fitted candidate's terms are away from their neutral values.
pub(crate) fn used_terms(s: &Scored) -> f64 {
    terms_used(&s.fit)
}

/// [`used_terms`] of a fit not yet scored.
pub(crate) fn terms_used(fit: &Fit) -> f64 {
    fit.values
        .iter()
        .zip(&fit.candidate.terms)
        .filter(|(v, t)| **v != t.neutral)
        .count() as f64
}

/// A candidate's held-out misfit (in noise floors squared) plus a BIC-like penalty of
/// ln(held-out samples) per term used: best first, a term that adds nothing on the held-out
/// blocks loses to a simpler candidate.
pub(crate) fn penalised(s: &Scored, heldout_samples: f64) -> f64 {
    s.fit.heldout_total() + used_terms(s) * heldout_samples.ln()
}

/// What each term of a discovered candidate must earn on the held-out blocks, in noise
/// floors squared: BIC's ln(samples), and at least a hundredth of a noise floor squared per
/// held-out sample. The second binds on long recordings, where ln n lets a term in for a
/// trend of a few hundredths of the noise (a pressure transducer's 8 kPa offset was otherwise
/// taken as an offset and a drift on both channels, for 11 Pa over 80 s against 150 Pa of
/// noise).
pub(crate) fn discovery_penalty_per_term(heldout_samples: f64) -> f64 {
    heldout_samples
        .ln()
        .max(MIN_MEAN_SQUARE_GAIN_PER_TERM * heldout_samples)
}

pub(crate) fn discovery_penalised(s: &Scored, heldout_samples: f64) -> f64 {
    s.fit.heldout_total() + used_terms(s) * discovery_penalty_per_term(heldout_samples)
}

/// The model constants whose sensitivities several fits share at one point, each once, with
/// its difference step: every fit's first linearisation reads them instead of replaying.
#[derive(Default)]
pub(crate) struct WantedSensitivities(Vec<(&'static str, f64)>);

impl WantedSensitivities {
    pub(crate) fn add(&mut self, name: &'static str, step: f64) {
        if !self.0.iter().any(|(n, _)| *n == name) {
            self.0.push((name, step));
        }
    }

    /// The constants that `terms` vary (not their curves, filters or modulations).
    pub(crate) fn add_constants_of(&mut self, terms: &[Term]) {
        for t in terms {
            if let Mechanism::Parameter(name) = t.mechanism {
                self.add(name, t.step);
            }
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// Each sensitivity replayed at `at`, over `jobs` threads (shown as `phase` on `bars`).
    pub(crate) fn taken(
        self,
        problem: &Problem,
        at: &Replay,
        jobs: usize,
        phase: &str,
        bars: &Option<std::sync::Arc<dyn ProgressBars>>,
    ) -> SharedSensitivities {
        let taken = parallel_map_shown(phase, bars, &self.0, jobs, |(name, step)| {
            problem.sensitivity(name, *step, at)
        });
        SharedSensitivities { wanted: self.0, taken }
    }
}

/// Sensitivities taken once at a point ([`WantedSensitivities::taken`]), read by name.
pub(crate) struct SharedSensitivities {
    wanted: Vec<(&'static str, f64)>,
    taken: Vec<Option<Sensitivity>>,
}

impl SharedSensitivities {
    pub(crate) fn get(&self, name: &'static str) -> Option<Sensitivity> {
        self.wanted
            .iter()
            .position(|(n, _)| *n == name)
            .and_then(|k| self.taken[k].clone())
    }

    /// Let go of every sensitivity but those of the constants `candidates` vary or modulate,
    /// the only ones their fits read from here on ([`Problem::fit`]). Every constant's (63
    /// of them on 100,000 rows and three channels: 76 MB), held while a few leaders were
    /// refined, made the peak of a 600 s recording's diagnosis: 236 MB, and 196 MB at that
    /// point without them.
    pub(crate) fn keep_those_of(&mut self, candidates: &[Candidate]) {
        let read = |name: &'static str| {
            candidates.iter().flat_map(|c| &c.terms).any(|t| match t.mechanism {
                Mechanism::Parameter(n) => n == name,
                Mechanism::Modulated { parameter, .. } => parameter == name,
                _ => false,
            })
        };
        for ((name, _), taken) in self.wanted.iter().zip(&mut self.taken) {
            if !read(name) {
                *taken = None;
            }
        }
    }
}

pub(crate) fn heldout_count(blocks: &[Block]) -> usize {
    count(blocks, Block::HeldOut).max(1)
}

/// Fit every candidate and rank the places of the chain.
pub(crate) fn localize(
    problem: &Problem,
    base_replay: &Replay,
    candidates: &[Candidate],
    options: &Options,
    screen: Option<crate::fit::screen::Screen>,
    progress: &mut dyn FnMut(&str),
) -> (Localization, usize) {
    let jobs = options.jobs;
    let bars = &options.bars;
    let base_prediction = [
        base_replay.force.clone(),
        base_replay.p1.clone(),
        base_replay.p2.clone(),
    ];
    let (_, heldout_before) = problem.errors(&base_prediction);
    let before_total: f64 = heldout_before.iter().sum::<f64>().max(1e-300);
    // Sensitivities at the base point, shared by every candidate's first step.
    let mut wanted = WantedSensitivities::default();
    for c in candidates.iter().filter(|c| c.settings.is_empty()) {
        for t in &c.terms {
            let name = match t.mechanism {
                Mechanism::Parameter(name) => Some((name, t.step)),
                Mechanism::Modulated { parameter, .. } => candidates
                    .iter()
                    .flat_map(|c| &c.terms)
                    .find(|u| u.mechanism == Mechanism::Parameter(parameter))
                    .map(|u| (parameter, u.step)),
                _ => None,
            };
            if let Some((name, step)) = name {
                wanted.add(name, step);
            }
        }
    }
    if screen.is_some() {
        for name in crate::candidates::modulation::modulatable() {
            wanted.add(
                name,
                crate::candidates::modulation::sensitivity_step(name, problem.base, candidates),
            );
        }
    }
    progress(&format!(
        "sensitivities of the outputs to {} model constants ({} threads)",
        wanted.len(),
        jobs
    ));
    let mut replays = wanted.len();
    let mut sensitivities = wanted.taken(problem, base_replay, jobs, "sensitivities", bars);
    let shared = |name: &'static str| sensitivities.get(name);
    let score = |mut fit: Fit| -> Scored {
        let explained = 1.0 - fit.heldout_total() / before_total;
        let residual = difference(&problem.recording.force, &fit.prediction[FORCE]);
        let force_heldout_rms = rms_where(&residual, problem.blocks, Block::HeldOut);
        // Only a named effect's force prediction is read once a candidate is scored (its
        // remainder, when it is added): the other series would be held for every candidate
        // until the diagnosis ends.
        fit.prediction[1] = Vec::new();
        fit.prediction[2] = Vec::new();
        // A discovered term is added through a fit of its own; only a named effect's
        // remainder is read from its scored prediction.
        if fit.candidate.named.is_none() {
            fit.prediction[FORCE] = Vec::new();
        }
        Scored {
            fit,
            explained,
            force_heldout_rms,
        }
    };
    progress(&format!("fitting {} candidate corrections", candidates.len()));
    // Scored as each fit ends: the pressures' predictions of every candidate at once were
    // the diagnosis's peak of memory (62 candidates, 119 MB of an 80 s recording's 292).
    let first: Vec<Option<Scored>> = parallel_map_shown("candidates", bars, candidates, jobs, |c| {
        problem.fit(c, 1, base_replay, &shared).ok().map(score)
    });
    let mut scored: Vec<Scored> = first.into_iter().flatten().collect();
    replays += scored.iter().map(|s| s.fit.replays).sum::<usize>();
    if let Some(screen) = screen {
        let penalty = discovery_penalty_per_term(heldout_count(problem.blocks) as f64);
        let started = std::time::Instant::now();
        let (found, answered) = crate::fit::screen::screen(
            problem,
            base_replay,
            &shared,
            candidates,
            screen.periodic_hz,
            penalty,
            jobs,
        );
        replays += answered;
        progress(&format!(
            "modulations screened in {:.1} s: {}",
            started.elapsed().as_secs_f64(),
            if found.is_empty() {
                "none beats a constant".to_string()
            } else {
                found
                    .iter()
                    .map(|s| format!("{} with {}", s.constant, s.follows))
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        ));
        for s in &found {
            if let (Some(c), Some(sensitivity)) = (
                crate::fit::screen::candidate(s, problem.base, candidates),
                shared(s.constant),
            ) {
                let fit = crate::fit::screen::first_order_fit(problem, base_replay, s, c, &sensitivity);
                replays += fit.replays;
                scored.push(score(fit));
            }
        }
    }
    scored.sort_by(|a, b| b.explained.total_cmp(&a.explained));
    // Refine the leaders (and every named effect near them) with more iterations.
    let not_output_only = |s: &&Scored| {
        s.fit
            .candidate
            .terms
            .iter()
            .any(|t| !matches!(t.mechanism, Mechanism::Output { .. }))
    };
    let mut leaders: Vec<Candidate> = scored
        .iter()
        .filter(not_output_only)
        .filter(|s| s.explained >= WORTH_REFINING)
        .take(REFINED)
        .map(|s| s.fit.candidate.clone())
        .collect();
    // Modulations among the leaders leave fewer places for the written candidates, whose
    // first-order fit can understate them: the best of those is refined too (a port's areas
    // scaled to 0.8, refined, explain all that a return area varying with the jet position
    // and with the pressure difference, the two leading modulations, explain in part).
    if leaders
        .iter()
        .filter(|c| crate::candidates::modulation::is_modulation(c))
        .count()
        >= 2
    {
        if let Some(written) = scored
            .iter()
            .filter(not_output_only)
            .filter(|s| s.explained >= WORTH_REFINING)
            .find(|s| {
                !crate::candidates::modulation::is_modulation(&s.fit.candidate) && !leaders.contains(&s.fit.candidate)
            })
        {
            leaders.push(written.fit.candidate.clone());
        }
    }
    // The static curves fitted through the model (the command's, the discharge
    // coefficient's) are always refined when worth it: one Gauss–Newton step from the
    // identity leaves them behind the single-constant candidates they compete with.
    // So are the transducers' lags, which the refining pass searches through the model where
    // it reads them between samples (`Problem::fit`): on the samples a lag within one can
    // rank below a delay of the command.
    for s in scored.iter().filter(|s| s.explained >= WORTH_REFINING) {
        let curve = crate::candidates::curves::is_command_curve(&s.fit.candidate)
            || crate::candidates::discharge::is_discharge_curve(&s.fit.candidate)
            || is_lag(&s.fit.candidate);
        if curve && !leaders.contains(&s.fit.candidate) {
            leaders.push(s.fit.candidate.clone());
        }
    }
    progress(&format!("refining the {} leading candidates", leaders.len()));
    sensitivities.keep_those_of(&leaders);
    let shared = |name: &'static str| sensitivities.get(name);
    // Fewer leaders than threads, and one of them may take most of the time (a smooth
    // hysteresis law): its finite differences share the threads too.
    problem.set_jobs(jobs);
    let refined: Vec<Option<Scored>> = parallel_map_shown("refining", bars, &leaders, jobs, |c| {
        problem.fit(c, REFINE_ITERATIONS, base_replay, &shared).ok().map(score)
    });
    problem.set_jobs(1);
    for better in refined.into_iter().flatten() {
        replays += better.fit.replays;
        if let Some(s) = scored.iter_mut().find(|s| s.fit.candidate == better.fit.candidate) {
            // A modulation's first fit is the screen's linear estimate, not a replay of its
            // values: where the model's fit of the same candidate gives less, the estimate
            // claimed a share the model does not give, and the model's fit replaces it.
            let estimated = crate::candidates::modulation::is_modulation(&s.fit.candidate);
            if estimated || better.explained > s.explained {
                *s = better;
            }
        }
    }
    for (l, e, label) in rank(&mut scored).by_location.iter().take(4) {
        progress(&format!("  {l:<16} explains {:5.1} % ({label})", 100.0 * e));
    }
    let mut ranked = rank(&mut scored);
    let measured = problem.weights.iter().filter(|w| **w > 0.0).count().max(1);
    ranked.before_mean_square = before_total / (heldout_count(problem.blocks) * measured) as f64;
    (ranked, replays)
}

/// Whether a candidate is a transducer's lag alone.
fn is_lag(candidate: &Candidate) -> bool {
    matches!(
        candidate.terms.as_slice(),
        [t] if matches!(t.mechanism, Mechanism::OutputFilter { filter: crate::candidates::Filter::Lag, .. })
    )
}

/// Rank the places of the chain by their best candidate.
pub(crate) fn rank(scored: &mut [Scored]) -> Localization {
    scored.sort_by(|a, b| b.explained.total_cmp(&a.explained));
    let mut by_location: Vec<(Place, f64, &'static str)> = vec![];
    for s in scored.iter() {
        if !by_location.iter().any(|(l, _, _)| *l == s.fit.candidate.location) {
            by_location.push((s.fit.candidate.location, s.explained, s.fit.candidate.label));
        }
    }
    let (location, family) = match scored.first() {
        Some(best) if best.explained >= LOCATED_SHARE => {
            // The family: the simplest candidate at that place that explains nearly as much.
            let place = best.fit.candidate.location;
            let simplest = scored
                .iter()
                .filter(|s| s.fit.candidate.location == place && s.explained >= best.explained - 0.02)
                .min_by_key(|s| s.fit.candidate.terms.len())
                .unwrap_or(best);
            (place, simplest.fit.candidate.family)
        }
        _ => (Place::Unknown, Family::Unknown),
    };
    Localization {
        location,
        family,
        by_location,
        candidates: scored.to_vec(),
        // Set by the caller, which knows the misfit before the candidates.
        before_mean_square: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::SharedSensitivities;
    use crate::candidates::{Candidate, Mechanism, Modulation};
    use crate::fit::scored::Localization;
    use crate::vocabulary::{Family, Place};

    #[test]
    fn only_the_sensitivities_the_leaders_read_are_kept_for_their_refinement() {
        let column = || Some(std::sync::Arc::new([vec![1.0f32; 4], vec![], vec![]]));
        let mut shared = SharedSensitivities {
            wanted: vec![("p_s", 1.0), ("k_cd", 1.0), ("i_offset", 1.0), ("A_0", 1.0)],
            taken: vec![column(), column(), column(), column()],
        };
        let leaders = [
            Candidate::of_mechanisms(vec![Mechanism::Parameter("p_s")]),
            Candidate::of_mechanisms(vec![Mechanism::Modulated {
                parameter: "k_cd",
                modulation: Modulation::Ramp,
            }]),
        ];
        shared.keep_those_of(&leaders);
        assert!(shared.get("p_s").is_some(), "a leader's constant");
        assert!(shared.get("k_cd").is_some(), "a leader's modulated constant");
        assert!(shared.get("i_offset").is_none());
        assert!(shared.get("A_0").is_none());
    }

    fn located(by_location: Vec<(Place, f64, &'static str)>) -> Localization {
        Localization {
            location: by_location[0].0,
            family: Family::ParameterOffset,
            by_location,
            candidates: vec![],
            before_mean_square: 4.0,
        }
    }

    #[test]
    fn places_that_explain_nearly_as_much_are_named_beside_the_term_added() {
        let l = located(vec![
            (Place::ForceSensor, 0.998, "force sensor offset and gain"),
            (Place::Supply, 0.9977, "supply pressure"),
            (Place::Mechanics, 0.5, "viscous friction"),
        ]);
        let clause = l
            .undecided_beside(l.location, false)
            .expect("the supply explains as much");
        assert!(clause.contains("the supply (99.8 %)"), "{clause}");
        assert!(!clause.contains("mechanics"), "{clause}");
        assert!(clause.contains("pressure channels"), "{clause}");
        assert!(!l
            .undecided_beside(l.location, true)
            .unwrap()
            .contains("pressure channels"));
        // A term added at the tied place names the located one beside it, not itself.
        let beside_supply = l.undecided_beside(Place::Supply, true).unwrap();
        assert!(beside_supply.contains("the force_sensor (99.8 %)"), "{beside_supply}");
        assert!(!beside_supply.contains("the supply"), "{beside_supply}");
    }

    #[test]
    fn a_place_well_ahead_of_the_others_is_added_without_a_doubt() {
        let l = located(vec![
            (Place::ForceSensor, 0.998, "force sensor lag"),
            (Place::JetPipe, 0.8, "jet pipe lag"),
        ]);
        assert_eq!(l.undecided_beside(l.location, true), None);
    }

    #[test]
    fn a_place_that_leaves_several_times_the_misfit_is_no_alternative_however_much_it_explains() {
        // 76 noise floors before: 99.98 % explained leaves about one, 99.1 % about seven.
        let l = located(vec![
            (Place::Valve, 0.9998, "discharge coefficient against the pressure ratio"),
            (Place::Command, 0.991, "command static curve"),
        ]);
        assert_eq!(l.undecided_beside(l.location, false), None);
        assert!(l.alternatives().is_empty());
    }

    #[test]
    fn the_margin_is_the_next_places_held_out_error_minus_the_winners_in_noise_floors() {
        // Two noise floors RMS before (4 floors squared a sample): the winner leaves a
        // quarter of the misfit (one floor), the next place 64 % of it (1.6 floors), the third
        // all of it.
        let l = located(vec![
            (Place::ForceSensor, 0.75, "force sensor lag"),
            (Place::JetPipe, 0.36, "jet pipe lag"),
            (Place::Supply, 0.0, "supply pressure"),
        ]);
        let winner = l.margin(Place::ForceSensor).unwrap();
        assert!((winner - 0.6).abs() < 1e-12, "{winner}");
        // The runner-up is measured against the winner: behind by as much.
        let runner_up = l.margin(Place::JetPipe).unwrap();
        assert!((runner_up + 0.6).abs() < 1e-12, "{runner_up}");
        assert_eq!(l.margin(Place::Valve), None, "no candidate there");
        assert_eq!(located(vec![(Place::Valve, 0.9, "valve")]).margin(Place::Valve), None);
    }
}
