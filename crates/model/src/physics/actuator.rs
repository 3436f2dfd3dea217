//! The assembled six-state model, (4.1): x = [i, x_jp, ẋ_jp, ẍ_jp, P1, P2].
//!
//! The current driver and jet pipe are linear apart from the static curve f3 and do not
//! feel the air; the chambers are driven by the jet pipe through the orifice areas.

use nalgebra::{SMatrix, SVector};

use super::chambers::{self, pressure_rate, CylinderGeometry};
use super::effects::{self, Hysteresis, PLAY_OPERATORS};
use super::jet_pipe::StaticCurve;
use super::orifice_flow::{self, leakage_flow, mass_flow, FlowConstants};
use super::orifice_geometry::{analytic_stretch, first_tangency_between, tabulated_orifice_areas, OrificeAreas};
use super::parameters::Parameters;
use super::restrictions::{self, node, Restrictions, PRESSURES_WITH_VOLUMES};
use super::sensors::{Channel, SensorLaw};
use super::{current_driver, extra_force, jet_pipe, piston};

pub const N_STATES: usize = 6;
pub type State = SVector<f64, N_STATES>;
pub type Jacobian = SMatrix<f64, N_STATES, N_STATES>;

/// Positions in the state vector.
pub mod index {
    pub const CURRENT: usize = 0;
    pub const JET_POSITION: usize = 1;
    pub const JET_VELOCITY: usize = 2;
    pub const JET_ACCELERATION: usize = 3;
    pub const P1: usize = 4;
    pub const P2: usize = 5;
}

/// Inputs at one instant: command, stopper position and stopper velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    pub v_da: f64,
    pub x_s: f64,
    pub x_s_rate: f64,
    /// Play states of the jet_pipe_hysteresis effect at the start of the step (`None`
    /// when the effect is off).
    pub plays: Option<[f64; PLAY_OPERATORS]>,
}

/// The mass flows of (2.24)–(2.25), kg/s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassFlows {
    pub supply_1: f64,
    pub return_1: f64,
    pub supply_2: f64,
    pub return_2: f64,
    /// From chamber 1 to chamber 2: past the piston, (2.23), and through the
    /// `chamber_laminar_cross_leak` path (zero in the thesis model).
    pub leakage: f64,
    /// What each chamber loses through leaks of its own: to the return pressure (the
    /// `chamber_vent_*` orifices, the `chamber_laminar_vent_*` paths) less what it gains from
    /// the supply (the `chamber_supply_leak_*` orifices, the `chamber_laminar_supply_leak_*`
    /// paths) less the extra flow slots' flows into it ([`super::extra_flow`]); zero in the
    /// thesis model.
    pub vent_1: f64,
    pub vent_2: f64,
}

impl MassFlows {
    /// Net inflow of chamber 1, (2.24).
    pub fn net_1(&self) -> f64 {
        self.supply_1 - self.return_1 - self.leakage - self.vent_1
    }
    /// Net inflow of chamber 2, (2.25).
    pub fn net_2(&self) -> f64 {
        self.supply_2 - self.return_2 + self.leakage - self.vent_2
    }
}

/// The flows with restrictions between the valve and the air ([`Actuator::network_flows`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NetworkFlows {
    /// The flows through the orifices of the valve (at the pressures behind the
    /// restrictions), the leakage and the vents.
    pub flows: MassFlows,
    /// The mass inflow of each chamber through its port: the port's net flow, or the
    /// restriction's behind a line volume.
    pub into_chambers: [f64; 2],
    /// The pressures behind the restrictions, in the order of [`node`].
    pub node_pressures: [f64; node::COUNT],
    /// The net mass inflow of each volume (0 unless `nodes` were given).
    pub node_inflows: [f64; node::COUNT],
}

/// The model's outputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outputs {
    pub f_act: f64,
    pub p1: f64,
    pub p2: f64,
    pub current: f64,
    pub x_jp: f64,
    /// The force as the force sensor reads it.
    pub f_meas: f64,
    /// The chamber pressures as their transducers read them.
    pub p1_meas: f64,
    pub p2_meas: f64,
}

impl Outputs {
    /// The transducers' readings, in the order of [`Channel::ALL`].
    pub fn readings(&self) -> [f64; 3] {
        [self.f_meas, self.p1_meas, self.p2_meas]
    }

    pub fn readings_mut(&mut self) -> [&mut f64; 3] {
        [&mut self.f_meas, &mut self.p1_meas, &mut self.p2_meas]
    }
}

/// The valve's orifices, as [`Actuator::discharge`] orders them.
const SUPPLY_1: usize = 0;
const RETURN_1: usize = 1;
const SUPPLY_2: usize = 2;
const RETURN_2: usize = 3;

/// The thesis model with fixed parameters; derived constants computed once.
#[derive(Clone, Debug)]
pub struct Actuator {
    pub params: Parameters,
    pub flow: FlowConstants,
    pub cylinder: CylinderGeometry,
    pub piston_area: f64,
    pub hysteresis: Hysteresis,
    /// Polytropic exponent of the chambers: γ unless the heat_transfer effect is on.
    pub polytropic_exponent: f64,
    /// C_d times the area factor of each orifice, [supply 1, return 1, supply 2, return 2]:
    /// C_d for all four in the thesis model, other factors under the valve asymmetry terms.
    pub discharge: [f64; 4],
    /// The area factor of each orifice, in the order of [`Self::discharge`]: with the
    /// discharge curve on, C_d(r) takes the place of C_d.
    pub(super) area_scales: [f64; 4],
    /// C_d as a function of the pressure ratio across each valve orifice
    /// (`discharge_curve_*`), when on.
    discharge_curve: Option<super::static_curve::StaticCurve>,
    /// Whether a chamber has a leak of its own or one to the other chamber beside the piston's
    /// (`chamber_vent_*`, `chamber_supply_leak_*`, `chamber_laminar_*`).
    chamber_leaks: bool,
    /// Restrictions between the valve and the air, and the volumes behind them.
    pub restrictions: Restrictions,
    /// The compliant stopper mount's lag (s), when it has one and a compliance: its state is
    /// then integrated with the volumes' ([`node::MOUNT`]).
    mount_lag: Option<f64>,
    /// Which terms of the pressure rates are live, decided here once for all evaluations.
    rate_terms: RateTerms,
    /// Whether the outputs are the thesis's alone: no friction or extra piston force, every
    /// transducer reading its quantity itself.
    thesis_outputs: bool,
    /// Whether the extra force's library terms beyond viscous friction and the position
    /// force are on ([`super::extra_force`]).
    extra_library: bool,
    /// Whether an extra force product slot is on ([`super::extra_force::ProductSlot`]).
    extra_products: bool,
    /// Whether a force on the piston follows the stopper's velocity or acceleration (friction,
    /// viscous friction, the extra force's library terms but the pressure difference): a
    /// simulation then forms the stopper's motion at each sample after each step
    /// ([`super::extra_force::StopperMotion`]).
    pub reads_stopper_motion: bool,
}

/// The factors of (2.29), dP/dt = (γ/V)(R T ṁ − P dV/dt), that do not change while the stopper
/// stays put: γ/V and dV/dt of each chamber (with (2.30)–(2.32)) and R T. A step whose stopper
/// does not move works them out once ([`Actuator::held_chambers`]) instead of in every
/// right-hand side; the rates are formed by the operations of
/// [`super::chambers::pressure_rate`], in its order, so they keep its bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeldChambers {
    gamma_over_volume: [f64; 2],
    volume_rate: [f64; 2],
    r_gas_temperature: f64,
}

impl HeldChambers {
    /// (2.29) for chamber `i` (0 or 1) with net mass inflow `net` at pressure `pressure`.
    #[inline(always)]
    fn pressure_rate(&self, i: usize, net: f64, pressure: f64) -> f64 {
        self.gamma_over_volume[i] * (self.r_gas_temperature * net - pressure * self.volume_rate[i])
    }
}

/// Which terms of the chambers' pressure rates a model has, decided once when it is built, so
/// that the thesis model's evaluations do not test, term by term, for effects that are off.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RateTerms {
    /// (2.18)–(2.29) alone: the four orifices of the valve at P_s and P_r, the leakage past the
    /// piston, a rigid stopper; no restriction, no chamber vent. Factors that are plain
    /// constants (C_d's area scales, dead volumes, the polytropic exponent of heat transfer)
    /// keep it.
    Thesis,
    /// The thesis's terms and any of: restrictions between the valve and the air, chamber
    /// vents, a compliant stopper, a discharge coefficient that varies with the pressure
    /// ratio.
    Extended,
}

impl Actuator {
    pub fn new(params: Parameters) -> Result<Self, String> {
        params.validate()?;
        let flow = params.flow_constants();
        let cylinder = params.cylinder();
        let piston_area = cylinder.piston_area();
        let hysteresis = params.hysteresis();
        let polytropic_exponent = effects::polytropic_exponent(params.gamma, params.heat_transfer_fraction);
        let area_scales = [
            params.supply_area_scale_1,
            params.return_area_scale_1,
            params.supply_area_scale_2,
            params.return_area_scale_2,
        ];
        let discharge = area_scales.map(|scale| params.c_d * scale);
        let discharge_curve = params.discharge_curve.is_on().then_some(params.discharge_curve);
        let restrictions = Restrictions::from_parameters(&params);
        let chamber_leaks = [
            params.chamber_vent_1,
            params.chamber_vent_2,
            params.chamber_supply_leak_1,
            params.chamber_supply_leak_2,
            params.chamber_laminar_vent_1,
            params.chamber_laminar_vent_2,
            params.chamber_laminar_supply_leak_1,
            params.chamber_laminar_supply_leak_2,
            params.chamber_laminar_cross_leak,
        ]
        .iter()
        .any(|&leak| leak != 0.0)
            || super::extra_flow::flows_on(&params.extra_flows)
            || params.extra_inflow_1 != 0.0
            || params.extra_inflow_2 != 0.0
            || super::modulation::modulates_inflows(&params);
        let rate_terms =
            if restrictions.any() || discharge_curve.is_some() || chamber_leaks || params.stopper_compliance != 0.0 {
                RateTerms::Extended
            } else {
                RateTerms::Thesis
            };
        let extra_library = params.extra_force_acceleration != 0.0
            || params.extra_force_velocity_squared != 0.0
            || params.extra_force_sign_pressure != 0.0
            || params.extra_force_pressure_difference != 0.0
            || super::modulation::modulates_extra_force(&params);
        let extra_products = extra_force::products_on(&params.extra_force_products);
        // The velocity the forces read is taken at the sample from the last two intervals'
        // motions ([`super::extra_force`]), as the acceleration is.
        let reads_stopper_motion = params.extra_force_acceleration != 0.0
            || params.extra_force_velocity_squared != 0.0
            || params.extra_force_sign_pressure != 0.0
            || extra_products
            || params.friction_coulomb != 0.0
            || params.friction_stribeck != 0.0
            || params.viscous_friction != 0.0
            || super::modulation::modulates_friction(&params);
        let thesis_outputs = !super::modulation::modulates_output_law(&params)
            && params.friction_coulomb == 0.0
            && params.friction_stribeck == 0.0
            && params.viscous_friction == 0.0
            && params.position_force_rate == 0.0
            && !extra_library
            && !extra_products
            && params.extra_force_offset == 0.0
            && Channel::ALL
                .iter()
                .all(|&channel| SensorLaw::of(&params, channel).is_identity());
        let mount_lag =
            (params.stopper_mount_lag > 0.0 && params.stopper_compliance != 0.0).then_some(params.stopper_mount_lag);
        Ok(Self {
            thesis_outputs,
            extra_library,
            extra_products,
            reads_stopper_motion,
            rate_terms,
            restrictions,
            mount_lag,
            params,
            flow,
            cylinder,
            piston_area,
            hysteresis,
            polytropic_exponent,
            discharge,
            area_scales,
            discharge_curve,
            chamber_leaks,
        })
    }

    /// The mass flow through valve orifice `orifice` (an index of [`Self::discharge`]) of
    /// geometric area `area` from `p_from` to `p_to`, (2.18), with the thesis's constant C_d
    /// or, with the discharge curve on, C_d at the orifice's pressure ratio
    /// P_down/P_up.
    #[inline]
    fn valve_flow(&self, orifice: usize, area: f64, p_from: f64, p_to: f64) -> f64 {
        let cd_area = match &self.discharge_curve {
            None => self.discharge[orifice] * area,
            Some(curve) => {
                let (up, down) = if p_from >= p_to { (p_from, p_to) } else { (p_to, p_from) };
                let ratio = if up > 0.0 { (down / up).clamp(0.0, 1.0) } else { 1.0 };
                self.area_scales[orifice] * curve.at(ratio).max(0.0) * area
            }
        };
        mass_flow(&self.flow, cd_area, p_from, p_to)
    }

    /// The four orifice areas at a jet pipe position, from the tabulated geometry (within
    /// 2e-15 of the port area of the closed forms (2.8)–(2.17), at a tenth of their cost).
    pub fn areas(&self, x_jp: f64) -> OrificeAreas {
        tabulated_orifice_areas(
            self.params.d_jp,
            jet_pipe::absolute_position(x_jp, self.params.x_jp_offset),
        )
    }

    /// The stretch between tangencies of the orifice geometry that `x_jp` lies in: the areas
    /// are analytic in x_jp within one ([`analytic_stretch`]).
    pub fn area_stretch(&self, x_jp: f64) -> i32 {
        analytic_stretch(
            self.params.d_jp,
            jet_pipe::absolute_position(x_jp, self.params.x_jp_offset),
        )
    }

    /// The jet pipe position of the first tangency crossed going from stretch `from` to `to`.
    pub fn tangency_position(&self, from: i32, to: i32) -> f64 {
        first_tangency_between(self.params.d_jp, from, to) - self.params.x_jp_offset
    }

    /// Mass flows for a jet pipe position and chamber pressures, (2.18)–(2.23).
    pub fn mass_flows(&self, x_jp: f64, p1: f64, p2: f64) -> MassFlows {
        self.mass_flows_through(&self.areas(x_jp), p1, p2)
    }

    /// [`Self::mass_flows`] for orifice areas already known (they depend on x_jp alone,
    /// and the integrators evaluate many pressures at one jet pipe position). With
    /// restrictions, the pressures behind them are quasi-static (see [`Self::network_flows`]).
    pub fn mass_flows_through(&self, a: &OrificeAreas, p1: f64, p2: f64) -> MassFlows {
        if self.restrictions.any() {
            return self.network_flows(a, p1, p2, None).flows;
        }
        let p = &self.params;
        let (vent_1, vent_2) = self.chamber_vents(p1, p2);
        MassFlows {
            supply_1: self.valve_flow(SUPPLY_1, a.supply_1, p.p_s, p1),
            return_1: self.valve_flow(RETURN_1, a.return_1, p1, p.p_r),
            supply_2: self.valve_flow(SUPPLY_2, a.supply_2, p.p_s, p2),
            return_2: self.valve_flow(RETURN_2, a.return_2, p2, p.p_r),
            leakage: self.leakage(p1, p2),
            vent_1,
            vent_2,
        }
    }

    /// From chamber 1 to chamber 2: past the piston, (2.23), and `chamber_laminar_cross_leak`'s c·(P1 − P2).
    fn leakage(&self, p1: f64, p2: f64) -> f64 {
        let p = &self.params;
        let piston = leakage_flow(&self.flow, p.c_dm_a_lpp, p.c_db_a_lpp, p1, p2);
        match p.chamber_laminar_cross_leak {
            c if c != 0.0 => piston + c * (p1 - p2),
            _ => piston,
        }
    }

    /// The flows each chamber loses through leaks other than the valve's and the piston's:
    /// the `chamber_vent_*` orifices to the return pressure, the `chamber_laminar_vent_*`
    /// paths to it, less what the `chamber_supply_leak_*` orifices and the
    /// `chamber_laminar_supply_leak_*` paths bring in from the supply and the extra flow
    /// slots and `extra_inflow_1`, `extra_inflow_2` bring in ([`super::extra_flow`]).
    fn chamber_vents(&self, p1: f64, p2: f64) -> (f64, f64) {
        if !self.chamber_leaks {
            return (0.0, 0.0);
        }
        let p = &self.params;
        let k = &self.flow;
        let lost = |vent: f64, laminar: f64, supplied: f64, chamber: f64| {
            mass_flow(k, vent, chamber, p.p_r) + laminar * (chamber - p.p_r) - mass_flow(k, supplied, p.p_s, chamber)
        };
        let pressures = super::extra_flow::ChamberPressures {
            p1,
            p2,
            p_s: p.p_s,
            p_r: p.p_r,
        };
        let [mut extra_1, mut extra_2] = super::extra_flow::inflows(&p.extra_flows, &pressures);
        // After the slots, as a slot of signal code 0 would add them.
        extra_1 += super::extra_flow::faded(p.extra_inflow_1, p1);
        extra_2 += super::extra_flow::faded(p.extra_inflow_2, p2);
        (
            lost(p.chamber_vent_1, p.chamber_laminar_vent_1, p.chamber_supply_leak_1, p1)
                - p.chamber_laminar_supply_leak_1 * (p.p_s - p1)
                - extra_1,
            lost(p.chamber_vent_2, p.chamber_laminar_vent_2, p.chamber_supply_leak_2, p2)
                - p.chamber_laminar_supply_leak_2 * (p.p_s - p2)
                - extra_2,
        )
    }

    /// The flows with restrictions between the valve and the air ([`super::restrictions`]).
    /// The pressure behind a restriction with a volume is `nodes`' entry when `nodes` is
    /// given; otherwise, and without a volume, it is quasi-static. Those are found one place
    /// at a time: the ports' with the supply and return pressures known or nominal, then the
    /// supply's and the return's with the ports' (a port restriction together with a
    /// quasi-static supply or return restriction is approximated, not solved jointly).
    pub fn network_flows(
        &self,
        a: &OrificeAreas,
        p1: f64,
        p2: f64,
        nodes: Option<&[f64; node::COUNT]>,
    ) -> NetworkFlows {
        let p = &self.params;
        let k = &self.flow;
        let places = &self.restrictions.places;
        let stated = |i: usize| nodes.filter(|_| places[i].has_volume()).map(|n| n[i]);
        let supply_known = stated(node::SUPPLY).unwrap_or(p.p_s);
        let return_known = stated(node::RETURN).unwrap_or(p.p_r);
        let port = |i: usize,
                    chamber: f64,
                    (supply_orifice, supply_area): (usize, f64),
                    (return_orifice, return_area): (usize, f64)| {
            if let Some(q) = stated(i) {
                return q;
            }
            let restriction = &places[i];
            let net_inflow = |q: f64| {
                (
                    self.valve_flow(supply_orifice, supply_area, supply_known, q),
                    self.valve_flow(return_orifice, return_area, q, return_known),
                )
            };
            if restriction.cd_area > 0.0 {
                let (lo, hi) = (
                    chamber.min(supply_known).min(return_known),
                    chamber.max(supply_known).max(return_known),
                );
                restrictions::balanced_pressure(lo, hi, |q| {
                    let (supplied, returned) = net_inflow(q);
                    // Flows the port takes in, against flows it gives out, each positive.
                    let onward = restriction.flow(k, q, chamber);
                    (supplied + (-onward).max(0.0), returned + onward.max(0.0))
                })
            } else {
                effects::port_pressure(chamber, restriction.resistance, supply_known, return_known, |q| {
                    let (supplied, returned) = net_inflow(q);
                    supplied - returned
                })
            }
        };
        let q1 = port(node::LINE_1, p1, (SUPPLY_1, a.supply_1), (RETURN_1, a.return_1));
        let q2 = port(node::LINE_2, p2, (SUPPLY_2, a.supply_2), (RETURN_2, a.return_2));
        let supply = |p_supply: f64| {
            (
                self.valve_flow(SUPPLY_1, a.supply_1, p_supply, q1),
                self.valve_flow(SUPPLY_2, a.supply_2, p_supply, q2),
            )
        };
        let supply_place = &places[node::SUPPLY];
        let p_supply = match stated(node::SUPPLY) {
            Some(p_supply) => p_supply,
            None if supply_place.cd_area > 0.0 => restrictions::balanced_pressure(q1.min(q2).min(p.p_s), p.p_s, |ps| {
                let (s1, s2) = supply(ps);
                (supply_place.flow(k, p.p_s, ps), s1 + s2)
            }),
            None => effects::supply_pressure_at_jet(p.p_s, supply_place.resistance, q1.min(q2), |ps| {
                let (s1, s2) = supply(ps);
                s1 + s2
            }),
        };
        let (supply_1, supply_2) = supply(p_supply);
        let returns = |p_return: f64| {
            (
                self.valve_flow(RETURN_1, a.return_1, q1, p_return),
                self.valve_flow(RETURN_2, a.return_2, q2, p_return),
            )
        };
        let return_place = &places[node::RETURN];
        let p_return = match stated(node::RETURN) {
            Some(p_return) => p_return,
            None if return_place.cd_area > 0.0 => {
                // At P_r nothing leaves and at the higher port pressure nothing enters.
                restrictions::balanced_pressure(p.p_r, q1.max(q2).max(p.p_r), |pr| {
                    let (r1, r2) = returns(pr);
                    (r1 + r2, return_place.flow(k, pr, p.p_r))
                })
            }
            None => effects::return_pressure_at_vent(p.p_r, return_place.resistance, q1.max(q2), |pr| {
                let (r1, r2) = returns(pr);
                r1 + r2
            }),
        };
        let (return_1, return_2) = returns(p_return);
        let (vent_1, vent_2) = self.chamber_vents(p1, p2);
        let into_chamber = |i: usize, q: f64, chamber: f64, through_port: f64| match stated(i) {
            Some(_) => places[i].flow(k, q, chamber),
            None => through_port,
        };
        let into_1 = into_chamber(node::LINE_1, q1, p1, supply_1 - return_1);
        let into_2 = into_chamber(node::LINE_2, q2, p2, supply_2 - return_2);
        let mut node_inflows = [0.0; node::COUNT];
        if nodes.is_some() {
            node_inflows = [
                supply_place.flow(k, p.p_s, p_supply) - supply_1 - supply_2,
                return_1 + return_2 - return_place.flow(k, p_return, p.p_r),
                supply_1 - return_1 - into_1,
                supply_2 - return_2 - into_2,
            ];
        }
        NetworkFlows {
            flows: MassFlows {
                supply_1,
                return_1,
                supply_2,
                return_2,
                leakage: self.leakage(p1, p2),
                vent_1,
                vent_2,
            },
            into_chambers: [into_1, into_2],
            node_pressures: [p_supply, p_return, q1, q2],
            node_inflows,
        }
    }

    /// Whether states beyond P1 and P2 are integrated: a gas volume behind a restriction, or
    /// a stopper mount that lags.
    pub fn has_volume_states(&self) -> bool {
        self.restrictions.has_volumes() || self.mount_lag.is_some()
    }

    /// Whether the stopper mount lags ([`node::MOUNT`] is a state).
    pub fn mount_lags(&self) -> bool {
        self.mount_lag.is_some()
    }

    /// The rates of P1, P2, the gas volumes' pressures ([`super::restrictions::node`]) and the
    /// mount's state for the states `p` in that order: (2.29) for the chambers, for each volume
    /// the same law at a fixed volume, and for the mount q̇ = (F/A_p − q)/τ, F the actuator
    /// force ([`Self::mount_load`]). A place
    /// without a volume, and the mount without a lag, have the rate 0.
    pub fn pressure_rates_with_volumes(
        &self,
        areas: &OrificeAreas,
        p: &[f64; PRESSURES_WITH_VOLUMES],
        x_s: f64,
        x_s_rate: f64,
    ) -> [f64; PRESSURES_WITH_VOLUMES] {
        let nodes = [p[2], p[3], p[4], p[5]];
        let network = self.network_flows(areas, p[0], p[1], Some(&nodes));
        let f = &network.flows;
        let net_1 = network.into_chambers[0] - f.leakage - f.vent_1;
        let net_2 = network.into_chambers[1] + f.leakage - f.vent_2;
        let mount = 2 + node::MOUNT;
        let (dp1, dp2, dq) = match self.mount_lag {
            Some(lag) => {
                let dq = (self.mount_load(p[0], p[1], x_s) - p[mount]) / lag;
                let (dp1, dp2) =
                    self.pressure_rates_on_a_lagging_mount(net_1, net_2, p[0], p[1], p[mount], dq, x_s, x_s_rate);
                (dp1, dp2, dq)
            }
            None => {
                let (dp1, dp2) = self.chamber_rates(net_1, net_2, p[0], p[1], x_s, x_s_rate);
                (dp1, dp2, 0.0)
            }
        };
        let mut rates = [0.0; PRESSURES_WITH_VOLUMES];
        rates[0] = dp1;
        rates[1] = dp2;
        rates[mount] = dq;
        let rt = self.params.r_gas * self.params.temperature;
        for (i, place) in self.restrictions.places.iter().enumerate() {
            if place.has_volume() {
                rates[2 + i] = self.polytropic_exponent * rt * network.node_inflows[i] / place.volume;
            }
        }
        rates
    }

    /// (2.29) when the piston sits c A_p q beyond the stopper (`stopper_compliance` c) and q
    /// moves at the rate `q_rate`: the volumes at x_s + c A_p q, their rates with
    /// ẋ_s + c A_p q̇. For a lagging mount q is its state; without a lag, on the spring's
    /// floor, q is the floor ([`Self::pressure_rates_on_a_compliant_stopper`]).
    #[allow(clippy::too_many_arguments)]
    fn pressure_rates_on_a_lagging_mount(
        &self,
        net_1: f64,
        net_2: f64,
        p1: f64,
        p2: f64,
        q: f64,
        q_rate: f64,
        x_s: f64,
        x_s_rate: f64,
    ) -> (f64, f64) {
        let p = &self.params;
        let n = self.polytropic_exponent;
        let stretch = p.stopper_compliance * self.piston_area;
        let (v1, v2) = self.cylinder.volumes(x_s + stretch * q);
        let (dv1, dv2) = self.cylinder.volume_rates(x_s_rate + stretch * q_rate);
        (
            pressure_rate(n, p.r_gas, p.temperature, v1, dv1, net_1, p1),
            pressure_rate(n, p.r_gas, p.temperature, v2, dv2, net_2, p2),
        )
    }

    /// dP1/dt and dP2/dt, (2.29).
    pub fn pressure_rates(&self, x_jp: f64, p1: f64, p2: f64, x_s: f64, x_s_rate: f64) -> (f64, f64) {
        self.pressure_rates_through(&self.areas(x_jp), p1, p2, x_s, x_s_rate)
    }

    /// [`Self::pressure_rates`] for orifice areas already known.
    pub fn pressure_rates_through(
        &self,
        areas: &OrificeAreas,
        p1: f64,
        p2: f64,
        x_s: f64,
        x_s_rate: f64,
    ) -> (f64, f64) {
        match self.rate_terms {
            RateTerms::Thesis => self.thesis_pressure_rates(areas, p1, p2, x_s, x_s_rate),
            RateTerms::Extended => self.extended_pressure_rates(areas, p1, p2, x_s, x_s_rate),
        }
    }

    /// [`Self::pressure_rates_through`] with every term tested for: right for any model.
    pub fn extended_pressure_rates(
        &self,
        areas: &OrificeAreas,
        p1: f64,
        p2: f64,
        x_s: f64,
        x_s_rate: f64,
    ) -> (f64, f64) {
        let flows = self.mass_flows_through(areas, p1, p2);
        self.chamber_rates(flows.net_1(), flows.net_2(), p1, p2, x_s, x_s_rate)
    }

    /// Which terms of the pressure rates this model has.
    pub fn rate_terms(&self) -> RateTerms {
        self.rate_terms
    }

    /// [`Self::pressure_rates_through`] of a model whose [`RateTerms`] are the thesis's: the
    /// flows (2.18)–(2.25) into (2.29), with no test for the terms that are off. The same
    /// operations in the same order as the general path's, so the same bits (a vent of zero
    /// is a subtraction of +0, which changes no value).
    #[inline(always)]
    pub fn thesis_pressure_rates(&self, a: &OrificeAreas, p1: f64, p2: f64, x_s: f64, x_s_rate: f64) -> (f64, f64) {
        let p = &self.params;
        let (net_1, net_2) = self.thesis_net_flows(a, p1, p2);
        let (v1, v2) = self.cylinder.volumes(x_s);
        let (dv1, dv2) = self.cylinder.volume_rates(x_s_rate);
        let n = self.polytropic_exponent;
        (
            pressure_rate(n, p.r_gas, p.temperature, v1, dv1, net_1, p1),
            pressure_rate(n, p.r_gas, p.temperature, v2, dv2, net_2, p2),
        )
    }

    /// [`Self::thesis_pressure_rates`] with the stopper's part worked out once for a step
    /// ([`Self::held_chambers`]): the same bits.
    #[inline(always)]
    pub fn thesis_pressure_rates_held(&self, a: &OrificeAreas, p1: f64, p2: f64, held: &HeldChambers) -> (f64, f64) {
        let (net_1, net_2) = self.thesis_net_flows(a, p1, p2);
        (held.pressure_rate(0, net_1, p1), held.pressure_rate(1, net_2, p2))
    }

    /// The net mass inflows (2.24), (2.25) of the chambers through the valve's four orifices
    /// (2.18)–(2.22) and past the piston (2.23), by the thesis's terms alone.
    #[inline(always)]
    fn thesis_net_flows(&self, a: &OrificeAreas, p1: f64, p2: f64) -> (f64, f64) {
        let p = &self.params;
        let k = &self.flow;
        let [cd_s1, cd_r1, cd_s2, cd_r2] = self.discharge;
        let (s1, r1, s2, r2) = (
            cd_s1 * a.supply_1,
            cd_r1 * a.return_1,
            cd_s2 * a.supply_2,
            cd_r2 * a.return_2,
        );
        // The open supply and the leakage, unchoked over most of the stroke, in one packed
        // evaluation (`orifice_flow::mass_flow_and_leakage`); the returns vent to the
        // atmosphere, choked, and a closed orifice costs a comparison.
        let (supply_1, supply_2, leakage) = if s2 == 0.0 {
            let [supply_1, leakage] =
                orifice_flow::mass_flow_and_leakage(k, s1, p.p_s, p1, p.c_dm_a_lpp, p.c_db_a_lpp, p1, p2);
            (supply_1, 0.0, leakage)
        } else {
            let [supply_2, leakage] =
                orifice_flow::mass_flow_and_leakage(k, s2, p.p_s, p2, p.c_dm_a_lpp, p.c_db_a_lpp, p1, p2);
            (orifice_flow::mass_flow_inline(k, s1, p.p_s, p1), supply_2, leakage)
        };
        let return_1 = orifice_flow::mass_flow_inline(k, r1, p1, p.p_r);
        let return_2 = orifice_flow::mass_flow_inline(k, r2, p2, p.p_r);
        // (2.24), (2.25)
        let net_1 = supply_1 - return_1 - leakage;
        let net_2 = supply_2 - return_2 + leakage;
        (net_1, net_2)
    }

    /// What (2.29) takes from the stopper and the gas over a step in which the stopper stays
    /// at `x_s` (moving at `x_s_rate` = ±0): see [`HeldChambers`].
    pub fn held_chambers(&self, x_s: f64, x_s_rate: f64) -> HeldChambers {
        let p = &self.params;
        let (v1, v2) = self.cylinder.volumes(x_s);
        let (dv1, dv2) = self.cylinder.volume_rates(x_s_rate);
        let n = self.polytropic_exponent;
        HeldChambers {
            gamma_over_volume: [n / v1, n / v2],
            volume_rate: [dv1, dv2],
            r_gas_temperature: p.r_gas * p.temperature,
        }
    }

    /// (2.29) for both chambers with their net mass inflows.
    fn chamber_rates(&self, net_1: f64, net_2: f64, p1: f64, p2: f64, x_s: f64, x_s_rate: f64) -> (f64, f64) {
        let p = &self.params;
        if p.stopper_compliance != 0.0 {
            return self.pressure_rates_on_a_compliant_stopper(net_1, net_2, p1, p2, x_s, x_s_rate);
        }
        let (v1, v2) = self.cylinder.volumes(x_s);
        let (dv1, dv2) = self.cylinder.volume_rates(x_s_rate);
        (
            pressure_rate(self.polytropic_exponent, p.r_gas, p.temperature, v1, dv1, net_1, p1),
            pressure_rate(self.polytropic_exponent, p.r_gas, p.temperature, v2, dv2, net_2, p2),
        )
    }

    /// (2.29) when the piston sits c F beyond the stopper (`stopper_compliance` c), F the
    /// force the mount carries: the actuator force of (2.36), A_p (P1 − P2) floored by the
    /// spring force. Above the floor the volumes move with the pressures, and so the rates
    /// appear on both sides, Ṗ1 = a1 − b1 (ẋ_s + c A_p D), Ṗ2 = a2 + b2 (ẋ_s + c A_p D) with
    /// D = Ṗ1 − Ṗ2, b_i = n P_i A_p / V_i, solved for D in closed form; on the floor the
    /// spring alone loads the mount, and the piston moves with the stopper and the spring.
    fn pressure_rates_on_a_compliant_stopper(
        &self,
        net_1: f64,
        net_2: f64,
        p1: f64,
        p2: f64,
        x_s: f64,
        x_s_rate: f64,
    ) -> (f64, f64) {
        let p = &self.params;
        let n = self.polytropic_exponent;
        let stretch = p.stopper_compliance * self.piston_area;
        let floor = self.mount_floor(x_s);
        if p1 - p2 < floor {
            let floor_rate = -p.k_spring * x_s_rate / self.piston_area;
            return self.pressure_rates_on_a_lagging_mount(net_1, net_2, p1, p2, floor, floor_rate, x_s, x_s_rate);
        }
        let (v1, v2) = self.cylinder.volumes(x_s + stretch * (p1 - p2));
        let (dv1, dv2) = self.cylinder.volume_rates(x_s_rate);
        let d1 = pressure_rate(n, p.r_gas, p.temperature, v1, dv1, net_1, p1);
        let d2 = pressure_rate(n, p.r_gas, p.temperature, v2, dv2, net_2, p2);
        let (b1, b2) = (n * p1 * self.piston_area / v1, n * p2 * self.piston_area / v2);
        let difference = (d1 - d2) / (1.0 + (b1 + b2) * stretch);
        (d1 - b1 * stretch * difference, d2 + b2 * stretch * difference)
    }

    /// The spring force of (2.37) over A_p: the pressure difference below which the spring,
    /// not the pressures, loads the stopper mount.
    fn mount_floor(&self, x_s: f64) -> f64 {
        self.spring_force(x_s) / self.piston_area
    }

    /// The pressure difference the stopper mount carries: the actuator force (2.36) over A_p,
    /// the state a lagging mount follows ([`node::MOUNT`]).
    pub fn mount_load(&self, p1: f64, p2: f64, x_s: f64) -> f64 {
        (p1 - p2).max(self.mount_floor(x_s))
    }

    /// Whether the piston sits at the stopper whatever the pressures ([`Self::piston_offset`] 0).
    pub fn stopper_is_rigid(&self) -> bool {
        self.params.stopper_compliance == 0.0
    }

    /// How far beyond the stopper the piston sits (m): 0 on a rigid stopper ((2.32) puts it
    /// at the stopper), c A_p times the mount's load on a compliant one: its state `mount` when
    /// it lags, else [`Self::mount_load`] (the laws of [`Self::pressure_rates_with_volumes`]).
    pub fn piston_offset(&self, p1: f64, p2: f64, mount: f64, x_s: f64) -> f64 {
        let stretch = self.params.stopper_compliance * self.piston_area;
        if self.stopper_is_rigid() {
            0.0
        } else if self.mount_lag.is_some() {
            stretch * mount
        } else {
            stretch * self.mount_load(p1, p2, x_s)
        }
    }

    /// The rate of [`Self::piston_offset`] with the stopper held, for the rates `dp1`, `dp2`
    /// and `dmount` of its pressures and of the mount's state.
    pub fn piston_offset_rate(&self, p1: f64, p2: f64, x_s: f64, dp1: f64, dp2: f64, dmount: f64) -> f64 {
        let stretch = self.params.stopper_compliance * self.piston_area;
        if self.stopper_is_rigid() {
            0.0
        } else if self.mount_lag.is_some() {
            stretch * dmount
        } else if p1 - p2 < self.mount_floor(x_s) {
            0.0
        } else {
            stretch * (dp1 - dp2)
        }
    }

    /// The chambers' volumes with the piston at [`Self::piston_offset`] beyond the stopper.
    pub fn chamber_volumes(&self, p1: f64, p2: f64, mount: f64, x_s: f64) -> (f64, f64) {
        self.cylinder.volumes(x_s + self.piston_offset(p1, p2, mount, x_s))
    }

    /// The chambers' pressures whose air, brought with no flow to the volumes `reference`, has
    /// the pressures `at_reference` ([`chambers::reference_pressure_rate`]), with the piston
    /// where those pressures put it. On a compliant stopper without a lag the offset e solves
    /// e = c A_p max(P1(e) − P2(e), floor), whose right side falls as e grows (the piston
    /// enlarges chamber 1 and shrinks chamber 2): one root, bracketed and found by the
    /// Illinois method.
    pub fn pressures_from_reference(
        &self,
        at_reference: [f64; 2],
        reference: (f64, f64),
        mount: f64,
        x_s: f64,
    ) -> [f64; 2] {
        let n = self.polytropic_exponent;
        let at = |offset: f64| {
            let (v1, v2) = self.cylinder.volumes(x_s + offset);
            [
                chambers::pressure_after_volume_jump(n, at_reference[0], reference.0, v1),
                chambers::pressure_after_volume_jump(n, at_reference[1], reference.1, v2),
            ]
        };
        if self.stopper_is_rigid() || self.mount_lag.is_some() {
            return at(self.piston_offset(0.0, 0.0, mount, x_s));
        }
        let stretch = self.params.stopper_compliance * self.piston_area;
        let floor = self.mount_floor(x_s);
        // Beyond the cylinder a pressure is not finite: the offset is too far, the side < 0.
        let side = |offset: f64| {
            let p = at(offset);
            let s = stretch * (p[0] - p[1]).max(floor) - offset;
            if s.is_finite() {
                s
            } else {
                f64::NEG_INFINITY
            }
        };
        let low = stretch * floor;
        let at_low = side(low);
        if at_low <= 0.0 {
            return at(low);
        }
        // The side falls at least as fast as the offset grows: its root is within at_low.
        let (mut a, mut fa, mut b, mut fb) = (low, at_low, low + at_low, side(low + at_low));
        for _ in 0..200 {
            if fb == 0.0 || (b - a).abs() <= 4.0 * f64::EPSILON * (x_s.abs() + b.abs()) {
                break;
            }
            let c = if fb.is_finite() && fa.is_finite() {
                b - fb * (b - a) / (fb - fa)
            } else {
                0.5 * (a + b)
            };
            let c = if c > a.min(b) && c < a.max(b) { c } else { 0.5 * (a + b) };
            let fc = side(c);
            if (fc > 0.0) == (fb > 0.0) {
                // a kept again: its side halved (Illinois), so that the next guess moves it.
                fa *= 0.5;
            } else {
                a = b;
                fa = fb;
            }
            b = c;
            fb = fc;
        }
        at(b)
    }

    /// The chambers' pressures after the stopper jumps from `from` to `to` with no time for a
    /// flow: the air in each conserved, P V^γ constant, the volumes before and after with the
    /// piston where the pressures put it ([`Self::chamber_volumes`]).
    pub fn pressures_after_stopper_jump(&self, p1: f64, p2: f64, mount: f64, from: f64, to: f64) -> [f64; 2] {
        let before = self.chamber_volumes(p1, p2, mount, from);
        self.pressures_from_reference([p1, p2], before, mount, to)
    }

    /// Static jet pipe position x̄ for a current, (2.4)–(2.5).
    pub fn static_jet_position(&self, current: f64) -> f64 {
        let p = &self.params;
        jet_pipe::F3::from_parameters(p).value(jet_pipe::tip_force(p.k_m, current))
    }

    /// The state equations (4.1).
    pub fn derivatives(&self, y: &State, u: &Inputs) -> State {
        use index::*;
        let p = &self.params;
        let static_current = current_driver::static_current(p.k_cd, p.i_offset, u.v_da);
        let x_bar = self.jet_input(y[CURRENT], u.plays.as_ref());
        let (dp1, dp2) = self.pressure_rates(y[JET_POSITION], y[P1], y[P2], u.x_s, u.x_s_rate);
        State::from([
            current_driver::current_rate(p.omega_cd, static_current, y[CURRENT]),
            y[JET_VELOCITY],
            y[JET_ACCELERATION],
            jet_pipe::LinearDynamics::from_parameters(p).third_derivative(
                x_bar,
                y[JET_POSITION],
                y[JET_VELOCITY],
                y[JET_ACCELERATION],
            ),
            dp1,
            dp2,
        ])
    }

    /// ∂f/∂y: exact for the current driver and jet pipe, forward differences for the
    /// two pressure rows (which depend on x_jp, P1 and P2 only).
    pub fn jacobian(&self, y: &State, u: &Inputs, f_y: &State) -> Jacobian {
        use index::*;
        let p = &self.params;
        let mut jac = Jacobian::zeros();
        jac[(CURRENT, CURRENT)] = -p.omega_cd;
        jac[(JET_POSITION, JET_VELOCITY)] = 1.0;
        jac[(JET_VELOCITY, JET_ACCELERATION)] = 1.0;
        let [c2, c3, c4] = jet_pipe::LinearDynamics::from_parameters(p).coefficients();
        let slope = jet_pipe::F3::from_parameters(p).slope(jet_pipe::tip_force(p.k_m, y[CURRENT]));
        jac[(JET_ACCELERATION, CURRENT)] = c4 * slope * p.k_m;
        jac[(JET_ACCELERATION, JET_POSITION)] = -c4;
        jac[(JET_ACCELERATION, JET_VELOCITY)] = -c3;
        jac[(JET_ACCELERATION, JET_ACCELERATION)] = -c2;
        for (column, scale) in [(JET_POSITION, 1e-7), (P1, 1e3), (P2, 1e3)] {
            let h = 1e-7 * y[column].abs().max(scale);
            let mut x = [y[JET_POSITION], y[P1], y[P2]];
            let slot = match column {
                JET_POSITION => 0,
                P1 => 1,
                _ => 2,
            };
            x[slot] += h;
            let (dp1, dp2) = self.pressure_rates(x[0], x[1], x[2], u.x_s, u.x_s_rate);
            jac[(P1, column)] = (dp1 - f_y[P1]) / h;
            jac[(P2, column)] = (dp2 - f_y[P2]) / h;
        }
        jac
    }

    pub fn spring_force(&self, x_s: f64) -> f64 {
        let p = &self.params;
        piston::spring_force(p.k_spring, p.l_spring0, p.l_s, p.l_p, x_s)
    }

    /// The hysteresis memory at the start of a run, at the static position of `current`
    /// (`hysteresis_start` places it in the loop).
    pub fn initial_hysteresis_memory(&self, current: f64) -> [f64; PLAY_OPERATORS] {
        self.hysteresis
            .initial_memory(self.static_jet_position(current), self.params.hysteresis_start)
    }

    /// The jet pipe input at rest at the start of a run: f3 of the current, or the
    /// hysteresis output where `hysteresis_start` puts the loop away from its middle.
    pub fn initial_jet_input(&self, current: f64) -> f64 {
        if self.hysteresis.is_active() && self.params.hysteresis_start != 0.0 {
            self.hysteresis.output(&self.initial_hysteresis_memory(current))
        } else {
            self.static_jet_position(current)
        }
    }

    /// Input of the jet pipe dynamics: f3 of the tip force, through the hysteresis
    /// operator when that effect is on (plays moved monotonically from `plays`).
    pub fn jet_input(&self, current: f64, plays: Option<&[f64; PLAY_OPERATORS]>) -> f64 {
        let x_bar = self.static_jet_position(current);
        match plays {
            Some(plays) if self.hysteresis.is_active() => self.hysteresis.output_after(plays, x_bar),
            _ => x_bar,
        }
    }

    /// Outputs for a state; `stopper_velocity` only matters with the piston_friction effect.
    pub fn outputs(&self, y: &State, x_s: f64, stopper_velocity: f64) -> Outputs {
        self.outputs_at(y, x_s, stopper_velocity, 0.0)
    }

    /// The outputs at time `time` (the transducers' drifts and pick-up depend on it; their
    /// filters are the caller's: see [`super::sensors::SensorMemory`]).
    pub fn outputs_at(&self, y: &State, x_s: f64, stopper_velocity: f64, time: f64) -> Outputs {
        self.outputs_in_motion(y, x_s, stopper_velocity, 0.0, time)
    }

    /// [`Self::outputs_at`] with the stopper's acceleration as the model forms it (see
    /// [`super::extra_force`]; it matters only with `extra_force_acceleration`).
    pub fn outputs_in_motion(
        &self,
        y: &State,
        x_s: f64,
        stopper_velocity: f64,
        stopper_acceleration: f64,
        time: f64,
    ) -> Outputs {
        use index::*;
        if self.thesis_outputs {
            // (2.36)–(2.38) with no friction term (a friction of ±0 subtracted from a
            // pressure force, which is never −0, changes no bit); each reading is its
            // quantity, as the general law's offset 0 plus gain 1 times it: 0 + x, which is x
            // but for −0.
            let f_act = piston::actuator_force(
                piston::pressure_force(self.piston_area, y[P1], y[P2]),
                self.spring_force(x_s),
            );
            return Outputs {
                f_act,
                f_meas: 0.0 + f_act,
                p1_meas: 0.0 + y[P1],
                p2_meas: 0.0 + y[P2],
                p1: y[P1],
                p2: y[P2],
                current: y[CURRENT],
                x_jp: y[JET_POSITION],
            };
        }
        let p = &self.params;
        let pressure_force = piston::pressure_force(self.piston_area, y[P1], y[P2])
            - effects::friction_force(
                p.friction_coulomb,
                p.friction_velocity,
                p.friction_stribeck,
                p.friction_stribeck_velocity,
                stopper_velocity,
            )
            - self.extra_piston_force(x_s, stopper_velocity, stopper_acceleration, y[P1], y[P2]);
        let f_act = piston::actuator_force(pressure_force, self.spring_force(x_s));
        Outputs {
            f_act,
            f_meas: SensorLaw::of(p, Channel::Force).static_reading(f_act, time),
            p1_meas: SensorLaw::of(p, Channel::Pressure1).static_reading(y[P1], time),
            p2_meas: SensorLaw::of(p, Channel::Pressure2).static_reading(y[P2], time),
            p1: y[P1],
            p2: y[P2],
            current: y[CURRENT],
            x_jp: y[JET_POSITION],
        }
    }

    /// Forces on the piston beyond the thesis's (2.33)–(2.38) and Coulomb friction, opposing
    /// the pressure force: viscous friction, a force on the stopper position and the extra
    /// force's library terms and product slots, which add to the pressure force (subtracted
    /// here; off by default).
    fn extra_piston_force(&self, x_s: f64, stopper_velocity: f64, stopper_acceleration: f64, p1: f64, p2: f64) -> f64 {
        let p = &self.params;
        let mut f = 0.0;
        if self.extra_library {
            let [quadratic, sign_pressure, difference] =
                extra_force::signals(stopper_velocity, p.extra_force_sign_velocity, p1, p2, p.p_r);
            f -= p.extra_force_acceleration * stopper_acceleration
                + p.extra_force_velocity_squared * quadratic
                + p.extra_force_sign_pressure * sign_pressure
                + p.extra_force_pressure_difference * difference;
        }
        if self.extra_products {
            let signals = extra_force::MechanicsSignals {
                x_s,
                velocity: stopper_velocity,
                acceleration: stopper_acceleration,
                sign_velocity: p.extra_force_sign_velocity,
                p1,
                p2,
                p_r: p.p_r,
            };
            f -= extra_force::product_force(&p.extra_force_products, &signals);
        }
        // Where a product slot of codes 0 × 0 adds its coefficient (so the two agree).
        f -= p.extra_force_offset;
        if p.viscous_friction != 0.0 {
            f += p.viscous_friction * stopper_velocity;
        }
        if p.position_force_rate != 0.0 {
            f += p.position_force_rate * (x_s - p.position_force_reference);
        }
        f
    }

    /// Per-state scales used for absolute tolerances: a current of 0.1 A, a tip
    /// displacement of 0.1 mm with its natural-frequency derivatives, and 1 bar.
    pub fn state_scales(&self) -> State {
        let w = self.params.omega_2;
        let x = 1e-4;
        State::from([0.1, x, x * w, x * w * w, 1e5, 1e5])
    }
}

#[cfg(test)]
mod tests;
