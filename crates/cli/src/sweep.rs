//! `jetpipe sweep`: the standard scenario ([`jetpipe_model::scenario`]) for every point of a
//! parameter grid, spread over threads, with one CSV row per run and a measured speed-up.
//!
//! * Parameters are named as in the FMU's variable table (`C_d`, `P_s`, ...), so a sweep
//!   found here can be replayed on the FMU by setting the same start values.
//! * A point's results depend only on its parameters: each run builds its own
//!   [`Simulation`] and shares nothing with the others, and rows are written in grid order
//!   whatever thread ran them, so the physics columns are bit-identical for any thread count
//!   (`tests/sweep_cli.rs` checks it). Only the timing columns change.
//! * Every point is validated before any run starts, so a bad name or value fails at once
//!   with a message naming the variable and the value, not after minutes of work.

use std::io::Write;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use crate::output::write_atomically;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::scenario;
use jetpipe_model::simulation::{Simulation, StepFailure, DEFAULT_RELATIVE_TOLERANCE};
use jetpipe_model::variables::VARIABLES;
use jetpipe_model::variables::{Causality, VarType};

/// More runs than this is almost certainly a typo in a grid count (e.g. `:1000` twice); every
/// point's parameters are built up front (about 300 bytes each).
pub const MAX_RUNS: usize = 100_000;

/// One swept parameter and its values.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    /// Name in the FMU variable table.
    pub name: &'static str,
    pub value_reference: u32,
    pub values: Vec<f64>,
}

/// Names that `--param` accepts: the Real parameters the model's [`Parameters`] holds.
/// (`P1_start`, `P2_start` and `start_at_equilibrium` are FMU parameters too, but the
/// sweep always starts at the equilibrium of the scenario's first inputs.)
pub fn sweepable_names() -> Vec<&'static str> {
    VARIABLES
        .iter()
        .filter(|v| is_sweepable(v.value_reference, v.causality, v.var_type))
        .map(|v| v.name)
        .collect()
}

fn is_sweepable(value_reference: u32, causality: Causality, var_type: VarType) -> bool {
    causality == Causality::Parameter
        && var_type == VarType::Real
        && Parameters::VALUE_REFERENCES.contains(&value_reference)
}

/// Parse `NAME=START:STOP:N` (N values evenly spaced, both ends included), `NAME=V1,V2,...`
/// (a list) or `NAME=V` (one value). Each value is checked against the parameter's own
/// bound here; constraints between parameters are checked per point by [`Sweep::new`].
pub fn parse_axis(spec: &str) -> Result<Axis, String> {
    let (name, values) = spec
        .split_once('=')
        .ok_or_else(|| format!("--param {spec:?} is invalid: expected NAME=START:STOP:N or NAME=V1,V2,..."))?;
    let name = name.trim();
    let variable = VARIABLES
        .iter()
        .find(|v| v.name == name && is_sweepable(v.value_reference, v.causality, v.var_type))
        .ok_or_else(|| unknown_name(name))?;
    let values = parse_values(spec, name, values)?;
    // The parameter's own bound (e.g. C_d >= 0), with the model's message naming it.
    let mut probe = Parameters::default();
    for &x in &values {
        probe
            .set(variable.value_reference, x)
            .map_err(|e| format!("--param {spec}: {e}"))?;
    }
    Ok(Axis {
        name: variable.name,
        value_reference: variable.value_reference,
        values,
    })
}

/// The values of `spec` after the `=`: a grid START:STOP:N, a list, or one value.
fn parse_values(spec: &str, name: &str, values: &str) -> Result<Vec<f64>, String> {
    let number = |text: &str| -> Result<f64, String> {
        let text = text.trim();
        let x: f64 = text
            .parse()
            .map_err(|_| format!("--param {spec}: {name} = {text:?} is not a number"))?;
        if !x.is_finite() {
            return Err(format!("--param {spec}: {name} = {x} is invalid: must be finite"));
        }
        Ok(x)
    };
    if !values.contains(':') {
        return values.split(',').map(number).collect();
    }
    let parts: Vec<&str> = values.split(':').collect();
    let [start, stop, count] = parts[..] else {
        return Err(format!(
            "--param {spec}: a grid is START:STOP:N (three fields), got {} fields",
            parts.len()
        ));
    };
    let (start, stop) = (number(start)?, number(stop)?);
    let n: usize = match count.trim().parse() {
        Ok(n) if n >= 1 => n,
        _ => {
            return Err(format!(
                "--param {spec}: the number of values N = {count:?} must be an integer >= 1"
            ))
        }
    };
    if n > MAX_RUNS {
        return Err(format!("--param {spec}: N = {n} is more than {MAX_RUNS} runs"));
    }
    if n == 1 {
        return Ok(vec![start]);
    }
    // start + (stop − start)·k/(N − 1), with the last value exactly `stop` (the formula can
    // miss it by an ulp, and a user who asks for 0.75 should see 0.75).
    Ok((0..n)
        .map(|k| {
            if k == n - 1 {
                stop
            } else {
                start + (stop - start) * k as f64 / (n - 1) as f64
            }
        })
        .collect())
}

fn unknown_name(name: &str) -> String {
    let names = sweepable_names();
    let listed = names.join(", ");
    if let Some(v) = VARIABLES.iter().find(|v| v.name == name) {
        let why = if v.causality == Causality::Parameter {
            "it sets the FMU's start when not at equilibrium, and a sweep always starts at the equilibrium of the \
             scenario's first inputs"
                .to_string()
        } else {
            format!("it is an {} of the FMU", format!("{:?}", v.causality).to_lowercase())
        };
        return format!("--param {name:?}: {name} cannot be swept ({why}); parameters: {listed}");
    }
    // A different case (c_d), or words of the description (supply_pressure -> P_s).
    let words = name.replace('_', " ").to_lowercase();
    let hint = names
        .iter()
        .find(|n| n.eq_ignore_ascii_case(name))
        .map(|n| n.to_string())
        .or_else(|| {
            VARIABLES
                .iter()
                .find(|v| names.contains(&v.name) && words.len() > 3 && v.description.to_lowercase().contains(&words))
                .map(|v| format!("{} ({})", v.name, v.description))
        })
        .map(|n| format!(" (did you mean {n}?)"))
        .unwrap_or_default();
    format!("--param {name:?}: unknown parameter{hint}; parameters: {listed}")
}

/// What each run simulates: the standard scenario, possibly cut short.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunSettings {
    /// Simulated seconds from t = 0, a whole number of 10 ms samples.
    pub duration: f64,
    /// Communication step: the 10 ms sample period divided by a whole number.
    pub step: f64,
    pub tolerance: f64,
}

impl Default for RunSettings {
    fn default() -> Self {
        Self {
            duration: scenario::DURATION,
            step: scenario::SAMPLE_PERIOD,
            tolerance: DEFAULT_RELATIVE_TOLERANCE,
        }
    }
}

impl RunSettings {
    pub fn check(&self) -> Result<(), String> {
        let samples = self.duration / scenario::SAMPLE_PERIOD;
        if !(self.duration.is_finite() && samples.round() >= 1.0 && (samples - samples.round()).abs() < 1e-6) {
            return Err(format!(
                "--duration {} s is invalid: must be a positive multiple of the {} s sample period",
                self.duration,
                scenario::SAMPLE_PERIOD
            ));
        }
        let substeps = scenario::SAMPLE_PERIOD / self.step;
        if !(self.step.is_finite()
            && self.step > 0.0
            && substeps.round() >= 1.0
            && (substeps - substeps.round()).abs() < 1e-6)
        {
            return Err(format!(
                "--step {} s is invalid: must divide the {} s sample period (0.01, 0.005, 0.001, ...)",
                self.step,
                scenario::SAMPLE_PERIOD
            ));
        }
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(format!("--tolerance {} is invalid: must be in (0, 1)", self.tolerance));
        }
        Ok(())
    }

    fn samples(&self) -> usize {
        (self.duration / scenario::SAMPLE_PERIOD).round() as usize
    }

    fn substeps(&self) -> usize {
        (scenario::SAMPLE_PERIOD / self.step).round() as usize
    }
}

/// A validated grid: the Cartesian product of the axes, last axis varying fastest.
#[derive(Clone, Debug)]
pub struct Sweep {
    pub axes: Vec<Axis>,
    /// Parameters of every point, in grid order.
    pub points: Vec<Parameters>,
    pub settings: RunSettings,
}

impl Sweep {
    /// Build every point from `base` and check it: each parameter's bound, the constraints
    /// between parameters, and that the scenario's stopper travel fits the cylinder.
    pub fn new(base: &Parameters, axes: Vec<Axis>, settings: RunSettings) -> Result<Self, String> {
        settings.check()?;
        if axes.is_empty() {
            return Err("no --param given: name at least one parameter to sweep".into());
        }
        for (k, a) in axes.iter().enumerate() {
            if axes[..k].iter().any(|b| b.value_reference == a.value_reference) {
                return Err(format!(
                    "--param {} is given twice: give all its values in one --param",
                    a.name
                ));
            }
        }
        let total = axes
            .iter()
            .try_fold(1usize, |n, a| n.checked_mul(a.values.len()))
            .filter(|&n| n <= MAX_RUNS)
            .ok_or_else(|| format!("the grid has more than {MAX_RUNS} points: use fewer values"))?;
        let (x_min, x_max) = (0..settings.samples())
            .map(|k| scenario::standard_inputs(k).1)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let mut points = Vec::with_capacity(total);
        for index in 0..total {
            let values = point_values(&axes, index);
            let mut p = base.clone();
            for (axis, &x) in axes.iter().zip(&values) {
                p.set(axis.value_reference, x)?;
            }
            let describe = || describe_point(&axes, &values);
            p.validate()
                .map_err(|e| format!("point {index} ({}): {e}", describe()))?;
            for x in [x_min, x_max] {
                p.check_stopper(x).map_err(|e| {
                    format!(
                        "point {index} ({}): the standard scenario moves the stopper over [{x_min}, {x_max}] m: {e}",
                        describe()
                    )
                })?;
            }
            points.push(p);
        }
        Ok(Self { axes, points, settings })
    }

    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The swept values of point `index`, in axis order.
    pub fn values(&self, index: usize) -> Vec<f64> {
        point_values(&self.axes, index)
    }

    pub fn describe(&self, index: usize) -> String {
        describe_point(&self.axes, &self.values(index))
    }
}

fn point_values(axes: &[Axis], mut index: usize) -> Vec<f64> {
    let mut values = vec![0.0; axes.len()];
    for (slot, axis) in values.iter_mut().zip(axes).rev() {
        *slot = axis.values[index % axis.values.len()];
        index /= axis.values.len();
    }
    values
}

fn describe_point(axes: &[Axis], values: &[f64]) -> String {
    axes.iter()
        .zip(values)
        .map(|(a, x)| format!("{} = {x}", a.name))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Summary figures of one run. The force figures are over the 10 ms samples, t = 0 included.
#[derive(Clone, Debug, PartialEq)]
pub struct RunResult {
    pub rms_force: f64,
    pub max_force: f64,
    pub min_force: f64,
    pub final_force: f64,
    pub final_p1: f64,
    pub final_p2: f64,
    pub steps: u64,
    pub rejected: u64,
    pub rhs_evaluations: u64,
    /// CPU time of the worker thread during the run (Linux; `None` elsewhere).
    pub cpu_seconds: Option<f64>,
    pub wall_seconds: f64,
    /// Why the run failed; the figures are NaN then.
    pub error: Option<String>,
}

impl RunResult {
    /// The figures that must not depend on how the sweep was scheduled, as bits.
    pub fn physics_bits(&self) -> [u64; 9] {
        [
            self.rms_force.to_bits(),
            self.max_force.to_bits(),
            self.min_force.to_bits(),
            self.final_force.to_bits(),
            self.final_p1.to_bits(),
            self.final_p2.to_bits(),
            self.steps,
            self.rejected,
            self.rhs_evaluations,
        ]
    }

    fn failed(error: String, wall_seconds: f64, cpu_seconds: Option<f64>) -> Self {
        Self {
            rms_force: f64::NAN,
            max_force: f64::NAN,
            min_force: f64::NAN,
            final_force: f64::NAN,
            final_p1: f64::NAN,
            final_p2: f64::NAN,
            steps: 0,
            rejected: 0,
            rhs_evaluations: 0,
            cpu_seconds,
            wall_seconds,
            error: Some(error),
        }
    }
}

/// CPU time consumed so far by the calling thread. Wall time alone would count the time a run
/// waited for a core, which on a loaded machine is most of what differs between serial and
/// parallel runs. clock_gettime brings the thread's runtime up to date when asked;
/// /proc/thread-self/schedstat, used before, advances only at scheduler ticks and read 0 for
/// runs shorter than one.
#[cfg(unix)]
pub fn thread_cpu_seconds() -> Option<f64> {
    let mut now = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `now` is a valid, writable timespec for the duration of the call.
    let status = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut now) };
    (status == 0).then_some(now.tv_sec as f64 + now.tv_nsec as f64 * 1e-9)
}

#[cfg(not(unix))]
pub fn thread_cpu_seconds() -> Option<f64> {
    None
}

/// Simulate one point. Never panics: a panic inside the model becomes a failed run.
pub fn run_point(params: &Parameters, settings: &RunSettings) -> RunResult {
    let cpu_start = thread_cpu_seconds();
    let started = Instant::now();
    let outcome = catch_unwind(AssertUnwindSafe(|| simulate(params, settings)));
    let wall = started.elapsed().as_secs_f64();
    let cpu = cpu_start.and_then(|a| thread_cpu_seconds().map(|b| b - a));
    let outcome = outcome.unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into());
        Err(format!("the model panicked: {what}"))
    });
    match outcome {
        Ok(mut result) => {
            result.cpu_seconds = cpu;
            result.wall_seconds = wall;
            result
        }
        Err(e) => RunResult::failed(e, wall, cpu),
    }
}

fn simulate(params: &Parameters, settings: &RunSettings) -> Result<RunResult, String> {
    let model = Actuator::new(params.clone())?;
    let (v0, x0) = scenario::standard_inputs(0);
    let mut sim = Simulation::at_equilibrium(model, v0, x0, 0.0, settings.tolerance)?;
    let substeps = settings.substeps();
    let h = scenario::SAMPLE_PERIOD / substeps as f64;
    let first = sim.outputs().f_act;
    let (mut sum_sq, mut max, mut min, mut n) = (first * first, first, first, 1usize);
    for k in 0..settings.samples() {
        let (v, x) = scenario::standard_inputs(k);
        sim.set_command(v)?;
        sim.set_stopper(x)?;
        for _ in 0..substeps {
            sim.step(h).map_err(|e| match e {
                StepFailure::InvalidRequest(message) => message,
                StepFailure::Integration { message, .. } => message,
            })?;
        }
        let f = sim.outputs().f_act;
        sum_sq += f * f;
        max = max.max(f);
        min = min.min(f);
        n += 1;
    }
    let last = sim.outputs();
    Ok(RunResult {
        rms_force: (sum_sq / n as f64).sqrt(),
        max_force: max,
        min_force: min,
        final_force: last.f_act,
        final_p1: last.p1,
        final_p2: last.p2,
        steps: sim.statistics().steps,
        rejected: sim.statistics().rejected,
        rhs_evaluations: sim.statistics().rhs_evaluations,
        cpu_seconds: None,
        wall_seconds: 0.0,
        error: None,
    })
}

/// Results of the points `indices` of `sweep` run on `threads` threads, in the order of
/// `indices`, and the wall time of the whole batch. Threads take the next point from a shared
/// counter (runs differ in cost, so a fixed split would leave threads idle at the end).
pub fn run_indices(sweep: &Sweep, indices: &[usize], threads: usize) -> (Vec<RunResult>, f64) {
    let started = Instant::now();
    let workers = threads.clamp(1, indices.len().max(1));
    let next = AtomicUsize::new(0);
    let slots: Mutex<Vec<Option<RunResult>>> = Mutex::new(vec![None; indices.len()]);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&index) = indices.get(k) else { break };
                let result = run_point(&sweep.points[index], &sweep.settings);
                // A poisoned lock could only come from a panic while holding it; the slots
                // are plain data, so keep going with them.
                slots.lock().unwrap_or_else(|e| e.into_inner())[k] = Some(result);
            });
        }
    });
    let wall = started.elapsed().as_secs_f64();
    let results = slots
        .into_inner()
        .unwrap_or_else(|e| e.into_inner())
        .into_iter()
        .map(|r| r.unwrap_or_else(|| RunResult::failed("the run did not complete".into(), 0.0, None)))
        .collect();
    (results, wall)
}

/// Every point of the sweep on `threads` threads.
pub fn run_all(sweep: &Sweep, threads: usize) -> (Vec<RunResult>, f64) {
    let indices: Vec<usize> = (0..sweep.len()).collect();
    run_indices(sweep, &indices, threads)
}

/// Columns after the swept parameters.
pub const RESULT_COLUMNS: &[&str] = &[
    "rms_F_act_N",
    "max_F_act_N",
    "min_F_act_N",
    "final_F_act_N",
    "final_P1_Pa",
    "final_P2_Pa",
    "steps",
    "rejected_steps",
    "rhs_evaluations",
    "cpu_s",
    "wall_s",
    "status",
];

/// The CSV text: `run`, one column per swept parameter, then [`RESULT_COLUMNS`]. Floats are
/// written in Rust's shortest round-trip form, so they read back to the same bits.
pub fn csv_text(sweep: &Sweep, results: &[RunResult]) -> String {
    let mut text = String::from("run");
    for a in &sweep.axes {
        text.push(',');
        text.push_str(a.name);
    }
    for c in RESULT_COLUMNS {
        text.push(',');
        text.push_str(c);
    }
    text.push('\n');
    for (index, r) in results.iter().enumerate() {
        let mut row = vec![index.to_string()];
        row.extend(sweep.values(index).iter().map(|x| x.to_string()));
        row.extend(
            [
                r.rms_force,
                r.max_force,
                r.min_force,
                r.final_force,
                r.final_p1,
                r.final_p2,
            ]
            .map(|x| x.to_string()),
        );
        row.extend([r.steps, r.rejected, r.rhs_evaluations].map(|x| x.to_string()));
        row.push(r.cpu_seconds.map_or(String::new(), |x| format!("{x:.6}")));
        row.push(format!("{:.6}", r.wall_seconds));
        // The message may hold commas and quotes: quote it as RFC 4180 says.
        row.push(match &r.error {
            None => "ok".into(),
            Some(e) => format!("\"failed: {}\"", e.replace('"', "\"\"").replace('\n', " ")),
        });
        text.push_str(&row.join(","));
        text.push('\n');
    }
    text
}

/// Options of `jetpipe sweep`.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// `--param` specifications.
    pub params: Vec<String>,
    /// Worker threads; `None`: every core the process may use.
    pub threads: Option<usize>,
    pub out: PathBuf,
    pub settings: RunSettings,
    /// Parameters the grid starts from (the thesis values, or `--base-params`).
    pub base: Parameters,
    /// Serial reference over every run instead of a subset.
    pub compare_serial: bool,
    /// No serial reference at all.
    pub no_serial: bool,
}

/// Points of the serial reference: `m` evenly spaced over the grid, so cheap and dear
/// corners of the grid are both in it.
pub fn serial_subset(total: usize, threads: usize, all: bool) -> Vec<usize> {
    let m = if all {
        total
    } else {
        total.min((4 * threads).max(total.div_ceil(4)))
    };
    (0..m).map(|k| k * total / m).collect()
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| {
            let f: Vec<&str> = s.split_whitespace().take(3).collect();
            (f.len() == 3).then(|| f.join(" "))
        })
        .unwrap_or_else(|| "unknown".into())
}

/// `jetpipe sweep`: run, write the CSV, print the timing report to `out`. Errors if a
/// specification is bad (before any run) or if any run failed (after writing the CSV).
pub fn run_command(options: &SweepOptions, out: &mut dyn Write) -> Result<(), String> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let threads = match options.threads {
        Some(0) => return Err("--threads 0 is invalid: must be >= 1".into()),
        Some(n) => n,
        None => cores,
    };
    let axes = options
        .params
        .iter()
        .map(|s| parse_axis(s))
        .collect::<Result<Vec<_>, _>>()?;
    let sweep = Sweep::new(&options.base, axes, options.settings)?;
    let total = sweep.len();
    let simulated = options.settings.duration;
    let mut say = |line: String| writeln!(out, "{line}").map_err(|e| format!("cannot write the report: {e}"));
    say(format!(
        "sweep: {total} runs of the standard scenario ({simulated} s, step {} s, tolerance {:e}) over {}",
        options.settings.step,
        options.settings.tolerance,
        sweep
            .axes
            .iter()
            .map(|a| format!("{} ({} values)", a.name, a.values.len()))
            .collect::<Vec<_>>()
            .join(" x ")
    ))?;
    let load_before = load_average();
    say(format!(
        "  {threads} threads on {cores} available cores; load average before: {load_before}"
    ))?;

    let (results, wall) = run_all(&sweep, threads);
    let cpu_total: f64 = results.iter().filter_map(|r| r.cpu_seconds).sum();
    say(format!(
        "  {threads} threads: wall {wall:.3} s, {:.2} runs/s, {:.1} simulated s per wall s, CPU {cpu_total:.3} s",
        total as f64 / wall,
        total as f64 * simulated / wall
    ))?;

    write_atomically(&options.out, &csv_text(&sweep, &results))?;

    if threads > 1 && !options.no_serial {
        let subset = serial_subset(total, threads, options.compare_serial);
        let (serial, serial_wall) = run_indices(&sweep, &subset, 1);
        let identical = subset
            .iter()
            .zip(&serial)
            .all(|(&i, s)| s.physics_bits() == results[i].physics_bits() && s.error == results[i].error);
        let serial_rate = subset.len() as f64 / serial_wall;
        let parallel_rate = total as f64 / wall;
        let speedup = parallel_rate / serial_rate;
        let which = if subset.len() == total {
            "every run".to_string()
        } else {
            format!("{} of the {total} runs, evenly spaced over the grid", subset.len())
        };
        say(format!(
            "  1 thread ({which}): wall {serial_wall:.3} s, {serial_rate:.2} runs/s"
        ))?;
        say(format!(
            "  speed-up {speedup:.2} on {threads} threads, parallel efficiency {:.0} %",
            100.0 * speedup / threads as f64
        ))?;
        // CPU per run of the same points, alone and side by side: a rise means the threads
        // slowed each other (shared caches, memory bandwidth, SMT siblings) or the machine was
        // busy; wall-time speed-up alone cannot tell those apart from scheduling overhead.
        let cpu_of = |rs: &mut dyn Iterator<Item = &RunResult>| -> Option<f64> {
            let v: Vec<f64> = rs.map(|r| r.cpu_seconds).collect::<Option<_>>()?;
            Some(v.iter().sum::<f64>() / v.len().max(1) as f64)
        };
        let cpu_serial = cpu_of(&mut serial.iter());
        let cpu_parallel = cpu_of(&mut subset.iter().map(|&i| &results[i]));
        if let (Some(a), Some(b)) = (cpu_serial, cpu_parallel) {
            say(format!(
                "  CPU per run of those runs: {:.1} ms alone, {:.1} ms in the {threads}-thread sweep ({:+.0} %)",
                a * 1e3,
                b * 1e3,
                100.0 * (b / a - 1.0)
            ))?;
        }
        // Cores the runs actually had: CPU over wall. Below 1 per thread means they waited for
        // a core, i.e. other processes were running; then both wall times, and so the speed-up,
        // depend on how much those took during each measurement.
        let serial_cpu: Option<f64> = serial.iter().map(|r| r.cpu_seconds).sum();
        if let Some(serial_cpu) = serial_cpu {
            let (busy, busy_serial) = (cpu_total / wall, serial_cpu / serial_wall);
            say(format!(
                "  cores used: {busy:.2} of {threads} in the {threads}-thread sweep, {busy_serial:.2} of 1 alone"
            ))?;
            if busy_serial < 0.9 || busy < 0.9 * threads.min(cores) as f64 || speedup > threads as f64 {
                say(format!(
                    "  note: other processes shared the cores (load average before: {load_before}); the speed-up \
                     is a ratio of wall times under that load, not the machine's alone"
                ))?;
            }
        }
        say(format!(
            "  serial results bit-identical to the {threads}-thread results: {}",
            if identical { "yes" } else { "NO" }
        ))?;
        if threads > cores {
            say(format!(
                "  note: {threads} threads on {cores} cores: efficiency cannot exceed {:.0} %",
                100.0 * cores as f64 / threads as f64
            ))?;
        }
        say(format!("  load average after: {}", load_average()))?;
        if !identical {
            return Err("the serial and parallel results differ: the sweep is not deterministic".into());
        }
    }
    say(format!("  wrote {}", options.out.display()))?;

    let failed: Vec<usize> = (0..total).filter(|&i| results[i].error.is_some()).collect();
    if let Some(&first) = failed.first() {
        return Err(format!(
            "{} of {total} runs failed (rows with status \"failed: ...\" in {}); first: run {first} ({}): {}",
            failed.len(),
            options.out.display(),
            sweep.describe(first),
            results[first].error.as_deref().unwrap_or("")
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_lists_and_single_values() {
        let a = parse_axis("C_d=0.6:0.75:4").unwrap();
        assert_eq!(a.name, "C_d");
        assert_eq!(a.values.len(), 4);
        assert_eq!((a.values[0], a.values[3]), (0.6, 0.75));
        assert!((a.values[1] - 0.65).abs() < 1e-15);
        assert_eq!(
            parse_axis("P_s=600000, 652925").unwrap().values,
            vec![600000.0, 652925.0]
        );
        assert_eq!(parse_axis("k_spring=90").unwrap().values, vec![90.0]);
        assert_eq!(parse_axis("C_d=0.6:0.75:1").unwrap().values, vec![0.6]);
    }

    #[test]
    fn bad_specifications_name_the_variable_and_value() {
        let e = parse_axis("Cd=0.6").unwrap_err();
        assert!(e.contains("Cd") && e.contains("C_d"), "{e}");
        let e = parse_axis("c_d=0.6").unwrap_err();
        assert!(e.contains("did you mean C_d"), "{e}");
        let e = parse_axis("F_act=1").unwrap_err();
        assert!(e.contains("F_act cannot be swept (it is an output"), "{e}");
        let e = parse_axis("supply_pressure=6e5").unwrap_err();
        assert!(e.contains("did you mean P_s"), "{e}");
        let e = parse_axis("C_d=abc").unwrap_err();
        assert!(e.contains("C_d") && e.contains("abc"), "{e}");
        let e = parse_axis("C_d=-0.1").unwrap_err();
        assert!(e.contains("C_d") && e.contains("-0.1") && e.contains("(0, 1]"), "{e}");
        let e = parse_axis("C_d=0.6:0.7:0").unwrap_err();
        assert!(e.contains("N") && e.contains("\"0\""), "{e}");
        let e = parse_axis("C_d=0.6:0.7").unwrap_err();
        assert!(e.contains("START:STOP:N"), "{e}");
        let e = parse_axis("C_d=inf").unwrap_err();
        assert!(e.contains("C_d") && e.contains("inf"), "{e}");
        let e = parse_axis("C_d").unwrap_err();
        assert!(e.contains("NAME="), "{e}");
    }

    #[test]
    fn points_are_checked_together() {
        let axes = vec![parse_axis("C_dm_A_lpp=-0.2e-6").unwrap()];
        let e = Sweep::new(&Parameters::default(), axes, RunSettings::default()).unwrap_err();
        assert!(
            e.contains("point 0 (C_dm_A_lpp = -0.0000002)") && e.contains("leakage"),
            "{e}"
        );
        // A cylinder too short for the scenario's stopper travel (0.044–0.064 m): x_s < 0.063 m.
        let axes = vec![parse_axis("L_cyl=0.078,0.045").unwrap()];
        let e = Sweep::new(&Parameters::default(), axes, RunSettings::default()).unwrap_err();
        assert!(
            e.contains("point 1") && e.contains("L_cyl = 0.045") && e.contains("x_s"),
            "{e}"
        );
        let twice = vec![parse_axis("C_d=0.6").unwrap(), parse_axis("C_d=0.7").unwrap()];
        assert!(Sweep::new(&Parameters::default(), twice, RunSettings::default())
            .unwrap_err()
            .contains("twice"));
    }

    /// The message of refusing `spec`, whether parsing it or building the grid refuses it.
    fn refusal(spec: &str) -> String {
        match parse_axis(spec) {
            Err(e) => e,
            Ok(axis) => Sweep::new(&Parameters::default(), vec![axis], RunSettings::default())
                .err()
                .unwrap_or_else(|| panic!("--param {spec} was accepted")),
        }
    }

    #[test]
    fn a_discharge_coefficient_above_one_is_refused_naming_the_value_and_the_limit() {
        let e = refusal("C_d=0.6,1.5");
        assert!(e.contains("C_d = 1.5 is invalid: must be in (0, 1]"), "{e}");
        let e = refusal("C_d=0");
        assert!(e.contains("C_d = 0 is invalid: must be in (0, 1]"), "{e}");
    }

    #[test]
    fn a_supply_pressure_below_the_return_pressure_is_refused_naming_both_values() {
        let e = refusal("P_s=652925,90000");
        assert!(
            e.contains("point 1 (P_s = 90000)") && e.contains("P_s = 90000 Pa is invalid: must be >= P_r = 101325 Pa"),
            "{e}"
        );
        let e = refusal("P_r=700000");
        assert!(
            e.contains("P_s = 652925 Pa is invalid: must be >= P_r = 700000 Pa"),
            "{e}"
        );
    }

    #[test]
    fn a_spring_rate_of_1e30_is_refused_naming_the_value_and_the_limit() {
        let e = refusal("k_spring=1e30");
        assert!(
            e.contains("k_spring = 1e30 N/m is invalid: must be in [0, 100000] N/m"),
            "{e}"
        );
    }

    #[test]
    fn the_sweep_refuses_with_the_message_of_the_table() {
        let e = refusal("k_spring=1e30");
        let table = jetpipe_model::variables::check(jetpipe_model::variables::vr::K_SPRING, 1e30).unwrap_err();
        assert!(e.ends_with(&table), "{e}");
    }

    #[test]
    fn grid_order_is_last_axis_fastest() {
        let axes = vec![
            parse_axis("C_d=0.6,0.7").unwrap(),
            parse_axis("k_spring=80,90,100").unwrap(),
        ];
        let sweep = Sweep::new(&Parameters::default(), axes, RunSettings::default()).unwrap();
        assert_eq!(sweep.len(), 6);
        assert_eq!(sweep.values(0), vec![0.6, 80.0]);
        assert_eq!(sweep.values(1), vec![0.6, 90.0]);
        assert_eq!(sweep.values(5), vec![0.7, 100.0]);
        assert_eq!(sweep.points[4].c_d, 0.7);
        assert_eq!(sweep.points[4].k_spring, 90.0);
    }

    #[test]
    fn serial_subset_is_spread_over_the_grid() {
        assert_eq!(serial_subset(5, 2, false), vec![0, 1, 2, 3, 4]);
        let s = serial_subset(100, 2, false);
        assert_eq!(s.len(), 25);
        assert_eq!((s[0], s[24]), (0, 96));
        assert_eq!(serial_subset(100, 2, true).len(), 100);
    }
}
