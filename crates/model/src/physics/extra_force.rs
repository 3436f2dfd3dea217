//! An extra force in the piston's balance (2.36), off by default: a sum of coefficients
//! times local signals at the piston, a library from which the diagnosis picks sparsely.
//!
//! The force the sensor reads, where the pressures set it, becomes
//! F = A_p (P1 − P2) − F_f − b v − k (x_s − x_0) + Σ c_j φ_j with
//!
//! | coefficient | signal φ_j | a physical reading |
//! |---|---|---|
//! | `extra_force_acceleration` (kg) | a, the stopper acceleration | a moving mass m: c = −m |
//! | `extra_force_velocity_squared` (N·s²/m²) | v \|v\| | quadratic (turbulent) damping: c < 0 |
//! | `extra_force_sign_pressure` (m²) | tanh(v / v_e) (P1 + P2 − 2 P_r) | a seal friction growing with the pressure: c < 0 |
//! | `extra_force_pressure_difference` (m²) | P1 − P2 | an error of the piston's effective area |
//!
//! The viscous term b v (`viscous_friction`), the spring on the stopper position
//! (`position_force_rate`) and Coulomb friction (the named `piston_friction`) are the
//! library's other members; they keep their parameters.
//!
//! **The stopper acceleration.** The stopper position is an input that moves linearly
//! between samples (or communication steps), so its second derivative is a train of
//! impulses. The acceleration the model uses is the rate of the stopper's piecewise-constant
//! velocity across the last two intervals: after an interval of length h in which the
//! stopper moved at the mean velocity v, following one of length h' at v',
//! a = (v − v') / ((h + h')/2) ([`StopperMotion`]). It is the second difference of the
//! positions: exact for a steady acceleration, one interval late (the acceleration at the
//! previous sample), no filter to bias or delay it further. The intervals are the
//! recording's samples (the diagnosis) or the FMU's communication steps: the FMU driven
//! at the recording's samples forms the same acceleration. At rest before the first
//! interval (v' = 0, h' = h).
//!
//! **The stopper velocity.** The velocity-dependent forces (friction, viscous friction,
//! v|v|, the seal's sign) read the velocity at the sample, v + a h / 2 with the
//! interval's mean v and the acceleration a above ([`velocity_at_sample`]), not the mean
//! itself, which is the velocity half an interval earlier: under a 2.5 Hz, 10 mm shake
//! sampled at 250 Hz that half interval is 2 ms, and quadratic damping of 300 N·s²/m² read
//! with it left 0.09 N (three times the noise) that no term explains.

/// The stopper's velocity at the end of an interval of length `interval` over which it moved
/// at the mean velocity `mean`, accelerating at `acceleration` ([`StopperMotion::advance`]):
/// the mean is the velocity at the interval's middle, half an interval before the sample.
pub fn velocity_at_sample(mean: f64, interval: f64, acceleration: f64) -> f64 {
    mean + 0.5 * interval * acceleration
}

/// The stopper's motion over the last interval, from which the next acceleration is formed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StopperMotion {
    /// The mean velocity over the last interval (m/s) and its length (s; 0 before the first).
    pub velocity: f64,
    pub interval: f64,
}

impl StopperMotion {
    pub fn at_rest() -> Self {
        Self {
            velocity: 0.0,
            interval: 0.0,
        }
    }

    /// The acceleration after an interval of `length` seconds at the mean velocity
    /// `velocity`, which becomes the last interval.
    pub fn advance(&mut self, velocity: f64, length: f64) -> f64 {
        let before = if self.interval > 0.0 { self.interval } else { length };
        let acceleration = (velocity - self.velocity) / (0.5 * (length + before));
        self.velocity = velocity;
        self.interval = length;
        acceleration
    }
}

/// The stopper velocity the forces read at each sample of a motion sampled at `time` (s)
/// and `x_s` (m), moving linearly between samples, from rest at the first
/// ([`velocity_at_sample`] with [`stopper_accelerations`]).
pub fn stopper_velocities(time: &[f64], x_s: &[f64]) -> Vec<f64> {
    let accelerations = stopper_accelerations(time, x_s);
    (0..x_s.len())
        .map(|k| {
            if k == 0 {
                return 0.0;
            }
            let h = time[k] - time[k - 1];
            velocity_at_sample((x_s[k] - x_s[k - 1]) / h, h, accelerations[k])
        })
        .collect()
}

/// The stopper acceleration at each sample of a motion sampled at `time` (s) and `x_s`
/// (m), moving linearly between samples, from rest at the first: what the model forms
/// when stepped from sample to sample.
pub fn stopper_accelerations(time: &[f64], x_s: &[f64]) -> Vec<f64> {
    let mut motion = StopperMotion::at_rest();
    let mut out = Vec::with_capacity(x_s.len());
    if !x_s.is_empty() {
        out.push(0.0);
    }
    for k in 1..x_s.len() {
        let h = time[k] - time[k - 1];
        out.push(motion.advance((x_s[k] - x_s[k - 1]) / h, h));
    }
    out
}

/// The library's signals other than the stopper's position and velocity, where the
/// pressures set the force: (v|v|, smooth sign × pressure sum, pressure difference).
pub fn signals(stopper_velocity: f64, sign_velocity: f64, p1: f64, p2: f64, p_r: f64) -> [f64; 3] {
    let v = stopper_velocity;
    [v * v.abs(), (v / sign_velocity).tanh() * (p1 + p2 - 2.0 * p_r), p1 - p2]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_velocity_at_the_sample_follows_a_sampled_sine_where_the_intervals_mean_lags_it() {
        // 2.5 Hz, 10 mm at 250 Hz: the mean of an interval is the velocity 2 ms earlier,
        // 0.031 of the amplitude 0.157 m/s off; 1.5 v̄₁ − 0.5 v̄₀ of the last two means is
        // v (1 + (ω h)²/3) to leading order.
        let w = 2.0 * std::f64::consts::PI * 2.5;
        let h = 4e-3;
        let time: Vec<f64> = (0..500).map(|k| k as f64 * h).collect();
        let x: Vec<f64> = time.iter().map(|t| 0.054 + 0.01 * (w * t).sin()).collect();
        let at_sample = stopper_velocities(&time, &x);
        let (mut worst_sample, mut worst_mean) = (0.0f64, 0.0f64);
        for k in 2..time.len() {
            let truth = 0.01 * w * (w * time[k]).cos();
            worst_sample = worst_sample.max((at_sample[k] - truth).abs());
            worst_mean = worst_mean.max(((x[k] - x[k - 1]) / h - truth).abs());
        }
        let amplitude = 0.01 * w;
        assert!(worst_sample < 0.4 * (w * h).powi(2) * amplitude, "{worst_sample} m/s");
        assert!(worst_mean > 0.025 * amplitude, "{worst_mean} m/s");
    }

    #[test]
    fn a_steady_acceleration_is_read_exactly_and_a_sine_one_interval_late() {
        // x = A t²/2 at 250 Hz: A at every sample after the first two.
        let a = 2.0;
        let time: Vec<f64> = (0..100).map(|k| k as f64 * 4e-3).collect();
        let x: Vec<f64> = time.iter().map(|t| 0.05 + 0.5 * a * t * t).collect();
        let acc = stopper_accelerations(&time, &x);
        for &value in &acc[2..] {
            assert!((value / a - 1.0).abs() < 1e-6, "{value}");
        }
        // 2.5 Hz, 10 mm at 1 kHz: −ω² x at the sample before, within 0.1 %.
        let w = 2.0 * std::f64::consts::PI * 2.5;
        let time: Vec<f64> = (0..1000).map(|k| k as f64 * 1e-3).collect();
        let x: Vec<f64> = time.iter().map(|t| 0.05 + 0.01 * (w * t).sin()).collect();
        let acc = stopper_accelerations(&time, &x);
        for k in 2..1000 {
            let truth = -0.01 * w * w * (w * time[k - 1]).sin();
            assert!((acc[k] - truth).abs() < 1e-3 * 0.01 * w * w, "{k}: {} {truth}", acc[k]);
        }
    }
}
