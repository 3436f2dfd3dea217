//! The model's parameters, with the defaults of Table 3.1 and docs/model.md (taken from the
//! FMU's variable table, so the two cannot disagree).

use super::chambers::CylinderGeometry;
use super::extra_flow::{FlowSlot, FLOW_SLOTS};
use super::extra_force::{ProductSlot, PRODUCT_SLOTS};
use super::flexible::{FlexibleSlot, FLEXIBLE_SLOTS};
use super::modulation::{Slot, SLOTS};
use super::orifice_flow::FlowConstants;
use super::static_curve::StaticCurve;
use crate::variables::{number, vr, VARIABLES};

/// Every constant of the thesis model, in SI units.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    pub p_s: f64,
    pub p_r: f64,
    pub temperature: f64,
    pub gamma: f64,
    pub r_gas: f64,
    pub k_cd: f64,
    pub i_offset: f64,
    pub omega_cd: f64,
    pub k_m: f64,
    pub omega_1: f64,
    pub omega_2: f64,
    pub zeta_2: f64,
    pub x_jp_sat: f64,
    pub f_jp_sat: f64,
    pub x_jp_offset: f64,
    pub d_jp: f64,
    pub c_d: f64,
    pub c_dm_a_lpp: f64,
    pub c_db_a_lpp: f64,
    pub l_cyl: f64,
    pub l_p: f64,
    pub l_s: f64,
    pub l_sup: f64,
    pub l_spring0: f64,
    pub d_cyl: f64,
    pub k_spring: f64,
    /// Effects the thesis model lacks; each is off at its default (see [`super::effects`]).
    pub hysteresis_width: f64,
    pub hysteresis_deadband: f64,
    pub hysteresis_exponent: f64,
    pub hysteresis_gain: f64,
    pub hysteresis_beta_share: f64,
    pub hysteresis_start: f64,
    pub friction_coulomb: f64,
    pub friction_velocity: f64,
    pub friction_stribeck: f64,
    pub friction_stribeck_velocity: f64,
    pub dead_volume_1: f64,
    pub dead_volume_2: f64,
    pub supply_resistance: f64,
    pub heat_transfer_fraction: f64,
    pub command_delay: f64,
    pub force_sensor_offset: f64,
    pub force_sensor_gain: f64,
    /// Generic correction terms of the diagnosis; each is off at its default.
    pub supply_area_scale_1: f64,
    pub supply_area_scale_2: f64,
    pub return_area_scale_1: f64,
    pub return_area_scale_2: f64,
    pub return_resistance: f64,
    pub chamber_vent_1: f64,
    pub chamber_vent_2: f64,
    /// C_d·A (m²) of a leak from the supply into chamber 1 or 2, (2.18).
    pub chamber_supply_leak_1: f64,
    pub chamber_supply_leak_2: f64,
    /// Laminar conductance (kg/(s·Pa)) from chamber 1 or 2 to the return pressure.
    pub chamber_laminar_vent_1: f64,
    pub chamber_laminar_vent_2: f64,
    /// Laminar conductance (kg/(s·Pa)) from the supply pressure into chamber 1 or 2.
    pub chamber_laminar_supply_leak_1: f64,
    pub chamber_laminar_supply_leak_2: f64,
    /// Laminar conductance (kg/(s·Pa)) from chamber 1 into chamber 2, beside (2.23).
    pub chamber_laminar_cross_leak: f64,
    pub port_resistance_1: f64,
    pub port_resistance_2: f64,
    pub stopper_compliance: f64,
    pub stopper_mount_lag: f64,
    pub command_lag: f64,
    pub command_filter_frequency: f64,
    pub command_filter_damping: f64,
    pub command_limit: f64,
    pub command_upper_limit: f64,
    pub command_lower_limit: f64,
    pub command_quantum: f64,
    pub command_quantum_origin: f64,
    pub command_quantum_threshold: f64,
    pub current_limit: f64,
    pub current_slew_limit: f64,
    pub f3_input_cubic: f64,
    pub f3_algebraic_share: f64,
    pub force_sensor_quadratic: f64,
    pub force_sensor_cubic: f64,
    pub force_sensor_drift: f64,
    pub force_sensor_lag: f64,
    pub force_sensor_delay: f64,
    pub force_sensor_play: f64,
    pub force_sensor_ripple_sine: f64,
    pub force_sensor_ripple_frequency: f64,
    pub force_sensor_ripple_cosine: f64,
    pub force_sensor_filter_frequency: f64,
    pub force_sensor_filter_damping: f64,
    pub viscous_friction: f64,
    pub position_force_rate: f64,
    pub position_force_reference: f64,
    pub extra_force_acceleration: f64,
    pub extra_force_velocity_squared: f64,
    pub extra_force_sign_pressure: f64,
    pub extra_force_pressure_difference: f64,
    pub extra_force_sign_velocity: f64,
    pub stopper_acceleration_input_share: f64,
    pub return_vent_area: f64,
    pub supply_drift: f64,
    pub supply_ripple_sine: f64,
    pub supply_ripple_frequency: f64,
    pub supply_ripple_cosine: f64,
    pub x_jp_offset_drift: f64,
    pub t_drift: f64,
    pub p1_sensor_offset: f64,
    pub p1_sensor_gain: f64,
    pub p1_sensor_drift: f64,
    pub p1_sensor_lag: f64,
    pub p1_sensor_delay: f64,
    pub p1_sensor_filter_frequency: f64,
    pub p1_sensor_filter_damping: f64,
    pub p2_sensor_offset: f64,
    pub p2_sensor_gain: f64,
    pub p2_sensor_drift: f64,
    pub p2_sensor_lag: f64,
    pub p2_sensor_delay: f64,
    pub p2_sensor_filter_frequency: f64,
    pub p2_sensor_filter_damping: f64,
    /// Restrictions as orifices and the gas volumes behind them (0 = off).
    pub supply_restriction_area: f64,
    pub supply_plenum_volume: f64,
    pub return_plenum_volume: f64,
    pub port_restriction_area_1: f64,
    pub port_restriction_area_2: f64,
    pub port_line_volume_1: f64,
    pub port_line_volume_2: f64,
    /// Static curves (off with no knots): the command the current driver sees as a function
    /// of v_DA, and each transducer's reading as a function of its quantity.
    pub command_curve: StaticCurve,
    pub force_sensor_curve: StaticCurve,
    pub p1_sensor_curve: StaticCurve,
    pub p2_sensor_curve: StaticCurve,
    /// The valve orifices' discharge coefficient as a function of the pressure ratio
    /// P_down/P_up across each (in place of `c_d`; off with no knots).
    pub discharge_curve: StaticCurve,
    /// The modulation slots: a constant that varies with a signal of the chain (off with
    /// no constant named; see [`super::modulation`]).
    pub modulation: [Slot; SLOTS],
    /// The extra force's product slots (off with a coefficient of 0; see
    /// [`super::extra_force`]).
    pub extra_force_products: [ProductSlot; PRODUCT_SLOTS],
    /// The extra flow slots: a flow into one chamber alone (off with a coefficient of 0; see
    /// [`super::extra_flow`]).
    pub extra_flows: [FlowSlot; FLOW_SLOTS],
    /// Plain additive constants, off at 0: a force where the pressures set the force
    /// ([`super::extra_force`]) and a mass flow into each chamber alone
    /// ([`super::extra_flow::faded`]).
    pub extra_force_offset: f64,
    pub extra_inflow_1: f64,
    pub extra_inflow_2: f64,
    /// The flexible slots: a constant plus a function of one or two signals, each optionally
    /// low-passed (off with no constant named; see [`super::flexible`]).
    pub flexible: [FlexibleSlot; FLEXIBLE_SLOTS],
}

/// Start value of a variable of the table (panics only on a programming error: a value
/// reference that the table does not have).
pub fn table_start(value_reference: u32) -> f64 {
    VARIABLES
        .iter()
        .find(|v| v.value_reference == value_reference)
        .map(|v| v.start)
        .unwrap_or_else(|| panic!("value reference {value_reference} is not in the variable table"))
}

impl Default for Parameters {
    fn default() -> Self {
        let mut p = Parameters {
            p_s: 0.0,
            p_r: 0.0,
            temperature: 0.0,
            gamma: 0.0,
            r_gas: 0.0,
            k_cd: 0.0,
            i_offset: 0.0,
            omega_cd: 0.0,
            k_m: 0.0,
            omega_1: 0.0,
            omega_2: 0.0,
            zeta_2: 0.0,
            x_jp_sat: 0.0,
            f_jp_sat: 0.0,
            x_jp_offset: 0.0,
            d_jp: 0.0,
            c_d: 0.0,
            c_dm_a_lpp: 0.0,
            c_db_a_lpp: 0.0,
            l_cyl: 0.0,
            l_p: 0.0,
            l_s: 0.0,
            l_sup: 0.0,
            l_spring0: 0.0,
            d_cyl: 0.0,
            k_spring: 0.0,
            hysteresis_width: 0.0,
            hysteresis_deadband: 0.0,
            hysteresis_exponent: 0.0,
            hysteresis_gain: 0.0,
            hysteresis_beta_share: 0.0,
            hysteresis_start: 0.0,
            friction_coulomb: 0.0,
            friction_velocity: 0.0,
            friction_stribeck: 0.0,
            friction_stribeck_velocity: 0.0,
            dead_volume_1: 0.0,
            dead_volume_2: 0.0,
            supply_resistance: 0.0,
            heat_transfer_fraction: 0.0,
            command_delay: 0.0,
            force_sensor_offset: 0.0,
            force_sensor_gain: 0.0,
            supply_area_scale_1: 0.0,
            supply_area_scale_2: 0.0,
            return_area_scale_1: 0.0,
            return_area_scale_2: 0.0,
            return_resistance: 0.0,
            chamber_vent_1: 0.0,
            chamber_vent_2: 0.0,
            chamber_supply_leak_1: 0.0,
            chamber_supply_leak_2: 0.0,
            chamber_laminar_vent_1: 0.0,
            chamber_laminar_vent_2: 0.0,
            chamber_laminar_supply_leak_1: 0.0,
            chamber_laminar_supply_leak_2: 0.0,
            chamber_laminar_cross_leak: 0.0,
            port_resistance_1: 0.0,
            port_resistance_2: 0.0,
            stopper_compliance: 0.0,
            stopper_mount_lag: 0.0,
            command_lag: 0.0,
            command_filter_frequency: 0.0,
            command_filter_damping: 0.0,
            command_limit: 0.0,
            command_upper_limit: 100.0,
            command_lower_limit: -100.0,
            command_quantum: 0.0,
            command_quantum_origin: 0.0,
            command_quantum_threshold: 0.5,
            current_limit: 0.0,
            current_slew_limit: 0.0,
            f3_input_cubic: 0.0,
            f3_algebraic_share: 0.0,
            force_sensor_quadratic: 0.0,
            force_sensor_cubic: 0.0,
            force_sensor_drift: 0.0,
            force_sensor_lag: 0.0,
            force_sensor_delay: 0.0,
            force_sensor_play: 0.0,
            force_sensor_ripple_sine: 0.0,
            force_sensor_ripple_frequency: 0.0,
            force_sensor_ripple_cosine: 0.0,
            force_sensor_filter_frequency: 0.0,
            force_sensor_filter_damping: 0.0,
            viscous_friction: 0.0,
            position_force_rate: 0.0,
            position_force_reference: 0.0,
            extra_force_acceleration: 0.0,
            extra_force_velocity_squared: 0.0,
            extra_force_sign_pressure: 0.0,
            extra_force_pressure_difference: 0.0,
            stopper_acceleration_input_share: 0.0,
            extra_force_sign_velocity: 1e-3,
            return_vent_area: 0.0,
            supply_drift: 0.0,
            supply_ripple_sine: 0.0,
            supply_ripple_frequency: 0.0,
            supply_ripple_cosine: 0.0,
            x_jp_offset_drift: 0.0,
            t_drift: 0.0,
            p1_sensor_offset: 0.0,
            p1_sensor_gain: 0.0,
            p1_sensor_drift: 0.0,
            p1_sensor_lag: 0.0,
            p1_sensor_delay: 0.0,
            p1_sensor_filter_frequency: 0.0,
            p1_sensor_filter_damping: 0.0,
            p2_sensor_offset: 0.0,
            p2_sensor_gain: 0.0,
            p2_sensor_drift: 0.0,
            p2_sensor_lag: 0.0,
            p2_sensor_delay: 0.0,
            p2_sensor_filter_frequency: 0.0,
            p2_sensor_filter_damping: 0.0,
            supply_restriction_area: 0.0,
            supply_plenum_volume: 0.0,
            return_plenum_volume: 0.0,
            port_restriction_area_1: 0.0,
            port_restriction_area_2: 0.0,
            port_line_volume_1: 0.0,
            port_line_volume_2: 0.0,
            command_curve: StaticCurve::default(),
            force_sensor_curve: StaticCurve::default(),
            p1_sensor_curve: StaticCurve::default(),
            p2_sensor_curve: StaticCurve::default(),
            discharge_curve: StaticCurve::default(),
            modulation: [Slot::default(); SLOTS],
            extra_force_products: [ProductSlot::default(); PRODUCT_SLOTS],
            extra_flows: [FlowSlot::default(); FLOW_SLOTS],
            extra_force_offset: 0.0,
            extra_inflow_1: 0.0,
            extra_inflow_2: 0.0,
            flexible: [FlexibleSlot::default(); FLEXIBLE_SLOTS],
        };
        for &vr in Parameters::VALUE_REFERENCES {
            *p.field_mut(vr).expect("every parameter value reference has a field") = table_start(vr);
        }
        p
    }
}

/// `first` then `second`, as one array of `N` (their total length).
const fn concatenated<const N: usize>(first: &[u32], second: &[u32]) -> [u32; N] {
    let mut out = [0u32; N];
    let mut k = 0;
    while k < first.len() {
        out[k] = first[k];
        k += 1;
    }
    let mut j = 0;
    while j < second.len() {
        out[k + j] = second[j];
        j += 1;
    }
    assert!(k + j == N, "the list's length is the sum of its parts'");
    out
}

const ALL_VALUE_REFERENCES: [u32; BEFORE_THE_FLEXIBLE_SLOTS.len() + super::flexible::VALUE_REFERENCES.len()] =
    concatenated(BEFORE_THE_FLEXIBLE_SLOTS, super::flexible::VALUE_REFERENCES);

impl Parameters {
    /// Value references of the fields, in the table's order.
    pub const VALUE_REFERENCES: &'static [u32] = &ALL_VALUE_REFERENCES;
}

/// [`Parameters::VALUE_REFERENCES`] but the flexible slots' (listed in their module).
const BEFORE_THE_FLEXIBLE_SLOTS: &[u32] = &[
    vr::P_S,
    vr::P_R,
    vr::T_GAS,
    vr::GAMMA,
    vr::R_GAS,
    vr::K_CD,
    vr::I_OFFSET,
    vr::OMEGA_CD,
    vr::K_M,
    vr::OMEGA_1,
    vr::OMEGA_2,
    vr::ZETA_2,
    vr::X_JP_SAT,
    vr::F_JP_SAT,
    vr::X_JP_OFFSET,
    vr::D_JP,
    vr::C_D,
    vr::C_DM_A_LPP,
    vr::C_DB_A_LPP,
    vr::L_CYL,
    vr::L_P,
    vr::L_S,
    vr::L_SUP,
    vr::L_SPRING0,
    vr::D_CYL,
    vr::K_SPRING,
    vr::HYSTERESIS_WIDTH,
    vr::HYSTERESIS_DEADBAND,
    vr::HYSTERESIS_EXPONENT,
    vr::HYSTERESIS_GAIN,
    vr::HYSTERESIS_BETA_SHARE,
    vr::HYSTERESIS_START,
    vr::FRICTION_COULOMB,
    vr::FRICTION_VELOCITY,
    vr::FRICTION_STRIBECK,
    vr::FRICTION_STRIBECK_VELOCITY,
    vr::DEAD_VOLUME_1,
    vr::DEAD_VOLUME_2,
    vr::SUPPLY_RESISTANCE,
    vr::HEAT_TRANSFER_FRACTION,
    vr::COMMAND_DELAY,
    vr::FORCE_SENSOR_OFFSET,
    vr::FORCE_SENSOR_GAIN,
    vr::SUPPLY_AREA_SCALE_1,
    vr::SUPPLY_AREA_SCALE_2,
    vr::RETURN_AREA_SCALE_1,
    vr::RETURN_AREA_SCALE_2,
    vr::RETURN_RESISTANCE,
    vr::CHAMBER_VENT_1,
    vr::CHAMBER_VENT_2,
    vr::CHAMBER_SUPPLY_LEAK_1,
    vr::CHAMBER_SUPPLY_LEAK_2,
    vr::CHAMBER_LAMINAR_VENT_1,
    vr::CHAMBER_LAMINAR_VENT_2,
    vr::CHAMBER_LAMINAR_SUPPLY_LEAK_1,
    vr::CHAMBER_LAMINAR_SUPPLY_LEAK_2,
    vr::CHAMBER_LAMINAR_CROSS_LEAK,
    vr::PORT_RESISTANCE_1,
    vr::PORT_RESISTANCE_2,
    vr::STOPPER_COMPLIANCE,
    vr::STOPPER_MOUNT_LAG,
    vr::COMMAND_LAG,
    vr::COMMAND_FILTER_FREQUENCY,
    vr::COMMAND_FILTER_DAMPING,
    vr::COMMAND_LIMIT,
    vr::COMMAND_UPPER_LIMIT,
    vr::COMMAND_LOWER_LIMIT,
    vr::COMMAND_QUANTUM,
    vr::COMMAND_QUANTUM_ORIGIN,
    vr::COMMAND_QUANTUM_THRESHOLD,
    vr::CURRENT_LIMIT,
    vr::CURRENT_SLEW_LIMIT,
    vr::F3_INPUT_CUBIC,
    vr::F3_ALGEBRAIC_SHARE,
    vr::FORCE_SENSOR_QUADRATIC,
    vr::FORCE_SENSOR_CUBIC,
    vr::FORCE_SENSOR_DRIFT,
    vr::FORCE_SENSOR_LAG,
    vr::FORCE_SENSOR_DELAY,
    vr::FORCE_SENSOR_PLAY,
    vr::FORCE_SENSOR_RIPPLE_SINE,
    vr::FORCE_SENSOR_RIPPLE_FREQUENCY,
    vr::FORCE_SENSOR_RIPPLE_COSINE,
    vr::FORCE_SENSOR_FILTER_FREQUENCY,
    vr::FORCE_SENSOR_FILTER_DAMPING,
    vr::VISCOUS_FRICTION,
    vr::POSITION_FORCE_RATE,
    vr::POSITION_FORCE_REFERENCE,
    vr::EXTRA_FORCE_ACCELERATION,
    vr::EXTRA_FORCE_VELOCITY_SQUARED,
    vr::EXTRA_FORCE_SIGN_PRESSURE,
    vr::EXTRA_FORCE_PRESSURE_DIFFERENCE,
    vr::EXTRA_FORCE_SIGN_VELOCITY,
    vr::STOPPER_ACCELERATION_INPUT_SHARE,
    vr::RETURN_VENT_AREA,
    vr::SUPPLY_DRIFT,
    vr::SUPPLY_RIPPLE_SINE,
    vr::SUPPLY_RIPPLE_FREQUENCY,
    vr::SUPPLY_RIPPLE_COSINE,
    vr::X_JP_OFFSET_DRIFT,
    vr::T_DRIFT,
    vr::P1_SENSOR_OFFSET,
    vr::P1_SENSOR_GAIN,
    vr::P1_SENSOR_DRIFT,
    vr::P1_SENSOR_LAG,
    vr::P1_SENSOR_DELAY,
    vr::P1_SENSOR_FILTER_FREQUENCY,
    vr::P1_SENSOR_FILTER_DAMPING,
    vr::P2_SENSOR_OFFSET,
    vr::P2_SENSOR_GAIN,
    vr::P2_SENSOR_DRIFT,
    vr::P2_SENSOR_LAG,
    vr::P2_SENSOR_DELAY,
    vr::P2_SENSOR_FILTER_FREQUENCY,
    vr::P2_SENSOR_FILTER_DAMPING,
    vr::SUPPLY_RESTRICTION_AREA,
    vr::SUPPLY_PLENUM_VOLUME,
    vr::RETURN_PLENUM_VOLUME,
    vr::PORT_RESTRICTION_AREA_1,
    vr::PORT_RESTRICTION_AREA_2,
    vr::PORT_LINE_VOLUME_1,
    vr::PORT_LINE_VOLUME_2,
    vr::COMMAND_CURVE_KNOTS,
    vr::COMMAND_CURVE_X,
    vr::COMMAND_CURVE_X + 1,
    vr::COMMAND_CURVE_X + 2,
    vr::COMMAND_CURVE_X + 3,
    vr::COMMAND_CURVE_X + 4,
    vr::COMMAND_CURVE_X + 5,
    vr::COMMAND_CURVE_X + 6,
    vr::COMMAND_CURVE_X + 7,
    vr::COMMAND_CURVE_Y,
    vr::COMMAND_CURVE_Y + 1,
    vr::COMMAND_CURVE_Y + 2,
    vr::COMMAND_CURVE_Y + 3,
    vr::COMMAND_CURVE_Y + 4,
    vr::COMMAND_CURVE_Y + 5,
    vr::COMMAND_CURVE_Y + 6,
    vr::COMMAND_CURVE_Y + 7,
    vr::FORCE_SENSOR_CURVE_KNOTS,
    vr::FORCE_SENSOR_CURVE_X,
    vr::FORCE_SENSOR_CURVE_X + 1,
    vr::FORCE_SENSOR_CURVE_X + 2,
    vr::FORCE_SENSOR_CURVE_X + 3,
    vr::FORCE_SENSOR_CURVE_X + 4,
    vr::FORCE_SENSOR_CURVE_X + 5,
    vr::FORCE_SENSOR_CURVE_X + 6,
    vr::FORCE_SENSOR_CURVE_X + 7,
    vr::FORCE_SENSOR_CURVE_Y,
    vr::FORCE_SENSOR_CURVE_Y + 1,
    vr::FORCE_SENSOR_CURVE_Y + 2,
    vr::FORCE_SENSOR_CURVE_Y + 3,
    vr::FORCE_SENSOR_CURVE_Y + 4,
    vr::FORCE_SENSOR_CURVE_Y + 5,
    vr::FORCE_SENSOR_CURVE_Y + 6,
    vr::FORCE_SENSOR_CURVE_Y + 7,
    vr::P1_SENSOR_CURVE_KNOTS,
    vr::P1_SENSOR_CURVE_X,
    vr::P1_SENSOR_CURVE_X + 1,
    vr::P1_SENSOR_CURVE_X + 2,
    vr::P1_SENSOR_CURVE_X + 3,
    vr::P1_SENSOR_CURVE_X + 4,
    vr::P1_SENSOR_CURVE_X + 5,
    vr::P1_SENSOR_CURVE_X + 6,
    vr::P1_SENSOR_CURVE_X + 7,
    vr::P1_SENSOR_CURVE_Y,
    vr::P1_SENSOR_CURVE_Y + 1,
    vr::P1_SENSOR_CURVE_Y + 2,
    vr::P1_SENSOR_CURVE_Y + 3,
    vr::P1_SENSOR_CURVE_Y + 4,
    vr::P1_SENSOR_CURVE_Y + 5,
    vr::P1_SENSOR_CURVE_Y + 6,
    vr::P1_SENSOR_CURVE_Y + 7,
    vr::P2_SENSOR_CURVE_KNOTS,
    vr::P2_SENSOR_CURVE_X,
    vr::P2_SENSOR_CURVE_X + 1,
    vr::P2_SENSOR_CURVE_X + 2,
    vr::P2_SENSOR_CURVE_X + 3,
    vr::P2_SENSOR_CURVE_X + 4,
    vr::P2_SENSOR_CURVE_X + 5,
    vr::P2_SENSOR_CURVE_X + 6,
    vr::P2_SENSOR_CURVE_X + 7,
    vr::P2_SENSOR_CURVE_Y,
    vr::P2_SENSOR_CURVE_Y + 1,
    vr::P2_SENSOR_CURVE_Y + 2,
    vr::P2_SENSOR_CURVE_Y + 3,
    vr::P2_SENSOR_CURVE_Y + 4,
    vr::P2_SENSOR_CURVE_Y + 5,
    vr::P2_SENSOR_CURVE_Y + 6,
    vr::P2_SENSOR_CURVE_Y + 7,
    vr::DISCHARGE_CURVE_KNOTS,
    vr::DISCHARGE_CURVE_X,
    vr::DISCHARGE_CURVE_X + 1,
    vr::DISCHARGE_CURVE_X + 2,
    vr::DISCHARGE_CURVE_X + 3,
    vr::DISCHARGE_CURVE_X + 4,
    vr::DISCHARGE_CURVE_X + 5,
    vr::DISCHARGE_CURVE_X + 6,
    vr::DISCHARGE_CURVE_X + 7,
    vr::DISCHARGE_CURVE_Y,
    vr::DISCHARGE_CURVE_Y + 1,
    vr::DISCHARGE_CURVE_Y + 2,
    vr::DISCHARGE_CURVE_Y + 3,
    vr::DISCHARGE_CURVE_Y + 4,
    vr::DISCHARGE_CURVE_Y + 5,
    vr::DISCHARGE_CURVE_Y + 6,
    vr::DISCHARGE_CURVE_Y + 7,
    vr::MODULATION_1_PARAMETER,
    vr::MODULATION_1_SIGNAL,
    vr::MODULATION_1_FREQUENCY,
    vr::MODULATION_1_KNOTS,
    vr::MODULATION_1_X,
    vr::MODULATION_1_X + 1,
    vr::MODULATION_1_X + 2,
    vr::MODULATION_1_X + 3,
    vr::MODULATION_1_X + 4,
    vr::MODULATION_1_X + 5,
    vr::MODULATION_1_X + 6,
    vr::MODULATION_1_X + 7,
    vr::MODULATION_1_X + 8,
    vr::MODULATION_1_X + 9,
    vr::MODULATION_1_X + 10,
    vr::MODULATION_1_X + 11,
    vr::MODULATION_1_Y,
    vr::MODULATION_1_Y + 1,
    vr::MODULATION_1_Y + 2,
    vr::MODULATION_1_Y + 3,
    vr::MODULATION_1_Y + 4,
    vr::MODULATION_1_Y + 5,
    vr::MODULATION_1_Y + 6,
    vr::MODULATION_1_Y + 7,
    vr::MODULATION_1_Y + 8,
    vr::MODULATION_1_Y + 9,
    vr::MODULATION_1_Y + 10,
    vr::MODULATION_1_Y + 11,
    vr::MODULATION_2_PARAMETER,
    vr::MODULATION_2_SIGNAL,
    vr::MODULATION_2_FREQUENCY,
    vr::MODULATION_2_KNOTS,
    vr::MODULATION_2_X,
    vr::MODULATION_2_X + 1,
    vr::MODULATION_2_X + 2,
    vr::MODULATION_2_X + 3,
    vr::MODULATION_2_X + 4,
    vr::MODULATION_2_X + 5,
    vr::MODULATION_2_X + 6,
    vr::MODULATION_2_X + 7,
    vr::MODULATION_2_X + 8,
    vr::MODULATION_2_X + 9,
    vr::MODULATION_2_X + 10,
    vr::MODULATION_2_X + 11,
    vr::MODULATION_2_Y,
    vr::MODULATION_2_Y + 1,
    vr::MODULATION_2_Y + 2,
    vr::MODULATION_2_Y + 3,
    vr::MODULATION_2_Y + 4,
    vr::MODULATION_2_Y + 5,
    vr::MODULATION_2_Y + 6,
    vr::MODULATION_2_Y + 7,
    vr::MODULATION_2_Y + 8,
    vr::MODULATION_2_Y + 9,
    vr::MODULATION_2_Y + 10,
    vr::MODULATION_2_Y + 11,
    vr::EXTRA_FORCE_PRODUCT_1_FIRST,
    vr::EXTRA_FORCE_PRODUCT_1_FIRST + 1,
    vr::EXTRA_FORCE_PRODUCT_1_FIRST + 2,
    vr::EXTRA_FORCE_PRODUCT_1_FIRST + 3,
    vr::EXTRA_FORCE_PRODUCT_2_FIRST,
    vr::EXTRA_FORCE_PRODUCT_2_FIRST + 1,
    vr::EXTRA_FORCE_PRODUCT_2_FIRST + 2,
    vr::EXTRA_FORCE_PRODUCT_2_FIRST + 3,
    vr::EXTRA_FORCE_PRODUCT_3_FIRST,
    vr::EXTRA_FORCE_PRODUCT_3_FIRST + 1,
    vr::EXTRA_FORCE_PRODUCT_3_FIRST + 2,
    vr::EXTRA_FORCE_PRODUCT_3_FIRST + 3,
    vr::EXTRA_FLOW_1_CHAMBER,
    vr::EXTRA_FLOW_1_CHAMBER + 1,
    vr::EXTRA_FLOW_1_CHAMBER + 2,
    vr::EXTRA_FLOW_2_CHAMBER,
    vr::EXTRA_FLOW_2_CHAMBER + 1,
    vr::EXTRA_FLOW_2_CHAMBER + 2,
    vr::EXTRA_FLOW_3_CHAMBER,
    vr::EXTRA_FLOW_3_CHAMBER + 1,
    vr::EXTRA_FLOW_3_CHAMBER + 2,
    vr::EXTRA_FORCE_OFFSET,
    vr::EXTRA_INFLOW_1,
    vr::EXTRA_INFLOW_2,
];

impl Parameters {
    pub(crate) fn field_mut(&mut self, value_reference: u32) -> Option<&mut f64> {
        Some(match value_reference {
            vr::P_S => &mut self.p_s,
            vr::P_R => &mut self.p_r,
            vr::T_GAS => &mut self.temperature,
            vr::GAMMA => &mut self.gamma,
            vr::R_GAS => &mut self.r_gas,
            vr::K_CD => &mut self.k_cd,
            vr::I_OFFSET => &mut self.i_offset,
            vr::OMEGA_CD => &mut self.omega_cd,
            vr::K_M => &mut self.k_m,
            vr::OMEGA_1 => &mut self.omega_1,
            vr::OMEGA_2 => &mut self.omega_2,
            vr::ZETA_2 => &mut self.zeta_2,
            vr::X_JP_SAT => &mut self.x_jp_sat,
            vr::F_JP_SAT => &mut self.f_jp_sat,
            vr::X_JP_OFFSET => &mut self.x_jp_offset,
            vr::D_JP => &mut self.d_jp,
            vr::C_D => &mut self.c_d,
            vr::C_DM_A_LPP => &mut self.c_dm_a_lpp,
            vr::C_DB_A_LPP => &mut self.c_db_a_lpp,
            vr::L_CYL => &mut self.l_cyl,
            vr::L_P => &mut self.l_p,
            vr::L_S => &mut self.l_s,
            vr::L_SUP => &mut self.l_sup,
            vr::L_SPRING0 => &mut self.l_spring0,
            vr::D_CYL => &mut self.d_cyl,
            vr::K_SPRING => &mut self.k_spring,
            vr::HYSTERESIS_WIDTH => &mut self.hysteresis_width,
            vr::HYSTERESIS_DEADBAND => &mut self.hysteresis_deadband,
            vr::HYSTERESIS_EXPONENT => &mut self.hysteresis_exponent,
            vr::HYSTERESIS_GAIN => &mut self.hysteresis_gain,
            vr::HYSTERESIS_BETA_SHARE => &mut self.hysteresis_beta_share,
            vr::HYSTERESIS_START => &mut self.hysteresis_start,
            vr::FRICTION_COULOMB => &mut self.friction_coulomb,
            vr::FRICTION_VELOCITY => &mut self.friction_velocity,
            vr::FRICTION_STRIBECK => &mut self.friction_stribeck,
            vr::FRICTION_STRIBECK_VELOCITY => &mut self.friction_stribeck_velocity,
            vr::DEAD_VOLUME_1 => &mut self.dead_volume_1,
            vr::DEAD_VOLUME_2 => &mut self.dead_volume_2,
            vr::SUPPLY_RESISTANCE => &mut self.supply_resistance,
            vr::HEAT_TRANSFER_FRACTION => &mut self.heat_transfer_fraction,
            vr::COMMAND_DELAY => &mut self.command_delay,
            vr::FORCE_SENSOR_OFFSET => &mut self.force_sensor_offset,
            vr::FORCE_SENSOR_GAIN => &mut self.force_sensor_gain,
            vr::SUPPLY_AREA_SCALE_1 => &mut self.supply_area_scale_1,
            vr::SUPPLY_AREA_SCALE_2 => &mut self.supply_area_scale_2,
            vr::RETURN_AREA_SCALE_1 => &mut self.return_area_scale_1,
            vr::RETURN_AREA_SCALE_2 => &mut self.return_area_scale_2,
            vr::RETURN_RESISTANCE => &mut self.return_resistance,
            vr::CHAMBER_VENT_1 => &mut self.chamber_vent_1,
            vr::CHAMBER_VENT_2 => &mut self.chamber_vent_2,
            vr::CHAMBER_SUPPLY_LEAK_1 => &mut self.chamber_supply_leak_1,
            vr::CHAMBER_SUPPLY_LEAK_2 => &mut self.chamber_supply_leak_2,
            vr::CHAMBER_LAMINAR_VENT_1 => &mut self.chamber_laminar_vent_1,
            vr::CHAMBER_LAMINAR_VENT_2 => &mut self.chamber_laminar_vent_2,
            vr::CHAMBER_LAMINAR_SUPPLY_LEAK_1 => &mut self.chamber_laminar_supply_leak_1,
            vr::CHAMBER_LAMINAR_SUPPLY_LEAK_2 => &mut self.chamber_laminar_supply_leak_2,
            vr::CHAMBER_LAMINAR_CROSS_LEAK => &mut self.chamber_laminar_cross_leak,
            vr::PORT_RESISTANCE_1 => &mut self.port_resistance_1,
            vr::PORT_RESISTANCE_2 => &mut self.port_resistance_2,
            vr::STOPPER_COMPLIANCE => &mut self.stopper_compliance,
            vr::STOPPER_MOUNT_LAG => &mut self.stopper_mount_lag,
            vr::COMMAND_LAG => &mut self.command_lag,
            vr::COMMAND_FILTER_FREQUENCY => &mut self.command_filter_frequency,
            vr::COMMAND_FILTER_DAMPING => &mut self.command_filter_damping,
            vr::COMMAND_LIMIT => &mut self.command_limit,
            vr::COMMAND_UPPER_LIMIT => &mut self.command_upper_limit,
            vr::COMMAND_LOWER_LIMIT => &mut self.command_lower_limit,
            vr::COMMAND_QUANTUM => &mut self.command_quantum,
            vr::COMMAND_QUANTUM_ORIGIN => &mut self.command_quantum_origin,
            vr::COMMAND_QUANTUM_THRESHOLD => &mut self.command_quantum_threshold,
            vr::CURRENT_LIMIT => &mut self.current_limit,
            vr::CURRENT_SLEW_LIMIT => &mut self.current_slew_limit,
            vr::F3_INPUT_CUBIC => &mut self.f3_input_cubic,
            vr::F3_ALGEBRAIC_SHARE => &mut self.f3_algebraic_share,
            vr::FORCE_SENSOR_QUADRATIC => &mut self.force_sensor_quadratic,
            vr::FORCE_SENSOR_CUBIC => &mut self.force_sensor_cubic,
            vr::FORCE_SENSOR_DRIFT => &mut self.force_sensor_drift,
            vr::FORCE_SENSOR_LAG => &mut self.force_sensor_lag,
            vr::FORCE_SENSOR_DELAY => &mut self.force_sensor_delay,
            vr::FORCE_SENSOR_PLAY => &mut self.force_sensor_play,
            vr::FORCE_SENSOR_RIPPLE_SINE => &mut self.force_sensor_ripple_sine,
            vr::FORCE_SENSOR_RIPPLE_FREQUENCY => &mut self.force_sensor_ripple_frequency,
            vr::FORCE_SENSOR_RIPPLE_COSINE => &mut self.force_sensor_ripple_cosine,
            vr::FORCE_SENSOR_FILTER_FREQUENCY => &mut self.force_sensor_filter_frequency,
            vr::FORCE_SENSOR_FILTER_DAMPING => &mut self.force_sensor_filter_damping,
            vr::VISCOUS_FRICTION => &mut self.viscous_friction,
            vr::POSITION_FORCE_RATE => &mut self.position_force_rate,
            vr::POSITION_FORCE_REFERENCE => &mut self.position_force_reference,
            vr::EXTRA_FORCE_ACCELERATION => &mut self.extra_force_acceleration,
            vr::EXTRA_FORCE_VELOCITY_SQUARED => &mut self.extra_force_velocity_squared,
            vr::EXTRA_FORCE_SIGN_PRESSURE => &mut self.extra_force_sign_pressure,
            vr::EXTRA_FORCE_PRESSURE_DIFFERENCE => &mut self.extra_force_pressure_difference,
            vr::EXTRA_FORCE_SIGN_VELOCITY => &mut self.extra_force_sign_velocity,
            vr::STOPPER_ACCELERATION_INPUT_SHARE => &mut self.stopper_acceleration_input_share,
            vr::RETURN_VENT_AREA => &mut self.return_vent_area,
            vr::SUPPLY_DRIFT => &mut self.supply_drift,
            vr::SUPPLY_RIPPLE_SINE => &mut self.supply_ripple_sine,
            vr::SUPPLY_RIPPLE_FREQUENCY => &mut self.supply_ripple_frequency,
            vr::SUPPLY_RIPPLE_COSINE => &mut self.supply_ripple_cosine,
            vr::X_JP_OFFSET_DRIFT => &mut self.x_jp_offset_drift,
            vr::T_DRIFT => &mut self.t_drift,
            vr::P1_SENSOR_OFFSET => &mut self.p1_sensor_offset,
            vr::P1_SENSOR_GAIN => &mut self.p1_sensor_gain,
            vr::P1_SENSOR_DRIFT => &mut self.p1_sensor_drift,
            vr::P1_SENSOR_LAG => &mut self.p1_sensor_lag,
            vr::P1_SENSOR_DELAY => &mut self.p1_sensor_delay,
            vr::P1_SENSOR_FILTER_FREQUENCY => &mut self.p1_sensor_filter_frequency,
            vr::P1_SENSOR_FILTER_DAMPING => &mut self.p1_sensor_filter_damping,
            vr::P2_SENSOR_OFFSET => &mut self.p2_sensor_offset,
            vr::P2_SENSOR_GAIN => &mut self.p2_sensor_gain,
            vr::P2_SENSOR_DRIFT => &mut self.p2_sensor_drift,
            vr::P2_SENSOR_LAG => &mut self.p2_sensor_lag,
            vr::P2_SENSOR_DELAY => &mut self.p2_sensor_delay,
            vr::P2_SENSOR_FILTER_FREQUENCY => &mut self.p2_sensor_filter_frequency,
            vr::P2_SENSOR_FILTER_DAMPING => &mut self.p2_sensor_filter_damping,
            vr::SUPPLY_RESTRICTION_AREA => &mut self.supply_restriction_area,
            vr::SUPPLY_PLENUM_VOLUME => &mut self.supply_plenum_volume,
            vr::RETURN_PLENUM_VOLUME => &mut self.return_plenum_volume,
            vr::PORT_RESTRICTION_AREA_1 => &mut self.port_restriction_area_1,
            vr::PORT_RESTRICTION_AREA_2 => &mut self.port_restriction_area_2,
            vr::PORT_LINE_VOLUME_1 => &mut self.port_line_volume_1,
            vr::PORT_LINE_VOLUME_2 => &mut self.port_line_volume_2,
            vr::EXTRA_FORCE_OFFSET => &mut self.extra_force_offset,
            vr::EXTRA_INFLOW_1 => &mut self.extra_inflow_1,
            vr::EXTRA_INFLOW_2 => &mut self.extra_inflow_2,
            vr::COMMAND_CURVE_KNOTS => &mut self.command_curve.knots,
            r @ vr::COMMAND_CURVE_X..=vr::COMMAND_CURVE_X_LAST => {
                &mut self.command_curve.x[(r - vr::COMMAND_CURVE_X) as usize]
            }
            r @ vr::COMMAND_CURVE_Y..=vr::COMMAND_CURVE_Y_LAST => {
                &mut self.command_curve.y[(r - vr::COMMAND_CURVE_Y) as usize]
            }
            vr::FORCE_SENSOR_CURVE_KNOTS => &mut self.force_sensor_curve.knots,
            r @ vr::FORCE_SENSOR_CURVE_X..=vr::FORCE_SENSOR_CURVE_X_LAST => {
                &mut self.force_sensor_curve.x[(r - vr::FORCE_SENSOR_CURVE_X) as usize]
            }
            r @ vr::FORCE_SENSOR_CURVE_Y..=vr::FORCE_SENSOR_CURVE_Y_LAST => {
                &mut self.force_sensor_curve.y[(r - vr::FORCE_SENSOR_CURVE_Y) as usize]
            }
            vr::P1_SENSOR_CURVE_KNOTS => &mut self.p1_sensor_curve.knots,
            r @ vr::P1_SENSOR_CURVE_X..=vr::P1_SENSOR_CURVE_X_LAST => {
                &mut self.p1_sensor_curve.x[(r - vr::P1_SENSOR_CURVE_X) as usize]
            }
            r @ vr::P1_SENSOR_CURVE_Y..=vr::P1_SENSOR_CURVE_Y_LAST => {
                &mut self.p1_sensor_curve.y[(r - vr::P1_SENSOR_CURVE_Y) as usize]
            }
            vr::P2_SENSOR_CURVE_KNOTS => &mut self.p2_sensor_curve.knots,
            r @ vr::P2_SENSOR_CURVE_X..=vr::P2_SENSOR_CURVE_X_LAST => {
                &mut self.p2_sensor_curve.x[(r - vr::P2_SENSOR_CURVE_X) as usize]
            }
            r @ vr::P2_SENSOR_CURVE_Y..=vr::P2_SENSOR_CURVE_Y_LAST => {
                &mut self.p2_sensor_curve.y[(r - vr::P2_SENSOR_CURVE_Y) as usize]
            }
            vr::DISCHARGE_CURVE_KNOTS => &mut self.discharge_curve.knots,
            r @ vr::DISCHARGE_CURVE_X..=vr::DISCHARGE_CURVE_X_LAST => {
                &mut self.discharge_curve.x[(r - vr::DISCHARGE_CURVE_X) as usize]
            }
            r @ vr::DISCHARGE_CURVE_Y..=vr::DISCHARGE_CURVE_Y_LAST => {
                &mut self.discharge_curve.y[(r - vr::DISCHARGE_CURVE_Y) as usize]
            }
            r @ vr::MODULATION_1_PARAMETER..=vr::MODULATION_LAST => {
                return super::modulation::field_mut(&mut self.modulation, r)
            }
            r @ vr::EXTRA_FORCE_PRODUCT_1_FIRST..=vr::EXTRA_FORCE_PRODUCT_LAST => {
                return super::extra_force::product_field_mut(&mut self.extra_force_products, r)
            }
            r @ vr::EXTRA_FLOW_1_CHAMBER..=vr::EXTRA_FLOW_LAST => {
                return super::extra_flow::flow_field_mut(&mut self.extra_flows, r)
            }
            r @ vr::FLEXIBLE_1_PARAMETER..=vr::FLEXIBLE_LAST => {
                return super::flexible::field_mut(&mut self.flexible, r)
            }
            _ => return None,
        })
    }

    /// The (min, max) that [`Parameters::set`] enforces on a parameter, as the variable table
    /// declares them (FMI's bounds are closed: "> 0" is declared as min 0).
    pub fn declared_range(value_reference: u32) -> Option<(Option<f64>, Option<f64>)> {
        Parameters::default().field_mut(value_reference)?;
        let v = &crate::variables::row(value_reference)?.variable;
        Some((v.min, v.max))
    }

    /// Value of the parameter with this value reference, if it is one.
    pub fn get(&self, value_reference: u32) -> Option<f64> {
        let mut copy = self.clone();
        copy.field_mut(value_reference).map(|f| *f)
    }

    /// Set one parameter within the limits of its row of the variable table (the FMU's
    /// setters, `jetpipe sweep` and `--params` files all come here). The message names the
    /// variable, the value and the limit.
    pub fn set(&mut self, value_reference: u32, value: f64) -> Result<(), String> {
        let field = self
            .field_mut(value_reference)
            .ok_or_else(|| format!("value reference {value_reference} is not a parameter of the model"))?;
        crate::variables::check(value_reference, value)?;
        *field = value;
        Ok(())
    }

    /// The jet_pipe_hysteresis operator these parameters describe.
    pub fn hysteresis(&self) -> super::effects::Hysteresis {
        super::effects::Hysteresis::new(
            self.hysteresis_width,
            self.hysteresis_deadband,
            self.hysteresis_exponent,
            self.hysteresis_gain,
            self.hysteresis_beta_share,
        )
    }

    /// Checks that involve several parameters (run before initialisation).
    pub fn validate(&self) -> Result<(), String> {
        if self.p_s < self.p_r {
            return Err(format!(
                "P_s = {} Pa is invalid: must be >= P_r = {} Pa (a supply below the return pressure would blow the air backwards through the valve; equal is the unpressurised actuator of §3.3.1)",
                number(self.p_s),
                number(self.p_r)
            ));
        }
        if self.c_db_a_lpp + self.c_dm_a_lpp < 0.0 {
            return Err(format!(
                "C_db_A_lpp + C_dm_A_lpp = {} m2 is invalid: the leakage area (2.23) must stay >= 0 for every pressure ratio",
                self.c_db_a_lpp + self.c_dm_a_lpp
            ));
        }
        if self.command_lower_limit >= self.command_upper_limit {
            return Err(format!(
                "command_lower_limit = {} V is invalid: must be below command_upper_limit = {} V",
                self.command_lower_limit, self.command_upper_limit
            ));
        }
        if self.hysteresis_deadband > self.hysteresis_width {
            return Err(format!(
                "hysteresis_deadband = {} m is invalid: must not exceed hysteresis_width = {} m",
                self.hysteresis_deadband, self.hysteresis_width
            ));
        }
        if self.hysteresis_exponent > 0.0 && self.hysteresis_deadband > 0.0 {
            return Err(format!(
                "hysteresis_deadband = {} m is invalid with hysteresis_exponent = {}: the deadband belongs to the play law (exponent 0); the Bouc-Wen law has none",
                self.hysteresis_deadband, self.hysteresis_exponent
            ));
        }
        super::restrictions::check(self)?;
        self.command_curve.check("command_curve", "V")?;
        self.force_sensor_curve.check("force_sensor_curve", "N")?;
        self.p1_sensor_curve.check("p1_sensor_curve", "Pa")?;
        self.p2_sensor_curve.check("p2_sensor_curve", "Pa")?;
        self.discharge_curve.check("discharge_curve", "1")?;
        if self.l_cyl <= self.l_p {
            return Err(format!(
                "L_cyl = {} m is invalid: must exceed L_p = {} m",
                self.l_cyl, self.l_p
            ));
        }
        super::extra_force::check_products(&self.extra_force_products)?;
        super::extra_flow::check_flows(&self.extra_flows)?;
        // Last: they validate the model with each slot's constant at each of its knots.
        super::modulation::validate(self)?;
        super::flexible::validate(self)
    }

    pub fn cylinder(&self) -> CylinderGeometry {
        CylinderGeometry {
            l_cyl: self.l_cyl,
            l_p: self.l_p,
            l_s: self.l_s,
            l_sup: self.l_sup,
            d_cyl: self.d_cyl,
            dead_volume_1: self.dead_volume_1,
            dead_volume_2: self.dead_volume_2,
        }
    }

    pub fn flow_constants(&self) -> FlowConstants {
        FlowConstants::new(self.gamma, self.r_gas, self.temperature)
    }

    /// Check a stopper position against the cylinder (both volumes positive).
    pub fn check_stopper(&self, x_s: f64) -> Result<(), String> {
        let (lo, hi) = self.cylinder().stopper_range();
        if !x_s.is_finite() || x_s <= lo || x_s >= hi {
            return Err(format!(
                "x_s = {x_s} m is outside the cylinder: both chamber volumes must be positive, {lo} < x_s < {hi} m"
            ));
        }
        Ok(())
    }
}

/// Name of a variable of the table, for messages.
pub fn variable_name(value_reference: u32) -> &'static str {
    VARIABLES
        .iter()
        .find(|v| v.value_reference == value_reference)
        .map(|v| v.name)
        .unwrap_or("<unknown>")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_table_3_1() {
        let p = Parameters::default();
        assert_eq!(p.k_m, 1.946);
        assert_eq!(p.omega_cd, 7050.0);
        assert_eq!(p.c_dm_a_lpp, -0.0475e-6);
        assert_eq!(p.p_s, 652_925.0);
        assert!(p.validate().is_ok());
    }

    #[test]
    fn a_deadband_with_the_bouc_wen_law_is_refused_by_name() {
        let mut p = Parameters {
            hysteresis_width: 0.16e-3,
            hysteresis_exponent: 2.0,
            ..Default::default()
        };
        assert!(p.validate().is_ok());
        p.hysteresis_deadband = 0.05e-3;
        let e = p.validate().unwrap_err();
        assert!(
            e.contains("hysteresis_deadband = 0.00005") && e.contains("hysteresis_exponent = 2"),
            "{e}"
        );
        p.hysteresis_exponent = 0.0;
        assert!(p.validate().is_ok());
    }

    /// The list that defaults, copies and the FMU state go through must hold every parameter
    /// of the variable table, or a new one is silently left at its start value there.
    #[test]
    fn every_parameter_of_the_table_is_a_listed_field() {
        let parameters: Vec<u32> = crate::variables::TABLE
            .iter()
            .map(|row| row.variable)
            .filter(|v| v.causality == crate::variable::Causality::Parameter)
            .map(|v| v.value_reference)
            // How a run starts, not a constant of the model.
            .filter(|vr| ![vr::START_AT_EQUILIBRIUM, vr::P1_START, vr::P2_START].contains(vr))
            .collect();
        let mut listed = Parameters::VALUE_REFERENCES.to_vec();
        listed.sort_unstable();
        let mut expected = parameters.clone();
        expected.sort_unstable();
        assert_eq!(listed, expected);
        for vr in parameters {
            assert!(Parameters::default().field_mut(vr).is_some(), "{}", variable_name(vr));
        }
    }

    #[test]
    fn bad_values_are_rejected_with_name_and_value() {
        let mut p = Parameters::default();
        let e = p.set(vr::P_S, -5.0).unwrap_err();
        assert!(e.contains("P_s") && e.contains("-5"), "{e}");
        let e = p.set(vr::C_D, f64::NAN).unwrap_err();
        assert!(e.contains("C_d") && e.contains("NaN"), "{e}");
        assert!(p.set(vr::D_CYL, 0.0).is_err());
        assert_eq!(p.p_s, 652_925.0, "a rejected value leaves the parameter unchanged");
        let e = p.check_stopper(0.02).unwrap_err();
        assert!(e.contains("x_s") && e.contains("0.02"), "{e}");
    }
}
