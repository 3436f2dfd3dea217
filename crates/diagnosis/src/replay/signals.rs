//! The recording's channels and the model's, sample by sample: the residuals the
//! diagnosis works on and the signals along the chain that a residual may follow.

use crate::input::blocks::Block;
use crate::input::recording::Recording;
use crate::input::stopper_motion::stopper_velocity;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::sensors::{Channel, SensorLaw};

/// Channels compared with the model: the force always, the two chamber pressures when the
/// recording has them.
pub const FORCE: usize = 0;
pub const P1: usize = 1;
pub const P2: usize = 2;
pub const CHANNELS: usize = 3;
pub const CHANNEL_NAMES: [&str; CHANNELS] = ["force", "p1", "p2"];

/// Centred difference quotient over ±`half` samples.
pub fn rate(time: &[f64], x: &[f64], half: usize) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(half), (k + half).min(n - 1));
            if b > a {
                (x[b] - x[a]) / (time[b] - time[a])
            } else {
                0.0
            }
        })
        .collect()
}

/// Direction of the command since its last reversal (+1 rising, −1 falling); a 50 mV
/// dead band ignores noise and D/A steps.
pub fn command_direction(v_da: &[f64]) -> Vec<f64> {
    let (mut direction, mut extreme) = (0.0, v_da.first().copied().unwrap_or(0.0));
    v_da.iter()
        .map(|&v| {
            if direction >= 0.0 && v > extreme || direction < 0.0 && v < extreme {
                extreme = v;
            }
            if direction >= 0.0 && v < extreme - 0.05 {
                direction = -1.0;
                extreme = v;
            } else if direction <= 0.0 && v > extreme + 0.05 {
                direction = 1.0;
                extreme = v;
            }
            direction
        })
        .collect()
}

/// The force the measured pressures give through the piston, with the spring floor
/// (2.36)–(2.38): what the force sensor should read if the mechanics are the thesis's.
pub fn force_from_pressures(model: &Actuator, recording: &Recording) -> Option<Vec<f64>> {
    let (p1, p2) = chamber_pressures(model, recording)?;
    Some(
        (0..recording.len())
            .map(|k| (model.piston_area * (p1[k] - p2[k])).max(model.spring_force(recording.x_s[k])))
            .collect(),
    )
}

/// The chamber pressures that gave the recording's pressure readings, through the model's
/// transducer laws (the readings themselves while those are off); `None` without pressure
/// channels, or where a law has no inverse.
pub fn chamber_pressures(model: &Actuator, recording: &Recording) -> Option<(Vec<f64>, Vec<f64>)> {
    let (p1, p2) = (recording.p1.as_ref()?, recording.p2.as_ref()?);
    let back = |channel: Channel, readings: &Vec<f64>| {
        let law = SensorLaw::of(&model.params, channel);
        if law.is_identity() {
            Some(readings.clone())
        } else {
            law.unread(&recording.time, readings)
        }
    };
    Some((back(Channel::Pressure1, p1)?, back(Channel::Pressure2, p2)?))
}

/// The signals along the chain, in the chain's order, for binned conditional means.
pub struct ChainSignals {
    pub names: Vec<&'static str>,
    pub values: Vec<Vec<f64>>,
}

impl ChainSignals {
    pub fn new(model: &Actuator, recording: &Recording, replay: &Replay) -> Self {
        let t = &recording.time;
        let n = recording.len();
        let mut supply = Vec::with_capacity(n);
        let mut returns = Vec::with_capacity(n);
        for k in 0..n {
            let f = model.mass_flows(replay.x_jp[k], replay.p1[k], replay.p2[k]);
            supply.push(f.supply_1 + f.supply_2);
            returns.push(f.return_1 + f.return_2);
        }
        let (p1, p2) = chamber_pressures(model, recording).unwrap_or_else(|| (replay.p1.clone(), replay.p2.clone()));
        let volume_1: Vec<f64> = recording.x_s.iter().map(|&x| model.cylinder.volumes(x).0).collect();
        let pairs: Vec<(&'static str, Vec<f64>)> = vec![
            ("command level v_DA", recording.v_da.clone()),
            ("command rate dv_DA/dt", rate(t, &recording.v_da, 10)),
            (
                "command direction since its last reversal",
                command_direction(&recording.v_da),
            ),
            ("coil current i", replay.current.clone()),
            ("jet pipe position x_jp", replay.x_jp.clone()),
            ("supply mass flow", supply),
            ("return mass flow", returns),
            ("chamber 1 pressure", p1),
            ("chamber 2 pressure", p2),
            ("chamber 1 volume", volume_1),
            ("stopper position x_s", recording.x_s.clone()),
            ("stopper velocity dx_s/dt", stopper_velocity(recording)),
            ("modelled force", replay.force.clone()),
            ("modelled force rate dF/dt", rate(t, &replay.force, 10)),
            ("time", t.clone()),
        ];
        let (names, values) = pairs.into_iter().unzip();
        Self { names, values }
    }
}

/// RMS of `x` over the samples of `blocks` that are `which`.
pub fn rms_where(x: &[f64], blocks: &[Block], which: Block) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (v, &b) in x.iter().zip(blocks) {
        if b == which {
            sum += v * v;
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

/// RMS of `x` over the samples of `blocks` that are not set aside as glitches.
pub fn rms_kept(x: &[f64], blocks: &[Block]) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (v, &b) in x.iter().zip(blocks) {
        if b != Block::SetAside {
            sum += v * v;
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

pub fn rms(x: &[f64]) -> f64 {
    if x.is_empty() {
        0.0
    } else {
        (x.iter().map(|v| v * v).sum::<f64>() / x.len() as f64).sqrt()
    }
}

pub fn difference(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}
