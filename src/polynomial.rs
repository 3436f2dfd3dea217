//! Piecewise polynomials of degree 8 on equal pieces, evaluated by Estrin's scheme: the
//! model's hot transcendental functions of one variable (the orifice areas of the jet pipe
//! position, r^{1/γ} in the flow law) are tabulated this way once, so the integrator's
//! critical path holds a handful of multiply-adds instead of `atan2` or `powf`.

/// Degree of every piece.
pub const DEGREE: usize = 8;

/// Coefficients of one piece in its local variable u ∈ [−1, 1], lowest power first.
pub type Piece = [f64; DEGREE + 1];

/// p(u) = Σ cₖ uᵏ by Estrin's scheme: four dependent multiply-adds instead of Horner's eight.
#[inline]
pub fn estrin(c: &Piece, u: f64) -> f64 {
    let u2 = u * u;
    let u4 = u2 * u2;
    let low = (c[0] + c[1] * u) + u2 * (c[2] + c[3] * u);
    let high = (c[4] + c[5] * u) + u2 * (c[6] + c[7] * u);
    low + u4 * (high + u4 * c[8])
}

/// `PIECES` equal pieces covering [start, end].
#[derive(Clone, Debug, PartialEq)]
pub struct Piecewise<const PIECES: usize> {
    start: f64,
    end: f64,
    pieces_per_unit: f64,
    coefficients: [Piece; PIECES],
}

impl<const PIECES: usize> Piecewise<PIECES> {
    /// Pieces from `piece(centre, half_width)`, which returns the coefficients in
    /// u = (x − centre)/half_width.
    pub fn from_pieces(start: f64, end: f64, mut piece: impl FnMut(f64, f64) -> Piece) -> Self {
        let width = (end - start) / PIECES as f64;
        let mut coefficients = [[0.0; DEGREE + 1]; PIECES];
        for (k, c) in coefficients.iter_mut().enumerate() {
            *c = piece(start + (k as f64 + 0.5) * width, 0.5 * width);
        }
        Self {
            start,
            end,
            pieces_per_unit: 1.0 / width,
            coefficients,
        }
    }

    /// The interpolant of `f` at the 9 Chebyshev points of each piece (never its ends, so `f`
    /// may be singular there), in monomials of u.
    pub fn interpolating(start: f64, end: f64, f: impl Fn(f64) -> f64) -> Self {
        Self::from_pieces(start, end, |centre, half| {
            chebyshev_interpolant(|u| f(centre + half * u))
        })
    }

    /// The value at `x`, or `None` outside [start, end] (and for NaN).
    #[inline]
    pub fn value(&self, x: f64) -> Option<f64> {
        if !(x >= self.start && x <= self.end) {
            return None;
        }
        let position = (x - self.start) * self.pieces_per_unit;
        // 0 ≤ position ≤ PIECES here: through i32 the conversion is one instruction and
        // a compare, without `as usize`'s handling of values at and above 2^63.
        let k = (position as i32).min(PIECES as i32 - 1) as usize;
        Some(estrin(&self.coefficients[k], 2.0 * (position - k as f64) - 1.0))
    }
}

/// Monomial coefficients of the degree-8 interpolant of `f` on [−1, 1] at the Chebyshev
/// points of the first kind.
pub fn chebyshev_interpolant(f: impl Fn(f64) -> f64) -> Piece {
    use std::f64::consts::PI;
    let n = DEGREE + 1;
    let angle = |j: usize| PI * (j as f64 + 0.5) / n as f64;
    let values: Vec<f64> = (0..n).map(|j| f(angle(j).cos())).collect();
    // c_k = (2/n) Σ_j f_j cos(k θ_j), c_0 halved.
    let chebyshev: Vec<f64> = (0..n)
        .map(|k| {
            let sum: f64 = (0..n).map(|j| values[j] * (k as f64 * angle(j)).cos()).sum();
            sum * 2.0 / n as f64 * if k == 0 { 0.5 } else { 1.0 }
        })
        .collect();
    // Σ c_k T_k(u) in monomials, with T_{k+1} = 2u T_k − T_{k−1}.
    let mut monomial = [0.0; DEGREE + 1];
    let (mut previous, mut current) = ([0.0; DEGREE + 1], [0.0; DEGREE + 1]);
    previous[0] = 1.0;
    current[1] = 1.0;
    for (k, c) in chebyshev.iter().enumerate() {
        let t_k = if k == 0 { &previous } else { &current };
        for (m, t) in monomial.iter_mut().zip(t_k) {
            *m += c * t;
        }
        if k >= 1 && k < DEGREE {
            let mut next = [0.0; DEGREE + 1];
            for i in 0..DEGREE {
                next[i + 1] = 2.0 * current[i];
            }
            for (x, p) in next.iter_mut().zip(&previous) {
                *x -= p;
            }
            previous = current;
            current = next;
        }
    }
    monomial
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_polynomials_of_degree_8_and_interpolates_smooth_functions() {
        let p = |x: f64| 1.0 - 2.0 * x + 0.5 * x.powi(3) - 0.25 * x.powi(8);
        let fit = Piecewise::<3>::interpolating(-1.5, 2.0, p);
        for j in 0..=1000 {
            let x = -1.5 + 3.5 * j as f64 / 1000.0;
            assert!(
                (fit.value(x).unwrap() - p(x)).abs() < 1e-12 * (1.0 + p(x).abs()),
                "x {x}"
            );
        }
        // exp on pieces of width 1/16: the truncation error is ~1e-19, so what is left is
        // rounding, mostly from converting Chebyshev to monomial coefficients (T_8 has
        // coefficients up to 128): 7 units in the last place measured, 16 allowed.
        let fit = Piecewise::<16>::interpolating(0.0, 1.0, f64::exp);
        let worst = (0..=1000)
            .map(|j| j as f64 / 1000.0)
            .map(|x| (fit.value(x).unwrap() - x.exp()).abs() / (x.exp() * f64::EPSILON))
            .fold(0.0, f64::max);
        assert!(worst <= 16.0, "{worst} ulp");
        assert_eq!(fit.value(-1e-9), None);
        assert_eq!(fit.value(1.0 + 1e-9), None);
        assert_eq!(fit.value(f64::NAN), None);
    }
}
