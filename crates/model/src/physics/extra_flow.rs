//! An extra mass flow into (or out of) one chamber alone, off by default: the chambers'
//! mass balances (2.24)–(2.25) gain a flow that no other place loses, a function of the
//! pressures, from a library of signals the diagnosis picks from (the leaks of
//! [`super::actuator`] conserve mass between two places; these slots need not).
//!
//! **The slots.** Three slots (`extra_flow_k_chamber`, `_signal`, `_coefficient`, k = 1..3,
//! off with a coefficient of 0) each add c_k g(P) to the net inflow of chamber i_k (1 or 2),
//! where g is one of the signals below over the reference unit 1 bar (1e5 Pa), so that the
//! coefficient c_k is a mass flow (kg/s): c > 0 brings mass into the chamber when g > 0.
//! P_i is the slot's chamber's pressure.
//!
//! | code | signal g | |
//! |---|---|---|
//! | 0 | 1 | a constant flow |
//! | 1 | (P1 − P2) / 1 bar | |
//! | 2 | (P_s − P_i) / 1 bar | a laminar path from the supply (`chamber_laminar_supply_leak_i` is its c / 1e5 Pa) |
//! | 3 | (P_i − P_r) / 1 bar | |
//! | 4 | sqrt(\|P1 − P2\| / 1 bar) · sign(P1 − P2) | |
//! | 5 | sqrt(\|P_s − P_i\| / 1 bar) · sign(P_s − P_i) | |
//! | 6 | sqrt(\|P_i − P_r\| / 1 bar) · sign(P_i − P_r) | |
//!
//! **Its thermodynamics.** As the chambers' leaks (`chamber_vent_*`, `chamber_laminar_*`),
//! the flow enters the chamber's mass balance only: with the constant gas temperature of §2.6
//! (2.29) every flow, in or out, carries R T per kilogram into the pressure rate, so the added
//! mass arrives at the chamber's temperature T (and the polytropic exponent of the
//! `heat_transfer_fraction` effect applies to it as to the valve's flows). It is summed
//! into [`super::actuator::MassFlows`]'s `vent_i`, what the chamber loses through leaks of its
//! own (less the flow added), so every path that forms the net flows (the restrictions'
//! network, the compliant mount) sees it.
//!
//! The square roots have an infinite slope at a zero difference, as the orifice law (2.18)
//! and the piston's leakage (2.23) have.
//!
//! **A chamber cannot give mass it has not got.** Where a slot takes mass out of a chamber
//! (c g < 0), the outflow fades in proportion to the chamber's pressure below
//! [`FADE_PRESSURE`] (0.1 bar absolute) and vanishes at 0: c g exactly wherever the chamber
//! holds 0.1 bar or more, which the return pressure (1 bar) keeps it above in any working
//! state. Without it an outflow that the valve cannot make up (a constant one, or one in
//! proportion to P1 − P2 with the wrong sign, which a fit may try) drove the pressure
//! through zero, where the integrators crawled at steps of 1e-12 s.

/// Reference unit of the signals: 1 bar.
pub const REFERENCE: f64 = 1e5;

/// Below this absolute pressure (Pa) of its chamber a slot's outflow fades to 0 at 0 Pa.
pub const FADE_PRESSURE: f64 = 1e4;

/// The number of extra flow slots.
pub const FLOW_SLOTS: usize = 3;

/// The largest signal code of an extra flow slot.
pub const LAST_FLOW_CODE: u32 = 6;

/// The signals of the extra flow slots, by code (see the module's table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FlowSignal {
    One,
    Difference,
    FromSupply,
    ToReturn,
    SqrtDifference,
    SqrtFromSupply,
    SqrtToReturn,
}

impl FlowSignal {
    pub const ALL: [FlowSignal; 7] = [
        FlowSignal::One,
        FlowSignal::Difference,
        FlowSignal::FromSupply,
        FlowSignal::ToReturn,
        FlowSignal::SqrtDifference,
        FlowSignal::SqrtFromSupply,
        FlowSignal::SqrtToReturn,
    ];

    pub fn code(self) -> u32 {
        self as u32
    }

    /// The signal of a code, if it is a whole number from 0 to [`LAST_FLOW_CODE`].
    pub fn from_code(code: f64) -> Option<Self> {
        if code.fract() != 0.0 || !(0.0..=f64::from(LAST_FLOW_CODE)).contains(&code) {
            return None;
        }
        Some(Self::ALL[code as usize])
    }

    /// A short name for chamber `chamber` (1 or 2), as the readings write it.
    pub fn name(self, chamber: usize) -> String {
        let own = format!("P{chamber}");
        match self {
            FlowSignal::One => "1".to_string(),
            FlowSignal::Difference => "(P1 − P2)".to_string(),
            FlowSignal::FromSupply => format!("(P_s − {own})"),
            FlowSignal::ToReturn => format!("({own} − P_r)"),
            FlowSignal::SqrtDifference => "sqrt|P1 − P2|·sign(P1 − P2)".to_string(),
            FlowSignal::SqrtFromSupply => format!("sqrt|P_s − {own}|·sign(P_s − {own})"),
            FlowSignal::SqrtToReturn => format!("sqrt|{own} − P_r|·sign({own} − P_r)"),
        }
    }

    /// The pressure difference the signal is formed from (Pa) and whether it is a root.
    fn difference(self, chamber: usize, p: &ChamberPressures) -> (f64, bool) {
        let own = if chamber == 2 { p.p2 } else { p.p1 };
        match self {
            FlowSignal::One => (REFERENCE, false),
            FlowSignal::Difference => (p.p1 - p.p2, false),
            FlowSignal::FromSupply => (p.p_s - own, false),
            FlowSignal::ToReturn => (own - p.p_r, false),
            FlowSignal::SqrtDifference => (p.p1 - p.p2, true),
            FlowSignal::SqrtFromSupply => (p.p_s - own, true),
            FlowSignal::SqrtToReturn => (own - p.p_r, true),
        }
    }

    /// g for chamber `chamber` (1 or 2): the signal over its reference unit, 1 bar.
    pub fn value(self, chamber: usize, p: &ChamberPressures) -> f64 {
        let (difference, root) = self.difference(chamber, p);
        let g = difference / REFERENCE;
        if root {
            g.abs().sqrt() * g.signum()
        } else {
            g
        }
    }
}

/// The pressures the signals are formed from (Pa).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChamberPressures {
    pub p1: f64,
    pub p2: f64,
    pub p_s: f64,
    pub p_r: f64,
}

/// One slot's settings: the chamber (1 or 2), the signal code and the coefficient
/// (kg/s per reference unit; 0 = off).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlowSlot {
    pub chamber: f64,
    pub signal: f64,
    pub coefficient: f64,
}

impl Default for FlowSlot {
    fn default() -> Self {
        Self {
            chamber: 1.0,
            signal: 0.0,
            coefficient: 0.0,
        }
    }
}

impl FlowSlot {
    pub fn is_on(&self) -> bool {
        self.coefficient != 0.0
    }

    /// The chamber's index (0 or 1), if the code is 1 or 2.
    fn chamber_index(&self) -> Option<usize> {
        if self.chamber == 1.0 {
            Some(0)
        } else if self.chamber == 2.0 {
            Some(1)
        } else {
            None
        }
    }

    /// g: the slot's signal for its chamber (0 for codes out of range, which
    /// [`check_flows`] refuses before a model is built).
    pub fn regressor(&self, p: &ChamberPressures) -> f64 {
        match (self.chamber_index(), FlowSignal::from_code(self.signal)) {
            (Some(i), Some(signal)) => signal.value(i + 1, p),
            _ => 0.0,
        }
    }
}

/// The mass flows (kg/s) the slots that are on bring into chambers 1 and 2: Σ c_k g_k, an
/// outflow faded below [`FADE_PRESSURE`] (see the module's comment).
pub fn inflows(slots: &[FlowSlot; FLOW_SLOTS], p: &ChamberPressures) -> [f64; 2] {
    let mut out = [0.0; 2];
    for slot in slots.iter().filter(|s| s.is_on()) {
        if let Some(i) = slot.chamber_index() {
            let own = if i == 0 { p.p1 } else { p.p2 };
            out[i] += faded(slot.coefficient * slot.regressor(p), own);
        }
    }
    out
}

/// A mass flow `flow` (kg/s) into a chamber at absolute pressure `own` (Pa), an outflow
/// faded below [`FADE_PRESSURE`] (see the module's comment): the slots' law, which the plain
/// constants `extra_inflow_1` and `extra_inflow_2` share (a constant inflow is a slot of
/// signal code 0).
pub fn faded(flow: f64, own: f64) -> f64 {
    if flow < 0.0 && own < FADE_PRESSURE {
        flow * (own / FADE_PRESSURE).max(0.0)
    } else {
        flow
    }
}

/// Whether an extra flow slot is on.
pub fn flows_on(slots: &[FlowSlot; FLOW_SLOTS]) -> bool {
    slots.iter().any(FlowSlot::is_on)
}

/// The field of an extra flow slot's value reference.
pub fn flow_field_mut(slots: &mut [FlowSlot; FLOW_SLOTS], value_reference: u32) -> Option<&mut f64> {
    use crate::variables::vr;
    if !(vr::EXTRA_FLOW_1_CHAMBER..=vr::EXTRA_FLOW_LAST).contains(&value_reference) {
        return None;
    }
    let offset = value_reference - vr::EXTRA_FLOW_1_CHAMBER;
    let slot = &mut slots[(offset / vr::EXTRA_FLOW_STRIDE) as usize];
    match offset % vr::EXTRA_FLOW_STRIDE {
        0 => Some(&mut slot.chamber),
        1 => Some(&mut slot.signal),
        2 => Some(&mut slot.coefficient),
        _ => None,
    }
}

/// The slots' chambers 1 or 2 and signal codes whole numbers from 0 to [`LAST_FLOW_CODE`]
/// (run with `Parameters::validate`, as the product slots' codes).
pub fn check_flows(slots: &[FlowSlot; FLOW_SLOTS]) -> Result<(), String> {
    for (k, slot) in slots.iter().enumerate() {
        if slot.chamber_index().is_none() {
            return Err(format!(
                "extra_flow_{}_chamber = {} is invalid: must be 1 or 2",
                k + 1,
                crate::variables::number(slot.chamber)
            ));
        }
        if FlowSignal::from_code(slot.signal).is_none() {
            return Err(format!(
                "extra_flow_{}_signal = {} is invalid: must be a whole number from 0 to {LAST_FLOW_CODE} ({})",
                k + 1,
                crate::variables::number(slot.signal),
                FlowSignal::ALL
                    .iter()
                    .map(|&s| format!("{} {}", s.code(), s.name(k + 1)))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_signal_is_its_pressure_difference_in_bar_the_roots_signed() {
        let p = ChamberPressures {
            p1: 3.5e5,
            p2: 5.5e5,
            p_s: 7e5,
            p_r: 1e5,
        };
        let expected = [
            (FlowSignal::One, 1, 1.0),
            (FlowSignal::Difference, 2, -2.0),
            (FlowSignal::FromSupply, 1, 3.5),
            (FlowSignal::FromSupply, 2, 1.5),
            (FlowSignal::ToReturn, 2, 4.5),
            (FlowSignal::SqrtDifference, 1, -(2.0f64.sqrt())),
            (FlowSignal::SqrtFromSupply, 2, 1.5f64.sqrt()),
            (FlowSignal::SqrtToReturn, 1, 2.5f64.sqrt()),
        ];
        for (signal, chamber, g) in expected {
            let value = signal.value(chamber, &p);
            assert!(
                (value - g).abs() < 1e-12,
                "{signal:?} in chamber {chamber}: {value} against {g}"
            );
        }
        let slots = [
            FlowSlot {
                chamber: 2.0,
                signal: 1.0,
                coefficient: 3e-6,
            },
            FlowSlot {
                chamber: 2.0,
                signal: 0.0,
                coefficient: 1e-7,
            },
            FlowSlot::default(),
        ];
        let [in_1, in_2] = inflows(&slots, &p);
        assert_eq!(in_1, 0.0);
        assert!((in_2 - (3e-6 * -2.0 + 1e-7)).abs() < 1e-18, "{in_2}");
    }

    #[test]
    fn an_outflow_fades_below_a_tenth_of_a_bar_and_an_inflow_does_not() {
        let out_of_2 = [
            FlowSlot {
                chamber: 2.0,
                signal: 0.0,
                coefficient: -2e-6,
            },
            FlowSlot {
                chamber: 1.0,
                signal: 0.0,
                coefficient: 3e-6,
            },
            FlowSlot::default(),
        ];
        let at = |p1: f64, p2: f64| {
            inflows(
                &out_of_2,
                &ChamberPressures {
                    p1,
                    p2,
                    p_s: 7e5,
                    p_r: 1e5,
                },
            )
        };
        assert_eq!(at(2e3, 1e4), [3e-6, -2e-6]);
        let [in_1, in_2] = at(2e3, 2.5e3);
        assert_eq!(in_1, 3e-6);
        assert!((in_2 + 0.5e-6).abs() < 1e-18, "{in_2}");
        assert_eq!(at(2e3, -1.0)[1], 0.0);
    }

    #[test]
    fn a_chamber_other_than_1_or_2_and_a_fractional_code_are_refused() {
        let mut slots = [FlowSlot::default(); FLOW_SLOTS];
        assert!(check_flows(&slots).is_ok());
        slots[1].chamber = 3.0;
        assert!(check_flows(&slots).unwrap_err().starts_with("extra_flow_2_chamber = 3"));
        slots[1].chamber = 2.0;
        slots[2].signal = 1.5;
        assert!(check_flows(&slots)
            .unwrap_err()
            .starts_with("extra_flow_3_signal = 1.5"));
        slots[2].signal = 7.0;
        assert!(check_flows(&slots).is_err());
    }
}
