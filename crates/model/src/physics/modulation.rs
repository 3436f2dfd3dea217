//! Modulation slots (all off by default): a constant of the parameter table that varies with
//! a signal of the chain. Slot k (k = 1, 2) names the constant by its value reference
//! (`modulation_k_parameter`, one of [`MODULATABLE`]), the signal by a code
//! (`modulation_k_signal`, [`ModulationSignal`]) and up to [`MAX_KNOTS`] knots
//! (`modulation_k_x_j`, `modulation_k_y_j`): the constant is its nominal value plus the
//! piecewise linear interpolation of the increments y at the signal's value, held at the first
//! and last knots' increments beyond them. One knot is a constant increment.
//!
//! Like the constants that vary in time ([`super::time_varying`]), a simulation holds each
//! modulated constant over a step: at the signals at the step's start (the time signals at
//! mid-step, as the time-varying constants are), with what the model derives from it
//! (the valve's discharge factors, the orifices' 1/√T, the chambers' dead volumes, the
//! current driver's and jet pipe's propagator), then restores it. The outputs at a communication point read the constants at
//! that point's signals (the ones the next step holds). A modulation on top of a drift adds to
//! the drifted value.
//!
//! The flexible slots ([`super::flexible`]) are the generalisation of these (two signals, a
//! lag on each): `apply` and `restore` walk both kinds, and every question below of
//! which constants the slots vary asks it of both.
//!
//! The chambers' dead volumes are modulatable as the pressure equations' capacity
//! (`DEAD_VOLUMES`), and the cylinder's bore as the piston's area (`BORE`), which the force and
//! both chambers' volumes read. The stopper's offset L_sup (`PISTON_PLACE`) places the piston:
//! modulated, it moves the piston as the stopper would, and the air in each chamber is carried
//! across each change from one step to the next, P V^γ constant (the simulation keeps the
//! offset the last step held), as it is across a jump of the stopper.

use super::actuator::Actuator;
use super::flexible::{self, FLEXIBLE_SLOTS};
use super::parameters::{variable_name, Parameters};
use crate::variables::{self, number, vr};

/// The slots.
pub const SLOTS: usize = 2;

/// The most knots a slot has.
pub const MAX_KNOTS: usize = 12;

/// The constants a slot may modulate, as value references.
pub const MODULATABLE: &[u32] = &[
    vr::K_CD,
    vr::I_OFFSET,
    vr::OMEGA_CD,
    vr::K_M,
    vr::OMEGA_1,
    vr::OMEGA_2,
    vr::ZETA_2,
    vr::X_JP_OFFSET,
    vr::X_JP_SAT,
    vr::F_JP_SAT,
    vr::D_JP,
    vr::C_D,
    vr::C_DM_A_LPP,
    vr::C_DB_A_LPP,
    vr::SUPPLY_AREA_SCALE_1,
    vr::SUPPLY_AREA_SCALE_2,
    vr::RETURN_AREA_SCALE_1,
    vr::RETURN_AREA_SCALE_2,
    vr::P_S,
    vr::P_R,
    vr::T_GAS,
    vr::DEAD_VOLUME_1,
    vr::DEAD_VOLUME_2,
    vr::D_CYL,
    vr::L_SUP,
    vr::K_SPRING,
    vr::FRICTION_COULOMB,
    vr::VISCOUS_FRICTION,
    vr::FORCE_SENSOR_OFFSET,
    vr::FORCE_SENSOR_GAIN,
    vr::P1_SENSOR_OFFSET,
    vr::P1_SENSOR_GAIN,
    vr::P2_SENSOR_OFFSET,
    vr::P2_SENSOR_GAIN,
    vr::EXTRA_FORCE_PRESSURE_DIFFERENCE,
];

/// Constants one might expect in [`MODULATABLE`] that the model cannot modulate correctly, with
/// the reason (none at present).
pub const NOT_MODULATABLE: &[(u32, &str)] = &[];

/// The cylinder's bore. Modulated, it is the piston's area A_p = π D²/4 at that instant: the
/// force A_p (P1 − P2) reads it, and the chambers' volumes and their rates A_p ẋ_s, as the
/// dead volumes' capacity is read (the pressure continuous across a change; a bore that really
/// widened would add its own dV/dt, which the model does not have: for a drift of 1 % over a
/// minute that term is 3e-4 of the volume a second, 2 dD/D).
const BORE: &[u32] = &[vr::D_CYL];

/// The chambers' dead volumes. Modulated, a dead volume is the capacity of the pressure
/// equations (2.30)–(2.31) at that instant: the pressure is continuous across a change, and the
/// change itself neither compresses nor lets out air (a volume that really moved would need
/// its own dV/dt term, which the model does not have).
const DEAD_VOLUMES: &[u32] = &[vr::DEAD_VOLUME_1, vr::DEAD_VOLUME_2];

/// The stopper's offset L_sup between the stopper and the piston (2.32): modulated, the
/// piston's place, which both chambers' volumes read; a change moves the piston and carries
/// the chambers' air with it ([`moves_the_piston`]).
const PISTON_PLACE: &[u32] = &[vr::L_SUP];

/// The constants the current driver's and jet pipe's propagator is built from.
const ELECTROMECHANICAL: &[u32] = &[
    vr::K_CD,
    vr::I_OFFSET,
    vr::OMEGA_CD,
    vr::K_M,
    vr::OMEGA_1,
    vr::OMEGA_2,
    vr::ZETA_2,
    vr::X_JP_SAT,
    vr::F_JP_SAT,
];

/// The constants of the valve's discharge factors ([`Actuator::discharge`]).
const DISCHARGE: &[u32] = &[
    vr::C_D,
    vr::SUPPLY_AREA_SCALE_1,
    vr::SUPPLY_AREA_SCALE_2,
    vr::RETURN_AREA_SCALE_1,
    vr::RETURN_AREA_SCALE_2,
];

/// The constants that switch on the outputs' general law (friction, the transducers' and the
/// piston's effective-area error).
const OUTPUT_LAW: &[u32] = &[
    vr::FRICTION_COULOMB,
    vr::VISCOUS_FRICTION,
    vr::FORCE_SENSOR_OFFSET,
    vr::FORCE_SENSOR_GAIN,
    vr::P1_SENSOR_OFFSET,
    vr::P1_SENSOR_GAIN,
    vr::P2_SENSOR_OFFSET,
    vr::P2_SENSOR_GAIN,
    vr::EXTRA_FORCE_PRESSURE_DIFFERENCE,
    vr::EXTRA_FORCE_OFFSET,
];

/// The constants the outputs at a communication point read, beyond the states: those of
/// [`OUTPUT_LAW`], the spring and the return pressure (the extra force's pressure terms).
const OUTPUTS: &[u32] = &[
    vr::FRICTION_COULOMB,
    vr::VISCOUS_FRICTION,
    vr::FORCE_SENSOR_OFFSET,
    vr::FORCE_SENSOR_GAIN,
    vr::P1_SENSOR_OFFSET,
    vr::P1_SENSOR_GAIN,
    vr::P2_SENSOR_OFFSET,
    vr::P2_SENSOR_GAIN,
    vr::K_SPRING,
    vr::P_R,
    vr::EXTRA_FORCE_PRESSURE_DIFFERENCE,
    vr::EXTRA_FORCE_OFFSET,
    vr::D_CYL,
];

/// The stopper velocity at which the sign signal, tanh(v / this), is 0.76.
pub const SIGN_VELOCITY: f64 = 1e-3;

/// A signal of the chain a slot follows, by its code (`modulation_k_signal`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModulationSignal {
    None,
    Time,
    Command,
    Current,
    JetPosition,
    StopperPosition,
    StopperVelocity,
    StopperVelocitySign,
    Force,
    P1,
    P2,
    PressureDifference,
    Sine,
    Cosine,
}

impl ModulationSignal {
    /// Every signal, in the order of their codes (0 to 13).
    pub const ALL: [ModulationSignal; 14] = [
        ModulationSignal::None,
        ModulationSignal::Time,
        ModulationSignal::Command,
        ModulationSignal::Current,
        ModulationSignal::JetPosition,
        ModulationSignal::StopperPosition,
        ModulationSignal::StopperVelocity,
        ModulationSignal::StopperVelocitySign,
        ModulationSignal::Force,
        ModulationSignal::P1,
        ModulationSignal::P2,
        ModulationSignal::PressureDifference,
        ModulationSignal::Sine,
        ModulationSignal::Cosine,
    ];

    /// The force or a chamber pressure: what the load on the piston is made of.
    pub fn is_load(self) -> bool {
        matches!(
            self,
            ModulationSignal::Force
                | ModulationSignal::P1
                | ModulationSignal::P2
                | ModulationSignal::PressureDifference
        )
    }

    /// The code `modulation_k_signal` takes for it.
    pub fn code(self) -> u32 {
        ModulationSignal::ALL.iter().position(|&s| s == self).unwrap_or(0) as u32
    }

    /// The signal of a code, if it is one (a whole number from 0 to 13).
    pub fn from_code(code: f64) -> Option<Self> {
        if code.fract() != 0.0 || !(0.0..=13.0).contains(&code) {
            return None;
        }
        Some(ModulationSignal::ALL[code as usize])
    }

    /// Its name, as a reading writes it.
    pub fn name(self) -> &'static str {
        match self {
            ModulationSignal::None => "none",
            ModulationSignal::Time => "t",
            ModulationSignal::Command => "v_DA",
            ModulationSignal::Current => "i",
            ModulationSignal::JetPosition => "x_jp",
            ModulationSignal::StopperPosition => "x_s",
            ModulationSignal::StopperVelocity => "stopper velocity",
            ModulationSignal::StopperVelocitySign => "sign of the stopper velocity",
            ModulationSignal::Force => "F_act",
            ModulationSignal::P1 => "P1",
            ModulationSignal::P2 => "P2",
            ModulationSignal::PressureDifference => "P1 - P2",
            ModulationSignal::Sine => "sin(2 pi f t)",
            ModulationSignal::Cosine => "cos(2 pi f t)",
        }
    }

    /// Its SI unit ("1" for a number).
    pub fn unit(self) -> &'static str {
        match self {
            ModulationSignal::None => "1",
            ModulationSignal::Time => "s",
            ModulationSignal::Command => "V",
            ModulationSignal::Current => "A",
            ModulationSignal::JetPosition | ModulationSignal::StopperPosition => "m",
            ModulationSignal::StopperVelocity => "m/s",
            ModulationSignal::StopperVelocitySign => "1",
            ModulationSignal::Force => "N",
            ModulationSignal::P1 | ModulationSignal::P2 | ModulationSignal::PressureDifference => "Pa",
            ModulationSignal::Sine | ModulationSignal::Cosine => "1",
        }
    }

    /// Whether it is a function of time alone (held at mid-step over a step).
    pub fn of_time(self) -> bool {
        matches!(
            self,
            ModulationSignal::Time | ModulationSignal::Sine | ModulationSignal::Cosine
        )
    }

    /// Its value at `signals`, with `frequency` (Hz) for the sine and cosine.
    pub fn value(self, signals: &Signals, frequency: f64) -> f64 {
        let phase = || 2.0 * std::f64::consts::PI * frequency * signals.time;
        match self {
            ModulationSignal::None => 0.0,
            ModulationSignal::Time => signals.time,
            ModulationSignal::Command => signals.v_da,
            ModulationSignal::Current => signals.current,
            ModulationSignal::JetPosition => signals.x_jp,
            ModulationSignal::StopperPosition => signals.x_s,
            ModulationSignal::StopperVelocity => signals.stopper_velocity,
            ModulationSignal::StopperVelocitySign => (signals.stopper_velocity / SIGN_VELOCITY).tanh(),
            ModulationSignal::Force => signals.f_act,
            ModulationSignal::P1 => signals.p1,
            ModulationSignal::P2 => signals.p2,
            ModulationSignal::PressureDifference => signals.p1 - signals.p2,
            ModulationSignal::Sine => phase().sin(),
            ModulationSignal::Cosine => phase().cos(),
        }
    }
}

/// The signals of the chain at one instant, in SI units. `f_act` is the actuator force with
/// the constants at their nominal values (a friction modulated by the force reads the force
/// without its own modulation: no algebraic loop). `lagged` holds the flexible slots'
/// low-passed signals ([`super::flexible`], per slot and axis) where a simulation follows
/// them; `None` reads the raw signals, as at the steady state a simulation starts from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Signals {
    pub lagged: Option<[[f64; 2]; FLEXIBLE_SLOTS]>,
    pub time: f64,
    pub v_da: f64,
    pub current: f64,
    pub x_jp: f64,
    pub x_s: f64,
    pub stopper_velocity: f64,
    pub f_act: f64,
    pub p1: f64,
    pub p2: f64,
}

/// One slot's parameters, as the FMU sets them (codes and counts as floats).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Slot {
    /// The value reference of the modulated constant (0 = off).
    pub parameter: f64,
    /// The signal's code ([`ModulationSignal`]).
    pub signal: f64,
    /// Hz, for the sine and the cosine.
    pub frequency: f64,
    /// The knots in use (0 to [`MAX_KNOTS`]).
    pub knots: f64,
    /// The knots' signal values, in the signal's unit.
    pub x: [f64; MAX_KNOTS],
    /// The constant's increments at the knots, in the constant's unit.
    pub y: [f64; MAX_KNOTS],
}

impl Slot {
    /// A slot that adds to constant `parameter` the increments `y` at the values `x` of
    /// `signal` (at most [`MAX_KNOTS`] knots).
    pub fn through(parameter: u32, signal: ModulationSignal, x: &[f64], y: &[f64]) -> Self {
        let mut s = Slot {
            parameter: parameter as f64,
            signal: signal.code() as f64,
            ..Slot::default()
        };
        let n = x.len().min(y.len()).min(MAX_KNOTS);
        s.knots = n as f64;
        s.x[..n].copy_from_slice(&x[..n]);
        s.y[..n].copy_from_slice(&y[..n]);
        s
    }

    /// The number of knots in use.
    pub fn len(&self) -> usize {
        if self.knots >= 1.0 {
            (self.knots as usize).min(MAX_KNOTS)
        } else {
            0
        }
    }

    /// Whether no knot is in use.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether the slot modulates a constant: one named and a knot in use.
    pub fn is_on(&self) -> bool {
        self.parameter != 0.0 && !self.is_empty()
    }

    /// The modulated constant's value reference (0 when off).
    pub fn constant(&self) -> u32 {
        if self.is_on() {
            self.parameter as u32
        } else {
            0
        }
    }

    /// The signal (none for a code that is not one: [`Parameters::validate`] refuses it).
    pub fn signal(&self) -> ModulationSignal {
        ModulationSignal::from_code(self.signal).unwrap_or(ModulationSignal::None)
    }

    /// The increment at signal value `s`: linear between knots, held beyond the end ones.
    pub fn increment(&self, s: f64) -> f64 {
        let n = self.len();
        interpolate(&self.x[..n], &self.y[..n], s)
    }

    /// The increment at `signals`.
    pub fn increment_at(&self, signals: &Signals) -> f64 {
        self.increment(self.signal().value(signals, self.frequency))
    }
}

/// The values `y` at the knots `x` (increasing) interpolated at `s`: linear between knots,
/// held at the end values beyond the end knots, `y[0]` for one knot, 0 for none. The law of
/// both kinds of slot (a flexible slot's along each axis), so that a flexible slot of one
/// signal is a modulation slot to the last bit.
pub(crate) fn interpolate(x: &[f64], y: &[f64], s: f64) -> f64 {
    let n = x.len();
    if n == 0 {
        return 0.0;
    }
    if n == 1 || s <= x[0] {
        return y[0];
    }
    if s >= x[n - 1] {
        return y[n - 1];
    }
    let mut k = 0;
    while k + 2 < n && s > x[k + 1] {
        k += 1;
    }
    let (x0, x1, y0, y1) = (x[k], x[k + 1], y[k], y[k + 1]);
    y0 + (s - x0) * (y1 - y0) / (x1 - x0)
}

/// Every slot of both kinds, modulation slots first.
pub const ALL_SLOTS: usize = SLOTS + FLEXIBLE_SLOTS;

/// Whether any slot of either kind is on.
pub fn any_on(p: &Parameters) -> bool {
    p.modulation.iter().any(Slot::is_on) || flexible::any_on(p)
}

/// The constants of the slots that are on, of both kinds (0 for a slot that is off), in the
/// order of [`increments`].
pub(crate) fn constants(p: &Parameters) -> [u32; ALL_SLOTS] {
    let mut out = [0; ALL_SLOTS];
    for (k, slot) in p.modulation.iter().enumerate() {
        out[k] = slot.constant();
    }
    for (k, slot) in p.flexible.iter().enumerate() {
        out[SLOTS + k] = slot.constant();
    }
    out
}

/// Each slot's increment at `signals` (0 for a slot that is off): the modulation slots', then
/// the flexible slots'.
pub(crate) fn increments(p: &Parameters, signals: &Signals) -> [f64; ALL_SLOTS] {
    let mut out = [0.0; ALL_SLOTS];
    for (k, slot) in p.modulation.iter().enumerate() {
        if slot.is_on() {
            out[k] = slot.increment_at(signals);
        }
    }
    for (k, slot) in p.flexible.iter().enumerate() {
        if slot.is_on() {
            out[SLOTS + k] = slot.increment_at(k, signals);
        }
    }
    out
}

/// Each slot's largest |increment| over its knots, in the order of [`increments`].
pub(crate) fn largest_increments(p: &Parameters) -> [f64; ALL_SLOTS] {
    let mut out = [0.0; ALL_SLOTS];
    for (k, slot) in p.modulation.iter().enumerate() {
        out[k] = slot.y[..slot.len()].iter().fold(0.0_f64, |m, y| m.max(y.abs()));
    }
    for (k, slot) in p.flexible.iter().enumerate() {
        out[SLOTS + k] = slot.largest_increment();
    }
    out
}

/// Whether a slot of either kind that is on varies one of `constants`.
fn modulates_any_of(p: &Parameters, constants: &[u32]) -> bool {
    self::constants(p).iter().any(|&c| c != 0 && constants.contains(&c))
}

/// Whether a slot varies the stopper's offset L_sup, so that a change moves the piston and the
/// air in the chambers is carried across it.
pub fn moves_the_piston(p: &Parameters) -> bool {
    modulates_any_of(p, PISTON_PLACE)
}

/// Whether a slot modulates the current driver or the jet pipe (their propagator is then
/// rebuilt for each step).
pub fn modulates_electromechanics(p: &Parameters) -> bool {
    modulates_any_of(p, ELECTROMECHANICAL)
}

/// Whether a slot modulates friction or a transducer's offset or gain: the outputs' general
/// law is then on, as that constant away from its default would put it.
pub fn modulates_output_law(p: &Parameters) -> bool {
    modulates_any_of(p, OUTPUT_LAW)
}

/// Whether a slot modulates a friction: the stopper's motion is then formed at each sample.
pub fn modulates_friction(p: &Parameters) -> bool {
    modulates_any_of(p, &[vr::FRICTION_COULOMB, vr::VISCOUS_FRICTION])
}

/// Whether a slot modulates a coefficient of the extra force's library (the library's terms
/// are then formed even where the coefficient's nominal value is 0).
pub fn modulates_extra_force(p: &Parameters) -> bool {
    modulates_any_of(p, &[vr::EXTRA_FORCE_PRESSURE_DIFFERENCE])
}

/// Whether a slot modulates a chamber's plain extra inflow (the chambers' leaks are then
/// formed even where its nominal value is 0).
pub fn modulates_inflows(p: &Parameters) -> bool {
    modulates_any_of(p, &[vr::EXTRA_INFLOW_1, vr::EXTRA_INFLOW_2])
}

/// Whether a slot modulates a constant the outputs read.
pub fn modulates_outputs(p: &Parameters) -> bool {
    modulates_any_of(p, OUTPUTS)
}

/// Whether a slot of either kind follows the force F_act (the signals then need it).
pub fn follows_the_force(p: &Parameters) -> bool {
    p.modulation
        .iter()
        .any(|slot| slot.is_on() && slot.signal() == ModulationSignal::Force)
        || flexible::follows_the_force(p)
}

/// For the Model Exchange interface, which does not have the slots: an error naming each
/// slot that is on, or Ok.
pub fn refuse_in_model_exchange(p: &Parameters) -> Result<(), String> {
    let on: Vec<String> = (0..SLOTS)
        .filter(|&k| p.modulation[k].is_on())
        .map(|k| {
            format!(
                "modulation_{}_parameter = {} ({})",
                k + 1,
                p.modulation[k].parameter,
                variable_name(p.modulation[k].constant())
            )
        })
        .collect();
    if on.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "{} switches on a modulation slot, which Model Exchange does not have (the constant is held over each communication step at the signals at its start); use the Co-Simulation interface of this FMU for it",
            on.join(", ")
        ))
    }
}

/// The slot (0-based) and the field of a slot's value reference.
pub fn field_mut(slots: &mut [Slot; SLOTS], value_reference: u32) -> Option<&mut f64> {
    if !(vr::MODULATION_1_PARAMETER..=vr::MODULATION_LAST).contains(&value_reference) {
        return None;
    }
    let offset = value_reference - vr::MODULATION_1_PARAMETER;
    let slot = &mut slots[(offset / vr::MODULATION_STRIDE) as usize];
    let j = (offset % vr::MODULATION_STRIDE) as usize;
    match j {
        0 => Some(&mut slot.parameter),
        1 => Some(&mut slot.signal),
        2 => Some(&mut slot.frequency),
        3 => Some(&mut slot.knots),
        4..=15 => Some(&mut slot.x[j - 4]),
        16..=27 => Some(&mut slot.y[j - 16]),
        _ => None,
    }
}

/// The value references of every slot's variables, in the table's order.
pub fn value_references() -> impl Iterator<Item = u32> {
    (0..SLOTS as u32).flat_map(|k| {
        let base = vr::MODULATION_1_PARAMETER + k * vr::MODULATION_STRIDE;
        base..base + 4 + 2 * MAX_KNOTS as u32
    })
}

fn allowed() -> String {
    MODULATABLE
        .iter()
        .map(|&r| format!("{} ({r})", variable_name(r)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The checks of one setting beyond its row's limits: the constant one of [`MODULATABLE`],
/// the signal and the knots whole numbers. `slot` is 1-based, for the message.
fn check_field(slot: usize, field: usize, value: f64) -> Result<(), String> {
    match field {
        0 => {
            if value == 0.0 {
                return Ok(());
            }
            let code = value as u32;
            if value.fract() == 0.0 && MODULATABLE.contains(&code) {
                return Ok(());
            }
            let why = match NOT_MODULATABLE.iter().find(|(r, _)| value.fract() == 0.0 && *r == code) {
                Some((r, reason)) => format!(" ({} is not: {reason})", variable_name(*r)),
                None => String::new(),
            };
            Err(format!(
                "modulation_{slot}_parameter = {} is invalid: must be 0 (off) or the value reference of a modulatable constant{why}: {}",
                number(value),
                allowed()
            ))
        }
        1 if ModulationSignal::from_code(value).is_none() => Err(format!(
            "modulation_{slot}_signal = {} is invalid: must be a whole number from 0 to 13 ({})",
            number(value),
            ModulationSignal::ALL
                .iter()
                .map(|s| format!("{} {} ({})", s.code(), s.name(), s.unit()))
                .collect::<Vec<_>>()
                .join(", ")
        )),
        3 if value.fract() != 0.0 => Err(format!(
            "modulation_{slot}_knots = {} is invalid: must be a whole number from 0 to {MAX_KNOTS}",
            number(value)
        )),
        _ => Ok(()),
    }
}

/// The checks of one slot variable's value beyond its row's limits, as [`validate`] makes them
/// (the constant one of [`MODULATABLE`], the signal and the knots whole numbers). Like the
/// static curves' knot counts, they are not made when a value is set but when the model is
/// built, so that a setter takes any value within the declared limits.
pub fn check_setting(value_reference: u32, value: f64) -> Result<(), String> {
    if !(vr::MODULATION_1_PARAMETER..=vr::MODULATION_LAST).contains(&value_reference) {
        return Ok(());
    }
    let offset = value_reference - vr::MODULATION_1_PARAMETER;
    check_field(
        (offset / vr::MODULATION_STRIDE) as usize + 1,
        (offset % vr::MODULATION_STRIDE) as usize,
        value,
    )
}

/// The slots' checks (run with [`Parameters::validate`]): each setting as
/// [`check_setting`] has it; for a slot that is on, the knots in use strictly increasing and,
/// at every knot, its constant within the constant's limits and the model's constraints
/// between constants met (those of [`Parameters::validate`], with that slot's constant at the
/// knot and the other slot's at its nominal value).
pub fn validate(p: &Parameters) -> Result<(), String> {
    for (k, slot) in p.modulation.iter().enumerate() {
        let n = k + 1;
        check_field(n, 0, slot.parameter)?;
        check_field(n, 1, slot.signal)?;
        check_field(n, 3, slot.knots)?;
        if !slot.is_on() {
            continue;
        }
        let constant = slot.constant();
        let name = variable_name(constant);
        let unit = slot.signal().unit();
        for j in 1..slot.len() {
            if slot.x[j] <= slot.x[j - 1] {
                return Err(format!(
                    "modulation_{n}_x_{} = {} {unit} is invalid: must exceed modulation_{n}_x_{} = {} {unit} (the knots' signal values increase)",
                    j + 1,
                    number(slot.x[j]),
                    j,
                    number(slot.x[j - 1])
                ));
            }
        }
        let nominal = p.get(constant).expect("a modulatable constant is a parameter");
        for j in 0..slot.len() {
            let value = nominal + slot.y[j];
            let at_knot = |e: String| {
                format!(
                    "modulation_{n}_y_{} = {} takes {name} from {} to {} at knot {} ({} = {} {unit}): {e}",
                    j + 1,
                    number(slot.y[j]),
                    number(nominal),
                    number(value),
                    j + 1,
                    slot.signal().name(),
                    number(slot.x[j])
                )
            };
            variables::check(constant, value).map_err(at_knot)?;
            if constant == vr::ZETA_2 && nominal < 1.0 && value >= 1.0 {
                return Err(at_knot(
                    "zeta_2 must stay below 1, where the current driver and jet pipe are propagated in the jet pipe's modes".into(),
                ));
            }
            let mut at = p.clone();
            at.modulation = [Slot::default(); SLOTS];
            at.flexible = Default::default();
            at.set(constant, value).map_err(at_knot)?;
            at.validate().map_err(at_knot)?;
        }
    }
    Ok(())
}

/// What [`apply`] changed, for [`restore`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Held {
    /// The constants' values before, in the order set.
    values: [(u32, f64); ALL_SLOTS],
    count: usize,
    discharge: [f64; 4],
    area_scales: [f64; 4],
    inv_sqrt_temperature: f64,
    dead_volumes: [f64; 2],
    bore_and_area: (f64, f64),
    piston_place: f64,
}

/// Each slot's constant, of both kinds (the modulation slots', then the flexible slots'),
/// set to its value plus the slot's increment at `signals`, with what the model derives from
/// it (the discharge factors, 1/√T, the chambers' dead volumes; the propagator is the
/// simulation's); an error, with the model unchanged, when a constant would leave its limits
/// (a drift adding to a modulation) or the supply fall below the return pressure.
pub(crate) fn apply(model: &mut Actuator, signals: &Signals) -> Result<Held, String> {
    let mut held = Held {
        values: [(0, 0.0); ALL_SLOTS],
        count: 0,
        discharge: model.discharge,
        area_scales: model.area_scales,
        inv_sqrt_temperature: model.flow.inv_sqrt_temperature,
        dead_volumes: [model.cylinder.dead_volume_1, model.cylinder.dead_volume_2],
        bore_and_area: (model.cylinder.d_cyl, model.piston_area),
        piston_place: model.cylinder.l_sup,
    };
    let constants = constants(&model.params);
    let increments = increments(&model.params, signals);
    for k in 0..ALL_SLOTS {
        let constant = constants[k];
        if constant == 0 {
            continue;
        }
        let field = model
            .params
            .field_mut(constant)
            .expect("a slot's constant is a parameter");
        let before = *field;
        let value = before + increments[k];
        held.values[held.count] = (constant, before);
        held.count += 1;
        *field = value;
        let refused = if !value.is_finite() {
            Some(format!(
                "{} = {value} is invalid: must be finite",
                variable_name(constant)
            ))
        } else if [vr::T_GAS, vr::P_S, vr::P_R, vr::D_CYL].contains(&constant) {
            variables::check(constant, value).err()
        } else {
            None
        };
        if let Some(e) = refused {
            restore(model, held);
            let p = &model.params;
            let slot = if k < SLOTS {
                let slot = &p.modulation[k];
                format!(
                    "modulation slot {} at {} = {} {}",
                    k + 1,
                    slot.signal().name(),
                    number(slot.signal().value(signals, slot.frequency)),
                    slot.signal().unit()
                )
            } else {
                let f = k - SLOTS;
                format!("flexible slot {} at {}", f + 1, p.flexible[f].describe_at(f, signals))
            };
            return Err(format!("{slot} (t = {} s): {e}", signals.time));
        }
    }
    let p = &model.params;
    if p.p_s < p.p_r {
        let e = format!(
            "the modulation and flexible slots take P_s to {} Pa and P_r to {} Pa at t = {} s: P_s must stay >= P_r",
            number(p.p_s),
            number(p.p_r),
            signals.time
        );
        restore(model, held);
        return Err(e);
    }
    if modulates_any_of(p, DISCHARGE) {
        model.area_scales = [
            p.supply_area_scale_1,
            p.return_area_scale_1,
            p.supply_area_scale_2,
            p.return_area_scale_2,
        ];
        let c_d = p.c_d;
        model.discharge = model.area_scales.map(|scale| c_d * scale);
    }
    if modulates_any_of(p, &[vr::T_GAS]) {
        model.flow.inv_sqrt_temperature = 1.0 / p.temperature.sqrt();
    }
    if modulates_any_of(p, DEAD_VOLUMES) {
        model.cylinder.dead_volume_1 = p.dead_volume_1;
        model.cylinder.dead_volume_2 = p.dead_volume_2;
    }
    if modulates_any_of(p, BORE) {
        model.cylinder.d_cyl = p.d_cyl;
        model.piston_area = model.cylinder.piston_area();
    }
    if modulates_any_of(p, PISTON_PLACE) {
        model.cylinder.l_sup = p.l_sup;
        if let Err(e) = p.check_stopper(signals.x_s) {
            let e = format!(
                "the slots take L_sup to {} m at t = {} s: {e}",
                number(p.l_sup),
                signals.time
            );
            restore(model, held);
            return Err(e);
        }
    }
    Ok(held)
}

/// Undo [`apply`].
pub(crate) fn restore(model: &mut Actuator, held: Held) {
    for &(constant, before) in held.values[..held.count].iter().rev() {
        *model
            .params
            .field_mut(constant)
            .expect("a slot's constant is a parameter") = before;
    }
    model.discharge = held.discharge;
    model.area_scales = held.area_scales;
    model.flow.inv_sqrt_temperature = held.inv_sqrt_temperature;
    [model.cylinder.dead_volume_1, model.cylinder.dead_volume_2] = held.dead_volumes;
    (model.cylinder.d_cyl, model.piston_area) = held.bore_and_area;
    model.cylinder.l_sup = held.piston_place;
}

/// A copy of `model` with the slots' constants at `signals` (for the outputs and the
/// equilibrium, which do not restore).
pub(crate) fn model_at(model: &Actuator, signals: &Signals) -> Result<Actuator, String> {
    let mut at = model.clone();
    apply(&mut at, signals)?;
    Ok(at)
}

#[cfg(test)]
mod tests;
