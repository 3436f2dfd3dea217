//! A fitted static curve read for people: its family (a limit, a dead zone, an offset) and
//! one sentence that states its largest departure from the straight line.

use crate::candidates::curves::FLAT;
use crate::vocabulary::Family;
use jetpipe_model::physics::static_curve::{StaticCurve, MAX_KNOTS};

/// The curves that `set` turns on: (prefix, curve).
fn curves_in(set: &[(&'static str, f64)]) -> Vec<(&'static str, StaticCurve)> {
    let mut out = vec![];
    for prefix in [
        "command_curve",
        "force_sensor_curve",
        "p1_sensor_curve",
        "p2_sensor_curve",
    ] {
        let get = |name: String| set.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
        let Some(n) = get(format!("{prefix}_knots")) else {
            continue;
        };
        let n = (n as usize).min(MAX_KNOTS);
        let x: Vec<f64> = (1..=n).map(|k| get(format!("{prefix}_x_{k}")).unwrap_or(0.0)).collect();
        let y: Vec<f64> = (1..=n).map(|k| get(format!("{prefix}_y_{k}")).unwrap_or(0.0)).collect();
        out.push((prefix, StaticCurve::through(&x, &y)));
    }
    out
}

/// The family of a discovered term: `limit` when a curve in `set` is flat at an end (a
/// saturation), else the candidate's.
pub fn family(candidate_family: Family, set: &[(&'static str, f64)]) -> Family {
    let curves = curves_in(set);
    if curves.is_empty() {
        return candidate_family;
    }
    if curves.iter().any(|(_, c)| flat_end(c).is_some()) {
        Family::Limit
    } else {
        Family::Nonlinearity
    }
}

fn slope(c: &StaticCurve, j: usize) -> f64 {
    (c.y[j + 1] - c.y[j]) / (c.x[j + 1] - c.x[j])
}

/// A flat end: (true for the upper end, the knot where it starts).
fn flat_end(c: &StaticCurve) -> Option<(bool, usize)> {
    let n = c.len();
    if n < 3 {
        return None;
    }
    if slope(c, n - 2).abs() < FLAT {
        // The flat run may span several segments: its first knot.
        let mut k = n - 2;
        while k > 0 && slope(c, k - 1).abs() < FLAT {
            k -= 1;
        }
        return Some((true, k));
    }
    if slope(c, 0).abs() < FLAT {
        let mut k = 1;
        while k + 1 < n && slope(c, k).abs() < FLAT {
            k += 1;
        }
        return Some((false, k));
    }
    None
}

/// A sentence on what a curve is, in physical words.
fn describe(prefix: &str, c: &StaticCurve) -> String {
    let (place, quantity, unit, scale, shown) = match prefix {
        "command_curve" => ("the command", "command", "V", 1.0, "V"),
        "force_sensor_curve" => ("the force sensor", "force", "N", 1.0, "N"),
        "p1_sensor_curve" => ("the chamber 1 pressure transducer", "pressure", "Pa", 1e-3, "kPa"),
        _ => ("the chamber 2 pressure transducer", "pressure", "Pa", 1e-3, "kPa"),
    };
    let _ = unit;
    let n = c.len();
    if let Some((upper, k)) = flat_end(c) {
        let level = c.y[k];
        return if upper {
            format!(
                "{place} saturates at {:.2} {shown}: above a {quantity} of {:.2} {shown} it reads {:.2} {shown}",
                scale * level,
                scale * c.x[k],
                scale * level
            )
        } else {
            format!(
                "{place} bottoms out at {:.2} {shown}: below a {quantity} of {:.2} {shown} it reads {:.2} {shown}",
                scale * level,
                scale * c.x[k],
                scale * level
            )
        };
    }
    // A flat stretch inside: a dead zone.
    let flat: Vec<usize> = (0..n - 1).filter(|&j| slope(c, j).abs() < FLAT).collect();
    if let (Some(&a), Some(&b)) = (flat.first(), flat.last()) {
        if flat.len() == b - a + 1 {
            let (lo, hi) = (c.x[a], c.x[b + 1]);
            let centre = 0.5 * (lo + hi);
            let half = 0.5 * (hi - lo);
            return if centre.abs() < 0.25 * half {
                format!(
                    "{place} has a dead zone of ±{:.2} {shown} (from {:.2} to {:.2} {shown}, where it gives {:.2} {shown})",
                    scale * half,
                    scale * lo,
                    scale * hi,
                    scale * c.y[a]
                )
            } else {
                format!(
                    "{place} has a dead zone from {:.2} to {:.2} {shown} of the {quantity}, where it gives {:.2} {shown}",
                    scale * lo,
                    scale * hi,
                    scale * c.y[a]
                )
            };
        }
    }
    // The largest departure from the identity at a knot.
    let (k, d) = (0..n)
        .map(|k| (k, c.y[k] - c.x[k]))
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .expect("a curve has knots");
    let slopes = (0..n - 1)
        .map(|j| format!("{:.3}", slope(c, j)))
        .collect::<Vec<_>>()
        .join(", ");
    // A curve that is a shift over most of its range headlines the shift, not the end
    // where it parts from it.
    if let Some(shift) = main_shift(c) {
        return format!(
            "{place} is shifted by {:+.3} {shown} over most of its range (the median departure from the identity at its knots; the largest, {:+.3} {shown}, at a {quantity} of {:.2} {shown}; slopes {slopes})",
            scale * shift,
            scale * d,
            scale * c.x[k],
        );
    }
    format!(
        "{place} departs most from the identity by {:+.3} {shown} at a {quantity} of {:.2} {shown} (slopes {slopes})",
        scale * d,
        scale * c.x[k],
    )
}

/// The curve's departure from the identity when it is nearly the same at most knots (all but
/// at most one within a fifth of the median departure from it) and that departure is at least
/// half the largest: the shift that describes it; `None` for a curve that bends.
fn main_shift(c: &StaticCurve) -> Option<f64> {
    let n = c.len();
    if n < 4 {
        return None;
    }
    let mut departures: Vec<f64> = (0..n).map(|k| c.y[k] - c.x[k]).collect();
    let largest = departures.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
    departures.sort_by(f64::total_cmp);
    let median = departures[n / 2];
    let near = departures
        .iter()
        .filter(|d| (*d - median).abs() <= 0.2 * median.abs())
        .count();
    (median != 0.0 && near + 1 >= n && median.abs() >= 0.5 * largest).then_some(median)
}

/// The reading of a discovered term whose parameters turn a curve on, or `None`.
pub fn reading(set: &[(&'static str, f64)]) -> Option<String> {
    let curves = curves_in(set);
    if curves.is_empty() {
        return None;
    }
    let parts: Vec<String> = curves
        .iter()
        .map(|(prefix, c)| {
            let knots: Vec<String> = (0..c.len())
                .map(|k| format!("({:.4e}, {:.4e})", c.x[k], c.y[k]))
                .collect();
            format!("{}; knots (x, y) in SI: {}", describe(prefix, c), knots.join(" "))
        })
        .collect();
    Some(format!("A static curve: {}.", parts.join("; ")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_command_curve_that_is_an_offset_but_at_one_end_reads_as_the_offset() {
        // 0.35 V over the range, 0.506 V at -10 V.
        let x = [-10.0, -7.0, -4.0, -1.0, 2.0, 5.0, 8.0, 10.0];
        let y: Vec<f64> = x.iter().map(|v| v + if *v == -10.0 { 0.506 } else { 0.35 }).collect();
        let sentence = describe("command_curve", &StaticCurve::through(&x, &y));
        assert!(sentence.starts_with("the command is shifted by +0.350 V"), "{sentence}");
        assert!(
            sentence.contains("the largest, +0.506 V, at a command of -10.00 V"),
            "{sentence}"
        );
    }

    #[test]
    fn a_command_curve_that_bends_reads_as_its_largest_departure() {
        let x = [-10.0, -5.0, 0.0, 5.0, 10.0];
        let y: Vec<f64> = x.iter().map(|v: &f64| v + 0.02 * v * v).collect();
        let sentence = describe("command_curve", &StaticCurve::through(&x, &y));
        assert!(
            sentence.starts_with("the command departs most from the identity by +2.000 V"),
            "{sentence}"
        );
    }

    #[test]
    fn a_flat_upper_end_reads_as_a_saturation_and_a_flat_middle_as_a_dead_zone() {
        let s = [
            ("force_sensor_curve_knots", 3.0),
            ("force_sensor_curve_x_1", 0.0),
            ("force_sensor_curve_y_1", 0.0),
            ("force_sensor_curve_x_2", 85.0),
            ("force_sensor_curve_y_2", 85.0),
            ("force_sensor_curve_x_3", 100.0),
            ("force_sensor_curve_y_3", 85.1),
        ];
        assert_eq!(family(Family::Nonlinearity, &s), Family::Limit);
        let r = reading(&s).unwrap();
        assert!(r.contains("the force sensor saturates at 85.00 N"), "{r}");
        let d = [
            ("command_curve_knots", 4.0),
            ("command_curve_x_1", -8.0),
            ("command_curve_y_1", -7.6),
            ("command_curve_x_2", -0.4),
            ("command_curve_y_2", 0.0),
            ("command_curve_x_3", 0.4),
            ("command_curve_y_3", 0.0),
            ("command_curve_x_4", 8.0),
            ("command_curve_y_4", 7.6),
        ];
        assert_eq!(family(Family::Nonlinearity, &d), Family::Nonlinearity);
        let r = reading(&d).unwrap();
        assert!(r.contains("the command has a dead zone of ±0.40 V"), "{r}");
    }
}
