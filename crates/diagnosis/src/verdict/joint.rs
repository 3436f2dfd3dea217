//! The verdict of a joint diagnosis recording by recording: each recording replayed alone,
//! at its own rate and with its own channels, with the starting model and with the joint one;
//! its noise floors and blocks measured as a diagnosis of it alone would; and which of the
//! additions it holds: taking one out of the joint model raises one of its channels by
//! [`HELD_BY_RECORDING_NOISE_FLOORS`] or more. An addition that not every recording holds
//! is reported as held by the ones that do: the others neither showed it nor contradict it
//! unless taking it out lowers their error, which is reported too.

use crate::candidates::parameter_value;
use crate::candidates::set_parameter;
use crate::context::Context;
use crate::context::Options;
use crate::input::recording::Recording;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::policy::HELD_BY_RECORDING_NOISE_FLOORS;
use crate::replay::errors::errors;
use crate::replay::errors::Errors;
use crate::replay::replay;
use crate::verdict::diagnosis::Diagnosis;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;
use serde_json::json;
use serde_json::Value;

/// One recording of a joint diagnosis, as the joint model meets it.
#[derive(Clone, Debug)]
pub struct RecordingVerdict {
    pub name: String,
    pub samples: usize,
    pub rate_hz: f64,
    /// Whether the joint fit saw it at a lower rate ([`crate::input::joint`]).
    pub resampled: bool,
    pub noise_floor: f64,
    pub pressure_noise: Option<[f64; 2]>,
    /// Seconds at its start neither fitted nor scored (its own starting state).
    pub settling: f64,
    pub glitches: usize,
    pub before: Errors,
    pub after: Errors,
    /// For each addition of the joint model (its name, in the report's order: the named
    /// effects, then the discovered terms), how far its worst channel rises without it, in
    /// its noise floors (negative: it is better without).
    pub without: Vec<(String, f64)>,
}

impl RecordingVerdict {
    /// Within its noise on every channel it has: the force held out, each pressure over the whole.
    pub fn explained(&self) -> bool {
        let force = self.after.heldout_rms <= EXPLAINED_WITHIN_NOISE * self.noise_floor;
        let pressures = match (self.after.pressure_rms, self.pressure_noise) {
            (Some(rms), Some(noise)) => (0..2).all(|c| rms[c] <= EXPLAINED_WITHIN_NOISE * noise[c]),
            _ => true,
        };
        force && pressures
    }

    /// The additions it holds.
    pub fn holds(&self) -> Vec<&str> {
        self.without
            .iter()
            .filter(|(_, rise)| *rise >= HELD_BY_RECORDING_NOISE_FLOORS)
            .map(|(name, _)| name.as_str())
            .collect()
    }

    pub fn to_json(&self) -> Value {
        let err = |e: &Errors| {
            let mut v = json!({"force_rms_N": e.rms, "force_nrmse": e.nrmse, "heldout_force_rms_N": e.heldout_rms});
            if let Some(p) = e.pressure_rms {
                v["pressure_rms_Pa"] = json!(p.to_vec());
            }
            v
        };
        json!({
            "recording": self.name,
            "samples": self.samples,
            "rate_Hz": self.rate_hz,
            "fitted_at_a_lower_rate": self.resampled,
            "noise_floor_N": self.noise_floor,
            "pressure_noise_Pa": self.pressure_noise.map(|p| p.to_vec()),
            "settling_s": self.settling,
            "glitches": self.glitches,
            "before": err(&self.before),
            "after": err(&self.after),
            "heldout_noise_floors": {
                "before": self.before.heldout_rms / self.noise_floor,
                "after": self.after.heldout_rms / self.noise_floor,
            },
            "explained": self.explained(),
            "holds": self.holds(),
            "without_each_addition_noise_floors": self.without.iter().map(|(name, rise)| json!({"addition": name, "rise": rise})).collect::<Vec<_>>(),
        })
    }
}

/// A recording to be judged: its name, its samples with glitches repaired, and the glitches'
/// spans (s, its own time).
pub struct RecordingToJudge {
    pub name: String,
    pub recording: Recording,
    pub glitch_spans: Vec<(f64, f64)>,
    pub glitches: usize,
    pub resampled: bool,
}

/// Each recording replayed with `base` and with the joint model of `diagnosis`.
pub fn judge_each(
    recordings: Vec<RecordingToJudge>,
    base: &Parameters,
    diagnosis: &Diagnosis,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Vec<RecordingVerdict>, String> {
    let additions = additions_of(diagnosis, base);
    let before_model = Actuator::new(base.clone())?;
    let after_model = Actuator::new(diagnosis.parameters.clone())?;
    let mut verdicts = vec![];
    for r in recordings {
        progress(&format!(
            "{}: replayed alone with the starting and the joint model",
            r.name
        ));
        let rate_hz = r.recording.sample_rate();
        let mut own = r.recording.into_stopper_smoothed();
        own.acceleration_window = diagnosis.acceleration_window;
        let mut checks = vec![];
        let mut cx = Context::measure(
            &own,
            &own,
            &before_model,
            options,
            r.glitch_spans,
            &mut checks,
            &mut |_| {},
        )?;
        let mut replays = 0;
        cx.lower_noise_to_departure(&diagnosis.parameters, &mut replays, &mut |_| {})?;
        let n = own.len();
        let score = |model: &Actuator| -> Result<Errors, String> {
            Ok(errors(&replay(model, &own, 1e-5, n)?, &own, &cx.blocks))
        };
        let (before, after) = (score(&before_model)?, score(&after_model)?);
        let worst = |e: &Errors| -> f64 {
            let force = e.heldout_rms / cx.noise;
            match (e.pressure_rms, cx.pressure_noise) {
                (Some(p), Some(noise)) => force.max(p[0] / noise[0]).max(p[1] / noise[1]),
                _ => force,
            }
        };
        let mut without = vec![];
        for (name, params) in &additions {
            let rise = match params {
                Some(params) => worst(&score(&Actuator::new(params.clone())?)?) - worst(&after),
                // Taken out, its parameters leave no valid model: it is held.
                None => f64::INFINITY,
            };
            without.push((name.clone(), rise));
        }
        verdicts.push(RecordingVerdict {
            name: r.name,
            samples: n,
            rate_hz,
            resampled: r.resampled,
            noise_floor: cx.noise,
            pressure_noise: cx.pressure_noise,
            settling: cx.settled_from - own.time[0],
            glitches: r.glitches,
            before,
            after,
            without,
        });
    }
    Ok(verdicts)
}

/// The joint model without each addition (its parameters that no other addition sets back
/// at `start`'s values), by the addition's name; `None` where that is no valid model.
fn additions_of(diagnosis: &Diagnosis, start: &Parameters) -> Vec<(String, Option<Parameters>)> {
    let lists: Vec<(String, &[(&'static str, f64)])> = diagnosis
        .effects
        .iter()
        .map(|e| (e.name.to_string(), e.parameters.as_slice()))
        .chain(
            diagnosis
                .discovered
                .iter()
                .map(|d| (d.candidate.to_string(), d.parameters.as_slice())),
        )
        .collect();
    (0..lists.len())
        .map(|k| {
            let others: Vec<&str> = (0..lists.len())
                .filter(|&j| j != k)
                .flat_map(|j| lists[j].1.iter().map(|(n, _)| *n))
                .collect();
            let mut trial = diagnosis.parameters.clone();
            let mut valid = true;
            for (name, _) in lists[k].1 {
                if !others.contains(name) {
                    valid &= set_parameter(&mut trial, name, parameter_value(start, name)).is_ok();
                }
            }
            if lists[k].0 == "piston_friction" {
                trial.friction_velocity = start.friction_velocity;
            }
            valid &= trial.validate().is_ok();
            (lists[k].0.clone(), valid.then_some(trial))
        })
        .collect()
}

/// Sentences on the additions that not every recording holds, and on any that a recording
/// would be better without.
pub fn sentences(verdicts: &[RecordingVerdict]) -> Vec<String> {
    let Some(first) = verdicts.first() else {
        return vec![];
    };
    let mut lines = vec![];
    for (k, (addition, _)) in first.without.iter().enumerate() {
        let rise = |v: &RecordingVerdict| v.without[k].1;
        let holding: Vec<&RecordingVerdict> = verdicts
            .iter()
            .filter(|v| rise(v) >= HELD_BY_RECORDING_NOISE_FLOORS)
            .collect();
        let others: Vec<&RecordingVerdict> = verdicts
            .iter()
            .filter(|v| rise(v) < HELD_BY_RECORDING_NOISE_FLOORS)
            .collect();
        if others.is_empty() {
            continue;
        }
        let listed = |vs: &[&RecordingVerdict]| {
            vs.iter()
                .map(|v| format!("{} ({:+.2})", v.name, rise(v)))
                .collect::<Vec<_>>()
                .join(", ")
        };
        lines.push(if holding.is_empty() {
            format!(
                "{addition} is held by no recording alone (the rise of each one's worst channel without it, in noise floors: {}): the recordings need it only together, or not at all.",
                listed(&others)
            )
        } else {
            format!(
                "{addition} is held by {} only: without it their worst channel rises by {} noise floors; {} {} not show it ({}), and the joint model carries it for them too.",
                holding.iter().map(|v| v.name.as_str()).collect::<Vec<_>>().join(", "),
                holding.iter().map(|v| format!("{:.2}", rise(v))).collect::<Vec<_>>().join(", "),
                others.iter().map(|v| v.name.as_str()).collect::<Vec<_>>().join(", "),
                if others.len() == 1 { "does" } else { "do" },
                listed(&others)
            )
        });
        for v in &others {
            if rise(v) <= -HELD_BY_RECORDING_NOISE_FLOORS {
                lines.push(format!(
                    "{} would be better without {addition}: its worst channel falls by {:.2} noise floors without it.",
                    v.name,
                    -rise(v)
                ));
            }
        }
    }
    lines
}

/// A joint diagnosis: the diagnosis of the recordings joined into one, and each recording's
/// verdict under the joint model.
pub struct JointDiagnosis {
    pub diagnosis: Diagnosis,
    pub recordings: Vec<RecordingVerdict>,
    /// The recordings as the joint fit saw them (the figures read it).
    pub joined: crate::input::joint::Joined,
    /// What the joining did and which additions not every recording holds, one sentence each.
    pub notes: Vec<String>,
}

impl JointDiagnosis {
    /// The report: a single report's fields for the joint model on the joined recordings
    /// (times in the joined recording's, each recording's offset in `recordings[]`), each
    /// addition's `held_by`, and `recordings[]` with each recording's errors alone.
    pub fn to_json(&self) -> Value {
        let names: Vec<&str> = self.recordings.iter().map(|r| r.name.as_str()).collect();
        let mut report = self.diagnosis.to_json(&names.join(" + "));
        let held_by = |addition: &str| -> Vec<&str> {
            self.recordings
                .iter()
                .filter(|r| r.holds().contains(&addition))
                .map(|r| r.name.as_str())
                .collect()
        };
        for (list, key) in [("effects", "name"), ("discovered", "candidate")] {
            if let Some(entries) = report[list].as_array_mut() {
                for entry in entries {
                    let addition = entry[key].as_str().unwrap_or_default().to_string();
                    entry["held_by"] = json!(held_by(&addition));
                }
            }
        }
        report["recordings"] = Value::Array(
            self.recordings
                .iter()
                .zip(&self.joined.parts)
                .map(|(r, part)| {
                    let mut v = r.to_json();
                    v["offset_in_joint_s"] = json!(part.offset_s);
                    v
                })
                .collect(),
        );
        report["joint"] = json!({
            "recordings": self.recordings.len(),
            "bridges_s": self.joined.bridges.iter().map(|(a, b)| vec![*a, *b]).collect::<Vec<_>>(),
            "notes": self.notes,
        });
        report
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn verdict(name: &str, rises: &[(&str, f64)]) -> RecordingVerdict {
        let errors = Errors {
            rms: 0.1,
            nrmse: 0.01,
            train_rms: 0.1,
            heldout_rms: 0.1,
            pressure_rms: None,
        };
        RecordingVerdict {
            name: name.into(),
            samples: 1000,
            rate_hz: 1000.0,
            resampled: false,
            noise_floor: 0.1,
            pressure_noise: None,
            settling: 0.0,
            glitches: 0,
            before: errors,
            after: errors,
            without: rises.iter().map(|(n, r)| (n.to_string(), *r)).collect(),
        }
    }

    #[test]
    fn an_addition_one_recording_holds_is_reported_as_held_by_it_only_and_one_both_hold_is_not_mentioned() {
        let verdicts = [
            verdict("a.csv", &[("piston_friction", 4.0), ("force_sensor_lag", 2.0)]),
            verdict("b.csv", &[("piston_friction", 0.01), ("force_sensor_lag", 3.0)]),
        ];
        let lines = sentences(&verdicts);
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(
            lines[0].starts_with("piston_friction is held by a.csv only"),
            "{}",
            lines[0]
        );
        assert!(
            lines[0].contains("b.csv does not show it (b.csv (+0.01))"),
            "{}",
            lines[0]
        );
        assert_eq!(verdicts[0].holds(), ["piston_friction", "force_sensor_lag"]);
        assert_eq!(verdicts[1].holds(), ["force_sensor_lag"]);
    }

    #[test]
    fn a_recording_better_without_an_addition_says_so() {
        let verdicts = [
            verdict("a.csv", &[("command_delay", 5.0)]),
            verdict("b.csv", &[("command_delay", -0.4)]),
        ];
        let lines = sentences(&verdicts);
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(lines[1].contains("b.csv would be better without command_delay: its worst channel falls by 0.40"));
    }

    #[test]
    fn within_its_noise_means_the_force_held_out_and_each_pressure_it_has() {
        let mut v = verdict("a.csv", &[]);
        v.after.heldout_rms = 0.15;
        assert!(v.explained());
        v.after.heldout_rms = 0.16;
        assert!(!v.explained());
        v.after.heldout_rms = 0.1;
        v.pressure_noise = Some([100.0, 100.0]);
        v.after.pressure_rms = Some([140.0, 160.0]);
        assert!(!v.explained());
    }
}
