//! What the three small FMUs of the antagonistic joint (`Tendon`, `FingerJoint`,
//! `JointController`) share on top of jetpipe's generic FMI layer: a value store driven by the
//! variable table (range checks with messages that name the variable), the versioned byte
//! format of their FMU states, a monotone scalar solver for their implicit integrators, and
//! the interface page of their archives. No FFI types here.

pub mod solve;
pub mod state_bytes;
pub mod units;
pub mod values;

pub use values::Values;

use jetpipe::fmi2::model::{Causality, ModelInfo, VarType};

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `documentation/index.html` of an FMU: `notes` (already HTML) and the interface table.
pub fn documentation_html(info: &ModelInfo, notes: &str) -> String {
    let mut rows = String::new();
    for v in info.variables {
        let causality = match v.causality {
            Causality::Parameter => "parameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
        };
        let start = match (v.causality, v.var_type) {
            (Causality::Output, _) => String::new(),
            (_, VarType::Boolean) => (v.start != 0.0).to_string(),
            _ => format!("{}", v.start),
        };
        let range = match (v.min, v.max) {
            (None, None) => String::new(),
            (lo, hi) => format!(
                "[{}, {}]",
                lo.map_or("-inf".to_string(), |x| x.to_string()),
                hi.map_or("inf".to_string(), |x| x.to_string())
            ),
        };
        rows.push_str(&format!(
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>\n",
            escape(v.name),
            causality,
            escape(v.unit.unwrap_or("")),
            start,
            range,
            escape(v.description)
        ));
    }
    format!(
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{name}</title></head><body>\n\
<h1>{name}</h1>\n<p>{description}</p>\n<p>FMI 2.0 Co-Simulation, version {version}.</p>\n{notes}\n\
<table border=\"1\" cellpadding=\"3\"><tr><th>name</th><th>causality</th><th>unit</th><th>start</th>\
<th>valid range</th><th>description</th></tr>\n{rows}</table>\n</body></html>\n",
        name = info.model_identifier,
        description = escape(info.description),
        version = info.version,
    )
}

/// The six log categories every model of this workspace declares (the layer's own).
pub const LOG_CATEGORIES: &[(&str, &str)] = &[
    ("logEvents", "initialisation, resets and state restores"),
    ("logStatusWarning", "messages with status fmi2Warning"),
    ("logStatusDiscard", "messages with status fmi2Discard"),
    ("logStatusError", "messages with status fmi2Error"),
    ("logStatusFatal", "messages with status fmi2Fatal"),
    ("logAll", "every message"),
];
