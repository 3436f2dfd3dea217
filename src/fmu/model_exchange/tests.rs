//! Model Exchange's hysteresis memory against Co-Simulation's: the same instance type driven
//! through both interfaces' traits, in-process.

use super::*;
use fmi2::model::CoSimModel;

/// presets/thesis_measured.json, read as the FMU's start values (the hysteresis there is the
/// Bouc–Wen law of exponent 20).
fn preset() -> Vec<(u32, f64)> {
    let text = include_str!("../../../presets/thesis_measured.json");
    text.lines()
        .filter_map(|line| {
            let (name, value) = line.trim().trim_end_matches(',').split_once(':')?;
            let name = name.trim().trim_matches('"');
            let v = jetpipe_model::VARIABLES.iter().find(|v| v.name == name)?;
            Some((v.value_reference, value.trim().parse().ok()?))
        })
        .collect()
}

/// An initialised instance of `interface` with `parameters`, at the equilibrium of `v_da`.
fn initialised(model_exchange: bool, parameters: &[(u32, f64)], v_da: f64) -> ActuatorFmu {
    let mut fmu = ActuatorFmu::instantiate();
    if model_exchange {
        fmu.use_model_exchange();
    }
    for &(r, v) in parameters {
        fmu.set_real(r, v).unwrap();
    }
    fmu.setup_experiment(Some(1e-8), 0.0, None).unwrap();
    fmu.set_real(vr::V_DA, v_da).unwrap();
    fmu.exit_initialization().unwrap();
    if model_exchange {
        fmu.new_discrete_states().unwrap();
    }
    fmu
}

/// A 40 Hz sine of ±3 V about 0.5 V sampled every `SAMPLE`, linear over each sample (what
/// Co-Simulation gets with `fmi2SetRealInputDerivatives`), with a −4 V jump at 30 ms (sample
/// `JUMP`): over sample `n`, v_DA = start + rate·(t − n `SAMPLE`).
const SAMPLE: f64 = 1e-4;
const JUMP: usize = 300;
fn segment(n: usize) -> (f64, f64) {
    let sine = |k: usize| 0.5 + 3.0 * (2.0 * std::f64::consts::PI * 40.0 * k as f64 * SAMPLE).sin();
    let jump = if n >= JUMP { -4.0 } else { 0.0 };
    (sine(n) + jump, (sine(n + 1) - sine(n)) / SAMPLE)
}
fn command(n: usize, t: f64) -> f64 {
    let (start, rate) = segment(n);
    start + rate * (t - n as f64 * SAMPLE)
}

/// When Model Exchange's hysteresis memory is advanced in [`explicit_run`].
#[derive(Clone, Copy, PartialEq)]
enum Updates {
    /// At the roots of z7 (events), at the jump (an event) and after every step.
    AsDeclared,
    /// Only every `SAMPLE` (an importer that calls nothing in between).
    EverySample,
}

/// The current and the jet pipe (the states the hysteresis acts on; the pressures do not act
/// on them) integrated by classical Runge–Kutta steps of `SAMPLE`/20 with v_DA at each
/// stage's time, the roots of z7 found by bisection: the memory's hysteresis output, and x_jp,
/// every `SAMPLE` to `t_end`.
fn explicit_run(parameters: &[(u32, f64)], t_end: f64, updates: Updates) -> Vec<(f64, f64)> {
    let mut fmu = initialised(true, parameters, command(0, 0.0));
    let h = SAMPLE / 20.0;
    let rk4 = |fmu: &mut ActuatorFmu, n: usize, t: f64, x: &[f64; STATES], h: f64| -> [f64; STATES] {
        let stage = |fmu: &mut ActuatorFmu, s: f64, y: &[f64; STATES]| {
            fmu.set_time(t + s).unwrap();
            fmu.set_real(vr::V_DA, command(n, t + s)).unwrap();
            fmu.set_continuous_states(y).unwrap();
            let mut d = [0.0; STATES];
            fmu.derivatives(&mut d).unwrap();
            d
        };
        let along = |k: &[f64; STATES], a: f64| {
            let mut y = *x;
            (0..4).for_each(|j| y[j] += a * k[j]);
            y
        };
        let k1 = stage(fmu, 0.0, x);
        let k2 = stage(fmu, 0.5 * h, &along(&k1, 0.5 * h));
        let k3 = stage(fmu, 0.5 * h, &along(&k2, 0.5 * h));
        let k4 = stage(fmu, h, &along(&k3, h));
        let mut y = *x;
        (0..4).for_each(|j| y[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]));
        y
    };
    let z7 = |fmu: &mut ActuatorFmu, n: usize, t: f64, x: &[f64; STATES]| {
        fmu.set_time(t).unwrap();
        fmu.set_real(vr::V_DA, command(n, t)).unwrap();
        fmu.set_continuous_states(x).unwrap();
        let mut z = [0.0; EVENT_INDICATORS];
        fmu.event_indicators(&mut z).unwrap();
        z[7]
    };
    let mut x = [0.0; STATES];
    fmu.continuous_states(&mut x).unwrap();
    let (mut t, mut out) = (0.0, vec![]);
    let samples = (t_end / SAMPLE).round() as usize;
    for n in 0..samples {
        let until = (n + 1) as f64 * SAMPLE;
        if n == JUMP && updates == Updates::AsDeclared {
            // the jump of the command: an input event
            fmu.set_real(vr::V_DA, command(n, t)).unwrap();
            fmu.new_discrete_states().unwrap();
        }
        while t < until - 1e-15 {
            let step = h.min(until - t);
            let before = z7(&mut fmu, n, t, &x);
            let mut next = rk4(&mut fmu, n, t, &x, step);
            let mut reached = t + step;
            if updates == Updates::AsDeclared && before * z7(&mut fmu, n, reached, &next) < 0.0 {
                // the root of z7 within the step, and the state just past it: an event
                let (mut lo, mut hi) = (0.0, step);
                while hi - lo > 1e-13 {
                    let mid = 0.5 * (lo + hi);
                    let at = rk4(&mut fmu, n, t, &x, mid);
                    if before * z7(&mut fmu, n, t + mid, &at) < 0.0 {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                next = rk4(&mut fmu, n, t, &x, hi);
                reached = t + hi;
                fmu.set_continuous_states(&next).unwrap();
                fmu.new_discrete_states().unwrap();
            }
            t = reached;
            x = next;
            fmu.set_time(t).unwrap();
            fmu.set_real(vr::V_DA, command(n, t)).unwrap();
            fmu.set_continuous_states(&x).unwrap();
            if updates == Updates::AsDeclared || (until - t).abs() < 1e-15 {
                fmu.completed_integrator_step().unwrap();
            }
        }
        let me = fmu.me.as_ref().unwrap();
        out.push((me.model.hysteresis.output(&me.memory.unwrap()), x[index::JET_POSITION]));
    }
    out
}

/// Co-Simulation of the same command, linear over each step: the memory's hysteresis output
/// and x_jp at each communication point.
fn co_simulation_run(parameters: &[(u32, f64)], t_end: f64) -> Vec<(f64, f64)> {
    let mut fmu = initialised(false, parameters, command(0, 0.0));
    let mut out = vec![];
    let samples = (t_end / SAMPLE).round() as usize;
    for n in 0..samples {
        let t = n as f64 * SAMPLE;
        let (start, rate) = segment(n);
        fmu.set_real(vr::V_DA, start).unwrap();
        fmu.set_real_input_derivative(vr::V_DA, 1, rate).unwrap();
        fmu.do_step(t, SAMPLE).unwrap();
        let s = fmu.simulation().unwrap();
        let memory = s.hysteresis_memory().unwrap();
        out.push((s.model().hysteresis.output(&memory), s.state()[index::JET_POSITION]));
    }
    out
}

fn largest_difference(a: &[(f64, f64)], b: &[(f64, f64)]) -> (f64, f64) {
    a.iter().zip(b).fold((0.0, 0.0), |(m0, m1), (p, q)| {
        (m0.max((p.0 - q.0).abs()), m1.max((p.1 - q.1).abs()))
    })
}

#[test]
fn the_memory_advanced_at_the_current_s_reversals_follows_co_simulation_s_through_a_sine_and_a_jump() {
    let preset = preset();
    assert!(
        preset.iter().any(|&(r, v)| r == vr::HYSTERESIS_EXPONENT && v > 0.0),
        "{preset:?}"
    );
    let t_end = 0.06;
    let cs = co_simulation_run(&preset, t_end);
    let me = explicit_run(&preset, t_end, Updates::AsDeclared);
    let coarse = explicit_run(&preset, t_end, Updates::EverySample);
    let (output, position) = largest_difference(&cs, &me);
    let (coarse_output, _) = largest_difference(&cs, &coarse);
    println!(
        "hysteresis output, ME - CS: {output:.2e} m as declared, {coarse_output:.2e} m advanced every sample; x_jp {position:.2e} m"
    );
    // the loop is 0.16 mm wide: both follow it to a millionth of its width
    let span =
        cs.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max) - cs.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    assert!(span > 0.16e-3, "the command sweeps the loop: {span} m");
    assert!(output < 1e-10 && position < 1e-10, "{output:e} m, {position:e} m");
    // a memory advanced only every sample misses the reversals within one, by far more
    assert!(
        coarse_output > 20.0 * output.max(1e-12),
        "{coarse_output:e} m against {output:e} m"
    );
}

#[test]
fn z7_is_the_current_s_approach_to_its_static_value_with_the_hysteresis_and_one_without() {
    for (parameters, hysteretic) in [(preset(), true), (vec![], false)] {
        let mut fmu = initialised(true, &parameters, 2.5);
        let mut x = [0.0; STATES];
        fmu.continuous_states(&mut x).unwrap();
        for (v_da, sign) in [(4.0, 1.0), (1.0, -1.0)] {
            fmu.set_real(vr::V_DA, v_da).unwrap();
            let mut z = [0.0; EVENT_INDICATORS];
            fmu.event_indicators(&mut z).unwrap();
            let mut dx = [0.0; STATES];
            fmu.derivatives(&mut dx).unwrap();
            if hysteretic {
                assert_eq!(z[7].signum(), sign);
                assert_eq!(z[7].signum(), dx[index::CURRENT].signum());
                assert!((z[7] * 7050.0 - dx[index::CURRENT]).abs() < 1e-9 * dx[index::CURRENT].abs());
            } else {
                assert_eq!(z[7], 1.0);
            }
        }
    }
}

#[test]
fn fmu_states_carry_the_hysteresis_memory_and_a_restored_instance_continues_bit_identically() {
    let mut fmu = initialised(true, &preset(), 2.5);
    let mut x = [0.0; STATES];
    fmu.continuous_states(&mut x).unwrap();
    // the current pushed up and the memory advanced there: away from where it started
    x[index::CURRENT] += 0.03;
    fmu.set_continuous_states(&x).unwrap();
    fmu.completed_integrator_step().unwrap();
    let started = initialised(true, &preset(), 2.5).me.unwrap().memory.unwrap();
    let memory = fmu.me.as_ref().unwrap().memory.unwrap();
    assert_ne!(memory, started);
    let bytes = fmu.serialize();
    let mut restored = initialised(true, &[], 2.5);
    restored.deserialize(&bytes).unwrap();
    assert_eq!(restored.me.as_ref().unwrap().memory, Some(memory));
    x[index::CURRENT] -= 0.05;
    let mut d = ([0.0; STATES], [0.0; STATES]);
    for (f, d) in [(&mut fmu, &mut d.0), (&mut restored, &mut d.1)] {
        f.set_continuous_states(&x).unwrap();
        f.derivatives(d).unwrap();
    }
    assert_eq!(d.0, d.1);
}

#[test]
fn a_rigid_stoppers_cached_factors_give_the_general_conversions_and_rates() {
    let model = Actuator::new(Parameters::default()).unwrap();
    let x = State::from([0.1, 1e-4, 0.02, -30.0, 4.2e5, 1.7e5]);
    let nodes = [0.0; node::STATES];
    let filters = [0.0; filters::STATES];
    let chain = [0.0; PADE_SECTIONS];
    for x_s in [0.03, 0.054, 0.061, 0.09] {
        let scale = AirScale::at(&model, x_s);
        assert!(matches!(scale, AirScale::Rigid(_)), "{scale:?}");
        let general = air_states(&model, &x, &nodes, x_s, AirScale::PistonMoves);
        assert_eq!(air_states(&model, &x, &nodes, x_s, scale), general, "x_s {x_s}");
        let back = pressures_of_air(&model, general, &nodes, x_s, scale);
        let back_general = pressures_of_air(&model, general, &nodes, x_s, AirScale::PistonMoves);
        for k in 0..2 {
            let p = x[index::P1 + k];
            assert!(
                (back[k] - back_general[k]).abs() <= 4.0 * f64::EPSILON * p,
                "x_s {x_s}: {back:?} {back_general:?}"
            );
            assert!(
                (back[k] - p).abs() <= 8.0 * f64::EPSILON * p,
                "x_s {x_s}: {back:?} for {p}"
            );
        }
        let at = |scale| At {
            model: &model,
            x: &x,
            nodes: &nodes,
            filters: &filters,
            chain: &chain,
            sections: 0,
            v_da: 3.0,
            x_s,
            scale,
            time: 0.0,
            memory: None,
        };
        assert_eq!(rates(&at(scale)), rates(&at(AirScale::PistonMoves)), "x_s {x_s}");
    }
    let compliant = Actuator::new(Parameters {
        stopper_compliance: 1e-5,
        ..Parameters::default()
    })
    .unwrap();
    assert_eq!(AirScale::at(&compliant, 0.054), AirScale::PistonMoves);
}
