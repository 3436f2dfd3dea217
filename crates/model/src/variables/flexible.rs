//! The rows of the three plain constants that give every place of the chain an additive
//! constant (`extra_force_offset`, `extra_inflow_1`, `extra_inflow_2`). Kept apart from the
//! rest of the table only for the length of `variables.rs`; [`super::TABLE`] holds them after
//! the extra flow slots.

use super::{parameter, Row};

/// Value references of the constants.
pub mod vr {
    pub const EXTRA_FORCE_OFFSET: u32 = 780;
    pub const EXTRA_INFLOW_1: u32 = 781;
    pub const EXTRA_INFLOW_2: u32 = 782;
}

const OFFSET: &str = "extra force on the piston: a constant force added to the force the sensor reads where the pressures set the force, as the extra force's library and product slots add theirs (0 = off)";
const INFLOW_1: &str = "extra mass flow into chamber 1 alone, at the chamber's gas temperature (negative: out of it, fading below 0.1 bar absolute in the chamber, as the extra flow slots' outflows; 0 = off)";
const INFLOW_2: &str = "extra mass flow into chamber 2 alone, at the chamber's gas temperature (negative: out of it, fading below 0.1 bar absolute in the chamber, as the extra flow slots' outflows; 0 = off)";
const FORCE: &str = "1000 N: nine times the largest force the actuator gives (109 N)";
const FLOW: &str = "1e-2 kg/s: ten times the jet pipe's whole flow of about 1e-3 kg/s; a constant flow that large is no leak";

/// The three constants' rows.
pub(super) const CONSTANTS: [Row; 3] = [
    parameter("extra_force_offset", vr::EXTRA_FORCE_OFFSET, "N", 0.0, OFFSET)
        .at_least(-1e3)
        .at_most(1e3)
        .cite("(2.36)")
        .because(FORCE),
    parameter("extra_inflow_1", vr::EXTRA_INFLOW_1, "kg/s", 0.0, INFLOW_1)
        .at_least(-1e-2)
        .at_most(1e-2)
        .cite("(2.24)")
        .because(FLOW),
    parameter("extra_inflow_2", vr::EXTRA_INFLOW_2, "kg/s", 0.0, INFLOW_2)
        .at_least(-1e-2)
        .at_most(1e-2)
        .cite("(2.25)")
        .because(FLOW),
];
