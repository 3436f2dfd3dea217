//! A named piston friction beside another effect. The friction is the smooth law
//! F_c tanh(v / 10 mm/s) (`friction_smoothing_velocity`), not the bench's Stribeck curve:
//! seals that deform over a wide range of speed, so that at the stopper's speeds much of
//! the friction lies below its Coulomb level. Each case holds the friction and one other
//! effect and asks for both, the friction by its name, each within a tenth of its size.

use jetpipe_diagnosis::Diagnosis;
use synthetic_bench::{BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion, UndeclaredEffects};

use super::{names, value_reference};

/// A smooth friction of `coulomb` N beside what `other` switches on.
fn friction_beside(coulomb: f64, other: BenchEffects) -> BenchEffects {
    BenchEffects {
        friction_coulomb: coulomb,
        undeclared: UndeclaredEffects {
            friction_smoothing_velocity: 0.01,
            ..other.undeclared
        },
        ..other
    }
}

/// The diagnosis of `spec`'s protocol with `effects`, printed.
fn diagnosed(label: &str, spec: ProtocolSpec, effects: &BenchEffects) -> Diagnosis {
    super::protocols::diagnosed(&format!("beside-{label}"), &spec, effects)
}

fn parameter(d: &Diagnosis, name: &str) -> f64 {
    d.parameters.get(value_reference(name)).unwrap()
}

fn assert_friction(d: &Diagnosis, coulomb: f64) {
    assert!(names(d).contains(&"piston_friction"), "named {:?}", names(d));
    let level = parameter(d, "friction_coulomb");
    assert!((level / coulomb - 1.0).abs() < 0.1, "friction_coulomb = {level} N");
}

fn shaken(centre: f64, amplitude: f64, frequency: f64) -> StopperMotion {
    StopperMotion::Sine {
        centre,
        amplitude,
        frequency,
    }
}

// A seal friction growing with the sum of the pressures fitted the friction to 0.1 % while
// the lag was still missing, and replaced it: as rich as the named effect, it must now close
// a share of the way to the noise.
#[test]
fn a_smooth_friction_beside_a_force_sensor_lag_is_the_named_friction_and_the_lag() {
    let other = BenchEffects {
        undeclared: UndeclaredEffects {
            force_sensor_lag: 0.002,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        stopper: shaken(0.066, 0.003, 1.4),
        sample_rate: 500.0,
        duration: 30.0,
        seed: 32,
        ..ProtocolSpec::default()
    };
    let d = diagnosed("lag", spec, &friction_beside(2.3, other));
    assert_friction(&d, 2.3);
    let found: Vec<&str> = d.discovered.iter().map(|t| t.candidate).collect();
    assert_eq!(found, ["force sensor lag"], "{:?}", d.summary());
    let lag = parameter(&d, "force_sensor_lag");
    assert!((lag / 0.002 - 1.0).abs() < 0.1, "force_sensor_lag = {lag} s");
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
}

// Left for the second round, the delay's departure is 1.5 noise floors of the force and 1.4
// of each pressure: the noise is half the misfit, and the delay, which took 92 % of the rest,
// was held to 80 % of all of it. Its force gain was half a floor, and the pressures' gain
// did not count for a named effect.
#[test]
#[ignore = "a broad case (about 3e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_half_millisecond_command_delay_beside_a_smooth_friction_is_the_named_delay_and_friction() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        stopper: shaken(0.064, 0.004, 1.5),
        sample_rate: 1000.0,
        duration: 20.0,
        seed: 34,
        ..ProtocolSpec::default()
    };
    let other = BenchEffects {
        command_delay: 0.0005,
        ..BenchEffects::default()
    };
    let d = diagnosed("delay", spec, &friction_beside(2.7, other));
    assert_friction(&d, 2.7);
    assert!(names(&d).contains(&"transport_delay"), "named {:?}", names(&d));
    let delay = parameter(&d, "command_delay");
    assert!((delay / 0.0005 - 1.0).abs() < 0.1, "command_delay = {delay} s");
    assert!(d.discovered.is_empty(), "{:?}", d.summary());
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
}

// The chamber 2 transducer's delay holds a third of the first round's misfit, which a
// friction cannot move: the named friction's share is of the force's departure, where it
// took all of it.
#[test]
#[ignore = "a broad case (about 4e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_smooth_friction_beside_a_late_chamber_2_transducer_is_the_named_friction_and_the_delay() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Sine,
        stopper: shaken(0.055, 0.0026, 1.76),
        sample_rate: 250.0,
        duration: 20.0,
        seed: 43,
        ..ProtocolSpec::default()
    };
    let other = BenchEffects {
        undeclared: UndeclaredEffects {
            pressure_sensor_delay_2: 0.012,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let d = diagnosed("p2-delay", spec, &friction_beside(2.33, other));
    assert_friction(&d, 2.33);
    let found: Vec<&str> = d.discovered.iter().map(|t| t.candidate).collect();
    assert_eq!(found, ["pressure sensor delay"], "{:?}", d.summary());
    let delay = parameter(&d, "p2_sensor_delay");
    assert!((delay / 0.012 - 1.0).abs() < 0.1, "p2_sensor_delay = {delay} s");
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
}

// An 8 ms delay explains the pressures but not the force while the friction is off; once
// the friction is added, the delay must be judged on the force the friction leaves, not on
// the scores of the round before (68 % where it explains all).
#[test]
#[ignore = "a broad case (about 7e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn an_eight_millisecond_command_delay_beside_a_friction_is_the_named_delay_once_the_friction_is_in() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Multisine,
        stopper: shaken(0.071, 0.0016, 1.33),
        sample_rate: 1000.0,
        duration: 20.0,
        seed: 42,
        ..ProtocolSpec::default()
    };
    let other = BenchEffects {
        command_delay: 0.008,
        ..BenchEffects::default()
    };
    let d = diagnosed("long-delay", spec, &friction_beside(2.76, other));
    assert_friction(&d, 2.76);
    assert!(names(&d).contains(&"transport_delay"), "named {:?}", names(&d));
    let delay = parameter(&d, "command_delay");
    assert!((delay / 0.008 - 1.0).abs() < 0.05, "command_delay = {delay} s");
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
}

// Without pressures, a 50 Hz filter on the force sensor is fitted first, at 34 Hz with the
// friction still off; the friction then falls short of its share and a term without a name
// takes its round. Tried in that term's place with every addition refitted, the named
// friction does as well, and the filter comes back to 50 Hz.
#[test]
#[ignore = "a broad case (about 1e+02 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn a_smooth_friction_beside_a_force_sensor_filter_without_pressures_is_the_named_friction_and_the_filter() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Ramps,
        stopper: StopperMotion::Moves { speed: 0.2 },
        sample_rate: 1000.0,
        duration: 20.0,
        pressures: false,
        seed: 41,
        ..ProtocolSpec::default()
    };
    let other = BenchEffects {
        undeclared: UndeclaredEffects {
            force_sensor_filter_frequency: 50.0,
            force_sensor_filter_damping: 0.88,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let d = diagnosed("filter", spec, &friction_beside(1.43, other));
    assert_friction(&d, 1.43);
    let found: Vec<&str> = d.discovered.iter().map(|t| t.candidate).collect();
    assert_eq!(found, ["force sensor second-order filter"], "{:?}", d.summary());
    let frequency = parameter(&d, "force_sensor_filter_frequency");
    assert!(
        (frequency / 50.0 - 1.0).abs() < 0.1,
        "force_sensor_filter_frequency = {frequency} Hz"
    );
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
}

/// Dead volumes (1.5 and 1.0 cm³) beside a laminar leak out of chamber 1 to the return
/// (8e-12 kg/(s·Pa)) under a staircase at 1 kHz with pressures. Alone, each of the dead
/// volumes and the heat exchange makes a chamber's pressure worse, the leak being the other
/// half of the pressures' departure, and nothing was added: the dead volumes are named with
/// the leak beside them, fitted together, each within a tenth of its size.
#[test]
#[ignore = "a broad case (about 3e+01 s of wall time two at a time; its kind has other cases here); scripts/bench_cases.sh runs every case"]
fn dead_volumes_beside_a_laminar_leak_out_of_chamber_1_are_the_named_dead_volumes_with_the_leak_beside_them() {
    let effects = BenchEffects {
        dead_volume_1: 1.5e-6,
        dead_volume_2: 1.0e-6,
        undeclared: UndeclaredEffects {
            laminar_leak_1: 8e-12,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        sample_rate: 1000.0,
        duration: 20.0,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let d = diagnosed("dead-volumes-leak", spec, &effects);
    assert_eq!(names(&d), ["dead_volume"], "{:?}", d.summary());
    for (name, size) in [
        ("dead_volume_1", 1.5e-6),
        ("dead_volume_2", 1.0e-6),
        ("chamber_laminar_vent_1", 8e-12),
    ] {
        let value = parameter(&d, name);
        assert!((value / size - 1.0).abs() < 0.1, "{name} = {value}");
    }
    assert_eq!(d.verdict(), "explained", "{}", d.summary()[0]);
}
