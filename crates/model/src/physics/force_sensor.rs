//! What the force sensor reads (`F_meas`) of the actuator force F_act. With every term at
//! its default the reading is F_act itself.
//!
//! The static reading at time t is
//!
//!   offset + gain F + quadratic F² + cubic F³ + drift t + a sin 2πft + b cos 2πft,
//!
//! and the sensor may pass it through, in this order, a delay, a first-order lag and a
//! play (backlash) of a given width. The filters act on the reading as it is sampled at
//! communication points: the delay interpolates linearly between them, the lag is exact
//! for the reading moving linearly over each interval. The FMU stepped at a recording's sample
//! times and the replay of that recording read the same.

use super::parameters::Parameters;
use std::collections::VecDeque;

/// The static reading (offset, gain, curve, drift and pick-up) of the force `force` at `time`.
pub fn static_reading(p: &Parameters, force: f64, time: f64) -> f64 {
    let mut y = p.force_sensor_offset + p.force_sensor_gain * force;
    if p.force_sensor_quadratic != 0.0 || p.force_sensor_cubic != 0.0 {
        y += force * force * (p.force_sensor_quadratic + p.force_sensor_cubic * force);
    }
    if p.force_sensor_drift != 0.0 {
        y += p.force_sensor_drift * time;
    }
    if p.force_sensor_ripple_sine != 0.0 || p.force_sensor_ripple_cosine != 0.0 {
        let phase = 2.0 * std::f64::consts::PI * p.force_sensor_ripple_frequency * time;
        y += p.force_sensor_ripple_sine * phase.sin() + p.force_sensor_ripple_cosine * phase.cos();
    }
    y
}

/// Whether the sensor filters its reading (and so has a memory).
pub fn filters(p: &Parameters) -> bool {
    p.force_sensor_delay > 0.0 || p.force_sensor_lag > 0.0 || p.force_sensor_play > 0.0
}

/// The sensor's memory: past static readings (for the delay) and the lag's and the
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

    fn delayed_at(&self, p: &Parameters, time: f64, reading: f64) -> f64 {
        if p.force_sensor_delay <= 0.0 {
            return reading;
        }
        let at = time - p.force_sensor_delay;
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

    /// `F_meas` at `time` (not before the last recorded time) when the static reading is
    /// `reading` there; the memory is unchanged.
    pub fn output(&self, p: &Parameters, time: f64, reading: f64) -> f64 {
        self.advanced(p, time, reading).3
    }

    fn advanced(&self, p: &Parameters, time: f64, reading: f64) -> (f64, f64, f64, f64) {
        let last = self.history.back().expect("the history is never empty").0;
        let delayed = self.delayed_at(p, time, reading);
        let lagged = if p.force_sensor_lag > 0.0 {
            // Exact for a reading that moves linearly between communication points: a
            // sensor reads a force that changes continuously, and holding it would lag the
            // reading by half an interval more.
            let dt = (time - last).max(0.0);
            let tau = p.force_sensor_lag;
            let decay = (-dt / tau).exp();
            let ramp_part = if dt > 0.0 { 1.0 - tau * (1.0 - decay) / dt } else { 0.0 };
            decay * self.lagged + (1.0 - decay) * self.delayed + ramp_part * (delayed - self.delayed)
        } else {
            delayed
        };
        let half = 0.5 * p.force_sensor_play;
        let played = if half > 0.0 {
            self.played.clamp(lagged - half, lagged + half)
        } else {
            lagged
        };
        (delayed, lagged, played, played)
    }

    /// Record the static reading at the communication point `time` and return `F_meas` there.
    pub fn record(&mut self, p: &Parameters, time: f64, reading: f64) -> f64 {
        let (delayed, lagged, played, out) = self.advanced(p, time, reading);
        self.delayed = delayed;
        self.lagged = lagged;
        self.played = played;
        self.history.push_back((time, reading));
        // Keep one point at or before the oldest time a later delay can ask for.
        let oldest = time - p.force_sensor_delay;
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

/// `F_meas` at every sample from the actuator forces `force` at times `time`.
pub fn readings(p: &Parameters, time: &[f64], force: &[f64]) -> Vec<f64> {
    let statics = time.iter().zip(force).map(|(&t, &f)| static_reading(p, f, t)).collect();
    filtered(p, time, statics)
}

/// `F_meas` at every sample from the static readings `statics` at times `time`.
pub fn filtered(p: &Parameters, time: &[f64], statics: Vec<f64>) -> Vec<f64> {
    if !filters(p) || time.is_empty() {
        return statics;
    }
    let mut memory = SensorMemory::at_rest(time[0], statics[0]);
    let mut out = Vec::with_capacity(time.len());
    for (k, (&t, &r)) in time.iter().zip(&statics).enumerate() {
        out.push(if k == 0 {
            memory.output(p, t, r)
        } else {
            memory.record(p, t, r)
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

    #[test]
    fn with_every_term_off_the_sensor_reads_the_force() {
        let p = Parameters::default();
        let f = [1.0, -2.0, 30.0];
        assert_eq!(readings(&p, &times(3), &f), f.to_vec());
    }

    #[test]
    fn a_quadratic_sensor_reads_its_curve() {
        let p = Parameters {
            force_sensor_quadratic: 4e-4,
            ..Parameters::default()
        };
        assert!((static_reading(&p, 50.0, 3.0) - (50.0 + 4e-4 * 2500.0)).abs() < 1e-12);
    }

    #[test]
    fn a_delayed_sensor_reads_the_force_of_that_long_ago() {
        let p = Parameters {
            force_sensor_delay: 2.5e-3,
            ..Parameters::default()
        };
        let t = times(10);
        let f: Vec<f64> = t.iter().map(|t| 1000.0 * t).collect();
        let y = readings(&p, &t, &f);
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
        let y = readings(&p, &t, &f);
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
        let y = readings(&p, &times(5), &[0.0, 0.5, 3.0, 2.5, 1.0]);
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
        m.record(&p, 1e-3, 2.0);
        m.record(&p, 2e-3, 5.0);
        let back = SensorMemory::from_values(&m.to_values()).unwrap();
        assert_eq!(back, m);
    }
}
