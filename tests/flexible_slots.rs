//! Issue 78: the flexible slots through the exported symbols. Set through the setters of
//! Co-Simulation (FMI 2.0 and 3.0), they give the library's outputs to the last bit; an FMU
//! state taken mid-run, with a slot's lag away from its start, continues bit for bit in a new
//! instance; Model Exchange refuses a slot by the name of its parameter.

#[path = "common/mod.rs"]
mod common;

use std::ffi::CString;
use std::ptr::{null, null_mut};

use common::*;
use fmi2::types::*;
use fmi3::types::*;
use jetpipe::fmu3_exports::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::vr;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::simulation::{Simulation, DEFAULT_RELATIVE_TOLERANCE};

/// Slot 1: C_d on a 3 x 2 grid of the command (low-passed, 10 ms) and the stopper position;
/// slot 2: extra_force_offset on P1 − P2, raw; both with a force transducer offset.
fn settings() -> Vec<(u32, f64)> {
    let s1 = vr::FLEXIBLE_1_PARAMETER;
    let s2 = vr::FLEXIBLE_2_PARAMETER;
    let mut v = vec![
        (vr::FORCE_SENSOR_OFFSET, 0.2),
        (s1, vr::C_D as f64),
        (s1 + 1, 2.0),
        (s1 + 2, 5.0),
        (s1 + 4, 0.01),
        (s1 + 6, 3.0),
        (s1 + 7, 2.0),
        (s1 + 8, 0.0),
        (s1 + 9, 3.0),
        (s1 + 10, 6.0),
        (s1 + 13, 0.05),
        (s1 + 14, 0.058),
        (s2, vr::EXTRA_FORCE_OFFSET as f64),
        (s2 + 1, 11.0),
        (s2 + 6, 2.0),
        (s2 + 8, -2e5),
        (s2 + 9, 2e5),
        (s2 + 18, -1.5),
        (s2 + 23, 2.5),
    ];
    for i in 0..3u32 {
        for j in 0..2u32 {
            v.push((s1 + 18 + 5 * i + j, 0.04 * i as f64 - 0.03 * j as f64));
        }
    }
    v
}

/// The inputs of sample k: a varying command, a stopper jumping now and then.
fn inputs(k: usize) -> (f64, f64) {
    let v = 2.5 + 2.0 * (0.07 * k as f64).sin() + if k % 40 < 20 { 0.0 } else { 1.5 };
    let x = if k % 50 < 25 { 0.054 } else { 0.057 };
    (v, x)
}

const H: f64 = 1e-3;
const SAMPLES: usize = 120;
const READ: [u32; 4] = [vr::F_ACT, vr::F_MEAS, vr::P1, vr::P2];

/// The library's readings of READ after each step.
fn library() -> Vec<[u64; 4]> {
    let mut p = Parameters::default();
    for (r, x) in settings() {
        p.set(r, x).unwrap();
    }
    let (v0, x0) = inputs(0);
    let mut sim =
        Simulation::at_equilibrium(Actuator::new(p).unwrap(), v0, x0, 0.0, DEFAULT_RELATIVE_TOLERANCE).unwrap();
    (0..SAMPLES)
        .map(|k| {
            let (v, x) = inputs(k);
            sim.set_command(v).unwrap();
            sim.set_stopper(x).unwrap();
            sim.step(H).unwrap();
            let y = sim.outputs();
            [y.f_act, y.f_meas, y.p1, y.p2].map(f64::to_bits)
        })
        .collect()
}

/// An FMI 2.0 Co-Simulation instance with the settings, initialised at the first inputs.
unsafe fn fmi2_instance(sink: &Sink) -> fmi2Component {
    let c = instantiate(sink, "flexible");
    let (v0, x0) = inputs(0);
    initialise(c, None, &settings(), v0, x0);
    c
}

/// Steps `from..to` of an FMI 2.0 instance, its readings after each.
unsafe fn fmi2_run(c: fmi2Component, from: usize, to: usize) -> Vec<[u64; 4]> {
    (from..to)
        .map(|k| {
            let (v, x) = inputs(k);
            set_inputs(c, v, x);
            assert_eq!(fmi2DoStep(c, k as f64 * H, H, fmi2True), fmi2OK, "step {k}");
            let (s, y) = get_reals(c, &READ);
            assert_eq!(s, fmi2OK);
            [y[0], y[1], y[2], y[3]].map(f64::to_bits)
        })
        .collect()
}

unsafe fn fmi3_instance() -> fmi3Instance {
    let name = CString::new("flexible3").unwrap();
    let token = guid();
    let c = fmi3InstantiateCoSimulation(
        name.as_ptr(),
        token.as_ptr(),
        null(),
        0,
        0,
        0,
        0,
        null(),
        0,
        null_mut(),
        None,
        None,
    );
    assert!(!c.is_null());
    assert_eq!(fmi3EnterInitializationMode(c, 0, 0.0, 0.0, 0, 0.0), fmi3OK);
    let (v0, x0) = inputs(0);
    for (r, x) in settings().into_iter().chain([(vr::V_DA, v0), (vr::X_S, x0)]) {
        assert_eq!(fmi3SetFloat64(c, &r, 1, &x, 1), fmi3OK, "vr {r} = {x}");
    }
    assert_eq!(fmi3ExitInitializationMode(c), fmi3OK);
    c
}

unsafe fn fmi3_run(c: fmi3Instance, from: usize, to: usize) -> Vec<[u64; 4]> {
    (from..to)
        .map(|k| {
            let (v, x) = inputs(k);
            let (vrs, xs) = ([vr::V_DA, vr::X_S], [v, x]);
            assert_eq!(fmi3SetFloat64(c, vrs.as_ptr(), 2, xs.as_ptr(), 2), fmi3OK);
            let (mut event, mut terminate, mut early, mut last) = (0, 0, 0, 0.0);
            let s = fmi3DoStep(c, k as f64 * H, H, 1, &mut event, &mut terminate, &mut early, &mut last);
            assert_eq!(s, fmi3OK, "step {k}");
            let mut y = [0.0; 4];
            assert_eq!(fmi3GetFloat64(c, READ.as_ptr(), 4, y.as_mut_ptr(), 4), fmi3OK);
            y.map(f64::to_bits)
        })
        .collect()
}

#[test]
fn co_simulation_of_fmi_2_and_3_with_the_slots_set_through_the_setters_gives_the_librarys_outputs() {
    let expected = library();
    // The slots act: without them the force differs.
    let sink = Sink::default();
    unsafe {
        let plain = instantiate(&sink, "plain");
        let (v0, x0) = inputs(0);
        initialise(plain, None, &[(vr::FORCE_SENSOR_OFFSET, 0.2)], v0, x0);
        assert_ne!(fmi2_run(plain, 0, SAMPLES), expected);
        free(plain);

        let c = fmi2_instance(&sink);
        assert_eq!(fmi2_run(c, 0, SAMPLES), expected, "FMI 2.0");
        free(c);

        let c3 = fmi3_instance();
        assert_eq!(fmi3_run(c3, 0, SAMPLES), expected, "FMI 3.0");
        fmi3FreeInstance(c3);
    }
}

#[test]
fn an_fmu_state_taken_mid_run_with_a_lagged_slot_continues_bit_for_bit_in_a_new_instance() {
    let sink = Sink::default();
    let expected = library();
    unsafe {
        // FMI 2.0: serialised after 60 steps (the command's lag is then away from its start).
        let a = fmi2_instance(&sink);
        fmi2_run(a, 0, 60);
        let mut st: fmi2FMUstate = null_mut();
        assert_eq!(fmi2GetFMUstate(a, &mut st), fmi2OK);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(a, st, &mut size), fmi2OK);
        let mut bytes = vec![0 as fmi2Byte; size];
        assert_eq!(fmi2SerializeFMUstate(a, st, bytes.as_mut_ptr(), size), fmi2OK);
        assert_eq!(fmi2FreeFMUstate(a, &mut st), fmi2OK);
        let b = instantiate(&sink, "restored");
        let mut restored: fmi2FMUstate = null_mut();
        assert_eq!(fmi2DeSerializeFMUstate(b, bytes.as_ptr(), size, &mut restored), fmi2OK);
        assert_eq!(fmi2SetFMUstate(b, restored), fmi2OK);
        assert_eq!(fmi2FreeFMUstate(b, &mut restored), fmi2OK);
        assert_eq!(fmi2_run(b, 60, SAMPLES), expected[60..], "FMI 2.0, restored");
        assert_eq!(fmi2_run(a, 60, SAMPLES), expected[60..], "FMI 2.0, original");
        free(a);
        free(b);

        // FMI 3.0, the same.
        let a = fmi3_instance();
        fmi3_run(a, 0, 60);
        let mut st: fmi3FMUState = null_mut();
        assert_eq!(fmi3GetFMUState(a, &mut st), fmi3OK);
        let mut size = 0;
        assert_eq!(fmi3SerializedFMUStateSize(a, st, &mut size), fmi3OK);
        let mut bytes = vec![0 as fmi3Byte; size];
        assert_eq!(fmi3SerializeFMUState(a, st, bytes.as_mut_ptr(), size), fmi3OK);
        assert_eq!(fmi3FreeFMUState(a, &mut st), fmi3OK);
        let b = fmi3_instance();
        let mut restored: fmi3FMUState = null_mut();
        assert_eq!(fmi3DeserializeFMUState(b, bytes.as_ptr(), size, &mut restored), fmi3OK);
        assert_eq!(fmi3SetFMUState(b, restored), fmi3OK);
        assert_eq!(fmi3FreeFMUState(b, &mut restored), fmi3OK);
        assert_eq!(fmi3_run(b, 60, SAMPLES), expected[60..], "FMI 3.0, restored");
        fmi3FreeInstance(a);
        fmi3FreeInstance(b);
    }
}

#[test]
fn model_exchange_refuses_a_flexible_slot_by_the_name_of_its_parameter() {
    let sink = Sink::default();
    unsafe {
        for parameter in [vr::FLEXIBLE_1_PARAMETER, vr::FLEXIBLE_2_PARAMETER] {
            let c = instantiate_model_exchange(&sink, "me");
            assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
            let from = sink.len();
            let value = vr::EXTRA_INFLOW_2 as f64;
            assert_eq!(fmi2SetReal(c, &parameter, 1, &value), fmi2Error);
            let e = sink
                .since(from)
                .into_iter()
                .rev()
                .find(|m| m.status == fmi2Error)
                .map(|m| m.message)
                .unwrap_or_default();
            let name = if parameter == vr::FLEXIBLE_1_PARAMETER {
                "flexible_1_parameter = 782"
            } else {
                "flexible_2_parameter = 782"
            };
            assert!(
                e.contains(name) && e.contains("the flexible slots") && e.contains("use the Co-Simulation interface"),
                "{e}"
            );
            // Not applied: initialisation ends with the thesis model.
            assert_eq!(fmi2ExitInitializationMode(c), fmi2OK);
            free(c);
        }
        // The plain constants need no memory: Model Exchange has them.
        let c = instantiate_model_exchange(&sink, "me");
        initialise(
            c,
            None,
            &[(vr::EXTRA_FORCE_OFFSET, 1.5), (vr::EXTRA_INFLOW_1, 1e-6)],
            2.5,
            0.054,
        );
        free(c);
    }
}
