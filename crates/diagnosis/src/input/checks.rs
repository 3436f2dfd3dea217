//! Doubts about the recording itself: units, length, sampling. A doubt that would make
//! every figure of the diagnosis wrong (a force column in kN, a time column in ms) refuses
//! the file with a message that names the column and the likely unit; a lesser one goes on
//! with a sentence in the report's `input_checks` and in the summary.

use crate::input::recording::Recording;
use jetpipe_model::physics::parameters::Parameters;

use crate::policy::BLOCK_SECONDS;

/// Fewer held-out blocks than this, and no held-out score means anything.
pub const MIN_BLOCKS: f64 = 4.0;
/// Below this many blocks the scores are given with a warning.
const FEW_BLOCKS: f64 = 8.0;

fn median(values: &mut [f64]) -> f64 {
    let mid = values.len() / 2;
    *values.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
}

fn quantile(values: &[f64], q: f64) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(|a, b| a.total_cmp(b));
    sorted[((sorted.len() - 1) as f64 * q).round() as usize]
}

/// Checks that need only the file: sampling, length, the ranges of the columns.
pub fn check_file(recording: &Recording, params: &Parameters) -> Result<Vec<String>, String> {
    let mut doubts = vec![];
    let t = &recording.time;
    let n = recording.len();
    let span = t[n - 1] - t[0];
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let step = median(&mut steps.clone());
    if step > 0.05 {
        let as_ms = step / 1000.0;
        return Err(if (1e-4..=0.05).contains(&as_ms) {
            format!(
                "column time_s: samples are {step} apart and the recording spans {span}: these look like milliseconds \
                 (a recording in seconds at {:.0} Hz would step by {as_ms} s); give the time in seconds",
                1.0 / as_ms
            )
        } else {
            format!(
                "column time_s: samples are {step} s apart (median): too coarse for the actuator, whose pressures \
                 settle within about 0.1 s; the diagnosis needs at most 0.05 s between samples"
            )
        });
    }
    let needed = MIN_BLOCKS * BLOCK_SECONDS;
    if span < needed || n < 200 {
        return Err(format!(
            "the recording spans {span:.3} s in {n} samples: the diagnosis fits on alternate {BLOCK_SECONDS} s blocks \
             and scores on the others, so it needs at least {needed} s and 200 samples"
        ));
    }
    if span < FEW_BLOCKS * BLOCK_SECONDS {
        doubts.push(format!(
            "The recording spans {span:.1} s, only {:.0} blocks of {BLOCK_SECONDS} s: the held-out scores rest on few blocks.",
            (span / BLOCK_SECONDS).floor()
        ));
    }
    steps.sort_by(|a, b| a.total_cmp(b));
    let irregular = steps.iter().filter(|s| (**s - step).abs() > 0.01 * step).count();
    if irregular > 0 {
        doubts.push(format!(
            "Sampling is irregular: {irregular} of {} steps differ from the median step {step:.6} s by more than 1 % \
             (shortest {:.6} s, longest {:.6} s). The command is held and the stopper interpolated across each step as \
             the format says; the noise floor assumes regular sampling and is less certain.",
            n - 1,
            steps[0],
            steps[steps.len() - 1]
        ));
    }
    let biggest_force = recording.force.iter().fold(0f64, |m, f| m.max(f.abs()));
    let rated = params.cylinder().piston_area() * (params.p_s - params.p_r);
    if biggest_force > 20.0 * rated {
        return Err(format!(
            "column force_N: values reach {biggest_force:.4e}, but the actuator gives at most about {rated:.0} N \
             (piston area times supply minus return pressure): is the column in millinewtons? Give newtons"
        ));
    }
    let biggest_command = recording.v_da.iter().fold(0f64, |m, v| m.max(v.abs()));
    if biggest_command > 100.0 {
        return Err(format!(
            "column v_da_V: values reach {biggest_command}, far beyond a ±10 V D/A: is the column in millivolts? Give volts"
        ));
    }
    if biggest_command > 10.5 {
        doubts.push(format!(
            "The command reaches {biggest_command:.2} V, beyond the ±10 V of the thesis's D/A; the model takes it as given."
        ));
    }
    if let (Some(p1), Some(p2)) = (&recording.p1, &recording.p2) {
        for (name, p) in [("p1_Pa", p1), ("p2_Pa", p2)] {
            let typical = median(&mut p.clone());
            if typical < 2000.0 {
                let unit = if typical < 1.5 {
                    "MPa"
                } else if typical < 15.0 {
                    "bar"
                } else if typical < 120.0 {
                    "psi"
                } else {
                    "kPa"
                };
                return Err(format!(
                    "column {name}: a typical value is {typical}, but chamber pressures lie between the return \
                     ({} Pa) and the supply ({} Pa): the column looks like {unit}; give absolute pascals",
                    params.p_r, params.p_s
                ));
            }
            let low = quantile(p, 0.05);
            if low < 0.5 * params.p_r {
                return Err(format!(
                    "column {name}: 5 % of the samples are below {low:.0} Pa, under half the return pressure {} Pa, \
                     which chambers venting to it do not reach: the column looks like gauge pressure; give absolute \
                     pressure (add the atmospheric pressure)",
                    params.p_r
                ));
            }
            let high = quantile(p, 0.99);
            if high > 1.2 * params.p_s {
                doubts.push(format!(
                    "Column {name} reaches {high:.0} Pa, above the supply pressure P_s = {} Pa that should bound it: \
                     a different supply, or a transducer gain error.",
                    params.p_s
                ));
            }
        }
    } else {
        doubts.push(
            "The recording has no pressure channels: a departure upstream of the chambers, in the mechanics and in the \
             force sensor can shift the force alike, and where the model departs is told from the force alone."
                .to_string(),
        );
    }
    Ok(doubts)
}

/// Checks against the thesis model's replay of the recording's inputs: a force or
/// pressure column off by a unit factor or by the atmosphere.
pub fn check_against_model(
    recording: &Recording,
    model_force: &[f64],
    model_pressures: Option<(&[f64], &[f64])>,
    params: &Parameters,
) -> Result<Vec<String>, String> {
    let mut doubts = vec![];
    let spread = |x: &[f64]| quantile(x, 0.95) - quantile(x, 0.05);
    let (measured, modelled) = (spread(&recording.force), spread(model_force));
    if modelled > 5.0 {
        let ratio = measured / modelled;
        if ratio < 0.02 {
            return Err(format!(
                "column force_N: the recorded force spans {measured:.4} (5th to 95th percentile) where the model, \
                 driven by the same inputs, spans {modelled:.1} N: the column looks like kilonewtons; give newtons"
            ));
        }
        if ratio > 50.0 {
            return Err(format!(
                "column force_N: the recorded force spans {measured:.1} (5th to 95th percentile) where the model, \
                 driven by the same inputs, spans {modelled:.1} N: the column looks like millinewtons; give newtons"
            ));
        }
        if !(0.5..=2.0).contains(&ratio) {
            doubts.push(format!(
                "The recorded force spans {ratio:.2} times the model's for the same inputs: a sensor gain or unit \
                 problem, or an actuator far from the thesis's."
            ));
        }
    }
    if let (Some((m1, m2)), Some(p1), Some(p2)) = (model_pressures, &recording.p1, &recording.p2) {
        let mean_offset = |p: &[f64], m: &[f64]| p.iter().zip(m).map(|(a, b)| a - b).sum::<f64>() / p.len() as f64;
        let offsets = [mean_offset(p1, m1), mean_offset(p2, m2)];
        if offsets.iter().all(|o| (o + params.p_r).abs() < 0.3 * params.p_r) {
            return Err(format!(
                "columns p1_Pa and p2_Pa: they lie {:.0} and {:.0} Pa below the model's on average, about one \
                 atmosphere: they look like gauge pressures; give absolute pressure",
                -offsets[0], -offsets[1]
            ));
        }
    }
    Ok(doubts)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn recording(step: f64, n: usize, force: impl Fn(f64) -> f64, pressures: Option<(f64, f64)>) -> Recording {
        let time: Vec<f64> = (0..n).map(|k| k as f64 * step).collect();
        Recording {
            p1: pressures.map(|(a, _)| vec![a; n]),
            p2: pressures.map(|(_, b)| vec![b; n]),
            ..Recording::of(
                time.clone(),
                vec![2.5; n],
                vec![0.054; n],
                time.iter().map(|&t| force(t)).collect(),
            )
        }
    }

    fn refusal(r: &Recording) -> String {
        check_file(r, &Parameters::default()).unwrap_err()
    }

    #[test]
    fn a_time_column_in_milliseconds_is_refused_by_name() {
        let e = refusal(&recording(1.0, 20_000, |_| 40.0, None));
        assert!(e.contains("time_s") && e.contains("milliseconds"), "{e}");
    }

    #[test]
    fn a_recording_too_short_to_hold_blocks_out_is_refused() {
        let e = refusal(&recording(1e-3, 10, |_| 40.0, None));
        assert!(e.contains("at least 8 s"), "{e}");
        let e = refusal(&recording(1e-3, 7_000, |_| 40.0, None));
        assert!(e.contains("7.0") || e.contains("6.999"), "{e}");
    }

    #[test]
    fn pressures_in_kpa_or_gauge_are_refused_with_the_likely_unit() {
        let e = refusal(&recording(1e-3, 20_000, |_| 40.0, Some((400.0, 200.0))));
        assert!(e.contains("p1_Pa") && e.contains("kPa"), "{e}");
        let e = refusal(&recording(1e-3, 20_000, |_| 40.0, Some((3e5, 20_000.0))));
        assert!(e.contains("p2_Pa") && e.contains("gauge"), "{e}");
    }

    #[test]
    fn a_force_in_millinewtons_is_refused() {
        let e = refusal(&recording(1e-3, 20_000, |t| 40_000.0 + 1000.0 * t, None));
        assert!(e.contains("force_N") && e.contains("millinewtons"), "{e}");
    }

    #[test]
    fn force_units_are_judged_against_the_model() {
        let r = recording(1e-3, 20_000, |t| 0.001 * (10.0 + 5.0 * t), None);
        let model: Vec<f64> = r.time.iter().map(|t| 10.0 + 5.0 * t).collect();
        let e = check_against_model(&r, &model, None, &Parameters::default()).unwrap_err();
        assert!(e.contains("kilonewtons"), "{e}");
        let fine = recording(1e-3, 20_000, |t| 10.0 + 5.0 * t, None);
        assert!(check_against_model(&fine, &model, None, &Parameters::default())
            .unwrap()
            .is_empty());
    }

    #[test]
    fn irregular_sampling_and_missing_pressures_are_said() {
        let mut r = recording(1e-3, 20_000, |_| 40.0, None);
        for t in r.time.iter_mut().skip(10_000) {
            *t += 0.0105;
        }
        let doubts = check_file(&r, &Parameters::default()).unwrap();
        assert!(doubts.iter().any(|d| d.contains("irregular")), "{doubts:?}");
        assert!(doubts.iter().any(|d| d.contains("no pressure channels")), "{doubts:?}");
    }
}
