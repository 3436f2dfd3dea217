//! Prints the glitches found in each recording given: `cargo run --release -p
//! jetpipe-diagnosis --example glitches -- a.csv b.csv ...` (scripts/bench_glitches.sh runs it
//! on every recording at hand). A clean recording should have none.

use jetpipe_diagnosis::input::glitches::find_and_repair;
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_model::physics::parameters::Parameters;

fn main() {
    let params = Parameters::default();
    let (mut files, mut with, mut total) = (0, 0, 0);
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
    println!("TOTALS: {files} recordings, {with} with glitches, {total} glitches");
}
