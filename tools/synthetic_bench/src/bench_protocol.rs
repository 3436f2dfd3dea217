//! The protocol of `bench/README.md` (segments A–E over 80 s) and the bench's A/D and D/A
//! quantisation.

use super::*;

/// Length of the bench protocol (s).
pub const PROTOCOL_DURATION: f64 = 80.0;
/// Stopper position outside segment E (m).
pub const STOPPER_HOME: f64 = 0.054;

pub(crate) fn piecewise_linear(t: f64, pts: &[(f64, f64)]) -> f64 {
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

pub(crate) fn quantise_force(f: f64) -> f64 {
    let lsb = 1000.0 / 65536.0;
    let code = ((f + 500.0) / lsb).round().clamp(0.0, 65535.0);
    -500.0 + code * lsb
}

pub(crate) fn quantise_pressure(p: f64) -> f64 {
    let lsb = 1.0e6 / 65536.0;
    (p / lsb).round().clamp(0.0, 65535.0) * lsb
}

pub(crate) fn quantise_stopper(x: f64) -> f64 {
    (x * 1e6).round() * 1e-6
}
