//! The closed forms that f3 (2.5) as a power series gives the jet pipe's response. The
//! series come from the curve (`physics::jet_pipe::StaticCurve::series`: tanh's for the
//! model's f3). With a held command the input f3(F̄ + ε e^{−ω_cd s}) is a series in
//! e^{−ω_cd s}; with a ramp once the current transient has died out, f3(α + β s) is a series
//! in s. Each term's response is known exactly, so a step's positions are two exponentials
//! plus a polynomial (`SeriesForm`, `RampForm`) instead of quadrature. The limits on the jump
//! and the horizon keep the series short and convergent; outside them, or for a curve that
//! offers no series, the trajectory integrates.

use crate::physics::jet_pipe::StaticCurve;

use super::modal::{
    growth_from, modal_bounds, modal_growth, modal_position, position_weights, ElectromechanicalPropagator,
    Exponentials,
};
use super::{Coefficients, C64, INLINE_TERMS};

/// Largest |ε|/ρ (jump over the series radius, the distance to f3's nearest singularity:
/// `StaticCurve::series_radius`) for which the series is used.
pub(super) const SERIES_RATIO_LIMIT: f64 = 0.5;
/// A larger jump is integrated by quadrature until it has decayed to this fraction of the
/// limit (rounding then cannot push the rest over it), and by the series from there.
pub(super) const LATE_SERIES_MARGIN: f64 = 0.9;
pub(super) const MAX_SERIES_TERMS: usize = 64;
/// Largest |k_m δ / F_jp_sat| (the current transient's share of f3's argument) that a
/// ramp's closed form neglects: its effect on the jet pipe is below 1e-15·x_jp_sat.
pub(super) const RAMP_TRANSIENT_LIMIT: f64 = 1e-15;
/// Largest |β T| / ρ (the ramp's change of f3's argument over the closed form's horizon,
/// over the series radius): the series terms shrink at least this fast.
pub(super) const RAMP_SERIES_RATIO: f64 = 0.2;
/// Longest horizon of a ramp's closed form, s (queries beyond it use quadrature).
pub(super) const RAMP_MAX_HORIZON: f64 = 1.0;

/// For a held command with the series form, each mode is
///   q_k(s) = e^{λk s} (q_k(0) + β_k Σₙ aₙ/(λk + nω)) − β_k Σₙ aₙ rⁿ/(λk + nω),  r = e^{−ω s},
/// so the position and its derivatives are two exponentials plus a real polynomial in r
/// whose coefficients are summed over the modes once per step, not once per query.
#[derive(Clone, Debug)]
pub(super) struct SeriesForm {
    /// q_k(0) + β_k Σₙ aₙ/(λk + nω).
    pub(super) amplitude: [C64; 3],
    /// [`position_weights`] of `amplitude`.
    pub(super) position_weights: [f64; 3],
    /// Coefficients of rⁿ in the position: −Re Σ_k β_k aₙ/(λk + nω). Those of the velocity
    /// and acceleration (moments 1 and 2 in place of 0) are summed where asked for, once per
    /// step at its end, from the series itself.
    pub(super) position: Coefficients,
    /// From when on the position's terms n ≥ 1 sum to under 1e-16 of the saturated stroke:
    /// past it the position needs neither e^{−ω s} nor the polynomial.
    pub(super) transient_over: f64,
}

impl SeriesForm {
    /// `None` when some λk + nω nearly vanishes (the term grows like s e^{λs}): the
    /// general per-query sum handles that case.
    pub(super) fn new<C>(p: &ElectromechanicalPropagator<C>, q0: &[C64; 3], series: &[f64]) -> Option<Self> {
        if series.is_empty() || series.len() > p.series_weights.len() {
            return None;
        }
        let mut amplitude = *q0;
        // Filled in an array and handed to the small vector whole: indexing a SmallVec checks
        // where it lives at every element.
        let mut inline = [0.0; INLINE_TERMS];
        let terms = series.len().min(INLINE_TERMS);
        for ((a, weight), c) in series.iter().zip(&p.series_weights).zip(&mut inline[..terms]) {
            for k in 0..3 {
                amplitude[k] += weight.modes[k] * *a;
            }
            *c = -a * weight.moments[0];
        }
        let mut position = Coefficients::from_buf_and_len(inline, terms);
        for (a, weight) in series.iter().zip(&p.series_weights).skip(INLINE_TERMS) {
            for k in 0..3 {
                amplitude[k] += weight.modes[k] * *a;
            }
            position.push(-a * weight.moments[0]);
        }
        // Σ_{n≥1} |cₙ| rⁿ ≤ r Σ|cₙ| for r ≤ 1.
        let (_, transient) = constant_and_spread(&position, 1.0);
        let negligible = 1e-16 * p.x_sat;
        let transient_over = if transient <= negligible {
            0.0
        } else {
            ln_upper_bound(transient / negligible) / p.driver.omega_cd
        };
        Some(Self {
            amplitude,
            position_weights: position_weights(&amplitude),
            position,
            transient_over,
        })
    }

    /// Modal coordinates: q_k(s) = amplitude_k e^{λk s} − Σₙ wₖ,ₙ aₙ rⁿ, for the `series` the
    /// form was built from.
    pub(super) fn modes<C>(&self, p: &ElectromechanicalPropagator<C>, series: &[f64], s: f64) -> [C64; 3] {
        let (mut q, r) = self.growth(p, s);
        let zero = C64::new(0.0, 0.0);
        let sum = series
            .iter()
            .zip(&p.series_weights)
            .rev()
            .fold([zero; 3], |acc, (a, w)| {
                [
                    acc[0] * r - w.modes[0] * *a,
                    acc[1] * r - w.modes[1] * *a,
                    acc[2] * r - w.modes[2] * *a,
                ]
            });
        for k in 0..3 {
            q[k] += sum[k];
        }
        q
    }

    /// The modal exponentials' parts e^{λk s}·amplitude_k, and r = e^{−ω s}.
    pub(super) fn growth<C>(&self, p: &ElectromechanicalPropagator<C>, s: f64) -> ([C64; 3], f64) {
        let e = p.exponentials(s, true);
        (growth_from(&self.amplitude, &e), e.decay)
    }

    /// Σ cₙ rⁿ as E(r²) + r O(r²), its even and odd parts by Horner side by side: half the
    /// dependent multiply-adds of one Horner chain, which the stage positions wait on.
    pub(super) fn horner(coefficients: &[f64], r: f64) -> f64 {
        let r2 = r * r;
        let pairs = coefficients.chunks_exact(2);
        let mut even = match pairs.remainder() {
            [highest] => *highest,
            _ => 0.0,
        };
        let mut odd = 0.0;
        for pair in pairs.rev() {
            even = even * r2 + pair[0];
            odd = odd * r2 + pair[1];
        }
        even + r * odd
    }

    pub(super) fn position<C>(&self, p: &ElectromechanicalPropagator<C>, s: f64) -> f64 {
        self.position_from(s, &p.exponentials(s, s < self.transient_over))
    }

    /// The position at `s` from the exponentials there (`decay` needed only before
    /// `transient_over`).
    pub(super) fn position_from(&self, s: f64, e: &Exponentials) -> f64 {
        let polynomial = if s >= self.transient_over {
            self.position[0]
        } else {
            Self::horner(&self.position, e.decay)
        };
        modal_position(&self.position_weights, e) + polynomial
    }

    /// Bounds on the position over [0, s_end].
    pub(super) fn position_bounds<C>(&self, p: &ElectromechanicalPropagator<C>, s_end: f64) -> (f64, f64) {
        let (constant, transient) = constant_and_spread(&self.position, 1.0);
        let (lo, hi) = modal_bounds(p, &self.amplitude, s_end);
        (lo + constant - transient, hi + constant + transient)
    }

    /// The position and its first two derivatives from the exponentials at `s` (with
    /// `decay`), for the `series` the form was built from.
    pub(super) fn derivatives_from<C>(
        &self,
        p: &ElectromechanicalPropagator<C>,
        series: &[f64],
        e: &Exponentials,
    ) -> [f64; 3] {
        let (g, r) = (growth_from(&self.amplitude, e), e.decay);
        let l = &p.lambda;
        // Σₙ −aₙ (moment m of term n) rⁿ for m = 1, 2, by Horner.
        let (velocity, acceleration) = series
            .iter()
            .zip(&p.series_weights)
            .rev()
            .fold((0.0, 0.0), |(v, a), (term, weight)| {
                (v * r - term * weight.moments[1], a * r - term * weight.moments[2])
            });
        [
            modal_position(&self.position_weights, e) + Self::horner(&self.position, r),
            (l[0] * g[0] + l[1] * g[1] + l[2] * g[2]).re + velocity,
            (l[0] * l[0] * g[0] + l[1] * l[1] * g[1] + l[2] * l[2] * g[2]).re + acceleration,
        ]
    }
}

/// For a command ramp once the current transient has died out (i(s) = i0 + ramp·s), the
/// jet pipe input u(s) = f3 at the argument α + β s is a power series in τ = s/T, Σ bₙ τⁿ, on a
/// horizon T short enough for it to converge fast. Each mode q' = λq + βu then has the
/// polynomial particular solution q_p = −β Σ_j u⁽ʲ⁾/λ^{j+1} (a finite sum), so
///   x(s) = Σ_k Re[(q_k(0) − q_p,k(0)) e^{λk s}] + P(τ),  P = Σ_j g_j u⁽ʲ⁾, g_j = −Re Σ_k β_k/λ_k^{j+1}:
/// two exponentials plus a polynomial, like [`SeriesForm`], instead of quadrature on
/// 0.1 ms panels.
#[derive(Clone, Debug)]
pub(super) struct RampForm {
    /// T, s: the form holds for 0 ≤ s ≤ T.
    pub(super) horizon: f64,
    /// q_k(0) − q_p,k(0).
    pub(super) amplitude: [C64; 3],
    /// [`position_weights`] of `amplitude`.
    pub(super) position_weights: [f64; 3],
    /// P and its first two derivatives with respect to s, as polynomials in τ.
    pub(super) polynomials: [Vec<f64>; 3],
    /// Each mode's particular solution q_p,k as a polynomial in τ.
    pub(super) particular_modes: [Vec<C64>; 3],
}

impl RampForm {
    /// `alpha`, `beta`: f3's argument α + β s. `None` when the curve offers no series or
    /// it would need too many terms.
    pub(super) fn new<C: StaticCurve>(
        p: &ElectromechanicalPropagator<C>,
        q0: &[C64; 3],
        alpha: f64,
        beta: f64,
    ) -> Option<Self> {
        let radius = p.curve.series_radius(alpha)?;
        let horizon = RAMP_MAX_HORIZON.min(RAMP_SERIES_RATIO * radius / beta.abs());
        let input = p.curve.series(alpha, beta * horizon, MAX_SERIES_TERMS, 1.0)?;
        if input.len() >= MAX_SERIES_TERMS {
            return None;
        }
        let n = input.len();
        // u^{(j)} in τ: (d/dτ)^j, and d/ds = (1/T) d/dτ.
        let derivative = |c: &[f64]| -> Vec<f64> { (1..c.len()).map(|m| m as f64 * c[m]).collect() };
        let mut amplitude = *q0;
        let mut particular = vec![0.0; n];
        let mut particular_modes = [
            vec![C64::new(0.0, 0.0); n],
            vec![C64::new(0.0, 0.0); n],
            vec![C64::new(0.0, 0.0); n],
        ];
        let mut u_j = input.to_vec();
        let mut scale = 1.0; // T^{-j}
        let mut inverse_power = [C64::new(1.0, 0.0); 3]; // λ_k^{-(j+1)}, built below
        for k in 0..3 {
            inverse_power[k] = C64::new(1.0, 0.0) / p.lambda[k];
        }
        for _ in 0..n {
            if u_j.is_empty() {
                break;
            }
            // β_k λ_k^{−(j+1)}
            let weights = [
                p.beta[0] * inverse_power[0],
                p.beta[1] * inverse_power[1],
                p.beta[2] * inverse_power[2],
            ];
            let mut g = 0.0;
            for k in 0..3 {
                // q_p,k(0) = −β_k Σ_j u^{(j)}(0) λ_k^{−(j+1)}
                amplitude[k] += weights[k] * (u_j[0] * scale);
                g -= weights[k].re;
            }
            // Element by element over the five polynomials at once (disjoint slices: no
            // aliasing for the compiler to check at run time).
            let [modes_0, modes_1, modes_2] = &mut particular_modes;
            let terms = u_j.iter().zip(particular.iter_mut());
            for ((((c, x), q_0), q_1), q_2) in terms
                .zip(modes_0.iter_mut())
                .zip(modes_1.iter_mut())
                .zip(modes_2.iter_mut())
            {
                *x += g * scale * c;
                *q_0 -= weights[0] * (scale * c);
                *q_1 -= weights[1] * (scale * c);
                *q_2 -= weights[2] * (scale * c);
            }
            u_j = derivative(&u_j);
            scale /= horizon;
            for k in 0..3 {
                inverse_power[k] /= p.lambda[k];
            }
        }
        let velocity: Vec<f64> = derivative(&particular).iter().map(|c| c / horizon).collect();
        let acceleration: Vec<f64> = derivative(&velocity).iter().map(|c| c / horizon).collect();
        Some(Self {
            horizon,
            amplitude,
            position_weights: position_weights(&amplitude),
            polynomials: [particular, velocity, acceleration],
            particular_modes,
        })
    }

    pub(super) fn covers(&self, s: f64) -> bool {
        (0.0..=self.horizon).contains(&s)
    }

    pub(super) fn growth<C>(&self, p: &ElectromechanicalPropagator<C>, s: f64) -> [C64; 3] {
        modal_growth(p, &self.amplitude, s)
    }

    pub(super) fn position<C>(&self, p: &ElectromechanicalPropagator<C>, s: f64) -> f64 {
        self.position_from(s, &p.exponentials(s, false))
    }

    pub(super) fn position_from(&self, s: f64, e: &Exponentials) -> f64 {
        modal_position(&self.position_weights, e) + SeriesForm::horner(&self.polynomials[0], s / self.horizon)
    }

    /// Bounds on the position over [0, s_end], s_end within the horizon.
    pub(super) fn position_bounds<C>(&self, p: &ElectromechanicalPropagator<C>, s_end: f64) -> (f64, f64) {
        let (constant, spread) = constant_and_spread(&self.polynomials[0], s_end / self.horizon);
        let (lo, hi) = modal_bounds(p, &self.amplitude, s_end);
        (lo + constant - spread, hi + constant + spread)
    }

    pub(super) fn derivatives<C>(&self, p: &ElectromechanicalPropagator<C>, s: f64) -> [f64; 3] {
        let e = p.exponentials(s, false);
        let g = growth_from(&self.amplitude, &e);
        let (l, tau) = (&p.lambda, s / self.horizon);
        [
            modal_position(&self.position_weights, &e) + SeriesForm::horner(&self.polynomials[0], tau),
            (l[0] * g[0] + l[1] * g[1] + l[2] * g[2]).re + SeriesForm::horner(&self.polynomials[1], tau),
            (l[0] * l[0] * g[0] + l[1] * l[1] * g[1] + l[2] * l[2] * g[2]).re
                + SeriesForm::horner(&self.polynomials[2], tau),
        ]
    }

    /// Modal coordinates: q_k(s) = amplitude_k e^{λk s} + q_p,k(s).
    pub(super) fn modes<C>(&self, p: &ElectromechanicalPropagator<C>, s: f64) -> [C64; 3] {
        let tau = s / self.horizon;
        let mut q = self.growth(p, s);
        for (q_k, polynomial) in q.iter_mut().zip(&self.particular_modes) {
            *q_k += polynomial.iter().rev().fold(C64::new(0.0, 0.0), |acc, c| acc * tau + c);
        }
        q
    }
}

/// A bound on ln x for finite x ≥ 1, within 0.31 above it, without a call to `ln`: with
/// x = m·2^e (1 ≤ m < 2), ln x = e ln 2 + ln m and ln m ≤ m − 1.
pub(super) fn ln_upper_bound(x: f64) -> f64 {
    const MANTISSA: u64 = (1 << 52) - 1;
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & MANTISSA) | (1023 << 52));
    exponent as f64 * std::f64::consts::LN_2 + (m - 1.0)
}

/// A polynomial Σ cₙ zⁿ on 0 ≤ z ≤ z_max, as its constant c₀ and a bound Σ_{n≥1} |cₙ| z_maxⁿ
/// on how far it moves from it.
pub(super) fn constant_and_spread(coefficients: &[f64], z_max: f64) -> (f64, f64) {
    let (constant, rest) = match coefficients.split_first() {
        Some(split) => split,
        None => return (0.0, 0.0),
    };
    let mut power = 1.0;
    let spread = rest
        .iter()
        .map(|c| {
            power *= z_max;
            c.abs() * power
        })
        .sum();
    (*constant, spread)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{ramp_start, reference};
    use super::super::{ElectromechanicalPropagator, ElectromechanicalState};
    use super::*;
    use crate::physics::effects::PLAY_OPERATORS;
    use crate::physics::parameters::Parameters;
    use nalgebra::SVector;

    #[test]
    fn ln_upper_bound_is_above_ln_by_at_most_0_31() {
        let mut x = 1.0f64;
        while x < 1e300 {
            for y in [x, x * 1.0001, x * std::f64::consts::LOG2_E, x * 1.9999] {
                let (bound, exact) = (ln_upper_bound(y), y.ln());
                assert!(
                    bound >= exact - 1e-15 * exact.abs() && bound - exact <= 0.307,
                    "{y}: {bound} vs {exact}"
                );
            }
            x *= 2.0;
        }
    }

    #[test]
    fn summed_series_form_matches_the_per_mode_sum() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let start = ElectromechanicalState {
            current: 0.05,
            position: 1.2e-4,
            velocity: 0.02,
            acceleration: -30.0,
        };
        let mut lengths = vec![];
        for v in [1.3, 2.0, 3.1] {
            let trajectory = propagator.trajectory(&start, v, 0.0, &[start.position; PLAY_OPERATORS]);
            let form = trajectory.series_form.as_ref().expect("series form");
            lengths.push(trajectory.series.len());
            // Past `transient_over` the position skips the current transient's terms: they
            // are still there below it, and gone (to rounding) above it.
            let over = form.transient_over;
            assert!(
                over > 1.0 / p.omega_cd && over < 1e-2,
                "v {v}: transient over at {over:e} s"
            );
            let (_, r) = form.growth(&propagator, over);
            let rest = SeriesForm::horner(&form.position, r) - form.position[0];
            // The difference is taken from the constant term: a few of its ulps come on top.
            let rounding = 1e-15 * form.position[0].abs();
            assert!(
                rest.abs() <= 1e-16 * propagator.x_sat + rounding,
                "v {v}: {rest:e} m left at {over:e} s"
            );
            let (_, r) = form.growth(&propagator, 0.5 * over);
            let before = SeriesForm::horner(&form.position, r) - form.position[0];
            assert!(
                before.abs() > 1e-14 * propagator.x_sat,
                "v {v}: {before:e} m at {:e} s",
                0.5 * over
            );
            for s in [0.0, 1e-5, 3e-4, 2e-3, 1e-2, 0.3] {
                let q = trajectory.modes_by_sum(s);
                let summed = trajectory.modes(s);
                for k in 0..3 {
                    assert!(
                        (q[k] - summed[k]).norm() < 1e-16,
                        "v {v} s {s} mode {k}: {} vs {}",
                        q[k],
                        summed[k]
                    );
                }
                let l = &propagator.lambda;
                let by_modes = [
                    (q[0] + q[1] + q[2]).re,
                    (l[0] * q[0] + l[1] * q[1] + l[2] * q[2]).re,
                    (l[0] * l[0] * q[0] + l[1] * l[1] * q[1] + l[2] * l[2] * q[2]).re,
                ];
                let fast = trajectory.state(s);
                for (name, a, b, scale) in [
                    ("x", fast.position, by_modes[0], 1e-3),
                    ("v", fast.velocity, by_modes[1], 1.0),
                    ("a", fast.acceleration, by_modes[2], 1e3),
                ] {
                    assert!((a - b).abs() < 1e-12 * scale, "v {v} s {s} {name}: {a} vs {b}");
                }
                let shortcut = trajectory.position(s) - fast.position;
                let rounding = 1e-15 * fast.position.abs();
                assert!(
                    shortcut.abs() <= 1e-16 * propagator.x_sat + rounding,
                    "v {v} s {s}: {shortcut:e}"
                );
            }
        }
        // The forms' polynomials held inline and spilled to the heap (10, 18, 25 terms).
        assert!(lengths.iter().any(|&n| n <= INLINE_TERMS) && lengths.iter().any(|&n| n > INLINE_TERMS + 1));
    }

    #[test]
    fn ramp_form_matches_quadrature_and_a_tight_numerical_solution() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        for (v, rate) in [(1.0, 2.5), (4.0, -2.5), (2.5, 400.0), (-3.0, -60.0), (6.0, 1e-3)] {
            // A ramp continued from the previous step: the current already lags it by rate/ω.
            let start = ramp_start(&p, v, rate);
            let plays = [start.position; PLAY_OPERATORS];
            let fast = propagator.trajectory(&start, v, rate, &plays);
            let form = fast.ramp_form.as_ref().expect("ramp form expected");
            // Up to 100 V/s (full scale in 0.1 s) one form covers a 10 ms step; faster ramps
            // hand the rest of the step to quadrature.
            assert!(
                rate.abs() > 100.0 || form.horizon >= 0.01,
                "v {v} rate {rate}: horizon {}",
                form.horizon
            );
            let mut slow = propagator.trajectory(&start, v, rate, &plays);
            slow.ramp_form = None;
            let y0 = SVector::<f64, 4>::new(start.current, start.position, start.velocity, start.acceleration);
            for s in [0.0, 1e-5, 3e-4, 2e-3, 7.3e-3, 1e-2] {
                let (a, b) = (fast.state(s), slow.state(s));
                for (name, x, y, scale) in [
                    ("x", a.position, b.position, 1e-3),
                    ("v", a.velocity, b.velocity, 1.0),
                    ("a", a.acceleration, b.acceleration, 1e3),
                ] {
                    assert!(
                        (x - y).abs() < 1e-13 * scale,
                        "v {v} rate {rate} s {s} {name}: {x} vs {y}"
                    );
                }
                assert_eq!(fast.position(s), a.position);
                let (qa, qb) = (fast.modes(s), slow.modes(s));
                for k in 0..3 {
                    assert!((qa[k] - qb[k]).norm() < 1e-16, "v {v} rate {rate} s {s} mode {k}");
                }
                if s > 0.0 {
                    let y = reference(&p, y0, v, rate, s);
                    assert!(
                        (a.position - y[1]).abs() < 1e-11,
                        "v {v} rate {rate} s {s}: x {} vs {}",
                        a.position,
                        y[1]
                    );
                }
            }
        }
        // A ramp followed long enough does not ring: the jet pipe lags it, and that lag is not
        // taken for ringing (which would hold the chamber steps below a quarter period).
        let rate = 2.5;
        let current = ramp_start(&p, 1.0, rate).current;
        let x0 = propagator.static_position(current);
        let start = ElectromechanicalState {
            current,
            position: x0,
            velocity: 0.0,
            acceleration: 0.0,
        };
        let plays = [x0; PLAY_OPERATORS];
        let first = propagator.trajectory(&start, 1.0, rate, &plays);
        let fresh = first.ringing_amplitude(0.0);
        let later = first.state(0.5);
        let continued = propagator.trajectory(&later, 1.0 + 0.5 * rate, rate, &plays);
        assert!(continued.ramp_form.is_some());
        let q = continued.modes(0.0);
        let about_static = 2.0 * (q[1] + propagator.beta[1] * continued.jet_input(0.0) / propagator.lambda[1]).norm();
        let ringing = continued.ringing_amplitude(0.0);
        assert!(
            fresh > 0.0 && ringing < 1e-6 * fresh,
            "{ringing:e} vs {fresh:e} at the start"
        );
        assert!(
            about_static > 1e3 * ringing,
            "lag {about_static:e}, ringing {ringing:e}"
        );

        // With a current transient the quadrature stays in charge.
        let start = ElectromechanicalState {
            current: 0.05,
            position: 1.2e-4,
            velocity: 0.02,
            acceleration: -30.0,
        };
        assert!(propagator
            .trajectory(&start, 1.0, 2.5, &[start.position; PLAY_OPERATORS])
            .ramp_form
            .is_none());
    }
}
