//! The effects the bench can switch on, beyond the thesis model, and their forms.
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
//!   Zero while the stopper is still. With `friction_smoothing_velocity` v_t > 0 the law is
//!   F_c tanh(v/v_t) instead, with neither stiction nor the viscous part.
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
//! Beyond the table (flags of `benchgen`, fields of [`UndeclaredEffects`], no standard size):
//!
//! * `stopper_position_offset` (`chambers`/`parameter_offset`): the logged stopper position is
//!   x_s + d (before quantisation); the plant moves with x_s.
//! * `contact_lag` (with `contact_stiffness`): τ_c of the compliant contact above instead of
//!   0.5 ms (a compliant stopper mount with its own mass and damping).
//! * `gas_temperature_drift` (`chambers`/`drift`, ΔT): the gas temperature T of (2.6), the
//!   supply's, the inflows' and (with heat exchange) the walls', is T + ΔT t / t_end, rising
//!   linearly over the recording; the chambers start at T.
//!
//! * `discharge_ratio_rise` (`valve`/`nonlinearity`, s): each of the four valve orifices
//!   flows with C_d (1 + s (1 − r)²) in place of C_d, r = P_down/P_up across it (a sharp-edged
//!   orifice's jet contracts less as it chokes; s = 0.3 takes C_d from 0.696 at equal
//!   pressures to 0.90 at r = 0). The leakage past the piston and the undeclared restrictions
//!   keep their laws.
//!
//! * `supply_leak_2` (`chambers`/`extra_flow`, C_d·A): an orifice from the supply (after
//!   any supply restriction) into chamber 2, the same compressible law, inflow at T.
//! * `laminar_leak_1` (`chambers`/`extra_flow`, g): chamber 1 loses g (P1 − 101 325 Pa) to
//!   atmosphere (a long, narrow path, laminar).
//! * `laminar_supply_leak_2` (`chambers`/`extra_flow`, g): chamber 2 gains g (P_s − P2) from
//!   the supply (after any supply restriction) through a long, narrow path, inflow at T.
//! * `laminar_cross_leak` (`chambers`/`extra_flow`, g): g (P1 − P2) flows from chamber 1 into
//!   chamber 2 beside the leakage past the piston (a scored bore), at the upstream chamber's
//!   temperature.
//! * `difference_inflow_2` (`chambers`/`extra_flow`, g): chamber 2 alone gains g (P1 − P2),
//!   which no other place loses (mass is not conserved: a flow from outside the model's two
//!   chambers that follows their difference); inflow at T, outflow (P1 < P2) at chamber 2's
//!   temperature.
//! * `position_sign_force` (`mechanics`/`extra_force`, k, with `position_sign_origin` x₀):
//!   the force gains k (x_s − x₀) tanh(v / 1 mm/s) with the stopper's own velocity.
//!   `chamber_1_pressure_force` (`mechanics`/`extra_force`, μ): it gains μ (P1 − P_r).
//! * `direction_friction_out`, `direction_friction_in` (`mechanics`/`asymmetry`, F_o, F_i): a
//!   friction whose level depends on the direction of the stopper's travel, the force losing
//!   F_o s⁺ + F_i s⁻ with s = tanh(v / 0.2 mm/s), s⁺ = max(s, 0), s⁻ = min(s, 0) (a seal that
//!   grips harder one way); either level may be 0 (a friction one way only).
//! * `current_offset_direction` (`current_driver`/`asymmetry`, d): the driver's offset is
//!   i_offset + d tanh(v / 0.5 mm/s) with the stopper's own velocity.
//!   `current_offset_ripple` (`current_driver`/`periodic`, r, with
//!   `current_offset_ripple_frequency` f): it is i_offset + r sin(2π f t).
//! * `force_sensor_filter_frequency` (`force_sensor`/`dynamics`, f_n, with
//!   `force_sensor_filter_damping` ζ): the force reading passes, after any lag, through
//!   y'' + 2ζω y' + ω² y = ω² u, ω = 2π f_n (an amplifier's anti-aliasing filter; ζ = 1/√2
//!   when 0). `pressure_sensor_filter_1` (`pressure_sensors`/`dynamics`, with
//!   `pressure_sensor_filter_damping_1`): the same on the chamber 1 transducer.
//!   `command_filter_frequency` (`command`/`dynamics`, with `command_filter_damping`): the
//!   same between the D/A and the current driver, after the driver's static input curve
//!   (a reconstruction filter on the held command). All three are integrated with the plant.
//!
//! Near equal pressures the orifice law is replaced below Δp = 20 Pa by the secant line through

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
    /// `force_sensor`/`periodic`: amplitude (N) of a pick-up on the force reading,
    /// a sin(2π f t + 1 rad) (mains hum on the bridge amplifier); 0 = none.
    pub force_sensor_pickup_amplitude: f64,
    /// Its frequency f (Hz).
    pub force_sensor_pickup_frequency: f64,
    /// `command`/`nonlinearity`: half width (V) of a dead zone in the D/A output the current
    /// driver sees: 0 within ±d, v ∓ d outside; 0 = none.
    pub command_dead_zone: f64,
    /// `command`/`nonlinearity`: the D/A output the current driver sees is rounded to
    /// multiples of this (V): a converter of fewer bits than the logged command; 0 = none.
    pub command_quantum: f64,
    /// `command`/`limit`: the D/A output the current driver sees saturates above this (V),
    /// and nothing below; 0 = none.
    pub command_upper_limit: f64,
    /// `force_sensor`/`limit`: the force reading saturates at ± this (N), after gain and
    /// offset, before noise and quantisation; 0 = none.
    pub force_sensor_saturation: f64,
    /// `mechanics`/`extra_force`: a mass (kg) that moves with the stopper between the piston
    /// and the sensor: the reading loses m · d²x_s/dt² (the stopper's own acceleration, by a
    /// centred difference of its velocity over ±1 µs); not passed through the contact
    /// compliance or the force sensor lag. 0 = none.
    pub moving_mass: f64,
    /// `mechanics`/`extra_force`: a seal friction growing with the chambers' gauge pressure,
    /// μ (P1 + P2 − 2 P_r) tanh(v / 0.2 mm/s), μ in N/Pa (m²); 0 = none.
    pub seal_pressure_friction: f64,
    /// `mechanics`/`extra_force`: quadratic damping q v|v| (N·s²/m²) opposing the stopper's
    /// velocity; 0 = none.
    pub quadratic_damping: f64,
    /// `mechanics`/`extra_force`: a Coulomb friction over a band of the bore, F_b b(x_s)
    /// tanh(v / 0.2 mm/s) with b = ½[tanh((x_s − 60 mm)/0.5 mm) − tanh((x_s − 66 mm)/0.5 mm)]
    /// (a scored stretch of the cylinder wall), F_b in N; 0 = none.
    pub friction_band: f64,
    /// `pressure_sensors`/`limit`: the chamber 1 pressure transducer's range ends at this
    /// absolute pressure (Pa): it reads min(P1, this), before noise and quantisation; 0 = none.
    pub pressure_sensor_saturation_1: f64,
    /// `pressure_sensors`/`nonlinearity`: the chamber 2 transducer reads
    /// P2 + q (P2 − 101 325 Pa)² with q this (1/Pa), before noise and quantisation; 0 = none.
    pub pressure_sensor_quadratic_2: f64,
    /// `chambers`/`parameter_offset`: the logged stopper position is this much (m) beyond the
    /// true one (a displacement transducer's zero, e.g. 1 mm); the plant moves with the true one.
    pub stopper_position_offset: f64,
    /// With `contact_stiffness`: the relaxation time (s) of the piston on its compliant mount
    /// (mass and damping of the mount); 0 = the standard 0.5 ms.
    pub contact_lag: f64,
    /// `chambers`/`drift`: the gas temperature rises linearly by this (K) from the start to the
    /// end of the recording (supply air warming up); the chamber walls follow it.
    pub gas_temperature_drift: f64,
    /// `mechanics`/`drift`: the cylinder's bore D changes linearly by this fraction of itself
    /// from the start to the end of the recording (−0.01: 1 % narrower at the end, a seal
    /// swelling); the piston's area π D²/4 in the force and both chambers' volumes follows it.
    pub bore_drift: f64,
    /// `valve`/`nonlinearity`: the valve orifices' discharge coefficient rises as the flow
    /// chokes, C_d (1 + s (1 − r)²) with r = P_down/P_up across each; s this; 0 = none.
    pub discharge_ratio_rise: f64,
    /// `chambers`/`extra_flow`: C_d·A (m²) of a leak from the supply into chamber 2 (a worn
    /// seat); 0 = none.
    pub supply_leak_2: f64,
    /// `chambers`/`extra_flow`: laminar conductance (kg/(s·Pa)) from chamber 1 to atmosphere,
    /// the flow (P1 − 101 325 Pa) times this (a porous seal); 0 = none.
    pub laminar_leak_1: f64,
    /// `chambers`/`extra_flow`: laminar conductance (kg/(s·Pa)) from the supply into chamber
    /// 2, the flow (P_s − P2) times this (a porous seal at the supply); 0 = none.
    pub laminar_supply_leak_2: f64,
    /// `chambers`/`extra_flow`: laminar conductance (kg/(s·Pa)) between the chambers, the flow
    /// (P1 − P2) times this from chamber 1 into chamber 2 (a scored bore); 0 = none.
    pub laminar_cross_leak: f64,
    /// `chambers`/`extra_flow`: chamber 2 alone gains this (kg/(s·Pa)) times (P1 − P2), taken
    /// from no other place (negative with P1 < P2, or with a negative g); 0 = none.
    pub difference_inflow_2: f64,
    /// `mechanics`/`extra_force`: a force that adds to the pressure force, k (x_s − x₀)
    /// tanh(v / 1 mm/s), v the stopper's own velocity: a friction that grows (and turns) along
    /// the bore; k in N/m; 0 = none.
    pub position_sign_force: f64,
    /// Its origin x₀ (m).
    pub position_sign_origin: f64,
    /// `mechanics`/`asymmetry`: a friction of level F_o (N) while the stopper moves out (v > 0)
    /// and F_i (N) while it moves in, F_o s⁺ + F_i s⁻ taken from the force with
    /// s = tanh(v / 0.2 mm/s); 0 = none.
    pub direction_friction_out: f64,
    pub direction_friction_in: f64,
    /// `current_driver`/`asymmetry`: the current driver's offset differs with the direction of
    /// the stopper's travel, i_offset + d tanh(v / 0.5 mm/s), v the stopper's own velocity (a
    /// pick-up from the stopper drive's direction line); d in A; 0 = none.
    pub current_offset_direction: f64,
    /// `current_driver`/`periodic`: the current driver's offset carries a ripple
    /// i_offset + r sin(2π f t), t from the first sample (a pick-up in the coil's loop); r in
    /// A, 0 = none.
    pub current_offset_ripple: f64,
    /// Its frequency f (Hz).
    pub current_offset_ripple_frequency: f64,
    /// `mechanics`/`extra_force`: a force that adds to the pressure force, μ (P1 − P_r), μ in
    /// m² (chamber 1's pressure acting on an annulus the thesis leaves out); 0 = none.
    pub chamber_1_pressure_force: f64,
    /// `force_sensor`/`dynamics`: natural frequency (Hz) of a second-order low-pass filter
    /// (the bridge amplifier's anti-aliasing filter) after any force sensor lag; 0 = none.
    pub force_sensor_filter_frequency: f64,
    /// Its damping ratio (0: 1/√2, Butterworth).
    pub force_sensor_filter_damping: f64,
    /// `pressure_sensors`/`dynamics`: natural frequency (Hz) of a second-order low-pass
    /// filter on the chamber 1 pressure transducer; 0 = none.
    pub pressure_sensor_filter_1: f64,
    /// Its damping ratio (0: 1/√2).
    pub pressure_sensor_filter_damping_1: f64,
    /// `command`/`dynamics`: natural frequency (Hz) of a second-order low-pass filter between
    /// the D/A and the current driver (a reconstruction filter); 0 = none.
    pub command_filter_frequency: f64,
    /// Its damping ratio (0: 1/√2).
    pub command_filter_damping: f64,
    /// `piston_friction`'s shape: when positive, F_c tanh(v / this) (m/s) replaces the
    /// Stribeck curve, with neither stiction nor the viscous part (seals that deform over a
    /// wide speed range); 0 = the Stribeck curve.
    pub friction_smoothing_velocity: f64,
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
