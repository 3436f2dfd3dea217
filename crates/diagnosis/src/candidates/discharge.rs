//! The valve orifices' discharge coefficient as a static curve of the pressure ratio across
//! each (the model's `discharge_curve_*`): the candidate that fits it through the model, and
//! its reading.
//!
//! The thesis takes one C_d for all four orifices at every pressure ratio. A sharp-edged
//! orifice's jet contracts less as the flow chokes, so a real C_d rises as the ratio
//! P_down/P_up falls; nothing else along the chain changes the flows by a factor that
//! depends on the ratio alone, so the curve is a place of its own at the valve.

use crate::candidates::{Candidate, Mechanism, Term};
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;

/// The pressure ratios of the knots: evenly over 0–1 (four knots left P2 1.6 noise floors
/// off where C_d follows a parabola in the ratio; five, 1.1), which the supply orifices
/// (P/P_s, about 0.2–0.95) and the return orifices (P_r/P, about 0.15–0.7) share.
pub const KNOT_RATIOS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

const VALUES: [&str; 5] = [
    "discharge_curve_y_1",
    "discharge_curve_y_2",
    "discharge_curve_y_3",
    "discharge_curve_y_4",
    "discharge_curve_y_5",
];
const ABSCISSAE: [&str; 5] = [
    "discharge_curve_x_1",
    "discharge_curve_x_2",
    "discharge_curve_x_3",
    "discharge_curve_x_4",
    "discharge_curve_x_5",
];

/// The candidate, where the model `base` has no discharge curve yet: the knot values are
/// fitted from the model's constant C_d (where the model starts as it is).
pub fn candidate(base: &Parameters) -> Option<Candidate> {
    if base.discharge_curve.is_on() {
        return None;
    }
    let mut settings = vec![("discharge_curve_knots", KNOT_RATIOS.len() as f64)];
    settings.extend(ABSCISSAE.iter().zip(KNOT_RATIOS).map(|(&name, x)| (name, x)));
    let terms = VALUES
        .iter()
        .map(|&name| Term {
            name,
            unit: "1",
            mechanism: Mechanism::Parameter(name),
            neutral: base.c_d,
            step: 0.01 * base.c_d,
            lower: 0.0,
            upper: 1.0,
        })
        .collect();
    Some(Candidate {
        label: "discharge coefficient against the pressure ratio",
        location: Place::Valve,
        family: Family::Nonlinearity,
        named: None,
        terms,
        settings,
    })
}

/// Whether `candidate` is this one.
pub fn is_discharge_curve(candidate: &Candidate) -> bool {
    candidate.settings.iter().any(|(n, _)| *n == "discharge_curve_knots")
}

/// What a fitted discharge curve in `set` says, in physical words; `None` when `set` has none.
pub fn reading(set: &[(&'static str, f64)], before: &Parameters) -> Option<String> {
    let get = |name: &str| set.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
    let knots = get("discharge_curve_knots")? as usize;
    let points: Vec<(f64, f64)> = (1..=knots.min(8))
        .filter_map(|k| {
            Some((
                get(&format!("discharge_curve_x_{k}"))?,
                get(&format!("discharge_curve_y_{k}"))?,
            ))
        })
        .collect();
    let (&(r_low, cd_low), &(r_high, cd_high)) = (points.first()?, points.last()?);
    let listed: Vec<String> = points.iter().map(|(r, cd)| format!("{cd:.3} at r = {r:.2}")).collect();
    let trend = if cd_low > cd_high {
        format!(
            "it rises by {:.0} % from r = {r_high:.2} to r = {r_low:.2}, as the flow chokes",
            100.0 * (cd_low / cd_high - 1.0)
        )
    } else {
        format!(
            "it falls by {:.0} % from r = {r_high:.2} to r = {r_low:.2}",
            100.0 * (1.0 - cd_low / cd_high)
        )
    };
    Some(format!(
        "At the valve (nonlinearity): the orifices' discharge coefficient depends on the pressure ratio r = P_down/P_up across each: C_d = {} (the model had {:.3} at every ratio); {trend}. FMU parameters discharge_curve_knots, discharge_curve_x_k (r) and discharge_curve_y_k (C_d).",
        listed.join(", "),
        before.c_d
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_candidate_starts_from_the_models_constant_discharge_coefficient_at_every_knot() {
        let base = Parameters::default();
        let c = candidate(&base).unwrap();
        assert_eq!(c.terms.len(), KNOT_RATIOS.len());
        assert!(c.terms.iter().all(|t| t.neutral == base.c_d));
        let mut with = base.clone();
        for (name, value) in &c.settings {
            crate::candidates::set_parameter(&mut with, name, *value).unwrap();
        }
        for t in &c.terms {
            crate::candidates::set_parameter(&mut with, t.name, t.neutral).unwrap();
        }
        // Flat at C_d over every ratio: the model as it was.
        for r in [0.0, 0.1, 0.5, 0.9, 1.0] {
            assert!((with.discharge_curve.at(r) - base.c_d).abs() < 1e-15);
        }
        // A model that already has a curve gets no second one.
        assert!(candidate(&with).is_none());
    }

    #[test]
    fn the_reading_gives_each_knot_and_the_rise_towards_choking() {
        let set = vec![
            ("discharge_curve_knots", 2.0),
            ("discharge_curve_x_1", 0.0),
            ("discharge_curve_x_2", 1.0),
            ("discharge_curve_y_1", 0.9),
            ("discharge_curve_y_2", 0.7),
        ];
        let text = reading(&set, &Parameters::default()).unwrap();
        assert!(
            text.contains("0.900 at r = 0.00") && text.contains("0.700 at r = 1.00"),
            "{text}"
        );
        assert!(text.contains("rises by 29 %") && text.contains("0.696"), "{text}");
        assert!(reading(&[("C_d", 0.7)], &Parameters::default()).is_none());
    }
}
