//! Work–precision of a general-purpose library, diffsol (BDF and ESDIRK on nalgebra), against
//! jetpipe's own split integrator, on the first second of the standard scenario:
//!
//!     cargo run --release -p diffsol_compare --target-dir target/tools [-- --seconds 1 --runs 3]
//!
//! Every method integrates the same six-state model (`Actuator::derivatives`, with
//! `Actuator::jacobian` for the Newton matrix) from the same equilibrium, at relative tolerances
//! 1e-4 .. 1e-8 with absolute tolerances rtol × `state_scales()` (as fmu_tests/scipy_reference.py).
//! Error = max |ΔF_act| at the 10 ms instants against jetpipe's `Simulation` at rtol 1e-10 with
//! 0.1 ms communication steps (the reference of fmu_tests/work_precision.py).
//!
//! Inputs are held for 10 ms and jump at each boundary, so diffsol is restarted there: the
//! problem is rebuilt with the new inputs as its parameters p = [v_DA, x_s], t0 = t_k and the
//! current state as its initial condition, and a fresh solver is made from it. A restart is
//! what the jump needs anyway (BDF's history and the step size from before the jump are
//! invalid after it), and it lets diffsol choose its own first step; the rebuild is timed.

use std::cell::{Cell, RefCell};

use diffsol::{
    DiffsolError, NalgebraLU, NalgebraMat, OdeBuilder, OdeEquations, OdeSolverMethod, OdeSolverStopReason, Vector,
};
use jetpipe_model::physics::actuator::{index, Actuator, Inputs, Jacobian, State};
use jetpipe_model::physics::chambers::pressure_after_volume_jump;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::scenario::{self, SAMPLE_PERIOD};
use jetpipe_model::simulation::{ChamberMethod, Simulation};

const TOLERANCES: [f64; 5] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8];
const ERROR_LEVELS: [f64; 3] = [1e-4, 1e-5, 1e-6];

#[derive(Clone, Copy, PartialEq)]
enum Method {
    Jetpipe,
    JetpipeSdirk4,
    Bdf,
    TrBdf2,
    Esdirk34,
}

impl Method {
    fn name(self) -> &'static str {
        match self {
            Method::Jetpipe => "jetpipe DP5 chambers",
            Method::JetpipeSdirk4 => "jetpipe SDIRK4 chambers",
            Method::Bdf => "diffsol BDF",
            Method::TrBdf2 => "diffsol TR-BDF2",
            Method::Esdirk34 => "diffsol ESDIRK34",
        }
    }
}

/// One run: force at t = 0 and every 10 ms, and the work done.
struct Run {
    forces: Vec<f64>,
    steps: u64,
    rhs: u64,
    jacobians: u64,
}

fn thread_cpu_seconds() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; the clock id is a constant libc knows.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    assert_eq!(rc, 0, "clock_gettime(CLOCK_THREAD_CPUTIME_ID) failed");
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

fn load() -> String {
    std::fs::read_to_string("/proc/loadavg").map_or_else(|_| "unknown".into(), |s| s.trim().to_string())
}

fn inputs(v_da: f64, x_s: f64) -> Inputs {
    Inputs {
        v_da,
        x_s,
        x_s_rate: 0.0,
        plays: None,
    }
}

/// jetpipe's `Simulation` (default split method), `substeps` communication steps per sample.
fn run_jetpipe(initial: &Simulation, samples: usize, substeps: usize) -> Result<Run, String> {
    let mut sim = initial.clone();
    let mut forces = vec![sim.outputs().f_act];
    for k in 0..samples {
        let (v, x) = scenario::standard_inputs(k);
        sim.set_command(v)?;
        sim.set_stopper(x)?;
        for _ in 0..substeps {
            sim.step(SAMPLE_PERIOD / substeps as f64)
                .map_err(|e| format!("{e:?}"))?;
        }
        forces.push(sim.outputs().f_act);
    }
    let (a, b) = (initial.statistics(), sim.statistics());
    Ok(Run {
        forces,
        steps: b.steps - a.steps,
        rhs: b.rhs_evaluations - a.rhs_evaluations,
        jacobians: b.jacobians - a.jacobians,
    })
}

/// Step `solver` to `t_end` exactly; its state there and the number of steps taken.
fn advance<'a, Eqn, S>(mut solver: S, t_end: f64) -> Result<(Vec<f64>, u64), DiffsolError>
where
    Eqn: OdeEquations<T = f64> + 'a,
    S: OdeSolverMethod<'a, Eqn>,
{
    solver.set_stop_time(t_end)?;
    while !matches!(solver.step()?, OdeSolverStopReason::TstopReached) {}
    Ok((
        solver.state().y.clone_as_vec(),
        solver.get_statistics().number_of_steps as u64,
    ))
}

fn run_diffsol(model: &Actuator, y0: &State, samples: usize, rtol: f64, method: Method) -> Result<Run, String> {
    let rhs_calls = Cell::new(0u64);
    // diffsol asks for Jacobian–vector products and assembles the dense matrix column by
    // column at one state; jetpipe's `jacobian` gives the whole matrix, so keep the last one
    // and compute it once per state instead of once per column.
    let jacobian: RefCell<Option<(State, Jacobian)>> = RefCell::new(None);
    let jacobians = Cell::new(0u64);
    let atol: Vec<f64> = (model.state_scales() * rtol).iter().copied().collect();

    let mut y = y0.clone_owned();
    let mut x_before = scenario::standard_inputs(0).1;
    let mut forces = vec![model.outputs(&y, x_before, 0.0).f_act];
    let mut steps = 0;
    for k in 0..samples {
        let (v, x) = scenario::standard_inputs(k);
        // A stopper jump compresses the air in each chamber adiabatically (as
        // `Simulation::set_stopper` and fmu_tests/scipy_reference.py do): not part of the ODE.
        if x != x_before {
            let gamma = model.polytropic_exponent;
            let ((v1, v2), (w1, w2)) = (model.cylinder.volumes(x_before), model.cylinder.volumes(x));
            y[index::P1] = pressure_after_volume_jump(gamma, y[index::P1], v1, w1);
            y[index::P2] = pressure_after_volume_jump(gamma, y[index::P2], v2, w2);
            x_before = x;
        }
        let y_start = y;
        let problem = OdeBuilder::<NalgebraMat<f64>>::new()
            .t0(k as f64 * SAMPLE_PERIOD)
            .rtol(rtol)
            .atol(atol.iter().copied())
            .p([v, x])
            .rhs_implicit(
                |s, p, _t, dy| {
                    rhs_calls.set(rhs_calls.get() + 1);
                    let f = model.derivatives(&State::from_column_slice(s), &inputs(p[0], p[1]));
                    dy.copy_from_slice(f.as_slice());
                },
                |s, p, _t, w, jw| {
                    let s = State::from_column_slice(s);
                    let mut cache = jacobian.borrow_mut();
                    if !matches!(&*cache, Some((at, _)) if *at == s) {
                        let u = inputs(p[0], p[1]);
                        let f = model.derivatives(&s, &u);
                        rhs_calls.set(rhs_calls.get() + 1);
                        jacobians.set(jacobians.get() + 1);
                        *cache = Some((s, model.jacobian(&s, &u, &f)));
                    }
                    let product = cache.as_ref().unwrap().1 * State::from_column_slice(w);
                    jw.copy_from_slice(product.as_slice());
                },
            )
            .init(
                move |_p, _t, init| init.copy_from_slice(y_start.as_slice()),
                y_start.len(),
            )
            .build()
            .map_err(|e| e.to_string())?;
        *jacobian.borrow_mut() = None; // the inputs changed
        let t_end = (k + 1) as f64 * SAMPLE_PERIOD;
        let (y_end, n) = match method {
            Method::Bdf => advance(problem.bdf::<NalgebraLU<f64>>().map_err(|e| e.to_string())?, t_end),
            Method::TrBdf2 => advance(problem.tr_bdf2::<NalgebraLU<f64>>().map_err(|e| e.to_string())?, t_end),
            Method::Esdirk34 => advance(problem.esdirk34::<NalgebraLU<f64>>().map_err(|e| e.to_string())?, t_end),
            Method::Jetpipe | Method::JetpipeSdirk4 => unreachable!("not a diffsol method"),
        }
        .map_err(|e| format!("t = {t_end}: {e}"))?;
        y = State::from_column_slice(&y_end);
        steps += n;
        forces.push(model.outputs(&y, x, 0.0).f_act);
    }
    Ok(Run {
        forces,
        steps,
        rhs: rhs_calls.get(),
        jacobians: jacobians.get(),
    })
}

/// Best CPU time of up to `runs` runs (stops repeating once a run takes over half a second).
fn timed(runs: usize, mut f: impl FnMut() -> Result<Run, String>) -> Result<(Run, f64), String> {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..runs.max(1) {
        let start = thread_cpu_seconds();
        let run = f()?;
        let cpu = thread_cpu_seconds() - start;
        best = best.min(cpu);
        last = Some(run);
        if cpu > 0.5 {
            break;
        }
    }
    Ok((last.unwrap(), best))
}

/// The (error, cpu) points no other point beats on both, error ascending, cpu descending.
fn pareto(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut sorted = points.to_vec();
    sorted.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let mut front: Vec<(f64, f64)> = Vec::new();
    for (err, cpu) in sorted {
        if front.last().is_none_or(|&(_, c)| cpu < c) {
            front.push((err.max(1e-300), cpu));
        }
    }
    front
}

/// CPU time to reach max error `level` along a curve, log-log interpolated between runs, as
/// in fmu_tests/work_precision.py; "<=" when the loosest run is already more accurate.
fn cost_at(points: &[(f64, f64)], level: f64) -> Option<(f64, &'static str)> {
    let front = pareto(points);
    let (first, last) = (front.first()?, front.last()?);
    if level < first.0 {
        return None;
    }
    if level >= last.0 {
        return Some((last.1, "<="));
    }
    front.windows(2).find(|w| w[0].0 <= level && level <= w[1].0).map(|w| {
        let ((e0, c0), (e1, c1)) = (w[0], w[1]);
        let s = (level.ln() - e0.ln()) / (e1.ln() - e0.ln());
        ((c0.ln() + s * (c1.ln() - c0.ln())).exp(), "=")
    })
}

fn main() -> Result<(), String> {
    let mut seconds = 1.0;
    let mut runs = 3;
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or_else(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--seconds" => seconds = value.parse().map_err(|e| format!("--seconds {value}: {e}"))?,
            "--runs" => runs = value.parse().map_err(|e| format!("--runs {value}: {e}"))?,
            _ => return Err(format!("unknown option {flag}")),
        }
    }
    let samples = (seconds / SAMPLE_PERIOD).round() as usize;
    let model = Actuator::new(Parameters::default())?;
    let (v0, x0) = scenario::standard_inputs(0);
    let start = |rtol| Simulation::at_equilibrium(model.clone(), v0, x0, 0.0, rtol);

    println!("first {seconds} s of the standard scenario; error = max |F_act - F_ref| at the 10 ms instants");
    println!("load average (before): {}", load());
    let (reference, ref_cpu) = timed(1, || run_jetpipe(&start(1e-10)?, samples, 100))?;
    println!("reference: jetpipe Simulation, rtol 1e-10, 0.1 ms communication steps ({ref_cpu:.3} s CPU)\n");
    let y0 = *start(1e-10)?.state();

    let methods = [
        Method::Jetpipe,
        Method::JetpipeSdirk4,
        Method::Bdf,
        Method::TrBdf2,
        Method::Esdirk34,
    ];
    let mut curves: Vec<Vec<(f64, f64)>> = vec![Vec::new(); methods.len()];
    println!(
        "{:<24} {:>6} {:>10} {:>10} {:>7} {:>8} {:>6}",
        "method", "rtol", "max|dF| N", "CPU s", "steps", "RHS", "jac"
    );
    for (m, &method) in methods.iter().enumerate() {
        for rtol in TOLERANCES {
            let result = if method == Method::Jetpipe || method == Method::JetpipeSdirk4 {
                // Each tolerance starts from its own equilibrium solve, outside the clock.
                let mut initial = start(rtol)?;
                if method == Method::JetpipeSdirk4 {
                    initial.set_chamber_method(ChamberMethod::Sdirk4);
                }
                timed(runs, || run_jetpipe(&initial, samples, 1))
            } else {
                timed(runs, || run_diffsol(&model, &y0, samples, rtol, method))
            };
            match result {
                Ok((run, cpu)) => {
                    let err = run
                        .forces
                        .iter()
                        .zip(&reference.forces)
                        .map(|(a, b)| (a - b).abs())
                        .fold(0.0, f64::max);
                    curves[m].push((err, cpu));
                    println!(
                        "{:<24} {rtol:>6.0e} {err:>10.2e} {cpu:>10.4} {:>7} {:>8} {:>6}",
                        method.name(),
                        run.steps,
                        run.rhs,
                        run.jacobians
                    );
                }
                Err(e) => println!("{:<24} {rtol:>6.0e} failed: {e}", method.name()),
            }
        }
    }

    println!("\nCPU time at equal accuracy (log-log interpolation; '<=' the loosest run already reaches it)");
    print!("{:>10}", "max|dF| N");
    for method in &methods {
        print!(" {:>24}", method.name());
    }
    println!(" {:>22}", "best diffsol / jetpipe");
    for level in ERROR_LEVELS {
        print!("{level:>10.0e}");
        let costs: Vec<_> = curves.iter().map(|c| cost_at(c, level)).collect();
        for cost in &costs {
            match cost {
                Some((c, how)) => print!(" {:>24}", format!("{}{c:.4}", if *how == "=" { "" } else { how })),
                None => print!(" {:>24}", "n/a"),
            }
        }
        let best = costs[2..].iter().flatten().min_by(|a, b| a.0.total_cmp(&b.0));
        match (costs[0], best) {
            (Some((ours, ours_how)), Some(&(theirs, their_how))) => {
                // An upper bound on one cost is a bound on the ratio.
                let bound = match (ours_how, their_how) {
                    ("<=", "=") => ">=",
                    ("=", "<=") => "<=",
                    _ => "~",
                };
                println!(" {:>22}", format!("{bound}{:.1}x", theirs / ours));
            }
            _ => println!(" {:>22}", "n/a"),
        }
    }
    println!("load average (after): {}", load());
    Ok(())
}
