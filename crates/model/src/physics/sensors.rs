//! What the transducers read: the force sensor (`F_meas`) of the actuator force F_act, and
//! the two pressure transducers (`P1_meas`, `P2_meas`) of the chamber pressures. With every
//! term at its default a reading is the quantity itself.
//!
//! One law serves the three channels. The static reading of a value y at time t is
//!
//!   offset + gain c(y) + quadratic c(y)² + cubic c(y)³ + drift t + a sin 2πft + b cos 2πft,
//!
//! with c the transducer's static curve (`*_curve_*`, [`super::static_curve`]; the identity
//! when off),
//!
//! and the transducer may pass it through, in this order, a delay, a first-order lag and a
//! play (backlash) of a given width. The filters act on the reading as it is sampled at
//! communication points: the delay interpolates linearly between them, the lag is exact
//! for the reading moving linearly over each interval. The FMU stepped at a recording's sample
//! times and the replay of that recording read the same. The force sensor has every term
//! (`force_sensor_*`); a pressure transducer has an offset, a gain, a drift, a delay and a lag
//! (`p1_sensor_*`, `p2_sensor_*`); each has a static curve.

use super::parameters::Parameters;
use super::static_curve::StaticCurve;
use std::collections::VecDeque;

/// The measured channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    Force,
    Pressure1,
    Pressure2,
}

impl Channel {
    pub const ALL: [Channel; 3] = [Channel::Force, Channel::Pressure1, Channel::Pressure2];
}

/// One transducer's law, taken from the parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorLaw {
    pub offset: f64,
    pub gain: f64,
    pub quadratic: f64,
    pub cubic: f64,
    pub drift: f64,
    pub ripple_sine: f64,
    pub ripple_cosine: f64,
    pub ripple_frequency: f64,
    pub delay: f64,
    pub lag: f64,
    pub play: f64,
    /// The reading's static curve, applied to the quantity first.
    pub curve: StaticCurve,
}

impl SensorLaw {
    /// The law of `channel`'s transducer under the parameters `p`.
    pub fn of(p: &Parameters, channel: Channel) -> Self {
        match channel {
            Channel::Force => Self {
                offset: p.force_sensor_offset,
                gain: p.force_sensor_gain,
                quadratic: p.force_sensor_quadratic,
                cubic: p.force_sensor_cubic,
                drift: p.force_sensor_drift,
                ripple_sine: p.force_sensor_ripple_sine,
                ripple_cosine: p.force_sensor_ripple_cosine,
                ripple_frequency: p.force_sensor_ripple_frequency,
                delay: p.force_sensor_delay,
                lag: p.force_sensor_lag,
                play: p.force_sensor_play,
                curve: p.force_sensor_curve,
            },
            Channel::Pressure1 => Self {
                curve: p.p1_sensor_curve,
                ..Self::pressure(
                    p.p1_sensor_offset,
                    p.p1_sensor_gain,
                    p.p1_sensor_drift,
                    p.p1_sensor_delay,
                    p.p1_sensor_lag,
                )
            },
            Channel::Pressure2 => Self {
                curve: p.p2_sensor_curve,
                ..Self::pressure(
                    p.p2_sensor_offset,
                    p.p2_sensor_gain,
                    p.p2_sensor_drift,
                    p.p2_sensor_delay,
                    p.p2_sensor_lag,
                )
            },
        }
    }

    fn pressure(offset: f64, gain: f64, drift: f64, delay: f64, lag: f64) -> Self {
        Self {
            offset,
            gain,
            quadratic: 0.0,
            cubic: 0.0,
            drift,
            ripple_sine: 0.0,
            ripple_cosine: 0.0,
            ripple_frequency: 0.0,
            delay,
            lag,
            play: 0.0,
            curve: StaticCurve::default(),
        }
    }

    /// The static reading (offset, gain, curve, drift and pick-up) of `value` at `time`.
    pub fn static_reading(&self, value: f64, time: f64) -> f64 {
        let value = self.curve.at(value);
        let mut y = self.offset + self.gain * value;
        if self.quadratic != 0.0 || self.cubic != 0.0 {
            y += value * value * (self.quadratic + self.cubic * value);
        }
        if self.drift != 0.0 {
            y += self.drift * time;
        }
        if self.ripple_sine != 0.0 || self.ripple_cosine != 0.0 {
            let phase = 2.0 * std::f64::consts::PI * self.ripple_frequency * time;
            y += self.ripple_sine * phase.sin() + self.ripple_cosine * phase.cos();
        }
        y
    }

    /// Whether the transducer filters its reading (and so has a memory).
    pub fn filters(&self) -> bool {
        self.delay > 0.0 || self.lag > 0.0 || self.play > 0.0
    }

    /// Whether the reading is the value itself.
    pub fn is_identity(&self) -> bool {
        *self == Self::pressure(0.0, 1.0, 0.0, 0.0, 0.0)
    }
}

impl SensorLaw {
    /// The quantity that gave the readings `readings` at times `time`: the law undone, as
    /// far as samples allow. The static part is inverted exactly; the delay by reading
    /// later samples (interpolated linearly; the last `delay` of the record holds its last
    /// value); the lag as y + τ dy/dt with centred differences (so it amplifies noise by
    /// about τ/Δt). `None` for a curve (polynomial or static), a pick-up or a play, which have no such inverse.
    pub fn unread(&self, time: &[f64], readings: &[f64]) -> Option<Vec<f64>> {
        if self.quadratic != 0.0
            || self.cubic != 0.0
            || self.ripple_sine != 0.0
            || self.ripple_cosine != 0.0
            || self.play > 0.0
            || self.curve.is_on()
        {
            return None;
        }
        let n = readings.len().min(time.len());
        let mut y: Vec<f64> = readings[..n].to_vec();
        if self.lag > 0.0 && n >= 3 {
            let lagged = y.clone();
            for k in 0..n {
                let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                y[k] = lagged[k] + self.lag * (lagged[b] - lagged[a]) / (time[b] - time[a]);
            }
        }
        if self.delay > 0.0 {
            let delayed = y.clone();
            let mut j = 0;
            for k in 0..n {
                let at = time[k] + self.delay;
                while j + 1 < n && time[j + 1] < at {
                    j += 1;
                }
                y[k] = if j + 1 < n && time[j] <= at {
                    let w = (at - time[j]) / (time[j + 1] - time[j]);
                    delayed[j] + w * (delayed[j + 1] - delayed[j])
                } else {
                    delayed[n - 1]
                };
            }
        }
        for (value, &t) in y.iter_mut().zip(time) {
            *value = (*value - self.offset - self.drift * t) / self.gain;
        }
        Some(y)
    }
}

/// A transducer's memory: past static readings (for the delay) and the lag's and the
/// play's outputs at the last communication point.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorMemory {
    /// (time, static reading), oldest first; at least one.
    history: VecDeque<(f64, f64)>,
    /// The delayed reading at the last communication point.
    delayed: f64,
    lagged: f64,
    played: f64,
}

impl SensorMemory {
    /// At rest: the reading `reading` since long before `time`.
    pub fn at_rest(time: f64, reading: f64) -> Self {
        let mut history = VecDeque::new();
        history.push_back((time, reading));
        Self {
            history,
            delayed: reading,
            lagged: reading,
            played: reading,
        }
    }

    fn delayed_at(&self, law: &SensorLaw, time: f64, reading: f64) -> f64 {
        if law.delay <= 0.0 {
            return reading;
        }
        let at = time - law.delay;
        let mut before = *self.history.front().expect("the history is never empty");
        if at <= before.0 {
            return before.1;
        }
        for &point in self.history.iter().skip(1).chain(std::iter::once(&(time, reading))) {
            if point.0 >= at {
                let span = point.0 - before.0;
                return if span > 0.0 {
                    before.1 + (at - before.0) / span * (point.1 - before.1)
                } else {
                    point.1
                };
            }
            before = point;
        }
        reading
    }

    /// The filtered reading at `time` (not before the last recorded time) when the static
    /// reading is `reading` there; the memory is unchanged.
    pub fn output(&self, law: &SensorLaw, time: f64, reading: f64) -> f64 {
        self.advanced(law, time, reading).3
    }

    fn advanced(&self, law: &SensorLaw, time: f64, reading: f64) -> (f64, f64, f64, f64) {
        let last = self.history.back().expect("the history is never empty").0;
        let delayed = self.delayed_at(law, time, reading);
        let lagged = if law.lag > 0.0 {
            // Exact for a reading that moves linearly between communication points: a
            // sensor reads a force that changes continuously, and holding it would lag the
            // reading by half an interval more.
            let dt = (time - last).max(0.0);
            let tau = law.lag;
            let decay = (-dt / tau).exp();
            let ramp_part = if dt > 0.0 { 1.0 - tau * (1.0 - decay) / dt } else { 0.0 };
            decay * self.lagged + (1.0 - decay) * self.delayed + ramp_part * (delayed - self.delayed)
        } else {
            delayed
        };
        let half = 0.5 * law.play;
        let played = if half > 0.0 {
            self.played.clamp(lagged - half, lagged + half)
        } else {
            lagged
        };
        (delayed, lagged, played, played)
    }

    /// Record the static reading at the communication point `time` and return the filtered
    /// reading there.
    pub fn record(&mut self, law: &SensorLaw, time: f64, reading: f64) -> f64 {
        let (delayed, lagged, played, out) = self.advanced(law, time, reading);
        self.delayed = delayed;
        self.lagged = lagged;
        self.played = played;
        self.history.push_back((time, reading));
        // Keep one point at or before the oldest time a later delay can ask for.
        let oldest = time - law.delay;
        while self.history.len() > 1 && self.history[1].0 <= oldest {
            self.history.pop_front();
        }
        out
    }

    /// The memory as numbers (for FMU states): delayed, lagged, played, then the history's
    /// (time, reading) pairs.
    pub fn to_values(&self) -> Vec<f64> {
        let mut v = vec![self.delayed, self.lagged, self.played];
        for &(t, r) in &self.history {
            v.push(t);
            v.push(r);
        }
        v
    }

    pub fn from_values(values: &[f64]) -> Option<Self> {
        if values.len() < 5 || (values.len() - 3) % 2 != 0 {
            return None;
        }
        Some(Self {
            delayed: values[0],
            lagged: values[1],
            played: values[2],
            history: values[3..].chunks(2).map(|c| (c[0], c[1])).collect(),
        })
    }
}

/// The readings at every sample of the values `values` at times `time`.
pub fn readings(law: &SensorLaw, time: &[f64], values: &[f64]) -> Vec<f64> {
    let statics = time
        .iter()
        .zip(values)
        .map(|(&t, &v)| law.static_reading(v, t))
        .collect();
    filtered(law, time, statics)
}

/// The filtered readings at every sample from the static readings `statics` at times `time`.
pub fn filtered(law: &SensorLaw, time: &[f64], statics: Vec<f64>) -> Vec<f64> {
    if !law.filters() || time.is_empty() {
        return statics;
    }
    let mut memory = SensorMemory::at_rest(time[0], statics[0]);
    let mut out = Vec::with_capacity(time.len());
    for (k, (&t, &r)) in time.iter().zip(&statics).enumerate() {
        out.push(if k == 0 {
            memory.output(law, t, r)
        } else {
            memory.record(law, t, r)
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn times(n: usize) -> Vec<f64> {
        (0..n).map(|k| k as f64 * 1e-3).collect()
    }

    fn force(p: &Parameters) -> SensorLaw {
        SensorLaw::of(p, Channel::Force)
    }

    #[test]
    fn with_the_defaults_every_transducer_reads_its_quantity() {
        for channel in Channel::ALL {
            let law = SensorLaw::of(&Parameters::default(), channel);
            assert!(law.is_identity(), "{channel:?}: {law:?}");
            assert_eq!(law.static_reading(6.5e5, 12.0), 6.5e5);
        }
    }

    #[test]
    fn a_pressure_transducer_reads_its_own_offset_gain_and_drift_and_not_the_others() {
        let p = Parameters {
            p1_sensor_offset: 8e3,
            p1_sensor_gain: 1.01,
            p1_sensor_drift: 50.0,
            p2_sensor_delay: 0.01,
            ..Parameters::default()
        };
        let one = SensorLaw::of(&p, Channel::Pressure1);
        assert!((one.static_reading(4e5, 2.0) - (8e3 + 1.01 * 4e5 + 100.0)).abs() < 1e-6);
        assert!(!one.filters());
        let two = SensorLaw::of(&p, Channel::Pressure2);
        assert_eq!(two.static_reading(4e5, 2.0), 4e5);
        assert!(two.filters());
        assert!(force(&p).is_identity());
    }

    #[test]
    fn unreading_gives_back_what_a_transducer_read() {
        let t = times(400);
        let pressure: Vec<f64> = t.iter().map(|t| 4e5 + 1e5 * (6.0 * t).sin()).collect();
        let p = Parameters {
            p1_sensor_offset: 8e3,
            p1_sensor_gain: 0.98,
            p1_sensor_drift: 300.0,
            p1_sensor_delay: 7e-3,
            p1_sensor_lag: 2e-3,
            ..Parameters::default()
        };
        let law = SensorLaw::of(&p, Channel::Pressure1);
        let back = law.unread(&t, &readings(&law, &t, &pressure)).unwrap();
        // Inside the record (past the lag settling from rest at t = 0, before the last
        // delay), to within what sampling leaves: the delay's linear interpolation, there
        // and back, errs by up to Δt²/8·|p″| = 0.45 Pa each on this 6 rad/s, 1e5 Pa sine;
        // the centred difference by Δt²/6·τ·|p‴| ≈ 0.01 Pa.
        for k in 20..390 {
            assert!(
                (back[k] - pressure[k]).abs() < 1.0,
                "{k}: {} against {}",
                back[k],
                pressure[k]
            );
        }
        let played = SensorLaw {
            play: 1.0,
            ..SensorLaw::of(&Parameters::default(), Channel::Force)
        };
        assert!(played.unread(&t, &pressure).is_none());
    }

    #[test]
    fn a_late_pressure_transducer_reads_the_pressure_of_that_long_ago() {
        let p = Parameters {
            p2_sensor_delay: 10e-3,
            ..Parameters::default()
        };
        let t = times(40);
        let pressure: Vec<f64> = t.iter().map(|t| 3e5 + 1e6 * t).collect();
        let y = readings(&SensorLaw::of(&p, Channel::Pressure2), &t, &pressure);
        for k in 10..40 {
            assert!(
                (y[k] - pressure[k - 10]).abs() < 1e-6,
                "{k}: {} against {}",
                y[k],
                pressure[k - 10]
            );
        }
    }

    #[test]
    fn with_every_term_off_the_sensor_reads_the_force() {
        let p = Parameters::default();
        let f = [1.0, -2.0, 30.0];
        assert_eq!(readings(&force(&p), &times(3), &f), f.to_vec());
    }

    #[test]
    fn a_quadratic_sensor_reads_its_curve() {
        let p = Parameters {
            force_sensor_quadratic: 4e-4,
            ..Parameters::default()
        };
        assert!((force(&p).static_reading(50.0, 3.0) - (50.0 + 4e-4 * 2500.0)).abs() < 1e-12);
    }

    #[test]
    fn a_delayed_sensor_reads_the_force_of_that_long_ago() {
        let p = Parameters {
            force_sensor_delay: 2.5e-3,
            ..Parameters::default()
        };
        let t = times(10);
        let f: Vec<f64> = t.iter().map(|t| 1000.0 * t).collect();
        let y = readings(&force(&p), &t, &f);
        for k in 3..10 {
            assert!((y[k] - 1000.0 * (t[k] - 2.5e-3)).abs() < 1e-9, "{k}: {}", y[k]);
        }
        assert_eq!(y[0], 0.0);
    }

    #[test]
    fn a_lagged_ramp_is_the_continuous_solution_at_every_sample() {
        // y' = (x - y)/tau with x = y = 0 at t = 0 and x = r t: y = r (t - tau (1 - e^(-t/tau))).
        let (tau, rate) = (0.01, 100.0);
        let p = Parameters {
            force_sensor_lag: tau,
            ..Parameters::default()
        };
        let t: Vec<f64> = (0..200).map(|k| k as f64 * 1e-3).collect();
        let f: Vec<f64> = t.iter().map(|t| rate * t).collect();
        let y = readings(&force(&p), &t, &f);
        for k in 0..t.len() {
            let exact = rate * (t[k] - tau * (1.0 - (-t[k] / tau).exp()));
            assert!((y[k] - exact).abs() < 1e-9, "{k}: {} against {exact}", y[k]);
        }
    }

    #[test]
    fn a_play_holds_its_reading_until_the_force_pushes_it() {
        let p = Parameters {
            force_sensor_play: 2.0,
            ..Parameters::default()
        };
        let y = readings(&force(&p), &times(5), &[0.0, 0.5, 3.0, 2.5, 1.0]);
        assert_eq!(y, vec![0.0, 0.0, 2.0, 2.0, 2.0]);
    }

    #[test]
    fn the_memory_survives_a_round_trip_through_numbers() {
        let p = Parameters {
            force_sensor_delay: 2e-3,
            force_sensor_lag: 1e-3,
            ..Parameters::default()
        };
        let mut m = SensorMemory::at_rest(0.0, 1.0);
        m.record(&force(&p), 1e-3, 2.0);
        m.record(&force(&p), 2e-3, 5.0);
        let back = SensorMemory::from_values(&m.to_values()).unwrap();
        assert_eq!(back, m);
    }
}
