//! The FMU's variable table: one row per variable. The model description, the getters
//! and the setters all come from here, so they cannot drift apart.

use crate::fmi2::model::{Causality, UnitDefinition, VarType, Variability, Variable};

/// Value references, named so code never uses bare numbers.
pub mod vr {
    pub const V_DA: u32 = 1;
    pub const X_S: u32 = 2;

    pub const F_ACT: u32 = 10;
    pub const P1: u32 = 11;
    pub const P2: u32 = 12;
    pub const I: u32 = 13;
    pub const X_JP: u32 = 14;
    pub const F_MEAS: u32 = 15;

    pub const P_S: u32 = 100;
    pub const P_R: u32 = 101;
    pub const T_GAS: u32 = 102;
    pub const GAMMA: u32 = 103;
    pub const R_GAS: u32 = 104;
    pub const K_CD: u32 = 110;
    pub const I_OFFSET: u32 = 111;
    pub const OMEGA_CD: u32 = 112;
    pub const K_M: u32 = 120;
    pub const OMEGA_1: u32 = 121;
    pub const OMEGA_2: u32 = 122;
    pub const ZETA_2: u32 = 123;
    pub const X_JP_SAT: u32 = 124;
    pub const F_JP_SAT: u32 = 125;
    pub const X_JP_OFFSET: u32 = 126;
    pub const D_JP: u32 = 130;
    pub const C_D: u32 = 131;
    pub const C_DM_A_LPP: u32 = 132;
    pub const C_DB_A_LPP: u32 = 133;
    pub const L_CYL: u32 = 140;
    pub const L_P: u32 = 141;
    pub const L_S: u32 = 142;
    pub const L_SUP: u32 = 143;
    pub const L_SPRING0: u32 = 144;
    pub const D_CYL: u32 = 145;
    pub const K_SPRING: u32 = 146;

    pub const START_AT_EQUILIBRIUM: u32 = 200;
    pub const P1_START: u32 = 201;
    pub const P2_START: u32 = 202;

    // Effects the thesis model lacks (MODEL.md), all off at their start values.
    pub const HYSTERESIS_WIDTH: u32 = 300;
    pub const HYSTERESIS_DEADBAND: u32 = 301;
    pub const FRICTION_COULOMB: u32 = 310;
    pub const FRICTION_VELOCITY: u32 = 311;
    pub const DEAD_VOLUME_1: u32 = 320;
    pub const DEAD_VOLUME_2: u32 = 321;
    pub const SUPPLY_RESISTANCE: u32 = 330;
    pub const HEAT_TRANSFER_FRACTION: u32 = 340;
    pub const COMMAND_DELAY: u32 = 350;
    pub const FORCE_SENSOR_OFFSET: u32 = 360;
    pub const FORCE_SENSOR_GAIN: u32 = 361;

    // Generic correction terms of the diagnosis (docs/model.md), all off at their start values.
    pub const SUPPLY_AREA_SCALE_1: u32 = 400;
    pub const SUPPLY_AREA_SCALE_2: u32 = 401;
    pub const RETURN_AREA_SCALE_1: u32 = 402;
    pub const RETURN_AREA_SCALE_2: u32 = 403;
    pub const RETURN_RESISTANCE: u32 = 410;
    pub const CHAMBER_VENT_1: u32 = 420;
    pub const CHAMBER_VENT_2: u32 = 421;
    pub const PORT_RESISTANCE_1: u32 = 430;
    pub const PORT_RESISTANCE_2: u32 = 431;
    pub const STOPPER_COMPLIANCE: u32 = 440;
    pub const COMMAND_LAG: u32 = 450;
    pub const COMMAND_LIMIT: u32 = 451;
    pub const CURRENT_LIMIT: u32 = 452;
    pub const CURRENT_SLEW_LIMIT: u32 = 453;
    pub const F3_INPUT_CUBIC: u32 = 454;
    pub const FORCE_SENSOR_QUADRATIC: u32 = 460;
    pub const FORCE_SENSOR_CUBIC: u32 = 461;
    pub const FORCE_SENSOR_DRIFT: u32 = 462;
    pub const FORCE_SENSOR_LAG: u32 = 463;
    pub const FORCE_SENSOR_DELAY: u32 = 464;
    pub const FORCE_SENSOR_PLAY: u32 = 465;
    pub const FORCE_SENSOR_RIPPLE_SINE: u32 = 466;
    pub const FORCE_SENSOR_RIPPLE_FREQUENCY: u32 = 467;
    pub const FORCE_SENSOR_RIPPLE_COSINE: u32 = 468;
    pub const VISCOUS_FRICTION: u32 = 470;
    pub const POSITION_FORCE_RATE: u32 = 471;
    pub const POSITION_FORCE_REFERENCE: u32 = 472;
    pub const RETURN_VENT_AREA: u32 = 480;
    pub const SUPPLY_DRIFT: u32 = 490;
    pub const SUPPLY_RIPPLE_SINE: u32 = 491;
    pub const SUPPLY_RIPPLE_FREQUENCY: u32 = 492;
    pub const SUPPLY_RIPPLE_COSINE: u32 = 493;
    pub const X_JP_OFFSET_DRIFT: u32 = 494;
}

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
];

const fn input(name: &'static str, vr: u32, unit: &'static str, start: f64, description: &'static str) -> Variable {
    Variable {
        name,
        value_reference: vr,
        var_type: VarType::Real,
        causality: Causality::Input,
        variability: Variability::Continuous,
        unit: Some(unit),
        start,
        min: None,
        max: None,
        description,
    }
}

const fn output(name: &'static str, vr: u32, unit: &'static str, description: &'static str) -> Variable {
    Variable {
        name,
        value_reference: vr,
        var_type: VarType::Real,
        causality: Causality::Output,
        variability: Variability::Continuous,
        unit: Some(unit),
        start: 0.0,
        min: None,
        max: None,
        description,
    }
}

const fn parameter(name: &'static str, vr: u32, unit: &'static str, start: f64, description: &'static str) -> Variable {
    Variable {
        name,
        value_reference: vr,
        var_type: VarType::Real,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: Some(unit),
        start,
        min: None,
        max: None,
        description,
    }
}

/// Every variable of the FMU. Defaults: Table 3.1 of the thesis and MODEL.md.
pub const VARIABLES: &[Variable] = &[
    input("v_DA", vr::V_DA, "V", 0.0, "D/A command voltage to the current driver"),
    input(
        "x_s",
        vr::X_S,
        "m",
        0.054,
        "rod stopper position (valid while both chamber volumes are positive)",
    ),
    output("F_act", vr::F_ACT, "N", "actuator (tendon) force, (2.36)-(2.38)"),
    output("P1", vr::P1, "Pa", "absolute pressure of chamber 1 (charging side)"),
    output("P2", vr::P2, "Pa", "absolute pressure of chamber 2 (venting side)"),
        output("i", vr::I, "A", "coil current"),
    output("F_meas", vr::F_MEAS, "N", "force as the force sensor reads it: F_act unless the force_sensor_* parameters give it an offset, gain, curve, drift, pick-up, delay, lag or play"),
    output(
        "x_jp",
        vr::X_JP,
        "m",
        "jet pipe tip position relative to rest, before the offset",
    ),
    parameter(
        "P_s",
        vr::P_S,
        "Pa",
        652_925.0,
        "supply pressure, absolute (551.6 kPa gauge)",
    ),
    parameter("P_r", vr::P_R, "Pa", 101_325.0, "return pressure, absolute"),
    parameter("T", vr::T_GAS, "K", 293.15, "gas temperature, constant (2.6)"),
    parameter("gamma", vr::GAMMA, "1", 1.4, "isentropic exponent of air"),
    parameter("R_gas", vr::R_GAS, "J/(kg.K)", 287.0, "gas constant of air"),
    parameter("k_cd", vr::K_CD, "A/V", 0.04, "current driver gain (2.3)"),
    parameter("i_offset", vr::I_OFFSET, "A", 0.0, "current driver offset (2.3)"),
    parameter(
        "omega_cd",
        vr::OMEGA_CD,
        "rad/s",
        7050.0,
        "current driver corner frequency (2.1)",
    ),
    parameter("k_m", vr::K_M, "N/A", 1.946, "jet pipe motor constant (2.4)"),
    parameter(
        "omega_1",
        vr::OMEGA_1,
        "rad/s",
        973.9,
        "jet pipe first-order corner (2.6)",
    ),
    parameter(
        "omega_2",
        vr::OMEGA_2,
        "rad/s",
        1856.7,
        "jet pipe natural frequency (2.6)",
    ),
    parameter("zeta_2", vr::ZETA_2, "1", 0.019, "jet pipe damping ratio (2.6)"),
    parameter(
        "x_jp_sat",
        vr::X_JP_SAT,
        "m",
        0.5e-3,
        "saturation of the static jet pipe curve f3 (2.5)",
    ),
    parameter(
        "F_jp_sat",
        vr::F_JP_SAT,
        "N",
        0.45,
        "force scale of the static jet pipe curve f3 (2.5)",
    ),
    parameter(
        "x_jp_offset",
        vr::X_JP_OFFSET,
        "m",
        0.099e-3,
        "jet pipe offset from the receiver centre (2.7)",
    ),
    parameter(
        "D_jp",
        vr::D_JP,
        "m",
        0.9652e-3,
        "jet pipe exit and port diameter (2.5)",
    ),
    parameter("C_d", vr::C_D, "1", 0.696, "orifice discharge coefficient (2.18)"),
    parameter(
        "C_dm_A_lpp",
        vr::C_DM_A_LPP,
        "m2",
        -0.0475e-6,
        "leakage discharge slope times area (2.23)",
    ),
    parameter(
        "C_db_A_lpp",
        vr::C_DB_A_LPP,
        "m2",
        0.0971e-6,
        "leakage discharge offset times area (2.23)",
    ),
    parameter("L_cyl", vr::L_CYL, "m", 78.0e-3, "cylinder length"),
    parameter("L_p", vr::L_P, "m", 8.0e-3, "piston length"),
    parameter("L_s", vr::L_S, "m", 7.0e-3, "stopper length"),
    parameter("L_sup", vr::L_SUP, "m", 11.0e-3, "support length"),
    parameter(
        "L_spring0",
        vr::L_SPRING0,
        "m",
        69.1e-3,
        "unloaded spring length (2.37)",
    ),
    parameter("D_cyl", vr::D_CYL, "m", 15.875e-3, "cylinder bore"),
    parameter("k_spring", vr::K_SPRING, "N/m", 88.14, "spring rate (2.37)"),
    Variable {
        name: "start_at_equilibrium",
        value_reference: vr::START_AT_EQUILIBRIUM,
        var_type: VarType::Boolean,
        causality: Causality::Parameter,
        variability: Variability::Fixed,
        unit: None,
        start: 1.0,
        min: None,
        max: None,
        description: "initialise at the equilibrium of the initial inputs; if false, start from P1_start and P2_start",
    },
    parameter(
        "P1_start",
        vr::P1_START,
        "Pa",
        101_325.0,
        "initial P1 when start_at_equilibrium is false",
    ),
    parameter(
        "P2_start",
        vr::P2_START,
        "Pa",
        101_325.0,
        "initial P2 when start_at_equilibrium is false"),
    parameter("hysteresis_width", vr::HYSTERESIS_WIDTH, "m", 0.0, "jet_pipe_hysteresis: separation of the rising and falling branches of the static tip position in large sweeps (Prandtl-Ishlinskii operator after f3; 0 = off)"),
        parameter("hysteresis_deadband", vr::HYSTERESIS_DEADBAND, "m", 0.0, "jet_pipe_hysteresis: travel of the static tip position after a reversal before the hysteretic output moves (smallest play width, at most hysteresis_width)"),
    parameter("friction_coulomb", vr::FRICTION_COULOMB, "N", 0.0, "piston_friction: Coulomb friction opposing stopper motion, (2.35) (0 = off)"),
    parameter("friction_velocity", vr::FRICTION_VELOCITY, "m/s", 0.0, "piston_friction: the friction reaches the Coulomb level as tanh(v / this) of the stopper velocity v (0 = at once, as (2.35))"),
    parameter("dead_volume_1", vr::DEAD_VOLUME_1, "m3", 0.0, "dead_volume: port and line volume added to chamber 1 (0 = off)"),
    parameter("dead_volume_2", vr::DEAD_VOLUME_2, "m3", 0.0, "dead_volume: port and line volume added to chamber 2 (0 = off)"),
    parameter("supply_resistance", vr::SUPPLY_RESISTANCE, "Pa.s/kg", 0.0, "supply_pressure_drop: the supply pressure at the jet pipe falls by this times the supply mass flow (0 = off)"),
    parameter("heat_transfer_fraction", vr::HEAT_TRANSFER_FRACTION, "1", 0.0, "heat_transfer: chambers polytropic with n = gamma - fraction*(gamma - 1): 0 adiabatic as the thesis, 1 isothermal"),
    parameter("command_delay", vr::COMMAND_DELAY, "s", 0.0, "transport_delay: the current driver sees v_DA delayed by this time (0 = off)"),
    parameter("force_sensor_offset", vr::FORCE_SENSOR_OFFSET, "N", 0.0, "sensor_offset_gain: offset of F_meas (0 = off)"),
    parameter("force_sensor_gain", vr::FORCE_SENSOR_GAIN, "1", 1.0, "sensor_offset_gain: gain of F_meas (1 = off)"),
    parameter("supply_area_scale_1", vr::SUPPLY_AREA_SCALE_1, "1", 1.0, "valve asymmetry: factor on the supply orifice area of port 1 (1 = the geometry of (2.8)-(2.17))"),
    parameter("supply_area_scale_2", vr::SUPPLY_AREA_SCALE_2, "1", 1.0, "valve asymmetry: factor on the supply orifice area of port 2 (1 = the geometry)"),
    parameter("return_area_scale_1", vr::RETURN_AREA_SCALE_1, "1", 1.0, "valve asymmetry: factor on the return orifice area of port 1 (1 = the geometry)"),
    parameter("return_area_scale_2", vr::RETURN_AREA_SCALE_2, "1", 1.0, "valve asymmetry: factor on the return orifice area of port 2 (1 = the geometry)"),
    parameter("return_resistance", vr::RETURN_RESISTANCE, "Pa.s/kg", 0.0, "return restriction: the pressure the return orifices vent into rises above P_r by this times the return mass flow (0 = off)"),
    parameter("chamber_vent_1", vr::CHAMBER_VENT_1, "m2", 0.0, "chamber leak: discharge coefficient times area of a leak from chamber 1 to the return pressure (0 = off)"),
    parameter("chamber_vent_2", vr::CHAMBER_VENT_2, "m2", 0.0, "chamber leak: discharge coefficient times area of a leak from chamber 2 to the return pressure (0 = off)"),
    parameter("port_resistance_1", vr::PORT_RESISTANCE_1, "Pa.s/kg", 0.0, "port restriction: the orifices of port 1 see a pressure that differs from chamber 1's by this times the net flow through the port (0 = off)"),
    parameter("port_resistance_2", vr::PORT_RESISTANCE_2, "Pa.s/kg", 0.0, "port restriction: the orifices of port 2 see a pressure that differs from chamber 2's by this times the net flow through the port (0 = off)"),
    parameter("stopper_compliance", vr::STOPPER_COMPLIANCE, "m/N", 0.0, "compliance between stopper and piston: the piston sits this times A_p (P1 - P2) beyond the stopper, which moves the chamber volumes (0 = rigid)"),
    parameter("command_lag", vr::COMMAND_LAG, "s", 0.0, "command dynamics: the current driver sees v_DA through a first-order lag of this time constant, updated at each communication point with the command held over the step (0 = off)"),
    parameter("command_limit", vr::COMMAND_LIMIT, "V", 0.0, "command limit: the command the current driver sees saturates at plus or minus this (0 = off)"),
    parameter("current_limit", vr::CURRENT_LIMIT, "A", 0.0, "current limit: the coil current saturates at plus or minus this, applied to the command through k_cd and i_offset (0 = off)"),
    parameter("current_slew_limit", vr::CURRENT_SLEW_LIMIT, "A/s", 0.0, "current slew limit: the held command changes by at most this over k_cd per second between communication points (0 = off)"),
    parameter("f3_input_cubic", vr::F3_INPUT_CUBIC, "V", 0.0, "jet pipe static curve: the command reaching f3 is bent by this times (v_DA / 10 V)^3 (0 = off)"),
    parameter("force_sensor_quadratic", vr::FORCE_SENSOR_QUADRATIC, "1/N", 0.0, "force sensor curve: F_meas gains this times F_act^2 (0 = off)"),
    parameter("force_sensor_cubic", vr::FORCE_SENSOR_CUBIC, "1/N2", 0.0, "force sensor curve: F_meas gains this times F_act^3 (0 = off)"),
    parameter("force_sensor_drift", vr::FORCE_SENSOR_DRIFT, "N/s", 0.0, "force sensor drift: F_meas gains this times the time (0 = off)"),
    parameter("force_sensor_lag", vr::FORCE_SENSOR_LAG, "s", 0.0, "force sensor dynamics: F_meas follows the reading through a first-order lag of this time constant, the reading held between communication points (0 = off)"),
    parameter("force_sensor_delay", vr::FORCE_SENSOR_DELAY, "s", 0.0, "force sensor delay: F_meas is the reading this long ago, interpolated between communication points (0 = off)"),
    parameter("force_sensor_play", vr::FORCE_SENSOR_PLAY, "N", 0.0, "force sensor hysteresis: F_meas stays within half this of the reading, moving only when pushed (a play operator; 0 = off)"),
    parameter("force_sensor_ripple_sine", vr::FORCE_SENSOR_RIPPLE_SINE, "N", 0.0, "force sensor pick-up: F_meas gains this times sin(2 pi f t) (0 = off)"),
    parameter("force_sensor_ripple_frequency", vr::FORCE_SENSOR_RIPPLE_FREQUENCY, "Hz", 0.0, "force sensor pick-up: its frequency f"),
    parameter("force_sensor_ripple_cosine", vr::FORCE_SENSOR_RIPPLE_COSINE, "N", 0.0, "force sensor pick-up: F_meas gains this times cos(2 pi f t) (0 = off)"),
    parameter("viscous_friction", vr::VISCOUS_FRICTION, "N.s/m", 0.0, "viscous friction: a force of this times the stopper velocity opposes the motion where the pressures set the force (0 = off)"),
    parameter("position_force_rate", vr::POSITION_FORCE_RATE, "N/m", 0.0, "a force of this times (x_s - position_force_reference) opposes the stopper position where the pressures set the force (0 = off)"),
    parameter("position_force_reference", vr::POSITION_FORCE_REFERENCE, "m", 0.054, "where the position_force vanishes"),
    parameter("return_vent_area", vr::RETURN_VENT_AREA, "m2", 0.0, "return restriction: the return orifices vent into a plenum that empties to P_r through an orifice of this discharge coefficient times area, (2.18) (0 = off: the return orifices see P_r)"),
    parameter("supply_drift", vr::SUPPLY_DRIFT, "Pa/s", 0.0, "supply drift: the supply pressure is P_s plus this times the time, held over each communication step at its mid-step value (0 = off)"),
    parameter("supply_ripple_sine", vr::SUPPLY_RIPPLE_SINE, "Pa", 0.0, "supply ripple: the supply pressure gains this times sin(2 pi f t), held over each communication step at its mid-step value (0 = off)"),
    parameter("supply_ripple_frequency", vr::SUPPLY_RIPPLE_FREQUENCY, "Hz", 0.0, "supply ripple: its frequency f"),
    parameter("supply_ripple_cosine", vr::SUPPLY_RIPPLE_COSINE, "Pa", 0.0, "supply ripple: the supply pressure gains this times cos(2 pi f t), held likewise (0 = off)"),
    parameter("x_jp_offset_drift", vr::X_JP_OFFSET_DRIFT, "m/s", 0.0, "jet pipe null drift: x_jp_offset gains this times the time, held over each communication step at its mid-step value (0 = off)"),
];
