//! What `jetpipe diagnose` reports: the whole diagnosis, its verdict and what is left.

use crate::decide::additions::AddedEffect;
use crate::decide::additions::DiscoveredTerm;
use crate::decide::withdraw::Withdrawn;
use crate::fit::calibrate::Calibrated;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::replay::errors::Errors;
use crate::replay::signature::Signature;
use crate::verdict::split::PressureSplit;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;
use serde_json::Value;

/// What is left when the verdict is not "explained".
#[derive(Clone, Debug)]
pub struct Unexplained {
    pub rms: f64,
    pub ratio_to_noise: f64,
    pub location: Place,
    pub family: Family,
    pub alternatives: Vec<Place>,
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
    /// The recording's glitches ([`crate::input::glitches`]): their samples were set aside.
    pub glitches: Vec<crate::input::glitches::Glitch>,
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
    /// The stopper positions the replays drove the model with
    /// ([`crate::input::recording::Recording::stopper_positions`]).
    pub stopper_positions: crate::input::recording::StopperPositions,
    /// The half-width (s) of the stopper acceleration the final model reads as its input a_s
    /// ([`crate::input::acceleration`]); 0 where it reads none (no force on the stopper's motion).
    pub acceleration_window: f64,
}

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
