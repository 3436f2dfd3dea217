//! The two chambers: volumes from the stopper position (2.30)–(2.32), net mass flows
//! (2.24)–(2.25) and the pressure rate (2.26)–(2.29) with the constant temperature of §2.6.

use std::f64::consts::PI;

/// Cylinder geometry needed for the chamber volumes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CylinderGeometry {
    pub l_cyl: f64,
    pub l_p: f64,
    pub l_s: f64,
    pub l_sup: f64,
    pub d_cyl: f64,
    /// Port and line volumes of each chamber (the `dead_volume` effect; 0 in the thesis).
    pub dead_volume_1: f64,
    pub dead_volume_2: f64,
}

impl CylinderGeometry {
    /// Piston area A_p = π D_cyl² / 4.
    pub fn piston_area(&self) -> f64 {
        PI * self.d_cyl * self.d_cyl / 4.0
    }

    /// Piston position from the stopper position, (2.32): x_p = x_s − (L_p + L_s + L_sup).
    pub fn piston_position(&self, x_s: f64) -> f64 {
        x_s - (self.l_p + self.l_s + self.l_sup)
    }

    /// Chamber volumes (V1, V2), (2.30)–(2.31): V1 = A_p x_p, V2 = A_p (L_cyl − x_p − L_p),
    /// plus the dead volumes of the `dead_volume` effect (zero in the thesis model).
    pub fn volumes(&self, x_s: f64) -> (f64, f64) {
        let a_p = self.piston_area();
        let x_p = self.piston_position(x_s);
        (
            a_p * x_p + self.dead_volume_1,
            a_p * (self.l_cyl - x_p - self.l_p) + self.dead_volume_2,
        )
    }

    /// Rates of change of the volumes for a stopper velocity: (A_p ẋ_s, −A_p ẋ_s).
    pub fn volume_rates(&self, x_s_dot: f64) -> (f64, f64) {
        let a_p = self.piston_area();
        (a_p * x_s_dot, -a_p * x_s_dot)
    }

    /// Open interval of stopper positions for which both volumes are positive.
    pub fn stopper_range(&self) -> (f64, f64) {
        let lower = self.l_p + self.l_s + self.l_sup;
        (lower, lower + self.l_cyl - self.l_p)
    }
}

/// Rate of change of a chamber pressure, (2.26)–(2.29) with ρ = P/(R T):
/// dP/dt = (γ / V) (R T ṁ − P dV/dt).
pub fn pressure_rate(
    gamma: f64,
    r_gas: f64,
    temperature: f64,
    volume: f64,
    volume_rate: f64,
    net_mass_flow: f64,
    pressure: f64,
) -> f64 {
    gamma / volume * (r_gas * temperature * net_mass_flow - pressure * volume_rate)
}

/// Pressure after an instantaneous volume change with no flow: the exact limit of
/// (2.29) over a vanishing time, P V^γ = const. The air in the chamber is conserved.
pub fn pressure_after_volume_jump(gamma: f64, pressure: f64, volume_before: f64, volume_after: f64) -> f64 {
    pressure * (volume_before / volume_after).powf(gamma)
}

/// The rate of the chamber's air as a pressure at a fixed reference volume V_ref, Q =
/// P (V/V_ref)^γ (the pressure [`pressure_after_volume_jump`] would bring it to there), for
/// the rate Ṗ of (2.29) at the volume's rate V̇: Q̇ = (V/V_ref)^γ (Ṗ + γ P V̇/V), which by
/// (2.29) is γ R T ṁ V^(γ−1)/V_ref^γ. V̇ cancels: Q's rate does not need the stopper's
/// velocity, which is why Model Exchange integrates Q.
pub fn reference_pressure_rate(
    gamma: f64,
    pressure: f64,
    pressure_rate: f64,
    volume: f64,
    volume_rate: f64,
    reference_volume: f64,
) -> f64 {
    (volume / reference_volume).powf(gamma) * (pressure_rate + gamma * pressure * volume_rate / volume)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thesis_cylinder() -> CylinderGeometry {
        CylinderGeometry {
            l_cyl: 78e-3,
            l_p: 8e-3,
            l_s: 7e-3,
            l_sup: 11e-3,
            d_cyl: 15.875e-3,
            dead_volume_1: 0.0,
            dead_volume_2: 0.0,
        }
    }

    #[test]
    fn volumes_and_valid_range() {
        let c = thesis_cylinder();
        let (lo, hi) = c.stopper_range();
        assert!((lo - 0.026).abs() < 1e-15 && (hi - 0.096).abs() < 1e-15);
        let (v1, v2) = c.volumes(0.054);
        let a_p = c.piston_area();
        assert!((v1 - a_p * 0.028).abs() < 1e-18 && (v2 - a_p * 0.042).abs() < 1e-18);
        let (v1_lo, _) = c.volumes(lo);
        let (_, v2_hi) = c.volumes(hi);
        assert!(v1_lo.abs() < 1e-20 && v2_hi.abs() < 1e-20);
    }

    #[test]
    fn closed_chamber_compression_follows_the_adiabat_and_conserves_air() {
        // Integrate (2.29) with no flow while the volume shrinks linearly; compare with
        // P V^γ = const, the jump formula.
        let (gamma, p0, v0, v1) = (1.4, 2e5, 5e-6, 3e-6);
        let n = 200_000;
        let dt = 1.0 / n as f64;
        let dv = v1 - v0;
        let mut p = p0;
        for k in 0..n {
            // midpoint rule
            let v = v0 + dv * (k as f64 + 0.5) * dt;
            let half = p + 0.5 * dt * pressure_rate(gamma, 287.0, 293.15, v - 0.5 * dv * dt, dv, 0.0, p);
            p += dt * pressure_rate(gamma, 287.0, 293.15, v, dv, 0.0, half);
        }
        let jump = pressure_after_volume_jump(gamma, p0, v0, v1);
        assert!((p - jump).abs() < 1e-6 * jump, "{p} vs {jump}");
    }

    #[test]
    fn the_pressure_at_a_reference_volume_moves_with_the_flow_alone() {
        let (gamma, r, t, p, v, v_ref, flow): (f64, f64, f64, f64, f64, f64, f64) =
            (1.4, 287.0, 293.15, 3e5, 4e-6, 5e-6, 2e-5);
        let alone = gamma * r * t * flow * v.powf(gamma - 1.0) / v_ref.powf(gamma);
        for volume_rate in [0.0, 1e-4, -3e-3] {
            let rate = pressure_rate(gamma, r, t, v, volume_rate, flow, p);
            let q_rate = reference_pressure_rate(gamma, p, rate, v, volume_rate, v_ref);
            assert!(
                (q_rate - alone).abs() < 1e-12 * alone.abs(),
                "{q_rate} vs {alone} at dV/dt {volume_rate}"
            );
        }
    }
}
