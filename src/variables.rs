//! The FMU's variables: the rows of the model's table (`jetpipe_model::variables::TABLE`) as
//! the FMI layer's variables, in the table's order, and the units of the model description.

use fmi2::model::{Causality, UnitDefinition, VarType, Variability, Variable};
use jetpipe_model::variables::{self as table, Row, TABLE};

/// Value references, named so code never uses bare numbers (the model table's).
pub use jetpipe_model::variables::vr;

/// The units of the table's variables, with their SI base-unit exponents (`<UnitDefinitions>`).
pub const UNITS: &[UnitDefinition] = &[
    UnitDefinition {
        name: "V",
        kg: 1,
        m: 2,
        s: -3,
        a: -1,
        k: 0,
    },
    UnitDefinition {
        name: "m",
        kg: 0,
        m: 1,
        s: 0,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "N",
        kg: 1,
        m: 1,
        s: -2,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "Pa",
        kg: 1,
        m: -1,
        s: -2,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "A",
        kg: 0,
        m: 0,
        s: 0,
        a: 1,
        k: 0,
    },
    UnitDefinition {
        name: "K",
        kg: 0,
        m: 0,
        s: 0,
        a: 0,
        k: 1,
    },
    UnitDefinition {
        name: "J/(kg.K)",
        kg: 0,
        m: 2,
        s: -2,
        a: 0,
        k: -1,
    },
    UnitDefinition {
        name: "A/V",
        kg: -1,
        m: -2,
        s: 3,
        a: 2,
        k: 0,
    },
    UnitDefinition {
        name: "rad/s",
        kg: 0,
        m: 0,
        s: -1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "N/A",
        kg: 1,
        m: 1,
        s: -2,
        a: -1,
        k: 0,
    },
    UnitDefinition {
        name: "m2",
        kg: 0,
        m: 2,
        s: 0,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "N/m",
        kg: 1,
        m: 0,
        s: -2,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "1",
        kg: 0,
        m: 0,
        s: 0,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "m3",
        kg: 0,
        m: 3,
        s: 0,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "s",
        kg: 0,
        m: 0,
        s: 1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "Pa.s/kg",
        kg: 0,
        m: -1,
        s: -1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        // kg/(s·Pa) = m·s: a laminar conductance.
        name: "kg/(s.Pa)",
        kg: 0,
        m: 1,
        s: 1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        // A mass flow: the extra flow slots' coefficients.
        name: "kg/s",
        kg: 1,
        m: 0,
        s: -1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "m/N",
        kg: -1,
        m: 0,
        s: 2,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "1/N",
        kg: -1,
        m: -1,
        s: 2,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "1/N2",
        kg: -2,
        m: -2,
        s: 4,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "N/s",
        kg: 1,
        m: 1,
        s: -3,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "Hz",
        kg: 0,
        m: 0,
        s: -1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "N.s/m",
        kg: 1,
        m: 0,
        s: -1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "Pa/s",
        kg: 1,
        m: -1,
        s: -3,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "K/s",
        kg: 0,
        m: 0,
        s: -1,
        a: 0,
        k: 1,
    },
    UnitDefinition {
        name: "m/s",
        kg: 0,
        m: 1,
        s: -1,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "A/s",
        kg: 0,
        m: 0,
        s: -1,
        a: 1,
        k: 0,
    },
    UnitDefinition {
        name: "kg",
        kg: 1,
        m: 0,
        s: 0,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "N.s2/m2",
        kg: 1,
        m: -1,
        s: 0,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "m/s2",
        kg: 0,
        m: 1,
        s: -2,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "m/s3",
        kg: 0,
        m: 1,
        s: -3,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "V/s",
        kg: 1,
        m: 2,
        s: -4,
        a: -1,
        k: 0,
    },
    UnitDefinition {
        name: "V/s2",
        kg: 1,
        m: 2,
        s: -5,
        a: -1,
        k: 0,
    },
    UnitDefinition {
        name: "N/s2",
        kg: 1,
        m: 1,
        s: -4,
        a: 0,
        k: 0,
    },
    UnitDefinition {
        name: "Pa/s2",
        kg: 1,
        m: -1,
        s: -4,
        a: 0,
        k: 0,
    },
];

const fn causality(c: table::Causality) -> Causality {
    match c {
        table::Causality::Parameter => Causality::Parameter,
        table::Causality::Input => Causality::Input,
        table::Causality::Output => Causality::Output,
        table::Causality::Local => Causality::Local,
    }
}

const fn variability(v: table::Variability) -> Variability {
    match v {
        table::Variability::Fixed => Variability::Fixed,
        table::Variability::Tunable => Variability::Tunable,
        table::Variability::Discrete => Variability::Discrete,
        table::Variability::Continuous => Variability::Continuous,
    }
}

const fn var_type(t: table::VarType) -> VarType {
    match t {
        table::VarType::Real => VarType::Real,
        table::VarType::Integer => VarType::Integer,
        table::VarType::Boolean => VarType::Boolean,
    }
}

/// The FMI variable of a row (const: the variables are a constant array).
const fn fmi_variable(row: &Row) -> Variable {
    let v = &row.variable;
    Variable {
        name: v.name,
        value_reference: v.value_reference,
        var_type: var_type(v.var_type),
        causality: causality(v.causality),
        variability: variability(v.variability),
        unit: v.unit,
        start: v.start,
        min: v.min,
        max: v.max,
        description: v.description,
    }
}

/// Value references of the variables of Model Exchange beyond the table's: the states that
/// are not outputs (the jet pipe's velocity and acceleration, the chambers' air, the gas
/// volumes', the mount's, the lags', the filters' and the Padé chain's) and the derivatives.
pub mod me_vr {
    pub const X_JP_VELOCITY: u32 = 900;
    pub const X_JP_ACCELERATION: u32 = 901;
    pub const DER_I: u32 = 902;
    pub const DER_X_JP: u32 = 903;
    pub const DER_X_JP_VELOCITY: u32 = 904;
    pub const DER_X_JP_ACCELERATION: u32 = 905;
    pub const DER_P1: u32 = 906;
    pub const DER_P2: u32 = 907;
    pub const P_SUPPLY_PLENUM: u32 = 908;
    pub const P_RETURN_PLENUM: u32 = 909;
    pub const P_PORT_LINE_1: u32 = 910;
    pub const P_PORT_LINE_2: u32 = 911;
    pub const STOPPER_MOUNT_LOAD: u32 = 912;
    pub const DER_P_SUPPLY_PLENUM: u32 = 913;
    pub const DER_P_RETURN_PLENUM: u32 = 914;
    pub const DER_P_PORT_LINE_1: u32 = 915;
    pub const DER_P_PORT_LINE_2: u32 = 916;
    pub const DER_STOPPER_MOUNT_LOAD: u32 = 917;
    /// The lags' and filters' states (three for each of the command stage, the force sensor
    /// and the two pressure transducers: the lag's output, the filter's output and rate),
    /// then their derivatives.
    pub const FILTER_STATES: [u32; 12] = [918, 919, 920, 921, 922, 923, 924, 925, 926, 927, 928, 929];
    pub const FILTER_DERIVATIVES: [u32; 12] = [930, 931, 932, 933, 934, 935, 936, 937, 938, 939, 940, 941];
    /// The Padé chain of the transport delay in Model Exchange: its number of sections (a
    /// parameter), its sections' states and their derivatives.
    pub const COMMAND_DELAY_PADE_SECTIONS: u32 = 942;
    pub const PADE_STATES: [u32; 8] = [943, 944, 945, 946, 947, 948, 949, 950];
    pub const PADE_DERIVATIVES: [u32; 8] = [951, 952, 953, 954, 955, 956, 957, 958];
    /// The chambers' air as pressures at mid-stroke: the states in place of P1 and P2.
    pub const P1_AT_MID_STROKE: u32 = 959;
    pub const P2_AT_MID_STROKE: u32 = 960;
    /// The states beyond the six, in the order of the state vector (the volumes' pressures,
    /// the mount's load, the lags and filters, the Padé chain).
    pub const STATES: [u32; 25] = {
        let nodes = [
            P_SUPPLY_PLENUM,
            P_RETURN_PLENUM,
            P_PORT_LINE_1,
            P_PORT_LINE_2,
            STOPPER_MOUNT_LOAD,
        ];
        let mut out = [0; 25];
        let mut k = 0;
        while k < 25 {
            out[k] = if k < 5 {
                nodes[k]
            } else if k < 17 {
                FILTER_STATES[k - 5]
            } else {
                PADE_STATES[k - 17]
            };
            k += 1;
        }
        out
    };
    /// The derivatives of every state, in the order of the state vector.
    pub const DERIVATIVES: [u32; 31] = {
        let first = [
            DER_I,
            DER_X_JP,
            DER_X_JP_VELOCITY,
            DER_X_JP_ACCELERATION,
            DER_P1,
            DER_P2,
            DER_P_SUPPLY_PLENUM,
            DER_P_RETURN_PLENUM,
            DER_P_PORT_LINE_1,
            DER_P_PORT_LINE_2,
            DER_STOPPER_MOUNT_LOAD,
        ];
        let mut out = [0; 31];
        let mut k = 0;
        while k < 31 {
            out[k] = if k < 11 {
                first[k]
            } else if k < 23 {
                FILTER_DERIVATIVES[k - 11]
            } else {
                PADE_DERIVATIVES[k - 23]
            };
            k += 1;
        }
        out
    };
    /// The first and the last of them.
    pub const FIRST: u32 = X_JP_VELOCITY;
    pub const LAST: u32 = P2_AT_MID_STROKE;
}

/// A continuous local of Model Exchange.
const fn local(name: &'static str, value_reference: u32, unit: &'static str, description: &'static str) -> Variable {
    Variable {
        name,
        value_reference,
        var_type: VarType::Real,
        causality: Causality::Local,
        variability: Variability::Continuous,
        unit: Some(unit),
        start: 0.0,
        min: None,
        max: None,
        description,
    }
}

/// The continuous states of Model Exchange and their derivatives, after the table's rows: the
/// six states of (4.1) with the chambers' air at mid-stroke in place of P1 and P2 (i and x_jp
/// are outputs), then
/// the pressures of the gas volumes behind restrictions and the lagging stopper mount's load,
/// then the command stage's and the transducers' lags and filters (each constant, its
/// derivative 0, while its effect is off).
pub const MODEL_EXCHANGE_VARIABLES: [Variable; 61] = [
    local(
        "x_jp_velocity",
        me_vr::X_JP_VELOCITY,
        "m/s",
        "jet-pipe tip velocity (a continuous state of Model Exchange)",
    ),
    local(
        "x_jp_acceleration",
        me_vr::X_JP_ACCELERATION,
        "m/s2",
        "jet-pipe tip acceleration (a continuous state of Model Exchange)",
    ),
    local(
        "P1_at_mid_stroke",
        me_vr::P1_AT_MID_STROKE,
        "Pa",
        "chamber 1's air as the pressure it would have at its volume with the stopper at mid-stroke, brought there with no flow (P1 (V1/V1_mid)^gamma): the state of Model Exchange in place of P1, which a moving stopper leaves unchanged",
    ),
    local(
        "P2_at_mid_stroke",
        me_vr::P2_AT_MID_STROKE,
        "Pa",
        "chamber 2's air as the pressure it would have at its volume with the stopper at mid-stroke, brought there with no flow (P2 (V2/V2_mid)^gamma): the state of Model Exchange in place of P2, which a moving stopper leaves unchanged",
    ),
    local("der(i)", me_vr::DER_I, "A/s", "rate of the coil current, (2.3)"),
    local("der(x_jp)", me_vr::DER_X_JP, "m/s", "rate of the jet-pipe position"),
    local(
        "der(x_jp_velocity)",
        me_vr::DER_X_JP_VELOCITY,
        "m/s2",
        "rate of the jet-pipe velocity",
    ),
    local(
        "der(x_jp_acceleration)",
        me_vr::DER_X_JP_ACCELERATION,
        "m/s3",
        "rate of the jet-pipe acceleration, (2.6)",
    ),
    local(
        "der(P1_at_mid_stroke)",
        me_vr::DER_P1,
        "Pa/s",
        "rate of P1_at_mid_stroke: (2.29) with the volume's rate taken out, which the stopper's motion does not enter",
    ),
    local(
        "der(P2_at_mid_stroke)",
        me_vr::DER_P2,
        "Pa/s",
        "rate of P2_at_mid_stroke: (2.29) with the volume's rate taken out, which the stopper's motion does not enter",
    ),
    local(
        "p_supply_plenum",
        me_vr::P_SUPPLY_PLENUM,
        "Pa",
        "pressure in the supply plenum behind its restriction (a state of Model Exchange; constant without supply_plenum_volume)",
    ),
    local(
        "p_return_plenum",
        me_vr::P_RETURN_PLENUM,
        "Pa",
        "pressure in the return plenum behind its restriction (a state of Model Exchange; constant without return_plenum_volume)",
    ),
    local(
        "p_port_line_1",
        me_vr::P_PORT_LINE_1,
        "Pa",
        "pressure in port line 1 behind its restriction (a state of Model Exchange; constant without port_line_volume_1)",
    ),
    local(
        "p_port_line_2",
        me_vr::P_PORT_LINE_2,
        "Pa",
        "pressure in port line 2 behind its restriction (a state of Model Exchange; constant without port_line_volume_2)",
    ),
    local(
        "stopper_mount_load",
        me_vr::STOPPER_MOUNT_LOAD,
        "Pa",
        "the pressure difference the lagging stopper mount has followed (a state of Model Exchange; constant without stopper_mount_lag)",
    ),
    local("der(p_supply_plenum)", me_vr::DER_P_SUPPLY_PLENUM, "Pa/s", "rate of the supply plenum's pressure"),
    local("der(p_return_plenum)", me_vr::DER_P_RETURN_PLENUM, "Pa/s", "rate of the return plenum's pressure"),
    local("der(p_port_line_1)", me_vr::DER_P_PORT_LINE_1, "Pa/s", "rate of port line 1's pressure"),
    local("der(p_port_line_2)", me_vr::DER_P_PORT_LINE_2, "Pa/s", "rate of port line 2's pressure"),
    local(
        "der(stopper_mount_load)",
        me_vr::DER_STOPPER_MOUNT_LOAD,
        "Pa/s",
        "rate of the lagging stopper mount's load",
    ),
    local(
        "command_lagged",
        me_vr::FILTER_STATES[0],
        "V",
        "the command stage's lag output (a state of Model Exchange; constant without command_lag)",
    ),
    local(
        "command_filtered",
        me_vr::FILTER_STATES[1],
        "V",
        "the command stage's second-order filter output (a state of Model Exchange; constant without command_filter_frequency)",
    ),
    local(
        "command_filtered_rate",
        me_vr::FILTER_STATES[2],
        "V/s",
        "rate of the command stage's filter output (a state of Model Exchange; constant without command_filter_frequency)",
    ),
    local(
        "F_meas_lagged",
        me_vr::FILTER_STATES[3],
        "N",
        "the force sensor's lag output (a state of Model Exchange; constant without force_sensor_lag)",
    ),
    local(
        "F_meas_filtered",
        me_vr::FILTER_STATES[4],
        "N",
        "the force sensor's second-order filter output (a state of Model Exchange; constant without force_sensor_filter_frequency)",
    ),
    local(
        "F_meas_filtered_rate",
        me_vr::FILTER_STATES[5],
        "N/s",
        "rate of the force sensor's filter output (a state of Model Exchange; constant without force_sensor_filter_frequency)",
    ),
    local(
        "P1_meas_lagged",
        me_vr::FILTER_STATES[6],
        "Pa",
        "pressure transducer 1's lag output (a state of Model Exchange; constant without p1_sensor_lag)",
    ),
    local(
        "P1_meas_filtered",
        me_vr::FILTER_STATES[7],
        "Pa",
        "pressure transducer 1's second-order filter output (a state of Model Exchange; constant without p1_sensor_filter_frequency)",
    ),
    local(
        "P1_meas_filtered_rate",
        me_vr::FILTER_STATES[8],
        "Pa/s",
        "rate of pressure transducer 1's filter output (a state of Model Exchange; constant without p1_sensor_filter_frequency)",
    ),
    local(
        "P2_meas_lagged",
        me_vr::FILTER_STATES[9],
        "Pa",
        "pressure transducer 2's lag output (a state of Model Exchange; constant without p2_sensor_lag)",
    ),
    local(
        "P2_meas_filtered",
        me_vr::FILTER_STATES[10],
        "Pa",
        "pressure transducer 2's second-order filter output (a state of Model Exchange; constant without p2_sensor_filter_frequency)",
    ),
    local(
        "P2_meas_filtered_rate",
        me_vr::FILTER_STATES[11],
        "Pa/s",
        "rate of pressure transducer 2's filter output (a state of Model Exchange; constant without p2_sensor_filter_frequency)",
    ),
    local(
        "der(command_lagged)",
        me_vr::FILTER_DERIVATIVES[0],
        "V/s",
        "rate of command_lagged",
    ),
    local(
        "der(command_filtered)",
        me_vr::FILTER_DERIVATIVES[1],
        "V/s",
        "rate of command_filtered",
    ),
    local(
        "der(command_filtered_rate)",
        me_vr::FILTER_DERIVATIVES[2],
        "V/s2",
        "rate of command_filtered_rate",
    ),
    local(
        "der(F_meas_lagged)",
        me_vr::FILTER_DERIVATIVES[3],
        "N/s",
        "rate of F_meas_lagged",
    ),
    local(
        "der(F_meas_filtered)",
        me_vr::FILTER_DERIVATIVES[4],
        "N/s",
        "rate of F_meas_filtered",
    ),
    local(
        "der(F_meas_filtered_rate)",
        me_vr::FILTER_DERIVATIVES[5],
        "N/s2",
        "rate of F_meas_filtered_rate",
    ),
    local(
        "der(P1_meas_lagged)",
        me_vr::FILTER_DERIVATIVES[6],
        "Pa/s",
        "rate of P1_meas_lagged",
    ),
    local(
        "der(P1_meas_filtered)",
        me_vr::FILTER_DERIVATIVES[7],
        "Pa/s",
        "rate of P1_meas_filtered",
    ),
    local(
        "der(P1_meas_filtered_rate)",
        me_vr::FILTER_DERIVATIVES[8],
        "Pa/s2",
        "rate of P1_meas_filtered_rate",
    ),
    local(
        "der(P2_meas_lagged)",
        me_vr::FILTER_DERIVATIVES[9],
        "Pa/s",
        "rate of P2_meas_lagged",
    ),
    local(
        "der(P2_meas_filtered)",
        me_vr::FILTER_DERIVATIVES[10],
        "Pa/s",
        "rate of P2_meas_filtered",
    ),
    local(
        "der(P2_meas_filtered_rate)",
        me_vr::FILTER_DERIVATIVES[11],
        "Pa/s2",
        "rate of P2_meas_filtered_rate",
    ),
    Variable {
        name: "command_delay_pade_sections",
        value_reference: me_vr::COMMAND_DELAY_PADE_SECTIONS,
        var_type: VarType::Real,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: None,
        start: 0.0,
        min: Some(0.0),
        max: Some(8.0),
        description: "Model Exchange only: the transport delay (command_delay) as a chain of this many first-order Pade sections (1 - s d/2n)/(1 + s d/2n), a whole number from 0 to 8 (0 = off: Model Exchange refuses command_delay); Co-Simulation keeps its exact delay",
    },
    local(
        "command_delay_pade_1",
        me_vr::PADE_STATES[0],
        "V",
        "state of section 1 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 1)",
    ),
    local(
        "command_delay_pade_2",
        me_vr::PADE_STATES[1],
        "V",
        "state of section 2 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 2)",
    ),
    local(
        "command_delay_pade_3",
        me_vr::PADE_STATES[2],
        "V",
        "state of section 3 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 3)",
    ),
    local(
        "command_delay_pade_4",
        me_vr::PADE_STATES[3],
        "V",
        "state of section 4 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 4)",
    ),
    local(
        "command_delay_pade_5",
        me_vr::PADE_STATES[4],
        "V",
        "state of section 5 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 5)",
    ),
    local(
        "command_delay_pade_6",
        me_vr::PADE_STATES[5],
        "V",
        "state of section 6 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 6)",
    ),
    local(
        "command_delay_pade_7",
        me_vr::PADE_STATES[6],
        "V",
        "state of section 7 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 7)",
    ),
    local(
        "command_delay_pade_8",
        me_vr::PADE_STATES[7],
        "V",
        "state of section 8 of the transport delay's Pade chain (a state of Model Exchange; constant unless command_delay_pade_sections >= 8)",
    ),
    local(
        "der(command_delay_pade_1)",
        me_vr::PADE_DERIVATIVES[0],
        "V/s",
        "rate of command_delay_pade_1",
    ),
    local(
        "der(command_delay_pade_2)",
        me_vr::PADE_DERIVATIVES[1],
        "V/s",
        "rate of command_delay_pade_2",
    ),
    local(
        "der(command_delay_pade_3)",
        me_vr::PADE_DERIVATIVES[2],
        "V/s",
        "rate of command_delay_pade_3",
    ),
    local(
        "der(command_delay_pade_4)",
        me_vr::PADE_DERIVATIVES[3],
        "V/s",
        "rate of command_delay_pade_4",
    ),
    local(
        "der(command_delay_pade_5)",
        me_vr::PADE_DERIVATIVES[4],
        "V/s",
        "rate of command_delay_pade_5",
    ),
    local(
        "der(command_delay_pade_6)",
        me_vr::PADE_DERIVATIVES[5],
        "V/s",
        "rate of command_delay_pade_6",
    ),
    local(
        "der(command_delay_pade_7)",
        me_vr::PADE_DERIVATIVES[6],
        "V/s",
        "rate of command_delay_pade_7",
    ),
    local(
        "der(command_delay_pade_8)",
        me_vr::PADE_DERIVATIVES[7],
        "V/s",
        "rate of command_delay_pade_8",
    ),
];

/// The states' value references in the order of the state vector, with their derivatives'.
pub const CONTINUOUS_STATES: [fmi2::model::ContinuousState; 31] = [
    state(vr::I, me_vr::DER_I),
    state(vr::X_JP, me_vr::DER_X_JP),
    state(me_vr::X_JP_VELOCITY, me_vr::DER_X_JP_VELOCITY),
    state(me_vr::X_JP_ACCELERATION, me_vr::DER_X_JP_ACCELERATION),
    state(me_vr::P1_AT_MID_STROKE, me_vr::DER_P1),
    state(me_vr::P2_AT_MID_STROKE, me_vr::DER_P2),
    state(me_vr::P_SUPPLY_PLENUM, me_vr::DER_P_SUPPLY_PLENUM),
    state(me_vr::P_RETURN_PLENUM, me_vr::DER_P_RETURN_PLENUM),
    state(me_vr::P_PORT_LINE_1, me_vr::DER_P_PORT_LINE_1),
    state(me_vr::P_PORT_LINE_2, me_vr::DER_P_PORT_LINE_2),
    state(me_vr::STOPPER_MOUNT_LOAD, me_vr::DER_STOPPER_MOUNT_LOAD),
    state(me_vr::FILTER_STATES[0], me_vr::FILTER_DERIVATIVES[0]),
    state(me_vr::FILTER_STATES[1], me_vr::FILTER_DERIVATIVES[1]),
    state(me_vr::FILTER_STATES[2], me_vr::FILTER_DERIVATIVES[2]),
    state(me_vr::FILTER_STATES[3], me_vr::FILTER_DERIVATIVES[3]),
    state(me_vr::FILTER_STATES[4], me_vr::FILTER_DERIVATIVES[4]),
    state(me_vr::FILTER_STATES[5], me_vr::FILTER_DERIVATIVES[5]),
    state(me_vr::FILTER_STATES[6], me_vr::FILTER_DERIVATIVES[6]),
    state(me_vr::FILTER_STATES[7], me_vr::FILTER_DERIVATIVES[7]),
    state(me_vr::FILTER_STATES[8], me_vr::FILTER_DERIVATIVES[8]),
    state(me_vr::FILTER_STATES[9], me_vr::FILTER_DERIVATIVES[9]),
    state(me_vr::FILTER_STATES[10], me_vr::FILTER_DERIVATIVES[10]),
    state(me_vr::FILTER_STATES[11], me_vr::FILTER_DERIVATIVES[11]),
    state(me_vr::PADE_STATES[0], me_vr::PADE_DERIVATIVES[0]),
    state(me_vr::PADE_STATES[1], me_vr::PADE_DERIVATIVES[1]),
    state(me_vr::PADE_STATES[2], me_vr::PADE_DERIVATIVES[2]),
    state(me_vr::PADE_STATES[3], me_vr::PADE_DERIVATIVES[3]),
    state(me_vr::PADE_STATES[4], me_vr::PADE_DERIVATIVES[4]),
    state(me_vr::PADE_STATES[5], me_vr::PADE_DERIVATIVES[5]),
    state(me_vr::PADE_STATES[6], me_vr::PADE_DERIVATIVES[6]),
    state(me_vr::PADE_STATES[7], me_vr::PADE_DERIVATIVES[7]),
];

const fn state(state: u32, derivative: u32) -> fmi2::model::ContinuousState {
    fmi2::model::ContinuousState { state, derivative }
}

const N_TABLE: usize = TABLE.len();
const N_VARIABLES: usize = N_TABLE + MODEL_EXCHANGE_VARIABLES.len();

const fn variables_of(rows: &[Row]) -> [Variable; N_VARIABLES] {
    let mut out = [fmi_variable(&rows[0]); N_VARIABLES];
    let mut k = 1;
    while k < N_TABLE {
        out[k] = fmi_variable(&rows[k]);
        k += 1;
    }
    while k < N_VARIABLES {
        out[k] = MODEL_EXCHANGE_VARIABLES[k - N_TABLE];
        k += 1;
    }
    out
}

// A const, not a static, so that `VARIABLES` below stays a const slice; it is built at compile
// time once.
#[allow(clippy::large_const_arrays)]
const VARIABLE_ARRAY: [Variable; N_VARIABLES] = variables_of(TABLE);

/// The FMI variables of the table, in its order, then those of Model Exchange: what the model
/// description, the getters and the setters of the FMI layer see.
pub const VARIABLES: &[Variable] = &VARIABLE_ARRAY;

#[cfg(test)]
mod tests {
    use super::*;
    use fmi2::model::{CoSimModel, ModelInfo};
    use fmi2::model_description::try_model_description_xml;
    use fmi2::testing::{clone_info, DummyModel as M};

    #[test]
    fn the_fmi_variables_are_the_table_rows() {
        assert_eq!(VARIABLES.len(), TABLE.len() + MODEL_EXCHANGE_VARIABLES.len());
        assert!(VARIABLES[TABLE.len()..]
            .iter()
            .zip(&MODEL_EXCHANGE_VARIABLES)
            .all(|(a, b)| a.value_reference == b.value_reference && a.name == b.name));
        for (v, row) in VARIABLES.iter().zip(TABLE) {
            let r = &row.variable;
            assert_eq!(
                (v.name, v.value_reference, v.unit, v.description),
                (r.name, r.value_reference, r.unit, r.description)
            );
            assert_eq!((v.start.to_bits(), v.min, v.max), (r.start.to_bits(), r.min, r.max));
            assert_eq!(
                format!("{:?}", (v.var_type, v.causality, v.variability)),
                format!("{:?}", (r.var_type, r.causality, r.variability))
            );
        }
    }

    #[test]
    fn model_description_of_the_actuator_table() {
        let info = ModelInfo {
            variables: VARIABLES,
            units: UNITS,
            extent: crate::fmu::extent,
            dependencies: crate::fmu::DEPENDENCIES,
            ..clone_info(M::info())
        };
        let xml = try_model_description_xml(&info).unwrap();
        assert!(xml.contains(r#"<ScalarVariable name="P_s" valueReference="100""#));
        assert!(xml.contains(r#"start="652925.0""#));
        assert!(xml.contains(r#"<Unit name="Pa">"#) && xml.contains(r#"<BaseUnit kg="1" m="-1" s="-2"/>"#));
        let outputs: Vec<usize> = info
            .variables
            .iter()
            .enumerate()
            .filter(|(_, v)| v.causality == Causality::Output)
            .map(|(i, _)| i + 1)
            .collect();
        assert_eq!(
            outputs,
            vec![4, 5, 6, 7, 8, 9, 10, 11],
            "F_act, P1, P2, i, F_meas, P1_meas, P2_meas, x_jp"
        );
        for i in outputs {
            assert_eq!(
                xml.matches(&format!(r#"<Unknown index="{i}" dependencies="#)).count(),
                2
            );
        }
        // Within a step only x_s (index 2) acts, on the forces and the pressures as they are
        // and as read, and a_s (index 3) on the forces; i and x_jp on nothing.
        for i in [4, 8] {
            assert!(xml.contains(&format!(
                r#"<Unknown index="{i}" dependencies="2 3" dependenciesKind="dependent dependent"/>"#
            )));
        }
        for i in [5, 6, 9, 10] {
            assert!(xml.contains(&format!(
                r#"<Unknown index="{i}" dependencies="2" dependenciesKind="dependent"/>"#
            )));
        }
        for i in [7, 11] {
            assert!(xml.contains(&format!(
                r#"<Unknown index="{i}" dependencies="" dependenciesKind=""/>"#
            )));
        }
        assert!(
            xml.contains(r#"<Real unit="m" start="0.054" min="0.026" max="0.096" nominal="0.054"/>"#),
            "{xml}"
        );
        assert!(xml.contains(r#"<Real unit="1" start="0.696" min="0.0" max="1.0" nominal="0.696"/>"#));
    }
}
