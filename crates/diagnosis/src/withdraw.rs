//! Never a worse model: additions the accurate replay finds worse than the starting model
//! are taken out again.

use jetpipe_model::physics::parameters::Parameters;

use crate::{rounds, Errors};

/// Additions taken out because, replayed accurately, they made the force error larger than
/// the starting model's, held out or over the whole recording.
#[derive(Clone, Debug)]
pub struct Withdrawn {
    /// The named effects and discovered terms, by name.
    pub names: Vec<&'static str>,
    /// The force RMS errors of the model with them, N: held out, then over the whole recording.
    pub heldout_with: f64,
    pub whole_with: f64,
}

/// A force error larger than the starting model's by at most this share of the noise floor
/// is not worse: a thousandth of the noise is beyond any measurement, and a term that leaves
/// the force alone (a pressure transducer's offset, say) moves it by about that much through
/// the chambers' start, which the transducers' readings set.
pub const NEGLIGIBLE_SHARE_OF_NOISE: f64 = 1e-3;

/// The search scores its additions on the fast replay; the accurate one decides. When it
/// finds the model with them worse than the model the diagnosis started from (`start`), held
/// out or over the whole recording, by more than [`NEGLIGIBLE_SHARE_OF_NOISE`] of the force's
/// `noise` floor, they are taken out and `found` is the starting model again.
pub(crate) fn withdraw_if_worse(
    found: &mut rounds::Findings,
    start: &Parameters,
    before: &Errors,
    after: &Errors,
    noise: f64,
) -> Option<Withdrawn> {
    let negligible = NEGLIGIBLE_SHARE_OF_NOISE * noise;
    if after.heldout_rms <= before.heldout_rms + negligible && after.rms <= before.rms + negligible {
        return None;
    }
    let names = found
        .effects
        .iter()
        .map(|e| e.name)
        .chain(found.discovered.iter().map(|d| d.candidate))
        .collect();
    found.effects.clear();
    found.discovered.clear();
    found.newest = None;
    found.joint_refit = None;
    found.params = start.clone();
    Some(Withdrawn {
        names,
        heldout_with: after.heldout_rms,
        whole_with: after.rms,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AddedEffect, DiscoveredTerm};

    fn errors(heldout_rms: f64, rms: f64) -> Errors {
        Errors {
            rms,
            nrmse: 0.0,
            train_rms: heldout_rms,
            heldout_rms,
            pressure_rms: None,
        }
    }

    /// Findings with one named effect and one discovered term, whose parameters differ from
    /// the start's.
    fn findings(start: &Parameters) -> rounds::Findings {
        let mut params = start.clone();
        params.force_sensor_offset = 0.7;
        rounds::Findings {
            params,
            effects: vec![AddedEffect {
                name: "sensor_offset_gain",
                location: "force_sensor",
                parameters: vec![("force_sensor_offset", 0.7)],
                evidence: String::new(),
                heldout_before: 0.3,
                heldout_after: 0.1,
                share: 0.9,
                remainder_follows: String::new(),
            }],
            discovered: vec![DiscoveredTerm {
                location: "jet_pipe",
                family: "dynamics",
                candidate: "jet pipe extra lag",
                parameters: vec![],
                reading: String::new(),
                heldout_before: 0.1,
                heldout_after: 0.09,
                share: 0.2,
                pressures_heldout: None,
                tied_locations: vec![],
            }],
            first_candidates: vec![],
            localization: None,
            joint_refit: Some((0.1, 0.09)),
            start: start.clone(),
            newest: Some((false, 0)),
        }
    }

    #[test]
    fn additions_that_lower_both_errors_stay() {
        let start = Parameters::default();
        let mut found = findings(&start);
        assert!(withdraw_if_worse(&mut found, &start, &errors(0.3, 0.4), &errors(0.1, 0.2), 0.05).is_none());
        assert_eq!((found.effects.len(), found.discovered.len()), (1, 1));
        assert_eq!(found.params.force_sensor_offset, 0.7);
    }

    #[test]
    fn additions_that_make_the_held_out_error_larger_are_withdrawn_and_the_start_comes_back() {
        let start = Parameters::default();
        let mut found = findings(&start);
        let withdrawn = withdraw_if_worse(&mut found, &start, &errors(0.3, 0.4), &errors(0.31, 0.2), 0.05).unwrap();
        assert_eq!(withdrawn.names, ["sensor_offset_gain", "jet pipe extra lag"]);
        assert_eq!((withdrawn.heldout_with, withdrawn.whole_with), (0.31, 0.2));
        assert!(found.effects.is_empty() && found.discovered.is_empty());
        assert_eq!(found.params.force_sensor_offset, start.force_sensor_offset);
        assert!(found.joint_refit.is_none() && found.newest.is_none());
    }

    #[test]
    fn additions_that_make_only_the_whole_recording_worse_are_withdrawn_too() {
        let start = Parameters::default();
        let mut found = findings(&start);
        assert!(withdraw_if_worse(&mut found, &start, &errors(0.3, 0.4), &errors(0.1, 0.41), 0.05).is_some());
        assert!(found.effects.is_empty());
    }

    #[test]
    fn a_force_error_larger_by_a_thousandth_of_the_noise_or_less_is_not_worse() {
        let start = Parameters::default();
        let mut found = findings(&start);
        // 0.05 N of noise: up to 5e-5 N is negligible, 6e-5 N is not.
        assert!(withdraw_if_worse(&mut found, &start, &errors(0.3, 0.4), &errors(0.30004, 0.40004), 0.05).is_none());
        assert_eq!(found.effects.len(), 1);
        assert!(withdraw_if_worse(&mut found, &start, &errors(0.3, 0.4), &errors(0.3, 0.40006), 0.05).is_some());
    }
}
