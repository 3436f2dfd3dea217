//! The propagator: the current driver (2.1)–(2.3) and the jet pipe's linear dynamics (2.6)
//! for one parameter set, as the physics states them (`physics::current_driver::CurrentDriver`,
//! the modes of `physics::jet_pipe::LinearDynamics`: eigenvalues λk, input gains βk, the
//! residues), with f3 (2.5) as a `physics::jet_pipe::StaticCurve`. Plus what every step's
//! closed forms share (the series terms' weights on the modes, and the exponentials e^{λk s}
//! and e^{−ω_cd s} they are made of). Built once per parameter set, so a step costs
//! multiplications; the hysteresis operator's affine stretches (plays) and parabolas (a Bouc–Wen branch) are recognised here too, as
//! they decide whether the series applies.

use crate::physics::current_driver::CurrentDriver;
use crate::physics::effects::{Hysteresis, PLAY_OPERATORS};
use crate::physics::jet_pipe::{self, LinearDynamics, StaticCurve, F3};
use crate::physics::parameters::Parameters;

use super::nodes::AdvanceCache;
use super::series::MAX_SERIES_TERMS;
use super::C64;

/// How far (in units of the hysteresis law's half-width) a parabola may depart from the
/// Bouc–Wen branch over a step for the closed-form series to stand in for quadrature: far
/// below the jet pipe position's own tolerance (1e-8 of a 0.08 mm half-width is 1e-12 m).
const QUADRATIC_TOLERANCE: f64 = 1e-8;

/// The hysteresis operator's output over a held command's step, where a closed form holds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum HysteresisOverStep {
    /// constant + slope·x̄ (plays that move or stay put throughout).
    Affine { constant: f64, slope: f64 },
    /// value + slope·d + curvature·d², d = x̄ − x̄(0) (a Bouc–Wen branch).
    Parabola { value: f64, slope: f64, curvature: f64 },
}

/// Precomputed modal form of the jet pipe for one parameter set, with f3 the curve `C`
/// (the model's [`F3`] unless a test asks for another).
#[derive(Clone, Debug, PartialEq)]
pub struct ElectromechanicalPropagator<C = F3> {
    /// The current driver, (2.1)–(2.3).
    pub(super) driver: CurrentDriver,
    /// k_m of the tip force, (2.4).
    pub(super) k_m: f64,
    /// f3, (2.5).
    pub(super) curve: C,
    /// x_jp_sat: the stroke against which a position is negligible.
    pub(super) x_sat: f64,
    /// The poles of (2.6).
    pub(super) lambda: [C64; 3],
    /// Rows of V⁻¹, V = [[1,1,1],[λ1,λ2,λ3],[λ1²,λ2²,λ3²]].
    pub(super) inverse: [[C64; 3]; 3],
    /// V⁻¹ b with b = [0, 0, ω1ω2²]: the residues of (2.6) at its poles.
    pub(super) beta: [C64; 3],
    /// The jet_pipe_hysteresis operator between f3 and the dynamics (inactive when off).
    pub(super) hysteresis: Hysteresis,
    /// What each term of a current transient's series does to the modes: see [`SeriesWeight`].
    /// Built once, so a step's trajectory costs multiplications instead of 3 complex
    /// divisions per term; it stops before the first n where λk + nω nearly vanishes.
    pub(super) series_weights: Vec<SeriesWeight>,
    /// The advances by cᵢh of the last few step sizes (see
    /// [`Trajectory::node_positions`](super::Trajectory::node_positions)).
    pub(super) advances: AdvanceCache,
    /// e^{Re λ1 s} and e^{Re λ2 s} at the last s asked for: the position bounds over a
    /// step and the ringing test ask at the same s every step of a regular grid.
    pub(super) real_mode_growth: ExpMemo,
    pub(super) ringing_envelope: ExpMemo,
    /// The exponentials at the last s asked for (see [`ExponentialsMemo`]).
    pub(super) last_exponentials: ExponentialsMemo,
    /// f3's tanh at the centre of the last series (a held command's steps share it).
    pub(super) tanh_memo: jet_pipe::TanhMemo,
    /// 2π/ω_d (s), the ringing pair's period, asked for twice a step.
    pub(super) ringing_period: f64,
    /// The quadrature's exponentials at a full panel's nodes (see [`full_panel_factors`]).
    pub(super) panel_factors: PanelFactors,
}

/// For the quadrature's full panel (of length [`PANEL`](super::trajectory::PANEL)), at its
/// Gauss nodes xⱼ: e^{λk h (1 − xⱼ)} and e^{−ω_cd h xⱼ}, h the half-length (the modes' growth
/// from a node to the panel's end, and the current transient's decay from its centre to the
/// node). Every full panel of every step shares them: they are taken once per parameter set.
/// Also e^{λk PANEL}, which carries the integral across a full panel.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct PanelFactors {
    pub(super) nodes: [([C64; 3], f64); 8],
    pub(super) across: [C64; 3],
}

pub(super) fn full_panel_factors(lambda: &[C64; 3], omega_cd: f64) -> PanelFactors {
    let panel = super::trajectory::PANEL;
    let half = 0.5 * panel;
    let mut nodes = [([C64::new(0.0, 0.0); 3], 0.0); 8];
    for (factor, node) in nodes.iter_mut().zip(super::trajectory::GAUSS_NODES) {
        for k in 0..3 {
            factor.0[k] = (lambda[k] * (half * (1.0 - node))).exp();
        }
        factor.1 = (-omega_cd * half * node).exp();
    }
    PanelFactors {
        nodes,
        across: [
            (lambda[0] * panel).exp(),
            (lambda[1] * panel).exp(),
            (lambda[2] * panel).exp(),
        ],
    }
}

/// [`ElectromechanicalPropagator::exponentials`] at the last s asked for, and whether with the
/// current transient's: each step asks for its state at the step's end, the same s from one
/// communication step to the next. A memo: it changes no result, so two propagators that
/// differ only in it are equal.
#[derive(Clone, Debug, Default)]
pub(super) struct ExponentialsMemo(std::cell::Cell<Option<(f64, Exponentials, bool)>>);

impl PartialEq for ExponentialsMemo {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// e^{rate·s} for a fixed rate, kept for the last s asked for. A memo: it changes no result,
/// so two propagators that differ only in it are equal.
#[derive(Clone, Debug)]
pub(super) struct ExpMemo {
    pub(super) rate: f64,
    pub(super) last: std::cell::Cell<Option<(f64, f64)>>,
}

impl ExpMemo {
    pub(super) fn new(rate: f64) -> Self {
        Self {
            rate,
            last: std::cell::Cell::new(None),
        }
    }

    pub(super) fn at(&self, s: f64) -> f64 {
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
pub(super) struct SeriesWeight {
    pub(super) modes: [C64; 3],
    pub(super) moments: [f64; 3],
}

impl ElectromechanicalPropagator {
    /// `None` when the jet pipe's eigenvalues are (nearly) repeated, e.g. ζ2 ≥ 1 or ω1 on
    /// the second-order pair: the modal form does not exist and callers integrate the
    /// full system instead.
    pub fn new(p: &Parameters) -> Option<Self> {
        Self::with_curve(p, F3::from_parameters(p))
    }
}

impl<C: StaticCurve> ElectromechanicalPropagator<C> {
    /// [`ElectromechanicalPropagator::new`] with `curve` as f3 (2.5). A curve that offers
    /// no power series has its input integrated by quadrature.
    pub fn with_curve(p: &Parameters, curve: C) -> Option<Self> {
        let dynamics = LinearDynamics::from_parameters(p);
        // The exponentials below take λ3 = conj λ2: a complex pair.
        if dynamics.zeta_2 >= 1.0 {
            return None;
        }
        let modes = dynamics.modes()?;
        let (lambda, inverse, beta) = (modes.poles, modes.from_state, modes.residues);
        let driver = CurrentDriver::from_parameters(p);
        let panel_factors = full_panel_factors(&lambda, driver.omega_cd);
        let mut series_weights = Vec::with_capacity(MAX_SERIES_TERMS);
        'terms: for n in 0..MAX_SERIES_TERMS {
            let n_omega = n as f64 * driver.omega_cd;
            let mut weight = SeriesWeight {
                modes: [C64::new(0.0, 0.0); 3],
                moments: [0.0; 3],
            };
            for k in 0..3 {
                let denominator = lambda[k] + n_omega;
                // Resonant: the term grows like s e^{λs}, which the series form does not hold.
                if denominator.norm_sqr() <= (1e-9 * driver.omega_cd).powi(2) {
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
            driver,
            k_m: p.k_m,
            curve,
            x_sat: p.x_jp_sat,
            lambda,
            inverse,
            beta,
            hysteresis: p.hysteresis(),
            series_weights,
            advances: AdvanceCache::default(),
            real_mode_growth: ExpMemo::new(lambda[0].re),
            ringing_envelope: ExpMemo::new(lambda[1].re),
            last_exponentials: ExponentialsMemo::default(),
            tanh_memo: jet_pipe::TanhMemo::default(),
            ringing_period: 2.0 * std::f64::consts::PI / lambda[1].im.abs(),
            panel_factors,
        })
    }
}

impl<C: StaticCurve> ElectromechanicalPropagator<C> {
    /// The static position f3(k_m i) for a current, (2.4)–(2.5).
    pub(super) fn static_position(&self, current: f64) -> f64 {
        self.curve.value(jet_pipe::tip_force(self.k_m, current))
    }

    /// With a held command the static position moves monotonically from f3(i(0)) to
    /// f3(ī). If no play of the hysteresis operator starts to move on the way, the
    /// operator's output is affine in the static position, u = C + f·x̄ (f the fraction of
    /// plays being dragged), and the closed-form series still applies. The Bouc–Wen law's
    /// branch is smooth: where it is a parabola in x̄ to within [`QUADRATIC_TOLERANCE`] of
    /// its half-width over the step's travel, so is the series (see
    /// [`Self::branch_as_quadratic`]).
    pub(super) fn hysteresis_over_step(
        &self,
        current: f64,
        static_current: f64,
        plays: &[f64; PLAY_OPERATORS],
    ) -> Option<HysteresisOverStep> {
        let (from, to) = (self.static_position(current), self.static_position(static_current));
        let half_widths = match self.hysteresis.play_half_widths() {
            Some(half_widths) => half_widths,
            None => return self.branch_as_quadratic(plays, from, to),
        };
        let rising = to >= from;
        let (mut constant, mut dragged) = (0.0, 0usize);
        for (p, r) in plays.iter().zip(half_widths) {
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
        Some(HysteresisOverStep::Affine {
            constant: constant / n,
            slope: dragged as f64 / n,
        })
    }

    /// The hysteresis output along a monotone move of the static position from `from` to
    /// `to` as c0 + c1 (x̄ − from) + c2 (x̄ − from)², through the law's exact values at both
    /// ends and the middle, if it stays within [`QUADRATIC_TOLERANCE`] half-widths of the
    /// law at the quarter points (`None` otherwise: the caller integrates by quadrature).
    fn branch_as_quadratic(&self, memory: &[f64; PLAY_OPERATORS], from: f64, to: f64) -> Option<HysteresisOverStep> {
        let law = &self.hysteresis;
        let span = to - from;
        let at = |fraction: f64| law.output_after(memory, from + fraction * span);
        let (y0, y_mid, y1) = (at(0.0), at(0.5), at(1.0));
        if span == 0.0 {
            return Some(HysteresisOverStep::Parabola {
                value: y0,
                slope: 0.0,
                curvature: 0.0,
            });
        }
        // Through the three points: in d = x̄ − from, y = y0 + c1 d + c2 d².
        let c2 = 2.0 * (y1 - 2.0 * y_mid + y0) / (span * span);
        let c1 = (y1 - y0) / span - c2 * span;
        let quadratic = |fraction: f64| {
            let d = fraction * span;
            y0 + c1 * d + c2 * d * d
        };
        let tolerance = QUADRATIC_TOLERANCE * law.scale();
        let fits = [0.25, 0.75].iter().all(|&f| (quadratic(f) - at(f)).abs() <= tolerance);
        fits.then_some(HysteresisOverStep::Parabola {
            value: y0,
            slope: c1,
            curvature: c2,
        })
    }
}

/// Bounds over 0 ≤ s ≤ s_end on Re Σ_k amplitude_k e^{λk s}: the real mode moves
/// monotonically between its ends, the decaying complex pair stays within its moduli.
pub(super) fn modal_bounds<C>(p: &ElectromechanicalPropagator<C>, amplitude: &[C64; 3], s_end: f64) -> (f64, f64) {
    let real = amplitude[0].re;
    let real_end = real * p.real_mode_growth.at(s_end);
    let ringing = modulus(amplitude[1]) + modulus(amplitude[2]);
    (real.min(real_end) - ringing, real.max(real_end) + ringing)
}

/// |c| for a modal amplitude (metres, far from overflow and underflow): the root of the
/// square, without the rescaling of `hypot`, which costs three times as much.
pub(super) fn modulus(c: C64) -> f64 {
    c.norm_sqr().sqrt()
}

/// e^{λk s}·amplitude_k for the three modes (λ3 = conj(λ2), so one complex exponential).
pub(super) fn modal_growth<C>(p: &ElectromechanicalPropagator<C>, amplitude: &[C64; 3], s: f64) -> [C64; 3] {
    growth_from(amplitude, &p.exponentials(s, false))
}

/// Weights (w₀, w₁, w₂) with Re Σ_k amplitude_k e^{λk s} = w₀ e^{λ1 s} + w₁ Re e^{λ2 s} +
/// w₂ Im e^{λ2 s}: the position's modal part in three products instead of three complex ones
/// (the pair's conjugate exponential folds into w₁ and w₂).
pub(super) fn position_weights(amplitude: &[C64; 3]) -> [f64; 3] {
    [
        amplitude[0].re,
        amplitude[1].re + amplitude[2].re,
        amplitude[2].im - amplitude[1].im,
    ]
}

pub(super) fn modal_position(weights: &[f64; 3], e: &Exponentials) -> f64 {
    weights[0] * e.real + weights[1] * e.oscillation.re + weights[2] * e.oscillation.im
}

pub(super) fn growth_from(amplitude: &[C64; 3], e: &Exponentials) -> [C64; 3] {
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
pub(super) struct Exponentials {
    pub(super) real: f64,
    pub(super) oscillation: C64,
    pub(super) decay: f64,
}

impl Exponentials {
    pub(super) fn then(&self, advance: &Exponentials) -> Exponentials {
        Exponentials {
            real: self.real * advance.real,
            oscillation: self.oscillation * advance.oscillation,
            decay: self.decay * advance.decay,
        }
    }
}

impl<C> ElectromechanicalPropagator<C> {
    /// The exponentials at `s`; `decay` is left at 0 unless `with_decay`.
    pub(super) fn exponentials(&self, s: f64, with_decay: bool) -> Exponentials {
        // A step's start, where most are asked for: exactly 1, without the calls.
        if s == 0.0 {
            return Exponentials {
                real: 1.0,
                oscillation: C64::new(1.0, 0.0),
                decay: if with_decay { 1.0 } else { 0.0 },
            };
        }
        if let Some((kept, e, has_decay)) = self.last_exponentials.0.get() {
            if kept == s && (has_decay || !with_decay) {
                return Exponentials {
                    decay: if with_decay { e.decay } else { 0.0 },
                    ..e
                };
            }
        }
        let e = self.exponentials_at(s, with_decay);
        self.last_exponentials.0.set(Some((s, e, with_decay)));
        e
    }

    /// [`Self::exponentials`] at s ≠ 0, computed.
    fn exponentials_at(&self, s: f64, with_decay: bool) -> Exponentials {
        let envelope = (self.lambda[1].re * s).exp();
        let (sin, cos) = (self.lambda[1].im * s).sin_cos();
        Exponentials {
            real: (self.lambda[0].re * s).exp(),
            oscillation: C64::new(envelope * cos, envelope * sin),
            decay: if with_decay {
                (-self.driver.omega_cd * s).exp()
            } else {
                0.0
            },
        }
    }
}
