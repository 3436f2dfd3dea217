//! The benchmark scenarios (issue 6), shared by `benches/core.rs` (criterion, time only) and
//! `examples/perf_report.rs` (CPU time, work counters, memory): both must time exactly the
//! same runs, so the definitions live here once. Included with `#[path]`; this directory has
//! no `main.rs`, so cargo does not take it for a bench target of its own.
//!
//! Each scenario is 10 s of simulated time at relative tolerance 1e-6, driven through the
//! public API of [`Simulation`] only (`at_equilibrium`, `set_*`, `step`, `outputs`,
//! `statistics`), so that changes to the integration internals do not break it:
//!
//! 1. `standard`: the standard scenario of `src/scenario.rs` (inputs held every 10 ms).
//! 2. `ramps`: open-loop ramps given as input derivatives every 10 ms (the FMU's
//!    `fmi2SetRealInputDerivatives` path): v_DA 0→5 V in 2 s, held 1 s, 5→0 V in 2 s,
//!    0→2.5 V in 1 s; then at 2.5 V the stopper 54→70 mm in 2 s and back in 2 s.
//! 3. `chirp`: v_DA = 2.5 + 1.5 sin φ(t), instantaneous frequency φ'/2π rising linearly
//!    from 0.1 Hz to 20 Hz over the 10 s, sampled and held every 1 ms (10 ms would leave
//!    five samples per period at 20 Hz); stopper fixed at 54 mm.
//! 4. `closed_loop`: the 500 Hz proportional force loop of docs/validation.md §7–8 with the
//!    inverse-static feedforward: every 2 ms read F_meas, set
//!    v_DA = clip(v_ff(F_ref) + (k_p/k_cd)(F_ref − F_meas), ±10 V) with k_p = 0.044 A/N
//!    (§4.1.1; 1.1 V/N with k_cd = 0.04 A/V), hold it for the 2 ms step. F_ref: steps every
//!    0.5 s between 20 and 70 N for 5 s, then 45 + 10 sin(2π·5 Hz·t) N. Stopper at 54 mm.
#![allow(dead_code)]

use std::f64::consts::PI;

use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::scenario;
use jetpipe_model::simulation::Simulation;
use jetpipe_model::Statistics;

/// Simulated time of every scenario, s.
pub const DURATION: f64 = 10.0;
/// The relative tolerance the targets are stated at.
pub const RELATIVE_TOLERANCE: f64 = 1e-6;
/// The speed target of issue 6: 10 s of any scenario in under 10 ms of CPU time at 1e-6.
pub const TARGET_CPU_SECONDS: f64 = 0.010;

/// Stopper position where it is held fixed, m.
const X_S_MID: f64 = 0.054;
/// Proportional gain of the force loop, A/N (thesis §4.1.1, docs/validation.md §7).
pub const K_P: f64 = 0.044;
/// Command limits of the D/A, V.
const V_LIMIT: f64 = 10.0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scenario {
    Standard,
    Ramps,
    Chirp,
    ClosedLoop,
}

impl Scenario {
    pub const ALL: [Scenario; 4] = [
        Scenario::Standard,
        Scenario::Ramps,
        Scenario::Chirp,
        Scenario::ClosedLoop,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Scenario::Standard => "standard",
            Scenario::Ramps => "ramps",
            Scenario::Chirp => "chirp",
            Scenario::ClosedLoop => "closed_loop",
        }
    }

    pub fn description(self) -> &'static str {
        match self {
            Scenario::Standard => "standard scenario, inputs held every 10 ms",
            Scenario::Ramps => "v_DA and stopper ramps as input derivatives, every 10 ms",
            Scenario::Chirp => "v_DA chirp 0.1-20 Hz, held every 1 ms",
            Scenario::ClosedLoop => "500 Hz P + feedforward force loop, steps and 5 Hz sine",
        }
    }

    /// Communication step, s.
    pub fn communication_step(self) -> f64 {
        match self {
            Scenario::Standard => scenario::SAMPLE_PERIOD,
            Scenario::Ramps => 0.01,
            Scenario::Chirp => 0.001,
            Scenario::ClosedLoop => 0.002,
        }
    }

    /// Number of communication steps in [`DURATION`].
    pub fn steps(self) -> usize {
        (DURATION / self.communication_step()).round() as usize
    }

    /// Inputs (v_DA, x_s) the simulation starts at equilibrium with.
    fn initial_inputs(self, feedforward: Option<&Feedforward>) -> (f64, f64) {
        match self {
            Scenario::Standard => scenario::standard_inputs(0),
            Scenario::Ramps => {
                let (v, _, x, _) = ramp_inputs(0.0);
                (v, x)
            }
            Scenario::Chirp => (chirp_command(0.0), X_S_MID),
            Scenario::ClosedLoop => (feedforward.map_or(0.0, |ff| ff.command(force_reference(0.0))), X_S_MID),
        }
    }
}

/// The thesis model with default parameters.
pub fn thesis_model() -> Actuator {
    Actuator::new(Parameters::default()).expect("the default parameters are valid")
}

/// Everything a run needs that is computed before the clock starts: the simulation at the
/// equilibrium of the first inputs, and for the closed loop the feedforward table.
#[derive(Clone, Debug)]
pub struct Prepared {
    pub scenario: Scenario,
    pub initial: Simulation,
    feedforward: Option<Feedforward>,
}

impl Prepared {
    pub fn new(scenario: Scenario, model: &Actuator, relative_tolerance: f64) -> Result<Self, String> {
        let feedforward = match scenario {
            Scenario::ClosedLoop => Some(Feedforward::new(model, X_S_MID)?),
            _ => None,
        };
        let initial = Self::initial_simulation(scenario, model, feedforward.as_ref(), relative_tolerance)?;
        Ok(Self {
            scenario,
            initial,
            feedforward,
        })
    }

    fn initial_simulation(
        scenario: Scenario,
        model: &Actuator,
        feedforward: Option<&Feedforward>,
        relative_tolerance: f64,
    ) -> Result<Simulation, String> {
        let (v, x) = scenario.initial_inputs(feedforward);
        Simulation::at_equilibrium(model.clone(), v, x, 0.0, relative_tolerance)
    }

    /// A fresh simulation at the start of the scenario, built as `initial` was (for
    /// measuring what one instance costs to set up).
    pub fn fresh_simulation(&self, model: &Actuator) -> Result<Simulation, String> {
        Self::initial_simulation(
            self.scenario,
            model,
            self.feedforward.as_ref(),
            self.initial.relative_tolerance(),
        )
    }

    /// Run the whole scenario on a copy of the initial simulation; returns it at the end.
    pub fn run(&self) -> Result<Simulation, String> {
        let mut sim = self.initial.clone();
        self.run_on(&mut sim, |_| {})?;
        Ok(sim)
    }

    /// Drive `sim` (at the scenario's start) through the scenario, calling `observe` after
    /// every communication step.
    pub fn run_on(&self, sim: &mut Simulation, mut observe: impl FnMut(&Simulation)) -> Result<(), String> {
        let h = self.scenario.communication_step();
        let step = |sim: &mut Simulation| sim.step(h).map_err(|e| format!("{e:?}"));
        for k in 0..self.scenario.steps() {
            // t_k from the index, never by accumulating h, so every run sees the same inputs.
            let t = k as f64 * h;
            match self.scenario {
                Scenario::Standard => {
                    let (v, x) = scenario::standard_inputs(k);
                    sim.set_command(v)?;
                    sim.set_stopper(x)?;
                }
                Scenario::Ramps => {
                    let (v, v_rate, x, x_rate) = ramp_inputs(t);
                    sim.set_command(v)?;
                    sim.set_stopper(x)?;
                    sim.set_command_rate(v_rate)?;
                    sim.set_stopper_rate(x_rate)?;
                }
                Scenario::Chirp => sim.set_command(chirp_command(t))?,
                Scenario::ClosedLoop => {
                    let feedforward = self.feedforward.as_ref().expect("prepared with the closed loop");
                    let f_ref = force_reference(t);
                    let gain = K_P / sim.model().params.k_cd;
                    let v = feedforward.command(f_ref) + gain * (f_ref - sim.outputs().f_meas);
                    sim.set_command(v.clamp(-V_LIMIT, V_LIMIT))?;
                }
            }
            step(sim)?;
            observe(sim);
        }
        Ok(())
    }
}

/// Work done by the integrator between two snapshots of its counters.
pub fn work_between(before: &Statistics, after: &Statistics) -> Statistics {
    Statistics {
        steps: after.steps - before.steps,
        rejected: after.rejected - before.rejected,
        rhs_evaluations: after.rhs_evaluations - before.rhs_evaluations,
        jacobians: after.jacobians - before.jacobians,
        newton_failures: after.newton_failures - before.newton_failures,
        stiff_handovers: after.stiff_handovers - before.stiff_handovers,
    }
}

/// Ramp scenario knots (t, v_DA, x_s); linear in between, at multiples of 10 ms so that no
/// communication step straddles a knot.
const RAMP_KNOTS: [(f64, f64, f64); 7] = [
    (0.0, 0.0, X_S_MID),
    (2.0, 5.0, X_S_MID),
    (3.0, 5.0, X_S_MID),
    (5.0, 0.0, X_S_MID),
    (6.0, 2.5, X_S_MID),
    (8.0, 2.5, 0.070),
    (10.0, 2.5, X_S_MID),
];

/// (v_DA, dv_DA/dt, x_s, dx_s/dt) of the ramp scenario at `t`, with the rates of the
/// segment that starts at or after `t`.
fn ramp_inputs(t: f64) -> (f64, f64, f64, f64) {
    let last = RAMP_KNOTS.len() - 1;
    // A tenth of a step of slack: t_k = k·h may land a rounding error short of a knot.
    let segment = (0..last).find(|&s| t < RAMP_KNOTS[s + 1].0 - 1e-3).unwrap_or(last - 1);
    let (t0, v0, x0) = RAMP_KNOTS[segment];
    let (t1, v1, x1) = RAMP_KNOTS[segment + 1];
    let (v_rate, x_rate) = ((v1 - v0) / (t1 - t0), (x1 - x0) / (t1 - t0));
    let s = (t - t0).max(0.0);
    (v0 + v_rate * s, v_rate, x0 + x_rate * s, x_rate)
}

/// The chirp command: frequency 0.1 → 20 Hz linearly over [`DURATION`], so the phase is
/// 2π(f0 t + (f1 − f0) t²/(2T)).
fn chirp_command(t: f64) -> f64 {
    let (f0, f1) = (0.1, 20.0);
    let phase = 2.0 * PI * (f0 * t + (f1 - f0) * t * t / (2.0 * DURATION));
    2.5 + 1.5 * phase.sin()
}

/// Force reference of the closed loop, N: a staircase of 0.5 s steps, then a 5 Hz sine.
fn force_reference(t: f64) -> f64 {
    const LEVELS: [f64; 10] = [45.0, 30.0, 60.0, 40.0, 50.0, 20.0, 70.0, 45.0, 35.0, 55.0];
    if t < 5.0 {
        LEVELS[((t / 0.5 + 1e-9) as usize).min(LEVELS.len() - 1)]
    } else {
        45.0 + 10.0 * (2.0 * PI * 5.0 * (t - 5.0)).sin()
    }
}

/// The inverse static curve v_DA(F) of the model at one stopper position: the static force
/// at a grid of commands, inverted by linear interpolation (docs/validation.md §8 does the
/// same with currents). Built once, before any timing.
#[derive(Clone, Debug)]
struct Feedforward {
    /// (static force, command), force strictly increasing.
    table: Vec<(f64, f64)>,
}

impl Feedforward {
    fn new(model: &Actuator, x_s: f64) -> Result<Self, String> {
        let mut table: Vec<(f64, f64)> = Vec::new();
        // -1..8 V in 0.1 V steps covers the spring floor up to the saturated force.
        for j in 0..=90 {
            let v = -1.0 + 0.1 * j as f64;
            let f = Simulation::at_equilibrium(model.clone(), v, x_s, 0.0, RELATIVE_TOLERANCE)?
                .outputs()
                .f_act;
            // Keep the strictly rising part only: on the spring floor F does not depend on v.
            if table.last().is_none_or(|&(f_last, _)| f > f_last + 1e-9) {
                table.push((f, v));
            }
        }
        if table.len() < 2 {
            return Err("the static force curve does not rise with the command".into());
        }
        Ok(Self { table })
    }

    /// The command whose static force is `force` (clamped to the table's ends).
    fn command(&self, force: f64) -> f64 {
        let t = &self.table;
        let j = t.partition_point(|&(f, _)| f < force).clamp(1, t.len() - 1);
        let ((f0, v0), (f1, v1)) = (t[j - 1], t[j]);
        let s = ((force - f0) / (f1 - f0)).clamp(0.0, 1.0);
        v0 + s * (v1 - v0)
    }
}

/// CPU time of the calling thread, s: the simulation is single-threaded, and unlike wall
/// time this does not count the time other processes on the machine take from it.
pub fn thread_cpu_seconds() -> f64 {
    jetpipe_cli::sweep::thread_cpu_seconds().expect("a thread CPU clock (clock_gettime) on this platform")
}
