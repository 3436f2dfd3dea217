//! An error-controlled, L-stable integrator for small stiff systems, kept apart from the
//! physics so the FMU, the CLI and the tests all run the same model the same way.
//!
//! Method: the 5-stage, order-4 SDIRK of Hairer & Wanner (Solving ODEs II, Table IV.6.5,
//! γ = 1/4) with its embedded order-3 solution. It is L-stable and stiffly accurate, so
//! the 7050 rad/s current driver, the 1857 rad/s lightly damped jet pipe and the stiff
//! chambers near the ends of the stroke are all integrated without a step-size limit
//! from stability; the step is set by accuracy alone. Being a one-step method it restarts
//! at full order after every communication point, where inputs jump.
//!
//! Newton iterations use the Jacobian supplied by the system (one LU per step); the error
//! estimate is filtered through (I − hγJ)⁻¹ (Hairer & Wanner IV.8) so stiff components do
//! not cause spurious rejections.
//!
//! [`explicit`] holds Dormand–Prince 5(4) and Verner's 6(5) for systems that are stiff only
//! now and then
//! ([`Sdirk4::integrate_nonstiff_first`] hands over between the two), and both end their
//! steps at the breakpoints a system reports ([`OdeSystem::breakpoint`]).
//!
//! [`rosenbrock`] holds ROS2, a fixed-step L-stable Rosenbrock method without error control,
//! for steps imposed from outside (a recording's samples) that are already small enough.

use nalgebra::{Const, DimMin, SMatrix, SVector};

#[path = "integrator/explicit.rs"]
pub mod explicit;
#[path = "integrator/rosenbrock.rs"]
pub mod rosenbrock;

/// A system y' = f(t, y) of `N` equations.
pub trait OdeSystem<const N: usize> {
    fn rhs(&self, t: f64, y: &SVector<f64, N>) -> SVector<f64, N>;

    /// The first time in (t0, t1) at which f stops being smooth in t, if the system knows of
    /// one (a kink or a fractional power in a forcing it computes exactly). The integrators
    /// end a step there: their error estimates assume a smooth f inside a step and can
    /// under-read the error across such a point by two orders of magnitude.
    fn breakpoint(&self, _t0: f64, _t1: f64) -> Option<f64> {
        None
    }

    /// Told, before an explicit step from `t` of size `h` evaluates its stages, their nodes
    /// cᵢ and the times it will ask for f at (t + cᵢh, or the step's exact end). A system
    /// whose forcing costs more than its dependence on y can work it out for all stages at
    /// once here; the default does nothing.
    fn prepare_stages(&self, _t: f64, _h: f64, _nodes: &[f64], _times: &[f64]) {}

    /// f at the time `t` of entry `stage` of the `times` last given to
    /// [`Self::prepare_stages`]: what [`Self::rhs`] gives there, found without looking the time
    /// up. The default is [`Self::rhs`].
    #[inline(always)]
    fn rhs_at_stage(&self, _stage: usize, t: f64, y: &SVector<f64, N>) -> SVector<f64, N> {
        self.rhs(t, y)
    }

    /// ∂f/∂y. The default is a forward difference; systems with known structure override it.
    fn jacobian(&self, t: f64, y: &SVector<f64, N>, f_y: &SVector<f64, N>) -> SMatrix<f64, N, N> {
        finite_difference_jacobian(|yy| self.rhs(t, yy), y, f_y)
    }
}

/// Forward-difference Jacobian of `f` at `y`, given f(y).
pub fn finite_difference_jacobian<const N: usize>(
    f: impl Fn(&SVector<f64, N>) -> SVector<f64, N>,
    y: &SVector<f64, N>,
    f_y: &SVector<f64, N>,
) -> SMatrix<f64, N, N> {
    let mut jac = SMatrix::<f64, N, N>::zeros();
    let mut yy = *y;
    for j in 0..N {
        let h = 1e-8 * y[j].abs().max(1e-8);
        yy[j] = y[j] + h;
        let column = (f(&yy) - f_y) / h;
        jac.set_column(j, &column);
        yy[j] = y[j];
    }
    jac
}

/// Relative tolerance and per-component absolute tolerances.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances<const N: usize> {
    pub relative: f64,
    pub absolute: SVector<f64, N>,
}

/// Work counters, for benchmarks and the closing notes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Statistics {
    pub steps: u64,
    pub rejected: u64,
    pub rhs_evaluations: u64,
    pub jacobians: u64,
    pub newton_failures: u64,
    /// Times the explicit method found the system stiff and handed over to SDIRK4.
    pub stiff_handovers: u64,
}

impl Statistics {
    pub fn add(&mut self, other: &Statistics) {
        self.steps += other.steps;
        self.rejected += other.rejected;
        self.rhs_evaluations += other.rhs_evaluations;
        self.jacobians += other.jacobians;
        self.newton_failures += other.newton_failures;
        self.stiff_handovers += other.stiff_handovers;
    }
}

/// Why an integration stopped before its end time.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegrationFailure<const N: usize> {
    pub message: String,
    /// Time and state of the last accepted step.
    pub time: f64,
    pub state: SVector<f64, N>,
}

const GAMMA: f64 = 0.25;
const C: [f64; 5] = [0.25, 0.75, 11.0 / 20.0, 0.5, 1.0];
const A: [[f64; 5]; 5] = [
    [0.25, 0.0, 0.0, 0.0, 0.0],
    [0.5, 0.25, 0.0, 0.0, 0.0],
    [17.0 / 50.0, -1.0 / 25.0, 0.25, 0.0, 0.0],
    [371.0 / 1360.0, -137.0 / 2720.0, 15.0 / 544.0, 0.25, 0.0],
    [25.0 / 24.0, -49.0 / 48.0, 125.0 / 16.0, -85.0 / 12.0, 0.25],
];
/// Lagrange weights, at c_i, of the slopes [f0, k_0, k_1, k_2, k_3] known before stage i:
/// f0 for stage 0, the line through (0, f0) and (c_0, k_0) for stage 1, then the parabola
/// through the last three (`slope_predictor_interpolates` checks them).
const SLOPE_PREDICTOR: [[f64; 5]; 5] = [
    [1.0, 0.0, 0.0, 0.0, 0.0],
    [-2.0, 3.0, 0.0, 0.0, 0.0],
    [-8.0 / 25.0, 22.0 / 25.0, 11.0 / 25.0, 0.0, 0.0],
    [0.0, 1.0 / 12.0, -1.0 / 8.0, 25.0 / 24.0, 0.0],
    [0.0, 0.0, 4.5, -12.5, 9.0],
];
/// Weights of the embedded order-3 solution.
const B_HAT: [f64; 5] = [59.0 / 48.0, -17.0 / 96.0, 225.0 / 32.0, -85.0 / 12.0, 0.0];

const MAX_NEWTON_ITERATIONS: usize = 8;
pub(crate) const MIN_STEP: f64 = 1e-14;

/// The explicit pair [`Sdirk4::integrate_nonstiff_first`] starts with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExplicitPair {
    /// Dormand–Prince 5(4), seven stages: the cheaper step where the error sets the steps.
    DormandPrince,
    /// Verner's 6(5), nine stages: its error estimate over-reads fast exponential forcing
    /// ([`explicit::VERNER_65`]), so it needs no cap where the forcing rings.
    Verner,
}

/// The integrator: its only memory between calls is the step size to try next, which is
/// part of the simulation state (it makes results reproducible after a state restore).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sdirk4 {
    pub next_step: f64,
    pub max_step: f64,
    /// Size of the first accepted step of the last `integrate` call.
    pub first_step: f64,
}

impl Default for Sdirk4 {
    fn default() -> Self {
        Self {
            next_step: 1e-5,
            max_step: f64::INFINITY,
            first_step: 1e-5,
        }
    }
}

pub(crate) fn error_norm<const N: usize>(
    e: &SVector<f64, N>,
    y0: &SVector<f64, N>,
    y1: &SVector<f64, N>,
    tol: &Tolerances<N>,
) -> f64 {
    let mut sum = 0.0;
    for k in 0..N {
        let scale = tol.absolute[k] + tol.relative * y0[k].abs().max(y1[k].abs());
        let r = e[k] / scale;
        sum += r * r;
    }
    (sum / N as f64).sqrt()
}

impl Sdirk4 {
    /// Integrate from (t0, y0) to t1 exactly. On failure the returned state is the last
    /// accepted one.
    pub fn integrate<const N: usize, S: OdeSystem<N>>(
        &mut self,
        system: &S,
        t0: f64,
        y0: SVector<f64, N>,
        t1: f64,
        tol: &Tolerances<N>,
        stats: &mut Statistics,
    ) -> Result<SVector<f64, N>, IntegrationFailure<N>>
    where
        Const<N>: DimMin<Const<N>, Output = Const<N>>,
    {
        let mut t = t0;
        let mut y = y0;
        let mut h = self.next_step.min(self.max_step).max(MIN_STEP);
        let mut last_rejected = false;
        let mut first_accepted = None;
        let mut previous_error: f64 = 1.0;
        let span = t1 - t0;
        while t1 - t > 1e-15 * span.abs().max(t1.abs()) {
            let (h_try, step_end, _) = step_towards(system, t, h, t1, span);
            match self.attempt(system, t, &y, h_try, tol, stats) {
                Attempt::Accepted { y_new, error } => {
                    stats.steps += 1;
                    if first_accepted.is_none() {
                        first_accepted = Some(h_try);
                    }
                    t = step_end.unwrap_or(t + h_try);
                    y = y_new;
                    // PI step-size control (Gustafsson): the previous error damps the
                    // oscillation of the step size that an oscillating forcing provokes.
                    let mut factor = if error == 0.0 {
                        5.0
                    } else {
                        0.9 * error.powf(-0.7 / 4.0) * previous_error.powf(0.4 / 4.0)
                    };
                    previous_error = error.max(1e-4);
                    factor = factor.clamp(0.2, 5.0);
                    if last_rejected {
                        factor = factor.min(1.0);
                    }
                    last_rejected = false;
                    let proposed = (h_try * factor).min(self.max_step);
                    // A step cut short to hit t1 or a breakpoint says nothing about the
                    // natural step size.
                    h = if step_end.is_some() && h_try < h {
                        h.max(proposed)
                    } else {
                        proposed
                    };
                }
                Attempt::Rejected { error } => {
                    stats.rejected += 1;
                    last_rejected = true;
                    let factor = if error.is_finite() {
                        (0.9 * error.powf(-0.25)).clamp(0.1, 0.9)
                    } else {
                        0.25
                    };
                    h = h_try * factor;
                }
                Attempt::NewtonFailed => {
                    stats.newton_failures += 1;
                    last_rejected = true;
                    h = h_try * 0.25;
                }
            }
            if h < MIN_STEP.max(1e-14 * t.abs()) {
                self.next_step = 1e-5;
                return Err(IntegrationFailure {
                    message: format!(
                        "the step size fell below {MIN_STEP:e} s: the solution is not smooth enough to integrate"
                    ),
                    time: t,
                    state: y,
                });
            }
        }
        self.next_step = h;
        if let Some(first) = first_accepted {
            self.first_step = first;
        }
        Ok(y)
    }

    /// Integrate from (t0, y0) to t1 with the explicit `pair` while the system is not stiff
    /// and with SDIRK4 from where it becomes so (or where the explicit step collapses) to t1.
    /// For systems that are mostly non-stiff, such as the chambers between their pressure
    /// limits: no Newton iterations and no Jacobians there.
    pub fn integrate_nonstiff_first<const N: usize, S: OdeSystem<N>>(
        &mut self,
        pair: ExplicitPair,
        system: &S,
        t0: f64,
        y0: SVector<f64, N>,
        t1: f64,
        tol: &Tolerances<N>,
        stats: &mut Statistics,
    ) -> Result<SVector<f64, N>, IntegrationFailure<N>>
    where
        Const<N>: DimMin<Const<N>, Output = Const<N>>,
    {
        let mut memory = explicit::StepMemory {
            next_step: self.next_step,
            max_step: self.max_step,
            first_step: None,
        };
        let outcome = match pair {
            ExplicitPair::DormandPrince => {
                explicit::integrate::<N, 7, explicit::DormandPrince, S>(&mut memory, system, t0, y0, t1, tol, stats)
            }
            ExplicitPair::Verner => {
                explicit::integrate::<N, 9, explicit::Verner, S>(&mut memory, system, t0, y0, t1, tol, stats)
            }
        };
        self.next_step = memory.next_step;
        if let Some(first) = memory.first_step {
            self.first_step = first;
        }
        match outcome {
            Ok(y) => Ok(y),
            Err(handover) => {
                stats.stiff_handovers += 1;
                let first = self.first_step;
                let result = self.integrate(system, handover.time, handover.state, t1, tol, stats);
                if memory.first_step.is_some() {
                    self.first_step = first;
                }
                result
            }
        }
    }

    fn attempt<const N: usize, S: OdeSystem<N>>(
        &self,
        system: &S,
        t: f64,
        y: &SVector<f64, N>,
        h: f64,
        tol: &Tolerances<N>,
        stats: &mut Statistics,
    ) -> Attempt<N>
    where
        Const<N>: DimMin<Const<N>, Output = Const<N>>,
    {
        let f0 = system.rhs(t, y);
        stats.rhs_evaluations += 1;
        let jac = system.jacobian(t, y, &f0);
        stats.jacobians += 1;
        let iteration_matrix = SMatrix::<f64, N, N>::identity() - jac * (h * GAMMA);
        // The explicit inverse, once per step: the Newton corrections are then products,
        // with no division on the iteration's critical path (N is 2 or 6).
        let inverse = match iteration_matrix.try_inverse() {
            Some(inverse) => inverse,
            None => return Attempt::NewtonFailed,
        };
        let mut k = [SVector::<f64, N>::zeros(); 5];
        let mut stage = *y;
        // Newton's corrections are measured in units of the error tolerance at the step's
        // start (the stages stay within a step's change of it), squared to spare the root.
        let newton_tolerance_squared = 0.01 * 0.01;
        let inverse_scale = SVector::<f64, N>::from_fn(|i, _| 1.0 / (tol.absolute[i] + tol.relative * y[i].abs()));
        let squared_norm = |d: &SVector<f64, N>| d.component_mul(&inverse_scale).norm_squared() / N as f64;
        for i in 0..5 {
            let mut known = *y;
            for j in 0..i {
                known += k[j] * (h * A[i][j]);
            }
            // Predict the stage slope by the polynomial through the last (up to) three
            // slopes known, f0 at c = 0 and the stages' at c_j: ~10-35 % fewer Newton
            // iterations than the previous slope alone where the forcing is smooth.
            let w = &SLOPE_PREDICTOR[i];
            let slope_guess = f0 * w[0] + k[0] * w[1] + k[1] * w[2] + k[2] * w[3] + k[3] * w[4];
            stage = known + slope_guess * (h * GAMMA);
            let t_stage = t + C[i] * h;
            let mut previous_norm = f64::INFINITY;
            let mut converged = false;
            for _ in 0..MAX_NEWTON_ITERATIONS {
                let f = system.rhs(t_stage, &stage);
                stats.rhs_evaluations += 1;
                let residual = stage - known - f * (h * GAMMA);
                let delta = -(inverse * residual);
                stage += delta;
                let norm = squared_norm(&delta);
                // Diverging: the correction more than doubled (squared norms: four times).
                if !norm.is_finite() || norm > 4.0 * previous_norm {
                    return Attempt::NewtonFailed;
                }
                if norm <= newton_tolerance_squared {
                    converged = true;
                    break;
                }
                previous_norm = norm;
            }
            if !converged {
                return Attempt::NewtonFailed;
            }
            k[i] = (stage - known) / (h * GAMMA);
        }
        let y_new = stage; // stiffly accurate: the last stage is the solution
        let mut difference = SVector::<f64, N>::zeros();
        for j in 0..5 {
            difference += k[j] * (h * (A[4][j] - B_HAT[j]));
        }
        let filtered = inverse * difference;
        let error = error_norm(&filtered, y, &y_new, tol);
        if error.is_finite() && error <= 1.0 && y_new.iter().all(|v| v.is_finite()) {
            Attempt::Accepted { y_new, error }
        } else {
            Attempt::Rejected { error }
        }
    }
}

/// The next step from `t` of at most `h` towards `t1`: its length, the time it ends at
/// exactly when that is t1 or a breakpoint of the system (so that rounding cannot leave a
/// sliver before it, nor put the end a hair on the wrong side of it), and whether it ends at
/// a breakpoint.
pub(crate) fn step_towards<const N: usize, S: OdeSystem<N>>(
    system: &S,
    t: f64,
    h: f64,
    t1: f64,
    span: f64,
) -> (f64, Option<f64>, bool) {
    let remaining = t1 - t;
    // Stretch a step that would leave a sliver to the end point.
    let (h_try, end) = if h >= remaining * 0.999_999 || remaining - h < 1e-3 * h {
        (remaining, t1)
    } else {
        (h, t + h)
    };
    match system.breakpoint(t, end) {
        Some(b) if b > t + 1e-12 * span.abs() && b < end => (b - t, Some(b), true),
        _ if end == t1 => (h_try, Some(t1), false),
        _ => (h_try, None, false),
    }
}

enum Attempt<const N: usize> {
    Accepted { y_new: SVector<f64, N>, error: f64 },
    Rejected { error: f64 },
    NewtonFailed,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tableau_satisfies_the_order_conditions() {
        let b = A[4];
        let ac = |i: usize| (0..5).map(|j| A[i][j] * C[j]).sum::<f64>();
        let acc = |i: usize| (0..5).map(|j| A[i][j] * C[j] * C[j]).sum::<f64>();
        let aac = |i: usize| (0..5).map(|j| A[i][j] * ac(j)).sum::<f64>();
        for i in 0..5 {
            assert!(((0..5).map(|j| A[i][j]).sum::<f64>() - C[i]).abs() < 1e-14);
        }
        let sum = |w: &[f64; 5], g: &dyn Fn(usize) -> f64| (0..5).map(|i| w[i] * g(i)).sum::<f64>();
        // order 4 for b
        let conditions: [(&dyn Fn(usize) -> f64, f64); 8] = [
            (&|_| 1.0, 1.0),
            (&|i| C[i], 0.5),
            (&|i| C[i] * C[i], 1.0 / 3.0),
            (&|i| ac(i), 1.0 / 6.0),
            (&|i| C[i].powi(3), 0.25),
            (&|i| C[i] * ac(i), 1.0 / 8.0),
            (&|i| acc(i), 1.0 / 12.0),
            (&|i| aac(i), 1.0 / 24.0),
        ];
        for (k, (g, value)) in conditions.iter().enumerate() {
            assert!((sum(&b, *g) - value).abs() < 1e-13, "order condition {k} for b");
            if k < 4 {
                assert!((sum(&B_HAT, *g) - value).abs() < 1e-13, "order condition {k} for b_hat");
            }
        }
    }

    #[test]
    fn slope_predictor_interpolates() {
        // Exact for slopes quadratic in c (linear for stage 1), and uses only known slopes.
        let nodes = [0.0, C[0], C[1], C[2], C[3]];
        for (i, w) in SLOPE_PREDICTOR.iter().enumerate() {
            assert!(w[i + 1..].iter().all(|&x| x == 0.0), "stage {i} uses an unknown slope");
            let degree = if i == 0 {
                0
            } else if i == 1 {
                1
            } else {
                2
            };
            for power in 0..=degree {
                let predicted: f64 = (0..5).map(|j| w[j] * nodes[j].powi(power)).sum();
                assert!((predicted - C[i].powi(power)).abs() < 1e-14, "stage {i}, c^{power}");
            }
        }
    }

    struct Oscillator;
    impl OdeSystem<2> for Oscillator {
        fn rhs(&self, _t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
            SVector::<f64, 2>::new(y[1], -y[0])
        }
    }

    struct StiffLinear;
    impl OdeSystem<2> for StiffLinear {
        // y1' = -1e6 (y1 - cos t), y2' = y1: y1 → cos t, y2 → sin t.
        fn rhs(&self, t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
            SVector::<f64, 2>::new(-1e6 * (y[0] - t.cos()), y[0])
        }
    }

    #[test]
    fn meets_the_tolerance_and_converges_with_it() {
        let mut errors = vec![];
        for rtol in [1e-4, 1e-6, 1e-8] {
            let tol = Tolerances {
                relative: rtol,
                absolute: SVector::<f64, 2>::repeat(rtol),
            };
            let mut integrator = Sdirk4::default();
            let mut stats = Statistics::default();
            let y = integrator
                .integrate(
                    &Oscillator,
                    0.0,
                    SVector::<f64, 2>::new(1.0, 0.0),
                    10.0,
                    &tol,
                    &mut stats,
                )
                .unwrap();
            let err = ((y[0] - 10f64.cos()).powi(2) + (y[1] + 10f64.sin()).powi(2)).sqrt();
            errors.push(err);
            assert!(err < 100.0 * rtol, "rtol {rtol}: error {err}");
        }
        assert!(errors[2] < errors[1] && errors[1] < errors[0], "{errors:?}");
    }

    #[test]
    fn stiff_problem_needs_no_tiny_steps() {
        let tol = Tolerances {
            relative: 1e-6,
            absolute: SVector::<f64, 2>::repeat(1e-8),
        };
        let mut integrator = Sdirk4::default();
        let mut stats = Statistics::default();
        let y = integrator
            .integrate(
                &StiffLinear,
                0.0,
                SVector::<f64, 2>::new(1.0, 0.0),
                5.0,
                &tol,
                &mut stats,
            )
            .unwrap();
        assert!((y[1] - 5f64.sin()).abs() < 1e-5, "{}", y[1]);
        // An explicit method would need > 5e6 steps (stability bound 2.8e-6 s).
        assert!(stats.steps < 2000, "{stats:?}");
    }

    #[test]
    fn stops_exactly_at_the_end_time_and_is_deterministic() {
        let tol = Tolerances {
            relative: 1e-6,
            absolute: SVector::<f64, 2>::repeat(1e-9),
        };
        let run = || {
            let mut integrator = Sdirk4::default();
            let mut stats = Statistics::default();
            let mut y = SVector::<f64, 2>::new(1.0, 0.0);
            let mut t = 0.0;
            for _ in 0..100 {
                y = integrator
                    .integrate(&Oscillator, t, y, t + 0.0123, &tol, &mut stats)
                    .unwrap();
                t += 0.0123;
            }
            y
        };
        assert_eq!(run(), run());
    }
}
