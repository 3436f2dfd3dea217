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
//! **Products of the mechanics' signals.** Beside the hand-picked members, three slots
//! (`extra_force_product_k_*`, k = 1..3, off with a coefficient of 0) each add
//! c_k g₁ g₂ to the force the sensor reads where the pressures set it, with
//! g₁ = (s₁ − o_k) / r₁ and g₂ = s₂ / r₂ two of the signals below ([`ProductSignal`]), o_k the
//! slot's origin (subtracted from the first signal, in its SI unit: it writes x_s − x₀) and
//! r the signal's reference unit, so that the coefficient c_k is a force (N): c > 0 adds to
//! the force the sensor reads (the same sign as the library's coefficients above).
//!
//! | code | signal s | reference unit r |
//! |---|---|---|
//! | 0 | the constant 1 (no factor; the origin is ignored) | 1 |
//! | 1 | x_s, the stopper position | 10 mm |
//! | 2 | v, the stopper velocity | 0.1 m/s |
//! | 3 | tanh(v / `extra_force_sign_velocity`), its smooth sign | 1 |
//! | 4 | a, the stopper acceleration | 1 m/s² |
//! | 5 | \|v\| | 0.1 m/s |
//! | 6 | P1 − P_r | 1 bar (1e5 Pa) |
//! | 7 | P2 − P_r | 1 bar (1e5 Pa) |
//!
//! The velocity and the acceleration are the library's (below); the diagnosis forms its
//! regressors with [`ProductSlot::regressor`] from the same signals.
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
//!
//! Where the motion from the sample on is known (a recording's next sample, or an FMU
//! master that sets der(x_s) for the coming step before it reads the outputs), the sample
//! lies between two known intervals ([`velocity_between_intervals`]). A motion that ran
//! steady and turns at the sample (a triangle's reversal, the start or end of a ramp) is
//! moving at the new interval's velocity from the sample on, as the command held from the
//! sample is the new one: read with the old interval's, a 2.8 N friction of a stopper
//! reversing at 27 mm/s, sampled at 250 Hz, was off by 5.6 N at every reversal (0.42 N RMS
//! over a recording, 15 noise floors) where the new interval's velocity leaves the noise.
//! A motion whose velocity was already changing (a sine) reads the mean of the two
//! intervals' velocities, as accurate there as the extrapolation above.

/// The stopper's velocity at the end of an interval of length `interval` over which it moved
/// at the mean velocity `mean`, accelerating at `acceleration` ([`StopperMotion::advance`]):
/// the mean is the velocity at the interval's middle, half an interval before the sample.
pub fn velocity_at_sample(mean: f64, interval: f64, acceleration: f64) -> f64 {
    mean + 0.5 * interval * acceleration
}

/// Whether a motion that moved at the mean velocity `before` over the last interval, its
/// velocity having changed by `change_before` from the interval preceding it, turns at
/// the sample into the coming interval at `next`: it ran steady before (its change at most
/// a quarter of the turn), and the turn is a quarter of its speed or more (near its
/// extreme, a sampled sine's velocity changes little and by either sign).
pub fn turns_at_sample(before: f64, change_before: f64, next: f64) -> bool {
    let turn = (next - before).abs();
    change_before.abs() <= 0.25 * turn && turn >= 0.25 * before.abs().max(next.abs())
}

/// The stopper's velocity at a sample between an interval at the mean velocity `before`,
/// over which the velocity had changed by `change_before`, and the coming interval at
/// `next` (see the module's notes): `next` where the motion turns at the sample
/// ([`turns_at_sample`]) or turned at the sample before (its corner lay within the last
/// interval, which then holds neither velocity), the mean of the two otherwise.
pub fn velocity_between_intervals(before: f64, change_before: f64, next: f64, turned_before: bool) -> f64 {
    if turned_before || turns_at_sample(before, change_before, next) {
        next
    } else {
        0.5 * (before + next)
    }
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
/// and `x_s` (m), moving linearly between samples, at rest before the first: between the
/// intervals on either side ([`velocity_between_intervals`]), at the last sample
/// [`velocity_at_sample`] with [`stopper_accelerations`].
pub fn stopper_velocities(time: &[f64], x_s: &[f64]) -> Vec<f64> {
    let accelerations = stopper_accelerations(time, x_s);
    let n = x_s.len();
    let mut turned_before = false;
    (0..n)
        .map(|k| {
            let next = (k + 1 < n).then(|| (x_s[k + 1] - x_s[k]) / (time[k + 1] - time[k]));
            let (before, change_before) = if k == 0 {
                (0.0, 0.0)
            } else {
                let h = time[k] - time[k - 1];
                ((x_s[k] - x_s[k - 1]) / h, accelerations[k] * h)
            };
            let turned = std::mem::replace(
                &mut turned_before,
                next.map_or(false, |next| turns_at_sample(before, change_before, next)),
            );
            match (k, next) {
                (_, Some(next)) => velocity_between_intervals(before, change_before, next, turned),
                (0, None) => 0.0,
                (_, None) => velocity_at_sample(before, time[k] - time[k - 1], accelerations[k]),
            }
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

/// The signals of the product slots, by code (see the module's table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProductSignal {
    One,
    Position,
    Velocity,
    Sign,
    Acceleration,
    Speed,
    Pressure1,
    Pressure2,
}

/// The number of extra force product slots.
pub const PRODUCT_SLOTS: usize = 3;

/// The largest signal code of a product slot.
pub const LAST_PRODUCT_CODE: u32 = 7;

impl ProductSignal {
    pub const ALL: [ProductSignal; 8] = [
        ProductSignal::One,
        ProductSignal::Position,
        ProductSignal::Velocity,
        ProductSignal::Sign,
        ProductSignal::Acceleration,
        ProductSignal::Speed,
        ProductSignal::Pressure1,
        ProductSignal::Pressure2,
    ];

    pub fn code(self) -> u32 {
        self as u32
    }

    /// The signal of a code, if it is a whole number from 0 to [`LAST_PRODUCT_CODE`].
    pub fn from_code(code: f64) -> Option<Self> {
        if code.fract() != 0.0 || !(0.0..=LAST_PRODUCT_CODE as f64).contains(&code) {
            return None;
        }
        Some(Self::ALL[code as usize])
    }

    /// A short name, as the readings write it.
    pub fn name(self) -> &'static str {
        match self {
            ProductSignal::One => "1",
            ProductSignal::Position => "x_s",
            ProductSignal::Velocity => "v",
            ProductSignal::Sign => "sign(v)",
            ProductSignal::Acceleration => "a",
            ProductSignal::Speed => "|v|",
            ProductSignal::Pressure1 => "(P1 − P_r)",
            ProductSignal::Pressure2 => "(P2 − P_r)",
        }
    }

    /// The signal's SI unit (of the origin, for the first factor).
    pub fn unit(self) -> &'static str {
        match self {
            ProductSignal::One | ProductSignal::Sign => "1",
            ProductSignal::Position => "m",
            ProductSignal::Velocity | ProductSignal::Speed => "m/s",
            ProductSignal::Acceleration => "m/s²",
            ProductSignal::Pressure1 | ProductSignal::Pressure2 => "Pa",
        }
    }

    /// The reference unit r in SI units: the factor is the signal over it.
    pub fn reference(self) -> f64 {
        match self {
            ProductSignal::One | ProductSignal::Sign | ProductSignal::Acceleration => 1.0,
            ProductSignal::Position => 0.01,
            ProductSignal::Velocity | ProductSignal::Speed => 0.1,
            ProductSignal::Pressure1 | ProductSignal::Pressure2 => 1e5,
        }
    }

    /// The reference unit in words.
    pub fn reference_text(self) -> &'static str {
        match self {
            ProductSignal::One | ProductSignal::Sign => "1",
            ProductSignal::Position => "10 mm",
            ProductSignal::Velocity | ProductSignal::Speed => "0.1 m/s",
            ProductSignal::Acceleration => "1 m/s²",
            ProductSignal::Pressure1 | ProductSignal::Pressure2 => "1 bar",
        }
    }

    /// The signal's value in its SI unit.
    pub fn value(self, m: &MechanicsSignals) -> f64 {
        match self {
            ProductSignal::One => 1.0,
            ProductSignal::Position => m.x_s,
            ProductSignal::Velocity => m.velocity,
            ProductSignal::Sign => (m.velocity / m.sign_velocity).tanh(),
            ProductSignal::Acceleration => m.acceleration,
            ProductSignal::Speed => m.velocity.abs(),
            ProductSignal::Pressure1 => m.p1 - m.p_r,
            ProductSignal::Pressure2 => m.p2 - m.p_r,
        }
    }
}

/// The mechanics' signals at a sample, from which the product slots' factors are formed:
/// the stopper position, its velocity at the sample and acceleration as the library forms
/// them, the smooth sign's velocity, the chamber and return pressures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MechanicsSignals {
    pub x_s: f64,
    pub velocity: f64,
    pub acceleration: f64,
    pub sign_velocity: f64,
    pub p1: f64,
    pub p2: f64,
    pub p_r: f64,
}

/// One product slot's settings: the two signal codes, the first's origin and the
/// coefficient (N; 0 = off).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ProductSlot {
    pub first: f64,
    pub second: f64,
    pub origin: f64,
    pub coefficient: f64,
}

impl ProductSlot {
    pub fn is_on(&self) -> bool {
        self.coefficient != 0.0
    }

    /// g₁ g₂: the first signal less the origin over its reference unit, times the second
    /// over its own (the constant 1 for code 0, whose origin is ignored). Codes out of range
    /// read as 0 ([`check_products`] refuses them before a model is built).
    pub fn regressor(&self, m: &MechanicsSignals) -> f64 {
        let (first, second) = match (
            ProductSignal::from_code(self.first),
            ProductSignal::from_code(self.second),
        ) {
            (Some(first), Some(second)) => (first, second),
            _ => return 0.0,
        };
        let g1 = match first {
            ProductSignal::One => 1.0,
            s => (s.value(m) - self.origin) / s.reference(),
        };
        g1 * (second.value(m) / second.reference())
    }
}

/// Σ c_k g₁ g₂ over the slots that are on: the force (N) the products add to the force the
/// sensor reads where the pressures set it.
pub fn product_force(slots: &[ProductSlot; PRODUCT_SLOTS], m: &MechanicsSignals) -> f64 {
    slots
        .iter()
        .filter(|slot| slot.is_on())
        .map(|slot| slot.coefficient * slot.regressor(m))
        .sum()
}

/// Whether a product slot is on.
pub fn products_on(slots: &[ProductSlot; PRODUCT_SLOTS]) -> bool {
    slots.iter().any(ProductSlot::is_on)
}

/// The slot (0-based) and field of a product slot's value reference.
pub fn product_field_mut(slots: &mut [ProductSlot; PRODUCT_SLOTS], value_reference: u32) -> Option<&mut f64> {
    use crate::variables::vr;
    if !(vr::EXTRA_FORCE_PRODUCT_1_FIRST..=vr::EXTRA_FORCE_PRODUCT_LAST).contains(&value_reference) {
        return None;
    }
    let offset = value_reference - vr::EXTRA_FORCE_PRODUCT_1_FIRST;
    let slot = &mut slots[(offset / vr::EXTRA_FORCE_PRODUCT_STRIDE) as usize];
    match offset % vr::EXTRA_FORCE_PRODUCT_STRIDE {
        0 => Some(&mut slot.first),
        1 => Some(&mut slot.second),
        2 => Some(&mut slot.origin),
        3 => Some(&mut slot.coefficient),
        _ => None,
    }
}

/// The slots' signal codes whole numbers from 0 to [`LAST_PRODUCT_CODE`] (run with
/// `Parameters::validate`; a setter takes any value within the row's limits, as the
/// modulation slots' codes).
pub fn check_products(slots: &[ProductSlot; PRODUCT_SLOTS]) -> Result<(), String> {
    for (k, slot) in slots.iter().enumerate() {
        for (field, code) in [("first", slot.first), ("second", slot.second)] {
            if ProductSignal::from_code(code).is_none() {
                return Err(format!(
                    "extra_force_product_{}_{field} = {} is invalid: must be a whole number from 0 to {LAST_PRODUCT_CODE} ({})",
                    k + 1,
                    crate::variables::number(code),
                    ProductSignal::ALL
                        .iter()
                        .map(|&s| match s {
                            ProductSignal::One => "0 none (the constant 1)".to_string(),
                            s => format!("{} {} ({}, per {})", s.code(), s.name(), s.unit(), s.reference_text()),
                        })
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
        }
    }
    Ok(())
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
    fn a_triangle_reversing_between_samples_moves_at_the_coming_intervals_velocity_at_each_sample() {
        // ±27.5 mm/s at 250 Hz, the reversal 1.74 ms after the sample at 1.2 s: the interval
        // holding it moves at 3.5 mm/s on average. At the sample before it the stopper moves
        // on at that mean; at the sample after, it moves at +27.5 mm/s: neither reads the
        // interval that ended there, nor a mean of the two.
        let (h, speed, reversal) = (4e-3, 0.0275, 1.20174);
        let time: Vec<f64> = (0..600).map(|k| k as f64 * h).collect();
        let x: Vec<f64> = time
            .iter()
            .map(|&t| 0.06 - speed * (t.min(reversal) - 1.0) + speed * (t - reversal).max(0.0))
            .collect();
        let v = stopper_velocities(&time, &x);
        let at = |t: f64| (t / h).round() as usize;
        let interval = |k: usize| (x[k + 1] - x[k]) / h;
        assert!((v[at(1.2)] - interval(at(1.2))).abs() < 1e-9, "{}", v[at(1.2)]);
        assert!(interval(at(1.2)).abs() < 0.2 * speed);
        assert!((v[at(1.204)] - speed).abs() < 1e-9, "{}", v[at(1.204)]);
        assert!((v[at(1.196)] + speed).abs() < 1e-9, "{}", v[at(1.196)]);
        // A ramp starting at a sample from rest: still at the sample before, moving at it.
        let start: Vec<f64> = time.iter().map(|&t| 0.05 + 0.2 * (t - 1.0).max(0.0)).collect();
        let v = stopper_velocities(&time, &start);
        assert_eq!(v[at(0.996)], 0.0);
        assert!((v[at(1.0)] - 0.2).abs() < 1e-9, "{}", v[at(1.0)]);
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
