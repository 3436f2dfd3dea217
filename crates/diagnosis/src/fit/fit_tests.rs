//! Tests of the fits' searches and steps.

use super::bounded_least_squares;

/// A staircase at 1 kHz, a level a second, through a D/A that saturates above 4 V: the
/// training blocks hold 2 V and 4.2 V, the held-out ones 3 V and, in the last second,
/// 9.5 V. No limit above 4.2 V changes a training row, so the misfit is flat over most of
/// the commands recorded; searched over what the fits train on, the limit is found at 4 V.
/// The symmetric limits clip no negative command and stay off.
#[test]
fn a_limit_that_clips_only_the_highest_training_level_is_found_though_held_out_rows_go_higher() {
    use crate::candidates::{catalogue, set_parameter};
    use crate::fit::Problem;
    use crate::input::blocks::Block;
    use crate::input::recording::Recording;
    use crate::replay::replay_fast;
    use jetpipe_model::physics::actuator::Actuator;
    use jetpipe_model::physics::parameters::Parameters;
    let n = 8000;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let levels = [2.0, 4.2, 3.0, 3.0, 2.0, 4.2, 3.0, 9.5];
    let v_da: Vec<f64> = (0..n).map(|k| levels[k / 1000]).collect();
    let mut recording = Recording::of(time, v_da, vec![0.06; n], vec![0.0; n]);
    let base = Parameters::default();
    let mut clipped = base.clone();
    set_parameter(&mut clipped, "command_upper_limit", 4.0).unwrap();
    recording.force = replay_fast(&Actuator::new(clipped).unwrap(), &recording, n)
        .unwrap()
        .force;
    let blocks = Block::alternating(n, 2000);
    let problem = Problem::new(&recording, &base, &blocks, [0.05, 0.0, 0.0]);
    let base_replay = replay_fast(&Actuator::new(base.clone()).unwrap(), &recording, n).unwrap();
    let knots = crate::candidates::curves::CurveKnots::default();
    let candidates = catalogue(&base, false, None, &knots);
    let none = |_: &'static str| None;
    let fitted = |label: &str| {
        let candidate = candidates.iter().find(|c| c.label == label).unwrap();
        problem.fit(candidate, 1, &base_replay, &none).unwrap()
    };
    let upper = fitted("command upper limit");
    assert!(
        (upper.values[0] - 4.0).abs() < 0.02,
        "upper limit at {} V",
        upper.values[0]
    );
    assert!(upper.heldout[0] < 1e-3 * problem.errors(&[base_replay.force.clone(), vec![], vec![]]).1[0]);
    for label in ["command limit", "current limit"] {
        let symmetric = fitted(label);
        assert_eq!(symmetric.values[0], symmetric.candidate.terms[0].neutral, "{label}");
    }
}

#[test]
fn a_term_whose_column_is_all_zeros_gets_no_step_and_the_others_their_least_squares_step() {
    // Normal equations of two coupled terms (steps 2 and −1) and, between them, a term that
    // moves nothing: its row and column of zeros.
    let ata = vec![vec![4.0, 0.0, 2.0], vec![0.0, 0.0, 0.0], vec![2.0, 0.0, 2.0]];
    let atb = vec![6.0, 0.0, 2.0];
    let unbounded = [f64::NEG_INFINITY; 3];
    let step = bounded_least_squares(&ata, &atb, &[true; 3], &unbounded, &[f64::INFINITY; 3]);
    assert_eq!(step[1], 0.0, "{step:?}");
    assert!((step[0] - 2.0).abs() < 1e-9 && (step[2] + 1.0).abs() < 1e-9, "{step:?}");
}

#[test]
fn a_step_past_a_bound_stops_at_the_bound_and_the_rest_is_solved_again() {
    // Coupled terms: unbounded, the steps are (1, 1); with the first held at most 0.5 the
    // second solves 0.5 + 2 x1 = 3, so x1 = 1.25.
    let ata = vec![vec![2.0, 1.0], vec![1.0, 2.0]];
    let atb = vec![3.0, 3.0];
    let step = bounded_least_squares(&ata, &atb, &[true; 2], &[f64::NEG_INFINITY; 2], &[0.5, f64::INFINITY]);
    assert!(
        (step[0] - 0.5).abs() < 1e-12 && (step[1] - 1.25).abs() < 1e-9,
        "{step:?}"
    );
}
