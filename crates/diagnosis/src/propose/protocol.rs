//! What a bench can play: the command within the D/A's ±10 V, the stopper within 35–90 mm at
//! most 200 mm/s, evenly sampled, open loop; built from segments that a design draws at
//! random.

/// The D/A's range, V.
pub const COMMAND_LIMIT: f64 = 10.0;
/// The stopper's travel on the hand's bench, m.
pub const STOPPER_RANGE: (f64, f64) = (0.035, 0.090);
/// The stopper's fastest motion, m/s.
pub const STOPPER_SPEED: f64 = 0.2;
/// Where a protocol starts the stopper: the thesis bench's home position, m.
pub const STOPPER_HOME: f64 = 0.054;
/// The speed a segment moves the stopper to its new position at, m/s: below the limit, so
/// that sampling never rounds a move above it.
const MOVE_SPEED: f64 = 0.15;

/// A protocol: the command held from each sample to the next, the stopper linear between them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Protocol {
    pub rate: f64,
    pub time: Vec<f64>,
    pub v_da: Vec<f64>,
    pub x_s: Vec<f64>,
}

impl Protocol {
    /// Whether a bench can play it, or a message naming the first sample that it cannot.
    pub fn check(&self) -> Result<(), String> {
        for k in 0..self.time.len() {
            let (v, x) = (self.v_da[k], self.x_s[k]);
            if v.is_nan() || v.abs() > COMMAND_LIMIT {
                return Err(format!(
                    "v_da_V = {v} V at {} s is outside ±{COMMAND_LIMIT} V",
                    self.time[k]
                ));
            }
            if !(STOPPER_RANGE.0..=STOPPER_RANGE.1).contains(&x) {
                return Err(format!("x_s_m = {x} m at {} s is outside 35–90 mm", self.time[k]));
            }
            if k > 0 {
                let speed = (x - self.x_s[k - 1]).abs() * self.rate;
                if speed > STOPPER_SPEED * (1.0 + 1e-9) {
                    return Err(format!(
                        "the stopper moves at {speed:.4} m/s at {} s, above {STOPPER_SPEED} m/s",
                        self.time[k]
                    ));
                }
            }
        }
        Ok(())
    }

    /// The CSV a bench and `jetpipe diagnose` read: `time_s, v_da_V, x_s_m`.
    pub fn to_csv(&self) -> String {
        let mut out = String::from("time_s,v_da_V,x_s_m\n");
        for k in 0..self.time.len() {
            out.push_str(&format!("{:.6},{:.6},{:.7}\n", self.time[k], self.v_da[k], self.x_s[k]));
        }
        out
    }

    pub fn len(&self) -> usize {
        self.time.len()
    }

    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }
}

/// A small random number generator (SplitMix64): a proposal is the same for the same seed.
#[derive(Clone, Debug)]
pub struct Draws(u64);

impl Draws {
    pub fn new(seed: u64) -> Draws {
        Draws(seed)
    }

    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Log-uniform in [lo, hi).
    pub fn log_uniform(&mut self, lo: f64, hi: f64) -> f64 {
        self.uniform(lo.ln(), hi.ln()).exp()
    }

    pub fn pick(&mut self, n: usize) -> usize {
        ((self.next() >> 11) as f64 / (1u64 << 53) as f64 * n as f64) as usize % n.max(1)
    }
}

/// The command over a segment.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// Levels, each held for its duration (s), repeated to the segment's end.
    Steps(Vec<(f64, f64)>),
    Sine {
        offset: f64,
        amplitude: f64,
        hz: f64,
    },
    /// A linear chirp from `from_hz` to `to_hz` over the segment.
    Chirp {
        offset: f64,
        amplitude: f64,
        from_hz: f64,
        to_hz: f64,
    },
    /// A triangle between two levels.
    Ramps {
        low: f64,
        high: f64,
        period: f64,
    },
}

/// The stopper over a segment: first moved from where the last segment left it, at
/// 150 mm/s, then held or swung about its new position.
#[derive(Clone, Debug, PartialEq)]
pub enum Stopper {
    Held(f64),
    Swinging { centre: f64, amplitude: f64, hz: f64 },
}

/// One segment of a protocol.
#[derive(Clone, Debug, PartialEq)]
pub struct Segment {
    pub seconds: f64,
    pub command: Command,
    pub stopper: Stopper,
}

impl Command {
    fn at(&self, t: f64, seconds: f64) -> f64 {
        use std::f64::consts::TAU;
        let v = match self {
            Command::Steps(levels) => {
                let cycle: f64 = levels.iter().map(|(d, _)| d).sum();
                let mut into = t % cycle;
                let mut value = levels[0].1;
                for &(d, level) in levels {
                    value = level;
                    if into < d {
                        break;
                    }
                    into -= d;
                }
                value
            }
            Command::Sine { offset, amplitude, hz } => offset + amplitude * (TAU * hz * t).sin(),
            Command::Chirp {
                offset,
                amplitude,
                from_hz,
                to_hz,
            } => {
                let phase = TAU * (from_hz * t + (to_hz - from_hz) * t * t / (2.0 * seconds));
                offset + amplitude * phase.sin()
            }
            Command::Ramps { low, high, period } => {
                let u = (t / period).fract();
                let tri = if u < 0.5 { 2.0 * u } else { 2.0 - 2.0 * u };
                low + (high - low) * tri
            }
        };
        v.clamp(-COMMAND_LIMIT, COMMAND_LIMIT)
    }

    /// How a reader names it.
    pub fn describe(&self) -> String {
        match self {
            Command::Steps(levels) => format!(
                "steps through {}",
                levels
                    .iter()
                    .map(|(d, v)| format!("{v:.2} V for {d:.2} s"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            Command::Sine { offset, amplitude, hz } => {
                format!("a {hz:.2} Hz sine of ±{amplitude:.2} V about {offset:.2} V")
            }
            Command::Chirp {
                offset,
                amplitude,
                from_hz,
                to_hz,
            } => format!("a chirp from {from_hz:.2} to {to_hz:.2} Hz of ±{amplitude:.2} V about {offset:.2} V"),
            Command::Ramps { low, high, period } => {
                format!("ramps between {low:.2} and {high:.2} V, {period:.2} s a period")
            }
        }
    }
}

impl Stopper {
    fn target(&self) -> f64 {
        match *self {
            Stopper::Held(x) => x,
            Stopper::Swinging { centre, .. } => centre,
        }
    }

    pub fn describe(&self) -> String {
        match self {
            Stopper::Held(x) => format!("the stopper held at {:.1} mm", x * 1e3),
            Stopper::Swinging { centre, amplitude, hz } => format!(
                "the stopper swinging ±{:.1} mm about {:.1} mm at {hz:.2} Hz",
                amplitude * 1e3,
                centre * 1e3
            ),
        }
    }
}

impl Segment {
    /// A segment drawn at random, the stopper starting at `from`.
    pub fn draw(draws: &mut Draws, seconds: f64) -> Segment {
        let command = match draws.pick(4) {
            0 => {
                let (centre, spread) = (draws.uniform(-4.0, 6.0), draws.uniform(1.0, 8.0));
                let count = 2 + draws.pick(4);
                Command::Steps(
                    (0..count)
                        .map(|_| (draws.log_uniform(0.05, 2.0), centre + spread * draws.uniform(-1.0, 1.0)))
                        .collect(),
                )
            }
            1 => Command::Sine {
                offset: draws.uniform(-3.0, 5.0),
                amplitude: draws.uniform(0.5, 6.0),
                hz: draws.log_uniform(0.1, 40.0),
            },
            2 => {
                let from_hz = draws.log_uniform(0.1, 5.0);
                Command::Chirp {
                    offset: draws.uniform(-3.0, 5.0),
                    amplitude: draws.uniform(0.5, 6.0),
                    from_hz,
                    to_hz: from_hz * draws.log_uniform(2.0, 40.0),
                }
            }
            _ => {
                let low = draws.uniform(-8.0, 6.0);
                Command::Ramps {
                    low,
                    high: (low + draws.uniform(1.0, 10.0)).min(COMMAND_LIMIT),
                    period: draws.log_uniform(0.2, seconds.max(0.3)),
                }
            }
        };
        let (lo, hi) = STOPPER_RANGE;
        let stopper = if draws.pick(2) == 0 {
            Stopper::Held(draws.uniform(lo + 0.002, hi - 0.002))
        } else {
            let amplitude = draws.uniform(0.002, 0.02);
            let centre = draws.uniform(lo + amplitude + 0.001, hi - amplitude - 0.001);
            // The swing's fastest motion, 2π f A, stays below the move speed.
            let hz = draws.log_uniform(0.05, (MOVE_SPEED / (std::f64::consts::TAU * amplitude)).min(5.0));
            Stopper::Swinging { centre, amplitude, hz }
        };
        Segment {
            seconds,
            command,
            stopper,
        }
    }

    /// The segment's samples at `rate` from time `t0`, the stopper starting at `from`: the
    /// samples after `t0`, up to and including `t0 + seconds`.
    pub fn samples(&self, rate: f64, t0: f64, from: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = (self.seconds * rate).round() as usize;
        let target = self.stopper.target();
        let travel = (target - from).abs() / MOVE_SPEED;
        let (mut time, mut v, mut x) = (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
        for k in 1..=n {
            let t = k as f64 / rate;
            time.push(t0 + t);
            v.push(self.command.at(t, self.seconds));
            let position = if t < travel {
                from + (target - from) * t / travel
            } else {
                match self.stopper {
                    Stopper::Held(x) => x,
                    Stopper::Swinging { centre, amplitude, hz } => {
                        centre + amplitude * (std::f64::consts::TAU * hz * (t - travel)).sin()
                    }
                }
            };
            x.push(position.clamp(STOPPER_RANGE.0, STOPPER_RANGE.1));
        }
        (time, v, x)
    }

    /// The command at the segment's start.
    pub fn first_command(&self) -> f64 {
        self.command.at(0.0, self.seconds)
    }

    pub fn describe(&self) -> String {
        format!("{}; {}", self.command.describe(), self.stopper.describe())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_drawn_segment_is_one_a_bench_can_play_from_wherever_the_stopper_is() {
        let mut draws = Draws::new(7);
        for k in 0..400 {
            let from = [0.035, 0.054, 0.09][k % 3];
            let segment = Segment::draw(&mut draws, 5.0);
            let (time, v_da, x_s) = segment.samples(1000.0, 0.0, from);
            let mut protocol = Protocol {
                rate: 1000.0,
                time: vec![0.0],
                v_da: vec![v_da[0]],
                x_s: vec![from],
            };
            protocol.time.extend(time);
            protocol.v_da.extend(v_da);
            protocol.x_s.extend(x_s);
            assert_eq!(protocol.len(), 5001);
            protocol
                .check()
                .unwrap_or_else(|e| panic!("{}: {e}", segment.describe()));
        }
    }

    #[test]
    fn a_protocol_outside_the_bench_is_refused_with_the_sample_named() {
        let p = Protocol {
            rate: 1000.0,
            time: vec![0.0, 0.001, 0.002],
            v_da: vec![0.0, 1.0, 1.0],
            x_s: vec![0.054, 0.054, 0.0545],
        };
        let e = p.check().unwrap_err();
        assert!(e.contains("0.5000 m/s") && e.contains("0.002 s"), "{e}");
        let p = Protocol {
            v_da: vec![0.0, 10.5, 1.0],
            x_s: vec![0.054; 3],
            ..p
        };
        assert!(p.check().unwrap_err().contains("10.5 V"));
    }
}
