//! The rows of the three plain constants that give every place of the chain an additive
//! constant (`extra_force_offset`, `extra_inflow_1`, `extra_inflow_2`) and of the flexible
//! slots ([`crate::physics::flexible`]). Kept apart from the rest of the table only for the
//! length of `variables.rs`; [`super::TABLE`] holds them after the extra flow slots.

use super::{parameter, ChainPlace, Row};

/// Value references of the constants and the flexible slots: slot k's variables from
/// `FLEXIBLE_k_PARAMETER`, in the order parameter, signal_1, signal_2, frequency, lag_1,
/// lag_2, knots_1, knots_2, x1_1..x1_5, x2_1..x2_5, y_1_1..y_5_5 (y_i_j at offset
/// 18 + 5 (i − 1) + (j − 1)), a stride of [`FLEXIBLE_STRIDE`] between slots.
pub mod vr {
    pub const EXTRA_FORCE_OFFSET: u32 = 780;
    pub const EXTRA_INFLOW_1: u32 = 781;
    pub const EXTRA_INFLOW_2: u32 = 782;
    pub const FLEXIBLE_1_PARAMETER: u32 = 800;
    pub const FLEXIBLE_1_SIGNAL_1: u32 = 801;
    pub const FLEXIBLE_1_SIGNAL_2: u32 = 802;
    pub const FLEXIBLE_1_FREQUENCY: u32 = 803;
    pub const FLEXIBLE_1_LAG_1: u32 = 804;
    pub const FLEXIBLE_1_LAG_2: u32 = 805;
    pub const FLEXIBLE_1_KNOTS_1: u32 = 806;
    pub const FLEXIBLE_1_KNOTS_2: u32 = 807;
    /// Axis 1's knot i at this plus i − 1 (i = 1..5); axis 2's at FLEXIBLE_1_X2 plus j − 1.
    pub const FLEXIBLE_1_X1: u32 = 808;
    pub const FLEXIBLE_1_X2: u32 = 813;
    /// The increment at node (i, j) at this plus 5 (i − 1) + (j − 1).
    pub const FLEXIBLE_1_Y: u32 = 818;
    pub const FLEXIBLE_2_PARAMETER: u32 = 850;
    /// From one slot's variable to the same variable of the next slot.
    pub const FLEXIBLE_STRIDE: u32 = FLEXIBLE_2_PARAMETER - FLEXIBLE_1_PARAMETER;
    /// The last value reference of the slots (slot 2's y_5_5).
    pub const FLEXIBLE_LAST: u32 = FLEXIBLE_2_PARAMETER + 42;
}

const OFFSET: &str = "extra force on the piston: a constant force added to the force the sensor reads where the pressures set the force, as the extra force's library and product slots add theirs (0 = off)";
const INFLOW_1: &str = "extra mass flow into chamber 1 alone, at the chamber's gas temperature (negative: out of it, fading below 0.1 bar absolute in the chamber, as the extra flow slots' outflows; 0 = off)";
const INFLOW_2: &str = "extra mass flow into chamber 2 alone, at the chamber's gas temperature (negative: out of it, fading below 0.1 bar absolute in the chamber, as the extra flow slots' outflows; 0 = off)";
const FORCE: &str = "1000 N: nine times the largest force the actuator gives (109 N)";
const FLOW: &str =
    "1e-2 kg/s: ten times the jet pipe's whole flow of about 1e-3 kg/s; a constant flow that large is no leak";

/// The three constants' rows.
pub(super) const CONSTANTS: [Row; 3] = [
    parameter("extra_force_offset", vr::EXTRA_FORCE_OFFSET, "N", 0.0, OFFSET)
        .at_least(-1e3)
        .at_most(1e3)
        .cite("(2.36)")
        .because(FORCE)
        .at(ChainPlace::Mechanics)
        .step(0.01),
    parameter("extra_inflow_1", vr::EXTRA_INFLOW_1, "kg/s", 0.0, INFLOW_1)
        .at_least(-1e-2)
        .at_most(1e-2)
        .cite("(2.24)")
        .because(FLOW)
        .at(ChainPlace::Chambers)
        .step(1e-7),
    parameter("extra_inflow_2", vr::EXTRA_INFLOW_2, "kg/s", 0.0, INFLOW_2)
        .at_least(-1e-2)
        .at_most(1e-2)
        .cite("(2.25)")
        .because(FLOW)
        .at(ChainPlace::Chambers)
        .step(1e-7),
];

const PARAMETER: &str = "flexible slot: the value reference of the constant it varies (0 = off): one of the constants a modulation slot may modulate (see modulation_1_parameter) or extra_force_offset 780, extra_inflow_1 781, extra_inflow_2 782; the constant is its start value plus the slot's increment at the signals, held over each step at the step's start";
const SIGNAL_1: &str = "flexible slot: the code of signal 1, as modulation_1_signal's: 0 none (reads 0), 1 time t (s), 2 the command v_DA (V), 3 the coil current i (A), 4 the jet pipe position x_jp (m), 5 the stopper position x_s (m), 6 the stopper velocity (m/s), 7 its sign tanh(v / 1 mm/s) (1), 8 the force F_act (N), 9 P1 (Pa), 10 P2 (Pa), 11 P1 - P2 (Pa), 12 sin(2 pi f t) (1), 13 cos(2 pi f t) (1)";
const SIGNAL_2: &str =
    "flexible slot: the code of signal 2, as signal 1's (0 none: the increment is a function of signal 1 alone)";
const FREQUENCY: &str =
    "flexible slot: the frequency f of the signals sin(2 pi f t) and cos(2 pi f t) (codes 12 and 13)";
const LAG_1: &str = "flexible slot: the time constant of a first-order low-pass on signal 1, advanced after each step by the exact response to the signal's mean over the step (0 = the signal itself)";
const LAG_2: &str = "flexible slot: the time constant of a first-order low-pass on signal 2 (0 = the signal itself)";
const KNOTS_1: &str = "flexible slot: the number of knots in use on axis 1 (0 = off; 1 = constant along it; else piecewise linear between the knots, held beyond the first and the last)";
const KNOTS_2: &str = "flexible slot: the number of knots in use on axis 2 (0 or 1: one signal, the increments y_i_1 alone; else bilinear between the nodes, held beyond the end knots)";
const X1: &str = "flexible slot: a knot of axis 1, in the SI unit of signal 1 (s, V, A, m, m/s, N, Pa or 1); the knots in use strictly increasing";
const X2: &str = "flexible slot: a knot of axis 2, in the SI unit of signal 2; the knots in use strictly increasing";
const Y: &str = "flexible slot: the increment of its constant at node (x1_i, x2_j), in the constant's SI unit; the constant plus each increment in use stays within the constant's limits";
const CODE: &str = "a value reference of this table: 0 (off) or a constant listed in the description";
const CODES: &str = "the signal codes run from 0 to 13";
const HERTZ: &str = "100 kHz: a hundred times the bench's sampling rate";
const SECONDS: &str = "1000 s: longer than any recording; a low-pass that slow holds its signal's start value";
const AT_MOST_FIVE: &str = "at most 5 knots on an axis";
const SIGNAL_VALUE: &str =
    "1e9 exceeds every signal of the chain in its SI unit (the largest, a pressure, is below 1e7 Pa)";
const INCREMENT: &str = "1e9 exceeds every constant's own limits; those are checked at each node";

macro_rules! flexible_rows {
    ($k:literal, $base:expr) => {
        [
            parameter(concat!("flexible_", $k, "_parameter"), $base + 0, "1", 0.0, PARAMETER)
                .at_least(0.0)
                .at_most(1000.0)
                .because(CODE),
            parameter(concat!("flexible_", $k, "_signal_1"), $base + 1, "1", 0.0, SIGNAL_1)
                .at_least(0.0)
                .at_most(13.0)
                .because(CODES),
            parameter(concat!("flexible_", $k, "_signal_2"), $base + 2, "1", 0.0, SIGNAL_2)
                .at_least(0.0)
                .at_most(13.0)
                .because(CODES),
            parameter(concat!("flexible_", $k, "_frequency"), $base + 3, "Hz", 0.0, FREQUENCY)
                .at_least(0.0)
                .at_most(1e5)
                .because(HERTZ),
            parameter(concat!("flexible_", $k, "_lag_1"), $base + 4, "s", 0.0, LAG_1)
                .at_least(0.0)
                .at_most(1e3)
                .because(SECONDS),
            parameter(concat!("flexible_", $k, "_lag_2"), $base + 5, "s", 0.0, LAG_2)
                .at_least(0.0)
                .at_most(1e3)
                .because(SECONDS),
            parameter(concat!("flexible_", $k, "_knots_1"), $base + 6, "1", 0.0, KNOTS_1)
                .at_least(0.0)
                .at_most(5.0)
                .because(AT_MOST_FIVE),
            parameter(concat!("flexible_", $k, "_knots_2"), $base + 7, "1", 0.0, KNOTS_2)
                .at_least(0.0)
                .at_most(5.0)
                .because(AT_MOST_FIVE),
            parameter(concat!("flexible_", $k, "_x1_1"), $base + 8, "1", 0.0, X1)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x1_2"), $base + 9, "1", 0.0, X1)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x1_3"), $base + 10, "1", 0.0, X1)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x1_4"), $base + 11, "1", 0.0, X1)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x1_5"), $base + 12, "1", 0.0, X1)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x2_1"), $base + 13, "1", 0.0, X2)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x2_2"), $base + 14, "1", 0.0, X2)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x2_3"), $base + 15, "1", 0.0, X2)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x2_4"), $base + 16, "1", 0.0, X2)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_x2_5"), $base + 17, "1", 0.0, X2)
                .at_least(-1e9)
                .at_most(1e9)
                .because(SIGNAL_VALUE),
            parameter(concat!("flexible_", $k, "_y_1_1"), $base + 18, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_1_2"), $base + 19, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_1_3"), $base + 20, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_1_4"), $base + 21, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_1_5"), $base + 22, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_2_1"), $base + 23, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_2_2"), $base + 24, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_2_3"), $base + 25, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_2_4"), $base + 26, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_2_5"), $base + 27, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_3_1"), $base + 28, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_3_2"), $base + 29, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_3_3"), $base + 30, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_3_4"), $base + 31, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_3_5"), $base + 32, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_4_1"), $base + 33, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_4_2"), $base + 34, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_4_3"), $base + 35, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_4_4"), $base + 36, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_4_5"), $base + 37, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_5_1"), $base + 38, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_5_2"), $base + 39, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_5_3"), $base + 40, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_5_4"), $base + 41, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
            parameter(concat!("flexible_", $k, "_y_5_5"), $base + 42, "1", 0.0, Y)
                .at_least(-1e9)
                .at_most(1e9)
                .because(INCREMENT),
        ]
    };
}

/// The rows of slot 1, then those of slot 2.
pub(super) const SLOT_1: [Row; 43] = flexible_rows!(1, vr::FLEXIBLE_1_PARAMETER);
pub(super) const SLOT_2: [Row; 43] = flexible_rows!(2, vr::FLEXIBLE_2_PARAMETER);
