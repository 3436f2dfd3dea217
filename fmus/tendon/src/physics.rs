//! The tendon between an actuator's rod and a joint pulley.
//!
//! In the Utah/MIT hand each actuator rod pulls a polymer tendon that runs over the pulleys
//! of the remotizer to the joint (thesis §1.1.1, §1.4). Three things of that path matter to
//! the joint: the moving mass at the actuator end, the tendon's elasticity (with the fact
//! that a tendon can pull but not push), and the Coulomb friction of the pulleys, which
//! Johnstun and Smith (1992, cited in §1.4) found to be the dominant loss.
//!
//! Model (x_a: rod displacement in the pulling direction from the stopper's nominal position
//! x_s0; x_j: tendon excursion at the joint, same direction; v = dx/dt):
//!
//! * tension at the joint end (the tendon is a one-sided spring-damper):
//!   T_j = 0 if s = x_a − x_j ≤ 0 (slack), else max(0, k s + c (v_a − v_j));
//! * capstan (Euler–Eytelwein) friction of the pulleys between rod and joint, lumped as one
//!   wrap μβ: the rod side carries T_a = T_j · exp(μβ · sgn(v_a)), with sgn regularised as
//!   tanh(v_a / v_f). The tension lost, T_a − T_j, has the sign of v_a, so the friction
//!   always takes power out of the motion, and it vanishes with the tension;
//! * the rod node: m_a dv_a/dt = F_act − T_a − c_a v_a (c_a: viscous friction of the piston
//!   seal and rod bushing), with the rod stopped inelastically at the ends of its stroke so
//!   the stopper position x_s = x_s0 + x_a never leaves the cylinder.
//!
//! Integration: implicit Euler on substeps of at most `max_substep`. Each substep is one
//! scalar equation in the new rod velocity that is strictly increasing (the mass term plus
//! tension and friction terms that only grow with the velocity), so it has exactly one
//! root whatever the kinks of slack and friction; see `fmu_common::solve`. Implicit Euler
//! keeps the stiff tendon (k/m_a ≈ (630 rad/s)² with the defaults) and the steep friction
//! regularisation stable at any substep; the substep bound keeps its numerical damping
//! (≈ ω·dt/2 of the tendon mode) below 2 %. The joint end moves linearly over the step with
//! the velocity given as an input, so the coupling to the joint FMU has no zero-order-hold
//! lag on position.

use fmu_common::solve::increasing_root;

#[derive(Clone, Debug, PartialEq)]
pub struct Parameters {
    /// Mass of piston, rod and stopper, lumped at the actuator end (kg).
    pub m_rod: f64,
    /// Viscous friction of the piston seal and rod bushing (N·s/m).
    pub c_rod: f64,
    /// Tendon stiffness, actuator to joint (N/m).
    pub k: f64,
    /// Tendon damping (N·s/m).
    pub c: f64,
    /// Capstan exponent μβ of the pulleys between actuator and joint (1).
    pub capstan: f64,
    /// Velocity below which the friction's sign is smoothed (m/s).
    pub v_friction: f64,
    /// Stopper position when x_a = 0 (m).
    pub x_s0: f64,
    /// Ends of the rod's stroke, as stopper positions (m).
    pub x_s_min: f64,
    pub x_s_max: f64,
    /// Largest internal substep (s).
    pub max_substep: f64,
}

impl Parameters {
    /// Relations between parameters that the table's per-variable ranges cannot express.
    pub fn check(&self) -> Result<(), String> {
        for (name, value, unit) in [
            ("m_rod", self.m_rod, "kg"),
            ("k", self.k, "N/m"),
            ("v_friction", self.v_friction, "m/s"),
            ("max_substep", self.max_substep, "s"),
        ] {
            if !(value > 0.0 && value.is_finite()) {
                return Err(format!("{name} = {value} {unit} is invalid: must be > 0"));
            }
        }
        if !(self.x_s_min < self.x_s0 && self.x_s0 < self.x_s_max) {
            return Err(format!(
                "x_s0 = {} m is invalid: must lie strictly between x_s_min = {} m and x_s_max = {} m",
                self.x_s0, self.x_s_min, self.x_s_max
            ));
        }
        Ok(())
    }

    /// Tension at the joint end, zero while slack.
    pub fn joint_tension(&self, x_a: f64, v_a: f64, x_j: f64, v_j: f64) -> f64 {
        let stretch = x_a - x_j;
        if stretch <= 0.0 {
            0.0
        } else {
            (self.k * stretch + self.c * (v_a - v_j)).max(0.0)
        }
    }

    /// Tension at the rod: the joint-end tension raised (rod pulling in, v_a > 0) or lowered
    /// (joint pulling out) by the capstan factor.
    pub fn rod_tension(&self, joint_tension: f64, v_a: f64) -> f64 {
        joint_tension * (self.capstan * (v_a / self.v_friction).tanh()).exp()
    }

    fn x_a_min(&self) -> f64 {
        self.x_s_min - self.x_s0
    }
    fn x_a_max(&self) -> f64 {
        self.x_s_max - self.x_s0
    }
}

/// The joint end's motion over a step: x_j(t) = x + v (t − t0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointEnd {
    pub x: f64,
    pub v: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct State {
    pub x_a: f64,
    pub v_a: f64,
    /// Joint end at the end of the last step (for the outputs).
    pub joint: JointEnd,
    /// Total time the tendon was slack (s), summed over substeps.
    pub slack_time: f64,
    /// Time since initialisation (s).
    pub elapsed: f64,
}

/// Outputs at the current state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outputs {
    pub tension: f64,
    pub rod_tension: f64,
    pub x_s: f64,
    pub v_rod: f64,
    pub stretch: f64,
    pub slack: bool,
}

impl State {
    /// Static equilibrium with the rod force `f_act` (friction does not act at rest): the
    /// tendon stretched by F/k, or just taut if the rod does not pull; within the stroke.
    pub fn equilibrium(p: &Parameters, f_act: f64, joint: JointEnd) -> Self {
        let x_a = (joint.x + f_act.max(0.0) / p.k).clamp(p.x_a_min(), p.x_a_max());
        Self {
            x_a,
            v_a: joint.v,
            joint,
            slack_time: 0.0,
            elapsed: 0.0,
        }
    }

    pub fn outputs(&self, p: &Parameters) -> Outputs {
        let tension = p.joint_tension(self.x_a, self.v_a, self.joint.x, self.joint.v);
        Outputs {
            tension,
            rod_tension: p.rod_tension(tension, self.v_a),
            x_s: p.x_s0 + self.x_a,
            v_rod: self.v_a,
            stretch: self.x_a - self.joint.x,
            slack: tension <= 0.0,
        }
    }

    /// Advance by `h` with the rod force `f_act` held and the joint end moving as `joint`.
    pub fn step(&mut self, p: &Parameters, f_act: f64, joint: JointEnd, h: f64) -> Result<(), String> {
        let n = (h / p.max_substep).ceil().max(1.0);
        if n > 1e7 {
            return Err(format!(
                "step {h} s needs {n} substeps of max_substep = {} s: too many",
                p.max_substep
            ));
        }
        let dt = h / n;
        for i in 0..n as usize {
            let x_j = joint.x + joint.v * dt * (i + 1) as f64;
            let (x, v) = (self.x_a, self.v_a);
            // Implicit Euler: m (v' − v)/dt = F − T_a(x + dt v', v') − c_a v'.
            let g = |v_new: f64| {
                let t_j = p.joint_tension(x + dt * v_new, v_new, x_j, joint.v);
                p.m_rod * (v_new - v) / dt - f_act + p.rod_tension(t_j, v_new) + p.c_rod * v_new
            };
            let scale = (f_act.abs() + 1.0) * dt / p.m_rod + p.v_friction;
            let mut v_new = increasing_root(g, v, scale).ok_or_else(|| {
                format!("the rod's implicit step found no solution (x_a = {x} m, v_a = {v} m/s, F_act = {f_act} N)")
            })?;
            let mut x_new = x + dt * v_new;
            // End of stroke: an inelastic stop keeps the stopper inside the cylinder.
            if x_new > p.x_a_max() {
                x_new = p.x_a_max();
                v_new = v_new.min(0.0);
            } else if x_new < p.x_a_min() {
                x_new = p.x_a_min();
                v_new = v_new.max(0.0);
            }
            self.x_a = x_new;
            self.v_a = v_new;
            if p.joint_tension(x_new, v_new, x_j, joint.v) <= 0.0 {
                self.slack_time += dt;
            }
        }
        self.joint = JointEnd {
            x: joint.x + joint.v * h,
            v: joint.v,
        };
        self.elapsed += h;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> Parameters {
        Parameters {
            m_rod: 0.05,
            c_rod: 5.0,
            k: 2e4,
            c: 10.0,
            capstan: 0.05,
            v_friction: 2e-3,
            x_s0: 0.054,
            x_s_min: 0.030,
            x_s_max: 0.090,
            max_substep: 5e-5,
        }
    }

    const FIXED: JointEnd = JointEnd { x: 0.0, v: 0.0 };

    #[test]
    fn slack_gives_zero_tension_and_is_timed() {
        let p = params();
        assert_eq!(p.joint_tension(-1e-3, 0.0, 0.0, 0.0), 0.0);
        // A taut tendon moving quickly to slack: the damping term cannot make it push.
        assert_eq!(p.joint_tension(1e-5, -1.0, 0.0, 0.0), 0.0);
        assert!(p.joint_tension(1e-3, 0.0, 0.0, 0.0) > 0.0);
        // No rod force and the joint end pulled 5 mm towards the actuator: the tendon goes
        // slack; the rod (no force on it) stays where it was.
        let mut s = State::equilibrium(&p, 0.0, FIXED);
        s.step(&p, 0.0, JointEnd { x: 5e-3, v: 0.0 }, 0.01).unwrap();
        let y = s.outputs(&p);
        assert!(y.slack && y.tension == 0.0 && y.rod_tension == 0.0, "{y:?}");
        assert!((s.slack_time - 0.01).abs() < 1e-9, "{}", s.slack_time);
    }

    #[test]
    fn friction_opposes_the_motion_and_dissipates() {
        let p = params();
        let t = 20.0;
        // Rod pulling in: the rod side pulls harder than the joint receives.
        assert!(p.rod_tension(t, 0.05) > t);
        // Joint pulling the tendon out: the joint side pulls harder than the rod feels.
        assert!(p.rod_tension(t, -0.05) < t);
        assert_eq!(p.rod_tension(t, 0.0), t);
        for v in [-0.1, -1e-3, 1e-4, 0.2] {
            assert!(
                (p.rod_tension(t, v) - t) * v >= 0.0,
                "friction power negative at v = {v}"
            );
        }
        // Capstan law at full slip: exp(μβ).
        assert!((p.rod_tension(t, 1.0) / t - 0.05f64.exp()).abs() < 1e-9);
    }

    #[test]
    fn settles_to_the_static_equilibrium() {
        let p = params();
        let mut s = State::equilibrium(&p, 10.0, FIXED);
        s.step(&p, 40.0, FIXED, 0.5).unwrap();
        let y = s.outputs(&p);
        // The smoothed friction acts as a steep viscous damper near rest (T·μβ/v_f), so the
        // last micro-newtons creep in slowly.
        assert!((y.tension - 40.0).abs() < 1e-3, "{y:?}");
        assert!((y.stretch - 40.0 / p.k).abs() < 1e-7);
        assert!((y.x_s - (0.054 + 40.0 / p.k)).abs() < 1e-7);
    }

    #[test]
    fn without_losses_energy_decays_only_by_implicit_eulers_known_factor() {
        let mut p = params();
        p.c = 0.0;
        p.c_rod = 0.0;
        p.capstan = 0.0;
        let f = 30.0;
        // 1 mm off the equilibrium under the constant F (the tendon stays taut), energy
        // measured from that equilibrium.
        let mut s = State::equilibrium(&p, f, FIXED);
        s.x_a += 1e-3;
        let energy = |s: &State| 0.5 * p.m_rod * s.v_a.powi(2) + 0.5 * p.k * (s.x_a - f / p.k).powi(2);
        let e0 = energy(&s);
        let mut last = e0;
        for _ in 0..200 {
            s.step(&p, f, FIXED, 1e-3).unwrap();
            let e = energy(&s);
            assert!(e < last, "energy grew: {last} -> {e}");
            last = e;
        }
        // For a linear oscillator implicit Euler divides the energy by exactly 1 + (ω dt)²
        // per substep: nothing else (no spurious source or sink) may show up.
        let substeps = 200.0 * (1e-3 / p.max_substep).ceil();
        let dt = 1e-3 / (1e-3 / p.max_substep).ceil();
        let omega2 = p.k / p.m_rod;
        let expected = e0 * (1.0 + omega2 * dt * dt).powf(-substeps);
        assert!((last / expected - 1.0).abs() < 1e-6, "{last} vs {expected}");
    }

    #[test]
    fn the_rod_stops_at_the_end_of_its_stroke() {
        let p = params();
        let mut s = State::equilibrium(&p, 0.0, FIXED);
        // Joint end runs away 40 mm and the actuator pulls hard: the rod would follow past
        // x_s_max; it must stop there.
        s.step(&p, 90.0, JointEnd { x: 0.0, v: 4.0 }, 0.01).unwrap();
        let y = s.outputs(&p);
        assert!(y.x_s <= p.x_s_max + 1e-15 && y.x_s >= p.x_s_max - 1e-9, "{y:?}");
        assert!(s.v_a <= 0.0);
    }

    #[test]
    fn bad_relations_are_named() {
        let mut p = params();
        p.x_s0 = 0.095;
        assert!(p.check().unwrap_err().contains("x_s0 = 0.095 m"));
        let mut p = params();
        p.k = 0.0;
        assert!(p.check().unwrap_err().contains("k = 0 N/m"));
    }
}
