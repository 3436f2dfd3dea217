//! Corrections to the model, built from three general mechanisms:
//!
//! * **a constant of the model re-identified** ([`Mechanism::Parameter`]): a thesis
//!   constant with another value, or one of the model's terms that are off in the thesis
//!   model (per-orifice area factors, a return line resistance, chamber vents, and the named
//!   effects' own parameters); a constant **varying in time** is the same constant with its
//!   sensitivity modulated by a ramp or a sinusoid ([`Mechanism::Modulated`]);
//! * **a transform inserted in the chain**: on the command ([`Mechanism::CommandLag`],
//!   [`Mechanism::CurrentLimit`]) or on a measured channel ([`Mechanism::Output`] with a
//!   sensor regressor);
//! * **an extra term in a balance**: a force on the piston from a library of local signals
//!   at the piston (the stopper's position, velocity, acceleration, the sign of its velocity,
//!   v|v|, the sign of its velocity times the chambers' pressures above the return's:
//!   [`Mechanism::Output`] with a mechanics regressor), each column's effect on the measured
//!   force the column itself where the pressures set the force; a mass flow through a vent.
//!
//! Each [`Candidate`] is a set of such terms at one place of the chain. It is fitted by
//! Gauss–Newton with bounds on the training blocks of every measured channel at once (each
//! channel weighted by its noise floor) and scored on the held-out blocks.

use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::extra_force::ProductSignal;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::physics::sensors::{self, Channel, SensorLaw};
use jetpipe_model::variables::VARIABLES;

use crate::replay::signals::{FORCE, P1, P2};

pub(crate) mod catalogue;
pub mod command_curve;
pub mod command_gaps;
pub mod command_path;
pub(crate) mod curve_reading;
pub mod curves;
pub mod discharge;
pub mod extra_flows;
pub mod flexible;
pub mod modulation;
pub mod products;
pub(crate) mod quantiser;

pub use catalogue::catalogue;

/// A signal that a measured channel may carry in proportion to a coefficient.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Regressor {
    One,
    /// The modelled value of the channel itself (a gain), and its powers.
    Own,
    OwnSquared,
    OwnCubed,
    /// −sign(dx_s/dt) where the pressures set the force: Coulomb friction.
    Friction,
    /// −tanh((dx_s/dt) / v_c) there: Coulomb friction reached over a speed v_c (the
    /// candidate's [`Mechanism::Shape`] term).
    SmoothFriction(f64),
    /// −exp(−(v/v_s)²) tanh(v/v_c) there: the Stribeck part, at the candidate's two shapes
    /// (v_c, v_s).
    Stribeck(f64, f64),
    /// −dx_s/dt where the pressures set the force: viscous friction.
    Viscous,
    /// x_s minus its mean where the pressures set the force: a spring on the piston.
    Position,
    /// The stopper acceleration as the model forms it (`jetpipe_model::physics::extra_force`)
    /// where the pressures set the force: a moving mass (its coefficient −m).
    Acceleration,
    /// v |v| there: quadratic damping (its coefficient negative).
    VelocitySquared,
    /// tanh(v / v_e) (P1 + P2 − 2 P_r) there, with the model's pressures: a seal friction
    /// that grows with the pressure. The speed v_e (`extra_force_sign_velocity`) is the
    /// candidate's [`Mechanism::Shape`] term (0: the base model's).
    SignPressure(f64),
    /// A product of two of the mechanics' signals there, the first less `origin`, each over
    /// its reference unit, as the model's product slots form it
    /// (`jetpipe_model::physics::extra_force::ProductSlot::regressor`; [`crate::candidates::products`]).
    Product {
        first: ProductSignal,
        second: ProductSignal,
        origin: f64,
    },
    /// (t − t_mid) / (t_end − t_start): drift.
    Ramp,
    Sine(f64),
    Cosine(f64),
    /// The share of the segment [lo, hi] that the channel's modelled value has risen
    /// through (0 below it, 1 above it; the end segments continued below or above): a
    /// static curve's increment ([`crate::candidates::curves`]).
    Segment {
        lo: f64,
        hi: f64,
        below: bool,
        above: bool,
    },
}

/// How a sensor may read its quantity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Filter {
    Delay,
    Lag,
    /// A second-order low-pass filter of this damping ratio; the coefficient is its natural
    /// frequency (Hz).
    SecondOrder(f64),
    Play,
}

impl Filter {
    /// The reading of `x` through the filter with coefficient `value`: the model's own
    /// transducer law (every channel's transducer is read the same way).
    pub fn apply(self, time: &[f64], x: &[f64], value: f64) -> Vec<f64> {
        let mut law = SensorLaw::of(&Parameters::default(), Channel::Force);
        match self {
            Filter::Delay => law.delay = value,
            Filter::Lag => law.lag = value,
            Filter::SecondOrder(damping) => {
                law.filter_frequency = value;
                law.filter_damping = damping;
            }
            Filter::Play => law.play = value,
        }
        sensors::filtered(&law, time, x.to_vec())
    }

    /// The model parameter that carries this filter on the measured `channel`, if the
    /// model's transducer there has it.
    pub fn sensor_parameter(self, channel: usize) -> Option<&'static str> {
        Some(match (channel, self) {
            (FORCE, Filter::Delay) => "force_sensor_delay",
            (FORCE, Filter::Lag) => "force_sensor_lag",
            (FORCE, Filter::SecondOrder(_)) => "force_sensor_filter_frequency",
            (FORCE, Filter::Play) => "force_sensor_play",
            (P1, Filter::Delay) => "p1_sensor_delay",
            (P1, Filter::Lag) => "p1_sensor_lag",
            (P1, Filter::SecondOrder(_)) => "p1_sensor_filter_frequency",
            (P2, Filter::Delay) => "p2_sensor_delay",
            (P2, Filter::Lag) => "p2_sensor_lag",
            (P2, Filter::SecondOrder(_)) => "p2_sensor_filter_frequency",
            _ => return None,
        })
    }
}

/// How a time-varying constant varies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Modulation {
    Ramp,
    Sine(f64),
    Cosine(f64),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mechanism {
    /// An FMU parameter of the model.
    Parameter(&'static str),
    /// An FMU parameter whose effect is not smooth from its neutral value (an orifice that
    /// is off at 0 area and at an infinite one), or nearly flat there (a corner frequency far
    /// above the signals'): found by a search over its range on a logarithmic scale.
    Searched(&'static str),
    /// A first-order lag (time constant, s) on the command the current driver sees.
    CommandLag,
    /// A corner frequency of the model (rad/s) fitted as its time constant 1/ω (s): where the
    /// corner lies above the signals the outputs move nearly linearly with the time constant
    /// (a lag that short is nearly a delay of its length), not with the frequency, so that a
    /// Gauss–Newton step from the thesis's corner reaches a slower one.
    TimeConstantOf(&'static str),
    /// The command the current driver sees saturates at ± this (V).
    CommandLimit,
    /// A cubic term on the static curve's input: the tip force k_m i, and so (the current
    /// driver being linear and fast) the command, bent by this times (v / 10 V)³.
    InputCubic,
    /// The current saturates at ± this (A): the command clipped where k_cd v + i_offset
    /// reaches it (the current driver is linear, so the two are the same).
    CurrentLimit,
    /// The current slews at most this fast (A/s): the command rate-limited where k_cd
    /// times it reaches that (the current driver is fast beside it).
    CurrentSlewLimit,
    /// A measured channel read through a delay, a lag or a play (the coefficient: its
    /// time, s, or its width in the channel's unit).
    OutputFilter { channel: usize, filter: Filter },
    /// A term on a measured channel: coefficient × regressor.
    Output { channel: usize, regressor: Regressor },
    /// The shape parameter of the candidate's regressors (a friction's speed scale) or of its
    /// filter (a second-order filter's damping ratio), found by a search over its range on a
    /// logarithmic scale with the amplitudes (or the filter's frequency) found at each value.
    Shape,
    /// A parameter varying in time: coefficient × its sensitivity × the modulation (first order).
    Modulated {
        parameter: &'static str,
        modulation: Modulation,
    },
}

impl Mechanism {
    pub(crate) fn is_searched(&self) -> bool {
        matches!(
            self,
            Mechanism::CurrentLimit
                | Mechanism::CommandLimit
                | Mechanism::CurrentSlewLimit
                | Mechanism::OutputFilter { .. }
                | Mechanism::Searched(_)
                | Mechanism::Shape
        )
    }

    /// The model parameter that carries this term in the replay, if one does.
    pub fn model_parameter(&self) -> Option<&'static str> {
        match *self {
            Mechanism::Parameter(name) | Mechanism::Searched(name) | Mechanism::TimeConstantOf(name) => Some(name),
            Mechanism::CommandLag => Some("command_lag"),
            Mechanism::CommandLimit => Some("command_limit"),
            Mechanism::CurrentLimit => Some("current_limit"),
            Mechanism::CurrentSlewLimit => Some("current_slew_limit"),
            Mechanism::InputCubic => Some("f3_input_cubic"),
            _ => None,
        }
    }

    /// The model parameter's value for the term's value `value` (a time constant's corner).
    pub fn model_value(&self, value: f64) -> f64 {
        match self {
            Mechanism::TimeConstantOf(_) => 1.0 / value,
            _ => value,
        }
    }

    pub(crate) fn is_linear(&self) -> bool {
        matches!(self, Mechanism::Output { .. } | Mechanism::Modulated { .. })
    }
}

/// One coefficient of a candidate.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    /// The name the report gives it (an FMU parameter name where it is one).
    pub name: &'static str,
    pub unit: &'static str,
    pub mechanism: Mechanism,
    /// Value with the term off (for parameters: their value in the base model).
    pub neutral: f64,
    /// Finite-difference step, and a typical size.
    pub step: f64,
    pub lower: f64,
    pub upper: f64,
}

/// Terms at one place of the chain, fitted together.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub label: &'static str,
    pub location: Place,
    pub family: Family,
    /// The named effect this candidate is, if it is one.
    pub named: Option<&'static str>,
    pub terms: Vec<Term>,
    /// Model parameters set before its terms are fitted (a ripple's frequency).
    pub settings: Vec<(&'static str, f64)>,
}

impl Candidate {
    /// How the candidate was formed: named, or as the slots and curves it fills show.
    pub fn origin(&self) -> crate::vocabulary::Origin {
        if self.named.is_some() {
            return crate::vocabulary::Origin::Named;
        }
        crate::vocabulary::Origin::of_parameters(
            self.settings
                .iter()
                .map(|(n, _)| *n)
                .chain(self.terms.iter().map(|t| t.name)),
        )
    }
}

/// The unit of an FMU parameter, from the variable table.
pub fn unit_of(name: &str) -> &'static str {
    jetpipe_model::variables::VARIABLES
        .iter()
        .find(|v| v.name == name)
        .and_then(|v| v.unit)
        .unwrap_or("")
}

#[cfg(test)]
impl Candidate {
    /// A candidate at the jet pipe with a term of each mechanism, for tests.
    pub(crate) fn of_mechanisms(terms: Vec<Mechanism>) -> Candidate {
        Candidate {
            label: "test",
            location: Place::JetPipe,
            family: Family::Dynamics,
            named: None,
            terms: terms
                .into_iter()
                .map(|mechanism| Term {
                    name: "x",
                    unit: "1",
                    mechanism,
                    neutral: 0.0,
                    step: 1e-3,
                    lower: -1.0,
                    upper: 1.0,
                })
                .collect(),
            settings: vec![],
        }
    }
}

fn value_reference(name: &str) -> u32 {
    VARIABLES
        .iter()
        .find(|v| v.name == name)
        .map(|v| v.value_reference)
        .unwrap_or_else(|| panic!("{name} is not a variable of the model"))
}

/// The base model's value of an FMU parameter.
pub fn parameter_value(p: &Parameters, name: &str) -> f64 {
    p.get(value_reference(name))
        .unwrap_or_else(|| panic!("{name} is not a parameter"))
}

/// The bounds the variable table declares for a parameter (infinite where it declares none).
pub fn declared_bounds(name: &str) -> (f64, f64) {
    match Parameters::declared_range(value_reference(name)) {
        Some((lower, upper)) => (lower.unwrap_or(f64::NEG_INFINITY), upper.unwrap_or(f64::INFINITY)),
        None => (f64::NEG_INFINITY, f64::INFINITY),
    }
}

/// Set an FMU parameter, with the model's own checks.
pub fn set_parameter(p: &mut Parameters, name: &str, value: f64) -> Result<(), String> {
    p.set(value_reference(name), value)
}

/// `params` with each parameter of `set` back at its value in `start`: the model without the
/// addition that set them. `Err` (the model's reason) when the model refuses that, because a
/// later term leans on the value (a dead volume varying in time, added beside a named dead
/// volume, takes the volume below 0 once the named one is removed); no rival can then stand
/// in the addition's place, and the caller keeps it rather than stopping the diagnosis.
pub fn without_addition(
    params: &Parameters,
    start: &Parameters,
    set: &[(&'static str, f64)],
) -> Result<Parameters, String> {
    let mut without = params.clone();
    for (name, _) in set {
        set_parameter(&mut without, name, parameter_value(start, name))?;
    }
    without.validate()?;
    Ok(without)
}

/// A name built at run time (a generated candidate's parameter or label) as the `&'static str`
/// the candidates carry: each distinct text is leaked once and shared afterwards, so the
/// memory held is bounded by the number of distinct generated names.
pub(crate) fn interned(text: String) -> &'static str {
    use std::collections::HashSet;
    use std::sync::Mutex;
    static NAMES: Mutex<Option<HashSet<&'static str>>> = Mutex::new(None);
    let mut names = NAMES.lock().unwrap_or_else(|e| e.into_inner());
    let set = names.get_or_insert_with(HashSet::new);
    if let Some(&name) = set.get(text.as_str()) {
        return name;
    }
    let name: &'static str = Box::leak(text.into_boxed_str());
    set.insert(name);
    name
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_corner_fitted_as_its_time_constant_puts_its_frequency_into_the_model() {
        let term = Mechanism::TimeConstantOf("omega_cd");
        assert_eq!(term.model_parameter(), Some("omega_cd"));
        assert_eq!(term.model_value(2e-3), 500.0);
        assert_eq!(Mechanism::Parameter("k_cd").model_value(0.05), 0.05);
        // The current driver's corner in the catalogue starts at the model's own.
        let base = Parameters::default();
        let knots = crate::candidates::curves::CurveKnots {
            command: vec![],
            channels: [vec![], vec![], vec![]],
        };
        let corner = catalogue(&base, true, None, &knots)
            .into_iter()
            .find(|c| c.label == "current driver corner")
            .unwrap();
        let start = &corner.terms[0];
        assert_eq!(start.mechanism.model_value(start.neutral), base.omega_cd);
    }

    #[test]
    fn an_addition_a_later_term_leans_on_cannot_be_removed_and_says_why_while_one_alone_can() {
        use jetpipe_model::physics::modulation::ModulationSignal;
        let start = Parameters::default();
        let mut named = start.clone();
        set_parameter(&mut named, "dead_volume_1", 1e-6).unwrap();
        let dead_volume = [("dead_volume_1", 1e-6)];
        let alone = without_addition(&named, &start, &dead_volume).unwrap();
        assert_eq!(alone, start);
        // A term added later lets the volume wander in time down to 0.1 cm3 (valid with the
        // named 1 cm3, below 0 without it).
        let mut leaning = named.clone();
        for (name, value) in [
            (
                "modulation_1_parameter",
                f64::from(jetpipe_model::variables::vr::DEAD_VOLUME_1),
            ),
            ("modulation_1_signal", f64::from(ModulationSignal::Time.code())),
            ("modulation_1_knots", 2.0),
            ("modulation_1_x_1", 0.0),
            ("modulation_1_x_2", 10.0),
            ("modulation_1_y_1", -0.9e-6),
            ("modulation_1_y_2", 0.5e-6),
        ] {
            set_parameter(&mut leaning, name, value).unwrap();
        }
        leaning.validate().unwrap();
        let why = without_addition(&leaning, &start, &dead_volume).unwrap_err();
        assert!(why.contains("dead_volume_1"), "{why}");
    }

    #[test]
    fn every_catalogue_parameter_is_a_parameter_of_the_model_within_its_declared_limits() {
        let base = Parameters::default();
        let knots = crate::candidates::curves::CurveKnots {
            command: vec![],
            channels: [vec![], vec![], vec![]],
        };
        for candidate in catalogue(&base, true, Some(50.0), &knots) {
            for term in &candidate.terms {
                let Some(name) = term.mechanism.model_parameter() else {
                    continue;
                };
                let (lower, upper) = declared_bounds(name);
                let start = term.mechanism.model_value(term.neutral);
                if term.neutral.is_finite() {
                    assert!(
                        (lower..=upper).contains(&start),
                        "{}: {name} starts at {start}, outside [{lower}, {upper}]",
                        candidate.label
                    );
                }
            }
        }
    }
}
