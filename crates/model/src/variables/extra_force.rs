//! The rows of the extra force's product slots ([`crate::physics::extra_force`]): three
//! slots, each two signal codes, the first signal's origin and a coefficient. Kept apart from
//! the rest of the table only for the length of `variables.rs`; [`super::TABLE`] holds them
//! after the modulation slots.

use super::{parameter, Row};

/// Value references of the slots: slot k's variables from `EXTRA_FORCE_PRODUCT_k_FIRST`, in
/// the order first, second, origin, coefficient (a stride of
/// [`EXTRA_FORCE_PRODUCT_STRIDE`] between slots).
pub mod vr {
    pub const EXTRA_FORCE_PRODUCT_1_FIRST: u32 = 740;
    pub const EXTRA_FORCE_PRODUCT_1_SECOND: u32 = 741;
    pub const EXTRA_FORCE_PRODUCT_1_ORIGIN: u32 = 742;
    pub const EXTRA_FORCE_PRODUCT_1_COEFFICIENT: u32 = 743;
    pub const EXTRA_FORCE_PRODUCT_2_FIRST: u32 = 744;
    pub const EXTRA_FORCE_PRODUCT_3_FIRST: u32 = 748;
    /// From one slot's variable to the same variable of the next slot.
    pub const EXTRA_FORCE_PRODUCT_STRIDE: u32 = EXTRA_FORCE_PRODUCT_2_FIRST - EXTRA_FORCE_PRODUCT_1_FIRST;
    /// The last value reference of the slots (slot 3's coefficient).
    pub const EXTRA_FORCE_PRODUCT_LAST: u32 = EXTRA_FORCE_PRODUCT_3_FIRST + 3;
}

const FIRST: &str = "extra force product slot: the code of its first signal, from which the origin is subtracted: 0 the constant 1 (none), 1 the stopper position x_s (per 10 mm), 2 the stopper velocity v (per 0.1 m/s), 3 its smooth sign tanh(v / extra_force_sign_velocity) (1), 4 the stopper acceleration a (per 1 m/s2), 5 |v| (per 0.1 m/s), 6 P1 - P_r (per 1 bar = 1e5 Pa), 7 P2 - P_r (per 1 bar); v and a as extra_force_acceleration forms them";
const SECOND: &str =
    "extra force product slot: the code of its second signal, as the first's (0 = the constant 1, i.e. none)";
const ORIGIN: &str = "extra force product slot: the origin subtracted from the first signal, in its SI unit (m, m/s, 1, m/s2 or Pa; ignored with code 0): x_s - x0 is the code 1 with the origin x0";
const COEFFICIENT: &str = "extra force product slot: the force the sensor reads gains this times (first signal - origin) / its reference unit times the second signal / its reference unit, where the pressures set the force (0 = off)";
const CODES: &str = "the signal codes run from 0 to 7";
const SIGNAL_VALUE: &str =
    "1e7 exceeds every signal in its SI unit (the largest, a pressure difference, is below the supply's 1e7 Pa limit)";
const FORCE: &str = "1e4 N per reference unit: a hundred times the largest force the actuator gives (109 N)";

macro_rules! product_rows {
    ($k:literal, $base:expr) => {
        [
            parameter(concat!("extra_force_product_", $k, "_first"), $base, "1", 0.0, FIRST)
                .at_least(0.0)
                .at_most(7.0)
                .cite("(2.36)")
                .because(CODES),
            parameter(
                concat!("extra_force_product_", $k, "_second"),
                $base + 1,
                "1",
                0.0,
                SECOND,
            )
            .at_least(0.0)
            .at_most(7.0)
            .cite("(2.36)")
            .because(CODES),
            parameter(
                concat!("extra_force_product_", $k, "_origin"),
                $base + 2,
                "1",
                0.0,
                ORIGIN,
            )
            .at_least(-1e7)
            .at_most(1e7)
            .cite("(2.36)")
            .because(SIGNAL_VALUE),
            parameter(
                concat!("extra_force_product_", $k, "_coefficient"),
                $base + 3,
                "N",
                0.0,
                COEFFICIENT,
            )
            .at_least(-1e4)
            .at_most(1e4)
            .cite("(2.36)")
            .because(FORCE),
        ]
    };
}

/// The rows of the three slots, one after the other.
pub(super) const SLOTS: [Row; 12] = {
    let rows = [
        product_rows!(1, vr::EXTRA_FORCE_PRODUCT_1_FIRST),
        product_rows!(2, vr::EXTRA_FORCE_PRODUCT_2_FIRST),
        product_rows!(3, vr::EXTRA_FORCE_PRODUCT_3_FIRST),
    ];
    let mut out = [rows[0][0]; 12];
    let mut k = 0;
    while k < 12 {
        out[k] = rows[k / 4][k % 4];
        k += 1;
    }
    out
};
