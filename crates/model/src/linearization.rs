//! Linearisation about an equilibrium, §4.2.2: Δẋ = A Δx + B Δv_DA, ΔF_act = C Δx + D Δv_DA,
//! with the state of (4.1) in this crate's order [i, x_jp, ẋ_jp, ẍ_jp, P1, P2].
//!
//! A is the model's Jacobian at the operating point (exact for the current driver and jet
//! pipe, central differences for the chambers); B and C are exact. The poles are the
//! eigenvalues of A. Since the current driver and jet pipe feed the chambers one way and
//! have no finite zeros, the zeros of F_act/v_DA are those of the chamber block from x_jp to
//! F_act, a 2×2 system whose single zero has a closed form (Table 4.1's fluid zero).

use nalgebra::{Complex, SMatrix, SVector};

use crate::physics::actuator::{index, Actuator, Inputs, Jacobian, N_STATES};
use crate::physics::current_driver::CurrentDriver;
use crate::simulation::equilibrium;

/// The operating point of a linearisation.
#[derive(Clone, Debug, PartialEq)]
pub struct OperatingPoint {
    pub v_da: f64,
    pub x_s: f64,
    pub f_act: f64,
    pub current: f64,
    pub x_jp: f64,
    pub p1: f64,
    pub p2: f64,
}

/// The linear model and its poles and zeros (rad/s).
#[derive(Clone, Debug)]
pub struct LinearModel {
    pub a: Jacobian,
    pub b: SVector<f64, N_STATES>,
    pub c: SVector<f64, N_STATES>,
    pub d: f64,
    pub poles: Vec<Complex<f64>>,
    pub zeros: Vec<Complex<f64>>,
    pub operating_point: OperatingPoint,
}

/// The command voltage whose equilibrium force is `force` at stopper position `x_s`.
pub fn command_for_force(model: &Actuator, force: f64, x_s: f64) -> Result<f64, String> {
    let f = |v: f64| -> Result<f64, String> {
        let y = equilibrium(model, v, x_s)?;
        Ok(model.outputs(&y, x_s, 0.0).f_act)
    };
    let (mut lo, mut hi) = (-10.0, 10.0);
    let (f_lo, f_hi) = (f(lo)?, f(hi)?);
    if !(f_lo <= force && force <= f_hi) {
        return Err(format!(
            "force = {force} N is not reachable at x_s = {x_s} m: the static force spans {f_lo:.3}..{f_hi:.3} N for v_DA in [-10, 10] V"
        ));
    }
    // The static force rises monotonically with the command: bisect.
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if f(mid)? < force {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-13 {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// Linearise at the equilibrium of command `v_da` and stopper position `x_s`.
pub fn linearize(model: &Actuator, v_da: f64, x_s: f64) -> Result<LinearModel, String> {
    if let Some(slot) = model.params.modulation.iter().position(|slot| slot.is_on()) {
        // The constant's dependence on the signals would add terms to every row it enters.
        return Err(format!(
            "modulation_{}_parameter = {}: the linearisation does not carry the modulation slots; switch them off (0) to linearise the model without them",
            slot + 1,
            model.params.modulation[slot].parameter
        ));
    }
    if let Some(slot) = model.params.flexible.iter().position(|slot| slot.is_on()) {
        return Err(format!(
            "flexible_{}_parameter = {}: the linearisation does not carry the flexible slots; switch them off (0) to linearise the model without them",
            slot + 1,
            model.params.flexible[slot].parameter
        ));
    }
    let y0 = equilibrium(model, v_da, x_s)?;
    let u = Inputs {
        v_da,
        x_s,
        x_s_rate: 0.0,
        plays: None,
    };
    let mut a = model.jacobian(&y0, &u, &model.derivatives(&y0, &u));
    // Central differences for the chamber rows (the integrator's Jacobian is one-sided).
    for column in [index::JET_POSITION, index::P1, index::P2] {
        let h = 1e-6
            * y0[column]
                .abs()
                .max(if column == index::JET_POSITION { 1e-6 } else { 1e3 });
        let mut plus = y0;
        let mut minus = y0;
        plus[column] += h;
        minus[column] -= h;
        let (fp, fm) = (model.derivatives(&plus, &u), model.derivatives(&minus, &u));
        for row in [index::P1, index::P2] {
            a[(row, column)] = (fp[row] - fm[row]) / (2.0 * h);
        }
    }
    let mut b = SVector::<f64, N_STATES>::zeros();
    b[index::CURRENT] = CurrentDriver::from_parameters(&model.params).command_gain();
    let outputs = model.outputs(&y0, x_s, 0.0);
    let on_spring_floor = outputs.f_act > model.piston_area * (y0[index::P1] - y0[index::P2]);
    let mut c = SVector::<f64, N_STATES>::zeros();
    if !on_spring_floor {
        c[index::P1] = model.piston_area;
        c[index::P2] = -model.piston_area;
    }
    let poles = a.complex_eigenvalues().iter().copied().collect();
    let zeros = chamber_zero(&a, &c).into_iter().collect();
    Ok(LinearModel {
        a,
        b,
        c,
        d: 0.0,
        poles,
        zeros,
        operating_point: OperatingPoint {
            v_da,
            x_s,
            f_act: outputs.f_act,
            current: outputs.current,
            x_jp: outputs.x_jp,
            p1: outputs.p1,
            p2: outputs.p2,
        },
    })
}

/// The zero of the chamber block x_jp → F_act: with A_f the 2×2 pressure block, b_f its
/// x_jp column and c_f the force row, C adj(sI − A_f) b is n1 s + n0.
fn chamber_zero(a: &Jacobian, c: &SVector<f64, N_STATES>) -> Option<Complex<f64>> {
    let (p1, p2, x) = (index::P1, index::P2, index::JET_POSITION);
    let (a11, a12, a21, a22) = (a[(p1, p1)], a[(p1, p2)], a[(p2, p1)], a[(p2, p2)]);
    let (b1, b2) = (a[(p1, x)], a[(p2, x)]);
    let (c1, c2) = (c[p1], c[p2]);
    let n1 = c1 * b1 + c2 * b2;
    let n0 = -c1 * a22 * b1 + c1 * a12 * b2 + c2 * a21 * b1 - c2 * a11 * b2;
    (n1 != 0.0).then(|| Complex::new(-n0 / n1, 0.0))
}

impl LinearModel {
    /// Frequency response F_act/v_DA at `omega` rad/s.
    pub fn response(&self, omega: f64) -> Complex<f64> {
        let s = Complex::new(0.0, omega);
        let m: SMatrix<Complex<f64>, N_STATES, N_STATES> =
            SMatrix::<Complex<f64>, N_STATES, N_STATES>::identity() * s - self.a.map(|v| Complex::new(v, 0.0));
        let b = self.b.map(|v| Complex::new(v, 0.0));
        let x = m
            .lu()
            .solve(&b)
            .unwrap_or_else(SVector::<Complex<f64>, N_STATES>::zeros);
        self.c.map(|v| Complex::new(v, 0.0)).dot(&x) + Complex::new(self.d, 0.0)
    }

    /// The −3 dB frequency (Hz) of F_act relative to its DC gain, by bisection on a
    /// log-frequency grid.
    pub fn bandwidth_hz(&self) -> Option<f64> {
        let dc = self.response(1e-6).norm();
        if dc == 0.0 {
            return None;
        }
        let target = dc / 2f64.sqrt();
        let mut previous = 1e-3;
        let mut omega = 1e-3;
        while omega < 1e6 {
            omega *= 1.05;
            if self.response(omega).norm() < target {
                let (mut lo, mut hi) = (previous, omega);
                for _ in 0..60 {
                    let mid = (lo * hi).sqrt();
                    if self.response(mid).norm() < target {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                return Some(0.5 * (lo + hi) / (2.0 * std::f64::consts::PI));
            }
            previous = omega;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::physics::parameters::Parameters;

    fn at_45_newtons() -> LinearModel {
        let model = Actuator::new(Parameters::default()).unwrap();
        let v = command_for_force(&model, 45.0, 0.054).unwrap();
        linearize(&model, v, 0.054).unwrap()
    }

    #[test]
    fn poles_and_zero_match_table_4_1() {
        let lin = at_45_newtons();
        assert!((lin.operating_point.f_act - 45.0).abs() < 1e-6);
        let mut poles = lin.poles.clone();
        poles.sort_by(|a, b| a.re.partial_cmp(&b.re).unwrap());
        let near =
            |target: Complex<f64>, within: f64| poles.iter().any(|p| (p - target).norm() <= within * target.norm());
        for (re, im) in [(-7049.7, 0.0), (-973.9, 0.0), (-35.3, 1856.3), (-35.3, -1856.3)] {
            assert!(
                near(Complex::new(re, im), 0.01),
                "no pole within 1 % of {re}{im:+}j: {poles:?}"
            );
        }
        for target in [-5.0, -14.5] {
            assert!(
                near(Complex::new(target, 0.0), 0.15),
                "no fluid pole within 15 % of {target}: {poles:?}"
            );
        }
        let zero = lin.zeros[0];
        assert!((zero.re + 7.1).abs() <= 0.4 * 7.1 && zero.im == 0.0, "zero {zero}");
        // The zero really is one: the response vanishes there.
        let s = zero.re;
        let m = Jacobian::identity() * s - lin.a;
        let x = m.lu().solve(&lin.b).unwrap();
        let g_zero = lin.c.dot(&x);
        let g_dc = lin.response(1e-6).norm();
        assert!(g_zero.abs() < 1e-6 * g_dc, "G(zero) = {g_zero}, |G(0)| = {g_dc}");
    }

    #[test]
    fn open_loop_bandwidth_is_a_few_hertz() {
        let bw = at_45_newtons().bandwidth_hz().unwrap();
        assert!(bw > 1.0 && bw < 5.0, "{bw} Hz");
    }
}
