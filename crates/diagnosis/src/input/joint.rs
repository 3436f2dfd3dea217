//! Several recordings of one actuator as one (`jetpipe diagnose --joint`): the recordings
//! follow each other in time, each joined to the one before it by a bridge whose samples are
//! set aside, so that one model with one set of constants and terms is fitted to all of them.
//!
//! A replay runs through the recordings in turn. Where one ends and the next begins, the
//! bench was stopped and started again: the command jumps and the stopper may stand elsewhere.
//! The bridge plays that change as a bench could (the command held at the next recording's
//! first value, the stopper moved to its first position at [`BRIDGE_STOPPER_SPEED`] at most) and then
//! holds both for [`BRIDGE_HOLD_SECONDS`], so that the model enters the next recording near the
//! equilibrium a replay of it alone would start from. Nothing was measured there: the bridge's
//! readings are the starting model's (put there by `diagnose.rs`), neither fitted, scored nor
//! counted in any error.
//!
//! The recordings may differ in rate: all are brought to the lowest, a faster one sampled at
//! that rate (the command held from the sample before, as the format says it was played; the
//! other channels interpolated linearly, which at a whole ratio is keeping every k-th
//! sample). They may differ in their channels: the pressures are fitted only when every
//! recording has them. Each recording's own errors, at its own rate and with its own
//! channels, are taken again once the joint model is found (`crate::verdict::joint`).

use crate::input::recording::Recording;
use crate::policy::BRIDGE_HOLD_SECONDS;
use crate::policy::BRIDGE_STOPPER_SPEED;
use crate::policy::SAME_RATE_WITHIN;

/// One recording's place in the joined one.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub name: String,
    /// Its samples in the joined recording.
    pub rows: std::ops::Range<usize>,
    /// Joined time = the recording's own time + this (s).
    pub offset_s: f64,
    /// Its own sampling rate (Hz).
    pub rate_hz: f64,
    /// Whether it was sampled at the joined recording's lower rate.
    pub resampled: bool,
}

/// Recordings joined into one.
#[derive(Clone, Debug)]
pub struct Joined {
    pub recording: Recording,
    pub parts: Vec<Part>,
    /// The bridges' spans (s, inclusive, joined time): set aside.
    pub bridges: Vec<(f64, f64)>,
    /// What the joining did that changes what is fitted, one sentence each.
    pub notes: Vec<String>,
}

/// Join `recordings` (name and recording, glitches already repaired) in the order given.
pub fn join(recordings: &[(String, Recording)]) -> Result<Joined, String> {
    if recordings.len() < 2 {
        return Err(format!(
            "--joint needs two or more recordings of one actuator, got {}",
            recordings.len()
        ));
    }
    for (name, r) in recordings {
        if r.len() < 2 {
            return Err(format!("{name}: {} samples, too few to join (at least 2)", r.len()));
        }
    }
    let rates: Vec<f64> = recordings.iter().map(|(_, r)| r.sample_rate()).collect();
    let rate = rates.iter().copied().fold(f64::INFINITY, f64::min);
    let dt = 1.0 / rate;
    let with_pressures = recordings.iter().all(|(_, r)| r.p1.is_some() && r.p2.is_some());
    let mut notes = vec![];
    if !with_pressures && recordings.iter().any(|(_, r)| r.p1.is_some()) {
        let without: Vec<&str> = recordings
            .iter()
            .filter(|(_, r)| r.p1.is_none() || r.p2.is_none())
            .map(|(n, _)| n.as_str())
            .collect();
        notes.push(format!(
            "The pressures are not fitted: {} {} none. Each recording's pressure errors are still given with its own.",
            without.join(", "),
            if without.len() == 1 { "has" } else { "have" }
        ));
    }
    let mut joined = Recording {
        time: vec![],
        v_da: vec![],
        x_s: vec![],
        force: vec![],
        p1: with_pressures.then(Vec::new),
        p2: with_pressures.then(Vec::new),
        full_rate: None,
        fast_replay: Default::default(),
        acceleration_window: 0.0,
        repeated_rows: vec![],
    };
    let (mut parts, mut bridges) = (vec![], vec![]);
    for ((name, own), &own_rate) in recordings.iter().zip(&rates) {
        let resampled = own_rate > rate * (1.0 + SAME_RATE_WITHIN);
        let part = if resampled {
            notes.push(format!(
                "{name} ({own_rate:.0} Hz) is fitted at {rate:.0} Hz, the lowest of the recordings' rates; its own errors are given at its own rate."
            ));
            at_rate(own, rate)
        } else {
            own.clone()
        };
        let offset = match joined.time.last() {
            None => 0.0,
            Some(&end) => {
                let from = end + dt;
                let to = bridge(&mut joined, &part, dt);
                bridges.push((from, to));
                to + dt - part.time[0]
            }
        };
        let first = joined.len();
        joined.time.extend(part.time.iter().map(|t| t + offset));
        joined.v_da.extend_from_slice(&part.v_da);
        joined.x_s.extend_from_slice(&part.x_s);
        joined.force.extend_from_slice(&part.force);
        if let (Some(p1), Some(p2), Some(q1), Some(q2)) = (joined.p1.as_mut(), joined.p2.as_mut(), &part.p1, &part.p2) {
            p1.extend_from_slice(q1);
            p2.extend_from_slice(q2);
        }
        parts.push(Part {
            name: name.clone(),
            rows: first..joined.len(),
            offset_s: offset,
            rate_hz: own_rate,
            resampled,
        });
    }
    Ok(Joined {
        recording: joined,
        parts,
        bridges,
        notes,
    })
}

/// Append the bridge from the joined recording's last sample to `next`'s first; returns
/// the bridge's last time. Its readings are a straight line from the one recording's to the
/// other's, until the diagnosis puts the starting model's there
/// (`diagnose.rs`, which may replay: this stage comes before the replays).
fn bridge(joined: &mut Recording, next: &Recording, dt: f64) -> f64 {
    let last = joined.len() - 1;
    let (t_end, x_from, x_to) = (joined.time[last], joined.x_s[last], next.x_s[0]);
    // A half-cosine of the velocity, its peak the bridge's speed: no jump of the acceleration
    // that a force on the stopper's motion would answer.
    let travel = std::f64::consts::FRAC_PI_2 * (x_to - x_from).abs() / BRIDGE_STOPPER_SPEED;
    let samples = ((travel + BRIDGE_HOLD_SECONDS) / dt).ceil() as usize;
    let line = |from: f64, to: f64, k: usize| from + (to - from) * k as f64 / (samples + 1) as f64;
    let moved = |k: usize| {
        let t = k as f64 * dt;
        if t >= travel {
            x_to
        } else {
            x_from + (x_to - x_from) * 0.5 * (1.0 - (std::f64::consts::PI * t / travel).cos())
        }
    };
    let force_from = joined.force[last];
    let pressures_from = joined
        .p1
        .as_ref()
        .zip(joined.p2.as_ref())
        .map(|(a, b)| (a[last], b[last]));
    for k in 1..=samples {
        joined.time.push(t_end + k as f64 * dt);
        joined.v_da.push(next.v_da[0]);
        joined.x_s.push(moved(k));
        joined.force.push(line(force_from, next.force[0], k));
        if let (Some((a, b)), Some(p1), Some(p2), Some(q1), Some(q2)) = (
            pressures_from,
            joined.p1.as_mut(),
            joined.p2.as_mut(),
            &next.p1,
            &next.p2,
        ) {
            p1.push(line(a, q1[0], k));
            p2.push(line(b, q2[0], k));
        }
    }
    t_end + samples as f64 * dt
}

/// The mean over `from..to` of `r`'s command as played: each sample's held until the next
/// (the last one's from there on).
fn held_mean(r: &Recording, from: f64, to: f64) -> f64 {
    let first = r.time.partition_point(|&s| s <= from).max(1) - 1;
    let (mut sum, mut k) = (0.0, first);
    while k < r.len() && r.time[k] < to {
        let start = r.time[k].max(from);
        let end = r.time.get(k + 1).map_or(to, |&next| next.min(to));
        sum += r.v_da[k] * (end - start).max(0.0);
        k += 1;
    }
    sum / (to - from)
}

/// `r` sampled at `rate` from its first sample: the measured channels and the stopper
/// interpolated linearly (at a whole ratio, every k-th sample), the command held over each
/// new interval at its mean as played there. Taking the sample at the interval's start
/// instead would delay the command by half the difference of the two intervals, which a
/// multisine sampled at 2 kHz and replayed at 1 kHz shows as a jet pipe faster by half.
fn at_rate(r: &Recording, rate: f64) -> Recording {
    let (t0, t_end) = (r.time[0], r.time[r.len() - 1]);
    let n = ((t_end - t0) * rate + 1e-9).floor() as usize + 1;
    let times: Vec<f64> = (0..n).map(|k| t0 + k as f64 / rate).collect();
    let at = |t: f64| -> (usize, f64) {
        let k = r.time.partition_point(|&s| s <= t).clamp(1, r.len() - 1) - 1;
        let span = r.time[k + 1] - r.time[k];
        (
            k,
            if span > 0.0 {
                ((t - r.time[k]) / span).clamp(0.0, 1.0)
            } else {
                0.0
            },
        )
    };
    let positions: Vec<(usize, f64)> = times.iter().map(|&t| at(t)).collect();
    let linear = |x: &[f64]| -> Vec<f64> {
        positions
            .iter()
            .map(|&(k, w)| if w == 0.0 { x[k] } else { x[k] + (x[k + 1] - x[k]) * w })
            .collect()
    };
    Recording {
        v_da: times.iter().map(|&t| held_mean(r, t, t + 1.0 / rate)).collect(),
        x_s: linear(&r.x_s),
        force: linear(&r.force),
        p1: r.p1.as_deref().map(linear),
        p2: r.p2.as_deref().map(linear),
        time: times,
        full_rate: None,
        fast_replay: Default::default(),
        acceleration_window: 0.0,
        repeated_rows: vec![],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recording(t0: f64, rate: f64, n: usize, x_s: f64, force: impl Fn(f64) -> f64) -> Recording {
        let time: Vec<f64> = (0..n).map(|k| t0 + k as f64 / rate).collect();
        let f = time.iter().map(|&t| force(t)).collect();
        let v = time.iter().map(|&t| if t - t0 < 0.5 { 1.0 } else { -2.0 }).collect();
        Recording::of(time, v, vec![x_s; n], f)
    }

    #[test]
    fn two_recordings_follow_each_other_with_a_bridge_that_moves_the_stopper_no_faster_than_a_bench_and_keep_their_samples(
    ) {
        let a = recording(0.0, 1000.0, 1001, 0.05, |t| t);
        let b = recording(3.0, 1000.0, 501, 0.08, |t| 10.0 + t);
        let joined = join(&[("a".into(), a.clone()), ("b".into(), b.clone())]).unwrap();
        let r = &joined.recording;
        let [pa, pb] = [&joined.parts[0], &joined.parts[1]];
        assert_eq!(pa.rows, 0..1001);
        assert_eq!(pb.rows.len(), 501);
        assert_eq!(&r.force[pb.rows.clone()], &b.force[..]);
        assert_eq!(&r.v_da[pb.rows.clone()], &b.v_da[..]);
        for (k, row) in pb.rows.clone().enumerate() {
            assert!((r.time[row] - (b.time[k] + pb.offset_s)).abs() < 1e-12);
        }
        // The bridge: 30 mm at the bench's speed at most (a half-cosine of the velocity), then
        // held; its span is set aside, and it lies between the two recordings.
        let (from, to) = joined.bridges[0];
        assert!((from - 1.001).abs() < 1e-9, "{from}");
        let length = to - from;
        let expected = std::f64::consts::FRAC_PI_2 * 0.03 / BRIDGE_STOPPER_SPEED + BRIDGE_HOLD_SECONDS;
        assert!((length - expected).abs() < 2e-3, "{length} against {expected}");
        assert!(r.time[pb.rows.start] > to && r.time[pa.rows.end - 1] < from);
        for k in 1..r.len() {
            assert!(r.time[k] > r.time[k - 1]);
            let speed = (r.x_s[k] - r.x_s[k - 1]).abs() / (r.time[k] - r.time[k - 1]);
            assert!(speed <= BRIDGE_STOPPER_SPEED * 1.001, "{speed} m/s at {}", r.time[k]);
        }
        assert!(joined.notes.is_empty());
    }

    #[test]
    fn a_faster_recording_is_brought_to_the_slower_rate_by_keeping_every_kth_sample_and_says_so() {
        let a = recording(0.0, 250.0, 251, 0.05, |t| t);
        let b = recording(0.0, 1000.0, 1001, 0.05, |t| (7.0 * t).sin());
        let joined = join(&[("slow".into(), a), ("fast".into(), b.clone())]).unwrap();
        let part = &joined.parts[1];
        assert!(part.resampled && !joined.parts[0].resampled);
        assert_eq!(part.rows.len(), 251);
        let kept = &joined.recording.force[part.rows.clone()];
        for (k, &f) in kept.iter().enumerate() {
            assert!(
                (f - b.force[4 * k]).abs() < 1e-9,
                "sample {k}: {f} against {}",
                b.force[4 * k]
            );
        }
        // The command switches at 0.5 s in both, on an interval's edge: its levels are kept.
        let commands = &joined.recording.v_da[part.rows.clone()];
        assert!(commands.iter().all(|&v| v == 1.0 || v == -2.0), "{commands:?}");
        assert_eq!(joined.notes.len(), 1);
        assert!(
            joined.notes[0].contains("fast (1000 Hz) is fitted at 250 Hz"),
            "{}",
            joined.notes[0]
        );
    }

    #[test]
    fn a_command_ramp_brought_to_a_lower_rate_is_held_at_its_mean_over_each_new_interval() {
        let time: Vec<f64> = (0..=400).map(|k| k as f64 / 1000.0).collect();
        let ramp: Vec<f64> = time.iter().map(|t| 10.0 * t).collect();
        let fine = Recording::of(time.clone(), ramp, vec![0.05; 401], vec![0.0; 401]);
        let coarse = at_rate(&fine, 250.0);
        assert_eq!(coarse.len(), 101);
        // The fine samples 4j..4j+3 held over 1 ms each: their mean, 10 × (4j + 1.5) ms.
        for (j, &v) in coarse.v_da.iter().enumerate().take(100) {
            let expected = 10.0 * (4.0 * j as f64 + 1.5) / 1000.0;
            assert!((v - expected).abs() < 1e-9, "interval {j}: {v} against {expected}");
        }
    }

    #[test]
    fn the_pressures_are_dropped_with_a_note_naming_the_recording_without_them() {
        let mut a = recording(0.0, 1000.0, 101, 0.05, |t| t);
        a.p1 = Some(vec![1e5; 101]);
        a.p2 = Some(vec![2e5; 101]);
        let b = recording(0.0, 1000.0, 101, 0.05, |t| t);
        let joined = join(&[("with.csv".into(), a), ("without.csv".into(), b)]).unwrap();
        assert!(joined.recording.p1.is_none() && joined.recording.p2.is_none());
        assert!(joined.notes[0].contains("without.csv has none"), "{}", joined.notes[0]);
    }

    #[test]
    fn one_recording_is_not_a_joint_diagnosis() {
        let a = recording(0.0, 1000.0, 101, 0.05, |t| t);
        let error = join(&[("a".into(), a)]).unwrap_err();
        assert!(error.contains("two or more recordings"), "{error}");
    }
}
