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

    /// start, end, pieces per unit length and the pieces: what [`Self::value`] works from,
    /// for evaluations that take several points at once.
    #[inline(always)]
    pub(crate) fn parts(&self) -> (f64, f64, f64, &[Piece; PIECES]) {
        (self.start, self.end, self.pieces_per_unit, &self.coefficients)
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

/// Two piecewise polynomials on the same `PIECES` equal pieces of [start, end], evaluated
/// together: one piece index, one local variable, and each power's two coefficients side by
/// side, so the two Estrin passes run as one on two-wide vector registers.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewisePair<const PIECES: usize> {
    start: f64,
    end: f64,
    pieces_per_unit: f64,
    coefficients: [[[f64; 2]; DEGREE + 1]; PIECES],
}

impl<const PIECES: usize> PiecewisePair<PIECES> {
    /// The interpolants of `f` and `g` at the Chebyshev points of each piece (see
    /// [`Piecewise::interpolating`]).
    pub fn interpolating(start: f64, end: f64, f: impl Fn(f64) -> f64, g: impl Fn(f64) -> f64) -> Self {
        let first = Piecewise::<PIECES>::interpolating(start, end, f);
        let second = Piecewise::<PIECES>::interpolating(start, end, g);
        let mut coefficients = [[[0.0; 2]; DEGREE + 1]; PIECES];
        for (piece, (a, b)) in coefficients
            .iter_mut()
            .zip(first.coefficients.iter().zip(&second.coefficients))
        {
            for (pair, (&ca, &cb)) in piece.iter_mut().zip(a.iter().zip(b)) {
                *pair = [ca, cb];
            }
        }
        Self {
            start,
            end,
            pieces_per_unit: first.pieces_per_unit,
            coefficients,
        }
    }

    /// Both values at `x`, or `None` outside [start, end] (and for NaN); the same to the bit
    /// as the two [`Piecewise`] evaluations.
    #[inline]
    pub fn value(&self, x: f64) -> Option<[f64; 2]> {
        if !(x >= self.start && x <= self.end) {
            return None;
        }
        let position = (x - self.start) * self.pieces_per_unit;
        let k = (position as i32).min(PIECES as i32 - 1) as usize;
        Some(estrin_pair(&self.coefficients[k], 2.0 * (position - k as f64) - 1.0))
    }
}

/// [`estrin`] for two coefficient sets at once.
#[inline]
fn estrin_pair(c: &[[f64; 2]; DEGREE + 1], u: f64) -> [f64; 2] {
    let u2 = u * u;
    let u4 = u2 * u2;
    let mut value = [0.0; 2];
    for (j, v) in value.iter_mut().enumerate() {
        let low = (c[0][j] + c[1][j] * u) + u2 * (c[2][j] + c[3][j] * u);
        let high = (c[4][j] + c[5][j] * u) + u2 * (c[6][j] + c[7][j] * u);
        *v = low + u4 * (high + u4 * c[8][j]);
    }
    value
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
        if (1..DEGREE).contains(&k) {
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

    #[test]
    fn a_pair_evaluates_to_the_bit_as_its_two_polynomials() {
        let (f, g) = (f64::exp, |x: f64| 1.0 / (2.0 + x));
        let pair = PiecewisePair::<10>::interpolating(-0.5, 2.0, f, g);
        let (single_f, single_g) = (
            Piecewise::<10>::interpolating(-0.5, 2.0, f),
            Piecewise::<10>::interpolating(-0.5, 2.0, g),
        );
        for j in 0..=2500 {
            let x = -0.5 + 2.5 * j as f64 / 2500.0;
            let [a, b] = pair.value(x).unwrap();
            assert_eq!(a, single_f.value(x).unwrap(), "x {x}");
            assert_eq!(b, single_g.value(x).unwrap(), "x {x}");
            assert!((a - f(x)).abs() < 1e-9 && (b - g(x)).abs() < 1e-9, "x {x}");
        }
        assert_eq!(pair.value(-0.5 - 1e-12), None);
        assert_eq!(pair.value(2.0 + 1e-12), None);
        assert_eq!(pair.value(f64::NAN), None);
    }
}
