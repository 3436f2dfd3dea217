//! `modelDescription.xml` of FMI 3.0 (Co-Simulation, and Model Exchange when the model has
//! it), generated from the same [`ModelInfo`] as the FMI 2.0 one and checked by the same
//! [`validate_model_info`].
//!
//! What FMI 3.0 asks beyond the table: an independent variable (`time`) and, for Model
//! Exchange, the event indicators as variables (`event_indicator_1` ...) that
//! `<EventIndicator>` names; both get value references after the table's largest
//! ([`time_value_reference`]) and are read with `fmi3GetFloat64`. The
//! instantiation token is the GUID of the FMI 2.0 description ([`crate::api::instantiation_token`]).

use std::fmt::Write;

use fmi2::model::{Causality, DependencyKind, ModelInfo, VarType};
use fmi2::model_description::{format_double, validate_model_info, xml_escape};

/// The value reference of the independent variable `time`.
pub fn time_value_reference(info: &ModelInfo) -> u32 {
    info.variables
        .iter()
        .map(|v| v.value_reference)
        .max()
        .map_or(0, |m| m + 1)
}

/// The value reference of event indicator `k` (from 0).
pub fn event_indicator_value_reference(info: &ModelInfo, k: usize) -> u32 {
    time_value_reference(info) + 1 + k as u32
}

/// The complete FMI 3.0 `modelDescription.xml`, or the problems [`validate_model_info`] finds.
pub fn try_model_description_xml(info: &ModelInfo) -> Result<String, Vec<String>> {
    validate_model_info(info)?;
    Ok(write_xml(info))
}

/// [`try_model_description_xml`] for a table known to be valid.
///
/// # Panics
/// On a broken variable table (a programming error).
pub fn model_description_xml(info: &ModelInfo) -> String {
    match try_model_description_xml(info) {
        Ok(x) => x,
        Err(problems) => panic!("invalid model info for {}: {}", info.model_name, problems.join("; ")),
    }
}

fn dependencies_attrs(list: &[(u32, DependencyKind)]) -> String {
    let mut known: Vec<(u32, DependencyKind)> = list.to_vec();
    known.sort_by_key(|&(vr, _)| vr);
    known.dedup_by_key(|k| k.0);
    let vrs: Vec<String> = known.iter().map(|(vr, _)| vr.to_string()).collect();
    let kinds: Vec<&str> = known.iter().map(|(_, k)| k.attr()).collect();
    format!(
        r#" dependencies="{}" dependenciesKind="{}""#,
        vrs.join(" "),
        kinds.join(" ")
    )
}

fn write_xml(info: &ModelInfo) -> String {
    let e = xml_escape;
    let me = info.model_exchange;
    let states = me.map_or(&[][..], |me| me.states);
    let n_indicators = me.map_or(0, |me| me.event_indicators);
    let mut x = String::new();
    let w = &mut x;
    // writing to a String cannot fail
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        w,
        r#"<fmiModelDescription fmiVersion="3.0" modelName="{}" instantiationToken="{}" description="{}" author="{}" version="{}" generationTool="{}" variableNamingConvention="flat">"#,
        e(info.model_name),
        e(info.guid()),
        e(info.description),
        e(info.author),
        e(info.version),
        e(info.generation_tool),
    );
    if let Some(me) = me {
        let _ = writeln!(
            w,
            r#"  <ModelExchange modelIdentifier="{}" canGetAndSetFMUState="true" canSerializeFMUState="true" providesDirectionalDerivatives="false" providesAdjointDerivatives="false" providesPerElementDependencies="false" needsCompletedIntegratorStep="{}" providesEvaluateDiscreteStates="false"/>"#,
            e(info.model_identifier),
            me.needs_completed_integrator_step
        );
    }
    let _ = writeln!(
        w,
        r#"  <CoSimulation modelIdentifier="{}" canGetAndSetFMUState="true" canSerializeFMUState="true" providesDirectionalDerivatives="false" providesAdjointDerivatives="false" providesPerElementDependencies="false" canHandleVariableCommunicationStepSize="true" maxOutputDerivativeOrder="0" providesIntermediateUpdate="false" mightReturnEarlyFromDoStep="false" canReturnEarlyAfterIntermediateUpdate="false" hasEventMode="false" providesEvaluateDiscreteStates="false"/>"#,
        e(info.model_identifier)
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
    for v in info.variables {
        let extent = info.extent_of(v);
        let mut attrs = format!(
            r#"name="{}" valueReference="{}" description="{}" causality="{}" variability="{}""#,
            e(v.name),
            v.value_reference,
            e(v.description),
            v.causality.name(),
            v.variability.name()
        );
        let has_start = matches!(v.causality, Causality::Parameter | Causality::Input);
        let element = match v.var_type {
            VarType::Real => {
                if let Some(unit) = v.unit {
                    let _ = write!(attrs, r#" unit="{}""#, e(unit));
                }
                for (name, value) in [("min", extent.min), ("max", extent.max), ("nominal", extent.nominal)] {
                    if let Some(value) = value {
                        let _ = write!(attrs, r#" {name}="{}""#, format_double(value));
                    }
                }
                if has_start {
                    let _ = write!(attrs, r#" start="{}""#, format_double(v.start));
                }
                if let Some(s) = states.iter().find(|s| s.derivative == v.value_reference) {
                    let _ = write!(attrs, r#" derivative="{}""#, s.state);
                }
                "Float64"
            }
            VarType::Integer => {
                for (name, value) in [("min", extent.min), ("max", extent.max)] {
                    if let Some(value) = value {
                        let _ = write!(attrs, r#" {name}="{}""#, value as i64);
                    }
                }
                if has_start {
                    let _ = write!(attrs, r#" start="{}""#, v.start as i64);
                }
                "Int32"
            }
            VarType::Boolean => {
                if has_start {
                    let _ = write!(attrs, r#" start="{}""#, v.start != 0.0);
                }
                "Boolean"
            }
        };
        let _ = writeln!(w, "    <{element} {attrs}/>");
    }
    // the time's unit only when the table declares the second
    let unit = if info.units.iter().any(|u| u.name == "s") {
        r#" unit="s""#
    } else {
        ""
    };
    let _ = writeln!(
        w,
        r#"    <Float64 name="time" valueReference="{}" causality="independent" variability="continuous"{unit} description="simulation time"/>"#,
        time_value_reference(info)
    );
    for k in 0..n_indicators {
        let _ = writeln!(
            w,
            r#"    <Float64 name="event_indicator_{}" valueReference="{}" causality="local" variability="continuous" description="event indicator {} of Model Exchange (fmi3GetEventIndicators)"/>"#,
            k + 1,
            event_indicator_value_reference(info, k),
            k + 1
        );
    }
    let _ = writeln!(w, "  </ModelVariables>");
    let _ = writeln!(w, "  <ModelStructure>");
    let all_knowns: Vec<(u32, DependencyKind)> = info
        .variables
        .iter()
        .filter(|v| matches!(v.causality, Causality::Input | Causality::Parameter))
        .map(|v| (v.value_reference, DependencyKind::Dependent))
        .collect();
    for v in info.variables.iter().filter(|v| v.causality == Causality::Output) {
        let mut attrs = String::new();
        if let Some(d) = info.dependencies.iter().find(|d| d.output == v.value_reference) {
            let mut list = d.step.to_vec();
            // With Model Exchange an output may also depend on every continuous state.
            list.extend(states.iter().map(|s| (s.state, DependencyKind::Dependent)));
            attrs = dependencies_attrs(&list);
        }
        let _ = writeln!(w, r#"    <Output valueReference="{}"{attrs}/>"#, v.value_reference);
    }
    for s in states {
        let _ = writeln!(
            w,
            r#"    <ContinuousStateDerivative valueReference="{}"/>"#,
            s.derivative
        );
    }
    // The initial unknowns: the outputs, and every state and derivative of Model Exchange,
    // in the order of the table.
    for v in info.variables {
        let vr = v.value_reference;
        let output = v.causality == Causality::Output;
        let is_state = states.iter().any(|s| s.state == vr || s.derivative == vr);
        if !(output || is_state) {
            continue;
        }
        let list = match info.dependencies.iter().find(|d| d.output == vr) {
            Some(d) => d.initial.map_or_else(|| all_knowns.clone(), |l| l.to_vec()),
            None => all_knowns.clone(),
        };
        let attrs = if list.is_empty() && info.dependencies.is_empty() {
            String::new()
        } else {
            dependencies_attrs(&list)
        };
        let _ = writeln!(w, r#"    <InitialUnknown valueReference="{vr}"{attrs}/>"#);
    }
    for k in 0..n_indicators {
        let _ = writeln!(
            w,
            r#"    <EventIndicator valueReference="{}"/>"#,
            event_indicator_value_reference(info, k)
        );
    }
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    x
}
