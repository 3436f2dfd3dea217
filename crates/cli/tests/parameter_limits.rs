//! The FMU refuses unphysical parameters through `fmi2SetReal` (fmi2Error, logged) with the
//! message of the variable table, the same message `jetpipe sweep` gives; a supply pressure
//! below the return pressure, which involves two parameters set in any order, is refused when
//! initialisation ends.

// The FMU's test helpers (a logging callback and instances through the exported symbols).
#[path = "../../../tests/common/mod.rs"]
mod common;

use common::*;
use fmi2::types::*;
use jetpipe::fmu_exports::*;
use jetpipe::variables::vr;
use jetpipe_cli::sweep::{parse_axis, RunSettings, Sweep};
use jetpipe_model::physics::parameters::Parameters;

/// The message `jetpipe sweep --param SPEC` refuses with.
fn sweep_refusal(spec: &str) -> String {
    match parse_axis(spec) {
        Err(e) => e,
        Ok(axis) => Sweep::new(&Parameters::default(), vec![axis], RunSettings::default())
            .err()
            .unwrap_or_else(|| panic!("the sweep took {spec}")),
    }
}

/// Set one Real before initialisation; its status and the error messages it logged.
unsafe fn set_before_initialisation(r: u32, x: f64) -> (fmi2Status, Vec<String>, fmi2Status) {
    let sink = Sink::default();
    let c = instantiate(&sink, "limits");
    assert_eq!(fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0), fmi2OK);
    assert_eq!(fmi2EnterInitializationMode(c), fmi2OK);
    let set = fmi2SetReal(c, &r, 1, &x);
    let exit = fmi2ExitInitializationMode(c);
    let errors = sink
        .since(0)
        .into_iter()
        .filter(|m| m.status == fmi2Error)
        .map(|m| m.message)
        .collect();
    fmi2FreeInstance(c);
    (set, errors, exit)
}

#[test]
fn the_fmu_refuses_a_discharge_coefficient_above_one_with_the_sweeps_message() {
    let (set, errors, _) = unsafe { set_before_initialisation(vr::C_D, 1.5) };
    assert_eq!(set, fmi2Error);
    let expected = "C_d = 1.5 is invalid: must be in (0, 1]";
    if logger_available() {
        assert!(errors.iter().any(|m| m.contains(expected)), "{errors:?}");
    }
    assert!(sweep_refusal("C_d=1.5").contains(expected));
}

#[test]
fn the_fmu_refuses_a_spring_rate_of_1e30_with_the_sweeps_message() {
    let (set, errors, exit) = unsafe { set_before_initialisation(vr::K_SPRING, 1e30) };
    assert_eq!(set, fmi2Error);
    assert_eq!(
        exit, fmi2OK,
        "the refused value was not applied: the defaults initialise"
    );
    let message = jetpipe_model::variables::check(vr::K_SPRING, 1e30).unwrap_err();
    assert!(
        message.starts_with("k_spring = 1e30 N/m is invalid: must be in [0, 100000] N/m"),
        "{message}"
    );
    if logger_available() {
        assert!(errors.iter().any(|m| m.contains(&message)), "{errors:?}");
    }
    assert!(sweep_refusal("k_spring=1e30").ends_with(&message));
}

#[test]
fn the_fmu_refuses_a_supply_below_the_return_pressure_when_initialisation_ends() {
    let (set, errors, exit) = unsafe { set_before_initialisation(vr::P_S, 90_000.0) };
    assert_eq!(set, fmi2OK, "P_s alone is within its limits; P_r may be set after it");
    assert_eq!(exit, fmi2Error);
    let expected = "P_s = 90000 Pa is invalid: must be >= P_r = 101325 Pa";
    if logger_available() {
        assert!(errors.iter().any(|m| m.contains(expected)), "{errors:?}");
    }
    assert!(sweep_refusal("P_s=90000").contains(expected));
}

#[test]
fn the_fmu_takes_a_lower_supply_once_the_return_pressure_is_below_it() {
    let sink = Sink::default();
    unsafe {
        let c = instantiate(&sink, "limits");
        initialise(c, None, &[(vr::P_S, 90_000.0), (vr::P_R, 50_000.0)], 1.0, 0.054);
        let y = outputs(c);
        assert!(y.iter().all(|v| v.is_finite()), "{y:?}");
        fmi2FreeInstance(c);
    }
}

#[test]
fn the_fmu_takes_an_unpressurised_actuator_with_the_supply_at_the_return_pressure() {
    let sink = Sink::default();
    unsafe {
        let c = instantiate(&sink, "limits");
        initialise(c, None, &[(vr::P_S, 101_325.0)], 0.0, 0.054);
        let y = outputs(c);
        assert!(y.iter().all(|v| v.is_finite()), "{y:?}");
        fmi2FreeInstance(c);
    }
}
