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
        // ∂f/∂t at a step of 1e-7 h: well above rounding of the forcing, well below its
        // variation over the step.
        let eps = 1e-7 * h;
        let f_t = (system.rhs(t + eps, y) - f0) / eps;
        // The Jacobian changes slowly: refresh it every few steps. A new h needs a new
        // matrix anyway, and then the Jacobian is formed at the same cost.
        if self.steps % self.jacobian_reuse == 0 || h != self.last_h {
            let jac = system.jacobian(t, y, &f0);
            self.inverse = (SMatrix::<f64, N, N>::identity() - jac * (GAMMA * h))
                .try_inverse()
                .ok_or("ROS2: I − γhJ is singular")?;
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

    #[test]
    fn a_stiff_component_is_damped_in_one_step() {
        // L-stability: with hλ = −1e6 the transient is gone after a single step, where the
        // trapezoidal rule would keep it at nearly full size with its sign flipped.
        let system = Linear { lambda: [-1e8, -1.0] };
        let mut ros2 = Ros2::<2>::new(1);
        let y0 = SVector::<f64, 2>::new(1.0, 2.0);
        let y = ros2.step(&system, 0.0, &y0, 1e-2).unwrap();
        assert!((y[0] - system.exact(1e-2)[0]).abs() < 1e-5, "{y}");
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
