//! Exact propagation of the current driver and jet pipe over a communication step.
//!
//! The current driver (2.1)–(2.3) and the jet pipe dynamics (2.6) are linear; only the
//! static curve f3 (2.5) between them is not, and neither feels the air. With the command
//! held (or linear in time) over a step the current is known in closed form,
//! i(s) = ī(s) + δ e^{−ω_cd s}, so the jet pipe input u(s) = f3(k_m i(s)) is a known
//! function of time, and in the jet pipe's modal coordinates (eigenvalues −ω1 and
//! −ζ2ω2 ± jω2√(1−ζ2²), eigenvectors [1, λ, λ²]) each mode obeys q' = λ q + β u(s):
//!
//!   q(s) = e^{λ s} q(0) + β ∫₀ˢ e^{λ(s−σ)} u(σ) dσ.
//!
//! For a held command the integral is a series: f3(F̄ + ε r) = Σ aₙ rⁿ with r = e^{−ω_cd σ},
//! and each term integrates in closed form. For large jumps (where the series converges
//! slowly), for commands that move within the step and for a curve that offers no series,
//! a composite 8-point Gauss–Legendre rule on 0.1 ms panels is used instead. Either way the
//! jet pipe is exact to rounding, so the chambers' integrator never has to resolve its
//! 295 Hz ringing or the 7050 rad/s current transient.
//!
//! Where each equation lives: this module states none of the thesis's equations. It takes
//! * the current driver (2.1)–(2.3) from `physics::current_driver`: `CurrentDriver` (the
//!   first-order mode: ω_cd, and the static current ī = k_cd v_DA + i_offset) and its
//!   closed-form `Response` i(s) = base + ramp·s + δ e^{−ω_cd s}, with the turning point and
//!   the settling time;
//! * the tip force (2.4), `physics::jet_pipe::tip_force`;
//! * f3 (2.5) as a `physics::jet_pipe::StaticCurve` (`F3`, i.e. `TanhSaturation`: its values,
//!   the argument F_jp/F_jp_sat its series are in, the distance to tanh's poles that bounds
//!   them, and the series from `tanh_series`). The propagator is generic over the curve
//!   (static dispatch; `ElectromechanicalPropagator::new` takes `F3`); a curve whose
//!   `series` is `None` is integrated by quadrature;
//! * the jet pipe's linear dynamics (2.6) from `physics::jet_pipe::LinearDynamics::modes`:
//!   the poles λk, the residues βk and V⁻¹.
//!
//! What is its own is what integrating those takes: the convolution's closed forms (the
//! weights βk/(λk + nω_cd) of the series terms, the ramp's polynomial particular solution),
//! the quadrature, and the choice between them.
//!
//! The files, by concept:
//! * `modal`: the propagator, i.e. the current driver and jet pipe for one parameter set in
//!   the jet pipe's modal coordinates, and the exponentials every closed form is made of;
//! * `series`: the two closed forms built on f3's series (a held command's current
//!   transient, a ramp's slow sweep);
//! * `trajectory`: one step's [`Trajectory`], which picks a closed form or quadrature for
//!   each query, and the jet pipe's ringing the chambers' step sizes follow;
//! * `nodes`: the stage positions of one integrator step at once, from exponentials kept per
//!   step size.

mod modal;
mod nodes;
mod series;
mod trajectory;

pub use modal::ElectromechanicalPropagator;
pub use nodes::MAX_NODES;
pub use trajectory::Trajectory;

use nalgebra::Complex;

use crate::physics::jet_pipe;

type C64 = Complex<f64>;

/// Series coefficients: on the stack up to 16 terms (a command step of ordinary size needs
/// fewer), so building a step's trajectory does not allocate.
type Coefficients = jet_pipe::SeriesCoefficients;
const INLINE_TERMS: usize = jet_pipe::SERIES_INLINE_TERMS;

/// Current, jet pipe position and its first two derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ElectromechanicalState {
    pub current: f64,
    pub position: f64,
    pub velocity: f64,
    pub acceleration: f64,
}

/// What the tests of several files start from and compare with.
#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::{OdeSystem, Sdirk4, Statistics, Tolerances};
    use crate::physics::current_driver::CurrentDriver;
    use crate::physics::jet_pipe::{LinearDynamics, StaticCurve, F3};
    use crate::physics::parameters::Parameters;
    use nalgebra::SVector;

    /// A jet pipe in mid-swing.
    pub(super) fn swinging() -> ElectromechanicalState {
        ElectromechanicalState {
            current: 0.05,
            position: 1.2e-4,
            velocity: 0.02,
            acceleration: -30.0,
        }
    }

    /// Mid-swing, with the current lagging a ramp of `rate` V/s through `v` as a ramp
    /// continued from the last step does (so the ramp's closed form applies).
    pub(super) fn ramp_start(p: &Parameters, v: f64, rate: f64) -> ElectromechanicalState {
        ElectromechanicalState {
            current: CurrentDriver::from_parameters(p).response(0.0, v, rate).base,
            ..swinging()
        }
    }

    /// The four electromechanical states of (4.1) with the command linear in time.
    struct Electromechanics(Parameters, f64, f64);
    impl OdeSystem<4> for Electromechanics {
        fn rhs(&self, t: f64, y: &SVector<f64, 4>) -> SVector<f64, 4> {
            let p = &self.0;
            let driver = CurrentDriver::from_parameters(p);
            let i_bar = driver.static_current(self.1 + self.2 * t);
            let x_bar = F3::from_parameters(p).value(jet_pipe::tip_force(p.k_m, y[0]));
            SVector::<f64, 4>::new(
                driver.rate(i_bar, y[0]),
                y[2],
                y[3],
                LinearDynamics::from_parameters(p).third_derivative(x_bar, y[1], y[2], y[3]),
            )
        }
    }

    pub(super) fn reference(p: &Parameters, start: SVector<f64, 4>, v: f64, rate: f64, s: f64) -> SVector<f64, 4> {
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
}
