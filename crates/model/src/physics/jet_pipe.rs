//! Jet pipe: tip force (2.4), static curve f3 (2.5), third-order dynamics (2.6) and the
//! offset from the receiver centre (2.7).

/// Tip force from the coil current, (2.4): F_jp = k_m i.
pub fn tip_force(k_m: f64, current: f64) -> f64 {
    k_m * current
}

/// Static tip position, (2.5): x̄ = f3(F_jp). The thesis's f3 is the midpoint line of
/// Fig. 3.5, which the text does not give; MODEL.md fixes x̄ = x_sat tanh(F_jp / F_sat).
pub fn static_position(x_jp_sat: f64, f_jp_sat: f64, tip_force: f64) -> f64 {
    x_jp_sat * (tip_force / f_jp_sat).tanh()
}

/// d x̄ / d F_jp, the slope of f3 (used by the linearisation, Appendix A's c5).
pub fn static_position_slope(x_jp_sat: f64, f_jp_sat: f64, tip_force: f64) -> f64 {
    let t = (tip_force / f_jp_sat).tanh();
    x_jp_sat / f_jp_sat * (1.0 - t * t)
}

/// Third derivative of the tip position, (2.6) in state form (Appendix A, c2..c4):
/// X(s)/X̄(s) = ω1/(s+ω1) · ω2²/(s² + 2ζ2ω2 s + ω2²), unity gain at DC, so
/// x''' = ω1ω2² (x̄ − x) − (2ζ2ω2 + ω1) x'' − (ω2² + 2ζ2ω1ω2) x'.
pub fn third_derivative(
    omega_1: f64,
    omega_2: f64,
    zeta_2: f64,
    static_position: f64,
    position: f64,
    velocity: f64,
    acceleration: f64,
) -> f64 {
    let c2 = 2.0 * zeta_2 * omega_2 + omega_1;
    let c3 = omega_2 * omega_2 + 2.0 * zeta_2 * omega_1 * omega_2;
    let c4 = omega_1 * omega_2 * omega_2;
    c4 * (static_position - position) - c2 * acceleration - c3 * velocity
}

/// Absolute tip position relative to the receiver centre, (2.7).
pub fn absolute_position(position: f64, x_jp_offset: f64) -> f64 {
    position + x_jp_offset
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_curve_is_odd_saturating_and_has_the_documented_slope() {
        let (xs, fs) = (0.5e-3, 0.45);
        assert_eq!(static_position(xs, fs, 0.0), 0.0);
        assert!((static_position(xs, fs, 0.3) + static_position(xs, fs, -0.3)).abs() < 1e-18);
        assert!(static_position(xs, fs, 100.0) <= xs);
        let h = 1e-7;
        let numeric = (static_position(xs, fs, 0.2 + h) - static_position(xs, fs, 0.2 - h)) / (2.0 * h);
        assert!((numeric - static_position_slope(xs, fs, 0.2)).abs() < 1e-9);
    }

    #[test]
    fn dynamics_have_unity_dc_gain() {
        // At rest at the static position every derivative vanishes.
        assert_eq!(third_derivative(973.9, 1856.7, 0.019, 1e-4, 1e-4, 0.0, 0.0), 0.0);
        assert!(third_derivative(973.9, 1856.7, 0.019, 1e-4, 0.0, 0.0, 0.0) > 0.0);
    }
}
