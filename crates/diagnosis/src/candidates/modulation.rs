//! A constant of the model that varies with a signal of the chain: one generated class.
//!
//! Any constant the model can modulate (`jetpipe_model::physics::modulation::MODULATABLE`)
//! times any signal of the chain (time, the command, the current, the jet position, the
//! stopper's position, velocity and direction, the force, each pressure and their
//! difference, a sinusoid at the residual's spectral line). The shape is piecewise linear
//! over knots at quantiles of the signal in the recording, flat beyond them; the simpler
//! shapes (a constant, a straight line between the end knots) are nested in it and win when
//! they do as well.
//!
//! Screening is first order: the constant's sensitivity S(t) (one replay, shared with the
//! other candidates) times the shape's basis functions φ_j(s(t)) gives columns on which the
//! residual of every measured channel is projected, on the training blocks, scored on the
//! held-out ones. Every pair costs one pass over the samples; the few best become candidates
//! whose knot values the model carries in a modulation slot (`modulation_k_*`), fitted and
//! checked through the model like every other candidate. A sinusoid is screened on the
//! model's answers to the constant oscillating (`oscillation.rs`), not on S(t) times sin
//! and cos: faster than the chambers, the product has the phase wrong.

use crate::candidates::{interned, parameter_value, Candidate, Mechanism};
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::modulation::{ModulationSignal, MODULATABLE};
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::variables::{ConstantKind, VARIABLES};

/// A signal a constant may follow in a recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Follows {
    Signal(ModulationSignal),
    /// A sinusoid of time at this frequency (Hz): both slots, sine and cosine.
    Periodic(f64),
}

impl Follows {
    /// The signal followed, a sinusoid at any frequency counting as one.
    pub(crate) fn kind(&self) -> Option<ModulationSignal> {
        match self {
            Follows::Signal(signal) => Some(*signal),
            Follows::Periodic(_) => None,
        }
    }
}

impl std::fmt::Display for Follows {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Follows::Signal(signal) => write!(f, "{}", signal.name()),
            Follows::Periodic(hz) => write!(f, "a sinusoid at {hz:.3} Hz"),
        }
    }
}

/// The place of the chain a constant belongs to: its row's place in the variable table.
pub fn place_of(constant: &'static str) -> Place {
    jetpipe_model::variables::TABLE
        .iter()
        .find(|r| r.variable.name == constant)
        .and_then(|r| r.place)
        .map_or(Place::Unknown, Place::from)
}

/// The family of a departure where `constant` at `place` follows `follows`: by what the
/// signal is, then by what the constant is (its row's kind), then by its place.
pub fn family_of(constant: &str, place: Place, follows: Follows) -> Family {
    let kind = jetpipe_model::variables::TABLE
        .iter()
        .find(|r| r.variable.name == constant)
        .and_then(|r| r.kind);
    match (follows, kind) {
        (Follows::Periodic(_), _) => Family::Periodic,
        (Follows::Signal(ModulationSignal::Time), _) => Family::Drift,
        (Follows::Signal(ModulationSignal::StopperVelocitySign), _) => Family::Asymmetry,
        (Follows::Signal(_), Some(ConstantKind::PortAreaFactor)) => Family::Asymmetry,
        (Follows::Signal(signal), Some(ConstantKind::LoadBearingLength)) if signal.is_load() => Family::Compliance,
        (Follows::Signal(_), _) => match place {
            Place::Mechanics => Family::ExtraForce,
            Place::Chambers => Family::ExtraFlow,
            _ => Family::Nonlinearity,
        },
    }
}

/// A difference step for a constant's sensitivity: the catalogue's where it fits the
/// constant, else a hundredth of its value, else the typical size its row in the variable
/// table gives, else 1e-3.
pub fn sensitivity_step(constant: &'static str, base: &Parameters, catalogue: &[Candidate]) -> f64 {
    if let Some(t) = catalogue
        .iter()
        .flat_map(|c| &c.terms)
        .find(|t| t.mechanism == Mechanism::Parameter(constant) && t.step > 0.0)
    {
        return t.step;
    }
    let value = parameter_value(base, constant);
    if value != 0.0 {
        return 0.01 * value.abs();
    }
    jetpipe_model::variables::TABLE
        .iter()
        .find(|r| r.variable.name == constant)
        .and_then(|r| r.sensitivity_step)
        .unwrap_or(1e-3)
}

/// The names of the constants the model can modulate.
pub fn modulatable() -> Vec<&'static str> {
    MODULATABLE
        .iter()
        .filter_map(|vr| VARIABLES.iter().find(|v| v.value_reference == *vr).map(|v| v.name))
        .collect()
}

/// The hat functions of piecewise-linear interpolation over increasing `knots`, flat
/// beyond the ends, at `s`: at most two are nonzero and they sum to one.
pub fn hats(knots: &[f64], s: f64, out: &mut [f64]) {
    out.iter_mut().for_each(|v| *v = 0.0);
    let last = knots.len() - 1;
    if s <= knots[0] {
        out[0] = 1.0;
        return;
    }
    if s >= knots[last] {
        out[last] = 1.0;
        return;
    }
    let j = knots.partition_point(|&x| x <= s).clamp(1, last);
    let share = (s - knots[j - 1]) / (knots[j] - knots[j - 1]);
    out[j - 1] = 1.0 - share;
    out[j] = share;
}

/// Whether a candidate is a modulation (it fills a modulation slot).
pub fn is_modulation(c: &Candidate) -> bool {
    c.origin() == crate::vocabulary::Origin::Modulation
}

/// Whether a modulation's knot values are one change of the constant (all within a tenth of
/// the largest of one another): then it is no modulation.
pub fn is_flat(values: &[f64]) -> bool {
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let (low, high) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    largest > 0.0 && high - low <= 0.1 * largest
}

/// The FMU parameter of slot `slot`'s field `field` (`"y_3"`, `"parameter"`...).
pub fn slot_parameter(slot: usize, field: &str) -> &'static str {
    interned(format!("modulation_{slot}_{field}"))
}

/// The modulation slots that `params` leaves off (a periodic modulation takes two).
pub fn free_slots(params: &Parameters) -> Vec<usize> {
    (1..=2)
        .filter(|&k| parameter_value(params, slot_parameter(k, "parameter")) == 0.0)
        .collect()
}

pub(crate) fn value_reference(name: &str) -> f64 {
    VARIABLES
        .iter()
        .find(|v| v.name == name)
        .map_or(0.0, |v| f64::from(v.value_reference))
}

/// One sentence in physical words for a set of parameters that fills modulation slots, or
/// `None` when it fills none: what varies, with what, by how much and where.
pub fn reading(set: &[(&'static str, f64)], before: &Parameters) -> Option<String> {
    let value = |name: &str| set.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
    let mut sentences = vec![];
    let mut periodic: Option<(String, f64, f64, f64, &'static str)> = None;
    for slot in 1..=2 {
        let Some(vr) = value(slot_parameter(slot, "parameter")) else {
            continue;
        };
        let Some(constant) = VARIABLES.iter().find(|v| f64::from(v.value_reference) == vr) else {
            continue;
        };
        let signal = ModulationSignal::from_code(value(slot_parameter(slot, "signal"))?)?;
        let knots = value(slot_parameter(slot, "knots")).unwrap_or(0.0) as usize;
        let xs: Vec<f64> = (1..=knots)
            .filter_map(|j| value(slot_parameter(slot, &format!("x_{j}"))))
            .collect();
        let ys: Vec<f64> = (1..=knots)
            .filter_map(|j| value(slot_parameter(slot, &format!("y_{j}"))))
            .collect();
        if xs.len() != knots || ys.len() != knots || knots == 0 {
            continue;
        }
        let nominal = parameter_value(before, constant.name);
        let unit = constant.unit.unwrap_or("");
        if matches!(signal, ModulationSignal::Sine | ModulationSignal::Cosine) {
            let hz = value(slot_parameter(slot, "frequency")).unwrap_or(0.0);
            let amplitude = 0.5 * (ys[knots - 1] - ys[0]);
            let entry = periodic.get_or_insert((constant.name.to_string(), hz, 0.0, 0.0, unit));
            if signal == ModulationSignal::Sine {
                entry.2 = amplitude;
            } else {
                entry.3 = amplitude;
            }
            continue;
        }
        let largest = ys
            .iter()
            .copied()
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(0.0);
        // Where it is near its largest: the knots within a fifth of it.
        let near: Vec<f64> = xs
            .iter()
            .zip(&ys)
            .filter(|(_, y)| (**y - largest).abs() <= 0.2 * largest.abs())
            .map(|(x, _)| *x)
            .collect();
        let (from, to) = (near[0], near[near.len() - 1]);
        let at = if from == to {
            format!("at {} of {}", shown(from, signal.unit()), signal.name())
        } else {
            format!(
                "between {} and {} of {}",
                shown(from, signal.unit()),
                shown(to, signal.unit()),
                signal.name()
            )
        };
        let relative = if nominal != 0.0 {
            format!(" ({:+.1} % of its {})", 100.0 * largest / nominal, shown(nominal, unit))
        } else {
            String::new()
        };
        let points: Vec<String> = xs
            .iter()
            .zip(&ys)
            .map(|(x, y)| format!("{} at {}", shown_signed(*y, unit), shown(*x, signal.unit())))
            .collect();
        let rising = ys.windows(2).all(|w| w[1] >= w[0]);
        let falling = ys.windows(2).all(|w| w[1] <= w[0]);
        let headline = if knots >= 2 && (rising || falling) {
            // A monotone change reads from end to end (a constant that follows a position
            // linearly is −5 % at one end and +5 % at the other, not "−5 % at" one end).
            format!(
                "{} {} from {} at {} to {} at {} of {}",
                constant.name,
                if rising { "rises" } else { "falls" },
                shown_signed(ys[0], unit),
                shown(xs[0], signal.unit()),
                shown_signed(ys[knots - 1], unit),
                shown(xs[knots - 1], signal.unit()),
                signal.name()
            )
        } else {
            format!(
                "{} changes by {}{relative} {at}",
                constant.name,
                shown_signed(largest, unit)
            )
        };
        sentences.push(format!(
            "{headline}; piecewise linear in {} through {}, constant beyond",
            signal.name(),
            points.join(", ")
        ));
    }
    if let Some((name, hz, sine, cosine, unit)) = periodic {
        sentences.push(format!(
            "{name} oscillates by {} at {hz:.3} Hz (phase {:.0}°)",
            shown(sine.hypot(cosine), unit),
            cosine.atan2(sine).to_degrees()
        ));
    }
    (!sentences.is_empty()).then(|| sentences.join("; "))
}

/// A value in a unit a person reads: millimetres, kilopascals, millimetres per second, else
/// the SI unit with four significant digits.
fn shown(value: f64, unit: &str) -> String {
    match unit {
        "m" => format!("{:.2} mm", value * 1e3),
        "Pa" => format!("{:.2} kPa", value * 1e-3),
        "m/s" => format!("{:.2} mm/s", value * 1e3),
        "s" => format!("{value:.2} s"),
        "1" | "" => format!("{value:.4}"),
        _ if value != 0.0 && (value.abs() >= 1e4 || value.abs() < 1e-2) => format!("{value:.3e} {unit}"),
        _ => format!("{value:.4} {unit}"),
    }
}

fn shown_signed(value: f64, unit: &str) -> String {
    let text = shown(value, unit);
    if value >= 0.0 {
        format!("+{text}")
    } else {
        text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hat_functions_interpolate_linearly_between_knots_and_stay_flat_beyond_them() {
        let knots = [0.0, 1.0, 3.0];
        let mut phi = [0.0; 3];
        hats(&knots, 2.0, &mut phi);
        assert_eq!(phi, [0.0, 0.5, 0.5]);
        hats(&knots, -4.0, &mut phi);
        assert_eq!(phi, [1.0, 0.0, 0.0]);
        hats(&knots, 9.0, &mut phi);
        assert_eq!(phi, [0.0, 0.0, 1.0]);
        hats(&knots, 1.0, &mut phi);
        assert!((phi[1] - 1.0).abs() < 1e-15 && phi.iter().sum::<f64>() == 1.0);
    }

    #[test]
    fn a_constant_that_follows_a_signal_linearly_reads_from_end_to_end_in_units_a_person_reads() {
        let set = [
            (
                "modulation_1_parameter",
                f64::from(jetpipe_model::variables::vr::F_JP_SAT),
            ),
            (
                "modulation_1_signal",
                f64::from(ModulationSignal::StopperPosition.code()),
            ),
            ("modulation_1_frequency", 0.0),
            ("modulation_1_knots", 2.0),
            ("modulation_1_x_1", 0.044),
            ("modulation_1_x_2", 0.087),
            ("modulation_1_y_1", -0.0235),
            ("modulation_1_y_2", 0.0233),
        ];
        let text = reading(&set, &Parameters::default()).unwrap();
        assert!(
            text.starts_with("F_jp_sat rises from -0.0235 N at 44.00 mm to +0.0233 N at 87.00 mm of x_s"),
            "{text}"
        );
        // A band reads where it is largest.
        let band = [
            (
                "modulation_1_parameter",
                f64::from(jetpipe_model::variables::vr::FRICTION_COULOMB),
            ),
            (
                "modulation_1_signal",
                f64::from(ModulationSignal::StopperPosition.code()),
            ),
            ("modulation_1_frequency", 0.0),
            ("modulation_1_knots", 4.0),
            ("modulation_1_x_1", 0.058),
            ("modulation_1_x_2", 0.060),
            ("modulation_1_x_3", 0.066),
            ("modulation_1_x_4", 0.068),
            ("modulation_1_y_1", 0.0),
            ("modulation_1_y_2", 2.5),
            ("modulation_1_y_3", 2.4),
            ("modulation_1_y_4", 0.0),
        ];
        let text = reading(&band, &Parameters::default()).unwrap();
        assert!(
            text.starts_with("friction_coulomb changes by +2.5000 N between 60.00 mm and 66.00 mm of x_s"),
            "{text}"
        );
    }
}

#[cfg(test)]
mod family_tests {
    use super::*;

    #[test]
    fn a_modulations_family_comes_from_the_signal_then_the_constants_kind_then_its_place() {
        let family = |constant: &'static str, follows| family_of(constant, place_of(constant), follows);
        let signal = Follows::Signal;
        assert_eq!(family("L_sup", signal(ModulationSignal::Force)), Family::Compliance);
        assert_eq!(
            family("L_sup", signal(ModulationSignal::PressureDifference)),
            Family::Compliance
        );
        // Not under the load: the place's kind (L_sup sits with the chambers' volumes).
        assert_eq!(
            family("L_sup", signal(ModulationSignal::JetPosition)),
            Family::ExtraFlow
        );
        assert_eq!(family("L_sup", signal(ModulationSignal::Time)), Family::Drift);
        assert_eq!(
            family("return_area_scale_2", signal(ModulationSignal::P2)),
            Family::Asymmetry
        );
        assert_eq!(family("C_d", signal(ModulationSignal::P2)), Family::Nonlinearity);
        assert_eq!(
            family("friction_coulomb", signal(ModulationSignal::StopperPosition)),
            Family::ExtraForce
        );
        assert_eq!(
            family("dead_volume_1", signal(ModulationSignal::Force)),
            Family::ExtraFlow
        );
        assert_eq!(family("P_s", Follows::Periodic(3.0)), Family::Periodic);
    }
}

#[cfg(test)]
mod place_tests {
    use super::*;
    use jetpipe_model::physics::flexible::FLEXIBLE_TARGETS;

    #[test]
    fn every_written_candidate_on_a_constant_the_slots_may_vary_sits_at_that_constants_place_in_the_variable_table() {
        let base = Parameters::default();
        let knots = crate::candidates::curves::CurveKnots::default();
        let mut checked = 0;
        for has_pressures in [true, false] {
            for periodic_hz in [None, Some(3.0)] {
                let catalogue = crate::candidates::catalogue::catalogue(&base, has_pressures, periodic_hz, &knots);
                for vr in FLEXIBLE_TARGETS.iter() {
                    let name = VARIABLES.iter().find(|v| v.value_reference == *vr).unwrap().name;
                    assert_ne!(
                        place_of(name),
                        Place::Unknown,
                        "{name} has no place in the variable table"
                    );
                    for c in catalogue
                        .iter()
                        .filter(|c| c.terms.iter().any(|t| t.mechanism == Mechanism::Parameter(name)))
                    {
                        assert_eq!(c.location, place_of(name), "{name} in {}", c.label);
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 20, "{checked}");
    }
}
