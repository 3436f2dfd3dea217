//! The report: the printed summary and the JSON of `jetpipe diagnose --report`.

use crate::fit::intervals::Interval;
use crate::input::recording::StopperPositions;
use crate::policy::MOST_TIED_LOCATIONS;
use crate::replay::errors::Errors;
use crate::verdict::diagnosis::Diagnosis;
use crate::vocabulary::Place;
use jetpipe_model::physics::parameters::Parameters;
use serde_json::json;
use serde_json::Value;

fn parameters_json(values: &[(&'static str, f64)]) -> Value {
    Value::Object(values.iter().map(|(n, v)| (n.to_string(), json!(v))).collect())
}

/// Beside an addition's `parameters`, per amount: `intervals_95` (`[low, high]`),
/// `interval_method` and `interval_heldout_ratio` (the held-out blocks' standard error over the
/// curvature's), each `null` for an amount without an interval.
fn intervals_json(values: &[(&'static str, f64)], intervals: &[Option<Interval>]) -> [(&'static str, Value); 3] {
    let per_amount = |f: &dyn Fn(&Interval) -> Value| {
        Value::Object(
            values
                .iter()
                .enumerate()
                .map(|(k, (n, _))| {
                    (
                        n.to_string(),
                        intervals.get(k).copied().flatten().as_ref().map_or(Value::Null, f),
                    )
                })
                .collect(),
        )
    };
    [
        ("intervals_95", per_amount(&|i| json!([i.low, i.high]))),
        ("interval_method", per_amount(&|i| json!(i.method.as_str()))),
        ("interval_heldout_ratio", per_amount(&|i| json!(i.heldout_ratio))),
    ]
}

/// `object` with `fields` added.
fn with(mut object: Value, fields: impl IntoIterator<Item = (&'static str, Value)>) -> Value {
    if let Some(map) = object.as_object_mut() {
        for (key, value) in fields {
            map.insert(key.to_string(), value);
        }
    }
    object
}

impl Diagnosis {
    /// The summary, opening with the verdict in words.
    pub fn summary(&self) -> Vec<String> {
        let mut lines = vec![];
        let ratio = self.after.heldout_rms / self.noise_floor.max(1e-12);
        let mut names: Vec<&str> = self.effects.iter().map(|e| e.name).collect();
        names.extend(self.discovered.iter().map(|d| d.candidate));
        lines.push(match (&self.unexplained, names.is_empty()) {
            (Some(u), _) if self.force_explained() => format!("Not explained in every channel: {}", u.sentence),
            (None, true) => format!(
                "Explained: the thesis model reproduces the force to within its noise (held-out error {:.4} N, {ratio:.1}× the noise floor {:.4} N); nothing was added.",
                self.after.heldout_rms, self.noise_floor
            ),
            (None, false) if self.effects.is_empty() && self.discovered.iter().all(|d| d.pressures_heldout.is_some()) => {
                format!(
                    "Explained with {}: the pressures now agree with the recording's, and the force stays within its noise (held-out error {:.4} N, {ratio:.1}× the noise floor {:.4} N).",
                    names.join(" and "),
                    self.after.heldout_rms,
                    self.noise_floor
                )
            }
            (None, false) => format!(
                "Explained with {}: the held-out force error falls from {:.4} N to {:.4} N, {ratio:.1}× the noise floor {:.4} N.",
                names.join(" and "),
                self.before.heldout_rms,
                self.after.heldout_rms,
                self.noise_floor
            ),
            (Some(u), _) => format!(
                "Not explained{}: {}",
                if names.is_empty() {
                    String::new()
                } else {
                    format!(" by {} alone", names.join(" and "))
                },
                u.sentence
            ),
        });
        if let Some(s) = &self.pressure_split {
            lines.push(s.sentence.clone());
        }
        if let Some(w) = &self.withdrawn {
            lines.push(format!(
                "Withdrawn: {} lowered the error of the replay the search fits with, but replayed accurately the model with every addition is worse than the starting model (held-out force error {:.4} N against {:.4} N, whole recording {:.4} N against {:.4} N); {}.",
                w.names.join(" and "),
                w.heldout_with,
                self.before.heldout_rms,
                w.whole_with,
                self.before.rms,
                if w.kept.is_empty() {
                    "the model reported is the starting model".to_string()
                } else {
                    format!(
                        "the model reported keeps {} as an earlier round fitted them, no worse than the starting model",
                        w.kept.join(" and ")
                    )
                }
            ));
        }
        lines.extend(self.input_checks.iter().cloned());
        for c in &self.calibrated {
            lines.push(format!(
                "Calibrated {} = {:.4e} (thesis {:.4e}){}",
                c.name,
                c.value,
                c.thesis,
                if c.flags.is_empty() {
                    String::new()
                } else {
                    format!(": {}", c.flags.join("; "))
                }
            ));
        }
        for d in &self.discovered {
            lines.push(match d.pressures_heldout {
                Some((before, after)) => format!(
                    "+ discovered: {} It lowers the held-out pressure errors from {:.0} and {:.0} Pa to {:.0} and {:.0} Pa in the model; the held-out force error is {:.4} N before and {:.4} N after.",
                    d.reading, before[0], before[1], after[0], after[1], d.heldout_before, d.heldout_after
                ),
                None => format!(
                    "+ discovered: {} It lowers the held-out force error from {:.4} N to {:.4} N in the model ({:.1} % of its mean square).",
                    d.reading,
                    d.heldout_before,
                    d.heldout_after,
                    100.0 * d.share
                ),
            });
        }
        for e in &self.effects {
            let values: Vec<String> = e.parameters.iter().map(|(n, v)| format!("{n} = {v:.4e}")).collect();
            lines.push(format!("+ {} ({}): {}", e.name, values.join(", "), e.evidence));
            if !e.remainder_follows.is_empty() {
                lines.push(format!("  what it leaves follows {}", e.remainder_follows));
            }
        }
        if let Some((a, b)) = self.joint_refit {
            lines.push(format!(
                "Refitted together, the added parameters lower the held-out force error from {a:.4} N to {b:.4} N (the values above are the refitted ones)."
            ));
        }
        lines.push(format!(
            "Force RMS error {:.4} N before, {:.4} N after (held-out {:.4} N before, {:.4} N after).",
            self.before.rms, self.after.rms, self.before.heldout_rms, self.after.heldout_rms
        ));
        lines
    }

    pub fn to_json(&self, recording_name: &str) -> Value {
        let err = |e: &Errors| match e.pressure_rms {
            Some(p) => json!({"force_rms_N": e.rms, "force_nrmse": e.nrmse, "pressure_rms_Pa": p.to_vec()}),
            None => json!({"force_rms_N": e.rms, "force_nrmse": e.nrmse}),
        };
        // Every parameter of the final model that is not the thesis's: with these the FMU
        // is the model whose errors the report gives.
        let thesis = Parameters::default();
        let mut start_values = serde_json::Map::new();
        for &value_reference in Parameters::VALUE_REFERENCES {
            let value = self.parameters.get(value_reference);
            if value != thesis.get(value_reference) {
                if let Some(v) = value {
                    start_values.insert(
                        jetpipe_model::physics::parameters::variable_name(value_reference).to_string(),
                        json!(v),
                    );
                }
            }
        }
        // The replays started the chambers where the transducers read them: the FMU starts
        // there too.
        if let Some([p1, p2]) = self.start_pressures {
            start_values.insert("start_at_equilibrium".into(), json!(false));
            start_values.insert("P1_start".into(), json!(p1));
            start_values.insert("P2_start".into(), json!(p2));
        }
        let mut report = json!({
            "recording": recording_name,
            "samples": self.samples,
            "noise_floor_N": self.noise_floor,
            "verdict": self.verdict(),
            "summary": self.summary(),
            "input_checks": self.input_checks,
            "glitches": self.glitches.iter().map(|g| json!({
                "kind": g.kind.as_str(),
                "column": g.column,
                "from_s": g.from_s,
                "to_s": g.to_s,
                "samples": g.samples,
                "set_aside": g.sets_aside(),
            })).collect::<Vec<_>>(),
            "before": err(&self.before),
            "after": err(&self.after),
            "heldout": {
                "before_rms_N": self.before.heldout_rms,
                "after_rms_N": self.after.heldout_rms,
                "settling_s": self.settling,
            },
            "effects": self.effects.iter().map(|e| with(json!({
                "name": e.name,
                "location": e.location,
                "parameters": parameters_json(&e.parameters),
                "heldout_before_rms_N": e.heldout_before,
                "heldout_after_rms_N": e.heldout_after,
                "share_of_heldout_explained": e.share,
                "remainder_follows": e.remainder_follows,
                "tied_effects": e.tied_effects,
                "evidence": e.evidence,
            }), intervals_json(&e.parameters, &e.intervals).into_iter().chain([("margin_noise_floors", json!(e.margin))]))).collect::<Vec<_>>(),
            "discovered": self.discovered.iter().map(|d| with(json!({
                "location": d.location,
                "family": d.family,
                "candidate": d.candidate,
                "origin": d.origin(),
                "parameters": parameters_json(&d.parameters),
                "units": d.parameters.iter().map(|(n, _)| (n.to_string(), json!(crate::candidates::unit_of(n)))).collect::<serde_json::Map<_, _>>(),
                "reading": d.reading,
                "heldout_before_rms_N": d.heldout_before,
                "heldout_after_rms_N": d.heldout_after,
                "share_of_heldout_explained": d.share,
                "pressures_heldout_before_rms_Pa": d.pressures_heldout.map(|(b, _)| b.to_vec()),
                "pressures_heldout_after_rms_Pa": d.pressures_heldout.map(|(_, a)| a.to_vec()),
                "tied_locations": d.tied_locations,
                "flexible": d.flexible.is_some(),
                "flexible_shape": d.flexible.as_ref().and_then(|n| {
                    let shape = crate::candidates::flexible::shape(&d.parameters)?;
                    Some(json!({
                        "adds_to": shape.constant,
                        "unit": shape.unit,
                        "largest": shape.largest,
                        "depends_on": shape.axes.iter().map(|(axis, strength)| json!({
                            "signal": axis.signal.name(),
                            "low_pass_s": axis.lag,
                            "change_along": strength,
                        })).collect::<Vec<_>>(),
                        "heldout_noise_floors": n.flexible_noise_floors,
                        "nearest_readable": n.readable.map(|(label, floors)| json!({
                            "candidate": label,
                            "heldout_noise_floors": floors,
                        })),
                    }))
                }),
            }), intervals_json(&d.parameters, &d.intervals).into_iter().chain([("margin_noise_floors", json!(d.margin))]))).collect::<Vec<_>>(),
            "calibrated": self.calibrated.iter().map(|c| (c.name.to_string(), json!({
                "value": c.value,
                "thesis": c.thesis,
                "relative_shift": if c.thesis != 0.0 { (c.value - c.thesis) / c.thesis.abs() } else { 0.0 },
                "first_half": c.halves_in_time.0,
                "second_half": c.halves_in_time.1,
                "commands_below_median": c.halves_in_command.0,
                "commands_above_median": c.halves_in_command.1,
                "flags": c.flags,
            }))).collect::<serde_json::Map<_, _>>(),
            "candidates": self.candidates.iter().map(|c| json!({
                "candidate": c.fit.candidate.label,
                "origin": c.fit.candidate.origin(),
                "location": c.fit.candidate.location,
                "family": c.fit.candidate.family,
                "named_effect": c.fit.candidate.named,
                "parameters": parameters_json(&c.parameters()),
                "settings": parameters_json(&c.fit.candidate.settings),
                "explained_share_heldout": c.explained,
                "force_heldout_rms_N": c.force_heldout_rms,
            })).collect::<Vec<_>>(),
            "residual_tests": self.residual_tests,
            "fmu_start_values": start_values,
            "stopper_positions": match self.stopper_positions {
                StopperPositions::Smoothed { .. } => "the model was driven with x_s_m smoothed by a quadratic Savitzky-Golay filter over samples k-3..k+3, weights (-2, 3, 6, 7, 6, 3, -2)/21, at each sample whose seven positions leave a sum of squares no larger than stopper_positions_smoothing_residual_limit_m2 about their least-squares quadratic (the recorded positions elsewhere, so at a motion's sharp turns, and at the first and last three samples), as the FMU must be to reproduce these errors, with der(x_s) on to the next sample set before the outputs at a sample are read",
                StopperPositions::AsRecorded => "the model was driven with x_s_m as recorded (sampled every 1.5 ms or slower, where the smoothing applied at faster rates would round the motion's turns), as the FMU must be to reproduce these errors, with der(x_s) on to the next sample set before the outputs at a sample are read",
                StopperPositions::AnsweringTheirRounding { .. } => "the model was driven with x_s_m as recorded (the force answers the positions' rounding, stopper_positions_rounding_correlation: the stopper moved in the steps it was logged in), as the FMU must be to reproduce these errors, with der(x_s) on to the next sample set before the outputs at a sample are read",
            },
            "stopper_positions_smoothed": self.stopper_positions.residual_limit().is_some(),
            "stopper_positions_smoothing_residual_limit_m2": self.stopper_positions.residual_limit(),
            "stopper_positions_rounding_correlation": match self.stopper_positions {
                StopperPositions::AnsweringTheirRounding { correlation } => Some(correlation),
                _ => None,
            },
            "stopper_acceleration_input": (self.acceleration_window > 0.0).then(|| json!({
                "half_width_s": self.acceleration_window,
                "recipe": "the model read the stopper acceleration from its input a_s (stopper_acceleration_input_share = 1): at each sample time t, (x(t + T) - 2 x(t) + x(t - T)) / T^2 with T = half_width_s, x the positions the model was driven with, linear between samples; T shrinks to the time left near either end, and a_s = 0 at the first and last samples. Feed the FMU the same a_s to reproduce these errors",
            })),
            "joint_refit": self.joint_refit.map(|(a, b)| json!({"heldout_before_rms_N": a, "heldout_after_rms_N": b})),
            "withdrawn": self.withdrawn.as_ref().map(|w| json!({
                "names": w.names,
                "heldout_with_rms_N": w.heldout_with,
                "whole_with_rms_N": w.whole_with,
                "kept": w.kept,
            })),
            "replays": self.replays,
            "fast_replay": {
                "step_s": self.fast_replay.step,
                "third_order": self.fast_replay.third_order,
                "force_departure_rms_N": self.fast_replay.force_departure,
                "force_departure_ratio_to_noise": self.fast_replay.force_ratio,
                "pressure_departure_rms_Pa": self.fast_replay.pressure_departure.map(|p| p.to_vec()),
                "agrees": self.fast_replay.agrees,
                "final_force_departure_rms_N": self.fast_replay_final.map(|f| f.0),
                "final_force_departure_ratio_to_noise": self.fast_replay_final.map(|f| f.1),
            },
        });
        let object = report.as_object_mut().expect("a JSON object");
        if let Some(p) = self.pressure_noise {
            object.insert("noise_floor_Pa".into(), json!({"p1": p[0], "p2": p[1]}));
        }
        if let Some(u) = &self.unexplained {
            object.insert(
                "unexplained".into(),
                json!({
                    "rms_N": u.rms,
                    "ratio_to_noise": u.ratio_to_noise,
                    "location": u.location,
                    "family": u.family,
                    "alternatives": u.alternatives,
                    "tied_locations": if u.alternatives.is_empty() || u.location == Place::Unknown {
                        vec![]
                    } else {
                        std::iter::once(u.location).chain(u.alternatives.iter().copied()).take(MOST_TIED_LOCATIONS).collect::<Vec<_>>()
                    },
                    "signature": u.signature.to_json("N"),
                    "sentence": u.sentence,
                    "channel": if self.force_explained() { "pressures" } else { "force" },
                    "margin_noise_floors": self.localization.as_ref().and_then(|l| l.margin(u.location)),
                }),
            );
        }
        object.insert(
            "pressure_split".into(),
            match &self.pressure_split {
                Some(s) => json!({
                    "available": true,
                    "force_vs_pressures_rms_N": s.force_vs_pressures_rms,
                    "force_vs_pressures_ratio_to_noise": s.force_vs_pressures_ratio,
                    "pressures_vs_model_rms_Pa": s.pressure_rms,
                    "pressures_vs_model_ratio_to_noise": s.pressure_ratio,
                    "pressures_vs_model_whole_ratio_to_noise": s.whole_pressure_ratio,
                    "sentence": s.sentence,
                }),
                None => json!({
                    "available": false,
                    "sentence": "Without pressure channels a departure upstream of the piston, in the mechanics and in the force sensor can move the force alike; the location comes from the force alone and is less certain.",
                }),
            },
        );
        if let Some(l) = &self.localization {
            object.insert(
                "localization".into(),
                json!({
                    "location": l.location,
                    "family": l.family,
                    "by_location": l.by_location.iter().map(|(loc, e, label)| json!({
                        "location": loc, "explained_share_heldout": e, "best_candidate": label,
                    })).collect::<Vec<_>>(),
                }),
            );
        }
        report
    }
}
