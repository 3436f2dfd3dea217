//! The interface table of docs/model.md, from the variable table.

use super::{number, vr, Causality, VarType, TABLE, V_DA_RANGE};

/// The interface table of docs/model.md, in Markdown (`jetpipe parameters` prints it; a test
/// checks that the docs carry it unchanged): every variable with its causality, unit, start
/// value, limits, thesis reference, meaning and the reason for its limits.
pub fn interface_table() -> String {
    let mut out = String::from(
        "| name | causality | unit | start | limits | thesis | meaning | why the limits |\n|---|---|---|---|---|---|---|---|\n",
    );
    for row in TABLE {
        let v = &row.variable;
        let causality = match v.causality {
            Causality::Parameter => "parameter",
            Causality::Input => "input",
            Causality::Output => "output",
            Causality::Local => "local",
        };
        let start = match (v.causality, v.var_type) {
            (Causality::Output, _) => String::new(),
            (_, VarType::Boolean) => (if v.start != 0.0 { "true" } else { "false" }).to_string(),
            _ => number(v.start),
        };
        let limits = match v.value_reference {
            vr::X_S => {
                let (lo, hi) = crate::physics::parameters::Parameters::default()
                    .cylinder()
                    .stopper_range();
                format!("in ({}, {}) m with the default geometry", number(lo), number(hi))
            }
            vr::V_DA => {
                let (lo, hi) = V_DA_RANGE;
                format!("in [{}, {}] V", number(lo), number(hi))
            }
            _ => row.limits_text(),
        };
        let why = match v.value_reference {
            vr::X_S => "both chamber volumes positive, (2.30)-(2.31)",
            vr::V_DA => "the D/A converter's range",
            _ => row.reason,
        };
        out.push_str(&format!(
            "| `{}` | {causality} | {} | {start} | {limits} | {} | {} | {why} |\n",
            v.name,
            v.unit.unwrap_or(""),
            row.reference,
            v.description
        ));
    }
    out
}
