//! Exact propagation of the current driver and jet pipe over a communication step.
//!
//! The current driver (2.1) and the jet pipe dynamics (2.6) are linear; only the static
//! curve f3 (2.5) between them is not, and neither feels the air. With the command held
//! (or linear in time) over a step the current is known in closed form,
//! i(s) = ī(s) + δ e^{−ω_cd s}, so the jet pipe input u(s) = f3(k_m i(s)) is a known
//! function of time, and in the jet pipe's modal coordinates (eigenvalues −ω1 and
//! −ζ2ω2 ± jω2√(1−ζ2²), eigenvectors [1, λ, λ²]) each mode obeys q' = λ q + β u(s):
//!
//!   q(s) = e^{λ s} q(0) + β ∫₀ˢ e^{λ(s−σ)} u(σ) dσ.
//!
//! For a held command the integral is a series: tanh(F̄ + ε r) = Σ cₙ εⁿ rⁿ with
//! r = e^{−ω_cd σ}, and each term integrates in closed form. For large jumps (where the
//! series converges slowly) and for commands that move within the step, a composite
//! 8-point Gauss–Legendre rule on 0.1 ms panels is used instead. Either way the jet pipe
//! is exact to rounding, so the chambers' integrator never has to resolve its 295 Hz
//! ringing or the 7050 rad/s current transient.

use nalgebra::Complex;
use smallvec::SmallVec;

use crate::physics::effects::{PrandtlIshlinskii, PLAY_OPERATORS};
use crate::physics::jet_pipe;
use crate::physics::parameters::Parameters;

type C64 = Complex<f64>;

/// Series coefficients: on the stack up to 16 terms (a command step of ordinary size needs
/// fewer), so building a step's trajectory does not allocate.
type Coefficients = SmallVec<[f64; INLINE_TERMS]>;
const INLINE_TERMS: usize = 16;

/// Current, jet pipe position and its first two derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElectromechanicalState {
    pub current: f64,
    pub position: f64,
    pub velocity: f64,
    pub acceleration: f64,
}

/// Precomputed modal form of the jet pipe for one parameter set.
#[derive(Clone, Debug, PartialEq)]
pub struct ElectromechanicalPropagator {
    omega_cd: f64,
    k_cd: f64,
    i_offset: f64,
    k_m: f64,
    x_sat: f64,
    f_sat: f64,
    lambda: [C64; 3],
    /// Rows of V⁻¹, V = [[1,1,1],[λ1,λ2,λ3],[λ1²,λ2²,λ3²]].
    inverse: [[C64; 3]; 3],
    /// V⁻¹ b with b = [0, 0, ω1ω2²].
    beta: [C64; 3],
    /// The jet_pipe_hysteresis operator between f3 and the dynamics (inactive when off).
    hysteresis: PrandtlIshlinskii,
    /// What each term of a current transient's series does to the modes: see [`SeriesWeight`].
    /// Built once, so a step's trajectory costs multiplications instead of 3 complex
    /// divisions per term; it stops before the first n where λk + nω nearly vanishes.
    series_weights: Vec<SeriesWeight>,
    /// The advances by cᵢh of the last few step sizes (see [`Trajectory::node_positions`]).
    advances: AdvanceCache,
    /// e^{Re λ1 s} and e^{Re λ2 s} at the last s asked for: the position bounds over a
    /// step and the ringing test ask at the same s every step of a regular grid.
    real_mode_growth: ExpMemo,
    ringing_envelope: ExpMemo,
}

/// e^{rate·s} for a fixed rate, kept for the last s asked for. A memo: it changes no result,
/// so two propagators that differ only in it are equal.
#[derive(Clone, Debug)]
struct ExpMemo {
    rate: f64,
    last: std::cell::Cell<Option<(f64, f64)>>,
}

impl ExpMemo {
    fn new(rate: f64) -> Self {
        Self {
            rate,
            last: std::cell::Cell::new(None),
        }
    }

    fn at(&self, s: f64) -> f64 {
        match self.last.get() {
            Some((kept, value)) if kept == s => value,
            _ => {
                let value = (self.rate * s).exp();
                self.last.set(Some((s, value)));
                value
            }
        }
    }
}

impl PartialEq for ExpMemo {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// For term aₙ e^{−nω s} of the jet pipe input: each mode's weight wₖ = β_k/(λk + nω) and
/// the moments Re Σ_k λk^m wₖ (m = 0, 1, 2) that give its share of position, velocity and
/// acceleration.
#[derive(Clone, Debug, PartialEq)]
struct SeriesWeight {
    modes: [C64; 3],
    moments: [f64; 3],
}

/// Largest |ε|/ρ (jump over the distance to tanh's nearest pole) for which the series is used.
const SERIES_RATIO_LIMIT: f64 = 0.5;
/// A larger jump is integrated by quadrature until it has decayed to this fraction of the
/// limit (rounding then cannot push the rest over it), and by the series from there.
const LATE_SERIES_MARGIN: f64 = 0.9;
const MAX_SERIES_TERMS: usize = 64;
/// Largest |k_m δ / F_jp_sat| (the current transient's share of tanh's argument) that a
/// ramp's closed form neglects: its effect on the jet pipe is below 1e-15·x_jp_sat.
const RAMP_TRANSIENT_LIMIT: f64 = 1e-15;
/// Largest |β T| / ρ (the ramp's change of tanh's argument over the closed form's horizon,
/// over the distance to tanh's nearest pole): the series terms shrink at least this fast.
const RAMP_SERIES_RATIO: f64 = 0.2;
/// Longest horizon of a ramp's closed form, s (queries beyond it use quadrature).
const RAMP_MAX_HORIZON: f64 = 1.0;
const PANEL: f64 = 1e-4;

const GAUSS_NODES: [f64; 8] = [
    -0.960_289_856_497_536_3,
    -0.796_666_477_413_626_7,
    -0.525_532_409_916_329,
    -0.183_434_642_495_649_8,
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
const GAUSS_WEIGHTS: [f64; 8] = [
    0.101_228_536_290_376_3,
    0.222_381_034_453_374_5,
    0.313_706_645_877_887_3,
    0.362_683_783_378_362,
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

impl ElectromechanicalPropagator {
    /// `None` when the jet pipe's eigenvalues are (nearly) repeated, e.g. ζ2 ≥ 1 or ω1 on
    /// the second-order pair: the modal form does not exist and callers integrate the
    /// full system instead.
    pub fn new(p: &Parameters) -> Option<Self> {
        if p.zeta_2 >= 1.0 {
            return None;
        }
        let damped = p.omega_2 * (1.0 - p.zeta_2 * p.zeta_2).sqrt();
        let lambda = [
            C64::new(-p.omega_1, 0.0),
            C64::new(-p.zeta_2 * p.omega_2, damped),
            C64::new(-p.zeta_2 * p.omega_2, -damped),
        ];
        let scale = lambda.iter().map(|l| l.norm()).fold(0.0, f64::max);
        for a in 0..3 {
            for b in a + 1..3 {
                if (lambda[a] - lambda[b]).norm() < 1e-6 * scale {
                    return None;
                }
            }
        }
        // Inverse of the Vandermonde matrix: row k holds the coefficients of the Lagrange
        // polynomial ℓ_k(s) = Π_{j≠k} (s − λj)/(λk − λj), i.e. [λaλb, −(λa+λb), 1]/den.
        let mut inverse = [[C64::new(0.0, 0.0); 3]; 3];
        for k in 0..3 {
            let (a, b) = ((k + 1) % 3, (k + 2) % 3);
            let den = (lambda[k] - lambda[a]) * (lambda[k] - lambda[b]);
            inverse[k] = [
                lambda[a] * lambda[b] / den,
                -(lambda[a] + lambda[b]) / den,
                C64::new(1.0, 0.0) / den,
            ];
        }
        let gain = p.omega_1 * p.omega_2 * p.omega_2;
        let beta = [inverse[0][2] * gain, inverse[1][2] * gain, inverse[2][2] * gain];
        let mut series_weights = Vec::with_capacity(MAX_SERIES_TERMS);
        'terms: for n in 0..MAX_SERIES_TERMS {
            let n_omega = n as f64 * p.omega_cd;
            let mut weight = SeriesWeight {
                modes: [C64::new(0.0, 0.0); 3],
                moments: [0.0; 3],
            };
            for k in 0..3 {
                let denominator = lambda[k] + n_omega;
                // Resonant: the term grows like s e^{λs}, which the series form does not hold.
                if denominator.norm_sqr() <= (1e-9 * p.omega_cd).powi(2) {
                    break 'terms;
                }
                let w = beta[k] / denominator;
                weight.modes[k] = w;
                weight.moments[0] += w.re;
                weight.moments[1] += (lambda[k] * w).re;
                weight.moments[2] += (lambda[k] * lambda[k] * w).re;
            }
            series_weights.push(weight);
        }
        Some(Self {
            omega_cd: p.omega_cd,
            k_cd: p.k_cd,
            i_offset: p.i_offset,
            k_m: p.k_m,
            x_sat: p.x_jp_sat,
            f_sat: p.f_jp_sat,
            lambda,
            inverse,
            beta,
            hysteresis: PrandtlIshlinskii::new(p.hysteresis_width, p.hysteresis_deadband),
            series_weights,
            advances: AdvanceCache::default(),
            real_mode_growth: ExpMemo::new(lambda[0].re),
            ringing_envelope: ExpMemo::new(lambda[1].re),
        })
    }

    /// The trajectory over a step starting from `start` with command v_DA(s) = v_da + v_da_rate·s.
    ///
    /// `plays` are the hysteresis operator's play states at the start; the current is
    /// monotone in time except at most at one turning point (with a moving command), so
    /// the plays at any instant follow from their start values in at most two moves.
    pub fn trajectory(
        &self,
        start: &ElectromechanicalState,
        v_da: f64,
        v_da_rate: f64,
        plays: &[f64; PLAY_OPERATORS],
    ) -> Trajectory<'_> {
        let static_current = self.k_cd * v_da + self.i_offset;
        let ramp = self.k_cd * v_da_rate;
        // i(s) = ī(0) + ramp·(s − 1/ω) + δ e^{−ω s}
        let base = static_current - ramp / self.omega_cd;
        let delta = start.current - base;
        let z = [start.position, start.velocity, start.acceleration];
        let mut q0 = [C64::new(0.0, 0.0); 3];
        for k in 0..3 {
            q0[k] = self.inverse[k][0] * z[0] + self.inverse[k][1] * z[1] + self.inverse[k][2] * z[2];
        }
        let mut series = Coefficients::new();
        // i'(s) = ramp − ω δ e^{−ω s} vanishes once at most.
        let ratio = ramp / (self.omega_cd * delta);
        let turning_point = (ratio > 0.0 && ratio < 1.0).then(|| -ratio.ln() / self.omega_cd);
        let linear_hysteresis = if ramp == 0.0 && self.hysteresis.is_active() {
            self.hysteresis_as_linear(start.current, base, plays)
        } else {
            None
        };
        // Where a held command's jump is too large for the series: when it has shrunk enough.
        let mut series_from = None;
        if ramp == 0.0 && (!self.hysteresis.is_active() || linear_hysteresis.is_some()) {
            let centre = self.k_m * base / self.f_sat;
            let epsilon = self.k_m * delta / self.f_sat;
            let radius = (centre * centre + std::f64::consts::FRAC_PI_2.powi(2)).sqrt();
            if epsilon.abs() <= SERIES_RATIO_LIMIT * radius {
                series = tanh_series(centre, epsilon, MAX_SERIES_TERMS);
                let (constant, slope) = linear_hysteresis.unwrap_or((0.0, 1.0));
                for a in series.iter_mut() {
                    *a *= self.x_sat * slope;
                }
                series[0] += constant;
            } else {
                let shrunk = LATE_SERIES_MARGIN * SERIES_RATIO_LIMIT * radius;
                series_from = Some((epsilon.abs() / shrunk).ln() / self.omega_cd);
            }
        }
        // A ramp whose current transient is below rounding (a ramp continued from the last
        // step): the input is a power series in time and the response has a closed form.
        let ramp_form = if ramp != 0.0
            && !self.hysteresis.is_active()
            && (self.k_m * delta / self.f_sat).abs() <= RAMP_TRANSIENT_LIMIT
        {
            RampForm::new(self, &q0, self.k_m * base / self.f_sat, self.k_m * ramp / self.f_sat).map(Box::new)
        } else {
            None
        };
        let mut trajectory = Trajectory {
            propagator: self,
            base,
            ramp,
            delta,
            q0,
            ramp_form,
            series_form: SeriesForm::new(self, &q0, &series),
            series,
            plays: *plays,
            turning_point,
            settled: None,
            kinks: vec![],
            panel_ends: std::cell::RefCell::new(vec![]),
            late: None,
            last_node: std::cell::Cell::new(None),
        };
        if trajectory.series.is_empty() {
            trajectory.kinks = trajectory.find_kinks();
        }
        if let Some(from) = series_from {
            // Quadrature up to `from` (a few panels), the series from there: the current
            // transient is then a jump the series converges for.
            let late = self.trajectory(&trajectory.state(from), v_da, 0.0, &trajectory.plays_at(from));
            if late.series_form.is_some() {
                trajectory.late = Some((from, Box::new(late)));
                return trajectory;
            }
        }
        if trajectory.series.is_empty() && ramp == 0.0 {
            // |δ| e^{−ω s} below 1e-15 A: the input is constant to rounding.
            let settled = (delta.abs() / 1e-15).ln().max(0.0) / self.omega_cd;
            let integral = trajectory.quadrature(settled);
            trajectory.settled = Some((settled, integral, trajectory.jet_input(settled)));
        }
        trajectory
    }
}

impl ElectromechanicalPropagator {
    /// With a held command the static position moves monotonically from f3(i(0)) to
    /// f3(ī). If no play of the hysteresis operator starts to move on the way, the
    /// operator's output is affine in the static position, u = C + f·x̄ (f the fraction of
    /// plays being dragged), and the closed-form series still applies: returns (C, f).
    fn hysteresis_as_linear(
        &self,
        current: f64,
        static_current: f64,
        plays: &[f64; PLAY_OPERATORS],
    ) -> Option<(f64, f64)> {
        let x_bar = |i: f64| jet_pipe::static_position(self.x_sat, self.f_sat, jet_pipe::tip_force(self.k_m, i));
        let (from, to) = (x_bar(current), x_bar(static_current));
        let rising = to >= from;
        let (mut constant, mut dragged) = (0.0, 0usize);
        for (p, r) in plays.iter().zip(&self.hysteresis.half_widths) {
            // Where the play is pushed from: the edge of its band on the moving side.
            let edge = if rising { from - r } else { from + r };
            let engaged = if rising { *p <= edge } else { *p >= edge };
            if engaged {
                dragged += 1;
                constant += if rising { -r } else { *r };
            } else {
                let engages_at = if rising { p + r } else { p - r };
                if (rising && engages_at < to) || (!rising && engages_at > to) {
                    return None;
                }
                constant += p;
            }
        }
        let n = PLAY_OPERATORS as f64;
        Some((constant / n, dragged as f64 / n))
    }
}

/// 1/(n + 1) for the series recurrence: a multiplication per term instead of a division.
const RECIPROCALS: [f64; MAX_SERIES_TERMS] = {
    let mut table = [0.0; MAX_SERIES_TERMS];
    let mut n = 0;
    while n < MAX_SERIES_TERMS {
        table[n] = 1.0 / (n as f64 + 1.0);
        n += 1;
    }
    table
};

/// Coefficients aₙ = cₙ εⁿ of tanh(x0 + ε r) = Σ aₙ rⁿ, truncated where they stop mattering.
fn tanh_series(x0: f64, epsilon: f64, max_terms: usize) -> Coefficients {
    let max_terms = max_terms.min(MAX_SERIES_TERMS);
    // The terms go to an array first, and to the small vector whole (indexing a SmallVec
    // checks where it lives at every element); only a series longer than the array spills.
    let mut inline = [0.0; INLINE_TERMS];
    inline[0] = x0.tanh();
    if epsilon == 0.0 {
        return Coefficients::from_buf_and_len(inline, 1);
    }
    let converged = |terms: &[f64]| match terms {
        [.., before, last] => terms.len() > 3 && last.abs() < 1e-17 && before.abs() < 1e-17,
        _ => false,
    };
    let mut count = 1;
    while count < max_terms.min(INLINE_TERMS) {
        inline[count] = next_tanh_term(&inline[..count], epsilon);
        count += 1;
        if converged(&inline[..count]) {
            return Coefficients::from_buf_and_len(inline, count);
        }
    }
    if count == max_terms {
        return Coefficients::from_buf_and_len(inline, count);
    }
    let mut spilled = Coefficients::from_slice(&inline);
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

/// For a held command with the series form, each mode is
///   q_k(s) = e^{λk s} (q_k(0) + β_k Σₙ aₙ/(λk + nω)) − β_k Σₙ aₙ rⁿ/(λk + nω),  r = e^{−ω s},
/// so the position and its derivatives are two exponentials plus a real polynomial in r
/// whose coefficients are summed over the modes once per step, not once per query.
#[derive(Clone, Debug)]
struct SeriesForm {
    /// q_k(0) + β_k Σₙ aₙ/(λk + nω).
    amplitude: [C64; 3],
    /// [`position_weights`] of `amplitude`.
    position_weights: [f64; 3],
    /// Coefficients of rⁿ in the position: −Re Σ_k β_k aₙ/(λk + nω). Those of the velocity
    /// and acceleration (moments 1 and 2 in place of 0) are summed where asked for, once per
    /// step at its end, from the series itself.
    position: Coefficients,
    /// From when on the position's terms n ≥ 1 sum to under 1e-16 of the saturated stroke:
    /// past it the position needs neither e^{−ω s} nor the polynomial.
    transient_over: f64,
}

impl SeriesForm {
    /// `None` when some λk + nω nearly vanishes (the term grows like s e^{λs}): the
    /// general per-query sum handles that case.
    fn new(p: &ElectromechanicalPropagator, q0: &[C64; 3], series: &[f64]) -> Option<Self> {
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
            ln_upper_bound(transient / negligible) / p.omega_cd
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
    fn modes(&self, p: &ElectromechanicalPropagator, series: &[f64], s: f64) -> [C64; 3] {
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
    fn growth(&self, p: &ElectromechanicalPropagator, s: f64) -> ([C64; 3], f64) {
        let e = p.exponentials(s, true);
        (growth_from(&self.amplitude, &e), e.decay)
    }

    /// Σ cₙ rⁿ as E(r²) + r O(r²), its even and odd parts by Horner side by side: half the
    /// dependent multiply-adds of one Horner chain, which the stage positions wait on.
    fn horner(coefficients: &[f64], r: f64) -> f64 {
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

    fn position(&self, p: &ElectromechanicalPropagator, s: f64) -> f64 {
        self.position_from(s, &p.exponentials(s, s < self.transient_over))
    }

    /// The position at `s` from the exponentials there (`decay` needed only before
    /// `transient_over`).
    fn position_from(&self, s: f64, e: &Exponentials) -> f64 {
        let polynomial = if s >= self.transient_over {
            self.position[0]
        } else {
            Self::horner(&self.position, e.decay)
        };
        modal_position(&self.position_weights, e) + polynomial
    }

    /// Bounds on the position over [0, s_end].
    fn position_bounds(&self, p: &ElectromechanicalPropagator, s_end: f64) -> (f64, f64) {
        let (constant, transient) = constant_and_spread(&self.position, 1.0);
        let (lo, hi) = modal_bounds(p, &self.amplitude, s_end);
        (lo + constant - transient, hi + constant + transient)
    }

    fn derivatives(&self, p: &ElectromechanicalPropagator, series: &[f64], s: f64) -> [f64; 3] {
        self.derivatives_from(p, series, &p.exponentials(s, true))
    }

    /// [`Self::derivatives`] from the exponentials at `s` (with `decay`), for the `series`
    /// the form was built from.
    fn derivatives_from(&self, p: &ElectromechanicalPropagator, series: &[f64], e: &Exponentials) -> [f64; 3] {
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
/// jet pipe input u(s) = x_sat tanh(α + β s) is a power series in τ = s/T, Σ bₙ τⁿ, on a
/// horizon T short enough for it to converge fast. Each mode q' = λq + βu then has the
/// polynomial particular solution q_p = −β Σ_j u⁽ʲ⁾/λ^{j+1} (a finite sum), so
///   x(s) = Σ_k Re[(q_k(0) − q_p,k(0)) e^{λk s}] + P(τ),  P = Σ_j g_j u⁽ʲ⁾, g_j = −Re Σ_k β_k/λ_k^{j+1}:
/// two exponentials plus a polynomial, like [`SeriesForm`], instead of quadrature on
/// 0.1 ms panels.
#[derive(Clone, Debug)]
struct RampForm {
    /// T, s: the form holds for 0 ≤ s ≤ T.
    horizon: f64,
    /// q_k(0) − q_p,k(0).
    amplitude: [C64; 3],
    /// [`position_weights`] of `amplitude`.
    position_weights: [f64; 3],
    /// P and its first two derivatives with respect to s, as polynomials in τ.
    polynomials: [Vec<f64>; 3],
    /// Each mode's particular solution q_p,k as a polynomial in τ.
    particular_modes: [Vec<C64>; 3],
}

impl RampForm {
    /// `alpha`, `beta`: tanh's argument α + β s. `None` when the series would need too
    /// many terms.
    fn new(p: &ElectromechanicalPropagator, q0: &[C64; 3], alpha: f64, beta: f64) -> Option<Self> {
        let radius = (alpha * alpha + std::f64::consts::FRAC_PI_2.powi(2)).sqrt();
        let horizon = RAMP_MAX_HORIZON.min(RAMP_SERIES_RATIO * radius / beta.abs());
        let mut input = tanh_series(alpha, beta * horizon, MAX_SERIES_TERMS);
        if input.len() >= MAX_SERIES_TERMS {
            return None;
        }
        for b in input.iter_mut() {
            *b *= p.x_sat;
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
            let mut g = 0.0;
            for k in 0..3 {
                // q_p,k(0) = −β_k Σ_j u^{(j)}(0) λ_k^{−(j+1)}
                amplitude[k] += p.beta[k] * inverse_power[k] * (u_j[0] * scale);
                g -= (p.beta[k] * inverse_power[k]).re;
            }
            for (m, c) in u_j.iter().enumerate() {
                particular[m] += g * scale * c;
                for k in 0..3 {
                    particular_modes[k][m] -= p.beta[k] * inverse_power[k] * (scale * c);
                }
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

    fn covers(&self, s: f64) -> bool {
        (0.0..=self.horizon).contains(&s)
    }

    fn growth(&self, p: &ElectromechanicalPropagator, s: f64) -> [C64; 3] {
        modal_growth(p, &self.amplitude, s)
    }

    fn position(&self, p: &ElectromechanicalPropagator, s: f64) -> f64 {
        self.position_from(s, &p.exponentials(s, false))
    }

    fn position_from(&self, s: f64, e: &Exponentials) -> f64 {
        modal_position(&self.position_weights, e) + SeriesForm::horner(&self.polynomials[0], s / self.horizon)
    }

    /// Bounds on the position over [0, s_end], s_end within the horizon.
    fn position_bounds(&self, p: &ElectromechanicalPropagator, s_end: f64) -> (f64, f64) {
        let (constant, spread) = constant_and_spread(&self.polynomials[0], s_end / self.horizon);
        let (lo, hi) = modal_bounds(p, &self.amplitude, s_end);
        (lo + constant - spread, hi + constant + spread)
    }

    fn derivatives(&self, p: &ElectromechanicalPropagator, s: f64) -> [f64; 3] {
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
    fn modes(&self, p: &ElectromechanicalPropagator, s: f64) -> [C64; 3] {
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
fn ln_upper_bound(x: f64) -> f64 {
    const MANTISSA: u64 = (1 << 52) - 1;
    let bits = x.to_bits();
    let exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let m = f64::from_bits((bits & MANTISSA) | (1023 << 52));
    exponent as f64 * std::f64::consts::LN_2 + (m - 1.0)
}

/// A polynomial Σ cₙ zⁿ on 0 ≤ z ≤ z_max, as its constant c₀ and a bound Σ_{n≥1} |cₙ| z_maxⁿ
/// on how far it moves from it.
fn constant_and_spread(coefficients: &[f64], z_max: f64) -> (f64, f64) {
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

/// Bounds over 0 ≤ s ≤ s_end on Re Σ_k amplitude_k e^{λk s}: the real mode moves
/// monotonically between its ends, the decaying complex pair stays within its moduli.
fn modal_bounds(p: &ElectromechanicalPropagator, amplitude: &[C64; 3], s_end: f64) -> (f64, f64) {
    let real = amplitude[0].re;
    let real_end = real * p.real_mode_growth.at(s_end);
    let ringing = modulus(amplitude[1]) + modulus(amplitude[2]);
    (real.min(real_end) - ringing, real.max(real_end) + ringing)
}

/// |c| for a modal amplitude (metres, far from overflow and underflow): the root of the
/// square, without the rescaling of `hypot`, which costs three times as much.
fn modulus(c: C64) -> f64 {
    c.norm_sqr().sqrt()
}

/// e^{λk s}·amplitude_k for the three modes (λ3 = conj(λ2), so one complex exponential).
fn modal_growth(p: &ElectromechanicalPropagator, amplitude: &[C64; 3], s: f64) -> [C64; 3] {
    growth_from(amplitude, &p.exponentials(s, false))
}

/// Weights (w₀, w₁, w₂) with Re Σ_k amplitude_k e^{λk s} = w₀ e^{λ1 s} + w₁ Re e^{λ2 s} +
/// w₂ Im e^{λ2 s}: the position's modal part in three products instead of three complex ones
/// (the pair's conjugate exponential folds into w₁ and w₂).
fn position_weights(amplitude: &[C64; 3]) -> [f64; 3] {
    [
        amplitude[0].re,
        amplitude[1].re + amplitude[2].re,
        amplitude[2].im - amplitude[1].im,
    ]
}

fn modal_position(weights: &[f64; 3], e: &Exponentials) -> f64 {
    weights[0] * e.real + weights[1] * e.oscillation.re + weights[2] * e.oscillation.im
}

fn growth_from(amplitude: &[C64; 3], e: &Exponentials) -> [C64; 3] {
    [
        amplitude[0] * e.real,
        amplitude[1] * e.oscillation,
        amplitude[2] * e.oscillation.conj(),
    ]
}

/// The exponentials a closed-form trajectory is made of, at one time s: e^{λ1 s} of the
/// real mode, e^{λ2 s} of the ringing pair (λ3 = conj λ2) and the current transient's
/// e^{−ω_cd s}. Those at s + δ are the products of those at s and at δ.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Exponentials {
    real: f64,
    oscillation: C64,
    decay: f64,
}

impl Exponentials {
    fn then(&self, advance: &Exponentials) -> Exponentials {
        Exponentials {
            real: self.real * advance.real,
            oscillation: self.oscillation * advance.oscillation,
            decay: self.decay * advance.decay,
        }
    }
}

impl ElectromechanicalPropagator {
    /// The exponentials at `s`; `decay` is left at 0 unless `with_decay`.
    fn exponentials(&self, s: f64, with_decay: bool) -> Exponentials {
        // A step's start, where most are asked for: exactly 1, without the calls.
        if s == 0.0 {
            return Exponentials {
                real: 1.0,
                oscillation: C64::new(1.0, 0.0),
                decay: if with_decay { 1.0 } else { 0.0 },
            };
        }
        let envelope = (self.lambda[1].re * s).exp();
        let (sin, cos) = (self.lambda[1].im * s).sin_cos();
        Exponentials {
            real: (self.lambda[0].re * s).exp(),
            oscillation: C64::new(envelope * cos, envelope * sin),
            decay: if with_decay { (-self.omega_cd * s).exp() } else { 0.0 },
        }
    }

    /// The exponentials at cᵢh for `nodes` cᵢ (`None` for more than [`MAX_NODES`]), kept
    /// per step size: stage positions are the product of the exponentials at the step's
    /// start and these, one set of transcendental functions per step instead of one per
    /// stage whenever the step size recurs, as it does while the chambers' integrator is
    /// capped at a quarter of the ringing period, and on its grid of step sizes otherwise.
    /// A step size met for the first time costs what positions one by one would, and
    /// takes the same product: the positions never depend on what the memo held, so a
    /// restored FMU state continues to the bit.
    fn with_advances<R>(&self, h: f64, nodes: &[f64], use_them: impl FnOnce(&[Exponentials]) -> R) -> Option<R> {
        if nodes.len() > MAX_NODES {
            return None;
        }
        let mut cache = self.advances.0.borrow_mut();
        if cache.nodes[..cache.count] != *nodes {
            cache.sets.clear();
            cache.nodes[..nodes.len()].copy_from_slice(nodes);
            cache.count = nodes.len();
        }
        if cache.sets.is_empty() {
            let unused = (f64::NAN, [Exponentials::default(); MAX_NODES]);
            cache.sets.resize(
                ADVANCE_SETS,
                AdvanceSet {
                    ways: [unused; 2],
                    older: 0,
                },
            );
        }
        // Two-way sets on the top mantissa bits and the low exponent bits, which tell the
        // integrator's grid sizes apart.
        let bits = h.to_bits();
        let set = &mut cache.sets[((bits >> 47) ^ (bits >> 52)) as usize % ADVANCE_SETS];
        let way = match set.ways.iter().position(|(kept, _)| *kept == h) {
            Some(way) => way,
            None => {
                let way = set.older;
                let (kept, advances) = &mut set.ways[way];
                *kept = h;
                for (advance, c) in advances.iter_mut().zip(nodes) {
                    *advance = self.exponentials(c * h, true);
                }
                way
            }
        };
        set.older = 1 - way;
        Some(use_them(&set.ways[way].1[..nodes.len()]))
    }
}

/// The closed form a trajectory's positions come from, when it has one.
#[derive(Clone, Copy)]
enum ClosedForm<'f> {
    Series(&'f SeriesForm),
    Ramp(&'f RampForm),
}

/// Most stages of one step [`Trajectory::node_positions`] takes: Verner's eight after the
/// first (Dormand–Prince has six).
pub const MAX_NODES: usize = 8;
/// Sets of two step sizes whose advances are kept (34 kB, allocated on first use): the
/// error-controlled steps and the rest of each communication step come in some hundred
/// sizes (the closed loop's current transients spread them most), and with 32 direct-mapped
/// slots three in ten steps of the closed loop recomputed theirs, with 128 in two-way sets
/// one in fifteen.
const ADVANCE_SETS: usize = 64;

#[derive(Clone, Debug, Default)]
struct AdvanceTable {
    nodes: [f64; MAX_NODES],
    count: usize,
    sets: Vec<AdvanceSet>,
}

/// Two step sizes and their advances (h is NaN in a way not yet used), and which of the two
/// was used less recently: the one a new size replaces.
#[derive(Clone, Copy, Debug)]
struct AdvanceSet {
    ways: [(f64, [Exponentials; MAX_NODES]); 2],
    older: usize,
}

/// A memo inside the propagator: it changes no result, so two propagators that differ
/// only in it are equal.
#[derive(Clone, Debug, Default)]
struct AdvanceCache(std::cell::RefCell<AdvanceTable>);

impl PartialEq for AdvanceCache {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// The current driver and jet pipe over one step, evaluable at any time within it.
pub struct Trajectory<'a> {
    propagator: &'a ElectromechanicalPropagator,
    base: f64,
    ramp: f64,
    delta: f64,
    q0: [C64; 3],
    /// x_sat·aₙ when the closed-form series applies; empty otherwise.
    series: Coefficients,
    /// The same series summed in closed form, for fast evaluation (see [`SeriesForm`]).
    series_form: Option<SeriesForm>,
    /// The closed form for a ramp without a current transient (see [`RampForm`]); boxed, as
    /// its polynomials are anyway, so the held commands' trajectories stay small to move.
    ramp_form: Option<Box<RampForm>>,
    /// Hysteresis play states at the start of the step.
    plays: [f64; PLAY_OPERATORS],
    /// For a held command integrated by quadrature: the time after which the current
    /// transient no longer moves the jet pipe input, the modal integrals up to then, and
    /// the input from then on.
    settled: Option<(f64, [C64; 3], f64)>,
    /// Where the current stops rising and starts falling or back, if within the step.
    turning_point: Option<f64>,
    /// Instants where the quadrature's integrand has a kink (the turning point, plays of
    /// the hysteresis operator starting to move): panels end there.
    kinks: Vec<f64>,
    /// Panel ends and the modal integrals up to them, filled as queries need them.
    panel_ends: std::cell::RefCell<Vec<(f64, [C64; 3])>>,
    /// For a held command whose jump is too large for the series: from when on the
    /// trajectory is the series-form one started there (queries from then on go to it).
    late: Option<(f64, Box<Trajectory<'a>>)>,
    /// The last stage time [`Self::node_positions`] took the series form's exponentials
    /// at (with the current transient's), and those exponentials: the step's end, where
    /// [`Self::state`] is asked next.
    last_node: std::cell::Cell<Option<(f64, Exponentials)>>,
}

impl Trajectory<'_> {
    /// The late part of the trajectory and the time into it, for `s` from its start on.
    fn late_at(&self, s: f64) -> Option<(&Self, f64)> {
        self.late
            .as_ref()
            .filter(|(from, _)| s >= *from)
            .map(|(from, late)| (&**late, s - from))
    }

    /// Coil current at `s` seconds into the step.
    pub fn current(&self, s: f64) -> f64 {
        self.base + self.ramp * s + self.delta * (-self.propagator.omega_cd * s).exp()
    }

    fn static_position(&self, s: f64) -> f64 {
        let p = self.propagator;
        jet_pipe::static_position(p.x_sat, p.f_sat, jet_pipe::tip_force(p.k_m, self.current(s)))
    }

    /// The hysteresis operator's play states at `s` (all at f3's output when it is off).
    pub fn plays_at(&self, s: f64) -> [f64; PLAY_OPERATORS] {
        if let Some((late, s)) = self.late_at(s) {
            return late.plays_at(s);
        }
        let operator = &self.propagator.hysteresis;
        if !operator.is_active() {
            return [self.static_position(s); PLAY_OPERATORS];
        }
        let mut plays = self.plays;
        if let Some(turn) = self.turning_point.filter(|&turn| turn < s) {
            operator.advance(&mut plays, self.static_position(turn));
        }
        operator.advance(&mut plays, self.static_position(s));
        plays
    }

    fn jet_input(&self, s: f64) -> f64 {
        if self.propagator.hysteresis.is_active() {
            PrandtlIshlinskii::output(&self.plays_at(s))
        } else {
            self.static_position(s)
        }
    }

    /// Kinks of the jet pipe input for a held command: the instants at which plays of the
    /// hysteresis operator start to move (the static position is monotone, so each is
    /// found by bisection), plus the current's turning point.
    fn find_kinks(&self) -> Vec<f64> {
        let mut kinks: Vec<f64> = self.turning_point.into_iter().collect();
        let operator = &self.propagator.hysteresis;
        if operator.is_active() && self.ramp == 0.0 {
            let settle = (self.delta.abs() / 1e-15).ln().max(0.0) / self.propagator.omega_cd;
            let (from, to) = (self.static_position(0.0), self.static_position(settle));
            let rising = to >= from;
            for (p, r) in self.plays.iter().zip(&operator.half_widths) {
                let engages_at = if rising { p + r } else { p - r };
                let inside = if rising {
                    engages_at > from && engages_at < to
                } else {
                    engages_at < from && engages_at > to
                };
                if !inside {
                    continue;
                }
                let (mut lo, mut hi) = (0.0, settle);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    let passed = if rising {
                        self.static_position(mid) >= engages_at
                    } else {
                        self.static_position(mid) <= engages_at
                    };
                    if passed {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                kinks.push(0.5 * (lo + hi));
            }
        }
        kinks.sort_by(|a, b| a.total_cmp(b));
        kinks
    }

    /// ∫ₐᵇ e^{λ(b−σ)} u(σ) dσ for each mode by an 8-point Gauss–Legendre rule.
    fn panel(&self, a: f64, b: f64) -> [C64; 3] {
        let p = self.propagator;
        let mut integral = [C64::new(0.0, 0.0); 3];
        let (centre, half) = (0.5 * (a + b), 0.5 * (b - a));
        for (node, weight) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
            let sigma = centre + half * node;
            let u = self.jet_input(sigma) * weight * half;
            for k in 0..3 {
                integral[k] += (p.lambda[k] * (b - sigma)).exp() * u;
            }
        }
        integral
    }

    /// ∫₀ˢ e^{λ(s−σ)} u(σ) dσ for each mode: composite Gauss–Legendre on panels of at most
    /// [`PANEL`] that end at every kink of u. The integrals at panel ends are kept, so a
    /// query costs one panel however far into the step it is.
    fn quadrature(&self, s: f64) -> [C64; 3] {
        let lambda = self.propagator.lambda;
        let carry = |integral: &[C64; 3], from: f64, to: f64, add: [C64; 3]| {
            let mut out = add;
            for k in 0..3 {
                out[k] += (lambda[k] * (to - from)).exp() * integral[k];
            }
            out
        };
        let mut table = self.panel_ends.borrow_mut();
        if table.is_empty() {
            table.push((0.0, [C64::new(0.0, 0.0); 3]));
        }
        loop {
            let (end, integral) = *table.last().expect("the table starts with 0");
            let next_kink = self.kinks.iter().copied().find(|&k| k > end * (1.0 + 1e-12) + 1e-15);
            let next = next_kink.map_or(end + PANEL, |k| k.min(end + PANEL));
            if next > s {
                break;
            }
            let value = carry(&integral, end, next, self.panel(end, next));
            table.push((next, value));
        }
        let j = table.partition_point(|(end, _)| *end <= s).saturating_sub(1);
        let (end, integral) = table[j];
        carry(&integral, end, s, self.panel(end, s))
    }

    /// Modal coordinates at `s`.
    fn modes(&self, s: f64) -> [C64; 3] {
        match &self.series_form {
            Some(form) => form.modes(self.propagator, &self.series, s),
            None => self.modes_by_sum(s),
        }
    }

    /// Modal coordinates from the series term by term, the ramp form, or quadrature.
    fn modes_by_sum(&self, s: f64) -> [C64; 3] {
        let p = self.propagator;
        let mut q = [C64::new(0.0, 0.0); 3];
        let mut integral = [C64::new(0.0, 0.0); 3];
        let growth = [
            (p.lambda[0] * s).exp(),
            (p.lambda[1] * s).exp(),
            (p.lambda[2] * s).exp(),
        ];
        if !self.series.is_empty() {
            // ∫₀ˢ e^{λ(s−σ)} e^{−nωσ} dσ = (e^{λs} − e^{−nωs}) / (λ + nω)
            let decay = (-p.omega_cd * s).exp();
            let mut decay_n = 1.0;
            for (n, a) in self.series.iter().enumerate() {
                let n_omega = n as f64 * p.omega_cd;
                for k in 0..3 {
                    let denominator = p.lambda[k] + n_omega;
                    integral[k] += if denominator.norm_sqr() > (1e-9 * p.omega_cd).powi(2) {
                        (growth[k] - decay_n) / denominator * *a
                    } else {
                        growth[k] * s * *a
                    };
                }
                decay_n *= decay;
            }
        } else if let Some(form) = self.ramp_form.as_ref().filter(|f| f.covers(s)) {
            return form.modes(p, s);
        } else if let Some((settled, at_settled, u_final)) = self.settled.filter(|(settled, _, _)| s > *settled) {
            // Past the current transient the input is constant: carry the integral up to
            // the settling time forward and add the constant input's part exactly.
            for k in 0..3 {
                let carry = (p.lambda[k] * (s - settled)).exp();
                integral[k] = carry * at_settled[k] + (carry - 1.0) / p.lambda[k] * u_final;
            }
        } else {
            integral = self.quadrature(s);
        }
        for k in 0..3 {
            q[k] = growth[k] * self.q0[k] + p.beta[k] * integral[k];
        }
        q
    }

    /// Amplitude (m) of the jet pipe's lightly damped oscillation at `s`. Where the response
    /// has a closed form this is exact: 2|c| e^{Re λ s} for the complex mode's homogeneous
    /// part c e^{λ s}, what is left once the part that follows the input is taken off (for a
    /// ramp, that part lags the input; it does not ring). Otherwise it is measured about the
    /// rest position of the static input at `s`: 2|q − q_rest|, q_rest = −β ū/λ.
    pub fn ringing_amplitude(&self, s: f64) -> f64 {
        if let Some((late, s)) = self.late_at(s) {
            return late.ringing_amplitude(s);
        }
        let p = self.propagator;
        let homogeneous = match (&self.series_form, &self.ramp_form) {
            (Some(form), _) => Some(form.amplitude[1]),
            (None, Some(form)) if form.covers(s) => Some(form.amplitude[1]),
            _ => None,
        };
        if let Some(c) = homogeneous {
            let envelope = if s == 0.0 { 1.0 } else { p.ringing_envelope.at(s) };
            return 2.0 * modulus(c) * envelope;
        }
        let q = self.modes(s);
        let u_rest = self.jet_input(s);
        2.0 * modulus(q[1] + p.beta[1] * u_rest / p.lambda[1])
    }

    /// Decay rate ζ2ω2 (1/s) and period 2π/ω_d (s) of that oscillation.
    pub fn ringing_decay_and_period(&self) -> (f64, f64) {
        let l = self.propagator.lambda[1];
        (-l.re, 2.0 * std::f64::consts::PI / l.im.abs())
    }

    /// Jet pipe positions at the stage offsets `offsets` (sᵢ = s0 + cᵢh up to rounding) of
    /// one step of a one-step method from `s0` with size `h` and nodes cᵢ, into `out`.
    /// Where the response has a closed form and `h` has come before, the exponentials are
    /// taken once, at s0, and carried to each stage by a product with those at cᵢh (see
    /// `ElectromechanicalPropagator::with_advances`); otherwise each is [`Self::position`].
    /// The two agree to rounding (`node_positions_match_the_positions`).
    pub fn node_positions(&self, s0: f64, h: f64, nodes: &[f64], offsets: &[f64], out: &mut [f64]) {
        if let Some((from, late)) = self
            .late
            .as_ref()
            .filter(|(from, _)| s0 >= *from && offsets.len() <= MAX_NODES)
        {
            let mut late_offsets = [0.0; MAX_NODES];
            for (late_s, s) in late_offsets.iter_mut().zip(offsets) {
                *late_s = s - from;
            }
            return late.node_positions(s0 - from, h, nodes, &late_offsets[..offsets.len()], out);
        }
        let p = self.propagator;
        let form = match (&self.series_form, &self.ramp_form) {
            (Some(form), _) => Some(ClosedForm::Series(form)),
            (None, Some(form)) if form.covers(s0) && offsets.iter().all(|&s| form.covers(s)) => {
                Some(ClosedForm::Ramp(form))
            }
            _ => None,
        };
        if let Some(form) = form {
            let with_decay = match form {
                ClosedForm::Series(series) => offsets.iter().any(|&s| s < series.transient_over),
                ClosedForm::Ramp(_) => false,
            };
            let done = p.with_advances(h, nodes, |advances| {
                // At a step's start the exponentials are 1, and the products the advances.
                let at_start = (s0 != 0.0).then(|| p.exponentials(s0, with_decay));
                let mut last = None;
                for ((x, &s), advance) in out.iter_mut().zip(offsets).zip(advances) {
                    let e = at_start.map_or(*advance, |start| start.then(advance));
                    *x = match form {
                        ClosedForm::Series(series) => series.position_from(s, &e),
                        ClosedForm::Ramp(ramp) => ramp.position_from(s, &e),
                    };
                    last = Some((s, e));
                }
                if with_decay && matches!(form, ClosedForm::Series(_)) {
                    self.last_node.set(last);
                }
            });
            if done.is_some() {
                return;
            }
        }
        let mut last: Option<(f64, f64)> = None;
        for (x, &s) in out.iter_mut().zip(offsets) {
            *x = match last {
                Some((at, position)) if at == s => position,
                _ => self.position(s),
            };
            last = Some((s, *x));
        }
    }

    /// Jet pipe position at `s` seconds into the step.
    pub fn position(&self, s: f64) -> f64 {
        if let Some((late, s)) = self.late_at(s) {
            return late.position(s);
        }
        if let Some(form) = &self.series_form {
            return form.position(self.propagator, s);
        }
        if let Some(form) = self.ramp_form.as_ref().filter(|f| f.covers(s)) {
            return form.position(self.propagator, s);
        }
        let q = self.modes(s);
        (q[0] + q[1] + q[2]).re
    }

    /// Bounds on the jet pipe position over [0, s_end] (m), where the response has a closed
    /// form (`None` elsewhere). They hold with a margin for rounding, and are tight when the
    /// jet pipe barely moves, which is when they are asked: a step whose bounds hold no
    /// tangency of the orifice geometry needs no search for one.
    pub fn position_bounds(&self, s_end: f64) -> Option<(f64, f64)> {
        let p = self.propagator;
        let (lo, hi) = if let Some(form) = &self.series_form {
            form.position_bounds(p, s_end)
        } else if let Some(form) = self.ramp_form.as_ref().filter(|f| f.covers(s_end)) {
            form.position_bounds(p, s_end)
        } else {
            return None;
        };
        let margin = 1e-12 * (lo.abs() + hi.abs() + p.x_sat);
        Some((lo - margin, hi + margin))
    }

    /// The full state at `s` seconds into the step.
    pub fn state(&self, s: f64) -> ElectromechanicalState {
        if let Some((late, s)) = self.late_at(s) {
            return late.state(s);
        }
        let closed_form = match (&self.series_form, &self.ramp_form) {
            (Some(form), _) => Some(match self.last_node.get() {
                // The current's transient e^{−ω s} is among the exponentials kept there.
                Some((at, e)) if at == s => (
                    form.derivatives_from(self.propagator, &self.series, &e),
                    self.base + self.ramp * s + self.delta * e.decay,
                ),
                _ => (form.derivatives(self.propagator, &self.series, s), self.current(s)),
            }),
            (None, Some(form)) if form.covers(s) => Some((form.derivatives(self.propagator, s), self.current(s))),
            _ => None,
        };
        if let Some(([position, velocity, acceleration], current)) = closed_form {
            return ElectromechanicalState {
                current,
                position,
                velocity,
                acceleration,
            };
        }
        let q = self.modes(s);
        let l = &self.propagator.lambda;
        ElectromechanicalState {
            current: self.current(s),
            position: (q[0] + q[1] + q[2]).re,
            velocity: (l[0] * q[0] + l[1] * q[1] + l[2] * q[2]).re,
            acceleration: (l[0] * l[0] * q[0] + l[1] * l[1] * q[1] + l[2] * l[2] * q[2]).re,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{OdeSystem, Sdirk4, Statistics, Tolerances};
    use nalgebra::SVector;

    #[test]
    fn gauss_rule_integrates_degree_15_exactly() {
        for degree in 0..=15 {
            let numeric: f64 = GAUSS_NODES
                .iter()
                .zip(GAUSS_WEIGHTS)
                .map(|(x, w)| w * x.powi(degree))
                .sum();
            let exact = if degree % 2 == 1 {
                0.0
            } else {
                2.0 / (degree + 1) as f64
            };
            assert!((numeric - exact).abs() < 1e-14, "degree {degree}: {numeric} vs {exact}");
        }
    }

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

    /// A jet pipe in mid-swing.
    fn swinging() -> ElectromechanicalState {
        ElectromechanicalState {
            current: 0.05,
            position: 1.2e-4,
            velocity: 0.02,
            acceleration: -30.0,
        }
    }

    /// Mid-swing, with the current lagging a ramp of `rate` V/s through `v` as a ramp
    /// continued from the last step does (so the ramp's closed form applies).
    fn ramp_start(p: &Parameters, v: f64, rate: f64) -> ElectromechanicalState {
        ElectromechanicalState {
            current: p.k_cd * v + p.i_offset - p.k_cd * rate / p.omega_cd,
            ..swinging()
        }
    }

    #[test]
    fn position_bounds_hold_the_trajectory_and_are_tight_when_it_barely_moves() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let settled = |v: f64| {
            let current = p.k_cd * v + p.i_offset;
            let position = jet_pipe::static_position(p.x_jp_sat, p.f_jp_sat, jet_pipe::tip_force(p.k_m, current));
            ElectromechanicalState {
                current,
                position,
                velocity: 0.0,
                acceleration: 0.0,
            }
        };
        let swinging = swinging();
        let ramp_start = |v: f64, rate: f64| ramp_start(&p, v, rate);
        let mut bounded = 0;
        for (start, v, rate, duration) in [
            (settled(2.0), 2.0, 0.0, 0.01),
            (settled(2.0), 2.001, 0.0, 0.001),
            (settled(2.0), -10.0, 0.0, 0.01),
            (swinging, 1.3, 0.0, 0.002),
            (swinging, 3.1, 0.0, 0.01),
            (ramp_start(1.0, 2.5), 1.0, 2.5, 0.01),
            (ramp_start(-3.0, -60.0), -3.0, -60.0, 0.01),
        ] {
            let trajectory = propagator.trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS]);
            let Some((lo, hi)) = trajectory.position_bounds(duration) else {
                // A full-scale swing takes tanh outside its series' reach: no closed form.
                assert_eq!(v, -10.0, "v {v} rate {rate}: bounds expected");
                continue;
            };
            bounded += 1;
            let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
            for j in 0..=4000 {
                let x = trajectory.position(duration * j as f64 / 4000.0);
                (min, max) = (min.min(x), max.max(x));
            }
            assert!(
                lo <= min && max <= hi,
                "v {v} rate {rate}: [{min}, {max}] not in [{lo}, {hi}]"
            );
            // A settled jet pipe is bounded to within a nanometre, a small step's bounds are
            // within an order of magnitude of its swing (the transient's terms and the modes
            // that cancel them are bounded apart): ~1e-7 m against tangencies D apart.
            if v == 2.0 {
                assert!(hi - lo < 1e-9, "settled: [{lo}, {hi}]");
            }
            if v == 2.001 {
                assert!(
                    hi - lo < 8.0 * (max - min) + 1e-12,
                    "small step: [{lo}, {hi}] vs [{min}, {max}]"
                );
            }
        }
        assert_eq!(bounded, 6);
    }

    /// Stage positions carried from the step's start by the advances of a recurring step
    /// size are the positions, to rounding: for a held command (with and without its
    /// current transient over within the step), a ramp, and a case with no closed form.
    #[test]
    fn node_positions_match_the_positions() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let swinging = swinging();
        let ramp_start = |v: f64, rate: f64| ramp_start(&p, v, rate);
        let nodes = [0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
        let mut fast_paths = 0;
        // The case without a closed form first (a ramp with its current transient): it must
        // not even record a step size. A jump too large for the series has none until it
        // has decayed enough, then the series form.
        for (start, v, rate, form) in [
            (swinging, 1.0, 400.0, "none"),
            (swinging, -10.0, 0.0, "late"),
            (swinging, 3.1, 0.0, "series"),
            (swinging, 1.3, 0.0, "series"),
            (ramp_start(1.0, 2.5), 1.0, 2.5, "ramp"),
        ] {
            let trajectory = propagator.trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS]);
            match form {
                "series" => assert!(trajectory.series_form.is_some()),
                "ramp" => assert!(trajectory.ramp_form.is_some()),
                _ => assert!(trajectory.series_form.is_none() && trajectory.ramp_form.is_none()),
            }
            let late_from = trajectory.late.as_ref().map(|(from, _)| *from);
            assert_eq!(late_from.is_some(), form == "late");
            if let Some(from) = late_from {
                // After the first step below, before the second.
                assert!(from > 8.5e-5 && from < 3.1e-4, "{from}");
            }
            // Early steps (transient alive) and late ones (past `transient_over` for the
            // held commands), each asked for twice: the second time takes the advances.
            // Both sum the modes' exponentials and round like the largest of them.
            let amplitudes = |t: &Trajectory| {
                t.series_form
                    .as_ref()
                    .map_or(0.0, |f| f.amplitude.iter().map(|a| modulus(*a)).sum::<f64>())
            };
            let largest_mode =
                amplitudes(&trajectory).max(trajectory.late.as_ref().map_or(0.0, |(_, l)| amplitudes(l)));
            for (s0, h) in [(0.0, 8.5e-5), (3.1e-4, 8.5e-5), (4.0e-3, 8.4e-4), (7.7e-3, 2.3e-3)] {
                let offsets: Vec<f64> = nodes.iter().map(|c| s0 + c * h).collect();
                let mut first_time = None;
                for _ in 0..2 {
                    let mut out = [0.0; 6];
                    trajectory.node_positions(s0, h, &nodes, &offsets, &mut out);
                    // The memo changes no bit: a step size met for the first time gives what
                    // it gives once kept (a restored FMU state continues exactly).
                    assert_eq!(*first_time.get_or_insert(out), out, "{form} s0 {s0} h {h}");
                    for (x, &s) in out.iter().zip(&offsets) {
                        let exact = trajectory.position(s);
                        assert!(
                            (x - exact).abs() <= 1e-15 * p.x_jp_sat.max(largest_mode),
                            "{form} v {v} s0 {s0} h {h} s {s}: {x} vs {exact}"
                        );
                    }
                    // The state at the last node, from the exponentials kept there, is a
                    // fresh trajectory's to rounding.
                    let end = *offsets.last().unwrap();
                    let kept = trajectory.state(end);
                    let fresh = propagator
                        .trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS])
                        .state(end);
                    let rate_scale = propagator.lambda.iter().map(|l| modulus(*l)).fold(0.0, f64::max);
                    let scale = 1e-15 * p.x_jp_sat.max(largest_mode);
                    assert!(
                        (kept.current - fresh.current).abs() <= 1e-15 * (fresh.current.abs() + trajectory.delta.abs()),
                        "{kept:?} {fresh:?}"
                    );
                    assert!((kept.position - fresh.position).abs() <= scale, "{kept:?} {fresh:?}");
                    assert!(
                        (kept.velocity - fresh.velocity).abs() <= scale * rate_scale,
                        "{kept:?} {fresh:?}"
                    );
                    assert!(
                        (kept.acceleration - fresh.acceleration).abs() <= scale * rate_scale * rate_scale,
                        "{kept:?} {fresh:?}"
                    );
                }
                let cached = propagator
                    .advances
                    .0
                    .borrow()
                    .sets
                    .iter()
                    .any(|set| set.ways.iter().any(|(kept, _)| *kept == h));
                let closed_form = match late_from {
                    Some(from) => s0 >= from,
                    None => form != "none",
                };
                assert_eq!(cached, closed_form, "{form} s0 {s0} h {h}");
                fast_paths += usize::from(cached);
            }
        }
        assert_eq!(fast_paths, 15);
        // The first two steps above lie before the transient is over, the last after it and
        // the third across it.
        let over = propagator
            .trajectory(&swinging, 3.1, 0.0, &[swinging.position; PLAY_OPERATORS])
            .series_form
            .expect("a series form for 3.1 V")
            .transient_over;
        assert!(over > 4.0e-3 && over < 4.0e-3 + 8.4e-4, "{over}");
    }

    #[test]
    fn ramp_form_matches_quadrature_and_a_tight_numerical_solution() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        for (v, rate) in [(1.0, 2.5), (4.0, -2.5), (2.5, 400.0), (-3.0, -60.0), (6.0, 1e-3)] {
            // A ramp continued from the previous step: the current already lags it by rate/ω.
            let current = p.k_cd * v + p.i_offset - p.k_cd * rate / p.omega_cd;
            let start = ElectromechanicalState {
                current,
                position: 1.2e-4,
                velocity: 0.02,
                acceleration: -30.0,
            };
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
        let current = p.k_cd * 1.0 + p.i_offset - p.k_cd * rate / p.omega_cd;
        let x0 = jet_pipe::static_position(p.x_jp_sat, p.f_jp_sat, jet_pipe::tip_force(p.k_m, current));
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

    /// The four electromechanical states of (4.1) with the command linear in time.
    struct Electromechanics(Parameters, f64, f64);
    impl OdeSystem<4> for Electromechanics {
        fn rhs(&self, t: f64, y: &SVector<f64, 4>) -> SVector<f64, 4> {
            let p = &self.0;
            let i_bar = p.k_cd * (self.1 + self.2 * t) + p.i_offset;
            let x_bar = jet_pipe::static_position(p.x_jp_sat, p.f_jp_sat, jet_pipe::tip_force(p.k_m, y[0]));
            SVector::<f64, 4>::new(
                p.omega_cd * (i_bar - y[0]),
                y[2],
                y[3],
                jet_pipe::third_derivative(p.omega_1, p.omega_2, p.zeta_2, x_bar, y[1], y[2], y[3]),
            )
        }
    }

    fn reference(p: &Parameters, start: SVector<f64, 4>, v: f64, rate: f64, s: f64) -> SVector<f64, 4> {
        let tol = Tolerances {
            relative: 1e-12,
            absolute: SVector::<f64, 4>::new(1e-14, 1e-16, 1e-13, 1e-10),
        };
        Sdirk4::default()
            .integrate(
                &Electromechanics(p.clone(), v, rate),
                0.0,
                start,
                s,
                &tol,
                &mut Statistics::default(),
            )
            .unwrap()
    }

    #[test]
    fn propagation_matches_a_tight_numerical_solution() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let start = ElectromechanicalState {
            current: 0.05,
            position: 1.2e-4,
            velocity: 0.02,
            acceleration: -30.0,
        };
        let y0 = SVector::<f64, 4>::new(start.current, start.position, start.velocity, start.acceleration);
        // small jump (series), large jumps (quadrature until the series converges, then the
        // series), and a ramp (quadrature)
        for (v, rate) in [(1.3, 0.0), (10.0, 0.0), (-8.0, 0.0), (1.0, 400.0)] {
            let trajectory = propagator.trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS]);
            assert_eq!(trajectory.late.is_some(), v.abs() > 5.0);
            for s in [1e-5, 3e-4, 2e-3, 1e-2] {
                let exact = trajectory.state(s);
                let y = reference(&p, y0, v, rate, s);
                assert!(
                    (exact.current - y[0]).abs() < 1e-10,
                    "v {v} s {s}: i {} vs {}",
                    exact.current,
                    y[0]
                );
                assert!(
                    (exact.position - y[1]).abs() < 1e-11,
                    "v {v} rate {rate} s {s}: x {} vs {}",
                    exact.position,
                    y[1]
                );
                assert!(
                    (exact.velocity - y[2]).abs() < 1e-7,
                    "v {v} s {s}: ẋ {} vs {}",
                    exact.velocity,
                    y[2]
                );
            }
        }
    }
}
