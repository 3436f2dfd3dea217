//! The rows of the extra flow slots ([`crate::physics::extra_flow`]): three slots, each a
//! chamber, a signal code and a coefficient. Kept apart from the rest of the table only for
//! the length of `variables.rs`; [`super::TABLE`] holds them after the extra force's product
//! slots.

use super::{parameter, Row};

/// Value references of the slots: slot k's variables from `EXTRA_FLOW_k_CHAMBER`, in the
/// order chamber, signal, coefficient (a stride of [`EXTRA_FLOW_STRIDE`] between slots).
pub mod vr {
    pub const EXTRA_FLOW_1_CHAMBER: u32 = 760;
    pub const EXTRA_FLOW_1_SIGNAL: u32 = 761;
    pub const EXTRA_FLOW_1_COEFFICIENT: u32 = 762;
    pub const EXTRA_FLOW_2_CHAMBER: u32 = 764;
    pub const EXTRA_FLOW_3_CHAMBER: u32 = 768;
    /// From one slot's variable to the same variable of the next slot.
    pub const EXTRA_FLOW_STRIDE: u32 = EXTRA_FLOW_2_CHAMBER - EXTRA_FLOW_1_CHAMBER;
    /// The last value reference of the slots (slot 3's coefficient).
    pub const EXTRA_FLOW_LAST: u32 = EXTRA_FLOW_3_CHAMBER + 2;
}

const CHAMBER: &str =
    "extra flow slot: the chamber (1 or 2) whose mass balance gains the slot's flow; no other place loses it";
const SIGNAL: &str = "extra flow slot: the code of its signal g, with P_i the slot's chamber's pressure: 0 the constant 1, 1 (P1 - P2) / 1 bar, 2 (P_s - P_i) / 1 bar, 3 (P_i - P_r) / 1 bar, 4 sqrt(|P1 - P2| / 1 bar) sign(P1 - P2), 5 sqrt(|P_s - P_i| / 1 bar) sign(P_s - P_i), 6 sqrt(|P_i - P_r| / 1 bar) sign(P_i - P_r) (1 bar = 1e5 Pa)";
const COEFFICIENT: &str = "extra flow slot: the chamber gains this times g as mass flow, at the chamber's gas temperature (negative: it loses it, fading below 0.1 bar absolute in the chamber; 0 = off)";
const CHAMBERS: &str = "the actuator has chambers 1 and 2";
const CODES: &str = "the signal codes run from 0 to 6";
const FLOW: &str = "0.1 kg/s per bar: as the laminar leaks' 1e-6 kg/(s.Pa), about a hundred times what the valve's open port passes from the supply";

macro_rules! flow_rows {
    ($k:literal, $base:expr) => {
        [
            parameter(concat!("extra_flow_", $k, "_chamber"), $base, "1", 1.0, CHAMBER)
                .at_least(1.0)
                .at_most(2.0)
                .cite("(2.24)-(2.25)")
                .because(CHAMBERS),
            parameter(concat!("extra_flow_", $k, "_signal"), $base + 1, "1", 0.0, SIGNAL)
                .at_least(0.0)
                .at_most(6.0)
                .cite("(2.24)-(2.25)")
                .because(CODES),
            parameter(
                concat!("extra_flow_", $k, "_coefficient"),
                $base + 2,
                "kg/s",
                0.0,
                COEFFICIENT,
            )
            .at_least(-0.1)
            .at_most(0.1)
            .cite("(2.24)-(2.25)")
            .because(FLOW),
        ]
    };
}

/// The rows of the three slots, one after the other.
pub(super) const SLOTS: [Row; 9] = {
    let rows = [
        flow_rows!(1, vr::EXTRA_FLOW_1_CHAMBER),
        flow_rows!(2, vr::EXTRA_FLOW_2_CHAMBER),
        flow_rows!(3, vr::EXTRA_FLOW_3_CHAMBER),
    ];
    let mut out = [rows[0][0]; 9];
    let mut k = 0;
    while k < 9 {
        out[k] = rows[k / 3][k % 3];
        k += 1;
    }
    out
};
