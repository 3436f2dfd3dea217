//! The pressure channels' split of the chain: the measured force against A_p (p1 − p2) of
//! the measured pressures speaks of the mechanics and the force sensor, the measured
//! pressures against the model's of everything upstream of the piston.

use crate::input::blocks::Block;
use crate::input::noise::noise_floor;
use crate::input::recording::Recording;
use crate::policy::EXPLAINED_WITHIN_NOISE;
use crate::replay::signals::{chamber_pressures, difference, rms, rms_kept};
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::sensors::{Channel, SensorLaw};

/// The pressure channels' split of the chain.
#[derive(Clone, Debug)]
pub struct PressureSplit {
    /// RMS of the measured force minus the force the measured pressures give, N, and in
    /// units of its own noise.
    pub force_vs_pressures_rms: f64,
    pub force_vs_pressures_ratio: f64,
    /// RMS of the measured minus the modelled pressures, Pa, and in units of their noise.
    pub pressure_rms: [f64; 2],
    pub pressure_ratio: [f64; 2],
    /// The same over the whole recording, its start included (the report's
    /// `after.pressure_rms_Pa`), in units of their noise. A model whose equilibrium at the
    /// first command is not the recording's shows here and not after the start.
    pub whole_pressure_ratio: [f64; 2],
    pub sentence: String,
}

impl PressureSplit {
    /// Whether each pressure is within its noise both after the start and over the whole
    /// recording: the verdict reads the figures the report gives.
    pub fn pressures_within_noise(&self) -> bool {
        self.pressure_ratio
            .iter()
            .chain(&self.whole_pressure_ratio)
            .all(|r| *r <= EXPLAINED_WITHIN_NOISE)
    }

    /// Whether the pressures are within their noise while the force departs from the force
    /// they give: the departure lies after the pressures, in the mechanics or the force sensor.
    pub fn departure_after_the_pressures(&self) -> bool {
        self.pressures_within_noise() && self.force_vs_pressures_ratio > EXPLAINED_WITHIN_NOISE
    }

    /// The chamber (0 or 1) whose pressure departs most, over either span.
    pub(crate) fn worse_chamber(&self) -> usize {
        let worst = |k: usize| self.pressure_ratio[k].max(self.whole_pressure_ratio[k]);
        if worst(0) >= worst(1) {
            0
        } else {
            1
        }
    }
}

/// Whether a measured pressure departs beyond its noise: as the pressure split says where it
/// could be formed; otherwise (a transducer's static curve, which the split cannot take back)
/// from the whole recording's pressure errors `whole_rms` against their noise floors.
pub(crate) fn pressures_off(
    split: Option<&PressureSplit>,
    pressure_noise: Option<[f64; 2]>,
    whole_rms: Option<[f64; 2]>,
) -> bool {
    match (split, pressure_noise, whole_rms) {
        (Some(split), _, _) => !split.pressures_within_noise(),
        (None, Some(noise), Some(rms)) => (0..2).any(|k| rms[k] > EXPLAINED_WITHIN_NOISE * noise[k]),
        _ => false,
    }
}

/// The pressure channels' split: the force against A_p (p1 − p2), the pressures against
/// the model's.
pub(crate) fn pressure_split(
    model: &Actuator,
    recording: &Recording,
    replay: &Replay,
    noise: f64,
    pressure_noise: [f64; 2],
    blocks: &[Block],
) -> Option<PressureSplit> {
    let (chamber_1, chamber_2) = chamber_pressures(model, recording)?;
    let from_pressures: Vec<f64> = (0..recording.len())
        .map(|k| (model.piston_area * (chamber_1[k] - chamber_2[k])).max(model.spring_force(recording.x_s[k])))
        .collect();
    let (p1, p2) = (recording.p1.as_ref()?, recording.p2.as_ref()?);
    // The pressures taken back through a lagging transducer's law carry its readings' noise
    // times the lag over the sampling interval (the inverse differentiates them): the force
    // they give is as noisy as they are, not as the readings.
    let unread_noise = |chamber: &[f64], readings: &[f64], noise: f64| {
        if chamber == readings {
            noise
        } else {
            noise_floor(chamber).max(noise)
        }
    };
    let chamber_noise = [
        unread_noise(&chamber_1, p1, pressure_noise[0]),
        unread_noise(&chamber_2, p2, pressure_noise[1]),
    ];
    // Over the samples after the start, where the model's starting state has faded.
    let after_start = |x: &[f64]| {
        let kept: Vec<f64> = x
            .iter()
            .zip(blocks)
            .filter(|(_, b)| b.is_used())
            .map(|(v, _)| *v)
            .collect();
        rms(&kept)
    };
    // The force the sensor's law read, taken back through it (an offset and a gain the model
    // has are not a departure of the force from the pressures), with the noise it then carries.
    let force_law = SensorLaw::of(&model.params, Channel::Force);
    let (force, force_noise) = match (!force_law.is_identity())
        .then(|| force_law.unread(&recording.time, &recording.force))
        .flatten()
    {
        Some(force) => {
            let floor = noise_floor(&force).max(noise / force_law.gain.abs().max(1e-12));
            (force, floor)
        }
        None => (recording.force.clone(), noise),
    };
    let mechanical = after_start(&difference(&force, &from_pressures));
    let area = model.piston_area;
    let mechanical_noise =
        (force_noise * force_noise + area * area * (chamber_noise[0].powi(2) + chamber_noise[1].powi(2))).sqrt();
    let pressure_rms = [
        after_start(&difference(p1, &replay.p1)),
        after_start(&difference(p2, &replay.p2)),
    ];
    let pressure_ratio = [
        pressure_rms[0] / pressure_noise[0].max(1e-9),
        pressure_rms[1] / pressure_noise[1].max(1e-9),
    ];
    let whole_pressure_ratio = [
        rms_kept(&difference(p1, &replay.p1), blocks) / pressure_noise[0].max(1e-9),
        rms_kept(&difference(p2, &replay.p2), blocks) / pressure_noise[1].max(1e-9),
    ];
    let ratio = mechanical / mechanical_noise.max(1e-12);
    let pressures_off = pressure_ratio.iter().any(|r| *r > EXPLAINED_WITHIN_NOISE);
    let force_off = ratio > EXPLAINED_WITHIN_NOISE;
    // Where both agree within their noise but the force departs from the model, the pressures
    // are too noisy to place the departure: one of them would move by half the force's
    // departure over A_p, which is within their noise.
    let force_from_model = after_start(&difference(&recording.force, &replay.force)) / noise.max(1e-12);
    let start_off = !pressures_off && whole_pressure_ratio.iter().any(|r| *r > EXPLAINED_WITHIN_NOISE);
    let reading = match (force_off, pressures_off) {
        (false, false) if force_from_model > EXPLAINED_WITHIN_NOISE => {
            "the force departs from the model, by less than the pressures' noise can place on either side of the piston"
        }
        (false, false) => "force, pressures and model agree",
        (false, true) => {
            "the force agrees with the pressures but the pressures depart from the model's: the departure lies upstream of the piston (command to chambers)"
        }
        (true, false) => {
            "the pressures agree with the model but the force does not agree with them: the departure lies in the mechanics or the force sensor"
        }
        (true, true) => {
            "neither the force agrees with the pressures nor the pressures with the model: a pressure sensor error, or departures on both sides of the piston"
        }
    };
    let start = if start_off {
        format!(
            " Over the whole recording, its start included, the pressures differ from the model's by {:.1}× and {:.1}× their noise: the model's state at the first command is not the recording's.",
            whole_pressure_ratio[0], whole_pressure_ratio[1]
        )
    } else {
        String::new()
    };
    Some(PressureSplit {
        force_vs_pressures_rms: mechanical,
        force_vs_pressures_ratio: ratio,
        pressure_rms,
        pressure_ratio,
        whole_pressure_ratio,
        sentence: format!(
            "The measured force differs from A_p (p1 − p2) of the measured pressures by {mechanical:.4} N RMS ({ratio:.1}× its noise) and the pressures differ from the model's by {:.0} and {:.0} Pa RMS ({:.1}× and {:.1}× their noise) after the start: {reading}.{start}",
            pressure_rms[0], pressure_rms[1], pressure_ratio[0], pressure_ratio[1]
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use jetpipe_model::physics::parameters::Parameters;

    /// A recording of 1000 samples at 1 kHz whose pressures are the model's `replay` plus
    /// alternating noise of `noise_pa`, the first `start` samples further off by `start_off` Pa;
    /// the replay's force equals A_p (p1 − p2) of the replay.
    fn recording_and_replay(model: &Actuator, noise_pa: f64, start: usize, start_off: f64) -> (Recording, Replay) {
        let n = 1000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let p1_model: Vec<f64> = time.iter().map(|t| 4.0e5 + 2.0e4 * (20.0 * t).sin()).collect();
        let p2_model: Vec<f64> = time.iter().map(|t| 3.0e5 - 2.0e4 * (20.0 * t).sin()).collect();
        let force: Vec<f64> = (0..n)
            .map(|k| model.piston_area * (p1_model[k] - p2_model[k]))
            .collect();
        let read = |model: &[f64], sign: f64| -> Vec<f64> {
            (0..n)
                .map(|k| {
                    let alternating = if k % 2 == 0 { noise_pa } else { -noise_pa };
                    model[k] + sign * alternating + if k < start { start_off } else { 0.0 }
                })
                .collect()
        };
        let recording = Recording {
            p1: Some(read(&p1_model, 1.0)),
            p2: Some(read(&p2_model, -1.0)),
            ..Recording::of(time, vec![1.0; n], vec![0.054; n], force.clone())
        };
        let replay = Replay {
            force,
            p1: p1_model,
            p2: p2_model,
            ..Replay::default()
        };
        (recording, replay)
    }

    #[test]
    fn without_a_split_a_pressure_off_by_four_noise_floors_over_the_recording_departs() {
        // A chamber 1 transducer's static curve left 793 Pa against a 182 Pa floor.
        let noise = Some([182.0, 173.0]);
        assert!(pressures_off(None, noise, Some([793.0, 197.0])));
        assert!(!pressures_off(None, noise, Some([200.0, 197.0])));
        assert!(!pressures_off(None, None, None));
    }

    #[test]
    fn pressures_off_only_at_the_start_are_not_within_their_noise() {
        let model = Actuator::new(Parameters::default()).unwrap();
        // 300 Pa of noise; the first tenth, the settling, 10 000 Pa off: over the whole
        // recording sqrt(300² + 0.1 × 10 000²) = 3,176 Pa, 10.6× the floor of 300 Pa.
        let (recording, replay) = recording_and_replay(&model, 300.0, 100, 10_000.0);
        let blocks: Vec<Block> = (0..1000)
            .map(|k| if k < 100 { Block::Settling } else { Block::HeldOut })
            .collect();
        let split = pressure_split(&model, &recording, &replay, 0.05, [300.0, 300.0], &blocks).unwrap();
        assert!(
            split.pressure_ratio.iter().all(|r| (r - 1.0).abs() < 0.01),
            "after the start the pressures are at their noise: {:?}",
            split.pressure_ratio
        );
        assert!(
            split.whole_pressure_ratio.iter().all(|r| (r - 10.59).abs() < 0.05),
            "over the whole recording: {:?}",
            split.whole_pressure_ratio
        );
        assert!(!split.pressures_within_noise());
        assert!(
            split.sentence.contains("state at the first command"),
            "{}",
            split.sentence
        );
    }

    #[test]
    fn pressures_at_their_noise_throughout_are_within_it() {
        let model = Actuator::new(Parameters::default()).unwrap();
        let (recording, replay) = recording_and_replay(&model, 300.0, 0, 0.0);
        let blocks: Vec<Block> = (0..1000)
            .map(|k| if k < 100 { Block::Settling } else { Block::Training })
            .collect();
        let split = pressure_split(&model, &recording, &replay, 0.05, [300.0, 300.0], &blocks).unwrap();
        assert!(
            split.pressures_within_noise(),
            "{:?} {:?}",
            split.pressure_ratio,
            split.whole_pressure_ratio
        );
        assert!(
            !split.sentence.contains("state at the first command"),
            "{}",
            split.sentence
        );
        assert!(!split.departure_after_the_pressures(), "the force is A_p (p1 − p2)");
    }

    #[test]
    fn a_force_apart_from_pressures_at_their_noise_places_the_departure_after_them() {
        let model = Actuator::new(Parameters::default()).unwrap();
        let (mut recording, replay) = recording_and_replay(&model, 300.0, 0, 0.0);
        // The force's own noise (0.05 N) and A_p times the pressures' leave a square wave of
        // 1 N that the pressures do not give at 1 N over their combined noise.
        for (k, f) in recording.force.iter_mut().enumerate() {
            *f += if k % 100 < 50 { 1.0 } else { -1.0 };
        }
        let blocks = vec![Block::Training; 1000];
        let split = pressure_split(&model, &recording, &replay, 0.05, [300.0, 300.0], &blocks).unwrap();
        let combined = (0.05f64.powi(2) + 2.0 * (model.piston_area * 300.0).powi(2)).sqrt();
        assert!(
            (split.force_vs_pressures_ratio - 1.0 / combined).abs() < 0.05 * split.force_vs_pressures_ratio,
            "{} against {}",
            split.force_vs_pressures_ratio,
            1.0 / combined
        );
        assert!(split.force_vs_pressures_ratio > 1.5);
        assert!(split.pressures_within_noise());
        assert!(split.departure_after_the_pressures());
    }

    #[test]
    fn pressures_taken_back_through_a_lag_carry_its_amplified_noise_and_place_nothing_after_them() {
        // p1 read through a 10 ms lag at 1 kHz with 300 Pa of pseudo-random noise: its
        // inverse multiplies the noise by about 7, 0.6 N of force over A_p, beside a force
        // noise of 0.05 N. The force is A_p (p1 − p2) of the true pressures.
        let lag = 10e-3;
        let model = Actuator::new(Parameters {
            p1_sensor_lag: lag,
            ..Parameters::default()
        })
        .unwrap();
        let (mut recording, mut replay) = recording_and_replay(&model, 0.0, 0, 0.0);
        let omega = 20.0_f64;
        let (gain, phase) = (1.0 / (1.0 + (omega * lag).powi(2)).sqrt(), (omega * lag).atan());
        let lagged: Vec<f64> = recording
            .time
            .iter()
            .map(|t| 4.0e5 + 2.0e4 * gain * (omega * t - phase).sin())
            .collect();
        let mut state = 7_u64;
        let mut noise = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            300.0 * 3.0_f64.sqrt() * (2.0 * ((state >> 11) as f64 / (1u64 << 53) as f64) - 1.0)
        };
        recording.p1 = Some(lagged.iter().map(|p| p + noise()).collect());
        let p2 = recording.p2.take().unwrap();
        recording.p2 = Some(p2.iter().map(|p| p + noise()).collect());
        replay.p1 = lagged;
        let blocks = vec![Block::Training; 1000];
        let split = pressure_split(&model, &recording, &replay, 0.05, [300.0, 300.0], &blocks).unwrap();
        assert!(split.pressures_within_noise(), "{:?}", split.pressure_ratio);
        assert!(
            split.force_vs_pressures_ratio <= crate::policy::EXPLAINED_WITHIN_NOISE,
            "{} in units of the noise the pressures taken back carry",
            split.force_vs_pressures_ratio
        );
        assert!(!split.departure_after_the_pressures());
    }

    #[test]
    fn a_force_read_through_the_models_sensor_offset_and_gain_agrees_with_the_pressures() {
        let model = Actuator::new(Parameters {
            force_sensor_offset: 0.5,
            force_sensor_gain: 1.03,
            ..Parameters::default()
        })
        .unwrap();
        let (mut recording, replay) = recording_and_replay(&model, 300.0, 0, 0.0);
        for f in recording.force.iter_mut() {
            *f = 0.5 + 1.03 * *f;
        }
        let blocks = vec![Block::Training; 1000];
        let split = pressure_split(&model, &recording, &replay, 0.05, [300.0, 300.0], &blocks).unwrap();
        // The pressures' alternating noise, opposite in the two, is all that is left.
        assert!(
            split.force_vs_pressures_ratio <= crate::policy::EXPLAINED_WITHIN_NOISE,
            "{}",
            split.force_vs_pressures_ratio
        );
        assert!(!split.departure_after_the_pressures());
        // The same readings against a model without the sensor's law depart.
        let plain = Actuator::new(Parameters::default()).unwrap();
        let split = pressure_split(&plain, &recording, &replay, 0.05, [300.0, 300.0], &blocks).unwrap();
        assert!(
            split.force_vs_pressures_ratio > 1.5,
            "{}",
            split.force_vs_pressures_ratio
        );
    }
}
