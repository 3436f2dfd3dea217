//! A fixed-step, two-stage, L-stable Rosenbrock method of order 2: ROS2 of Verwer, Spee,
//! Blom & Hundsdorfer (SIAM J. Sci. Comput. 20, 1999), γ = 1 + 1/√2,
//!
//!   (I − γhJ) k₁ = f(t, y) + γh ∂f/∂t,
//!   (I − γhJ) k₂ = f(t + h, y + h k₁) − 2 k₁ − γh ∂f/∂t,
//!   y₊ = y + (3/2) h k₁ + (1/2) h k₂.
//!
//! For when the step is imposed (a recording's sample interval) and is already far below
//! the system's time constants, so error control would only cost: no Newton iterations and
//! one linear solve per stage. ROS2 keeps its order 2 for any matrix in place of J (it is a
//! W-method), so the Jacobian is refreshed only every few steps, and ∂f/∂t is a forward
//! difference (the systems here are driven by exactly known forcings of time).

use nalgebra::{Const, DimMin, SMatrix, SVector};

use super::OdeSystem;

/// γ of ROS2: 1 + 1/√2 makes it L-stable.
pub const GAMMA: f64 = 1.0 + std::f64::consts::FRAC_1_SQRT_2;

/// A fixed-step method: the state `h` after `t` and how many Jacobians it has formed.
pub trait FixedStepMethod<const N: usize> {
    /// Right-hand sides a step takes, besides those of its Jacobians.
    const RHS_PER_STEP: u64;
    fn step<S: OdeSystem<N>>(
        &mut self,
        system: &S,
        t: f64,
        y: &SVector<f64, N>,
        h: f64,
    ) -> Result<SVector<f64, N>, String>;
    fn jacobians(&self) -> u64;
}

/// ∂f/∂t at (t, y) by a forward difference of 1e-7 h: well above rounding of the forcing,
/// well below its variation over the step.
fn time_derivative<const N: usize, S: OdeSystem<N>>(
    system: &S,
    t: f64,
    y: &SVector<f64, N>,
    f0: &SVector<f64, N>,
    h: f64,
) -> SVector<f64, N> {
    let eps = 1e-7 * h;
    (system.rhs(t + eps, y) - f0) / eps
}

/// The system's Jacobian at (t, y) and (I − γh J)⁻¹, for `gamma_h` = γh.
fn jacobian_and_inverse<const N: usize, S: OdeSystem<N>>(
    system: &S,
    t: f64,
    y: &SVector<f64, N>,
    f0: &SVector<f64, N>,
    gamma_h: f64,
) -> Result<(SMatrix<f64, N, N>, SMatrix<f64, N, N>), String>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    let jacobian = system.jacobian(t, y, f0);
    let inverse = (SMatrix::<f64, N, N>::identity() - jacobian * gamma_h)
        .try_inverse()
        .ok_or("Rosenbrock step: I − γhJ is singular")?;
    Ok((jacobian, inverse))
}

/// The integrator's memory: (I − γhJ)⁻¹ and when it was formed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ros2<const N: usize> {
    /// The Jacobian is formed again on every this-many-th step (and whenever h changes).
    pub jacobian_reuse: u64,
    /// Steps taken so far.
    pub steps: u64,
    /// Jacobians formed so far.
    pub jacobians: u64,
    /// (I − γhJ)⁻¹ for `last_h`.
    inverse: SMatrix<f64, N, N>,
    last_h: f64,
}

impl<const N: usize> Ros2<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    pub fn new(jacobian_reuse: u64) -> Self {
        Self {
            jacobian_reuse: jacobian_reuse.max(1),
            steps: 0,
            jacobians: 0,
            inverse: SMatrix::identity(),
            last_h: f64::NAN,
        }
    }

    /// The state at t + h from y at t. The Jacobian comes from [`OdeSystem::jacobian`] at
    /// (t, y), so a system controls how it is differenced.
    pub fn step<S: OdeSystem<N>>(
        &mut self,
        system: &S,
        t: f64,
        y: &SVector<f64, N>,
        h: f64,
    ) -> Result<SVector<f64, N>, String> {
        let f0 = system.rhs(t, y);
        let f_t = time_derivative(system, t, y, &f0, h);
        // The Jacobian changes slowly: refresh it every few steps. A new h needs a new
        // matrix anyway, and then the Jacobian is formed at the same cost.
        if self.steps % self.jacobian_reuse == 0 || h != self.last_h {
            (_, self.inverse) = jacobian_and_inverse(system, t, y, &f0, GAMMA * h)?;
            self.last_h = h;
            self.jacobians += 1;
        }
        let w = &self.inverse;
        let k1 = w * (f0 + f_t * (GAMMA * h));
        let k2 = w * (system.rhs(t + h, &(y + k1 * h)) - k1 * 2.0 - f_t * (GAMMA * h));
        self.steps += 1;
        Ok(y + (k1 * (1.5 * h) + k2 * (0.5 * h)))
    }
}

/// ROS34PW2 of Rang & Angermann (BIT 45, 2005): a four-stage Rosenbrock-W method of order 3,
/// stiffly accurate and L-stable, in the standard form
///
///   (I − γhA) kᵢ = h f(t + αᵢh, y + Σⱼ αᵢⱼ kⱼ) + hA Σⱼ γᵢⱼ kⱼ + γᵢ h² ∂f/∂t,
///   y₊ = y + Σᵢ bᵢ kᵢ,
///
/// with αᵢ = Σⱼ αᵢⱼ and γᵢ = γ + Σⱼ γᵢⱼ (j < i). Its order holds for any matrix A (a
/// W-method), so A is refreshed as [`Ros2`]'s is. Two more right-hand sides a step than
/// ROS2 buy one order: where ROS2's error at the sample interval is above what a fit can
/// accept, this method reaches it with fewer steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ros34pw2<const N: usize> {
    pub jacobian_reuse: u64,
    pub steps: u64,
    pub jacobians: u64,
    jacobian: SMatrix<f64, N, N>,
    /// (I − γhA)⁻¹ for `last_h`.
    inverse: SMatrix<f64, N, N>,
    last_h: f64,
}

// ROS34PW2's γ, αᵢⱼ, γᵢⱼ (strictly lower, by rows) and bᵢ, to the digits published.
#[allow(clippy::excessive_precision)]
const W_GAMMA: f64 = 4.358_665_215_084_590e-1;
#[allow(clippy::excessive_precision)]
const W_ALPHA: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [8.717_330_430_169_180e-1, 0.0, 0.0],
    [8.445_706_001_536_942e-1, -1.129_906_423_648_419e-1, 0.0],
    [0.0, 0.0, 1.0],
];
#[allow(clippy::excessive_precision)]
const W_GAMMAS: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [-8.717_330_430_169_180e-1, 0.0, 0.0],
    [-9.033_805_701_304_408e-1, 5.418_067_238_809_533e-2, 0.0],
    [
        2.421_238_070_609_535e-1,
        -1.223_250_583_904_515,
        5.452_602_553_351_021e-1,
    ],
];
#[allow(clippy::excessive_precision)]
const W_B: [f64; 4] = [
    2.421_238_070_609_535e-1,
    -1.223_250_583_904_515,
    1.545_260_255_335_102,
    4.358_665_215_084_590e-1,
];

impl<const N: usize> Ros34pw2<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    pub fn new(jacobian_reuse: u64) -> Self {
        Self {
            jacobian_reuse: jacobian_reuse.max(1),
            steps: 0,
            jacobians: 0,
            jacobian: SMatrix::zeros(),
            inverse: SMatrix::identity(),
            last_h: f64::NAN,
        }
    }

    /// The state at t + h from y at t, as [`Ros2::step`].
    pub fn step<S: OdeSystem<N>>(
        &mut self,
        system: &S,
        t: f64,
        y: &SVector<f64, N>,
        h: f64,
    ) -> Result<SVector<f64, N>, String> {
        let f0 = system.rhs(t, y);
        let f_t = time_derivative(system, t, y, &f0, h);
        if self.steps % self.jacobian_reuse == 0 || h != self.last_h {
            (self.jacobian, self.inverse) = jacobian_and_inverse(system, t, y, &f0, W_GAMMA * h)?;
            self.last_h = h;
            self.jacobians += 1;
        }
        let mut k = [SVector::<f64, N>::zeros(); 4];
        let mut y_next = *y;
        for i in 0..4 {
            let (mut stage_state, mut coupled, mut alpha, mut gamma) = (*y, SVector::<f64, N>::zeros(), 0.0, W_GAMMA);
            for j in 0..i {
                stage_state += k[j] * W_ALPHA[i][j];
                coupled += k[j] * W_GAMMAS[i][j];
                alpha += W_ALPHA[i][j];
                gamma += W_GAMMAS[i][j];
            }
            let f = if i == 0 {
                f0
            } else {
                system.rhs(t + alpha * h, &stage_state)
            };
            k[i] = self.inverse * (f * h + self.jacobian * coupled * h + f_t * (gamma * h * h));
            y_next += k[i] * W_B[i];
        }
        self.steps += 1;
        Ok(y_next)
    }
}

impl<const N: usize> FixedStepMethod<N> for Ros2<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    const RHS_PER_STEP: u64 = 3;
    fn step<S: OdeSystem<N>>(
        &mut self,
        system: &S,
        t: f64,
        y: &SVector<f64, N>,
        h: f64,
    ) -> Result<SVector<f64, N>, String> {
        Ros2::step(self, system, t, y, h)
    }
    fn jacobians(&self) -> u64 {
        self.jacobians
    }
}

impl<const N: usize> FixedStepMethod<N> for Ros34pw2<N>
where
    Const<N>: DimMin<Const<N>, Output = Const<N>>,
{
    const RHS_PER_STEP: u64 = 5;
    fn step<S: OdeSystem<N>>(
        &mut self,
        system: &S,
        t: f64,
        y: &SVector<f64, N>,
        h: f64,
    ) -> Result<SVector<f64, N>, String> {
        Ros34pw2::step(self, system, t, y, h)
    }
    fn jacobians(&self) -> u64 {
        self.jacobians
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::SMatrix;

    /// y' = A y + g(t) with a stiff, a slow and an oscillating forcing: y = e^{At} y₀ plus
    /// the forced part, known exactly (Prothero–Robinson in each component).
    struct Linear {
        lambda: [f64; 2],
    }

    impl Linear {
        fn exact(&self, t: f64) -> SVector<f64, 2> {
            // y_i = φ_i(t) + e^{λ_i t} (y_i(0) − φ_i(0)), with φ = (sin t, cos 3t).
            let phi = |t: f64| SVector::<f64, 2>::new(t.sin(), (3.0 * t).cos());
            let y0 = SVector::<f64, 2>::new(1.0, 2.0);
            let d = y0 - phi(0.0);
            phi(t) + SVector::<f64, 2>::new((self.lambda[0] * t).exp() * d[0], (self.lambda[1] * t).exp() * d[1])
        }
    }

    impl OdeSystem<2> for Linear {
        fn rhs(&self, t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
            // y' = λ (y − φ) + φ'
            SVector::<f64, 2>::new(
                self.lambda[0] * (y[0] - t.sin()) + t.cos(),
                self.lambda[1] * (y[1] - (3.0 * t).cos()) - 3.0 * (3.0 * t).sin(),
            )
        }
        fn jacobian(&self, _t: f64, _y: &SVector<f64, 2>, _f: &SVector<f64, 2>) -> SMatrix<f64, 2, 2> {
            SMatrix::<f64, 2, 2>::new(self.lambda[0], 0.0, 0.0, self.lambda[1])
        }
    }

    fn error_at_one_second(system: &Linear, steps: usize, reuse: u64) -> f64 {
        let mut ros2 = Ros2::<2>::new(reuse);
        let h = 1.0 / steps as f64;
        let mut y = system.exact(0.0);
        for k in 0..steps {
            y = ros2.step(system, k as f64 * h, &y, h).unwrap();
        }
        (y - system.exact(1.0)).amax()
    }

    #[test]
    fn the_error_falls_fourfold_when_the_step_halves() {
        // λ = −1e4 is stiff at every step tried: an explicit method would blow up.
        let system = Linear { lambda: [-2.0, -1e4] };
        for reuse in [1, 8] {
            let errors: Vec<f64> = [50, 100, 200, 400]
                .iter()
                .map(|&n| error_at_one_second(&system, n, reuse))
                .collect();
            for pair in errors.windows(2) {
                let ratio = pair[0] / pair[1];
                assert!(
                    (3.6..4.4).contains(&ratio),
                    "reuse {reuse}: errors {errors:?}, ratio {ratio}"
                );
            }
            assert!(errors[3] < 3e-5, "{errors:?}");
        }
    }

    /// [`Linear`] with a Jacobian 30 % off: a W-method keeps its order with it.
    struct WrongJacobian(Linear);

    impl OdeSystem<2> for WrongJacobian {
        fn rhs(&self, t: f64, y: &SVector<f64, 2>) -> SVector<f64, 2> {
            self.0.rhs(t, y)
        }
        fn jacobian(&self, t: f64, y: &SVector<f64, 2>, f: &SVector<f64, 2>) -> SMatrix<f64, 2, 2> {
            self.0.jacobian(t, y, f) * 0.7
        }
    }

    fn ros34pw2_error_at_one_second<S: OdeSystem<2>>(
        system: &S,
        exact: SVector<f64, 2>,
        y0: SVector<f64, 2>,
        steps: usize,
    ) -> f64 {
        let mut method = Ros34pw2::<2>::new(8);
        let h = 1.0 / steps as f64;
        let mut y = y0;
        for k in 0..steps {
            y = method.step(system, k as f64 * h, &y, h).unwrap();
        }
        (y - exact).amax()
    }

    #[test]
    fn ros34pw2_error_falls_eightfold_when_the_step_halves_even_with_a_wrong_jacobian() {
        // Stiff with the exact Jacobian; with a wrong one the order of a W-method holds where
        // h times the Jacobian's error is small (λ = −20, off by 6 at most).
        let stiff = Linear { lambda: [-2.0, -1e4] };
        let mild = Linear { lambda: [-2.0, -20.0] };
        let (stiff_from, stiff_to) = (stiff.exact(0.0), stiff.exact(1.0));
        let (mild_from, mild_to) = (mild.exact(0.0), mild.exact(1.0));
        let wrong = WrongJacobian(mild);
        for (name, errors) in [
            (
                "exact",
                [25, 50, 100, 200].map(|n| ros34pw2_error_at_one_second(&stiff, stiff_to, stiff_from, n)),
            ),
            (
                "wrong",
                [25, 50, 100, 200].map(|n| ros34pw2_error_at_one_second(&wrong, mild_to, mild_from, n)),
            ),
        ] {
            for pair in errors.windows(2) {
                // Order 3 at least: a W-method of order 2 with the wrong matrix would fall
                // fourfold; the stiff case is in the asymptotic range already.
                let ratio = pair[0] / pair[1];
                let in_range = if name == "exact" {
                    (7.0..9.0).contains(&ratio)
                } else {
                    ratio > 7.0
                };
                assert!(in_range, "{name} Jacobian: errors {errors:?}, ratio {ratio}");
            }
        }
    }

    #[test]
    fn a_stiff_component_is_damped_in_one_step() {
        // L-stability: with hλ = −1e6 the transient is gone after a single step, where the
        // trapezoidal rule would keep it at nearly full size with its sign flipped.
        let system = Linear { lambda: [-1e8, -1.0] };
        let mut ros2 = Ros2::<2>::new(1);
        let y0 = SVector::<f64, 2>::new(1.0, 2.0);
        let y = ros2.step(&system, 0.0, &y0, 1e-2).unwrap();
        assert!((y[0] - system.exact(1e-2)[0]).abs() < 1e-5, "{y}");
        let y = Ros34pw2::<2>::new(1).step(&system, 0.0, &y0, 1e-2).unwrap();
        assert!((y[0] - system.exact(1e-2)[0]).abs() < 1e-5, "ROS34PW2: {y}");
    }

    #[test]
    fn the_jacobian_is_formed_every_reuse_steps_and_when_h_changes() {
        let system = Linear { lambda: [-2.0, -3.0] };
        let mut ros2 = Ros2::<2>::new(8);
        let mut y = system.exact(0.0);
        for k in 0..16 {
            y = ros2.step(&system, k as f64 * 1e-3, &y, 1e-3).unwrap();
        }
        assert_eq!(ros2.jacobians, 2);
        ros2.step(&system, 0.016, &y, 5e-4).unwrap();
        assert_eq!(ros2.jacobians, 3);
    }
}
