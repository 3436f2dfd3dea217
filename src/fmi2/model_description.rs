//! `modelDescription.xml` (FMI 2.0 Co-Simulation) generated from a [`ModelInfo`].

use std::collections::HashSet;
use std::fmt::Write;

use super::model::{Causality, ModelInfo, VarType, Variability, Variable};

/// Check the model info for what the XML (and the layer) rely on: unique, non-empty
/// variable names; unique value references; declared units; legal
/// causality/variability combinations; start values within min/max; unique log
/// categories. Returns every problem found.
pub fn validate_model_info(info: &ModelInfo) -> Result<(), Vec<String>> {
    let mut problems = Vec::new();
    let mut names = HashSet::new();
    let mut vrs = HashSet::new();
    for v in info.variables {
        if v.name.is_empty() {
            problems.push(format!(
                "variable with value reference {} has an empty name",
                v.value_reference
            ));
        }
        if !names.insert(v.name) {
            problems.push(format!("duplicate variable name {:?}", v.name));
        }
        if !vrs.insert(v.value_reference) {
            problems.push(format!(
                "duplicate value reference {} (variable {:?})",
                v.value_reference, v.name
            ));
        }
        if let Some(unit) = v.unit {
            if v.var_type == VarType::Real && !info.units.iter().any(|u| u.name == unit) {
                problems.push(format!(
                    "variable {:?}: unit {unit:?} is not in the unit definitions",
                    v.name
                ));
            }
        }
        match (v.causality, v.variability) {
            (Causality::Parameter, Variability::Fixed | Variability::Tunable) => {}
            (Causality::Parameter, _) => problems.push(format!("parameter {:?} must be fixed or tunable", v.name)),
            (Causality::Input | Causality::Output, Variability::Fixed | Variability::Tunable) => problems.push(
                format!("{:?}: inputs and outputs must be discrete or continuous", v.name),
            ),
            (_, Variability::Continuous) if v.var_type != VarType::Real => {
                problems.push(format!("{:?}: only Real variables can be continuous", v.name))
            }
            _ => {}
        }
        if has_start(v) {
            if !v.start.is_finite() {
                problems.push(format!("variable {:?}: start {} is not finite", v.name, v.start));
            }
            if v.min.is_some_and(|m| v.start < m) || v.max.is_some_and(|m| v.start > m) {
                problems.push(format!("variable {:?}: start {} outside [min, max]", v.name, v.start));
            }
            if v.var_type != VarType::Real && v.start.fract() != 0.0 {
                problems.push(format!("variable {:?}: start {} is not an integer", v.name, v.start));
            }
        }
    }
    let mut cats = HashSet::new();
    for (name, _) in info.log_categories {
        if !cats.insert(*name) {
            problems.push(format!("duplicate log category {name:?}"));
        }
    }
    let mut units = HashSet::new();
    for u in info.units {
        if !units.insert(u.name) {
            problems.push(format!("duplicate unit {:?}", u.name));
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems)
    }
}

/// Parameters and inputs carry a start value; outputs and locals are calculated.
fn has_start(v: &Variable) -> bool {
    matches!(v.causality, Causality::Parameter | Causality::Input)
}

/// Escape text for an XML attribute value.
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for ch in s.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\n' => out.push_str("&#10;"),
            '\r' => out.push_str("&#13;"),
            '\t' => out.push_str("&#9;"),
            c if (c as u32) < 0x20 => {} // not allowed in XML 1.0
            c => out.push(c),
        }
    }
    out
}

/// A valid `xs:double` that parses back to exactly `x` (shortest round-trip digits).
pub fn format_double(x: f64) -> String {
    if x.is_nan() {
        "NaN".to_owned()
    } else if x.is_infinite() {
        if x > 0.0 { "INF" } else { "-INF" }.to_owned()
    } else {
        // Rust's Debug gives the shortest round-trip form: "652925.0", "1e-7", "-4.75e-8"
        format!("{x:?}")
    }
}

fn causality_attr(c: Causality) -> &'static str {
    match c {
        Causality::Parameter => "parameter",
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Local => "local",
    }
}

fn variability_attr(v: Variability) -> &'static str {
    match v {
        Variability::Fixed => "fixed",
        Variability::Tunable => "tunable",
        Variability::Discrete => "discrete",
        Variability::Continuous => "continuous",
    }
}

/// The complete `modelDescription.xml`, or the problems found by [`validate_model_info`].
pub fn try_model_description_xml(info: &ModelInfo) -> Result<String, Vec<String>> {
    validate_model_info(info)?;
    let e = xml_escape;
    let mut x = String::new();
    let w = &mut x;
    // writing to a String cannot fail
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        w,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{}" guid="{}" description="{}" author="{}" version="{}" generationTool="{}" variableNamingConvention="flat" numberOfEventIndicators="0">"#,
        e(info.model_name),
        e(info.guid),
        e(info.description),
        e(info.author),
        e(info.version),
        e(info.generation_tool)
    );
    let _ = writeln!(
        w,
        r#"  <CoSimulation modelIdentifier="{}" canHandleVariableCommunicationStepSize="true" canInterpolateInputs="{}" maxOutputDerivativeOrder="0" canGetAndSetFMUstate="true" canSerializeFMUstate="true" canNotUseMemoryManagementFunctions="true" providesDirectionalDerivative="false"/>"#,
        e(info.model_identifier),
        info.can_interpolate_inputs
    );
    if !info.units.is_empty() {
        let _ = writeln!(w, "  <UnitDefinitions>");
        for u in info.units {
            let mut base = String::new();
            for (attr, exp) in [("kg", u.kg), ("m", u.m), ("s", u.s), ("A", u.a), ("K", u.k)] {
                if exp != 0 {
                    let _ = write!(base, r#" {attr}="{exp}""#);
                }
            }
            let _ = writeln!(w, r#"    <Unit name="{}">"#, e(u.name));
            let _ = writeln!(w, r#"      <BaseUnit{base}/>"#);
            let _ = writeln!(w, "    </Unit>");
        }
        let _ = writeln!(w, "  </UnitDefinitions>");
    }
    if !info.log_categories.is_empty() {
        let _ = writeln!(w, "  <LogCategories>");
        for (name, description) in info.log_categories {
            let _ = writeln!(
                w,
                r#"    <Category name="{}" description="{}"/>"#,
                e(name),
                e(description)
            );
        }
        let _ = writeln!(w, "  </LogCategories>");
    }
    let _ = writeln!(
        w,
        r#"  <DefaultExperiment startTime="{}" stopTime="{}" tolerance="{}" stepSize="{}"/>"#,
        format_double(info.default_start_time),
        format_double(info.default_stop_time),
        format_double(info.default_tolerance),
        format_double(info.default_step_size)
    );
    let _ = writeln!(w, "  <ModelVariables>");
    let mut outputs = Vec::new();
    for (i, v) in info.variables.iter().enumerate() {
        let index = i + 1;
        let _ = writeln!(w, "    <!-- index {index} -->");
        let _ = writeln!(
            w,
            r#"    <ScalarVariable name="{}" valueReference="{}" description="{}" causality="{}" variability="{}">"#,
            e(v.name),
            v.value_reference,
            e(v.description),
            causality_attr(v.causality),
            variability_attr(v.variability)
        );
        let mut attrs = String::new();
        match v.var_type {
            VarType::Real => {
                if let Some(unit) = v.unit {
                    let _ = write!(attrs, r#" unit="{}""#, e(unit));
                }
                if has_start(v) {
                    let _ = write!(attrs, r#" start="{}""#, format_double(v.start));
                }
                if let Some(m) = v.min {
                    let _ = write!(attrs, r#" min="{}""#, format_double(m));
                }
                if let Some(m) = v.max {
                    let _ = write!(attrs, r#" max="{}""#, format_double(m));
                }
            }
            VarType::Integer => {
                if has_start(v) {
                    let _ = write!(attrs, r#" start="{}""#, v.start as i64);
                }
                if let Some(m) = v.min {
                    let _ = write!(attrs, r#" min="{}""#, m as i64);
                }
                if let Some(m) = v.max {
                    let _ = write!(attrs, r#" max="{}""#, m as i64);
                }
            }
            VarType::Boolean => {
                if has_start(v) {
                    let _ = write!(attrs, r#" start="{}""#, v.start != 0.0);
                }
            }
        }
        let element = match v.var_type {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
        };
        let _ = writeln!(w, "      <{element}{attrs}/>");
        let _ = writeln!(w, "    </ScalarVariable>");
        if v.causality == Causality::Output {
            outputs.push(index);
        }
    }
    let _ = writeln!(w, "  </ModelVariables>");
    let _ = writeln!(w, "  <ModelStructure>");
    for section in ["Outputs", "InitialUnknowns"] {
        if !outputs.is_empty() {
            let _ = writeln!(w, "    <{section}>");
            for i in &outputs {
                let _ = writeln!(w, r#"      <Unknown index="{i}"/>"#);
            }
            let _ = writeln!(w, "    </{section}>");
        }
    }
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    Ok(x)
}

/// The complete `modelDescription.xml` for `info`.
///
/// # Panics
/// If [`validate_model_info`] finds a problem (duplicate names or value references,
/// undeclared units, ...): a broken variable table is a programming error.
pub fn model_description_xml(info: &ModelInfo) -> String {
    match try_model_description_xml(info) {
        Ok(x) => x,
        Err(problems) => panic!("invalid model info for {}: {}", info.model_name, problems.join("; ")),
    }
}
