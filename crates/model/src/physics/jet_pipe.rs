//! Jet pipe: tip force (2.4), static curve f3 (2.5), third-order dynamics (2.6) and the
//! offset from the receiver centre (2.7).
//!
//! Each equation is stated here once, in the forms that consume it: the assembled model
//! (`actuator`) evaluates them, and the exact propagator (`crate::electromechanics`) takes
//! f3 as a [`StaticCurve`] (values and power series) and (2.6) as [`LinearDynamics`] (its
//! characteristic polynomial and modes) instead of deriving either again.

use nalgebra::Complex;
use smallvec::SmallVec;

use super::parameters::Parameters;

/// Tip force from the coil current, (2.4): F_jp = k_m i.
pub fn tip_force(k_m: f64, current: f64) -> f64 {
    k_m * current
}

/// Power-series coefficients of a static curve: on the stack up to
/// [`SERIES_INLINE_TERMS`] (a command step of ordinary size needs fewer), so a step's
/// series does not allocate.
pub type SeriesCoefficients = SmallVec<[f64; SERIES_INLINE_TERMS]>;
pub const SERIES_INLINE_TERMS: usize = 16;

/// The static curve f3 of (2.5), x̄ = f3(F_jp), as the model and the propagator use it.
///
/// Power series are in the curve's own argument x = [`Self::argument`]`(F_jp)`, which is
/// proportional to the tip force (so a change of tip force maps to a change of argument the
/// same way). A curve that offers no series keeps the defaults (`None`), and the propagator
/// then integrates its input by quadrature.
pub trait StaticCurve {
    /// x̄ = f3(F_jp), m.
    fn value(&self, tip_force: f64) -> f64;
    /// dx̄/dF_jp, m/N (the linearisation's slope, Appendix A's c5 over k_m).
    fn slope(&self, tip_force: f64) -> f64;
    /// The argument the series are in, for a tip force (or a change of tip force).
    fn argument(&self, tip_force: f64) -> f64;
    /// Distance from the argument `x0` to the curve's nearest singularity in the complex
    /// plane: the radius of convergence of its power series about `x0`.
    fn series_radius(&self, _x0: f64) -> Option<f64> {
        None
    }
    /// Coefficients aₙ of gain·f3 at the argument x0 + ε r as a series in r,
    /// Σ aₙ rⁿ (0 ≤ r ≤ 1, |ε| within [`Self::series_radius`]), truncated where the terms stop
    /// mattering or at `max_terms` (a series that long has not converged). `gain` is a
    /// factor applied after f3 (the hysteresis operator's dragged fraction, 1 otherwise),
    /// folded into the curve's amplitude so each coefficient is rounded once.
    fn series(&self, _x0: f64, _epsilon: f64, _max_terms: usize, _gain: f64) -> Option<SeriesCoefficients> {
        None
    }
    /// [`Self::series`], with a memo of the curve's value at the last x0 for a curve that
    /// can use it (the tanh's: a held command's steps share their x0). The same coefficients.
    fn series_with_memo(
        &self,
        x0: f64,
        epsilon: f64,
        max_terms: usize,
        gain: f64,
        _memo: &TanhMemo,
    ) -> Option<SeriesCoefficients> {
        self.series(x0, epsilon, max_terms, gain)
    }
}

/// tanh at the last argument asked for, kept to the bit (see
/// [`StaticCurve::series_with_memo`]). A memo: it changes no result, so two holders that differ
/// only in it are equal.
#[derive(Clone, Debug, Default)]
pub struct TanhMemo(std::cell::Cell<Option<(u64, f64)>>);

impl TanhMemo {
    pub fn tanh(&self, x: f64) -> f64 {
        match self.0.get() {
            Some((bits, value)) if bits == x.to_bits() => value,
            _ => {
                let value = x.tanh();
                self.0.set(Some((x.to_bits(), value)));
                value
            }
        }
    }
}

impl PartialEq for TanhMemo {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// f3 as docs/model.md fixes it: x̄ = x_jp_sat tanh(F_jp / F_jp_sat). The thesis's f3 is the
/// midpoint line of Fig. 3.5, which the text does not give. Its argument is
/// x = F_jp / F_jp_sat, and tanh's nearest singularities are the poles at x = ±iπ/2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TanhSaturation {
    pub x_jp_sat: f64,
    pub f_jp_sat: f64,
}

/// The static curve of (2.5) the model uses: the FMU, the assembled model's right-hand side
/// and Jacobian, and the propagator all take it from here. It is the tanh of docs/model.md, blended
/// with the algebraic sigmoid u/√(1 + u²) in the share `f3_algebraic_share` (0 by
/// default): x̄ = x_jp_sat [(1 − β) tanh u + β u/√(1 + u²)], u = F_jp / F_jp_sat. Both have
/// the slope x_jp_sat/F_jp_sat at 0 and saturate at x_jp_sat; the algebraic one has the
/// softer knee. With β = 0 every method is the tanh's, to the bit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct F3 {
    pub tanh: TanhSaturation,
    pub algebraic_share: f64,
}

impl F3 {
    pub fn from_parameters(p: &Parameters) -> Self {
        Self {
            tanh: TanhSaturation::from_parameters(p),
            algebraic_share: p.f3_algebraic_share,
        }
    }
}

impl StaticCurve for F3 {
    fn value(&self, tip_force: f64) -> f64 {
        if self.algebraic_share == 0.0 {
            return self.tanh.value(tip_force);
        }
        let u = self.tanh.argument(tip_force);
        let beta = self.algebraic_share;
        self.tanh.x_jp_sat * ((1.0 - beta) * u.tanh() + beta * u / (1.0 + u * u).sqrt())
    }

    fn slope(&self, tip_force: f64) -> f64 {
        if self.algebraic_share == 0.0 {
            return self.tanh.slope(tip_force);
        }
        let u = self.tanh.argument(tip_force);
        let (t, beta) = (u.tanh(), self.algebraic_share);
        let algebraic = (1.0 + u * u).powf(-1.5);
        self.tanh.x_jp_sat / self.tanh.f_jp_sat * ((1.0 - beta) * (1.0 - t * t) + beta * algebraic)
    }

    fn argument(&self, tip_force: f64) -> f64 {
        self.tanh.argument(tip_force)
    }

    /// The nearer of tanh's poles at ±iπ/2 and the algebraic sigmoid's branch points at ±i.
    fn series_radius(&self, x0: f64) -> Option<f64> {
        let tanh = self.tanh.series_radius(x0)?;
        if self.algebraic_share == 0.0 {
            return Some(tanh);
        }
        Some(tanh.min((x0 * x0 + 1.0).sqrt()))
    }

    fn series_with_memo(
        &self,
        x0: f64,
        epsilon: f64,
        max_terms: usize,
        gain: f64,
        memo: &TanhMemo,
    ) -> Option<SeriesCoefficients> {
        if self.algebraic_share == 0.0 {
            return self.tanh.series_with_memo(x0, epsilon, max_terms, gain, memo);
        }
        self.series(x0, epsilon, max_terms, gain)
    }

    fn series(&self, x0: f64, epsilon: f64, max_terms: usize, gain: f64) -> Option<SeriesCoefficients> {
        let beta = self.algebraic_share;
        if beta == 0.0 {
            return self.tanh.series(x0, epsilon, max_terms, gain);
        }
        let tanh = tanh_series(x0, epsilon, max_terms);
        let algebraic = algebraic_sigmoid_series(x0, epsilon, max_terms);
        let amplitude = self.tanh.x_jp_sat * gain;
        let terms = tanh.len().max(algebraic.len());
        let term = |a: &SeriesCoefficients, n: usize| a.get(n).copied().unwrap_or(0.0);
        Some(
            (0..terms)
                .map(|n| amplitude * ((1.0 - beta) * term(&tanh, n) + beta * term(&algebraic, n)))
                .collect(),
        )
    }
}

/// Coefficients gₙ of g(x0 + ε r) = Σ gₙ rⁿ for the algebraic sigmoid g(x) = x/√(1 + x²),
/// truncated where they stop mattering (at most [`TANH_SERIES_TERMS`]). With
/// q = 1 + (x0 + εr)² = a + b r + c r² and h = q^(−1/2) = Σ hₙ rⁿ, q h' = −q'h/2 gives
/// (n+1) a h_{n+1} = −b (n + ½) hₙ − c n h_{n−1}, and gₙ = x0 hₙ + ε h_{n−1}. They converge
/// for |ε| below the distance to the branch points at ±i, √(x0² + 1).
pub fn algebraic_sigmoid_series(x0: f64, epsilon: f64, max_terms: usize) -> SeriesCoefficients {
    let max_terms = max_terms.clamp(1, TANH_SERIES_TERMS);
    let (a, b, c) = (1.0 + x0 * x0, 2.0 * x0 * epsilon, epsilon * epsilon);
    let mut h_before = 0.0;
    let mut h = 1.0 / a.sqrt();
    let mut g = SeriesCoefficients::new();
    g.push(x0 * h);
    if epsilon == 0.0 {
        return g;
    }
    for n in 0..max_terms - 1 {
        let h_next = -(b * (n as f64 + 0.5) * h + c * n as f64 * h_before) * RECIPROCALS[n] / a;
        g.push(x0 * h_next + epsilon * h);
        h_before = h;
        h = h_next;
        let k = g.len();
        if k > 3 && g[k - 1].abs() < 1e-17 && g[k - 2].abs() < 1e-17 {
            break;
        }
    }
    g
}

impl TanhSaturation {
    pub fn new(x_jp_sat: f64, f_jp_sat: f64) -> Self {
        Self { x_jp_sat, f_jp_sat }
    }

    pub fn from_parameters(p: &Parameters) -> Self {
        Self::new(p.x_jp_sat, p.f_jp_sat)
    }
}

impl StaticCurve for TanhSaturation {
    fn value(&self, tip_force: f64) -> f64 {
        self.x_jp_sat * self.argument(tip_force).tanh()
    }

    fn slope(&self, tip_force: f64) -> f64 {
        let t = self.argument(tip_force).tanh();
        self.x_jp_sat / self.f_jp_sat * (1.0 - t * t)
    }

    fn argument(&self, tip_force: f64) -> f64 {
        tip_force / self.f_jp_sat
    }

    /// |x0 ± iπ/2|: the distance to tanh's nearest poles.
    fn series_radius(&self, x0: f64) -> Option<f64> {
        Some((x0 * x0 + std::f64::consts::FRAC_PI_2.powi(2)).sqrt())
    }

    fn series(&self, x0: f64, epsilon: f64, max_terms: usize, gain: f64) -> Option<SeriesCoefficients> {
        Some(self.scaled(tanh_series(x0, epsilon, max_terms), gain))
    }

    fn series_with_memo(
        &self,
        x0: f64,
        epsilon: f64,
        max_terms: usize,
        gain: f64,
        memo: &TanhMemo,
    ) -> Option<SeriesCoefficients> {
        Some(self.scaled(tanh_series_from(memo.tanh(x0), epsilon, max_terms), gain))
    }
}

impl TanhSaturation {
    /// The series of tanh scaled to the curve's: x_jp_sat·gain times each coefficient.
    #[inline]
    fn scaled(&self, mut coefficients: SeriesCoefficients, gain: f64) -> SeriesCoefficients {
        for a in coefficients.iter_mut() {
            *a *= self.x_jp_sat * gain;
        }
        coefficients
    }
}

/// Most terms [`tanh_series`] computes (the length of its table of reciprocals).
pub const TANH_SERIES_TERMS: usize = 64;

/// 1/(n + 1) for the series recurrence: a multiplication per term instead of a division.
const RECIPROCALS: [f64; TANH_SERIES_TERMS] = {
    let mut table = [0.0; TANH_SERIES_TERMS];
    let mut n = 0;
    while n < TANH_SERIES_TERMS {
        table[n] = 1.0 / (n as f64 + 1.0);
        n += 1;
    }
    table
};

/// Coefficients aₙ = cₙ εⁿ of tanh(x0 + ε r) = Σ aₙ rⁿ, truncated where they stop mattering
/// (at most [`TANH_SERIES_TERMS`]). They converge for |ε| below the distance to tanh's
/// nearest pole, [`TanhSaturation::series_radius`].
pub fn tanh_series(x0: f64, epsilon: f64, max_terms: usize) -> SeriesCoefficients {
    tanh_series_from(x0.tanh(), epsilon, max_terms)
}

/// [`tanh_series`] from tanh x0.
pub fn tanh_series_from(tanh_x0: f64, epsilon: f64, max_terms: usize) -> SeriesCoefficients {
    let max_terms = max_terms.min(TANH_SERIES_TERMS);
    // The terms go to an array first, and to the small vector whole (indexing a SmallVec
    // checks where it lives at every element); only a series longer than the array spills.
    let mut inline = [0.0; SERIES_INLINE_TERMS];
    inline[0] = tanh_x0;
    if epsilon == 0.0 {
        return SeriesCoefficients::from_buf_and_len(inline, 1);
    }
    let converged = |terms: &[f64]| match terms {
        [.., before, last] => terms.len() > 3 && last.abs() < 1e-17 && before.abs() < 1e-17,
        _ => false,
    };
    let mut count = 1;
    while count < max_terms.min(SERIES_INLINE_TERMS) {
        inline[count] = next_tanh_term(&inline[..count], epsilon);
        count += 1;
        if converged(&inline[..count]) {
            return SeriesCoefficients::from_buf_and_len(inline, count);
        }
    }
    if count == max_terms {
        return SeriesCoefficients::from_buf_and_len(inline, count);
    }
    let mut spilled = SeriesCoefficients::from_slice(&inline);
    while spilled.len() < max_terms {
        let term = next_tanh_term(&spilled, epsilon);
        spilled.push(term);
        if converged(&spilled) {
            break;
        }
    }
    spilled
}

/// The next coefficient of [`tanh_series`] from `terms` a₀ … aₙ: y' = 1 − y² in the
/// variable εr gives (n+1) a_{n+1} = ε ([n = 0] − Σ_{k=0}^{n} a_k a_{n−k}). The newest term
/// aₙ enters the sum only as 2a₀aₙ: the rest (pairs folded in half, over two accumulators)
/// does not wait for it, so each term is three dependent operations after the one before.
#[inline]
fn next_tanh_term(terms: &[f64], epsilon: f64) -> f64 {
    let n = terms.len() - 1;
    let scale = epsilon * RECIPROCALS[n];
    if n == 0 {
        return (1.0 - terms[0] * terms[0]) * scale;
    }
    // a_1 … a_{n−1}, paired from both ends.
    let inner = &terms[1..n];
    let (low, high) = inner.split_at(inner.len() / 2);
    let (mut even, mut odd) = (0.0, 0.0);
    let mut pairs = low.iter().zip(high.iter().rev());
    while let Some((a, b)) = pairs.next() {
        even += a * b;
        if let Some((a, b)) = pairs.next() {
            odd += a * b;
        }
    }
    let middle = if inner.len() % 2 == 1 {
        inner[inner.len() / 2] * inner[inner.len() / 2]
    } else {
        0.0
    };
    let older = 2.0 * (even + odd) + middle;
    -((2.0 * terms[0]) * terms[n] + older) * scale
}

/// The jet pipe's linear dynamics, (2.6): X(s)/X̄(s) = ω1/(s+ω1) · ω2²/(s² + 2ζ2ω2 s + ω2²),
/// i.e. X/X̄ = c4 / (s³ + c2 s² + c3 s + c4) with Appendix A's c2..c4, unity gain at DC.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearDynamics {
    pub omega_1: f64,
    pub omega_2: f64,
    pub zeta_2: f64,
}

/// (2.6) in modal form: X/X̄ = Σ_k r_k / (s − λk) with distinct poles λk, so each modal
/// coordinate obeys q_k' = λk q_k + r_k x̄ and x = Re Σ q_k.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Modes {
    /// λ1 = −ω1 and the pair −ζ2ω2 ± jω2√(1−ζ2²) (real for ζ2 ≥ 1).
    pub poles: [Complex<f64>; 3],
    /// Residues r_k of X/X̄ at the poles: the modes' input gains.
    pub residues: [Complex<f64>; 3],
    /// Rows of V⁻¹, V = `[[1,1,1],[λ1,λ2,λ3],[λ1²,λ2²,λ3²]]`: the modal coordinates of a state
    /// [x, ẋ, ẍ] are q = V⁻¹ [x, ẋ, ẍ].
    pub from_state: [[Complex<f64>; 3]; 3],
}

impl LinearDynamics {
    pub fn new(omega_1: f64, omega_2: f64, zeta_2: f64) -> Self {
        Self {
            omega_1,
            omega_2,
            zeta_2,
        }
    }

    pub fn from_parameters(p: &Parameters) -> Self {
        Self::new(p.omega_1, p.omega_2, p.zeta_2)
    }

    /// [c2, c3, c4] of the characteristic polynomial s³ + c2 s² + c3 s + c4 (Appendix A):
    /// c2 = 2ζ2ω2 + ω1, c3 = ω2² + 2ζ2ω1ω2, c4 = ω1ω2², also the numerator's gain.
    pub fn coefficients(&self) -> [f64; 3] {
        let (omega_1, omega_2, zeta_2) = (self.omega_1, self.omega_2, self.zeta_2);
        let c2 = 2.0 * zeta_2 * omega_2 + omega_1;
        let c3 = omega_2 * omega_2 + 2.0 * zeta_2 * omega_1 * omega_2;
        let c4 = omega_1 * omega_2 * omega_2;
        [c2, c3, c4]
    }

    /// The gain b of the input in x''' = … + b x̄: the numerator ω1ω2² of X/X̄.
    pub fn input_gain(&self) -> f64 {
        self.omega_1 * self.omega_2 * self.omega_2
    }

    /// X/X̄ at s = 0: the numerator over c4, 1 (the jet pipe rests at x̄).
    pub fn dc_gain(&self) -> f64 {
        self.input_gain() / self.coefficients()[2]
    }

    /// Third derivative of the tip position, (2.6) in state form:
    /// x''' = c4 (x̄ − x) − c2 x'' − c3 x'.
    pub fn third_derivative(&self, static_position: f64, position: f64, velocity: f64, acceleration: f64) -> f64 {
        let [c2, c3, c4] = self.coefficients();
        c4 * (static_position - position) - c2 * acceleration - c3 * velocity
    }

    /// The roots of the characteristic polynomial: −ω1 and −ζ2ω2 ± jω2√(1−ζ2²) (a complex
    /// pair for ζ2 < 1, two real poles −ζ2ω2 ± ω2√(ζ2²−1) otherwise).
    pub fn poles(&self) -> [Complex<f64>; 3] {
        let (omega_2, zeta_2) = (self.omega_2, self.zeta_2);
        let real = Complex::new(-self.omega_1, 0.0);
        if zeta_2 < 1.0 {
            let damped = omega_2 * (1.0 - zeta_2 * zeta_2).sqrt();
            [
                real,
                Complex::new(-zeta_2 * omega_2, damped),
                Complex::new(-zeta_2 * omega_2, -damped),
            ]
        } else {
            let spread = omega_2 * (zeta_2 * zeta_2 - 1.0).sqrt();
            [
                real,
                Complex::new(-zeta_2 * omega_2 + spread, 0.0),
                Complex::new(-zeta_2 * omega_2 - spread, 0.0),
            ]
        }
    }

    /// The modal form, `None` when two poles (nearly) coincide (e.g. ζ2 = 1, or ω1 on the
    /// second-order pair): then it does not exist.
    pub fn modes(&self) -> Option<Modes> {
        let poles = self.poles();
        let scale = poles.iter().map(|l| l.norm()).fold(0.0, f64::max);
        for a in 0..3 {
            for b in a + 1..3 {
                if (poles[a] - poles[b]).norm() < 1e-6 * scale {
                    return None;
                }
            }
        }
        // Inverse of the Vandermonde matrix: row k holds the coefficients of the Lagrange
        // polynomial ℓ_k(s) = Π_{j≠k} (s − λj)/(λk − λj), i.e. [λaλb, −(λa+λb), 1]/den.
        let one = Complex::new(1.0, 0.0);
        let mut from_state = [[Complex::new(0.0, 0.0); 3]; 3];
        for k in 0..3 {
            let (a, b) = ((k + 1) % 3, (k + 2) % 3);
            let den = (poles[k] - poles[a]) * (poles[k] - poles[b]);
            from_state[k] = [poles[a] * poles[b] / den, -(poles[a] + poles[b]) / den, one / den];
        }
        // r_k = b / Π_{j≠k}(λk − λj): the last column of V⁻¹ times the input gain.
        let gain = self.input_gain();
        let residues = [
            from_state[0][2] * gain,
            from_state[1][2] * gain,
            from_state[2][2] * gain,
        ];
        Some(Modes {
            poles,
            residues,
            from_state,
        })
    }
}

/// Absolute tip position relative to the receiver centre, (2.7).
pub fn absolute_position(position: f64, x_jp_offset: f64) -> f64 {
    position + x_jp_offset
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_curve_is_odd_saturating_and_has_the_documented_slope() {
        let f3 = TanhSaturation::new(0.5e-3, 0.45);
        let xs = f3.x_jp_sat;
        assert_eq!(f3.value(0.0), 0.0);
        assert!((f3.value(0.3) + f3.value(-0.3)).abs() < 1e-18);
        assert!(f3.value(100.0) <= xs);
        let h = 1e-7;
        let numeric = (f3.value(0.2 + h) - f3.value(0.2 - h)) / (2.0 * h);
        assert!((numeric - f3.slope(0.2)).abs() < 1e-9);
    }

    #[test]
    fn the_series_with_the_tanh_memo_are_the_series_to_the_bit() {
        let memo = TanhMemo::default();
        for share in [0.0, 0.4] {
            let p = Parameters {
                f3_algebraic_share: share,
                ..Parameters::default()
            };
            let f3 = F3::from_parameters(&p);
            // Repeated centres (a held command's steps) and new ones, with and without a jump.
            for (x0, eps) in [
                (0.3, 0.1),
                (0.3, 0.01),
                (0.3, 0.0),
                (-1.2, 0.4),
                (-1.2, 0.0),
                (0.3, 0.2),
            ] {
                let kept = f3.series_with_memo(x0, eps, 64, 0.7, &memo).unwrap();
                let fresh = f3.series(x0, eps, 64, 0.7).unwrap();
                let bits = |a: &SeriesCoefficients| a.iter().map(|c| c.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&kept), bits(&fresh), "share {share} x0 {x0} eps {eps}");
            }
        }
    }

    #[test]
    fn tanh_series_matches_tanh() {
        for (x0, eps) in [(0.0, 0.3), (0.7, -0.5), (-1.2, 0.6), (2.0, 0.05)] {
            let a = tanh_series(x0, eps, 64);
            for r in [0.0f64, 0.3, 0.9, 1.0] {
                let sum: f64 = a.iter().enumerate().map(|(n, c)| c * r.powi(n as i32)).sum();
                assert!((sum - (x0 + eps * r).tanh()).abs() < 1e-13, "x0 {x0} eps {eps} r {r}");
            }
        }
    }

    #[test]
    fn the_curves_series_are_its_values_within_the_radius() {
        let f3 = TanhSaturation::new(0.5e-3, 0.45);
        for (force, change) in [(0.1, 0.2), (-0.3, 0.25), (0.9, -0.4)] {
            let x0 = f3.argument(force);
            let epsilon = f3.argument(change);
            assert!(epsilon.abs() < 0.5 * f3.series_radius(x0).unwrap());
            let a = f3.series(x0, epsilon, 64, 0.5).unwrap();
            for r in [0.0f64, 0.5, 1.0] {
                let sum: f64 = a.iter().enumerate().map(|(n, c)| c * r.powi(n as i32)).sum();
                let exact = 0.5 * f3.value(force + change * r);
                assert!((sum - exact).abs() < 1e-13 * f3.x_jp_sat, "{force} {change} {r}");
            }
        }
        // The radius is the distance to the poles at ±iπ/2: tanh's series about 0 has
        // coefficients falling like (2/π)ⁿ.
        assert!((f3.series_radius(0.0).unwrap() - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn the_algebraic_sigmoids_series_is_its_value_within_the_radius() {
        for (x0, eps) in [(0.0f64, 0.5f64), (0.7, -0.6), (-1.5, 0.9), (3.0, 0.1)] {
            assert!(eps.abs() < 0.7 * f64::sqrt(x0 * x0 + 1.0));
            let g = algebraic_sigmoid_series(x0, eps, 64);
            for r in [0.0f64, 0.3, 0.9, 1.0] {
                let x = x0 + eps * r;
                let sum: f64 = g.iter().enumerate().map(|(n, c)| c * r.powi(n as i32)).sum();
                assert!(
                    (sum - x / (1.0 + x * x).sqrt()).abs() < 1e-13,
                    "x0 {x0} eps {eps} r {r}"
                );
            }
        }
    }

    #[test]
    fn the_blended_curve_keeps_the_slope_and_saturation_and_softens_the_knee() {
        let p = Parameters {
            f3_algebraic_share: 0.6,
            ..Parameters::default()
        };
        let (blended, tanh) = (F3::from_parameters(&p), F3::from_parameters(&Parameters::default()));
        assert_eq!(blended.slope(0.0), tanh.slope(0.0));
        assert!((blended.value(1e3) - p.x_jp_sat).abs() < 1e-6 * p.x_jp_sat);
        // At the knee (F_jp = F_jp_sat) the blend sits 0.6 of the way from tanh 1 = 0.7616
        // to 1/√2 = 0.7071 of x_jp_sat.
        let knee = 0.4 * 1f64.tanh() + 0.6 * std::f64::consts::FRAC_1_SQRT_2;
        assert!((blended.value(p.f_jp_sat) - knee * p.x_jp_sat).abs() < 1e-15);
        let h = 1e-7;
        for force in [-0.9, 0.1, 0.45, 1.3] {
            let numeric = (blended.value(force + h) - blended.value(force - h)) / (2.0 * h);
            assert!((numeric - blended.slope(force)).abs() < 1e-9, "{force}");
        }
        for (force, change) in [(0.1, 0.2), (-0.3, 0.25), (0.9, -0.3)] {
            let x0 = blended.argument(force);
            let epsilon = blended.argument(change);
            assert!(epsilon.abs() < 0.7 * blended.series_radius(x0).unwrap());
            let a = blended.series(x0, epsilon, 64, 0.5).unwrap();
            for r in [0.0f64, 0.5, 1.0] {
                let sum: f64 = a.iter().enumerate().map(|(n, c)| c * r.powi(n as i32)).sum();
                let exact = 0.5 * blended.value(force + change * r);
                assert!((sum - exact).abs() < 1e-13 * p.x_jp_sat, "{force} {change} {r}");
            }
        }
        // Without the share every method is the tanh's.
        assert_eq!(tanh.value(0.37), tanh.tanh.value(0.37));
        assert_eq!(tanh.series(0.2, 0.3, 64, 1.0), tanh.tanh.series(0.2, 0.3, 64, 1.0));
    }

    #[test]
    fn dynamics_have_unity_dc_gain() {
        let dynamics = LinearDynamics::new(973.9, 1856.7, 0.019);
        // At rest at the static position every derivative vanishes.
        assert_eq!(dynamics.third_derivative(1e-4, 1e-4, 0.0, 0.0), 0.0);
        assert!(dynamics.third_derivative(1e-4, 0.0, 0.0, 0.0) > 0.0);
        assert_eq!(dynamics.dc_gain(), 1.0);
        // The modes' static responses −r_k/λk add up to the DC gain.
        let modes = dynamics.modes().unwrap();
        let dc: f64 = (0..3).map(|k| (-modes.residues[k] / modes.poles[k]).re).sum();
        assert!((dc - 1.0).abs() < 1e-12, "{dc}");
    }

    #[test]
    fn poles_are_the_roots_of_the_characteristic_polynomial_and_modes_its_partial_fractions() {
        for zeta in [0.019, 0.7, 1.0, 2.5] {
            let dynamics = LinearDynamics::new(973.9, 1856.7, zeta);
            let [c2, c3, c4] = dynamics.coefficients();
            for l in dynamics.poles() {
                let residual = ((l + c2) * l + c3) * l + c4;
                assert!(residual.norm() < 1e-9 * c4, "ζ2 {zeta}: {l} leaves {residual}");
            }
            let modes = match dynamics.modes() {
                Some(modes) => modes,
                None => {
                    assert_eq!(zeta, 1.0, "only the critically damped pair coincides");
                    continue;
                }
            };
            // Σ r_k/(s − λk) is the transfer function c4/(s³ + c2 s² + c3 s + c4) ...
            let s = Complex::new(-300.0, 2000.0);
            let fractions: Complex<f64> = (0..3).map(|k| modes.residues[k] / (s - modes.poles[k])).sum();
            let transfer = c4 / (((s + c2) * s + c3) * s + c4);
            assert!((fractions - transfer).norm() < 1e-12 * transfer.norm(), "ζ2 {zeta}");
            // ... and V⁻¹ inverts the Vandermonde matrix of the poles.
            for (row, inverse) in modes.from_state.iter().enumerate() {
                for column in 0..3 {
                    let l = modes.poles[column];
                    let product = inverse[0] + inverse[1] * l + inverse[2] * l * l;
                    let expected = if row == column { 1.0 } else { 0.0 };
                    assert!((product - expected).norm() < 1e-12, "ζ2 {zeta} ({row}, {column})");
                }
            }
        }
    }
}
