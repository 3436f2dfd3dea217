//! The Tendon FMU's variable table: the single source of its model description, getters and
//! setters. Defaults: see the parameter descriptions (values chosen for the Utah/MIT hand's
//! tendon path where the thesis gives none; the README's co-simulation section says which).

use fmi2::model::{Causality, UnitDefinition, VarType, Variability, Variable};
use fmu_common::units;
use fmu_common::values::rows::{input, output, parameter, ANY, NON_NEGATIVE};

pub mod vr {
    pub const F_ACT: u32 = 1;
    pub const X_JOINT: u32 = 2;
    pub const V_JOINT: u32 = 3;

    pub const T: u32 = 10;
    pub const T_ROD: u32 = 11;
    pub const X_S: u32 = 12;
    pub const V_ROD: u32 = 13;
    pub const STRETCH: u32 = 14;
    pub const SLACK_TIME: u32 = 15;
    pub const SLACK: u32 = 16;

    pub const M_ROD: u32 = 100;
    pub const C_ROD: u32 = 101;
    pub const K: u32 = 102;
    pub const C: u32 = 103;
    pub const CAPSTAN: u32 = 104;
    pub const V_FRICTION: u32 = 105;
    pub const X_S0: u32 = 106;
    pub const X_S_MIN: u32 = 107;
    pub const X_S_MAX: u32 = 108;
    pub const MAX_SUBSTEP: u32 = 109;
}

pub const UNITS: &[UnitDefinition] = &[
    units::N,
    units::M,
    units::M_PER_S,
    units::KG,
    units::N_PER_M,
    units::N_S_PER_M,
    units::ONE,
    units::S,
];

/// The actuator's stopper range with the thesis geometry (docs/model.md: 0.026 < x_s < 0.096).
const STROKE: (Option<f64>, Option<f64>) = (Some(0.026), Some(0.096));

pub const VARIABLES: &[Variable] = &[
    input(
        "F_act",
        vr::F_ACT,
        "N",
        0.0,
        ANY,
        "force of the actuator on the rod, pulling (the actuator's F_act)",
    ),
    input(
        "x_joint",
        vr::X_JOINT,
        "m",
        0.0,
        ANY,
        "tendon excursion at the joint, positive towards the actuator (the joint's x_flexor or x_extensor)",
    ),
    input(
        "v_joint",
        vr::V_JOINT,
        "m/s",
        0.0,
        ANY,
        "rate of x_joint; the joint end moves linearly over each step with it",
    ),
    output("T", vr::T, "N", "tension at the joint end, >= 0 (0 while slack)"),
    output(
        "T_rod",
        vr::T_ROD,
        "N",
        "tension at the rod: T times the capstan factor exp(capstan*tanh(v_rod/v_friction))",
    ),
    output(
        "x_s",
        vr::X_S,
        "m",
        "stopper position for the actuator: x_s0 + rod displacement, within [x_s_min, x_s_max]",
    ),
    output("v_rod", vr::V_ROD, "m/s", "rod velocity, positive pulling in"),
    output(
        "stretch",
        vr::STRETCH,
        "m",
        "rod displacement minus joint-end excursion (tendon slack when <= 0)",
    ),
    output(
        "slack_time",
        vr::SLACK_TIME,
        "s",
        "total time the tendon has been slack since initialisation (summed over internal substeps)",
    ),
    Variable {
        name: "slack",
        value_reference: vr::SLACK,
        var_type: VarType::Boolean,
        causality: Causality::Output,
        variability: Variability::Discrete,
        unit: None,
        start: 0.0,
        min: None,
        max: None,
        description: "true while the tendon carries no tension",
    },
    parameter(
        "m_rod",
        vr::M_ROD,
        "kg",
        0.05,
        NON_NEGATIVE,
        "mass of piston, rod and stopper lumped at the actuator end (> 0)",
    ),
    parameter(
        "c_rod",
        vr::C_ROD,
        "N.s/m",
        5.0,
        NON_NEGATIVE,
        "viscous friction of the piston seal and rod bushing",
    ),
    parameter(
        "k",
        vr::K,
        "N/m",
        2.0e4,
        NON_NEGATIVE,
        "tendon stiffness from rod to joint (> 0); 2e4 N/m: a polymer tendon of ~1 mm2 over the remotizer's ~0.5 m",
    ),
    parameter("c", vr::C, "N.s/m", 10.0, NON_NEGATIVE, "tendon damping"),
    parameter(
        "capstan",
        vr::CAPSTAN,
        "1",
        0.02,
        NON_NEGATIVE,
        "capstan exponent mu*beta of the pulleys (Euler-Eytelwein): sliding changes the tension by exp(+-capstan), 2 % by default",
    ),
    parameter(
        "v_friction",
        vr::V_FRICTION,
        "m/s",
        2.0e-3,
        NON_NEGATIVE,
        "velocity scale of the smoothed friction sign tanh(v/v_friction) (> 0)",
    ),
    parameter(
        "x_s0",
        vr::X_S0,
        "m",
        0.054,
        STROKE,
        "stopper position when the rod is at its nominal position (the thesis's mid-stroke 54 mm)",
    ),
    parameter(
        "x_s_min",
        vr::X_S_MIN,
        "m",
        0.030,
        STROKE,
        "rod stroke end (as stopper position): the rod stops here inelastically",
    ),
    parameter(
        "x_s_max",
        vr::X_S_MAX,
        "m",
        0.090,
        STROKE,
        "rod stroke end (as stopper position): the rod stops here inelastically",
    ),
    parameter(
        "max_substep",
        vr::MAX_SUBSTEP,
        "s",
        5.0e-5,
        (Some(1e-7), Some(1e-2)),
        "largest internal implicit-Euler substep",
    ),
];
