//! `benchgen`: write a synthetic bench recording (protocol of `bench/README.md`) from the
//! independent simulator in `jetpipe::synthetic_bench`, with chosen effects beyond the thesis model.

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

use clap::Parser;
use jetpipe::synthetic_bench::{generate, write_csv, BenchEffects, PROTOCOL_DURATION};

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
    /// Length of the recording, s (at most 80: the protocol is truncated).
    #[arg(long, default_value_t = PROTOCOL_DURATION)]
    duration: f64,
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
}

fn main() -> ExitCode {
    let cli = Cli::parse();
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
