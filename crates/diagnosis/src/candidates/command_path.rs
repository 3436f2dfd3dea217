//! The places along the command's path to the jet pipe's force, which a static function of
//! the command makes alike.
//!
//! The logged command v reaches the jet pipe as the tip force k_m i, i = k_cd v + i_offset
//! through the current driver's lag, and the jet's position as x_jp_sat f3(k_m i / F_jp_sat).
//! A curve, an offset, a gain or a limit anywhere before f3 makes that force one static
//! function of the command: placed at the command, in the driver or at the torque motor it
//! gives the same outputs but for the driver's lag (its corner is near 300 Hz in the thesis),
//! which a command held or swept slower does not show. The recording has no current column,
//! so it cannot tell these places apart, and a report says so (`tied_locations`).

use crate::candidates::modulation::slot_parameter;
use crate::vocabulary::Place;
use jetpipe_model::physics::modulation::ModulationSignal;
use jetpipe_model::variables::vr;

/// The command, the current driver and the torque motor (the jet pipe's place).
pub const COMMAND_PATH: [Place; 3] = [Place::Command, Place::CurrentDriver, Place::JetPipe];

/// The constants before f3 whose change is a static function of the command: the driver's
/// gain and offset, the torque motor's constant and f3's input scale (u = k_m i / F_jp_sat).
/// f3's output scale `x_jp_sat` and the jet's null `x_jp_offset` act after f3's
/// saturation, where a curve of the command cannot always follow them.
const CONSTANTS_BEFORE_F3: [u32; 4] = [vr::K_CD, vr::I_OFFSET, vr::K_M, vr::F_JP_SAT];

/// The model parameters, besides those constants, that put a static function of the command
/// before f3: the command's curve, quantiser and limits, the current limit and f3's input
/// cubic. (The driver's corner, the slew limit, the command's lag, filter and delay have
/// memory: they are told apart from a curve.)
const STATIC_BEFORE_F3: [&str; 9] = [
    "command_quantum",
    "command_quantum_origin",
    "command_quantum_threshold",
    "command_limit",
    "command_upper_limit",
    "command_lower_limit",
    "current_limit",
    "f3_input_cubic",
    "f3_algebraic_share",
];

/// Whether slot `slot` of `set` holds a constant before f3 following the command or the
/// current; `None` when `set` does not fill that slot. (A staircase's 7-bit command quantiser
/// was found as `k_m` varying with the command, explained at the noise, while the command's
/// own curve, with its knots where the staircase has no levels, fitted worse than none.)
fn slot_is_static_in_the_command(set: &[(&'static str, f64)], slot: usize) -> Option<bool> {
    let value = |field: &str| {
        let name = slot_parameter(slot, field);
        set.iter().find(|(n, _)| *n == name).map(|&(_, v)| v)
    };
    let parameter = value("parameter")?;
    let follows_the_command = [ModulationSignal::Command, ModulationSignal::Current].map(|s| f64::from(s.code()));
    Some(
        CONSTANTS_BEFORE_F3.map(f64::from).contains(&parameter)
            && matches!(value("signal"), Some(s) if follows_the_command.contains(&s)),
    )
}

/// Whether every parameter the term `set` carries makes a static function of the command
/// before f3: a change of a constant there (an offset or a gain of the driver), the command's
/// curve, quantiser or limits, f3's input curve, or such a constant following the command.
/// A term with any other parameter, or with a slot following another signal, is not.
pub fn acts_alike_along_the_command_path(set: &[(&'static str, f64)]) -> bool {
    let constant_names: Vec<&str> = CONSTANTS_BEFORE_F3
        .iter()
        .filter_map(|&r| {
            jetpipe_model::variables::VARIABLES
                .iter()
                .find(|v| v.value_reference == r)
                .map(|v| v.name)
        })
        .collect();
    let slots_static = (1..=2).all(|slot| slot_is_static_in_the_command(set, slot) != Some(false));
    !set.is_empty()
        && slots_static
        && set.iter().all(|(name, _)| {
            name.starts_with("modulation_")
                || name.starts_with("command_curve_")
                || STATIC_BEFORE_F3.contains(name)
                || constant_names.contains(name)
        })
}

/// The places a static function of the command at `place` is tied with, `place` first.
pub fn tied_along_the_command_path(place: Place) -> Vec<Place> {
    std::iter::once(place)
        .chain(COMMAND_PATH.iter().copied().filter(|&p| p != place))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn slot(parameter: u32, signal: ModulationSignal) -> Vec<(&'static str, f64)> {
        vec![
            ("modulation_1_parameter", f64::from(parameter)),
            ("modulation_1_signal", f64::from(signal.code())),
            ("modulation_1_y_1", 0.01),
        ]
    }

    #[test]
    fn an_offset_a_gain_or_a_curve_before_f3_acts_alike_along_the_command_path_and_memory_or_what_follows_f3_does_not()
    {
        assert!(acts_alike_along_the_command_path(&[
            ("k_cd", 0.011),
            ("i_offset", 2e-3)
        ]));
        assert!(acts_alike_along_the_command_path(&[
            ("command_curve_knots", 3.0),
            ("command_curve_x_1", -1.0),
            ("command_curve_y_1", -1.2),
        ]));
        assert!(acts_alike_along_the_command_path(&[("f3_input_cubic", 0.4)]));
        assert!(acts_alike_along_the_command_path(&[("command_quantum", 0.3)]));
        assert!(acts_alike_along_the_command_path(&slot(
            vr::K_M,
            ModulationSignal::Command
        )));
        assert!(acts_alike_along_the_command_path(&slot(
            vr::I_OFFSET,
            ModulationSignal::Current
        )));

        assert!(!acts_alike_along_the_command_path(&[]));
        assert!(!acts_alike_along_the_command_path(&[("x_jp_offset", 1e-5)]));
        assert!(!acts_alike_along_the_command_path(&[
            ("f3_input_cubic", 0.4),
            ("x_jp_sat", 2e-4)
        ]));
        assert!(!acts_alike_along_the_command_path(&[("command_lag", 0.004)]));
        assert!(!acts_alike_along_the_command_path(&[("current_slew_limit", 30.0)]));
        assert!(!acts_alike_along_the_command_path(&slot(
            vr::K_CD,
            ModulationSignal::StopperPosition
        )));
        assert!(!acts_alike_along_the_command_path(&slot(
            vr::OMEGA_CD,
            ModulationSignal::Command
        )));
        assert!(!acts_alike_along_the_command_path(&slot(
            vr::D_JP,
            ModulationSignal::Command
        )));
        assert_eq!(
            tied_along_the_command_path(Place::JetPipe),
            [Place::JetPipe, Place::Command, Place::CurrentDriver]
        );
    }
}
