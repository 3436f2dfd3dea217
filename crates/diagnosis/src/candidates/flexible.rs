//! The flexible term: where no readable term brings every channel within its noise, a smooth
//! function of one or two signals of the chain, each read directly or through a first-order
//! low-pass (a departure with a state of its own), added to the constant that stands for its
//! place. It is the modulation class ([`crate::candidates::modulation`]) with a second signal
//! and memory: a bilinear surface over a grid of knots at the signals' quantiles, which the
//! model carries in a flexible slot (`flexible_k_*`, `jetpipe_model::physics::flexible`).
//!
//! The place's constant is one that adds where the place acts: a force on the piston, a mass
//! flow into each chamber, each transducer's offset, the current the driver adds, the jet
//! pipe's offset, the supply and return pressures, and the valve's discharge coefficient
//! (whose change scales every orifice's flow). The stopper position input has none: the
//! model reads the stopper where the recording puts it.
//!
//! Screening is first order, as the modulation class screens
//! (`fit/flexible_screen.rs`); the leading few are fitted through the model.

use crate::candidates::modulation::sensitivity_step;
use crate::candidates::modulation::value_reference;
use crate::candidates::{declared_bounds, interned, parameter_value, unit_of, Candidate, Mechanism, Term};
use crate::input::blocks::Block;
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::modulation::ModulationSignal;
use jetpipe_model::physics::parameters::Parameters;

/// The flexible slots the model has.
pub const SLOTS: usize = 2;

/// Knots on an axis of a surface of one signal, and on each axis of a surface of two.
pub const KNOTS_ALONE: usize = 5;
pub const KNOTS_PAIRED: usize = 4;

/// The low-passes a signal is screened through, s (0: the signal itself). From a hundredth of
/// a second (the chambers' own time) to three seconds (a thermal or leak memory a 40 s
/// protocol still shows several times).
pub const LAGS: [f64; 6] = [0.0, 0.01, 0.03, 0.1, 0.3, 1.0];

/// The constant a flexible term adds to at each place (the place its row in the variable
/// table gives): a force on the piston, a mass flow into each chamber, each transducer's offset,
/// the current's and the jet's offsets, the discharge coefficient, the supply and return.
pub const TARGETS: [&str; 11] = [
    "extra_force_offset",
    "extra_inflow_1",
    "extra_inflow_2",
    "force_sensor_offset",
    "p1_sensor_offset",
    "p2_sensor_offset",
    "i_offset",
    "x_jp_offset",
    "C_d",
    "P_s",
    "P_r",
];

/// The signals a flexible term may follow: every signal of the chain the slots read but the
/// sinusoids (a line is the modulation class's).
pub fn signals() -> impl Iterator<Item = ModulationSignal> {
    ModulationSignal::ALL.into_iter().filter(|s| {
        !matches!(
            s,
            ModulationSignal::None | ModulationSignal::Sine | ModulationSignal::Cosine
        )
    })
}

/// One axis of a surface: a signal, read through a low-pass of `lag` seconds (0: directly).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axis {
    pub signal: ModulationSignal,
    pub lag: f64,
}

impl Axis {
    /// How a reading names it.
    pub fn name(&self) -> String {
        if self.lag > 0.0 {
            format!("{} low-passed over {:.3} s", self.signal.name(), self.lag)
        } else {
            self.signal.name().to_string()
        }
    }
}

/// A surface screened against the residual.
#[derive(Clone, Debug)]
pub struct Surface {
    pub place: Place,
    pub constant: &'static str,
    pub axes: Vec<Axis>,
    /// Each axis's knots.
    pub knots: Vec<Vec<f64>>,
    /// The first-order values at the grid's nodes, axis 1 slowest.
    pub values: Vec<f64>,
    /// Held-out weighted sum of squares after, plus the penalty of its coefficients.
    pub penalised: f64,
}

/// The family of a flexible term: `dynamics` where it has memory, else the place's kind of
/// departure (a force or a flow at a balance, a nonlinearity at a transducer or along the
/// command path).
pub fn family(place: Place, axes: &[Axis]) -> Family {
    if axes.iter().any(|a| a.lag > 0.0) {
        return Family::Dynamics;
    }
    match place {
        Place::Mechanics => Family::ExtraForce,
        Place::Chambers => Family::ExtraFlow,
        _ => Family::Nonlinearity,
    }
}

/// `values` through the slot's low-pass of time constant `lag`, formed as the model forms it
/// between samples: u ← u + (1 − e^(−h/τ)) ((s_before + s_after)/2 − u), from u = s at the
/// first sample (the state the replay starts from is steady).
pub fn low_passed(time: &[f64], values: &[f64], lag: f64) -> Vec<f64> {
    if lag <= 0.0 || values.is_empty() {
        return values.to_vec();
    }
    let mut out = Vec::with_capacity(values.len());
    let mut u = values[0];
    out.push(u);
    for k in 1..values.len() {
        let h = time[k] - time[k - 1];
        let gain = -(-h / lag).exp_m1();
        u += gain * (0.5 * (values[k - 1] + values[k]) - u);
        out.push(u);
    }
    out
}

/// `count` knots at evenly spaced quantiles of the used samples' values (from the 1st to the
/// 99th percentile), strictly increasing; `None` when the signal hardly moves.
pub fn quantile_knots(values: &[f64], blocks: &[Block], count: usize) -> Option<Vec<f64>> {
    let mut kept: Vec<f64> = values
        .iter()
        .zip(blocks)
        .filter(|(v, b)| b.is_used() && v.is_finite())
        .map(|(v, _)| *v)
        .collect();
    if kept.len() < 10 * count {
        return None;
    }
    kept.sort_by(|a, b| a.total_cmp(b));
    let at = |q: f64| kept[((kept.len() - 1) as f64 * q).round() as usize];
    let span = at(0.99) - at(0.01);
    if span.is_nan() || span <= 1e-9 * at(0.5).abs().max(1e-300) {
        return None;
    }
    let mut knots: Vec<f64> = vec![];
    for j in 0..count {
        let x = at(0.01 + 0.98 * j as f64 / (count - 1) as f64);
        if knots.last().map_or(true, |&last| x > last + 1e-3 * span) {
            knots.push(x);
        }
    }
    (knots.len() >= 2).then_some(knots)
}

/// The flexible slot `slot`'s FMU parameter `field` (`"y_2_3"`, `"signal_1"`...).
pub fn slot_parameter(slot: usize, field: &str) -> &'static str {
    interned(format!("flexible_{slot}_{field}"))
}

/// The flexible slots that `params` leaves off.
pub fn free_slots(params: &Parameters) -> Vec<usize> {
    (1..=SLOTS)
        .filter(|&k| parameter_value(params, slot_parameter(k, "parameter")) == 0.0)
        .collect()
}

/// Whether a candidate is a flexible term (it fills a flexible slot).
pub fn is_flexible(c: &Candidate) -> bool {
    c.origin() == crate::vocabulary::Origin::Flexible
}

/// A screened surface as a candidate in flexible slot `slot`: its grid's values are the
/// terms, the constant, signals, lags and knots its settings.
pub fn candidate(s: &Surface, slot: usize, params: &Parameters, catalogue: &[Candidate]) -> Candidate {
    let nominal = parameter_value(params, s.constant);
    let (lower, upper) = declared_bounds(s.constant);
    let step = sensitivity_step(s.constant, params, catalogue);
    let mut settings: Vec<(&'static str, f64)> = vec![
        (slot_parameter(slot, "parameter"), value_reference(s.constant)),
        (slot_parameter(slot, "frequency"), 0.0),
    ];
    for (a, axis) in s.axes.iter().enumerate() {
        settings.push((
            slot_parameter(slot, &format!("signal_{}", a + 1)),
            f64::from(axis.signal.code()),
        ));
        settings.push((slot_parameter(slot, &format!("lag_{}", a + 1)), axis.lag));
        settings.push((
            slot_parameter(slot, &format!("knots_{}", a + 1)),
            s.knots[a].len() as f64,
        ));
        for (j, &x) in s.knots[a].iter().enumerate() {
            settings.push((slot_parameter(slot, &format!("x{}_{}", a + 1, j + 1)), x));
        }
    }
    if s.axes.len() == 1 {
        settings.push((slot_parameter(slot, "signal_2"), 0.0));
        settings.push((slot_parameter(slot, "lag_2"), 0.0));
        settings.push((slot_parameter(slot, "knots_2"), 1.0));
    }
    let columns = s.knots.get(1).map_or(1, Vec::len);
    let terms = (0..s.knots[0].len())
        .flat_map(|i| (0..columns).map(move |j| (i, j)))
        .map(|(i, j)| {
            let name = slot_parameter(slot, &format!("y_{}_{}", i + 1, j + 1));
            Term {
                name,
                unit: unit_of(s.constant),
                mechanism: Mechanism::Parameter(name),
                neutral: 0.0,
                step,
                lower: lower - nominal,
                upper: upper - nominal,
            }
        })
        .collect();
    let follows: Vec<String> = s.axes.iter().map(Axis::name).collect();
    Candidate {
        label: interned(format!("flexible term in {} of {}", s.constant, follows.join(" and "))),
        location: s.place,
        family: family(s.place, &s.axes),
        named: None,
        terms,
        settings,
    }
}

/// How a flexible term compares with the nearest readable form: the best readable candidate
/// of the last localization (at its place, else anywhere) with its held-out misfit, and the
/// flexible term's, both in noise floors (RMS over the held-out samples and channels).
#[derive(Clone, Debug, PartialEq)]
pub struct Nearest {
    pub readable: Option<(&'static str, f64)>,
    pub flexible_noise_floors: f64,
}

/// What a reading of a flexible term says: each axis with how much the term changes along
/// it (the range of the grid's mean over the other axis), and its largest value.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    pub constant: &'static str,
    pub unit: &'static str,
    pub axes: Vec<(Axis, f64)>,
    pub largest: f64,
}

/// The shape of the flexible slot `set` fills, read from its parameters.
pub fn shape(set: &[(&'static str, f64)]) -> Option<Shape> {
    let value = |name: &str| set.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
    let slot = (1..=SLOTS).find(|&k| value(slot_parameter(k, "parameter")).map_or(false, |v| v != 0.0))?;
    let vr = value(slot_parameter(slot, "parameter"))?;
    let constant = jetpipe_model::variables::VARIABLES
        .iter()
        .find(|v| f64::from(v.value_reference) == vr)?;
    let mut axes = vec![];
    let mut counts = vec![];
    for a in 1..=2 {
        let code = value(slot_parameter(slot, &format!("signal_{a}"))).unwrap_or(0.0);
        let signal = ModulationSignal::from_code(code)?;
        let n = value(slot_parameter(slot, &format!("knots_{a}"))).unwrap_or(0.0) as usize;
        if signal == ModulationSignal::None || n == 0 {
            continue;
        }
        let lag = value(slot_parameter(slot, &format!("lag_{a}"))).unwrap_or(0.0);
        axes.push(Axis { signal, lag });
        counts.push(n);
    }
    let (n1, n2) = (*counts.first()?, *counts.get(1).unwrap_or(&1));
    let y = |i: usize, j: usize| value(slot_parameter(slot, &format!("y_{}_{}", i + 1, j + 1))).unwrap_or(0.0);
    let range = |means: Vec<f64>| {
        let (lo, hi) = means
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
        hi - lo
    };
    let along_1 = range(
        (0..n1)
            .map(|i| (0..n2).map(|j| y(i, j)).sum::<f64>() / n2 as f64)
            .collect(),
    );
    let along_2 = range(
        (0..n2)
            .map(|j| (0..n1).map(|i| y(i, j)).sum::<f64>() / n1 as f64)
            .collect(),
    );
    let largest = (0..n1)
        .flat_map(|i| (0..n2).map(move |j| (i, j)))
        .map(|(i, j)| y(i, j))
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(0.0);
    let strengths = [along_1, along_2];
    Some(Shape {
        constant: constant.name,
        unit: constant.unit.unwrap_or(""),
        axes: axes.into_iter().zip(strengths).collect(),
        largest,
    })
}

/// One sentence for a flexible term, or `None` when `set` fills no flexible slot.
pub fn reading(set: &[(&'static str, f64)]) -> Option<String> {
    let s = shape(set)?;
    let along: Vec<String> = s
        .axes
        .iter()
        .map(|(axis, strength)| format!("{} (it changes by {:.4e} {} along it)", axis.name(), strength, s.unit))
        .collect();
    Some(format!(
        "a flexible term added to {}: a smooth function of {}, at most {:+.4e} {}; no readable form at any place brought every channel within its noise",
        s.constant,
        along.join(" and "),
        s.largest,
        s.unit
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_low_pass_follows_a_step_as_one_minus_an_exponential_and_passes_the_signal_without_a_lag() {
        let time: Vec<f64> = (0..2001).map(|k| k as f64 * 1e-3).collect();
        let step: Vec<f64> = time.iter().map(|&t| if t > 0.0 { 1.0 } else { 0.0 }).collect();
        let tau = 0.2;
        let u = low_passed(&time, &step, tau);
        for k in [100, 200, 600, 2000] {
            let want = 1.0 - (-time[k] / tau).exp();
            // The first interval takes half the step (the trapezoid): the exponential half a
            // sample late, with 1 − u larger by cosh(h/2τ), at most (h/τ)²/8 relative.
            let late = 1.0 - (-(time[k] - 0.5e-3) / tau).exp();
            let bound = (1e-3f64 / tau).powi(2) / 8.0 * (1.0 - late);
            assert!(
                (u[k] - late).abs() <= 1.01 * bound && (u[k] - want).abs() < 3e-3,
                "{k}: {} against {late} (bound {bound:e})",
                u[k]
            );
        }
        assert_eq!(low_passed(&time, &step, 0.0), step);
    }

    #[test]
    fn a_flexible_term_reads_its_constant_its_signals_with_their_lags_and_its_size() {
        let set = vec![
            (slot_parameter(1, "parameter"), value_reference("extra_force_offset")),
            (
                slot_parameter(1, "signal_1"),
                f64::from(ModulationSignal::Command.code()),
            ),
            (slot_parameter(1, "lag_1"), 0.3),
            (slot_parameter(1, "knots_1"), 2.0),
            (
                slot_parameter(1, "signal_2"),
                f64::from(ModulationSignal::StopperPosition.code()),
            ),
            (slot_parameter(1, "lag_2"), 0.0),
            (slot_parameter(1, "knots_2"), 2.0),
            (slot_parameter(1, "y_1_1"), 0.0),
            (slot_parameter(1, "y_1_2"), 0.1),
            (slot_parameter(1, "y_2_1"), 0.4),
            (slot_parameter(1, "y_2_2"), 0.5),
        ];
        let s = shape(&set).unwrap();
        assert_eq!(s.constant, "extra_force_offset");
        assert_eq!(s.unit, "N");
        assert!(
            (s.axes[0].1 - 0.4).abs() < 1e-12 && (s.axes[1].1 - 0.1).abs() < 1e-12,
            "{s:?}"
        );
        assert_eq!(s.largest, 0.5);
        let text = reading(&set).unwrap();
        assert!(
            text.contains("v_DA low-passed over 0.300 s") && text.contains("x_s"),
            "{text}"
        );
        assert_eq!(family(Place::Mechanics, &[s.axes[0].0]), Family::Dynamics);
        assert_eq!(family(Place::Mechanics, &[s.axes[1].0]), Family::ExtraForce);
        assert_eq!(family(Place::ForceSensor, &[s.axes[1].0]), Family::Nonlinearity);
    }
}
