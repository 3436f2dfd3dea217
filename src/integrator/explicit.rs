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
    /// only a ninth of the error of a step from such a point.
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

/// Integrate from (t0, y0) towards t1 with `tableau`. Returns the state at t1, or a handover
/// (last accepted time and state) when the system turned stiff or the step size collapsed.
pub fn integrate<const N: usize, const S: usize, Sys: OdeSystem<N>>(
    tableau: &Tableau<S>,
    memory: &mut StepMemory,
    system: &Sys,
    t0: f64,
    y0: SVector<f64, N>,
    t1: f64,
    tol: &Tolerances<N>,
    stats: &mut Statistics,
) -> Result<SVector<f64, N>, Handover<N>> {
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
        for (i, time) in stage_times.iter_mut().enumerate().skip(1) {
            *time = match step_end {
                Some(end) if i == S - 1 => end,
                _ => t + tableau.c[i] * h_try,
            };
        }
        system.prepare_stages(t, h_try, &tableau.c[1..], &stage_times[1..]);
        for i in 1..S {
            let mut stage = y;
            for j in 0..i {
                if tableau.a[i][j] != 0.0 {
                    stage += k[j] * (h_try * tableau.a[i][j]);
                }
            }
            k[i] = system.rhs(stage_times[i], &stage);
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

    /// Order conditions up to order 5 for the propagating weights and up to 4 for the
    /// embedded ones (trees of Hairer, Nørsett & Wanner I, Table II.2.2).
    #[test]
    fn dormand_prince_satisfies_the_order_conditions() {
        let t = &DORMAND_PRINCE_54;
        let s = 7;
        let b: Vec<f64> = t.a[s - 1].to_vec();
        let b_hat: Vec<f64> = (0..s).map(|i| b[i] - t.error_weights[i]).collect();
        for i in 0..s {
            let row: f64 = t.a[i].iter().sum();
            assert!((row - t.c[i]).abs() < 1e-14, "row {i} sums to {row}");
        }
        let a_times = |v: &[f64]| -> Vec<f64> { (0..s).map(|i| (0..s).map(|j| t.a[i][j] * v[j]).sum()).collect() };
        let c: Vec<f64> = t.c.to_vec();
        let pow = |p: i32| -> Vec<f64> { c.iter().map(|x| x.powi(p)).collect() };
        let ac = a_times(&c);
        let ac2 = a_times(&pow(2));
        let aac = a_times(&ac);
        let times = |u: &[f64], v: &[f64]| -> Vec<f64> { u.iter().zip(v).map(|(x, y)| x * y).collect() };
        let ones = vec![1.0; s];
        // (vector g, 1/γ(tree), order of the tree)
        let trees: Vec<(Vec<f64>, f64, u32)> = vec![
            (ones.clone(), 1.0, 1),
            (c.clone(), 1.0 / 2.0, 2),
            (pow(2), 1.0 / 3.0, 3),
            (ac.clone(), 1.0 / 6.0, 3),
            (pow(3), 1.0 / 4.0, 4),
            (times(&c, &ac), 1.0 / 8.0, 4),
            (ac2.clone(), 1.0 / 12.0, 4),
            (aac.clone(), 1.0 / 24.0, 4),
            (pow(4), 1.0 / 5.0, 5),
            (times(&pow(2), &ac), 1.0 / 10.0, 5),
            (times(&ac, &ac), 1.0 / 20.0, 5),
            (times(&c, &ac2), 1.0 / 15.0, 5),
            (times(&c, &aac), 1.0 / 30.0, 5),
            (a_times(&pow(3)), 1.0 / 20.0, 5),
            (a_times(&times(&c, &ac)), 1.0 / 40.0, 5),
            (a_times(&ac2), 1.0 / 60.0, 5),
            (a_times(&aac), 1.0 / 120.0, 5),
        ];
        for (n, (g, value, order)) in trees.iter().enumerate() {
            let sum_b: f64 = b.iter().zip(g).map(|(x, y)| x * y).sum();
            assert!(
                (sum_b - value).abs() < 1e-14,
                "tree {n} (order {order}) for b: {sum_b} vs {value}"
            );
            if *order <= 4 {
                let sum_hat: f64 = b_hat.iter().zip(g).map(|(x, y)| x * y).sum();
                assert!((sum_hat - value).abs() < 1e-14, "tree {n} for b̂: {sum_hat} vs {value}");
            }
        }
        // b̂ is only of order 4: some order-5 condition must fail for it.
        let fifth: f64 = b_hat.iter().zip(&pow(4)).map(|(x, y)| x * y).sum();
        assert!((fifth - 0.2).abs() > 1e-6);
        assert_eq!(t.c[t.stiffness_stage], t.c[s - 1]);
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
            let y = integrate(
                &DORMAND_PRINCE_54,
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
