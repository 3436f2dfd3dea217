//! Orifice areas from the receiver-plate geometry, (2.8)–(2.17), §2.5.
//!
//! Geometry (docs/model.md, "Orifice areas"): the two control ports are circles of radius R = D_jp/2 centred at
//! +D_jp (port 1, charging side) and −D_jp (port 2, venting side); the jet exit is a circle
//! of radius R centred at the absolute tip position x; the tip flange is a disc of radius
//! 3R centred at x.
//!
//! * supply area of port i: A_si = area(port i ∩ jet exit), (2.8) and (2.10);
//! * return area of port i: A_ri = area(port i) − area(port i ∩ flange), (2.9) and (2.11).
//!
//! The thesis writes these piecewise with the helper functions f_a, f_b, f_r1, f_r2
//! (2.12)–(2.17), whose OCR has sign slips; all of them are the area of a lens between two
//! circles, which [`circle_intersection_area`] computes in closed form. The unit tests check
//! every area against a numerical integration of the geometry and against (2.8)/(2.12).

use std::f64::consts::PI;

use crate::polynomial::PiecewisePair;

/// Area of the intersection of two discs of radii `r1`, `r2` whose centres are `d` apart.
pub fn circle_intersection_area(r1: f64, r2: f64, d: f64) -> f64 {
    let d = d.abs();
    if d >= r1 + r2 {
        return 0.0;
    }
    let r_small = r1.min(r2);
    if d <= (r1 - r2).abs() {
        return PI * r_small * r_small;
    }
    // Half chord c and the signed distances a1, a2 of the chord from each centre; atan2
    // keeps the segment angles accurate near tangency, where acos would lose half the digits.
    let kite = (-d + r1 + r2) * (d + r1 - r2) * (d - r1 + r2) * (d + r1 + r2);
    let half_chord = 0.5 * kite.max(0.0).sqrt() / d;
    // (r1 − r2)(r1 + r2), not r1² − r2²: for nearly concentric discs d² would be lost
    // against r1², and for equal discs this is exactly d/2.
    let a1 = (d * d + (r1 - r2) * (r1 + r2)) / (2.0 * d);
    let a2 = d - a1;
    let segment = |r: f64, a: f64| r * r * half_chord.atan2(a) - a * half_chord;
    if r1 == r2 {
        // Equal discs (the jet exit over a port): two equal segments, one arctangent.
        return 2.0 * segment(r1, a1);
    }
    segment(r1, a1) + segment(r2, a2)
}

/// Area of the jet exit and of each port, A_jp = π R².
pub fn port_area(d_jp: f64) -> f64 {
    let r = 0.5 * d_jp;
    PI * r * r
}

/// Supply area of port 1, (2.8): overlap of the jet exit at `x_abs` with port 1 at +D.
pub fn supply_area_port1(d_jp: f64, x_abs: f64) -> f64 {
    let r = 0.5 * d_jp;
    circle_intersection_area(r, r, x_abs - d_jp)
}

/// Supply area of port 2, (2.10): A_s2(x) = A_s1(−x), port 2 at −D.
pub fn supply_area_port2(d_jp: f64, x_abs: f64) -> f64 {
    supply_area_port1(d_jp, -x_abs)
}

/// Return area of port 1, (2.9): the part of port 1 not covered by the flange (radius 3R).
pub fn return_area_port1(d_jp: f64, x_abs: f64) -> f64 {
    let r = 0.5 * d_jp;
    (port_area(d_jp) - circle_intersection_area(r, 3.0 * r, x_abs - d_jp)).max(0.0)
}

/// Return area of port 2, (2.11): A_r2(x) = A_r1(−x), the part of port 2 (at −D) not
/// covered by the flange.
pub fn return_area_port2(d_jp: f64, x_abs: f64) -> f64 {
    return_area_port1(d_jp, -x_abs)
}

/// The four orifice areas at one tip position.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct OrificeAreas {
    pub supply_1: f64,
    pub return_1: f64,
    pub supply_2: f64,
    pub return_2: f64,
}

/// All four areas for the absolute tip position `x_abs` (2.7).
pub fn orifice_areas(d_jp: f64, x_abs: f64) -> OrificeAreas {
    OrificeAreas {
        supply_1: supply_area_port1(d_jp, x_abs),
        return_1: return_area_port1(d_jp, x_abs),
        supply_2: supply_area_port2(d_jp, x_abs),
        return_2: return_area_port2(d_jp, x_abs),
    }
}

/// Which stretch between tangencies `x_abs` lies in. The four areas (2.8)–(2.17) are analytic
/// in x_abs between consecutive multiples of D_jp and not across them: jet, port and flange
/// circles touch at ξ = x_abs/D = 0, ±2, ±3 (a lens opens like the 3/2 power of the distance)
/// and the jet lies right over a port at ξ = ±1 (a corner); beyond ±3D nothing changes.
/// The integrators end their steps where the jet pipe crosses one of these.
pub fn analytic_stretch(d_jp: f64, x_abs: f64) -> i32 {
    // ⌊ξ⌋ clamped to [−4, 3], as ⌊clamp(ξ)⌋ by truncation: `floor` is a library call on the
    // baseline x86-64 target, and the integrator asks twice per step (NaN gives 0 either way).
    let xi = (x_abs / d_jp).clamp(-4.0, 3.0);
    let truncated = xi as i32;
    if truncated as f64 > xi {
        truncated - 1
    } else {
        truncated
    }
}

/// The tangency between stretches `from` and `to` (adjacent or not) that a jet pipe moving from
/// one to the other crosses first.
pub fn first_tangency_between(d_jp: f64, from: i32, to: i32) -> f64 {
    let boundary = if to > from { from + 1 } else { from };
    boundary as f64 * d_jp
}

/// Pieces of the tabulated areas over |ξ| ∈ [0, 1]; the return area changes form at
/// |ξ| = 1/2, a piece boundary.
const AREA_PIECES: usize = 16;

/// The areas of a geometry with D = 1 (every length scales with D, so A(D, x) = D² A(1, x/D)),
/// tabulated once per process: the closed forms cost three to six `atan2` per call and the
/// integrator calls them at every stage. Each area is zero or a full port over most of the
/// stroke and grows like the 3/2 power of the distance from a tangency, so each tabulated
/// part is that power times a piecewise polynomial of degree 8, interpolated at Chebyshev
/// points: within 2e-15 of the port area of the closed forms (`tabulated_areas_match_the_closed_forms`).
///
/// With ξ = x/D, a = |ξ|, R = 1/2 and the port area π/4, for |ξ| ≤ 1 (the whole operating
/// range: the jet pipe saturates near ξ = ±0.5) one port's supply and the other's return
/// are open, and both are functions of a:
/// * supply(a) = a^{3/2} S(a);
/// * return(a) = a^{3/2} T(a) on [0, 1/2), π/4 − (1 − a)^{3/2} U(a) on [1/2, 1];
/// * A_s1 = supply, A_r2 = return for ξ ≥ 0; A_s2 = supply, A_r1 = return for ξ < 0.
///
/// S and T or U share their pieces ([`PiecewisePair`]): one lookup gives both open areas.
/// Beyond |ξ| = 1 the geometry repeats by reflection: A_s1(ξ) = A_s1(2 − ξ) on (1, 2) and 0
/// beyond, A_r1 = π/4 for ξ ≤ −1 and A_r1(ξ) = A_r1(2 − ξ) for ξ > 1 (0 up to ξ = 2).
#[derive(Debug)]
struct UnitAreaTable {
    supply_and_return: PiecewisePair<AREA_PIECES>,
}

impl UnitAreaTable {
    fn get() -> &'static Self {
        static TABLE: crate::compat::OnceLock<UnitAreaTable> = crate::compat::OnceLock::new();
        TABLE.get_or_init(|| {
            let power = |t: f64| t * t.sqrt();
            Self {
                supply_and_return: PiecewisePair::interpolating(
                    0.0,
                    1.0,
                    |a| supply_area_port1(1.0, a) / power(a),
                    |a| {
                        if a < 0.5 {
                            return_area_port1(1.0, -a) / power(a)
                        } else {
                            (port_area(1.0) - return_area_port1(1.0, -a)) / power(1.0 - a)
                        }
                    },
                ),
            }
        })
    }

    /// The open supply and return areas at a = |ξ| ≤ 1 (see the table's description).
    #[inline]
    fn open_areas(&self, a: f64) -> (f64, f64) {
        let [s, r] = self.supply_and_return.value(a).unwrap_or([0.0; 2]);
        let power = a * a.sqrt();
        let supply = power * s;
        let ret = if a < 0.5 {
            power * r
        } else {
            let t = 1.0 - a;
            port_area(1.0) - t * t.sqrt() * r
        };
        (supply, ret)
    }

    /// A_s1 at any ξ, through the reflection beyond ξ = 1.
    fn supply_1(&self, xi: f64) -> f64 {
        let xi = if xi > 1.0 { 2.0 - xi } else { xi };
        if (0.0..=1.0).contains(&xi) {
            self.open_areas(xi).0
        } else {
            0.0
        }
    }

    /// A_r1 at any ξ, through the reflection beyond ξ = 1.
    fn return_1(&self, xi: f64) -> f64 {
        let xi = if xi > 1.0 { 2.0 - xi } else { xi };
        if xi >= 0.0 {
            0.0
        } else if xi > -1.0 {
            self.open_areas(-xi).1
        } else {
            port_area(1.0)
        }
    }
}

/// [`orifice_areas`] from the tabulated unit geometry: what the integrators use.
pub fn tabulated_orifice_areas(d_jp: f64, x_abs: f64) -> OrificeAreas {
    let xi = x_abs / d_jp;
    let table = UnitAreaTable::get();
    let scale = d_jp * d_jp;
    if xi.abs() <= 1.0 {
        let (supply, ret) = table.open_areas(xi.abs());
        let (supply, ret) = (scale * supply, scale * ret);
        return if xi >= 0.0 {
            OrificeAreas {
                supply_1: supply,
                return_1: 0.0,
                supply_2: 0.0,
                return_2: ret,
            }
        } else {
            OrificeAreas {
                supply_1: 0.0,
                return_1: ret,
                supply_2: supply,
                return_2: 0.0,
            }
        };
    }
    if !xi.is_finite() {
        return orifice_areas(d_jp, x_abs);
    }
    OrificeAreas {
        supply_1: scale * table.supply_1(xi),
        return_1: scale * table.return_1(xi),
        supply_2: scale * table.supply_1(-xi),
        return_2: scale * table.return_1(-xi),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const D: f64 = 0.9652e-3;

    #[test]
    fn stretches_are_the_clamped_floor_of_the_position_in_diameters() {
        let mut xis: Vec<f64> = (-1000..=1000).map(|k| k as f64 * 0.0073).collect();
        xis.extend([
            -4.0, -3.0, -2.0, -1.0, -0.0, 0.0, 1.0, 2.0, 3.0, 4.0, -4.5, 3.5, 1e300, -1e300,
        ]);
        xis.extend([
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            -1e-300,
            1.0 - 1e-16,
            -1.0 - 2e-16,
        ]);
        for xi in xis {
            let x_abs = xi * D;
            let expected = (x_abs / D).floor().clamp(-4.0, 3.0) as i32;
            assert_eq!(analytic_stretch(D, x_abs), expected, "ξ = {xi}");
        }
    }

    /// Area of (disc a ∩ disc b) minus nothing, or of (disc a \ disc b), by integrating the
    /// chord overlap over y with the substitution y = r_a sin θ (smooth at the poles).
    fn numerical_area(ca: f64, ra: f64, cb: f64, rb: f64, subtract: bool) -> f64 {
        let n = 200_000;
        let mut sum = 0.0;
        for k in 0..n {
            let theta = -PI / 2.0 + PI * (k as f64 + 0.5) / n as f64;
            let y = ra * theta.sin();
            let dy = ra * theta.cos() * PI / n as f64;
            let ha = (ra * ra - y * y).max(0.0).sqrt();
            let (a0, a1) = (ca - ha, ca + ha);
            let overlap = if y.abs() < rb {
                let hb = (rb * rb - y * y).sqrt();
                (a1.min(cb + hb) - a0.max(cb - hb)).max(0.0)
            } else {
                0.0
            };
            sum += if subtract { (a1 - a0) - overlap } else { overlap } * dy;
        }
        sum
    }

    #[test]
    fn areas_match_numerical_integration_of_the_geometry() {
        let r = D / 2.0;
        let a_jp = port_area(D);
        for k in 0..=80 {
            let x = -4.0 * D + 8.0 * D * k as f64 / 80.0;
            let s1 = numerical_area(D, r, x, r, false);
            let r1 = numerical_area(D, r, x, 3.0 * r, true);
            let s2 = numerical_area(-D, r, x, r, false);
            let r2 = numerical_area(-D, r, x, 3.0 * r, true);
            let a = orifice_areas(D, x);
            for (name, closed, numeric) in [
                ("A_s1", a.supply_1, s1),
                ("A_r1", a.return_1, r1),
                ("A_s2", a.supply_2, s2),
                ("A_r2", a.return_2, r2),
            ] {
                assert!(
                    (closed - numeric).abs() < 2e-6 * a_jp,
                    "{name} at x = {x:e}: closed form {closed:e}, integral {numeric:e}"
                );
            }
        }
    }

    #[test]
    fn tabulated_areas_match_the_closed_forms() {
        for d in [0.5e-3, D, 2e-3] {
            let a_jp = port_area(d);
            let mut worst = 0.0f64;
            let mut check = |x: f64| {
                let (t, e) = (tabulated_orifice_areas(d, x), orifice_areas(d, x));
                for (tab, exact) in [
                    (t.supply_1, e.supply_1),
                    (t.return_1, e.return_1),
                    (t.supply_2, e.supply_2),
                    (t.return_2, e.return_2),
                ] {
                    // Closed orifices stay exactly closed (the flow law skips them), except
                    // within rounding of a tangency, where the closed form's kite product
                    // cancels and either form may give zero for an area below ~ε A_jp.
                    let open = |a: f64| a > 1e-15 * a_jp;
                    assert!(
                        !(exact == 0.0 && open(tab) || tab == 0.0 && open(exact)),
                        "x/D = {}: {tab:e} vs {exact:e}",
                        x / d
                    );
                    worst = worst.max((tab - exact).abs() / a_jp);
                }
            };
            for k in 0..=200_000 {
                check(d * (-3.5 + 7.0 * k as f64 / 200_000.0));
            }
            // Close to every tangency and piece end, from both sides.
            for centre in [-3.0, -2.0, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0] {
                for e in [1e-15, 1e-12, 1e-9, 1e-6, 1e-3] {
                    check(d * (centre - e));
                    check(d * (centre + e));
                }
            }
            assert!(worst < 1e-14, "D = {d}: worst deviation {worst:e} of the port area");
        }
        let nan = tabulated_orifice_areas(D, f64::NAN);
        assert!(nan.supply_1.is_nan() || nan.supply_1 == orifice_areas(D, f64::NAN).supply_1);
    }

    #[test]
    fn supply_area_agrees_with_the_thesis_form_2_8() {
        // (2.8): A_s1 = 2 f_a(|D − x|/2, R) for 0 ≤ x ≤ 2D, f_a(a, r) = r² acos(a/r) − a√(r² − a²).
        let r = D / 2.0;
        let f_a = |a: f64, r: f64| r * r * (a / r).acos() - a * (r * r - a * a).sqrt();
        for k in 0..=50 {
            let x = 2.0 * D * k as f64 / 50.0;
            let thesis = 2.0 * f_a(((D - x) / 2.0).abs(), r);
            assert!((supply_area_port1(D, x) - thesis).abs() < 1e-15, "x = {x}");
        }
    }

    #[test]
    fn centred_tip_covers_both_return_ports_and_feeds_neither() {
        let a = orifice_areas(D, 0.0);
        assert_eq!(a.supply_1, 0.0);
        assert_eq!(a.supply_2, 0.0);
        assert!(a.return_1.abs() < 1e-20 && a.return_2.abs() < 1e-20);
        // Fully deflected onto port 1: port 1 fully fed, port 2 fully open to return.
        let a = orifice_areas(D, D);
        assert!((a.supply_1 - port_area(D)).abs() < 1e-18);
        assert!((a.return_2 - port_area(D)).abs() < 1e-18);
        assert_eq!(a.return_1, 0.0);
        // Symmetry A_s2(x) = A_s1(−x), A_r2(x) = A_r1(−x) (docs/model.md's correction of (2.10)–(2.11)).
        for x in [-1.7 * D, -0.3 * D, 0.2 * D, 1.1 * D, 2.5 * D] {
            assert_eq!(supply_area_port2(D, x), supply_area_port1(D, -x));
            assert_eq!(return_area_port2(D, x), return_area_port1(D, -x));
        }
    }

    #[test]
    fn piecewise_breakpoints_of_2_9_and_2_11() {
        let a_jp = port_area(D);
        // A_r1 = A_jp for x ≤ −D and x ≥ 3D, 0 on [0, 2D].
        assert!((return_area_port1(D, -D) - a_jp).abs() < 1e-12 * a_jp);
        assert!((return_area_port1(D, 3.0 * D) - a_jp).abs() < 1e-12 * a_jp);
        assert!(return_area_port1(D, 0.5 * D) < 1e-20);
        assert!(return_area_port1(D, 2.0 * D) < 1e-20);
        // A_r2 = A_jp for x ≥ D, 0 on [−2D, 0].
        assert!((return_area_port2(D, D) - a_jp).abs() < 1e-12 * a_jp);
        assert!(return_area_port2(D, -D) < 1e-20);
    }
}
