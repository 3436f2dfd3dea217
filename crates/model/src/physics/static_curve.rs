//! A static curve at a place of the chain: y = c(x), piecewise linear through up to
//! [`MAX_KNOTS`] knots (x_k, y_k), continued beyond the end knots along the end segments.
//! Off (the identity) with fewer than two knots.
//!
//! Piecewise linear rather than a monotone cubic Hermite spline: the mechanisms it stands
//! for (a dead zone, a saturation, a clipped range) have corners, which a knot reproduces
//! exactly and a C¹ spline rounds off; a reading is linear in the knot values, so a curve
//! on a measured channel is fitted by linear least squares on hat functions; and the curve
//! is non-decreasing exactly when its knot values are.
//!
//! The model has one at the command (the D/A voltage the current driver sees as a function
//! of the logged command, `command_curve_*`), at the force sensor (the reading as a
//! function of the force, `force_sensor_curve_*`) and at each pressure transducer
//! (`p1_sensor_curve_*`, `p2_sensor_curve_*`).

/// The most knots a curve has.
pub const MAX_KNOTS: usize = 8;

/// A curve's parameters: the number of knots in use (0 = off; a float, as the FMU sets
/// it) and the knots' abscissae and values, in the units of the place.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StaticCurve {
    pub knots: f64,
    pub x: [f64; MAX_KNOTS],
    pub y: [f64; MAX_KNOTS],
}

impl Default for StaticCurve {
    fn default() -> Self {
        Self {
            knots: 0.0,
            x: [0.0; MAX_KNOTS],
            y: [0.0; MAX_KNOTS],
        }
    }
}

impl StaticCurve {
    /// A curve through the knots `(x, y)` (at most [`MAX_KNOTS`]).
    pub fn through(x: &[f64], y: &[f64]) -> Self {
        let mut c = Self::default();
        let n = x.len().min(y.len()).min(MAX_KNOTS);
        c.knots = n as f64;
        c.x[..n].copy_from_slice(&x[..n]);
        c.y[..n].copy_from_slice(&y[..n]);
        c
    }

    /// The number of knots in use.
    pub fn len(&self) -> usize {
        if self.knots >= 2.0 {
            (self.knots as usize).min(MAX_KNOTS)
        } else {
            0
        }
    }

    /// Whether no knot is in use (the curve is off).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether the curve is on (two knots or more).
    pub fn is_on(&self) -> bool {
        self.len() >= 2
    }

    /// c(v): linear between knots, along the end segments beyond them; v itself when off.
    pub fn at(&self, v: f64) -> f64 {
        let n = self.len();
        if n < 2 {
            return v;
        }
        // The segment [x_k, x_k+1] that v lies in, the end ones extended.
        let mut k = 0;
        while k + 2 < n && v > self.x[k + 1] {
            k += 1;
        }
        let (x0, x1, y0, y1) = (self.x[k], self.x[k + 1], self.y[k], self.y[k + 1]);
        y0 + (v - x0) * (y1 - y0) / (x1 - x0)
    }

    /// The least v that the curve takes to `y` or above: the curve undone where it rises,
    /// and the start of a flat end for a reading at or beyond its level (a saturated
    /// transducer's lowest quantity that reads so). `y` itself when off. A curve that falls
    /// somewhere (a fitted curve that dips where the noise lets it) has no such inverse, and
    /// gives the preimage of `y` nearest `y`, as a transducer's curve departs little from
    /// its identity; `None` when it has none.
    pub fn inverse(&self, y: f64) -> Option<f64> {
        let n = self.len();
        if n < 2 {
            return Some(y);
        }
        // Knot values a rounding apart are one level (a fitted curve's flat end is a sum of
        // increments, and its knots differ in the last bit).
        let level = 1e-12 * self.y[..n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let along = |k: usize| self.x[k] + (y - self.y[k]) * (self.x[k + 1] - self.x[k]) / (self.y[k + 1] - self.y[k]);
        if (1..n).any(|k| self.y[k] < self.y[k - 1] - level) {
            let mut nearest: Option<f64> = None;
            for k in 0..n - 1 {
                if (self.y[k + 1] - self.y[k]).abs() <= level {
                    continue;
                }
                let v = along(k);
                // The end segments extend beyond their knots, as `at` does.
                let from = if k == 0 { f64::NEG_INFINITY } else { self.x[k] };
                let to = if k == n - 2 { f64::INFINITY } else { self.x[k + 1] };
                if v >= from && v <= to && nearest.map_or(true, |m| (v - y).abs() < (m - y).abs()) {
                    nearest = Some(v);
                }
            }
            return nearest;
        }
        let rises = |k: usize| self.y[k + 1] > self.y[k] + level;
        if y <= self.y[0] {
            // Below the first knot, along the first segment when it rises.
            return Some(if rises(0) { along(0) } else { self.x[0] });
        }
        for k in 0..n - 1 {
            if y <= self.y[k + 1] && rises(k) {
                return Some(along(k));
            }
        }
        // At or above the last knot's level: along the last segment when it rises, else
        // where the flat stretch at the top begins.
        if rises(n - 2) {
            return Some(along(n - 2));
        }
        let mut k = n - 1;
        while k > 0 && self.y[k - 1] >= self.y[n - 1] - level {
            k -= 1;
        }
        Some(self.x[k])
    }

    /// Checks of a curve whose parameters are named `prefix`_knots, `prefix`_x_k,
    /// `prefix`_y_k: the count a whole number in {0, 2, …, 8}, the abscissae in use
    /// strictly increasing.
    pub fn check(&self, prefix: &str, unit: &str) -> Result<(), String> {
        let k = self.knots;
        if !(k == 0.0 || (k.fract() == 0.0 && (2.0..=MAX_KNOTS as f64).contains(&k))) {
            return Err(format!(
                "{prefix}_knots = {k} is invalid: must be 0 (off) or a whole number from 2 to {MAX_KNOTS}"
            ));
        }
        for j in 1..self.len() {
            if self.x[j] <= self.x[j - 1] {
                return Err(format!(
                    "{prefix}_x_{} = {} {unit} is invalid: must exceed {prefix}_x_{} = {} {unit} (the knots' abscissae increase)",
                    j + 1,
                    self.x[j],
                    j,
                    self.x[j - 1]
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_curve_is_undone_where_it_rises_at_the_start_of_a_flat_end_and_where_it_dips_nearest_the_reading() {
        // The identity up to 40, flat at 40 beyond: a saturation.
        let c = StaticCurve::through(&[0.0, 20.0, 40.0, 90.0], &[0.0, 20.0, 40.0, 40.0]);
        for v in [-5.0, 3.0, 25.0, 39.5] {
            let back = c.inverse(c.at(v)).unwrap();
            assert!((back - v).abs() < 1e-12, "{v} came back as {back}");
        }
        assert_eq!(c.inverse(40.0), Some(40.0));
        assert_eq!(c.inverse(40.3), Some(40.0), "a reading above the level");
        // A dead zone: flat from -1 to 1 at 0; a reading of 0 goes to the zone's start.
        let dz = StaticCurve::through(&[-5.0, -1.0, 1.0, 5.0], &[-4.0, 0.0, 0.0, 4.0]);
        assert_eq!(dz.inverse(0.0), Some(-1.0));
        assert!((dz.inverse(2.0).unwrap() - 3.0).abs() < 1e-12);
        assert_eq!(StaticCurve::default().inverse(7.0), Some(7.0));
        // A curve that dips: the preimage nearest the reading.
        let falls = StaticCurve::through(&[0.0, 1.0, 2.0], &[0.0, 2.0, 1.0]);
        assert_eq!(falls.inverse(1.5), Some(1.5));
        let dips = StaticCurve::through(&[0.0, 1.0, 2.0, 3.0], &[0.0, 1.1, 1.0, 3.0]);
        assert!((dips.inverse(1.05).unwrap() - 1.05 / 1.1).abs() < 1e-12);
        assert!((dips.inverse(2.0).unwrap() - 2.5).abs() < 1e-12);
        assert!(
            (dips.inverse(-1.0).unwrap() - -1.0 / 1.1).abs() < 1e-12,
            "along the first segment"
        );
        // A reading above all that a falling last segment leaves it: no preimage.
        assert_eq!(falls.inverse(5.0), None);
        // A flat end whose knots differ in the last bit is flat.
        let rounded = StaticCurve::through(
            &[0.0, 1.0, 2.0, 3.0],
            &[0.0, 449992.5683787812, 449992.56837878114, 449992.56837878114],
        );
        assert_eq!(rounded.inverse(450000.0), Some(1.0));
    }

    #[test]
    fn an_off_curve_is_the_identity_bit_for_bit() {
        let c = StaticCurve::default();
        for v in [-3.7, 0.0, 1e-300, 4.2e5, f64::MAX] {
            assert_eq!(c.at(v).to_bits(), v.to_bits());
        }
    }

    #[test]
    fn a_curve_is_linear_between_knots_and_along_its_end_segments_beyond_them() {
        // A dead zone of ±0.4 V within ±10 V.
        let c = StaticCurve::through(&[-10.0, -0.4, 0.4, 10.0], &[-9.6, 0.0, 0.0, 9.6]);
        assert_eq!(c.at(0.2), 0.0);
        assert!((c.at(5.2) - 4.8).abs() < 1e-12);
        assert!((c.at(-12.0) - -11.6).abs() < 1e-12, "{}", c.at(-12.0));
        assert!((c.at(12.0) - 11.6).abs() < 1e-12);
        // A saturation: flat beyond its last knot.
        let s = StaticCurve::through(&[0.0, 85.0, 100.0], &[0.0, 85.0, 85.0]);
        assert_eq!(s.at(130.0), 85.0);
    }

    #[test]
    fn knots_that_do_not_increase_are_refused_naming_the_variable_the_value_and_the_limit() {
        let c = StaticCurve::through(&[0.0, 2.0, 2.0], &[0.0, 1.0, 2.0]);
        let e = c.check("force_sensor_curve", "N").unwrap_err();
        assert!(
            e.starts_with("force_sensor_curve_x_3 = 2 N is invalid: must exceed force_sensor_curve_x_2 = 2 N"),
            "{e}"
        );
        let mut one = StaticCurve::through(&[0.0, 1.0], &[0.0, 1.0]);
        one.knots = 2.5;
        let e = one.check("command_curve", "V").unwrap_err();
        assert!(e.starts_with("command_curve_knots = 2.5 is invalid"), "{e}");
        assert!(StaticCurve::default().check("command_curve", "V").is_ok());
    }
}
