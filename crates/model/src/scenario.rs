//! The standard scenario shared by the CLI, the Rust tests and `fmu_tests/scenarios.py`:
//! 10 s, inputs sampled every 10 ms and held,
//! v_DA(t_k) = 2.5 + 3.0 sin(2π·0.3 t_k) + 0.5 sin(2π·6 t_k) V,
//! x_s(t_k) = 0.054 + 0.01 sin(2π·0.1 t_k) m, t_k = 0.01 k.

use std::f64::consts::PI;

pub const SAMPLE_PERIOD: f64 = 0.01;
pub const DURATION: f64 = 10.0;

/// Held inputs (v_DA, x_s) of sample `k`.
pub fn standard_inputs(k: usize) -> (f64, f64) {
    let t = SAMPLE_PERIOD * k as f64;
    let v = 2.5 + 3.0 * (2.0 * PI * 0.3 * t).sin() + 0.5 * (2.0 * PI * 6.0 * t).sin();
    let x = 0.054 + 0.01 * (2.0 * PI * 0.1 * t).sin();
    (v, x)
}

/// Number of samples in the scenario.
pub fn standard_samples() -> usize {
    (DURATION / SAMPLE_PERIOD).round() as usize
}
