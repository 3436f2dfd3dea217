//! What the rounds have found so far, and one round's replay of it: the state every step of
//! the decision reads and changes.

use crate::candidates::parameter_value;
use crate::candidates::Candidate;
use crate::context::Context;
use crate::decide::additions::AddedEffect;
use crate::decide::additions::DiscoveredTerm;
use crate::fit::scored::Localization;
use crate::fit::scored::Scored;
use crate::fit::Problem;
use crate::input::blocks::Block;
use crate::policy::MIN_GAIN_IN_NOISE;
use crate::policy::MIN_RELATIVE_GAIN;
use crate::replay::signals::difference;
use crate::replay::signals::rms_where;
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// What the rounds found: the model's parameters with every effect and term added.
#[derive(Clone)]
pub(crate) struct Findings {
    pub params: Parameters,
    pub effects: Vec<AddedEffect>,
    pub discovered: Vec<DiscoveredTerm>,
    /// The first round's scored candidates, for the report.
    pub first_candidates: Vec<Scored>,
    /// Where the departure left unexplained sits (none when every channel is within its noise).
    pub localization: Option<Localization>,
    /// The held-out force error before and after the last joint refit that was kept.
    pub joint_refit: Option<(f64, f64)>,
    /// The parameters before the rounds, to which a removed addition's go back.
    pub start: Parameters,
    /// The latest addition: a named effect (`true`) or a discovered term, by index.
    pub newest: Option<(bool, usize)>,
    /// The findings as each round with an addition left them, earliest first, to which the
    /// final check can go back (`withdraw.rs`).
    pub stages: Vec<Stage>,
}

/// The findings as one round left them.
#[derive(Clone)]
pub(crate) struct Stage {
    pub params: Parameters,
    pub effects: Vec<AddedEffect>,
    pub discovered: Vec<DiscoveredTerm>,
    pub joint_refit: Option<(f64, f64)>,
}

impl Stage {
    pub(crate) fn of(f: &Findings) -> Stage {
        Stage {
            params: f.params.clone(),
            effects: f.effects.clone(),
            discovered: f.discovered.clone(),
            joint_refit: f.joint_refit,
        }
    }
}

/// One round's replay of the current model and how far it is from the recording.
pub(crate) struct Round {
    pub(crate) model: Actuator,
    pub(crate) current: Replay,
    pub(crate) heldout: [f64; CHANNELS],
    /// Held-out samples.
    pub(crate) count: f64,
    pub(crate) force_before: f64,
    pub(crate) pressures_agree: bool,
    pub(crate) candidates: Vec<Candidate>,
    /// The force residual's spectral line, if it has one.
    pub(crate) periodic: Option<f64>,
}

/// Every addition's constants and reading as they now stand in the parameters.
pub(crate) fn sync_earlier(f: &mut Findings) {
    for (name, value) in f.effects.iter_mut().flat_map(|e| e.parameters.iter_mut()) {
        *value = parameter_value(&f.params, name);
    }
    for d in f.discovered.iter_mut() {
        let mut moved = false;
        for (name, value) in d.parameters.iter_mut() {
            let now = parameter_value(&f.params, name);
            moved |= now != *value;
            *value = now;
        }
        if moved {
            d.reading = crate::decide::discover::reading(d.candidate, d.location, d.family, &d.parameters, &f.start);
        }
    }
}

/// Whether two discovered terms are the same candidate carried by the same parameters.
pub(crate) fn same_term(a: &DiscoveredTerm, b: &DiscoveredTerm) -> bool {
    carried_alike(a, b.candidate, &b.parameters)
}

/// Whether `term` is `candidate` carried by the parameters named in `parameters`.
pub(crate) fn carried_alike(term: &DiscoveredTerm, candidate: &str, parameters: &[(&'static str, f64)]) -> bool {
    term.candidate == candidate
        && term.parameters.len() == parameters.len()
        && term.parameters.iter().zip(parameters).all(|(x, y)| x.0 == y.0)
}

/// Named effects are the hypotheses tried first: once a term outside them has been added,
/// a named effect found later may be absorbing what that term's form misses, and only those
/// whose own signature is tested in the residual (friction, the sensor's offset and gain,
/// hysteresis) are still tried.
pub(crate) fn nameable(s: &Scored, discovered: &[DiscoveredTerm]) -> bool {
    s.fit.candidate.named.map_or(false, |name| {
        discovered.is_empty() || crate::decide::named::has_signature_test(name)
    })
}

/// Whether the pressures' held-out misfit (noise floors squared, summed over `count`
/// samples) falls from `was` to `now` by enough to earn an addition: the force's rule in
/// their noise, in mean square. Two channels at their noise read √2 floors together, so a
/// term that takes them from 2.0 to their noise gains 0.6 floor of the RMS but 2 of the mean
/// square (a chamber 1 transducer saturating over its top 5 kPa: 1.98 -> 1.42).
pub(crate) fn pressures_gain(was: &[f64; CHANNELS], now: &[f64; CHANNELS], count: f64) -> bool {
    let in_noise = |h: &[f64; CHANNELS]| ((h[1] + h[2]) / count).sqrt();
    let (was, now) = (in_noise(was), in_noise(now));
    was - now >= MIN_RELATIVE_GAIN * was && was * was - now * now >= MIN_GAIN_IN_NOISE
}

/// For a transducer's curve, its corners beyond the quantities the recording visits
/// (`crate::candidates::curves::corners_across_unvisited`); other candidates' `set` unchanged.
pub(crate) fn curve_corners_across_unvisited(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    params: &Parameters,
    candidate: &Candidate,
    set: &mut Vec<(&'static str, f64)>,
) {
    if !crate::candidates::curves::is_channel_curve(candidate) {
        return;
    }
    // The curve's coordinates are the quantity the transducer reads: its reading with the
    // transducer's offset and gain taken off.
    let p = params;
    let unread = |reading: &[f64], o: f64, g: f64| -> Vec<f64> { reading.iter().map(|v| (v - o) / g).collect() };
    let quantities = [
        unread(&r.current.force, p.force_sensor_offset, p.force_sensor_gain),
        unread(&r.current.p1, p.p1_sensor_offset, p.p1_sensor_gain),
        unread(&r.current.p2, p.p2_sensor_offset, p.p2_sensor_gain),
    ];
    crate::candidates::curves::corners_across_unvisited(
        set,
        [&quantities[0], &quantities[1], &quantities[2]],
        problem.measured,
        &cx.blocks,
    );
}

/// Whether a candidate may be added as a discovered term, which claims no name: one outside
/// the named effects, or a named effect whose name this round cannot give (see [`nameable`]).
/// A term may be found first and the named effect after it: beside chamber leaks found in a
/// first round, the dead volumes explained 98 % of the second and could be neither named nor
/// added, and 12 noise floors stayed.
pub(crate) fn unclaimed(s: &Scored, discovered: &[DiscoveredTerm]) -> bool {
    s.fit.candidate.named.is_none() || !nameable(s, discovered)
}

/// A pressure transducer's term leaves the force as it is: it is judged on the pressures,
/// by the same rule in their noise, and must leave the force no worse. When it passes, the
/// held-out RMS of each pressure before and after, Pa.
pub(crate) fn pressures_judgement(
    cx: &Context,
    r: &Round,
    problem: &Problem,
    with: &Replay,
    after: f64,
    progress: &mut dyn FnMut(&str),
    label: &str,
) -> Option<([f64; 2], [f64; 2])> {
    let recording = cx.recording;
    let (_, replayed) = problem.errors(&[with.force.clone(), with.p1.clone(), with.p2.clone()]);
    let in_noise = |h: &[f64; CHANNELS]| ((h[1] + h[2]) / r.count).sqrt();
    progress(&format!(
        "  {label}: in the model, pressures held-out {:.2} -> {:.2} noise floors",
        in_noise(&r.heldout),
        in_noise(&replayed)
    ));
    let rms_pa = |series: [&[f64]; 2]| {
        let measured = [recording.p1.as_deref(), recording.p2.as_deref()];
        [0, 1].map(|c| {
            measured[c].map_or(0.0, |m| {
                rms_where(&difference(m, series[c]), &cx.blocks, Block::HeldOut)
            })
        })
    };
    let better = pressures_gain(&r.heldout, &replayed, r.count) && after <= r.force_before + 0.05 * cx.noise;
    better.then(|| (rms_pa([&r.current.p1, &r.current.p2]), rms_pa([&with.p1, &with.p2])))
}
