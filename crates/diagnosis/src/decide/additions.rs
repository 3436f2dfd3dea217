//! What the decision adds to the model: named effects and discovered terms, each with the
//! error it removed and the places it cannot be told from.

use crate::candidates::Candidate;
use crate::fit::intervals::Interval;
#[cfg(doc)]
use crate::fit::scored::Localization;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;

/// A named effect that was added.
#[derive(Clone, Debug)]
pub struct AddedEffect {
    pub name: &'static str,
    pub location: Place,
    pub parameters: Vec<(&'static str, f64)>,
    pub evidence: String,
    pub heldout_before: f64,
    pub heldout_after: f64,
    /// Share of the held-out force mean square it removes.
    pub share: f64,
    pub remainder_follows: String,
    /// Other named effects at its place that explained nearly as much when it was named
    /// (name, share of the held-out misfit), tried in its place once every round is done
    /// (`named_rivals.rs`).
    pub rivals: Vec<(&'static str, f64)>,
    /// The named effects this recording cannot tell it from, its own name first; empty when
    /// it tells them apart.
    pub tied_effects: Vec<&'static str>,
    /// The 95 % interval of each of `parameters`, in their order, taken once on the final
    /// model ([`crate::fit::intervals`]): empty until then, `None` for an amount without one.
    pub intervals: Vec<Option<Interval>>,
    /// How clearly its place won in the round that added it ([`Localization::margin`]), in
    /// noise floors; `None` where that round ranked no other place.
    pub margin: Option<f64>,
}

/// A term outside the named effects that was added (see `discover.rs`).
#[derive(Clone, Debug)]
pub struct DiscoveredTerm {
    pub location: Place,
    pub family: Family,
    pub candidate: &'static str,
    /// The FMU parameters that carry it, in SI units.
    pub parameters: Vec<(&'static str, f64)>,
    pub reading: String,
    pub heldout_before: f64,
    pub heldout_after: f64,
    /// Share of the held-out force mean square it removes.
    pub share: f64,
    /// For a term on the pressure transducers, which the force does not see: the held-out
    /// RMS of each pressure, Pa, before and after.
    pub pressures_heldout: Option<([f64; 2], [f64; 2])>,
    /// The places this recording cannot tell the term's from, its own first (at most
    /// [`crate::policy::MOST_TIED_LOCATIONS`]); empty when it tells the place.
    pub tied_locations: Vec<Place>,
    /// As [`AddedEffect::intervals`].
    pub intervals: Vec<Option<Interval>>,
    /// As [`AddedEffect::margin`].
    pub margin: Option<f64>,
    /// For a flexible term, how it compares with the nearest readable form.
    pub flexible: Option<crate::candidates::flexible::Nearest>,
}

impl DiscoveredTerm {
    /// How the term was formed, as the slots and curves its parameters fill show.
    pub fn origin(&self) -> crate::vocabulary::Origin {
        crate::vocabulary::Origin::of_parameters(self.parameters.iter().map(|(n, _)| *n))
    }

    /// The fitted `candidate`, carried by the model parameters `set` (read against their
    /// values in `params`), as a term that takes the held-out force error from `before` to
    /// `after`; its family as the fitted shape reads (a curve that flattens is a limit).
    pub(crate) fn fitted(
        candidate: &Candidate,
        set: Vec<(&'static str, f64)>,
        params: &Parameters,
        before: f64,
        after: f64,
    ) -> Self {
        DiscoveredTerm {
            location: candidate.location,
            family: crate::candidates::curve_reading::family(candidate.family, &set),
            candidate: candidate.label,
            reading: crate::decide::discover::reading(
                candidate.label,
                candidate.location,
                candidate.family,
                &set,
                params,
            ),
            parameters: set,
            heldout_before: before,
            heldout_after: after,
            share: 1.0 - (after / before).powi(2),
            pressures_heldout: None,
            tied_locations: vec![],
            intervals: vec![],
            margin: None,
            flexible: None,
        }
    }
}
