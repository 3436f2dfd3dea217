//! Independent synthetic bench: the test oracle for the diagnosis of bench recordings.
//!
//! This module writes recordings in the format of docs/model.md ("CSV formats") following the
//! protocol of `bench/README.md`, from its own implementation of the thesis model (Henri 1994,
//! §2.2–2.7) plus optional physical effects the thesis model lacks. It deliberately shares no
//! code with the model under test (`physics`, `simulation`, `integrator`, `electromechanics`,
//! `fmu`): equations are re-derived from the specification, integrated by classical fixed-step
//! RK4 (20 µs), and every effect uses a form that differs from the obvious one.
//!
//! Forms of the effects (all off by default; with all off the model is the thesis model):
//!
//! * `jet_pipe_hysteresis` (`hysteresis_width`, m): a Bouc–Wen state z (n = 1) driven by the static
//!   jet-pipe position x̄ = f3(k_m i): ż = A ẋ̄ − β |ẋ̄| z − γ ẋ̄ |z| with A = 0.5, β = 0.75/w,
//!   γ = 0.25/w, so that z saturates at ±w/2 after a large sweep; the jet pipe dynamics are
//!   driven by x̄ − z (rising branch w/2 below the midpoint line, falling branch w/2 above it:
//!   full separation w). Minor loops arise by themselves. The history before the recording is a
//!   falling approach (z = −w/2), as when the command goes from 0 V down to the first command.
//! * `piston_friction` (`friction_coulomb` = F_c, N): Stribeck curve on the stopper velocity v,
//!   F_f = [F_c + (F_s − F_c) exp(−(v/v_s)²)] tanh(v/v_ε) + b v with F_s = 1.5 F_c,
//!   v_s = 5 mm/s, v_ε = 0.2 mm/s, b = F_c · 1 s/m; F_act = max(A_p(P1 − P2) − F_f, F_spring).
//!   Zero while the stopper is still.
//! * `dead_volume` (`dead_volume_1`, `dead_volume_2`, m³): a side volume per chamber (lines,
//!   transducer port) joined to the chamber through a short laminar line, ṁ = (P_i − P_di)/R_l,
//!   R_l = γ R T τ_l / V_d with τ_l = 1 ms, so the line fills in about 1 ms and the volume acts as
//!   added volume below ≈ 100 Hz. The side volume follows (2.29) at temperature T.
//! * `supply_pressure_drop` (`supply_resistance` = R_s, Pa·s/kg): a plenum of 2 cm³ (enlarged
//!   automatically only when R_s is so small that RK4 would need it) between P_s and the jet
//!   pipe, fed through a compressible orifice of C_d A = sqrt(ṁ_nom / (ρ_s R_s)),
//!   ṁ_nom = 2.0e-4 kg/s, ρ_s = P_s/(R T); for an incompressible orifice dΔp/dṁ = 2Δp/ṁ, so this
//!   gives dP/dṁ = R_s at ṁ_nom (a drop of R_s ṁ_nom / 2 there). The jet-pipe supply flows are
//!   drawn from the plenum, at the plenum pressure.
//! * `heat_transfer` (α, 0..1): for α > 0 each chamber gets a temperature state and the energy
//!   equation Ṗ = (γ/V)(R Σ ṁ_k T_k,up − P V̇) + P (T_w − T)/(T τ_th),
//!   Ṫ = T (Ṗ/P + V̇/V) − R T² ṁ/(P V), with the wall at 293.15 K and
//!   τ_th = 0.5 ms · 1000^(1−α) / α (α = 1: 0.5 ms, nearly isothermal up to ≈ 100 Hz;
//!   α = 0.5: 32 ms; α = 0.25: 0.36 s). Outflows leave at the chamber temperature, inflows
//!   arrive at the upstream temperature (supply at T). α = 0 is exactly (2.29) at constant T.
//! * `transport_delay` (`command_delay`, s): the current driver sees the D/A output delayed,
//!   the zero-order-hold history evaluated at t − τ (the logged v_da is the undelayed command).
//! * `sensor_offset_gain`: logged force = gain · F_act + offset (before noise and quantisation).
//!
//! Undeclared mechanisms (`BenchEffects::undeclared`, all neutral by default; with all neutral
//! the rows are bit-identical to those of the code before they were added). They test whether
//! the diagnosis places a departure it cannot name at the right `location` along the signal
//! chain and in the right `family`; [`UNDECLARED`] lists each at its standard size. The force
//! effect quoted is the noiseless, unquantised difference from the effect-free run over the
//! whole 80 s protocol (rms / max), as printed by the test
//! `undeclared_force_effects_over_the_protocol`:
//!
//! * `p1_sensor_offset` (`pressure_sensors`/`parameter_offset`, `pressure_sensor_offset_1`,
//!   standard 8 kPa): logged p1 = P1 + offset before noise and quantisation; force and p2 are
//!   bit-identical (force effect 0; p1 shifted by 8 kPa = 53 noise rms).
//! * `supply_drift` (`supply`/`drift`, `supply_drift` = d, standard 30 kPa): the pressure at the
//!   supply source is P_s − d · clamp(t / 80 s, 0, 1); constant before t = 0. With the supply
//!   plenum on it feeds the plenum. Force effect 1.6 N rms / 3.9 N max.
//! * `supply_ripple` (`supply`/`periodic`, `supply_ripple_amplitude` = a,
//!   `supply_ripple_frequency` = f, standard 15 kPa at 7 Hz): source pressure
//!   P_s + a sin(2π f t), for all t including the settling time. Force 1.0 N rms / 3.0 N max.
//! * `command_limit` (`command`/`limit`, `command_limit` = L, standard 7 V): the current driver
//!   sees clamp(v_da, −L, L); the logged v_da is the requested command. Rows are bit-identical
//!   while |v_da| < L. Force 0.66 N rms / 3.4 N max (segments A and B above 7 V).
//! * `current_slew_limit` (`current_driver`/`limit`, `current_slew_limit` = S, standard 3 A/s):
//!   the driver's compliance voltage limits di/dt to ±S: di/dt = clamp(ω_cd (k_cd v + i_0 − i),
//!   −S, S). Statics unchanged; steps (D) and the fast end of the chirp (C) are slewed. (A static
//!   current clamp at ±I would be indistinguishable from `command_limit` at ±I/k_cd with
//!   i_0 = 0, so the current driver's limit is its slew rate.) Force 0.68 N rms / 16 N max.
//! * `jet_pipe_lag` (`jet_pipe`/`dynamics`, `jet_pipe_lag` = τ, standard 15 ms): an extra
//!   first-order lag τ ẋ_L = x̄ − x_L between the static curve f3 (after the hysteresis, if on)
//!   and the jet pipe's first-order/second-order dynamics. Force 0.72 N rms / 8.6 N max.
//! * `chamber_1_leak` (`chambers`/`extra_flow`, `chamber_leak_1` = C_d·A, standard 0.01 mm²):
//!   chamber 1 loses ṁ = orifice(C_d·A, P1 → 101 325 Pa) by the same compressible law as the
//!   ports (outflow at the chamber temperature). Force 1.6 N rms / 3.4 N max.
//! * `viscous_friction` (`mechanics`/`extra_force`, `viscous_friction` = b, standard 60 N·s/m):
//!   F_act = max(A_p(P1 − P2) − F_f − b v, F_spring) with v the stopper velocity (the sign of
//!   `piston_friction`: lower while extending). Bit-identical while the stopper is still
//!   (t < 60 s). Force 1.5 N rms / 5.7 N max.
//! * `contact_compliance` (`mechanics`/`compliance`, `contact_stiffness` = k, standard
//!   2·10⁴ N/m): a spring between stopper and piston; the piston sits δ beyond the stopper with
//!   τ_c δ̇ = F_act/k − δ, τ_c = 0.5 ms (piston mass and seal damping), and the chamber volumes
//!   and their rates use x_s + δ, ẋ_s + δ̇ (the return spring and the friction still use the
//!   stopper). Statics unchanged. Force 1.4 N rms / 6.1 N max.
//! * `force_sensor_lag` (`force_sensor`/`dynamics`, `force_sensor_lag` = τ_F, standard 10 ms):
//!   the logged force is F_L with τ_F Ḟ_L = F_act − F_L, integrated with the plant (then gain
//!   and offset of `sensor_offset_gain`). Pressures bit-identical. Force 0.91 N rms / 6.3 N max.
//! * `return_back_pressure` (`return`/`parameter_offset`, `return_back_pressure`, standard
//!   40 kPa): the ports exhaust into P_r + 40 kPa (a clogged muffler); the chamber 1 leak and
//!   the initial pressures keep the thesis P_r. Force 1.3 N rms / 3.7 N max (p2 6.9 kPa rms).
//! * `p2_sensor_delay` (`pressure_sensors`/`delay`, `pressure_sensor_delay_2`, standard 10 ms,
//!   rounded to whole samples): logged p2 at sample k is P2 at sample k − d (the value at t = 0
//!   before), then noise and quantisation; force and p1 bit-identical (force effect 0).
//! * `receiver_offset` (`jet_pipe`/`parameter_offset`, `receiver_offset`, standard 10 µm): the
//!   port areas are evaluated at x_jp + (x_jp_offset + 10 µm), i.e. the receivers sit further
//!   from the jet pipe null (the static force curve shifts along the command axis). The
//!   offset is the jet pipe's constant x_jp_offset of x_abs = x_jp + x_jp_offset (2.4)–(2.7),
//!   so the chain places it at the jet pipe. Force 1.9 N rms / 3.0 N max.
//! * `force_sensor_backlash` (`force_sensor`/`hysteresis`, `force_sensor_backlash` = w,
//!   standard 1.5 N): the reading passes a play operator of half width r = w/2 at the samples,
//!   y_k = clamp(y_{k−1}, F_k − r, F_k + r), y_0 = F_0 (after the force lag, before gain,
//!   offset, noise and quantisation). Pressures bit-identical. Force 0.71 N rms / 0.75 N max.
//! * `jet_pipe_curve` (`jet_pipe`/`nonlinearity`, `jet_pipe_curve_blend` = β, standard 1):
//!   f3 becomes x_sat [(1 − β) tanh u + β u/√(1 + u²)], u = k_m i / f_sat: the same slope at 0
//!   and the same saturation, a softer knee (the Bouc–Wen drive uses its slope). Force
//!   1.7 N rms / 2.9 N max.
//! * `return_area_reduction` (`valve`/`asymmetry`, `return_area_reduction` = r, standard 0.05):
//!   both return (vent) areas A_r1, A_r2 are multiplied by 1 − r, the supply areas are not
//!   (supply against return, symmetric between the ports; not the shared port 2 example).
//!   Force 1.7 N rms / 2.4 N max.
//! * `port_1_restriction` (`valve`/`restriction`, `port_1_restriction` = C_d·A, standard
//!   0.2 mm², about 40 % of a fully open port): receiver port 1 fills and vents a line of
//!   3 cm³ (at T, (2.29); enlarged only if RK4 at 20 µs would need it) that reaches chamber 1
//!   through an orifice of that C_d·A (same compressible law, inflow to the chamber at T).
//!   Force 2.2 N rms / 6.9 N max.
//!
//! Near equal pressures the orifice law is replaced below Δp = 20 Pa by the secant line through
//! zero and the compressible law's value at 20 Pa (continuous, Lipschitz).

use std::f64::consts::PI;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Effects beyond the thesis model. `Default` switches every effect off.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchEffects {
    /// Full separation (m) of the rising and falling branches of the static jet pipe position.
    pub hysteresis_width: f64,
    /// Coulomb friction level (N) of the piston; stiction 1.5×, see module docs.
    pub friction_coulomb: f64,
    /// Dead volume (m³) joined to chamber 1.
    pub dead_volume_1: f64,
    /// Dead volume (m³) joined to chamber 2.
    pub dead_volume_2: f64,
    /// Supply line resistance (Pa·s/kg), dP/dṁ at the nominal flow 2e-4 kg/s.
    pub supply_resistance: f64,
    /// Heat exchange of the chambers with the wall, 0 (adiabatic, (2.29)) .. 1 (nearly isothermal).
    pub heat_transfer: f64,
    /// Delay (s) of the command seen by the current driver.
    pub command_delay: f64,
    /// Force sensor offset (N).
    pub force_sensor_offset: f64,
    /// Force sensor gain (1 = none).
    pub force_sensor_gain: f64,
    /// Mechanisms the diagnosis does not name (see [`UNDECLARED`]); `Default` switches all off.
    pub undeclared: UndeclaredEffects,
}

/// Mechanisms beyond the seven named effects, for testing where along the signal chain the
/// diagnosis places a departure it cannot name. Every field is neutral at its default (0), and
/// with all neutral the recording is bit-identical to one without them. Forms and standard sizes
/// are in the module docs and in [`UNDECLARED`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UndeclaredEffects {
    /// `pressure_sensors`/`parameter_offset`: offset (Pa) of the chamber 1 pressure transducer.
    pub pressure_sensor_offset_1: f64,
    /// `supply`/`drift`: fall (Pa) of the supply pressure, linear from t = 0 to t = 80 s.
    pub supply_drift: f64,
    /// `supply`/`periodic`: amplitude (Pa) of a supply pressure ripple.
    pub supply_ripple_amplitude: f64,
    /// Frequency (Hz) of the supply ripple.
    pub supply_ripple_frequency: f64,
    /// `command`/`limit`: the D/A output seen by the current driver saturates at ± this (V);
    /// 0 = no limit.
    pub command_limit: f64,
    /// `current_driver`/`limit`: the coil current slews at most this fast (A/s); 0 = no limit.
    pub current_slew_limit: f64,
    /// `jet_pipe`/`dynamics`: time constant (s) of an extra first-order lag between the static
    /// curve f3 and the jet pipe dynamics.
    pub jet_pipe_lag: f64,
    /// `chambers`/`extra_flow`: C_d·A (m²) of a leak from chamber 1 to the atmosphere.
    pub chamber_leak_1: f64,
    /// `mechanics`/`extra_force`: viscous friction coefficient (N·s/m) on the stopper velocity.
    pub viscous_friction: f64,
    /// `mechanics`/`compliance`: stiffness (N/m) between piston and stopper; 0 = rigid.
    pub contact_stiffness: f64,
    /// `force_sensor`/`dynamics`: time constant (s) of a first-order lag of the force sensor.
    pub force_sensor_lag: f64,
    /// `return`/`parameter_offset`: the return (exhaust) pressure is higher by this (Pa).
    pub return_back_pressure: f64,
    /// `pressure_sensors`/`delay`: the chamber 2 pressure is logged this late (s, rounded to
    /// whole 1 ms samples).
    pub pressure_sensor_delay_2: f64,
    /// `valve`/`parameter_offset`: the receivers sit this much (m) further from the jet pipe
    /// null than the thesis offset `x_jp_offset`.
    pub receiver_offset: f64,
    /// `force_sensor`/`hysteresis`: full width (N) of a play (backlash) operator on the force
    /// reading.
    pub force_sensor_backlash: f64,
    /// `jet_pipe`/`nonlinearity`: blend β (0..1) of the static curve f3 towards the algebraic
    /// sigmoid: x̄ = x_sat [(1 − β) tanh u + β u/√(1 + u²)].
    pub jet_pipe_curve_blend: f64,
    /// `valve`/`asymmetry`: fractional reduction of both return (vent) areas, supply areas
    /// unchanged.
    pub return_area_reduction: f64,
    /// `valve`/`restriction`: C_d·A (m²) of an orifice between receiver port 1 and chamber 1,
    /// with a line volume on the receiver side; 0 = none.
    pub port_1_restriction: f64,
}

impl Default for BenchEffects {
    fn default() -> Self {
        Self {
            hysteresis_width: 0.0,
            friction_coulomb: 0.0,
            dead_volume_1: 0.0,
            dead_volume_2: 0.0,
            supply_resistance: 0.0,
            heat_transfer: 0.0,
            command_delay: 0.0,
            force_sensor_offset: 0.0,
            force_sensor_gain: 1.0,
            undeclared: UndeclaredEffects::default(),
        }
    }
}

/// One undeclared mechanism at its standard test size: where along the signal chain it acts
/// (`location`) and what kind of departure it is (`family`), in the vocabulary of the diagnosis.
#[derive(Clone, Copy, Debug)]
pub struct UndeclaredMechanism {
    /// Short identifier (also the value of `benchgen --undeclared`).
    pub name: &'static str,
    /// `command`, `current_driver`, `jet_pipe`, `valve`, `supply`, `return`, `chambers`,
    /// `mechanics`, `force_sensor` or `pressure_sensors`.
    pub location: &'static str,
    /// `parameter_offset`, `drift`, `periodic`, `limit`, `dynamics`, `delay`, `extra_flow`,
    /// `extra_force`, `compliance`, `nonlinearity`, `asymmetry`, `restriction` or `hysteresis`.
    pub family: &'static str,
    /// The truth in one line, with the standard size.
    pub truth: &'static str,
    /// The effects with only this mechanism on, at its standard size.
    pub effects: fn() -> BenchEffects,
    /// The model's (and the FMU's) parameters that are this mechanism at its standard
    /// size, where the model has them; empty where it has no such parameters (then a
    /// diagnosis can place the mechanism but not add it).
    pub model_parameters: &'static [(&'static str, f64)],
}

fn with_undeclared(u: UndeclaredEffects) -> BenchEffects {
    BenchEffects {
        undeclared: u,
        ..Default::default()
    }
}

fn std_p1_sensor_offset() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        pressure_sensor_offset_1: 8000.0,
        ..Default::default()
    })
}
fn std_supply_drift() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        supply_drift: 30_000.0,
        ..Default::default()
    })
}
fn std_supply_ripple() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        supply_ripple_amplitude: 15_000.0,
        supply_ripple_frequency: 7.0,
        ..Default::default()
    })
}
fn std_command_limit() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        command_limit: 7.0,
        ..Default::default()
    })
}
fn std_current_slew_limit() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        current_slew_limit: 3.0,
        ..Default::default()
    })
}
fn std_jet_pipe_lag() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        jet_pipe_lag: 15e-3,
        ..Default::default()
    })
}
fn std_chamber_leak_1() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        chamber_leak_1: 0.01e-6,
        ..Default::default()
    })
}
fn std_viscous_friction() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        viscous_friction: 60.0,
        ..Default::default()
    })
}
fn std_contact_compliance() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        contact_stiffness: 2e4,
        ..Default::default()
    })
}
fn std_return_back_pressure() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        return_back_pressure: 40_000.0,
        ..Default::default()
    })
}
fn std_p2_sensor_delay() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        pressure_sensor_delay_2: 10e-3,
        ..Default::default()
    })
}
fn std_receiver_offset() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        receiver_offset: 10e-6,
        ..Default::default()
    })
}
fn std_force_sensor_backlash() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        force_sensor_backlash: 1.5,
        ..Default::default()
    })
}
fn std_jet_pipe_curve() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        jet_pipe_curve_blend: 1.0,
        ..Default::default()
    })
}
fn std_return_area_reduction() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        return_area_reduction: 0.05,
        ..Default::default()
    })
}
fn std_port_1_restriction() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        port_1_restriction: 0.2e-6,
        ..Default::default()
    })
}
fn std_force_sensor_lag() -> BenchEffects {
    with_undeclared(UndeclaredEffects {
        force_sensor_lag: 10e-3,
        ..Default::default()
    })
}

/// The undeclared mechanisms, each at its standard test size (module docs: forms and the
/// measured noiseless force effect). None is one of the four shared examples (current driver
/// gain, port 2 area asymmetry, vented return, quadratic force sensor). Together they cover
/// all ten locations and all thirteen families (checked by a test).
///
/// ```no_run
/// use synthetic_bench::{generate, undeclared_mechanism, UNDECLARED};
/// for m in UNDECLARED {
///     let rows = generate(&(m.effects)(), 1, 80.0); // 80 s protocol with noise, seed 1
///     println!("{} at {}/{}: {} rows", m.name, m.location, m.family, rows.len());
/// }
/// let leak = (undeclared_mechanism("chamber_1_leak").unwrap().effects)();
/// let _rows = generate(&leak, 7, 80.0);
/// ```
pub const UNDECLARED: &[UndeclaredMechanism] = &[
    UndeclaredMechanism {
        name: "p1_sensor_offset",
        location: "pressure_sensors",
        family: "parameter_offset",
        truth: "the chamber 1 pressure transducer reads 8 kPa high; force and p2 are unaffected",
        effects: std_p1_sensor_offset,
        model_parameters: &[("p1_sensor_offset", 8e3)],
    },
    UndeclaredMechanism {
        name: "supply_drift",
        location: "supply",
        family: "drift",
        truth: "the supply pressure falls linearly by 30 kPa from t = 0 to t = 80 s",
        effects: std_supply_drift,
        model_parameters: &[("supply_drift", -30e3 / 80.0)],
    },
    UndeclaredMechanism {
        name: "supply_ripple",
        location: "supply",
        family: "periodic",
        truth: "the supply pressure carries a 15 kPa, 7 Hz sinusoidal ripple (compressor)",
        effects: std_supply_ripple,
        model_parameters: &[("supply_ripple_sine", 15e3), ("supply_ripple_frequency", 7.0)],
    },
    UndeclaredMechanism {
        name: "command_limit",
        location: "command",
        family: "limit",
        truth: "the D/A output seen by the current driver saturates at ±7 V (logged command is the requested one)",
        effects: std_command_limit,
        model_parameters: &[("command_limit", 7.0)],
    },
    UndeclaredMechanism {
        name: "current_slew_limit",
        location: "current_driver",
        family: "limit",
        truth: "the coil current slews at most 3 A/s (driver voltage headroom)",
        effects: std_current_slew_limit,
        model_parameters: &[("current_slew_limit", 3.0)],
    },
    UndeclaredMechanism {
        name: "jet_pipe_lag",
        location: "jet_pipe",
        family: "dynamics",
        truth: "an extra first-order lag of 15 ms between the static curve f3 and the jet pipe dynamics",
        effects: std_jet_pipe_lag,
        model_parameters: &[],
    },
    UndeclaredMechanism {
        name: "chamber_1_leak",
        location: "chambers",
        family: "extra_flow",
        truth: "chamber 1 leaks to the atmosphere through C_d·A = 0.01 mm² (compressible orifice law)",
        effects: std_chamber_leak_1,
        model_parameters: &[("chamber_vent_1", 0.01e-6)],
    },
    UndeclaredMechanism {
        name: "viscous_friction",
        location: "mechanics",
        family: "extra_force",
        truth: "viscous friction 60 N·s/m on the stopper velocity: force reads F_act − b v",
        effects: std_viscous_friction,
        model_parameters: &[("viscous_friction", 60.0)],
    },
    UndeclaredMechanism {
        name: "contact_compliance",
        location: "mechanics",
        family: "compliance",
        truth: "a 2e4 N/m spring between piston and stopper: the piston, and the volumes, shift by F/k",
        effects: std_contact_compliance,
        model_parameters: &[("stopper_compliance", 1.0 / 2e4)],
    },
    UndeclaredMechanism {
        name: "force_sensor_lag",
        location: "force_sensor",
        family: "dynamics",
        truth: "the force sensor reads through a first-order lag of 10 ms",
        effects: std_force_sensor_lag,
        model_parameters: &[("force_sensor_lag", 0.01)],
    },
    UndeclaredMechanism {
        name: "return_back_pressure",
        location: "return",
        family: "parameter_offset",
        truth: "the return (exhaust) pressure is 40 kPa above the thesis value (clogged exhaust muffler)",
        effects: std_return_back_pressure,
        model_parameters: &[("P_r", 101_325.0 + 40e3)],
    },
    UndeclaredMechanism {
        name: "p2_sensor_delay",
        location: "pressure_sensors",
        family: "delay",
        truth: "the chamber 2 pressure is logged 10 ms late; force and p1 are unaffected",
        effects: std_p2_sensor_delay,
        model_parameters: &[("p2_sensor_delay", 10e-3)],
    },
    UndeclaredMechanism {
        name: "receiver_offset",
        location: "jet_pipe",
        family: "parameter_offset",
        truth: "the receivers sit 10 µm further from the jet pipe null (x_jp_offset 0.099 → 0.109 mm)",
        effects: std_receiver_offset,
        model_parameters: &[("x_jp_offset", 0.109e-3)],
    },
    UndeclaredMechanism {
        name: "force_sensor_backlash",
        location: "force_sensor",
        family: "hysteresis",
        truth: "the force reading passes a play (backlash) operator of full width 1.5 N",
        effects: std_force_sensor_backlash,
        model_parameters: &[("force_sensor_play", 1.5)],
    },
    UndeclaredMechanism {
        name: "jet_pipe_curve",
        location: "jet_pipe",
        family: "nonlinearity",
        truth: "the static jet pipe curve is x_sat u/sqrt(1 + u^2) instead of x_sat tanh u (same slope at 0, same saturation)",
        effects: std_jet_pipe_curve,
        model_parameters: &[("f3_algebraic_share", 1.0)],
    },
    UndeclaredMechanism {
        name: "return_area_reduction",
        location: "valve",
        family: "asymmetry",
        truth: "both return (vent) areas are 5 % smaller, the supply areas unchanged (supply against return)",
        effects: std_return_area_reduction,
        model_parameters: &[("return_area_scale_1", 0.95), ("return_area_scale_2", 0.95)],
    },
    UndeclaredMechanism {
        name: "port_1_restriction",
        location: "valve",
        family: "restriction",
        truth: "receiver port 1 reaches chamber 1 through a 3 cm³ line and an orifice of C_d·A = 0.2 mm²",
        effects: std_port_1_restriction,
        model_parameters: &[("port_restriction_area_1", 0.2e-6), ("port_line_volume_1", 3e-6)],
    },
];

/// The undeclared mechanism of this name, if any.
pub fn undeclared_mechanism(name: &str) -> Option<&'static UndeclaredMechanism> {
    UNDECLARED.iter().find(|m| m.name == name)
}

/// Constants of the thesis model with the defaults of docs/model.md (SI units).
#[derive(Clone, Debug, PartialEq)]
pub struct BenchParams {
    pub p_supply: f64,
    pub p_return: f64,
    pub temperature: f64,
    pub gamma: f64,
    pub r_gas: f64,
    pub k_cd: f64,
    pub i_offset: f64,
    pub omega_cd: f64,
    pub k_m: f64,
    pub omega_1: f64,
    pub omega_2: f64,
    pub zeta_2: f64,
    pub x_jp_sat: f64,
    pub f_jp_sat: f64,
    pub x_jp_offset: f64,
    pub d_jp: f64,
    pub c_d: f64,
    pub c_dm_a_lpp: f64,
    pub c_db_a_lpp: f64,
    pub l_cyl: f64,
    pub l_p: f64,
    pub l_s: f64,
    pub l_sup: f64,
    pub l_spring0: f64,
    pub d_cyl: f64,
    pub k_spring: f64,
}

impl Default for BenchParams {
    fn default() -> Self {
        Self {
            p_supply: 652_925.0,
            p_return: 101_325.0,
            temperature: 293.15,
            gamma: 1.4,
            r_gas: 287.0,
            k_cd: 0.04,
            i_offset: 0.0,
            omega_cd: 7050.0,
            k_m: 1.946,
            omega_1: 973.9,
            omega_2: 1856.7,
            zeta_2: 0.019,
            x_jp_sat: 0.5e-3,
            f_jp_sat: 0.45,
            x_jp_offset: 0.099e-3,
            d_jp: 0.9652e-3,
            c_d: 0.696,
            c_dm_a_lpp: -0.0475e-6,
            c_db_a_lpp: 0.0971e-6,
            l_cyl: 78e-3,
            l_p: 8e-3,
            l_s: 7e-3,
            l_sup: 11e-3,
            l_spring0: 69.1e-3,
            d_cyl: 15.875e-3,
            k_spring: 88.14,
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Geometry: circle overlaps (own closed forms, checked against grid integration in the tests)
// ---------------------------------------------------------------------------------------------

/// Overlap of two circles of equal radius `r` whose centres are `d` apart: r²(θ − sin θ),
/// θ the central angle of the common chord.
fn lens_equal(d: f64, r: f64) -> f64 {
    let d = d.abs();
    if d >= 2.0 * r {
        return 0.0;
    }
    let theta = 2.0 * (d / (2.0 * r)).acos();
    r * r * (theta - theta.sin())
}

/// Overlap of a circle of radius `a` with a circle of radius `b ≥ a`, centres `d` apart: the sum
/// of the two circular segments cut by the common chord, each r²(φ − sin φ cos φ) with φ the
/// half angle seen from its centre.
fn lens_general(d: f64, a: f64, b: f64) -> f64 {
    let d = d.abs();
    if d >= a + b {
        return 0.0;
    }
    if d <= b - a {
        return PI * a * a;
    }
    let ca = ((d * d + a * a - b * b) / (2.0 * d * a)).clamp(-1.0, 1.0);
    let cb = ((d * d + b * b - a * a) / (2.0 * d * b)).clamp(-1.0, 1.0);
    let (pa, pb) = (ca.acos(), cb.acos());
    a * a * (pa - pa.sin() * ca) + b * b * (pb - pb.sin() * cb)
}

/// Supply and return areas of ports 1 and 2 at jet pipe absolute position `x`:
/// (A_s1, A_r1, A_s2, A_r2).
fn port_areas(x: f64, d_jp: f64) -> (f64, f64, f64, f64) {
    let r = 0.5 * d_jp;
    let a_port = PI * r * r;
    let (d1, d2) = (x - d_jp, x + d_jp);
    let a_s1 = lens_equal(d1, r);
    let a_s2 = lens_equal(d2, r);
    let a_r1 = (a_port - lens_general(d1, r, 3.0 * r)).max(0.0);
    let a_r2 = (a_port - lens_general(d2, r, 3.0 * r)).max(0.0);
    (a_s1, a_r1, a_s2, a_r2)
}

// ---------------------------------------------------------------------------------------------
// Model
// ---------------------------------------------------------------------------------------------

const NS: usize = 16;
type State = [f64; NS];
const S_I: usize = 0; // coil current
const S_X1: usize = 1; // output of the first-order jet pipe lag
const S_XJP: usize = 2; // jet pipe position (before offset)
const S_VJP: usize = 3; // its velocity
const S_Z: usize = 4; // Bouc–Wen hysteresis state
const S_P1: usize = 5;
const S_P2: usize = 6;
const S_T1: usize = 7;
const S_T2: usize = 8;
const S_PD1: usize = 9; // dead volume pressures
const S_PD2: usize = 10;
const S_PPL: usize = 11; // supply plenum pressure
const S_XL: usize = 12; // output of the extra jet pipe lag (undeclared)
const S_FF: usize = 13; // force sensor lag output (undeclared)
const S_DEL: usize = 14; // piston-stopper contact deflection (undeclared)
const S_PL1: usize = 15; // port 1 line pressure upstream of the restriction (undeclared)

/// Integration step (s): 50 steps per 1 ms command/log period.
const H: f64 = 20e-6;
const STEPS_PER_SAMPLE: usize = 50;
const SAMPLE: f64 = 1e-3;
/// Below this pressure difference the orifice law is the secant line through zero.
const DP_LIN: f64 = 20.0;
const M_DOT_NOMINAL: f64 = 2.0e-4;
const PLENUM_VOLUME: f64 = 2e-6;
const LINE_TAU: f64 = 1e-3;
const TAU_ISO: f64 = 0.5e-3;
/// Atmosphere into which the undeclared chamber leak vents (Pa).
const P_ATM: f64 = 101_325.0;
/// Line volume between receiver port 1 and the undeclared restriction (m³), enlarged only
/// when RK4 would need it.
const LINE1_VOLUME: f64 = 3e-6;
/// Relaxation time of the piston on its contact compliance (s): mass and seal damping.
const TAU_CONTACT: f64 = 0.5e-3;

struct Model {
    p: BenchParams,
    e: BenchEffects,
    a_p: f64,
    l_dead: f64, // L_p + L_s + L_sup
    r_crit: f64,
    c1: f64,
    c2: f64,
    inv_gamma: f64,
    // effects
    hyst: bool,
    bw_a: f64,
    bw_beta: f64,
    bw_gamma: f64,
    heat: bool,
    inv_tau_th: f64,
    dead1: bool,
    dead2: bool,
    g_line1: f64, // 1/R_line
    g_line2: f64,
    supply: bool,
    cda_supply: f64,
    v_plenum: f64,
    // undeclared mechanisms
    cmd_limit: bool,
    slew: bool,
    jp_lag: bool,
    leak1: bool,
    viscous: bool,
    contact: bool,
    f_lag: bool,
    ret_bp: bool,
    rcv_off: bool,
    blend: bool,
    ret_area: bool,
    line1: bool,
    v_line1: f64,
}

impl Model {
    fn new(p: &BenchParams, e: &BenchEffects) -> Self {
        let g = p.gamma;
        let rt = p.r_gas * p.temperature;
        let a_p = PI * p.d_cyl * p.d_cyl / 4.0;
        let w = e.hysteresis_width;
        let hyst = w > 0.0;
        let heat = e.heat_transfer > 0.0;
        let alpha = e.heat_transfer.clamp(0.0, 1.0);
        let inv_tau_th = if heat {
            alpha / (TAU_ISO * 1000f64.powf(1.0 - alpha))
        } else {
            0.0
        };
        let dead1 = e.dead_volume_1 > 0.0;
        let dead2 = e.dead_volume_2 > 0.0;
        let g_line = |v: f64| if v > 0.0 { v / (g * rt * LINE_TAU) } else { 0.0 };
        let supply = e.supply_resistance > 0.0;
        let rho_s = p.p_supply / rt;
        let cda_supply = if supply {
            (M_DOT_NOMINAL / (rho_s * e.supply_resistance)).sqrt()
        } else {
            0.0
        };
        // Plenum: 2 cm³, or larger if the linear-zone conductances would make RK4 marginal.
        let rho_max = p.p_supply.max(p.p_return) / rt;
        let slope = |cda: f64| cda * (2.0 * rho_max / DP_LIN).sqrt();
        let port_max = p.c_d * PI * p.d_jp * p.d_jp / 4.0;
        let v_needed = g * rt * H * (slope(cda_supply) + 2.0 * slope(port_max)) / 1.0;
        let v_plenum = PLENUM_VOLUME.max(v_needed);
        let cda_line1 = e.undeclared.port_1_restriction.max(0.0);
        let v_line1 = LINE1_VOLUME.max(g * rt * H * (slope(cda_line1) + 2.0 * slope(port_max)));
        Self {
            p: p.clone(),
            e: e.clone(),
            a_p,
            l_dead: p.l_p + p.l_s + p.l_sup,
            r_crit: (2.0 / (g + 1.0)).powf(g / (g - 1.0)),
            c1: (g / p.r_gas * (2.0 / (g + 1.0)).powf((g + 1.0) / (g - 1.0))).sqrt(),
            c2: (g / p.r_gas * (2.0 / (g - 1.0))).sqrt(),
            inv_gamma: 1.0 / g,
            hyst,
            bw_a: 0.5,
            bw_beta: if hyst { 0.75 / w } else { 0.0 },
            bw_gamma: if hyst { 0.25 / w } else { 0.0 },
            heat,
            inv_tau_th,
            dead1,
            dead2,
            g_line1: g_line(e.dead_volume_1),
            g_line2: g_line(e.dead_volume_2),
            supply,
            cda_supply,
            v_plenum,
            cmd_limit: e.undeclared.command_limit > 0.0,
            slew: e.undeclared.current_slew_limit > 0.0,
            jp_lag: e.undeclared.jet_pipe_lag > 0.0,
            leak1: e.undeclared.chamber_leak_1 > 0.0,
            viscous: e.undeclared.viscous_friction > 0.0,
            contact: e.undeclared.contact_stiffness > 0.0,
            f_lag: e.undeclared.force_sensor_lag > 0.0,
            ret_bp: e.undeclared.return_back_pressure != 0.0,
            rcv_off: e.undeclared.receiver_offset != 0.0,
            blend: e.undeclared.jet_pipe_curve_blend != 0.0,
            ret_area: e.undeclared.return_area_reduction != 0.0,
            line1: e.undeclared.port_1_restriction > 0.0,
            v_line1,
        }
    }

    /// Command as the current driver sees it (after the undeclared D/A limit).
    #[inline]
    fn driver_input(&self, v: f64) -> f64 {
        if self.cmd_limit {
            let l = self.e.undeclared.command_limit;
            v.clamp(-l, l)
        } else {
            v
        }
    }

    /// Compressible orifice flow (2.18)–(2.22) from `pu` to `pd` (pu > pd), ≥ 0.
    #[inline]
    fn flow_down(&self, cda: f64, pu: f64, tu: f64, pd: f64) -> f64 {
        let r = pd / pu;
        let k = cda * pu / tu.sqrt();
        if r <= self.r_crit {
            k * self.c1
        } else {
            // r^(2/γ) − r^((γ+1)/γ) = a (a − r), a = r^(1/γ)
            let a = r.powf(self.inv_gamma);
            k * self.c2 * (a * (a - r)).max(0.0).sqrt()
        }
    }

    /// Signed mass flow from side a to side b through C_d·A = `cda`, regularised near Δp = 0.
    #[inline]
    fn orifice(&self, cda: f64, pa: f64, ta: f64, pb: f64, tb: f64) -> f64 {
        if cda <= 0.0 {
            return 0.0;
        }
        let (pu, tu, pd, s) = if pa >= pb {
            (pa, ta, pb, 1.0)
        } else {
            (pb, tb, pa, -1.0)
        };
        let dp = pu - pd;
        if dp >= DP_LIN {
            s * self.flow_down(cda, pu, tu, pd)
        } else {
            s * self.flow_down(cda, pu, tu, pu - DP_LIN) * (dp / DP_LIN)
        }
    }

    fn volumes(&self, xs: f64) -> (f64, f64) {
        let xp = xs - self.l_dead;
        let v1 = self.a_p * xp + 0.0;
        let v2 = self.a_p * (self.p.l_cyl - xp - self.p.l_p);
        (v1, v2)
    }

    fn static_position(&self, i: f64) -> f64 {
        if self.blend {
            let u = self.p.k_m * i / self.p.f_jp_sat;
            let b = self.e.undeclared.jet_pipe_curve_blend;
            return self.p.x_jp_sat * ((1.0 - b) * u.tanh() + b * u / (1.0 + u * u).sqrt());
        }
        self.p.x_jp_sat * (self.p.k_m * i / self.p.f_jp_sat).tanh()
    }

    fn spring_force(&self, xs: f64) -> f64 {
        self.p.k_spring * (self.p.l_spring0 - (xs - self.p.l_s - self.p.l_p))
    }

    fn friction(&self, v: f64) -> f64 {
        let fc = self.e.friction_coulomb;
        if fc <= 0.0 {
            return 0.0;
        }
        let fs = 1.5 * fc;
        let (v_s, v_eps, b) = (5e-3, 0.2e-3, fc * 1.0);
        (fc + (fs - fc) * (-(v / v_s) * (v / v_s)).exp()) * (v / v_eps).tanh() + b * v
    }

    /// True actuator force (2.36)–(2.38) with friction.
    fn force(&self, y: &State, xs: f64, xs_dot: f64) -> f64 {
        let mut fp = self.a_p * (y[S_P1] - y[S_P2]) - self.friction(xs_dot);
        if self.viscous {
            fp -= self.e.undeclared.viscous_friction * xs_dot;
        }
        fp.max(self.spring_force(xs))
    }

    /// Time derivatives.
    /// `p_src` is the supply pressure at the source (the thesis constant unless an undeclared
    /// supply drift or ripple is on).
    fn rhs(&self, y: &State, v_cmd: f64, xs: f64, xs_dot: f64, p_src: f64, dy: &mut State) {
        let p = &self.p;
        let t0 = p.temperature;
        let rt = p.r_gas * t0;
        // current driver (2.1)–(2.3)
        let i = y[S_I];
        let v_cmd = self.driver_input(v_cmd);
        let mut di = p.omega_cd * (p.k_cd * v_cmd + p.i_offset - i);
        if self.slew {
            let s = self.e.undeclared.current_slew_limit;
            di = di.clamp(-s, s);
        }
        dy[S_I] = di;
        // static jet pipe curve f3 and hysteresis
        let u = p.k_m * i / p.f_jp_sat;
        let th = u.tanh();
        let mut xbar = p.x_jp_sat * th;
        // slope dx̄/du / x_sat
        let mut slope = 1.0 - th * th;
        if self.blend {
            // undeclared: static curve blended towards the algebraic sigmoid
            let b = self.e.undeclared.jet_pipe_curve_blend;
            let q = 1.0 / (1.0 + u * u).sqrt();
            xbar = p.x_jp_sat * ((1.0 - b) * th + b * u * q);
            slope = (1.0 - b) * slope + b * q * q * q;
        }
        let mut target = xbar;
        if self.hyst {
            let xbar_dot = p.x_jp_sat * slope * p.k_m * di / p.f_jp_sat;
            let z = y[S_Z];
            dy[S_Z] = self.bw_a * xbar_dot - self.bw_beta * xbar_dot.abs() * z - self.bw_gamma * xbar_dot * z.abs();
            target -= z;
        } else {
            dy[S_Z] = 0.0;
        }
        // undeclared extra lag between f3 and the jet pipe dynamics
        if self.jp_lag {
            dy[S_XL] = (target - y[S_XL]) / self.e.undeclared.jet_pipe_lag;
            target = y[S_XL];
        } else {
            dy[S_XL] = 0.0;
        }
        // jet pipe: first-order lag then second-order mode, unity DC gain
        dy[S_X1] = p.omega_1 * (target - y[S_X1]);
        dy[S_XJP] = y[S_VJP];
        dy[S_VJP] = p.omega_2 * p.omega_2 * (y[S_X1] - y[S_XJP]) - 2.0 * p.zeta_2 * p.omega_2 * y[S_VJP];
        // orifice areas
        let x_abs = if self.rcv_off {
            y[S_XJP] + (p.x_jp_offset + self.e.undeclared.receiver_offset)
        } else {
            y[S_XJP] + p.x_jp_offset
        };
        let (a_s1, mut a_r1, a_s2, mut a_r2) = port_areas(x_abs, p.d_jp);
        if self.ret_area {
            let f = 1.0 - self.e.undeclared.return_area_reduction;
            a_r1 *= f;
            a_r2 *= f;
        }
        let (p1, p2) = (y[S_P1], y[S_P2]);
        let (t1, t2) = if self.heat { (y[S_T1], y[S_T2]) } else { (t0, t0) };
        let ps = if self.supply { y[S_PPL] } else { p_src };
        let pr = if self.ret_bp {
            p.p_return + self.e.undeclared.return_back_pressure
        } else {
            p.p_return
        };
        // with the undeclared port 1 restriction, port 1 feeds a line at temperature T
        let (p1v, t1v) = if self.line1 { (y[S_PL1], t0) } else { (p1, t1) };
        let m_s1 = self.orifice(p.c_d * a_s1, ps, t0, p1v, t1v);
        let m_r1 = self.orifice(p.c_d * a_r1, p1v, t1v, pr, t0);
        // line → chamber 1 through the restriction
        let m_ln = if self.line1 {
            let m = self.orifice(self.e.undeclared.port_1_restriction, p1v, t0, p1, t1);
            dy[S_PL1] = p.gamma * rt * (m_s1 - m_r1 - m) / self.v_line1;
            m
        } else {
            dy[S_PL1] = 0.0;
            0.0
        };
        let m_s2 = self.orifice(p.c_d * a_s2, ps, t0, p2, t2);
        let m_r2 = self.orifice(p.c_d * a_r2, p2, t2, pr, t0);
        // leakage past the piston (2.23), positive 1 → 2
        let (pu, pd) = if p1 >= p2 { (p1, p2) } else { (p2, p1) };
        let cda_l = (p.c_dm_a_lpp * (pd / pu) + p.c_db_a_lpp).max(0.0);
        let m_l = self.orifice(cda_l, p1, t1, p2, t2);
        // dead volumes (side branches), positive chamber → branch
        let m_d1 = if self.dead1 {
            (p1 - y[S_PD1]) * self.g_line1
        } else {
            0.0
        };
        let m_d2 = if self.dead2 {
            (p2 - y[S_PD2]) * self.g_line2
        } else {
            0.0
        };
        dy[S_PD1] = if self.dead1 {
            p.gamma * rt * m_d1 / self.e.dead_volume_1
        } else {
            0.0
        };
        dy[S_PD2] = if self.dead2 {
            p.gamma * rt * m_d2 / self.e.dead_volume_2
        } else {
            0.0
        };
        // supply plenum
        if self.supply {
            let m_in = self.orifice(self.cda_supply, p_src, t0, ps, t0);
            dy[S_PPL] = p.gamma * rt * (m_in - m_s1 - m_s2) / self.v_plenum;
        } else {
            dy[S_PPL] = 0.0;
        }
        // undeclared leak of chamber 1 to the atmosphere, positive outwards
        let m_a1 = if self.leak1 {
            self.orifice(self.e.undeclared.chamber_leak_1, p1, t1, P_ATM, t0)
        } else {
            0.0
        };
        // undeclared compliance between piston and stopper: the piston sits δ beyond the
        // stopper, δ relaxing to F/k
        let (x_pist, x_pist_dot) = if self.contact {
            let f = self.force(y, xs, xs_dot);
            let dd = (f / self.e.undeclared.contact_stiffness - y[S_DEL]) / TAU_CONTACT;
            dy[S_DEL] = dd;
            (xs + y[S_DEL], xs_dot + dd)
        } else {
            dy[S_DEL] = 0.0;
            (xs, xs_dot)
        };
        // undeclared force sensor lag
        dy[S_FF] = if self.f_lag {
            (self.force(y, xs, xs_dot) - y[S_FF]) / self.e.undeclared.force_sensor_lag
        } else {
            0.0
        };
        // chambers
        let (v1, v2) = self.volumes(x_pist);
        let (dv1, dv2) = (self.a_p * x_pist_dot, -self.a_p * x_pist_dot);
        let mut m1 = if self.line1 {
            m_ln - m_l - m_d1
        } else {
            m_s1 - m_r1 - m_l - m_d1
        };
        if self.leak1 {
            m1 -= m_a1;
        }
        let m2 = m_s2 - m_r2 + m_l - m_d2;
        if !self.heat {
            dy[S_P1] = p.gamma / v1 * (rt * m1 - p1 * dv1);
            dy[S_P2] = p.gamma / v2 * (rt * m2 - p2 * dv2);
            dy[S_T1] = 0.0;
            dy[S_T2] = 0.0;
        } else {
            // enthalpy flux Σ ṁ_k T_k,up (inflows at their source temperature, outflows at T_i)
            let up = |m: f64, t_src: f64, t_own: f64| if m > 0.0 { m * t_src } else { m * t_own };
            let mut h1 = if self.line1 {
                up(m_ln, t0, t1) + up(-m_l, t2, t1) + up(-m_d1, t0, t1)
            } else {
                up(m_s1, t0, t1) + up(-m_r1, t0, t1) + up(-m_l, t2, t1) + up(-m_d1, t0, t1)
            };
            if self.leak1 {
                h1 += up(-m_a1, t0, t1);
            }
            let h2 = up(m_s2, t0, t2) + up(-m_r2, t0, t2) + up(m_l, t1, t2) + up(-m_d2, t0, t2);
            let chamber = |pc: f64, tc: f64, v: f64, dv: f64, m: f64, h: f64| {
                let dp = p.gamma / v * (p.r_gas * h - pc * dv) + pc * (t0 - tc) / tc * self.inv_tau_th;
                let dt = tc * (dp / pc + dv / v) - p.r_gas * tc * tc * m / (pc * v);
                (dp, dt)
            };
            let (dp1, dt1) = chamber(p1, t1, v1, dv1, m1, h1);
            let (dp2, dt2) = chamber(p2, t2, v2, dv2, m2, h2);
            dy[S_P1] = dp1;
            dy[S_P2] = dp2;
            dy[S_T1] = dt1;
            dy[S_T2] = dt2;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Protocol (bench/README.md)
// ---------------------------------------------------------------------------------------------

/// Length of the bench protocol (s).
pub const PROTOCOL_DURATION: f64 = 80.0;
/// Stopper position outside segment E (m).
pub const STOPPER_HOME: f64 = 0.054;

fn piecewise_linear(t: f64, pts: &[(f64, f64)]) -> f64 {
    if t <= pts[0].0 {
        return pts[0].1;
    }
    for w in pts.windows(2) {
        let ((t0, v0), (t1, v1)) = (w[0], w[1]);
        if t <= t1 {
            return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
        }
    }
    pts[pts.len() - 1].1
}

/// The commanded voltage of the protocol at time `t` (before D/A quantisation).
pub fn protocol_command(t: f64) -> f64 {
    if t < 20.0 {
        // A: triangle −4 → 10 → −4 V at 1.4 V/s
        let tt = t.max(0.0);
        if tt <= 10.0 {
            -4.0 + 1.4 * tt
        } else {
            10.0 - 1.4 * (tt - 10.0)
        }
    } else if t < 35.0 {
        piecewise_linear(
            t,
            &[
                (20.0, -4.0),
                (23.0, 6.0),
                (25.0, 2.0),
                (28.0, 8.0),
                (30.0, 4.0),
                (33.0, 10.0),
                (35.0, 2.5),
            ],
        )
    } else if t < 50.0 {
        // C: logarithmic chirp 0.2 → 30 Hz over 15 s around 2.5 V, amplitude 1 V
        let (f0, f1, tc) = (0.2, 30.0, 15.0);
        let k: f64 = f1 / f0;
        let tau = t - 35.0;
        let phase = 2.0 * PI * f0 * tc / k.ln() * (k.powf(tau / tc) - 1.0);
        2.5 + phase.sin()
    } else if t < 60.0 {
        const STEPS: [f64; 5] = [1.0, 4.0, 2.0, 6.0, 1.0];
        STEPS[(((t - 50.0) / 2.0).floor() as usize).min(4)]
    } else {
        2.5
    }
}

/// Stopper position (m) and velocity (m/s) of the protocol at time `t`.
pub fn protocol_stopper(t: f64) -> (f64, f64) {
    let a = 0.010;
    if t < 60.0 {
        (STOPPER_HOME, 0.0)
    } else if t < 70.0 {
        let w = 2.0 * PI * 0.5;
        (
            STOPPER_HOME + a * (w * (t - 60.0)).sin(),
            a * w * (w * (t - 60.0)).cos(),
        )
    } else {
        let w = 2.0 * PI * 1.5;
        (
            STOPPER_HOME + a * (w * (t - 70.0)).sin(),
            a * w * (w * (t - 70.0)).cos(),
        )
    }
}

/// 12-bit D/A over ±10 V.
pub fn quantise_da(v: f64) -> f64 {
    let lsb = 20.0 / 4096.0;
    let code = ((v + 10.0) / lsb).round().clamp(0.0, 4095.0);
    -10.0 + code * lsb
}

fn quantise_force(f: f64) -> f64 {
    let lsb = 1000.0 / 65536.0;
    let code = ((f + 500.0) / lsb).round().clamp(0.0, 65535.0);
    -500.0 + code * lsb
}

fn quantise_pressure(p: f64) -> f64 {
    let lsb = 1.0e6 / 65536.0;
    (p / lsb).round().clamp(0.0, 65535.0) * lsb
}

fn quantise_stopper(x: f64) -> f64 {
    (x * 1e6).round() * 1e-6
}

// ---------------------------------------------------------------------------------------------
// Noise: splitmix64-seeded xorshift64* with Box–Muller
// ---------------------------------------------------------------------------------------------

struct Rng {
    s: u64,
    spare: Option<f64>,
}

impl Rng {
    fn new(seed: u64) -> Self {
        let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        Self {
            s: if z == 0 { 0x2545_F491_4F6C_DD1D } else { z },
            spare: None,
        }
    }
    fn next_u64(&mut self) -> u64 {
        let mut x = self.s;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.s = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// Uniform in (0, 1).
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = 2.0 * PI * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

// ---------------------------------------------------------------------------------------------
// Simulation
// ---------------------------------------------------------------------------------------------

/// Options of a run (the public [`generate`] uses the bench values).
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Sensor noise (force 0.05 N rms, pressures 150 Pa rms); `None` for noiseless runs.
    pub noise_seed: Option<u64>,
    /// Quantise the logged signals like the bench A/Ds.
    pub quantise: bool,
    /// Simulated time before t = 0 at the first command (s): settling plus the 3 s hold.
    pub pre_time: f64,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            noise_seed: None,
            quantise: true,
            pre_time: 8.0,
        }
    }
}

/// Run a recording of `n_samples` rows at 1 kHz. `command(t)` gives the un-quantised command at
/// the sample instants (it is D/A-quantised and held for 1 ms); `stopper(t)` the stopper position
/// and velocity at any time. Before t = 0 the first command and stopper position are held.
pub fn simulate<C, S>(
    params: &BenchParams,
    effects: &BenchEffects,
    command: C,
    stopper: S,
    n_samples: usize,
    opts: &RunOptions,
) -> Vec<[f64; 6]>
where
    C: Fn(f64) -> f64,
    S: Fn(f64) -> (f64, f64),
{
    let m = Model::new(params, effects);
    let cmds: Vec<f64> = (0..n_samples.max(1))
        .map(|k| quantise_da(command(k as f64 * SAMPLE)))
        .collect();
    let delay = effects.command_delay.max(0.0);
    let cmd_at = |t: f64| -> f64 {
        let te = t - delay;
        if te < 0.0 {
            return cmds[0];
        }
        let k = (te / SAMPLE).floor() as usize;
        cmds[k.min(cmds.len() - 1)]
    };
    let stop_at = |t: f64| if t < 0.0 { stopper(0.0).0 } else { stopper(t).0 };
    let stopv_at = |t: f64| if t < 0.0 { 0.0 } else { stopper(t).1 };
    // supply pressure at the source: the thesis constant unless drift or ripple is on
    let und = &effects.undeclared;
    let supply_varies = und.supply_drift != 0.0 || und.supply_ripple_amplitude != 0.0;
    let w_ripple = 2.0 * PI * und.supply_ripple_frequency;
    let psrc_at = |t: f64| {
        if supply_varies {
            params.p_supply - und.supply_drift * (t / PROTOCOL_DURATION).clamp(0.0, 1.0)
                + und.supply_ripple_amplitude * (w_ripple * t).sin()
        } else {
            params.p_supply
        }
    };

    // initial state at the first command: static jet pipe, pressures at mid values
    let mut y: State = [0.0; NS];
    let i0 = params.k_cd * m.driver_input(cmds[0]) + params.i_offset;
    y[S_I] = i0;
    if m.hyst {
        y[S_Z] = -0.5 * effects.hysteresis_width; // falling approach
    }
    let x0 = m.static_position(i0) - y[S_Z];
    y[S_X1] = x0;
    y[S_XJP] = x0;
    y[S_XL] = x0;
    let pm = 0.5 * (params.p_supply + params.p_return);
    y[S_P1] = pm;
    y[S_P2] = pm;
    y[S_T1] = params.temperature;
    y[S_T2] = params.temperature;
    y[S_PD1] = pm;
    y[S_PD2] = pm;
    y[S_PPL] = params.p_supply;
    y[S_DEL] = 0.0;
    y[S_PL1] = pm;
    if m.contact {
        // δ = F/k at the start (the force does not depend on δ)
        y[S_DEL] = m.force(&y, stop_at(0.0), 0.0) / und.contact_stiffness;
    }
    y[S_FF] = m.force(&y, stop_at(0.0), 0.0);

    let pre_steps = (opts.pre_time / H).round() as i64;
    let mut step: i64 = -pre_steps;
    let mut k1 = [0.0; NS];
    let mut k2 = [0.0; NS];
    let mut k3 = [0.0; NS];
    let mut k4 = [0.0; NS];
    let mut tmp = [0.0; NS];
    let eps = 1e-6 * H;
    let mut do_step = |y: &mut State, n: i64| {
        let t_lo = n as f64 * H;
        let t_hi = (n + 1) as f64 * H;
        // inputs evaluated inside the step (left/right limits at its ends)
        let inp = |t: f64| {
            let te = t.clamp(t_lo + eps, t_hi - eps);
            (cmd_at(te), stop_at(te), stopv_at(te), psrc_at(te))
        };
        let (v, xs, xd, ps) = inp(t_lo);
        m.rhs(y, v, xs, xd, ps, &mut k1);
        let (v, xs, xd, ps) = inp(t_lo + 0.5 * H);
        for j in 0..NS {
            tmp[j] = y[j] + 0.5 * H * k1[j];
        }
        m.rhs(&tmp, v, xs, xd, ps, &mut k2);
        for j in 0..NS {
            tmp[j] = y[j] + 0.5 * H * k2[j];
        }
        m.rhs(&tmp, v, xs, xd, ps, &mut k3);
        let (v, xs, xd, ps) = inp(t_hi);
        for j in 0..NS {
            tmp[j] = y[j] + H * k3[j];
        }
        m.rhs(&tmp, v, xs, xd, ps, &mut k4);
        for j in 0..NS {
            y[j] += H / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
    };
    while step < 0 {
        do_step(&mut y, step);
        step += 1;
    }

    let mut rng = opts.noise_seed.map(Rng::new);
    let mut rows = Vec::with_capacity(n_samples);
    // undeclared p2 transducer delay, whole samples; before t = 0 the plant is at rest
    let p2_delay = (und.pressure_sensor_delay_2.max(0.0) / SAMPLE).round() as usize;
    let mut p2_hist: Vec<f64> = Vec::new();
    // undeclared force sensor play operator, half width r, starting centred
    let play_r = 0.5 * und.force_sensor_backlash.max(0.0);
    let mut play_y: Option<f64> = None;
    for (k, &cmd) in cmds.iter().enumerate().take(n_samples) {
        let t = k as f64 * SAMPLE;
        let (xs, xd) = stopper(t);
        let mut f_true = if m.f_lag { y[S_FF] } else { m.force(&y, xs, xd) };
        if play_r > 0.0 {
            let yp = play_y.map_or(f_true, |yp| yp.clamp(f_true - play_r, f_true + play_r));
            play_y = Some(yp);
            f_true = yp;
        }
        let mut f = effects.force_sensor_gain * f_true + effects.force_sensor_offset;
        let (mut p1, mut p2) = (y[S_P1], y[S_P2]);
        if und.pressure_sensor_offset_1 != 0.0 {
            p1 += und.pressure_sensor_offset_1;
        }
        if p2_delay > 0 {
            p2_hist.push(p2);
            p2 = p2_hist[k.saturating_sub(p2_delay)];
        }
        if let Some(r) = rng.as_mut() {
            f += 0.05 * r.normal();
            p1 += 150.0 * r.normal();
            p2 += 150.0 * r.normal();
        }
        let mut row = [t, cmd, xs, f, p1, p2];
        if opts.quantise {
            row[2] = quantise_stopper(xs);
            row[3] = quantise_force(f);
            row[4] = quantise_pressure(p1);
            row[5] = quantise_pressure(p2);
        }
        rows.push(row);
        for _ in 0..STEPS_PER_SAMPLE {
            do_step(&mut y, step);
            step += 1;
        }
    }
    rows
}

/// A bench recording of the protocol of `bench/README.md`, truncated to `duration` s (≤ 80):
/// rows (time_s, v_da_V, x_s_m, force_N, p1_Pa, p2_Pa) at 1 kHz with noise from `seed`.
pub fn generate(effects: &BenchEffects, seed: u64, duration: f64) -> Vec<[f64; 6]> {
    let n = (duration.clamp(0.0, PROTOCOL_DURATION) / SAMPLE).round() as usize;
    let opts = RunOptions {
        noise_seed: Some(seed),
        ..RunOptions::default()
    };
    simulate(
        &BenchParams::default(),
        effects,
        protocol_command,
        protocol_stopper,
        n,
        &opts,
    )
}

/// Write rows in the format of the bench recordings (header and number formatting).
pub fn write_csv(rows: &[[f64; 6]], path: impl AsRef<Path>) -> std::io::Result<()> {
    let mut w = BufWriter::new(std::fs::File::create(path)?);
    writeln!(w, "time_s,v_da_V,x_s_m,force_N,p1_Pa,p2_Pa")?;
    for r in rows {
        writeln!(
            w,
            "{:.3},{:.6},{:.6},{:.4},{:.1},{:.1}",
            r[0], r[1], r[2], r[3], r[4], r[5]
        )?;
    }
    w.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area_numeric(cx_a: f64, ra: f64, cx_b: f64, rb: f64) -> f64 {
        // grid integration of the overlap of two discs centred on the x axis
        let n = 1200;
        let (x0, x1) = ((cx_a - ra).max(cx_b - rb), (cx_a + ra).min(cx_b + rb));
        if x1 <= x0 {
            return 0.0;
        }
        let dx = (x1 - x0) / n as f64;
        let mut s = 0.0;
        for k in 0..n {
            let x = x0 + (k as f64 + 0.5) * dx;
            let ha = (ra * ra - (x - cx_a).powi(2)).max(0.0).sqrt();
            let hb = (rb * rb - (x - cx_b).powi(2)).max(0.0).sqrt();
            s += 2.0 * ha.min(hb) * dx;
        }
        s
    }

    #[test]
    fn areas_match_numerical_integration() {
        let d = 0.9652e-3;
        let r = d / 2.0;
        for k in -40..=40 {
            let x = k as f64 * 0.05e-3;
            let (s1, r1, s2, r2) = port_areas(x, d);
            let n_s1 = area_numeric(d, r, x, r);
            let n_s2 = area_numeric(-d, r, x, r);
            let n_r1 = PI * r * r - area_numeric(d, r, x, 3.0 * r);
            let n_r2 = PI * r * r - area_numeric(-d, r, x, 3.0 * r);
            let tol = 2e-4 * PI * r * r;
            assert!((s1 - n_s1).abs() < tol, "A_s1 at {x}: {s1} vs {n_s1}");
            assert!((s2 - n_s2).abs() < tol, "A_s2 at {x}");
            assert!((r1 - n_r1).abs() < tol, "A_r1 at {x}: {r1} vs {n_r1}");
            assert!((r2 - n_r2).abs() < tol, "A_r2 at {x}");
            // symmetry
            let (s1m, r1m, _, _) = port_areas(-x, d);
            assert!((s1m - s2).abs() < 1e-18 && (r1m - r2).abs() < 1e-18);
        }
        let (s1, r1, s2, r2) = port_areas(0.0, d);
        assert!(s1.abs() < 1e-15 && r1.abs() < 1e-15 && s2.abs() < 1e-15 && r2.abs() < 1e-15);
    }

    fn clean() -> RunOptions {
        RunOptions {
            noise_seed: None,
            quantise: false,
            pre_time: 6.0,
        }
    }

    /// Noiseless static force at a constant command and stopper (last sample of a short run).
    fn static_force(params: &BenchParams, e: &BenchEffects, v: f64) -> f64 {
        let rows = simulate(params, e, |_| v, |_| (STOPPER_HOME, 0.0), 2, &clean());
        rows[1][3]
    }

    #[test]
    fn static_force_is_bounded_and_rises_with_command() {
        let p = BenchParams::default();
        let e = BenchEffects::default();
        let a_p = PI * p.d_cyl * p.d_cyl / 4.0;
        let f_spring = p.k_spring * (p.l_spring0 - (STOPPER_HOME - p.l_s - p.l_p));
        let f_max = a_p * (p.p_supply - p.p_return);
        let mut last = f_spring - 1e-9;
        for v in [-4.0, 0.0, 2.0, 4.0, 6.0, 10.0] {
            let f = static_force(&p, &e, v);
            assert!(f >= f_spring - 1e-9 && f <= f_max, "v={v}: F={f}");
            assert!(f >= last, "force must rise with command: v={v} F={f} last={last}");
            last = f;
        }
        assert!(
            last > 90.0,
            "full command must give most of the rated force, got {last}"
        );
        // no supply pressure: only the spring
        let p0 = BenchParams {
            p_supply: p.p_return,
            ..p.clone()
        };
        let f = static_force(&p0, &e, 5.0);
        assert!((f - f_spring).abs() < 1e-9, "P_s = P_r: {f} vs {f_spring}");
    }

    fn run_custom<C: Fn(f64) -> f64, S: Fn(f64) -> (f64, f64)>(
        e: &BenchEffects,
        c: C,
        s: S,
        n: usize,
    ) -> Vec<[f64; 6]> {
        simulate(&BenchParams::default(), e, c, s, n, &clean())
    }

    #[test]
    fn friction_lowers_force_while_extending() {
        let s = |t: f64| {
            let w = 2.0 * PI * 1.5;
            (STOPPER_HOME + 0.01 * (w * t).sin(), 0.01 * w * (w * t).cos())
        };
        let base = run_custom(&BenchEffects::default(), |_| 2.5, s, 700);
        let fr = run_custom(
            &BenchEffects {
                friction_coulomb: 2.0,
                ..Default::default()
            },
            |_| 2.5,
            s,
            700,
        );
        let (mut ext, mut ret) = (0, 0);
        for k in 0..700 {
            let xd = s(base[k][0]).1;
            if xd > 0.02 {
                assert!(fr[k][3] < base[k][3] - 1.9, "t={} extending", base[k][0]);
                ext += 1;
            } else if xd < -0.02 {
                assert!(fr[k][3] > base[k][3] + 1.9, "t={} retracting", base[k][0]);
                ret += 1;
            }
        }
        assert!(ext > 50 && ret > 50);
    }

    #[test]
    fn hysteresis_lags_the_command() {
        // triangle −8 → 10 → −8 V over 4 s
        let c = |t: f64| {
            if t < 2.0 {
                -8.0 + 9.0 * t
            } else {
                10.0 - 9.0 * (t - 2.0)
            }
        };
        let hs = BenchEffects {
            hysteresis_width: 0.16e-3,
            ..Default::default()
        };
        let base = run_custom(&BenchEffects::default(), c, |_| (STOPPER_HOME, 0.0), 4000);
        let hy = run_custom(&hs, c, |_| (STOPPER_HOME, 0.0), 4000);
        // at 2 V rising (t = 1.111 s) the force is lower, falling (t = 2.889 s) higher
        assert!(
            hy[1111][3] < base[1111][3] - 1.0,
            "rising {} vs {}",
            hy[1111][3],
            base[1111][3]
        );
        assert!(
            hy[2889][3] > base[2889][3] + 1.0,
            "falling {} vs {}",
            hy[2889][3],
            base[2889][3]
        );
    }

    fn step_cmd(t: f64) -> f64 {
        if t < 0.1 {
            2.0
        } else {
            5.0
        }
    }

    #[test]
    fn dead_volume_slows_the_step_but_keeps_the_static_force() {
        let base = run_custom(&BenchEffects::default(), step_cmd, |_| (STOPPER_HOME, 0.0), 1500);
        let dv = BenchEffects {
            dead_volume_1: 5e-6,
            dead_volume_2: 5e-6,
            ..Default::default()
        };
        let d = run_custom(&dv, step_cmd, |_| (STOPPER_HOME, 0.0), 1500);
        let rise = |r: &Vec<[f64; 6]>| r[130][3] - r[99][3];
        assert!(rise(&d) < 0.8 * rise(&base), "dead {} base {}", rise(&d), rise(&base));
        assert!(
            (d[1499][3] - base[1499][3]).abs() < 0.3,
            "{} vs {}",
            d[1499][3],
            base[1499][3]
        );
    }

    #[test]
    fn supply_resistance_lowers_high_force() {
        let p = BenchParams::default();
        let f0 = static_force(&p, &BenchEffects::default(), 8.0);
        let f1 = static_force(
            &p,
            &BenchEffects {
                supply_resistance: 2e8,
                ..Default::default()
            },
            8.0,
        );
        assert!(f1 < f0 - 0.5, "{f1} vs {f0}");
    }

    #[test]
    fn heat_transfer_softens_the_pressure_response() {
        let base = run_custom(&BenchEffects::default(), step_cmd, |_| (STOPPER_HOME, 0.0), 200);
        let ht = run_custom(
            &BenchEffects {
                heat_transfer: 1.0,
                ..Default::default()
            },
            step_cmd,
            |_| (STOPPER_HOME, 0.0),
            200,
        );
        let rise = |r: &Vec<[f64; 6]>| r[110][4] - r[99][4];
        assert!(rise(&ht) < 0.85 * rise(&base), "{} vs {}", rise(&ht), rise(&base));
        // same equilibrium before the step
        assert!((ht[99][3] - base[99][3]).abs() < 0.05);
    }

    #[test]
    fn command_delay_postpones_the_response() {
        let base = run_custom(&BenchEffects::default(), step_cmd, |_| (STOPPER_HOME, 0.0), 130);
        let dl = run_custom(
            &BenchEffects {
                command_delay: 0.008,
                ..Default::default()
            },
            step_cmd,
            |_| (STOPPER_HOME, 0.0),
            130,
        );
        // before the delayed step arrives nothing has changed
        assert!((dl[107][4] - dl[99][4]).abs() < 1.0);
        assert!(base[107][4] - base[99][4] > 100.0);
        // the delayed response is the base response shifted by 8 samples
        assert!(
            (dl[125][4] - base[117][4]).abs() < 5.0,
            "{} vs {}",
            dl[125][4],
            base[117][4]
        );
    }

    #[test]
    fn sensor_offset_and_gain_apply_to_force_only() {
        let base = run_custom(&BenchEffects::default(), step_cmd, |_| (STOPPER_HOME, 0.0), 150);
        let e = BenchEffects {
            force_sensor_offset: 1.5,
            force_sensor_gain: 1.05,
            ..Default::default()
        };
        let s = run_custom(&e, step_cmd, |_| (STOPPER_HOME, 0.0), 150);
        for k in 0..150 {
            assert!((s[k][3] - (1.05 * base[k][3] + 1.5)).abs() < 1e-9);
            assert_eq!(s[k][4], base[k][4]);
        }
    }

    #[test]
    fn deterministic_for_a_seed() {
        let e = BenchEffects::default();
        let a = generate(&e, 7, 0.3);
        let b = generate(&e, 7, 0.3);
        let c = generate(&e, 8, 0.3);
        assert_eq!(a.len(), 300);
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert!((a[0][1] - (-3.999023)).abs() < 1e-6);
        assert!((a[0][3] - 2.653).abs() < 0.3, "{}", a[0][3]);
    }

    /// FNV-1a over the bit patterns of the rows.
    fn hash_rows(rows: &[[f64; 6]]) -> u64 {
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for r in rows {
            for x in r {
                for b in x.to_bits().to_le_bytes() {
                    h ^= b as u64;
                    h = h.wrapping_mul(0x0100_0000_01b3);
                }
            }
        }
        h
    }

    /// Rows before the undeclared mechanisms were added (hashes recorded from that code):
    /// the effect-free path and the seven declared effects at once, 0.5 s at seed 2024.
    #[test]
    fn rows_are_bit_identical_to_the_code_before_undeclared_mechanisms() {
        let base = generate(&BenchEffects::default(), 2024, 0.5);
        let all = BenchEffects {
            hysteresis_width: 0.12e-3,
            friction_coulomb: 2.0,
            dead_volume_1: 3e-6,
            dead_volume_2: 4e-6,
            supply_resistance: 5e8,
            heat_transfer: 0.7,
            command_delay: 0.004,
            force_sensor_offset: 0.3,
            force_sensor_gain: 1.02,
            undeclared: UndeclaredEffects::default(),
        };
        let with_all = generate(&all, 2024, 0.5);
        // noiseless and unquantised, so that any change in the last bit shows
        let raw = |e: &BenchEffects| {
            simulate(
                &BenchParams::default(),
                e,
                protocol_command,
                protocol_stopper,
                500,
                &clean(),
            )
        };
        let (hb, ha) = (hash_rows(&base), hash_rows(&with_all));
        let (rb, ra) = (hash_rows(&raw(&BenchEffects::default())), hash_rows(&raw(&all)));
        println!("hash effect-free {hb:#018x}, all declared {ha:#018x}, raw {rb:#018x} {ra:#018x}");
        assert_eq!(hb, 0xf4a5_85b3_1e9d_ad37);
        assert_eq!(ha, 0xe6ad_f4eb_bea1_0f5f);
        assert_eq!(rb, 0xc101_7108_da49_e184);
        assert_eq!(ra, 0xe283_826a_51e3_d3c1);
    }

    #[test]
    fn undeclared_defaults_are_neutral_and_the_table_is_well_formed() {
        let u = UndeclaredEffects::default();
        let fields = [
            u.pressure_sensor_offset_1,
            u.supply_drift,
            u.supply_ripple_amplitude,
            u.supply_ripple_frequency,
            u.command_limit,
            u.current_slew_limit,
            u.jet_pipe_lag,
            u.chamber_leak_1,
            u.viscous_friction,
            u.contact_stiffness,
            u.force_sensor_lag,
            u.return_back_pressure,
            u.pressure_sensor_delay_2,
            u.receiver_offset,
            u.force_sensor_backlash,
            u.jet_pipe_curve_blend,
            u.return_area_reduction,
            u.port_1_restriction,
        ];
        assert!(fields.iter().all(|&x| x == 0.0));
        assert_eq!(BenchEffects::default().undeclared, u);
        const LOCATIONS: [&str; 10] = [
            "command",
            "current_driver",
            "jet_pipe",
            "valve",
            "supply",
            "return",
            "chambers",
            "mechanics",
            "force_sensor",
            "pressure_sensors",
        ];
        const FAMILIES: [&str; 13] = [
            "parameter_offset",
            "drift",
            "periodic",
            "limit",
            "dynamics",
            "delay",
            "extra_flow",
            "extra_force",
            "compliance",
            "nonlinearity",
            "asymmetry",
            "restriction",
            "hysteresis",
        ];
        let mut locs = std::collections::BTreeSet::new();
        let mut fams = std::collections::BTreeSet::new();
        let mut names = std::collections::BTreeSet::new();
        for m in UNDECLARED {
            assert!(LOCATIONS.contains(&m.location), "{}", m.location);
            assert!(FAMILIES.contains(&m.family), "{}", m.family);
            assert!(names.insert(m.name), "duplicate {}", m.name);
            locs.insert(m.location);
            fams.insert(m.family);
            let e = (m.effects)();
            // only the undeclared part differs from the default
            assert_eq!(
                BenchEffects {
                    undeclared: UndeclaredEffects::default(),
                    ..e.clone()
                },
                BenchEffects::default(),
                "{}",
                m.name
            );
            assert_ne!(e.undeclared, u, "{}", m.name);
            assert_eq!(undeclared_mechanism(m.name).unwrap().name, m.name);
        }
        assert!(UNDECLARED.len() >= 8);
        assert_eq!(locs.len(), LOCATIONS.len(), "locations {locs:?}");
        assert_eq!(fams.len(), FAMILIES.len(), "families {fams:?}");
        assert!(undeclared_mechanism("no_such").is_none());
    }

    fn und(u: UndeclaredEffects) -> BenchEffects {
        BenchEffects {
            undeclared: u,
            ..Default::default()
        }
    }

    /// Lags, the slew limit and the contact compliance leave the statics alone but slow the
    /// step of `step_cmd` (within 0.5 N of the base 0.3 s later: the plant has a slow tail);
    /// the leak lowers p1 and the force at rest.
    #[test]
    fn undeclared_dynamics_keep_the_statics_and_slow_the_step() {
        let p = BenchParams::default();
        let base_e = BenchEffects::default();
        let cases = [
            (
                "jet_pipe_lag",
                und(UndeclaredEffects {
                    jet_pipe_lag: 15e-3,
                    ..Default::default()
                }),
            ),
            (
                "current_slew_limit",
                und(UndeclaredEffects {
                    current_slew_limit: 3.0,
                    ..Default::default()
                }),
            ),
            (
                "contact_compliance",
                und(UndeclaredEffects {
                    contact_stiffness: 2e4,
                    ..Default::default()
                }),
            ),
            (
                "force_sensor_lag",
                und(UndeclaredEffects {
                    force_sensor_lag: 10e-3,
                    ..Default::default()
                }),
            ),
        ];
        let base = run_custom(&base_e, step_cmd, |_| (STOPPER_HOME, 0.0), 400);
        let rise = |r: &Vec<[f64; 6]>| r[105][3] - r[99][3];
        for (name, e) in &cases {
            for v in [1.0, 4.0, 8.0] {
                let (f0, f1) = (static_force(&p, &base_e, v), static_force(&p, e, v));
                assert!((f1 - f0).abs() < 1e-3, "{name} at {v} V: {f1} vs {f0}");
            }
            let r = run_custom(e, step_cmd, |_| (STOPPER_HOME, 0.0), 400);
            println!("{name}: rise in 5 ms {:.3} N (base {:.3} N)", rise(&r), rise(&base));
            assert!(rise(&r) < 0.8 * rise(&base), "{name}: {} vs {}", rise(&r), rise(&base));
            println!("  at 0.3 s after the step: {:.4} N vs {:.4} N", r[399][3], base[399][3]);
            assert!((r[399][3] - base[399][3]).abs() < 0.5, "{name} settles");
            if *name == "force_sensor_lag" {
                assert!(r.iter().zip(&base).all(|(a, b)| a[4] == b[4] && a[5] == b[5]));
            }
        }
        let leak = und(UndeclaredEffects {
            chamber_leak_1: 0.01e-6,
            ..Default::default()
        });
        let (b, l) = (
            run_custom(&base_e, |_| 3.0, |_| (STOPPER_HOME, 0.0), 2),
            run_custom(&leak, |_| 3.0, |_| (STOPPER_HOME, 0.0), 2),
        );
        assert!(l[1][4] < b[1][4] - 5000.0, "leak p1 {} vs {}", l[1][4], b[1][4]);
        assert!(l[1][3] < b[1][3] - 0.5, "leak force {} vs {}", l[1][3], b[1][3]);
    }

    /// Every mechanism, declared and undeclared, at once: finite, bounded rows (RK4 stays
    /// stable with all extra states and the supply plenum fed by a varying source).
    #[test]
    fn all_mechanisms_at_once_stay_finite() {
        let mut e = BenchEffects {
            hysteresis_width: 0.12e-3,
            friction_coulomb: 2.0,
            dead_volume_1: 3e-6,
            dead_volume_2: 4e-6,
            supply_resistance: 5e8,
            heat_transfer: 0.7,
            command_delay: 0.004,
            force_sensor_offset: 0.3,
            force_sensor_gain: 1.02,
            undeclared: UndeclaredEffects::default(),
        };
        for m in UNDECLARED {
            // each standard constructor sets only its own fields (the rest are 0): add them up
            let u = (m.effects)().undeclared;
            let t = &mut e.undeclared;
            t.pressure_sensor_offset_1 += u.pressure_sensor_offset_1;
            t.supply_drift += u.supply_drift;
            t.supply_ripple_amplitude += u.supply_ripple_amplitude;
            t.supply_ripple_frequency += u.supply_ripple_frequency;
            t.command_limit += u.command_limit;
            t.current_slew_limit += u.current_slew_limit;
            t.jet_pipe_lag += u.jet_pipe_lag;
            t.chamber_leak_1 += u.chamber_leak_1;
            t.viscous_friction += u.viscous_friction;
            t.contact_stiffness += u.contact_stiffness;
            t.force_sensor_lag += u.force_sensor_lag;
            t.return_back_pressure += u.return_back_pressure;
            t.pressure_sensor_delay_2 += u.pressure_sensor_delay_2;
            t.receiver_offset += u.receiver_offset;
            t.force_sensor_backlash += u.force_sensor_backlash;
            t.jet_pipe_curve_blend += u.jet_pipe_curve_blend;
            t.return_area_reduction += u.return_area_reduction;
            t.port_1_restriction += u.port_1_restriction;
        }
        assert!(e.undeclared.contact_stiffness > 0.0 && e.undeclared.supply_drift > 0.0);
        // protocol segments B (steps of slope) and E (moving stopper), 1.5 s each
        for t0 in [20.0, 68.5] {
            let rows = run_custom(&e, |t| protocol_command(t + t0), |t| protocol_stopper(t + t0), 1500);
            for r in &rows {
                assert!(r.iter().all(|x| x.is_finite()), "{r:?}");
                assert!(r[3] > -5.0 && r[3] < 150.0, "{r:?}");
                assert!(r[4] > 50_000.0 && r[4] < 700_000.0 && r[5] > 50_000.0 && r[5] < 700_000.0);
            }
        }
    }

    /// Noiseless, unquantised protocol run (bench pre-time), first `n` samples.
    fn protocol_clean(e: &BenchEffects, n: usize) -> Vec<[f64; 6]> {
        let opts = RunOptions {
            noise_seed: None,
            quantise: false,
            pre_time: RunOptions::default().pre_time,
        };
        simulate(&BenchParams::default(), e, protocol_command, protocol_stopper, n, &opts)
    }

    /// `f` of every item, over as many threads as the machine has cores, in the items' order.
    fn on_every_core<T: Sync, R: Send>(items: &[T], f: impl Fn(&T) -> R + Sync) -> Vec<R> {
        let threads = std::thread::available_parallelism().map_or(2, |n| n.get());
        let next = std::sync::atomic::AtomicUsize::new(0);
        let mut out: Vec<(usize, R)> = std::thread::scope(|scope| {
            let workers: Vec<_> = (0..threads.min(items.len()))
                .map(|_| {
                    scope.spawn(|| {
                        let mut mine = vec![];
                        loop {
                            let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                            let Some(item) = items.get(k) else { break };
                            mine.push((k, f(item)));
                        }
                        mine
                    })
                })
                .collect();
            workers.into_iter().flat_map(|w| w.join().unwrap()).collect()
        });
        out.sort_by_key(|(k, _)| *k);
        out.into_iter().map(|(_, r)| r).collect()
    }

    /// rms and max of the difference of column `c`.
    fn diff_stats(a: &[[f64; 6]], b: &[[f64; 6]], c: usize) -> (f64, f64) {
        let mut s2 = 0.0;
        let mut mx: f64 = 0.0;
        for (ra, rb) in a.iter().zip(b) {
            let d = ra[c] - rb[c];
            s2 += d * d;
            mx = mx.max(d.abs());
        }
        ((s2 / a.len() as f64).sqrt(), mx)
    }

    /// The force effect of every undeclared mechanism at its standard size over the whole
    /// protocol (noiseless), printed, and within the range the module docs state.
    #[test]
    fn undeclared_force_effects_over_the_protocol() {
        let n = (PROTOCOL_DURATION / SAMPLE).round() as usize;
        // The 18 noiseless protocol runs (the base and every mechanism) are independent and
        // take most of this binary's time: run on one harness thread, one after another,
        // they left the other core idle for half a minute. They run on every core instead;
        // each run is the same deterministic computation, so the rows are the same.
        let mut effects = vec![BenchEffects::default()];
        effects.extend(UNDECLARED.iter().map(|m| (m.effects)()));
        let mut runs = on_every_core(&effects, |e| protocol_clean(e, n)).into_iter();
        let base = runs.next().unwrap();
        let mut off_size = Vec::new();
        for (m, rows) in UNDECLARED.iter().zip(runs) {
            let (f_rms, f_max) = diff_stats(&rows, &base, 3);
            let (p1_rms, _) = diff_stats(&rows, &base, 4);
            let (p2_rms, _) = diff_stats(&rows, &base, 5);
            println!(
                "{:<20} {:<17} {:<17} force rms {f_rms:.3} N max {f_max:.3} N; p1 rms {p1_rms:.0} Pa, p2 rms {p2_rms:.0} Pa",
                m.name, m.location, m.family
            );
            // documented rms force effect (module docs), within −30 % / +40 %
            let doc_rms = match m.name {
                "p1_sensor_offset" => 0.0,
                "supply_drift" => 1.64,
                "supply_ripple" => 1.02,
                "command_limit" => 0.66,
                "current_slew_limit" => 0.68,
                "jet_pipe_lag" => 0.72,
                "chamber_1_leak" => 1.57,
                "viscous_friction" => 1.49,
                "contact_compliance" => 1.41,
                "force_sensor_lag" => 0.91,
                "return_back_pressure" => 1.31,
                "p2_sensor_delay" => 0.0,
                "receiver_offset" => 1.9,
                "force_sensor_backlash" => 0.71,
                "jet_pipe_curve" => 1.71,
                "return_area_reduction" => 1.69,
                "port_1_restriction" => 2.21,
                other => panic!("no documented size for {other}"),
            };
            if !(f_rms >= 0.7 * doc_rms && f_rms <= 1.4 * doc_rms) {
                off_size.push(format!("{}: force rms {f_rms} vs documented {doc_rms}", m.name));
            }
            let same_until = |col: usize, t_end: f64| {
                rows.iter()
                    .zip(&base)
                    .take_while(|(r, _)| r[0] < t_end)
                    .all(|(r, b)| r[col].to_bits() == b[col].to_bits())
            };
            match m.name {
                "p1_sensor_offset" => {
                    assert!(same_until(3, 81.0) && same_until(5, 81.0));
                    assert!(rows.iter().zip(&base).all(|(r, b)| (r[4] - b[4] - 8000.0).abs() < 1e-8));
                }
                "command_limit" => {
                    // −4 + 1.4 t reaches 7 V at t = 7.857 s
                    assert!(same_until(3, 7.85) && same_until(4, 7.85) && same_until(5, 7.85));
                    assert!(!same_until(3, 9.0));
                }
                "viscous_friction" => {
                    assert!(same_until(3, 60.0) && same_until(4, 81.0) && same_until(5, 81.0));
                }
                "force_sensor_lag" => assert!(same_until(4, 81.0) && same_until(5, 81.0)),
                "force_sensor_backlash" => {
                    assert!(same_until(4, 81.0) && same_until(5, 81.0));
                    assert!(f_max <= 0.75 + 1e-9, "the play is at most half its width");
                }
                "p2_sensor_delay" => {
                    assert!(same_until(3, 81.0) && same_until(4, 81.0));
                    assert!(rows[10..].iter().zip(&base).all(|(r, b)| r[5] == b[5]));
                    assert!(rows[..10].iter().all(|r| r[5] == base[0][5]));
                }
                "supply_drift" => {
                    let early = diff_stats(&rows[..20_000], &base[..20_000], 3).0;
                    let late = diff_stats(&rows[60_000..], &base[60_000..], 3).0;
                    assert!(late > 2.0 * early, "drift grows: early {early}, late {late}");
                }
                _ => {}
            }
        }
        assert!(off_size.is_empty(), "{off_size:?}");
    }

    #[test]
    fn protocol_is_continuous_where_it_should_be() {
        assert!((protocol_command(10.0) - 10.0).abs() < 1e-12);
        assert!((protocol_command(19.999) - protocol_command(20.0)).abs() < 0.01);
        assert!((protocol_command(34.999) - protocol_command(35.0)).abs() < 0.01);
        assert!((protocol_stopper(70.0).0 - STOPPER_HOME).abs() < 1e-12);
        assert!((protocol_stopper(60.5).0 - 0.064).abs() < 1e-9);
    }
}
