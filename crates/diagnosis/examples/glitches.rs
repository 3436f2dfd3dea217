//! Prints the glitches found in each recording given, and each channel whose noise level
//! varies (on the recorded channel: the diagnosis also asks it of the departure from the model): `cargo run --release -p
//! jetpipe-diagnosis --example glitches -- a.csv b.csv ...` (scripts/bench_glitches.sh runs it
//! on every recording at hand). A clean recording should have none.

use jetpipe_diagnosis::input::glitches::find_and_repair;
use jetpipe_diagnosis::input::noise::{noise_floor, quantisation_step, varying};
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_model::physics::parameters::Parameters;

fn main() {
    let params = Parameters::default();
    let (mut files, mut with, mut total, mut varied) = (0, 0, 0, 0);
    for path in std::env::args().skip(1) {
        let mut recording = match Recording::read(std::path::Path::new(&path), &params) {
            Ok(r) => r,
            Err(e) => {
                println!("{path}: refused: {e}");
                continue;
            }
        };
        let started = std::time::Instant::now();
        let glitches = find_and_repair(&mut recording);
        let seconds = started.elapsed().as_secs_f64();
        files += 1;
        total += glitches.len();
        if !glitches.is_empty() {
            with += 1;
        }
        println!(
            "{path}: {} samples, {} glitches, {:.1} ms",
            recording.len(),
            glitches.len(),
            seconds * 1e3
        );
        let mut channels = vec![("force_N", &recording.force)];
        if let (Some(p1), Some(p2)) = (&recording.p1, &recording.p2) {
            channels.push(("p1_Pa", p1));
            channels.push(("p2_Pa", p2));
        }
        for (name, x) in channels {
            if std::env::var_os("GLITCHES_VERBOSE").is_some() {
                println!(
                    "  {name}: noise floor {:.4e}, rounded to {:?}",
                    noise_floor(x),
                    quantisation_step(x)
                );
            }
            if let Some(v) = varying(x, x, &recording.v_da) {
                varied += 1;
                println!(
                    "  noise of {name} varies: {:.4e} to {:.4e}, RMS {:.4e} (floor {:.4e}), {}",
                    v.lowest,
                    v.highest,
                    v.rms,
                    noise_floor(x),
                    if v.follows_level { "with the level" } else { "in time" }
                );
            }
        }
        for g in glitches.iter().take(12) {
            println!(
                "  {} {} {:.4}..{:.4} s ({} samples)",
                g.kind.as_str(),
                g.column,
                g.from_s,
                g.to_s,
                g.samples
            );
        }
    }
    println!("TOTALS: {files} recordings, {with} with glitches, {total} glitches, {varied} channels of varying noise");
}
