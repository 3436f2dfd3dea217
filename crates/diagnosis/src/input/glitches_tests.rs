use super::*;
use crate::input::noise::tests::normals;

/// A recording at 1 kHz whose force is `force(t)` plus 0.05 N of noise, with pressures.
fn recording(seconds: f64, force: impl Fn(f64) -> f64, seed: u64) -> Recording {
    let n = (seconds * 1000.0) as usize;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-3).collect();
    let noise = normals(seed, 3 * n);
    Recording {
        force: time.iter().zip(&noise).map(|(&t, e)| force(t) + 0.05 * e).collect(),
        p1: Some(
            time.iter()
                .zip(&noise[n..])
                .map(|(&t, e)| 4e5 + 1e5 * (3.0 * t).sin() + 300.0 * e)
                .collect(),
        ),
        p2: Some(
            time.iter()
                .zip(&noise[2 * n..])
                .map(|(&t, e)| 3e5 - 1e5 * (3.0 * t).sin() + 300.0 * e)
                .collect(),
        ),
        v_da: time
            .iter()
            .map(|&t| if (t * 2.0) as i64 % 2 == 0 { 10.0 } else { -10.0 })
            .collect(),
        x_s: vec![0.054; n],
        time,
        full_rate: None,
        fast_replay: Default::default(),
        acceleration_window: 0.0,
        repeated_rows: vec![],
    }
}

/// Steps of ±30 N with a 5 ms rise, a 100 Hz chirp-like wobble of 8 N, and kinks.
fn busy_force(t: f64) -> f64 {
    let phase = (t * 2.0).fract();
    let step = 30.0 * (1.0 - (-phase / 0.005).exp()) * if (t * 2.0) as i64 % 2 == 0 { 1.0 } else { -1.0 };
    let wobble = 8.0 * (2.0 * std::f64::consts::PI * (5.0 + 10.0 * t) * t).sin();
    let kink = 20.0 * ((t * 7.0).fract() - 0.5).abs();
    step + wobble + kink
}

#[test]
fn a_clean_recording_with_steps_kinks_and_a_fast_wobble_has_no_glitches() {
    for seed in 1..=5 {
        let mut r = recording(10.0, busy_force, seed);
        let before = r.clone();
        assert_eq!(find_and_repair(&mut r), vec![], "seed {seed}");
        assert_eq!(r, before);
    }
}

#[test]
fn isolated_spikes_are_found_where_they_are_and_repaired_towards_the_signal() {
    let mut r = recording(10.0, busy_force, 7);
    let clean = r.clone();
    let at = [1234usize, 2345, 3777];
    for (i, &k) in at.iter().enumerate() {
        r.force[k] += if i % 2 == 0 { 3.0 } else { -5.0 };
    }
    r.p1.as_mut().unwrap()[5200] += 20_000.0;
    let found = find_and_repair(&mut r);
    let spikes: Vec<(&str, f64)> = found.iter().map(|g| (g.column, g.from_s)).collect();
    assert_eq!(
        spikes,
        vec![
            ("force_N", 1.234),
            ("force_N", 2.345),
            ("force_N", 3.777),
            ("p1_Pa", 5.2)
        ]
    );
    assert!(found.iter().all(|g| g.kind == GlitchKind::Spike && g.samples == 1));
    for &k in &at {
        assert!(
            (r.force[k] - clean.force[k]).abs() < 0.5,
            "{} against {}",
            r.force[k],
            clean.force[k]
        );
    }
}

#[test]
fn a_stuck_pressure_and_a_clipped_force_are_told_apart_and_interpolated() {
    let mut r = recording(10.0, |t| 40.0 * (t * 1.3).sin(), 3);
    let p1 = r.p1.as_mut().unwrap();
    let held = p1[3000];
    for v in &mut p1[3001..3040] {
        *v = held;
    }
    let top = r.force.iter().cloned().fold(f64::NEG_INFINITY, f64::max) + 0.2;
    for k in 1100..1300 {
        r.force[k] = r.force[k].min(top);
    }
    let peak = (1100..1300).max_by(|&a, &b| r.force[a].total_cmp(&r.force[b])).unwrap();
    for k in peak - 20..peak + 20 {
        r.force[k] = top - 0.2 + 0.0;
    }
    let found = find_and_repair(&mut r);
    let kinds: Vec<(GlitchKind, &str, usize)> = found.iter().map(|g| (g.kind, g.column, g.samples)).collect();
    assert!(kinds.contains(&(GlitchKind::Stuck, "p1_Pa", 39)), "{kinds:?}");
    assert!(kinds.contains(&(GlitchKind::Clipped, "force_N", 40)), "{kinds:?}");
    assert_eq!(found.len(), 2, "{kinds:?}");
    let p1 = r.p1.as_ref().unwrap();
    assert!(p1[3001..3040].windows(2).all(|w| w[0] != w[1]));
}

#[test]
fn one_repeated_sample_of_an_unrounded_channel_is_found_but_a_rounded_channel_repeats_by_itself() {
    let mut r = recording(10.0, |t| 40.0 * (t * 1.3).sin(), 4);
    r.force[2500] = r.force[2499];
    let found = find_and_repair(&mut r);
    assert_eq!(found.len(), 1);
    assert_eq!(
        (found[0].kind, found[0].column, found[0].samples),
        (GlitchKind::Repeated, "force_N", 1)
    );

    // Rounded to 0.02 N with 0.05 N of noise, about one sample in ten repeats the one before.
    let mut rounded = recording(10.0, |t| 40.0 * (t * 1.3).sin(), 4);
    for v in &mut rounded.force {
        *v = (*v / 0.02).round() * 0.02;
    }
    rounded.force[2500] = rounded.force[2499];
    assert_eq!(find_and_repair(&mut rounded), vec![]);
}

#[test]
fn a_dropped_sample_is_a_gap_of_one_missing_sample() {
    let mut r = recording(10.0, |t| 40.0 * (t * 1.3).sin(), 5);
    for column in [&mut r.time, &mut r.force, &mut r.v_da, &mut r.x_s] {
        column.remove(6000);
    }
    for p in [r.p1.as_mut().unwrap(), r.p2.as_mut().unwrap()] {
        p.remove(6000);
    }
    let found = find_and_repair(&mut r);
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!((found[0].kind, found[0].samples), (GlitchKind::Gap, 1));
    assert!((found[0].from_s - 5.999).abs() < 1e-9 && (found[0].to_s - 6.001).abs() < 1e-9);
    assert!(!found[0].sets_aside());
}

#[test]
fn a_noiseless_simulated_recording_has_no_glitches_but_a_spike_in_it_is_found() {
    let mut r = recording(10.0, busy_force, 1);
    r.force = r.time.iter().map(|&t| busy_force(t)).collect();
    let mut spiked = r.clone();
    assert!(find_and_repair(&mut r).iter().all(|g| g.column != "force_N"));
    spiked.force[3100] += 5.0;
    let found = find_and_repair(&mut spiked);
    assert!(
        found
            .iter()
            .any(|g| g.column == "force_N" && g.kind == GlitchKind::Spike && g.from_s == 3.1),
        "{found:?}"
    );
}

#[test]
fn the_sentence_counts_each_kind_and_names_the_columns() {
    let glitches = vec![
        Glitch {
            kind: GlitchKind::Spike,
            column: "force_N",
            from_s: 1.0,
            to_s: 1.0,
            samples: 1,
        },
        Glitch {
            kind: GlitchKind::Spike,
            column: "p1_Pa",
            from_s: 2.0,
            to_s: 2.0,
            samples: 1,
        },
        Glitch {
            kind: GlitchKind::Gap,
            column: "time_s",
            from_s: 3.0,
            to_s: 3.003,
            samples: 2,
        },
    ];
    let s = sentence(&glitches).unwrap();
    assert!(s.contains("2 spikes in force_N, p1_Pa, the first at 1.000 s"), "{s}");
    assert!(s.contains("1 gap in time (2 samples missing)"), "{s}");
    assert_eq!(sentence(&[]), None);
}

#[test]
fn a_force_impulse_where_the_stopper_changes_speed_is_the_actuators_answer_not_a_spike() {
    let mut r = recording(10.0, |t| 40.0 * (t * 1.3).sin(), 8);
    // The stopper moves at 20 mm/s from 4 s, logged to 1 µm; a force on its acceleration
    // answers the start with one sample of 2 N.
    for (k, x) in r.x_s.iter_mut().enumerate() {
        let t = k as f64 * 1e-3;
        *x = ((0.054 + 0.02 * (t - 4.0).max(0.0)) * 1e6).round() / 1e6;
    }
    r.force[4000] += 2.0;
    r.force[2200] += 2.0;
    let found = find_and_repair(&mut r);
    let at: Vec<f64> = found.iter().map(|g| g.from_s).collect();
    assert_eq!(at, vec![2.2], "{found:?}");
}

#[test]
fn a_force_dip_at_each_one_micrometre_kink_of_a_slow_stopper_is_not_a_spike() {
    // 3.3 mm/s logged to 1 µm at 1 kHz: the increments go 3, 3, 4 µm, a kink of one step of
    // the rounding every few samples, and a plant driven by the logged positions answers
    // each with 0.75 N; a spike where the stopper rests is still found.
    let mut r = recording(10.0, |t| 40.0 * (t * 1.3).sin(), 9);
    for (k, x) in r.x_s.iter_mut().enumerate() {
        let t = k as f64 * 1e-3;
        *x = ((0.054 + 0.0033 * (t - 1.0).clamp(0.0, 6.0)) * 1e6).round() / 1e6;
    }
    for k in 1001..7000 {
        if r.x_s[k + 1] - 2.0 * r.x_s[k] + r.x_s[k - 1] != 0.0 {
            r.force[k] -= 0.75;
        }
    }
    r.force[8200] += 2.0;
    let found = find_and_repair(&mut r);
    let at: Vec<f64> = found.iter().map(|g| g.from_s).collect();
    assert_eq!(at, vec![8.2], "{found:?}");
}
