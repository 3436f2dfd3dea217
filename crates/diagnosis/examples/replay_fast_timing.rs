//! Wall time of `replay_fast` on a recording, for the model at its defaults and with the
//! terms that take their own paths through it (delay line, varying constants, command
//! stage, filtering sensor, hysteresis), with a digest of every output bit so a change in
//! how it is computed can be checked to leave the numbers alone.
//!
//! `cargo run --release -p jetpipe-diagnosis --example replay_fast_timing -- FILE [RUNS]`

use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_diagnosis::replay::{replay_fast, Replay};
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;
use std::time::Instant;

fn digest(r: &Replay) -> u64 {
    // FNV-1a over the bits: any change in any output shows.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for series in [&r.force, &r.p1, &r.p2, &r.current, &r.x_jp] {
        for v in series.iter() {
            h ^= v.to_bits();
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h ^ r.steps
}

/// CPU time of this thread (ns) from Linux's scheduler statistics, or 0 elsewhere: on a
/// machine shared with others the wall time mostly measures their load.
fn cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|v| v.parse().ok()))
        .unwrap_or(0)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = args.get(1).expect("usage: replay_fast_timing FILE [RUNS]");
    let runs: usize = args.get(2).map_or(5, |s| s.parse().expect("RUNS"));
    let recording = Recording::read(std::path::Path::new(path), &Parameters::default()).unwrap();
    let cases: Vec<(&str, Parameters)> = vec![
        ("defaults", Parameters::default()),
        (
            "command delay",
            Parameters {
                command_delay: 2.5e-3,
                ..Parameters::default()
            },
        ),
        (
            "supply ripple",
            Parameters {
                supply_ripple_sine: 15e3,
                supply_ripple_frequency: 7.0,
                ..Parameters::default()
            },
        ),
        (
            "command lag",
            Parameters {
                command_lag: 0.02,
                ..Parameters::default()
            },
        ),
        (
            "sensor lag",
            Parameters {
                force_sensor_lag: 0.01,
                ..Parameters::default()
            },
        ),
        (
            "hysteresis",
            Parameters {
                hysteresis_width: 0.12e-3,
                ..Parameters::default()
            },
        ),
    ];
    let (mut total, mut total_cpu) = (0.0, 0.0);
    for (name, p) in cases {
        let model = Actuator::new(p).unwrap();
        let (mut best, mut best_cpu) = (f64::INFINITY, f64::INFINITY);
        let mut d = 0;
        for _ in 0..runs {
            let (start, start_cpu) = (Instant::now(), cpu_ns());
            let r = replay_fast(&model, &recording, recording.len()).unwrap();
            best = best.min(start.elapsed().as_secs_f64());
            best_cpu = best_cpu.min((cpu_ns() - start_cpu) as f64 * 1e-9);
            d = digest(&r);
        }
        total += best;
        total_cpu += best_cpu;
        println!(
            "{name:>14}: best {:6.1} ms wall, {:6.1} ms CPU  digest {d:016x}",
            best * 1e3,
            best_cpu * 1e3
        );
    }
    println!(
        "{:>14}: {:6.1} ms wall, {:6.1} ms CPU",
        "sum of bests",
        total * 1e3,
        total_cpu * 1e3
    );
}
