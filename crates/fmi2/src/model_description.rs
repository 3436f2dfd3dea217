//! `modelDescription.xml` (FMI 2.0 Co-Simulation, and Model Exchange when the model has it)
//! generated from a [`ModelInfo`].

use std::collections::HashSet;
use std::fmt::Write;

use super::model::{Causality, DependencyKind, ModelInfo, VarType, Variability, Variable};

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
        let extent = info.extent_of(v);
        if let (Some(lo), Some(hi)) = (extent.min, extent.max) {
            // NaN bounds are reported too.
            if lo > hi || lo.is_nan() || hi.is_nan() {
                problems.push(format!("variable {:?}: min {lo} > max {hi}", v.name));
            }
        }
        if let Some(n) = extent.nominal {
            if !(n.is_finite() && n > 0.0) || v.var_type != VarType::Real {
                problems.push(format!(
                    "variable {:?}: nominal {n} must be finite, > 0 and on a Real",
                    v.name
                ));
            }
        }
        if has_start(v) {
            if !v.start.is_finite() {
                problems.push(format!("variable {:?}: start {} is not finite", v.name, v.start));
            }
            if extent.min.map_or(false, |m| v.start < m) || extent.max.map_or(false, |m| v.start > m) {
                problems.push(format!("variable {:?}: start {} outside [min, max]", v.name, v.start));
            }
            if v.var_type != VarType::Real && v.start.fract() != 0.0 {
                problems.push(format!("variable {:?}: start {} is not an integer", v.name, v.start));
            }
        }
    }
    problems.extend(dependency_problems(info));
    problems.extend(model_exchange_problems(info));
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

/// What is wrong with `info.dependencies`: an output listed twice or not at all (when the
/// list is not empty), a listed variable that is not an output, `<Outputs>` dependencies on
/// anything but inputs, `<InitialUnknowns>` dependencies on anything but inputs and
/// parameters, or a known listed twice.
fn dependency_problems(info: &ModelInfo) -> Vec<String> {
    let mut problems = Vec::new();
    if info.dependencies.is_empty() {
        return problems;
    }
    let by_vr = |vr: u32| info.variables.iter().find(|v| v.value_reference == vr);
    let mut seen = HashSet::new();
    for d in info.dependencies {
        match by_vr(d.output) {
            Some(v) if v.causality == Causality::Output => {}
            _ => problems.push(format!("dependencies: value reference {} is not an output", d.output)),
        }
        if !seen.insert(d.output) {
            problems.push(format!("dependencies: output {} is listed twice", d.output));
        }
        let mut check = |list: &[(u32, DependencyKind)], section: &str, allowed: &[Causality]| {
            let mut knowns = HashSet::new();
            for &(vr, _) in list {
                match by_vr(vr) {
                    Some(v) if allowed.contains(&v.causality) => {}
                    _ => problems.push(format!(
                        "{section} dependencies of output {}: value reference {vr} is not one of {allowed:?}",
                        d.output
                    )),
                }
                if !knowns.insert(vr) {
                    problems.push(format!(
                        "{section} dependencies of output {}: {vr} is listed twice",
                        d.output
                    ));
                }
            }
        };
        check(d.step, "Outputs", &[Causality::Input]);
        if let Some(initial) = d.initial {
            check(initial, "InitialUnknowns", &[Causality::Input, Causality::Parameter]);
        }
    }
    for v in info.variables {
        if v.causality == Causality::Output && !seen.contains(&v.value_reference) {
            problems.push(format!("dependencies: output {:?} is not listed", v.name));
        }
    }
    problems
}

/// What is wrong with `info.model_exchange`: a state or derivative that is not a continuous
/// Real variable of the table, or that is a parameter or an input, or one listed twice.
fn model_exchange_problems(info: &ModelInfo) -> Vec<String> {
    let mut problems = Vec::new();
    let me = match info.model_exchange {
        Some(me) => me,
        None => return problems,
    };
    let mut seen = HashSet::new();
    for (k, s) in me.states.iter().enumerate() {
        for (what, vr) in [("state", s.state), ("derivative", s.derivative)] {
            match info.variables.iter().find(|v| v.value_reference == vr) {
                Some(v)
                    if v.var_type == VarType::Real
                        && v.variability == Variability::Continuous
                        && matches!(v.causality, Causality::Output | Causality::Local) => {}
                _ => problems.push(format!(
                    "model exchange: the {what} of state {k} (value reference {vr}) is not a continuous Real output or local"
                )),
            }
            if !seen.insert(vr) {
                problems.push(format!("model exchange: value reference {vr} is listed twice"));
            }
        }
    }
    problems
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
    Ok(write_xml(info, info.guid()))
}

/// The GUID of [`ModelInfo::guid`]: a version-5 UUID (RFC 4122, SHA-1 in the URL namespace)
/// of the model description written with `guid=""`, in braces.
pub fn content_guid(info: &ModelInfo) -> String {
    format!("{{{}}}", uuid_v5(&URL_NAMESPACE, write_xml(info, "").as_bytes()))
}

/// RFC 4122's namespace for URLs (6ba7b811-9dad-11d1-80b4-00c04fd430c8).
const URL_NAMESPACE: [u8; 16] = [
    0x6b, 0xa7, 0xb8, 0x11, 0x9d, 0xad, 0x11, 0xd1, 0x80, 0xb4, 0x00, 0xc0, 0x4f, 0xd4, 0x30, 0xc8,
];

/// A name-based UUID, version 5 (RFC 4122 section 4.3), in its lowercase hyphenated form.
pub fn uuid_v5(namespace: &[u8; 16], name: &[u8]) -> String {
    let mut data = Vec::with_capacity(16 + name.len());
    data.extend_from_slice(namespace);
    data.extend_from_slice(name);
    let hash = sha1(&data);
    let mut b = [0u8; 16];
    b.copy_from_slice(&hash[..16]);
    b[6] = (b[6] & 0x0f) | 0x50;
    b[8] = (b[8] & 0x3f) | 0x80;
    let hex: String = b.iter().map(|x| format!("{x:02x}")).collect();
    format!(
        "{}-{}-{}-{}-{}",
        &hex[0..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..32]
    )
}

/// SHA-1 (FIPS 180-4); here only to name a UUID, not for security.
pub fn sha1(message: &[u8]) -> [u8; 20] {
    let mut h: [u32; 5] = [0x6745_2301, 0xEFCD_AB89, 0x98BA_DCFE, 0x1032_5476, 0xC3D2_E1F0];
    let mut padded = message.to_vec();
    padded.push(0x80);
    while padded.len() % 64 != 56 {
        padded.push(0);
    }
    padded.extend_from_slice(&((message.len() as u64).wrapping_mul(8)).to_be_bytes());
    for chunk in padded.chunks(64) {
        let mut w = [0u32; 80];
        for (i, word) in chunk.chunks(4).enumerate() {
            w[i] = u32::from_be_bytes([word[0], word[1], word[2], word[3]]);
        }
        for i in 16..80 {
            w[i] = (w[i - 3] ^ w[i - 8] ^ w[i - 14] ^ w[i - 16]).rotate_left(1);
        }
        let [mut a, mut b, mut c, mut d, mut e] = h;
        for (i, &wi) in w.iter().enumerate() {
            let (f, k) = match i {
                0..=19 => ((b & c) | (!b & d), 0x5A82_7999),
                20..=39 => (b ^ c ^ d, 0x6ED9_EBA1),
                40..=59 => ((b & c) | (b & d) | (c & d), 0x8F1B_BCDC),
                _ => (b ^ c ^ d, 0xCA62_C1D6),
            };
            let t = a
                .rotate_left(5)
                .wrapping_add(f)
                .wrapping_add(e)
                .wrapping_add(k)
                .wrapping_add(wi);
            e = d;
            d = c;
            c = b.rotate_left(30);
            b = a;
            a = t;
        }
        for (x, y) in h.iter_mut().zip([a, b, c, d, e]) {
            *x = x.wrapping_add(y);
        }
    }
    let mut out = [0u8; 20];
    for (i, x) in h.iter().enumerate() {
        out[4 * i..4 * i + 4].copy_from_slice(&x.to_be_bytes());
    }
    out
}

/// The XML with the given GUID, unchecked.
fn write_xml(info: &ModelInfo, guid: &str) -> String {
    let e = xml_escape;
    let index_of = |vr: u32| {
        info.variables
            .iter()
            .position(|v| v.value_reference == vr)
            .map(|i| i + 1)
    };
    let states = info.model_exchange.map_or(&[][..], |me| me.states);
    let mut x = String::new();
    let w = &mut x;
    // writing to a String cannot fail
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        w,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{}" guid="{}" description="{}" author="{}" version="{}" generationTool="{}" variableNamingConvention="flat" numberOfEventIndicators="{}">"#,
        e(info.model_name),
        e(guid),
        e(info.description),
        e(info.author),
        e(info.version),
        e(info.generation_tool),
        info.model_exchange.map_or(0, |me| me.event_indicators)
    );
    if info.model_exchange.is_some() {
        let _ = writeln!(
            w,
            r#"  <ModelExchange modelIdentifier="{}" completedIntegratorStepNotNeeded="{}" canGetAndSetFMUstate="true" canSerializeFMUstate="true" canNotUseMemoryManagementFunctions="true" providesDirectionalDerivative="false"/>"#,
            e(info.model_identifier),
            !info
                .model_exchange
                .map_or(false, |me| me.needs_completed_integrator_step)
        );
    }
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
        let extent = info.extent_of(v);
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
                if let Some(m) = extent.min {
                    let _ = write!(attrs, r#" min="{}""#, format_double(m));
                }
                if let Some(m) = extent.max {
                    let _ = write!(attrs, r#" max="{}""#, format_double(m));
                }
                if let Some(n) = extent.nominal {
                    let _ = write!(attrs, r#" nominal="{}""#, format_double(n));
                }
                let state = states.iter().find(|s| s.derivative == v.value_reference);
                if let Some(j) = state.and_then(|s| index_of(s.state)) {
                    let _ = write!(attrs, r#" derivative="{j}""#);
                }
            }
            VarType::Integer => {
                if has_start(v) {
                    let _ = write!(attrs, r#" start="{}""#, v.start as i64);
                }
                if let Some(m) = extent.min {
                    let _ = write!(attrs, r#" min="{}""#, m as i64);
                }
                if let Some(m) = extent.max {
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
            outputs.push((index, v.value_reference));
        }
    }
    let _ = writeln!(w, "  </ModelVariables>");
    let _ = writeln!(w, "  <ModelStructure>");
    let all_knowns: Vec<(u32, DependencyKind)> = info
        .variables
        .iter()
        .filter(|v| matches!(v.causality, Causality::Input | Causality::Parameter))
        .map(|v| (v.value_reference, DependencyKind::Dependent))
        .collect();
    // Model Exchange: the derivatives, and among the initial unknowns every state and
    // derivative as well (FMI 2.0, 2.2.8), each depending on every known.
    let derivatives: Vec<(usize, u32)> = states
        .iter()
        .filter_map(|s| index_of(s.derivative).map(|i| (i, s.derivative)))
        .collect();
    let mut initial_unknowns = outputs.clone();
    for s in states {
        for vr in [s.state, s.derivative] {
            if let Some(i) = index_of(vr) {
                if !initial_unknowns.iter().any(|&(j, _)| j == i) {
                    initial_unknowns.push((i, vr));
                }
            }
        }
    }
    initial_unknowns.sort_by_key(|&(i, _)| i);
    for (section, initial) in [("Outputs", false), ("InitialUnknowns", true)] {
        if initial && !derivatives.is_empty() {
            // between <Outputs> and <InitialUnknowns>, as the schema orders them
            let _ = writeln!(w, "    <Derivatives>");
            for &(i, _) in &derivatives {
                let _ = writeln!(w, r#"      <Unknown index="{i}"/>"#);
            }
            let _ = writeln!(w, "    </Derivatives>");
        }
        let unknowns = if initial { &initial_unknowns } else { &outputs };
        if unknowns.is_empty() {
            continue;
        }
        let _ = writeln!(w, "    <{section}>");
        for &(i, vr) in unknowns {
            let listed = info.dependencies.iter().find(|d| d.output == vr);
            let is_state = states.iter().any(|s| s.state == vr || s.derivative == vr);
            match listed {
                // a state or a derivative of Model Exchange: after initialisation it depends
                // on every input and parameter
                None if initial && is_state && !all_knowns.is_empty() => {
                    let known: Vec<String> = all_knowns
                        .iter()
                        .filter_map(|&(vr, _)| index_of(vr).map(|j| j.to_string()))
                        .collect();
                    let _ = writeln!(
                        w,
                        r#"      <Unknown index="{i}" dependencies="{}" dependenciesKind="{}"/>"#,
                        known.join(" "),
                        vec!["dependent"; known.len()].join(" ")
                    );
                }
                None => {
                    let _ = writeln!(w, r#"      <Unknown index="{i}"/>"#);
                }
                Some(d) => {
                    let mut list: Vec<(u32, DependencyKind)> = match (initial, d.initial) {
                        (false, _) => d.step.to_vec(),
                        (true, Some(l)) => l.to_vec(),
                        (true, None) => all_knowns.clone(),
                    };
                    if !initial {
                        // With Model Exchange the knowns of an output are the inputs and the
                        // continuous states: an output may depend on every state.
                        list.extend(states.iter().map(|s| (s.state, DependencyKind::Dependent)));
                    }
                    // Ascending indices, as the standard's examples list them.
                    let mut known: Vec<(usize, DependencyKind)> = list
                        .iter()
                        .filter_map(|&(vr, kind)| index_of(vr).map(|j| (j, kind)))
                        .collect();
                    known.sort_by_key(|&(j, _)| j);
                    let indices: Vec<String> = known.iter().map(|(j, _)| j.to_string()).collect();
                    let kinds: Vec<&str> = known.iter().map(|(_, k)| k.attr()).collect();
                    let _ = writeln!(
                        w,
                        r#"      <Unknown index="{i}" dependencies="{}" dependenciesKind="{}"/>"#,
                        indices.join(" "),
                        kinds.join(" ")
                    );
                }
            }
        }
        let _ = writeln!(w, "    </{section}>");
    }
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    x
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
