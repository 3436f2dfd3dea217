//! Each effect and term was fitted with those before it held: after the rounds they are
//! refitted together ([`crate::fit::refit`]), and what the refit turns off is retired.

use crate::candidates::parameter_value;
use crate::context::Context;
use crate::fit::refit::refit_constants;
use crate::fit::refit::refittable;
use jetpipe_model::physics::parameters::Parameters;

/// Each effect and term was fitted with those before it held: refit them together, and
/// keep the refit when the held-out force error falls. The error before and after.
pub(crate) fn refit_jointly(
    cx: &Context,
    found: &mut crate::decide::findings::Findings,
    replays: &mut usize,
    progress: &mut dyn FnMut(&str),
) -> Result<Option<(f64, f64)>, String> {
    if found.effects.len() + found.discovered.len() < 2 {
        return Ok(None);
    }
    let params = &found.params;
    let names: Vec<&'static str> = found
        .effects
        .iter()
        .flat_map(|e| e.parameters.iter())
        .chain(found.discovered.iter().flat_map(|d| d.parameters.iter()))
        .map(|(name, _)| *name)
        .filter(|name| parameter_value(params, name) != 0.0)
        .filter(|name| refittable(name))
        .collect();
    progress(&format!("joint refit of the {} parameters added", names.len()));
    let Some((trial, before_joint, after_joint)) = refit_constants(cx, params, &names, replays)? else {
        return Ok(None);
    };
    progress(&format!(
        "  held-out force error {before_joint:.4} -> {after_joint:.4} N"
    ));
    if after_joint >= before_joint {
        return Ok(None);
    }
    found.params = trial;
    retire_switched_off(found, progress);
    Ok(Some((before_joint, after_joint)))
}

/// After the joint refit: a named effect the refit turned off (its amplitude at zero:
/// another term took over what it explained) is no longer there, and the others report
/// their refitted values.
pub(crate) fn retire_switched_off(found: &mut crate::decide::findings::Findings, progress: &mut dyn FnMut(&str)) {
    let params = &mut found.params;
    let count = found.effects.len();
    found.effects.retain(|e| {
        let off = match e.name {
            "piston_friction" => params.friction_coulomb == 0.0,
            _ => e
                .parameters
                .iter()
                .all(|(name, _)| parameter_value(params, name) == parameter_value(&Parameters::default(), name)),
        };
        if off {
            progress(&format!("  {} is off after the refit: removed", e.name));
        }
        !off
    });
    if found.effects.len() != count && matches!(found.newest, Some((true, _))) {
        found.newest = None;
    }
    if params.friction_coulomb == 0.0 {
        params.friction_velocity = 0.0;
    }
    for (name, value) in found
        .effects
        .iter_mut()
        .flat_map(|e| e.parameters.iter_mut())
        .chain(found.discovered.iter_mut().flat_map(|d| d.parameters.iter_mut()))
    {
        *value = parameter_value(params, name);
    }
}
