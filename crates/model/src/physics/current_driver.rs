//! Current driver: a first-order low-pass voltage-to-current converter, (2.1)–(2.3).
//!
//! Stated here once: the assembled model takes the rate (2.1)–(2.2) and the static current
//! (2.3), and the exact propagator (`crate::electromechanics`) takes the driver as a
//! first-order mode, [`CurrentDriver`], with its closed-form [`Response`].

use super::parameters::Parameters;

/// Static current for a D/A voltage, (2.3): ī = k_cd v_DA + i_offset.
pub fn static_current(k_cd: f64, i_offset: f64, v_da: f64) -> f64 {
    k_cd * v_da + i_offset
}

/// Rate of change of the coil current, (2.1)–(2.2): di/dt = ω_cd (ī − i).
pub fn current_rate(omega_cd: f64, static_current: f64, current: f64) -> f64 {
    omega_cd * (static_current - current)
}

/// The D/A voltage at which the static current (2.3) is `current`.
pub fn command_for_current(k_cd: f64, i_offset: f64, current: f64) -> f64 {
    (current - i_offset) / k_cd
}

/// The current driver as a first-order mode: rate ω_cd, static gain k_cd and offset
/// i_offset, (2.1)–(2.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurrentDriver {
    pub omega_cd: f64,
    pub k_cd: f64,
    pub i_offset: f64,
}

impl CurrentDriver {
    pub fn from_parameters(p: &Parameters) -> Self {
        Self {
            omega_cd: p.omega_cd,
            k_cd: p.k_cd,
            i_offset: p.i_offset,
        }
    }

    /// (2.3).
    pub fn static_current(&self, v_da: f64) -> f64 {
        static_current(self.k_cd, self.i_offset, v_da)
    }

    /// (2.1)–(2.2).
    pub fn rate(&self, static_current: f64, current: f64) -> f64 {
        current_rate(self.omega_cd, static_current, current)
    }

    /// ∂(di/dt)/∂v_DA: the input column of the linearised (2.1)–(2.3), ω_cd k_cd.
    pub fn command_gain(&self) -> f64 {
        self.omega_cd * self.k_cd
    }

    /// (2.1)–(2.3) solved exactly from the current `current` for a command linear in time,
    /// v_DA(s) = `v_da` + `v_da_rate`·s.
    pub fn response(&self, current: f64, v_da: f64, v_da_rate: f64) -> Response {
        let static_current = self.static_current(v_da);
        let ramp = self.k_cd * v_da_rate;
        // i(s) = ī(0) + ramp·(s − 1/ω) + δ e^{−ω s}
        let base = static_current - ramp / self.omega_cd;
        Response {
            omega_cd: self.omega_cd,
            base,
            ramp,
            delta: current - base,
        }
    }
}

/// The current of (2.1)–(2.3) under a command linear in time, integrated in closed form:
/// di/ds = ω_cd (ī(s) − i) with ī(s) = ī(0) + ramp·s gives
/// i(s) = base + ramp·s + δ e^{−ω_cd s}, base = ī(0) − ramp/ω_cd: the static current's ramp,
/// lagging by 1/ω_cd, and the transient δ of the driver's one mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Response {
    pub omega_cd: f64,
    /// A.
    pub base: f64,
    /// dī/ds = k_cd dv_DA/ds, A/s.
    pub ramp: f64,
    /// The transient's amplitude at s = 0, A.
    pub delta: f64,
}

impl Response {
    /// i(s).
    pub fn at(&self, s: f64) -> f64 {
        self.with_decay(s, (-self.omega_cd * s).exp())
    }

    /// i(s) from the transient's decay e^{−ω_cd s} there.
    pub fn with_decay(&self, s: f64, decay: f64) -> f64 {
        self.base + self.ramp * s + self.delta * decay
    }

    /// Where di/ds = ramp − ω_cd δ e^{−ω_cd s} vanishes, if at some s > 0 (at most once):
    /// the current turns there.
    pub fn turning_point(&self) -> Option<f64> {
        let ratio = self.ramp / (self.omega_cd * self.delta);
        (ratio > 0.0 && ratio < 1.0).then(|| -ratio.ln() / self.omega_cd)
    }

    /// When the transient |δ| e^{−ω_cd s} falls to `level` (0 if it is below already).
    pub fn transient_below(&self, level: f64) -> f64 {
        (self.delta.abs() / level).ln().max(0.0) / self.omega_cd
    }
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
        assert!((command_for_current(0.04, 0.01, 0.41) - 10.0).abs() < 1e-14);
    }

    #[test]
    fn the_response_solves_the_rate_equation() {
        let driver = CurrentDriver {
            omega_cd: 7050.0,
            k_cd: 0.04,
            i_offset: 0.01,
        };
        for (i0, v, rate) in [(0.05, 1.3, 0.0), (0.2, -3.0, 40.0), (0.0, 2.0, -400.0)] {
            let response = driver.response(i0, v, rate);
            assert!((response.at(0.0) - i0).abs() < 1e-16);
            for s in [1e-5, 1e-4, 2e-3] {
                let h = 1e-9;
                let derivative = (response.at(s + h) - response.at(s - h)) / (2.0 * h);
                let expected = driver.rate(driver.static_current(v + rate * s), response.at(s));
                assert!(
                    (derivative - expected).abs() < 1e-6 * (1.0 + expected.abs()),
                    "{derivative} vs {expected}"
                );
            }
            if let Some(turn) = response.turning_point() {
                let h = 1e-9;
                assert!((response.at(turn + h) - response.at(turn - h)).abs() < 1e-12);
            }
            let settled = response.transient_below(1e-15);
            assert!((response.delta * (-driver.omega_cd * settled).exp()).abs() <= 1.0001e-15);
        }
    }
}
