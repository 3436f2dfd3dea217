//! The extra force on the piston as a generated class: products of two of the mechanics'
//! signals (the stopper position, velocity, the sign of the velocity, acceleration and speed,
//! the chambers' pressures above the return's), each a candidate at (mechanics, extra_force)
//! whose coefficient is one of the model's product slots
//! (`jetpipe_model::physics::extra_force`, `extra_force_product_k_*`).
//!
//! Every unordered pair of the seven signals is a candidate, a signal with itself too, but
//! for the pairs the library already has or that repeat another: sign(v)·sign(v) (nearly 1),
//! v·|v| (`extra_force_velocity_squared`), |v|·|v| (v·v), sign(v)·v (nearly |v|) and
//! sign(v)·|v| (nearly v, viscous friction); and the singles that the library lacks:
//! P1 − P_r, P2 − P_r and |v| (v, x_s, sign(v) and a alone are viscous friction, the
//! position force, Coulomb friction and the moving mass). Where the stopper position is a
//! factor it comes first, centred on the recording's mean x̄ (the slot's origin, a setting),
//! and the candidate has a second slot with the other factor alone, so that
//! c₁ (x_s − x̄) g + c₂ g = c₁ (x_s − x₀) g stays linear in its coefficients.

use crate::candidates::{interned, parameter_value, Candidate, Mechanism, Regressor, Term};
use crate::replay::signals::FORCE;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::extra_force::{ProductSignal, PRODUCT_SLOTS};
use jetpipe_model::physics::parameters::Parameters;

/// The name of a product slot's variable (`slot` 1-based; `field` one of first, second,
/// origin, coefficient).
pub fn slot_parameter(slot: usize, field: &str) -> &'static str {
    const NAMES: [[&str; 4]; PRODUCT_SLOTS] = [
        [
            "extra_force_product_1_first",
            "extra_force_product_1_second",
            "extra_force_product_1_origin",
            "extra_force_product_1_coefficient",
        ],
        [
            "extra_force_product_2_first",
            "extra_force_product_2_second",
            "extra_force_product_2_origin",
            "extra_force_product_2_coefficient",
        ],
        [
            "extra_force_product_3_first",
            "extra_force_product_3_second",
            "extra_force_product_3_origin",
            "extra_force_product_3_coefficient",
        ],
    ];
    let j = ["first", "second", "origin", "coefficient"]
        .iter()
        .position(|f| *f == field)
        .unwrap_or_else(|| panic!("{field} is not a field of a product slot"));
    NAMES[slot - 1][j]
}

/// The product slots that `params` leaves off (1-based).
pub fn free_slots(params: &Parameters) -> Vec<usize> {
    (1..=PRODUCT_SLOTS)
        .filter(|&k| parameter_value(params, slot_parameter(k, "coefficient")) == 0.0)
        .collect()
}

/// The factors of the generated candidates: (first, second), `One` for a single.
pub fn pairs() -> Vec<(ProductSignal, ProductSignal)> {
    use ProductSignal::*;
    let signals = &ProductSignal::ALL[1..];
    let repeated = [
        (Sign, Sign),
        (Velocity, Speed),
        (Speed, Speed),
        (Velocity, Sign),
        (Sign, Speed),
    ];
    let mut out = vec![];
    for (i, &a) in signals.iter().enumerate() {
        for &b in &signals[i..] {
            let (a, b) = (a.min_code(b), a.max_code(b));
            if repeated.iter().any(|&(x, y)| (x, y) == (a, b) || (y, x) == (a, b)) {
                continue;
            }
            out.push((a, b));
        }
    }
    for single in [Pressure1, Pressure2, Speed] {
        out.push((single, One));
    }
    out
}

trait ByCode {
    fn min_code(self, other: Self) -> Self;
    fn max_code(self, other: Self) -> Self;
}

impl ByCode for ProductSignal {
    fn min_code(self, other: Self) -> Self {
        if self.code() <= other.code() {
            self
        } else {
            other
        }
    }
    fn max_code(self, other: Self) -> Self {
        if self.code() <= other.code() {
            other
        } else {
            self
        }
    }
}

/// The label of a product: "extra force ∝ (x_s − x0)·a", "extra force ∝ (P1 − P_r)".
fn label(first: ProductSignal, second: ProductSignal) -> &'static str {
    let name = |s: ProductSignal| match s {
        ProductSignal::Position => "(x_s − x0)",
        s => s.name(),
    };
    let text = if second == ProductSignal::One {
        format!("extra force ∝ {}", name(first))
    } else {
        format!("extra force ∝ {}·{}", name(first), name(second))
    };
    interned(text)
}

/// One slot's coefficient as a linear term on the force channel.
fn term(slot: usize, first: ProductSignal, second: ProductSignal, origin: f64) -> Term {
    Term {
        name: slot_parameter(slot, "coefficient"),
        unit: "N",
        mechanism: Mechanism::Output {
            channel: FORCE,
            regressor: Regressor::Product { first, second, origin },
        },
        neutral: 0.0,
        step: 0.1,
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
    }
}

/// The generated candidates in the product slots `params` leaves off, the stopper position
/// centred on `mean_position` (m); none where too few slots are free.
pub fn candidates(params: &Parameters, mean_position: f64) -> Vec<Candidate> {
    let free = free_slots(params);
    let mut out = vec![];
    for (first, second) in pairs() {
        let centred = first == ProductSignal::Position;
        let needed = if centred { 2 } else { 1 };
        if free.len() < needed {
            continue;
        }
        let mut settings = vec![];
        let mut terms = vec![];
        let mut slot = |k: usize, a: ProductSignal, b: ProductSignal, origin: f64| {
            settings.push((slot_parameter(k, "first"), f64::from(a.code())));
            settings.push((slot_parameter(k, "second"), f64::from(b.code())));
            settings.push((slot_parameter(k, "origin"), origin));
            terms.push(term(k, a, b, origin));
        };
        if centred {
            slot(free[0], first, second, mean_position);
            // The other factor alone (for x_s·x_s, x_s itself, from the model's origin 0).
            slot(free[1], second, ProductSignal::One, 0.0);
        } else {
            slot(free[0], first, second, 0.0);
        }
        out.push(Candidate {
            label: label(first, second),
            location: Place::Mechanics,
            family: Family::ExtraForce,
            named: None,
            terms,
            settings,
        });
    }
    out
}

/// A slot's settings in `set`, else in `before`.
fn slot_value(set: &[(&'static str, f64)], before: &Parameters, slot: usize, field: &str) -> f64 {
    let name = slot_parameter(slot, field);
    set.iter()
        .rev()
        .find(|(n, _)| *n == name)
        .map_or_else(|| parameter_value(before, name), |(_, v)| *v)
}

/// The words of a signal in a reading.
fn words(s: ProductSignal) -> &'static str {
    match s {
        ProductSignal::One => "1",
        ProductSignal::Position => "the stopper position",
        ProductSignal::Velocity => "the stopper velocity",
        ProductSignal::Sign => "the sign of the stopper velocity (tanh(v / extra_force_sign_velocity))",
        ProductSignal::Acceleration => "the stopper acceleration",
        ProductSignal::Speed => "the stopper speed |v|",
        ProductSignal::Pressure1 => "chamber 1's pressure above the return's (P1 − P_r)",
        ProductSignal::Pressure2 => "chamber 2's pressure above the return's (P2 − P_r)",
    }
}

/// The SI unit of a signal as a reading writes it in a product of units.
fn unit(s: ProductSignal) -> &'static str {
    match s {
        ProductSignal::One | ProductSignal::Sign => "",
        s => s.unit(),
    }
}

/// The extra force products that `set` adds to the model `before`, in physical words: the
/// coefficient per SI unit of the signals, the stopper position less its origin; a slot of
/// the stopper position times g beside one of g alone is read as one product with the
/// origin moved, c₁ (x_s − x̄)/r g + c₂ g = c₁ (x_s − x₀)/r g, x₀ = x̄ − r c₂/c₁.
pub fn reading(set: &[(&'static str, f64)], before: &Parameters) -> Option<String> {
    let slots: Vec<(usize, ProductSignal, ProductSignal, f64, f64)> = (1..=PRODUCT_SLOTS)
        .filter(|&k| set.iter().any(|(n, _)| *n == slot_parameter(k, "coefficient")))
        .filter_map(|k| {
            let added =
                slot_value(set, before, k, "coefficient") - parameter_value(before, slot_parameter(k, "coefficient"));
            let first = ProductSignal::from_code(slot_value(set, before, k, "first"))?;
            let second = ProductSignal::from_code(slot_value(set, before, k, "second"))?;
            (added != 0.0).then(|| (k, first, second, slot_value(set, before, k, "origin"), added))
        })
        .collect();
    if slots.is_empty() {
        return None;
    }
    let mut used = vec![false; slots.len()];
    let mut sentences = vec![];
    for i in 0..slots.len() {
        if used[i] {
            continue;
        }
        used[i] = true;
        let (_, first, second, mut origin, c) = slots[i];
        if first == ProductSignal::Position {
            if let Some(j) =
                (0..slots.len()).find(|&j| !used[j] && slots[j].1 == second && slots[j].2 == ProductSignal::One)
            {
                used[j] = true;
                origin -= first.reference() * slots[j].4 / c;
            }
        }
        let per_si = c / (first.reference() * second.reference());
        let units: Vec<&str> = [unit(first), unit(second)]
            .into_iter()
            .filter(|u| !u.is_empty())
            .collect();
        let per = match units.len() {
            0 => String::new(),
            1 => format!(" per {}", units[0]),
            _ => format!(" per ({})", units.join(" · ")),
        };
        let first_words = match first {
            ProductSignal::Position => format!("(x_s − {:.1} mm)", origin * 1e3),
            ProductSignal::One => String::new(),
            s if origin != 0.0 => format!("({} less {origin:.4e} {})", words(s), s.unit()),
            s => words(s).to_string(),
        };
        let factors = match (first, second) {
            (ProductSignal::One, ProductSignal::One) => "a constant".to_string(),
            (ProductSignal::One, s) => words(s).to_string(),
            (_, ProductSignal::One) => first_words,
            (_, s) => format!("{first_words} × {}", words(s)),
        };
        let references: Vec<&str> = [first, second]
            .into_iter()
            .map(ProductSignal::reference_text)
            .filter(|&r| r != "1")
            .collect();
        sentences.push(format!(
            "An extra force on the piston of {per_si:.4e} N{per} × {factors} ({c:.4e} N per {}); it adds to the force the sensor reads.",
            references.join(" × ")
        ));
    }
    Some(sentences.join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_generated_pairs_skip_the_librarys_members_and_the_repeats() {
        use ProductSignal::*;
        let pairs = pairs();
        // 28 unordered pairs of 7 signals, 5 left out, 3 singles.
        assert_eq!(pairs.len(), 28 - 5 + 3, "{pairs:?}");
        for skipped in [
            (Sign, Sign),
            (Velocity, Speed),
            (Speed, Speed),
            (Velocity, Sign),
            (Sign, Speed),
        ] {
            assert!(!pairs.contains(&skipped), "{skipped:?}");
        }
        assert!(pairs.contains(&(Position, Acceleration)));
        assert!(pairs.contains(&(Position, Sign)));
        assert!(pairs.contains(&(Acceleration, Pressure2)));
        assert!(pairs.contains(&(Pressure1, One)));
        let labels: Vec<&str> = candidates(&Parameters::default(), 0.053)
            .iter()
            .map(|c| c.label)
            .collect();
        assert!(labels.contains(&"extra force ∝ (x_s − x0)·a"), "{labels:?}");
        assert!(labels.contains(&"extra force ∝ (P1 − P_r)"), "{labels:?}");
    }

    #[test]
    fn each_products_column_is_the_models_force_difference_with_its_slot_set() {
        use crate::candidates::set_parameter;
        use crate::fit::Problem;
        use crate::input::recording::Recording;
        use crate::replay::replay_fast;
        use jetpipe_model::physics::actuator::Actuator;
        // The stopper shaken at 3 Hz by 8 mm about 54 mm at 1 kHz, the command swept within
        // the range where the pressures set the force.
        let n = 1500;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
        let w = 2.0 * std::f64::consts::PI * 3.0;
        let recording = Recording {
            x_s: time.iter().map(|t| 0.054 + 0.008 * (w * t).sin()).collect(),
            v_da: time.iter().map(|t| 5.0 + 2.0 * (7.0 * t).sin()).collect(),
            force: vec![0.0; n],
            p1: None,
            p2: None,
            time,
            full_rate: None,
            fast_replay: crate::input::recording::FastReplayMethod::default(),
            acceleration_window: 0.0,
            repeated_rows: vec![],
        };
        let base = Parameters::default();
        let blocks = crate::input::blocks::blocks(&recording.time, &recording.x_s, 0.1, &[]);
        let problem = Problem::new(&recording, &base, &blocks, [0.05, 0.0, 0.0]);
        let plain = replay_fast(&Actuator::new(base.clone()).unwrap(), &recording, n).unwrap();
        let c = 0.8;
        for (first, second) in pairs() {
            let origin = if first == ProductSignal::Position { 0.0535 } else { 0.0 };
            let mut p = base.clone();
            for (field, value) in [
                ("first", f64::from(first.code())),
                ("second", f64::from(second.code())),
                ("origin", origin),
                ("coefficient", c),
            ] {
                set_parameter(&mut p, slot_parameter(2, field), value).unwrap();
            }
            let with = replay_fast(&Actuator::new(p).unwrap(), &recording, n).unwrap();
            let column = problem.column(Regressor::Product { first, second, origin }, &plain);
            let mut largest = 0.0f64;
            for k in 0..n {
                let difference = with.force[k] - plain.force[k];
                assert!(
                    (difference - c * column[k]).abs() < 1e-9 * (1.0 + plain.force[k].abs()),
                    "{first:?}·{second:?}, sample {k}: {difference} N against {} N",
                    c * column[k]
                );
                largest = largest.max(difference.abs());
            }
            assert!(largest > 1e-3, "{first:?}·{second:?} is felt: {largest} N");
        }
    }

    #[test]
    fn a_centred_product_is_read_with_its_origin_moved() {
        let before = Parameters::default();
        let set = [
            ("extra_force_product_1_first", 1.0),
            ("extra_force_product_1_second", 4.0),
            ("extra_force_product_1_origin", 0.054),
            ("extra_force_product_1_coefficient", 2.0),
            ("extra_force_product_2_first", 4.0),
            ("extra_force_product_2_second", 0.0),
            ("extra_force_product_2_origin", 0.0),
            ("extra_force_product_2_coefficient", 0.2),
        ];
        // x0 = 54 mm − 10 mm × 0.2/2 = 53 mm; 2 N per 10 mm × 1 m/s² = 200 N per (m · m/s²).
        let text = reading(&set, &before).unwrap();
        assert!(text.contains("2.0000e2 N per (m · m/s²)"), "{text}");
        assert!(text.contains("(x_s − 53.0 mm)"), "{text}");
        assert!(text.contains("the stopper acceleration"), "{text}");
    }
}
