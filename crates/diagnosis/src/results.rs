//! What a diagnosis finds: its errors, scores, localization, additions and the whole report.

use crate::candidates::Candidate;
use crate::fit::calibrate::Calibrated;
use crate::fit::Fit;
use crate::input::blocks::Block;
use crate::input::recording::Recording;
use crate::replay::signals::difference;
use crate::replay::signals::rms;
use crate::replay::signals::rms_where;
use crate::replay::Replay;
use crate::verdict::signature::Signature;
use jetpipe_model::physics::parameters::Parameters;
use serde_json::Value;

#[allow(unused_imports)]
use crate::*;

/// Errors of a force trace against the recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    pub rms: f64,
    pub nrmse: f64,
    pub train_rms: f64,
    pub heldout_rms: f64,
    /// RMS of each measured pressure minus the model's reading of it, Pa, over the whole
    /// recording (when it has pressure channels).
    pub pressure_rms: Option<[f64; 2]>,
}

pub(crate) fn errors(model: &Replay, recording: &Recording, blocks: &[Block]) -> Errors {
    let residual = difference(&recording.force, &model.force);
    let (lo, hi) = recording
        .force
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &f| (a.min(f), b.max(f)));
    let total = rms(&residual);
    Errors {
        rms: total,
        nrmse: if hi > lo { total / (hi - lo) } else { 0.0 },
        train_rms: rms_where(&residual, blocks, Block::Training),
        heldout_rms: rms_where(&residual, blocks, Block::HeldOut),
        pressure_rms: match (&recording.p1, &recording.p2) {
            (Some(p1), Some(p2)) => Some([rms(&difference(p1, &model.p1)), rms(&difference(p2, &model.p2))]),
            _ => None,
        },
    }
}

/// A candidate's score in one round.
#[derive(Clone, Debug)]
pub struct Scored {
    pub fit: Fit,
    /// Share of the held-out misfit (all channels, each in its noise floors) it removes.
    pub explained: f64,
    /// Held-out force RMS error with it, N.
    pub force_heldout_rms: f64,
}

impl Scored {
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        self.fit
            .candidate
            .terms
            .iter()
            .zip(&self.fit.values)
            .map(|(t, v)| (t.name, *v))
            .collect()
    }
}

/// Where the model departs, from one round of candidates.
#[derive(Clone, Debug)]
pub struct Localization {
    /// The place whose best candidate explains most, or "unknown" when none explains
    /// [`LOCATED_SHARE`] of the misfit.
    pub location: &'static str,
    pub family: &'static str,
    /// Best share explained at each place, best first, with the candidate that did it.
    pub by_location: Vec<(&'static str, f64, &'static str)>,
    pub candidates: Vec<Scored>,
}

impl Localization {
    pub(crate) fn best_at(&self, location: &str) -> Option<&Scored> {
        self.candidates
            .iter()
            .filter(|s| s.fit.candidate.location == location)
            .max_by(|a, b| a.explained.total_cmp(&b.explained))
    }

    /// A clause naming the places that explain nearly as much as the located one
    /// ([`Localization::alternatives`]), with their shares, for a term added at `added` (the
    /// located place or one of those); `None` when there are none. What the recording cannot
    /// tell apart is said beside what was added.
    pub fn undecided_beside(&self, added: &str, has_pressures: bool) -> Option<String> {
        let others: Vec<String> = std::iter::once(self.location)
            .chain(self.alternatives())
            .filter(|l| *l != added)
            .filter_map(|l| self.by_location.iter().find(|(at, _, _)| *at == l))
            .map(|(l, e, _)| format!("the {l} ({:.1} %)", 100.0 * e))
            .collect();
        if others.is_empty() {
            return None;
        }
        Some(format!(
            "a correction at {} explains nearly as much, which this recording does not tell apart{}",
            others.join(" or at "),
            if has_pressures {
                ""
            } else {
                " (pressure channels would split the chain at the piston)"
            }
        ))
    }

    /// The places a term added at `added` cannot be told apart from on this recording
    /// ([`Self::alternatives`] and the located place), `added` first and at most three in
    /// all; empty when the recording tells the place.
    pub fn tied_with(&self, added: &'static str) -> Vec<&'static str> {
        let others: Vec<&'static str> = std::iter::once(self.location)
            .chain(self.alternatives())
            .filter(|l| *l != added)
            .collect();
        if others.is_empty() {
            return vec![];
        }
        std::iter::once(added).chain(others).take(MOST_TIED_LOCATIONS).collect()
    }

    /// Places that explain nearly as much as the best: they leave at most a quarter more
    /// of the held-out misfit than it does. Measured on what is left, not on the share
    /// explained: where the model is far off, 99 % explained can leave seven noise floors
    /// beside one.
    pub fn alternatives(&self) -> Vec<&'static str> {
        let Some(&(_, top, _)) = self.by_location.first() else {
            return vec![];
        };
        self.by_location
            .iter()
            .skip(1)
            .filter(|(_, e, _)| 1.0 - *e <= ALTERNATIVE_REMAINDER * (1.0 - top) && *e >= LOCATED_SHARE)
            .map(|(l, _, _)| *l)
            .collect()
    }
}

/// A named effect that was added.
#[derive(Clone, Debug)]
pub struct AddedEffect {
    pub name: &'static str,
    pub location: &'static str,
    pub parameters: Vec<(&'static str, f64)>,
    pub evidence: String,
    pub heldout_before: f64,
    pub heldout_after: f64,
    /// Share of the held-out force mean square it removes.
    pub share: f64,
    pub remainder_follows: String,
    /// Other named effects at its place that explained nearly as much when it was named
    /// (name, share of the held-out misfit), tried in its place once every round is done
    /// (`named_rivals.rs`).
    pub rivals: Vec<(&'static str, f64)>,
    /// The named effects this recording cannot tell it from, its own name first; empty when
    /// it tells them apart.
    pub tied_effects: Vec<&'static str>,
}

/// A term outside the named effects that was added (see `discover.rs`).
#[derive(Clone, Debug)]
pub struct DiscoveredTerm {
    pub location: &'static str,
    pub family: &'static str,
    pub candidate: &'static str,
    /// The FMU parameters that carry it, in SI units.
    pub parameters: Vec<(&'static str, f64)>,
    pub reading: String,
    pub heldout_before: f64,
    pub heldout_after: f64,
    /// Share of the held-out force mean square it removes.
    pub share: f64,
    /// For a term on the pressure transducers, which the force does not see: the held-out
    /// RMS of each pressure, Pa, before and after.
    pub pressures_heldout: Option<([f64; 2], [f64; 2])>,
    /// The places this recording cannot tell the term's from, its own first (at most
    /// [`MOST_TIED_LOCATIONS`]); empty when it tells the place.
    pub tied_locations: Vec<&'static str>,
}

impl DiscoveredTerm {
    /// The fitted `candidate`, carried by the model parameters `set` (read against their
    /// values in `params`), as a term that takes the held-out force error from `before` to
    /// `after`; its family as the fitted shape reads (a curve that flattens is a limit).
    pub(crate) fn fitted(
        candidate: &Candidate,
        set: Vec<(&'static str, f64)>,
        params: &Parameters,
        before: f64,
        after: f64,
    ) -> Self {
        DiscoveredTerm {
            location: candidate.location,
            family: crate::candidates::curves::family(candidate.family, &set),
            candidate: candidate.label,
            reading: crate::decide::discover::reading(
                candidate.label,
                candidate.location,
                candidate.family,
                &set,
                params,
            ),
            parameters: set,
            heldout_before: before,
            heldout_after: after,
            share: 1.0 - (after / before).powi(2),
            pressures_heldout: None,
            tied_locations: vec![],
        }
    }
}

/// What is left when the verdict is not "explained".
#[derive(Clone, Debug)]
pub struct Unexplained {
    pub rms: f64,
    pub ratio_to_noise: f64,
    pub location: &'static str,
    pub family: &'static str,
    pub alternatives: Vec<&'static str>,
    pub signature: Signature,
    pub sentence: String,
}

/// What `jetpipe diagnose` reports.
#[derive(Clone, Debug)]
pub struct Diagnosis {
    pub samples: usize,
    pub noise_floor: f64,
    pub pressure_noise: Option<[f64; 2]>,
    pub input_checks: Vec<String>,
    pub before: Errors,
    pub after: Errors,
    /// The seconds at the start in which the model's starting state still shows: neither
    /// fitted nor scored ([`crate::input::blocks`]).
    pub settling: f64,
    pub calibrated: Vec<Calibrated>,
    pub effects: Vec<AddedEffect>,
    pub discovered: Vec<DiscoveredTerm>,
    /// The held-out force error before and after the joint refit of everything added,
    /// when there were two or more and the refit helped.
    pub joint_refit: Option<(f64, f64)>,
    /// Every candidate of the first round.
    pub candidates: Vec<Scored>,
    /// The last round's localization (none when every channel was within its noise).
    pub localization: Option<Localization>,
    pub pressure_split: Option<PressureSplit>,
    pub unexplained: Option<Unexplained>,
    pub residual_tests: Value,
    pub parameters: Parameters,
    pub before_force: Vec<f64>,
    pub after_force: Vec<f64>,
    pub replays: usize,
    /// What the search added and the accurate replay then found worse than the model the
    /// diagnosis started from: taken out again, so that the report never hands back a worse
    /// model than it was given.
    pub withdrawn: Option<Withdrawn>,
    /// The fits' fixed-step replay against the error-controlled one, and the step they used.
    pub fast_replay: crate::replay::agreement::FastReplayCheck,
    /// The final model's fixed-step replay against its error-controlled one: the force's RMS
    /// departure, N, and in noise floors; none when nothing was added.
    pub fast_replay_final: Option<(f64, f64)>,
    /// The chamber pressures the final model's replay started from, where the recording has
    /// pressure channels ([`crate::replay::start_pressures`]); at the equilibrium otherwise.
    pub start_pressures: Option<[f64; 2]>,
    /// Where the replays drove the stopper with the smoothed positions
    /// ([`crate::input::recording::Recording::with_stopper_smoothed`]), the smoothing's residual limit, m²;
    /// `None` where they drove it with the recorded ones.
    pub stopper_smoothing: Option<f64>,
    /// The half-width (s) of the stopper acceleration the final model reads as its input a_s
    /// ([`crate::input::acceleration`]); 0 where it reads none (no force on the stopper's motion).
    pub acceleration_window: f64,
}

pub use crate::decide::withdraw::Withdrawn;
pub use crate::verdict::split::PressureSplit;

impl Diagnosis {
    /// Whether the force is within its noise on the held-out blocks.
    pub fn force_explained(&self) -> bool {
        self.after.heldout_rms <= EXPLAINED_WITHIN_NOISE * self.noise_floor
    }
    /// Whether every measured channel is within its noise: the force on the held-out blocks,
    /// and each pressure, when the recording has them, after the start and over the whole
    /// recording.
    pub fn explained(&self) -> bool {
        self.force_explained()
            && !crate::verdict::split::pressures_off(
                self.pressure_split.as_ref(),
                self.pressure_noise,
                self.after.pressure_rms,
            )
    }
    pub fn verdict(&self) -> &'static str {
        if self.explained() {
            "explained"
        } else {
            "unexplained_remainder"
        }
    }
}
