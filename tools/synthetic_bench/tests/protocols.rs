//! The protocol generator: its signals checked against what each protocol promises (levels,
//! spectra, bit sequences, speeds), its recordings against the sampling, noise and channels
//! asked for, and its refusals.

use synthetic_bench::protocols::{DURATION_RANGE, STOPPER_RANGE};
use synthetic_bench::{
    command_signal, generate_protocol, stopper_signal, BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion,
};

fn samples(f: &dyn Fn(f64) -> f64, rate: f64, duration: f64) -> Vec<f64> {
    (0..(rate * duration) as usize).map(|k| f(k as f64 / rate)).collect()
}

/// |DFT| at frequency `f` of `x` sampled at `rate`, scaled to a sine's amplitude.
fn amplitude_at(x: &[f64], rate: f64, f: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let phase = 2.0 * std::f64::consts::PI * f * k as f64 / rate;
        re += v * phase.cos();
        im += v * phase.sin();
    }
    2.0 * (re * re + im * im).sqrt() / x.len() as f64
}

#[test]
fn each_open_loop_command_is_a_function_of_its_seed_alone() {
    for kind in CommandProtocol::ALL
        .iter()
        .copied()
        .filter(|k| *k != CommandProtocol::ForceTracking)
    {
        let a = samples(&*command_signal(kind, 7, 30.0).unwrap(), 100.0, 30.0);
        let b = samples(&*command_signal(kind, 7, 30.0).unwrap(), 100.0, 30.0);
        let c = samples(&*command_signal(kind, 8, 30.0).unwrap(), 100.0, 30.0);
        assert_eq!(a, b, "{}", kind.name());
        assert_ne!(a, c, "{}: another seed gives the same command", kind.name());
        assert!(
            a.iter().all(|v| v.abs() <= 10.0),
            "{} leaves the D/A range",
            kind.name()
        );
    }
}

#[test]
fn the_staircase_holds_levels_within_its_range_for_its_hold_times() {
    let x = samples(
        &*command_signal(CommandProtocol::Staircase, 3, 120.0).unwrap(),
        1000.0,
        120.0,
    );
    assert!(x.iter().all(|v| (-3.0..=9.0).contains(v)));
    let changes: Vec<usize> = (1..x.len()).filter(|&k| x[k] != x[k - 1]).collect();
    // holds of 0.3–3 s: 40–400 changes in 120 s
    assert!((40..=400).contains(&changes.len()), "{} changes", changes.len());
    for w in changes.windows(2) {
        let hold = (w[1] - w[0]) as f64 / 1000.0;
        assert!((0.299..=3.001).contains(&hold), "a level held {hold} s");
    }
}

#[test]
fn the_multisine_has_its_twelve_lines_and_nothing_between_them() {
    let rate = 200.0;
    let duration = 100.0; // every line's frequency is off the 0.01 Hz grid by less than a bin
    let x = samples(
        &*command_signal(CommandProtocol::Multisine, 2, duration).unwrap(),
        rate,
        duration,
    );
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    assert!((mean - 2.5).abs() < 0.05, "mean {mean}");
    let centred: Vec<f64> = x.iter().map(|v| v - mean).collect();
    for k in 0..12 {
        let f = 0.1 * 200f64.powf(k as f64 / 11.0);
        // a line between grid frequencies leaks; its peak over the nearest bins is still near 0.6 V
        let peak = (-2..=2)
            .map(|d| amplitude_at(&centred, rate, ((f * duration).round() + d as f64) / duration))
            .fold(0.0, f64::max);
        assert!(peak > 0.35 && peak < 0.65, "line at {f:.3} Hz: {peak:.3} V");
    }
    for f in [25.0, 40.0, 60.0] {
        assert!(amplitude_at(&centred, rate, f) < 0.05, "power at {f} Hz");
    }
}

#[test]
fn the_prbs_switches_between_two_levels_on_its_bit_clock_with_balanced_bits() {
    let x = samples(&*command_signal(CommandProtocol::Prbs, 5, 41.0).unwrap(), 1000.0, 40.92);
    assert!(x.iter().all(|v| *v == 0.5 || *v == 4.5));
    for k in 1..x.len() {
        if x[k] != x[k - 1] {
            assert_eq!(k % 40, 0, "a switch at sample {k}, off the 40 ms bit clock");
        }
    }
    // one period of a maximal 10-bit sequence: 512 ones and 511 zeros
    let ones = (0..1023).filter(|b| x[b * 40] == 4.5).count();
    assert_eq!(ones, 512);
}

#[test]
fn the_slow_sine_stays_between_its_extremes_at_a_frequency_below_one_hertz() {
    let x = samples(&*command_signal(CommandProtocol::Sine, 9, 60.0).unwrap(), 500.0, 60.0);
    let (lo, hi) = x.iter().fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(*v), b.max(*v)));
    assert!((lo + 1.5).abs() < 0.01 && (hi - 6.5).abs() < 0.01, "{lo} … {hi}");
    let crossings = (1..x.len()).filter(|&k| (x[k] - 2.5) * (x[k - 1] - 2.5) < 0.0).count();
    assert!(
        (11..=121).contains(&crossings),
        "{crossings} crossings of the mean in 60 s"
    );
}

#[test]
fn the_ramps_are_continuous_and_move_at_bounded_rates() {
    let x = samples(&*command_signal(CommandProtocol::Ramps, 4, 60.0).unwrap(), 1000.0, 60.0);
    let max_rate = (1..x.len())
        .map(|k| (x[k] - x[k - 1]).abs() * 1000.0)
        .fold(0.0, f64::max);
    // 12 V in at least 0.5 s
    assert!(max_rate <= 24.0 + 1e-9, "{max_rate} V/s");
    assert!(x.iter().all(|v| (-3.0..=9.0).contains(v)));
}

#[test]
fn the_force_tracking_protocol_is_refused_as_a_function_of_time() {
    let err = command_signal(CommandProtocol::ForceTracking, 1, 30.0).err().unwrap();
    assert!(err.contains("force_tracking"), "{err}");
}

#[test]
fn stopper_moves_reach_their_peak_speed_and_stay_inside_the_cylinder() {
    for speed in [0.005, 0.02, 0.1] {
        let s = stopper_signal(StopperMotion::Moves { speed }, 11, 60.0);
        let rate = 2000.0;
        let (mut peak, mut x_prev) = (0.0f64, s(0.0).0);
        for k in 1..(60.0 * rate) as usize {
            let (x, v) = s(k as f64 / rate);
            assert!((0.035 - 1e-12..=0.080 + 1e-12).contains(&x), "x = {x} at sample {k}");
            // the velocity is the derivative of the position
            let slope = (x - x_prev) * rate;
            assert!((slope - v).abs() <= 0.01 * speed, "slope {slope} against v {v}");
            peak = peak.max(v.abs());
            x_prev = x;
        }
        assert!(
            peak <= speed * 1.0001 && peak >= 0.95 * speed,
            "peak {peak} for {speed}"
        );
    }
}

#[test]
fn a_single_stopper_move_rests_at_home_before_and_at_its_end_after_at_its_peak_speed_between() {
    let (at, to, speed) = (2.6, 0.08, 0.5);
    let s = stopper_signal(StopperMotion::Move { at, to, speed }, 11, 20.0);
    // 26 mm with a half-cosine profile at a peak of 0.5 m/s: π/2 · 26 mm / 0.5 m/s = 81.7 ms.
    let length = 0.5 * std::f64::consts::PI * (to - 0.054) / speed;
    assert_eq!(s(at - 1e-6), (0.054, 0.0));
    assert_eq!(s(at + length + 1e-6), (to, 0.0));
    assert_eq!(s(19.9), (to, 0.0));
    let (middle, peak) = s(at + 0.5 * length);
    assert!(
        (middle - 0.067).abs() < 1e-9 && (peak - speed).abs() < 1e-9,
        "{middle} m, {peak} m/s"
    );
}

#[test]
fn the_protocol_checks_name_the_field_its_value_and_the_limit() {
    let refused = |spec: ProtocolSpec, words: &[&str]| {
        let err = spec.check().expect_err("refused");
        for w in words {
            assert!(err.contains(w), "{err:?} lacks {w:?}");
        }
    };
    refused(
        ProtocolSpec {
            sample_rate: 3000.0,
            ..Default::default()
        },
        &["sample_rate", "3000", "2000"],
    );
    refused(
        ProtocolSpec {
            sample_rate: 300.0,
            ..Default::default()
        },
        &["sample_rate", "300", "integration steps"],
    );
    refused(
        ProtocolSpec {
            duration: 10.0,
            ..Default::default()
        },
        &["duration", "10", &DURATION_RANGE.0.to_string()],
    );
    refused(
        ProtocolSpec {
            force_noise: -0.1,
            ..Default::default()
        },
        &["force_noise", "-0.1"],
    );
    refused(
        ProtocolSpec {
            stopper: StopperMotion::Sine {
                centre: 0.085,
                amplitude: 0.01,
                frequency: 2.5,
            },
            ..Default::default()
        },
        &["stopper centre + amplitude", "0.095", &STOPPER_RANGE.1.to_string()],
    );
    for rate in [250.0, 500.0, 1000.0, 1250.0, 2000.0] {
        assert!(
            ProtocolSpec {
                sample_rate: rate,
                ..Default::default()
            }
            .check()
            .is_ok(),
            "{rate} Hz"
        );
    }
}

#[test]
fn a_recording_has_the_asked_sampling_channels_and_noise() {
    // The same seed with and without noise: the same command and stopper, so the difference
    // is the noise (plus the force channel's 0.015 N quantisation, 0.0044 N RMS).
    let spec = ProtocolSpec {
        command: CommandProtocol::Prbs,
        stopper: StopperMotion::Sine {
            centre: 0.054,
            amplitude: 0.005,
            frequency: 2.5,
        },
        sample_rate: 250.0,
        duration: 20.0,
        force_noise: 0.08,
        pressure_noise: 300.0,
        pressures: false,
        seed: 21,
    };
    let noisy = generate_protocol(&spec, &BenchEffects::default()).unwrap();
    let clean = generate_protocol(
        &ProtocolSpec {
            force_noise: 0.0,
            pressure_noise: 0.0,
            ..spec.clone()
        },
        &BenchEffects::default(),
    )
    .unwrap();
    assert_eq!(noisy.rows.len(), 5000);
    assert!((noisy.rows[1][0] - 0.004).abs() < 1e-12 && (noisy.rows[4999][0] - 19.996).abs() < 1e-9);
    let rms = |c: usize| {
        (noisy
            .rows
            .iter()
            .zip(&clean.rows)
            .map(|(a, b)| (a[c] - b[c]).powi(2))
            .sum::<f64>()
            / 5000.0)
            .sqrt()
    };
    assert!((rms(3) - 0.08).abs() < 0.006, "force noise {}", rms(3));
    assert!((rms(4) - 300.0).abs() < 25.0, "p1 noise {}", rms(4));
    assert!(noisy
        .rows
        .iter()
        .zip(&clean.rows)
        .all(|(a, b)| a[1] == b[1] && a[2] == b[2]));
    let path = std::env::temp_dir().join(format!("protocol_nop_{}.csv", std::process::id()));
    noisy.write_csv(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let _ = std::fs::remove_file(&path);
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("time_s,v_da_V,x_s_m,force_N"));
    assert_eq!(lines.next().unwrap().split(',').count(), 4);
}

#[test]
fn the_force_tracking_controller_brings_the_logged_force_to_each_reference() {
    let spec = ProtocolSpec {
        command: CommandProtocol::ForceTracking,
        sample_rate: 500.0,
        duration: 20.0,
        seed: 4,
        ..Default::default()
    };
    let rec = generate_protocol(&spec, &BenchEffects::default()).unwrap();
    let reference = rec.reference.as_ref().unwrap();
    // At the end of each level held 1 s or longer, the force is within 1.5 N of the reference.
    let mut checked = 0;
    let mut start = 0;
    for k in 1..=reference.len() {
        if k == reference.len() || reference[k] != reference[k - 1] {
            if k - start >= 500 {
                let end: Vec<f64> = rec.rows[k - 50..k].iter().map(|r| r[3]).collect();
                let mean = end.iter().sum::<f64>() / 50.0;
                assert!(
                    (mean - reference[k - 1]).abs() < 1.5,
                    "{mean:.2} N against the reference {:.2} N at t = {:.2} s",
                    reference[k - 1],
                    rec.rows[k - 1][0]
                );
                checked += 1;
            }
            start = k;
        }
    }
    assert!(checked >= 4, "{checked} levels checked");
    // the command is the controller's, D/A-quantised: it moves, within ±10 V
    let commands: Vec<f64> = rec.rows.iter().map(|r| r[1]).collect();
    assert!(commands.iter().all(|v| v.abs() <= 10.0));
    assert!(commands.windows(2).filter(|w| w[0] != w[1]).count() > 1000);
}

fn with_undeclared(undeclared: synthetic_bench::UndeclaredEffects) -> BenchEffects {
    BenchEffects {
        undeclared,
        ..BenchEffects::default()
    }
}

#[test]
fn a_stopper_position_offset_moves_the_logged_position_alone() {
    let spec = ProtocolSpec {
        duration: 20.0,
        sample_rate: 500.0,
        ..ProtocolSpec::default()
    };
    let clean = generate_protocol(&spec, &BenchEffects::default()).unwrap();
    let offset = generate_protocol(
        &spec,
        &with_undeclared(synthetic_bench::UndeclaredEffects {
            stopper_position_offset: 1e-3,
            ..Default::default()
        }),
    )
    .unwrap();
    for (a, b) in clean.rows.iter().zip(&offset.rows) {
        // The logged position is rounded to 1 µm.
        assert!((b[2] - a[2] - 1e-3).abs() < 1.5e-6, "{} against {}", b[2], a[2]);
        assert_eq!((a[0], a[1], a[3], a[4], a[5]), (b[0], b[1], b[3], b[4], b[5]));
    }
}

#[test]
fn a_warming_gas_moves_the_pressures_late_in_the_recording_more_than_at_its_start() {
    let spec = ProtocolSpec {
        duration: 20.0,
        sample_rate: 500.0,
        ..ProtocolSpec::default()
    };
    let clean = generate_protocol(&spec, &BenchEffects::default()).unwrap();
    let warming = generate_protocol(
        &spec,
        &with_undeclared(synthetic_bench::UndeclaredEffects {
            gas_temperature_drift: 20.0,
            ..Default::default()
        }),
    )
    .unwrap();
    let rms_gap = |from: usize, to: usize| {
        let rows = clean.rows[from..to].iter().zip(&warming.rows[from..to]);
        (rows.map(|(a, b)| (a[4] - b[4]).powi(2)).sum::<f64>() / (to - from) as f64).sqrt()
    };
    let n = clean.rows.len();
    let (early, late) = (rms_gap(0, n / 10), rms_gap(n - n / 10, n));
    assert!(
        late > 3.0 * early && late > 100.0,
        "p1 apart by {early} Pa early, {late} Pa late"
    );
}

#[test]
fn a_slower_stopper_mount_changes_the_logged_force_of_a_moving_stopper() {
    let spec = ProtocolSpec {
        duration: 20.0,
        sample_rate: 500.0,
        stopper: StopperMotion::Moves { speed: 0.02 },
        ..ProtocolSpec::default()
    };
    let mount = |lag: f64| {
        generate_protocol(
            &spec,
            &with_undeclared(synthetic_bench::UndeclaredEffects {
                contact_stiffness: 2e4,
                contact_lag: lag,
                ..Default::default()
            }),
        )
        .unwrap()
    };
    let (standard, slow) = (mount(0.0), mount(2e-3));
    let gap: Vec<f64> = standard
        .rows
        .iter()
        .zip(&slow.rows)
        .map(|(a, b)| (a[3] - b[3]).abs())
        .collect();
    assert!(gap.iter().cloned().fold(0.0, f64::max) > 0.1, "the lag changes nothing");
}

/// Mean P1 and P2 (columns 4 and 5) over the recording's second half.
fn late_mean_pressures(rec: &synthetic_bench::ProtocolRecording) -> (f64, f64) {
    let late = &rec.rows[rec.rows.len() / 2..];
    let n = late.len() as f64;
    (
        late.iter().map(|r| r[4]).sum::<f64>() / n,
        late.iter().map(|r| r[5]).sum::<f64>() / n,
    )
}

#[test]
fn a_leak_from_the_supply_raises_chamber_2_and_a_laminar_leak_to_atmosphere_lowers_chamber_1() {
    let spec = ProtocolSpec {
        duration: 20.0,
        sample_rate: 500.0,
        ..ProtocolSpec::default()
    };
    let clean = late_mean_pressures(&generate_protocol(&spec, &BenchEffects::default()).unwrap());
    let supplied = late_mean_pressures(
        &generate_protocol(
            &spec,
            &with_undeclared(synthetic_bench::UndeclaredEffects {
                supply_leak_2: 1e-8,
                ..Default::default()
            }),
        )
        .unwrap(),
    );
    let vented = late_mean_pressures(
        &generate_protocol(
            &spec,
            &with_undeclared(synthetic_bench::UndeclaredEffects {
                laminar_leak_1: 3e-11,
                ..Default::default()
            }),
        )
        .unwrap(),
    );
    assert!(supplied.1 > clean.1 + 1e3, "P2 {} against {}", supplied.1, clean.1);
    assert!(vented.0 < clean.0 - 1e3, "P1 {} against {}", vented.0, clean.0);
}

#[test]
fn a_laminar_leak_from_the_supply_raises_chamber_2_and_one_between_the_chambers_narrows_their_difference() {
    let spec = ProtocolSpec {
        duration: 20.0,
        sample_rate: 500.0,
        ..ProtocolSpec::default()
    };
    let with = |undeclared: synthetic_bench::UndeclaredEffects| {
        late_mean_pressures(&generate_protocol(&spec, &with_undeclared(undeclared)).unwrap())
    };
    let clean = late_mean_pressures(&generate_protocol(&spec, &BenchEffects::default()).unwrap());
    let supplied = with(synthetic_bench::UndeclaredEffects {
        laminar_supply_leak_2: 2e-11,
        ..Default::default()
    });
    let crossed = with(synthetic_bench::UndeclaredEffects {
        laminar_cross_leak: 2e-11,
        ..Default::default()
    });
    assert!(supplied.1 > clean.1 + 1e3, "P2 {} against {}", supplied.1, clean.1);
    let (gap, clean_gap) = ((crossed.0 - crossed.1).abs(), (clean.0 - clean.1).abs());
    assert!(gap < clean_gap - 1e3, "|P1 - P2| {gap} against {clean_gap}");
}

#[test]
fn a_flow_into_chamber_2_alone_raises_both_chambers_where_a_leak_between_them_of_the_same_size_lowers_chamber_1() {
    let spec = ProtocolSpec {
        duration: 20.0,
        sample_rate: 500.0,
        ..ProtocolSpec::default()
    };
    let with = |undeclared: synthetic_bench::UndeclaredEffects| {
        late_mean_pressures(&generate_protocol(&spec, &with_undeclared(undeclared)).unwrap())
    };
    let clean = late_mean_pressures(&generate_protocol(&spec, &BenchEffects::default()).unwrap());
    let alone = with(synthetic_bench::UndeclaredEffects {
        difference_inflow_2: 2e-11,
        ..Default::default()
    });
    let crossed = with(synthetic_bench::UndeclaredEffects {
        laminar_cross_leak: 2e-11,
        ..Default::default()
    });
    // P1's mean stays above P2's over the protocol's second half: both move mass into chamber 2.
    assert!(clean.0 > clean.1 + 5e4, "P1 {} P2 {}", clean.0, clean.1);
    let moved = |p: (f64, f64)| (p.0 - clean.0, p.1 - clean.1);
    let (alone_1, alone_2) = moved(alone);
    let (crossed_1, crossed_2) = moved(crossed);
    assert!(
        alone_2 > 1e3 && crossed_2 > 1e3,
        "P2 moved {alone_2} Pa alone, {crossed_2} Pa between"
    );
    // The flow between the chambers comes out of chamber 1; the flow into chamber 2 alone is
    // mass gained, which reaches chamber 1 past the piston.
    assert!(
        crossed_1 < -500.0,
        "P1 moved {crossed_1} Pa with the leak between the chambers"
    );
    assert!(
        alone_1 > 500.0,
        "P1 moved {alone_1} Pa with the flow into chamber 2 alone"
    );
}

#[test]
fn a_discharge_coefficient_rising_as_the_flow_chokes_changes_the_pressures_and_zero_changes_nothing() {
    let spec = ProtocolSpec {
        duration: 20.0,
        sample_rate: 500.0,
        ..ProtocolSpec::default()
    };
    let rise = |s: f64| {
        generate_protocol(
            &spec,
            &with_undeclared(synthetic_bench::UndeclaredEffects {
                discharge_ratio_rise: s,
                ..Default::default()
            }),
        )
        .unwrap()
    };
    let clean = generate_protocol(&spec, &BenchEffects::default()).unwrap();
    assert_eq!(rise(0.0).rows, clean.rows);
    let risen = rise(0.3);
    let gap = clean
        .rows
        .iter()
        .zip(&risen.rows)
        .map(|(a, b)| (a[4] - b[4]).abs().max((a[5] - b[5]).abs()))
        .fold(0.0, f64::max);
    assert!(gap > 5e3, "the pressures move by {gap} Pa at most");
}
