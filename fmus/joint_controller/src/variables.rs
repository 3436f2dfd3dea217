//! The JointController FMU's variable table: the single source of its model description,
//! getters and setters.

use fmi2::model::{UnitDefinition, Variable};
use fmu_common::units;
use fmu_common::values::rows::{input, output, parameter, ANY, NON_NEGATIVE};

pub mod vr {
    pub const THETA_REF: u32 = 1;
    pub const THETA: u32 = 2;
    pub const OMEGA: u32 = 3;
    pub const F_FLEXOR: u32 = 4;
    pub const F_EXTENSOR: u32 = 5;

    pub const V_DA_FLEXOR: u32 = 10;
    pub const V_DA_EXTENSOR: u32 = 11;
    pub const T_FLEXOR_REF: u32 = 12;
    pub const T_EXTENSOR_REF: u32 = 13;
    pub const TAU_REF: u32 = 14;

    pub const R: u32 = 100;
    pub const T_CO: u32 = 101;
    pub const T_MIN: u32 = 102;
    pub const T_MAX: u32 = 103;
    pub const KP: u32 = 104;
    pub const KI: u32 = 105;
    pub const KD: u32 = 106;
    pub const TAU_I_MAX: u32 = 107;
    pub const K_F: u32 = 108;
    pub const K_FF: u32 = 109;
    pub const V_MIN: u32 = 110;
    pub const V_MAX: u32 = 111;
    pub const THETA_STEP: u32 = 120;
    pub const T_STEP: u32 = 121;
}

pub const UNITS: &[UnitDefinition] = &[
    units::RAD,
    units::RAD_PER_S,
    units::N,
    units::V,
    units::N_M,
    units::M,
    units::N_M_PER_RAD,
    units::N_M_PER_RAD_S,
    units::N_M_S_PER_RAD,
    units::V_PER_N,
    units::ONE,
    units::S,
];

pub const VARIABLES: &[Variable] = &[
    input("theta_ref", vr::THETA_REF, "rad", 0.0, ANY, "joint angle reference"),
    input(
        "theta",
        vr::THETA,
        "rad",
        0.0,
        ANY,
        "measured joint angle (the joint's theta)",
    ),
    input(
        "omega",
        vr::OMEGA,
        "rad/s",
        0.0,
        ANY,
        "measured joint velocity (the joint's omega), for the derivative term",
    ),
    input(
        "F_flexor",
        vr::F_FLEXOR,
        "N",
        25.0,
        ANY,
        "measured force of the flexor actuator (its F_meas); start: the default co-contraction",
    ),
    input(
        "F_extensor",
        vr::F_EXTENSOR,
        "N",
        25.0,
        ANY,
        "measured force of the extensor actuator (its F_meas); start: the default co-contraction",
    ),
    output(
        "v_DA_flexor",
        vr::V_DA_FLEXOR,
        "V",
        "command of the flexor actuator (its v_DA)",
    ),
    output(
        "v_DA_extensor",
        vr::V_DA_EXTENSOR,
        "V",
        "command of the extensor actuator (its v_DA)",
    ),
    output(
        "T_flexor_ref",
        vr::T_FLEXOR_REF,
        "N",
        "flexor tension asked of the force loop, in [T_min, T_max]",
    ),
    output(
        "T_extensor_ref",
        vr::T_EXTENSOR_REF,
        "N",
        "extensor tension asked of the force loop, in [T_min, T_max]",
    ),
    output("tau_ref", vr::TAU_REF, "N.m", "joint torque asked by the position loop"),
    parameter(
        "r",
        vr::R,
        "m",
        0.01,
        NON_NEGATIVE,
        "pulley radius of the joint (> 0; must equal the joint's r)",
    ),
    parameter(
        "T_co",
        vr::T_CO,
        "N",
        25.0,
        NON_NEGATIVE,
        "co-contraction: both tensions at zero torque",
    ),
    parameter(
        "T_min",
        vr::T_MIN,
        "N",
        8.0,
        NON_NEGATIVE,
        "least tension asked of either tendon (> 0, keeps them from going slack)",
    ),
    parameter(
        "T_max",
        vr::T_MAX,
        "N",
        85.0,
        NON_NEGATIVE,
        "most tension asked of either tendon (the actuator saturates at 92.9 N)",
    ),
    parameter(
        "Kp",
        vr::KP,
        "N.m/rad",
        0.8,
        NON_NEGATIVE,
        "proportional gain of the angle loop",
    ),
    parameter(
        "Ki",
        vr::KI,
        "N.m/(rad.s)",
        2.0,
        NON_NEGATIVE,
        "integral gain of the angle loop (removes the offset of pulley friction)",
    ),
    parameter(
        "Kd",
        vr::KD,
        "N.m.s/rad",
        0.015,
        NON_NEGATIVE,
        "derivative gain of the angle loop, on the measured velocity",
    ),
    parameter(
        "tau_i_max",
        vr::TAU_I_MAX,
        "N.m",
        0.2,
        NON_NEGATIVE,
        "clamp of the integral term (anti-windup)",
    ),
    parameter(
        "K_F",
        vr::K_F,
        "V/N",
        1.1,
        NON_NEGATIVE,
        "force-loop gain: the thesis's k_p = 0.044 A/N over the driver's 0.04 A/V",
    ),
    parameter(
        "k_feedforward",
        vr::K_FF,
        "1",
        1.0,
        (Some(0.0), Some(1.0)),
        "weight of the inverse static force map in the command (1: on, 0: off)",
    ),
    parameter("v_min", vr::V_MIN, "V", -10.0, ANY, "lower limit of the D/A command"),
    parameter("v_max", vr::V_MAX, "V", 10.0, ANY, "upper limit of the D/A command"),
    parameter(
        "theta_step",
        vr::THETA_STEP,
        "rad",
        0.0,
        ANY,
        "a step added to theta_ref from t_step on (0: none), for masters that cannot drive an input",
    ),
    parameter(
        "t_step",
        vr::T_STEP,
        "s",
        0.0,
        ANY,
        "time of the theta_step (the first step that starts at or after it sees it)",
    ),
];
