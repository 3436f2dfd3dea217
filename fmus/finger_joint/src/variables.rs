//! The FingerJoint FMU's variable table: the single source of its model description, getters
//! and setters.

use fmi2::model::{UnitDefinition, Variable};
use fmu_common::units;
use fmu_common::values::rows::{input, output, parameter, ANY, NON_NEGATIVE};

pub mod vr {
    pub const T_FLEXOR: u32 = 1;
    pub const T_EXTENSOR: u32 = 2;
    pub const TAU_EXT: u32 = 3;

    pub const THETA: u32 = 10;
    pub const OMEGA: u32 = 11;
    pub const X_FLEXOR: u32 = 12;
    pub const V_FLEXOR: u32 = 13;
    pub const X_EXTENSOR: u32 = 14;
    pub const V_EXTENSOR: u32 = 15;
    pub const TAU_TENDONS: u32 = 16;
    pub const TAU_LIMIT: u32 = 17;

    pub const J: u32 = 100;
    pub const B: u32 = 101;
    pub const R: u32 = 102;
    pub const THETA_MIN: u32 = 103;
    pub const THETA_MAX: u32 = 104;
    pub const K_LIMIT: u32 = 105;
    pub const C_LIMIT: u32 = 106;
    pub const THETA_START: u32 = 107;
    pub const OMEGA_START: u32 = 108;
    pub const MAX_SUBSTEP: u32 = 109;
}

pub const UNITS: &[UnitDefinition] = &[
    units::N,
    units::N_M,
    units::RAD,
    units::RAD_PER_S,
    units::M,
    units::M_PER_S,
    units::KG_M2,
    units::N_M_S_PER_RAD,
    units::N_M_PER_RAD,
    units::S,
];

pub const VARIABLES: &[Variable] = &[
    input(
        "T_flexor",
        vr::T_FLEXOR,
        "N",
        0.0,
        ANY,
        "tension of the flexor tendon at the joint (its T)",
    ),
    input(
        "T_extensor",
        vr::T_EXTENSOR,
        "N",
        0.0,
        ANY,
        "tension of the extensor tendon at the joint (its T)",
    ),
    input(
        "tau_ext",
        vr::TAU_EXT,
        "N.m",
        0.0,
        ANY,
        "external torque on the joint, positive flexing (a load or a contact)",
    ),
    output("theta", vr::THETA, "rad", "joint angle, positive flexing"),
    output("omega", vr::OMEGA, "rad/s", "joint angular velocity"),
    output(
        "x_flexor",
        vr::X_FLEXOR,
        "m",
        "flexor tendon excursion towards its actuator, r*theta (the flexor tendon's x_joint)",
    ),
    output("v_flexor", vr::V_FLEXOR, "m/s", "rate of x_flexor, r*omega"),
    output(
        "x_extensor",
        vr::X_EXTENSOR,
        "m",
        "extensor tendon excursion towards its actuator, -r*theta (the extensor tendon's x_joint)",
    ),
    output("v_extensor", vr::V_EXTENSOR, "m/s", "rate of x_extensor, -r*omega"),
    output(
        "tau_tendons",
        vr::TAU_TENDONS,
        "N.m",
        "torque of the tendons, r*(T_flexor - T_extensor), with the inputs of the last step",
    ),
    output(
        "tau_limit",
        vr::TAU_LIMIT,
        "N.m",
        "torque of the joint stops (0 inside the range)",
    ),
    parameter(
        "J",
        vr::J,
        "kg.m2",
        2.0e-4,
        NON_NEGATIVE,
        "inertia of the distal finger about the joint (> 0): ~0.1 kg of links at ~4 cm",
    ),
    parameter(
        "b",
        vr::B,
        "N.m.s/rad",
        2.0e-3,
        NON_NEGATIVE,
        "viscous damping of the joint",
    ),
    parameter(
        "r",
        vr::R,
        "m",
        0.01,
        NON_NEGATIVE,
        "pulley radius, the moment arm of both tendons (> 0)",
    ),
    parameter(
        "theta_min",
        vr::THETA_MIN,
        "rad",
        -0.3,
        ANY,
        "lower joint stop (extension)",
    ),
    parameter(
        "theta_max",
        vr::THETA_MAX,
        "rad",
        1.6,
        ANY,
        "upper joint stop (flexion)",
    ),
    parameter(
        "k_limit",
        vr::K_LIMIT,
        "N.m/rad",
        20.0,
        NON_NEGATIVE,
        "stiffness of the joint stops",
    ),
    parameter(
        "c_limit",
        vr::C_LIMIT,
        "N.m.s/rad",
        0.05,
        NON_NEGATIVE,
        "damping of the joint stops (acts only while in contact and pushing)",
    ),
    parameter("theta_start", vr::THETA_START, "rad", 0.0, ANY, "initial joint angle"),
    parameter(
        "omega_start",
        vr::OMEGA_START,
        "rad/s",
        0.0,
        ANY,
        "initial joint velocity",
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
