//! Protocols other than the bench's: the same plant and effects driven by random staircases,
//! multisines, PRBS, slow sines, ramps or a force-tracking controller, with the stopper fixed,
//! oscillating or moving between positions, sampled at 250 Hz–2 kHz for 20–3600 s with chosen
//! noise, and logged with or without the pressure channels. A diagnosis developed on the bench
//! protocol alone learns that protocol; these recordings are where it is tried on others.
//!
//! Every random choice comes from the protocol's seed (its own stream, apart from the sensor
//! noise's), so a [`ProtocolSpec`] names its recording.

use super::*;

/// The command's kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommandProtocol {
    /// Levels uniform in −3…9 V, each held 0.3–3 s.
    Staircase,
    /// Twelve sines, log-spaced 0.1–20 Hz, random phases, 0.6 V each, about 2.5 V.
    Multisine,
    /// A maximal-length 10-bit shift-register sequence between 0.5 and 4.5 V, 40 ms a bit.
    Prbs,
    /// One slow sine about 2.5 V, 4 V amplitude, at 0.1–1 Hz.
    Sine,
    /// Straight ramps between random levels in −3…9 V, 0.5–4 s each.
    Ramps,
    /// A PI controller on the logged force tracking a random staircase of forces (5–80 N,
    /// 1–4 s each), the command clamped to ±10 V, as a bench controller would run it.
    ForceTracking,
}

impl CommandProtocol {
    pub const ALL: [CommandProtocol; 6] = [
        CommandProtocol::Staircase,
        CommandProtocol::Multisine,
        CommandProtocol::Prbs,
        CommandProtocol::Sine,
        CommandProtocol::Ramps,
        CommandProtocol::ForceTracking,
    ];

    pub fn name(self) -> &'static str {
        match self {
            CommandProtocol::Staircase => "staircase",
            CommandProtocol::Multisine => "multisine",
            CommandProtocol::Prbs => "prbs",
            CommandProtocol::Sine => "sine",
            CommandProtocol::Ramps => "ramps",
            CommandProtocol::ForceTracking => "force_tracking",
        }
    }

    pub fn from_name(name: &str) -> Result<Self, String> {
        Self::ALL.iter().copied().find(|p| p.name() == name).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|p| p.name()).collect();
            format!("command protocol {name:?} is not one of {}", names.join(", "))
        })
    }
}

/// How the stopper moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StopperMotion {
    /// Held at `position` (m).
    Fixed { position: f64 },
    /// A sine about `centre` (m) of `amplitude` (m) at `frequency` (Hz).
    Sine {
        centre: f64,
        amplitude: f64,
        frequency: f64,
    },
    /// Moves of at least 5 mm between random positions in 35–80 mm at a peak speed of `speed`
    /// (m/s), with a half-cosine velocity profile, dwelling 0.5–2 s between moves.
    Moves { speed: f64 },
    /// One move from the home position to `to` (m) starting at `at` (s), at a peak speed of
    /// `speed` (m/s) with a half-cosine velocity profile: a stopper set once during a run.
    Move { at: f64, to: f64, speed: f64 },
}

/// The stopper positions a protocol may use (m): inside the cylinder's 26–96 mm with margin.
pub const STOPPER_RANGE: (f64, f64) = (0.030, 0.090);
/// Sampling rates a protocol may use (Hz).
pub const SAMPLE_RATE_RANGE: (f64, f64) = (250.0, 2000.0);
/// Lengths a protocol may have (s).
pub const DURATION_RANGE: (f64, f64) = (20.0, 3600.0);

/// A recording's protocol: what drives the plant, how it is sampled and how noisy it is.
#[derive(Clone, Debug, PartialEq)]
pub struct ProtocolSpec {
    pub command: CommandProtocol,
    pub stopper: StopperMotion,
    /// Hz; the period must be a whole number of the 20 µs integration steps.
    pub sample_rate: f64,
    /// s.
    pub duration: f64,
    /// RMS noise of the force sensor, N.
    pub force_noise: f64,
    /// RMS noise of each pressure transducer, Pa.
    pub pressure_noise: f64,
    /// Whether the recording carries the pressure channels.
    pub pressures: bool,
    /// Seed of the protocol's random choices and of the sensor noise.
    pub seed: u64,
}

impl Default for ProtocolSpec {
    fn default() -> Self {
        Self {
            command: CommandProtocol::Staircase,
            stopper: StopperMotion::Fixed { position: STOPPER_HOME },
            sample_rate: 1000.0,
            duration: 60.0,
            force_noise: 0.05,
            pressure_noise: 150.0,
            pressures: true,
            seed: 1,
        }
    }
}

impl ProtocolSpec {
    /// The protocol's checks: each refusal names the field, its value and the limit.
    pub fn check(&self) -> Result<(), String> {
        let (r0, r1) = SAMPLE_RATE_RANGE;
        if !(self.sample_rate >= r0 && self.sample_rate <= r1) {
            return Err(format!("sample_rate = {} Hz is outside {r0}–{r1} Hz", self.sample_rate));
        }
        let steps = 1.0 / (self.sample_rate * H);
        if (steps - steps.round()).abs() > 1e-9 {
            return Err(format!(
                "sample_rate = {} Hz: its period is not a whole number of the {H} s integration steps (try 250, 500, 1000, 1250 or 2000 Hz)",
                self.sample_rate
            ));
        }
        let (d0, d1) = DURATION_RANGE;
        if !(self.duration >= d0 && self.duration <= d1) {
            return Err(format!("duration = {} s is outside {d0}–{d1} s", self.duration));
        }
        if !(self.force_noise >= 0.0 && self.force_noise.is_finite()) {
            return Err(format!("force_noise = {} N must be finite and ≥ 0", self.force_noise));
        }
        if !(self.pressure_noise >= 0.0 && self.pressure_noise.is_finite()) {
            return Err(format!(
                "pressure_noise = {} Pa must be finite and ≥ 0",
                self.pressure_noise
            ));
        }
        let (x0, x1) = STOPPER_RANGE;
        let inside = |name: &str, x: f64| {
            if x >= x0 && x <= x1 {
                Ok(())
            } else {
                Err(format!("{name} = {x} m leaves the stopper range {x0}–{x1} m"))
            }
        };
        match self.stopper {
            StopperMotion::Fixed { position } => inside("stopper position", position)?,
            StopperMotion::Sine {
                centre,
                amplitude,
                frequency,
            } => {
                if !(amplitude >= 0.0 && frequency > 0.0 && frequency <= 20.0) {
                    return Err(format!(
                        "stopper sine: amplitude = {amplitude} m must be ≥ 0 and frequency = {frequency} Hz within (0, 20] Hz"
                    ));
                }
                inside("stopper centre − amplitude", centre - amplitude)?;
                inside("stopper centre + amplitude", centre + amplitude)?;
            }
            StopperMotion::Moves { speed } => {
                if !(speed > 0.0 && speed <= 1.0) {
                    return Err(format!("stopper speed = {speed} m/s is outside (0, 1] m/s"));
                }
            }
            StopperMotion::Move { at, to, speed } => {
                if !(speed > 0.0 && speed <= 1.0) {
                    return Err(format!("stopper speed = {speed} m/s is outside (0, 1] m/s"));
                }
                if !(at >= 0.0 && at < self.duration) {
                    return Err(format!(
                        "stopper move at = {at} s is outside the recording's 0–{} s",
                        self.duration
                    ));
                }
                inside("stopper move's end", to)?;
            }
        }
        Ok(())
    }

    /// A short name for file names and tables, e.g. `staircase_fixed54_1000hz_60s_p`.
    pub fn label(&self) -> String {
        let stopper = match self.stopper {
            StopperMotion::Fixed { position } => format!("fixed{:.0}", position * 1e3),
            StopperMotion::Sine { frequency, .. } => format!("shake{frequency}hz"),
            StopperMotion::Moves { speed } => format!("moves{:.0}mms", speed * 1e3),
            StopperMotion::Move { at, to, .. } => format!("move{:.0}at{at}s", to * 1e3),
        };
        format!(
            "{}_{stopper}_{}hz_{}s_{}",
            self.command.name(),
            self.sample_rate,
            self.duration,
            if self.pressures { "p" } else { "nop" }
        )
    }
}

/// A recording made under a protocol.
#[derive(Clone, Debug)]
pub struct ProtocolRecording {
    /// (time_s, v_da_V, x_s_m, force_N, p1_Pa, p2_Pa); the pressures are simulated even
    /// when the recording does not carry them.
    pub rows: Vec<[f64; 6]>,
    pub pressures: bool,
    /// For a force-tracking protocol, the reference force at each sample (N).
    pub reference: Option<Vec<f64>>,
}

impl ProtocolRecording {
    /// Write in the bench's CSV format, without the pressure columns when the protocol has
    /// none; times with enough decimals for the sampling rate.
    pub fn write_csv(&self, path: impl AsRef<Path>) -> std::io::Result<()> {
        let mut w = BufWriter::new(std::fs::File::create(path)?);
        if self.pressures {
            writeln!(w, "time_s,v_da_V,x_s_m,force_N,p1_Pa,p2_Pa")?;
        } else {
            writeln!(w, "time_s,v_da_V,x_s_m,force_N")?;
        }
        for r in &self.rows {
            write!(w, "{:.6},{:.6},{:.6},{:.4}", r[0], r[1], r[2], r[3])?;
            if self.pressures {
                write!(w, ",{:.1},{:.1}", r[4], r[5])?;
            }
            writeln!(w)?;
        }
        w.flush()
    }
}

/// The random choices of one part of a protocol (`part`: 1 the command, 2 the stopper, 3 the
/// tracked reference), each a stream apart from the others and from the sensor noise's.
fn choices(seed: u64, part: u64) -> Rng {
    Rng::new(seed ^ 0x005E_ED0F_9207_0C01_u64.wrapping_mul(part))
}

/// Piecewise-constant levels: (start time, level), the first at 0.
fn random_levels(rng: &mut Rng, duration: f64, level: (f64, f64), hold: (f64, f64)) -> Vec<(f64, f64)> {
    let mut out = vec![];
    let mut t = 0.0;
    while t <= duration {
        out.push((t, level.0 + (level.1 - level.0) * rng.uniform()));
        t += hold.0 + (hold.1 - hold.0) * rng.uniform();
    }
    out
}

fn level_at(levels: &[(f64, f64)], t: f64) -> f64 {
    let k = levels.partition_point(|(t0, _)| *t0 <= t);
    levels[k.saturating_sub(1)].1
}

/// The command of an open-loop protocol as a function of time (V, before D/A quantisation).
/// The force-tracking command is a controller, not a function of time: see
/// [`generate_protocol`].
pub fn command_signal(kind: CommandProtocol, seed: u64, duration: f64) -> Result<Box<dyn Fn(f64) -> f64>, String> {
    let rng = &mut choices(seed, 1);
    Ok(match kind {
        CommandProtocol::Staircase => {
            let levels = random_levels(rng, duration, (-3.0, 9.0), (0.3, 3.0));
            Box::new(move |t| level_at(&levels, t))
        }
        CommandProtocol::Multisine => {
            let lines: Vec<(f64, f64)> = (0..12)
                .map(|k| {
                    let f = 0.1 * (200.0f64).powf(k as f64 / 11.0);
                    (f, 2.0 * PI * rng.uniform())
                })
                .collect();
            Box::new(move |t| {
                2.5 + lines
                    .iter()
                    .map(|(f, phase)| 0.6 * (2.0 * PI * f * t + phase).sin())
                    .sum::<f64>()
            })
        }
        CommandProtocol::Prbs => {
            // x^10 + x^7 + 1: period 1023 bits (41 s at 40 ms a bit)
            let mut register: u32 = 1 + (rng.next_u64() % 1023) as u32;
            let bits = (duration / 0.040).ceil() as usize + 1;
            let sequence: Vec<bool> = (0..bits)
                .map(|_| {
                    let bit = ((register >> 9) ^ (register >> 6)) & 1;
                    register = ((register << 1) | bit) & 0x3FF;
                    bit == 1
                })
                .collect();
            Box::new(move |t| {
                // the bit clock ticks on sample instants: no rounding may move a tick a sample late
                let k = ((t / 0.040 + 1e-9).floor().max(0.0) as usize).min(sequence.len() - 1);
                if sequence[k] {
                    4.5
                } else {
                    0.5
                }
            })
        }
        CommandProtocol::Sine => {
            let f = 0.1 + 0.9 * rng.uniform();
            Box::new(move |t| 2.5 + 4.0 * (2.0 * PI * f * t).sin())
        }
        CommandProtocol::Ramps => {
            let corners = random_levels(rng, duration + 4.0, (-3.0, 9.0), (0.5, 4.0));
            Box::new(move |t| {
                let k = corners.partition_point(|(t0, _)| *t0 <= t).max(1);
                if k >= corners.len() {
                    return corners[corners.len() - 1].1;
                }
                let ((t0, v0), (t1, v1)) = (corners[k - 1], corners[k]);
                v0 + (v1 - v0) * (t - t0) / (t1 - t0)
            })
        }
        CommandProtocol::ForceTracking => {
            return Err("the force_tracking command is a controller on the logged force, not a function of time".into())
        }
    })
}

/// Proportional and integral gains of the force-tracking controller (V/N, V/(N·s)): about a
/// tenth of the plant's static force per volt in proportional gain, an integral crossover
/// near 0.5 Hz, below the open-loop bandwidth (0.8–2.8 Hz, §3.3.2).
const TRACKING_GAINS: (f64, f64) = (0.02, 0.6);
/// Where the controller's integrator starts (V): a mid-range force.
const TRACKING_START: f64 = 2.5;

/// The stopper's position (m) and velocity (m/s) as functions of time.
pub fn stopper_signal(motion: StopperMotion, seed: u64, duration: f64) -> Box<dyn Fn(f64) -> (f64, f64)> {
    let rng = &mut choices(seed, 2);
    match motion {
        StopperMotion::Fixed { position } => Box::new(move |_| (position, 0.0)),
        StopperMotion::Sine {
            centre,
            amplitude,
            frequency,
        } => {
            let w = 2.0 * PI * frequency;
            Box::new(move |t| (centre + amplitude * (w * t).sin(), amplitude * w * (w * t).cos()))
        }
        StopperMotion::Moves { speed } => {
            // (start, end of the move, from, to); dwell between moves
            let mut moves: Vec<(f64, f64, f64, f64)> = vec![];
            let (mut t, mut x) = (0.5, STOPPER_HOME);
            while t < duration {
                let mut to = 0.035 + 0.045 * rng.uniform();
                while (to - x).abs() < 0.005 {
                    to = 0.035 + 0.045 * rng.uniform();
                }
                // half-cosine profile: peak speed π/2 times the mean
                let length = 0.5 * PI * (to - x).abs() / speed;
                moves.push((t, t + length, x, to));
                x = to;
                t += length + 0.5 + 1.5 * rng.uniform();
            }
            along_moves(moves)
        }
        StopperMotion::Move { at, to, speed } => {
            let length = 0.5 * PI * (to - STOPPER_HOME).abs() / speed;
            along_moves(vec![(at, at + length, STOPPER_HOME, to)])
        }
    }
}

/// The stopper through `moves` (start, end of the move, from, to), each with a half-cosine
/// velocity profile, at home before the first.
fn along_moves(moves: Vec<(f64, f64, f64, f64)>) -> Box<dyn Fn(f64) -> (f64, f64)> {
    Box::new(move |t| {
        let k = moves.partition_point(|m| m.0 <= t);
        if k == 0 {
            return (STOPPER_HOME, 0.0);
        }
        let (t0, t1, x0, x1) = moves[k - 1];
        if t >= t1 {
            return (x1, 0.0);
        }
        let phase = PI * (t - t0) / (t1 - t0);
        (
            x0 + (x1 - x0) * 0.5 * (1.0 - phase.cos()),
            (x1 - x0) * 0.5 * phase.sin() * PI / (t1 - t0),
        )
    })
}

/// A recording of `effects` under the protocol `spec` (checked first).
pub fn generate_protocol(spec: &ProtocolSpec, effects: &BenchEffects) -> Result<ProtocolRecording, String> {
    generate_protocol_with(&BenchParams::default(), spec, effects)
}

/// [`generate_protocol`] for a plant whose thesis constants are `params` (a supply set low).
pub fn generate_protocol_with(
    params: &BenchParams,
    spec: &ProtocolSpec,
    effects: &BenchEffects,
) -> Result<ProtocolRecording, String> {
    spec.check()?;
    let stopper = stopper_signal(spec.stopper, spec.seed, spec.duration);
    let opts = RunOptions {
        noise_seed: Some(spec.seed),
        sample_period: 1.0 / spec.sample_rate,
        force_noise: spec.force_noise,
        pressure_noise: spec.pressure_noise,
        ..RunOptions::default()
    };
    let n = (spec.duration * spec.sample_rate).round() as usize;
    if spec.command == CommandProtocol::ForceTracking {
        let levels = random_levels(&mut choices(spec.seed, 3), spec.duration, (5.0, 80.0), (1.0, 4.0));
        let reference: Vec<f64> = (0..n).map(|k| level_at(&levels, k as f64 / spec.sample_rate)).collect();
        let (kp, ki) = TRACKING_GAINS;
        let period = opts.sample_period;
        let mut integral = TRACKING_START;
        let mut controller = |t: f64, measured: Option<f64>| -> f64 {
            let Some(force) = measured else {
                return TRACKING_START;
            };
            let error = level_at(&levels, t) - force;
            let unclamped = integral + kp * error;
            // anti-windup: the integrator only moves while the command is inside the D/A range
            if unclamped.abs() < 10.0 || unclamped.signum() != error.signum() {
                integral += ki * error * period;
            }
            (integral + kp * error).clamp(-10.0, 10.0)
        };
        let rows = run(
            params,
            effects,
            CommandSource::Closed(&mut controller),
            &*stopper,
            n,
            &opts,
        );
        return Ok(ProtocolRecording {
            rows,
            pressures: spec.pressures,
            reference: Some(reference),
        });
    }
    let command = command_signal(spec.command, spec.seed, spec.duration)?;
    let rows = run(params, effects, CommandSource::Open(&*command), &*stopper, n, &opts);
    Ok(ProtocolRecording {
        rows,
        pressures: spec.pressures,
        reference: None,
    })
}
