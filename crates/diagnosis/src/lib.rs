//! Diagnosis of a bench recording: where does the thesis model depart from it, and is
//! the departure one of the named effects?
//!
//! 1. Check the file (units, length, sampling) and estimate each channel's noise floor.
//! 2. Optionally re-identify what the thesis identified from static loops (`--calibrate`).
//! 3. Replay the recording's inputs through the model. With pressure channels, split the
//!    residual: the force against A_p (p1 − p2) speaks of the mechanics and the force
//!    sensor, the pressures against the model's of everything upstream.
//! 4. Fit every candidate correction ([`corrections`]) on the training blocks of all
//!    channels and score it on the held-out blocks; the place in the chain whose best
//!    candidate explains most of the held-out misfit is where the model departs.
//! 5. A named effect is added only when it is a candidate at that place, explains most of
//!    what that place can explain, lowers the force error by more than the noise
//!    ([`worth_adding`]), makes no
//!    channel worse, and the residual carries its own signature (`named.rs`). Repeat.
//! 6. Verdict: explained when the held-out force error after is within 1.5 noise floors;
//!    otherwise the remainder, where it sits in the chain and its signature.
//!
//! The recordings themselves are [`recording`]; [`replay`](mod@replay) runs their inputs
//! through the model (crate `jetpipe-model`).

pub mod acceleration;
pub mod agreement;
mod alternatives;
mod beside;
pub mod blocks;
pub mod calibrate;
pub mod checks;
pub mod command_gaps;
pub mod command_path;
mod conclude;
pub mod corrections;
pub mod curves;
pub mod discharge;
mod discover;
mod eliminate;
pub mod extra_flows;
pub mod lines;
mod localize;
pub mod modulation;
mod named;
mod named_instead;
mod named_places;
mod named_rivals;
pub mod noise;
mod oscillation;
mod pairs;
pub mod products;
mod quantiser;
pub mod recording;
pub mod replay;
mod report;
mod rounds;
pub mod signals;
pub mod signature;
mod split;
mod withdraw;

use serde_json::{json, Value};

use crate::recording::Recording;
use crate::replay::{replay, replay_fast, Replay};
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

use blocks::{count, Block};
use calibrate::Calibrated;
use corrections::{catalogue, parameter_value, set_parameter, Candidate, Fit, Mechanism, Problem, Sensitivity, Term};
use signals::{difference, force_from_pressures, rms, rms_where, ChainSignals, CHANNELS, CHANNEL_NAMES, FORCE};
use signature::Signature;

use localize::{
    discovery_penalised, discovery_penalty_per_term, heldout_count, localize, parallel_map, penalised, used_terms,
};

/// Length of the alternating training / held-out blocks.
pub const BLOCK_SECONDS: f64 = 2.0;
/// The verdict is "explained" when the held-out force error is within this many noise floors.
pub const EXPLAINED_WITHIN_NOISE: f64 = 1.5;

/// The most places a report names as not told apart (`tied_locations`).
pub const MOST_TIED_LOCATIONS: usize = 3;
/// A named effect must lower the held-out force error by this fraction…
pub const MIN_RELATIVE_GAIN: f64 = 0.1;
/// …and by at least this many noise floors (the pressures' judgement, in their RMS).
pub const MIN_GAIN_IN_NOISE: f64 = 1.0;
/// The held-out force error (in noise floors) below which a new term that brings it within
/// [`EXPLAINED_WITHIN_NOISE`] is judged on the mean square ([`worth_adding`]).
pub const LAST_MILE_WITHIN_NOISE: f64 = 2.5;

/// Whether lowering the held-out force RMS error from `before` to `after` earns an
/// addition: by [`MIN_RELATIVE_GAIN`] of it, and by at least one noise floor of it. A term
/// that `refines` one already added (the same candidate on the same parameters, refitted)
/// claims nothing new, and earns its place by one noise floor squared of the mean square
/// instead: a remainder of two noise floors can lose at most one floor of its RMS to a
/// perfect term but 1.7 of its mean square's four, and a viscous friction refitted from
/// 59.0 to 60.2 N·s/m took 2.26 floors to 1.41 (0.85 floor of RMS, 3.1 of mean square).
/// A new term keeps the RMS bar: on a clean multisine at 250 Hz with a shaken stopper, the
/// mean-square bar let a viscous friction absorb the stopper's reconstruction between
/// samples (1.88 → 1.17 floors, 0.76 of RMS). But below two noise floors no term can gain
/// one floor of RMS, so a remainder between [`EXPLAINED_WITHIN_NOISE`] and
/// [`LAST_MILE_WITHIN_NOISE`] floors is closed by a new term on the mean-square bar when it
/// brings the force within [`EXPLAINED_WITHIN_NOISE`] floors (a torque-motor gain stepping
/// with P1 − P2, at 1.72 floors beside the gain fitted against the force, went to 1.18).
pub fn worth_adding(before: f64, after: f64, noise: f64, refines: bool) -> bool {
    let gain = before - after;
    let last_mile = before <= LAST_MILE_WITHIN_NOISE * noise && after <= EXPLAINED_WITHIN_NOISE * noise;
    let in_noise = if refines || last_mile {
        before * before - after * after >= MIN_GAIN_IN_NOISE * noise * noise
    } else {
        gain >= MIN_GAIN_IN_NOISE * noise
    };
    gain >= MIN_RELATIVE_GAIN * before && in_noise
}
/// A place is an alternative to the located one when the held-out misfit it leaves is at
/// most this many times the located one's ([`Localization::alternatives`]).
pub const ALTERNATIVE_REMAINDER: f64 = 1.25;
/// A place in the chain is named when its best candidate explains at least this share of
/// the held-out misfit (sum over channels, each in its own noise floors).
pub const LOCATED_SHARE: f64 = 0.3;
/// A named effect must explain at least this fraction of what the best candidate at its
/// place explains: otherwise the departure there is of another kind.
pub const NAMED_SHARE_OF_PLACE: f64 = 0.75;
/// …and at least this share of the held-out misfit (of the force against the pressures,
/// for the mechanics and the force sensor): a named effect that leaves more is standing in
/// for something else (measured: 0.88–1.00 for the named effects of the synthetic bench,
/// Bouc–Wen hysteresis lowest; 0.63–0.76 for a supply drift and a port restriction).
pub const NAMED_MIN_SHARE: f64 = 0.8;
const MAX_EFFECTS: usize = 3;
/// How many of the located place's candidates are tried in the model, best first.
const DISCOVERY_TRIALS: usize = 3;
/// Candidates refitted with more Gauss–Newton iterations after the first pass.
const REFINED: usize = 3;
/// Only candidates whose first step explains at least this share are refined.
const WORTH_REFINING: f64 = 0.1;
const REFINE_ITERATIONS: usize = 10;

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

fn errors(model: &Replay, recording: &Recording, blocks: &[Block]) -> Errors {
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

/// Where a diagnosis shows how far its long phases are (the CLI draws progress bars).
pub trait ProgressBars: Send + Sync {
    /// A phase of `total` steps begins.
    fn start(&self, phase: &str, total: usize);
    /// One step of the phase is done (called from any worker thread).
    fn advance(&self);
    fn finish(&self);
}

/// Options of a diagnosis.
#[derive(Clone)]
pub struct Options {
    /// Re-identify the jet pipe offset, C_d and the leakage first (§3.3.1).
    pub calibrate: bool,
    /// Worker threads for the candidates.
    pub jobs: usize,
    pub bars: Option<std::sync::Arc<dyn ProgressBars>>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            calibrate: false,
            jobs: std::thread::available_parallelism().map_or(2, |n| n.get()),
            bars: None,
        }
    }
}

/// [`parallel_map`] with a progress bar over the items.
fn parallel_map_shown<T: Sync, R: Send>(
    phase: &str,
    bars: &Option<std::sync::Arc<dyn ProgressBars>>,
    items: &[T],
    jobs: usize,
    f: impl Fn(&T) -> R + Sync,
) -> Vec<R> {
    match bars {
        None => parallel_map(items, jobs, f),
        Some(bars) => {
            bars.start(phase, items.len());
            let out = parallel_map(items, jobs, |item| {
                let r = f(item);
                bars.advance();
                r
            });
            bars.finish();
            out
        }
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
    fn best_at(&self, location: &str) -> Option<&Scored> {
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
            family: crate::curves::family(candidate.family, &set),
            candidate: candidate.label,
            reading: discover::reading(candidate.label, candidate.location, candidate.family, &set, params),
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
    /// fitted nor scored ([`blocks`]).
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
    pub fast_replay: agreement::FastReplayCheck,
    /// The final model's fixed-step replay against its error-controlled one: the force's RMS
    /// departure, N, and in noise floors; none when nothing was added.
    pub fast_replay_final: Option<(f64, f64)>,
    /// The chamber pressures the final model's replay started from, where the recording has
    /// pressure channels ([`replay::start_pressures`]); at the equilibrium otherwise.
    pub start_pressures: Option<[f64; 2]>,
    /// Where the replays drove the stopper with the smoothed positions
    /// ([`recording::Recording::with_stopper_smoothed`]), the smoothing's residual limit, m²;
    /// `None` where they drove it with the recorded ones.
    pub stopper_smoothing: Option<f64>,
    /// The half-width (s) of the stopper acceleration the final model reads as its input a_s
    /// ([`acceleration`]); 0 where it reads none (no force on the stopper's motion).
    pub acceleration_window: f64,
}

pub use split::PressureSplit;
pub use withdraw::Withdrawn;

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
            && !split::pressures_off(
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

/// The force sensor's reading if the measured pressures drove the model's mechanics
/// (friction, spring floor) and sensor: what the force should be when only the
/// mechanics and the force sensor are in question.
fn force_through_mechanics(model: &Actuator, recording: &Recording) -> Option<Replay> {
    let (p1, p2) = signals::chamber_pressures(model, recording)?;
    let velocity = signals::stopper_velocity(recording);
    let force = (0..recording.len())
        .map(|k| {
            let state = jetpipe_model::physics::actuator::State::from([0.0, 0.0, 0.0, 0.0, p1[k], p2[k]]);
            model.outputs(&state, recording.x_s[k], velocity[k]).f_meas
        })
        .collect();
    Some(Replay {
        force,
        p1,
        p2,
        ..Replay::default()
    })
}

/// Apply a named effect's fitted values to the model's parameters.
fn apply_named(p: &mut Parameters, scored: &Scored) -> Result<Vec<(&'static str, f64)>, String> {
    let mut set = vec![];
    let values = scored.parameters();
    match scored.fit.candidate.named {
        Some("piston_friction") => {
            // Forces read through the sensor's gain; the speed scale as fitted.
            for (name, value) in values {
                let value = match name {
                    "friction_coulomb" => p.friction_coulomb + value / p.force_sensor_gain,
                    "friction_stribeck" => p.friction_stribeck + value / p.force_sensor_gain,
                    "viscous_friction" => p.viscous_friction + value / p.force_sensor_gain,
                    _ => value,
                };
                set_parameter(p, name, value)?;
                set.push((name, value));
            }
        }
        Some("sensor_offset_gain") => {
            let (offset, gain_error) = (values[0].1, values[1].1);
            let gain = (1.0 + gain_error) * p.force_sensor_gain;
            let offset = (1.0 + gain_error) * p.force_sensor_offset + offset;
            set_parameter(p, "force_sensor_gain", gain)?;
            set_parameter(p, "force_sensor_offset", offset)?;
            set.push(("force_sensor_offset", offset));
            set.push(("force_sensor_gain", gain));
        }
        _ => {
            for (name, value) in values {
                set_parameter(p, name, value)?;
                set.push((name, value));
            }
        }
    }
    p.validate()?;
    Ok(set)
}

/// The named effect's own signature in the current residual; `fitted_force` is the force of
/// the model with the effect fitted.
#[allow(clippy::too_many_arguments)]
fn named_signature(
    name: &str,
    recording: &Recording,
    model: &Actuator,
    replay: &Replay,
    fitted_force: &[f64],
    blocks: &[Block],
    noise: f64,
    mechanical_noise: f64,
) -> named::SignatureTest {
    let force_residual = difference(&recording.force, &replay.force);
    // With pressures, the mechanics and the sensor are judged on the force against the
    // pressures; without them, against the model.
    let (residual, reference, judged_noise) = match force_from_pressures(model, recording) {
        Some(f) => (difference(&recording.force, &f), f, mechanical_noise),
        None => (force_residual.clone(), replay.force.clone(), noise),
    };
    match name {
        "sensor_offset_gain" => named::sensor_is_affine(&residual, &reference, blocks, judged_noise),
        "piston_friction" => named::friction_changes_sign(&residual, recording, judged_noise),
        "jet_pipe_hysteresis" => named::loop_with_command_direction(
            &force_residual,
            &difference(fitted_force, &replay.force),
            recording,
            noise,
        ),
        _ => named::SignatureTest {
            present: true,
            sentence: String::new(),
        },
    }
}

/// Diagnose a recording (see the module's account). `progress` receives one line per stage.
pub fn diagnose(
    recording: &Recording,
    base: &Parameters,
    calibrate_static: bool,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    let options = Options {
        calibrate: calibrate_static,
        ..Options::default()
    };
    diagnose_with(recording, base, &options, progress)
}

/// What every stage of a diagnosis reads: the recording, its training blocks and the
/// channels' noise floors.
struct Context<'a> {
    /// The rows the fits work on: the whole recording, or stretches of a long one
    /// ([`Recording::rows_for_fits`]).
    recording: &'a Recording,
    /// Every sample: the noise floors and the errors reported are its.
    full: &'a Recording,
    options: &'a Options,
    /// What each of the fits' rows is for.
    blocks: Vec<Block>,
    /// From when (s) the model's starting state no longer shows.
    settled_from: f64,
    n: usize,
    noise: f64,
    pressure_noise: Option<[f64; 2]>,
    channel_noise: [f64; CHANNELS],
    /// The noise of the force against the pressures.
    mechanical_noise: f64,
    /// The piston's area, m², once known ([`Self::with_piston_area`]; 0 before).
    piston_area: f64,
    /// Where the replays drive the stopper with smoothed positions, the residual limit of
    /// the smoothing ([`recording::smoothed_stopper_positions`]), m².
    stopper_smoothing: Option<f64>,
}

impl<'a> Context<'a> {
    /// Estimate the channels' noise floors (step 1), and how long `model`'s starting state
    /// shows; a force channel rounded coarser than its noise gets a line in `input_checks`.
    fn measure(
        full: &'a Recording,
        recording: &'a Recording,
        model: &Actuator,
        options: &'a Options,
        input_checks: &mut Vec<String>,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Self, String> {
        let n = recording.len();
        // The noise floors from every sample. A sharp line (a pick-up) is a departure to
        // find, not noise.
        let sample_rate = full.sample_rate();
        let floor = |x: &[f64]| noise::noise_floor(&lines::without_lines(x, sample_rate, 3));
        // A signal that curves within a few samples (a 20 Hz multisine or a shaken stopper
        // sampled at 250 Hz) lifts the floor of the recorded channel; the model follows most
        // of it, so the channel's departure from the model keeps the noise alone. A model far
        // off in fast motion lifts the departure's instead: each floor is the lower of the two.
        let modelled = replay_fast(model, full, full.len()).ok();
        let floor_of = |x: &[f64], channel: fn(&Replay) -> &Vec<f64>| {
            let recorded = floor(x);
            match &modelled {
                Some(m) if channel(m).len() == x.len() => recorded.min(floor(&difference(x, channel(m)))),
                _ => recorded,
            }
        };
        let noise = floor_of(&full.force, |m| &m.force);
        let pressure_noise = match (&full.p1, &full.p2) {
            (Some(a), Some(b)) => Some([floor_of(a, |m| &m.p1), floor_of(b, |m| &m.p2)]),
            _ => None,
        };
        drop(modelled);
        if n < full.len() {
            let message = format!(
                "The fits use {n} of the {} samples: stretches of {} s spread over the whole recording. The errors reported are of every sample, and so are the noise floors but for one taken again on the stretches after an addition.",
                full.len(),
                recording::FIT_STRETCH_SECONDS
            );
            progress(&message);
            input_checks.push(message);
        }
        if let Some(q) = noise::quantisation_step(&full.force) {
            if q > noise {
                input_checks.push(format!(
                    "The force channel is quantised in steps of {q:.4} N, coarser than its noise {noise:.4} N: errors below a step cannot be told from rounding."
                ));
            }
        }
        progress(&format!(
            "{n} samples, force noise floor {noise:.4} N{}",
            pressure_noise
                .map(|p| format!(", pressure noise floors {:.0} and {:.0} Pa", p[0], p[1]))
                .unwrap_or_default()
        ));
        let mut channel_noise = [noise, 0.0, 0.0];
        if let Some(p) = pressure_noise {
            channel_noise[1] = p[0];
            channel_noise[2] = p[1];
        }
        let settled_from = blocks::settling_time(model, recording, channel_noise)?;
        let t0 = recording.time[0];
        if settled_from > t0 {
            progress(&format!(
                "the model's starting state shows until {:.2} s: the samples before are neither fitted nor scored",
                settled_from - t0
            ));
        }
        Ok(Self {
            recording,
            full,
            options,
            blocks: blocks::blocks(&recording.time, &recording.x_s, settled_from),
            settled_from,
            n,
            noise,
            pressure_noise,
            channel_noise,
            mechanical_noise: noise,
            piston_area: 0.0,
            stopper_smoothing: None,
        })
    }

    /// The force against the pressures carries the pressures' noise through the piston area.
    fn with_piston_area(mut self, area: f64) -> Self {
        self.piston_area = area;
        self.set_mechanical_noise();
        self
    }

    fn set_mechanical_noise(&mut self) {
        let (noise, area) = (self.noise, self.piston_area);
        self.mechanical_noise = self
            .pressure_noise
            .map(|p| (noise * noise + area * area * (p[0] * p[0] + p[1] * p[1])).sqrt())
            .unwrap_or(noise);
    }

    /// After an addition, each channel's floor taken again from its departure from the model
    /// with `params`, where that is lower: a departure the model before could not follow (a
    /// friction's sharp turns at the reversals) lifted the first estimate as a fast signal
    /// lifts the recording's, and a floor too high reads an error left as noise. On a
    /// recording thinned for the fits, from the departure on its stretches: the floor is a
    /// median over windows of 64 samples, which the few windows across a gap do not move.
    fn lower_noise_to_departure(
        &mut self,
        params: &Parameters,
        replays: &mut usize,
        progress: &mut dyn FnMut(&str),
    ) -> Result<(), String> {
        let with = replay_fast(&Actuator::new(params.clone())?, self.recording, self.n)?;
        *replays += 1;
        let sample_rate = self.recording.sample_rate();
        let floor = |x: &[f64], m: &[f64]| noise::noise_floor(&lines::without_lines(&difference(x, m), sample_rate, 3));
        // Lower by a hundredth at least: the same floor again is no news.
        let force = floor(&self.recording.force, &with.force);
        if force < 0.99 * self.noise {
            progress(&format!(
                "force noise floor {force:.4} N from the departure after the additions (was {:.4} N)",
                self.noise
            ));
            self.noise = force;
            self.channel_noise[FORCE] = force;
        }
        if let (Some(p), Some(p1), Some(p2)) = (self.pressure_noise.as_mut(), &self.recording.p1, &self.recording.p2) {
            for (c, (x, m)) in [(p1, &with.p1), (p2, &with.p2)].into_iter().enumerate() {
                let lower = floor(x, m);
                if lower < 0.99 * p[c] {
                    p[c] = lower;
                    self.channel_noise[c + 1] = lower;
                }
            }
        }
        self.set_mechanical_noise();
        Ok(())
    }
}

/// Diagnose a recording with the given options: the steps of the module's account, in order.
/// A fault of the diagnosis itself (a panic) comes back as an error that says so, not as the
/// end of the caller's process: a batch goes on with its other recordings.
pub fn diagnose_with(
    recording: &Recording,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    diagnose_owned(recording.clone(), base, options, progress)
}

/// [`diagnose_with`] on a recording the diagnosis may keep and change (its stopper
/// positions smoothed in place): a long recording is held once, not twice (a 600 s
/// recording at 1 kHz is 29 MB).
pub fn diagnose_owned(
    recording: Recording,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    let run = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        diagnose_unguarded(recording, base, options, progress)
    }));
    run.unwrap_or_else(|fault| {
        let message = fault
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| fault.downcast_ref::<&str>().copied())
            .unwrap_or("no message");
        Err(format!(
            "the diagnosis failed on a fault of its own, not of the recording ({message}); please report it with the recording"
        ))
    })
}

fn diagnose_unguarded(
    recording: Recording,
    base: &Parameters,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    // 1. The file's checks and the noise floors.
    let mut input_checks = checks::check_file(&recording, base)?;
    let stopper_smoothing = recording.stopper_smoothing();
    let mut smoothed = recording.into_stopper_smoothed();
    let before_model = Actuator::new(base.clone())?;
    // The fits' fixed-step replay, checked against the error-controlled one of the starting
    // model, which the verdict compares the final model with.
    progress("the starting model replayed with the error-controlled integrator");
    let before_accurate = replay(&before_model, &smoothed, 1e-5, smoothed.len())?;
    let fast_replay = agreement::fast_step_that_agrees(&before_model, &smoothed, &before_accurate)?;
    smoothed.fast_replay = fast_replay.method();
    if let Some(sentence) = fast_replay.sentence() {
        progress(&sentence);
        input_checks.push(sentence);
    }
    smoothed.acceleration_window =
        acceleration::choose_window(&smoothed, &signals::difference(&smoothed.force, &before_accurate.force));
    let departures = before_departures(&smoothed, &before_accurate);
    let departures: Vec<&[f64]> = departures.iter().map(Vec::as_slice).collect();
    let fitted = smoothed.rows_for_fits_where_departing(recording::MAX_FIT_ROWS, &departures);
    let cx = Context::measure(&smoothed, &fitted, &before_model, options, &mut input_checks, progress)?;
    let before_fast = replay_fast(&before_model, cx.recording, cx.n)?;
    input_checks.extend(checks::check_against_model(
        cx.recording,
        &before_fast.force,
        Some((&before_fast.p1, &before_fast.p2)),
        base,
    )?);
    // 2. The static identification, when asked for.
    let (mut params, calibrated) = if options.calibrate {
        calibrate_static(&cx, base, progress)
    } else {
        (base.clone(), vec![])
    };
    // The forces on the stopper's motion read the acceleration smoothed from the recording
    // (a model without such a force reads none: the share goes back to 0 at the end).
    params.stopper_acceleration_input_share = 1.0;
    let mut cx = cx.with_piston_area(before_model.piston_area);
    cx.stopper_smoothing = stopper_smoothing;
    // 3–5. Replay, localize, add what earns its place; then refit the additions together.
    let mut replays = 1;
    let found = rounds::run_rounds(&mut cx, params, &mut replays, progress)?;
    let joint_refit = found.joint_refit;
    // 6. The verdict, from the accurate replays.
    conclude::conclude(
        &cx,
        (before_model, before_accurate, fast_replay),
        found,
        joint_refit,
        input_checks,
        calibrated,
        replays,
        progress,
    )
}

/// The starting model's error on each measured channel at every sample.
fn before_departures(recording: &Recording, before: &Replay) -> Vec<Vec<f64>> {
    let mut departures = vec![signals::difference(&recording.force, &before.force)];
    if let (Some(p1), Some(p2)) = (&recording.p1, &recording.p2) {
        departures.push(signals::difference(p1, &before.p1));
        departures.push(signals::difference(p2, &before.p2));
    }
    departures
}

/// Re-identify what the thesis identified from static loops (§3.3.1).
fn calibrate_static(cx: &Context, base: &Parameters, progress: &mut dyn FnMut(&str)) -> (Parameters, Vec<Calibrated>) {
    progress("calibration: x_jp_offset, C_d and the leakage (§3.3.1), on the whole and on halves");
    let (params, calibrated) = calibrate::calibrate(cx.recording, base, &cx.blocks);
    for c in &calibrated {
        progress(&format!(
            "  {} = {:.4e} (thesis {:.4e}){}",
            c.name,
            c.value,
            c.thesis,
            if c.flags.is_empty() { "" } else { "  FLAGGED" }
        ));
    }
    (params, calibrated)
}

/// Whether an added parameter is an amount a refit may move: a curve's knot count and
/// abscissae are its grid, and a modulation slot's constant, signal, frequency and knot
/// count say what varies with what (its knots' abscissae move: a band of friction 60–66 mm
/// wide, first placed at the signal's quantiles, was refitted from 2.5 noise floors to 1.2).
pub(crate) fn refittable(name: &str) -> bool {
    if name.starts_with("modulation_") {
        return name.contains("_y_") || name.contains("_x_");
    }
    !name.ends_with("_curve_knots") && !name.contains("_curve_x_")
}

/// The added parameters as one candidate, starting from their current values.
fn joint_candidate(params: &Parameters, names: &[&'static str]) -> Candidate {
    let terms: Vec<Term> = names
        .iter()
        .map(|&name| {
            let value = parameter_value(params, name);
            let (lower, upper) = corrections::declared_bounds(name);
            Term {
                name,
                unit: discover::unit_of(name),
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
        location: "",
        family: "",
        named: None,
        terms,
        settings: vec![],
    }
}

/// Each effect and term was fitted with those before it held: refit them together, and
/// keep the refit when the held-out force error falls. The error before and after.
pub(crate) fn refit_jointly(
    cx: &Context,
    found: &mut rounds::Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(f64, f64)>, String> {
    if found.effects.len() + found.discovered.len() < 2 {
        return Ok(None);
    }
    let params = &found.params;
    let names: Vec<&'static str> = found
        .effects
        .iter()
        .flat_map(|e| e.parameters.iter())
        .chain(found.discovered.iter().flat_map(|d| d.parameters.iter()))
        .map(|(name, _)| *name)
        .filter(|name| parameter_value(params, name) != 0.0)
        .filter(|name| refittable(name))
        .collect();
    progress(&format!("joint refit of the {} parameters added", names.len()));
    let Some((trial, before_joint, after_joint)) = refit_constants(cx, params, &names, replays)? else {
        return Ok(None);
    };
    progress(&format!(
        "  held-out force error {before_joint:.4} -> {after_joint:.4} N"
    ));
    if after_joint >= before_joint {
        return Ok(None);
    }
    found.params = trial;
    retire_switched_off(found, progress);
    Ok(Some((before_joint, after_joint)))
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
    curves::monotone_command(&mut refitted);
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

/// After the joint refit: a named effect the refit turned off (its amplitude at zero:
/// another term took over what it explained) is no longer there, and the others report
/// their refitted values.
fn retire_switched_off(found: &mut rounds::Findings, progress: &mut dyn FnMut(&str)) {
    let params = &mut found.params;
    let count = found.effects.len();
    found.effects.retain(|e| {
        let off = match e.name {
            "piston_friction" => params.friction_coulomb == 0.0,
            _ => e
                .parameters
                .iter()
                .all(|(name, _)| parameter_value(params, name) == parameter_value(&Parameters::default(), name)),
        };
        if off {
            progress(&format!("  {} is off after the refit: removed", e.name));
        }
        !off
    });
    if found.effects.len() != count && matches!(found.newest, Some((true, _))) {
        found.newest = None;
    }
    if params.friction_coulomb == 0.0 {
        params.friction_velocity = 0.0;
    }
    for (name, value) in found
        .effects
        .iter_mut()
        .flat_map(|e| e.parameters.iter_mut())
        .chain(found.discovered.iter_mut().flat_map(|d| d.parameters.iter_mut()))
    {
        *value = parameter_value(params, name);
    }
}
