//! The fixed-step replay the fits use, checked against the error-controlled one on each
//! recording before any fit: where the two part (a command that switches at every sample of
//! a slow recording, say), the fits would chase the fixed step's error, so they use the
//! cheapest shorter or third-order stepping that agrees.

use crate::input::lines;
use crate::input::noise;
use crate::input::recording::FastReplayMethod;
use crate::input::recording::Recording;
use crate::policy::MAX_FAST_STEP;
use crate::replay::signals::{difference, rms};
use crate::replay::{replay_fast, Replay};
use jetpipe_model::physics::actuator::Actuator;

/// The largest RMS departure of the fixed-step replay from the error-controlled one, in
/// noise floors of each measured channel, that the fits accept.
pub const AGREEMENT_WITHIN_NOISE: f64 = 0.2;

/// How many times the step may be halved: [`MAX_FAST_STEP`] down to a sixteenth of it.
pub const MOST_HALVINGS: u32 = 4;

/// The outcome of the check: the stepping the fits use and how far that replay departs.
#[derive(Clone, Debug, PartialEq)]
pub struct FastReplayCheck {
    /// The longest step of the fixed-step replay, s.
    pub step: f64,
    /// Whether it steps with ROS34PW2 (order 3) rather than ROS2.
    pub third_order: bool,
    /// RMS of the fixed-step replay's force minus the error-controlled one's, N, and in noise
    /// floors of the force.
    pub force_departure: f64,
    pub force_ratio: f64,
    /// The same for the pressures, Pa and noise floors, when the recording has them.
    pub pressure_departure: Option<[f64; 2]>,
    pub pressure_ratio: Option<[f64; 2]>,
    /// Whether the force's departure is within [`AGREEMENT_WITHIN_NOISE`].
    pub agrees: bool,
}

impl FastReplayCheck {
    /// What the check found, as a sentence for the report; none when the usual stepping (ROS2
    /// at [`MAX_FAST_STEP`]) agrees.
    pub fn sentence(&self) -> Option<String> {
        if self.agrees && self.method() == FastReplayMethod::default() {
            return None;
        }
        let stepping = format!(
            "{}steps of {:.3} ms",
            if self.third_order {
                "third-order (ROS34PW2) "
            } else {
                ""
            },
            1e3 * self.step
        );
        let departure = format!(
            "{:.4} N ({:.2} noise floors){}",
            self.force_departure,
            self.force_ratio,
            self.pressure_ratio.map_or_else(String::new, |r| format!(
                ", pressures {:.2} and {:.2} noise floors",
                r[0], r[1]
            ))
        );
        Some(if self.agrees {
            format!(
                "The fixed-step replay the fits use departed from the error-controlled one with ROS2 steps of {:.2} ms; with {stepping} it departs by {departure}, and the fits use those.",
                1e3 * MAX_FAST_STEP,
            )
        } else {
            format!(
                "The fixed-step replay the fits use departs from the error-controlled one by {departure} even with {stepping}: the fits may follow its error, and the error-controlled replay decides the figures reported.",
            )
        })
    }

    /// The stepping the fits use.
    pub fn method(&self) -> FastReplayMethod {
        FastReplayMethod {
            step: self.step,
            third_order: self.third_order,
        }
    }
}

/// The steppings the check tries, cheapest first: ROS2, then ROS34PW2, at [`MAX_FAST_STEP`]
/// halved up to [`MOST_HALVINGS`] times. A ROS34PW2 step takes five right-hand sides and
/// ROS2's three, with two more for each Jacobian (formed on most steps, where the sample
/// intervals differ in their last bits): about 6.4 against 4.4, so ROS34PW2 at a length
/// comes before ROS2 at half of it.
fn steppings() -> impl Iterator<Item = FastReplayMethod> {
    (0..=MOST_HALVINGS).flat_map(|halvings| {
        [false, true].into_iter().map(move |third_order| FastReplayMethod {
            step: MAX_FAST_STEP / f64::from(1u32 << halvings),
            third_order,
        })
    })
}

/// A channel's noise floor: the lower of the floors of the recorded channel and of its
/// departure from the error-controlled replay (which a fast signal does not lift).
fn floor(recorded: &[f64], modelled: &[f64], sample_rate: f64) -> f64 {
    let of = |x: &[f64]| noise::noise_floor(&lines::without_lines(x, sample_rate, 3));
    of(recorded).min(of(&difference(recorded, modelled)))
}

/// The cheapest stepping (ROS2, then ROS34PW2, at each length from [`MAX_FAST_STEP`] down)
/// with which the fixed-step replay of `model` agrees with `accurate`, its error-controlled
/// replay of the whole `recording`, to within [`AGREEMENT_WITHIN_NOISE`] of the force's noise
/// floor; the shortest third-order one when none does.
pub fn fast_step_that_agrees(
    model: &Actuator,
    recording: &Recording,
    accurate: &Replay,
) -> Result<FastReplayCheck, String> {
    let n = recording.len();
    let sample_rate = recording.sample_rate();
    let force_noise = floor(&recording.force, &accurate.force, sample_rate).max(1e-12);
    let pressure_noise = match (&recording.p1, &recording.p2) {
        (Some(p1), Some(p2)) => Some([
            floor(p1, &accurate.p1, sample_rate).max(1e-12),
            floor(p2, &accurate.p2, sample_rate).max(1e-12),
        ]),
        _ => None,
    };
    let mut trial = recording.clone();
    let mut last = None;
    for method in steppings() {
        trial.fast_replay = method;
        let fast = replay_fast(model, &trial, n)?;
        let force_departure = rms(&difference(&fast.force, &accurate.force));
        let pressure_departure = pressure_noise.map(|_| {
            [
                rms(&difference(&fast.p1, &accurate.p1)),
                rms(&difference(&fast.p2, &accurate.p2)),
            ]
        });
        let force_ratio = force_departure / force_noise;
        let pressure_ratio = pressure_departure
            .zip(pressure_noise)
            .map(|(d, noise)| [d[0] / noise[0], d[1] / noise[1]]);
        // Judged on the force, the channel every recording has and the verdict's first: the
        // pressures' departures are reported beside it. (Halving the step for a 500 Hz
        // staircase whose pressures part by 0.34 noise floors, its force by 0.18, moved a
        // current slew limit's fit from 1.4 to 1.9 force noise floors.)
        let check = FastReplayCheck {
            step: method.step,
            third_order: method.third_order,
            force_departure,
            force_ratio,
            pressure_departure,
            pressure_ratio,
            agrees: force_ratio <= AGREEMENT_WITHIN_NOISE,
        };
        if check.agrees {
            return Ok(check);
        }
        last = Some(check);
    }
    Ok(last.expect("at least one stepping is tried"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::replay::replay;
    use jetpipe_model::physics::parameters::Parameters;

    /// `seconds` at `rate` Hz: a command that jumps between ±8 V at every sample (a
    /// controller's output at a slow rate), the force noise `noise` N, the force the accurate
    /// replay's with that noise added.
    fn switching_recording(model: &Actuator, rate: f64, seconds: f64, noise: f64) -> Recording {
        let n = (rate * seconds) as usize;
        let time: Vec<f64> = (0..n).map(|k| k as f64 / rate).collect();
        let mut state = 12345_u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let v_da: Vec<f64> = (0..n).map(|_| if uniform() < 0.5 { -8.0 } else { 8.0 }).collect();
        let mut recording = Recording {
            x_s: vec![0.054; n],
            force: vec![0.0; n],
            time,
            v_da,
            p1: None,
            p2: None,
            full_rate: None,
            fast_replay: FastReplayMethod::default(),
            acceleration_window: 0.0,
            repeated_rows: vec![],
        };
        let accurate = replay(model, &recording, 1e-7, n).unwrap();
        // Gaussian noise by the sum of twelve uniforms.
        recording.force = accurate
            .force
            .iter()
            .map(|f| f + noise * ((0..12).map(|_| uniform()).sum::<f64>() - 6.0))
            .collect();
        recording
    }

    #[test]
    fn a_slow_recording_of_a_command_switching_at_every_sample_gets_the_cheapest_stepping_that_agrees() {
        let model = Actuator::new(Parameters::default()).unwrap();
        // The usual step departs by about 0.6 N here, far above a fifth of the bench's 0.05 N
        // of noise.
        let recording = switching_recording(&model, 250.0, 8.0, 0.05);
        let accurate = replay(&model, &recording, 1e-7, recording.len()).unwrap();
        let departure = |method: FastReplayMethod| {
            let mut trial = recording.clone();
            trial.fast_replay = method;
            let fast = replay_fast(&model, &trial, trial.len()).unwrap();
            rms(&difference(&fast.force, &accurate.force))
        };
        let usual = departure(FastReplayMethod::default());
        let check = fast_step_that_agrees(&model, &recording, &accurate).unwrap();
        assert!(
            usual > AGREEMENT_WITHIN_NOISE * 0.05,
            "the usual step agrees already ({usual} N): the test shows nothing"
        );
        assert!(check.agrees, "{check:?}");
        assert!(check.step < MAX_FAST_STEP, "{check:?}");
        // The noise floor is estimated from the recording: within a third of the 0.05 N drawn.
        assert!(
            check.force_departure <= AGREEMENT_WITHIN_NOISE * 0.05 * 1.3,
            "{check:?}"
        );
        // Every cheaper stepping departs further than the check accepts.
        let noise_floor = check.force_departure / check.force_ratio;
        let cheaper: Vec<FastReplayMethod> = steppings().take_while(|m| *m != check.method()).collect();
        assert!(cheaper.len() >= 2, "{check:?}");
        for method in cheaper {
            let d = departure(method);
            assert!(
                d > AGREEMENT_WITHIN_NOISE * noise_floor,
                "{method:?} departs by {d} N; {check:?}"
            );
        }
        assert!(check.sentence().unwrap().contains("steps of"));
    }

    #[test]
    fn the_steppings_tried_grow_dearer_one_by_one() {
        // Right-hand sides a sample interval of MAX_FAST_STEP, with a Jacobian (two more) on
        // seven steps in ten: ROS2 4.4 a step, ROS34PW2 6.4.
        let cost = |m: &FastReplayMethod| (MAX_FAST_STEP / m.step) * if m.third_order { 6.4 } else { 4.4 };
        let all: Vec<FastReplayMethod> = steppings().collect();
        assert_eq!(all.len(), 2 * (MOST_HALVINGS as usize + 1));
        assert_eq!(all[0], FastReplayMethod::default());
        for pair in all.windows(2) {
            assert!(cost(&pair[0]) < cost(&pair[1]), "{pair:?}");
        }
    }

    #[test]
    fn a_bench_rate_recording_keeps_the_usual_step() {
        let model = Actuator::new(Parameters::default()).unwrap();
        let mut recording = switching_recording(&model, 1000.0, 8.0, 0.05);
        // A slow command: a staircase of 1 s steps.
        recording.v_da = recording
            .time
            .iter()
            .map(|t| 2.0 + 3.0 * ((t.floor() as i64) % 3) as f64)
            .collect();
        let accurate = replay(&model, &recording, 1e-7, recording.len()).unwrap();
        recording.force = accurate.force.clone();
        let noisy: Vec<f64> = recording
            .force
            .iter()
            .enumerate()
            .map(|(k, f)| f + 0.05 * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5) * 3.46)
            .collect();
        recording.force = noisy;
        let check = fast_step_that_agrees(&model, &recording, &accurate).unwrap();
        assert_eq!(check.method(), FastReplayMethod::default(), "{check:?}");
        assert!(check.agrees && check.sentence().is_none(), "{check:?}");
    }
}
