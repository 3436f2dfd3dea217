//! The split method's integrated part: the two chamber pressures (and the pressures of the
//! gas volumes behind restrictions when there are any, [`crate::physics::restrictions`]), driven by the jet pipe's
//! exactly known trajectory. Most of what is here keeps the integrator from paying twice for
//! the same thing (the orifice areas at a stage time, the rates at a step's start and end)
//! and stops its steps at the tangencies of the orifice geometry, where the flows have kinks.

use nalgebra::SVector;

use crate::electromechanics::{Trajectory, MAX_NODES};
use crate::integrator::{finite_difference_jacobian, OdeSystem};
use crate::physics::actuator::{Actuator, HeldChambers};
use crate::physics::orifice_geometry::OrificeAreas;
use crate::physics::restrictions::PRESSURES_WITH_VOLUMES;

/// The jet pipe position, pressures and pressure rates at the end of a step.
pub(super) type EndRates<const N: usize> = (f64, SVector<f64, N>, SVector<f64, N>);

/// The law of the N integrated pressures' rates: a type, chosen once per step from what the
/// model has ([`Actuator::rate_terms`], its volumes), so that each right-hand side runs the
/// law's own code, inlined into the integrator, with no test of which terms are live.
pub(super) trait PressureLaw<const N: usize> {
    fn rates(model: &Actuator, areas: &OrificeAreas, p: &SVector<f64, N>, x_s: f64, x_s_rate: f64) -> SVector<f64, N>;

    /// [`Self::rates`] over a step in which the stopper stays at `x_s` (`x_s_rate` = ±0), with
    /// what the chambers take from it worked out once for the step in `held`; the same bits.
    #[inline(always)]
    fn rates_held(
        model: &Actuator,
        _held: &HeldChambers,
        areas: &OrificeAreas,
        p: &SVector<f64, N>,
        x_s: f64,
        x_s_rate: f64,
    ) -> SVector<f64, N> {
        Self::rates(model, areas, p, x_s, x_s_rate)
    }
}

/// P1 and P2 by the thesis's terms alone ([`crate::physics::actuator::RateTerms::Thesis`]).
pub(super) struct ThesisLaw;

/// P1 and P2 with any of the terms the thesis model lacks ([`crate::physics::actuator::RateTerms::Extended`]).
pub(super) struct ExtendedLaw;

/// P1, P2 and the pressures of the gas volumes behind restrictions
/// ([`PRESSURES_WITH_VOLUMES`]).
pub(super) struct VolumesLaw;

impl PressureLaw<2> for ThesisLaw {
    #[inline(always)]
    fn rates(model: &Actuator, areas: &OrificeAreas, p: &SVector<f64, 2>, x_s: f64, x_s_rate: f64) -> SVector<f64, 2> {
        let (a, b) = model.thesis_pressure_rates(areas, p[0], p[1], x_s, x_s_rate);
        SVector::<f64, 2>::new(a, b)
    }

    #[inline(always)]
    fn rates_held(
        model: &Actuator,
        held: &HeldChambers,
        areas: &OrificeAreas,
        p: &SVector<f64, 2>,
        _x_s: f64,
        _x_s_rate: f64,
    ) -> SVector<f64, 2> {
        let (a, b) = model.thesis_pressure_rates_held(areas, p[0], p[1], held);
        SVector::<f64, 2>::new(a, b)
    }
}

impl PressureLaw<2> for ExtendedLaw {
    fn rates(model: &Actuator, areas: &OrificeAreas, p: &SVector<f64, 2>, x_s: f64, x_s_rate: f64) -> SVector<f64, 2> {
        let (a, b) = model.extended_pressure_rates(areas, p[0], p[1], x_s, x_s_rate);
        SVector::<f64, 2>::new(a, b)
    }
}

impl PressureLaw<PRESSURES_WITH_VOLUMES> for VolumesLaw {
    fn rates(
        model: &Actuator,
        areas: &OrificeAreas,
        p: &SVector<f64, PRESSURES_WITH_VOLUMES>,
        x_s: f64,
        x_s_rate: f64,
    ) -> SVector<f64, PRESSURES_WITH_VOLUMES> {
        let mut pressures = [0.0; PRESSURES_WITH_VOLUMES];
        for (slot, value) in pressures.iter_mut().zip(p.iter()) {
            *slot = *value;
        }
        SVector::<f64, PRESSURES_WITH_VOLUMES>::from(
            model.pressure_rates_with_volumes(areas, &pressures, x_s, x_s_rate),
        )
    }
}

/// The chambers over one step, driven by the exactly known jet pipe trajectory. Its time
/// is counted from the step's start, as the trajectory's is: a step size the integrator
/// repeats (the cap, the rest of an equal communication step) is then the same to the last
/// bit each time, which [`Trajectory::node_positions`] relies on.
pub(super) struct ChamberSystem<'a, const N: usize, L> {
    pub(super) model: &'a Actuator,
    pub(super) trajectory: &'a Trajectory<'a>,
    pub(super) x_s: f64,
    pub(super) x_s_rate: f64,
    /// The jet pipe position at t = 0: the state's, which the trajectory starts from (its
    /// own value there agrees to rounding).
    pub(super) start_position: f64,
    /// The jet pipe position and orifice areas at the last time asked for: Newton
    /// iterations and the Jacobian evaluate many pressures at one stage time, and the jet
    /// pipe position and the areas (four lens areas) cost more than the flows.
    pub(super) areas_at: std::cell::Cell<Option<(f64, f64, OrificeAreas)>>,
    /// The areas at the stage times of the current explicit step, worked out together in
    /// [`OdeSystem::prepare_stages`]. An entry from an earlier step is still right: the
    /// areas depend on the time alone. The table is the simulation's, emptied here, so that
    /// a step does not clear its 400 bytes.
    pub(super) stage_areas: &'a std::cell::RefCell<StageAreas>,
    /// The pressures and rates at the step's start (t = 0), asked for twice: by the ringing
    /// test and by the integrator's first stage.
    pub(super) start_rates: std::cell::Cell<Option<(SVector<f64, N>, SVector<f64, N>)>>,
    /// The jet pipe position, pressures and rates of the last evaluation at t = duration:
    /// the integrator's last stage, whose rates are the next step's rates at its start.
    pub(super) end_rates: std::cell::Cell<Option<EndRates<N>>>,
    /// The last time asked about in [`OdeSystem::breakpoint`] and its area stretch: the next
    /// question starts there.
    pub(super) stretch_at: std::cell::Cell<Option<(f64, i32)>>,
    /// Whether the trajectory's position bounds over [0, duration] lie within one
    /// stretch of the orifice geometry (then no step inside has a breakpoint); found on the
    /// first question.
    pub(super) tangency_free: std::cell::Cell<Option<bool>>,
    pub(super) duration: f64,
    /// What the chambers take from a stopper that stays put over the step (`x_s_rate` = ±0),
    /// worked out once ([`Actuator::held_chambers`]); `None` while it moves.
    held: Option<HeldChambers>,
    law: std::marker::PhantomData<L>,
}

impl<'a, const N: usize, L: PressureLaw<N>> ChamberSystem<'a, N, L> {
    /// The chambers over [0, duration], from the jet pipe position `start_position`; the
    /// pressure rates at the start are `start_rates` when they are already known.
    pub(super) fn new(
        model: &'a Actuator,
        trajectory: &'a Trajectory<'a>,
        stage_areas: &'a std::cell::RefCell<StageAreas>,
        duration: f64,
        start_position: f64,
        start_rates: Option<(SVector<f64, N>, SVector<f64, N>)>,
        x_s: f64,
        x_s_rate: f64,
    ) -> Self {
        Self {
            model,
            trajectory,
            x_s,
            x_s_rate,
            start_position,
            areas_at: std::cell::Cell::new(None),
            stage_areas: {
                stage_areas.borrow_mut().count = 0;
                stage_areas
            },
            start_rates: std::cell::Cell::new(start_rates),
            end_rates: std::cell::Cell::new(None),
            stretch_at: std::cell::Cell::new(None),
            tangency_free: std::cell::Cell::new(None),
            duration,
            held: (x_s_rate == 0.0).then(|| model.held_chambers(x_s, x_s_rate)),
            law: std::marker::PhantomData,
        }
    }

    /// Whether the jet pipe provably stays within one stretch over the whole system's time.
    pub(super) fn tangency_free(&self) -> bool {
        if let Some(free) = self.tangency_free.get() {
            return free;
        }
        let free = self
            .trajectory
            .position_bounds(self.duration)
            .map_or(false, |(lo, hi)| {
                self.model.area_stretch(lo) == self.model.area_stretch(hi)
            });
        self.tangency_free.set(Some(free));
        free
    }

    pub(super) fn areas(&self, t: f64) -> OrificeAreas {
        self.position_and_areas(t).1
    }

    /// The jet pipe position at `t` and the orifice areas there.
    #[inline(always)]
    pub(super) fn position_and_areas(&self, t: f64) -> (f64, OrificeAreas) {
        if let Some(known) = self.stage_areas.borrow_mut().at(t, self.model) {
            return known;
        }
        self.position_and_areas_off_the_stages(t)
    }

    /// [`Self::position_and_areas`] at a time that is not one of the current explicit step's
    /// stages (Newton iterations, Jacobians, the ringing test): out of line, so that the
    /// stages' right-hand side stays small in the integrator's loop.
    #[inline(never)]
    fn position_and_areas_off_the_stages(&self, t: f64) -> (f64, OrificeAreas) {
        match self.areas_at.get() {
            Some((cached, position, areas)) if cached == t => (position, areas),
            _ => {
                let position = if t == 0.0 {
                    self.start_position
                } else {
                    self.trajectory.position(t)
                };
                let areas = self.model.areas(position);
                self.areas_at.set(Some((t, position, areas)));
                (position, areas)
            }
        }
    }

    /// The time in (a, b] at which the jet pipe, in `stretch_a` at a and not at b, reaches
    /// `tangency`: regula falsi (Illinois) on the exact trajectory, returning a time already
    /// past the crossing (within 1e-12 s), so a step ending there does not contain it.
    pub(super) fn crossing_time(&self, mut a: f64, mut b: f64, tangency: f64, stretch_a: i32) -> f64 {
        let gap = |t: f64| self.trajectory.position(t) - tangency;
        let (mut ga, mut gb) = (gap(a), gap(b));
        let mut last_moved = 0;
        for _ in 0..60 {
            if b - a <= 1e-12 {
                break;
            }
            let mut t = if ga != gb {
                b - gb * (b - a) / (gb - ga)
            } else {
                0.5 * (a + b)
            };
            if !(t > a && t < b) {
                t = 0.5 * (a + b);
            }
            let position = self.trajectory.position(t);
            let g = position - tangency;
            let past = self.model.area_stretch(position) != stretch_a;
            if past {
                b = t;
                gb = g;
                if last_moved == 1 {
                    ga *= 0.5;
                }
                last_moved = 1;
            } else {
                a = t;
                ga = g;
                if last_moved == -1 {
                    gb *= 0.5;
                }
                last_moved = -1;
            }
        }
        b
    }

    /// The rates at t = 0, kept (see `start_rates`); out of line, so the stages' path stays
    /// small enough to be inlined into the integrator.
    #[inline(never)]
    pub(super) fn rates_at_start(&self, p: &SVector<f64, N>) -> SVector<f64, N> {
        match self.start_rates.get() {
            Some((pressures, rates)) if pressures == *p => rates,
            _ => {
                let rates = self.rates(&self.areas(0.0), 0.0, p);
                self.start_rates.set(Some((*p, rates)));
                rates
            }
        }
    }

    /// The rates at `t` ≠ 0 with the jet pipe at `position`; at t = duration recorded with the
    /// position and pressures (see `end_rates`).
    #[inline(always)]
    fn rates_recording_the_end(
        &self,
        position: f64,
        areas: &OrificeAreas,
        t: f64,
        p: &SVector<f64, N>,
    ) -> SVector<f64, N> {
        let rates = self.rates(areas, t, p);
        if t == self.duration {
            self.end_rates.set(Some((position, *p, rates)));
        }
        rates
    }

    #[inline(always)]
    pub(super) fn rates(&self, areas: &OrificeAreas, t: f64, p: &SVector<f64, N>) -> SVector<f64, N> {
        // x_s + ±0·t is x_s (a stopper inside the cylinder is never at 0).
        match &self.held {
            Some(held) => L::rates_held(self.model, held, areas, p, self.x_s, self.x_s_rate),
            None => self.rates_with_the_stopper_moving(areas, t, p),
        }
    }

    /// [`Self::rates`] while the stopper moves: out of line (see `position_and_areas_off_the_stages`).
    #[inline(never)]
    fn rates_with_the_stopper_moving(&self, areas: &OrificeAreas, t: f64, p: &SVector<f64, N>) -> SVector<f64, N> {
        L::rates(self.model, areas, p, self.x_s + self.x_s_rate * t, self.x_s_rate)
    }
}

/// Jet pipe positions and orifice areas at the stage times of one step.
///
/// A stage's areas are worked out when the stage asks for them, not with the positions:
/// they depend on the position alone, not on the pressures, so between the stages' chain
/// of dependent floating-point operations (stage sum, flows, rates) the processor works
/// them out beside the previous stage's chain instead of before the first stage. The same
/// operations on the same positions: the same bits (`tests/reference_outputs.rs`), and in
/// the side-by-side benchmark about 6 % less time per step than all areas first.
#[derive(Clone, Debug, Default)]
pub(super) struct StageAreas {
    pub(super) count: usize,
    /// Whether `times[..count]` never decreases (an equal time is then next to its first).
    pub(super) ordered: bool,
    pub(super) times: [f64; MAX_NODES],
    pub(super) positions: [f64; MAX_NODES],
    pub(super) areas: [OrificeAreas; MAX_NODES],
    /// Bit i: `areas[i]` is worked out for `positions[i]`.
    pub(super) areas_known: u32,
}

impl StageAreas {
    /// The first entry at time `t`.
    pub(super) fn at(&mut self, t: f64, model: &Actuator) -> Option<(f64, OrificeAreas)> {
        let i = self.times[..self.count].iter().position(|&time| time == t)?;
        Some((self.positions[i], self.areas_of(i, model)))
    }

    /// The areas at entry `i`, worked out on the first question.
    #[inline(always)]
    fn areas_of(&mut self, i: usize, model: &Actuator) -> OrificeAreas {
        if self.areas_known & (1 << i) == 0 {
            self.areas[i] = model.areas(self.positions[i]);
            self.areas_known |= 1 << i;
        }
        self.areas[i]
    }

    /// Entry `i` if it is at time `t` and is the first at that time (what [`Self::at`] finds),
    /// known without a search while the times are ordered; `None` otherwise.
    #[inline(always)]
    pub(super) fn entry(&mut self, i: usize, t: f64, model: &Actuator) -> Option<(f64, OrificeAreas)> {
        let first = i < self.count && self.times[i] == t && (i == 0 || (self.ordered && self.times[i - 1] < t));
        if !first {
            return None;
        }
        Some((self.positions[i], self.areas_of(i, model)))
    }
}

impl<const N: usize, L: PressureLaw<N>> OdeSystem<N> for ChamberSystem<'_, N, L> {
    // Inlined into the integrator's stages with what it calls on their path (the law, the
    // rates at the end, the stage areas' lookup): out of line, the right-hand side with f2
    // cost 2.5 % more instructions per step, the rates at the end and the lookup another
    // 1.7 % (callgrind, the standard scenario's inputs at 1 kHz).
    // At t = duration the rates are recorded with the position and pressures (see
    // `end_rates`); one inlined copy of the law serves every stage.
    #[inline(always)]
    fn rhs(&self, t: f64, p: &SVector<f64, N>) -> SVector<f64, N> {
        if t == 0.0 {
            return self.rates_at_start(p);
        }
        let (position, areas) = self.position_and_areas(t);
        self.rates_recording_the_end(position, &areas, t, p)
    }
    /// The stage's entry of the stage areas when it is the one [`StageAreas::at`] would find
    /// (see [`StageAreas::entry`]), so that an explicit step's stages need no search.
    #[inline(always)]
    fn rhs_at_stage(&self, stage: usize, t: f64, p: &SVector<f64, N>) -> SVector<f64, N> {
        let known = self.stage_areas.borrow_mut().entry(stage, t, self.model);
        match known {
            Some((position, areas)) if t != 0.0 => self.rates_recording_the_end(position, &areas, t, p),
            _ => self.rhs(t, p),
        }
    }
    /// The jet pipe positions at all stages at once ([`Trajectory::node_positions`]); their
    /// areas are worked out at each stage, when it asks ([`StageAreas::entry`]).
    fn prepare_stages(&self, t: f64, h: f64, nodes: &[f64], times: &[f64]) {
        let count = nodes.len().min(times.len());
        if count > MAX_NODES {
            return;
        }
        let mut table = self.stage_areas.borrow_mut();
        self.trajectory
            .node_positions(t, h, &nodes[..count], &times[..count], &mut table.positions[..count]);
        table.times[..count].copy_from_slice(&times[..count]);
        table.count = count;
        table.areas_known = 0;
        table.ordered = times[..count].windows(2).all(|pair| pair[0] <= pair[1]);
    }
    /// Where the jet pipe crosses a tangency of the orifice geometry: the areas, and so the
    /// pressure rates, have a corner or a 3/2 power in time there. Looked for at the middle
    /// and the end of the step (steps are at most a quarter of the ringing period, so only
    /// a graze of a tangency can be missed, and a graze opens next to no area).
    fn breakpoint(&self, t0: f64, t1: f64) -> Option<f64> {
        if self.tangency_free() && t1 <= self.duration {
            return None;
        }
        let stretch = |t: f64| self.model.area_stretch(self.trajectory.position(t));
        let (mut a, mut stretch_a) = match self.stretch_at.get() {
            Some((t, s)) if t == t0 => (t0, s),
            _ => (t0, stretch(t0)),
        };
        for b in [0.5 * (t0 + t1), t1] {
            let stretch_b = stretch(b);
            if stretch_b != stretch_a {
                let tangency = self.model.tangency_position(stretch_a, stretch_b);
                let crossing = self.crossing_time(a, b, tangency, stretch_a);
                self.stretch_at.set(Some((crossing, stretch(crossing))));
                return Some(crossing);
            }
            (a, stretch_a) = (b, stretch_b);
        }
        self.stretch_at.set(Some((t1, stretch_a)));
        None
    }
    fn jacobian(&self, t: f64, p: &SVector<f64, N>, f_p: &SVector<f64, N>) -> nalgebra::SMatrix<f64, N, N> {
        let areas = self.areas(t);
        finite_difference_jacobian(|q| self.rates(&areas, t, q), p, f_p)
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::thesis_model;
    use super::super::Simulation;
    use super::*;
    use crate::physics::actuator::index;

    #[test]
    fn steps_end_where_the_jet_pipe_crosses_a_tangency() {
        let model = thesis_model();
        let sim = Simulation::at_equilibrium(model.clone(), 2.5, 0.054, 0.0, 1e-6).unwrap();
        let propagator = sim.propagator.as_ref().unwrap();
        let start = sim.electromechanical_state();
        let trajectory = propagator.trajectory(&start, -10.0, 0.0, &sim.plays);
        // The chambers' time starts at the step's start, as the trajectory's does.
        let stage_areas = std::cell::RefCell::new(StageAreas::default());
        let system = ChamberSystem::<2, ThesisLaw>::new(
            &model,
            &trajectory,
            &stage_areas,
            0.002,
            sim.state[index::JET_POSITION],
            None,
            sim.x_s,
            0.0,
        );
        let stretch_at = |t: f64| model.area_stretch(trajectory.position(t));
        assert_ne!(stretch_at(0.0), stretch_at(0.002), "the swing must cross a tangency");
        // Walk through 2 ms in 0.1 ms pieces, as an integrator would.
        let mut t: f64 = 0.0;
        let mut crossings = vec![];
        while t < 0.002 {
            let end = (t + 1e-4).min(0.002);
            match system.breakpoint(t, end) {
                Some(b) => {
                    assert!(b > t && b < end, "{b} outside ({t}, {end})");
                    crossings.push(b);
                    t = b;
                }
                None => t = end,
            }
        }
        assert!(!crossings.is_empty());
        for &b in &crossings {
            let (before, after) = (stretch_at(b - 1e-11), stretch_at(b));
            assert_ne!(before, after, "no tangency at {b}");
            let tangency = model.tangency_position(before, after);
            let speed = (trajectory.position(b + 1e-9) - trajectory.position(b)).abs() / 1e-9;
            assert!(
                (trajectory.position(b) - tangency).abs() <= 2e-12 * speed + 1e-15,
                "{b}"
            );
        }
    }

    /// The rates at t = 0 are kept for the pressures last asked about there, and only there.
    #[test]
    fn chambers_keep_the_rates_at_the_start_for_the_same_pressures_only() {
        let model = thesis_model();
        let sim = Simulation::at_equilibrium(model.clone(), 2.5, 0.054, 0.0, 1e-6).unwrap();
        let propagator = sim.propagator.as_ref().unwrap();
        let start = sim.electromechanical_state();
        let trajectory = propagator.trajectory(&start, 4.0, 0.0, &sim.plays);
        let stage_areas = std::cell::RefCell::new(StageAreas::default());
        let system = ChamberSystem::<2, ThesisLaw>::new(
            &model,
            &trajectory,
            &stage_areas,
            0.01,
            sim.state[index::JET_POSITION],
            None,
            sim.x_s,
            0.0,
        );
        // At t = 0 the chambers see the state's jet pipe position (the trajectory's agrees to
        // rounding).
        let position = |t: f64| {
            if t == 0.0 {
                sim.state[index::JET_POSITION]
            } else {
                trajectory.position(t)
            }
        };
        let fresh = |t: f64, p: &SVector<f64, 2>| system.rates(&model.areas(position(t)), t, p);
        let p = SVector::<f64, 2>::new(sim.state[index::P1], sim.state[index::P2]);
        let q = p * 1.01;
        for pressures in [p, p, q, p, q, q] {
            assert_eq!(system.rhs(0.0, &pressures), fresh(0.0, &pressures));
        }
        assert_eq!(system.start_rates.get().map(|(kept, _)| kept), Some(q));
        assert_eq!(system.rhs(1e-3, &p), fresh(1e-3, &p));
        assert_eq!(system.start_rates.get().map(|(kept, _)| kept), Some(q));
        assert_ne!(system.rhs(0.0, &p), system.rhs(0.0, &q));
    }
}
