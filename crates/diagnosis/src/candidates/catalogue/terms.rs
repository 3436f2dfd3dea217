//! The terms the written catalogue is made of: a constant of the table, a term off by
//! default, an output filter or regressor, a searched term.

use crate::candidates::parameter_value;
use crate::candidates::Candidate;
use crate::candidates::Filter;
use crate::candidates::Mechanism;
use crate::candidates::Modulation;
use crate::candidates::Regressor;
use crate::candidates::Term;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;

pub(super) fn parameter(
    base: &Parameters,
    name: &'static str,
    unit: &'static str,
    relative: f64,
    lower: f64,
    upper: f64,
) -> Term {
    let neutral = parameter_value(base, name);
    Term {
        name,
        unit,
        mechanism: Mechanism::Parameter(name),
        neutral,
        step: relative * neutral.abs().max(1e-30),
        lower,
        upper,
    }
}

pub(super) fn term_off(name: &'static str, unit: &'static str, step: f64, upper: f64) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Parameter(name),
        neutral: 0.0,
        step,
        lower: 0.0,
        upper,
    }
}

/// A restriction as an orifice ([`orifice_area`]) and the gas volume behind it. The orifice
/// alone is the volume's limit at zero, where its refinement may take it: a quasi-static
/// orifice needs a root at every evaluation, and a replay with it takes two to three times
/// as long, so it is not a candidate of its own. The area is searched with a
/// volume that fills within a tenth of a millisecond (0.1 cm³: the restriction nearly alone,
/// at the cost of the fast replay's fixed steps rather than a root at every evaluation), then
/// both are refined together ([`Mechanism::Searched`] followed by parameters).
pub(super) fn volume_behind(area: &'static str, volume: &'static str) -> Vec<Term> {
    vec![orifice_area(area), started(volume, "m3", 1e-7, 2e-7, 0.0, 1e-4)]
}

/// A corner frequency (rad/s) searched over `lower`–`upper` on a logarithmic scale: the
/// outputs barely move with a corner far above the signals' frequencies, so one Gauss–Newton
/// step from the thesis's fast corner does not reach a slow one (the jet pipe's 974 rad/s
/// against an extra 15 ms lag, 60 rad/s together).
pub(super) fn corner(base: &Parameters, name: &'static str, lower: f64, upper: f64) -> Term {
    Term {
        name,
        unit: "rad/s",
        mechanism: Mechanism::Searched(name),
        neutral: parameter_value(base, name),
        step: 0.0,
        lower,
        upper,
    }
}

/// An orifice's C_d·A (m²), searched over 0.01–10 mm² on a logarithmic scale: it is off at
/// zero area and at an infinite one.
pub(super) fn orifice_area(name: &'static str) -> Term {
    Term {
        name,
        unit: "m2",
        mechanism: Mechanism::Searched(name),
        neutral: 0.0,
        step: 0.0,
        lower: 1e-8,
        upper: 1e-5,
    }
}

/// Where the Bouc–Wen law's fit starts: exponent, gain and β share (a rounded bend, the
/// output still at a reversal, symmetric).
pub(super) const BOUC_WEN_START: [f64; 3] = [2.0, 1.0, 0.5];
/// The thesis's width of the position/current loop (§3.2.1, 0.16 mm): with the law on from
/// the start, its shape parameters have sensitivities at the first step.
pub(super) const BOUC_WEN_START_WIDTH: f64 = 0.16e-3;

/// A parameter whose fit starts at `start` rather than at the base model's value (a law's
/// shape, which only matters once the law is on).
pub(super) fn started(name: &'static str, unit: &'static str, start: f64, step: f64, lower: f64, upper: f64) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Parameter(name),
        neutral: start,
        step,
        lower,
        upper,
    }
}

pub(super) fn output(name: &'static str, unit: &'static str, channel: usize, regressor: Regressor, step: f64) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Output { channel, regressor },
        neutral: 0.0,
        step,
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
    }
}

pub(super) fn filter(
    name: &'static str,
    unit: &'static str,
    channel: usize,
    filter: Filter,
    lower: f64,
    upper: f64,
) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::OutputFilter { channel, filter },
        neutral: 0.0,
        step: 0.0,
        lower,
        upper,
    }
}

/// A second-order low-pass filter on a measured channel: its natural frequency searched on
/// a logarithmic scale for each damping ratio tried (the damping a shape, 0.2–5).
pub(super) fn second_order(frequency: &'static str, damping: &'static str, channel: usize) -> Vec<Term> {
    vec![
        filter(
            frequency,
            "Hz",
            channel,
            Filter::SecondOrder(std::f64::consts::FRAC_1_SQRT_2),
            1.0,
            2000.0,
        ),
        Term {
            name: damping,
            unit: "1",
            mechanism: Mechanism::Shape,
            neutral: std::f64::consts::FRAC_1_SQRT_2,
            step: 0.0,
            lower: 0.2,
            upper: 5.0,
        },
    ]
}

pub(super) fn modulated(
    name: &'static str,
    unit: &'static str,
    parameter: &'static str,
    modulation: Modulation,
    step: f64,
) -> Term {
    Term {
        name,
        unit,
        mechanism: Mechanism::Modulated { parameter, modulation },
        neutral: 0.0,
        step,
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
    }
}

/// A candidate of the written catalogue: its label, place, family, the named effect it is (if
/// any) and its terms.
pub(super) fn c(
    label: &'static str,
    location: Place,
    family: Family,
    named: Option<&'static str>,
    terms: Vec<Term>,
) -> Candidate {
    Candidate {
        label,
        location,
        family,
        named,
        terms,
        settings: vec![],
    }
}

/// A term searched over its range rather than solved for.
pub(super) fn searched(name: &'static str, unit: &'static str, mechanism: Mechanism, lower: f64, upper: f64) -> Term {
    Term {
        name,
        unit,
        mechanism,
        neutral: f64::INFINITY,
        step: 0.0,
        lower,
        upper,
    }
}
