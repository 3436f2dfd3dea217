//! Corrections to the model, built from three general mechanisms:
//!
//! * **a constant of the model re-identified** ([`Mechanism::Parameter`]): a thesis
//!   constant with another value, or one of the model's terms that are off in the thesis
//!   model (per-orifice area factors, a return line resistance, chamber vents, and the named
//!   effects' own parameters); a constant **varying in time** is the same constant with its
//!   sensitivity modulated by a ramp or a sinusoid ([`Mechanism::Modulated`]);
//! * **a transform inserted in the chain**: on the command ([`Mechanism::CommandLag`],
//!   [`Mechanism::CurrentLimit`]) or on a measured channel ([`Mechanism::Output`] with a
//!   sensor regressor);
//! * **an extra term in a balance**: a force on the piston as a function of the stopper's
//!   motion ([`Mechanism::Output`] with a mechanics regressor), a mass flow through a vent.
//!
//! Each [`Candidate`] is a set of such terms at one place of the chain. It is fitted by
//! Gauss–Newton with bounds on the training blocks of every measured channel at once (each
//! channel weighted by its noise floor) and scored on the held-out blocks.

use crate::recording::Recording;
use crate::replay::{replay_fast, Replay};
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::current_driver;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::physics::sensors::{self, Channel, SensorLaw};
use jetpipe_model::variables::VARIABLES;

use super::signals::{difference, stopper_velocity, CHANNELS, FORCE, P1, P2};

/// A signal that a measured channel may carry in proportion to a coefficient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Regressor {
    One,
    /// The modelled value of the channel itself (a gain), and its powers.
    Own,
    OwnSquared,
    OwnCubed,
    /// −sign(dx_s/dt) where the pressures set the force: Coulomb friction.
    Friction,
    /// −tanh((dx_s/dt) / v_c) there: Coulomb friction reached over a speed v_c (the
    /// candidate's [`Mechanism::Shape`] term).
    SmoothFriction(f64),
    /// −exp(−(v/v_s)²) tanh(v/v_c) there: the Stribeck part, at the candidate's two shapes
    /// (v_c, v_s).
    Stribeck(f64, f64),
    /// −dx_s/dt where the pressures set the force: viscous friction.
    Viscous,
    /// x_s minus its mean where the pressures set the force: a spring on the piston.
    Position,
    /// (t − t_mid) / (t_end − t_start): drift.
    Ramp,
    Sine(f64),
    Cosine(f64),
}

/// How a sensor may read its quantity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    Delay,
    Lag,
    Play,
}

impl Filter {
    /// The reading of `x` through the filter with coefficient `value`: the model's own
    /// transducer law (every channel's transducer is read the same way).
    pub fn apply(self, time: &[f64], x: &[f64], value: f64) -> Vec<f64> {
        let mut law = SensorLaw::of(&Parameters::default(), Channel::Force);
        match self {
            Filter::Delay => law.delay = value,
            Filter::Lag => law.lag = value,
            Filter::Play => law.play = value,
        }
        sensors::filtered(&law, time, x.to_vec())
    }

    /// The model parameter that carries this filter on the measured `channel`, if the
    /// model's transducer there has it.
    pub fn sensor_parameter(self, channel: usize) -> Option<&'static str> {
        Some(match (channel, self) {
            (FORCE, Filter::Delay) => "force_sensor_delay",
            (FORCE, Filter::Lag) => "force_sensor_lag",
            (FORCE, Filter::Play) => "force_sensor_play",
            (P1, Filter::Delay) => "p1_sensor_delay",
            (P1, Filter::Lag) => "p1_sensor_lag",
            (P2, Filter::Delay) => "p2_sensor_delay",
            (P2, Filter::Lag) => "p2_sensor_lag",
            _ => return None,
        })
    }
}

/// How a time-varying constant varies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Modulation {
    Ramp,
    Sine(f64),
    Cosine(f64),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mechanism {
    /// An FMU parameter of the model.
    Parameter(&'static str),
    /// An FMU parameter whose effect is not smooth from its neutral value (an orifice that
    /// is off at 0 area and at an infinite one): found by a search over its range on a
    /// logarithmic scale.
    Searched(&'static str),
    /// A first-order lag (time constant, s) on the command the current driver sees.
    CommandLag,
    /// The command the current driver sees saturates at ± this (V).
    CommandLimit,
    /// A cubic term on the static curve's input: the tip force k_m i, and so (the current
    /// driver being linear and fast) the command, bent by this times (v / 10 V)³.
    InputCubic,
    /// The current saturates at ± this (A): the command clipped where k_cd v + i_offset
    /// reaches it (the current driver is linear, so the two are the same).
    CurrentLimit,
    /// The current slews at most this fast (A/s): the command rate-limited where k_cd
    /// times it reaches that (the current driver is fast beside it).
    CurrentSlewLimit,
    /// A measured channel read through a delay, a lag or a play (the coefficient: its
    /// time, s, or its width in the channel's unit).
    OutputFilter { channel: usize, filter: Filter },
    /// A term on a measured channel: coefficient × regressor.
    Output { channel: usize, regressor: Regressor },
    /// The shape parameter of the candidate's regressors (a friction's speed scale), found
    /// by a search over its range on a logarithmic scale with the amplitudes solved at each
    /// value.
    Shape,
    /// A parameter varying in time: coefficient × its sensitivity × the modulation (first order).
    Modulated {
        parameter: &'static str,
        modulation: Modulation,
    },
}

impl Mechanism {
    fn is_searched(&self) -> bool {
        matches!(
            self,
            Mechanism::CurrentLimit
                | Mechanism::CommandLimit
                | Mechanism::CurrentSlewLimit
                | Mechanism::OutputFilter { .. }
                | Mechanism::Searched(_)
                | Mechanism::Shape
        )
    }

    /// The model parameter that carries this term in the replay, if one does.
    pub fn model_parameter(&self) -> Option<&'static str> {
        match *self {
            Mechanism::Parameter(name) | Mechanism::Searched(name) => Some(name),
            Mechanism::CommandLag => Some("command_lag"),
            Mechanism::CommandLimit => Some("command_limit"),
            Mechanism::CurrentLimit => Some("current_limit"),
            Mechanism::CurrentSlewLimit => Some("current_slew_limit"),
            Mechanism::InputCubic => Some("f3_input_cubic"),
            _ => None,
        }
    }

    fn is_linear(&self) -> bool {
        matches!(self, Mechanism::Output { .. } | Mechanism::Modulated { .. })
    }
}

/// One coefficient of a candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    /// The name the report gives it (an FMU parameter name where it is one).
    pub name: &'static str,
    pub unit: &'static str,
    pub mechanism: Mechanism,
    /// Value with the term off (for parameters: their value in the base model).
    pub neutral: f64,
    /// Finite-difference step, and a typical size.
    pub step: f64,
    pub lower: f64,
    pub upper: f64,
}

/// Terms at one place of the chain, fitted together.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub label: &'static str,
    pub location: &'static str,
    pub family: &'static str,
    /// The named effect this candidate is, if it is one.
    pub named: Option<&'static str>,
    pub terms: Vec<Term>,
    /// Model parameters set before its terms are fitted (a ripple's frequency).
    pub settings: Vec<(&'static str, f64)>,
}

fn value_reference(name: &str) -> u32 {
    VARIABLES
        .iter()
        .find(|v| v.name == name)
        .map(|v| v.value_reference)
        .unwrap_or_else(|| panic!("{name} is not a variable of the model"))
}

/// The base model's value of an FMU parameter.
pub fn parameter_value(p: &Parameters, name: &str) -> f64 {
    p.get(value_reference(name))
        .unwrap_or_else(|| panic!("{name} is not a parameter"))
}

/// The bounds the variable table declares for a parameter (infinite where it declares none).
pub fn declared_bounds(name: &str) -> (f64, f64) {
    match Parameters::declared_range(value_reference(name)) {
        Some((lower, upper)) => (lower.unwrap_or(f64::NEG_INFINITY), upper.unwrap_or(f64::INFINITY)),
        None => (f64::NEG_INFINITY, f64::INFINITY),
    }
}

/// Set an FMU parameter, with the model's own checks.
pub fn set_parameter(p: &mut Parameters, name: &str, value: f64) -> Result<(), String> {
    p.set(value_reference(name), value)
}

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

/// Golden-section steps of a searched term: its bracket shrinks to 0.618^16 = 5e-4 of its
/// range (a thousandth of a decade over three), or, for the first pass's ranking, to
/// 0.618^10 = 8e-3 (6 % in value over three decades; a limit's range is linear, 0.8 % of
/// it). The leaders' refinement and a discovered term's trial search to the finer bracket.
const GOLDEN_STEPS: usize = 16;
const COARSE_GOLDEN_STEPS: usize = 10;

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
pub fn catalogue(base: &Parameters, has_pressures: bool, periodic_hz: Option<f64>) -> Vec<Candidate> {
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
            "command limit",
            "command",
            "limit",
            None,
            vec![searched("command_limit", "V", Mechanism::CommandLimit, 0.0, inf)],
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
            "jet pipe lag",
            "jet_pipe",
            "dynamics",
            None,
            vec![p("omega_1", "rad/s", 0.05, 1.0, 1e5)],
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
        c(
            "stopper compliance",
            "mechanics",
            "compliance",
            None,
            vec![term_off("stopper_compliance", "m/N", 1e-6, 1e-3)],
        ),
        c(
            "force on the stopper position",
            "mechanics",
            "extra_force",
            None,
            vec![output("position_stiffness", "N/m", FORCE, Regressor::Position, 10.0)],
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
        for (channel, lag, delay) in [
            (P1, "p1_sensor_lag", "p1_sensor_delay"),
            (P2, "p2_sensor_lag", "p2_sensor_delay"),
        ] {
            list.push(c(
                "pressure sensor lag",
                "pressure_sensors",
                "dynamics",
                None,
                vec![filter(lag, "s", channel, Filter::Lag, 1e-4, 0.2)],
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
    list
}

/// The fixed part of a fitting problem: the recording, the base model, the blocks and
/// the channels' weights.
pub struct Problem<'a> {
    pub recording: &'a Recording,
    pub base: &'a Parameters,
    /// Training samples (the others are held out).
    pub training: &'a [bool],
    /// 1/noise floor of each channel (0 for a channel the recording lacks).
    pub weights: [f64; CHANNELS],
    pub measured: [&'a [f64]; CHANNELS],
    velocity: Vec<f64>,
    /// The stopper's mean position, where the position regressor vanishes.
    pub mean_position: f64,
    /// The middle and the span of the recording's time, for the ramp regressor.
    pub t_mid: f64,
    pub t_span: f64,
    /// Threads for the finite-difference replays of one Gauss–Newton step (1 while the
    /// candidates themselves are spread over the threads).
    pub jobs: std::sync::atomic::AtomicUsize,
}

impl<'a> Problem<'a> {
    pub fn new(recording: &'a Recording, base: &'a Parameters, training: &'a [bool], noise: [f64; CHANNELS]) -> Self {
        let empty: &[f64] = &[];
        let measured = [
            recording.force.as_slice(),
            recording.p1.as_deref().unwrap_or(empty),
            recording.p2.as_deref().unwrap_or(empty),
        ];
        let mut weights = [0.0; CHANNELS];
        for c in 0..CHANNELS {
            if !measured[c].is_empty() && noise[c] > 0.0 {
                weights[c] = 1.0 / noise[c];
            }
        }
        let n = recording.len();
        let (t0, t1) = (recording.time[0], recording.time[n - 1]);
        Self {
            recording,
            base,
            training,
            weights,
            measured,
            velocity: stopper_velocity(recording),
            mean_position: recording.x_s.iter().sum::<f64>() / n as f64,
            t_mid: 0.5 * (t0 + t1),
            t_span: (t1 - t0).max(1e-9),
            jobs: std::sync::atomic::AtomicUsize::new(1),
        }
    }

    /// Spread each Gauss–Newton step's finite-difference replays over `jobs` threads.
    pub fn set_jobs(&self, jobs: usize) {
        self.jobs.store(jobs.max(1), std::sync::atomic::Ordering::Relaxed);
    }

    /// Model outputs with the nonlinear terms at `values` (linear terms are added by
    /// [`Self::predict`]).
    fn replay(&self, candidate: &Candidate, values: &[f64]) -> Result<Replay, String> {
        let mut p = self.base.clone();
        for &(name, value) in &candidate.settings {
            set_parameter(&mut p, name, value)?;
        }
        for (term, &value) in candidate.terms.iter().zip(values) {
            if let Some(name) = term.mechanism.model_parameter() {
                set_parameter(&mut p, name, value)?;
            }
        }
        replay_fast(&Actuator::new(p)?, self.recording, self.recording.len())
    }

    fn regressor(&self, regressor: Regressor, own: &[f64], floor: &[bool], k: usize) -> f64 {
        let t = self.recording.time[k];
        let v = self.velocity[k];
        let set_by_pressures = !floor[k];
        match regressor {
            Regressor::One => 1.0,
            Regressor::Own => own[k],
            Regressor::OwnSquared => own[k] * own[k],
            Regressor::OwnCubed => own[k] * own[k] * own[k],
            Regressor::Friction if set_by_pressures && v.abs() > 1e-9 => -v.signum(),
            Regressor::SmoothFriction(vc) if set_by_pressures => {
                -jetpipe_model::physics::effects::friction_force(1.0, vc, 0.0, 0.0, v)
            }
            Regressor::Stribeck(vc, vs) if set_by_pressures => {
                -jetpipe_model::physics::effects::friction_force(0.0, vc, 1.0, vs, v)
            }
            Regressor::Viscous if set_by_pressures => -v,
            Regressor::Position if set_by_pressures => -(self.recording.x_s[k] - self.mean_position),
            Regressor::Friction
            | Regressor::SmoothFriction(_)
            | Regressor::Stribeck(..)
            | Regressor::Viscous
            | Regressor::Position => 0.0,
            Regressor::Ramp => (t - self.t_mid) / self.t_span,
            Regressor::Sine(f) => (2.0 * std::f64::consts::PI * f * t).sin(),
            Regressor::Cosine(f) => (2.0 * std::f64::consts::PI * f * t).cos(),
        }
    }
}

fn modulation_at(m: Modulation, t: f64, t_mid: f64, t_span: f64) -> f64 {
    match m {
        Modulation::Ramp => (t - t_mid) / t_span,
        Modulation::Sine(f) => (2.0 * std::f64::consts::PI * f * t).sin(),
        Modulation::Cosine(f) => (2.0 * std::f64::consts::PI * f * t).cos(),
    }
}

/// A candidate fitted: its values, what it predicts, and its errors.
#[derive(Clone, Debug)]
pub struct Fit {
    pub candidate: Candidate,
    pub values: Vec<f64>,
    pub prediction: [Vec<f64>; CHANNELS],
    /// Weighted sums of squares per channel on the training and held-out samples.
    pub train: [f64; CHANNELS],
    pub heldout: [f64; CHANNELS],
    pub replays: usize,
}

impl Fit {
    pub fn train_total(&self) -> f64 {
        self.train.iter().sum()
    }
    pub fn heldout_total(&self) -> f64 {
        self.heldout.iter().sum()
    }
}

/// Sensitivities of the model's outputs to the nonlinear terms, shared by candidates that
/// start from the same point.
pub type Sensitivity = [Vec<f64>; CHANNELS];

/// Everything needed at one point of a candidate's terms.
struct Point {
    values: Vec<f64>,
    replay: Replay,
}

impl Problem<'_> {
    /// Predictions of the measured channels for a candidate at `values`, from a replay at
    /// those values and the sensitivities of modulated parameters.
    fn predict(&self, terms: &[Term], point: &Point, sensitivities: &[Option<Sensitivity>]) -> [Vec<f64>; CHANNELS] {
        let r = &point.replay;
        let mut out = [r.force.clone(), r.p1.clone(), r.p2.clone()];
        let n = self.recording.len();
        let mut floor: Option<Vec<bool>> = None;
        for (j, (term, &value)) in terms.iter().zip(&point.values).enumerate() {
            if value == 0.0 {
                continue;
            }
            match term.mechanism {
                Mechanism::Output { channel, regressor } => {
                    let own = [&r.force, &r.p1, &r.p2][channel];
                    let floor = floor.get_or_insert_with(|| self.floor(r));
                    for k in 0..n {
                        out[channel][k] += value * self.regressor(regressor, own, floor, k);
                    }
                }
                Mechanism::Modulated { modulation, .. } => {
                    if let Some(s) = &sensitivities[j] {
                        for c in 0..CHANNELS {
                            if s[c].is_empty() {
                                continue;
                            }
                            for k in 0..n {
                                let m = modulation_at(modulation, self.recording.time[k], self.t_mid, self.t_span);
                                out[c][k] += value * s[c][k] * m;
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        out
    }

    /// Samples where the spring floor, not the pressures, sets the modelled force.
    fn floor(&self, r: &Replay) -> Vec<bool> {
        let p = &self.base;
        let area = std::f64::consts::PI * p.d_cyl * p.d_cyl / 4.0;
        (0..self.recording.len())
            .map(|k| {
                let spring = jetpipe_model::physics::piston::spring_force(
                    p.k_spring,
                    p.l_spring0,
                    p.l_s,
                    p.l_p,
                    self.recording.x_s[k],
                );
                area * (r.p1[k] - r.p2[k]) <= spring
            })
            .collect()
    }

    /// Weighted sums of squares per channel, training and held-out.
    pub fn errors(&self, prediction: &[Vec<f64>; CHANNELS]) -> ([f64; CHANNELS], [f64; CHANNELS]) {
        let mut train = [0.0; CHANNELS];
        let mut heldout = [0.0; CHANNELS];
        for c in 0..CHANNELS {
            let w = self.weights[c];
            if w == 0.0 {
                continue;
            }
            for (k, (&m, &y)) in self.measured[c].iter().zip(&prediction[c]).enumerate() {
                let e = w * (m - y);
                if self.training[k] {
                    train[c] += e * e;
                } else {
                    heldout[c] += e * e;
                }
            }
        }
        (train, heldout)
    }

    /// Sensitivity of the outputs to one parameter at a point of the base model.
    pub fn sensitivity(&self, name: &'static str, step: f64, at: &Replay) -> Option<Sensitivity> {
        let mut p = self.base.clone();
        let value = parameter_value(&p, name);
        set_parameter(&mut p, name, value + step).ok()?;
        let model = Actuator::new(p).ok()?;
        let moved = replay_fast(&model, self.recording, self.recording.len()).ok()?;
        let d = |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| (x - y) / step).collect() };
        Some([d(&moved.force, &at.force), d(&moved.p1, &at.p1), d(&moved.p2, &at.p2)])
    }

    /// Fit a candidate: bounded Gauss–Newton from its neutral values, at most `iterations`
    /// linearisations. `start` may give the base replay and the sensitivities to the
    /// candidate's nonlinear terms at the neutral point (shared between candidates).
    pub fn fit(
        &self,
        candidate: &Candidate,
        iterations: usize,
        base_replay: &Replay,
        shared: &dyn Fn(&'static str) -> Option<Sensitivity>,
    ) -> Result<Fit, String> {
        let terms = &candidate.terms;
        if terms.iter().any(|t| t.mechanism == Mechanism::Shape) {
            return self.fit_shape(candidate, base_replay);
        }
        if terms.iter().any(|t| t.mechanism.is_searched()) {
            if terms.len() > 1 {
                return self.fit_search_then_refine(candidate, iterations, base_replay);
            }
            // The first pass only ranks the candidates: a coarser search does for that.
            let steps = if iterations <= 1 {
                COARSE_GOLDEN_STEPS
            } else {
                GOLDEN_STEPS
            };
            return self.fit_search(candidate, base_replay, steps);
        }
        // Sensitivities of the modulated parameters (at the base point: first order).
        let modulated: Vec<Option<Sensitivity>> = terms
            .iter()
            .map(|t| match t.mechanism {
                Mechanism::Modulated { parameter, .. } => shared(parameter),
                _ => None,
            })
            .collect();
        let mut point = Point {
            values: terms.iter().map(|t| t.neutral).collect(),
            replay: base_replay.clone(),
        };
        let mut replays = 0;
        let mut prediction = self.predict(terms, &point, &modulated);
        let (mut train, _) = self.errors(&prediction);
        for iteration in 0..iterations.max(1) {
            // Columns: nonlinear terms by finite differences (shared ones at the start), their
            // replays spread over the threads; `known` ends up holding both kinds.
            let mut known: Vec<Option<Sensitivity>> = terms
                .iter()
                .map(|term| match term.mechanism {
                    Mechanism::Parameter(name) if iteration == 0 && candidate.settings.is_empty() => shared(name),
                    _ => None,
                })
                .collect();
            let differenced: Vec<(usize, f64)> = terms
                .iter()
                .enumerate()
                .filter(|(j, term)| {
                    known[*j].is_none()
                        && matches!(
                            term.mechanism,
                            Mechanism::Parameter(_) | Mechanism::CommandLag | Mechanism::InputCubic
                        )
                })
                .map(|(j, term)| {
                    let step = if point.values[j] + term.step <= term.upper {
                        term.step
                    } else {
                        -term.step
                    };
                    (j, step)
                })
                .collect();
            let jobs = self.jobs.load(std::sync::atomic::Ordering::Relaxed);
            let moved_replays = crate::parallel_map(&differenced, jobs, |&(j, step)| {
                let mut moved = point.values.clone();
                moved[j] += step;
                self.replay(candidate, &moved).ok().map(|r| {
                    let d =
                        |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(x, y)| (x - y) / step).collect() };
                    [
                        d(&r.force, &point.replay.force),
                        d(&r.p1, &point.replay.p1),
                        d(&r.p2, &point.replay.p2),
                    ]
                })
            });
            replays += differenced.len();
            for (&(j, _), column) in differenced.iter().zip(moved_replays) {
                known[j] = column;
            }
            let mut columns: Vec<Sensitivity> = Vec::with_capacity(terms.len());
            for (j, term) in terms.iter().enumerate() {
                let column = match term.mechanism {
                    _ if known[j].is_some() => known[j].take(),
                    Mechanism::Output { .. } | Mechanism::Modulated { .. } => {
                        let mut unit = point.values.clone();
                        unit.iter_mut().zip(terms).for_each(|(v, t)| {
                            if t.mechanism.is_linear() {
                                *v = 0.0
                            }
                        });
                        unit[j] = 1.0;
                        let only = Point {
                            values: unit,
                            replay: point.replay.clone(),
                        };
                        let with = self.predict(terms, &only, &modulated);
                        Some([
                            difference(&with[0], &point.replay.force),
                            difference(&with[1], &point.replay.p1),
                            difference(&with[2], &point.replay.p2),
                        ])
                    }
                    _ => None,
                };
                columns.push(column.unwrap_or_else(|| [vec![], vec![], vec![]]));
            }
            let step = self.solve(terms, &point.values, &columns, &prediction);
            // Line search on the true model.
            let mut accepted = false;
            let mut alpha = 1.0;
            for _ in 0..4 {
                let values: Vec<f64> = point
                    .values
                    .iter()
                    .zip(&step)
                    .zip(terms)
                    .map(|((v, s), t)| (v + alpha * s).clamp(t.lower, t.upper))
                    .collect();
                let nonlinear_moved = terms
                    .iter()
                    .zip(values.iter().zip(&point.values))
                    .any(|(t, (a, b))| !t.mechanism.is_linear() && a != b);
                let replay = if nonlinear_moved {
                    replays += 1;
                    match self.replay(candidate, &values) {
                        Ok(r) => r,
                        Err(_) => {
                            alpha *= 0.5;
                            continue;
                        }
                    }
                } else {
                    point.replay.clone()
                };
                let trial = Point { values, replay };
                let trial_prediction = self.predict(terms, &trial, &modulated);
                let (trial_train, _) = self.errors(&trial_prediction);
                if trial_train.iter().sum::<f64>() < train.iter().sum::<f64>() {
                    point = trial;
                    prediction = trial_prediction;
                    train = trial_train;
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            if !accepted || terms.iter().all(|t| t.mechanism.is_linear()) {
                break;
            }
        }
        let (train, heldout) = self.errors(&prediction);
        Ok(Fit {
            candidate: candidate.clone(),
            values: point.values,
            prediction,
            train,
            heldout,
            replays,
        })
    }

    /// Bounded linear least squares for the step of every term, on the training samples.
    fn solve(
        &self,
        terms: &[Term],
        values: &[f64],
        columns: &[Sensitivity],
        prediction: &[Vec<f64>; CHANNELS],
    ) -> Vec<f64> {
        let m = terms.len();
        let usable: Vec<bool> = columns.iter().map(|c| c.iter().any(|ch| !ch.is_empty())).collect();
        let mut ata = vec![vec![0.0; m]; m];
        let mut atb = vec![0.0; m];
        for c in 0..CHANNELS {
            let w2 = self.weights[c] * self.weights[c];
            if w2 == 0.0 {
                continue;
            }
            for k in 0..self.recording.len() {
                if !self.training[k] {
                    continue;
                }
                let r = self.measured[c][k] - prediction[c][k];
                for a in 0..m {
                    let ja = if usable[a] && !columns[a][c].is_empty() {
                        columns[a][c][k]
                    } else {
                        0.0
                    };
                    if ja == 0.0 {
                        continue;
                    }
                    atb[a] += w2 * ja * r;
                    for b in a..m {
                        let jb = if usable[b] && !columns[b][c].is_empty() {
                            columns[b][c][k]
                        } else {
                            0.0
                        };
                        ata[a][b] += w2 * ja * jb;
                    }
                }
            }
        }
        for a in 0..m {
            for b in 0..a {
                ata[a][b] = ata[b][a];
            }
        }
        let lower: Vec<f64> = terms.iter().zip(values).map(|(t, v)| t.lower - v).collect();
        let upper: Vec<f64> = terms.iter().zip(values).map(|(t, v)| t.upper - v).collect();
        bounded_least_squares(&ata, &atb, &usable, &lower, &upper)
    }

    /// A transform with one coefficient whose sensitivity vanishes where it is off (a
    /// limit does nothing until it clips, a slew limit until the command jumps) or that
    /// acts on a measured channel exactly (a delay, a lag, a play): golden-section search
    /// on the coefficient, on a logarithmic scale where it spans decades.
    /// A candidate whose regressors share one or two shape parameters (a friction's speed
    /// scales): golden-section search of their logarithms (the second outside the first),
    /// the linear amplitudes solved at each trial point.
    fn fit_shape(&self, candidate: &Candidate, base_replay: &Replay) -> Result<Fit, String> {
        let shapes: Vec<usize> = (0..candidate.terms.len())
            .filter(|&k| candidate.terms[k].mechanism == Mechanism::Shape)
            .collect();
        let range = |k: usize| (candidate.terms[shapes[k]].lower, candidate.terms[shapes[k]].upper);
        let value_of = |k: usize, u: f64| {
            let (lower, upper) = range(k);
            lower * (upper / lower).powf(u)
        };
        let shaped = |vc: f64, vs: f64| -> Candidate {
            let mut c = candidate.clone();
            c.terms.retain(|t| t.mechanism != Mechanism::Shape);
            for t in c.terms.iter_mut() {
                if let Mechanism::Output { channel, regressor } = t.mechanism {
                    let regressor = match regressor {
                        Regressor::SmoothFriction(_) => Regressor::SmoothFriction(vc),
                        Regressor::Stribeck(..) => Regressor::Stribeck(vc, vs),
                        other => other,
                    };
                    t.mechanism = Mechanism::Output { channel, regressor };
                }
            }
            c
        };
        let none = |_: &'static str| None;
        let fit_at = |vc: f64, vs: f64| self.fit(&shaped(vc, vs), 1, base_replay, &none).ok();
        let cost = |fit: &Option<Fit>| fit.as_ref().map_or(f64::INFINITY, |f| f.train_total());
        // The best u in [0, 1] of a unimodal cost, and its cost.
        let golden = |iterations: usize, f: &dyn Fn(f64) -> f64| -> (f64, f64) {
            let phi = (5f64.sqrt() - 1.0) / 2.0;
            let (mut a, mut b) = (0.0, 1.0);
            let mut c = b - phi * (b - a);
            let mut d = a + phi * (b - a);
            let (mut fc, mut fd) = (f(c), f(d));
            for _ in 0..iterations {
                if fc < fd {
                    b = d;
                    d = c;
                    fd = fc;
                    c = b - phi * (b - a);
                    fc = f(c);
                } else {
                    a = c;
                    c = d;
                    fc = fd;
                    d = a + phi * (b - a);
                    fd = f(d);
                }
            }
            if fc < fd {
                (c, fc)
            } else {
                (d, fd)
            }
        };
        let inner = |vs: f64| golden(14, &|u| cost(&fit_at(value_of(0, u), vs)));
        let (vc, vs) = if shapes.len() >= 2 {
            let (u_s, _) = golden(10, &|u| inner(value_of(1, u)).1);
            let vs = value_of(1, u_s);
            (value_of(0, inner(vs).0), vs)
        } else {
            (value_of(0, inner(0.0).0), 0.0)
        };
        let fit = fit_at(vc, vs).ok_or("the shaped fit failed")?;
        let mut values = fit.values.clone();
        values.insert(shapes[0], vc);
        if shapes.len() >= 2 {
            values.insert(shapes[1], vs);
        }
        Ok(Fit {
            candidate: candidate.clone(),
            values,
            ..fit
        })
    }

    /// A searched term followed by parameters that only act once it is on (an orifice and the
    /// volume behind it): the search with the parameters at their starts, then Gauss–Newton on
    /// all of them from there, the searched term now a parameter. A first pass (one
    /// iteration: the ranking of every candidate) searches coarser. It still takes its one
    /// Gauss–Newton step: the volume can matter more than the orifice (a wide orifice in front
    /// of a line acts as a volume added to the chamber), and without the step such a candidate
    /// would rank below the ones that mimic it and never be refined.
    fn fit_search_then_refine(
        &self,
        candidate: &Candidate,
        iterations: usize,
        base_replay: &Replay,
    ) -> Result<Fit, String> {
        let (first, rest) = candidate.terms.split_first().ok_or("a candidate without terms")?;
        let mut settings = candidate.settings.clone();
        settings.extend(
            rest.iter()
                .filter_map(|t| t.mechanism.model_parameter().map(|name| (name, t.neutral))),
        );
        let searched = Candidate {
            terms: vec![first.clone()],
            settings,
            ..candidate.clone()
        };
        let first_pass = iterations <= 1;
        let found = self.fit_search(
            &searched,
            base_replay,
            if first_pass { COARSE_GOLDEN_STEPS } else { GOLDEN_STEPS },
        )?;
        let neutral: Vec<f64> = candidate.terms.iter().map(|t| t.neutral).collect();
        if found.values[0] == first.neutral {
            // Nothing the search could find: the candidate stays off, and so do the parameters
            // that act only behind it.
            let mut values = neutral;
            for (value, term) in values.iter_mut().zip(&candidate.terms).skip(1) {
                if let Some(name) = term.mechanism.model_parameter() {
                    *value = parameter_value(self.base, name);
                }
            }
            return Ok(Fit {
                candidate: candidate.clone(),
                values,
                ..found
            });
        }
        let name = first
            .mechanism
            .model_parameter()
            .ok_or("a searched term without a parameter")?;
        let mut refined = candidate.clone();
        refined.terms[0] = Term {
            mechanism: Mechanism::Parameter(name),
            neutral: found.values[0],
            step: 0.02 * found.values[0],
            ..first.clone()
        };
        let start: Vec<f64> = refined.terms.iter().map(|t| t.neutral).collect();
        let start_replay = self.replay(&refined, &start)?;
        let none = |_: &'static str| None;
        let fit = self.fit(&refined, iterations, &start_replay, &none)?;
        Ok(Fit {
            candidate: candidate.clone(),
            replays: fit.replays + found.replays + 1,
            ..fit
        })
    }

    fn fit_search(&self, candidate: &Candidate, base_replay: &Replay, golden_steps: usize) -> Result<Fit, String> {
        let p = self.base;
        let term = &candidate.terms[0];
        let commands = self.recording.v_da.iter();
        let (lower, upper, logarithmic) = match term.mechanism {
            Mechanism::CurrentLimit => {
                let largest = commands
                    .map(|v| current_driver::static_current(p.k_cd, p.i_offset, *v).abs())
                    .fold(0.0, f64::max);
                (0.2 * largest, largest, false)
            }
            Mechanism::CommandLimit => {
                let largest = commands.map(|v| v.abs()).fold(0.0, f64::max);
                (0.2 * largest, largest, false)
            }
            _ => (term.lower, term.upper, true),
        };
        let base = Prediction::of_replay(base_replay);
        let mut replays = 0;
        let mut evaluate = |value: f64| -> (f64, Option<[Vec<f64>; CHANNELS]>) {
            let prediction = match term.mechanism {
                Mechanism::OutputFilter { channel, filter } => {
                    let mut out = base.clone();
                    out[channel] = filter.apply(&self.recording.time, &base[channel], value);
                    Some(out)
                }
                _ => {
                    replays += 1;
                    self.replay(candidate, &[value]).ok().map(|r| Prediction::of_replay(&r))
                }
            };
            match prediction {
                Some(y) => (self.errors(&y).0.iter().sum(), Some(y)),
                None => (f64::INFINITY, None),
            }
        };
        let to_value = |u: f64| {
            if logarithmic {
                lower * (upper / lower).powf(u)
            } else {
                lower + (upper - lower) * u
            }
        };
        let phi = (5f64.sqrt() - 1.0) / 2.0;
        let (mut a, mut b) = (0.0, 1.0);
        let mut c = b - phi * (b - a);
        let mut d = a + phi * (b - a);
        let (mut fc, mut fd) = (evaluate(to_value(c)).0, evaluate(to_value(d)).0);
        for _ in 0..golden_steps {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - phi * (b - a);
                fc = evaluate(to_value(c)).0;
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + phi * (b - a);
                fd = evaluate(to_value(d)).0;
            }
        }
        let best = to_value(if fc < fd { c } else { d });
        let (cost, prediction) = evaluate(best);
        let (values, prediction) = match prediction {
            Some(y) if cost < self.errors(&base).0.iter().sum::<f64>() => (vec![best], y),
            _ => (vec![term.neutral], base),
        };
        let (train, heldout) = self.errors(&prediction);
        Ok(Fit {
            candidate: candidate.clone(),
            values,
            prediction,
            train,
            heldout,
            replays,
        })
    }
}

struct Prediction;

impl Prediction {
    fn of_replay(r: &Replay) -> [Vec<f64>; CHANNELS] {
        [r.force.clone(), r.p1.clone(), r.p2.clone()]
    }
}

/// min |A x − b|² given the normal equations (ata, atb), with lower ≤ x ≤ upper and the
/// unusable unknowns at 0: solve the free unknowns, clamp those that leave their bounds,
/// and solve again for the rest (at most once per unknown).
fn bounded_least_squares(ata: &[Vec<f64>], atb: &[f64], usable: &[bool], lower: &[f64], upper: &[f64]) -> Vec<f64> {
    let m = atb.len();
    let mut x = vec![0.0; m];
    let mut fixed: Vec<bool> = usable.iter().map(|u| !u).collect();
    for _ in 0..=m {
        let free: Vec<usize> = (0..m).filter(|&j| !fixed[j]).collect();
        if free.is_empty() {
            return x;
        }
        let mut a = nalgebra::DMatrix::<f64>::zeros(free.len(), free.len());
        let mut b = nalgebra::DVector::<f64>::zeros(free.len());
        for (i, &fi) in free.iter().enumerate() {
            b[i] = atb[fi] - (0..m).filter(|&j| fixed[j]).map(|j| ata[fi][j] * x[j]).sum::<f64>();
            for (j, &fj) in free.iter().enumerate() {
                a[(i, j)] = ata[fi][fj];
            }
            // A whisker of ridge keeps nearly collinear columns solvable.
            a[(i, i)] += 1e-10 * ata[fi][fi].max(1e-300);
        }
        let Some(solution) = a.lu().solve(&b) else { return x };
        let mut clamped = false;
        for (i, &fi) in free.iter().enumerate() {
            x[fi] = solution[i];
            if !(lower[fi]..=upper[fi]).contains(&x[fi]) {
                x[fi] = x[fi].clamp(lower[fi], upper[fi]);
                fixed[fi] = true;
                clamped = true;
            }
        }
        if !clamped {
            return x;
        }
    }
    x
}
