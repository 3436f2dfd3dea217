//! Checks a model's declared `<ModelStructure>` dependencies by perturbation, through the
//! [`CoSimModel`] contract (no FFI): every model's tests call [`check_dependencies`].
//!
//! * `<Outputs>`: after one step, each input in turn is set to a nearby value; the outputs
//!   that change before the next step must be exactly the ones that list that input.
//! * `<InitialUnknowns>`: each input and parameter in turn is set to a nearby value before
//!   initialisation ends; every output that changes must list it (listing more is allowed:
//!   a perturbation may be too small to show a dependence, or a setting may be refused).
//!
//! An output "changes" when it moves by more than 1e-9 of its size or nominal: an
//! equilibrium found by iteration moves in its last bits with any parameter.

use super::model::{Causality, CoSimModel, ModelInfo, VarType, Variable};

/// What [`check_dependencies`] found: the problems, and the knowns it could not perturb
/// (the model refused the nearby value, e.g. a bound shared with another parameter).
#[derive(Debug, Default)]
pub struct DependencyReport {
    pub problems: Vec<String>,
    pub skipped: Vec<String>,
    /// (output, input) pairs seen to act within a step, for the caller's own checks.
    pub step_pairs: Vec<(&'static str, &'static str)>,
}

/// A value near `v`'s start that the model should accept.
fn nearby(info: &ModelInfo, v: &Variable) -> f64 {
    match v.var_type {
        VarType::Boolean => {
            if v.start != 0.0 {
                0.0
            } else {
                1.0
            }
        }
        VarType::Integer => {
            let e = info.extent_of(v);
            if e.max.map_or(false, |m| v.start + 1.0 > m) {
                v.start - 1.0
            } else {
                v.start + 1.0
            }
        }
        VarType::Real => {
            let e = info.extent_of(v);
            let candidate = if v.start != 0.0 {
                v.start * 1.01
            } else if let (Some(lo), Some(hi)) = (e.min, e.max) {
                v.start + 0.01 * (hi - lo)
            } else {
                e.nominal.map_or(1e-3, |n| 0.01 * n)
            };
            if e.max.map_or(false, |m| candidate > m) {
                v.start * 0.99
            } else {
                candidate
            }
        }
    }
}

fn set<M: CoSimModel>(m: &mut M, v: &Variable, value: f64) -> Result<(), String> {
    match v.var_type {
        VarType::Real => m.set_real(v.value_reference, value),
        VarType::Integer => m.set_integer(v.value_reference, value as i32),
        VarType::Boolean => m.set_boolean(v.value_reference, value != 0.0),
    }
}

fn outputs<M: CoSimModel>(m: &M, info: &ModelInfo) -> Result<Vec<f64>, String> {
    info.variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .map(|v| match v.var_type {
            VarType::Real => m.get_real(v.value_reference),
            VarType::Integer => m.get_integer(v.value_reference).map(f64::from),
            VarType::Boolean => m.get_boolean(v.value_reference).map(|b| b as u8 as f64),
        })
        .collect()
}

/// Whether output `out` moved from `base` to `y` by more than rounding and solver noise:
/// 1e-9 of the larger of the two and of the output's nominal.
fn moved(info: &ModelInfo, out: &Variable, base: f64, y: f64) -> bool {
    let scale = base.abs().max(y.abs()).max(info.extent_of(out).nominal.unwrap_or(0.0));
    (y - base).abs() > 1e-9 * scale
}

fn initialised<M: CoSimModel>(before_exit: impl FnOnce(&mut M) -> Result<(), String>) -> Result<M, String> {
    let mut m = M::instantiate();
    m.setup_experiment(None, 0.0, None)?;
    m.enter_initialization()?;
    before_exit(&mut m)?;
    m.exit_initialization()?;
    Ok(m)
}

/// Compare `M::info().dependencies` with what perturbations show (see the module doc).
/// `step_size` is the one step taken before the `<Outputs>` perturbations.
pub fn check_dependencies<M: CoSimModel>(step_size: f64) -> DependencyReport {
    check_dependencies_with::<M>(step_size, &[])
}

/// [`check_dependencies`] with the Real parameters `settings` (value reference, value) set
/// before every initialisation: for an input that acts only where a parameter switches on
/// what reads it.
pub fn check_dependencies_with<M: CoSimModel>(step_size: f64, settings: &[(u32, f64)]) -> DependencyReport {
    let apply = |m: &mut M| -> Result<(), String> {
        for &(value_reference, value) in settings {
            m.set_real(value_reference, value)?;
        }
        Ok(())
    };
    let info = M::info();
    let mut report = DependencyReport::default();
    let outs: Vec<&Variable> = info
        .variables
        .iter()
        .filter(|v| v.causality == Causality::Output)
        .collect();
    let declared = |out: u32| info.dependencies.iter().find(|d| d.output == out);
    if info.dependencies.is_empty() {
        report.problems.push("no dependencies are declared".to_string());
        return report;
    }
    // <Outputs>
    let mut stepped = match initialised::<M>(apply) {
        Ok(m) => m,
        Err(e) => {
            report
                .problems
                .push(format!("initialisation at the start values failed: {e}"));
            return report;
        }
    };
    if let Err(e) = stepped.do_step(0.0, step_size) {
        report
            .problems
            .push(format!("one step from the start values failed: {e:?}"));
        return report;
    }
    let bytes = stepped.serialize();
    let base = match outputs(&stepped, info) {
        Ok(y) => y,
        Err(e) => {
            report.problems.push(format!("outputs after one step: {e}"));
            return report;
        }
    };
    for u in info.variables.iter().filter(|v| v.causality == Causality::Input) {
        let mut m = M::instantiate();
        if let Err(e) = m.deserialize(&bytes) {
            report.problems.push(format!("restoring the stepped state: {e}"));
            return report;
        }
        if let Err(e) = set(&mut m, u, nearby(info, u)) {
            report.skipped.push(format!("{} after a step: {e}", u.name));
            continue;
        }
        let y = match outputs(&m, info) {
            Ok(y) => y,
            Err(e) => {
                report.problems.push(format!("outputs after setting {}: {e}", u.name));
                continue;
            }
        };
        for (k, out) in outs.iter().enumerate() {
            let changed = moved(info, out, base[k], y[k]);
            let listed =
                declared(out.value_reference).map_or(false, |d| d.step.iter().any(|&(r, _)| r == u.value_reference));
            if changed {
                report.step_pairs.push((out.name, u.name));
            }
            if changed != listed {
                report.problems.push(format!(
                    "<Outputs>: {} {} on {} ({} before the next step when {} is set), but it is {}listed",
                    out.name,
                    if changed { "depends" } else { "does not depend" },
                    u.name,
                    if changed { "it changes" } else { "it stays" },
                    u.name,
                    if listed { "" } else { "not " }
                ));
            }
        }
    }
    // <InitialUnknowns>
    let base = match initialised::<M>(apply).and_then(|m| outputs(&m, info)) {
        Ok(y) => y,
        Err(e) => {
            report.problems.push(format!("initial outputs: {e}"));
            return report;
        }
    };
    for k in info
        .variables
        .iter()
        .filter(|v| matches!(v.causality, Causality::Input | Causality::Parameter))
    {
        let value = nearby(info, k);
        let y = match initialised::<M>(|m| apply(m).and_then(|()| set(m, k, value))).and_then(|m| outputs(&m, info)) {
            Ok(y) => y,
            Err(e) => {
                report
                    .skipped
                    .push(format!("{} = {value} before initialisation: {e}", k.name));
                continue;
            }
        };
        for (j, out) in outs.iter().enumerate() {
            if !moved(info, out, base[j], y[j]) {
                continue;
            }
            let listed = match declared(out.value_reference).and_then(|d| d.initial) {
                None => true,
                Some(list) => list.iter().any(|&(r, _)| r == k.value_reference),
            };
            if !listed {
                report.problems.push(format!(
                    "<InitialUnknowns>: {} changes when {} is set to {value} before initialisation, but does not list it",
                    out.name, k.name
                ));
            }
        }
    }
    report
}
