//! A named effect applied to the model, and its signature in the residual.

use crate::candidates::set_parameter;
use crate::fit::scored::Scored;
use crate::input::blocks::Block;
use crate::input::recording::Recording;
use crate::replay::signals::difference;
use crate::replay::signals::force_from_pressures;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// The force sensor's reading if the measured pressures drove the model's mechanics
/// (friction, spring floor) and sensor: what the force should be when only the
/// mechanics and the force sensor are in question.
pub(crate) fn force_through_mechanics(model: &Actuator, recording: &Recording) -> Option<Replay> {
    let (p1, p2) = crate::replay::signals::chamber_pressures(model, recording)?;
    let velocity = crate::input::stopper_motion::stopper_velocity(recording);
    let force = (0..recording.len())
        .map(|k| {
            let state = jetpipe_model::physics::actuator::State::from([0.0, 0.0, 0.0, 0.0, p1[k], p2[k]]);
            model.outputs(&state, recording.x_s[k], velocity[k]).f_meas
        })
        .collect();
    Some(Replay {
        force,
        p1,
        p2,
        ..Replay::default()
    })
}

/// Apply a named effect's fitted values to the model's parameters.
pub(crate) fn apply_named(p: &mut Parameters, scored: &Scored) -> Result<Vec<(&'static str, f64)>, String> {
    let mut set = vec![];
    let values = scored.parameters();
    match scored.fit.candidate.named {
        Some("piston_friction") => {
            // Forces read through the sensor's gain; the speed scale as fitted.
            for (name, value) in values {
                let value = match name {
                    "friction_coulomb" => p.friction_coulomb + value / p.force_sensor_gain,
                    "friction_stribeck" => p.friction_stribeck + value / p.force_sensor_gain,
                    "viscous_friction" => p.viscous_friction + value / p.force_sensor_gain,
                    _ => value,
                };
                set_parameter(p, name, value)?;
                set.push((name, value));
            }
        }
        Some("sensor_offset_gain") => {
            let (offset, gain_error) = (values[0].1, values[1].1);
            let gain = (1.0 + gain_error) * p.force_sensor_gain;
            let offset = (1.0 + gain_error) * p.force_sensor_offset + offset;
            set_parameter(p, "force_sensor_gain", gain)?;
            set_parameter(p, "force_sensor_offset", offset)?;
            set.push(("force_sensor_offset", offset));
            set.push(("force_sensor_gain", gain));
        }
        _ => {
            for (name, value) in values {
                set_parameter(p, name, value)?;
                set.push((name, value));
            }
        }
    }
    p.validate()?;
    Ok(set)
}

/// The named effect's own signature in the current residual; `fitted_force` is the force of
/// the model with the effect fitted.
#[allow(clippy::too_many_arguments)]
pub(crate) fn named_signature(
    name: &str,
    recording: &Recording,
    model: &Actuator,
    replay: &Replay,
    fitted_force: &[f64],
    blocks: &[Block],
    noise: f64,
    mechanical_noise: f64,
) -> crate::decide::named::SignatureTest {
    let force_residual = difference(&recording.force, &replay.force);
    // With pressures, the mechanics and the sensor are judged on the force against the
    // pressures; without them, against the model.
    let (residual, reference, judged_noise) = match force_from_pressures(model, recording) {
        Some(f) => (difference(&recording.force, &f), f, mechanical_noise),
        None => (force_residual.clone(), replay.force.clone(), noise),
    };
    match name {
        "sensor_offset_gain" => crate::decide::named::sensor_is_affine(&residual, &reference, blocks, judged_noise),
        "piston_friction" => crate::decide::named::friction_changes_sign(&residual, recording, judged_noise),
        "jet_pipe_hysteresis" => crate::decide::named::loop_with_command_direction(
            &force_residual,
            &difference(fitted_force, &replay.force),
            recording,
            noise,
        ),
        _ => crate::decide::named::SignatureTest {
            present: true,
            sentence: String::new(),
        },
    }
}
