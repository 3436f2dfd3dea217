//! Piston force, (2.36)–(2.38). The piston is taken as stuck to the stopper (§2.7), so
//! the rod force is the pressure force, floored by the residual spring force.

/// Spring force with the piston against the top of the cylinder, (2.37)–(2.38):
/// F_spring = k_spring (L_spring,0 − (x_s − L_s − L_p)).
pub fn spring_force(k_spring: f64, l_spring0: f64, l_s: f64, l_p: f64, x_s: f64) -> f64 {
    k_spring * (l_spring0 - (x_s - l_s - l_p))
}

/// Pressure force on the piston, (2.34)/(2.36): A_p (P1 − P2).
pub fn pressure_force(piston_area: f64, p1: f64, p2: f64) -> f64 {
    piston_area * (p1 - p2)
}

/// Actuator (tendon) force: the pressure force, never below the spring force (§2.7).
pub fn actuator_force(pressure_force: f64, spring_force: f64) -> f64 {
    pressure_force.max(spring_force)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spring_law_at_midstroke() {
        // x_s = 54 mm: spring length 39 mm, compression 30.1 mm at 88.14 N/m.
        let f = spring_force(88.14, 69.1e-3, 7e-3, 8e-3, 54e-3);
        assert!((f - 88.14 * 30.1e-3).abs() < 1e-12);
        assert_eq!(actuator_force(-5.0, f), f);
        assert_eq!(actuator_force(50.0, f), 50.0);
    }
}
