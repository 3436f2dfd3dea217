//! The jet pipe positions at all stages of one step of the chambers' integrator at once.
//! Where a closed form applies, the exponentials are taken at the step's start and carried
//! to each stage by products with those at cᵢh, which are kept per step size: the step
//! sizes recur, so most steps need one set of transcendental functions instead of one per
//! stage. The memo never changes a result, so a restored FMU state continues to the bit.

use crate::physics::jet_pipe::StaticCurve;

use super::modal::Exponentials;
use super::series::{RampForm, SeriesForm};
use super::{ElectromechanicalPropagator, Trajectory};

/// The closed form a trajectory's positions come from, when it has one.
#[derive(Clone, Copy)]
pub(super) enum ClosedForm<'f> {
    Series(&'f SeriesForm),
    Ramp(&'f RampForm),
}

/// Most stages of one step [`Trajectory::node_positions`] takes: Verner's eight after the
/// first (Dormand–Prince has six).
pub const MAX_NODES: usize = 8;
/// Sets of two step sizes whose advances are kept (34 kB, allocated on first use): the
/// error-controlled steps and the rest of each communication step come in some hundred
/// sizes (the closed loop's current transients spread them most), and with 32 direct-mapped
/// slots three in ten steps of the closed loop recomputed theirs, with 128 in two-way sets
/// one in fifteen.
pub(super) const ADVANCE_SETS: usize = 64;

#[derive(Clone, Debug, Default)]
pub(super) struct AdvanceTable {
    pub(super) nodes: [f64; MAX_NODES],
    pub(super) count: usize,
    pub(super) sets: Vec<AdvanceSet>,
}

/// Two step sizes and their advances (h is NaN in a way not yet used), and which of the two
/// was used less recently: the one a new size replaces.
#[derive(Clone, Copy, Debug)]
pub(super) struct AdvanceSet {
    pub(super) ways: [(f64, [Exponentials; MAX_NODES]); 2],
    pub(super) older: usize,
}

/// A memo inside the propagator: it changes no result, so two propagators that differ
/// only in it are equal.
#[derive(Clone, Debug, Default)]
pub(super) struct AdvanceCache(std::cell::RefCell<AdvanceTable>);

impl PartialEq for AdvanceCache {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

impl<C> ElectromechanicalPropagator<C> {
    /// The exponentials at cᵢh for `nodes` cᵢ (`None` for more than [`MAX_NODES`]), kept
    /// per step size: stage positions are the product of the exponentials at the step's
    /// start and these, one set of transcendental functions per step instead of one per
    /// stage whenever the step size recurs, as it does while the chambers' integrator is
    /// capped at a quarter of the ringing period, and on its grid of step sizes otherwise.
    /// A step size met for the first time costs what positions one by one would, and
    /// takes the same product: the positions never depend on what the memo held, so a
    /// restored FMU state continues to the bit.
    pub(super) fn with_advances<R>(
        &self,
        h: f64,
        nodes: &[f64],
        use_them: impl FnOnce(&[Exponentials]) -> R,
    ) -> Option<R> {
        if nodes.len() > MAX_NODES {
            return None;
        }
        let mut cache = self.advances.0.borrow_mut();
        if cache.nodes[..cache.count] != *nodes {
            cache.sets.clear();
            cache.nodes[..nodes.len()].copy_from_slice(nodes);
            cache.count = nodes.len();
        }
        if cache.sets.is_empty() {
            let unused = (f64::NAN, [Exponentials::default(); MAX_NODES]);
            cache.sets.resize(
                ADVANCE_SETS,
                AdvanceSet {
                    ways: [unused; 2],
                    older: 0,
                },
            );
        }
        // Two-way sets on the top mantissa bits and the low exponent bits, which tell the
        // integrator's grid sizes apart.
        let bits = h.to_bits();
        let set = &mut cache.sets[((bits >> 47) ^ (bits >> 52)) as usize % ADVANCE_SETS];
        let way = match set.ways.iter().position(|(kept, _)| *kept == h) {
            Some(way) => way,
            None => {
                let way = set.older;
                let (kept, advances) = &mut set.ways[way];
                *kept = h;
                for (advance, c) in advances.iter_mut().zip(nodes) {
                    *advance = self.exponentials(c * h, true);
                }
                way
            }
        };
        set.older = 1 - way;
        Some(use_them(&set.ways[way].1[..nodes.len()]))
    }
}

impl<C: StaticCurve> Trajectory<'_, C> {
    /// Jet pipe positions at the stage offsets `offsets` (sᵢ = s0 + cᵢh up to rounding) of
    /// one step of a one-step method from `s0` with size `h` and nodes cᵢ, into `out`.
    /// Where the response has a closed form and `h` has come before, the exponentials are
    /// taken once, at s0, and carried to each stage by a product with those at cᵢh (see
    /// `ElectromechanicalPropagator::with_advances`); otherwise each is [`Self::position`].
    /// The two agree to rounding (`node_positions_match_the_positions`).
    pub fn node_positions(&self, s0: f64, h: f64, nodes: &[f64], offsets: &[f64], out: &mut [f64]) {
        if let Some((from, late)) = self
            .late
            .as_ref()
            .filter(|(from, _)| s0 >= *from && offsets.len() <= MAX_NODES)
        {
            let mut late_offsets = [0.0; MAX_NODES];
            for (late_s, s) in late_offsets.iter_mut().zip(offsets) {
                *late_s = s - from;
            }
            return late.node_positions(s0 - from, h, nodes, &late_offsets[..offsets.len()], out);
        }
        let p = self.propagator;
        let form = match (&self.series_form, &self.ramp_form) {
            (Some(form), _) => Some(ClosedForm::Series(form)),
            (None, Some(form)) if form.covers(s0) && offsets.iter().all(|&s| form.covers(s)) => {
                Some(ClosedForm::Ramp(form))
            }
            _ => None,
        };
        if let Some(form) = form {
            let with_decay = match form {
                ClosedForm::Series(series) => offsets.iter().any(|&s| s < series.transient_over),
                ClosedForm::Ramp(_) => false,
            };
            let done = p.with_advances(h, nodes, |advances| {
                // At a step's start the exponentials are 1, and the products the advances.
                let at_start = (s0 != 0.0).then(|| p.exponentials(s0, with_decay));
                let mut last = None;
                for ((x, &s), advance) in out.iter_mut().zip(offsets).zip(advances) {
                    let e = at_start.map_or(*advance, |start| start.then(advance));
                    *x = match form {
                        ClosedForm::Series(series) => series.position_from(s, &e),
                        ClosedForm::Ramp(ramp) => ramp.position_from(s, &e),
                    };
                    last = Some((s, e));
                }
                if with_decay && matches!(form, ClosedForm::Series(_)) {
                    self.last_node.set(last);
                }
            });
            if done.is_some() {
                return;
            }
        }
        let mut last: Option<(f64, f64)> = None;
        for (x, &s) in out.iter_mut().zip(offsets) {
            *x = match last {
                Some((at, position)) if at == s => position,
                _ => self.position(s),
            };
            last = Some((s, *x));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::modal::modulus;
    use super::super::tests::{ramp_start, swinging};
    use super::*;
    use crate::physics::effects::PLAY_OPERATORS;
    use crate::physics::parameters::Parameters;

    /// Stage positions carried from the step's start by the advances of a recurring step
    /// size are the positions, to rounding: for a held command (with and without its
    /// current transient over within the step), a ramp, and a case with no closed form.
    #[test]
    fn node_positions_match_the_positions() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let swinging = swinging();
        let ramp_start = |v: f64, rate: f64| ramp_start(&p, v, rate);
        let nodes = [0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
        let mut fast_paths = 0;
        // The case without a closed form first (a ramp with its current transient): it must
        // not even record a step size. A jump too large for the series has none until it
        // has decayed enough, then the series form.
        for (start, v, rate, form) in [
            (swinging, 1.0, 400.0, "none"),
            (swinging, -10.0, 0.0, "late"),
            (swinging, 3.1, 0.0, "series"),
            (swinging, 1.3, 0.0, "series"),
            (ramp_start(1.0, 2.5), 1.0, 2.5, "ramp"),
        ] {
            let trajectory = propagator.trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS]);
            match form {
                "series" => assert!(trajectory.series_form.is_some()),
                "ramp" => assert!(trajectory.ramp_form.is_some()),
                _ => assert!(trajectory.series_form.is_none() && trajectory.ramp_form.is_none()),
            }
            let late_from = trajectory.late.as_ref().map(|(from, _)| *from);
            assert_eq!(late_from.is_some(), form == "late");
            if let Some(from) = late_from {
                // After the first step below, before the second.
                assert!(from > 8.5e-5 && from < 3.1e-4, "{from}");
            }
            // Early steps (transient alive) and late ones (past `transient_over` for the
            // held commands), each asked for twice: the second time takes the advances.
            // Both sum the modes' exponentials and round like the largest of them.
            let amplitudes = |t: &Trajectory| {
                t.series_form
                    .as_ref()
                    .map_or(0.0, |f| f.amplitude.iter().map(|a| modulus(*a)).sum::<f64>())
            };
            let largest_mode =
                amplitudes(&trajectory).max(trajectory.late.as_ref().map_or(0.0, |(_, l)| amplitudes(l)));
            for (s0, h) in [(0.0, 8.5e-5), (3.1e-4, 8.5e-5), (4.0e-3, 8.4e-4), (7.7e-3, 2.3e-3)] {
                let offsets: Vec<f64> = nodes.iter().map(|c| s0 + c * h).collect();
                let mut first_time = None;
                for _ in 0..2 {
                    let mut out = [0.0; 6];
                    trajectory.node_positions(s0, h, &nodes, &offsets, &mut out);
                    // The memo changes no bit: a step size met for the first time gives what
                    // it gives once kept (a restored FMU state continues exactly).
                    assert_eq!(*first_time.get_or_insert(out), out, "{form} s0 {s0} h {h}");
                    for (x, &s) in out.iter().zip(&offsets) {
                        let exact = trajectory.position(s);
                        assert!(
                            (x - exact).abs() <= 1e-15 * p.x_jp_sat.max(largest_mode),
                            "{form} v {v} s0 {s0} h {h} s {s}: {x} vs {exact}"
                        );
                    }
                    // The state at the last node, from the exponentials kept there, is a
                    // fresh trajectory's to rounding.
                    let end = *offsets.last().unwrap();
                    let kept = trajectory.state(end);
                    let fresh = propagator
                        .trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS])
                        .state(end);
                    let rate_scale = propagator.lambda.iter().map(|l| modulus(*l)).fold(0.0, f64::max);
                    let scale = 1e-15 * p.x_jp_sat.max(largest_mode);
                    assert!(
                        (kept.current - fresh.current).abs()
                            <= 1e-15 * (fresh.current.abs() + trajectory.drive.delta.abs()),
                        "{kept:?} {fresh:?}"
                    );
                    assert!((kept.position - fresh.position).abs() <= scale, "{kept:?} {fresh:?}");
                    assert!(
                        (kept.velocity - fresh.velocity).abs() <= scale * rate_scale,
                        "{kept:?} {fresh:?}"
                    );
                    assert!(
                        (kept.acceleration - fresh.acceleration).abs() <= scale * rate_scale * rate_scale,
                        "{kept:?} {fresh:?}"
                    );
                }
                let cached = propagator
                    .advances
                    .0
                    .borrow()
                    .sets
                    .iter()
                    .any(|set| set.ways.iter().any(|(kept, _)| *kept == h));
                let closed_form = match late_from {
                    Some(from) => s0 >= from,
                    None => form != "none",
                };
                assert_eq!(cached, closed_form, "{form} s0 {s0} h {h}");
                fast_paths += usize::from(cached);
            }
        }
        assert_eq!(fast_paths, 15);
        // The first two steps above lie before the transient is over, the last after it and
        // the third across it.
        let over = propagator
            .trajectory(&swinging, 3.1, 0.0, &[swinging.position; PLAY_OPERATORS])
            .series_form
            .expect("a series form for 3.1 V")
            .transient_over;
        assert!(over > 4.0e-3 && over < 4.0e-3 + 8.4e-4, "{over}");
    }
}
