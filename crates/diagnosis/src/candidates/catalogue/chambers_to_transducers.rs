//! The written candidates from the chambers to the transducers: the chambers, the mechanics,
//! the force sensor, a constant oscillating at a spectral line, and the pressure transducers.

use super::terms::{c, filter, modulated, output, parameter, second_order, started, term_off};
use crate::candidates::Candidate;
use crate::candidates::Filter;
use crate::candidates::Mechanism;
use crate::candidates::Modulation;
use crate::candidates::Regressor;
use crate::candidates::Term;
use crate::replay::signals::FORCE;
use crate::replay::signals::P1;
use crate::replay::signals::P2;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;

/// The written candidates from the chambers to the transducers, in the chain's order;
/// `periodic_hz` is the residual's spectral line, if it has one.
pub(super) fn chambers_to_transducers(
    base: &Parameters,
    has_pressures: bool,
    periodic_hz: Option<f64>,
) -> Vec<Candidate> {
    let p = |name, unit, relative, lower, upper| parameter(base, name, unit, relative, lower, upper);
    let offset = |name, unit, step, lower, upper| Term {
        step,
        ..parameter(base, name, unit, 0.0, lower, upper)
    };
    let _inf = f64::INFINITY;
    let mut list = vec![
        c(
            "dead volumes",
            Place::Chambers,
            Family::ParameterOffset,
            Some("dead_volume"),
            vec![
                term_off("dead_volume_1", "m3", 5e-7, 1e-4),
                term_off("dead_volume_2", "m3", 5e-7, 1e-4),
            ],
        ),
        c(
            "heat exchange",
            Place::Chambers,
            Family::ParameterOffset,
            Some("heat_transfer"),
            vec![term_off("heat_transfer_fraction", "1", 0.05, 1.0)],
        ),
        c(
            "leakage past the piston",
            Place::Chambers,
            Family::ParameterOffset,
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
            Place::Chambers,
            Family::ParameterOffset,
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
            Place::Chambers,
            Family::ParameterOffset,
            None,
            vec![p("gamma", "1", 0.005, 1.0 + 1e-6, 5.0 / 3.0)],
        ),
        // The gas temperature of (2.6), a constant of the model (the orifices' mass flows and
        // the chambers' pressure rates), and the same drifting over the recording (the supply
        // air warming up): the FMU carries the ramp as T_drift.
        c(
            "gas temperature",
            Place::Chambers,
            Family::ParameterOffset,
            None,
            vec![p("T", "K", 0.005, 200.0, 400.0)],
        ),
        c(
            "gas temperature drift",
            Place::Chambers,
            Family::Drift,
            None,
            vec![
                p("T", "K", 0.005, 200.0, 400.0),
                modulated("T_drift", "K", "T", Modulation::Ramp, 1.0),
            ],
        ),
        c(
            "chamber leaks to the return",
            Place::Chambers,
            Family::ExtraFlow,
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
            Place::Chambers,
            Family::ExtraFlow,
            None,
            vec![
                term_off("chamber_laminar_vent_1", "kg/(s.Pa)", 1e-11, 1e-6),
                term_off("chamber_laminar_vent_2", "kg/(s.Pa)", 1e-11, 1e-6),
            ],
        ),
        c(
            "chamber leaks from the supply",
            Place::Chambers,
            Family::ExtraFlow,
            None,
            vec![
                term_off("chamber_supply_leak_1", "m2", 5e-9, 1e-6),
                term_off("chamber_supply_leak_2", "m2", 5e-9, 1e-6),
            ],
        ),
        c(
            "laminar chamber leaks from the supply",
            Place::Chambers,
            Family::ExtraFlow,
            None,
            vec![
                term_off("chamber_laminar_supply_leak_1", "kg/(s.Pa)", 1e-11, 1e-6),
                term_off("chamber_laminar_supply_leak_2", "kg/(s.Pa)", 1e-11, 1e-6),
            ],
        ),
        // Beside the leakage past the piston (2.23), which keeps its orifice law (its own candidate).
        c(
            "laminar leak between the chambers",
            Place::Chambers,
            Family::ExtraFlow,
            None,
            vec![term_off("chamber_laminar_cross_leak", "kg/(s.Pa)", 1e-11, 1e-6)],
        ),
        c(
            "Coulomb friction",
            Place::Mechanics,
            Family::ExtraForce,
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
            Place::Mechanics,
            Family::ExtraForce,
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
            Place::Mechanics,
            Family::ExtraForce,
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
            Place::Mechanics,
            Family::ExtraForce,
            None,
            vec![output("viscous_friction", "N.s/m", FORCE, Regressor::Viscous, 1.0)],
        ),
        // The return spring's rate and its free length, (2.37): the floor the force sits on
        // while the pressures push less than the spring. Where the stopper stays put only the
        // floor's force shows, and either gives it; where it moves, the held-out blocks choose.
        c(
            "piston bore",
            Place::Mechanics,
            Family::ParameterOffset,
            None,
            // D_cyl sets the piston's area, (2.30)–(2.34): the force per pressure difference and
            // the chambers' volumes together.
            vec![p("D_cyl", "m", 0.002, 1e-3, 0.1)],
        ),
        c(
            "return spring rate",
            Place::Mechanics,
            Family::ParameterOffset,
            None,
            vec![p("k_spring", "N/m", 0.01, 0.0, 1e5)],
        ),
        c(
            "return spring free length",
            Place::Mechanics,
            Family::ParameterOffset,
            None,
            vec![offset("L_spring0", "m", 1e-4, 0.0, 1.0)],
        ),
        c(
            "stopper compliance",
            Place::Mechanics,
            Family::Compliance,
            None,
            vec![term_off("stopper_compliance", "m/N", 1e-6, 1e-3)],
        ),
        c(
            "stopper mount with a lag",
            Place::Mechanics,
            Family::Compliance,
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
            Place::Mechanics,
            Family::ExtraForce,
            None,
            vec![output("position_stiffness", "N/m", FORCE, Regressor::Position, 10.0)],
        ),
        // The extra force's library beyond friction, viscous friction and the position force:
        // single columns, added one per round (forward selection on the held-out blocks)
        // and refitted jointly. (P1 − P2), an error of the piston area, is in the model but
        // not tried: it reads as the force sensor's gain wherever the pressures set the force.
        c(
            "moving mass",
            Place::Mechanics,
            Family::ExtraForce,
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
            Place::Mechanics,
            Family::ExtraForce,
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
            Place::Mechanics,
            Family::ExtraForce,
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
            Place::ForceSensor,
            Family::ParameterOffset,
            Some("sensor_offset_gain"),
            vec![
                output("force_sensor_offset", "N", FORCE, Regressor::One, 0.1),
                output("force_sensor_gain_error", "1", FORCE, Regressor::Own, 1e-3),
            ],
        ),
        c(
            "force sensor curve",
            Place::ForceSensor,
            Family::Nonlinearity,
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
            Place::ForceSensor,
            Family::Dynamics,
            None,
            vec![filter("force_sensor_lag", "s", FORCE, Filter::Lag, 1e-4, 0.2)],
        ),
        c(
            "force sensor second-order filter",
            Place::ForceSensor,
            Family::Dynamics,
            None,
            second_order("force_sensor_filter_frequency", "force_sensor_filter_damping", FORCE),
        ),
        c(
            "force sensor delay",
            Place::ForceSensor,
            Family::Delay,
            None,
            vec![filter("force_sensor_delay", "s", FORCE, Filter::Delay, 1e-4, 0.2)],
        ),
        c(
            "force sensor play",
            Place::ForceSensor,
            Family::Hysteresis,
            None,
            vec![filter("force_sensor_play", "N", FORCE, Filter::Play, 1e-3, 20.0)],
        ),
        c(
            "force sensor drift",
            Place::ForceSensor,
            Family::Drift,
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
            Place::Supply,
            Family::Periodic,
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
            Place::ForceSensor,
            Family::Periodic,
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
            Place::PressureSensors,
            Family::ParameterOffset,
            None,
            vec![output("p1_sensor_offset", "Pa", P1, Regressor::One, 100.0)],
        ));
        list.push(c(
            "chamber 2 pressure sensor offset",
            Place::PressureSensors,
            Family::ParameterOffset,
            None,
            vec![output("p2_sensor_offset", "Pa", P2, Regressor::One, 100.0)],
        ));
        list.push(c(
            "pressure sensor offsets and gains",
            Place::PressureSensors,
            Family::ParameterOffset,
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
                Place::PressureSensors,
                Family::Dynamics,
                None,
                vec![filter(lag, "s", channel, Filter::Lag, 1e-4, 0.2)],
            ));
            list.push(c(
                "pressure sensor second-order filter",
                Place::PressureSensors,
                Family::Dynamics,
                None,
                second_order(frequency, damping, channel),
            ));
            list.push(c(
                "pressure sensor delay",
                Place::PressureSensors,
                Family::Delay,
                None,
                vec![filter(delay, "s", channel, Filter::Delay, 1e-4, 0.2)],
            ));
        }
        list.push(c(
            "pressure sensor drift",
            Place::PressureSensors,
            Family::Drift,
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
