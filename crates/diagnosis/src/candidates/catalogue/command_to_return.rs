//! The written candidates along the chain from the command to the return line: the command
//! path, the current driver, the jet pipe, the valve, the supply and the return.

use super::terms::{
    c, corner, modulated, parameter, searched, started, term_off, volume_behind, BOUC_WEN_START, BOUC_WEN_START_WIDTH,
};
use crate::candidates::parameter_value;
use crate::candidates::Candidate;
use crate::candidates::Mechanism;
use crate::candidates::Modulation;
use crate::candidates::Term;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;

/// The written candidates from the command to the return line, in the chain's order.
pub(super) fn command_to_return(base: &Parameters) -> Vec<Candidate> {
    let p = |name, unit, relative, lower, upper| parameter(base, name, unit, relative, lower, upper);
    let offset = |name, unit, step, lower, upper| Term {
        step,
        ..parameter(base, name, unit, 0.0, lower, upper)
    };
    let inf = f64::INFINITY;
    vec![
        c(
            "command delay",
            Place::Command,
            Family::Delay,
            Some("transport_delay"),
            vec![term_off("command_delay", "s", 1e-3, 0.05)],
        ),
        c(
            "command lag",
            Place::Command,
            Family::Dynamics,
            None,
            vec![Term {
                name: "command_lag",
                unit: "s",
                mechanism: Mechanism::CommandLag,
                neutral: 0.0,
                step: 1e-3,
                lower: 0.0,
                upper: 0.2,
            }],
        ),
        c(
            "command second-order filter",
            Place::Command,
            Family::Dynamics,
            None,
            // The natural frequency searched on a logarithmic scale (a corner far above the
            // signals barely moves the outputs), then refined with the damping.
            vec![
                Term {
                    name: "command_filter_frequency",
                    unit: "Hz",
                    mechanism: Mechanism::Searched("command_filter_frequency"),
                    neutral: 0.0,
                    step: 0.0,
                    lower: 1.0,
                    upper: 1000.0,
                },
                started(
                    "command_filter_damping",
                    "1",
                    std::f64::consts::FRAC_1_SQRT_2,
                    0.05,
                    0.2,
                    5.0,
                ),
            ],
        ),
        c(
            "command limit",
            Place::Command,
            Family::Limit,
            None,
            vec![searched("command_limit", "V", Mechanism::CommandLimit, 0.0, inf)],
        ),
        // A D/A or a driver stage that saturates on one side only (a supply rail): the
        // symmetric limit would clip the other side too, where a closed loop drives the
        // command. Off at ±100 V.
        // A D/A of fewer bits than the logger's: the command the driver sees takes its levels.
        c(
            "command quantiser",
            Place::Command,
            Family::Nonlinearity,
            None,
            vec![Term {
                neutral: 0.0,
                ..searched(
                    "command_quantum",
                    "V",
                    Mechanism::Searched("command_quantum"),
                    0.0,
                    10.0,
                )
            }],
        ),
        c(
            "command upper limit",
            Place::Command,
            Family::Limit,
            None,
            vec![Term {
                neutral: 100.0,
                ..searched(
                    "command_upper_limit",
                    "V",
                    Mechanism::Searched("command_upper_limit"),
                    -100.0,
                    100.0,
                )
            }],
        ),
        c(
            "command lower limit",
            Place::Command,
            Family::Limit,
            None,
            vec![Term {
                neutral: -100.0,
                ..searched(
                    "command_lower_limit",
                    "V",
                    Mechanism::Searched("command_lower_limit"),
                    -100.0,
                    100.0,
                )
            }],
        ),
        c(
            "current driver gain and offset",
            Place::CurrentDriver,
            Family::ParameterOffset,
            None,
            vec![
                p("k_cd", "A/V", 0.01, 0.0, inf),
                offset("i_offset", "A", 1e-3, -0.2, 0.2),
            ],
        ),
        c(
            "current driver corner",
            Place::CurrentDriver,
            Family::Dynamics,
            None,
            vec![Term {
                name: "current_driver_time_constant",
                unit: "s",
                mechanism: Mechanism::TimeConstantOf("omega_cd"),
                neutral: 1.0 / parameter_value(base, "omega_cd"),
                step: 2e-5,
                lower: 1e-5,
                upper: 0.01,
            }],
        ),
        c(
            "current limit",
            Place::CurrentDriver,
            Family::Limit,
            None,
            vec![searched("current_limit", "A", Mechanism::CurrentLimit, 0.0, inf)],
        ),
        c(
            "current slew limit",
            Place::CurrentDriver,
            Family::Limit,
            None,
            vec![searched(
                "current_slew_limit",
                "A/s",
                Mechanism::CurrentSlewLimit,
                0.05,
                200.0,
            )],
        ),
        c(
            "jet pipe null",
            Place::JetPipe,
            Family::ParameterOffset,
            None,
            vec![offset("x_jp_offset", "m", 2e-6, -1e-3, 1e-3)],
        ),
        c(
            "jet pipe null and travel",
            Place::JetPipe,
            Family::ParameterOffset,
            None,
            vec![
                offset("x_jp_offset", "m", 2e-6, -1e-3, 1e-3),
                p("x_jp_sat", "m", 0.01, 1e-5, 5e-3),
            ],
        ),
        c(
            "jet pipe static curve",
            Place::JetPipe,
            Family::Nonlinearity,
            None,
            vec![
                Term {
                    name: "f3_input_cubic",
                    unit: "V",
                    mechanism: Mechanism::InputCubic,
                    neutral: 0.0,
                    step: 0.05,
                    lower: -5.0,
                    upper: 5.0,
                },
                p("x_jp_sat", "m", 0.01, 1e-5, 5e-3),
            ],
        ),
        c(
            "jet pipe static curve with a softer knee",
            Place::JetPipe,
            Family::Nonlinearity,
            None,
            vec![term_off("f3_algebraic_share", "1", 0.05, 1.0)],
        ),
        c(
            "jet and receiver diameter",
            Place::Valve,
            Family::ParameterOffset,
            None,
            // D_jp sets the receiver's geometry, (2.8)–(2.17): the areas' shape along the jet's
            // travel, not only their size.
            vec![p("D_jp", "m", 0.01, 1e-4, 5e-3)],
        ),
        c(
            "jet pipe lag",
            Place::JetPipe,
            Family::Dynamics,
            None,
            vec![corner(base, "omega_1", 10.0, 1e4)],
        ),
        c(
            "jet pipe resonance",
            Place::JetPipe,
            Family::Dynamics,
            None,
            // ω2 and ζ2 of (2.6): the modal form the model steps with needs ζ2 below 1.
            vec![
                p("omega_2", "rad/s", 0.01, 100.0, 1e5),
                offset("zeta_2", "1", 0.01, 0.001, 0.95),
            ],
        ),
        c(
            "jet pipe hysteresis",
            Place::JetPipe,
            Family::Hysteresis,
            Some("jet_pipe_hysteresis"),
            vec![
                term_off("hysteresis_width", "m", 2e-5, 1e-3),
                term_off("hysteresis_deadband", "m", 5e-6, 1e-3),
                offset("hysteresis_start", "1", 0.05, -1.0, 1.0),
            ],
        ),
        Candidate {
            settings: vec![
                ("hysteresis_exponent", BOUC_WEN_START[0]),
                ("hysteresis_width", BOUC_WEN_START_WIDTH),
            ],
            ..c(
                "jet pipe hysteresis, smooth law",
                Place::JetPipe,
                Family::Hysteresis,
                Some("jet_pipe_hysteresis"),
                vec![
                    started("hysteresis_width", "m", BOUC_WEN_START_WIDTH, 2e-6, 0.0, 1e-3),
                    started("hysteresis_exponent", "1", BOUC_WEN_START[0], 0.1, 0.5, 50.0),
                    started("hysteresis_gain", "1", BOUC_WEN_START[1], 0.02, 0.05, 2.0),
                    started("hysteresis_beta_share", "1", BOUC_WEN_START[2], 0.02, 0.0, 1.0),
                    offset("hysteresis_start", "1", 0.05, -1.0, 1.0),
                ],
            )
        },
        c(
            "jet pipe null drift",
            Place::JetPipe,
            Family::Drift,
            None,
            vec![
                offset("x_jp_offset", "m", 2e-6, -1e-3, 1e-3),
                modulated("x_jp_offset_drift", "m", "x_jp_offset", Modulation::Ramp, 1e-6),
            ],
        ),
        c(
            "discharge coefficient",
            Place::Valve,
            Family::ParameterOffset,
            None,
            vec![p("C_d", "1", 0.01, 1e-3, 1.0)],
        ),
        c(
            "orifice areas port by port",
            Place::Valve,
            Family::Asymmetry,
            None,
            vec![
                p("supply_area_scale_1", "1", 0.01, 0.0, 3.0),
                p("supply_area_scale_2", "1", 0.01, 0.0, 3.0),
                p("return_area_scale_1", "1", 0.01, 0.0, 3.0),
                p("return_area_scale_2", "1", 0.01, 0.0, 3.0),
            ],
        ),
        c(
            "port restrictions",
            Place::Valve,
            Family::Restriction,
            None,
            vec![
                term_off("port_resistance_1", "Pa.s/kg", 1e8, 1e11),
                term_off("port_resistance_2", "Pa.s/kg", 1e8, 1e11),
            ],
        ),
        c(
            "port 1 orifice with a line volume",
            Place::Valve,
            Family::Restriction,
            None,
            volume_behind("port_restriction_area_1", "port_line_volume_1"),
        ),
        c(
            "port 2 orifice with a line volume",
            Place::Valve,
            Family::Restriction,
            None,
            volume_behind("port_restriction_area_2", "port_line_volume_2"),
        ),
        c(
            "supply pressure",
            Place::Supply,
            Family::ParameterOffset,
            None,
            vec![p("P_s", "Pa", 0.005, 1.2e5, 2e6)],
        ),
        c(
            "supply line resistance",
            Place::Supply,
            Family::Restriction,
            Some("supply_pressure_drop"),
            vec![term_off("supply_resistance", "Pa.s/kg", 1e8, 1e11)],
        ),
        c(
            "supply orifice with a plenum",
            Place::Supply,
            Family::Restriction,
            Some("supply_pressure_drop"),
            volume_behind("supply_restriction_area", "supply_plenum_volume"),
        ),
        c(
            "supply pressure drift",
            Place::Supply,
            Family::Drift,
            None,
            vec![
                p("P_s", "Pa", 0.005, 1.2e5, 2e6),
                modulated("P_s_drift", "Pa", "P_s", Modulation::Ramp, 1e3),
            ],
        ),
        c(
            "return pressure",
            Place::Return,
            Family::ParameterOffset,
            None,
            vec![p("P_r", "Pa", 0.01, 1e4, 6e5)],
        ),
        c(
            "return line resistance",
            Place::Return,
            Family::Restriction,
            None,
            vec![term_off("return_resistance", "Pa.s/kg", 1e8, 1e11)],
        ),
        c(
            "return vent orifice with a plenum",
            Place::Return,
            Family::Restriction,
            None,
            volume_behind("return_vent_area", "return_plenum_volume"),
        ),
    ]
}
