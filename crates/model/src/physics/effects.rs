//! Effects the thesis model lacks (MODEL.md, "Effects the thesis model lacks"). Each is
//! off at its parameter's default, and then the model is the thesis model exactly.
//!
//! | name | parameter(s) | where it acts |
//! |---|---|---|
//! | `jet_pipe_hysteresis` | `hysteresis_width`, `hysteresis_deadband` (m) | Prandtl–Ishlinskii operator on f3's output, before the jet pipe dynamics (§3.2.1–3.2.2) |
//! | `piston_friction` | `friction_coulomb` (N), `friction_velocity` (m/s), `friction_stribeck` (N), `friction_stribeck_velocity` (m/s) | rod force while the stopper moves, (2.33)–(2.35) |
//! | `dead_volume` | `dead_volume_1`, `dead_volume_2` (m³) | added to (2.30)–(2.31) |
//! | `supply_pressure_drop` | `supply_resistance` (Pa·s/kg) | supply pressure at the jet pipe (§2.6) |
//! | `heat_transfer` | `heat_transfer_fraction` (1) | polytropic exponent in (2.29) |
//! | `transport_delay` | `command_delay` (s) | command seen by the current driver |
//! | `sensor_offset_gain` | `force_sensor_offset` (N), `force_sensor_gain` (1) | the `F_meas` output (see [`super::force_sensor`]) |

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

/// Pressure of a return plenum that empties to `p_r` through an orifice: the root of
/// ṁ_in(p) = ṁ_out(p), where `flows(p)` gives (ṁ_in, the return flow into the plenum,
/// which falls as p rises; ṁ_out, the vent's flow (2.18), which rises). The plenum's
/// volume is not modelled: it fills in far less than the chambers do. At P_r nothing
/// leaves and at `highest` nothing enters, so the root lies in [P_r, highest].
#[inline(never)]
pub fn return_pressure_at_vent_orifice(p_r: f64, highest: f64, flows: impl Fn(f64) -> (f64, f64)) -> f64 {
    // The flows' imbalance relative to their sum, in the pressures' scale, so that the
    // root finder's tolerances (relative to the pressures) mean something for flows.
    let scale = highest.max(p_r);
    increasing_root(p_r, scale, |p| {
        let (inflow, outflow) = flows(p);
        scale * (outflow - inflow) / (outflow + inflow + f64::MIN_POSITIVE)
    })
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
fn increasing_root(a: f64, b: f64, residual: impl Fn(f64) -> f64) -> f64 {
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
