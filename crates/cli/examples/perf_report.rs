//! Performance figures of the Rust core for issue 6, next to its targets:
//!
//!     cargo run --release --example perf_report [-- --runs 5] [--scenario ramps]
//!
//! For each benchmark scenario (`benches/common/scenarios.rs`, 10 s at relative tolerance
//! 1e-6): CPU time of the 10 s (best of `--runs`), simulated seconds per CPU second,
//! integrator steps, right-hand sides and Jacobians per simulated second, and the memory of
//! one instance (its `size_of`, the heap it keeps after initialisation, and the extra heap
//! at the peak of a 10 s run, counted by a wrapper around the system allocator). Then the cost
//! of one right-hand-side evaluation. Criterion (`cargo bench --bench core`) times the same
//! runs with statistics but reports wall time only.
//!
//! CPU time is the thread's own (CLOCK_THREAD_CPUTIME_ID), which other processes on a loaded
//! machine inflate much less than wall time; best-of-N removes most of the rest. The load
//! average is printed so that figures from a busy machine can be recognised.

use std::alloc::{GlobalAlloc, Layout, System};
use std::hint::black_box;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use jetpipe_model::physics::actuator::{index, Inputs, State};
use jetpipe_model::simulation::Simulation;

#[path = "../benches/common/scenarios.rs"]
mod scenarios;

use scenarios::{
    thread_cpu_seconds, work_between, Prepared, Scenario, DURATION, RELATIVE_TOLERANCE, TARGET_CPU_SECONDS,
};

/// The system allocator, counting live bytes, their peak and the number of allocations.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);
static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);

fn grew(bytes: usize) {
    let live = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
    PEAK.fetch_max(live, Ordering::Relaxed);
}

// SAFETY: every call is forwarded unchanged to `System`; the counters only observe.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc(layout);
        if !p.is_null() {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
            grew(layout.size());
        }
        p
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        let p = System.alloc_zeroed(layout);
        if !p.is_null() {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
            grew(layout.size());
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout);
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = System.realloc(ptr, layout, new_size);
        if !p.is_null() {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
            if new_size >= layout.size() {
                grew(new_size - layout.size());
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

fn live_bytes() -> usize {
    LIVE.load(Ordering::Relaxed)
}

/// Start a new peak measurement from what is live now.
fn reset_peak() -> usize {
    let live = live_bytes();
    PEAK.store(live, Ordering::Relaxed);
    live
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// Tolerance of the reference run that the accuracy columns compare with.
const REFERENCE_TOLERANCE: f64 = 1e-10;

struct Figures {
    scenario: Scenario,
    /// max and RMS |F_act − F_ref| over the communication points, N.
    max_force_error: f64,
    rms_force_error: f64,
    /// Smallest and largest reference force, N.
    force_range: (f64, f64),
    init_cpu: f64,
    best_cpu: f64,
    median_cpu: f64,
    steps: u64,
    rejected: u64,
    rhs: u64,
    jacobians: u64,
    heap_after_init: usize,
    peak_extra_heap: usize,
    allocations: u64,
}

fn measure(scenario: Scenario, runs: usize) -> Result<Figures, String> {
    let model = scenarios::thesis_model();
    let prepared = Prepared::new(scenario, &model, RELATIVE_TOLERANCE)?;

    // One instance: what initialisation keeps on the heap (its own model, as an FMU
    // instance builds one, with the model's tables), and what it costs.
    let before = live_bytes();
    let init_start = thread_cpu_seconds();
    let fresh = prepared.fresh_simulation(&scenarios::thesis_model())?;
    let init_cpu = thread_cpu_seconds() - init_start;
    let heap_after_init = live_bytes().saturating_sub(before);
    drop(fresh);

    // The extra heap a 10 s run needs at its peak, and how often it allocates.
    let mut sim = prepared.initial.clone();
    let allocations_before = ALLOCATIONS.load(Ordering::Relaxed);
    let base = reset_peak();
    let start_counts = sim.statistics();
    prepared.run_on(&mut sim, |_| {})?;
    let peak_extra_heap = PEAK.load(Ordering::Relaxed).saturating_sub(base);
    let allocations = ALLOCATIONS.load(Ordering::Relaxed) - allocations_before;
    let work = work_between(&start_counts, &sim.statistics());
    drop(sim);

    let mut times = Vec::with_capacity(runs);
    for _ in 0..runs {
        let mut sim = prepared.initial.clone();
        let start = thread_cpu_seconds();
        prepared.run_on(&mut sim, |_| {})?;
        times.push(thread_cpu_seconds() - start);
        black_box(&sim);
    }
    times.sort_by(f64::total_cmp);

    // Accuracy of what was timed: the force at every communication point against the same
    // scenario run at a tolerance four decades tighter.
    let forces = |p: &Prepared| -> Result<Vec<f64>, String> {
        let mut sim = p.initial.clone();
        let mut out = Vec::with_capacity(scenario.steps());
        p.run_on(&mut sim, |s| out.push(s.outputs().f_act))?;
        Ok(out)
    };
    let reference = forces(&Prepared::new(scenario, &model, REFERENCE_TOLERANCE)?)?;
    let timed = forces(&prepared)?;
    let differences: Vec<f64> = timed.iter().zip(&reference).map(|(a, b)| (a - b).abs()).collect();
    let max_force_error = differences.iter().copied().fold(0.0, f64::max);
    let rms_force_error = (differences.iter().map(|d| d * d).sum::<f64>() / differences.len() as f64).sqrt();
    let force_range = (
        reference.iter().copied().fold(f64::INFINITY, f64::min),
        reference.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    Ok(Figures {
        force_range,
        max_force_error,
        rms_force_error,
        scenario,
        init_cpu,
        best_cpu: times[0],
        median_cpu: times[times.len() / 2],
        steps: work.steps,
        rejected: work.rejected,
        rhs: work.rhs_evaluations,
        jacobians: work.jacobians,
        heap_after_init,
        peak_extra_heap,
        allocations,
    })
}

/// Best-of-`rounds` nanoseconds per call of `f` over `points`.
fn ns_per_call(points: &[(State, Inputs)], rounds: usize, f: impl Fn(&State, &Inputs)) -> f64 {
    let repeats = 20_000;
    let mut best = f64::INFINITY;
    for _ in 0..rounds {
        let start = thread_cpu_seconds();
        for _ in 0..repeats {
            for (y, u) in points {
                f(black_box(y), black_box(u));
            }
        }
        let elapsed = thread_cpu_seconds() - start;
        best = best.min(elapsed / (repeats * points.len()) as f64);
    }
    best * 1e9
}

/// (states sampled, ns per six-state RHS, per chamber RHS, per Jacobian).
fn rhs_costs() -> Result<(usize, f64, f64, f64), String> {
    let model = scenarios::thesis_model();
    // States met along the standard scenario (every 160 ms), so every branch of the flow law
    // is timed in proportion.
    let prepared = Prepared::new(Scenario::Standard, &model, 1e-4)?;
    let mut sim = prepared.initial.clone();
    let mut points = Vec::new();
    let mut k = 0;
    prepared.run_on(&mut sim, |s| {
        if k % 16 == 0 {
            points.push((
                *s.state(),
                Inputs {
                    v_da: s.v_da(),
                    x_s: s.x_s(),
                    x_s_rate: 0.0,
                    plays: None,
                },
            ));
        }
        k += 1;
    })?;
    let six = ns_per_call(&points, 5, |y, u| {
        black_box(model.derivatives(y, u));
    });
    let chambers = ns_per_call(&points, 5, |y, u| {
        black_box(model.pressure_rates(y[index::JET_POSITION], y[index::P1], y[index::P2], u.x_s, u.x_s_rate));
    });
    // The Jacobian needs f(y) as input: time both together and take the RHS off.
    let with_rhs = ns_per_call(&points, 3, |y, u| {
        let f = model.derivatives(y, u);
        black_box(model.jacobian(y, u, &f));
    });
    Ok((points.len(), six, chambers, with_rhs - six))
}

/// `--runs N` (default 5) and `--scenario NAME` (default all).
fn parse_args() -> Result<(usize, Vec<Scenario>), String> {
    let usage = "usage: perf_report [--runs N] [--scenario standard|ramps|chirp|closed_loop]";
    let (mut runs, mut chosen) = (5, Scenario::ALL.to_vec());
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or_else(|| format!("{flag} needs a value; {usage}"))?;
        match flag.as_str() {
            "--runs" => {
                runs = value
                    .parse::<usize>()
                    .ok()
                    .filter(|&n| n > 0)
                    .ok_or_else(|| format!("--runs {value}: expected a positive integer"))?
            }
            "--scenario" => {
                let scenario = Scenario::ALL
                    .into_iter()
                    .find(|s| s.name() == value)
                    .ok_or_else(|| format!("--scenario {value}: unknown; {usage}"))?;
                chosen = vec![scenario];
            }
            _ => return Err(format!("unknown option {flag}; {usage}")),
        }
    }
    Ok((runs, chosen))
}

fn main() -> Result<(), String> {
    let (runs, chosen) = parse_args()?;
    if cfg!(debug_assertions) {
        eprintln!("warning: a debug build; run with --release for meaningful figures");
    }
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    println!("jetpipe core performance: {DURATION} s per scenario, relative tolerance {RELATIVE_TOLERANCE:e}");
    println!(
        "machine: {cores} cores, load average {} (before); CPU time of this thread, best of {runs}",
        load_average()
    );
    println!(
        "target: {DURATION} s of any scenario in < {:.0} ms CPU\n",
        TARGET_CPU_SECONDS * 1e3
    );
    println!(
        "{:<12} {:>6} {:>10} {:>10} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}  target",
        "scenario", "comm", "CPU best", "CPU med", "sim/CPU", "init", "steps/s", "rej/s", "RHS/s", "Jac/s"
    );
    let mut all = Vec::new();
    for scenario in chosen {
        let f = measure(scenario, runs)?;
        let per_second = |n: u64| n as f64 / DURATION;
        println!(
            "{:<12} {:>4}ms {:>8.2}ms {:>8.2}ms {:>8.0}x {:>7.1}ms {:>9.0} {:>9.0} {:>9.0} {:>9.0}  {}",
            scenario.name(),
            scenario.communication_step() * 1e3,
            f.best_cpu * 1e3,
            f.median_cpu * 1e3,
            DURATION / f.best_cpu,
            f.init_cpu * 1e3,
            per_second(f.steps),
            per_second(f.rejected),
            per_second(f.rhs),
            per_second(f.jacobians),
            if f.best_cpu < TARGET_CPU_SECONDS {
                "PASS"
            } else {
                "MISS"
            },
        );
        all.push(f);
    }
    println!("\n(steps, rejections, RHS and Jacobian evaluations are per simulated second; init is the");
    println!(" equilibrium start, not part of the 10 s)\n");

    println!(
        "accuracy of the timed runs: F_act at every communication point against a run at rtol {REFERENCE_TOLERANCE:e}"
    );
    println!(
        "{:<12} {:>14} {:>14} {:>16}",
        "scenario", "max |dF|", "RMS |dF|", "F_act range"
    );
    for f in &all {
        println!(
            "{:<12} {:>12.2e} N {:>12.2e} N {:>6.1}-{:.1} N",
            f.scenario.name(),
            f.max_force_error,
            f.rms_force_error,
            f.force_range.0,
            f.force_range.1
        );
    }
    println!();

    println!(
        "memory per instance (size_of::<Simulation>() = {} B):",
        std::mem::size_of::<Simulation>()
    );
    println!(
        "{:<12} {:>14} {:>16} {:>14} {:>18}",
        "scenario", "heap at init", "peak extra heap", "total peak", "allocations/10 s"
    );
    for f in &all {
        println!(
            "{:<12} {:>12} B {:>14} B {:>12} B {:>18}",
            f.scenario.name(),
            f.heap_after_init,
            f.peak_extra_heap,
            std::mem::size_of::<Simulation>() + f.heap_after_init + f.peak_extra_heap,
            f.allocations
        );
    }

    let (states, six, chambers, jacobian) = rhs_costs()?;
    println!("\nright-hand side (mean over {states} states along the standard scenario, best of 5):");
    println!("  six-state model (Actuator::derivatives)        {six:8.1} ns");
    println!("  chambers only (Actuator::pressure_rates)       {chambers:8.1} ns");
    println!("  six-state Jacobian (Actuator::jacobian)        {jacobian:8.1} ns");

    let misses = all.iter().filter(|f| f.best_cpu >= TARGET_CPU_SECONDS).count();
    println!(
        "\ntarget {DURATION} s in < {:.0} ms CPU at {RELATIVE_TOLERANCE:e}: {} ({} of {} scenarios miss; slowest {:.1} ms)",
        TARGET_CPU_SECONDS * 1e3,
        if misses == 0 { "PASS" } else { "MISS" },
        misses,
        all.len(),
        all.iter().map(|f| f.best_cpu).fold(0.0, f64::max) * 1e3
    );
    println!("load average {} (after)", load_average());
    Ok(())
}
