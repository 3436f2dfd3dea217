//! Restrictions between the valve and the air around it, and the gas volumes behind them
//! (off by default; the thesis's valve sees P_s, P_r and the chamber pressures directly).
//!
//! Four places can hold a restriction: the supply line (between P_s and the jet pipe), the
//! return line (between the return orifices and P_r), and each receiver port (between the
//! port's orifices and its chamber). A restriction is a linear resistance (Pa·s/kg: the
//! pressure falls by R ṁ) or an orifice of effective area C_d·A with the compressible law
//! (2.18). Without a volume the pressure behind it is quasi-static: the root at which the flow
//! through the restriction equals the flow the valve draws or delivers at that pressure. With a
//! volume V it is a state with the chambers' law (2.29) at a fixed volume,
//! Ṗ = n R T ṁ_net / V, so the restriction and the volume together are a first-order lag on
//! the valve's side, of time constant about R_eff V / (n R T) with R_eff = dΔp/dṁ of the
//! restriction (3 cm³ behind 0.2 mm²: a few milliseconds).

use super::effects;
use super::orifice_flow::{mass_flow, FlowConstants};
use super::parameters::Parameters;

/// One restriction and the gas volume on the valve's side of it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Restriction {
    /// Linear resistance, Pa·s/kg (0 = not this law).
    pub resistance: f64,
    /// Discharge coefficient times area of an orifice, m² (0 = not this law).
    pub cd_area: f64,
    /// Gas volume between the valve and the restriction, m³ (0 = none: quasi-static).
    pub volume: f64,
}

impl Restriction {
    pub fn is_present(&self) -> bool {
        self.resistance > 0.0 || self.cd_area > 0.0
    }

    /// Whether the pressure behind it is a state.
    pub fn has_volume(&self) -> bool {
        self.volume > 0.0 && self.is_present()
    }

    /// Mass flow through it from pressure `from` to pressure `to`, kg/s.
    #[inline]
    pub fn flow(&self, k: &FlowConstants, from: f64, to: f64) -> f64 {
        if self.resistance > 0.0 {
            (from - to) / self.resistance
        } else {
            mass_flow(k, self.cd_area, from, to)
        }
    }
}

/// Positions of the gas volumes' pressures after P1 and P2 in the extended pressure vector
/// the integrators carry when any volume is on, and after them the lagging stopper mount's
/// state.
pub mod node {
    pub const SUPPLY: usize = 0;
    pub const RETURN: usize = 1;
    pub const LINE_1: usize = 2;
    pub const LINE_2: usize = 3;
    /// The places that can hold a restriction.
    pub const COUNT: usize = 4;
    /// The pressure difference P1 − P2 as the lagging stopper mount has followed it
    /// (`stopper_mount_lag`): the piston sits `stopper_compliance` A_p times it beyond the
    /// stopper. In Pa, so that the integrators' tolerances, set for pressures, fit it.
    pub const MOUNT: usize = 4;
    /// The states after P1 and P2.
    pub const STATES: usize = 5;
}

/// The states the integrators carry with the volumes: P1, P2, the four nodes' pressures and
/// the mount's.
pub const PRESSURES_WITH_VOLUMES: usize = 2 + node::STATES;

/// The restrictions of the four places, in the order of [`node`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Restrictions {
    pub places: [Restriction; node::COUNT],
}

impl Restrictions {
    pub fn from_parameters(p: &Parameters) -> Self {
        Self {
            places: [
                Restriction {
                    resistance: p.supply_resistance,
                    cd_area: p.supply_restriction_area,
                    volume: p.supply_plenum_volume,
                },
                Restriction {
                    resistance: p.return_resistance,
                    cd_area: p.return_vent_area,
                    volume: p.return_plenum_volume,
                },
                Restriction {
                    resistance: p.port_resistance_1,
                    cd_area: p.port_restriction_area_1,
                    volume: p.port_line_volume_1,
                },
                Restriction {
                    resistance: p.port_resistance_2,
                    cd_area: p.port_restriction_area_2,
                    volume: p.port_line_volume_2,
                },
            ],
        }
    }

    pub fn any(&self) -> bool {
        self.places.iter().any(Restriction::is_present)
    }

    /// Whether any pressure behind a restriction is a state.
    pub fn has_volumes(&self) -> bool {
        self.places.iter().any(Restriction::has_volume)
    }
}

/// The parameter names of each place, in the order of [`node`], for messages.
pub const PLACE_NAMES: [(&str, &str, &str); node::COUNT] = [
    ("supply_resistance", "supply_restriction_area", "supply_plenum_volume"),
    ("return_resistance", "return_vent_area", "return_plenum_volume"),
    ("port_resistance_1", "port_restriction_area_1", "port_line_volume_1"),
    ("port_resistance_2", "port_restriction_area_2", "port_line_volume_2"),
];

/// A place's restriction has one law, and a volume only behind a restriction.
pub fn check(p: &Parameters) -> Result<(), String> {
    let restrictions = Restrictions::from_parameters(p);
    for (r, (resistance, area, volume)) in restrictions.places.iter().zip(PLACE_NAMES) {
        if r.resistance > 0.0 && r.cd_area > 0.0 {
            return Err(format!(
                "{resistance} = {} Pa.s/kg and {area} = {} m2 are both set: they are two laws of the same restriction, set one",
                r.resistance, r.cd_area
            ));
        }
        if r.volume > 0.0 && !r.is_present() {
            return Err(format!(
                "{volume} = {} m3 is invalid without a restriction: set {resistance} or {area} (a volume open to the valve on one side and to nothing on the other holds no pressure of its own)",
                r.volume
            ));
        }
    }
    Ok(())
}

/// The quasi-static pressure between a flow `inflow(q)` that falls as q rises and a flow
/// `outflow(q)` that rises, in [lo, hi]: the root of outflow = inflow. The imbalance is taken
/// relative to the flows' size and in the pressures' scale, so the root finder's tolerances
/// (relative to the pressures) mean something for flows of any size.
#[inline(never)]
pub fn balanced_pressure(lo: f64, hi: f64, flows: impl Fn(f64) -> (f64, f64)) -> f64 {
    let scale = lo.abs().max(hi.abs());
    effects::increasing_root(lo, hi, |q| {
        let (inflow, outflow) = flows(q);
        scale * (outflow - inflow) / (outflow.abs() + inflow.abs() + f64::MIN_POSITIVE)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_restriction_flows_from_the_higher_pressure_by_its_law() {
        let k = Parameters::default().flow_constants();
        let linear = Restriction {
            resistance: 1e8,
            ..Default::default()
        };
        assert_eq!(linear.flow(&k, 3e5, 2e5), 1e-3);
        assert_eq!(linear.flow(&k, 2e5, 3e5), -1e-3);
        let orifice = Restriction {
            cd_area: 0.2e-6,
            ..Default::default()
        };
        assert_eq!(orifice.flow(&k, 3e5, 2e5), mass_flow(&k, 0.2e-6, 3e5, 2e5));
        assert_eq!(orifice.flow(&k, 2e5, 3e5), -orifice.flow(&k, 3e5, 2e5));
        assert!(!Restriction::default().is_present());
        assert!(!Restriction {
            volume: 1e-6,
            ..Default::default()
        }
        .has_volume());
    }

    #[test]
    fn a_volume_without_a_restriction_and_two_laws_at_once_are_refused_by_name() {
        let e = check(&Parameters {
            port_line_volume_1: 3e-6,
            ..Default::default()
        })
        .unwrap_err();
        assert!(
            e.contains("port_line_volume_1 = 0.000003") && e.contains("port_restriction_area_1"),
            "{e}"
        );
        let e = check(&Parameters {
            supply_resistance: 1e8,
            supply_restriction_area: 1e-7,
            ..Default::default()
        })
        .unwrap_err();
        assert!(
            e.contains("supply_resistance = 100000000") && e.contains("supply_restriction_area"),
            "{e}"
        );
        assert!(check(&Parameters {
            return_vent_area: 0.35e-6,
            return_plenum_volume: 2e-6,
            ..Default::default()
        })
        .is_ok());
    }

    #[test]
    fn the_balanced_pressure_equates_the_two_flows() {
        let k = Parameters::default().flow_constants();
        // A node fed from 6e5 Pa through 0.3 mm² and emptied to 1e5 Pa through 0.5 mm².
        let q = balanced_pressure(1e5, 6e5, |q| {
            (mass_flow(&k, 0.3e-6, 6e5, q), mass_flow(&k, 0.5e-6, q, 1e5))
        });
        let (inflow, outflow) = (mass_flow(&k, 0.3e-6, 6e5, q), mass_flow(&k, 0.5e-6, q, 1e5));
        assert!((inflow - outflow).abs() < 1e-9 * inflow, "{q}: {inflow} vs {outflow}");
        assert!(q > 1e5 && q < 6e5);
    }
}
