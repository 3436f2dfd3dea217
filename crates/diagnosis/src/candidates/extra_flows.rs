//! An extra mass flow into one chamber alone as a generated class: each signal of the model's
//! extra flow slots (`jetpipe_model::physics::extra_flow`, `extra_flow_k_*`) into each chamber
//! is a candidate at (chambers, extra_flow), its coefficient (kg/s per bar of the signal) a
//! model parameter in a free slot, fitted through the model as the laminar leaks are.
//!
//! The signals are the constant 1, P1 − P2 and the signed roots of P1 − P2, P_s − P_i and
//! P_i − P_r (over 1 bar). Left out, because the library has them exactly: c (P_s − P_i) into
//! chamber i is `chamber_laminar_supply_leak_i` and c (P_i − P_r) out of it is
//! `chamber_laminar_vent_i`. Ten candidates: five signals into each of two chambers.

use crate::candidates::{interned, parameter_value, Candidate, Mechanism, Term};
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::extra_flow::{FlowSignal, FLOW_SLOTS};
use jetpipe_model::physics::parameters::Parameters;

/// The name of an extra flow slot's variable (`slot` 1-based; `field` one of chamber, signal,
/// coefficient).
pub fn slot_parameter(slot: usize, field: &str) -> &'static str {
    const NAMES: [[&str; 3]; FLOW_SLOTS] = [
        [
            "extra_flow_1_chamber",
            "extra_flow_1_signal",
            "extra_flow_1_coefficient",
        ],
        [
            "extra_flow_2_chamber",
            "extra_flow_2_signal",
            "extra_flow_2_coefficient",
        ],
        [
            "extra_flow_3_chamber",
            "extra_flow_3_signal",
            "extra_flow_3_coefficient",
        ],
    ];
    let j = ["chamber", "signal", "coefficient"]
        .iter()
        .position(|f| *f == field)
        .unwrap_or_else(|| panic!("{field} is not a field of an extra flow slot"));
    NAMES[slot - 1][j]
}

/// The extra flow slots that `params` leaves off (1-based).
pub fn free_slots(params: &Parameters) -> Vec<usize> {
    (1..=FLOW_SLOTS)
        .filter(|&k| parameter_value(params, slot_parameter(k, "coefficient")) == 0.0)
        .collect()
}

/// The generated (signal, chamber) pairs: every signal into each chamber but those the
/// library has (see the module's comment).
pub fn members() -> Vec<(FlowSignal, usize)> {
    FlowSignal::ALL
        .iter()
        .filter(|s| !matches!(s, FlowSignal::FromSupply | FlowSignal::ToReturn))
        .flat_map(|&s| [(s, 1), (s, 2)])
        .collect()
}

/// The label of a member: "extra flow into chamber 2 ∝ (P1 − P2)".
fn label(signal: FlowSignal, chamber: usize) -> &'static str {
    interned(match signal {
        FlowSignal::One => format!("constant extra flow into chamber {chamber}"),
        s => format!("extra flow into chamber {chamber} ∝ {}", s.name(chamber)),
    })
}

/// The generated candidates in the first extra flow slot `params` leaves off; none when every
/// slot is on.
pub fn candidates(params: &Parameters) -> Vec<Candidate> {
    let Some(&slot) = free_slots(params).first() else {
        return vec![];
    };
    let coefficient = slot_parameter(slot, "coefficient");
    members()
        .into_iter()
        .map(|(signal, chamber)| Candidate {
            label: label(signal, chamber),
            location: Place::Chambers,
            family: Family::ExtraFlow,
            named: None,
            terms: vec![Term {
                name: coefficient,
                unit: "kg/s",
                mechanism: Mechanism::Parameter(coefficient),
                neutral: 0.0,
                // 1e-6 kg/s per bar: the laminar leaks' step of 1e-11 kg/(s·Pa).
                step: 1e-6,
                lower: -1e-2,
                upper: 1e-2,
            }],
            settings: vec![
                (slot_parameter(slot, "chamber"), chamber as f64),
                (slot_parameter(slot, "signal"), f64::from(signal.code())),
            ],
        })
        .collect()
}

/// A slot's setting in `set`, else in `before`.
fn slot_value(set: &[(&'static str, f64)], before: &Parameters, slot: usize, field: &str) -> f64 {
    let name = slot_parameter(slot, field);
    set.iter()
        .rev()
        .find(|(n, _)| *n == name)
        .map_or_else(|| parameter_value(before, name), |(_, v)| *v)
}

/// The words of a signal for chamber `chamber` in a reading.
fn words(signal: FlowSignal, chamber: usize) -> String {
    let own = format!("P{chamber}");
    match signal {
        FlowSignal::One => "a constant".to_string(),
        FlowSignal::Difference => "bar of P1 − P2".to_string(),
        FlowSignal::FromSupply => format!("bar of P_s − {own}"),
        FlowSignal::ToReturn => format!("bar of {own} − P_r"),
        FlowSignal::SqrtDifference => "sqrt(|P1 − P2| / 1 bar)·sign(P1 − P2)".to_string(),
        FlowSignal::SqrtFromSupply => format!("sqrt(|P_s − {own}| / 1 bar)·sign(P_s − {own})"),
        FlowSignal::SqrtToReturn => format!("sqrt(|{own} − P_r| / 1 bar)·sign({own} − P_r)"),
    }
}

/// The extra flows that `set` adds to the model `before`, in physical words: "A flow into
/// chamber 2 alone of 3.1000e-6 kg/s per bar of P1 − P2 (…)".
pub fn reading(set: &[(&'static str, f64)], before: &Parameters) -> Option<String> {
    let sentences: Vec<String> = (1..=FLOW_SLOTS)
        .filter(|&k| set.iter().any(|(n, _)| *n == slot_parameter(k, "coefficient")))
        .filter_map(|k| {
            let added =
                slot_value(set, before, k, "coefficient") - parameter_value(before, slot_parameter(k, "coefficient"));
            let chamber = slot_value(set, before, k, "chamber");
            let chamber = if chamber == 2.0 { 2 } else { 1 };
            let signal = FlowSignal::from_code(slot_value(set, before, k, "signal"))?;
            (added != 0.0).then(|| {
                let per = match signal {
                    FlowSignal::One => "constant".to_string(),
                    FlowSignal::SqrtDifference | FlowSignal::SqrtFromSupply | FlowSignal::SqrtToReturn => {
                        format!("times {}", words(signal, chamber))
                    }
                    s => format!("per {}", words(s, chamber)),
                };
                let direction = if added > 0.0 { "into" } else { "out of" };
                let size = match signal {
                    FlowSignal::One => format!("{:.3} mg/s {direction} the chamber", added.abs() * 1e6),
                    _ => format!(
                        "mass {direction} the chamber where the signal is positive, {:.3} mg/s at 1 bar",
                        added.abs() * 1e6
                    ),
                };
                format!(
                    "A flow into chamber {chamber} alone of {added:.4e} kg/s {per} ({size}; no other place loses or gains it)."
                )
            })
        })
        .collect();
    (!sentences.is_empty()).then(|| sentences.join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_members_are_five_signals_into_each_chamber_without_the_librarys_laminar_leaks() {
        let members = members();
        assert_eq!(members.len(), 10, "{members:?}");
        for chamber in [1, 2] {
            assert!(!members.contains(&(FlowSignal::FromSupply, chamber)));
            assert!(!members.contains(&(FlowSignal::ToReturn, chamber)));
            assert!(members.contains(&(FlowSignal::SqrtToReturn, chamber)));
        }
        let list = candidates(&Parameters::default());
        let labels: Vec<&str> = list.iter().map(|c| c.label).collect();
        assert!(labels.contains(&"extra flow into chamber 2 ∝ (P1 − P2)"), "{labels:?}");
        assert!(list
            .iter()
            .all(|c| c.location == Place::Chambers && c.family == Family::ExtraFlow && c.terms.len() == 1));
    }

    #[test]
    fn the_candidates_take_the_first_free_slot_and_none_when_every_slot_is_on() {
        let mut params = Parameters::default();
        params.extra_flows[0].coefficient = 1e-6;
        let list = candidates(&params);
        assert!(list.iter().all(|c| c.terms[0].name == "extra_flow_2_coefficient"));
        assert!(list.iter().all(|c| c.settings[0].0 == "extra_flow_2_chamber"));
        params.extra_flows[1].coefficient = 1e-6;
        params.extra_flows[2].coefficient = -1e-6;
        assert!(candidates(&params).is_empty());
    }

    #[test]
    fn a_flow_into_chamber_2_is_read_per_bar_of_its_signal() {
        let set = [
            ("extra_flow_1_chamber", 2.0),
            ("extra_flow_1_signal", 1.0),
            ("extra_flow_1_coefficient", 3.1e-6),
        ];
        let text = reading(&set, &Parameters::default()).unwrap();
        assert!(
            text.contains("A flow into chamber 2 alone of 3.1000e-6 kg/s per bar of P1 − P2"),
            "{text}"
        );
        assert!(text.contains("3.100 mg/s at 1 bar"), "{text}");
    }
}
