//! One step's trajectory of the current driver and jet pipe: the current in closed form,
//! the jet pipe from the series or ramp form where one applies, and otherwise by composite
//! Gauss–Legendre quadrature of the modal convolution on panels that end at the input's
//! kinks. A held command's jump too large for the series is integrated until it has shrunk,
//! then continued by a series-form trajectory started there. Also the ringing the chambers'
//! integrator has to resolve, measured where it is exact.

use crate::physics::current_driver;
use crate::physics::effects::PLAY_OPERATORS;
use crate::physics::jet_pipe::{self, StaticCurve, F3};

use super::modal::{modulus, Exponentials, HysteresisOverStep};
use super::series::{
    RampForm, SeriesForm, LATE_SERIES_MARGIN, MAX_SERIES_TERMS, RAMP_TRANSIENT_LIMIT, SERIES_RATIO_LIMIT,
};
use super::{Coefficients, ElectromechanicalPropagator, ElectromechanicalState, C64};

pub(super) const PANEL: f64 = 1e-4;

pub(super) const GAUSS_NODES: [f64; 8] = [
    -0.960_289_856_497_536_3,
    -0.796_666_477_413_626_7,
    -0.525_532_409_916_329,
    -0.183_434_642_495_649_8,
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_3,
];
pub(super) const GAUSS_WEIGHTS: [f64; 8] = [
    0.101_228_536_290_376_3,
    0.222_381_034_453_374_5,
    0.313_706_645_877_887_3,
    0.362_683_783_378_362,
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

impl<C: StaticCurve> ElectromechanicalPropagator<C> {
    /// The trajectory over a step starting from `start` with command v_DA(s) = v_da + v_da_rate·s.
    ///
    /// `plays` are the hysteresis operator's play states at the start; the current is
    /// monotone in time except at most at one turning point (with a moving command), so
    /// the plays at any instant follow from their start values in at most two moves.
    pub fn trajectory(
        &self,
        start: &ElectromechanicalState,
        v_da: f64,
        v_da_rate: f64,
        plays: &[f64; PLAY_OPERATORS],
    ) -> Trajectory<'_, C> {
        // i(s) = ī(0) + ramp·(s − 1/ω) + δ e^{−ω s}, (2.1)–(2.3) solved.
        let drive = self.driver.response(start.current, v_da, v_da_rate);
        let (base, ramp, delta) = (drive.base, drive.ramp, drive.delta);
        let z = [start.position, start.velocity, start.acceleration];
        let mut q0 = [C64::new(0.0, 0.0); 3];
        for k in 0..3 {
            q0[k] = self.inverse[k][0] * z[0] + self.inverse[k][1] * z[1] + self.inverse[k][2] * z[2];
        }
        let mut series = Coefficients::new();
        let turning_point = drive.turning_point();
        let hysteresis_form = if ramp == 0.0 && self.hysteresis.is_active() {
            self.hysteresis_over_step(start.current, base, plays)
        } else {
            None
        };
        // Where a held command's jump is too large for the series: when it has shrunk enough.
        let mut series_from = None;
        // f3's argument (2.4)–(2.5) for a current, and for a change of current.
        let argument = |current: f64| self.curve.argument(jet_pipe::tip_force(self.k_m, current));
        let centre = argument(base);
        let series_applies = ramp == 0.0 && (!self.hysteresis.is_active() || hysteresis_form.is_some());
        let radius = if series_applies {
            self.curve.series_radius(centre)
        } else {
            None
        };
        if let Some(radius) = radius {
            let epsilon = argument(delta);
            if epsilon.abs() <= SERIES_RATIO_LIMIT * radius {
                match hysteresis_form {
                    Some(HysteresisOverStep::Parabola {
                        value,
                        slope,
                        curvature,
                    }) => {
                        // A Bouc–Wen branch as a parabola about the start: the series of
                        // d = x̄ − x̄(0), then value + slope d + curvature d².
                        if let Some(mut terms) = self.curve.series(centre, epsilon, MAX_SERIES_TERMS, 1.0) {
                            let start: f64 = terms.iter().sum();
                            terms[0] -= start;
                            let squared: Coefficients = (0..terms.len())
                                .map(|n| (0..=n).map(|k| terms[k] * terms[n - k]).sum())
                                .collect();
                            for (a, d2) in terms.iter_mut().zip(&squared) {
                                *a = slope * *a + curvature * d2;
                            }
                            terms[0] += value;
                            series = terms;
                        }
                    }
                    affine => {
                        let (constant, slope) = match affine {
                            Some(HysteresisOverStep::Affine { constant, slope }) => (constant, slope),
                            _ => (0.0, 1.0),
                        };
                        let terms =
                            self.curve
                                .series_with_memo(centre, epsilon, MAX_SERIES_TERMS, slope, &self.tanh_memo);
                        if let Some(terms) = terms {
                            series = terms;
                            series[0] += constant;
                        }
                    }
                }
            } else {
                let shrunk = LATE_SERIES_MARGIN * SERIES_RATIO_LIMIT * radius;
                series_from = Some((epsilon.abs() / shrunk).ln() / self.driver.omega_cd);
            }
        }
        // A ramp whose current transient is below rounding (a ramp continued from the last
        // step): the input is a power series in time and the response has a closed form.
        let ramp_form = if ramp != 0.0 && !self.hysteresis.is_active() && argument(delta).abs() <= RAMP_TRANSIENT_LIMIT
        {
            RampForm::new(self, &q0, centre, argument(ramp)).map(Box::new)
        } else {
            None
        };
        let series_form = SeriesForm::new(self, &q0, &series);
        let assemble = |series_form, series, ramp_form| Trajectory {
            propagator: self,
            drive,
            q0,
            ramp_form,
            series_form,
            series,
            plays: *plays,
            turning_point,
            settled: None,
            at_settled: std::cell::Cell::new(None),
            kinks: vec![],
            panel_ends: std::cell::RefCell::new(vec![]),
            late: None,
            last_node: std::cell::Cell::new(None),
        };
        if !series.is_empty() && series_from.is_none() {
            // The closed-form series, nothing more to work out: built where it is returned
            // (a trajectory is some 800 bytes, and moving it cost a tenth of its building).
            return assemble(series_form, series, ramp_form);
        }
        let mut trajectory = assemble(series_form, series, ramp_form);
        if trajectory.series.is_empty() {
            trajectory.kinks = trajectory.find_kinks();
        }
        if let Some(from) = series_from {
            // Quadrature up to `from` (a few panels), the series from there: the current
            // transient is then a jump the series converges for.
            let late = self.trajectory(&trajectory.state(from), v_da, 0.0, &trajectory.plays_at(from));
            if late.series_form.is_some() {
                trajectory.late = Some((from, Box::new(late)));
                return trajectory;
            }
        }
        if trajectory.series.is_empty() && ramp == 0.0 {
            // |δ| e^{−ω s} below 1e-15 A: the input is constant to rounding. The integral up
            // to then is taken when a query goes past it: a replay's step is often a tenth
            // of the settling time, and its quadrature all the way cost ten times the step's.
            trajectory.settled = Some(drive.transient_below(1e-15));
        }
        trajectory
    }
}

/// The current driver and jet pipe over one step, evaluable at any time within it.
pub struct Trajectory<'a, C = F3> {
    pub(super) propagator: &'a ElectromechanicalPropagator<C>,
    /// The current, (2.1)–(2.3) in closed form.
    pub(super) drive: current_driver::Response,
    pub(super) q0: [C64; 3],
    /// x_sat·aₙ when the closed-form series applies; empty otherwise.
    pub(super) series: Coefficients,
    /// The same series summed in closed form, for fast evaluation (see [`SeriesForm`]).
    pub(super) series_form: Option<SeriesForm>,
    /// The closed form for a ramp without a current transient (see [`RampForm`]); boxed, as
    /// its polynomials are anyway, so the held commands' trajectories stay small to move.
    pub(super) ramp_form: Option<Box<RampForm>>,
    /// Hysteresis play states at the start of the step.
    pub(super) plays: [f64; PLAY_OPERATORS],
    /// For a held command integrated by quadrature: the time after which the current
    /// transient no longer moves the jet pipe input.
    pub(super) settled: Option<f64>,
    /// The modal integrals up to [`Self::settled`] and the input from then on, once a query
    /// has gone past it.
    pub(super) at_settled: std::cell::Cell<Option<([C64; 3], f64)>>,
    /// Where the current stops rising and starts falling or back, if within the step.
    pub(super) turning_point: Option<f64>,
    /// Instants where the quadrature's integrand has a kink (the turning point, plays of
    /// the hysteresis operator starting to move): panels end there.
    pub(super) kinks: Vec<f64>,
    /// Panel ends and the modal integrals up to them, filled as queries need them.
    pub(super) panel_ends: std::cell::RefCell<Vec<(f64, [C64; 3])>>,
    /// For a held command whose jump is too large for the series: from when on the
    /// trajectory is the series-form one started there (queries from then on go to it).
    pub(super) late: Option<(f64, Box<Trajectory<'a, C>>)>,
    /// The last stage time [`Self::node_positions`] took the series form's exponentials
    /// at (with the current transient's), and those exponentials: the step's end, where
    /// [`Self::state`] is asked next.
    pub(super) last_node: std::cell::Cell<Option<(f64, Exponentials)>>,
}

impl<C: StaticCurve> Trajectory<'_, C> {
    /// The late part of the trajectory and the time into it, for `s` from its start on.
    pub(super) fn late_at(&self, s: f64) -> Option<(&Self, f64)> {
        self.late
            .as_ref()
            .filter(|(from, _)| s >= *from)
            .map(|(from, late)| (&**late, s - from))
    }

    /// Coil current at `s` seconds into the step.
    pub fn current(&self, s: f64) -> f64 {
        self.drive.at(s)
    }

    pub(super) fn static_position(&self, s: f64) -> f64 {
        self.propagator.static_position(self.current(s))
    }

    /// The hysteresis operator's play states at `s` (all at f3's output when it is off).
    pub fn plays_at(&self, s: f64) -> [f64; PLAY_OPERATORS] {
        if let Some((late, s)) = self.late_at(s) {
            return late.plays_at(s);
        }
        let operator = &self.propagator.hysteresis;
        if !operator.is_active() {
            return [self.static_position(s); PLAY_OPERATORS];
        }
        let mut plays = self.plays;
        if let Some(turn) = self.turning_point.filter(|&turn| turn < s) {
            operator.advance(&mut plays, self.static_position(turn));
        }
        operator.advance(&mut plays, self.static_position(s));
        plays
    }

    pub(super) fn jet_input(&self, s: f64) -> f64 {
        if self.propagator.hysteresis.is_active() {
            self.propagator.hysteresis.output(&self.plays_at(s))
        } else {
            self.static_position(s)
        }
    }

    /// [`Self::jet_input`] with the current transient's decay e^{−ω_cd s} given.
    fn jet_input_with_decay(&self, s: f64, decay: f64) -> f64 {
        if self.propagator.hysteresis.is_active() {
            self.propagator.hysteresis.output(&self.plays_at(s))
        } else {
            self.propagator.static_position(self.drive.with_decay(s, decay))
        }
    }

    /// Kinks of the jet pipe input for a held command: the instants at which plays of the
    /// hysteresis operator start to move (the static position is monotone, so each is
    /// found by bisection), plus the current's turning point.
    pub(super) fn find_kinks(&self) -> Vec<f64> {
        let mut kinks: Vec<f64> = self.turning_point.into_iter().collect();
        let operator = &self.propagator.hysteresis;
        // The Bouc–Wen law bends smoothly: only plays have kinks.
        let half_widths = operator
            .play_half_widths()
            .filter(|_| operator.is_active() && self.drive.ramp == 0.0);
        if let Some(half_widths) = half_widths {
            let settle = self.drive.transient_below(1e-15);
            let (from, to) = (self.static_position(0.0), self.static_position(settle));
            let rising = to >= from;
            for (p, r) in self.plays.iter().zip(half_widths) {
                let engages_at = if rising { p + r } else { p - r };
                let inside = if rising {
                    engages_at > from && engages_at < to
                } else {
                    engages_at < from && engages_at > to
                };
                if !inside {
                    continue;
                }
                let (mut lo, mut hi) = (0.0, settle);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    let passed = if rising {
                        self.static_position(mid) >= engages_at
                    } else {
                        self.static_position(mid) <= engages_at
                    };
                    if passed {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                kinks.push(0.5 * (lo + hi));
            }
        }
        kinks.sort_by(|a, b| a.total_cmp(b));
        kinks
    }

    /// ∫ₐᵇ e^{λ(b−σ)} u(σ) dσ for each mode by an 8-point Gauss–Legendre rule.
    pub(super) fn panel(&self, a: f64, b: f64) -> [C64; 3] {
        let p = self.propagator;
        let mut integral = [C64::new(0.0, 0.0); 3];
        let (centre, half) = (0.5 * (a + b), 0.5 * (b - a));
        for (node, weight) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS) {
            let sigma = centre + half * node;
            let u = self.jet_input(sigma) * weight * half;
            for k in 0..3 {
                integral[k] += (p.lambda[k] * (b - sigma)).exp() * u;
            }
        }
        integral
    }

    /// [`Self::panel`] over [a, a + PANEL], with the exponentials that every such panel
    /// shares (the propagator's `panel_factors`) and one exponential of the current's decay.
    fn full_panel(&self, a: f64) -> [C64; 3] {
        let p = self.propagator;
        let mut integral = [C64::new(0.0, 0.0); 3];
        let half = 0.5 * PANEL;
        let centre = a + half;
        let decay_at_centre = (-p.driver.omega_cd * centre).exp();
        for ((node, weight), (modes, decay)) in GAUSS_NODES.iter().zip(GAUSS_WEIGHTS).zip(&p.panel_factors.nodes) {
            let sigma = centre + half * node;
            let u = self.jet_input_with_decay(sigma, decay_at_centre * decay) * weight * half;
            for k in 0..3 {
                integral[k] += modes[k] * u;
            }
        }
        integral
    }

    /// ∫₀ˢ e^{λ(s−σ)} u(σ) dσ for each mode: composite Gauss–Legendre on panels of at most
    /// [`PANEL`] that end at every kink of u. The integrals at panel ends are kept, so a
    /// query costs one panel however far into the step it is.
    pub(super) fn quadrature(&self, s: f64) -> [C64; 3] {
        let lambda = self.propagator.lambda;
        let carry = |integral: &[C64; 3], from: f64, to: f64, add: [C64; 3]| {
            let mut out = add;
            for k in 0..3 {
                out[k] += (lambda[k] * (to - from)).exp() * integral[k];
            }
            out
        };
        let mut table = self.panel_ends.borrow_mut();
        if table.is_empty() {
            table.push((0.0, [C64::new(0.0, 0.0); 3]));
        }
        loop {
            let (end, integral) = *table.last().expect("the table starts with 0");
            let next_kink = self.kinks.iter().copied().find(|&k| k > end * (1.0 + 1e-12) + 1e-15);
            let next = next_kink.map_or(end + PANEL, |k| k.min(end + PANEL));
            if next > s {
                break;
            }
            let value = if next_kink.map_or(true, |k| k >= end + PANEL) {
                let across = &self.propagator.panel_factors.across;
                let mut value = self.full_panel(end);
                for k in 0..3 {
                    value[k] += across[k] * integral[k];
                }
                value
            } else {
                carry(&integral, end, next, self.panel(end, next))
            };
            table.push((next, value));
        }
        let j = table.partition_point(|(end, _)| *end <= s).saturating_sub(1);
        let (end, integral) = table[j];
        carry(&integral, end, s, self.panel(end, s))
    }

    /// Modal coordinates at `s`.
    pub(super) fn modes(&self, s: f64) -> [C64; 3] {
        match &self.series_form {
            Some(form) => form.modes(self.propagator, &self.series, s),
            None => self.modes_by_sum(s),
        }
    }

    /// Modal coordinates from the series term by term, the ramp form, or quadrature.
    pub(super) fn modes_by_sum(&self, s: f64) -> [C64; 3] {
        let p = self.propagator;
        let mut q = [C64::new(0.0, 0.0); 3];
        let mut integral = [C64::new(0.0, 0.0); 3];
        let growth = [
            (p.lambda[0] * s).exp(),
            (p.lambda[1] * s).exp(),
            (p.lambda[2] * s).exp(),
        ];
        if !self.series.is_empty() {
            // ∫₀ˢ e^{λ(s−σ)} e^{−nωσ} dσ = (e^{λs} − e^{−nωs}) / (λ + nω)
            let omega_cd = p.driver.omega_cd;
            let decay = (-omega_cd * s).exp();
            let mut decay_n = 1.0;
            for (n, a) in self.series.iter().enumerate() {
                let n_omega = n as f64 * omega_cd;
                for k in 0..3 {
                    let denominator = p.lambda[k] + n_omega;
                    integral[k] += if denominator.norm_sqr() > (1e-9 * omega_cd).powi(2) {
                        (growth[k] - decay_n) / denominator * *a
                    } else {
                        growth[k] * s * *a
                    };
                }
                decay_n *= decay;
            }
        } else if let Some(form) = self.ramp_form.as_ref().filter(|f| f.covers(s)) {
            return form.modes(p, s);
        } else if let Some(settled) = self.settled.filter(|&settled| s > settled) {
            // Past the current transient the input is constant: carry the integral up to
            // the settling time forward and add the constant input's part exactly.
            let (at_settled, u_final) = match self.at_settled.get() {
                Some(known) => known,
                None => {
                    let known = (self.quadrature(settled), self.jet_input(settled));
                    self.at_settled.set(Some(known));
                    known
                }
            };
            for k in 0..3 {
                let carry = (p.lambda[k] * (s - settled)).exp();
                integral[k] = carry * at_settled[k] + (carry - 1.0) / p.lambda[k] * u_final;
            }
        } else {
            integral = self.quadrature(s);
        }
        for k in 0..3 {
            q[k] = growth[k] * self.q0[k] + p.beta[k] * integral[k];
        }
        q
    }

    /// Amplitude (m) of the jet pipe's lightly damped oscillation at `s`. Where the response
    /// has a closed form this is exact: 2|c| e^{Re λ s} for the complex mode's homogeneous
    /// part c e^{λ s}, what is left once the part that follows the input is taken off (for a
    /// ramp, that part lags the input; it does not ring). Otherwise it is measured about the
    /// rest position of the static input at `s`: 2|q − q_rest|, q_rest = −β ū/λ.
    pub fn ringing_amplitude(&self, s: f64) -> f64 {
        if let Some((late, s)) = self.late_at(s) {
            return late.ringing_amplitude(s);
        }
        let p = self.propagator;
        let homogeneous = match (&self.series_form, &self.ramp_form) {
            (Some(form), _) => Some(form.amplitude[1]),
            (None, Some(form)) if form.covers(s) => Some(form.amplitude[1]),
            _ => None,
        };
        if let Some(c) = homogeneous {
            let envelope = if s == 0.0 { 1.0 } else { p.ringing_envelope.at(s) };
            return 2.0 * modulus(c) * envelope;
        }
        let q = self.modes(s);
        let u_rest = self.jet_input(s);
        2.0 * modulus(q[1] + p.beta[1] * u_rest / p.lambda[1])
    }

    /// The larger of [`Self::ringing_amplitude`] at 0 and at `s` ≥ 0. Where the ringing is a
    /// closed form's homogeneous part from the step's start (a held command's series form),
    /// its envelope e^{Re λ s} is at most 1, and the amplitude at 0 is the larger to the bit.
    pub fn ringing_amplitude_at_start_or(&self, s: f64) -> f64 {
        if self.late.is_none() && self.series_form.is_some() && self.propagator.lambda[1].re <= 0.0 {
            return self.ringing_amplitude(0.0);
        }
        self.ringing_amplitude(0.0).max(self.ringing_amplitude(s))
    }

    /// Decay rate ζ2ω2 (1/s) and period 2π/ω_d (s) of that oscillation.
    pub fn ringing_decay_and_period(&self) -> (f64, f64) {
        (-self.propagator.lambda[1].re, self.propagator.ringing_period)
    }

    /// Jet pipe position at `s` seconds into the step.
    pub fn position(&self, s: f64) -> f64 {
        if let Some((late, s)) = self.late_at(s) {
            return late.position(s);
        }
        if let Some(form) = &self.series_form {
            return form.position(self.propagator, s);
        }
        if let Some(form) = self.ramp_form.as_ref().filter(|f| f.covers(s)) {
            return form.position(self.propagator, s);
        }
        let q = self.modes(s);
        (q[0] + q[1] + q[2]).re
    }

    /// Bounds on the jet pipe position over [0, s_end] (m), where the response has a closed
    /// form (`None` elsewhere). They hold with a margin for rounding, and are tight when the
    /// jet pipe barely moves, which is when they are asked: a step whose bounds hold no
    /// tangency of the orifice geometry needs no search for one.
    pub fn position_bounds(&self, s_end: f64) -> Option<(f64, f64)> {
        let p = self.propagator;
        let (lo, hi) = if let Some(form) = &self.series_form {
            form.position_bounds(p, s_end)
        } else if let Some(form) = self.ramp_form.as_ref().filter(|f| f.covers(s_end)) {
            form.position_bounds(p, s_end)
        } else {
            return None;
        };
        let margin = 1e-12 * (lo.abs() + hi.abs() + p.x_sat);
        Some((lo - margin, hi + margin))
    }

    /// The full state at `s` seconds into the step.
    pub fn state(&self, s: f64) -> ElectromechanicalState {
        if let Some((late, s)) = self.late_at(s) {
            return late.state(s);
        }
        let closed_form = match (&self.series_form, &self.ramp_form) {
            (Some(form), _) => Some(match self.last_node.get() {
                // The current's transient e^{−ω s} is among the exponentials kept there.
                Some((at, e)) if at == s => (
                    form.derivatives_from(self.propagator, &self.series, &e),
                    self.drive.with_decay(s, e.decay),
                ),
                // The current's e^{−ω s} is the exponentials' decay, to the bit.
                _ => {
                    let e = self.propagator.exponentials(s, true);
                    (
                        form.derivatives_from(self.propagator, &self.series, &e),
                        self.drive.with_decay(s, e.decay),
                    )
                }
            }),
            (None, Some(form)) if form.covers(s) => Some((form.derivatives(self.propagator, s), self.current(s))),
            _ => None,
        };
        if let Some(([position, velocity, acceleration], current)) = closed_form {
            return ElectromechanicalState {
                current,
                position,
                velocity,
                acceleration,
            };
        }
        let q = self.modes(s);
        let l = &self.propagator.lambda;
        ElectromechanicalState {
            current: self.current(s),
            position: (q[0] + q[1] + q[2]).re,
            velocity: (l[0] * q[0] + l[1] * q[1] + l[2] * q[2]).re,
            acceleration: (l[0] * l[0] * q[0] + l[1] * l[1] * q[1] + l[2] * l[2] * q[2]).re,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{ramp_start, reference, swinging};
    use super::*;
    use crate::physics::parameters::Parameters;
    use nalgebra::SVector;

    /// f3 with tanh's values and slope but no power series.
    #[derive(Clone, Debug, PartialEq)]
    struct WithoutSeries(F3);

    impl StaticCurve for WithoutSeries {
        fn value(&self, tip_force: f64) -> f64 {
            self.0.value(tip_force)
        }
        fn slope(&self, tip_force: f64) -> f64 {
            self.0.slope(tip_force)
        }
        fn argument(&self, tip_force: f64) -> f64 {
            self.0.argument(tip_force)
        }
    }

    /// The ringing test's amplitude is the larger of those at the start and at `s`, to the bit,
    /// for series forms (where it skips the second) and the others (a ramp, a large jump).
    #[test]
    fn the_larger_ringing_amplitude_is_the_max_of_the_two() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let start = swinging();
        let plays = [start.position; PLAY_OPERATORS];
        for (v, rate) in [(1.3, 0.0), (3.1, 0.0), (-10.0, 0.0), (1.0, 400.0)] {
            let trajectory = propagator.trajectory(&start, v, rate, &plays);
            for s in [0.0, 1e-5, 7.1e-4, 1e-3, 5e-3] {
                let both = trajectory.ringing_amplitude(0.0).max(trajectory.ringing_amplitude(s));
                assert_eq!(
                    trajectory.ringing_amplitude_at_start_or(s).to_bits(),
                    both.to_bits(),
                    "v {v} rate {rate} s {s}"
                );
            }
        }
    }

    /// A curve that offers no series is integrated by quadrature by the propagator itself,
    /// and gives the trajectory of the series and ramp forms to 1e-12 of the scales (6e-14 measured).
    #[test]
    fn a_curve_without_a_series_gives_the_same_trajectory_by_quadrature() {
        // The tanh of (2.5), with a play hysteresis, and the tanh blended with the algebraic
        // sigmoid (whose series the blend's are).
        for (hysteresis, algebraic_share) in [(0.0, 0.0), (4e-5, 0.0), (0.0, 0.8)] {
            let p = Parameters {
                hysteresis_width: hysteresis,
                f3_algebraic_share: algebraic_share,
                ..Parameters::default()
            };
            let series = ElectromechanicalPropagator::new(&p).unwrap();
            let quadrature =
                ElectromechanicalPropagator::with_curve(&p, WithoutSeries(F3::from_parameters(&p))).unwrap();
            let mut closed_forms = 0;
            for (start, v, rate) in [
                (swinging(), 1.3, 0.0),
                (swinging(), 3.1, 0.0),
                (swinging(), -10.0, 0.0),
                (ramp_start(&p, 1.0, 2.5), 1.0, 2.5),
                (ramp_start(&p, -3.0, -60.0), -3.0, -60.0),
                (swinging(), 1.0, 400.0),
            ] {
                // Plays as a rise to f3 of the start current leaves them: a rise from there
                // drags them all, and the held commands' series form still applies.
                let x0 = series.static_position(start.current);
                let mut plays = [x0 - 1e-3; PLAY_OPERATORS];
                series.hysteresis.advance(&mut plays, x0);
                let fast = series.trajectory(&start, v, rate, &plays);
                let slow = quadrature.trajectory(&start, v, rate, &plays);
                assert!(slow.series.is_empty() && slow.series_form.is_none() && slow.ramp_form.is_none());
                assert!(slow.late.is_none());
                let late = fast.late.as_ref().map(|(_, late)| &**late);
                let closed = |t: &Trajectory| t.series_form.is_some() || t.ramp_form.is_some();
                closed_forms += usize::from(closed(&fast) || late.map_or(false, closed));
                let w = modulus(series.lambda[1]);
                for s in [0.0, 1e-5, 3e-4, 2e-3, 7.3e-3, 1e-2] {
                    let (a, b) = (fast.state(s), slow.state(s));
                    for (name, x, y, scale) in [
                        ("i", a.current, b.current, 0.5),
                        ("x", a.position, b.position, p.x_jp_sat),
                        ("v", a.velocity, b.velocity, p.x_jp_sat * w),
                        ("a", a.acceleration, b.acceleration, p.x_jp_sat * w * w),
                    ] {
                        assert!(
                            (x - y).abs() <= 1e-12 * scale,
                            "hysteresis {hysteresis} share {algebraic_share} v {v} rate {rate} s {s} {name}: {x} vs {y}"
                        );
                    }
                    assert!((fast.position(s) - slow.position(s)).abs() <= 1e-12 * p.x_jp_sat);
                }
            }
            // The series path did take its closed forms: all but the fast ramp with its
            // current transient; with hysteresis, the two rises that drag every play.
            assert_eq!(
                closed_forms,
                if hysteresis == 0.0 { 5 } else { 2 },
                "hysteresis {hysteresis}"
            );
        }
    }

    /// A full panel takes its exponentials from the propagator's shared factors and the
    /// current's decay from the panel's centre: the general panel's integral within 1e-13 of
    /// its size, for a ramp with a current transient (the command filter's steps), a held
    /// jump, and with a play hysteresis.
    #[test]
    fn a_full_panel_from_the_shared_factors_is_the_general_panels_integral() {
        for hysteresis in [0.0, 4e-5] {
            let p = Parameters {
                hysteresis_width: hysteresis,
                ..Parameters::default()
            };
            let quadrature =
                ElectromechanicalPropagator::with_curve(&p, WithoutSeries(F3::from_parameters(&p))).unwrap();
            for (v, rate) in [(1.0, 400.0), (-3.0, -60.0), (3.1, 0.0)] {
                let x0 = quadrature.static_position(swinging().current);
                let mut plays = [x0 - 1e-3; PLAY_OPERATORS];
                quadrature.hysteresis.advance(&mut plays, x0);
                let trajectory = quadrature.trajectory(&swinging(), v, rate, &plays);
                for a in [0.0, 3.0 * PANEL, 7.0 * PANEL] {
                    let (shared, general) = (trajectory.full_panel(a), trajectory.panel(a, a + PANEL));
                    for k in 0..3 {
                        let size = general[k].norm().max(1e-30);
                        assert!(
                            (shared[k] - general[k]).norm() <= 1e-13 * size,
                            "hysteresis {hysteresis} v {v} rate {rate} a {a} mode {k}: {} vs {}",
                            shared[k],
                            general[k]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn gauss_rule_integrates_degree_15_exactly() {
        for degree in 0..=15 {
            let numeric: f64 = GAUSS_NODES
                .iter()
                .zip(GAUSS_WEIGHTS)
                .map(|(x, w)| w * x.powi(degree))
                .sum();
            let exact = if degree % 2 == 1 {
                0.0
            } else {
                2.0 / (degree + 1) as f64
            };
            assert!((numeric - exact).abs() < 1e-14, "degree {degree}: {numeric} vs {exact}");
        }
    }

    #[test]
    fn position_bounds_hold_the_trajectory_and_are_tight_when_it_barely_moves() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let settled = |v: f64| {
            let current = current_driver::static_current(p.k_cd, p.i_offset, v);
            let position = propagator.static_position(current);
            ElectromechanicalState {
                current,
                position,
                velocity: 0.0,
                acceleration: 0.0,
            }
        };
        let swinging = swinging();
        let ramp_start = |v: f64, rate: f64| ramp_start(&p, v, rate);
        let mut bounded = 0;
        for (start, v, rate, duration) in [
            (settled(2.0), 2.0, 0.0, 0.01),
            (settled(2.0), 2.001, 0.0, 0.001),
            (settled(2.0), -10.0, 0.0, 0.01),
            (swinging, 1.3, 0.0, 0.002),
            (swinging, 3.1, 0.0, 0.01),
            (ramp_start(1.0, 2.5), 1.0, 2.5, 0.01),
            (ramp_start(-3.0, -60.0), -3.0, -60.0, 0.01),
        ] {
            let trajectory = propagator.trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS]);
            let Some((lo, hi)) = trajectory.position_bounds(duration) else {
                // A full-scale swing takes tanh outside its series' reach: no closed form.
                assert_eq!(v, -10.0, "v {v} rate {rate}: bounds expected");
                continue;
            };
            bounded += 1;
            let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
            for j in 0..=4000 {
                let x = trajectory.position(duration * j as f64 / 4000.0);
                (min, max) = (min.min(x), max.max(x));
            }
            assert!(
                lo <= min && max <= hi,
                "v {v} rate {rate}: [{min}, {max}] not in [{lo}, {hi}]"
            );
            // A settled jet pipe is bounded to within a nanometre, a small step's bounds are
            // within an order of magnitude of its swing (the transient's terms and the modes
            // that cancel them are bounded apart): ~1e-7 m against tangencies D apart.
            if v == 2.0 {
                assert!(hi - lo < 1e-9, "settled: [{lo}, {hi}]");
            }
            if v == 2.001 {
                assert!(
                    hi - lo < 8.0 * (max - min) + 1e-12,
                    "small step: [{lo}, {hi}] vs [{min}, {max}]"
                );
            }
        }
        assert_eq!(bounded, 6);
    }

    #[test]
    fn propagation_matches_a_tight_numerical_solution() {
        let p = Parameters::default();
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let start = ElectromechanicalState {
            current: 0.05,
            position: 1.2e-4,
            velocity: 0.02,
            acceleration: -30.0,
        };
        let y0 = SVector::<f64, 4>::new(start.current, start.position, start.velocity, start.acceleration);
        // small jump (series), large jumps (quadrature until the series converges, then the
        // series), and a ramp (quadrature)
        for (v, rate) in [(1.3, 0.0), (10.0, 0.0), (-8.0, 0.0), (1.0, 400.0)] {
            let trajectory = propagator.trajectory(&start, v, rate, &[start.position; PLAY_OPERATORS]);
            assert_eq!(trajectory.late.is_some(), v.abs() > 5.0);
            for s in [1e-5, 3e-4, 2e-3, 1e-2] {
                let exact = trajectory.state(s);
                let y = reference(&p, y0, v, rate, s);
                assert!(
                    (exact.current - y[0]).abs() < 1e-10,
                    "v {v} s {s}: i {} vs {}",
                    exact.current,
                    y[0]
                );
                assert!(
                    (exact.position - y[1]).abs() < 1e-11,
                    "v {v} rate {rate} s {s}: x {} vs {}",
                    exact.position,
                    y[1]
                );
                assert!(
                    (exact.velocity - y[2]).abs() < 1e-7,
                    "v {v} s {s}: ẋ {} vs {}",
                    exact.velocity,
                    y[2]
                );
            }
        }
    }

    #[test]
    fn a_bouc_wen_branch_taken_as_a_parabola_agrees_with_quadrature() {
        let p = Parameters {
            hysteresis_width: 0.16e-3,
            hysteresis_exponent: 3.7,
            hysteresis_beta_share: 0.52,
            hysteresis_gain: 0.99,
            ..Default::default()
        };
        let propagator = ElectromechanicalPropagator::new(&p).unwrap();
        let law = p.hysteresis();
        let mut checked = 0;
        for (v_from, v, z) in [
            (2.0, 2.001, 0.3),
            (2.0, 2.01, -0.5),
            (3.0, 2.999, 0.9),
            (1.0, 1.002, 0.0),
            (2.5, 2.5, 0.2),
        ] {
            let current = p.k_cd * v_from + p.i_offset;
            let x = F3::from_parameters(&p).value(jet_pipe::tip_force(p.k_m, current));
            let mut memory = [x; PLAY_OPERATORS];
            memory[1] = x - z * 0.08e-3;
            let start = ElectromechanicalState {
                current,
                position: law.output(&memory),
                velocity: 0.0,
                acceleration: 0.0,
            };
            let fast = propagator.trajectory(&start, v, 0.0, &memory);
            if fast.series.is_empty() {
                continue;
            }
            checked += 1;
            let mut slow = propagator.trajectory(&start, v, 0.0, &memory);
            slow.series.clear();
            slow.series_form = None;
            for s in [1e-5, 1e-4, 5e-4, 1e-3] {
                let (a, b) = (fast.position(s), slow.position(s));
                assert!(
                    (a - b).abs() < 1e-11,
                    "from {v_from} V to {v} V, z {z}: {a} vs {b} at {s} s"
                );
            }
        }
        assert!(checked >= 3, "only {checked} steps took the parabola");
    }
}
