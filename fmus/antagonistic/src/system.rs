//! The structure of the AntagonisticJoint system: components, connectors, connections and the
//! parameter set, and their SSD XML (each component's start values inline).

use fmi2::model::{Causality, ModelInfo, VarType};
use fmi2::model_description::{format_double, xml_escape};

/// Name of the system and of the `.ssp`.
pub const SYSTEM_NAME: &str = "AntagonisticJoint";
/// Name of each component's parameter set (inline in the SSD).
pub const PARAMETER_SET_NAME: &str = "start";

pub struct Component {
    pub name: &'static str,
    pub info: &'static ModelInfo,
    /// Connectors: the variables the system exchanges or records.
    pub connectors: &'static [&'static str],
}

impl Component {
    pub fn source(&self) -> String {
        format!("resources/{}.fmu", self.info.model_identifier)
    }
}

/// (start element or None for the system, connector, end element, connector).
pub type Connection = (Option<&'static str>, &'static str, &'static str, &'static str);

const ACTUATOR_CONNECTORS: &[&str] = &["v_DA", "x_s", "F_act", "F_meas"];
const TENDON_CONNECTORS: &[&str] = &["F_act", "x_joint", "v_joint", "T", "x_s", "slack_time"];

pub fn components() -> Vec<Component> {
    vec![
        Component {
            name: "controller",
            info: &joint_controller::fmu::MODEL_INFO,
            connectors: &[
                "theta",
                "omega",
                "F_flexor",
                "F_extensor",
                "v_DA_flexor",
                "v_DA_extensor",
                "T_flexor_ref",
                "T_extensor_ref",
                "tau_ref",
            ],
        },
        Component {
            name: "actuator_flexor",
            info: &jetpipe::fmu::MODEL_INFO,
            connectors: ACTUATOR_CONNECTORS,
        },
        Component {
            name: "actuator_extensor",
            info: &jetpipe::fmu::MODEL_INFO,
            connectors: ACTUATOR_CONNECTORS,
        },
        Component {
            name: "tendon_flexor",
            info: &tendon::fmu::MODEL_INFO,
            connectors: TENDON_CONNECTORS,
        },
        Component {
            name: "tendon_extensor",
            info: &tendon::fmu::MODEL_INFO,
            connectors: TENDON_CONNECTORS,
        },
        Component {
            name: "joint",
            info: &finger_joint::fmu::MODEL_INFO,
            connectors: &[
                "T_flexor",
                "T_extensor",
                "theta",
                "omega",
                "x_flexor",
                "v_flexor",
                "x_extensor",
                "v_extensor",
                "tau_limit",
            ],
        },
    ]
}

/// The system has no connectors of its own (libcosim's SSP parser takes none): the parameter
/// set asks for a reference step through the controller's `theta_step` at `t_step`.
pub const SYSTEM_INPUTS: &[(&str, &str)] = &[];

/// Component connectors that are inputs no connection feeds (none: FMPy's SSP reader fails on
/// one). The controller's theta_ref is no connector; it holds its start value.
pub const OPEN_INPUTS: &[(&str, &str)] = &[];

/// The reference step of the parameter set: `theta_step` rad at `t_step` s.
pub const REFERENCE_STEP: (f64, f64) = (0.5, 1.0);

pub const CONNECTIONS: &[Connection] = &[
    (Some("joint"), "theta", "controller", "theta"),
    (Some("joint"), "omega", "controller", "omega"),
    (Some("actuator_flexor"), "F_meas", "controller", "F_flexor"),
    (Some("actuator_extensor"), "F_meas", "controller", "F_extensor"),
    (Some("controller"), "v_DA_flexor", "actuator_flexor", "v_DA"),
    (Some("controller"), "v_DA_extensor", "actuator_extensor", "v_DA"),
    (Some("tendon_flexor"), "x_s", "actuator_flexor", "x_s"),
    (Some("tendon_extensor"), "x_s", "actuator_extensor", "x_s"),
    (Some("actuator_flexor"), "F_act", "tendon_flexor", "F_act"),
    (Some("actuator_extensor"), "F_act", "tendon_extensor", "F_act"),
    (Some("joint"), "x_flexor", "tendon_flexor", "x_joint"),
    (Some("joint"), "v_flexor", "tendon_flexor", "v_joint"),
    (Some("joint"), "x_extensor", "tendon_extensor", "x_joint"),
    (Some("joint"), "v_extensor", "tendon_extensor", "v_joint"),
    (Some("tendon_flexor"), "T", "joint", "T_flexor"),
    (Some("tendon_extensor"), "T", "joint", "T_extensor"),
];

/// The co-contraction tension the system starts at (the controller's default T_co).
pub fn co_contraction() -> f64 {
    start_of(&joint_controller::fmu::MODEL_INFO, "T_co")
}

fn start_of(info: &ModelInfo, name: &str) -> f64 {
    info.variables
        .iter()
        .find(|v| v.name == name)
        .map(|v| v.start)
        .unwrap_or_else(|| panic!("{} has no variable {name}", info.model_name))
}

/// The parameter set: `component.variable` = value. Parameters are the models' defaults made
/// explicit, so the tuning is visible in the `.ssp`; the inputs' start values put every
/// component at the rest state of the co-contraction (both tendons at T_co, the joint at 0):
/// the actuators' commands at the inverse static map of T_co and their stoppers where the
/// stretched tendons put them.
pub fn parameter_set() -> Vec<(String, f64)> {
    let t_co = co_contraction();
    let tendon = &tendon::fmu::MODEL_INFO;
    let x_s = start_of(tendon, "x_s0") + t_co / start_of(tendon, "k");
    let v_da = joint_controller::control::static_command(t_co);
    let mut set = Vec::new();
    let mut add = |component: &str, name: &str, value: f64| set.push((format!("{component}.{name}"), value));
    for name in ["r", "T_co", "T_min", "T_max", "Kp", "Ki", "Kd", "tau_i_max", "K_F"] {
        add("controller", name, start_of(&joint_controller::fmu::MODEL_INFO, name));
    }
    add("controller", "theta_step", REFERENCE_STEP.0);
    add("controller", "t_step", REFERENCE_STEP.1);
    // Every connected input has its start value here (masters that read connector start values
    // from parameter bindings start their connections there): the joint at rest at its start.
    let joint = &finger_joint::fmu::MODEL_INFO;
    let (theta0, omega0, r) = (
        start_of(joint, "theta_start"),
        start_of(joint, "omega_start"),
        start_of(joint, "r"),
    );
    add("controller", "theta", theta0);
    add("controller", "omega", omega0);
    add("controller", "F_flexor", t_co);
    add("controller", "F_extensor", t_co);
    for side in ["flexor", "extensor"] {
        add(&format!("actuator_{side}"), "v_DA", v_da);
        add(&format!("actuator_{side}"), "x_s", x_s);
        let name = format!("tendon_{side}");
        for p in ["m_rod", "c_rod", "k", "c", "capstan", "x_s0"] {
            add(&name, p, start_of(tendon, p));
        }
        add(&name, "F_act", t_co);
        let sign = if side == "flexor" { 1.0 } else { -1.0 };
        add(&name, "x_joint", sign * r * theta0);
        add(&name, "v_joint", sign * r * omega0);
    }
    for p in ["J", "b", "r", "theta_min", "theta_max"] {
        add("joint", p, start_of(&finger_joint::fmu::MODEL_INFO, p));
    }
    add("joint", "T_flexor", t_co);
    add("joint", "T_extensor", t_co);
    set
}

fn causality_kind(c: Causality) -> &'static str {
    match c {
        Causality::Input => "input",
        Causality::Output => "output",
        Causality::Parameter => "parameter",
        Causality::Local => "local",
    }
}

/// Every connector, connection and parameter against the models' tables: names exist, kinds
/// match, each component input is fed exactly once (FMPy's master needs every declared input
/// connected), outputs feed only inputs, the two ends agree in unit.
pub fn check() -> Result<(), Vec<String>> {
    let components = components();
    let mut problems = Vec::new();
    let find = |element: &str, connector: &str| -> Result<(Causality, Option<&'static str>), String> {
        let c = components
            .iter()
            .find(|c| c.name == element)
            .ok_or_else(|| format!("no component {element}"))?;
        if !c.connectors.contains(&connector) {
            return Err(format!("{element}.{connector} is not a connector of the SSD"));
        }
        let v = c
            .info
            .variables
            .iter()
            .find(|v| v.name == connector)
            .ok_or_else(|| format!("{element}: {} has no variable {connector}", c.info.model_name))?;
        if v.var_type != VarType::Real {
            return Err(format!("{element}.{connector} is not Real"));
        }
        Ok((v.causality, v.unit))
    };
    for c in &components {
        for &connector in c.connectors {
            match find(c.name, connector) {
                Ok((Causality::Input, _)) => {
                    let feeds = CONNECTIONS
                        .iter()
                        .filter(|(_, _, e, ec)| *e == c.name && *ec == connector)
                        .count();
                    let open = OPEN_INPUTS.contains(&(c.name, connector));
                    if feeds != usize::from(!open) {
                        problems.push(format!("{}.{connector} is fed by {feeds} connections, not 1", c.name));
                    }
                }
                Ok((Causality::Output, _)) => {}
                Ok((other, _)) => problems.push(format!(
                    "{}.{connector} is a {} (only inputs and outputs are connectors here)",
                    c.name,
                    causality_kind(other)
                )),
                Err(e) => problems.push(e),
            }
        }
    }
    for &(start, sc, end, ec) in CONNECTIONS {
        let end_side = find(end, ec);
        let start_side = match start {
            None => SYSTEM_INPUTS
                .iter()
                .find(|(n, _)| *n == sc)
                .map(|(_, u)| (Causality::Output, Some(*u)))
                .ok_or_else(|| format!("no system input {sc}")),
            Some(s) => find(s, sc),
        };
        match (start_side, end_side) {
            (Ok((Causality::Output, u1)), Ok((Causality::Input, u2))) => {
                if u1 != u2 {
                    problems.push(format!(
                        "{}.{sc} ({u1:?}) -> {end}.{ec} ({u2:?}): units differ",
                        start.unwrap_or(SYSTEM_NAME)
                    ));
                }
            }
            (Ok(_), Ok(_)) => problems.push(format!(
                "{}.{sc} -> {end}.{ec} does not go from an output to an input",
                start.unwrap_or(SYSTEM_NAME)
            )),
            (a, b) => problems.extend(a.err().into_iter().chain(b.err())),
        }
    }
    for (name, value) in parameter_set() {
        let Some((element, variable)) = name.split_once('.') else {
            problems.push(format!("parameter {name} does not name a component"));
            continue;
        };
        let Some(c) = components.iter().find(|c| c.name == element) else {
            problems.push(format!("parameter {name}: no component {element}"));
            continue;
        };
        match c.info.variables.iter().find(|v| v.name == variable) {
            None => problems.push(format!(
                "parameter {name}: {} has no variable {variable}",
                c.info.model_name
            )),
            Some(v) if !matches!(v.causality, Causality::Parameter | Causality::Input) => {
                problems.push(format!("parameter {name}: {variable} is an output"))
            }
            Some(v) => {
                if let Err(e) = fmu_common::values::check(v, value) {
                    problems.push(format!("parameter {name}: {e}"));
                }
            }
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems)
    }
}

/// Units of the system's connectors, for `<ssd:Units>`.
fn units_used() -> Vec<&'static fmi2::model::UnitDefinition> {
    let mut names: Vec<&str> = Vec::new();
    let mut units = Vec::new();
    for c in components() {
        for &connector in c.connectors {
            let Some(unit) = c
                .info
                .variables
                .iter()
                .find(|v| v.name == connector)
                .and_then(|v| v.unit)
            else {
                continue;
            };
            if names.contains(&unit) {
                continue;
            }
            if let Some(u) = c.info.units.iter().find(|u| u.name == unit) {
                names.push(unit);
                units.push(u);
            }
        }
    }
    units
}

/// `SystemStructure.ssd`.
pub fn ssd_xml(stop_time: f64) -> String {
    let e = xml_escape;
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    x.push_str(&format!(
        "<ssd:SystemStructureDescription xmlns:ssc=\"http://ssp-standard.org/SSP1/SystemStructureCommon\" \
xmlns:ssd=\"http://ssp-standard.org/SSP1/SystemStructureDescription\" \
xmlns:ssv=\"http://ssp-standard.org/SSP1/SystemStructureParameterValues\" version=\"1.0\" name=\"{SYSTEM_NAME}\" \
generationTool=\"jetpipe antagonistic {}\">\n",
        env!("CARGO_PKG_VERSION")
    ));
    x.push_str(&format!(
        "  <ssd:System name=\"{SYSTEM_NAME}\" description=\"One finger joint of the Utah/MIT Dextrous Hand \
driven antagonistically (2N) by two jet-pipe actuators through two tendons, under joint position control with \
co-contraction\">\n"
    ));
    if !SYSTEM_INPUTS.is_empty() {
        x.push_str("    <ssd:Connectors>\n");
        for (name, unit) in SYSTEM_INPUTS {
            x.push_str(&format!(
                "      <ssd:Connector name=\"{name}\" kind=\"input\"><ssc:Real unit=\"{unit}\"/></ssd:Connector>\n"
            ));
        }
        x.push_str("    </ssd:Connectors>\n");
    }
    x.push_str("    <ssd:Elements>\n");
    for c in components() {
        x.push_str(&format!(
            "      <ssd:Component name=\"{}\" type=\"application/x-fmu-sharedlibrary\" source=\"{}\">\n        <ssd:Connectors>\n",
            c.name,
            c.source()
        ));
        for &connector in c.connectors {
            let v = c
                .info
                .variables
                .iter()
                .find(|v| v.name == connector)
                .expect("checked by check()");
            let unit = v.unit.map_or(String::new(), |u| format!(" unit=\"{}\"", e(u)));
            x.push_str(&format!(
                "          <ssd:Connector name=\"{}\" kind=\"{}\"><ssc:Real{unit}/></ssd:Connector>\n",
                e(connector),
                causality_kind(v.causality)
            ));
        }
        x.push_str("        </ssd:Connectors>\n");
        // The component's start values, inline and under its own names: libcosim reads parameter
        // bindings only on components, FMPy and others read them there too.
        let prefix = format!("{}.", c.name);
        let own: Vec<(String, f64)> = parameter_set()
            .into_iter()
            .filter_map(|(name, value)| name.strip_prefix(&prefix).map(|n| (n.to_string(), value)))
            .collect();
        if !own.is_empty() {
            x.push_str(&format!(
                "        <ssd:ParameterBindings>\n          <ssd:ParameterBinding>\n            <ssd:ParameterValues>\n              \
<ssv:ParameterSet version=\"1.0\" name=\"{PARAMETER_SET_NAME}\">\n                <ssv:Parameters>\n"
            ));
            for (name, value) in own {
                x.push_str(&format!(
                    "                  <ssv:Parameter name=\"{}\"><ssv:Real value=\"{}\"/></ssv:Parameter>\n",
                    e(&name),
                    format_double(value)
                ));
            }
            x.push_str(
                "                </ssv:Parameters>\n              </ssv:ParameterSet>\n            </ssd:ParameterValues>\n          \
</ssd:ParameterBinding>\n        </ssd:ParameterBindings>\n",
            );
        }
        x.push_str("      </ssd:Component>\n");
    }
    x.push_str("    </ssd:Elements>\n    <ssd:Connections>\n");
    for &(start, sc, end, ec) in CONNECTIONS {
        let start_element = start.map_or(String::new(), |s| format!(" startElement=\"{s}\""));
        x.push_str(&format!(
            "      <ssd:Connection{start_element} startConnector=\"{sc}\" endElement=\"{end}\" endConnector=\"{ec}\"/>\n"
        ));
    }
    x.push_str("    </ssd:Connections>\n  </ssd:System>\n  <ssd:Units>\n");
    for u in units_used() {
        let mut base = String::new();
        for (attr, exp) in [("kg", u.kg), ("m", u.m), ("s", u.s), ("A", u.a), ("K", u.k)] {
            if exp != 0 {
                base.push_str(&format!(" {attr}=\"{exp}\""));
            }
        }
        x.push_str(&format!(
            "    <ssc:Unit name=\"{}\"><ssc:BaseUnit{base}/></ssc:Unit>\n",
            e(u.name)
        ));
    }
    x.push_str(&format!(
        "  </ssd:Units>\n  <ssd:DefaultExperiment startTime=\"0\" stopTime=\"{}\"/>\n</ssd:SystemStructureDescription>\n",
        format_double(stop_time)
    ));
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_system_matches_the_models_tables() {
        if let Err(problems) = check() {
            panic!("{}", problems.join("\n"));
        }
    }

    #[test]
    fn every_input_of_every_component_is_fed_and_the_loop_is_closed() {
        // The physical loop: each actuator's x_s from its tendon, each tendon's F_act from its
        // actuator, each tendon's joint end from the joint, the joint's tensions from the tendons.
        for side in ["flexor", "extensor"] {
            let actuator = format!("actuator_{side}");
            let tendon = format!("tendon_{side}");
            let fed = |end: &str, ec: &str, start: &str, sc: &str| {
                CONNECTIONS
                    .iter()
                    .any(|&(s, c, e, x)| s == Some(start) && c == sc && e == end && x == ec)
            };
            assert!(fed(&actuator, "x_s", &tendon, "x_s"));
            assert!(fed(&tendon, "F_act", &actuator, "F_act"));
            assert!(fed(&tendon, "x_joint", "joint", &format!("x_{side}")));
            assert!(fed(&tendon, "v_joint", "joint", &format!("v_{side}")));
            assert!(fed("joint", &format!("T_{side}"), &tendon, "T"));
        }
    }

    #[test]
    fn the_start_is_a_rest_state() {
        let set = parameter_set();
        let get = |n: &str| set.iter().find(|(k, _)| k == n).map(|(_, v)| *v).unwrap();
        let t_co = co_contraction();
        assert_eq!(get("tendon_flexor.F_act"), t_co);
        assert!((get("actuator_flexor.x_s") - (0.054 + t_co / 2e4)).abs() < 1e-12);
        // The actuator at that command is at T_co (the static map, to its interpolation error).
        use fmi2::model::CoSimModel;
        let mut a = jetpipe::fmu::ActuatorFmu::instantiate();
        a.set_real(jetpipe::variables::vr::V_DA, get("actuator_flexor.v_DA"))
            .unwrap();
        a.set_real(jetpipe::variables::vr::X_S, get("actuator_flexor.x_s"))
            .unwrap();
        a.exit_initialization().unwrap();
        let f = a.get_real(jetpipe::variables::vr::F_ACT).unwrap();
        assert!((f - t_co).abs() < 0.05, "{f} N vs {t_co} N");
    }

    /// The joint controller's feedforward table must be the actuator's own static curve:
    /// recompute it from jetpipe's actuator FMU model (equilibrium at the default parameters).
    /// Here, not in fmus/joint_controller: a test there would link the actuator's `fmi2*`
    /// symbols next to the controller's own.
    #[test]
    fn static_force_map_is_the_actuators_equilibrium() {
        use fmi2::model::CoSimModel;
        use jetpipe::fmu::ActuatorFmu;
        use jetpipe::variables::vr as actuator;
        use joint_controller::control::STATIC_FORCE_MAP;
        for &(v, f) in STATIC_FORCE_MAP {
            let mut a = ActuatorFmu::instantiate();
            a.set_real(actuator::V_DA, v).unwrap();
            a.exit_initialization().unwrap();
            let force = a.get_real(actuator::F_ACT).unwrap();
            assert!(
                (force - f).abs() < 2e-3,
                "v_DA = {v} V: table {f} N, actuator {force} N"
            );
        }
    }
}
