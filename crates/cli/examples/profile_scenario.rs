//! One benchmark scenario (10 s at rtol 1e-6), run N times and nothing else, for profilers
//! and for instruction counts that do not drift with the machine's load:
//!
//!     cargo build --release --example profile_scenario
//!     valgrind --tool=callgrind target/release/examples/profile_scenario chirp 1
//!
//! Scenarios: standard, ramps, chirp, closed_loop (its feedforward table is built first,
//! about 255 M instructions that are not part of the run).

#[path = "../benches/common/scenarios.rs"]
mod scenarios;

use scenarios::{Prepared, Scenario, RELATIVE_TOLERANCE};

fn main() -> Result<(), String> {
    let usage = "usage: profile_scenario standard|ramps|chirp|closed_loop [RUNS]";
    let mut args = std::env::args().skip(1);
    let name = args.next().ok_or(usage)?;
    let scenario = Scenario::ALL
        .into_iter()
        .find(|s| s.name() == name)
        .ok_or_else(|| format!("scenario {name}: unknown; {usage}"))?;
    let runs: usize = match args.next() {
        Some(value) => value
            .parse()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("RUNS {value}: expected a positive integer; {usage}"))?,
        None => 1,
    };
    let prepared = Prepared::new(scenario, &scenarios::thesis_model(), RELATIVE_TOLERANCE)?;
    for _ in 0..runs {
        std::hint::black_box(prepared.run()?);
    }
    Ok(())
}
