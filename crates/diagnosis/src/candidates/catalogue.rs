//! The candidates: every correction the diagnosis tries, place by place, as instances of the
//! three general mechanisms of [`super`].

use crate::candidates::parameter_value;
use crate::candidates::Candidate;
use crate::candidates::Filter;
use crate::candidates::Mechanism;
use crate::candidates::Modulation;
use crate::candidates::Regressor;
use crate::candidates::Term;
use crate::replay::signals::FORCE;
use crate::replay::signals::P1;
use crate::replay::signals::P2;
use jetpipe_model::physics::parameters::Parameters;

fn parameter(base: &Parameters, name: &'static str, unit: &'static str, relative: f64, lower: f64, upper: f64) -> Term {
    let neutral = parameter_value(base, name);
    Term {
        name,
        unit,
        mechanism: Mechanism::Parameter(name),
        neutral,
        step: relative * neutral.abs().max(1e-30),
        lower,
        upper,
    }
}

fn term_off(name: &'static str, unit: &'static str, step: f64, upper: f64) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Parameter(name),
        neutral: 0.0,
        step,
        lower: 0.0,
        upper,
    }
}

/// A restriction as an orifice ([`orifice_area`]) and the gas volume behind it. The orifice
/// alone is the volume's limit at zero, where its refinement may take it: a quasi-static
/// orifice needs a root at every evaluation, and a replay with it takes two to three times
/// as long, so it is not a candidate of its own. The area is searched with a
/// volume that fills within a tenth of a millisecond (0.1 cm³: the restriction nearly alone,
/// at the cost of the fast replay's fixed steps rather than a root at every evaluation), then
/// both are refined together ([`Mechanism::Searched`] followed by parameters).
fn volume_behind(area: &'static str, volume: &'static str) -> Vec<Term> {
    vec![orifice_area(area), started(volume, "m3", 1e-7, 2e-7, 0.0, 1e-4)]
}

/// A corner frequency (rad/s) searched over `lower`–`upper` on a logarithmic scale: the
/// outputs barely move with a corner far above the signals' frequencies, so one Gauss–Newton
/// step from the thesis's fast corner does not reach a slow one (the jet pipe's 974 rad/s
/// against an extra 15 ms lag, 60 rad/s together).
fn corner(base: &Parameters, name: &'static str, lower: f64, upper: f64) -> Term {
    Term {
        name,
        unit: "rad/s",
        mechanism: Mechanism::Searched(name),
        neutral: parameter_value(base, name),
        step: 0.0,
        lower,
        upper,
    }
}

/// An orifice's C_d·A (m²), searched over 0.01–10 mm² on a logarithmic scale: it is off at
/// zero area and at an infinite one.
fn orifice_area(name: &'static str) -> Term {
    Term {
        name,
        unit: "m2",
        mechanism: Mechanism::Searched(name),
        neutral: 0.0,
        step: 0.0,
        lower: 1e-8,
        upper: 1e-5,
    }
}

/// Where the Bouc–Wen law's fit starts: exponent, gain and β share (a rounded bend, the
/// output still at a reversal, symmetric).
const BOUC_WEN_START: [f64; 3] = [2.0, 1.0, 0.5];
/// The thesis's width of the position/current loop (§3.2.1, 0.16 mm): with the law on from
/// the start, its shape parameters have sensitivities at the first step.
const BOUC_WEN_START_WIDTH: f64 = 0.16e-3;

/// A parameter whose fit starts at `start` rather than at the base model's value (a law's
/// shape, which only matters once the law is on).
fn started(name: &'static str, unit: &'static str, start: f64, step: f64, lower: f64, upper: f64) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Parameter(name),
        neutral: start,
        step,
        lower,
        upper,
    }
}

fn output(name: &'static str, unit: &'static str, channel: usize, regressor: Regressor, step: f64) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Output { channel, regressor },
        neutral: 0.0,
        step,
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
    }
}

fn filter(name: &'static str, unit: &'static str, channel: usize, filter: Filter, lower: f64, upper: f64) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::OutputFilter { channel, filter },
        neutral: 0.0,
        step: 0.0,
        lower,
        upper,
    }
}

/// A second-order low-pass filter on a measured channel: its natural frequency searched on
/// a logarithmic scale for each damping ratio tried (the damping a shape, 0.2–5).
fn second_order(frequency: &'static str, damping: &'static str, channel: usize) -> Vec<Term> {
    vec![
        filter(
            frequency,
            "Hz",
            channel,
            Filter::SecondOrder(std::f64::consts::FRAC_1_SQRT_2),
            1.0,
            2000.0,
        ),
        Term {
            name: damping,
            unit: "1",
            mechanism: Mechanism::Shape,
            neutral: std::f64::consts::FRAC_1_SQRT_2,
            step: 0.0,
            lower: 0.2,
            upper: 5.0,
        },
    ]
}

fn modulated(
    name: &'static str,
    unit: &'static str,
    parameter: &'static str,
    modulation: Modulation,
    step: f64,
) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Modulated { parameter, modulation },
        neutral: 0.0,
        step,
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
    }
}

/// Every candidate, for a base model and a recording with or without pressures.
/// `periodic_hz` is the residual's spectral line, if it has one. Where two places fit
/// alike (a command limit and a current limit), the earlier in the chain comes first and
/// wins the tie.
/// `knots` places the static curves' knots ([`crate::candidates::curves`]).
pub fn catalogue(
    base: &Parameters,
    has_pressures: bool,
    periodic_hz: Option<f64>,
    knots: &crate::candidates::curves::CurveKnots,
) -> Vec<Candidate> {
    let c = |label, location, family, named, terms| Candidate {
        label,
        location,
        family,
        named,
        terms,
        settings: vec![],
    };
    let p = |name, unit, relative, lower, upper| parameter(base, name, unit, relative, lower, upper);
    let offset = |name, unit, step, lower, upper| Term {
        step,
        ..parameter(base, name, unit, 0.0, lower, upper)
    };
    let searched = |name, unit, mechanism, lower, upper| Term {
        name,
        unit,
        mechanism,
        neutral: f64::INFINITY,
        step: 0.0,
        lower,
        upper,
    };
    let inf = f64::INFINITY;
    let mut list = vec![
        c(
            "command delay",
            "command",
            "delay",
            Some("transport_delay"),
            vec![term_off("command_delay", "s", 1e-3, 0.05)],
        ),
        c(
            "command lag",
            "command",
            "dynamics",
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
            "command",
            "dynamics",
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
            "command",
            "limit",
            None,
            vec![searched("command_limit", "V", Mechanism::CommandLimit, 0.0, inf)],
        ),
        // A D/A or a driver stage that saturates on one side only (a supply rail): the
        // symmetric limit would clip the other side too, where a closed loop drives the
        // command. Off at ±100 V.
        // A D/A of fewer bits than the logger's: the command the driver sees takes its levels.
        c(
            "command quantiser",
            "command",
            "nonlinearity",
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
            "command",
            "limit",
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
            "command",
            "limit",
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
            "current_driver",
            "parameter_offset",
            None,
            vec![
                p("k_cd", "A/V", 0.01, 0.0, inf),
                offset("i_offset", "A", 1e-3, -0.2, 0.2),
            ],
        ),
        c(
            "current driver corner",
            "current_driver",
            "dynamics",
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
            "current_driver",
            "limit",
            None,
            vec![searched("current_limit", "A", Mechanism::CurrentLimit, 0.0, inf)],
        ),
        c(
            "current slew limit",
            "current_driver",
            "limit",
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
            "jet_pipe",
            "parameter_offset",
            None,
            vec![offset("x_jp_offset", "m", 2e-6, -1e-3, 1e-3)],
        ),
        c(
            "jet pipe null and travel",
            "jet_pipe",
            "parameter_offset",
            None,
            vec![
                offset("x_jp_offset", "m", 2e-6, -1e-3, 1e-3),
                p("x_jp_sat", "m", 0.01, 1e-5, 5e-3),
            ],
        ),
        c(
            "jet pipe static curve",
            "jet_pipe",
            "nonlinearity",
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
            "jet_pipe",
            "nonlinearity",
            None,
            vec![term_off("f3_algebraic_share", "1", 0.05, 1.0)],
        ),
        c(
            "jet and receiver diameter",
            "valve",
            "parameter_offset",
            None,
            // D_jp sets the receiver's geometry, (2.8)–(2.17): the areas' shape along the jet's
            // travel, not only their size.
            vec![p("D_jp", "m", 0.01, 1e-4, 5e-3)],
        ),
        c(
            "jet pipe lag",
            "jet_pipe",
            "dynamics",
            None,
            vec![corner(base, "omega_1", 10.0, 1e4)],
        ),
        c(
            "jet pipe resonance",
            "jet_pipe",
            "dynamics",
            None,
            // ω2 and ζ2 of (2.6): the modal form the model steps with needs ζ2 below 1.
            vec![
                p("omega_2", "rad/s", 0.01, 100.0, 1e5),
                offset("zeta_2", "1", 0.01, 0.001, 0.95),
            ],
        ),
        c(
            "jet pipe hysteresis",
            "jet_pipe",
            "hysteresis",
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
                "jet_pipe",
                "hysteresis",
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
            "jet_pipe",
            "drift",
            None,
            vec![
                offset("x_jp_offset", "m", 2e-6, -1e-3, 1e-3),
                modulated("x_jp_offset_drift", "m", "x_jp_offset", Modulation::Ramp, 1e-6),
            ],
        ),
        c(
            "discharge coefficient",
            "valve",
            "parameter_offset",
            None,
            vec![p("C_d", "1", 0.01, 1e-3, 1.0)],
        ),
        c(
            "orifice areas port by port",
            "valve",
            "asymmetry",
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
            "valve",
            "restriction",
            None,
            vec![
                term_off("port_resistance_1", "Pa.s/kg", 1e8, 1e11),
                term_off("port_resistance_2", "Pa.s/kg", 1e8, 1e11),
            ],
        ),
        c(
            "port 1 orifice with a line volume",
            "valve",
            "restriction",
            None,
            volume_behind("port_restriction_area_1", "port_line_volume_1"),
        ),
        c(
            "port 2 orifice with a line volume",
            "valve",
            "restriction",
            None,
            volume_behind("port_restriction_area_2", "port_line_volume_2"),
        ),
        c(
            "supply pressure",
            "supply",
            "parameter_offset",
            None,
            vec![p("P_s", "Pa", 0.005, 1.2e5, 2e6)],
        ),
        c(
            "supply line resistance",
            "supply",
            "restriction",
            Some("supply_pressure_drop"),
            vec![term_off("supply_resistance", "Pa.s/kg", 1e8, 1e11)],
        ),
        c(
            "supply orifice with a plenum",
            "supply",
            "restriction",
            Some("supply_pressure_drop"),
            volume_behind("supply_restriction_area", "supply_plenum_volume"),
        ),
        c(
            "supply pressure drift",
            "supply",
            "drift",
            None,
            vec![
                p("P_s", "Pa", 0.005, 1.2e5, 2e6),
                modulated("P_s_drift", "Pa", "P_s", Modulation::Ramp, 1e3),
            ],
        ),
        c(
            "return pressure",
            "return",
            "parameter_offset",
            None,
            vec![p("P_r", "Pa", 0.01, 1e4, 6e5)],
        ),
        c(
            "return line resistance",
            "return",
            "restriction",
            None,
            vec![term_off("return_resistance", "Pa.s/kg", 1e8, 1e11)],
        ),
        c(
            "return vent orifice with a plenum",
            "return",
            "restriction",
            None,
            volume_behind("return_vent_area", "return_plenum_volume"),
        ),
        c(
            "dead volumes",
            "chambers",
            "parameter_offset",
            Some("dead_volume"),
            vec![
                term_off("dead_volume_1", "m3", 5e-7, 1e-4),
                term_off("dead_volume_2", "m3", 5e-7, 1e-4),
            ],
        ),
        c(
            "heat exchange",
            "chambers",
            "parameter_offset",
            Some("heat_transfer"),
            vec![term_off("heat_transfer_fraction", "1", 0.05, 1.0)],
        ),
        c(
            "leakage past the piston",
            "chambers",
            "parameter_offset",
            None,
            vec![
                offset("C_dm_A_lpp", "m2", 2e-9, -1e-6, 1e-6),
                offset("C_db_A_lpp", "m2", 2e-9, 0.0, 1e-6),
            ],
        ),
        // The chamber volumes are those of the stopper position the model sees: a logged
        // position off by a constant (a transducer's zero) moves both volumes by A_p times
        // it, which is the support length L_sup changed by as much (§2.6, (2.31)–(2.32)).
        c(
            "stopper position offset",
            "chambers",
            "parameter_offset",
            None,
            vec![offset(
                "L_sup",
                "m",
                1e-5,
                (base.l_sup - 5e-3).max(0.0),
                base.l_sup + 5e-3,
            )],
        ),
        // The gas's isentropic exponent: in the orifices' law (2.19)–(2.22) and the chambers'
        // (2.29) together (heat exchange changes the chambers' exponent alone).
        c(
            "gas isentropic exponent",
            "chambers",
            "parameter_offset",
            None,
            vec![p("gamma", "1", 0.005, 1.0 + 1e-6, 5.0 / 3.0)],
        ),
        // The gas temperature of (2.6), a constant of the model (the orifices' mass flows and
        // the chambers' pressure rates), and the same drifting over the recording (the supply
        // air warming up): the FMU carries the ramp as T_drift.
        c(
            "gas temperature",
            "chambers",
            "parameter_offset",
            None,
            vec![p("T", "K", 0.005, 200.0, 400.0)],
        ),
        c(
            "gas temperature drift",
            "chambers",
            "drift",
            None,
            vec![
                p("T", "K", 0.005, 200.0, 400.0),
                modulated("T_drift", "K", "T", Modulation::Ramp, 1.0),
            ],
        ),
        c(
            "chamber leaks to the return",
            "chambers",
            "extra_flow",
            None,
            vec![
                term_off("chamber_vent_1", "m2", 5e-9, 1e-6),
                term_off("chamber_vent_2", "m2", 5e-9, 1e-6),
            ],
        ),
        // The chambers' mass balances take a leak from the library of each source (the return,
        // the supply, the other chamber) and law (an orifice, a laminar path; between the
        // chambers the orifice is the piston's leakage); the pairs combine two of them.
        c(
            "laminar chamber leaks to the return",
            "chambers",
            "extra_flow",
            None,
            vec![
                term_off("chamber_laminar_vent_1", "kg/(s.Pa)", 1e-11, 1e-6),
                term_off("chamber_laminar_vent_2", "kg/(s.Pa)", 1e-11, 1e-6),
            ],
        ),
        c(
            "chamber leaks from the supply",
            "chambers",
            "extra_flow",
            None,
            vec![
                term_off("chamber_supply_leak_1", "m2", 5e-9, 1e-6),
                term_off("chamber_supply_leak_2", "m2", 5e-9, 1e-6),
            ],
        ),
        c(
            "laminar chamber leaks from the supply",
            "chambers",
            "extra_flow",
            None,
            vec![
                term_off("chamber_laminar_supply_leak_1", "kg/(s.Pa)", 1e-11, 1e-6),
                term_off("chamber_laminar_supply_leak_2", "kg/(s.Pa)", 1e-11, 1e-6),
            ],
        ),
        // Beside the leakage past the piston (2.23), which keeps its orifice law (its own candidate).
        c(
            "laminar leak between the chambers",
            "chambers",
            "extra_flow",
            None,
            vec![term_off("chamber_laminar_cross_leak", "kg/(s.Pa)", 1e-11, 1e-6)],
        ),
        c(
            "Coulomb friction",
            "mechanics",
            "extra_force",
            Some("piston_friction"),
            vec![Term {
                lower: 0.0,
                ..output("friction_coulomb", "N", FORCE, Regressor::Friction, 0.1)
            }],
        ),
        // Seals deform before they slide, over a small speed: up to 20 mm/s, so that a
        // law rising with speed beyond it stays viscous friction, an undeclared term.
        c(
            "smooth Coulomb friction",
            "mechanics",
            "extra_force",
            Some("piston_friction"),
            vec![
                Term {
                    lower: 0.0,
                    ..output("friction_coulomb", "N", FORCE, Regressor::SmoothFriction(0.0), 0.1)
                },
                Term {
                    name: "friction_velocity",
                    unit: "m/s",
                    mechanism: Mechanism::Shape,
                    neutral: 0.0,
                    step: 0.0,
                    lower: 1e-4,
                    upper: 0.02,
                },
            ],
        ),
        c(
            "Stribeck friction",
            "mechanics",
            "extra_force",
            Some("piston_friction"),
            vec![
                Term {
                    lower: 0.0,
                    ..output("friction_coulomb", "N", FORCE, Regressor::SmoothFriction(0.0), 0.1)
                },
                Term {
                    lower: 0.0,
                    ..output("friction_stribeck", "N", FORCE, Regressor::Stribeck(0.0, 0.0), 0.1)
                },
                Term {
                    name: "friction_velocity",
                    unit: "m/s",
                    mechanism: Mechanism::Shape,
                    neutral: 0.0,
                    step: 0.0,
                    lower: 1e-4,
                    upper: 0.02,
                },
                Term {
                    name: "friction_stribeck_velocity",
                    unit: "m/s",
                    mechanism: Mechanism::Shape,
                    neutral: 0.0,
                    step: 0.0,
                    lower: 1e-3,
                    upper: 0.05,
                },
            ],
        ),
        c(
            "viscous friction",
            "mechanics",
            "extra_force",
            None,
            vec![output("viscous_friction", "N.s/m", FORCE, Regressor::Viscous, 1.0)],
        ),
        // The return spring's rate and its free length, (2.37): the floor the force sits on
        // while the pressures push less than the spring. Where the stopper stays put only the
        // floor's force shows, and either gives it; where it moves, the held-out blocks choose.
        c(
            "piston bore",
            "mechanics",
            "parameter_offset",
            None,
            // D_cyl sets the piston's area, (2.30)–(2.34): the force per pressure difference and
            // the chambers' volumes together.
            vec![p("D_cyl", "m", 0.002, 1e-3, 0.1)],
        ),
        c(
            "return spring rate",
            "mechanics",
            "parameter_offset",
            None,
            vec![p("k_spring", "N/m", 0.01, 0.0, 1e5)],
        ),
        c(
            "return spring free length",
            "mechanics",
            "parameter_offset",
            None,
            vec![offset("L_spring0", "m", 1e-4, 0.0, 1.0)],
        ),
        c(
            "stopper compliance",
            "mechanics",
            "compliance",
            None,
            vec![term_off("stopper_compliance", "m/N", 1e-6, 1e-3)],
        ),
        c(
            "stopper mount with a lag",
            "mechanics",
            "compliance",
            None,
            // The lag acts only with a compliance: started at 0.5 ms, it moves from the
            // second Gauss–Newton step on, once the compliance has.
            vec![
                term_off("stopper_compliance", "m/N", 1e-6, 1e-3),
                started("stopper_mount_lag", "s", 5e-4, 1e-4, 0.0, 0.1),
            ],
        ),
        c(
            "force on the stopper position",
            "mechanics",
            "extra_force",
            None,
            vec![output("position_stiffness", "N/m", FORCE, Regressor::Position, 10.0)],
        ),
        // The extra force's library beyond friction, viscous friction and the position force:
        // single columns, added one per round (forward selection on the held-out blocks)
        // and refitted jointly. (P1 − P2), an error of the piston area, is in the model but
        // not tried: it reads as the force sensor's gain wherever the pressures set the force.
        c(
            "moving mass",
            "mechanics",
            "extra_force",
            None,
            vec![output(
                "extra_force_acceleration",
                "kg",
                FORCE,
                Regressor::Acceleration,
                0.01,
            )],
        ),
        c(
            "quadratic damping",
            "mechanics",
            "extra_force",
            None,
            vec![output(
                "extra_force_velocity_squared",
                "N.s2/m2",
                FORCE,
                Regressor::VelocitySquared,
                10.0,
            )],
        ),
        c(
            "seal friction growing with the pressure",
            "mechanics",
            "extra_force",
            None,
            vec![
                output(
                    "extra_force_sign_pressure",
                    "m2",
                    FORCE,
                    Regressor::SignPressure(0.0),
                    1e-7,
                ),
                // The speed over which the seal turns, as the smooth Coulomb friction's.
                Term {
                    name: "extra_force_sign_velocity",
                    unit: "m/s",
                    mechanism: Mechanism::Shape,
                    neutral: 0.0,
                    step: 0.0,
                    lower: 1e-4,
                    upper: 0.02,
                },
            ],
        ),
        c(
            "force sensor offset and gain",
            "force_sensor",
            "parameter_offset",
            Some("sensor_offset_gain"),
            vec![
                output("force_sensor_offset", "N", FORCE, Regressor::One, 0.1),
                output("force_sensor_gain_error", "1", FORCE, Regressor::Own, 1e-3),
            ],
        ),
        c(
            "force sensor curve",
            "force_sensor",
            "nonlinearity",
            None,
            vec![
                output("force_sensor_offset", "N", FORCE, Regressor::One, 0.1),
                output("force_sensor_gain_error", "1", FORCE, Regressor::Own, 1e-3),
                output("force_sensor_quadratic", "1/N", FORCE, Regressor::OwnSquared, 1e-5),
                output("force_sensor_cubic", "1/N2", FORCE, Regressor::OwnCubed, 1e-7),
            ],
        ),
        c(
            "force sensor lag",
            "force_sensor",
            "dynamics",
            None,
            vec![filter("force_sensor_lag", "s", FORCE, Filter::Lag, 1e-4, 0.2)],
        ),
        c(
            "force sensor second-order filter",
            "force_sensor",
            "dynamics",
            None,
            second_order("force_sensor_filter_frequency", "force_sensor_filter_damping", FORCE),
        ),
        c(
            "force sensor delay",
            "force_sensor",
            "delay",
            None,
            vec![filter("force_sensor_delay", "s", FORCE, Filter::Delay, 1e-4, 0.2)],
        ),
        c(
            "force sensor play",
            "force_sensor",
            "hysteresis",
            None,
            vec![filter("force_sensor_play", "N", FORCE, Filter::Play, 1e-3, 20.0)],
        ),
        c(
            "force sensor drift",
            "force_sensor",
            "drift",
            None,
            vec![
                output("force_sensor_offset", "N", FORCE, Regressor::One, 0.1),
                output("force_sensor_drift", "N", FORCE, Regressor::Ramp, 0.1),
            ],
        ),
    ];
    if let Some(f) = periodic_hz {
        // The chambers filter a fast ripple, so its amplitudes are fitted through the
        // model at the spectral line's frequency, not as a modulated static sensitivity.
        let mut ripple = c(
            "supply pressure ripple",
            "supply",
            "periodic",
            None,
            vec![
                Term {
                    step: 1e3,
                    lower: -2e5,
                    upper: 2e5,
                    ..term_off("supply_ripple_sine", "Pa", 1e3, 2e5)
                },
                Term {
                    step: 1e3,
                    lower: -2e5,
                    upper: 2e5,
                    ..term_off("supply_ripple_cosine", "Pa", 1e3, 2e5)
                },
                // The line is placed to a fraction of 1/span; the fit polishes it.
                Term {
                    neutral: f,
                    step: 1e-4,
                    lower: 0.95 * f,
                    upper: 1.05 * f,
                    ..term_off("supply_ripple_frequency", "Hz", 1e-4, 1e3)
                },
            ],
        );
        ripple.settings = vec![("supply_ripple_frequency", f)];
        list.push(ripple);
        list.push(c(
            "force sensor pick-up",
            "force_sensor",
            "periodic",
            None,
            vec![
                output("force_sensor_ripple_sin", "N", FORCE, Regressor::Sine(f), 0.1),
                output("force_sensor_ripple_cos", "N", FORCE, Regressor::Cosine(f), 0.1),
            ],
        ));
    }
    if has_pressures {
        list.push(c(
            "chamber 1 pressure sensor offset",
            "pressure_sensors",
            "parameter_offset",
            None,
            vec![output("p1_sensor_offset", "Pa", P1, Regressor::One, 100.0)],
        ));
        list.push(c(
            "chamber 2 pressure sensor offset",
            "pressure_sensors",
            "parameter_offset",
            None,
            vec![output("p2_sensor_offset", "Pa", P2, Regressor::One, 100.0)],
        ));
        list.push(c(
            "pressure sensor offsets and gains",
            "pressure_sensors",
            "parameter_offset",
            None,
            vec![
                output("p1_sensor_offset", "Pa", P1, Regressor::One, 100.0),
                output("p1_sensor_gain_error", "1", P1, Regressor::Own, 1e-3),
                output("p2_sensor_offset", "Pa", P2, Regressor::One, 100.0),
                output("p2_sensor_gain_error", "1", P2, Regressor::Own, 1e-3),
            ],
        ));
        for (channel, lag, delay, [frequency, damping]) in [
            (
                P1,
                "p1_sensor_lag",
                "p1_sensor_delay",
                ["p1_sensor_filter_frequency", "p1_sensor_filter_damping"],
            ),
            (
                P2,
                "p2_sensor_lag",
                "p2_sensor_delay",
                ["p2_sensor_filter_frequency", "p2_sensor_filter_damping"],
            ),
        ] {
            list.push(c(
                "pressure sensor lag",
                "pressure_sensors",
                "dynamics",
                None,
                vec![filter(lag, "s", channel, Filter::Lag, 1e-4, 0.2)],
            ));
            list.push(c(
                "pressure sensor second-order filter",
                "pressure_sensors",
                "dynamics",
                None,
                second_order(frequency, damping, channel),
            ));
            list.push(c(
                "pressure sensor delay",
                "pressure_sensors",
                "delay",
                None,
                vec![filter(delay, "s", channel, Filter::Delay, 1e-4, 0.2)],
            ));
        }
        list.push(c(
            "pressure sensor drift",
            "pressure_sensors",
            "drift",
            None,
            vec![
                output("p1_sensor_offset", "Pa", P1, Regressor::One, 100.0),
                output("p1_sensor_drift", "Pa", P1, Regressor::Ramp, 100.0),
                output("p2_sensor_offset", "Pa", P2, Regressor::One, 100.0),
                output("p2_sensor_drift", "Pa", P2, Regressor::Ramp, 100.0),
            ],
        ));
    }
    list.extend(crate::candidates::curves::candidates(base, knots, has_pressures));
    list.extend(crate::candidates::discharge::candidate(base));
    // A flow into one chamber alone, generated from the extra flow slots' signals.
    list.extend(crate::candidates::extra_flows::candidates(base));
    list
}
