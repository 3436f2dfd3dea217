//! Glitches in the data, found before any fitting: isolated spikes, repeated samples, a
//! channel stuck or clipped for a stretch, gaps in time. A glitch is a fault of the
//! recording, not of the actuator, so it is never read as a mechanism: its samples are
//! set aside (neither fitted nor scored, and left out of every error the report gives),
//! and their values are replaced by an interpolation from the samples either side, so that
//! what reads the recording as a whole (the replays' stopper positions, the spectra, the
//! correlations) does not see them either. Gaps in time are only reported: the samples
//! either side are good, and the replays hold the command across them as the format says.
//!
//! Each test asks only what noise cannot do, so a clean recording has none:
//! - a **spike** is one sample that lies beyond the straight lines through the two samples
//!   before it and the two after it, and beyond the chord of its neighbours, all on the same
//!   side, by [`SPIKE_NOISE_FLOORS`] noise floors and by [`SPIKE_LOCAL_SCALES`] times the
//!   typical distance of the samples around it from a cubic through their neighbours. A
//!   smooth curve lies on opposite sides of its chord and of its tangents; a kink lies on one
//!   of the two lines; and the samples either side of a spike are closer to each other than
//!   to it, where those either side of a step are not;
//! - a **repeated**, **stuck** or **clipped** stretch is a run of exactly equal values in a
//!   measured channel that is improbable: fewer than one such run in a hundred recordings,
//!   given how often the channel repeats a value around it. A channel rounded to a step its
//!   noise hardly exceeds may be quieter than its step for a while: only a run of
//!   [`STUCK_SAMPLES`] repeats counts there. It is clipped
//!   when it sits at the channel's highest or lowest value, stuck when it lasts
//!   [`STUCK_SAMPLES`] samples or more, repeated below that;
//!   A spike within a sample of an abrupt change of the inputs (a command step, a kink of the
//!   stopper's motion) is the actuator's answer to it and is left alone;
//! - a **gap** is a step in time longer than [`GAP_STEPS`] median steps.
//!
//! Rows that repeat the row before them exactly, time included, are dropped when the file is
//! read ([`crate::input::recording::Recording::repeated_rows`]) and reported here.

use crate::input::noise::noise_floor;
use crate::input::noise::quantisation_step;
use crate::input::recording::Recording;
use crate::policy::GAP_STEPS;
use crate::policy::SPIKE_LOCAL_SCALES;
use crate::policy::SPIKE_NOISE_FLOORS;
use crate::policy::STUCK_SAMPLES;

/// What is wrong with a stretch of samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GlitchKind {
    Spike,
    Repeated,
    Stuck,
    Clipped,
    Gap,
    /// A row repeating the row before it exactly, time included: dropped.
    RepeatedRow,
}

impl GlitchKind {
    /// The word reports use.
    pub fn as_str(self) -> &'static str {
        match self {
            GlitchKind::Spike => "spike",
            GlitchKind::Repeated => "repeated",
            GlitchKind::Stuck => "stuck",
            GlitchKind::Clipped => "clipped",
            GlitchKind::Gap => "gap",
            GlitchKind::RepeatedRow => "repeated_row",
        }
    }
}

/// A glitch: its kind, the column, the time span (s) and how many samples it touches (for a
/// gap, how many are missing).
#[derive(Clone, Debug, PartialEq)]
pub struct Glitch {
    pub kind: GlitchKind,
    pub column: &'static str,
    pub from_s: f64,
    pub to_s: f64,
    pub samples: usize,
}

impl Glitch {
    /// Whether its samples are set aside (a gap's and a dropped row's are not: there are none).
    pub fn sets_aside(&self) -> bool {
        !matches!(self.kind, GlitchKind::Gap | GlitchKind::RepeatedRow)
    }
}

/// The time spans (s, inclusive) whose samples are set aside.
pub fn set_aside_spans(glitches: &[Glitch]) -> Vec<(f64, f64)> {
    glitches
        .iter()
        .filter(|g| g.sets_aside())
        .map(|g| (g.from_s, g.to_s))
        .collect()
}

/// Find the recording's glitches and replace the values of the samples set aside by
/// interpolation. The command is what was played and is never changed.
pub fn find_and_repair(recording: &mut Recording) -> Vec<Glitch> {
    let time = recording.time.clone();
    let mut glitches: Vec<Glitch> = recording
        .repeated_rows
        .iter()
        .map(|&(_, t)| Glitch {
            kind: GlitchKind::RepeatedRow,
            column: "all columns",
            from_s: t,
            to_s: t,
            samples: 1,
        })
        .collect();
    glitches.extend(gaps(&time));
    let mut channels: Vec<(&'static str, &mut Vec<f64>, bool)> = vec![("force_N", &mut recording.force, true)];
    if let (Some(p1), Some(p2)) = (recording.p1.as_mut(), recording.p2.as_mut()) {
        channels.push(("p1_Pa", p1, true));
        channels.push(("p2_Pa", p2, true));
    }
    let events = input_events(&recording.v_da, &recording.x_s);
    // A stopper held still logs the same position for seconds: only its spikes are glitches.
    channels.push(("x_s_m", &mut recording.x_s, false));
    for (column, values, measured) in channels {
        let noise = noise_floor(values);
        let (low, high) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
        // A channel without noise (a simulated one) gives no scale to tell a glitch by.
        if noise.is_nan() || noise <= 1e-9 * (high - low).max(f64::MIN_POSITIVE) {
            continue;
        }
        if measured {
            for glitch in runs(values, noise, &time, column, (low, high)) {
                glitches.push(glitch);
            }
        }
        let events: &[bool] = if measured { &events } else { &[] };
        glitches.extend(spikes(values, noise, &time, column, events));
    }
    glitches.sort_by(|a, b| a.from_s.total_cmp(&b.from_s).then(a.column.cmp(b.column)));
    glitches
}

/// Steps in time longer than [`GAP_STEPS`] median steps.
fn gaps(time: &[f64]) -> Vec<Glitch> {
    if time.len() < 3 {
        return vec![];
    }
    let mut steps: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = steps.len() / 2;
    let step = *steps.clone().select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
    steps
        .drain(..)
        .enumerate()
        .filter(|&(_, s)| s > GAP_STEPS * step)
        .map(|(k, s)| Glitch {
            kind: GlitchKind::Gap,
            column: "time_s",
            from_s: time[k],
            to_s: time[k + 1],
            samples: ((s / step).round() as usize).saturating_sub(1).max(1),
        })
        .collect()
}

/// Runs of exactly equal values that the channel's noise makes improbable, interpolated over.
fn runs(values: &mut [f64], noise: f64, time: &[f64], column: &'static str, range: (f64, f64)) -> Vec<Glitch> {
    let n = values.len();
    let repeats = values.windows(2).filter(|w| w[1] == w[0]).count();
    // How often the channel repeats a value by itself: never when it is not rounded (a
    // float of noise), as often as it does when rounded coarser than a small part of it.
    // A channel written to a few decimals repeats values where it is quiet: the rate of
    // repeats is taken around each run (and over the whole, the run left out). A channel
    // rounded to a step its noise hardly exceeds may be quieter than its step for a while:
    // there only a run of [`STUCK_SAMPLES`] is a glitch.
    let rounded = quantisation_step(values).map_or(false, |q| q > 1e-3 * noise) || repeats * 1000 > n;
    let shortest = if rounded { STUCK_SAMPLES + 1 } else { 2 };
    let repeated: Vec<bool> = (0..n).map(|k| k > 0 && values[k] == values[k - 1]).collect();
    let natural_around = |from: usize, to: usize| -> f64 {
        let (a, b) = (from.saturating_sub(RATE_WINDOW), (to + RATE_WINDOW).min(n));
        let outside = (a..from).chain(to..b);
        let count = outside.clone().count().max(1);
        let elsewhere = repeats.saturating_sub(to - from - 1) as f64 / n as f64;
        (outside.filter(|&k| repeated[k]).count() as f64 / count as f64).max(elsewhere)
    };
    let mut found = vec![];
    let mut k = 0;
    while k + 1 < n {
        let mut end = k + 1;
        while end < n && values[end] == values[k] {
            end += 1;
        }
        let length = end - k;
        // Runs as long as this one, expected in a hundred recordings of this length.
        let expected = if length >= shortest {
            100.0 * n as f64 * natural_around(k, end).powi(length as i32 - 1)
        } else {
            f64::INFINITY
        };
        if length >= 2 && expected < 1.0 {
            let at_rail = values[k] == range.0 || values[k] == range.1;
            let kind = if at_rail {
                GlitchKind::Clipped
            } else if length >= STUCK_SAMPLES {
                GlitchKind::Stuck
            } else {
                GlitchKind::Repeated
            };
            // The first sample of a repeated or stuck run was read; a clipped one was not.
            let first = if at_rail { k } else { k + 1 };
            let (before, after) = (first.checked_sub(1), (end < n).then_some(end));
            interpolate(values, time, first, end, before, after);
            found.push(Glitch {
                kind,
                column,
                from_s: time[first],
                to_s: time[end - 1],
                samples: end - first,
            });
        }
        k = end;
    }
    found
}

/// Values at `from..to` set on the line between the samples `before` and `after` (or held
/// from the one that exists).
fn interpolate(values: &mut [f64], time: &[f64], from: usize, to: usize, before: Option<usize>, after: Option<usize>) {
    for k in from..to {
        values[k] = match (before, after) {
            (Some(a), Some(b)) => {
                let w = (time[k] - time[a]) / (time[b] - time[a]);
                values[a] + w * (values[b] - values[a])
            }
            (Some(a), None) => values[a],
            (None, Some(b)) => values[b],
            (None, None) => values[k],
        };
    }
}

/// Isolated one-sample spikes, each replaced by the cubic through the two samples either side.
fn spikes(values: &mut [f64], noise: f64, time: &[f64], column: &'static str, events: &[bool]) -> Vec<Glitch> {
    let n = values.len();
    let mut found = vec![];
    if n < 5 {
        return found;
    }
    let bar = SPIKE_NOISE_FLOORS * noise;
    for k in 2..n - 2 {
        if events.get(k).copied().unwrap_or(false) {
            continue;
        }
        let x = &values[k - 2..=k + 2];
        let from_left = x[2] - (2.0 * x[1] - x[0]);
        let from_right = x[2] - (2.0 * x[3] - x[4]);
        let from_chord = x[2] - 0.5 * (x[1] + x[3]);
        let same_side = from_left.signum() == from_right.signum() && from_left.signum() == from_chord.signum();
        let size = from_left.abs().min(from_right.abs()).min(from_chord.abs());
        if !same_side || size <= bar || size <= SPIKE_LOCAL_SCALES * local_curvature(values, k) {
            continue;
        }
        if !isolated(values, k) {
            continue;
        }
        values[k] = cubic_between(&values[k - 2..=k + 2]);
        found.push(Glitch {
            kind: GlitchKind::Spike,
            column,
            from_s: time[k],
            to_s: time[k],
            samples: 1,
        });
    }
    found
}

/// Whether the sample `k` strays from the cubic through its neighbours by a quarter more than
/// they do from theirs and twice as much as the samples two away (a spike's neighbours stray
/// by two thirds of it and those two away by a sixth; a step's by as much as its edge, a
/// ringing at half the sampling rate's by as much every other sample),
/// and with `k` on that cubic its neighbours lie on their cubics within a quarter of its
/// departure (a step's would not: its edge moves along).
fn isolated(values: &[f64], k: usize) -> bool {
    let n = values.len();
    let departure = |x: &[f64], j: usize| x[j] - cubic_between(&x[j - 2..=j + 2]);
    let own = departure(values, k).abs();
    let others = (k.saturating_sub(2).max(2)..=(k + 2).min(n - 3)).filter(|&j| j != k);
    if others.clone().any(|j| {
        let bar = if j + 1 == k || j == k + 1 { 1.25 } else { 2.0 };
        bar * departure(values, j).abs() > own
    }) {
        return false;
    }
    let mut repaired = values[k.saturating_sub(5)..(k + 6).min(n)].to_vec();
    let at = k - k.saturating_sub(5);
    repaired[at] = cubic_between(&repaired[at - 2..=at + 2]);
    (at.saturating_sub(2).max(2)..=(at + 2).min(repaired.len() - 3))
        .filter(|&j| j != at)
        .all(|j| departure(&repaired, j).abs() <= 0.25 * own)
}

/// The samples within one of an abrupt change of the inputs: a step of the command, or a
/// kink of the stopper's motion (a change of its velocity within a sample, which a force on
/// its acceleration answers with a one-sample impulse). An abrupt change is one that stands
/// [`EVENT_LOCAL_SCALES`] times above the changes around it; a command's, also above two
/// steps of its rounding. Every kink of a rounded stopper position counts, one step of the
/// rounding too: a plant driven by the logged positions answers those (an independent
/// simulator's force on the stopper's acceleration dipped by 0.75 N at each 1 µm kink at
/// 4 kHz). The measured channels' answer to either is the actuator's, not a spike.
fn input_events(v_da: &[f64], x_s: &[f64]) -> Vec<bool> {
    let n = v_da.len();
    let mut events = vec![false; n];
    let jumps: Vec<f64> = (0..n)
        .map(|k| if k == 0 { 0.0 } else { (v_da[k] - v_da[k - 1]).abs() })
        .collect();
    let kinks: Vec<f64> = (0..n)
        .map(|k| {
            if k == 0 || k + 1 == n {
                0.0
            } else {
                (x_s[k + 1] - 2.0 * x_s[k] + x_s[k - 1]).abs()
            }
        })
        .collect();
    // A logged position's every kink is one (its rounding makes them, and a plant driven by
    // it answers each); an unrounded position's, only one that stands out of its noise.
    let stopper_rounded = quantisation_step(x_s).is_some();
    for (changes, rounding, every) in [
        (&jumps, 2.0 * quantisation_step(v_da).unwrap_or(0.0), false),
        (&kinks, 0.0, stopper_rounded),
    ] {
        for k in 0..n {
            let change = changes[k];
            if change == 0.0 || change <= rounding {
                continue;
            }
            if every {
                for e in &mut events[k.saturating_sub(2)..(k + 2).min(n)] {
                    *e = true;
                }
                continue;
            }
            let from = k.saturating_sub(LOCAL_WINDOW);
            let to = (k + LOCAL_WINDOW).min(n - 1);
            let mut around: Vec<f64> = (from..=to).filter(|&j| j != k).map(|j| changes[j]).collect();
            let mid = around.len() / 2;
            let typical = *around.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
            if change > EVENT_LOCAL_SCALES * typical {
                for e in &mut events[k.saturating_sub(2)..(k + 2).min(n)] {
                    *e = true;
                }
            }
        }
    }
    events
}

/// An input's change this many times the median change around it is abrupt.
const EVENT_LOCAL_SCALES: f64 = 5.0;

/// The value at the middle of five samples of the cubic through the other four.
fn cubic_between(x: &[f64]) -> f64 {
    (-x[0] + 4.0 * x[1] + 4.0 * x[3] - x[4]) / 6.0
}

/// Samples either side of a run of a rounded channel over which its rate of repeats is taken.
const RATE_WINDOW: usize = 256;

/// Samples either side of a spike whose curvature gives the local scale.
const LOCAL_WINDOW: usize = 16;

/// The median distance of the samples within [`LOCAL_WINDOW`] of `k` from the cubic through
/// the two samples either side of each, those the sample `k` enters left out: how far the
/// signal itself strays from a cubic there (a sine sampled ten times a period, 2.4 % of its
/// amplitude; where the signal is slow, the noise's 0.94 noise floors).
fn local_curvature(values: &[f64], k: usize) -> f64 {
    let from = k.saturating_sub(LOCAL_WINDOW).max(2);
    let to = (k + LOCAL_WINDOW).min(values.len() - 3);
    let mut sizes: Vec<f64> = (from..=to)
        .filter(|&j| j + 2 < k || j > k + 2)
        .map(|j| (values[j] - cubic_between(&values[j - 2..=j + 2])).abs())
        .collect();
    if sizes.is_empty() {
        return 0.0;
    }
    let mid = sizes.len() / 2;
    *sizes.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
}

/// One line for the report's input checks, if anything was found.
pub fn sentence(glitches: &[Glitch]) -> Option<String> {
    if glitches.is_empty() {
        return None;
    }
    let mut parts: Vec<String> = vec![];
    for kind in [
        GlitchKind::Spike,
        GlitchKind::Repeated,
        GlitchKind::Stuck,
        GlitchKind::Clipped,
        GlitchKind::Gap,
        GlitchKind::RepeatedRow,
    ] {
        let of_kind: Vec<&Glitch> = glitches.iter().filter(|g| g.kind == kind).collect();
        if of_kind.is_empty() {
            continue;
        }
        let mut columns: Vec<&str> = of_kind.iter().map(|g| g.column).collect();
        columns.dedup();
        columns.sort_unstable();
        columns.dedup();
        let samples: usize = of_kind.iter().map(|g| g.samples).sum();
        let what = match kind {
            GlitchKind::Spike => format!("{} spike{}", of_kind.len(), plural(of_kind.len())),
            GlitchKind::Repeated => format!("{samples} repeated sample{}", plural(samples)),
            GlitchKind::Stuck => format!(
                "{} stuck stretch{} ({samples} samples)",
                of_kind.len(),
                plural_es(of_kind.len())
            ),
            GlitchKind::Clipped => {
                format!(
                    "{} clipped stretch{} ({samples} samples)",
                    of_kind.len(),
                    plural_es(of_kind.len())
                )
            }
            GlitchKind::Gap => format!(
                "{} gap{} in time ({samples} sample{} missing)",
                of_kind.len(),
                plural(of_kind.len()),
                plural(samples)
            ),
            GlitchKind::RepeatedRow => format!(
                "{samples} row{} repeating the row before exactly (dropped)",
                plural(samples)
            ),
        };
        let first = of_kind[0].from_s;
        parts.push(format!("{what} in {}, the first at {first:.3} s", columns.join(", ")));
    }
    Some(format!(
        "Glitches in the data: {}. The samples of spikes and of repeated, stuck or clipped stretches are set aside: \
         neither fitted nor scored, and left out of the errors reported; their values are interpolated for the replays \
         and the spectra. They are faults of the recording, never read as a mechanism.",
        parts.join("; ")
    ))
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

fn plural_es(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "es"
    }
}

#[cfg(test)]
#[path = "glitches_tests.rs"]
mod tests;
