//! Current driver: a first-order low-pass voltage-to-current converter, (2.1)–(2.3).

/// Static current for a D/A voltage, (2.3): ī = k_cd v_DA + i_offset.
pub fn static_current(k_cd: f64, i_offset: f64, v_da: f64) -> f64 {
    k_cd * v_da + i_offset
}

/// Rate of change of the coil current, (2.1)–(2.2): di/dt = ω_cd (ī − i).
pub fn current_rate(omega_cd: f64, static_current: f64, current: f64) -> f64 {
    omega_cd * (static_current - current)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settles_to_the_static_current_with_the_corner_time_constant() {
        // Exact solution of the linear ODE: i(t) = ī (1 − e^{−ω t}); integrate with tiny
        // explicit steps and compare at t = 1/ω (63.2 %).
        let (omega, target): (f64, f64) = (7050.0, 0.1);
        let (mut i, dt) = (0.0, 1e-8);
        let steps = (1.0 / omega / dt).round() as usize;
        for _ in 0..steps {
            i += dt * current_rate(omega, target, i);
        }
        let expected = target * (1.0 - (-1.0f64).exp());
        assert!((i - expected).abs() < 1e-6, "{i} vs {expected}");
        assert!((static_current(0.04, 0.01, 10.0) - 0.41).abs() < 1e-15);
    }
}
