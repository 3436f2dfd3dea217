//! Replaying a recording's inputs through the model: the command held between samples,
//! the stopper moving linearly between samples (docs/model.md, "CSV formats").

use crate::recording::Recording;
use jetpipe_model::physics::actuator::{Actuator, Outputs};
use jetpipe_model::simulation::{FixedStep, Simulation, StepFailure};

/// The model's outputs at every sample of a recording.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Replay {
    /// The force the bench's sensor would read (`F_meas`).
    pub force: Vec<f64>,
    /// The chamber pressures as the transducers would read them (`P1_meas`, `P2_meas`).
    pub p1: Vec<f64>,
    pub p2: Vec<f64>,
    pub current: Vec<f64>,
    /// Jet pipe tip position relative to its rest position.
    pub x_jp: Vec<f64>,
    /// Work done, for progress and benchmarks.
    pub steps: u64,
}

impl Replay {
    fn with_capacity(n: usize) -> Self {
        Self {
            force: Vec::with_capacity(n),
            p1: Vec::with_capacity(n),
            p2: Vec::with_capacity(n),
            current: Vec::with_capacity(n),
            x_jp: Vec::with_capacity(n),
            steps: 0,
        }
    }

    fn record(&mut self, y: &Outputs) {
        self.force.push(y.f_meas);
        self.p1.push(y.p1_meas);
        self.p2.push(y.p2_meas);
        self.current.push(y.current);
        self.x_jp.push(y.x_jp);
    }
}

/// Simulate `recording` from the equilibrium of its first sample (the bench holds the
/// first command before t = 0). Samples in `0..end` only.
pub fn replay(model: &Actuator, recording: &Recording, tolerance: f64, end: usize) -> Result<Replay, String> {
    let n = end.min(recording.len());
    let mut sim = Simulation::at_equilibrium(
        model.clone(),
        recording.v_da[0],
        recording.x_s[0],
        recording.time[0],
        tolerance,
    )?;
    let mut out = Replay::with_capacity(n);
    for k in 0..n {
        let y = sim.outputs();
        out.record(&y);
        if k + 1 == n {
            break;
        }
        let dt = recording.time[k + 1] - recording.time[k];
        sim.set_command(recording.v_da[k])?;
        sim.set_stopper_rate((recording.x_s[k + 1] - recording.x_s[k]) / dt)?;
        sim.step(dt).map_err(|e| describe(e, k + 1))?;
        // Land exactly on the recorded stopper position (no drift from rounding).
        sim.land_stopper_at(recording.x_s[k + 1]);
    }
    out.steps = sim.statistics().steps;
    Ok(out)
}

/// The longest fixed step of [`replay_fast`] (s): a recording sampled more coarsely than
/// the bench's 1 ms is stepped in equal parts of at most this. One 4 ms ROS2 step per
/// sample at 250 Hz left the pressures 3–8 noise floors off a clean recording that the
/// error-controlled replay reproduces within its noise.
pub const MAX_FAST_STEP: f64 = 1.05e-3;

/// A cheaper replay for fitting: the model's fixed-step simulation ([`FixedStep`]: one ROS2
/// step of the chamber pressures per sample interval, or per equal part of at most
/// [`MAX_FAST_STEP`], the current driver and jet pipe still propagated exactly). No error
/// control: the step (1 ms on the bench) is far below the chambers' time constants, and
/// the accurate replay checks the final figures. Falls back to [`replay`] when the jet pipe
/// has no modal form.
pub fn replay_fast(model: &Actuator, recording: &Recording, end: usize) -> Result<Replay, String> {
    let n = end.min(recording.len());
    let t = &recording.time;
    let mut sim = match FixedStep::at_equilibrium(model.clone(), recording.v_da[0], recording.x_s[0], t[0])? {
        Some(sim) => sim,
        None => return replay(model, recording, 1e-5, end),
    };
    let mut out = Replay::with_capacity(n);
    for k in 0..n {
        out.record(&sim.outputs());
        if k + 1 == n {
            break;
        }
        sim.set_command(recording.v_da[k])?;
        // the stopper moves linearly between samples
        let parts = ((t[k + 1] - t[k]) / MAX_FAST_STEP).ceil().max(1.0) as usize;
        sim.step_to_in_parts(t[k + 1], recording.x_s[k + 1], parts)
            .map_err(|e| describe(e, k + 1))?;
    }
    out.steps = sim.simulation().statistics().steps;
    Ok(out)
}

/// A failed step as the diagnosis reports it, naming the sample it was to reach.
fn describe(failure: StepFailure, sample: usize) -> String {
    match failure {
        StepFailure::InvalidRequest(m) => format!("sample {sample}: {m}"),
        StepFailure::Integration { message, time } => format!("sample {sample} (t = {time} s): {message}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use jetpipe_model::physics::parameters::Parameters;

    /// 3 s at 1 kHz: command steps and a sine, the stopper moving in and out.
    fn protocol() -> Recording {
        let n = 3000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let v_da = time
            .iter()
            .map(|&t| {
                if t < 1.0 {
                    2.0 + 4.0 * (t > 0.3) as i32 as f64
                } else {
                    3.0 * (6.0 * t).sin()
                }
            })
            .collect();
        let x_s = time.iter().map(|&t| 0.054 + 0.01 * (2.0 * t).sin()).collect();
        Recording {
            time,
            v_da,
            x_s,
            force: vec![0.0; n],
            p1: None,
            p2: None,
        }
    }

    fn rms_difference(a: &[f64], b: &[f64]) -> f64 {
        (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    }

    #[test]
    fn the_fast_replay_follows_the_error_controlled_one_with_every_added_term() {
        let recording = protocol();
        let cases: Vec<(&str, Parameters)> = vec![
            ("thesis", Parameters::default()),
            (
                "command lag",
                Parameters {
                    command_lag: 0.02,
                    ..Parameters::default()
                },
            ),
            (
                "command limit",
                Parameters {
                    command_limit: 4.0,
                    ..Parameters::default()
                },
            ),
            (
                "current slew limit",
                Parameters {
                    current_slew_limit: 2.0,
                    ..Parameters::default()
                },
            ),
            (
                "f3 input cubic",
                Parameters {
                    f3_input_cubic: 2.0,
                    ..Parameters::default()
                },
            ),
            (
                "sensor curve and drift",
                Parameters {
                    force_sensor_quadratic: 4e-4,
                    force_sensor_drift: 0.1,
                    ..Parameters::default()
                },
            ),
            (
                "sensor delay",
                Parameters {
                    force_sensor_delay: 4.5e-3,
                    ..Parameters::default()
                },
            ),
            (
                "sensor lag and play",
                Parameters {
                    force_sensor_lag: 0.01,
                    force_sensor_play: 1.0,
                    ..Parameters::default()
                },
            ),
            (
                "sensor pick-up",
                Parameters {
                    force_sensor_ripple_sine: 0.5,
                    force_sensor_ripple_frequency: 7.0,
                    ..Parameters::default()
                },
            ),
            (
                "viscous friction and a position force",
                Parameters {
                    viscous_friction: 20.0,
                    position_force_rate: 100.0,
                    ..Parameters::default()
                },
            ),
            (
                "return vent orifice",
                Parameters {
                    return_vent_area: 0.35e-6,
                    ..Parameters::default()
                },
            ),
            (
                "supply drift and ripple",
                Parameters {
                    supply_drift: -400.0,
                    supply_ripple_sine: 15e3,
                    supply_ripple_frequency: 7.0,
                    ..Parameters::default()
                },
            ),
            (
                "jet pipe null drift",
                Parameters {
                    x_jp_offset_drift: 4e-6,
                    ..Parameters::default()
                },
            ),
        ];
        let thesis_model = Actuator::new(Parameters::default()).unwrap();
        let thesis = replay(&thesis_model, &recording, 1e-6, recording.len()).unwrap();
        let thesis_gap = rms_difference(
            &thesis.force,
            &replay_fast(&thesis_model, &recording, recording.len()).unwrap().force,
        );
        for (name, p) in cases {
            let model = Actuator::new(p).unwrap();
            let accurate = replay(&model, &recording, 1e-6, recording.len()).unwrap();
            let fast = replay_fast(&model, &recording, recording.len()).unwrap();
            let gap = rms_difference(&accurate.force, &fast.force);
            // The fast replay's own error (ROS2 after the 4 V steps) is 0.01 N here: a term
            // must not add to it, which it would if the two paths implemented it apart.
            assert!(
                gap < 0.02,
                "{name}: the fast replay is {gap} N RMS from the accurate one"
            );
            assert!(
                gap <= 1.1 * thesis_gap + 1e-3,
                "{name}: {gap} N against the thesis model's {thesis_gap} N"
            );
            if name != "thesis" {
                let effect = rms_difference(&accurate.force, &thesis.force);
                assert!(
                    effect > 0.1,
                    "{name}: the term changes the force by only {effect} N RMS"
                );
            }
        }
    }
}
