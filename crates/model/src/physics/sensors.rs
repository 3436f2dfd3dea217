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
//! and the transducer may pass it through, in this order, a delay, a first-order lag, a
//! second-order low-pass filter (an amplifier's anti-aliasing filter: natural frequency ω_f,
//! damping ratio ζ_f, unit gain) and a play (backlash) of a given width. The filters act on
//! the reading as it is sampled at communication points: the delay interpolates linearly
//! between them, the lag and the second-order filter are exact for their input moving linearly
//! over each interval. The FMU stepped at a recording's sample times and the replay of that
//! recording read the same. The force sensor has every term (`force_sensor_*`); a pressure
//! transducer has an offset, a gain, a drift, a delay, a lag and a second-order filter
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

/// The most parts a step is recorded in by a transducer that lags or filters
/// ([`SensorLaw::parts_over`]).
pub const MAX_RECORDED_PARTS: usize = 16;

/// The longest part of a step a lagging or filtering transducer is recorded over, however
/// slow it is (s). After a command step the force rises within about a millisecond; read as
/// one chord over a 4 ms sample, it reached a 10 ms force-sensor lag early, and such a lag
/// under a PRBS at 250 Hz was 0.028 N (0.56 noise floors) from the same lag recorded every
/// 0.5 ms. Recorded every millisecond, it is 0.0045 N.
pub const LONGEST_RECORDED_PART: f64 = 1e-3;

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
    /// The second-order filter's natural frequency (Hz; 0: off) and damping ratio.
    pub filter_frequency: f64,
    pub filter_damping: f64,
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
                filter_frequency: p.force_sensor_filter_frequency,
                filter_damping: p.force_sensor_filter_damping,
                play: p.force_sensor_play,
                curve: p.force_sensor_curve,
            },
            Channel::Pressure1 => Self {
                curve: p.p1_sensor_curve,
                filter_frequency: p.p1_sensor_filter_frequency,
                filter_damping: p.p1_sensor_filter_damping,
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
                filter_frequency: p.p2_sensor_filter_frequency,
                filter_damping: p.p2_sensor_filter_damping,
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
            filter_frequency: 0.0,
            filter_damping: std::f64::consts::FRAC_1_SQRT_2,
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
        self.delay > 0.0 || self.lag > 0.0 || self.filter_frequency > 0.0 || self.play > 0.0
    }

    /// The equal parts a step of `step` seconds is recorded in by this transducer: parts no
    /// longer than its lag or 1/(2π f) of its filter, nor than [`LONGEST_RECORDED_PART`], at
    /// most [`MAX_RECORDED_PARTS`]; one where it neither lags nor filters. Its memory takes the
    /// quantity it reads as linear between the points it is recorded at; a 112 Hz force sensor
    /// recorded only at the 4 ms samples of a 250 Hz recording read the force's corners as
    /// chords and left 1.8 noise floors that a sensor following the force itself does not.
    pub fn parts_over(&self, step: f64) -> usize {
        let lag = if self.lag > 0.0 { self.lag } else { f64::INFINITY };
        let filter = if self.filter_frequency > 0.0 {
            1.0 / (2.0 * std::f64::consts::PI * self.filter_frequency)
        } else {
            f64::INFINITY
        };
        let fastest = lag.min(filter);
        if !fastest.is_finite() || step.is_nan() || step <= 0.0 {
            return 1;
        }
        ((step / fastest.min(LONGEST_RECORDED_PART)).ceil() as usize).clamp(1, MAX_RECORDED_PARTS)
    }

    /// Whether the reading is the value itself (the second-order filter's damping matters
    /// only with its frequency on).
    pub fn is_identity(&self) -> bool {
        Self {
            filter_damping: std::f64::consts::FRAC_1_SQRT_2,
            ..*self
        } == Self::pressure(0.0, 1.0, 0.0, 0.0, 0.0)
    }
}

impl SensorLaw {
    /// The quantity that gave the readings `readings` at times `time`: the law undone, as
    /// far as samples allow. The static part is inverted exactly; the delay by reading
    /// later samples (interpolated linearly; the last `delay` of the record holds its last
    /// value); the lag as y + τ dy/dt with centred differences (so it amplifies noise by
    /// about τ/Δt). `None` for a curve (polynomial or static), a pick-up, a play or a
    /// second-order filter, which have no such inverse here.
    pub fn unread(&self, time: &[f64], readings: &[f64]) -> Option<Vec<f64>> {
        if self.quadratic != 0.0
            || self.cubic != 0.0
            || self.ripple_sine != 0.0
            || self.ripple_cosine != 0.0
            || self.play > 0.0
            || self.filter_frequency > 0.0
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

/// A transducer's memory: past static readings at communication points (for the delay) and
/// the lag's, the second-order filter's and the play's outputs at the last time recorded,
/// which may lie between communication points (a step taken in parts).
#[derive(Clone, Debug, PartialEq)]
pub struct SensorMemory {
    /// (time, static reading) at communication points, oldest first; at least one.
    history: VecDeque<(f64, f64)>,
    /// The last time recorded: the end of the history, or a point inside the step after it.
    last_time: f64,
    /// The delayed reading at the last communication point.
    delayed: f64,
    lagged: f64,
    /// The second-order filter's output and its rate.
    filtered: f64,
    filtered_rate: f64,
    played: f64,
}

/// The filters' outputs at one time.
struct Advanced {
    delayed: f64,
    lagged: f64,
    filtered: f64,
    filtered_rate: f64,
    played: f64,
}

/// The first-order lag τ y' = u − y: its rate (the equation whose exact solutions the
/// command stage's and the transducers' lags step over communication intervals; Model
/// Exchange integrates it as it stands).
pub fn first_order_rate(lag: f64, input: f64, y: f64) -> f64 {
    (input - y) / lag
}

/// The second-order low-pass filter y'' + 2ζω y' + ω² y = ω² u, ω = 2π `frequency`, as a
/// first-order system: the rates (y', y'') of (y, y') under the input `input` (the equation
/// [`second_order_step`] solves exactly; Model Exchange integrates it as it stands).
pub fn second_order_rates(frequency: f64, damping: f64, (y, rate): (f64, f64), input: f64) -> (f64, f64) {
    let omega = 2.0 * std::f64::consts::PI * frequency;
    (rate, omega * omega * (input - y) - 2.0 * damping * omega * rate)
}

/// The second-order low-pass filter y'' + 2ζω y' + ω² y = ω² u over an interval h in which
/// its input u moves linearly from `from` to `to`, exactly: the particular solution of the
/// ramp, u − 2ζ u'/ω, plus the homogeneous motion e^{Ah} of what departs from it. Returns
/// (y, y') at the interval's end.
pub fn second_order_step(frequency: f64, damping: f64, h: f64, state: (f64, f64), from: f64, to: f64) -> (f64, f64) {
    if h <= 0.0 {
        return state;
    }
    let omega = 2.0 * std::f64::consts::PI * frequency;
    let transition = second_order_transition(omega, damping, h);
    second_order_advance(omega, damping, h, &transition, state, from, to)
}

/// [`second_order_step`] with its transition matrix e^{Ah} given.
fn second_order_advance(
    omega: f64,
    damping: f64,
    h: f64,
    transition: &[[f64; 2]; 2],
    (y, rate): (f64, f64),
    from: f64,
    to: f64,
) -> (f64, f64) {
    let slope = (to - from) / h;
    let shift = 2.0 * damping * slope / omega;
    let (e0, e1) = (y - (from - shift), rate - slope);
    let [[a, b], [c, d]] = *transition;
    (to - shift + a * e0 + b * e1, slope + c * e0 + d * e1)
}

/// e^{Ah} for A = [[0, 1], [−ω², −2ζω]]: e^{−ζωh} [[C + ζω S, S], [−ω² S, C − ζω S]] with
/// C = cos ω_d h, S = sin(ω_d h)/ω_d, ω_d = ω√(1 − ζ²) (cosh and sinh above ζ = 1, and their
/// series where ω_d h is small, so that critical damping is no special case).
fn second_order_transition(omega: f64, damping: f64, h: f64) -> [[f64; 2]; 2] {
    let decay_rate = damping * omega;
    let beyond = damping * damping - 1.0;
    let omega_d = omega * beyond.abs().sqrt();
    let q = omega_d * h;
    let (ec, es) = if q < 1e-3 {
        let q2 = if beyond > 0.0 { q * q } else { -q * q };
        let e = (-decay_rate * h).exp();
        (
            e * (1.0 + q2 / 2.0 + q2 * q2 / 24.0),
            e * h * (1.0 + q2 / 6.0 + q2 * q2 / 120.0),
        )
    } else if beyond > 0.0 {
        // e^{−ζωh} cosh and sinh from the two real poles' decays, neither of which overflows.
        let slow = (-(decay_rate - omega_d) * h).exp();
        let fast = (-(decay_rate + omega_d) * h).exp();
        (0.5 * (slow + fast), 0.5 * (slow - fast) / omega_d)
    } else {
        let e = (-decay_rate * h).exp();
        (e * q.cos(), e * q.sin() / omega_d)
    };
    [[ec + decay_rate * es, es], [-omega * omega * es, ec - decay_rate * es]]
}

impl SensorMemory {
    /// At rest: the reading `reading` since long before `time`.
    pub fn at_rest(time: f64, reading: f64) -> Self {
        let mut history = VecDeque::new();
        history.push_back((time, reading));
        Self {
            history,
            last_time: time,
            delayed: reading,
            lagged: reading,
            filtered: reading,
            filtered_rate: 0.0,
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
        self.advanced(law, time, reading).played
    }

    fn advanced(&self, law: &SensorLaw, time: f64, reading: f64) -> Advanced {
        let dt = (time - self.last_time).max(0.0);
        let delayed = self.delayed_at(law, time, reading);
        let lagged = if law.lag > 0.0 {
            // Exact for a reading that moves linearly between communication points: a
            // sensor reads a force that changes continuously, and holding it would lag the
            // reading by half an interval more.
            let tau = law.lag;
            let decay = (-dt / tau).exp();
            let ramp_part = if dt > 0.0 { 1.0 - tau * (1.0 - decay) / dt } else { 0.0 };
            decay * self.lagged + (1.0 - decay) * self.delayed + ramp_part * (delayed - self.delayed)
        } else {
            delayed
        };
        let (filtered, filtered_rate) = if law.filter_frequency > 0.0 {
            second_order_step(
                law.filter_frequency,
                law.filter_damping,
                dt,
                (self.filtered, self.filtered_rate),
                self.lagged,
                lagged,
            )
        } else {
            (lagged, 0.0)
        };
        let half = 0.5 * law.play;
        let played = if half > 0.0 {
            self.played.clamp(filtered - half, filtered + half)
        } else {
            filtered
        };
        Advanced {
            delayed,
            lagged,
            filtered,
            filtered_rate,
            played,
        }
    }

    /// Record the static reading at the communication point `time` and return the filtered
    /// reading there.
    pub fn record(&mut self, law: &SensorLaw, time: f64, reading: f64) -> f64 {
        let played = self.record_between(law, time, reading);
        self.history.push_back((time, reading));
        // Keep one point at or before the oldest time a later delay can ask for.
        let oldest = time - law.delay;
        while self.history.len() > 1 && self.history[1].0 <= oldest {
            self.history.pop_front();
        }
        played
    }

    /// Advance the lag, the filter and the play to `time`, inside a step taken in parts, and
    /// return the filtered reading there. The delay keeps interpolating between communication
    /// points, so a step taken in parts reads what the same step taken whole reads.
    pub fn record_between(&mut self, law: &SensorLaw, time: f64, reading: f64) -> f64 {
        let a = self.advanced(law, time, reading);
        self.delayed = a.delayed;
        self.lagged = a.lagged;
        self.filtered = a.filtered;
        self.filtered_rate = a.filtered_rate;
        self.played = a.played;
        self.last_time = time;
        a.played
    }

    /// The lag's output, the second-order filter's output and its rate at the last time
    /// recorded: the continuous states of [`first_order_rate`] and [`second_order_rates`].
    pub fn dynamic_states(&self) -> [f64; 3] {
        [self.lagged, self.filtered, self.filtered_rate]
    }

    /// The memory as numbers (for FMU states): the last time recorded, delayed, lagged,
    /// filtered, its rate, played, then the history's (time, reading) pairs.
    pub fn to_values(&self) -> Vec<f64> {
        let mut v = vec![
            self.last_time,
            self.delayed,
            self.lagged,
            self.filtered,
            self.filtered_rate,
            self.played,
        ];
        for &(t, r) in &self.history {
            v.push(t);
            v.push(r);
        }
        v
    }

    pub fn from_values(values: &[f64]) -> Option<Self> {
        if values.len() < 8 || (values.len() - 6) % 2 != 0 {
            return None;
        }
        Some(Self {
            last_time: values[0],
            delayed: values[1],
            lagged: values[2],
            filtered: values[3],
            filtered_rate: values[4],
            played: values[5],
            history: values[6..].chunks(2).map(|c| (c[0], c[1])).collect(),
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
    if law.delay <= 0.0 && law.lag <= 0.0 && law.play <= 0.0 {
        return second_order_filtered(law, time, &statics);
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

/// [`filtered`] through the second-order filter alone, the memory's arithmetic with the
/// transition matrix computed once for each run of equal intervals (a recording's samples are
/// evenly spaced): the diagnosis filters a channel at every trial of its search.
fn second_order_filtered(law: &SensorLaw, time: &[f64], statics: &[f64]) -> Vec<f64> {
    let omega = 2.0 * std::f64::consts::PI * law.filter_frequency;
    let mut out = Vec::with_capacity(time.len());
    let mut state = (statics[0], 0.0);
    out.push(state.0);
    let mut transition: Option<(f64, [[f64; 2]; 2])> = None;
    for k in 1..time.len().min(statics.len()) {
        let h = (time[k] - time[k - 1]).max(0.0);
        if h > 0.0 {
            let matrix = match transition {
                Some((at, m)) if at == h => m,
                _ => {
                    let m = second_order_transition(omega, law.filter_damping, h);
                    transition = Some((h, m));
                    m
                }
            };
            state = second_order_advance(omega, law.filter_damping, h, &matrix, state, statics[k - 1], statics[k]);
        }
        out.push(state.0);
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

    /// y'' + 2ζω y' + ω² y = ω² u with u linear between the samples, by classical RK4 at a
    /// hundred steps a sample: an oracle apart from the closed form.
    fn second_order_by_rk4(frequency: f64, damping: f64, t: &[f64], u: &[f64]) -> Vec<f64> {
        let omega = 2.0 * std::f64::consts::PI * frequency;
        let (mut y, mut v) = (u[0], 0.0);
        let mut out = vec![y];
        for k in 1..t.len() {
            let h = (t[k] - t[k - 1]) / 100.0;
            let input = |s: f64| u[k - 1] + (u[k] - u[k - 1]) * s / (t[k] - t[k - 1]);
            let f = |s: f64, y: f64, v: f64| (v, omega * omega * (input(s) - y) - 2.0 * damping * omega * v);
            for j in 0..100 {
                let s = j as f64 * h;
                let k1 = f(s, y, v);
                let k2 = f(s + h / 2.0, y + h / 2.0 * k1.0, v + h / 2.0 * k1.1);
                let k3 = f(s + h / 2.0, y + h / 2.0 * k2.0, v + h / 2.0 * k2.1);
                let k4 = f(s + h, y + h * k3.0, v + h * k3.1);
                y += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
                v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            }
            out.push(y);
        }
        out
    }

    #[test]
    fn a_second_order_filter_reads_what_integrating_its_equation_gives_at_any_damping() {
        // Uneven samples (1 ms with every fifth 0.4 ms late), a step, a ramp and a sine.
        let t: Vec<f64> = (0..300)
            .map(|k| k as f64 * 1e-3 + if k % 5 == 0 { 4e-4 } else { 0.0 })
            .collect();
        let force_at = |t: f64| {
            if t < 0.05 {
                0.0
            } else if t < 0.1 {
                40.0
            } else {
                40.0 + 300.0 * (t - 0.1) + 15.0 * (90.0 * t).sin()
            }
        };
        let f: Vec<f64> = t.iter().map(|&t| force_at(t)).collect();
        for (frequency, damping) in [
            (60.0, 0.2),
            (60.0, std::f64::consts::FRAC_1_SQRT_2),
            (150.0, 1.0),
            (35.0, 1.0 + 1e-9),
            (80.0, 3.0),
        ] {
            let p = Parameters {
                force_sensor_filter_frequency: frequency,
                force_sensor_filter_damping: damping,
                ..Parameters::default()
            };
            let law = force(&p);
            assert!(law.filters() && !law.is_identity());
            let y = readings(&law, &t, &f);
            let oracle = second_order_by_rk4(frequency, damping, &t, &f);
            for k in 0..t.len() {
                assert!(
                    (y[k] - oracle[k]).abs() < 1e-7,
                    "{frequency} Hz, ζ {damping}, sample {k}: {} against {}",
                    y[k],
                    oracle[k]
                );
            }
        }
    }

    #[test]
    fn the_second_order_filters_fast_loop_is_the_memorys_to_the_bit() {
        let mut t = times(200);
        t[50] = t[49];
        t[120] += 3e-4;
        let f: Vec<f64> = t
            .iter()
            .map(|&t| 20.0 * (70.0 * t).sin() + if t > 0.1 { 5.0 } else { 0.0 })
            .collect();
        let p = Parameters {
            force_sensor_filter_frequency: 45.0,
            force_sensor_filter_damping: 0.6,
            ..Parameters::default()
        };
        let law = force(&p);
        let mut memory = SensorMemory::at_rest(t[0], f[0]);
        let mut slow = vec![memory.output(&law, t[0], f[0])];
        for k in 1..t.len() {
            slow.push(memory.record(&law, t[k], f[k]));
        }
        let fast = readings(&law, &t, &f);
        assert_eq!(
            fast.iter().map(|y| y.to_bits()).collect::<Vec<_>>(),
            slow.iter().map(|y| y.to_bits()).collect::<Vec<_>>()
        );
    }

    #[test]
    fn a_second_order_filter_passes_a_constant_and_settles_on_a_step() {
        let p = Parameters {
            p2_sensor_filter_frequency: 50.0,
            p2_sensor_filter_damping: 0.5,
            ..Parameters::default()
        };
        let law = SensorLaw::of(&p, Channel::Pressure2);
        let t = times(400);
        assert!(readings(&law, &t, &vec![3e5; 400]).iter().all(|&y| y == 3e5));
        let step: Vec<f64> = t.iter().map(|&t| if t > 0.0 { 4e5 } else { 3e5 }).collect();
        let y = readings(&law, &t, &step);
        // ζ = 0.5 overshoots by e^(−πζ/√(1−ζ²)) = 16.3 %, and has settled after 0.4 s.
        let peak = y.iter().cloned().fold(f64::MIN, f64::max);
        assert!(((peak - 4e5) / 1e5 - 0.163).abs() < 0.01, "peak {peak}");
        assert!((y[399] - 4e5).abs() < 1.0);
        assert!(SensorLaw::of(&Parameters::default(), Channel::Pressure2).is_identity());
        assert!(law.unread(&t, &y).is_none());
    }

    #[test]
    fn the_memory_survives_a_round_trip_through_numbers() {
        let p = Parameters {
            force_sensor_delay: 2e-3,
            force_sensor_lag: 1e-3,
            force_sensor_filter_frequency: 80.0,
            ..Parameters::default()
        };
        let mut m = SensorMemory::at_rest(0.0, 1.0);
        m.record(&force(&p), 1e-3, 2.0);
        m.record(&force(&p), 2e-3, 5.0);
        let back = SensorMemory::from_values(&m.to_values()).unwrap();
        assert_eq!(back, m);
    }
}
