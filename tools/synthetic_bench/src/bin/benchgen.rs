//! `benchgen`: write a synthetic bench recording (the protocol of `bench/README.md`, or another
//! with `--protocol`) from the independent simulator of the `synthetic_bench` library, with
//! chosen effects beyond the thesis model.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::Parser;
use synthetic_bench::{
    generate, generate_protocol_with, undeclared_mechanism, write_csv, BenchEffects, BenchParams, CommandProtocol,
    ProtocolSpec, StopperMotion, UndeclaredEffects, PROTOCOL_DURATION, UNDECLARED,
};

#[derive(Parser)]
#[command(
    name = "benchgen",
    about = "Synthetic bench recordings of the jet-pipe actuator (test oracle)"
)]
struct Cli {
    /// Output CSV file.
    #[arg(long)]
    out: PathBuf,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Length of the recording, s: with the bench protocol at most 80 (it is truncated), with
    /// --protocol 20–3600.
    #[arg(long, default_value_t = PROTOCOL_DURATION)]
    duration: f64,
    /// Another protocol than the bench's: staircase, multisine, prbs, sine, ramps or
    /// force_tracking (a PI controller on the logged force).
    #[arg(long)]
    protocol: Option<String>,
    /// With --protocol: the stopper's motion, `fixed:X` (m), `sine:CENTRE:AMPLITUDE:HZ` (m, m,
    /// Hz), `moves:SPEED` (m/s, between random positions) or `move:AT:TO:SPEED` (s, m, m/s: one
    /// move from the home position).
    #[arg(long, default_value = "fixed:0.054")]
    stopper: String,
    /// With --protocol: sampling rate, Hz (250–2000, a whole number of 20 µs steps a sample).
    #[arg(long, default_value_t = 1000.0)]
    sample_rate: f64,
    /// With --protocol: RMS noise of the force sensor, N.
    #[arg(long, default_value_t = 0.05)]
    force_noise: f64,
    /// With --protocol: RMS noise of each pressure transducer, Pa.
    #[arg(long, default_value_t = 150.0)]
    pressure_noise: f64,
    /// With --protocol: write no pressure columns.
    #[arg(long)]
    no_pressures: bool,
    /// jet_pipe_hysteresis: full branch separation of the static jet pipe position, m (e.g. 0.16e-3).
    #[arg(long, default_value_t = 0.0)]
    hysteresis_width: f64,
    /// piston_friction: Coulomb level of the Stribeck curve, N.
    #[arg(long, default_value_t = 0.0)]
    friction_coulomb: f64,
    /// dead_volume of chamber 1, m³.
    #[arg(long, default_value_t = 0.0)]
    dead_volume_1: f64,
    /// dead_volume of chamber 2, m³.
    #[arg(long, default_value_t = 0.0)]
    dead_volume_2: f64,
    /// supply_pressure_drop: supply line resistance dP/dṁ at 2e-4 kg/s, Pa·s/kg.
    #[arg(long, default_value_t = 0.0)]
    supply_resistance: f64,
    /// heat_transfer: 0 (adiabatic, thesis) .. 1 (nearly isothermal).
    #[arg(long, default_value_t = 0.0)]
    heat_transfer: f64,
    /// transport_delay: delay of the command seen by the current driver, s.
    #[arg(long, default_value_t = 0.0)]
    command_delay: f64,
    /// sensor_offset_gain: force sensor offset, N.
    #[arg(long, default_value_t = 0.0)]
    force_sensor_offset: f64,
    /// sensor_offset_gain: force sensor gain.
    #[arg(long, default_value_t = 1.0)]
    force_sensor_gain: f64,
    /// Switch on one undeclared mechanism at its standard size (see --list-undeclared); the
    /// flags below, where given, override its parameters.
    #[arg(long)]
    undeclared: Option<String>,
    /// List the undeclared mechanisms (name, location, family, truth) and exit.
    #[arg(long)]
    list_undeclared: bool,
    /// p1_sensor_offset: offset of the chamber 1 pressure transducer, Pa (e.g. 8000).
    #[arg(long)]
    pressure_sensor_offset_1: Option<f64>,
    /// supply_drift: linear fall of the supply pressure over 80 s, Pa (e.g. 30000).
    #[arg(long)]
    supply_drift: Option<f64>,
    /// supply_ripple: amplitude of a supply pressure ripple, Pa (e.g. 15000).
    #[arg(long)]
    supply_ripple_amplitude: Option<f64>,
    /// supply_ripple: frequency of the ripple, Hz (e.g. 7).
    #[arg(long)]
    supply_ripple_frequency: Option<f64>,
    /// command_limit: D/A output seen by the current driver saturates at ± this, V (e.g. 7).
    #[arg(long)]
    command_limit: Option<f64>,
    /// current_slew_limit: largest rate of the coil current, A/s (e.g. 3).
    #[arg(long)]
    current_slew_limit: Option<f64>,
    /// jet_pipe_lag: extra first-order lag after the static jet pipe curve, s (e.g. 0.015).
    #[arg(long)]
    jet_pipe_lag: Option<f64>,
    /// chamber_1_leak: C_d·A of a leak from chamber 1 to the atmosphere, m² (e.g. 1e-8).
    #[arg(long)]
    chamber_leak_1: Option<f64>,
    /// viscous_friction: coefficient on the stopper velocity, N·s/m (e.g. 60).
    #[arg(long)]
    viscous_friction: Option<f64>,
    /// contact_compliance: stiffness between piston and stopper, N/m (e.g. 2e4).
    #[arg(long)]
    contact_stiffness: Option<f64>,
    /// force_sensor_lag: first-order lag of the force sensor, s (e.g. 0.01).
    #[arg(long)]
    force_sensor_lag: Option<f64>,
    /// return_back_pressure: the return (exhaust) pressure is higher by this, Pa (e.g. 20000).
    #[arg(long)]
    return_back_pressure: Option<f64>,
    /// p2_sensor_delay: the chamber 2 pressure is logged this late, s (whole ms; e.g. 0.005).
    #[arg(long)]
    pressure_sensor_delay_2: Option<f64>,
    /// receiver_offset: receivers further from the jet pipe null than x_jp_offset, m (e.g. 1e-5).
    #[arg(long)]
    receiver_offset: Option<f64>,
    /// force_sensor_backlash: full width of a play operator on the force reading, N (e.g. 1.5).
    #[arg(long)]
    force_sensor_backlash: Option<f64>,
    /// jet_pipe_curve: blend 0..1 of the static jet pipe curve towards u/sqrt(1+u²) (e.g. 1).
    #[arg(long)]
    jet_pipe_curve_blend: Option<f64>,
    /// return_area_reduction: fractional reduction 0..1 of both return areas (e.g. 0.05).
    #[arg(long)]
    return_area_reduction: Option<f64>,
    /// port_1_restriction: C_d·A of an orifice between receiver port 1 and chamber 1, m² (e.g. 2e-7).
    #[arg(long)]
    port_1_restriction: Option<f64>,
    /// A pick-up on the force reading, a sin(2π f t + 1 rad): its amplitude, N (e.g. 0.1).
    #[arg(long)]
    force_sensor_pickup_amplitude: Option<f64>,
    /// Its frequency, Hz (e.g. 50).
    #[arg(long)]
    force_sensor_pickup_frequency: Option<f64>,
    /// A dead zone in the D/A output the current driver sees: its half width, V (e.g. 0.4).
    #[arg(long)]
    command_dead_zone: Option<f64>,
    /// The D/A output the current driver sees is rounded to multiples of this, V: a converter
    /// of fewer bits than the logged command (e.g. 0.3125, 6 bits over ±10 V).
    #[arg(long)]
    command_quantum: Option<f64>,
    /// The D/A output the current driver sees saturates above this, V, and not below (e.g. 6).
    #[arg(long)]
    command_upper_limit: Option<f64>,
    /// The force reading saturates at ± this, N (e.g. 85).
    #[arg(long)]
    force_sensor_saturation: Option<f64>,
    /// A mass moving with the stopper between piston and sensor, kg (e.g. 0.1): the reading
    /// loses m times the stopper's acceleration. Move the stopper (--stopper) for it to show.
    #[arg(long)]
    moving_mass: Option<f64>,
    /// A seal friction growing with the chambers' gauge pressure, N/Pa (e.g. 2e-6: 1 N at
    /// 5 bar above the return): mu (P1 + P2 - 2 P_r) tanh(v / 0.2 mm/s).
    #[arg(long)]
    seal_pressure_friction: Option<f64>,
    /// Quadratic damping on the stopper velocity, N.s2/m2 (e.g. 100): q v|v|.
    #[arg(long)]
    quadratic_damping: Option<f64>,
    /// A Coulomb friction over the band 60-66 mm of stopper position (smooth edges of 0.5 mm), N
    /// (e.g. 2.5). Move the stopper across it (--stopper) for it to show.
    #[arg(long)]
    friction_band: Option<f64>,
    /// The chamber 1 pressure transducer's range ends at this absolute pressure, Pa (e.g. 4.5e5).
    #[arg(long)]
    pressure_sensor_saturation: Option<f64>,
    /// The chamber 2 transducer reads P2 + q (P2 − 101 325 Pa)²: q, 1/Pa (e.g. 2e-7).
    #[arg(long)]
    pressure_sensor_quadratic: Option<f64>,
    /// The logged stopper position is this far beyond the true one, m (e.g. 1e-3).
    #[arg(long, allow_hyphen_values = true)]
    stopper_position_offset: Option<f64>,
    /// With --contact-stiffness: the relaxation time of the piston on its compliant mount, s
    /// (0.5 ms unless given; e.g. 1e-3).
    #[arg(long)]
    contact_lag: Option<f64>,
    /// The gas temperature rises linearly by this over the recording, K (e.g. 20).
    #[arg(long, allow_hyphen_values = true)]
    gas_temperature_drift: Option<f64>,
    /// With --friction-coulomb: the friction is F_c tanh(v / this), v the stopper's velocity,
    /// m/s, instead of the Stribeck curve (e.g. 0.01).
    #[arg(long)]
    friction_smoothing_velocity: Option<f64>,
    /// The cylinder's bore changes linearly by this fraction of itself over the recording
    /// (e.g. -0.01: 1 % narrower at the end), the piston's area in the force and the volumes with it.
    #[arg(long, allow_hyphen_values = true)]
    bore_drift: Option<f64>,
    /// The valve orifices' C_d grows to C_d (1 + s (1 − r)²) at pressure ratio r: s (e.g. 0.3).
    #[arg(long)]
    discharge_ratio_rise: Option<f64>,
    /// A leak from the supply into chamber 2: its C_d·A, m² (e.g. 5e-9).
    #[arg(long)]
    supply_leak_2: Option<f64>,
    /// A laminar leak from chamber 1 to atmosphere: its conductance, kg/(s·Pa) (e.g. 2e-11).
    #[arg(long)]
    laminar_leak_1: Option<f64>,
    /// A laminar leak from the supply into chamber 2: its conductance, kg/(s·Pa) (e.g. 4e-12).
    #[arg(long)]
    laminar_supply_leak_2: Option<f64>,
    /// A laminar leak from chamber 1 into chamber 2: its conductance, kg/(s·Pa) (e.g. 4e-12).
    #[arg(long)]
    laminar_cross_leak: Option<f64>,
    /// A flow into chamber 2 alone in proportion to P1 − P2 (chamber 1 does not lose it): its
    /// coefficient, kg/(s·Pa), of either sign (e.g. 5e-12).
    #[arg(long, allow_hyphen_values = true)]
    difference_inflow_2: Option<f64>,
    /// A force on the piston k (x_s − x0) tanh(v / 1 mm/s), v the stopper's velocity (a
    /// friction that grows and turns along the bore): k, N/m, of either sign (e.g. 75).
    #[arg(long, allow_hyphen_values = true)]
    position_sign_force: Option<f64>,
    /// With --position-sign-force: its origin x0, m (e.g. 0.054).
    #[arg(long, allow_hyphen_values = true)]
    position_sign_origin: Option<f64>,
    /// A friction while the stopper moves out (its velocity positive), N (e.g. 2): with
    /// --direction-friction-in, a friction whose level depends on the direction of travel.
    #[arg(long)]
    direction_friction_out: Option<f64>,
    /// A friction while the stopper moves in, N (e.g. 0.5).
    #[arg(long)]
    direction_friction_in: Option<f64>,
    /// A force on the piston μ (P1 − P_r) (chamber 1's pressure on an annulus the thesis leaves
    /// out): μ, m², of either sign (e.g. 1e-6).
    #[arg(long, allow_hyphen_values = true)]
    chamber_1_pressure_force: Option<f64>,
    /// The force reading passes through a second-order low-pass filter of this natural
    /// frequency, Hz (e.g. 40).
    #[arg(long)]
    force_sensor_filter: Option<f64>,
    /// With --force-sensor-filter: its damping ratio (1/√2 unless given).
    #[arg(long)]
    force_sensor_filter_damping: Option<f64>,
    /// The chamber 1 pressure reading passes through a second-order low-pass filter of this
    /// natural frequency, Hz (e.g. 40).
    #[arg(long)]
    pressure_sensor_filter_1: Option<f64>,
    /// With --pressure-sensor-filter-1: its damping ratio (1/√2 unless given).
    #[arg(long)]
    pressure_sensor_filter_damping_1: Option<f64>,
    /// The held command passes through a second-order low-pass filter of this natural
    /// frequency on its way to the current driver, Hz (e.g. 30).
    #[arg(long)]
    command_filter: Option<f64>,
    /// With --command-filter: its damping ratio (1/√2 unless given).
    #[arg(long)]
    command_filter_damping: Option<f64>,
    /// With --protocol: a thesis constant of the plant other than its default, NAME=VALUE in SI
    /// units, NAME a field of the bench's constants (k_spring, l_spring0, omega_cd, d_jp, ...);
    /// repeatable.
    #[arg(long, value_name = "NAME=VALUE")]
    plant: Vec<String>,
    /// With --protocol: the supply pressure, Pa (the thesis's 652 925 Pa by default).
    #[arg(long)]
    supply_pressure: Option<f64>,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    if cli.list_undeclared {
        for m in UNDECLARED {
            println!("{}\t{}\t{}\t{}", m.name, m.location, m.family, m.truth);
        }
        return ExitCode::SUCCESS;
    }
    let mut und = match cli.undeclared.as_deref() {
        None => UndeclaredEffects::default(),
        Some(name) => match undeclared_mechanism(name) {
            Some(m) => (m.effects)().undeclared,
            None => {
                let names: Vec<&str> = UNDECLARED.iter().map(|m| m.name).collect();
                eprintln!("benchgen: unknown undeclared mechanism {name:?}; one of {names:?}");
                return ExitCode::from(2);
            }
        },
    };
    let set = |dst: &mut f64, v: Option<f64>| {
        if let Some(v) = v {
            *dst = v;
        }
    };
    set(&mut und.pressure_sensor_offset_1, cli.pressure_sensor_offset_1);
    set(&mut und.supply_drift, cli.supply_drift);
    set(&mut und.supply_ripple_amplitude, cli.supply_ripple_amplitude);
    set(&mut und.supply_ripple_frequency, cli.supply_ripple_frequency);
    set(&mut und.command_limit, cli.command_limit);
    set(&mut und.current_slew_limit, cli.current_slew_limit);
    set(&mut und.jet_pipe_lag, cli.jet_pipe_lag);
    set(&mut und.chamber_leak_1, cli.chamber_leak_1);
    set(&mut und.viscous_friction, cli.viscous_friction);
    set(&mut und.contact_stiffness, cli.contact_stiffness);
    set(&mut und.force_sensor_lag, cli.force_sensor_lag);
    set(&mut und.return_back_pressure, cli.return_back_pressure);
    set(&mut und.pressure_sensor_delay_2, cli.pressure_sensor_delay_2);
    set(&mut und.receiver_offset, cli.receiver_offset);
    set(&mut und.force_sensor_backlash, cli.force_sensor_backlash);
    set(&mut und.jet_pipe_curve_blend, cli.jet_pipe_curve_blend);
    set(&mut und.return_area_reduction, cli.return_area_reduction);
    set(&mut und.port_1_restriction, cli.port_1_restriction);
    set(
        &mut und.force_sensor_pickup_amplitude,
        cli.force_sensor_pickup_amplitude,
    );
    set(
        &mut und.force_sensor_pickup_frequency,
        cli.force_sensor_pickup_frequency,
    );
    set(&mut und.command_dead_zone, cli.command_dead_zone);
    set(&mut und.command_upper_limit, cli.command_upper_limit);
    set(&mut und.command_quantum, cli.command_quantum);
    set(&mut und.force_sensor_saturation, cli.force_sensor_saturation);
    set(&mut und.moving_mass, cli.moving_mass);
    set(&mut und.seal_pressure_friction, cli.seal_pressure_friction);
    set(&mut und.quadratic_damping, cli.quadratic_damping);
    set(&mut und.friction_band, cli.friction_band);
    set(&mut und.pressure_sensor_saturation_1, cli.pressure_sensor_saturation);
    set(&mut und.pressure_sensor_quadratic_2, cli.pressure_sensor_quadratic);
    set(&mut und.stopper_position_offset, cli.stopper_position_offset);
    set(&mut und.contact_lag, cli.contact_lag);
    set(&mut und.gas_temperature_drift, cli.gas_temperature_drift);
    set(&mut und.bore_drift, cli.bore_drift);
    set(&mut und.friction_smoothing_velocity, cli.friction_smoothing_velocity);
    set(&mut und.discharge_ratio_rise, cli.discharge_ratio_rise);
    set(&mut und.supply_leak_2, cli.supply_leak_2);
    set(&mut und.laminar_leak_1, cli.laminar_leak_1);
    set(&mut und.laminar_supply_leak_2, cli.laminar_supply_leak_2);
    set(&mut und.laminar_cross_leak, cli.laminar_cross_leak);
    set(&mut und.difference_inflow_2, cli.difference_inflow_2);
    set(&mut und.position_sign_force, cli.position_sign_force);
    set(&mut und.position_sign_origin, cli.position_sign_origin);
    set(&mut und.chamber_1_pressure_force, cli.chamber_1_pressure_force);
    set(&mut und.direction_friction_out, cli.direction_friction_out);
    set(&mut und.direction_friction_in, cli.direction_friction_in);
    set(&mut und.force_sensor_filter_frequency, cli.force_sensor_filter);
    set(&mut und.force_sensor_filter_damping, cli.force_sensor_filter_damping);
    set(&mut und.pressure_sensor_filter_1, cli.pressure_sensor_filter_1);
    set(
        &mut und.pressure_sensor_filter_damping_1,
        cli.pressure_sensor_filter_damping_1,
    );
    set(&mut und.command_filter_frequency, cli.command_filter);
    set(&mut und.command_filter_damping, cli.command_filter_damping);
    let und_bad = [
        und.supply_ripple_frequency,
        und.command_limit,
        und.current_slew_limit,
        und.jet_pipe_lag,
        und.chamber_leak_1,
        und.viscous_friction,
        und.contact_stiffness,
        und.force_sensor_lag,
        und.pressure_sensor_delay_2,
        und.force_sensor_backlash,
        und.jet_pipe_curve_blend,
        und.return_area_reduction,
        und.port_1_restriction,
        und.force_sensor_pickup_frequency,
        und.command_dead_zone,
        und.command_upper_limit,
        und.command_quantum,
        und.force_sensor_saturation,
        und.moving_mass,
        und.seal_pressure_friction,
        und.quadratic_damping,
        und.friction_band,
        und.pressure_sensor_saturation_1,
        und.contact_lag,
        und.discharge_ratio_rise,
        und.supply_leak_2,
        und.laminar_leak_1,
        und.laminar_supply_leak_2,
        und.laminar_cross_leak,
        und.force_sensor_filter_frequency,
        und.force_sensor_filter_damping,
        und.pressure_sensor_filter_1,
        und.pressure_sensor_filter_damping_1,
        und.command_filter_frequency,
        und.command_filter_damping,
        und.friction_smoothing_velocity,
        und.direction_friction_out,
        und.direction_friction_in,
    ]
    .iter()
    .any(|&x| !x.is_finite() || x < 0.0)
        || ![
            und.pressure_sensor_offset_1,
            und.supply_drift,
            und.supply_ripple_amplitude,
            und.return_back_pressure,
            und.receiver_offset,
            und.force_sensor_pickup_amplitude,
            und.pressure_sensor_quadratic_2,
            und.stopper_position_offset,
            und.gas_temperature_drift,
            und.bore_drift,
            und.difference_inflow_2,
            und.position_sign_force,
            und.position_sign_origin,
            und.chamber_1_pressure_force,
        ]
        .iter()
        .all(|x| x.is_finite());
    let und_bad = und_bad
        || und.stopper_position_offset.abs() > 5e-3
        || und.gas_temperature_drift.abs() > 100.0
        || und.bore_drift.abs() > 0.1
        || und.discharge_ratio_rise > 1.0;
    let und_bad = und_bad || und.jet_pipe_curve_blend > 1.0 || und.return_area_reduction > 1.0;
    if und_bad {
        eprintln!(
            "benchgen: undeclared mechanism parameters must be finite; limits, lags, leak, \
             friction, moving mass, seal friction, damping, filter frequencies and dampings, stiffness, delay, backlash, restriction and ripple frequency non-negative; curve \
             blend, return area reduction and discharge ratio rise in 0..1; stopper position \
             offset within ±5 mm, gas temperature drift within ±100 K, bore drift within ±0.1"
        );
        return ExitCode::from(2);
    }
    let effects = BenchEffects {
        hysteresis_width: cli.hysteresis_width,
        friction_coulomb: cli.friction_coulomb,
        dead_volume_1: cli.dead_volume_1,
        dead_volume_2: cli.dead_volume_2,
        supply_resistance: cli.supply_resistance,
        heat_transfer: cli.heat_transfer,
        command_delay: cli.command_delay,
        force_sensor_offset: cli.force_sensor_offset,
        force_sensor_gain: cli.force_sensor_gain,
        undeclared: und,
    };
    let bad = |x: f64| !x.is_finite() || x < 0.0;
    if bad(cli.duration)
        || [
            effects.hysteresis_width,
            effects.friction_coulomb,
            effects.dead_volume_1,
            effects.dead_volume_2,
            effects.supply_resistance,
            effects.heat_transfer,
            effects.command_delay,
        ]
        .iter()
        .any(|&x| bad(x))
        || effects.heat_transfer > 1.0
        || !effects.force_sensor_offset.is_finite()
        || !effects.force_sensor_gain.is_finite()
    {
        eprintln!("benchgen: effect parameters must be finite and non-negative (heat transfer ≤ 1)");
        return ExitCode::from(2);
    }
    if let Some(name) = cli.protocol.as_deref() {
        let spec = match protocol_spec(&cli, name) {
            Ok(spec) => spec,
            Err(e) => {
                eprintln!("benchgen: {e}");
                return ExitCode::from(2);
            }
        };
        let start = Instant::now();
        let mut params = BenchParams::default();
        if let Some(p) = cli.supply_pressure {
            if !(p > params.p_return && p.is_finite()) {
                eprintln!(
                    "benchgen: --supply-pressure = {p} Pa must exceed the return pressure {} Pa",
                    params.p_return
                );
                return ExitCode::from(2);
            }
            params.p_supply = p;
        }
        for setting in &cli.plant {
            let parsed = setting
                .split_once('=')
                .and_then(|(name, value)| Some((name, value.trim().parse::<f64>().ok()?)));
            let Some((name, value)) = parsed.filter(|(_, v)| v.is_finite()) else {
                eprintln!("benchgen: --plant {setting:?} is not NAME=VALUE with a finite number");
                return ExitCode::from(2);
            };
            match params.field_mut(name.trim()) {
                Some(field) => *field = value,
                None => {
                    eprintln!("benchgen: --plant {name:?} is not a constant of the bench");
                    return ExitCode::from(2);
                }
            }
        }
        let recording = match generate_protocol_with(&params, &spec, &effects) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("benchgen: {e}");
                return ExitCode::from(2);
            }
        };
        if let Err(e) = recording.write_csv(&cli.out) {
            eprintln!("benchgen: cannot write {}: {e}", cli.out.display());
            return ExitCode::FAILURE;
        }
        eprintln!(
            "benchgen: {} rows of {} to {} in {:.2} s ({effects:?})",
            recording.rows.len(),
            spec.label(),
            cli.out.display(),
            start.elapsed().as_secs_f64()
        );
        return ExitCode::SUCCESS;
    }
    let start = Instant::now();
    let rows = generate(&effects, cli.seed, cli.duration);
    let elapsed = start.elapsed().as_secs_f64();
    if let Err(e) = write_csv(&rows, &cli.out) {
        eprintln!("benchgen: cannot write {}: {e}", cli.out.display());
        return ExitCode::FAILURE;
    }
    eprintln!(
        "benchgen: {} rows to {} in {elapsed:.2} s ({effects:?})",
        rows.len(),
        cli.out.display()
    );
    ExitCode::SUCCESS
}

/// The protocol of `--protocol` and the options that go with it.
fn protocol_spec(cli: &Cli, name: &str) -> Result<ProtocolSpec, String> {
    let number = |field: &str, text: &str| -> Result<f64, String> {
        text.parse::<f64>()
            .map_err(|_| format!("--stopper: {field} = {text:?} is not a number"))
    };
    let parts: Vec<&str> = cli.stopper.split(':').collect();
    let stopper = match parts.as_slice() {
        ["fixed", x] => StopperMotion::Fixed {
            position: number("position", x)?,
        },
        ["sine", c, a, f] => StopperMotion::Sine {
            centre: number("centre", c)?,
            amplitude: number("amplitude", a)?,
            frequency: number("frequency", f)?,
        },
        ["moves", v] => StopperMotion::Moves {
            speed: number("speed", v)?,
        },
        ["move", at, to, v] => StopperMotion::Move {
            at: number("at", at)?,
            to: number("to", to)?,
            speed: number("speed", v)?,
        },
        _ => {
            return Err(format!(
                "--stopper {:?} is not fixed:X, sine:CENTRE:AMPLITUDE:HZ, moves:SPEED or move:AT:TO:SPEED",
                cli.stopper
            ))
        }
    };
    let spec = ProtocolSpec {
        command: CommandProtocol::from_name(name)?,
        stopper,
        sample_rate: cli.sample_rate,
        duration: cli.duration,
        force_noise: cli.force_noise,
        pressure_noise: cli.pressure_noise,
        pressures: !cli.no_pressures,
        seed: cli.seed,
    };
    spec.check()?;
    Ok(spec)
}
