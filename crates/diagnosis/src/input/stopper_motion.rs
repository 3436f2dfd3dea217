//! The stopper's velocity and acceleration as the replays' forces read them at each sample of a
//! recording, and the half-width of the acceleration formed from its positions
//! ([`crate::input::acceleration`]) chosen for it.

use crate::input::acceleration::{smoothed_accelerations, WINDOWS};
use crate::input::recording::Recording;
use jetpipe_model::physics::extra_force;

/// The half-width of [`WINDOWS`] whose acceleration best carries the force `residual`
/// (recorded minus the starting model's replay, at the recording's rows): for each, the
/// largest share of the residual's variance that one coefficient times the acceleration
/// times one of 1, |v| and the position about its mean explains (a moving mass, a mass that
/// grows with the speed or the stroke). With no such force the choice moves nothing: the
/// model reads its input only through a force that follows the acceleration.
pub fn choose_window(recording: &Recording, residual: &[f64]) -> f64 {
    let n = recording.len().min(residual.len());
    if n < 8 {
        return WINDOWS[2];
    }
    let mean_position = recording.x_s[..n].iter().sum::<f64>() / n as f64;
    let r_mean = residual[..n].iter().sum::<f64>() / n as f64;
    let r_var: f64 = residual[..n].iter().map(|r| (r - r_mean).powi(2)).sum();
    let mut best = (WINDOWS[2], f64::NEG_INFINITY);
    for &window in &WINDOWS {
        let mut probe = recording.clone();
        probe.acceleration_window = window;
        let a = stopper_acceleration(&probe);
        let v = stopper_velocity(&probe);
        let explained = [0usize, 1, 2]
            .iter()
            .map(|&factor| {
                let g = |k: usize| match factor {
                    0 => a[k],
                    1 => a[k] * v[k].abs(),
                    _ => a[k] * (recording.x_s[k] - mean_position),
                };
                let g_mean = (0..n).map(g).sum::<f64>() / n as f64;
                let (mut cross, mut g_var) = (0.0, 0.0);
                for k in 0..n {
                    let d = g(k) - g_mean;
                    cross += d * (residual[k] - r_mean);
                    g_var += d * d;
                }
                if g_var > 0.0 && r_var > 0.0 {
                    cross * cross / (g_var * r_var)
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max);
        if explained > best.1 {
            best = (window, explained);
        }
    }
    best.0
}

/// Stopper velocity as the replays' forces read it at sample k: the slope of the interval
/// that ends there carried to the sample with the acceleration the positions form
/// ([`jetpipe_model::physics::extra_force::stopper_velocities`]; zero at the first sample),
/// whatever acceleration input the replays are given. For a recording thinned for the fits,
/// the full-rate recording's at the row.
pub fn stopper_velocity(recording: &Recording) -> Vec<f64> {
    at_rows(recording, &extra_force::stopper_velocities)
}

/// The stopper acceleration the model reads at each sample: formed from the positions
/// (`jetpipe_model::physics::extra_force::stopper_accelerations`), or, with an
/// acceleration window, the input the replays give it ([`crate::input::acceleration`]); of the
/// full-rate recording at the rows of a thinned one.
pub fn stopper_acceleration(recording: &Recording) -> Vec<f64> {
    let window = recording.acceleration_window;
    if window <= 0.0 {
        return at_rows(recording, &extra_force::stopper_accelerations);
    }
    at_rows(recording, &|time: &[f64], x_s: &[f64]| {
        smoothed_accelerations(time, x_s, window)
    })
}

/// A series formed from a motion's sample times and positions.
type StopperMotionOf<'a> = dyn Fn(&[f64], &[f64]) -> Vec<f64> + 'a;

/// `motion` of the recording's stopper positions at its rows.
fn at_rows(recording: &Recording, motion: &StopperMotionOf<'_>) -> Vec<f64> {
    match &recording.full_rate {
        Some(full) => {
            let all = motion(&full.time, &full.x_s);
            full.rows.iter().map(|&k| all[k]).collect()
        }
        None => motion(&recording.time, &recording.x_s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_half_width_chosen_is_the_one_whose_acceleration_the_residual_follows() {
        // A stopper stepping between positions on 40 ms ramps, logged to a micrometre at
        // 2 kHz; a residual of 0.3 kg times the acceleration over 10 ms, and then over 40 ms,
        // with noise: each is found.
        let time: Vec<f64> = (0..20_000).map(|k| k as f64 * 5e-4).collect();
        let x_s: Vec<f64> = time
            .iter()
            .map(|&t| {
                let phase = (t % 1.0).min(0.04) / 0.04;
                let level = 0.05 + 0.01 * ((t.floor() as i64 % 3) as f64);
                ((level + 0.004 * phase) * 1e6).round() / 1e6
            })
            .collect();
        let recording = Recording::of(time.clone(), vec![2.0; time.len()], x_s.clone(), vec![0.0; time.len()]);
        for window in [0.01, 0.04] {
            let a = smoothed_accelerations(&time, &x_s, window);
            let residual: Vec<f64> = a
                .iter()
                .enumerate()
                .map(|(k, a)| -0.3 * a + 0.05 * ((k as f64 * 1.7).sin() * 43758.5).fract())
                .collect();
            assert_eq!(choose_window(&recording, &residual), window);
        }
    }
}
