//! The command's curve across a stretch of commands the training blocks never hold.
//!
//! A staircase holds a few levels. Between two of them no training sample constrains the
//! command's curve, and the chord its knots draw there is whatever the fit left; a level that
//! only the held-out blocks hold then misses by the chord's error (a ±0.4 V dead zone under a
//! 20 s staircase: 3.25 V held only in a held-out block, between training levels at −1.01 and
//! 3.84 V, read 0.06 V off, and 5.9 noise floors of force left). Such a stretch gets its
//! neighbours' lines instead, extended into the gap and joined where they meet, or, where the
//! lower line runs above the upper one, by a flat stretch in the middle of the gap (a dead
//! zone's shape). The replay keeps a join only where it fits the held-out blocks no worse than
//! the chord, as [`crate::candidates::curves::corners_across_unvisited`] does on a channel's curve.

/// The command curve's knots in `set`, or None when it has none.
fn knots(set: &[(&'static str, f64)]) -> Option<(Vec<f64>, Vec<f64>)> {
    let get = |name: &str| set.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
    let n = get("command_curve_knots")? as usize;
    let x: Option<Vec<f64>> = (1..=n).map(|k| get(&format!("command_curve_x_{k}"))).collect();
    let y: Option<Vec<f64>> = (1..=n).map(|k| get(&format!("command_curve_y_{k}"))).collect();
    Some((x?, y?))
}

fn with_knots(set: &[(&'static str, f64)], x: &[f64], y: &[f64]) -> Vec<(&'static str, f64)> {
    let mut out = set.to_vec();
    for (name, value) in out.iter_mut() {
        for (k, (&xk, &yk)) in x.iter().zip(y).enumerate() {
            if *name == format!("command_curve_x_{}", k + 1) {
                *value = xk;
            } else if *name == format!("command_curve_y_{}", k + 1) {
                *value = yk;
            }
        }
    }
    out
}

/// The stretches between knots `j` and `j + 1` with no `training` command (sorted) strictly
/// inside, and a stretch on either side whose line can be extended: their `j`. A command
/// held at levels visits points, not ranges, so a stretch with one level inside is visited.
pub fn unvisited_stretches(x: &[f64], training: &[f64]) -> Vec<usize> {
    (1..x.len().saturating_sub(2))
        .filter(|&j| {
            let from = training.partition_point(|&v| v <= x[j]);
            let to = training.partition_point(|&v| v < x[j + 1]);
            to <= from
        })
        .collect()
}

/// The knots with stretch `j` replaced by its neighbours' lines joined inside the gap the
/// `training` commands (sorted) leave around it: at the lines' crossing, or by a flat stretch
/// centred in the gap when the line below runs above the line beyond. None when neither
/// fits inside the gap.
pub fn joined_across(x: &[f64], y: &[f64], j: usize, training: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
    if j == 0 || j + 2 >= x.len() {
        return None;
    }
    let below = (y[j] - y[j - 1]) / (x[j] - x[j - 1]);
    let beyond = (y[j + 2] - y[j + 1]) / (x[j + 2] - x[j + 1]);
    let lower = |v: f64| y[j] + below * (v - x[j]);
    let upper = |v: f64| y[j + 1] + beyond * (v - x[j + 1]);
    // The gap: from the last training command at or below the stretch's start to the first
    // at or above its end, within the neighbouring knots so that the knots stay in order.
    let last_below = training[..training.partition_point(|&v| v <= x[j])].last().copied();
    let first_beyond = training.get(training.partition_point(|&v| v < x[j + 1])).copied();
    let lo = last_below.unwrap_or(x[j - 1]).max(x[j - 1]);
    let hi = first_beyond.unwrap_or(x[j + 2]).min(x[j + 2]);
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let (mut nx, mut ny) = (x.to_vec(), y.to_vec());
    if (below - beyond).abs() > 1e-9 {
        let crossing = (y[j + 1] - y[j] + below * x[j] - beyond * x[j + 1]) / (below - beyond);
        if crossing > lo && crossing < hi {
            let after = 0.5 * (crossing + hi);
            nx[j] = crossing;
            ny[j] = lower(crossing);
            nx[j + 1] = after;
            ny[j + 1] = upper(after);
            return Some((nx, ny));
        }
    }
    let middle = 0.5 * (lo + hi);
    let step = lower(middle) - upper(middle);
    if step <= 0.0 || below + beyond <= 0.0 {
        return None;
    }
    let width = 2.0 * step / (below + beyond);
    if width >= hi - lo {
        return None;
    }
    let (start, end) = (middle - 0.5 * width, middle + 0.5 * width);
    nx[j] = start;
    ny[j] = lower(start);
    nx[j + 1] = end;
    ny[j + 1] = upper(end);
    Some((nx, ny))
}

/// The force's held-out RMS error of a replay with a parameter set, None when the model
/// refuses the set.
pub type HeldOutRms<'a> = dyn FnMut(&[(&'static str, f64)]) -> Option<f64> + 'a;

/// The command curve in `set` with every unvisited stretch joined from its neighbours where
/// `heldout_rms` (the force's held-out RMS error of a replay with a set, None when the model
/// refuses it) is no larger with the join than without: the set, and how many replays that
/// took. `training` holds the training blocks' commands, sorted.
pub fn joined_where_held_out_agrees(
    set: Vec<(&'static str, f64)>,
    training: &[f64],
    heldout_now: f64,
    heldout_rms: &mut HeldOutRms,
) -> (Vec<(&'static str, f64)>, usize) {
    let Some((mut x, mut y)) = knots(&set) else {
        return (set, 0);
    };
    let (mut set, mut best, mut replays) = (set, heldout_now, 0);
    for j in unvisited_stretches(&x, training) {
        let Some((nx, ny)) = joined_across(&x, &y, j, training) else {
            continue;
        };
        let trial = with_knots(&set, &nx, &ny);
        replays += 1;
        if let Some(rms) = heldout_rms(&trial) {
            if rms <= best {
                (set, best, x, y) = (trial, rms, nx, ny);
            }
        }
    }
    (set, replays)
}

#[cfg(test)]
mod tests {
    use super::*;
    use jetpipe_model::physics::static_curve::StaticCurve;

    /// A ±0.4 V dead zone seen at training levels −3, −1.01, 3.84, 4.39 and 5.44 V, fitted
    /// with knots that left a chord across the gap: slope 1 on either side, offset +0.4 V
    /// below the gap and −0.4 V above it.
    fn dead_zone_fit() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let x = vec![-3.0, 1.97, 3.36, 5.11, 8.46];
        let y = vec![-2.6, 2.37, 2.96, 4.71, 8.06];
        let training = vec![-3.0, -1.01, 3.84, 4.39, 5.44];
        (x, y, training)
    }

    #[test]
    fn a_stretch_no_training_command_visits_is_found_and_a_visited_one_is_not() {
        let (x, _, training) = dead_zone_fit();
        assert_eq!(unvisited_stretches(&x, &training), vec![1]);
    }

    #[test]
    fn parallel_lines_a_step_apart_are_joined_by_a_flat_stretch_that_keeps_each_side_on_its_line() {
        let (x, y, training) = dead_zone_fit();
        let (nx, ny) = joined_across(&x, &y, 1, &training).expect("a join");
        let curve = StaticCurve::through(&nx, &ny);
        // The held-out level between the training levels lies on the line above the gap.
        assert!((curve.at(3.25) - 2.85).abs() < 0.01, "{}", curve.at(3.25));
        // The training levels keep their values.
        for v in [-1.01, 3.84, 4.39] {
            let before = StaticCurve::through(&x, &y).at(v);
            assert!(
                (curve.at(v) - before).abs() < 1e-9,
                "{v}: {} against {before}",
                curve.at(v)
            );
        }
        // The join is flat, 0.8 V wide (the step over the lines' slope), centred in the gap.
        assert!((ny[1] - ny[2]).abs() < 1e-9);
        assert!((nx[2] - nx[1] - 0.8).abs() < 0.01, "{:?}", nx);
        assert!((0.5 * (nx[1] + nx[2]) - 0.5 * (-1.01 + 3.84)).abs() < 1e-9);
    }

    #[test]
    fn lines_that_cross_inside_the_gap_are_joined_at_their_crossing() {
        // A saturation at 2 V: slope 1 below, flat above, the chord from 1 to 5 V unvisited.
        let x = vec![-2.0, 1.0, 5.0, 8.0];
        let y = vec![-2.0, 1.0, 2.0, 2.0];
        let training = vec![-2.0, 0.0, 1.0, 6.0, 8.0];
        let (nx, ny) = joined_across(&x, &y, 1, &training).expect("a join");
        let curve = StaticCurve::through(&nx, &ny);
        assert!((nx[1] - 2.0).abs() < 1e-9, "{:?}", nx);
        assert!((curve.at(3.0) - 2.0).abs() < 1e-9);
        assert!((curve.at(1.5) - 1.5).abs() < 1e-9);
    }

    #[test]
    fn a_join_is_kept_only_where_the_held_out_blocks_fit_it_no_worse() {
        let (x, y, training) = dead_zone_fit();
        let mut set = vec![("command_curve_knots", x.len() as f64)];
        for k in 0..x.len() {
            set.push((
                [
                    "command_curve_x_1",
                    "command_curve_x_2",
                    "command_curve_x_3",
                    "command_curve_x_4",
                    "command_curve_x_5",
                ][k],
                x[k],
            ));
            set.push((
                [
                    "command_curve_y_1",
                    "command_curve_y_2",
                    "command_curve_y_3",
                    "command_curve_y_4",
                    "command_curve_y_5",
                ][k],
                y[k],
            ));
        }
        let at_held_out_level = |s: &[(&'static str, f64)]| {
            let (x, y) = knots(s).unwrap();
            (StaticCurve::through(&x, &y).at(3.25) - 2.85).abs()
        };
        let now = at_held_out_level(&set);
        let (joined, replays) =
            joined_where_held_out_agrees(set.clone(), &training, now, &mut |s| Some(at_held_out_level(s)));
        assert_eq!(replays, 1);
        assert!(at_held_out_level(&joined) < 0.01);
        let (kept, _) =
            joined_where_held_out_agrees(set.clone(), &training, now, &mut |s| Some(1.0 - at_held_out_level(s)));
        assert_eq!(kept, set);
    }
}
