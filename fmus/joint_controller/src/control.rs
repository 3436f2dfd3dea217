//! Antagonistic joint control with co-contraction.
//!
//! Two tendons can only pull, so a joint torque τ must be made as a difference of two
//! tensions, and their common part, the co-contraction, is free. Jacobsen et al. (1989, 1990;
//! thesis §1.4) keep both tendons above a minimum tension so neither goes slack, and otherwise
//! share the torque equally:
//!
//!   T_flexor = T_co + τ/(2r),   T_extensor = T_co − τ/(2r),
//!
//! and when one of them would fall below T_min both are raised until it is at T_min (the
//! torque is kept); when one would exceed T_max both are lowered, and if that pushes the
//! other below T_min the torque saturates instead. The joint torque comes from a PID on the
//! angle, the derivative from the measured joint velocity:
//!
//!   τ = K_p (θ_ref − θ) + K_i ∫(θ_ref − θ) dt − K_d θ̇,
//!
//! with the integral clamped to ±tau_i_max (anti-windup). Each actuator then gets a force
//! loop as in the thesis's §4.1: the inverse static force map as feedforward (4.2) plus
//! proportional feedback on the measured actuator force,
//!
//!   v_DA = v_static(T_ref) + K_F (T_ref − F_meas),
//!
//! where K_F = 1.1 V/N is the thesis's k_p = 0.044 A/N divided by the driver's 0.04 A/V. The
//! static map is the actuator model's equilibrium force against command at the default
//! parameters (`STATIC_FORCE_MAP`; a test of fmus/antagonistic recomputes it from jetpipe's
//! actuator).
//!
//! The controller is sampled: each communication step it reads its inputs at the step's
//! start and holds its outputs over the next step, as a digital controller running at the
//! communication rate would (1 kHz at the usual 1 ms step).

/// Command (V) against equilibrium force (N) of the jet-pipe actuator at its default
/// parameters and x_s = 54 mm (the static force does not depend on x_s, thesis §3.3.1).
/// Below −0.3 V the force is the spring's alone (2.65 N); above 10 V it saturates at 92.9 N.
pub const STATIC_FORCE_MAP: &[(f64, f64)] = &[
    (-0.30, 2.994),
    (-0.20, 4.050),
    (-0.10, 5.281),
    (0.00, 6.680),
    (0.10, 8.235),
    (0.20, 9.935),
    (0.30, 11.764),
    (0.40, 13.708),
    (0.50, 15.751),
    (0.60, 17.879),
    (0.70, 20.077),
    (0.80, 22.329),
    (0.90, 24.624),
    (1.00, 26.948),
    (1.25, 32.810),
    (1.50, 38.623),
    (1.75, 44.262),
    (2.00, 49.638),
    (2.25, 54.673),
    (2.50, 59.157),
    (2.75, 63.094),
    (3.00, 66.553),
    (3.50, 72.275),
    (4.00, 76.732),
    (4.50, 80.233),
    (5.00, 83.005),
    (6.00, 86.992),
    (7.00, 89.518),
    (8.00, 91.143),
    (10.00, 92.937),
];

/// The command whose equilibrium force is `force`: linear interpolation of the inverse of
/// [`STATIC_FORCE_MAP`] (monotone), clamped to the table's ends.
pub fn static_command(force: f64) -> f64 {
    let map = STATIC_FORCE_MAP;
    if force <= map[0].1 {
        return map[0].0;
    }
    for w in map.windows(2) {
        let ((v0, f0), (v1, f1)) = (w[0], w[1]);
        if force <= f1 {
            return v0 + (v1 - v0) * (force - f0) / (f1 - f0);
        }
    }
    map[map.len() - 1].0
}

#[derive(Clone, Debug, PartialEq)]
pub struct Gains {
    /// Pulley radius of the joint (m): must be the joint's.
    pub radius: f64,
    pub t_co: f64,
    pub t_min: f64,
    pub t_max: f64,
    pub kp: f64,
    pub ki: f64,
    pub kd: f64,
    pub tau_i_max: f64,
    pub k_force: f64,
    /// Weight of the static feedforward (1: on, 0: off).
    pub k_feedforward: f64,
    pub v_min: f64,
    pub v_max: f64,
}

impl Gains {
    pub fn check(&self) -> Result<(), String> {
        if self.radius.is_nan() || self.radius <= 0.0 {
            return Err(format!("r = {} m is invalid: must be > 0", self.radius));
        }
        if !(self.t_min > 0.0 && self.t_min <= self.t_co && self.t_co < self.t_max) {
            return Err(format!(
                "tensions T_min = {} N, T_co = {} N, T_max = {} N are invalid: need 0 < T_min <= T_co < T_max",
                self.t_min, self.t_co, self.t_max
            ));
        }
        if self.v_min >= self.v_max {
            return Err(format!(
                "v_min = {} V is invalid: must be below v_max = {} V",
                self.v_min, self.v_max
            ));
        }
        Ok(())
    }

    /// Tensions (flexor, extensor) for the torque `tau`, both within [T_min, T_max].
    pub fn distribute(&self, tau: f64) -> (f64, f64) {
        let half = tau / (2.0 * self.radius);
        let (mut flexor, mut extensor) = (self.t_co + half, self.t_co - half);
        let low = flexor.min(extensor);
        if low < self.t_min {
            flexor += self.t_min - low;
            extensor += self.t_min - low;
        }
        let high = flexor.max(extensor);
        if high > self.t_max {
            flexor -= high - self.t_max;
            extensor -= high - self.t_max;
        }
        (
            flexor.clamp(self.t_min, self.t_max),
            extensor.clamp(self.t_min, self.t_max),
        )
    }
}

/// What the controller measures at a sampling instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurements {
    pub theta_ref: f64,
    pub theta: f64,
    pub omega: f64,
    pub f_flexor: f64,
    pub f_extensor: f64,
}

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Commands {
    pub tau: f64,
    pub t_flexor: f64,
    pub t_extensor: f64,
    pub v_flexor: f64,
    pub v_extensor: f64,
}

/// The controller's memory: the integral of the angle error (as a torque).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Controller {
    pub integral: f64,
}

impl Controller {
    /// The commands for measurements `m`; with `dt` > 0 the integral first advances over
    /// the sampling period that starts now (explicit, so the command reacts to this sample).
    pub fn update(&mut self, g: &Gains, m: &Measurements, dt: f64) -> Commands {
        let error = m.theta_ref - m.theta;
        if dt > 0.0 {
            self.integral = (self.integral + g.ki * error * dt).clamp(-g.tau_i_max, g.tau_i_max);
        }
        let tau = g.kp * error + self.integral - g.kd * m.omega;
        let (t_flexor, t_extensor) = g.distribute(tau);
        let command = |t_ref: f64, f_meas: f64| {
            (g.k_feedforward * static_command(t_ref) + g.k_force * (t_ref - f_meas)).clamp(g.v_min, g.v_max)
        };
        Commands {
            tau,
            t_flexor,
            t_extensor,
            v_flexor: command(t_flexor, m.f_flexor),
            v_extensor: command(t_extensor, m.f_extensor),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gains() -> Gains {
        Gains {
            radius: 0.01,
            t_co: 25.0,
            t_min: 8.0,
            t_max: 85.0,
            kp: 0.5,
            ki: 2.0,
            kd: 0.01,
            tau_i_max: 0.2,
            k_force: 1.1,
            k_feedforward: 1.0,
            v_min: -10.0,
            v_max: 10.0,
        }
    }

    #[test]
    fn tensions_never_fall_below_t_min_and_keep_the_torque_while_they_can() {
        let g = gains();
        for i in -400..=400 {
            let tau = i as f64 * 0.005; // −2 … 2 N·m
            let (f, e) = g.distribute(tau);
            assert!(f >= g.t_min && e >= g.t_min, "tau {tau}: {f} {e}");
            assert!(f <= g.t_max && e <= g.t_max, "tau {tau}: {f} {e}");
            let reachable = (g.t_max - g.t_min) * g.radius;
            if tau.abs() <= reachable {
                assert!((g.radius * (f - e) - tau).abs() < 1e-12, "tau {tau}: {f} {e}");
            } else {
                assert!((g.radius * (f - e)).abs() <= reachable + 1e-12);
                assert_eq!((g.radius * (f - e)).signum(), tau.signum());
            }
        }
        // Small torques: symmetric about the co-contraction, as Jacobsen's law.
        let (f, e) = g.distribute(0.1);
        assert!((f - 30.0).abs() < 1e-12 && (e - 20.0).abs() < 1e-12);
        // A torque that would take the extensor below T_min raises both.
        let (f, e) = g.distribute(0.4);
        assert_eq!(e, g.t_min);
        assert!((f - (g.t_min + 40.0)).abs() < 1e-12);
    }

    #[test]
    fn static_command_inverts_the_map_and_is_monotone() {
        for &(v, f) in STATIC_FORCE_MAP {
            assert!((static_command(f) - v).abs() < 1e-12);
        }
        let mut last = f64::NEG_INFINITY;
        for i in 0..1000 {
            let v = static_command(i as f64 * 0.1);
            assert!(v >= last);
            last = v;
        }
        assert_eq!(static_command(-5.0), -0.3);
        assert_eq!(static_command(500.0), 10.0);
    }

    #[test]
    fn commands_stay_within_the_actuator_range_whatever_the_measurements() {
        let g = gains();
        let mut c = Controller::default();
        for &(theta_ref, theta, omega, ff, fe) in &[
            (0.0, 0.0, 0.0, 25.0, 25.0),
            (10.0, -10.0, 0.0, 0.0, 200.0),
            (-10.0, 10.0, 1e3, 500.0, -50.0),
            (0.5, 0.4, -3.0, 30.0, 20.0),
        ] {
            let m = Measurements {
                theta_ref,
                theta,
                omega,
                f_flexor: ff,
                f_extensor: fe,
            };
            let u = c.update(&g, &m, 1e-3);
            for v in [u.v_flexor, u.v_extensor] {
                assert!((g.v_min..=g.v_max).contains(&v), "{v}");
            }
            assert!(c.integral.abs() <= g.tau_i_max);
        }
    }

    #[test]
    fn at_rest_on_target_it_commands_the_static_co_contraction() {
        let g = gains();
        let mut c = Controller::default();
        let m = Measurements {
            theta_ref: 0.3,
            theta: 0.3,
            omega: 0.0,
            f_flexor: 25.0,
            f_extensor: 25.0,
        };
        let u = c.update(&g, &m, 1e-3);
        assert_eq!(u.tau, 0.0);
        assert!((u.v_flexor - static_command(25.0)).abs() < 1e-12);
        assert_eq!(u.v_flexor, u.v_extensor);
        // A flexion error raises the flexor's command and lowers the extensor's.
        let m = Measurements { theta: 0.2, ..m };
        let u = c.update(&g, &m, 1e-3);
        assert!(u.tau > 0.0 && u.v_flexor > u.v_extensor);
    }

    #[test]
    fn bad_relations_are_named() {
        let mut g = gains();
        g.t_min = 30.0;
        assert!(g.check().unwrap_err().contains("T_min = 30 N"));
        let mut g = gains();
        g.v_max = -20.0;
        assert!(g.check().unwrap_err().contains("v_max = -20 V"));
    }
}
