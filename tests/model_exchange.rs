//! Issue 44: the actuator through the exported Model Exchange symbols. Its derivatives are the
//! model's own (also with gas volumes behind restrictions and a lagging stopper mount), an
//! explicit integration of them follows the Co-Simulation step, a stopper moved in event mode
//! jumps the pressures as in Co-Simulation, the effects with a memory are refused with their
//! names, and FMU states keep the interface and the states.

#[path = "common/mod.rs"]
mod common;

use std::ptr::{null, null_mut};

use common::*;
use fmi2::state::State;
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::{me_vr, vr};
use jetpipe_model::physics::actuator::{Actuator, Inputs, State as ModelState};
use jetpipe_model::physics::parameters::Parameters;

const NX: usize = 31;
const NZ: usize = 8;

unsafe fn states(c: fmi2Component) -> [f64; NX] {
    let mut x = [f64::NAN; NX];
    assert_eq!(fmi2GetContinuousStates(c, x.as_mut_ptr(), NX), fmi2OK);
    x
}

unsafe fn derivatives(c: fmi2Component) -> [f64; NX] {
    let mut dx = [f64::NAN; NX];
    assert_eq!(fmi2GetDerivatives(c, dx.as_mut_ptr(), NX), fmi2OK);
    dx
}

/// One classical Runge–Kutta step of `h` from `t` of the states `x` at the rates `rate`.
fn runge_kutta_step(x: &mut [f64; NX], t: f64, h: f64, rate: impl Fn(f64, &[f64; NX]) -> [f64; NX]) {
    let along = |k: &[f64; NX], s: f64| {
        let mut y = *x;
        for i in 0..NX {
            y[i] += s * k[i];
        }
        y
    };
    let k1 = rate(t, x);
    let k2 = rate(t + h / 2.0, &along(&k1, h / 2.0));
    let k3 = rate(t + h / 2.0, &along(&k2, h / 2.0));
    let k4 = rate(t + h, &along(&k3, h));
    for i in 0..NX {
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

/// A Model Exchange instance initialised at the equilibrium of `v_da`, `x_s`, in
/// continuous-time mode.
unsafe fn running(sink: &Sink, v_da: f64, x_s: f64) -> fmi2Component {
    let c = instantiate_model_exchange(sink, "me");
    initialise(c, None, &[], v_da, x_s);
    assert_eq!(layer_state(c), State::EventMode);
    let mut info = fmi2EventInfo::default();
    assert_eq!(fmi2NewDiscreteStates(c, &mut info), fmi2OK);
    assert_eq!(info, fmi2EventInfo::default(), "nothing happens at the start");
    assert_eq!(fmi2EnterContinuousTimeMode(c), fmi2OK);
    assert_eq!(layer_state(c), State::ContinuousTimeMode);
    c
}

fn last_error(sink: &Sink, from: usize) -> String {
    sink.since(from)
        .into_iter()
        .rev()
        .find(|m| m.status == fmi2Error)
        .map(|m| m.message)
        .unwrap_or_default()
}

#[test]
fn the_states_start_at_the_co_simulations_equilibrium_and_the_derivatives_are_the_models() {
    let sink = Sink::default();
    unsafe {
        let c = running(&sink, 2.5, 0.054);
        let cs = instantiate(&sink, "cs");
        initialise(cs, None, &[], 2.5, 0.054);
        let x = states(c);
        let (_, y) = get_reals(cs, &[vr::I, vr::X_JP, vr::P1, vr::P2]);
        let (_, pressures) = get_reals(c, &[vr::P1, vr::P2]);
        assert_eq!([x[0], x[1], pressures[0], pressures[1]], [y[0], y[1], y[2], y[3]]);
        // the chambers' states are their air at mid-stroke (x_s = 61 mm): P (V/V_mid)^1.4,
        // chamber 1 at 28 mm of its 35 mm there, chamber 2 at 42 mm of 35
        let air = [y[2] * (28.0f64 / 35.0).powf(1.4), y[3] * (42.0f64 / 35.0).powf(1.4)];
        assert!(
            (x[4] / air[0] - 1.0).abs() < 1e-12 && (x[5] / air[1] - 1.0).abs() < 1e-12,
            "{x:?} vs {air:?}"
        );
        // at rest: every rate vanishes (the pressures' to the equilibrium solver's tolerance)
        let dx = derivatives(c);
        assert!(dx[..4].iter().all(|d| d.abs() < 1e-9), "{dx:?}");
        assert!(dx[4].abs() < 1.0 && dx[5].abs() < 1.0, "{dx:?}");
        // without volumes, a lagging mount, lags, filters or Padé chain the twenty-five states beyond the
        // six stay put
        assert_eq!(dx[6..], [0.0; 25]);
        // away from rest: Actuator::derivatives itself, at the pressures of the air set, the
        // air's rates those of the pressures scaled to mid-stroke (the stopper held)
        let moved = [0.12, 1.5e-4, 0.02, -30.0, 4.1e5, 1.9e5];
        let mut all = x;
        all[..6].copy_from_slice(&moved);
        let scale = [(28.0f64 / 35.0).powf(1.4), (42.0f64 / 35.0).powf(1.4)];
        let mut at_pressures = moved;
        at_pressures[4] /= scale[0];
        at_pressures[5] /= scale[1];
        assert_eq!(fmi2SetContinuousStates(c, all.as_ptr(), NX), fmi2OK);
        let v_da = 3.0;
        assert_eq!(fmi2SetReal(c, &vr::V_DA, 1, &v_da), fmi2OK);
        let model = Actuator::new(Parameters::default()).unwrap();
        let expected = model.derivatives(
            &ModelState::from(at_pressures),
            &Inputs {
                v_da,
                x_s: 0.054,
                x_s_rate: 0.0,
                plays: None,
            },
        );
        let dx = derivatives(c);
        let (_, pressures) = get_reals(c, &[vr::P1, vr::P2]);
        for k in 0..2 {
            assert!(
                (pressures[k] / at_pressures[4 + k] - 1.0).abs() < 1e-12,
                "{pressures:?} vs {at_pressures:?}"
            );
            let rate = expected[4 + k] * scale[k];
            assert!(
                (dx[4 + k] - rate).abs() <= 1e-9 * rate.abs(),
                "{dx:?}: {rate} for state {}",
                4 + k
            );
        }
        assert_eq!(dx[..4].to_vec(), expected.as_slice()[..4].to_vec());
        // the derivative variables read the same
        let (_, d) = get_reals(c, &[me_vr::DER_I, me_vr::DER_P1, me_vr::X_JP_ACCELERATION]);
        assert_eq!(d, vec![expected[0], dx[4], moved[3]]);
        free(c);
        free(cs);
    }
}

#[test]
fn an_explicit_integration_of_the_derivatives_follows_the_co_simulation_step() {
    let sink = Sink::default();
    unsafe {
        let c = running(&sink, 2.5, 0.054);
        let cs = instantiate(&sink, "cs");
        initialise(cs, Some(1e-8), &[], 2.5, 0.054);
        // a command step, then 4 ms of classical Runge–Kutta at 0.5 µs through the C ABI
        assert_eq!(fmi2EnterEventMode(c), fmi2OK);
        set_inputs(c, 6.0, 0.054);
        set_inputs(cs, 6.0, 0.054);
        let mut info = fmi2EventInfo::default();
        assert_eq!(fmi2NewDiscreteStates(c, &mut info), fmi2OK);
        assert_eq!(info.valuesOfContinuousStatesChanged, fmi2False);
        assert_eq!(fmi2EnterContinuousTimeMode(c), fmi2OK);
        let h = 0.5e-6;
        let mut x = states(c);
        let rate = |t: f64, x: &[f64; NX]| {
            assert_eq!(fmi2SetTime(c, t), fmi2OK);
            assert_eq!(fmi2SetContinuousStates(c, x.as_ptr(), NX), fmi2OK);
            derivatives(c)
        };
        for n in 0..8000 {
            runge_kutta_step(&mut x, n as f64 * h, h, rate);
        }
        assert_eq!(fmi2SetContinuousStates(c, x.as_ptr(), NX), fmi2OK);
        assert_eq!(fmi2DoStep(cs, 0.0, 4e-3, fmi2True), fmi2OK);
        let (_, me) = get_reals(c, &[vr::F_ACT, vr::P1, vr::P2]);
        let (_, co) = get_reals(cs, &[vr::F_ACT, vr::P1, vr::P2]);
        assert!((me[0] - co[0]).abs() < 1e-4, "F_act {} vs {}", me[0], co[0]);
        assert!(
            (me[1] - co[1]).abs() < 1.0 && (me[2] - co[2]).abs() < 1.0,
            "{me:?} vs {co:?}"
        );
        free(c);
        free(cs);
    }
}

/// The stopper's law of the moving-stopper cases: 54 mm ± 8 mm at 20 Hz.
fn swinging_stopper(t: f64) -> f64 {
    0.054 + 0.008 * (2.0 * std::f64::consts::PI * 20.0 * t).sin()
}

#[test]
fn a_stopper_moved_continuously_in_continuous_time_mode_compresses_the_air_as_in_co_simulation() {
    let sink = Sink::default();
    // rigid, compliant (2e-5 m/N), and compliant on a mount lagging by 2 ms
    let compliant = [(vr::STOPPER_COMPLIANCE, 2e-5)];
    let lagging = [(vr::STOPPER_COMPLIANCE, 2e-5), (vr::STOPPER_MOUNT_LAG, 2e-3)];
    for params in [&[][..], &compliant[..], &lagging[..]] {
        unsafe { run_swinging(&sink, params) }
    }
}

/// [`a_stopper_moved_continuously_in_continuous_time_mode_compresses_the_air_as_in_co_simulation`] with `params`.
unsafe fn run_swinging(sink: &Sink, params: &[(u32, f64)]) {
    // Model Exchange by classical Runge–Kutta at 1 µs through the C ABI, x_s set at each
    // stage's time as an importer feeds a continuous input; Co-Simulation stepped every
    // 10 µs with x_s and its slope over the step; a third instance with the stopper held.
    let c = instantiate_model_exchange(sink, "me");
    initialise(c, None, params, 2.5, swinging_stopper(0.0));
    assert_eq!(fmi2EnterContinuousTimeMode(c), fmi2OK);
    let cs = instantiate(sink, "cs");
    initialise(cs, Some(1e-8), params, 2.5, swinging_stopper(0.0));
    let held = instantiate(sink, "held");
    initialise(held, Some(1e-8), params, 2.5, swinging_stopper(0.0));
    let h = 1e-6;
    let mut x = states(c);
    let rate = |t: f64, x: &[f64; NX]| {
        assert_eq!(fmi2SetTime(c, t), fmi2OK);
        let x_s = swinging_stopper(t);
        assert_eq!(fmi2SetReal(c, &vr::X_S, 1, &x_s), fmi2OK);
        assert_eq!(fmi2SetContinuousStates(c, x.as_ptr(), NX), fmi2OK);
        derivatives(c)
    };
    let (step, steps) = (1e-5, 1500);
    let mut largest = [0.0f64; 3];
    let mut moved_by_the_stopper = 0.0f64;
    for n in 0..steps {
        let t = n as f64 * step;
        for k in 0..10 {
            runge_kutta_step(&mut x, t + k as f64 * h, h, rate);
        }
        let slope = (swinging_stopper(t + step) - swinging_stopper(t)) / step;
        let x_s = swinging_stopper(t);
        let order = 1;
        assert_eq!(fmi2SetReal(cs, &vr::X_S, 1, &x_s), fmi2OK);
        assert_eq!(fmi2SetRealInputDerivatives(cs, &vr::X_S, 1, &order, &slope), fmi2OK);
        assert_eq!(fmi2DoStep(cs, t, step, fmi2True), fmi2OK);
        assert_eq!(fmi2DoStep(held, t, step, fmi2True), fmi2OK);
        rate(t + step, &x);
        let (_, me) = get_reals(c, &[vr::F_ACT, vr::P1, vr::P2]);
        let (_, co) = get_reals(cs, &[vr::F_ACT, vr::P1, vr::P2]);
        let (_, still) = get_reals(held, &[vr::F_ACT]);
        for k in 0..3 {
            largest[k] = largest[k].max((me[k] - co[k]).abs());
        }
        moved_by_the_stopper = moved_by_the_stopper.max((co[0] - still[0]).abs());
    }
    // 15 ms: the stopper's swing moves the force by newtons; Model Exchange follows it.
    println!("{params:?}: F_act, P1, P2 {largest:?} apart, the swing {moved_by_the_stopper} N");
    assert!(
        moved_by_the_stopper > 1.0,
        "{params:?}: the swing moves F_act by {moved_by_the_stopper} N"
    );
    assert!(largest[0] < 1e-3, "{params:?}: F_act {} N apart", largest[0]);
    assert!(largest[1] < 10.0 && largest[2] < 10.0, "{params:?}: P1, P2 {largest:?}");
    free(c);
    free(cs);
    free(held);
}

#[test]
fn a_stopper_moved_in_event_mode_jumps_the_pressures_as_in_co_simulation_and_leaves_the_states() {
    let sink = Sink::default();
    unsafe {
        let c = running(&sink, 2.5, 0.054);
        let cs = instantiate(&sink, "cs");
        initialise(cs, None, &[], 2.5, 0.054);
        assert_eq!(fmi2EnterEventMode(c), fmi2OK);
        let air = states(c);
        set_inputs(c, 2.5, 0.06);
        set_inputs(cs, 2.5, 0.06);
        let mut info = fmi2EventInfo::default();
        assert_eq!(fmi2NewDiscreteStates(c, &mut info), fmi2OK);
        assert_eq!(info.valuesOfContinuousStatesChanged, fmi2False, "the air stays");
        assert_eq!(info.newDiscreteStatesNeeded, fmi2False);
        let moved = states(c);
        for k in [4, 5] {
            assert!((moved[k] / air[k] - 1.0).abs() < 1e-14, "{moved:?} vs {air:?}");
        }
        let (me, co) = (outputs(c), outputs(cs));
        for k in 0..5 {
            assert!(
                (me[k] - co[k]).abs() <= 1e-12 * co[k].abs().max(1.0),
                "{me:?} vs {co:?}"
            );
        }
        // outside the cylinder: refused, nothing moved
        let before = states(c);
        let from = sink.len();
        assert_eq!(fmi2SetReal(c, &vr::X_S, 1, &0.2), fmi2Error);
        assert!(
            last_error(&sink, from).contains("x_s = 0.2 m"),
            "{}",
            last_error(&sink, from)
        );
        assert_eq!(states(c), before);
        free(c);
        free(cs);
    }
}

#[test]
fn an_effect_with_a_memory_is_refused_in_model_exchange_by_name_and_stays_in_co_simulation() {
    let sink = Sink::default();
    unsafe {
        for (parameter, value, effect) in [
            (vr::CURRENT_SLEW_LIMIT, 2.0, "slew limit"),
            (vr::FORCE_SENSOR_DELAY, 1e-3, "the transducers' delays"),
            (vr::FRICTION_COULOMB, 1.0, "piston_friction"),
            (vr::MODULATION_1_PARAMETER, vr::P_S as f64, "the modulation slots"),
        ] {
            let c = instantiate_model_exchange(&sink, "me");
            assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
            let from = sink.len();
            assert_eq!(fmi2SetReal(c, &parameter, 1, &value), fmi2Error);
            let e = last_error(&sink, from);
            assert!(
                e.starts_with("fmi2SetReal: ") && e.contains(effect) && e.contains("Model Exchange does not have"),
                "{e}"
            );
            // not applied: initialisation ends with the thesis model
            assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
            free(c);
            // Co-Simulation takes it
            let cs = instantiate(&sink, "cs");
            initialise(cs, None, &[(parameter, value)], 2.5, 0.054);
            assert_eq!(fmi2DoStep(cs, 0.0, 1e-3, fmi2True), fmi2OK);
            free(cs);
        }
        // a term without a memory (here a dead volume) is Model Exchange's as well
        let c = instantiate_model_exchange(&sink, "me");
        initialise(c, None, &[(vr::DEAD_VOLUME_1, 2e-6)], 2.5, 0.054);
        assert_eq!(layer_state(c), State::EventMode);
        free(c);
    }
}

#[test]
fn fmu_states_keep_the_continuous_states_and_the_interface() {
    let sink = Sink::default();
    unsafe {
        let c = running(&sink, 2.5, 0.054);
        let mut moved = states(c);
        moved[..6].copy_from_slice(&[0.11, 1.4e-4, 0.01, -20.0, 4.0e5, 2.0e5]);
        assert_eq!(fmi2SetContinuousStates(c, moved.as_ptr(), NX), fmi2OK);
        assert_eq!(fmi2SetTime(c, 0.125), fmi2OK);
        let mut p: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut p), fmi2OK);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(c, p, &mut size), fmi2OK);
        let mut bytes = vec![0 as fmi2Byte; size];
        assert_eq!(fmi2SerializeFMUstate(c, p, bytes.as_mut_ptr(), size), fmi2OK);
        // elsewhere, then back
        assert_eq!(fmi2EnterEventMode(c), fmi2OK);
        set_inputs(c, 4.0, 0.05);
        let mut q: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(c, bytes.as_ptr(), size, &mut q), fmi2OK);
        assert_eq!(fmi2SetFMUstate(c, q), fmi2OK);
        assert_eq!(layer_state(c), State::ContinuousTimeMode);
        assert_eq!(states(c), moved);
        assert_eq!(model_time(c), 0.125);
        let (_, inputs) = get_reals(c, &[vr::V_DA, vr::X_S]);
        assert_eq!(inputs, vec![2.5, 0.054]);
        // a Co-Simulation instance refuses it, and a Model Exchange instance a Co-Simulation one
        let cs = instantiate(&sink, "cs");
        let from = sink.len();
        assert_eq!(fmi2SetFMUstate(cs, q), fmi2Error);
        assert!(
            last_error(&sink, from).contains("taken from a Model Exchange instance"),
            "{}",
            last_error(&sink, from)
        );
        let mut r: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(cs, &mut r), fmi2OK);
        assert_eq!(fmi2SetFMUstate(c, r), fmi2Error);
        for mut s in [p, q, r] {
            assert_eq!(fmi2FreeFMUstate(c, &mut s), fmi2OK);
        }
        free(c);
        free(cs);
    }
}

#[test]
fn wrong_lengths_null_arrays_and_non_states_are_errors_that_change_nothing() {
    let sink = Sink::default();
    unsafe {
        let c = running(&sink, 2.5, 0.054);
        let before = states(c);
        let mut x = [0.0; NX + 1];
        let mut z = [0.0; NZ];
        let cases: [(&str, fmi2Status, &str); 7] = [
            (
                "nx",
                fmi2GetContinuousStates(c, x.as_mut_ptr(), NX + 1),
                "nx = 32, but the model description declares 31",
            ),
            (
                "ni",
                fmi2GetEventIndicators(c, z.as_mut_ptr(), NZ - 1),
                "ni = 7, but the model description declares 8",
            ),
            ("NULL", fmi2GetDerivatives(c, null_mut(), NX), "is NULL"),
            ("NULL x", fmi2SetContinuousStates(c, null(), NX), "x[] is NULL"),
            (
                "NaN",
                {
                    let mut y = before;
                    y[2] = f64::NAN;
                    fmi2SetContinuousStates(c, y.as_ptr(), NX)
                },
                "x[2] = NaN is not finite",
            ),
            (
                "P1 <= 0",
                {
                    let mut y = before;
                    y[4] = 0.0;
                    fmi2SetContinuousStates(c, y.as_ptr(), NX)
                },
                "x[4] = 0 Pa is not an absolute pressure of P1",
            ),
            ("time", fmi2SetTime(c, f64::INFINITY), "time = inf is not finite"),
        ];
        for (what, status, needle) in cases {
            assert_eq!(status, fmi2Error, "{what}");
            assert!(
                sink.since(0)
                    .iter()
                    .any(|m| m.status == fmi2Error && m.message.contains(needle)),
                "{what}: no message with {needle:?}"
            );
        }
        assert_eq!(states(c), before);
        assert_eq!(fmi2GetEventIndicators(c, z.as_mut_ptr(), NZ), fmi2OK);
        // P1 above the floor; the supply and return flows forward
        assert!(
            z[0] > 0.0 && z[2] > 0.0 && z[3] > 0.0 && z[4] > 0.0 && z[5] > 0.0,
            "{z:?}"
        );
        // without the hysteresis, z7 (the current's reversal) never changes sign
        assert_eq!(z[7], 1.0);
        // Co-Simulation calls are illegal here, with the interface in the message
        let from = sink.len();
        assert_eq!(fmi2DoStep(c, 0.0, 1e-3, fmi2True), fmi2Error);
        assert!(last_error(&sink, from).contains("fmi2DoStep: illegal call in state continuousTimeMode"));
        free(c);
    }
}

#[test]
fn an_x_s_outside_the_cylinder_set_during_initialisation_starts_at_the_last_valid_one_and_refuses_derivatives_until_corrected(
) {
    let sink = Sink::default();
    unsafe {
        let c = instantiate_model_exchange(&sink, "me");
        assert_eq!(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
        assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
        set_inputs(c, 2.5, 0.0);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
        let reference = running(&sink, 2.5, 0.054);
        assert_eq!(states(c), states(reference));
        let from = sink.len();
        let mut dx = [0.0; NX];
        assert_eq!(fmi2GetDerivatives(c, dx.as_mut_ptr(), NX), fmi2Error);
        let e = last_error(&sink, from);
        assert!(
            e.contains("x_s = 0 m") && e.contains("set a valid x_s in event mode"),
            "{e}"
        );
        set_inputs(c, 2.5, 0.054);
        assert_eq!(derivatives(c), derivatives(reference));
        free(c);
        free(reference);
    }
}

/// The gas volumes behind restrictions and the lagging stopper mount are ODEs: their states
/// follow the states of (4.1), with the rates the Co-Simulation step integrates them with.
#[test]
fn the_gas_volumes_and_the_lagging_mount_are_states_with_the_co_simulations_rates() {
    use jetpipe_model::physics::restrictions::PRESSURES_WITH_VOLUMES;
    let sink = Sink::default();
    let params = [
        (vr::PORT_RESTRICTION_AREA_1, 0.5e-6),
        (vr::PORT_LINE_VOLUME_1, 1e-6),
        (vr::SUPPLY_RESTRICTION_AREA, 2e-6),
        (vr::SUPPLY_PLENUM_VOLUME, 5e-6),
        (vr::STOPPER_COMPLIANCE, 2e-5),
        (vr::STOPPER_MOUNT_LAG, 2e-3),
    ];
    unsafe {
        let c = instantiate_model_exchange(&sink, "me volumes");
        initialise(c, None, &params, 2.5, 0.054);
        let cs = instantiate(&sink, "cs volumes");
        initialise(cs, None, &params, 2.5, 0.054);
        assert_eq!(outputs(c), outputs(cs), "the same start");
        assert_eq!(fmi2EnterContinuousTimeMode(c), fmi2OK);
        let mut x = states(c);
        x[4] *= 1.01;
        x[6] *= 0.99; // the supply plenum
        x[8] *= 1.02; // port line 1
        assert_eq!(fmi2SetContinuousStates(c, x.as_ptr(), NX), fmi2OK);
        let mut p = Parameters::default();
        for &(r, v) in &params {
            p.set(r, v).unwrap();
        }
        let model = Actuator::new(p).unwrap();
        assert!(model.has_volume_states());
        let mut pressures = [0.0; PRESSURES_WITH_VOLUMES];
        let (_, chambers) = get_reals(c, &[vr::P1, vr::P2]);
        pressures[0] = chambers[0];
        pressures[1] = chambers[1];
        pressures[2..].copy_from_slice(&x[6..11]);
        let expected = model.pressure_rates_with_volumes(&model.areas(x[1]), &pressures, 0.054, 0.0);
        let dx = derivatives(c);
        assert_eq!(dx[6..11].to_vec(), expected[2..].to_vec());
        // The chambers' air at mid-stroke (x_s = 61 mm): the piston sits c A_p q beyond the
        // stopper and moves with the mount's state q, so Q = P (V/V_mid)^1.4 moves at
        // (V/V_mid)^1.4 (Ṗ + 1.4 P V̇/V), V1 = A_p (x_s + c A_p q − 26 mm), V2 = A_p (96 mm − …).
        let area = std::f64::consts::PI * 15.875e-3f64.powi(2) / 4.0;
        let stretch = 2e-5 * area;
        let at = 0.054 + stretch * x[10];
        let volumes = [area * (at - 0.026), area * (0.096 - at)];
        let volume_rates = [area * stretch * dx[10], -area * stretch * dx[10]];
        for k in 0..2 {
            let air_rate = (volumes[k] / (area * 0.035)).powf(1.4)
                * (expected[k] + 1.4 * pressures[k] * volume_rates[k] / volumes[k]);
            assert!(
                (dx[4 + k] - air_rate).abs() <= 1e-9 * air_rate.abs(),
                "{dx:?}: {air_rate} for state {}",
                4 + k
            );
            let air = pressures[k] * (volumes[k] / (area * 0.035)).powf(1.4);
            assert!(
                (x[4 + k] / air - 1.0).abs() < 1e-12,
                "state {}: {} for {air}",
                4 + k,
                x[4 + k]
            );
        }
        assert_eq!(dx[11..], [0.0; 20], "no lag, filter or Pade chain");
        assert!(dx[6] != 0.0 && dx[8] != 0.0 && dx[10] != 0.0, "{dx:?}");
        assert_eq!(dx[7], 0.0, "no return plenum");
        free(c);
        free(cs);
    }
}

/// A benchmark, not a test (`bash scripts/bench_rhs.sh`, or `cargo test --release --test
/// model_exchange -- --ignored --nocapture`): right-hand-side evaluations per second through
/// the exported `fmi2SetContinuousStates` + `fmi2GetDerivatives` and
/// `fmi3SetContinuousStates` + `fmi3GetContinuousStateDerivatives`, as an importer's solver
/// calls them, for the thesis model and with gas volumes and a lagging mount; the two versions
/// in alternating rounds, the best round of each.
#[test]
#[ignore]
fn right_hand_side_evaluations_per_second_through_fmi2_get_derivatives_and_fmi3_get_continuous_state_derivatives() {
    use jetpipe::fmu3_exports::*;
    let sink = Sink::default();
    let volumes = [
        (vr::PORT_RESTRICTION_AREA_1, 0.5e-6),
        (vr::PORT_LINE_VOLUME_1, 1e-6),
        (vr::STOPPER_COMPLIANCE, 2e-5),
        (vr::STOPPER_MOUNT_LAG, 2e-3),
    ];
    let n = 200_000;
    for (label, params) in [
        ("thesis model", &[][..]),
        ("gas volume and lagging mount", &volumes[..]),
    ] {
        unsafe {
            let c2 = instantiate_model_exchange(&sink, "bench2");
            initialise(c2, None, params, 2.5, 0.054);
            assert_eq!(fmi2EnterContinuousTimeMode(c2), fmi2OK);
            let x0 = states(c2);
            let token = guid();
            let c3 = fmi3InstantiateModelExchange(
                b"bench3\0".as_ptr() as *const _,
                token.as_ptr(),
                null(),
                0,
                0,
                null_mut(),
                None,
            );
            assert!(!c3.is_null());
            for &(r, x) in params {
                assert_eq!(fmi3SetFloat64(c3, &r, 1, &x, 1), 0);
            }
            let inputs = [vr::V_DA, vr::X_S];
            assert_eq!(fmi3SetFloat64(c3, inputs.as_ptr(), 2, [2.5, 0.054].as_ptr(), 2), 0);
            assert_eq!(fmi3EnterInitializationMode(c3, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi3ExitInitializationMode(c3), 0);
            assert_eq!(fmi3EnterContinuousTimeMode(c3), 0);
            let mut dx2 = [0.0; NX];
            let mut dx3 = [0.0; NX];
            let (mut best2, mut best3) = (f64::INFINITY, f64::INFINITY);
            for _round in 0..3 {
                let started = std::time::Instant::now();
                for k in 0..n {
                    // a state that moves a little, so that nothing can be cached
                    let mut x = x0;
                    x[4] += (k % 97) as f64;
                    x[1] += (k % 89) as f64 * 1e-9;
                    assert_eq!(fmi2SetContinuousStates(c2, x.as_ptr(), NX), fmi2OK);
                    assert_eq!(fmi2GetDerivatives(c2, dx2.as_mut_ptr(), NX), fmi2OK);
                }
                best2 = best2.min(started.elapsed().as_secs_f64());
                let started = std::time::Instant::now();
                for k in 0..n {
                    let mut x = x0;
                    x[4] += (k % 97) as f64;
                    x[1] += (k % 89) as f64 * 1e-9;
                    assert_eq!(fmi3SetContinuousStates(c3, x.as_ptr(), NX), 0);
                    assert_eq!(fmi3GetContinuousStateDerivatives(c3, dx3.as_mut_ptr(), NX), 0);
                }
                best3 = best3.min(started.elapsed().as_secs_f64());
            }
            assert_eq!(dx2, dx3, "the two versions' right-hand sides at the same state");
            for (name, seconds) in [
                ("fmi2GetDerivatives", best2),
                ("fmi3GetContinuousStateDerivatives", best3),
            ] {
                println!(
                    "{label}: {:.2e} right-hand-side evaluations per second through {name} ({:.0} ns each, with the SetContinuousStates)",
                    n as f64 / seconds,
                    1e9 * seconds / n as f64
                );
            }
            free(c2);
            fmi3FreeInstance(c3);
        }
    }
}

/// Every parameter at the extremes (NaN, ±inf, 0, −1, 1e300) in a Model Exchange instance:
/// refused when set or when initialisation ends with a message, or taken, and then the states,
/// derivatives, event indicators and outputs are finite or refused with fmi2Error and a
/// message; never fmi2Fatal, never a non-finite value handed out.
#[test]
fn every_parameter_at_every_extreme_gives_finite_rates_or_an_error_in_model_exchange() {
    let sink = Sink::default();
    let (mut taken, mut refused) = (0, 0);
    for &r in Parameters::VALUE_REFERENCES.iter().chain(&[vr::P1_START, vr::P2_START]) {
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -1.0, 1e300] {
            unsafe {
                let c = instantiate_model_exchange(&sink, "abuse");
                assert_eq!(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
                assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
                let from = sink.len();
                let set = fmi2SetReal(c, &r, 1, &x);
                set_inputs(c, 2.5, 0.054);
                let exit = fmi2ExitInitializationMode(c);
                let label = format!("vr {r} = {x:e}");
                for s in [set, exit] {
                    assert!(s == fmi2OK || s == fmi2Error, "{label}: {}", status_name(s));
                    if s == fmi2Error {
                        assert!(!last_error(&sink, from).is_empty(), "{label}: no message");
                    }
                }
                if set != fmi2OK || exit != fmi2OK {
                    refused += 1;
                }
                if exit != fmi2OK {
                    free(c);
                    continue;
                }
                if set == fmi2OK {
                    taken += 1;
                }
                assert_eq!(fmi2EnterContinuousTimeMode(c), fmi2OK, "{label}");
                let mut x = [f64::NAN; NX];
                let mut dx = [f64::NAN; NX];
                let mut z = [f64::NAN; NZ];
                let statuses = [
                    (fmi2GetContinuousStates(c, x.as_mut_ptr(), NX), &x[..]),
                    (fmi2GetDerivatives(c, dx.as_mut_ptr(), NX), &dx[..]),
                    (fmi2GetEventIndicators(c, z.as_mut_ptr(), NZ), &z[..]),
                ];
                for (s, values) in statuses {
                    assert!(s == fmi2OK || s == fmi2Error, "{label}: {}", status_name(s));
                    if s == fmi2OK {
                        assert!(values.iter().all(|v| v.is_finite()), "{label}: {values:?}");
                    }
                }
                let (s, y) = get_reals(c, &OUTPUTS);
                assert!(s == fmi2OK || s == fmi2Error, "{label}: {}", status_name(s));
                assert!(s != fmi2OK || y.iter().all(|v| v.is_finite()), "{label}: {y:?}");
                free(c);
            }
        }
    }
    println!("model exchange abuse: {taken} values taken, {refused} refused (when set or when initialisation ends)");
    assert!(taken > 0 && refused > 0);
}
