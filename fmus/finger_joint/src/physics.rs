//! One revolute finger joint with a pulley of radius r for its two tendons.
//!
//! J θ̈ = r (T_flexor − T_extensor) + τ_ext − b θ̇ + τ_limit(θ, θ̇)
//!
//! θ > 0 is flexion. Flexing lets the flexor tendon be drawn towards its actuator by r·θ and
//! pulls the extensor out by the same length: the excursions, both positive towards their
//! actuators as the Tendon FMU expects, are x_flexor = r θ and x_extensor = −r θ. The joint stops are one-sided
//! stiff spring-dampers that only push back: beyond θ_max,
//! τ_limit = −max(0, k_lim (θ − θ_max) + c_lim θ̇), and symmetrically below θ_min.
//!
//! J is the inertia of the distal finger about the joint; the rod masses of the actuators live
//! in the Tendon FMUs, so they are not reflected here.
//!
//! Integration: implicit Euler on substeps of at most `max_substep`, one strictly increasing
//! scalar equation in the new θ̇ per substep (`fmu_common::solve`), so a stiff limit
//! (√(k_lim/J) ≈ 300 rad/s with the defaults) is stable at any step. The tensions are held
//! over the communication step (they come from the tendons at the step's start).

use fmu_common::solve::increasing_root;

#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    /// Inertia about the joint axis (kg·m²).
    pub inertia: f64,
    /// Viscous damping of the joint (N·m·s/rad).
    pub damping: f64,
    /// Pulley radius: the moment arm of both tendons (m).
    pub radius: f64,
    pub theta_min: f64,
    pub theta_max: f64,
    /// Stiffness and damping of the joint stops (N·m/rad, N·m·s/rad).
    pub k_limit: f64,
    pub c_limit: f64,
    pub max_substep: f64,
}

impl Parameters {
    pub fn check(&self) -> Result<(), String> {
        for (name, value, unit) in [
            ("J", self.inertia, "kg.m2"),
            ("r", self.radius, "m"),
            ("max_substep", self.max_substep, "s"),
        ] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(format!("{name} = {value} {unit} is invalid: must be > 0"));
            }
        }
        if self.theta_min >= self.theta_max {
            return Err(format!(
                "theta_min = {} rad is invalid: must be below theta_max = {} rad",
                self.theta_min, self.theta_max
            ));
        }
        Ok(())
    }

    /// Torque of the stops: zero inside [θ_min, θ_max], pushing back (never pulling) outside.
    pub fn limit_torque(&self, theta: f64, omega: f64) -> f64 {
        if theta > self.theta_max {
            -(self.k_limit * (theta - self.theta_max) + self.c_limit * omega).max(0.0)
        } else if theta < self.theta_min {
            (self.k_limit * (self.theta_min - theta) - self.c_limit * omega).max(0.0)
        } else {
            0.0
        }
    }
}

/// What drives the joint over a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    pub t_flexor: f64,
    pub t_extensor: f64,
    pub tau_ext: f64,
}

impl Inputs {
    pub fn tendon_torque(&self, p: &Parameters) -> f64 {
        p.radius * (self.t_flexor - self.t_extensor)
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub theta: f64,
    pub omega: f64,
    pub elapsed: f64,
}

impl State {
    pub fn step(&mut self, p: &Parameters, u: Inputs, h: f64) -> Result<(), String> {
        let n = (h / p.max_substep).ceil().max(1.0);
        if n > 1e7 {
            return Err(format!(
                "step {h} s needs {n} substeps of max_substep = {} s: too many",
                p.max_substep
            ));
        }
        let dt = h / n;
        let drive = u.tendon_torque(p) + u.tau_ext;
        for _ in 0..n as usize {
            let (theta, omega) = (self.theta, self.omega);
            // Implicit Euler: J (ω' − ω)/dt = τ + τ_limit(θ + dt ω', ω') − b ω'.
            let g = |w: f64| p.inertia * (w - omega) / dt - drive + p.damping * w - p.limit_torque(theta + dt * w, w);
            let scale = (drive.abs() + 1e-3) * dt / p.inertia;
            let w = increasing_root(g, omega, scale).ok_or_else(|| {
                format!("the joint's implicit step found no solution (theta = {theta} rad, omega = {omega} rad/s)")
            })?;
            self.theta = theta + dt * w;
            self.omega = w;
        }
        self.elapsed += h;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> Parameters {
        Parameters {
            inertia: 2e-4,
            damping: 2e-3,
            radius: 0.01,
            theta_min: -0.3,
            theta_max: 1.6,
            k_limit: 20.0,
            c_limit: 0.05,
            max_substep: 5e-5,
        }
    }

    fn at(theta: f64) -> State {
        State {
            theta,
            omega: 0.0,
            elapsed: 0.0,
        }
    }

    #[test]
    fn limits_hold_and_only_push() {
        let p = params();
        assert_eq!(p.limit_torque(1.0, 5.0), 0.0);
        assert!(p.limit_torque(1.7, 0.0) < 0.0 && p.limit_torque(-0.4, 0.0) > 0.0);
        // Leaving the stop quickly: it does not pull the joint back in.
        assert_eq!(p.limit_torque(1.61, -10.0), 0.0);
        // 80 N of flexor against 5 N of extensor: 0.75 N·m into the upper stop.
        let mut s = at(1.0);
        let u = Inputs {
            t_flexor: 80.0,
            t_extensor: 5.0,
            tau_ext: 0.0,
        };
        let mut peak: f64 = 0.0;
        for _ in 0..2000 {
            s.step(&p, u, 1e-3).unwrap();
            peak = peak.max(s.theta);
        }
        let tau = 0.75;
        let rest = p.theta_max + tau / p.k_limit;
        assert!((s.theta - rest).abs() < 1e-6, "{} vs {rest}", s.theta);
        // The stop can absorb at most the work done on the way in: ½ k x² = τ (0.6 rad + x).
        let bound = (tau + (tau * tau + 2.0 * p.k_limit * tau * (p.theta_max - 1.0)).sqrt()) / p.k_limit;
        assert!(
            peak > p.theta_max && peak - p.theta_max < bound,
            "overran the stop to {peak}"
        );
    }

    #[test]
    fn balanced_tensions_are_a_static_equilibrium() {
        let p = params();
        let mut s = at(0.4);
        let u = Inputs {
            t_flexor: 25.0,
            t_extensor: 25.0,
            tau_ext: 0.0,
        };
        s.step(&p, u, 0.5).unwrap();
        assert_eq!((s.theta, s.omega), (0.4, 0.0));
        assert_eq!(s.elapsed, 0.5);
    }

    #[test]
    fn torque_accelerates_as_j_theta_ddot_and_damping_dissipates() {
        let mut p = params();
        p.damping = 0.0;
        let mut s = at(0.0);
        let u = Inputs {
            t_flexor: 26.0,
            t_extensor: 24.0,
            tau_ext: 0.0,
        };
        // 0.02 N·m on 2e-4 kg·m²: 100 rad/s²; after 10 ms θ̇ = 1 rad/s, θ = 5 mrad.
        s.step(&p, u, 0.01).unwrap();
        assert!((s.omega - 1.0).abs() < 1e-9, "{}", s.omega);
        assert!((s.theta - 0.005).abs() < 1e-4, "{}", s.theta);
        // Free motion with damping: kinetic energy only falls.
        let p = params();
        let mut s = State {
            theta: 0.0,
            omega: 5.0,
            elapsed: 0.0,
        };
        let free = Inputs {
            t_flexor: 0.0,
            t_extensor: 0.0,
            tau_ext: 0.0,
        };
        let mut last = s.omega.abs();
        for _ in 0..50 {
            s.step(&p, free, 1e-3).unwrap();
            assert!(s.omega.abs() < last);
            last = s.omega.abs();
        }
    }

    #[test]
    fn bad_relations_are_named() {
        let mut p = params();
        p.theta_min = 2.0;
        assert!(p.check().unwrap_err().contains("theta_min = 2 rad"));
        let mut p = params();
        p.inertia = 0.0;
        assert!(p.check().unwrap_err().contains("J = 0 kg.m2"));
    }
}
