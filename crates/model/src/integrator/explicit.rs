//! Explicit embedded Runge–Kutta for the stretches where the system is not stiff, with the
//! stiffness test of Hairer's DOPRI5 to say when it stops being so.
//!
//! Why: the chamber pressures are slow (the fluid poles of the standard scenarios lie between
//! −5 and −300 rad/s, against steps of ~0.3 ms set by the jet pipe's 295 Hz forcing), so an
//! implicit method's Newton iterations and Jacobians buy nothing there. Near the ends of the
//! stroke or at a √Δp flow law's steep end they do; [`super::Sdirk4`] takes over then.

use nalgebra::SVector;

use super::{error_norm, step_towards, OdeSystem, Statistics, Tolerances, MIN_STEP};

/// An embedded explicit Runge–Kutta pair, first same as last (its last stage is the slope at
/// the new solution, which is also the next step's first).
pub struct Tableau<const S: usize> {
    pub c: [f64; S],
    /// Strictly lower triangular; row S−1 holds the propagating weights b.
    pub a: [[f64; S]; S],
    /// b − b̂: the error estimate is h·Σ eᵢkᵢ.
    pub error_weights: [f64; S],
    /// Order of the embedded (lower-order) solution: the step size scales as error^(−1/(q+1)).
    pub embedded_order: u32,
    /// A stage at c = 1, whose difference from the last estimates h·‖J‖ (Hairer, Nørsett &
    /// Wanner I, §II.10, stiffness detection), and the bound on the negative real axis above
    /// which the method is stability- rather than accuracy-limited.
    pub stiffness_stage: usize,
    pub stability_boundary: f64,
    /// [`Tableau::singular_error_ratios`], written out: the integrator scales estimates by
    /// them at every breakpoint, and they cost fourteen `powf` to compute
    /// (`written_singular_ratios_are_the_computed_ones` keeps the two equal).
    pub singular_ratios: (f64, f64),
}

impl<const S: usize> Tableau<S> {
    /// By how much the error estimate under-reads the error of a step that starts, or ends,
    /// where the forcing grows like the 3/2 power of the time from it (a lens area opening):
    /// |Σ bᵢcᵢ^{3/2} − 2/5| / |Σ eᵢcᵢ^{3/2}|, with 1 − cᵢ for the end; at least 1. A smooth
    /// forcing's error expansion does not hold there, and Dormand–Prince's estimate sees
    /// only a ninth of the error of a step from such a point. (The integrator uses the
    /// ratios written out in `singular_ratios`; the tests check them against this.)
    #[cfg(test)]
    pub fn singular_error_ratios(&self) -> (f64, f64) {
        let ratio = |node: &dyn Fn(f64) -> f64| {
            let (mut quadrature, mut estimate) = (0.0, 0.0);
            for i in 0..S {
                let g = node(self.c[i]).powf(1.5);
                quadrature += self.a[S - 1][i] * g;
                estimate += self.error_weights[i] * g;
            }
            ((quadrature - 0.4).abs() / estimate.abs()).max(1.0)
        };
        (ratio(&|c| c), ratio(&|c| 1.0 - c))
    }
}

/// Dormand & Prince's 5(4) pair (Hairer, Nørsett & Wanner I, Table II.5.2).
pub const DORMAND_PRINCE_54: Tableau<7> = Tableau {
    c: [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0],
    a: [
        [0.0; 7],
        [0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0, 0.0],
        [
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
            0.0,
            0.0,
        ],
        [
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
            0.0,
        ],
    ],
    error_weights: [
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ],
    embedded_order: 4,
    stiffness_stage: 5,
    stability_boundary: 3.3,
    singular_ratios: (11.342_242_568_999_96, 3.245_564_693_225_630_6),
};

/// Verner's "most efficient" 6(5) pair (J. H. Verner, Numerically optimal Runge–Kutta pairs
/// with interpolants, Numer. Algorithms 53 (2010) 383–396, his RKV65.IIIXb "efficient"
/// coefficients): nine stages, the last at the new solution (first same as last), eight
/// right-hand sides per step against Dormand–Prince's six.
///
/// Why a second pair: its error estimate over-reads the quadrature error of an exponential
/// forcing e^{zt} (the jet pipe's ringing and current transient) for |z| up to a full
/// ringing period per step and hω_cd up to 40, where Dormand–Prince's under-reads beyond half
/// a period and from hω_cd = 3 on (`estimates_read_the_error_of_fast_exponential_forcing`). So
/// it needs no quarter-period cap while the jet pipe rings, and one step of it replaces the
/// two capped ones Dormand–Prince takes for a 1 ms communication step.
///
/// The coefficients are Verner's 40-digit values as published; the compiler rounds them.
#[allow(clippy::excessive_precision)]
pub const VERNER_65: Tableau<9> = Tableau {
    c: [
        0.0,
        0.06,
        0.095_933_333_333_333_333_33,
        0.1439,
        0.4973,
        0.9725,
        0.9995,
        1.0,
        1.0,
    ],
    a: [
        [0.0; 9],
        [0.06, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [
            0.019_239_962_962_962_962_962_96,
            0.076_693_370_370_370_370_370_37,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [0.035_975, 0.0, 0.107_925, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [
            1.318_683_415_233_148_260_919_747_276_431_735_612_861,
            0.0,
            -5.042_058_063_628_562_225_427_761_634_715_637_693_344,
            4.220_674_648_395_413_964_508_014_358_283_902_080_483,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            -41.872_591_664_327_514_618_037_577_806_443_468_129_05,
            0.0,
            159.432_562_163_137_491_770_036_566_907_034_683_045_3,
            -122.119_213_565_010_030_920_251_620_338_924_214_066_3,
            5.531_743_066_200_053_768_252_631_238_332_999_150_076,
            0.0,
            0.0,
            0.0,
            0.0,
        ],
        [
            -54.430_156_935_316_504_332_506_420_512_941_424_612_71,
            0.0,
            207.067_251_365_018_464_427_365_717_386_650_983_598_7,
            -158.610_813_784_589_999_182_874_242_436_505_859_946_9,
            6.991_816_585_950_242_321_992_597_280_791_793_907_096,
            -0.018_597_231_062_203_233_977_651_717_995_492_946_236_92,
            0.0,
            0.0,
            0.0,
        ],
        [
            -54.663_741_787_281_976_802_412_156_480_503_869_593_51,
            0.0,
            207.952_806_255_389_373_451_582_481_669_983_424_423_8,
            -159.288_957_474_499_507_150_895_980_587_142_665_421_6,
            7.018_743_740_796_944_434_698_170_760_964_252_490_817,
            -0.018_338_785_905_045_723_064_727_820_051_417_382_683_61,
            -0.000_511_948_499_788_209_907_787_543_249_724_516_839_584_0,
            0.0,
            0.0,
        ],
        [
            0.034_389_578_683_570_360_092_788_201_247_283_223_865_20,
            0.0,
            0.0,
            0.258_262_455_563_350_340_465_955_809_858_612_085_876_7,
            0.420_937_118_967_353_715_064_255_151_406_980_196_703_2,
            4.405_396_469_669_310_170_148_836_816_197_095_664_891,
            -176.483_119_024_298_657_615_174_094_249_900_212_502_9,
            172.364_133_401_415_073_029_402_258_271_190_241_331_5,
            0.0,
        ],
    ],
    error_weights: [
        -0.014_710_097_800_254_537_216_280_348_032_429_034_499_59,
        0.0,
        0.0,
        0.033_151_232_611_697_925_125_816_277_804_624_552_928_20,
        -0.048_531_106_335_602_488_878_939_701_097_758_544_552_10,
        3.598_817_244_670_423_399_385_420_635_297_573_866_747,
        -176.483_119_024_298_657_615_174_094_249_900_212_502_9,
        172.971_252_890_592_869_009_169_553_417_715_863_043_7,
        -0.056_861_139_440_475_692_411_476_031_787_661_381_535_94,
    ],
    embedded_order: 5,
    stiffness_stage: 7,
    // |R(z)| = 1 at z = −4.855 on the negative real axis.
    stability_boundary: 4.8,
    // The estimate does not under-read a 3/2 power at either end (both ratios come out
    // below 1 and are clamped there).
    singular_ratios: (1.0, 1.0),
};

/// Accepted steps in a row that must look stiff before the explicit method gives up; and how
/// many non-stiff ones clear that count (DOPRI5's 15 and 6).
const STIFF_STEPS_TO_SWITCH: u32 = 15;
const NON_STIFF_STEPS_TO_FORGET: u32 = 6;

/// Why the explicit method handed over before the end time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Handover<const N: usize> {
    pub time: f64,
    pub state: SVector<f64, N>,
}

/// Step-size memory shared with the implicit method that takes over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepMemory {
    pub next_step: f64,
    pub max_step: f64,
    pub first_step: Option<f64>,
}

/// ln 1e-4: the PI controller's memory of the last error is at least 1e-4.
const LN_ERROR_FLOOR: f64 = -9.210_340_371_976_182;

/// Mantissa bits a step size keeps (32 evenly spaced sizes per octave, each less than
/// 1/32 below the size asked for).
const STEP_GRID_BITS: u32 = 5;

/// `h` rounded down onto a grid of 32 step sizes per octave, unless it is the cap
/// `max_step`. A system that works out its forcing for all stages of a step at once
/// ([`OdeSystem::prepare_stages`]) can then reuse that work whenever a step size recurs,
/// instead of meeting a new size at nearly every step.
fn on_step_grid(h: f64, max_step: f64) -> f64 {
    if h == max_step || !h.is_finite() || h <= 0.0 {
        return h;
    }
    f64::from_bits(h.to_bits() & !((1u64 << (52 - STEP_GRID_BITS)) - 1))
}

/// A pair's tableau as a compile-time constant: [`integrate`] is compiled once per pair, its
/// stages unrolled, so each coefficient is a constant and each zero one costs nothing (with
/// the tableau read at run time, testing the coefficients for zero cost as much as the
/// stage sums: 1.8 % of a 1 ms step's instructions, callgrind, the standard scenario).
pub trait Pair<const S: usize> {
    const TABLEAU: Tableau<S>;
}

/// [`DORMAND_PRINCE_54`] as a [`Pair`].
pub struct DormandPrince;

impl Pair<7> for DormandPrince {
    const TABLEAU: Tableau<7> = DORMAND_PRINCE_54;
}

/// [`VERNER_65`] as a [`Pair`].
pub struct Verner;

impl Pair<9> for Verner {
    const TABLEAU: Tableau<9> = VERNER_65;
}

/// Most stages a [`Pair`] may have (Verner's nine); the stages are unrolled up to it.
const MAX_STAGES: usize = 9;

/// Stage i's state, y + Σ_j h a_ij k_j over the non-zero a_ij in order of j: one unrolled sum
/// per row, its coefficients constants, so that only the stages' one right-hand side is
/// compiled into the integrator's loop (eight inlined copies of it made the code too large
/// for the instruction cache).
#[inline(always)]
fn stage_sum<const N: usize, const S: usize, P: Pair<S>>(
    i: usize,
    y: &SVector<f64, N>,
    k: &[SVector<f64, N>; S],
    h: f64,
) -> SVector<f64, N> {
    macro_rules! row {
        ($i:literal) => {{
            let mut stage = *y;
            if $i < S {
                for j in 0..$i {
                    let a = P::TABLEAU.a[$i][j];
                    if a != 0.0 {
                        stage += k[j] * (h * a);
                    }
                }
            }
            stage
        }};
    }
    match i {
        1 => row!(1),
        2 => row!(2),
        3 => row!(3),
        4 => row!(4),
        5 => row!(5),
        6 => row!(6),
        7 => row!(7),
        _ => row!(8),
    }
}

/// Integrate from (t0, y0) towards t1 with the pair `P`. Returns the state at t1, or a handover
/// (last accepted time and state) when the system turned stiff or the step size collapsed.
pub fn integrate<const N: usize, const S: usize, P: Pair<S>, Sys: OdeSystem<N>>(
    memory: &mut StepMemory,
    system: &Sys,
    t0: f64,
    y0: SVector<f64, N>,
    t1: f64,
    tol: &Tolerances<N>,
    stats: &mut Statistics,
) -> Result<SVector<f64, N>, Handover<N>> {
    let tableau = &P::TABLEAU;
    assert!(S <= MAX_STAGES, "a pair of at most {MAX_STAGES} stages");
    let exponent = 1.0 / (tableau.embedded_order as f64 + 1.0);
    let mut t = t0;
    let mut y = y0;
    let mut h = memory.next_step.min(memory.max_step).max(MIN_STEP);
    let mut slope = system.rhs(t, &y);
    stats.rhs_evaluations += 1;
    let mut last_rejected = false;
    // ln of the last accepted error (at least 1e-4), kept as a logarithm so the PI
    // controller takes one `ln` and one `exp` per step instead of two `powf`.
    let mut ln_previous_error = LN_ERROR_FLOOR;
    let (mut stiff_count, mut non_stiff_count) = (0, 0);
    let mut last_breakpoint: Option<f64> = None;
    let span = t1 - t0;
    let mut k = [SVector::<f64, N>::zeros(); S];
    while t1 - t > 1e-15 * span.abs().max(t1.abs()) {
        let (h_try, step_end, to_breakpoint) = step_towards(system, t, h, t1, span);
        let from_breakpoint = last_breakpoint == Some(t);
        k[0] = slope;
        let i_stiff = tableau.stiffness_stage;
        let mut stiffness_stage = y;
        let mut y_new = y;
        let mut stage_times = [t; S];
        for i in 1..S {
            stage_times[i] = match step_end {
                Some(end) if i == S - 1 => end,
                _ => t + tableau.c[i] * h_try,
            };
        }
        system.prepare_stages(t, h_try, &tableau.c[1..], &stage_times[1..]);
        for i in 1..S {
            let stage = stage_sum::<N, S, P>(i, &y, &k, h_try);
            k[i] = system.rhs_at_stage(i - 1, stage_times[i], &stage);
            if i == i_stiff {
                stiffness_stage = stage;
            }
            if i == S - 1 {
                y_new = stage;
            }
        }
        stats.rhs_evaluations += S as u64 - 1;
        let mut difference = SVector::<f64, N>::zeros();
        for (i, &e) in tableau.error_weights.iter().enumerate() {
            if e != 0.0 {
                difference += k[i] * (h_try * e);
            }
        }
        let mut error = error_norm(&difference, &y, &y_new, tol);
        if from_breakpoint || to_breakpoint {
            let (from_start, from_end) = tableau.singular_ratios;
            error *= match (from_breakpoint, to_breakpoint) {
                (true, true) => from_start.max(from_end),
                (true, false) => from_start,
                _ => from_end,
            };
        }
        if error.is_finite() && error <= 1.0 && y_new.iter().all(|v| v.is_finite()) {
            stats.steps += 1;
            memory.first_step.get_or_insert(h_try);
            let spread = (y_new - stiffness_stage).norm_squared();
            if spread > 0.0 {
                let h_rho_squared = (k[S - 1] - k[i_stiff]).norm_squared() / spread * h_try * h_try;
                if h_rho_squared > tableau.stability_boundary * tableau.stability_boundary {
                    non_stiff_count = 0;
                    stiff_count += 1;
                } else {
                    non_stiff_count += 1;
                    if non_stiff_count == NON_STIFF_STEPS_TO_FORGET {
                        stiff_count = 0;
                    }
                }
            }
            t = step_end.unwrap_or(t + h_try);
            y = y_new;
            slope = k[S - 1];
            let ln_error = error.ln();
            let mut factor = if error == 0.0 {
                5.0
            } else {
                0.9 * (exponent * (-0.7 * ln_error + 0.4 * ln_previous_error)).exp()
            };
            ln_previous_error = ln_error.max(LN_ERROR_FLOOR);
            factor = factor.clamp(0.2, 5.0);
            if last_rejected {
                factor = factor.min(1.0);
            }
            last_rejected = false;
            let mut proposed = on_step_grid((h_try * factor).min(memory.max_step), memory.max_step);
            if to_breakpoint {
                last_breakpoint = step_end;
            }
            // Near a breakpoint the error estimate holds only for steps short against the
            // distance from it (growth 2 keeps it within a factor 1.4 for a 3/2 power).
            if let Some(b) = last_breakpoint.filter(|&b| t > b) {
                proposed = proposed.min(2.0 * (t - b));
            }
            h = if step_end.is_some() && h_try < h {
                h.max(proposed)
            } else {
                proposed
            };
            if stiff_count >= STIFF_STEPS_TO_SWITCH && t < t1 {
                memory.next_step = h;
                return Err(Handover { time: t, state: y });
            }
        } else {
            stats.rejected += 1;
            last_rejected = true;
            let factor = if error.is_finite() {
                (0.9 * error.powf(-exponent)).clamp(0.1, 0.9)
            } else {
                0.25
            };
            h = on_step_grid(h_try * factor, memory.max_step);
            if h < MIN_STEP.max(1e-12 * t.abs()) {
                memory.next_step = 1e-5;
                return Err(Handover { time: t, state: y });
            }
        }
    }
    memory.next_step = h;
    Ok(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rooted tree's order, γ, elementary weight vector Φ over the stages, and |Φ| computed
    /// with |A|: the scale of the rounding in Φ (Verner's coefficients reach 207 and cancel).
    type Tree = (usize, f64, Vec<f64>, Vec<f64>);

    /// Every rooted tree up to `max_order`: a tree is a root with a multiset of subtrees,
    /// Φ = Π_k A·Φ(t_k) elementwise and γ = order · Π_k γ(t_k) (Hairer, Nørsett & Wanner I,
    /// §II.2). The order conditions are b·Φ(t) = 1/γ(t).
    fn trees<const S: usize>(t: &Tableau<S>, max_order: usize) -> Vec<Tree> {
        let a_times = |v: &[f64], absolute: bool| -> Vec<f64> {
            (0..S)
                .map(|i| {
                    (0..S)
                        .map(|j| {
                            if absolute {
                                (t.a[i][j] * v[j]).abs()
                            } else {
                                t.a[i][j] * v[j]
                            }
                        })
                        .sum()
                })
                .collect()
        };
        let mut all: Vec<Tree> = vec![(1, 1.0, vec![1.0; S], vec![1.0; S])];
        // Children are taken in non-decreasing index order, so each multiset comes once.
        #[allow(clippy::too_many_arguments)]
        fn extend(
            all: &[Tree],
            a_phi: &[(Vec<f64>, Vec<f64>)],
            remaining: usize,
            first: usize,
            gamma: f64,
            phi: Vec<f64>,
            size: Vec<f64>,
            out: &mut Vec<(f64, Vec<f64>, Vec<f64>)>,
        ) {
            if remaining == 0 {
                out.push((gamma, phi, size));
                return;
            }
            for k in first..all.len() {
                let (order, g, _, _) = &all[k];
                if *order > remaining {
                    continue;
                }
                let product = phi.iter().zip(&a_phi[k].0).map(|(x, y)| x * y).collect();
                let bound = size.iter().zip(&a_phi[k].1).map(|(x, y)| x * y).collect();
                extend(all, a_phi, remaining - order, k, gamma * g, product, bound, out);
            }
        }
        for order in 2..=max_order {
            let a_phi: Vec<(Vec<f64>, Vec<f64>)> = all
                .iter()
                .map(|(_, _, phi, size)| (a_times(phi, false), a_times(size, true)))
                .collect();
            let mut built = vec![];
            extend(&all, &a_phi, order - 1, 0, 1.0, vec![1.0; S], vec![1.0; S], &mut built);
            all.extend(
                built
                    .into_iter()
                    .map(|(g, phi, size)| (order, order as f64 * g, phi, size)),
            );
        }
        all
    }

    /// The propagating weights satisfy every order condition up to `order`, the embedded
    /// ones up to `order − 1` and not all of `order`.
    fn assert_order<const S: usize>(t: &Tableau<S>, order: usize) {
        let b: Vec<f64> = t.a[S - 1].to_vec();
        let b_hat: Vec<f64> = (0..S).map(|i| b[i] - t.error_weights[i]).collect();
        for i in 0..S {
            let row: f64 = t.a[i].iter().sum();
            let size: f64 = t.a[i].iter().map(|x| x.abs()).sum();
            assert!(
                (row - t.c[i]).abs() <= 8.0 * f64::EPSILON * size,
                "row {i} sums to {row}"
            );
        }
        let all = trees(t, order);
        assert_eq!(
            all.len(),
            [1, 2, 4, 8, 17, 37][order - 1],
            "rooted trees up to order {order}"
        );
        // Rounding stays within a few ulps of Σ|wᵢ|·|Φ|ᵢ; a wrong digit in a coefficient does not.
        let residual = |w: &[f64], phi: &[f64], size: &[f64], gamma: f64| {
            let sum: f64 = w.iter().zip(phi).map(|(x, y)| x * y).sum();
            let scale: f64 = w.iter().zip(size).map(|(x, y)| (x * y).abs()).sum();
            ((sum - 1.0 / gamma).abs(), 16.0 * f64::EPSILON * scale)
        };
        let mut embedded_fails = false;
        for (n, (tree_order, gamma, phi, size)) in all.iter().enumerate() {
            let (r, allowed) = residual(&b, phi, size, *gamma);
            assert!(
                r <= allowed,
                "tree {n} (order {tree_order}, γ {gamma}) for b: residual {r:e} > {allowed:e}"
            );
            let (r, allowed) = residual(&b_hat, phi, size, *gamma);
            if *tree_order < order {
                assert!(
                    r <= allowed,
                    "tree {n} (order {tree_order}, γ {gamma}) for b̂: residual {r:e} > {allowed:e}"
                );
            } else if r > 1e-6 {
                embedded_fails = true;
            }
        }
        assert!(embedded_fails, "the embedded weights must be of lower order");
        assert_eq!(t.c[t.stiffness_stage], t.c[S - 1]);
        assert_eq!(t.embedded_order as usize, order - 1);
    }

    #[test]
    fn dormand_prince_and_verner_satisfy_their_order_conditions() {
        assert_order(&DORMAND_PRINCE_54, 5);
        assert_order(&VERNER_65, 6);
    }

    /// What each pair's estimate sees of a step's quadrature error for a forcing e^{zτ}
    /// (τ = t/h): |Σ bᵢe^{zcᵢ} − (e^z − 1)/z| against |Σ eᵢe^{zcᵢ}|, for the jet pipe's
    /// ringing (z = 2πi·steps per period) and current transient (z = −hω_cd). Above 1 the
    /// estimate under-reads the error: why Dormand–Prince is capped at a quarter of the
    /// ringing period while the jet pipe rings, and Verner need not be within a period.
    #[test]
    fn estimates_read_the_error_of_fast_exponential_forcing() {
        type C64 = nalgebra::Complex<f64>;
        fn under_reading<const S: usize>(t: &Tableau<S>, z: C64) -> f64 {
            let b = &t.a[S - 1];
            let (mut quadrature, mut estimate) = (C64::new(0.0, 0.0), C64::new(0.0, 0.0));
            for i in 0..S {
                let e = (z * t.c[i]).exp();
                quadrature += b[i] * e;
                estimate += t.error_weights[i] * e;
            }
            (quadrature - (z.exp() - 1.0) / z).norm() / estimate.norm()
        }
        let ringing = |fraction: f64| C64::new(0.0, 2.0 * std::f64::consts::PI * fraction);
        let transient = |h_omega: f64| C64::new(-h_omega, 0.0);
        // Verner over-reads (by at least 5×) up to a period and hω_cd = 40.
        for k in 1..=20 {
            let fraction = k as f64 / 20.0;
            assert!(
                under_reading(&VERNER_65, ringing(fraction)) < 0.2,
                "Verner, {fraction} period"
            );
        }
        for k in 1..=40 {
            assert!(
                under_reading(&VERNER_65, transient(k as f64)) < 0.75,
                "Verner, hω = {k}"
            );
        }
        // Dormand–Prince over-reads up to a quarter period, not from half a period on, and
        // under-reads the transient from hω_cd = 3 (the 0.85 ms cap is hω_cd = 6).
        assert!(under_reading(&DORMAND_PRINCE_54, ringing(0.25)) < 0.5);
        assert!(under_reading(&DORMAND_PRINCE_54, ringing(0.6)) > 1.0);
        assert!(under_reading(&DORMAND_PRINCE_54, transient(3.0)) > 1.0);
        assert!(under_reading(&DORMAND_PRINCE_54, transient(6.0)) > 4.0);
    }

    #[test]
    fn step_sizes_go_onto_a_grid_of_32_per_octave_below_the_request() {
        let cap = 8.461_678_959_015_4e-4;
        let mut sizes = std::collections::BTreeSet::new();
        for k in 0..10_000 {
            let h = 1e-4 * (1.0 + 9.0 * k as f64 / 10_000.0);
            let on_grid = on_step_grid(h, cap);
            assert!(on_grid <= h && on_grid > h * (1.0 - 1.0 / 32.0), "{h} -> {on_grid}");
            assert_eq!(on_step_grid(on_grid, cap), on_grid, "{on_grid} is not on the grid");
            sizes.insert(on_grid.to_bits());
        }
        // From 1e-4 to 1e-3: log2(10) = 3.3 octaves of 32 sizes each (evenly spaced within
        // an octave, so the partial octaves at the ends hold 11.6 and 0.8), and the size
        // just below 1e-4.
        assert!((107..=110).contains(&sizes.len()), "{} sizes", sizes.len());
        assert_eq!(on_step_grid(cap, cap), cap);
        assert_eq!(on_step_grid(f64::INFINITY, cap), f64::INFINITY);
        assert_eq!(LN_ERROR_FLOOR, 1e-4f64.ln());
    }

    #[test]
    fn written_singular_ratios_are_the_computed_ones() {
        let (start, end) = DORMAND_PRINCE_54.singular_error_ratios();
        let (written_start, written_end) = DORMAND_PRINCE_54.singular_ratios;
        assert!(
            (start - written_start).abs() < 1e-12 * start,
            "{start} vs {written_start}"
        );
        assert!((end - written_end).abs() < 1e-12 * end, "{end} vs {written_end}");
        assert_eq!(VERNER_65.singular_error_ratios(), VERNER_65.singular_ratios);
    }

    /// The under-reading at a 3/2-power singularity, checked on y' = (t − t0)^{3/2} and
    /// y' = (t0 + h − t)^{3/2}, where one step's error and estimate are known exactly.
    #[test]
    fn singular_ratios_are_what_one_step_shows() {
        struct Power {
            from_start: bool,
            t0: f64,
            h: f64,
        }
        impl OdeSystem<1> for Power {
            fn rhs(&self, t: f64, _y: &SVector<f64, 1>) -> SVector<f64, 1> {
                let s = if self.from_start {
                    t - self.t0
                } else {
                    self.t0 + self.h - t
                };
                SVector::<f64, 1>::new(s.max(0.0).powf(1.5))
            }
        }
        let (start, end) = DORMAND_PRINCE_54.singular_error_ratios();
        assert!(
            (start - 11.34).abs() < 0.01 && (end - 3.25).abs() < 0.01,
            "{start} {end}"
        );
        for (from_start, expected) in [(true, start), (false, end)] {
            let (t0, h) = (0.3, 0.01);
            let system = Power { from_start, t0, h };
            // One step of exactly h (max_step = h; a huge tolerance accepts it).
            let mut memory = StepMemory {
                next_step: h,
                max_step: h,
                first_step: None,
            };
            let tol = Tolerances {
                relative: 0.0,
                absolute: SVector::<f64, 1>::new(1.0),
            };
            let mut stats = Statistics::default();
            let y = integrate::<1, 7, DormandPrince, _>(
                &mut memory,
                &system,
                t0,
                SVector::<f64, 1>::zeros(),
                t0 + h,
                &tol,
                &mut stats,
            )
            .unwrap();
            let error = (y[0] - h.powf(2.5) / 2.5).abs();
            let k: Vec<f64> = DORMAND_PRINCE_54
                .c
                .iter()
                .map(|&c| system.rhs(t0 + c * h, &SVector::<f64, 1>::zeros())[0])
                .collect();
            let estimate: f64 = (0..7)
                .map(|i| DORMAND_PRINCE_54.error_weights[i] * k[i] * h)
                .sum::<f64>()
                .abs();
            assert_eq!(stats.steps, 1);
            assert!(
                (error / estimate - expected).abs() < 1e-6 * expected,
                "{} vs {expected}",
                error / estimate
            );
        }
    }
}
