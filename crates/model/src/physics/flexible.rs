//! Flexible slots (all off by default): a constant of the parameter table plus a smooth
//! function of one or two signals of the chain, each optionally low-passed. They generalise
//! the modulation slots ([`super::modulation`]): a modulation slot is a flexible slot with one
//! signal and no lag. The diagnosis adds one where no readable term closes the residual.
//!
//! Slot k (k = 1, 2) names the constant by its value reference (`flexible_k_parameter`, one
//! of [`FLEXIBLE_TARGETS`]: the modulatable constants and the plain constants
//! `extra_force_offset`, `extra_inflow_1`, `extra_inflow_2`), two signals by their codes
//! (`flexible_k_signal_1`, `_signal_2`, [`ModulationSignal`]), a knot grid of up to
//! [`MAX_GRID`] knots per axis (`flexible_k_x1_i`, `_x2_j`) and the constant's increments at
//! its nodes (`flexible_k_y_i_j`). The increment at (u1, u2) is the tensor product of the two
//! axes' piecewise-linear hat bases (bilinear within a cell), held at the edge values beyond
//! the end knots as a modulation slot's increment is; one knot on an axis makes it constant
//! along that axis, and axis 2 with 0 or 1 knot reads the column y_i_1 alone.
//!
//! u_j is signal j, or with `flexible_k_lag_j` = τ > 0 its first-order low-pass
//! τ u̇ = s − u, advanced after each completed step of length h by the exact response to the
//! signal's mean over the step (the trapezoid of its two ends):
//! u ← u + (1 − e^(−h/τ)) ((s_start + s_end)/2 − u). That is exact for a signal constant over
//! the step and second-order accurate in h/τ otherwise; before the first step u is the signal
//! at the state the simulation starts from (its steady state, where the lag has settled).
//!
//! The semantics are the modulation slots': the constant is held over each step at the
//! signals at the step's start (the time signals at mid-step), with what the model derives
//! from it rebuilt, by the same machinery ([`super::modulation`]'s `apply` walks both kinds of
//! slot); the outputs at a communication point read it at that point's signals. Both kinds
//! may be on at once: their increments add.

use super::modulation::{ModulationSignal, Signals, MODULATABLE};
use super::parameters::{variable_name, Parameters};
use crate::variables::{self, number, vr};

/// The slots.
pub const FLEXIBLE_SLOTS: usize = 2;

/// The most knots on an axis of a slot's grid.
pub const MAX_GRID: usize = 5;

/// The plain constants a flexible slot may vary beyond the modulatable ones.
const PLAIN_CONSTANTS: [u32; 3] = [vr::EXTRA_FORCE_OFFSET, vr::EXTRA_INFLOW_1, vr::EXTRA_INFLOW_2];

const TARGET_COUNT: usize = MODULATABLE.len() + PLAIN_CONSTANTS.len();

const TARGET_ARRAY: [u32; TARGET_COUNT] = {
    let mut out = [0u32; TARGET_COUNT];
    let mut k = 0;
    while k < MODULATABLE.len() {
        out[k] = MODULATABLE[k];
        k += 1;
    }
    let mut j = 0;
    while j < PLAIN_CONSTANTS.len() {
        out[k + j] = PLAIN_CONSTANTS[j];
        j += 1;
    }
    out
};

/// The constants a flexible slot may vary, as value references: those of [`MODULATABLE`]
/// and the plain constants `extra_force_offset`, `extra_inflow_1`, `extra_inflow_2` (kept
/// out of [`MODULATABLE`], whose list sets the diagnosis's modulation candidates).
pub const FLEXIBLE_TARGETS: &[u32] = &TARGET_ARRAY;

/// The variables of one slot, in the order of their value references from
/// `flexible_k_parameter`.
pub const SLOT_VARIABLES: usize = 18 + MAX_GRID * MAX_GRID;

const VALUE_REFERENCE_ARRAY: [u32; FLEXIBLE_SLOTS * SLOT_VARIABLES] = {
    let mut out = [0u32; FLEXIBLE_SLOTS * SLOT_VARIABLES];
    let mut k = 0;
    while k < FLEXIBLE_SLOTS {
        let mut j = 0;
        while j < SLOT_VARIABLES {
            out[k * SLOT_VARIABLES + j] = vr::FLEXIBLE_1_PARAMETER + (k as u32) * vr::FLEXIBLE_STRIDE + j as u32;
            j += 1;
        }
        k += 1;
    }
    out
};

/// The value references of every slot's variables, in the table's order.
pub const VALUE_REFERENCES: &[u32] = &VALUE_REFERENCE_ARRAY;

/// One slot's parameters, as the FMU sets them (codes and counts as floats). Index 0 of each
/// pair is axis 1 (signal 1), index 1 axis 2.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlexibleSlot {
    /// The value reference of the constant (0 = off).
    pub parameter: f64,
    /// The two signals' codes ([`ModulationSignal`]; 0 on axis 2: a function of signal 1).
    pub signals: [f64; 2],
    /// Hz, for the sine and the cosine.
    pub frequency: f64,
    /// The low-passes' time constants, s (0 = the signal itself).
    pub lags: [f64; 2],
    /// The knots in use on each axis (0 on axis 1 = off; 0 or 1 on axis 2 = one signal).
    pub knots: [f64; 2],
    /// The knots' signal values on each axis, in the signal's unit.
    pub x: [[f64; MAX_GRID]; 2],
    /// The constant's increments at the nodes: `y[i][j]` at (`x[0][i]`, `x[1][j]`).
    pub y: [[f64; MAX_GRID]; MAX_GRID],
}

impl FlexibleSlot {
    /// A slot of one signal, no lag: the increments `y` at the values `x` of `signal` (as
    /// [`super::modulation::Slot::through`]).
    pub fn through(parameter: u32, signal: ModulationSignal, x: &[f64], y: &[f64]) -> Self {
        let mut s = FlexibleSlot {
            parameter: parameter as f64,
            ..FlexibleSlot::default()
        };
        s.signals[0] = signal.code() as f64;
        let n = x.len().min(y.len()).min(MAX_GRID);
        s.knots[0] = n as f64;
        s.x[0][..n].copy_from_slice(&x[..n]);
        for i in 0..n {
            s.y[i][0] = y[i];
        }
        s
    }

    /// The knots in use on `axis` (0 or 1) as given (0 to [`MAX_GRID`]).
    pub fn knots_on(&self, axis: usize) -> usize {
        if self.knots[axis] >= 1.0 {
            (self.knots[axis] as usize).min(MAX_GRID)
        } else {
            0
        }
    }

    /// The grid's size: knots on axis 1, and on axis 2 at least one (the column y_i_1).
    pub fn grid(&self) -> (usize, usize) {
        (self.knots_on(0), self.knots_on(1).max(1))
    }

    /// Whether the slot varies a constant: one named and a knot in use on axis 1.
    pub fn is_on(&self) -> bool {
        self.parameter != 0.0 && self.knots_on(0) > 0
    }

    /// The constant's value reference (0 when off).
    pub fn constant(&self) -> u32 {
        if self.is_on() {
            self.parameter as u32
        } else {
            0
        }
    }

    /// The signal of `axis` (none for a code that is not one: validation refuses it).
    pub fn signal(&self, axis: usize) -> ModulationSignal {
        ModulationSignal::from_code(self.signals[axis]).unwrap_or(ModulationSignal::None)
    }

    /// Whether `axis` is read (axis 2 only with a second signal and knots to tell its values
    /// apart) and low-passed.
    pub fn lags_on(&self, axis: usize) -> bool {
        self.lags[axis] > 0.0 && (axis == 0 || self.knots_on(1) > 1)
    }

    /// The raw signal of `axis` at `signals`.
    pub fn raw(&self, axis: usize, signals: &Signals) -> f64 {
        self.signal(axis).value(signals, self.frequency)
    }

    /// u of `axis` for slot `k` (0-based): the low-passed signal where the axis lags and
    /// `signals` carry the lag state, the raw signal otherwise.
    pub fn input(&self, k: usize, axis: usize, signals: &Signals) -> f64 {
        match signals.lagged {
            Some(lagged) if self.lags_on(axis) => lagged[k][axis],
            _ => self.raw(axis, signals),
        }
    }

    /// The increment at (u1, u2): along axis 1 in each column in use, then along axis 2
    /// between the columns, each piecewise linear and held beyond its end knots (the
    /// tensor-product hat basis). With one column it is exactly a modulation slot's increment
    /// through the same knots.
    pub fn increment(&self, u1: f64, u2: f64) -> f64 {
        let (n1, n2) = self.grid();
        if n1 == 0 {
            return 0.0;
        }
        let mut columns = [0.0; MAX_GRID];
        for (j, column) in columns.iter_mut().enumerate().take(n2) {
            let mut y = [0.0; MAX_GRID];
            for i in 0..n1 {
                y[i] = self.y[i][j];
            }
            *column = super::modulation::interpolate(&self.x[0][..n1], &y[..n1], u1);
        }
        if n2 == 1 {
            return columns[0];
        }
        super::modulation::interpolate(&self.x[1][..n2], &columns[..n2], u2)
    }

    /// The increment at `signals` for slot `k` (0-based).
    pub fn increment_at(&self, k: usize, signals: &Signals) -> f64 {
        let u2 = if self.grid().1 > 1 {
            self.input(k, 1, signals)
        } else {
            0.0
        };
        self.increment(self.input(k, 0, signals), u2)
    }

    /// The largest |increment| over the grid in use.
    pub fn largest_increment(&self) -> f64 {
        let (n1, n2) = self.grid();
        let mut largest = 0.0_f64;
        for row in &self.y[..n1] {
            for y in &row[..n2] {
                largest = largest.max(y.abs());
            }
        }
        largest
    }

    /// What a message says of the slot's signals at `signals` (slot `k`, 0-based).
    pub fn describe_at(&self, k: usize, signals: &Signals) -> String {
        let mut out = format!(
            "{} = {} {}",
            self.signal(0).name(),
            number(self.input(k, 0, signals)),
            self.signal(0).unit()
        );
        if self.grid().1 > 1 {
            out.push_str(&format!(
                ", {} = {} {}",
                self.signal(1).name(),
                number(self.input(k, 1, signals)),
                self.signal(1).unit()
            ));
        }
        out
    }
}

/// Whether any flexible slot is on.
pub fn any_on(p: &Parameters) -> bool {
    p.flexible.iter().any(FlexibleSlot::is_on)
}

/// Whether a slot that is on low-passes a signal (the simulation then follows its lag state).
pub fn lags_on(p: &Parameters) -> bool {
    p.flexible
        .iter()
        .any(|slot| slot.is_on() && (slot.lags_on(0) || slot.lags_on(1)))
}

/// The lag states at the state the simulation starts from: each slot's raw signals there
/// (0 for a slot that is off).
pub fn initial_lags(p: &Parameters, signals: &Signals) -> [[f64; 2]; FLEXIBLE_SLOTS] {
    let mut u = [[0.0; 2]; FLEXIBLE_SLOTS];
    for (slot, u) in p.flexible.iter().zip(u.iter_mut()) {
        if slot.is_on() {
            *u = [slot.raw(0, signals), slot.raw(1, signals)];
        }
    }
    u
}

/// The lag states after a completed step of `step` seconds between the raw signals `start`
/// and `end`: u ← u + (1 − e^(−h/τ)) ((s_start + s_end)/2 − u) on each axis that lags (see
/// the module's comment); the others keep their values.
pub fn advance_lags(p: &Parameters, lags: &mut [[f64; 2]; FLEXIBLE_SLOTS], step: f64, start: &Signals, end: &Signals) {
    for (slot, u) in p.flexible.iter().zip(lags.iter_mut()) {
        if !slot.is_on() {
            continue;
        }
        for axis in 0..2 {
            if slot.lags_on(axis) {
                let mean = 0.5 * (slot.raw(axis, start) + slot.raw(axis, end));
                // -expm1 keeps the small fraction h/τ of a long lag without cancellation.
                let share = -(-step / slot.lags[axis]).exp_m1();
                u[axis] += share * (mean - u[axis]);
            }
        }
    }
}

/// Whether a slot that is on follows the force F_act on either axis it reads.
pub fn follows_the_force(p: &Parameters) -> bool {
    p.flexible.iter().any(|slot| {
        slot.is_on()
            && (slot.signal(0) == ModulationSignal::Force
                || (slot.grid().1 > 1 && slot.signal(1) == ModulationSignal::Force))
    })
}

/// For the Model Exchange interface, which does not have the slots: an error naming each
/// slot that is on, or Ok.
pub fn refuse_in_model_exchange(p: &Parameters) -> Result<(), String> {
    let on: Vec<String> = (0..FLEXIBLE_SLOTS)
        .filter(|&k| p.flexible[k].is_on())
        .map(|k| {
            format!(
                "flexible_{}_parameter = {} ({})",
                k + 1,
                number(p.flexible[k].parameter),
                variable_name(p.flexible[k].constant())
            )
        })
        .collect();
    if on.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} switches on a flexible slot, which Model Exchange does not have (the constant is held over each communication step at the signals at its start, and a lag follows them from step to step); use the Co-Simulation interface of this FMU for it",
            on.join(", ")
        ))
    }
}

/// The field of a slot variable's value reference.
pub fn field_mut(slots: &mut [FlexibleSlot; FLEXIBLE_SLOTS], value_reference: u32) -> Option<&mut f64> {
    if !(vr::FLEXIBLE_1_PARAMETER..=vr::FLEXIBLE_LAST).contains(&value_reference) {
        return None;
    }
    let offset = value_reference - vr::FLEXIBLE_1_PARAMETER;
    let slot = &mut slots[(offset / vr::FLEXIBLE_STRIDE) as usize];
    let j = (offset % vr::FLEXIBLE_STRIDE) as usize;
    match j {
        0 => Some(&mut slot.parameter),
        1 | 2 => Some(&mut slot.signals[j - 1]),
        3 => Some(&mut slot.frequency),
        4 | 5 => Some(&mut slot.lags[j - 4]),
        6 | 7 => Some(&mut slot.knots[j - 6]),
        8..=17 => Some(&mut slot.x[(j - 8) / MAX_GRID][(j - 8) % MAX_GRID]),
        18..=42 => Some(&mut slot.y[(j - 18) / MAX_GRID][(j - 18) % MAX_GRID]),
        _ => None,
    }
}

fn allowed() -> String {
    FLEXIBLE_TARGETS
        .iter()
        .map(|&r| format!("{} ({r})", variable_name(r)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The codes of slot `n` (1-based): the constant one of [`FLEXIBLE_TARGETS`], the signals
/// and the knot counts whole numbers in range.
fn check_codes(n: usize, slot: &FlexibleSlot) -> Result<(), String> {
    let value = slot.parameter;
    if value != 0.0 && !(value.fract() == 0.0 && FLEXIBLE_TARGETS.contains(&(value as u32))) {
        return Err(format!(
            "flexible_{n}_parameter = {} is invalid: must be 0 (off) or the value reference of a constant a flexible slot may vary: {}",
            number(value),
            allowed()
        ));
    }
    for axis in 0..2 {
        let code = slot.signals[axis];
        if ModulationSignal::from_code(code).is_none() {
            return Err(format!(
                "flexible_{n}_signal_{} = {} is invalid: must be a whole number from 0 to 13 ({})",
                axis + 1,
                number(code),
                ModulationSignal::ALL
                    .iter()
                    .map(|s| format!("{} {} ({})", s.code(), s.name(), s.unit()))
                    .collect::<Vec<_>>()
                    .join(", ")
            ));
        }
    }
    for axis in 0..2 {
        let knots = slot.knots[axis];
        if knots.fract() != 0.0 || !(0.0..=MAX_GRID as f64).contains(&knots) {
            return Err(format!(
                "flexible_{n}_knots_{} = {} is invalid: must be a whole number from 0 to {MAX_GRID}",
                axis + 1,
                number(knots)
            ));
        }
    }
    Ok(())
}

/// The slots' checks (run with [`Parameters::validate`]): the codes whole numbers in range
/// and the constant one of [`FLEXIBLE_TARGETS`]; for a slot that is on, the knots in use on
/// each axis strictly increasing and, at every node of the grid in use, its constant within
/// the constant's limits and the model's constraints between constants met (those of
/// [`Parameters::validate`], with that slot's constant at the node and every other slot off),
/// as the modulation slots are checked at each knot.
pub fn validate(p: &Parameters) -> Result<(), String> {
    for (k, slot) in p.flexible.iter().enumerate() {
        let n = k + 1;
        check_codes(n, slot)?;
        if !slot.is_on() {
            continue;
        }
        let (n1, n2) = slot.grid();
        for axis in 0..2 {
            let used = if axis == 0 { n1 } else { slot.knots_on(1) };
            let unit = slot.signal(axis).unit();
            let x = &slot.x[axis];
            for j in 1..used {
                if x[j] <= x[j - 1] {
                    return Err(format!(
                        "flexible_{n}_x{}_{} = {} {unit} is invalid: must exceed flexible_{n}_x{}_{} = {} {unit} (the knots of axis {} increase)",
                        axis + 1,
                        j + 1,
                        number(x[j]),
                        axis + 1,
                        j,
                        number(x[j - 1]),
                        axis + 1
                    ));
                }
            }
        }
        let constant = slot.constant();
        let name = variable_name(constant);
        let nominal = p.get(constant).expect("a flexible slot's constant is a parameter");
        for i in 0..n1 {
            for j in 0..n2 {
                let value = nominal + slot.y[i][j];
                let at_node = |e: String| {
                    let second = if n2 > 1 {
                        format!(
                            ", {} = {} {}",
                            slot.signal(1).name(),
                            number(slot.x[1][j]),
                            slot.signal(1).unit()
                        )
                    } else {
                        String::new()
                    };
                    format!(
                        "flexible_{n}_y_{}_{} = {} takes {name} from {} to {} at node ({}, {}) ({} = {} {}{second}): {e}",
                        i + 1,
                        j + 1,
                        number(slot.y[i][j]),
                        number(nominal),
                        number(value),
                        i + 1,
                        j + 1,
                        slot.signal(0).name(),
                        number(slot.x[0][i]),
                        slot.signal(0).unit()
                    )
                };
                variables::check(constant, value).map_err(at_node)?;
                if constant == vr::ZETA_2 && nominal < 1.0 && value >= 1.0 {
                    return Err(at_node(
                        "zeta_2 must stay below 1, where the current driver and jet pipe are propagated in the jet pipe's modes".into(),
                    ));
                }
                let mut at = p.clone();
                at.modulation = Default::default();
                at.flexible = [FlexibleSlot::default(); FLEXIBLE_SLOTS];
                at.set(constant, value).map_err(at_node)?;
                at.validate().map_err(at_node)?;
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests;
