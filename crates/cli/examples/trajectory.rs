//! The force of the standard scenario at its 10 ms sample instants, with the in-process CPU
//! time of the run, for `fmu_tests/work_precision.py` (issue 6):
//!
//!     cargo run --release --example trajectory -- --rtol 1e-6 [--seconds 1] [--step 0.01] [--runs 5] [--monolithic]
//!
//! Prints `# initial_state` (the six states at t = 0), `# cpu_seconds <best of runs>`, `# steps ...`, `# rhs_evaluations ...` and then
//! the CSV `time_s,F_act_N` (t = 0 and every 10 ms up to `--seconds`). The CPU time is the
//! thread's own and excludes the equilibrium start, as SciPy's in the script starts from
//! the given state; `--step` below 10 ms divides each sample into communication steps (the
//! inputs stay held), which a tight reference run uses.

use jetpipe_model::scenario;
use jetpipe_model::simulation::{Method, Simulation};

#[path = "../benches/common/scenarios.rs"]
mod scenarios;

struct Options {
    rtol: f64,
    seconds: f64,
    step: f64,
    runs: usize,
    monolithic: bool,
}

fn parse() -> Result<Options, String> {
    let mut o = Options {
        rtol: 1e-6,
        seconds: 1.0,
        step: scenario::SAMPLE_PERIOD,
        runs: 5,
        monolithic: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(flag) = args.next() {
        if flag == "--monolithic" {
            o.monolithic = true;
            continue;
        }
        let value = args.next().ok_or_else(|| format!("{flag} needs a value"))?;
        let number = |what: &str| value.parse::<f64>().map_err(|e| format!("{flag} {value}: {what}: {e}"));
        match flag.as_str() {
            "--rtol" => o.rtol = number("expected a number")?,
            "--seconds" => o.seconds = number("expected a number")?,
            "--step" => o.step = number("expected a number")?,
            "--runs" => o.runs = number("expected a count")? as usize,
            _ => return Err(format!("unknown option {flag}")),
        }
    }
    if !(o.rtol > 0.0 && o.rtol < 1.0) {
        return Err(format!("--rtol {} must be in (0, 1)", o.rtol));
    }
    if !(o.seconds > 0.0 && o.seconds <= scenario::DURATION) {
        return Err(format!(
            "--seconds {} must be in (0, {}]",
            o.seconds,
            scenario::DURATION
        ));
    }
    if !(o.step > 0.0 && o.step <= scenario::SAMPLE_PERIOD) {
        return Err(format!("--step {} must be in (0, {}]", o.step, scenario::SAMPLE_PERIOD));
    }
    o.runs = o.runs.max(1);
    Ok(o)
}

fn main() -> Result<(), String> {
    let o = parse()?;
    let samples = (o.seconds / scenario::SAMPLE_PERIOD).round() as usize;
    let substeps = (scenario::SAMPLE_PERIOD / o.step).round().max(1.0) as usize;
    let h = scenario::SAMPLE_PERIOD / substeps as f64;
    let (v0, x0) = scenario::standard_inputs(0);
    let mut initial = Simulation::at_equilibrium(scenarios::thesis_model(), v0, x0, 0.0, o.rtol)?;
    if o.monolithic {
        initial.set_method(Method::Monolithic);
    }
    let mut best = f64::INFINITY;
    let mut forces = Vec::with_capacity(samples + 1);
    let mut work = initial.statistics();
    for _ in 0..o.runs {
        let mut sim = initial.clone();
        forces.clear();
        forces.push(sim.outputs().f_act);
        let start = scenarios::thread_cpu_seconds();
        for k in 0..samples {
            let (v, x) = scenario::standard_inputs(k);
            sim.set_command(v)?;
            sim.set_stopper(x)?;
            for _ in 0..substeps {
                sim.step(h).map_err(|e| format!("{e:?}"))?;
            }
            forces.push(sim.outputs().f_act);
        }
        best = best.min(scenarios::thread_cpu_seconds() - start);
        work = scenarios::work_between(&initial.statistics(), &sim.statistics());
    }
    // The start state, for an independent integrator to start from the same equilibrium.
    let y0: Vec<String> = initial.state().iter().map(|v| format!("{v:.17e}")).collect();
    let mut out = format!(
        "# initial_state {}\n# cpu_seconds {best:e}\n# runs {}\n# steps {}\n# rejected {}\n# rhs_evaluations {}\n# jacobians {}\ntime_s,F_act_N\n",
        y0.join(" "),
        o.runs,
        work.steps, work.rejected, work.rhs_evaluations, work.jacobians
    );
    for (k, f) in forces.iter().enumerate() {
        out.push_str(&format!("{},{f:.17e}\n", k as f64 * scenario::SAMPLE_PERIOD));
    }
    print!("{out}");
    Ok(())
}
