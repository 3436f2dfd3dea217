//! Two and three departures at once, of which one is a named effect: a supply line
//! resistance (the named `supply_pressure_drop`) beside a mass moving with the stopper, and
//! beside that mass and a force sensor lag. The first round sees every departure at once, so
//! its candidates each carry a share of all of them; each departure must still be found at
//! its place, the supply's by its name. The bench's supply restriction is sized from its
//! resistance and feeds an enlarged plenum, which the model's laws hold to within 2 noise
//! floors on their own (`synthetic.rs`), so that is the bar where it is found alone beside
//! the mass.

use jetpipe_diagnosis::Diagnosis;
use synthetic_bench::{BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion, UndeclaredEffects};

use super::{names, value_reference};

fn diagnosed(label: &str, effects: &BenchEffects) -> Diagnosis {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        stopper: StopperMotion::Moves { speed: 0.2 },
        sample_rate: 1000.0,
        duration: 24.0,
        force_noise: 0.03,
        seed: 77,
        ..ProtocolSpec::default()
    };
    super::protocols::diagnosed(&format!("compound-{label}"), &spec, effects)
}

fn parameter(d: &Diagnosis, name: &str) -> f64 {
    d.parameters.get(value_reference(name)).unwrap()
}

fn assert_supply_named(d: &Diagnosis) {
    assert!(
        names(d).contains(&"supply_pressure_drop"),
        "named {:?}; {}",
        names(d),
        d.summary().join(" | ")
    );
}

// Fails today (issue 78): the supply is named and the mass found, but the mass is fitted
// 21 % heavy and 2.1 noise floors stay, where the mass alone is fitted within 10 %.
#[test]
#[ignore = "fails today: the mass fitted 21 % heavy, 2.1 noise floors left (issue 78); scripts/bench_cases.sh runs every case"]
fn a_supply_restriction_beside_a_moving_mass_is_the_named_supply_drop_and_the_mass() {
    let effects = BenchEffects {
        supply_resistance: 5e8,
        undeclared: UndeclaredEffects {
            moving_mass: 0.1,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let d = diagnosed("supply-mass", &effects);
    assert_supply_named(&d);
    let moving = parameter(&d, "extra_force_acceleration");
    assert!(
        (moving / -0.1 - 1.0).abs() < 0.15,
        "extra_force_acceleration = {moving} kg"
    );
    assert!(
        d.after.heldout_rms <= 2.0 * d.noise_floor,
        "held-out {:.4} N on a floor of {:.4} N",
        d.after.heldout_rms,
        d.noise_floor
    );
}

// Explained, but the mass and the lag are read together as one second-order filter of the
// force sensor: a term that stands in for two, which the diagnosis does not yet split.
#[test]
#[ignore = "a broad case (about 30 s of wall time); scripts/bench_cases.sh runs every case"]
fn a_supply_restriction_a_moving_mass_and_a_force_sensor_lag_are_explained_with_the_supply_named() {
    let effects = BenchEffects {
        supply_resistance: 5e8,
        undeclared: UndeclaredEffects {
            moving_mass: 0.1,
            force_sensor_lag: 0.004,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let d = diagnosed("supply-mass-lag", &effects);
    assert_supply_named(&d);
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
}
