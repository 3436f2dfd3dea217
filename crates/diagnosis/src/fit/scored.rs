//! A candidate's score in one round, and the places of the chain ranked by the candidates
//! scored there (where the model departs).

use crate::fit::Fit;
use crate::policy::ALTERNATIVE_REMAINDER;
use crate::policy::LOCATED_SHARE;
use crate::policy::MOST_TIED_LOCATIONS;
use crate::vocabulary::{Family, Place};

/// A candidate's score in one round.
#[derive(Clone, Debug)]
pub struct Scored {
    pub fit: Fit,
    /// Share of the held-out misfit (all channels, each in its noise floors) it removes.
    pub explained: f64,
    /// Held-out force RMS error with it, N.
    pub force_heldout_rms: f64,
}

impl Scored {
    pub fn parameters(&self) -> Vec<(&'static str, f64)> {
        self.fit
            .candidate
            .terms
            .iter()
            .zip(&self.fit.values)
            .map(|(t, v)| (t.name, *v))
            .collect()
    }
}

/// Where the model departs, from one round of candidates.
#[derive(Clone, Debug)]
pub struct Localization {
    /// The place whose best candidate explains most, or "unknown" when none explains
    /// [`LOCATED_SHARE`] of the misfit.
    pub location: Place,
    pub family: Family,
    /// Best share explained at each place, best first, with the candidate that did it.
    pub by_location: Vec<(Place, f64, &'static str)>,
    pub candidates: Vec<Scored>,
    /// The held-out misfit before any candidate, per held-out sample and measured channel,
    /// in noise floors squared: what turns a share explained into an error, for the margins.
    pub before_mean_square: f64,
}

impl Localization {
    pub(crate) fn best_at(&self, location: Place) -> Option<&Scored> {
        self.candidates
            .iter()
            .filter(|s| s.fit.candidate.location == location)
            .max_by(|a, b| a.explained.total_cmp(&b.explained))
    }

    /// A clause naming the places that explain nearly as much as the located one
    /// ([`Localization::alternatives`]), with their shares, for a term added at `added` (the
    /// located place or one of those); `None` when there are none. What the recording cannot
    /// tell apart is said beside what was added.
    pub fn undecided_beside(&self, added: Place, has_pressures: bool) -> Option<String> {
        let others: Vec<String> = std::iter::once(self.location)
            .chain(self.alternatives())
            .filter(|l| *l != added)
            .filter_map(|l| self.by_location.iter().find(|(at, _, _)| *at == l))
            .map(|(l, e, _)| format!("the {l} ({:.1} %)", 100.0 * e))
            .collect();
        if others.is_empty() {
            return None;
        }
        Some(format!(
            "a correction at {} explains nearly as much, which this recording does not tell apart{}",
            others.join(" or at "),
            if has_pressures {
                ""
            } else {
                " (pressure channels would split the chain at the piston)"
            }
        ))
    }

    /// The places a term added at `added` cannot be told apart from on this recording
    /// ([`Self::alternatives`] and the located place), `added` first and at most three in
    /// all; empty when the recording tells the place.
    pub fn tied_with(&self, added: Place) -> Vec<Place> {
        let others: Vec<Place> = std::iter::once(self.location)
            .chain(self.alternatives())
            .filter(|l| *l != added)
            .collect();
        if others.is_empty() {
            return vec![];
        }
        std::iter::once(added).chain(others).take(MOST_TIED_LOCATIONS).collect()
    }

    /// How clearly `place` won: the held-out misfit the best candidate of the next-best place
    /// leaves, minus the one `place`'s best leaves, each as an RMS in noise floors over the
    /// held-out samples of every measured channel (with the force alone, the difference of
    /// the two held-out force errors over its floor). Negative for a place that is not the
    /// best; `None` when `place` has no candidate or no other place has one. RMS, not mean
    /// square: a margin of one noise floor then reads the same at 2 floors as at 20.
    pub fn margin(&self, place: Place) -> Option<f64> {
        let own = self.by_location.iter().find(|(l, _, _)| *l == place)?.1;
        let next = self
            .by_location
            .iter()
            .filter(|(l, _, _)| *l != place)
            .map(|(_, e, _)| *e)
            .max_by(f64::total_cmp)?;
        let left = |share: f64| (self.before_mean_square * (1.0 - share)).max(0.0).sqrt();
        Some(left(next) - left(own))
    }

    /// Places that explain nearly as much as the best: they leave at most a quarter more
    /// of the held-out misfit than it does. Measured on what is left, not on the share
    /// explained: where the model is far off, 99 % explained can leave seven noise floors
    /// beside one.
    pub fn alternatives(&self) -> Vec<Place> {
        let Some(&(_, top, _)) = self.by_location.first() else {
            return vec![];
        };
        self.by_location
            .iter()
            .skip(1)
            .filter(|(_, e, _)| 1.0 - *e <= ALTERNATIVE_REMAINDER * (1.0 - top) && *e >= LOCATED_SHARE)
            .map(|(l, _, _)| *l)
            .collect()
    }
}
