//! Criterion benchmarks of the Rust core (issue 6): one right-hand side of the model, and
//! 10 s of each benchmark scenario at relative tolerance 1e-6 (`benches/common/scenarios.rs`).
//!
//!     cargo bench --bench core                                   # full
//!     cargo bench --bench core -- --measurement-time 3 --warm-up-time 1   # quicker
//!
//! Criterion reports wall time only; `cargo run --release --example perf_report` prints
//! CPU time, integrator work and memory for the same scenarios.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use jetpipe_model::physics::actuator::{index, Actuator, Inputs, State};

#[path = "common/scenarios.rs"]
mod scenarios;

use scenarios::{Prepared, Scenario, RELATIVE_TOLERANCE};

/// States and inputs met along the standard scenario, so the right-hand side is timed across
/// its branches (choked and unchoked flows, either flow direction) rather than at one point.
fn sample_points(model: &Actuator, count: usize) -> Vec<(State, Inputs)> {
    let prepared = Prepared::new(Scenario::Standard, model, 1e-4).expect("standard scenario starts");
    let every = (Scenario::Standard.steps() / count).max(1);
    let mut sim = prepared.initial.clone();
    let mut points = Vec::with_capacity(count);
    let mut k = 0;
    prepared
        .run_on(&mut sim, |s| {
            if k % every == 0 && points.len() < count {
                let inputs = Inputs {
                    v_da: s.v_da(),
                    x_s: s.x_s(),
                    x_s_rate: 0.0,
                    plays: None,
                };
                points.push((*s.state(), inputs));
            }
            k += 1;
        })
        .expect("standard scenario runs");
    points
}

fn right_hand_sides(c: &mut Criterion) {
    let model = scenarios::thesis_model();
    let points = sample_points(&model, 64);
    let mut group = c.benchmark_group("rhs");
    // Per evaluation: criterion divides by the element count.
    group.throughput(Throughput::Elements(points.len() as u64));
    group.bench_function("six_state_derivatives", |b| {
        b.iter(|| {
            for (y, u) in &points {
                black_box(model.derivatives(black_box(y), black_box(u)));
            }
        })
    });
    // What the split integrator evaluates: the chamber pressures only, for a given jet pipe
    // position (its trajectory is known in closed form).
    group.bench_function("chamber_pressure_rates", |b| {
        b.iter(|| {
            for (y, u) in &points {
                black_box(model.pressure_rates(
                    black_box(y[index::JET_POSITION]),
                    black_box(y[index::P1]),
                    black_box(y[index::P2]),
                    black_box(u.x_s),
                    black_box(u.x_s_rate),
                ));
            }
        })
    });
    group.bench_function("six_state_jacobian", |b| {
        let rates: Vec<State> = points.iter().map(|(y, u)| model.derivatives(y, u)).collect();
        b.iter(|| {
            for ((y, u), f) in points.iter().zip(&rates) {
                black_box(model.jacobian(black_box(y), black_box(u), black_box(f)));
            }
        })
    });
    group.finish();
}

fn scenarios_10s(c: &mut Criterion) {
    let model = scenarios::thesis_model();
    let mut group = c.benchmark_group("simulate_10s_rtol_1e-6");
    for scenario in Scenario::ALL {
        let prepared = Prepared::new(scenario, &model, RELATIVE_TOLERANCE).expect("scenario starts");
        group.bench_function(scenario.name(), |b| {
            // The equilibrium start is set-up, not part of the 10 s: each run gets a copy.
            b.iter_batched(
                || prepared.initial.clone(),
                |mut sim| {
                    prepared.run_on(&mut sim, |_| {}).expect("scenario runs");
                    sim
                },
                BatchSize::SmallInput,
            )
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    // A 10 s run takes tenths of a second today: ten samples are enough to see a change and
    // keep `cargo bench` within minutes. Command-line options override these.
    config = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5));
    targets = right_hand_sides, scenarios_10s
}
criterion_main!(benches);
