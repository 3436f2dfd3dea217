//! A proposal on a report that ties a jet pipe lag with a command delay: who the rivals are,
//! that the protocol separates them far more than a slow sine does, and that its predicted
//! differences are what the diagnosis's own replay of the protocol gives.

use super::explanations::rivals;
use super::protocol::Protocol;
use super::*;
use crate::input::recording::Recording;
use crate::replay::replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::{table_start, Parameters};
use jetpipe_model::simulation::DEFAULT_RELATIVE_TOLERANCE;
use jetpipe_model::variables::vr;
use serde_json::{json, Value};

const FORCE_NOISE: f64 = 0.05;

/// A report whose model has a jet pipe lag (ω1 lowered to 62.4 rad/s) that the command delay
/// ties, a candidate at the same place as the addition, and one at another place.
fn tied_report() -> Value {
    json!({
        "verdict": "explained",
        "noise_floor_N": FORCE_NOISE,
        "fmu_start_values": {"omega_1": 62.4, "start_at_equilibrium": false, "P1_start": 3.5e5, "P2_start": 5.1e5},
        "effects": [],
        "discovered": [{"candidate": "jet pipe lag", "location": "jet_pipe", "parameters": {"omega_1": 62.4},
                        "tied_locations": ["jet_pipe", "command"]}],
        "candidates": [
            {"candidate": "jet pipe lag", "location": "jet_pipe", "parameters": {"omega_1": 62.4}, "settings": {},
             "explained_share_heldout": 0.92},
            {"candidate": "jet pipe null", "location": "jet_pipe", "parameters": {"x_jp_offset": 1e-6}, "settings": {},
             "explained_share_heldout": 0.5},
            {"candidate": "force sensor offset and gain", "location": "force_sensor",
             "parameters": {"force_sensor_offset": 0.3}, "settings": {}, "explained_share_heldout": 0.1},
            {"candidate": "command delay", "location": "command", "named_effect": "transport_delay",
             "parameters": {"command_delay": 0.015}, "settings": {}, "explained_share_heldout": 0.918}
        ]
    })
}

/// Explanations `a` and `b`'s RMS force difference on `protocol`, in noise floors, through the
/// diagnosis's error-controlled replay.
fn replayed_difference(a: &Parameters, b: &Parameters, protocol: &Protocol) -> f64 {
    let recording = Recording::of(
        protocol.time.clone(),
        protocol.v_da.clone(),
        protocol.x_s.clone(),
        vec![0.0; protocol.len()],
    );
    let force = |p: &Parameters| {
        replay(
            &Actuator::new(p.clone()).unwrap(),
            &recording,
            DEFAULT_RELATIVE_TOLERANCE,
            usize::MAX,
        )
        .unwrap()
        .force
    };
    let (fa, fb) = (force(a), force(b));
    let sum: f64 = fa.iter().zip(&fb).map(|(x, y)| ((x - y) / FORCE_NOISE).powi(2)).sum();
    (sum / fa.len() as f64).sqrt()
}

#[test]
fn the_rivals_are_the_reports_model_then_the_tied_place_then_the_ranking_one_a_place() {
    let r = rivals(&tied_report(), 4).unwrap();
    let labels: Vec<&str> = r.explanations.iter().map(|e| e.label.as_str()).collect();
    assert_eq!(
        labels,
        [
            "the report's model (jet pipe lag)",
            "command delay",
            "force sensor offset and gain"
        ],
        "the jet pipe null is at the addition's place, which the report's model stands for"
    );
    assert_eq!(r.tied, ["jet_pipe", "command"]);
    // A place the remainder ties again, not next to its first mention, is named once.
    let mut again = tied_report();
    again["unexplained"] = json!({"tied_locations": ["jet_pipe"], "alternatives": ["unknown", "command"]});
    assert_eq!(rivals(&again, 4).unwrap().tied, ["jet_pipe", "command"]);
    let (model, delay) = (&r.explanations[0].parameters, &r.explanations[1].parameters);
    assert_eq!(model.get(vr::OMEGA_1), Some(62.4));
    assert_eq!(model.get(vr::COMMAND_DELAY), Some(0.0));
    // The rival is set on the model without the report's addition.
    assert_eq!(delay.get(vr::OMEGA_1), Some(table_start(vr::OMEGA_1)));
    assert_eq!(delay.get(vr::COMMAND_DELAY), Some(0.015));
    assert_eq!(r.noise, [FORCE_NOISE]);
}

#[test]
fn a_report_that_is_no_report_or_holds_one_explanation_is_refused_in_words() {
    let e = rivals(&json!({"noise_floor_N": 0.05}), 4).unwrap_err();
    assert!(e.contains("fmu_start_values"), "{e}");
    let mut alone = tied_report();
    alone["candidates"] = json!([]);
    let e = rivals(&alone, 4).unwrap_err();
    assert!(e.contains("nothing to separate"), "{e}");
    let options = ProposeOptions {
        seconds: 200.0,
        ..Default::default()
    };
    let e = propose(&tied_report(), &options, &mut |_| {}).unwrap_err();
    assert!(e.contains("--seconds 200") && e.contains("120"), "{e}");
}

#[test]
fn the_proposal_separates_a_tied_lag_and_delay_far_more_than_a_slow_sine_and_its_figures_are_the_replays() {
    let options = ProposeOptions {
        seconds: 10.0,
        draws_per_segment: 8,
        seed: 3,
        ..Default::default()
    };
    let p = propose(&tied_report(), &options, &mut |_| {}).unwrap();
    p.protocol.check().unwrap();
    assert_eq!(p.protocol.len(), 10_001);
    let lag_delay = p.differences.iter().find(|d| (d.first, d.second) == (0, 1)).unwrap();
    let (lag, delay) = (&p.explanations[0].parameters, &p.explanations[1].parameters);
    // The same figure through the diagnosis's own replay of the written protocol.
    let replayed = replayed_difference(lag, delay, &p.protocol);
    assert!(
        (replayed - lag_delay.noise_floors).abs() <= 0.02 * replayed,
        "proposal {:.3} against the replay's {replayed:.3} noise floors",
        lag_delay.noise_floors
    );
    // A slow sine, as a bench protocol that leaves the two tied.
    let n = 10_001;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let slow = Protocol {
        rate: 1000.0,
        v_da: time
            .iter()
            .map(|t| 2.0 + 2.0 * (std::f64::consts::TAU * 0.2 * t).sin())
            .collect(),
        x_s: vec![0.054; n],
        time,
    };
    let naive = replayed_difference(lag, delay, &slow);
    println!(
        "lag against delay: {:.2} noise floors proposed, {naive:.2} on a slow sine",
        lag_delay.noise_floors
    );
    assert!(
        lag_delay.noise_floors > 3.0 * naive,
        "{} against {naive}",
        lag_delay.noise_floors
    );
    assert!(p.smallest().noise_floors > 1.0);
}
