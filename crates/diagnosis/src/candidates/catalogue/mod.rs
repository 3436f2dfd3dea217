//! The candidates: every correction the diagnosis tries, place by place, as instances of the
//! three general mechanisms of [`super`].

mod chambers_to_transducers;
mod command_to_return;
mod terms;

use crate::candidates::Candidate;
use jetpipe_model::physics::parameters::Parameters;

/// Every candidate, for a base model and a recording with or without pressures.
/// `periodic_hz` is the residual's spectral line, if it has one. Where two places fit
/// alike (a command limit and a current limit), the earlier in the chain comes first and
/// wins the tie.
/// `knots` places the static curves' knots ([`crate::candidates::curves`]).
pub fn catalogue(
    base: &Parameters,
    has_pressures: bool,
    periodic_hz: Option<f64>,
    knots: &crate::candidates::curves::CurveKnots,
) -> Vec<Candidate> {
    let mut list = command_to_return::command_to_return(base);
    list.extend(chambers_to_transducers::chambers_to_transducers(
        base,
        has_pressures,
        periodic_hz,
    ));
    list.extend(crate::candidates::curves::candidates(base, knots, has_pressures));
    list.extend(crate::candidates::discharge::candidate(base));
    // A flow into one chamber alone, generated from the extra flow slots' signals.
    list.extend(crate::candidates::extra_flows::candidates(base));
    list
}
