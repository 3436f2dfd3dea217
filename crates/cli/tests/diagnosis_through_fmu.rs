//! The FMU with a diagnosis report's `fmu_start_values` is the model whose error the report
//! gives: the recording replayed through the exported `fmi2*` functions (the command held
//! over each sample interval, the stopper moving linearly between the smoothed positions the
//! report's `stopper_positions` names) reproduces the reported force error after.

// The FMU's test helpers (a logging callback and instances through the exported symbols).
#[path = "../../../tests/common/mod.rs"]
mod common;

use common::*;
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::vr;
use jetpipe_diagnosis::diagnose;
use jetpipe_diagnosis::input::recording::Recording;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::variable::VarType;
use jetpipe_model::variables::VARIABLES;
use synthetic_bench::{
    generate_protocol_with, BenchEffects, CommandProtocol, ProtocolSpec, StopperMotion, UndeclaredEffects,
};

/// The report's `stopper_positions`: where it gives a
/// `stopper_positions_smoothing_residual_limit_m2`, x_s smoothed over samples k-3..k+3 with
/// the weights (-2, 3, 6, 7, 6, 3, -2)/21 at each sample whose seven positions leave at most
/// that sum of squares about their least-squares quadratic (by the normal equations), the
/// recorded positions elsewhere and at the first and last three samples; else x_s as recorded.
fn stopper_positions(x: &[f64], residual_limit: Option<f64>) -> Vec<f64> {
    let Some(limit) = residual_limit else {
        return x.to_vec();
    };
    let n = x.len();
    let weights = [-2.0, 3.0, 6.0, 7.0, 6.0, 3.0, -2.0];
    (0..n)
        .map(|k| {
            if k < 3 || k + 3 >= n {
                return x[k];
            }
            let d: Vec<f64> = (0..7).map(|j| x[k + j - 3] - x[k]).collect();
            if quadratic_fit_residual(&d) > limit {
                return x[k];
            }
            x[k] + (0..7).map(|j| weights[j] / 21.0 * d[j]).sum::<f64>()
        })
        .collect()
}

/// The sum of squares seven values at i = -3..=3 leave about their least-squares quadratic
/// a + b i + c i², solved from the normal equations by Cramer's rule.
fn quadratic_fit_residual(d: &[f64]) -> f64 {
    let moment = |p: i32| (-3..=3).map(|i: i32| f64::from(i).powi(p)).sum::<f64>();
    let projection = |p: i32| (-3..=3).zip(d).map(|(i, y)| f64::from(i).powi(p) * y).sum::<f64>();
    let m = [
        [moment(0), moment(1), moment(2)],
        [moment(1), moment(2), moment(3)],
        [moment(2), moment(3), moment(4)],
    ];
    let r = [projection(0), projection(1), projection(2)];
    let det = |a: [[f64; 3]; 3]| {
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    };
    let whole = det(m);
    let coefficient = |c: usize| {
        let mut a = m;
        for (row, value) in a.iter_mut().zip(r) {
            row[c] = value;
        }
        det(a) / whole
    };
    let (a, b, c) = (coefficient(0), coefficient(1), coefficient(2));
    (-3..=3)
        .zip(d)
        .map(|(i, y)| {
            let i = f64::from(i);
            (y - a - b * i - c * i * i).powi(2)
        })
        .sum()
}

/// F_meas at every sample of `recording` from the FMU with `start_values` set, the stopper
/// driven with the positions the diagnosis replayed.
fn replayed_force(recording: &Recording, start_values: &[(u32, f64)], smoothing: Option<f64>) -> Vec<f64> {
    let (t, v) = (&recording.time, &recording.v_da);
    let x = stopper_positions(&recording.x_s, smoothing);
    let sink = Sink::default();
    let mut force = Vec::with_capacity(t.len());
    unsafe {
        let c = instantiate(&sink, "replay");
        assert_eq!(fmi2SetupExperiment(c, fmi2False, 0.0, t[0], fmi2False, 0.0), fmi2OK);
        assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
        for &(r, value) in start_values {
            let boolean = VARIABLES
                .iter()
                .any(|v| v.value_reference == r && v.var_type == VarType::Boolean);
            let status = if boolean {
                fmi2SetBoolean(c, &r, 1, &((value != 0.0) as fmi2Boolean))
            } else {
                fmi2SetReal(c, &r, 1, &value)
            };
            assert_eq!(status, fmi2OK, "vr {r} = {value}: {:?}", sink.since(0));
        }
        set_inputs(c, v[0], x[0]);
        assert_eq!(fmi2ExitInitializationMode(c), fmi2OK, "{:?}", sink.since(0));
        let order = 1;
        for k in 0..t.len() {
            // The stopper's motion on to the next sample is set before the outputs at this
            // one are read, as the diagnosis replays it.
            let dt = if k + 1 < t.len() { t[k + 1] - t[k] } else { 0.0 };
            if k + 1 < t.len() {
                let rate = (x[k + 1] - x[k]) / dt;
                assert_eq!(fmi2SetRealInputDerivatives(c, &vr::X_S, 1, &order, &rate), fmi2OK);
            }
            let (status, y) = get_reals(c, &[vr::F_MEAS]);
            assert_eq!(status, fmi2OK);
            force.push(y[0]);
            if k + 1 == t.len() {
                break;
            }
            assert_eq!(fmi2SetReal(c, &vr::V_DA, 1, &v[k]), fmi2OK);
            assert_eq!(fmi2DoStep(c, t[k], dt, fmi2True), fmi2OK, "{:?}", sink.since(0));
        }
        fmi2FreeInstance(c);
    }
    force
}

/// The gas temperature rising 20 K over a 20 s staircase at 500 Hz: the diagnosis adds
/// `T_drift`, and the FMU with the report's start values (`T`, `T_drift`) gives the reported
/// force error after within 10 %, against a force error before at least twice it.
#[test]
fn the_fmu_with_the_start_values_of_a_drifting_gas_temperature_reproduces_the_reported_error_after() {
    let spec = ProtocolSpec {
        command: CommandProtocol::Staircase,
        stopper: StopperMotion::Fixed { position: 0.054 },
        sample_rate: 500.0,
        duration: 20.0,
        pressures: true,
        seed: 5,
        ..ProtocolSpec::default()
    };
    let effects = BenchEffects {
        undeclared: UndeclaredEffects {
            gas_temperature_drift: 20.0,
            ..UndeclaredEffects::default()
        },
        ..BenchEffects::default()
    };
    let dir = std::env::temp_dir().join(format!("jetpipe-gas-drift-fmu-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("recording.csv");
    generate_protocol_with(&Default::default(), &spec, &effects)
        .unwrap()
        .write_csv(&path)
        .unwrap();
    let recording = Recording::read(&path, &Parameters::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let d = diagnose(&recording, &Parameters::default(), false, &mut |_| {}).unwrap();
    let report = d.to_json("gas-drift");
    let start_values: Vec<(u32, f64)> = report["fmu_start_values"]
        .as_object()
        .unwrap()
        .iter()
        .map(|(name, value)| {
            let variable = VARIABLES
                .iter()
                .find(|v| v.name == name)
                .unwrap_or_else(|| panic!("{name} is not an FMU variable"));
            let value = value.as_f64().or_else(|| value.as_bool().map(f64::from)).unwrap();
            (variable.value_reference, value)
        })
        .collect();
    assert!(
        start_values.iter().any(|&(r, value)| r == vr::T_DRIFT && value > 0.0),
        "no T_drift among {:?}",
        report["fmu_start_values"]
    );
    let smoothing = report["stopper_positions_smoothing_residual_limit_m2"].as_f64();
    let force = replayed_force(&recording, &start_values, smoothing);
    let n = force.len() as f64;
    let rms = (force
        .iter()
        .zip(&recording.force)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let (reported, before) = (d.after.rms, d.before.rms);
    println!(
        "force error after: reported {reported:.5} N, FMU replay {rms:.5} N; before {before:.4} N; {:?}",
        report["fmu_start_values"]
    );
    assert!(before > 2.0 * reported, "before {before} N, after {reported} N");
    assert!(
        (rms - reported).abs() <= 0.1 * reported,
        "FMU {rms} N against reported {reported} N"
    );
}
