//! Effects the thesis model lacks (docs/model.md, "Effects and correction terms"). Each is
//! off at its parameter's default, and then the model is the thesis model exactly.
//!
//! | name | parameter(s) | where it acts |
//! |---|---|---|
//! | `jet_pipe_hysteresis` | `hysteresis_width`, `hysteresis_deadband` (m), `hysteresis_exponent`, `hysteresis_gain`, `hysteresis_beta_share` (1) | on f3's output, before the jet pipe dynamics (§3.2.1–3.2.2): a Prandtl–Ishlinskii operator, or with an exponent a smooth Bouc–Wen law (see [`Hysteresis`]) |
//! | `piston_friction` | `friction_coulomb` (N), `friction_velocity` (m/s), `friction_stribeck` (N), `friction_stribeck_velocity` (m/s) | rod force while the stopper moves, (2.33)–(2.35) |
//! | `dead_volume` | `dead_volume_1`, `dead_volume_2` (m³) | added to (2.30)–(2.31) |
//! | `supply_pressure_drop` | `supply_resistance` (Pa·s/kg), or `supply_restriction_area` (m²) with `supply_plenum_volume` (m³) | supply pressure at the jet pipe (§2.6; see [`super::restrictions`]) |
//! | `heat_transfer` | `heat_transfer_fraction` (1) | polytropic exponent in (2.29) |
//! | `transport_delay` | `command_delay` (s) | command seen by the current driver |
//! | `sensor_offset_gain` | `force_sensor_offset` (N), `force_sensor_gain` (1) | the `F_meas` output (see [`super::sensors`]) |

/// The names of the effects, as reports and parameters use them.
pub const EFFECT_NAMES: [&str; 7] = [
    "jet_pipe_hysteresis",
    "piston_friction",
    "dead_volume",
    "supply_pressure_drop",
    "heat_transfer",
    "transport_delay",
    "sensor_offset_gain",
];

/// Number of play operators of the Prandtl–Ishlinskii hysteresis operator.
pub const PLAY_OPERATORS: usize = 16;

/// A Prandtl–Ishlinskii operator: the mean of [`PLAY_OPERATORS`] play (backlash)
/// operators whose half-widths are the quantiles of an exponential distribution. Unlike
/// Frame's model (§3.2.2), it predicts minor loops: after a reversal the output stays
/// put until the input has moved by the smallest width, then bends onto the new branch
/// as more plays are dragged along, and a closed minor loop returns to where it began.
/// In a large sweep the two branches are `width` apart (mean half-width = width/2), and
/// the output's slope far from reversals is the input's (unit total weight).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PrandtlIshlinskii {
    pub half_widths: [f64; PLAY_OPERATORS],
}

impl PrandtlIshlinskii {
    /// `deadband` (≤ `width`) is the smallest play's full width: how far the input must
    /// travel after a reversal before the output moves at all.
    pub fn new(width: f64, deadband: f64) -> Self {
        let deadband = deadband.clamp(0.0, width);
        let mut half_widths = [0.0; PLAY_OPERATORS];
        let mut sum = 0.0;
        for (k, r) in half_widths.iter_mut().enumerate() {
            let q = (k as f64 + 0.5) / PLAY_OPERATORS as f64;
            *r = -(1.0 - q).ln();
            sum += *r;
        }
        // Scale the spread so the mean half-width is exactly width/2.
        let spread = 0.5 * (width - deadband);
        let scale = if sum > 0.0 {
            spread * PLAY_OPERATORS as f64 / sum
        } else {
            0.0
        };
        for r in half_widths.iter_mut() {
            *r = 0.5 * deadband + *r * scale;
        }
        Self { half_widths }
    }

    pub fn is_active(&self) -> bool {
        self.half_widths.iter().any(|&r| r > 0.0)
    }

    /// Play states after the input moves monotonically to `input`.
    pub fn advance(&self, plays: &mut [f64; PLAY_OPERATORS], input: f64) {
        for (p, r) in plays.iter_mut().zip(&self.half_widths) {
            *p = p.clamp(input - r, input + r);
        }
    }

    /// Output for plays that moved monotonically from `plays` to `input` (the plays
    /// themselves are not changed).
    pub fn output_after(&self, plays: &[f64; PLAY_OPERATORS], input: f64) -> f64 {
        let sum: f64 = plays
            .iter()
            .zip(&self.half_widths)
            .map(|(p, r)| p.clamp(input - r, input + r))
            .sum();
        sum / PLAY_OPERATORS as f64
    }

    pub fn output(plays: &[f64; PLAY_OPERATORS]) -> f64 {
        plays.iter().sum::<f64>() / PLAY_OPERATORS as f64
    }
}

/// The jet_pipe_hysteresis operator between f3's output x̄ and the jet pipe dynamics, by
/// law. Its memory is an array of [`PLAY_OPERATORS`] numbers whatever the law, all equal to
/// x̄ in the anhysteretic state (the state a long decaying oscillation leaves), so the
/// simulation, the fast replay and the FMU state carry it alike.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hysteresis {
    /// Rate-independent, with closed minor loops (congruent, wiping out).
    Play(PrandtlIshlinskii),
    /// Smooth, and minor loops that do not close: under a steady oscillation the output
    /// creeps to the middle of the loop.
    BoucWen(BoucWen),
}

impl Hysteresis {
    /// `exponent` = 0 selects the play law (with `deadband`); > 0 the Bouc–Wen law with
    /// that exponent, `gain` and `beta_share` (its deadband must be 0, see
    /// `Parameters::validate`). `width` = 0 turns the effect off (a play law of no width).
    pub fn new(width: f64, deadband: f64, exponent: f64, gain: f64, beta_share: f64) -> Self {
        if width > 0.0 && exponent > 0.0 {
            Hysteresis::BoucWen(BoucWen {
                half_width: 0.5 * width,
                exponent,
                gain,
                beta_share,
            })
        } else {
            Hysteresis::Play(PrandtlIshlinskii::new(width, deadband))
        }
    }

    pub fn is_active(&self) -> bool {
        match self {
            Hysteresis::Play(op) => op.is_active(),
            Hysteresis::BoucWen(_) => true,
        }
    }

    /// The memory after the input moves monotonically to `input`.
    pub fn advance(&self, memory: &mut [f64; PLAY_OPERATORS], input: f64) {
        match self {
            Hysteresis::Play(op) => op.advance(memory, input),
            Hysteresis::BoucWen(law) => {
                let output = law.output_after(memory, input);
                *memory = [input; PLAY_OPERATORS];
                memory[BoucWen::OUTPUT] = output;
            }
        }
    }

    /// The output for an input that moved monotonically from `memory`'s to `input` (the
    /// memory itself is not changed).
    pub fn output_after(&self, memory: &[f64; PLAY_OPERATORS], input: f64) -> f64 {
        match self {
            Hysteresis::Play(op) => op.output_after(memory, input),
            Hysteresis::BoucWen(law) => law.output_after(memory, input),
        }
    }

    /// The output of a memory.
    pub fn output(&self, memory: &[f64; PLAY_OPERATORS]) -> f64 {
        match self {
            Hysteresis::Play(_) => PrandtlIshlinskii::output(memory),
            Hysteresis::BoucWen(_) => memory[BoucWen::OUTPUT],
        }
    }

    /// The memory at the start of a run with the static position at `x_bar`: `start` (in
    /// half-widths, see `hysteresis_start`) is where the output stands in the loop, 0 in
    /// its middle, +1 on the rising branch (the input came from below), −1 on the falling
    /// one.
    pub fn initial_memory(&self, x_bar: f64, start: f64) -> [f64; PLAY_OPERATORS] {
        let mut memory = [x_bar; PLAY_OPERATORS];
        if start != 0.0 {
            match self {
                Hysteresis::Play(op) => {
                    for (p, r) in memory.iter_mut().zip(&op.half_widths) {
                        *p = x_bar - start * r;
                    }
                }
                Hysteresis::BoucWen(law) => memory[BoucWen::OUTPUT] = x_bar - start * law.half_width,
            }
        }
        memory
    }

    /// The input scale of the law: the half-width of the Bouc–Wen law, the widest play's.
    pub fn scale(&self) -> f64 {
        match self {
            Hysteresis::Play(op) => op.half_widths.iter().fold(0.0, |m: f64, &r| m.max(r)),
            Hysteresis::BoucWen(law) => law.half_width,
        }
    }

    /// The plays' half-widths (play law only): where the output's slope jumps, which the
    /// propagator's closed forms and quadrature panels use.
    pub fn play_half_widths(&self) -> Option<&[f64; PLAY_OPERATORS]> {
        match self {
            Hysteresis::Play(op) => Some(&op.half_widths),
            _ => None,
        }
    }
}

/// A Bouc–Wen hysteresis on the static tip position x̄: the output is x̄ − z, with
///
///   dz/dx̄ = A [1 − (a sgn(dx̄ z) + 1 − a) |z/r|ⁿ],
///
/// r the half-width (z saturates at ±r after a large sweep, so the branches are 2r
/// apart), n the exponent (sharpness of the bend onto a branch: large n approaches a
/// backlash), A the gain (A = 1: the output stops at a reversal when a = ½), and a the
/// share of β in β + γ of the usual form (a = ½: symmetric, the output stands still
/// after a reversal until z has crossed zero). Rate-independent, so it is integrated in x̄
/// (fourth-order Runge–Kutta, steps of r/32, error below 1e-9 r), not in time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWen {
    pub half_width: f64,
    pub exponent: f64,
    pub gain: f64,
    pub beta_share: f64,
}

impl BoucWen {
    /// Where the memory keeps the input it last saw and the output there.
    const INPUT: usize = 0;
    const OUTPUT: usize = 1;
    /// Knots of a branch per half-width of input travel: the cubic Hermite interpolant
    /// between them is within 1e-9 r of the branch for exponents from 1 to 8 (the test
    /// `a_bouc_wen_branch_from_its_knots_agrees_with_fine_direct_integration`).
    const KNOTS_PER_HALF_WIDTH: f64 = 256.0;
    /// Beyond this many knots a branch is integrated directly (a width far below the
    /// input's travel, where the law is a play to rounding anyway).
    const MAX_KNOTS: f64 = 32768.0;
    /// At most this many steps of a knot's spacing in a direct integration: a branch reaches
    /// its asymptote long before unless the law is slower than any fitted one (A n ≲ 0.01).
    const MAX_DIRECT_STEPS: usize = 1 << 20;

    /// dw/dv in units of the half-width (w = z/r, v = x̄/r), moving in `direction`.
    fn slope(&self, w: f64, direction: f64) -> f64 {
        let sign = if direction * w > 0.0 { 1.0 } else { -1.0 };
        let share = self.beta_share * sign + 1.0 - self.beta_share;
        self.gain * (1.0 - share * w.abs().powf(self.exponent))
    }

    /// One classical Runge–Kutta step of `h` (in v) from `w`. The slope has a kink where z
    /// changes sign (the law's coefficient switches there), so a step that crosses zero is
    /// split at the crossing, found by a step of dv/dw on the near side.
    fn runge_kutta(&self, w: f64, h: f64, direction: f64) -> f64 {
        let next = self.smooth_step(w, h, direction);
        if w == 0.0 || next == 0.0 || next.signum() == w.signum() {
            return next;
        }
        let dv_dw = |x: f64| 1.0 / self.slope(x, direction);
        let (k1, k2, k4) = (dv_dw(w), dv_dw(0.5 * w), dv_dw(0.0));
        let to_zero = -w / 6.0 * (k1 + 4.0 * k2 + k4);
        if !(to_zero * h > 0.0 && to_zero.abs() < h.abs()) {
            return next;
        }
        self.smooth_step(0.0, h - to_zero, direction)
    }

    fn smooth_step(&self, w: f64, h: f64, direction: f64) -> f64 {
        let k1 = self.slope(w, direction);
        let k2 = self.slope(w + 0.5 * h * k1, direction);
        let k3 = self.slope(w + 0.5 * h * k2, direction);
        let k4 = self.slope(w + h * k3, direction);
        w + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    }

    /// w after a travel of more half-widths than the knots reach. The branch rises
    /// monotonically to its asymptote w = ±1 (in the travel's direction), where the slope
    /// vanishes and it stays: steps of a knot's spacing until it is there to rounding. A law
    /// so slow that it is not there after [`Self::MAX_DIRECT_STEPS`] covers the rest in
    /// [`Self::MAX_KNOTS`] equal steps, each kept short of the asymptote, so the work has a
    /// bound whatever the travel.
    fn far_along_branch(&self, w0: f64, travel: f64) -> f64 {
        let direction = travel.signum();
        let toward_asymptote = |w: f64| if direction > 0.0 { w.min(1.0) } else { w.max(-1.0) };
        let spacing = 1.0 / Self::KNOTS_PER_HALF_WIDTH;
        let mut left = travel.abs();
        let mut w = w0;
        for _ in 0..Self::MAX_DIRECT_STEPS {
            if left <= 0.0 {
                return w;
            }
            let h = spacing.min(left);
            let next = toward_asymptote(self.runge_kutta(w, h * direction, direction));
            if next == w {
                return w;
            }
            w = next;
            left -= h;
        }
        if left <= 0.0 {
            return w;
        }
        let h = left / Self::MAX_KNOTS * direction;
        for _ in 0..Self::MAX_KNOTS as usize {
            w = toward_asymptote(self.runge_kutta(w, h, direction));
        }
        w
    }

    /// The output for an input moved monotonically from the memory's to `input`.
    ///
    /// A branch (the law integrated from the memory in one direction) is a function of the
    /// memory alone, so its knots, one Runge–Kutta step apart on a grid anchored at the
    /// memory's input, are kept per thread and shared by every query from that memory: the
    /// propagator asks for the output at up to about 160 instants of a step (its quadrature),
    /// or at 5 (to place a parabola), all from the step's starting memory. The result depends
    /// only on the arguments (the knots are a cache, not a state).
    pub fn output_after(&self, memory: &[f64; PLAY_OPERATORS], input: f64) -> f64 {
        let r = self.half_width;
        let from = memory[Self::INPUT];
        let travel = (input - from) / r;
        let w0 = (from - memory[Self::OUTPUT]) / r;
        if travel == 0.0 || !travel.is_finite() {
            return input - r * w0;
        }
        let direction = travel.signum();
        let position = travel.abs() * Self::KNOTS_PER_HALF_WIDTH;
        if position > Self::MAX_KNOTS {
            return input - r * self.far_along_branch(w0, travel);
        }
        let h = direction / Self::KNOTS_PER_HALF_WIDTH;
        let k = position.floor() as usize;
        let t = position - k as f64;
        let key = BranchKey {
            law: [self.half_width, self.exponent, self.gain, self.beta_share].map(f64::to_bits),
            from: from.to_bits(),
            w0: w0.to_bits(),
            direction: direction > 0.0,
        };
        let w = BRANCH.with(|cell| {
            let mut branch = cell.borrow_mut();
            if branch.key != Some(key) {
                branch.key = Some(key);
                branch.knots.clear();
                branch.knots.push((w0, self.slope(w0, direction)));
            }
            while branch.knots.len() < k + 2 {
                let (last, _) = branch.knots[branch.knots.len() - 1];
                let next = self.runge_kutta(last, h, direction);
                branch.knots.push((next, self.slope(next, direction)));
            }
            let ((wa, sa), (wb, sb)) = (branch.knots[k], branch.knots[k + 1]);
            // Cubic Hermite on [k, k+1] with the law's own slopes at the knots.
            let t2 = t * t;
            let t3 = t2 * t;
            (2.0 * t3 - 3.0 * t2 + 1.0) * wa
                + (t3 - 2.0 * t2 + t) * h * sa
                + (-2.0 * t3 + 3.0 * t2) * wb
                + (t3 - t2) * h * sb
        });
        input - r * w
    }
}

/// What a branch of the Bouc–Wen law depends on, bit for bit.
#[derive(Clone, Copy, PartialEq, Eq)]
struct BranchKey {
    law: [u64; 4],
    from: u64,
    w0: u64,
    direction: bool,
}

struct Branch {
    key: Option<BranchKey>,
    /// (w, dw/dv) at the memory's input plus k steps of the grid.
    knots: Vec<(f64, f64)>,
}

thread_local! {
    static BRANCH: std::cell::RefCell<Branch> = const { std::cell::RefCell::new(Branch { key: None, knots: Vec::new() }) };
}

/// Polytropic exponent of the chambers: γ for adiabatic chambers (the thesis, (2.29)),
/// 1 for isothermal ones; `fraction` goes linearly between them.
pub fn polytropic_exponent(gamma: f64, heat_transfer_fraction: f64) -> f64 {
    gamma - heat_transfer_fraction * (gamma - 1.0)
}

/// Coulomb friction on the rod force, opposing the stopper velocity (2.35); zero at rest
/// (stiction holds whatever force the pressures give, and the prescribed stopper does not
/// stick).
///
/// With `friction_velocity` > 0 the law is smooth, F_c tanh(v / v_c): seals that deform
/// before they slide reach the Coulomb level over a speed v_c instead of at once.
///
/// A Stribeck term adds `stribeck` · exp(−(v/v_s)²) to the level: the seals stick harder at
/// low speed than they slide at high speed.
pub fn friction_force(
    friction_coulomb: f64,
    friction_velocity: f64,
    stribeck: f64,
    stribeck_velocity: f64,
    stopper_velocity: f64,
) -> f64 {
    let mut level = friction_coulomb;
    if stribeck != 0.0 && stribeck_velocity > 0.0 {
        level += stribeck * (-(stopper_velocity / stribeck_velocity).powi(2)).exp();
    }
    if friction_velocity > 0.0 {
        level * (stopper_velocity / friction_velocity).tanh()
    } else if stopper_velocity.abs() < 1e-9 {
        0.0
    } else {
        level * stopper_velocity.signum()
    }
}

/// Supply pressure at the jet pipe when a supply line of resistance `resistance` (Pa·s/kg)
/// carries the supply mass flow `supply_flow(p)` drawn at that pressure: the root of
/// p = P_s − R ṁ(p). ṁ rises with p, and at `lowest` (the lower chamber pressure) no air
/// leaves the supply, so the root lies in [lowest, P_s]; the Illinois variant of regula
/// falsi finds it without leaving the bracket, however large R is.
#[inline]
pub fn supply_pressure_at_jet(p_s: f64, resistance: f64, lowest: f64, supply_flow: impl Fn(f64) -> f64) -> f64 {
    // Without the effect (the default) this is every right-hand side's first question:
    // answered inline, the root search stays out of line.
    if resistance == 0.0 {
        return p_s;
    }
    supply_pressure_through_line(p_s, resistance, lowest, supply_flow)
}

#[inline(never)]
fn supply_pressure_through_line(p_s: f64, resistance: f64, lowest: f64, supply_flow: impl Fn(f64) -> f64) -> f64 {
    increasing_root(lowest.min(p_s), p_s, |p| p - p_s + resistance * supply_flow(p))
}

/// Pressure that the return orifices vent into when the return line has a resistance
/// `resistance` (Pa·s/kg) to the return pressure `p_r`: the root of p = P_r + R ṁ(p),
/// with ṁ(p) the return mass flow, which falls as p rises. At `highest` (the higher
/// chamber pressure) no air enters the line, so the root lies in [P_r, highest].
#[inline]
pub fn return_pressure_at_vent(p_r: f64, resistance: f64, highest: f64, return_flow: impl Fn(f64) -> f64) -> f64 {
    if resistance == 0.0 {
        return p_r;
    }
    return_pressure_through_line(p_r, resistance, highest, return_flow)
}

#[inline(never)]
fn return_pressure_through_line(p_r: f64, resistance: f64, highest: f64, return_flow: impl Fn(f64) -> f64) -> f64 {
    increasing_root(p_r, highest.max(p_r), |p| p - p_r - resistance * return_flow(p))
}

/// Pressure that the orifices of a port see when a restriction of `resistance` (Pa·s/kg)
/// lies between them and the chamber: the root of q = P_chamber + R ṁ(q), with ṁ(q) the
/// net flow into the port (supply in, return out), which falls as q rises. The root lies
/// between the lowest and the highest of the chamber, supply and return pressures.
#[inline]
pub fn port_pressure(chamber: f64, resistance: f64, p_s: f64, p_r: f64, net_inflow: impl Fn(f64) -> f64) -> f64 {
    if resistance == 0.0 {
        return chamber;
    }
    port_pressure_through_restriction(chamber, resistance, p_s, p_r, net_inflow)
}

#[inline(never)]
fn port_pressure_through_restriction(
    chamber: f64,
    resistance: f64,
    p_s: f64,
    p_r: f64,
    net_inflow: impl Fn(f64) -> f64,
) -> f64 {
    let (lo, hi) = (chamber.min(p_r).min(p_s), chamber.max(p_s).max(p_r));
    increasing_root(lo, hi, |q| q - chamber - resistance * net_inflow(q))
}

/// The root in [a, b] of an increasing `residual` (the end nearest the sign change when
/// the bracket holds none): the Illinois variant of regula falsi, which never leaves the
/// bracket however steep the residual is.
pub(crate) fn increasing_root(a: f64, b: f64, residual: impl Fn(f64) -> f64) -> f64 {
    let scale = a.abs().max(b.abs());
    let (mut a, mut fa) = (a, residual(a));
    let (mut b, mut fb) = (b, residual(b));
    if fb <= 0.0 {
        return b;
    }
    if fa >= 0.0 {
        return a;
    }
    let mut side = 0;
    for iteration in 0..200 {
        // Every third iteration bisect, so the bracket halves whatever the curvature.
        let c = if iteration % 3 == 2 {
            0.5 * (a + b)
        } else {
            (a * fb - b * fa) / (fb - fa)
        };
        let fc = residual(c);
        if fc.abs() < 1e-10 * scale || (b - a).abs() < 1e-12 * scale {
            return c;
        }
        if fc > 0.0 {
            b = c;
            fb = fc;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            a = c;
            fa = fc;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sweep(op: &PrandtlIshlinskii, plays: &mut [f64; PLAY_OPERATORS], from: f64, to: f64) -> Vec<(f64, f64)> {
        (0..=200)
            .map(|k| {
                let x = from + (to - from) * k as f64 / 200.0;
                op.advance(plays, x);
                (x, PrandtlIshlinskii::output(plays))
            })
            .collect()
    }

    #[test]
    fn large_sweeps_have_branches_width_apart() {
        let width = 0.16e-3;
        let op = PrandtlIshlinskii::new(width, 0.0);
        let mut plays = [0.0; PLAY_OPERATORS];
        sweep(&op, &mut plays, 0.0, -1e-3);
        let rising = sweep(&op, &mut plays, -1e-3, 1e-3);
        let falling = sweep(&op, &mut plays, 1e-3, -1e-3);
        // At x = 0 on both branches, far from the reversals:
        let up = rising[100].1;
        let down = falling[100].1;
        assert!(
            ((down - up) - width).abs() < 1e-3 * width,
            "separation {} vs {width}",
            down - up
        );
    }

    #[test]
    fn minor_loops_close_and_stay_inside_the_major_loop() {
        let op = PrandtlIshlinskii::new(0.16e-3, 0.05e-3);
        let mut plays = [0.0; PLAY_OPERATORS];
        sweep(&op, &mut plays, 0.0, -1e-3);
        sweep(&op, &mut plays, -1e-3, 0.2e-3);
        let before = PrandtlIshlinskii::output(&plays);
        let saved = plays;
        sweep(&op, &mut plays, 0.2e-3, 0.05e-3);
        sweep(&op, &mut plays, 0.05e-3, 0.2e-3);
        // Return-point memory: the minor loop closes where it began.
        assert!((PrandtlIshlinskii::output(&plays) - before).abs() < 1e-15);
        for (a, b) in plays.iter().zip(&saved) {
            assert!((a - b).abs() < 1e-18, "{a} vs {b}");
        }
    }

    /// The Bouc–Wen law of the synthetic bench (n = 1, A = 0.5, a = 0.75) and of rec_01's fit.
    fn bouc_wen(exponent: f64, gain: f64, beta_share: f64) -> Hysteresis {
        Hysteresis::new(0.16e-3, 0.0, exponent, gain, beta_share)
    }

    /// The law's output along a piecewise-linear input path, 50 points per leg.
    fn follow(law: &Hysteresis, memory: &mut [f64; PLAY_OPERATORS], corners: &[f64]) -> Vec<(f64, f64)> {
        let mut out = vec![];
        for leg in corners.windows(2) {
            for k in 1..=50 {
                let x = leg[0] + (leg[1] - leg[0]) * k as f64 / 50.0;
                law.advance(memory, x);
                out.push((x, law.output(memory)));
            }
        }
        out
    }

    #[test]
    fn bouc_wen_branches_end_a_width_apart_after_large_sweeps() {
        for (n, gain, share) in [(1.0, 0.5, 0.75), (3.7, 1.0, 0.52), (8.0, 1.0, 0.5)] {
            let law = bouc_wen(n, gain, share);
            let mut memory = [0.0; PLAY_OPERATORS];
            // Far past the loop (40 half-widths) both ways: z saturates at ±r.
            follow(&law, &mut memory, &[0.0, -3.2e-3]);
            let rising = follow(&law, &mut memory, &[-3.2e-3, 3.2e-3]);
            let falling = follow(&law, &mut memory, &[3.2e-3, -3.2e-3]);
            // Output minus input (−z) at the path's point nearest to x.
            let at = |path: &[(f64, f64)], x: f64| {
                let (px, py) = path
                    .iter()
                    .min_by(|a, b| (a.0 - x).abs().total_cmp(&(b.0 - x).abs()))
                    .unwrap();
                py - px
            };
            for x in [-1.6e-3, 1.6e-3] {
                let gap = at(&falling, x) - at(&rising, x);
                assert!(
                    (gap - 0.16e-3).abs() < 1e-3 * 0.16e-3,
                    "n {n}: branches {gap} m apart at {x} m"
                );
            }
        }
    }

    #[test]
    fn after_a_reversal_the_symmetric_bouc_wen_output_stands_still_until_z_changes_sign() {
        // A = 1, a = 1/2: dz/dx = 1 while |z| shrinks, so the output x - z does not move.
        let law = bouc_wen(3.0, 1.0, 0.5);
        let mut memory = [0.0; PLAY_OPERATORS];
        follow(&law, &mut memory, &[0.0, 1e-3]);
        let top = law.output(&memory);
        let back = follow(&law, &mut memory, &[1e-3, 1e-3 - 0.07e-3]);
        for (x, y) in back {
            assert!((y - top).abs() < 1e-12, "at {x} m the output moved from {top} to {y}");
        }
    }

    #[test]
    fn under_a_steady_oscillation_bouc_wen_creeps_to_the_middle_where_plays_close_their_loop() {
        // From the falling branch, cycles of ±0.05 mm (less than the 0.16 mm width) about
        // 0.2 mm: the backlash's minor loop closes, each cycle ends where the first did (0.03
        // mm above the middle), while the Bouc–Wen loop keeps drifting to the middle, as
        // rec_01's loops at 38-50 s do.
        let cycle = [0.25e-3, 0.15e-3, 0.2e-3];
        let smooth = bouc_wen(3.7, 1.0, 0.52);
        let backlash = Hysteresis::new(0.16e-3, 0.16e-3, 0.0, 1.0, 0.5);
        for law in [smooth, backlash] {
            let mut memory = law.initial_memory(0.2e-3, -1.0);
            let mut ends = vec![];
            let mut x = 0.2e-3;
            for _ in 0..40 {
                for &corner in &cycle {
                    follow(&law, &mut memory, &[x, corner]);
                    x = corner;
                }
                ends.push(law.output(&memory) - 0.2e-3);
            }
            let (first, last) = (ends[0], ends[39]);
            match law {
                Hysteresis::BoucWen(_) => assert!(
                    last.abs() < 0.1 * first.abs() && last.abs() < 0.05 * 0.08e-3,
                    "Bouc–Wen: {first} m from the middle after one cycle, {last} m after 40"
                ),
                Hysteresis::Play(_) => assert!((last - first).abs() < 1e-15, "plays: {first} m, then {last} m"),
            }
        }
    }

    #[test]
    fn a_bouc_wen_branch_from_its_knots_agrees_with_fine_direct_integration() {
        for (n, gain, share) in [(1.0, 0.5, 0.75), (2.0, 1.0, 0.5), (3.7, 0.99, 0.52), (8.0, 1.2, 0.3)] {
            let Hysteresis::BoucWen(law) = bouc_wen(n, gain, share) else {
                unreachable!()
            };
            let r = law.half_width;
            for (z0, travel) in [(0.0, 3.0), (-0.9, 2.5), (0.7, -1.7), (0.99, 0.013), (-0.3, -0.0004)] {
                let mut memory = [1e-4; PLAY_OPERATORS];
                memory[BoucWen::OUTPUT] = 1e-4 - z0 * r;
                let input = 1e-4 + travel * r;
                let steps = 200_000;
                let h = travel / steps as f64;
                let mut w = z0;
                for _ in 0..steps {
                    w = law.runge_kutta(w, h, travel.signum());
                }
                let exact = input - r * w;
                let from_knots = law.output_after(&memory, input);
                // Measured: at most 2e-10 r (n = 8, where the bend is sharpest).
                assert!(
                    (from_knots - exact).abs() < 1e-9 * r,
                    "n {n}, z0 {z0}, travel {travel}: {from_knots} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn a_branch_beyond_the_knots_reach_agrees_with_fine_integration_and_ends_on_its_asymptote() {
        for (n, gain, share) in [(1.0, 0.5, 0.75), (3.7, 0.99, 0.52), (8.0, 1.2, 0.3)] {
            let Hysteresis::BoucWen(law) = bouc_wen(n, gain, share) else {
                unreachable!()
            };
            let r = law.half_width;
            // 150 half-widths: past the 128 the knots reach.
            for (z0, travel) in [(0.0, 150.0), (-0.9, -150.0), (0.5, -150.0)] {
                let mut memory = [1e-4; PLAY_OPERATORS];
                memory[BoucWen::OUTPUT] = 1e-4 - z0 * r;
                let input = 1e-4 + travel * r;
                let steps = 1_000_000;
                let h = travel / steps as f64;
                let mut w: f64 = z0;
                for _ in 0..steps {
                    w = law.runge_kutta(w, h, travel.signum());
                }
                let direct = law.output_after(&memory, input);
                assert!(
                    (direct - (input - r * w)).abs() < 1e-9 * r,
                    "n {n}, z0 {z0}, travel {travel}: {direct} vs {}",
                    input - r * w
                );
                // On the asymptote: the output trails the input by one half-width.
                assert!((direct - (input - travel.signum() * r)).abs() < 1e-9 * r);
            }
        }
        // A law far slower than any fitted one, over a million half-widths: the work is
        // bounded and the branch still rises monotonically, short of its asymptote.
        let Hysteresis::BoucWen(slow) = bouc_wen(1e-3, 1e-3, 0.5) else {
            unreachable!()
        };
        let r = slow.half_width;
        let memory = [1e-4; PLAY_OPERATORS];
        let w_far = |travel: f64| (1e-4 + travel * r - slow.output_after(&memory, 1e-4 + travel * r)) / r;
        let (near, far) = (w_far(200.0), w_far(1e6));
        assert!(0.0 < near && near < far && far <= 1.0, "{near} then {far}");
    }

    #[test]
    fn a_bouc_wen_output_depends_only_on_its_arguments() {
        // The knots are a per-thread cache: what was asked before must not change an answer.
        let law = bouc_wen(3.7, 0.99, 0.52);
        let a = [1e-4; PLAY_OPERATORS];
        let mut b = a;
        b[1] = 0.5e-4;
        let first = law.output_after(&a, 1.5e-4);
        let others = [
            law.output_after(&a, 1.9e-4),
            law.output_after(&b, 1.2e-4),
            law.output_after(&a, 0.4e-4),
        ];
        assert!(others.iter().all(|y| y.is_finite()));
        assert_eq!(law.output_after(&a, 1.5e-4).to_bits(), first.to_bits());
    }

    #[test]
    fn the_start_puts_either_law_on_its_branch() {
        for law in [
            bouc_wen(3.7, 1.0, 0.5),
            Hysteresis::new(0.16e-3, 0.05e-3, 0.0, 1.0, 0.5),
        ] {
            assert_eq!(law.initial_memory(2e-4, 0.0), [2e-4; PLAY_OPERATORS]);
            let rising = law.output(&law.initial_memory(2e-4, 1.0));
            let falling = law.output(&law.initial_memory(2e-4, -1.0));
            assert!((rising - (2e-4 - 0.08e-3)).abs() < 1e-15, "{law:?}: rising {rising}");
            assert!((falling - (2e-4 + 0.08e-3)).abs() < 1e-15, "{law:?}: falling {falling}");
        }
    }

    #[test]
    fn zero_width_is_the_identity() {
        let op = PrandtlIshlinskii::new(0.0, 0.0);
        assert!(!op.is_active());
        let mut plays = [0.0; PLAY_OPERATORS];
        op.advance(&mut plays, 3e-4);
        assert_eq!(PrandtlIshlinskii::output(&plays), 3e-4);
    }

    #[test]
    fn supply_drop_solves_its_equation() {
        // Choked supply flow ∝ p: p = P_s − R k p ⇒ p = P_s / (1 + R k).
        let (p_s, r, k) = (652_925.0, 2e8, 1e-10);
        let p = supply_pressure_at_jet(p_s, r, 0.0, |p| k * p);
        assert!((p - p_s / (1.0 + r * k)).abs() < 1e-6 * p_s, "{p}");
        assert_eq!(supply_pressure_at_jet(p_s, 0.0, 0.0, |p| k * p), p_s);
        // An enormous resistance: the jet sees (almost) the chamber pressure, never less.
        let chamber = 3e5;
        let p = supply_pressure_at_jet(p_s, 1e300, chamber, |p| k * (p - chamber));
        assert!(p >= chamber && p < chamber + 1.0, "{p}");
    }

    #[test]
    fn return_restriction_solves_its_equation() {
        // Return flow falling linearly in the vent pressure: ṁ = k (P_h − p), so
        // p = P_r + R k (P_h − p) ⇒ p = (P_r + R k P_h) / (1 + R k).
        let (p_r, p_h, r, k) = (101_325.0, 4e5, 3e8, 1e-9);
        let p = return_pressure_at_vent(p_r, r, p_h, |p| k * (p_h - p));
        let exact = (p_r + r * k * p_h) / (1.0 + r * k);
        assert!((p - exact).abs() < 1e-6 * p_h, "{p} vs {exact}");
        assert_eq!(return_pressure_at_vent(p_r, 0.0, p_h, |p| k * (p_h - p)), p_r);
        // An enormous resistance: the vent rises to (almost) the higher chamber pressure.
        let p = return_pressure_at_vent(p_r, 1e300, p_h, |p| k * (p_h - p));
        assert!(p <= p_h && p > p_h - 1.0, "{p}");
    }

    #[test]
    fn other_effects_are_off_at_their_defaults() {
        assert_eq!(polytropic_exponent(1.4, 0.0), 1.4);
        assert_eq!(polytropic_exponent(1.4, 1.0), 1.0);
        assert_eq!(friction_force(0.0, 0.0, 0.0, 0.0, 0.3), 0.0);
        assert_eq!(friction_force(2.0, 0.0, 0.0, 0.0, -0.3), -2.0);
        // The smooth law: tanh(1) of the level at v = v_c, the level far beyond.
        assert!((friction_force(2.0, 0.005, 0.0, 0.0, 0.005) - 2.0 * 1f64.tanh()).abs() < 1e-12);
        assert!((friction_force(2.0, 0.005, 0.0, 0.0, -0.1) + 2.0).abs() < 1e-8);
        // Stribeck: the level is F_c + F_s e^-1 at v = v_s, F_c far beyond.
        let at_vs = friction_force(2.0, 0.0, 1.0, 0.005, 0.005);
        assert!((at_vs - (2.0 + (-1f64).exp())).abs() < 1e-12);
        assert!((friction_force(2.0, 0.0, 1.0, 0.005, 0.1) - 2.0).abs() < 1e-12);
    }
}
