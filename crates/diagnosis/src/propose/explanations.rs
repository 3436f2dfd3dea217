//! The rival explanations of a recording, read from its report.
//!
//! The report's own model is one: its FMU start values, standing for the places of its
//! additions. The others are the first round's candidates (the report's `candidates`, each
//! fitted on the model before any addition, with its `settings` and `parameters`), the best at
//! each other place: first the places the report ties with an addition or with the
//! remainder, then the next places of the ranking. Each is set on the report's model with the
//! report's additions taken out (their parameters back at the table's start), where that
//! candidate was fitted. A candidate that is one of the report's own additions is the
//! report's model already and is left out.

use jetpipe_model::physics::parameters::{table_start, Parameters};
use jetpipe_model::variables::{Causality, VARIABLES};
use serde_json::{Map, Value};

/// The FMU parameters that set the start state rather than the model's constants: a
/// proposal starts every explanation at the equilibrium of its first inputs.
const START_STATE: [&str; 3] = ["start_at_equilibrium", "P1_start", "P2_start"];

/// One explanation of the recording: a model the report's numbers support.
#[derive(Clone, Debug)]
pub struct Explanation {
    /// What it is, in the report's words ("the report's model: …", or a candidate's label).
    pub label: String,
    /// The places of the chain it puts the departure at.
    pub places: Vec<String>,
    pub parameters: Parameters,
}

/// The explanations to separate and the report's noise floors, in the channels' order
/// (force in N, then each pressure in Pa where the recording had them).
#[derive(Clone, Debug)]
pub struct Rivals {
    pub explanations: Vec<Explanation>,
    pub noise: Vec<f64>,
    /// The places the report ties (with an addition or with the remainder).
    pub tied: Vec<String>,
    /// Whether the report explains the recording within its noise.
    pub explained: bool,
}

fn object<'a>(value: &'a Value, key: &str) -> Result<&'a Map<String, Value>, String> {
    value
        .get(key)
        .and_then(Value::as_object)
        .ok_or_else(|| format!("the report has no '{key}' object: is it a `jetpipe diagnose` report?"))
}

fn strings(value: Option<&Value>) -> Vec<String> {
    value
        .and_then(Value::as_array)
        .map(|a| a.iter().filter_map(|s| s.as_str().map(str::to_string)).collect())
        .unwrap_or_default()
}

/// `values` (FMU parameter name → number or boolean) set on the thesis's parameters.
pub fn parameters_from(values: &Map<String, Value>) -> Result<Parameters, String> {
    let mut p = Parameters::default();
    for (name, v) in values {
        if START_STATE.contains(&name.as_str()) {
            continue;
        }
        let variable = VARIABLES
            .iter()
            .find(|var| var.name == name && var.causality == Causality::Parameter)
            .ok_or_else(|| format!("'{name}' is not a parameter of the model"))?;
        let x = v
            .as_f64()
            .or_else(|| v.as_bool().map(f64::from))
            .ok_or_else(|| format!("'{name}' must be a number, got {v}"))?;
        p.set(variable.value_reference, x)?;
    }
    p.validate()?;
    Ok(p)
}

fn value_reference(name: &str) -> Option<u32> {
    VARIABLES
        .iter()
        .find(|v| v.name == name && v.causality == Causality::Parameter)
        .map(|v| v.value_reference)
}

/// The rivals of `report`, at most `most` of them.
pub fn rivals(report: &Value, most: usize) -> Result<Rivals, String> {
    let start = object(report, "fmu_start_values")?;
    let force_noise = report
        .get("noise_floor_N")
        .and_then(Value::as_f64)
        .filter(|n| n.is_finite() && *n > 0.0)
        .ok_or("the report has no positive 'noise_floor_N'")?;
    let mut noise = vec![force_noise];
    if let Some(p) = report.get("noise_floor_Pa") {
        for channel in ["p1", "p2"] {
            let floor = p
                .get(channel)
                .and_then(Value::as_f64)
                .filter(|n| n.is_finite() && *n > 0.0)
                .ok_or_else(|| format!("the report's noise_floor_Pa has no positive '{channel}'"))?;
            noise.push(floor);
        }
    }
    let additions: Vec<&Value> = ["effects", "discovered"]
        .iter()
        .flat_map(|key| report.get(*key).and_then(Value::as_array).into_iter().flatten())
        .collect();
    let mut added_labels = vec![];
    let mut added_places = vec![];
    let mut base_values = start.clone();
    let mut tied = vec![];
    for a in &additions {
        let label = a
            .get("name")
            .or_else(|| a.get("candidate"))
            .and_then(Value::as_str)
            .unwrap_or("?");
        added_labels.push(label.to_string());
        if let Some(place) = a.get("location").and_then(Value::as_str) {
            added_places.push(place.to_string());
        }
        for name in a
            .get("parameters")
            .and_then(Value::as_object)
            .into_iter()
            .flat_map(|p| p.keys())
        {
            match value_reference(name) {
                Some(vr) => {
                    base_values.insert(name.clone(), Value::from(table_start(vr)));
                }
                None => {
                    return Err(format!(
                        "an addition's parameter '{name}' is not a parameter of the model"
                    ))
                }
            }
        }
        tied.extend(strings(a.get("tied_locations")));
    }
    let unexplained = report.get("unexplained").filter(|u| !u.is_null());
    if let Some(u) = unexplained {
        tied.extend(strings(u.get("tied_locations")));
        tied.extend(strings(u.get("alternatives")));
    }
    let mut seen = vec![];
    tied.retain(|p| {
        !p.is_empty() && p != "unknown" && !seen.contains(p) && {
            seen.push(p.clone());
            true
        }
    });
    let model = parameters_from(start).map_err(|e| format!("the report's fmu_start_values: {e}"))?;
    let mut explanations = vec![Explanation {
        label: match added_labels.is_empty() {
            true => "the report's model (nothing added)".to_string(),
            false => format!("the report's model ({})", added_labels.join(", ")),
        },
        places: added_places.clone(),
        parameters: model,
    }];
    // The best first-round candidate at each place, in the ranking's order.
    let mut best: Vec<(String, &Value)> = vec![];
    let mut ranked: Vec<&Value> = report
        .get("candidates")
        .and_then(Value::as_array)
        .map(|a| a.iter().collect())
        .unwrap_or_default();
    let share = |c: &Value| {
        c.get("explained_share_heldout")
            .and_then(Value::as_f64)
            .unwrap_or(f64::NEG_INFINITY)
    };
    ranked.sort_by(|a, b| share(b).total_cmp(&share(a)));
    for c in ranked {
        let label = c.get("candidate").and_then(Value::as_str).unwrap_or("");
        let named = c.get("named_effect").and_then(Value::as_str).unwrap_or("");
        let place = c.get("location").and_then(Value::as_str).unwrap_or("").to_string();
        // The report's model stands for the places of its additions.
        let added = added_labels
            .iter()
            .any(|a| a == label || (!named.is_empty() && a == named));
        if place.is_empty() || added || added_places.contains(&place) {
            continue;
        }
        if !best.iter().any(|(p, _)| *p == place) {
            best.push((place, c));
        }
    }
    // Tied places first, then the ranking.
    best.sort_by_key(|(place, _)| !tied.contains(place));
    for (place, c) in best {
        if explanations.len() >= most {
            break;
        }
        // Its settings (a slot's constant, signal and knots; a ripple's frequency), then its
        // fitted amounts.
        let mut values = base_values.clone();
        for key in ["settings", "parameters"] {
            for (name, v) in c.get(key).and_then(Value::as_object).into_iter().flatten() {
                values.insert(name.clone(), v.clone());
            }
        }
        // A candidate the model refuses on this base (a slot it shares with another term) is
        // no explanation it can simulate.
        if let Ok(parameters) = parameters_from(&values) {
            explanations.push(Explanation {
                label: c.get("candidate").and_then(Value::as_str).unwrap_or("?").to_string(),
                places: vec![place],
                parameters,
            });
        }
    }
    if explanations.len() < 2 {
        return Err("the report holds one explanation only (no first-round candidate at another place): there is nothing to separate".into());
    }
    let explained = report.get("verdict").and_then(Value::as_str) == Some("explained");
    Ok(Rivals {
        explanations,
        noise,
        tied,
        explained,
    })
}
