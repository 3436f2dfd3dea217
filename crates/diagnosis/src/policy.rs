//! The thresholds and precedence rules by which the diagnosis decides, each stated once with its
//! reason: what is explained, what earns a place in the model, which of two forms wins, how many
//! places and rounds are tried. The numerical settings of each method (grids, steps, knots, a
//! class's own limits) stay with the method.

/// Length of the alternating training / held-out blocks.
pub const BLOCK_SECONDS: f64 = 2.0;
/// The verdict is "explained" when the held-out force error is within this many noise floors.
pub const EXPLAINED_WITHIN_NOISE: f64 = 1.5;

// Glitches in the data ([`crate::input::glitches`]): each bar is one noise cannot reach, so
// that a clean recording has none.

/// A spike stands this many noise floors off the lines through its neighbours: white noise
/// reaches it about once in 10^10 samples (the three distances have standard deviations of
/// 2.4, 2.4 and 1.2 floors).
pub const SPIKE_NOISE_FLOORS: f64 = 10.0;
/// …and this many times the median distance of the samples around it from a cubic through
/// their neighbours, so that a signal curving fast (a chirp sampled a few times a period)
/// does not read as spikes: in white noise that median is 0.94 floors, so there the first
/// bar decides.
pub const SPIKE_LOCAL_SCALES: f64 = 8.0;
/// A run of equal values this long or longer is a stuck channel; shorter, repeated samples.
pub const STUCK_SAMPLES: usize = 10;
/// A step in time longer than this many median steps is a gap (a dropped sample doubles one).
pub const GAP_STEPS: f64 = 1.5;

/// A channel's noise is not steady when its local level's ninetieth percentile over windows
/// of 64 samples is this many times its tenth (white noise of one level: about 1.2). Its
/// floor is then the RMS of its local level, what a model without error leaves, so that
/// `explained` still means within [`EXPLAINED_WITHIN_NOISE`] of the noise measured.
pub const NOISE_VARIES: f64 = 1.6;

/// A channel's local noise level follows a series (the channel's own size, the command's
/// activity) when their correlation over the windows exceeds this: for noise growing in
/// proportion to a force swinging 15–75 N it is about 0.98; a level that falls as the force
/// grows does not follow it.
pub const NOISE_FOLLOWS_CORRELATION: f64 = 0.5;

/// The force answers the stopper positions' rounding, and the model is driven with them as
/// recorded, when their correlation exceeds this many times its standard error with none,
/// 1/√n ([`crate::input::recording::force_answers_stopper_rounding`]): by chance once in
/// about two million recordings.
pub const STOPPER_ROUNDING_STANDARD_ERRORS: f64 = 5.0;

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
/// most this many times the located one's (`Localization::alternatives`).
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
/// How many additions the rounds may make: up to three departures at different places,
/// besides a named effect.
pub const MAX_EFFECTS: usize = 4;

/// How many additions, the earliest first, are revisited once the rounds leave a channel
/// above its bar (`decide/revisit.rs`): each revisit costs a round.
pub const REVISITED: usize = 2;
/// How many of the located place's candidates are tried in the model, best first.
pub const DISCOVERY_TRIALS: usize = 3;
/// Candidates refitted with more Gauss–Newton iterations after the first pass.
pub const REFINED: usize = 3;
/// Only candidates whose first step explains at least this share are refined.
pub const WORTH_REFINING: f64 = 0.1;
pub const REFINE_ITERATIONS: usize = 10;

// The replay's stepping.

/// The longest fixed step of `replay_fast` (s): a recording sampled more coarsely than
/// the bench's 1 ms is stepped in equal parts of at most this. One 4 ms ROS2 step per
/// sample at 250 Hz left the pressures 3–8 noise floors off a clean recording that the
/// error-controlled replay reproduces within its noise.
pub const MAX_FAST_STEP: f64 = 1.05e-3;

// The decision stage's rules: when a richer or a written term is preferred, how many places and
// rounds are tried, and when an addition counts as redundant or negligible.

/// A term richer than the named effect it would replace must close at least this share of
/// the gap between the named effect's held-out force error and the noise floor.
pub const RICHER_SHARE_OF_GAP: f64 = 0.2;

/// A term as rich as the named effect it would replace must close at least this share of
/// that gap, or take this share of the named effect's held-out misfit (a departure in the
/// pressures).
pub const EQUAL_SHARE_OF_GAP: f64 = 0.05;

/// An addition with at least this many parameters (a static curve through its knots) can
/// stand in for a simpler term at another place of the chain: those are re-tried after it.
pub const FLEXIBLE_TERMS: f64 = 4.0;

/// The simpler terms re-tried at other places have at most this many parameters.
pub const SIMPLE_TERMS: f64 = 2.0;

/// How many of them: the best of each place, best first by their penalised held-out misfit.
pub const ELSEWHERE_TRIALS: usize = 8;

/// Places whose best candidate enters the pairs.
pub const PAIRED_PLACES: usize = 6;

/// Pairs fitted again from fresh sensitivities after the first step's ranking.
pub const LEADING_PAIRS: usize = 3;

/// A departure of this many noise floors of a channel lifts the channel's held-out misfit,
/// noise and departure together, to [`EXPLAINED_WITHIN_NOISE`]: √(1 + 1.118²) = 1.5.
pub const PRESSURES_SHOW_FROM: f64 = 1.118;

/// A named effect at the same place whose share of the held-out misfit was at most this much
/// below the named one's is a rival.
pub const RIVAL_SHARE_GAP: f64 = 0.05;

/// At most this many rivals are tried for each named effect.
pub const MOST_RIVALS: usize = 2;

/// A written term that earns its place but leaves more than the verdict's bar ends the
/// trials only when no later trial's fit promises to leave at most this share of its
/// held-out force error: a current driver's gain, as good as tied with the jet pipe, is
/// tried after the jet pipe's curve that leaves 7 noise floors.
pub const PROMISE_BEYOND_WRITTEN: f64 = 0.5;

/// See `shown_mostly_where_fitted` (`decide/new_term.rs`).
pub const TRAINING_GAIN_IN_NOISE: f64 = 3.0;

/// A written term that does within this factor of a modulation's held-out force error in the
/// model (or within the verdict's bar) is added instead of it.
pub const WRITTEN_INSTEAD_WITHIN: f64 = 1.1;

/// A force error larger than the starting model's by at most this share of the noise floor
/// is not worse: a thousandth of the noise is beyond any measurement, and a term that leaves
/// the force alone (a pressure transducer's offset, say) moves it by about that much through
/// the chambers' start, which the transducers' readings set.
pub const NEGLIGIBLE_SHARE_OF_NOISE: f64 = 1e-3;

/// At most this many earlier rounds' models are replayed accurately before every addition
/// goes: each costs an error-controlled replay of the whole recording.
pub const EARLIER_ROUNDS_TRIED: usize = 3;

/// Candidates of the round fitted beside the earlier additions.
pub const BESIDE_MEMBERS: usize = 4;

/// Written candidates away from the named effect's place fitted beside it (all at its place are).
pub const ELSEWHERE_BESIDE_NAMED: usize = 3;

/// The held-out force error below which taking an addition out counts as costing nothing,
/// in noise floors.
pub const REDUNDANT_WITHIN_NOISE: f64 = 0.1;

/// See `discovery_penalty_per_term` (`fit/localize.rs`).
pub const MIN_MEAN_SQUARE_GAIN_PER_TERM: f64 = 0.01;

/// How much more held-out misfit than a modulation a written candidate at the same place may
/// leave and still be tried first: the simpler, named form wins where it is adequate (a
/// quadratic damping before a viscous friction varying with the velocity, a transducer's
/// static curve before its gain varying with its pressure).
pub const WRITTEN_FIRST_WITHIN: f64 = 1.25;

/// A written candidate whose first-order fit leaves the force within this many noise floors
/// is tried before a modulation at its place: its refit in the model usually gains the rest.
pub const WRITTEN_ADEQUATE_WITHIN: f64 = 2.0;

/// A readable candidate whose held-out misfit is within this factor of a flexible term's
/// stands instead of it (`decide/flexible.rs`): a form a person reads is worth a little misfit.
pub const READABLE_WINS_WITHIN: f64 = 1.25;

/// The flexible surfaces, best screened first, fitted through the model in a slot.
pub const FLEXIBLE_FITTED: usize = 3;

/// Gauss–Newton linearisations of a flexible term's fit through the model.
pub const FLEXIBLE_ITERATIONS: usize = 3;

// Several recordings of one actuator diagnosed together ([`crate::input::joint`]).

/// Rates within this fraction of each other are one rate: no recording is resampled.
pub const SAME_RATE_WITHIN: f64 = 0.01;
/// The stopper's speed between two recordings (m/s): half the most a bench plays (200 mm/s),
/// so that the chambers' volumes change as on a bench.
pub const BRIDGE_STOPPER_SPEED: f64 = 0.1;
/// How long the bridge holds the next recording's first inputs (s): the chambers, the jet
/// pipe and the transducers settle within tens of milliseconds.
pub const BRIDGE_HOLD_SECONDS: f64 = 1.0;
/// An addition is held by a recording when taking it out of the joint model raises one of
/// that recording's channels by this many noise floors (held out for the force, over the
/// whole for a pressure): a tenth of a floor, as an addition earns its keep
/// ([`REDUNDANT_WITHIN_NOISE`]).
pub const HELD_BY_RECORDING_NOISE_FLOORS: f64 = REDUNDANT_WITHIN_NOISE;

#[cfg(test)]
mod tests {
    use super::*;

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
}
