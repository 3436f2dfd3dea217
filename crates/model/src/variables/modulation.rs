//! The rows of the modulation slots ([`crate::physics::modulation`]): two slots, each a
//! constant of the table, a signal of the chain, a frequency and up to twelve knots. Kept apart
//! from the rest of the table only for the length of `variables.rs`; [`super::TABLE`] holds
//! them after the others.

use super::{parameter, Row};

/// Value references of the slots: slot k's variables from `MODULATION_k_PARAMETER`, in the
/// order parameter, signal, frequency, knots, x_1..x_12, y_1..y_12 (a stride of
/// [`MODULATION_STRIDE`] between slots).
pub mod vr {
    pub const MODULATION_1_PARAMETER: u32 = 1000;
    pub const MODULATION_1_SIGNAL: u32 = 1001;
    pub const MODULATION_1_FREQUENCY: u32 = 1002;
    pub const MODULATION_1_KNOTS: u32 = 1003;
    /// Knot j's signal value at this plus j − 1 (j = 1..12); its increment at MODULATION_1_Y plus j − 1.
    pub const MODULATION_1_X: u32 = 1004;
    pub const MODULATION_1_X_LAST: u32 = MODULATION_1_X + 11;
    pub const MODULATION_1_Y: u32 = 1016;
    pub const MODULATION_1_Y_LAST: u32 = MODULATION_1_Y + 11;
    pub const MODULATION_2_PARAMETER: u32 = 1030;
    pub const MODULATION_2_SIGNAL: u32 = 1031;
    pub const MODULATION_2_FREQUENCY: u32 = 1032;
    pub const MODULATION_2_KNOTS: u32 = 1033;
    /// Knot j's signal value at this plus j − 1 (j = 1..12); its increment at MODULATION_2_Y plus j − 1.
    pub const MODULATION_2_X: u32 = 1034;
    pub const MODULATION_2_X_LAST: u32 = MODULATION_2_X + 11;
    pub const MODULATION_2_Y: u32 = 1046;
    pub const MODULATION_2_Y_LAST: u32 = MODULATION_2_Y + 11;
    /// From one slot's variable to the same variable of the next slot.
    pub const MODULATION_STRIDE: u32 = MODULATION_2_PARAMETER - MODULATION_1_PARAMETER;
    /// The last value reference of the slots.
    pub const MODULATION_LAST: u32 = MODULATION_2_Y_LAST;
}

const PARAMETER: &str = "the value reference of the constant this slot modulates (0 = off): one of k_cd 110, i_offset 111, omega_cd 112, k_m 120, omega_1 121, omega_2 122, zeta_2 123, x_jp_sat 124, F_jp_sat 125, x_jp_offset 126, D_jp 130, C_d 131, C_dm_A_lpp 132, C_db_A_lpp 133, supply/return area scales 400-403, P_s 100, P_r 101, T 102, dead_volume_1 320, dead_volume_2 321, D_cyl 145, L_sup 143 (the piston moves, the chambers' air carried), k_spring 146, friction_coulomb 310, viscous_friction 470, force_sensor_offset 360, force_sensor_gain 361, p1_sensor_offset 500, p1_sensor_gain 501, p2_sensor_offset 510, p2_sensor_gain 511, extra_force_pressure_difference 476 (an error of the piston's effective area); the constant is its start value plus the slot's increment at the signal's value, held over each step at the step's start";
const SIGNAL: &str = "the signal the increment follows: 0 none (reads 0), 1 time t (s), 2 the command v_DA (V), 3 the coil current i (A), 4 the jet pipe position x_jp (m), 5 the stopper position x_s (m), 6 the stopper velocity (m/s), 7 its sign tanh(v / 1 mm/s) (1), 8 the force F_act (N), 9 P1 (Pa), 10 P2 (Pa), 11 P1 - P2 (Pa), 12 sin(2 pi f t) (1), 13 cos(2 pi f t) (1)";
const FREQUENCY: &str = "the frequency f of the signals sin(2 pi f t) and cos(2 pi f t) (codes 12 and 13)";
const KNOTS: &str = "the number of knots in use (0 = off; 1 = a constant increment; else piecewise linear between the knots, held beyond the first and the last)";
const X: &str = "a knot's signal value, in the SI unit of the slot's signal (s, V, A, m, m/s, N, Pa or 1); the knots in use strictly increasing";
const Y: &str = "the increment of the slot's constant at the knot, in the constant's SI unit; the constant plus each increment stays within the constant's limits";
const CODE: &str = "a value reference of this table: 0 (off) or a constant listed in the description";
const CODES: &str = "the signal codes run from 0 to 13";
const HERTZ: &str = "100 kHz: a hundred times the bench's sampling rate";
const AT_MOST_TWELVE: &str = "at most 12 knots";
const SIGNAL_VALUE: &str =
    "1e9 exceeds every signal of the chain in its SI unit (the largest, a pressure, is below 1e7 Pa)";
const INCREMENT: &str = "1e9 exceeds every constant's own limits; those are checked at each knot";

macro_rules! slot_rows {
    ($k:literal, $base:expr) => {
        [
            parameter(concat!("modulation_", $k, "_parameter"), $base, "1", 0.0, PARAMETER)
                .at_least(0.0)
                .at_most(1000.0)
                .because(CODE),
            parameter(concat!("modulation_", $k, "_signal"), $base + 1, "1", 0.0, SIGNAL)
                .at_least(0.0)
                .at_most(13.0)
                .because(CODES),
            parameter(
                concat!("modulation_", $k, "_frequency"),
                $base + 2,
                "Hz",
                0.0,
                FREQUENCY,
            )
            .at_least(0.0)
            .at_most(1e5)
            .because(HERTZ),
            parameter(concat!("modulation_", $k, "_knots"), $base + 3, "1", 0.0, KNOTS)
                .at_least(0.0)
                .at_most(12.0)
                .because(AT_MOST_TWELVE),
            parameter(concat!("modulation_", $k, "_x_1"), $base + 4, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_2"), $base + 5, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_3"), $base + 6, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_4"), $base + 7, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_5"), $base + 8, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_6"), $base + 9, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_7"), $base + 10, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_8"), $base + 11, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_9"), $base + 12, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_10"), $base + 13, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_11"), $base + 14, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_x_12"), $base + 15, "1", 0.0, X)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("modulation_", $k, "_y_1"), $base + 16, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_2"), $base + 17, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_3"), $base + 18, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_4"), $base + 19, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_5"), $base + 20, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_6"), $base + 21, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_7"), $base + 22, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_8"), $base + 23, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_9"), $base + 24, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_10"), $base + 25, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_11"), $base + 26, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("modulation_", $k, "_y_12"), $base + 27, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
        ]
    };
}

/// The rows of slot 1, then those of slot 2.
pub(super) const SLOT_1: [Row; 28] = slot_rows!(1, vr::MODULATION_1_PARAMETER);
pub(super) const SLOT_2: [Row; 28] = slot_rows!(2, vr::MODULATION_2_PARAMETER);

/// The slots' rows after the table's others: the modulation slots', the extra force's product
/// slots' (`variables/extra_force.rs`), the extra flow slots' (`variables/extra_flow.rs`), the
/// plain constants and the flexible slots of `variables/flexible.rs`.
pub(super) const SLOT_ROWS: [&[Row]; 7] = [
    &SLOT_1,
    &SLOT_2,
    &super::extra_force::SLOTS,
    &super::extra_flow::SLOTS,
    &super::flexible::CONSTANTS,
    &super::flexible::SLOT_1,
    &super::flexible::SLOT_2,
];

/// The number of rows in `parts`.
pub(super) const fn length(parts: &[&[Row]]) -> usize {
    let mut total = 0;
    let mut part = 0;
    while part < parts.len() {
        total += parts[part].len();
        part += 1;
    }
    total
}

/// `first`, then `parts` one after the other, as one array of `N` rows (N their total length).
pub(super) const fn concatenated<const N: usize>(first: &[Row], parts: &[&[Row]]) -> [Row; N] {
    let mut out = [first[0]; N];
    let mut k = 0;
    while k < first.len() {
        out[k] = first[k];
        k += 1;
    }
    let mut part = 0;
    while part < parts.len() {
        let mut i = 0;
        while i < parts[part].len() {
            out[k] = parts[part][i];
            k += 1;
            i += 1;
        }
        part += 1;
    }
    assert!(k == N, "the table's length is the sum of its parts'");
    out
}
