//! What the current driver sees of the D/A command when the command stage departs from
//! the thesis's ideal D/A (all off by default, and then it sees v_DA itself):
//!
//! | parameter | law |
//! |---|---|
//! | `command_quantum`, `_origin`, `_threshold` (V, V, 1) | o + q ⌊(v − o)/q + 1 − r⌋: the levels o + k q of a D/A with fewer bits than the logged command, the next level taken r of the way to it ([`quantised`]) |
//! | `command_curve_*` (V) | c(v): a static curve of the logged command, piecewise linear through its knots ([`super::static_curve`]) |
//! | `f3_input_cubic` (V) | v + c (v / 10 V)³: a static curve before f3 (the current driver is linear and fast, so a curve on the tip force k_m i is the same as one on the command) |
//! | `command_limit` (V) | clipped at ± the limit |
//! | `command_upper_limit`, `command_lower_limit` (V) | clipped above the one and below the other |
//! | `current_limit` (A) | clipped where k_cd v + i_offset reaches ± the limit, (2.1) |
//! | `current_slew_limit` (A/s) | the command moves towards the applied one at most the limit / k_cd per second, continuously: a ramp within the step that ends where it reaches it ([`CommandStage::pieces_over`]) |
//! | `command_lag` (s) | a first-order lag, exact for the command held between communication points |
//! | `command_filter_frequency` (Hz), `command_filter_damping` | a second-order low-pass filter after the lag, exact for its input held between communication points (or, without the lag, for the slew limit's ramp and hold) |
//!
//! The slew limit, the lag and the filter act on the command as it is held between communication
//! points (a sampled D/A stage): the FMU stepped at a recording's sample times and the
//! replay of that recording see the same command. The slew limit is continuous: with the
//! driver's corner at 7050 rad/s, a command slewing at S / k_cd gives a current that slews at S
//! to within 0.14 ms, as a driver whose own di/dt is limited does. Held at each communication
//! point instead, a 3 A/s limit sampled at 250 Hz moved in 4 ms stairs and left 0.5 N between
//! such a driver and the model with the true limit. The output of the last of them, the filter's,
//! the lag's or else the slew limit's, moves linearly from its value at the step's start to its exact value at
//! the step's end ([`CommandStage::rate_over`]), or, where it is fast beside the step, through
//! its exact values at up to [`MAX_FILTER_PIECES`] nodes within it
//! ([`CommandStage::pieces_over`]). Held over the step instead, a 5.8 ms lag sampled at
//! 500 Hz reached the driver about a step late, and a fit took 3.2 ms for it. With both on,
//! the filter's input is the lag's output held over each step.

use super::current_driver;
use super::parameters::Parameters;
use super::sensors::second_order_step;

/// The most linear pieces a step of the command's second-order filter is cut into.
pub const MAX_FILTER_PIECES: usize = 16;

/// Whether any term of the command stage is on.
pub fn is_active(p: &Parameters) -> bool {
    p.f3_input_cubic != 0.0
        || p.command_quantum > 0.0
        || p.command_curve.is_on()
        || p.command_limit > 0.0
        || has_one_sided_limit(p)
        || p.current_limit > 0.0
        || p.current_slew_limit > 0.0
        || p.command_lag > 0.0
        || p.command_filter_frequency > 0.0
}

/// Whether a one-sided limit is on: off from ±100 V, ten times the D/A's span.
fn has_one_sided_limit(p: &Parameters) -> bool {
    p.command_upper_limit < 100.0 || p.command_lower_limit > -100.0
}

/// The command on the quantiser's levels o + k q: the level below, or the next one from r of
/// the way to it (r = ½ rounds to the nearest level, r = 1 truncates).
pub fn quantised(p: &Parameters, v_da: f64) -> f64 {
    let (q, o) = (p.command_quantum, p.command_quantum_origin);
    o + q * ((v_da - o) / q + 1.0 - p.command_quantum_threshold).floor()
}

/// The static part of the stage: the quantiser, the static curve, the cubic, then the
/// command and current limits.
pub fn static_map(p: &Parameters, v_da: f64) -> f64 {
    let v = if p.command_quantum > 0.0 {
        quantised(p, v_da)
    } else {
        v_da
    };
    let mut v = p.command_curve.at(v);
    if p.f3_input_cubic != 0.0 {
        v += p.f3_input_cubic * (v / 10.0).powi(3);
    }
    if p.command_limit > 0.0 {
        v = v.clamp(-p.command_limit, p.command_limit);
    }
    if has_one_sided_limit(p) {
        v = v.clamp(p.command_lower_limit, p.command_upper_limit);
    }
    if p.current_limit > 0.0 && p.k_cd != 0.0 {
        let (a, b) = (
            current_driver::command_for_current(p.k_cd, p.i_offset, -p.current_limit),
            current_driver::command_for_current(p.k_cd, p.i_offset, p.current_limit),
        );
        v = v.clamp(a.min(b), a.max(b));
    }
    v
}

/// How many numbers [`CommandStage::to_values`] gives.
pub const VALUES: usize = 6;

/// The slew limit as a rate of the command (V/s), when it is on.
fn slew_rate(p: &Parameters) -> Option<f64> {
    (p.current_slew_limit > 0.0 && p.k_cd != 0.0).then(|| p.current_slew_limit / p.k_cd.abs())
}

/// A piece of command: (duration, value at its start, rate).
type Piece = (f64, f64, f64);
type Pieces = smallvec::SmallVec<[Piece; 2]>;

/// The stage's memory between communication points.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CommandStage {
    /// Time of the last communication point.
    time: f64,
    /// The slew-limited command at that time.
    held: f64,
    /// The command the slew limit moves towards since then (the static map of the command
    /// applied then).
    target: f64,
    /// The lag's output at that time.
    lagged: f64,
    /// The second-order filter's output and its rate (V/s) at that time.
    filtered: f64,
    filtered_rate: f64,
}

impl CommandStage {
    /// At rest at time `time` with the command `v_da` held since long before.
    pub fn at_rest(p: &Parameters, time: f64, v_da: f64) -> Self {
        let v = static_map(p, v_da);
        Self {
            time,
            held: v,
            target: v,
            lagged: v,
            filtered: v,
            filtered_rate: 0.0,
        }
    }

    /// The command the current driver sees from `time` on, with `v_da` applied at `time`
    /// (times never decrease).
    pub fn next(&mut self, p: &Parameters, time: f64, v_da: f64) -> f64 {
        let dt = (time - self.time).max(0.0);
        let v = static_map(p, v_da);
        if p.command_filter_frequency > 0.0 {
            (self.filtered, self.filtered_rate) = self.filtered_after(p, dt);
        }
        if p.command_lag > 0.0 {
            self.lagged = self.lagged_after(p, dt);
        }
        self.held = if slew_rate(p).is_some() {
            self.slewed_after(p, dt)
        } else {
            v
        };
        self.target = v;
        self.time = time;
        self.current(p)
    }

    /// The slew limit's output `after` seconds past the last communication point.
    fn slewed_after(&self, p: &Parameters, after: f64) -> f64 {
        match slew_rate(p) {
            Some(rate) => self.held + (self.target - self.held).clamp(-rate * after, rate * after),
            None => self.target,
        }
    }

    /// The slew limit's output over the `span` seconds from the last communication point: a
    /// ramp at the limit, then the applied command held once it is reached.
    fn slew_pieces(&self, p: &Parameters, span: f64) -> Pieces {
        let gap = self.target - self.held;
        match slew_rate(p) {
            Some(rate) if gap != 0.0 => {
                let reached = gap.abs() / rate;
                let ramp = rate.copysign(gap);
                if reached >= span {
                    smallvec::smallvec![(span, self.held, ramp)]
                } else {
                    smallvec::smallvec![(reached, self.held, ramp), (span - reached, self.target, 0.0)]
                }
            }
            _ => smallvec::smallvec![(span, self.target, 0.0)],
        }
    }

    /// The second-order filter's output and rate `after` seconds past the last communication
    /// point: driven by the lag's output held there, or else by the slew limit's output.
    fn filtered_after(&self, p: &Parameters, after: f64) -> (f64, f64) {
        let (frequency, damping) = (p.command_filter_frequency, p.command_filter_damping);
        let mut state = (self.filtered, self.filtered_rate);
        if p.command_lag > 0.0 {
            return second_order_step(frequency, damping, after, state, self.lagged, self.lagged);
        }
        for (duration, start, rate) in self.slew_pieces(p, after) {
            state = second_order_step(frequency, damping, duration, state, start, start + rate * duration);
        }
        state
    }

    /// The command the current driver has seen since the last communication point.
    pub fn current(&self, p: &Parameters) -> f64 {
        if p.command_filter_frequency > 0.0 {
            self.filtered
        } else {
            self.unfiltered(p)
        }
    }

    /// The rate (V/s) at which the command the driver sees moves over the next `step` seconds:
    /// from the output of the stage's last term now to its exact output at the step's end
    /// (the filter's, the lag's or the slew limit's), linear between rather than held, which
    /// would lag it by half a step; 0 when the command is held.
    pub fn rate_over(&self, p: &Parameters, step: f64) -> f64 {
        if step.is_nan() || step <= 0.0 {
            return 0.0;
        }
        let end = if p.command_filter_frequency > 0.0 {
            self.filtered_after(p, step).0
        } else if p.command_lag > 0.0 {
            self.lagged_after(p, step)
        } else {
            self.slewed_after(p, step)
        };
        (end - self.current(p)) / step
    }

    /// With the second-order filter on and fast beside `step` (more than a quarter of its
    /// natural period), the command the driver sees over the step as linear pieces between
    /// the filter's exact values, its input held, at most [`MAX_FILTER_PIECES`] of them and
    /// each at most a quarter period long: (duration, value at its start, rate). `None` when
    /// one ramp over the whole step does ([`Self::rate_over`]). A 460 Hz filter ramped over
    /// the 4 ms of a 250 Hz sample reached its input 2 ms late, where it takes 0.5 ms. With the
    /// slew limit last, its ramp and then the applied command held, where the ramp ends within
    /// the step.
    pub fn pieces_over(&self, p: &Parameters, step: f64) -> Option<Pieces> {
        if step.is_nan() || step <= 0.0 {
            return None;
        }
        if p.command_filter_frequency <= 0.0 && p.command_lag <= 0.0 {
            let pieces = self.slew_pieces(p, step);
            return (pieces.len() > 1).then_some(pieces);
        }
        if p.command_filter_frequency <= 0.0 {
            return self.lag_pieces_over(p, step);
        }
        let pieces = (4.0 * p.command_filter_frequency * step)
            .ceil()
            .min(MAX_FILTER_PIECES as f64);
        if pieces < 2.0 {
            return None;
        }
        let pieces = pieces as usize;
        let mut out = smallvec::SmallVec::new();
        let mut value = self.filtered;
        let mut elapsed = 0.0;
        for k in 1..=pieces {
            let until = step * k as f64 / pieces as f64;
            let (end, _) = self.filtered_after(p, until);
            let duration = until - elapsed;
            out.push((duration, value, (end - value) / duration));
            value = end;
            elapsed = until;
        }
        Some(out)
    }

    /// The lag's output `after` seconds past the last communication point: the exact solution
    /// of the first-order lag driven by the slew limit's output, a ramp u₀ + b s and a hold,
    /// y(s) = u₀ + b (s − τ) + (y₀ − u₀ + b τ) e^{−s/τ} over each piece.
    fn lagged_after(&self, p: &Parameters, after: f64) -> f64 {
        let lag = p.command_lag;
        let mut y = self.lagged;
        for (duration, start, rate) in self.slew_pieces(p, after) {
            y = start + rate * (duration - lag) + (y - start + rate * lag) * (-duration / lag).exp();
        }
        y
    }

    /// With the lag on (and no filter after it) and fast beside `step` (the step longer than
    /// a quarter of the lag), the command the driver sees over the step as linear pieces
    /// between the lag's exact values, each at most a quarter of the lag long and at most
    /// [`MAX_FILTER_PIECES`] of them; `None` when one ramp does ([`Self::rate_over`]). The
    /// chord of an exponential over a quarter of its time constant departs from it by less
    /// than 1/128 of the way it moves.
    fn lag_pieces_over(&self, p: &Parameters, step: f64) -> Option<Pieces> {
        if p.command_lag <= 0.0 {
            return None;
        }
        let pieces = (4.0 * step / p.command_lag).ceil().min(MAX_FILTER_PIECES as f64);
        if pieces < 2.0 {
            return None;
        }
        let pieces = pieces as usize;
        let mut out = smallvec::SmallVec::new();
        let (mut value, mut elapsed) = (self.lagged, 0.0);
        for k in 1..=pieces {
            let until = step * k as f64 / pieces as f64;
            let end = self.lagged_after(p, until);
            let duration = until - elapsed;
            out.push((duration, value, (end - value) / duration));
            value = end;
            elapsed = until;
        }
        Some(out)
    }

    /// The command before the second-order filter.
    fn unfiltered(&self, p: &Parameters) -> f64 {
        if p.command_lag > 0.0 {
            self.lagged
        } else {
            self.held
        }
    }

    /// The lag's output, the second-order filter's output and its rate at the last
    /// communication point: the continuous states of [`super::sensors::first_order_rate`]
    /// and [`super::sensors::second_order_rates`] (the lag driven by [`static_map`] of the
    /// command, the filter by the lag's output, or by the static map without the lag).
    pub fn dynamic_states(&self) -> [f64; 3] {
        [self.lagged, self.filtered, self.filtered_rate]
    }

    /// The stage as numbers (for FMU states): time, held, target, lagged, filtered and its
    /// rate.
    pub fn to_values(&self) -> [f64; VALUES] {
        [
            self.time,
            self.held,
            self.target,
            self.lagged,
            self.filtered,
            self.filtered_rate,
        ]
    }

    pub fn from_values(values: [f64; VALUES]) -> Self {
        Self {
            time: values[0],
            held: values[1],
            target: values[2],
            lagged: values[3],
            filtered: values[4],
            filtered_rate: values[5],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The commands the current driver sees at each sample of a recording.
    fn seen_commands(p: &Parameters, time: &[f64], v_da: &[f64]) -> Vec<f64> {
        if !is_active(p) || time.is_empty() {
            return v_da.to_vec();
        }
        let mut stage = CommandStage::at_rest(p, time[0], v_da[0]);
        time.iter().zip(v_da).map(|(&t, &v)| stage.next(p, t, v)).collect()
    }

    #[test]
    fn with_every_term_off_the_driver_sees_the_command_itself() {
        let p = Parameters::default();
        let t = [0.0, 0.001, 0.002, 0.003];
        let v = [1.0, 5.0, -3.0, 0.25];
        assert_eq!(seen_commands(&p, &t, &v), v.to_vec());
    }

    #[test]
    fn a_six_bit_converter_rounds_or_truncates_the_command_onto_its_levels() {
        // 64 levels over ±10 V: 0.3125 V apart, 0 V among them.
        let rounding = Parameters {
            command_quantum: 0.3125,
            ..Parameters::default()
        };
        let t = [0.0, 0.001, 0.002, 0.003, 0.004];
        let v = [0.1, 0.2, 0.3, -0.2, 9.99];
        assert_eq!(
            seen_commands(&rounding, &t, &v),
            vec![0.0, 0.3125, 0.3125, -0.3125, 10.0]
        );
        let truncating = Parameters {
            command_quantum_threshold: 1.0,
            ..rounding
        };
        assert_eq!(seen_commands(&truncating, &t, &v), vec![0.0, 0.0, 0.0, -0.3125, 9.6875]);
        // Levels through 0.1 V instead: 0.1 + k 0.3125.
        let shifted = Parameters {
            command_quantum_origin: 0.1,
            ..rounding
        };
        let seen = seen_commands(&shifted, &t, &v);
        for (got, want) in seen.iter().zip([0.1, 0.1, 0.4125, -0.2125, 10.1]) {
            assert!((got - want).abs() < 1e-12, "{seen:?}");
        }
    }

    #[test]
    fn a_one_sided_limit_clips_its_own_side_alone() {
        let t = [0.0, 0.001, 0.002, 0.003];
        let v = [-9.5, 5.0, 7.5, 9.0];
        let upper = Parameters {
            command_upper_limit: 7.0,
            ..Parameters::default()
        };
        assert_eq!(seen_commands(&upper, &t, &v), vec![-9.5, 5.0, 7.0, 7.0]);
        let lower = Parameters {
            command_lower_limit: 0.5,
            ..Parameters::default()
        };
        assert_eq!(seen_commands(&lower, &t, &v), vec![0.5, 5.0, 7.5, 9.0]);
        // Beside the symmetric limit, the tighter of the two on each side.
        let both = Parameters {
            command_limit: 8.0,
            command_upper_limit: 9.5,
            command_lower_limit: -2.0,
            ..Parameters::default()
        };
        assert_eq!(seen_commands(&both, &t, &v), vec![-2.0, 5.0, 7.5, 8.0]);
    }

    #[test]
    fn a_lower_limit_at_or_above_the_upper_one_is_refused_naming_both() {
        let p = Parameters {
            command_upper_limit: 2.0,
            command_lower_limit: 2.0,
            ..Parameters::default()
        };
        let e = p.validate().unwrap_err();
        assert!(
            e.contains("command_lower_limit = 2 V") && e.contains("command_upper_limit = 2 V"),
            "{e}"
        );
    }

    #[test]
    fn a_lagged_step_reaches_63_percent_after_one_time_constant() {
        let p = Parameters {
            command_lag: 0.01,
            ..Parameters::default()
        };
        let t: Vec<f64> = (0..=20).map(|k| k as f64 * 1e-3).collect();
        let mut v = vec![0.0; t.len()];
        v[1..].iter_mut().for_each(|x| *x = 1.0);
        let seen = seen_commands(&p, &t, &v);
        // The step is applied at t = 1 ms; 10 ms later the lag has 1 − e⁻¹ of it.
        assert!((seen[11] - (1.0 - (-1.0f64).exp())).abs() < 1e-12, "{}", seen[11]);
        assert_eq!(seen[1], 0.0, "a lag does not pass a step at once");
    }

    #[test]
    fn a_filtered_step_follows_the_second_order_step_response_at_every_sample() {
        // The filter's input held between samples is the step itself, so the samples lie on
        // the continuous response 1 − e^{−ζωt} (cos ω_d t + ζ/√(1−ζ²) sin ω_d t).
        for (frequency, damping) in [(40.0, 0.3), (40.0, std::f64::consts::FRAC_1_SQRT_2), (15.0, 0.95)] {
            let p = Parameters {
                command_filter_frequency: frequency,
                command_filter_damping: damping,
                ..Parameters::default()
            };
            let t: Vec<f64> = (0..=60).map(|k| k as f64 * 1e-3).collect();
            let mut v = vec![0.0; t.len()];
            v[1..].iter_mut().for_each(|x| *x = 2.0);
            let seen = seen_commands(&p, &t, &v);
            let omega = 2.0 * std::f64::consts::PI * frequency;
            let omega_d = omega * (1.0 - damping * damping).sqrt();
            for k in 1..t.len() {
                let s = t[k] - 1e-3;
                let response = 1.0
                    - (-damping * omega * s).exp()
                        * ((omega_d * s).cos() + damping / (1.0 - damping * damping).sqrt() * (omega_d * s).sin());
                assert!(
                    (seen[k] - 2.0 * response).abs() < 1e-12,
                    "{frequency} Hz, ζ {damping}, sample {k}: {} against {}",
                    seen[k],
                    2.0 * response
                );
            }
        }
    }

    /// A 460 Hz filter over a 4 ms step (a 250 Hz recording): the pieces meet the continuous
    /// step response at their nodes, a quarter period apart at most, and join end to end.
    #[test]
    fn a_filter_fast_beside_the_step_is_cut_into_pieces_on_its_step_response() {
        let (frequency, damping) = (460.0, 0.7);
        let p = Parameters {
            command_filter_frequency: frequency,
            command_filter_damping: damping,
            ..Parameters::default()
        };
        let mut stage = CommandStage::at_rest(&p, 0.0, 0.0);
        stage.next(&p, 0.0, 2.0);
        let step = 4e-3;
        let pieces = stage.pieces_over(&p, step).expect("fast beside the step");
        assert_eq!(pieces.len(), 8, "ceil(4 f h) = ceil(7.36)");
        let omega = 2.0 * std::f64::consts::PI * frequency;
        let omega_d = omega * (1.0 - damping * damping).sqrt();
        let response = |s: f64| {
            2.0 * (1.0
                - (-damping * omega * s).exp()
                    * ((omega_d * s).cos() + damping / (1.0 - damping * damping).sqrt() * (omega_d * s).sin()))
        };
        let mut start = 0.0;
        for (duration, value, rate) in &pieces {
            assert!(*duration <= 0.25 / frequency + 1e-15);
            assert!((value - response(start)).abs() < 1e-12, "at {start}: {value}");
            let end = value + rate * duration;
            start += duration;
            assert!((end - response(start)).abs() < 1e-12, "at {start}: {end}");
        }
        assert!((start - step).abs() < 1e-15);
        // Slow beside the step: one ramp, as before.
        let slow = Parameters {
            command_filter_frequency: 30.0,
            ..p.clone()
        };
        assert!(CommandStage::at_rest(&slow, 0.0, 0.0)
            .pieces_over(&slow, 1e-3)
            .is_none());
    }

    #[test]
    fn a_filter_after_a_lag_takes_the_lags_output_held_over_each_step() {
        let p = Parameters {
            command_lag: 0.005,
            command_filter_frequency: 50.0,
            command_filter_damping: 1.0,
            ..Parameters::default()
        };
        let lag_only = Parameters {
            command_filter_frequency: 0.0,
            ..p.clone()
        };
        let t: Vec<f64> = (0..=40).map(|k| k as f64 * 1e-3).collect();
        let mut v = vec![0.0; t.len()];
        v[1..].iter_mut().for_each(|x| *x = 1.0);
        let lagged = seen_commands(&lag_only, &t, &v);
        let both = seen_commands(&p, &t, &v);
        // The filter alone, driven by the lag's samples.
        let filter = Parameters {
            command_lag: 0.0,
            ..p.clone()
        };
        let refiltered = seen_commands(&filter, &t, &lagged);
        for k in 0..t.len() {
            assert!(
                (both[k] - refiltered[k]).abs() < 1e-12,
                "{k}: {} against {}",
                both[k],
                refiltered[k]
            );
        }
        assert!(both[10] < lagged[10], "the filter slows the lagged step further");
    }

    #[test]
    fn a_slew_limit_turns_a_step_into_a_ramp_of_the_limit_over_k_cd() {
        let p = Parameters {
            current_slew_limit: 0.4,
            ..Parameters::default()
        };
        let rate = 0.4 / p.k_cd; // V/s
                                 // Applied at 1 ms, the step of 5 V starts there and is reached rate · 1 ms short of
                                 // the end of the ramp's 5 / rate seconds.
        let t: Vec<f64> = (0..=5).map(|k| k as f64 * 1e-3).collect();
        let seen = seen_commands(&p, &t, &[0.0, 5.0, 5.0, 5.0, 5.0, 5.0]);
        for k in 1..=5 {
            assert!(
                (seen[k] - rate * 1e-3 * (k - 1) as f64).abs() < 1e-12,
                "{k}: {}",
                seen[k]
            );
        }
        let mut stage = CommandStage::at_rest(&p, 0.0, 0.0);
        stage.next(&p, 0.0, 5.0);
        assert!(stage.pieces_over(&p, 1e-3).is_none(), "a ramp over the whole step");
        assert!((stage.rate_over(&p, 1e-3) - rate).abs() < 1e-9 * rate);
    }

    /// A step of 0.05 V at 0.4 A/s (10 V/s with k_cd = 0.04 A/V) is reached 5 ms into a 10 ms step: the
    /// driver sees the ramp, then the command held, as a driver whose di/dt is limited would.
    #[test]
    fn a_slew_limit_reaches_the_command_within_the_step_and_holds_it_there() {
        let p = Parameters {
            current_slew_limit: 0.4,
            ..Parameters::default()
        };
        let rate = 0.4 / p.k_cd;
        let mut stage = CommandStage::at_rest(&p, 0.0, 1.0);
        assert_eq!(stage.next(&p, 0.0, 1.05), 1.0, "the command does not jump");
        let pieces = stage.pieces_over(&p, 0.01).expect("the ramp ends within the step");
        assert_eq!(pieces.len(), 2);
        let (ramp, hold) = (pieces[0], pieces[1]);
        assert!((ramp.0 - 0.05 / rate).abs() < 1e-12 && ramp.1 == 1.0 && (ramp.2 - rate).abs() < 1e-9);
        assert!((ramp.0 - 5e-3).abs() < 1e-12);
        assert!((ramp.0 + hold.0 - 0.01).abs() < 1e-15 && (hold.1 - 1.05).abs() < 1e-15 && hold.2 == 0.0);
        assert!((stage.next(&p, 0.01, 1.05) - 1.05).abs() < 1e-15);
        assert!(stage.pieces_over(&p, 0.01).is_none() && stage.rate_over(&p, 0.01) == 0.0);
    }

    /// Behind a slew limit, the lag's value at each communication point is the continuous
    /// response of y' = (u − y)/τ to the slew's ramp: against a fine integration with the input
    /// taken at each small step's middle.
    #[test]
    fn a_lag_behind_a_slew_limit_follows_the_ramp_as_it_moves() {
        let p = Parameters {
            current_slew_limit: 2.0,
            command_lag: 3e-3,
            ..Parameters::default()
        };
        let rate = 2.0 / p.k_cd;
        let t: Vec<f64> = (0..=10).map(|k| k as f64 * 2e-3).collect();
        let mut v = vec![0.0; t.len()];
        v[1..].iter_mut().for_each(|x| *x = 0.1 * rate * 10e-3);
        let seen = seen_commands(&p, &t, &v);
        let (h, mut y) = (1e-7, 0.0);
        let mut s = 0.0;
        for k in 2..t.len() {
            while s < t[k] - 2e-3 - h / 2.0 {
                let u = (rate * (s + h / 2.0)).min(v[1]);
                y += (1.0 - (-h / p.command_lag).exp()) * (u - y);
                s += h;
            }
            assert!((seen[k] - y).abs() < 1e-6 * v[1], "{k}: {} against {y}", seen[k]);
        }
    }

    #[test]
    fn a_current_limit_clips_the_command_where_the_current_reaches_it() {
        let p = Parameters {
            current_limit: 0.2,
            ..Parameters::default()
        };
        let v = static_map(&p, 10.0);
        assert!((current_driver::static_current(p.k_cd, p.i_offset, v) - 0.2).abs() < 1e-12);
        assert_eq!(static_map(&p, 1.0), 1.0);
    }

    /// A 5.8 ms lag over the 2 ms and 4 ms steps of 500 Hz and 250 Hz recordings: the driver
    /// sees the lag's continuous response to the step applied at the step's start, not its
    /// value at the start held.
    #[test]
    fn a_lag_moves_within_the_step_along_its_exponential() {
        let lag = 5.8e-3;
        let p = Parameters {
            command_lag: lag,
            ..Parameters::default()
        };
        for step in [2e-3, 4e-3, 1e-4] {
            let mut stage = CommandStage::at_rest(&p, 0.0, 0.0);
            stage.next(&p, 0.0, 3.0);
            let exact = |s: f64| 3.0 * (1.0 - (-s / lag).exp());
            let seen: Vec<(f64, f64, f64)> = match stage.pieces_over(&p, step) {
                Some(pieces) => pieces.to_vec(),
                None => vec![(step, stage.current(&p), stage.rate_over(&p, step))],
            };
            let mut start = 0.0;
            for (duration, value, rate) in seen {
                assert!(
                    duration <= 0.25 * lag + 1e-15 || step < 0.25 * lag,
                    "{step}: {duration}"
                );
                assert!((value - exact(start)).abs() < 1e-12, "{step}, at {start}: {value}");
                for j in 1..=4 {
                    let s = duration * j as f64 / 4.0;
                    let chord = value + rate * s;
                    // Chord and exponential part by at most (duration/lag)²/8 of the move.
                    let bound = 3.0 * (duration / lag).powi(2) / 8.0 + 1e-12;
                    assert!(
                        (chord - exact(start + s)).abs() <= bound,
                        "{step}, at {}: {chord}",
                        start + s
                    );
                }
                start += duration;
            }
            assert!((start - step).abs() < 1e-15);
            // The next communication point holds the lag's exact value.
            assert!((stage.next(&p, step, 3.0) - exact(step)).abs() < 1e-12);
        }
    }
}
