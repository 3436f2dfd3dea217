//! Several recordings of one actuator diagnosed together (`jetpipe diagnose --joint`): one
//! model for all, each recording's errors under it, and a departure that only one recording
//! holds reported as such.

use super::balance::moving_mass;
use super::diagnose;
use super::protocols::recorded;
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::{Diagnosis, JointDiagnosis, Options};
use jetpipe_model::physics::parameters::Parameters;
use synthetic_bench::{BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion};

use super::value_reference;

fn alone(label: &str, recording: &Recording) -> Diagnosis {
    let started = std::time::Instant::now();
    let d = diagnose(recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    println!(
        "{label} alone: {} in {:.1} s, held-out {:.4} → {:.4} N; {}",
        d.verdict(),
        started.elapsed().as_secs_f64(),
        d.before.heldout_rms,
        d.after.heldout_rms,
        d.summary().join(" | ")
    );
    d
}

fn together(recordings: Vec<(String, Recording)>) -> JointDiagnosis {
    let started = std::time::Instant::now();
    let joint = jetpipe_diagnosis::diagnose_joint(recordings, &Parameters::default(), &Options::default(), &mut |_| {})
        .unwrap();
    println!(
        "joint: {} in {:.1} s; {}; notes {:?}",
        joint.diagnosis.verdict(),
        started.elapsed().as_secs_f64(),
        joint.diagnosis.summary().join(" | "),
        joint.notes
    );
    joint
}

// A 0.1 kg mass moving with the stopper: one recording moves the stopper (a staircase of the
// command, 1 kHz), the other holds it still under a multisine sampled at 2 kHz, which the
// joint fit sees at 1 kHz. Only the first can show the mass.
#[test]
fn a_moving_mass_that_only_the_recording_with_a_moving_stopper_shows_is_found_together_and_held_by_that_one_only() {
    let effects = BenchEffects {
        undeclared: moving_mass(0.1),
        ..BenchEffects::default()
    };
    let moving = ProtocolSpec {
        command: CommandProtocol::Staircase,
        stopper: StopperMotion::Moves { speed: 0.2 },
        duration: 20.0,
        force_noise: 0.03,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let still = ProtocolSpec {
        command: CommandProtocol::Multisine,
        sample_rate: 2000.0,
        duration: 20.0,
        force_noise: 0.03,
        seed: 6,
        ..ProtocolSpec::default()
    };
    let a = recorded("joint-moving", &moving, &effects);
    let b = recorded("joint-still", &still, &effects);
    let (own_a, own_b) = (alone("moving", &a), alone("still", &b));
    let joint = together(vec![("moving.csv".into(), a), ("still.csv".into(), b)]);
    let d = &joint.diagnosis;
    let found = d
        .discovered
        .iter()
        .find(|t| t.candidate == "moving mass")
        .unwrap_or_else(|| panic!("no moving mass: {}", d.summary()[0]));
    let mass = d.parameters.get(value_reference("extra_force_acceleration")).unwrap();
    assert!(
        (mass / -0.1 - 1.0).abs() < 0.1,
        "{mass} kg·(N/(m/s²)) against the bench's 0.1 kg"
    );
    assert!(
        d.effects.is_empty(),
        "named {:?}",
        d.effects.iter().map(|e| e.name).collect::<Vec<_>>()
    );
    let [moving, still] = [&joint.recordings[0], &joint.recordings[1]];
    assert!(moving.holds().contains(&found.candidate), "{:?}", moving.without);
    assert!(!still.holds().contains(&found.candidate), "{:?}", still.without);
    assert!(
        joint
            .notes
            .iter()
            .any(|n| n.starts_with("moving mass is held by moving.csv only")),
        "{:?}",
        joint.notes
    );
    assert!(still.resampled && !moving.resampled);
    assert_eq!((moving.samples, still.samples), (20_000, 40_000));
    // Joint is never worse: each recording's held-out error under the joint model within a
    // tenth of its own diagnosis's.
    for (label, own, joint) in [("moving", &own_a, moving), ("still", &own_b, still)] {
        assert!(
            joint.after.heldout_rms <= 1.1 * own.after.heldout_rms,
            "{label}: {:.4} N jointly against {:.4} N alone",
            joint.after.heldout_rms,
            own.after.heldout_rms
        );
        assert!(
            joint.explained(),
            "{label}: {:.2} noise floors",
            joint.after.heldout_rms / joint.noise_floor
        );
    }
    let report = joint.to_json();
    assert_eq!(report["recordings"].as_array().unwrap().len(), 2);
    assert_eq!(report["discovered"][0]["held_by"], serde_json::json!(["moving.csv"]));
    assert_eq!(report["recording"], "moving.csv + still.csv");
}
