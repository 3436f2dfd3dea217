//! The bench's own implementation of the thesis model (§2.2–2.7) with its effects: the
//! orifice geometry, the constants and the right-hand side that RK4 integrates.

use super::*;

/// Constants of the thesis model with the defaults of docs/model.md (SI units).
#[derive(Clone, Debug, PartialEq)]
pub struct BenchParams {
    pub p_supply: f64,
    pub p_return: f64,
    pub temperature: f64,
    pub gamma: f64,
    pub r_gas: f64,
    pub k_cd: f64,
    pub i_offset: f64,
    pub omega_cd: f64,
    pub k_m: f64,
    pub omega_1: f64,
    pub omega_2: f64,
    pub zeta_2: f64,
    pub x_jp_sat: f64,
    pub f_jp_sat: f64,
    pub x_jp_offset: f64,
    pub d_jp: f64,
    pub c_d: f64,
    pub c_dm_a_lpp: f64,
    pub c_db_a_lpp: f64,
    pub l_cyl: f64,
    pub l_p: f64,
    pub l_s: f64,
    pub l_sup: f64,
    pub l_spring0: f64,
    pub d_cyl: f64,
    pub k_spring: f64,
}

impl Default for BenchParams {
    fn default() -> Self {
        Self {
            p_supply: 652_925.0,
            p_return: 101_325.0,
            temperature: 293.15,
            gamma: 1.4,
            r_gas: 287.0,
            k_cd: 0.04,
            i_offset: 0.0,
            omega_cd: 7050.0,
            k_m: 1.946,
            omega_1: 973.9,
            omega_2: 1856.7,
            zeta_2: 0.019,
            x_jp_sat: 0.5e-3,
            f_jp_sat: 0.45,
            x_jp_offset: 0.099e-3,
            d_jp: 0.9652e-3,
            c_d: 0.696,
            c_dm_a_lpp: -0.0475e-6,
            c_db_a_lpp: 0.0971e-6,
            l_cyl: 78e-3,
            l_p: 8e-3,
            l_s: 7e-3,
            l_sup: 11e-3,
            l_spring0: 69.1e-3,
            d_cyl: 15.875e-3,
            k_spring: 88.14,
        }
    }
}

impl BenchParams {
    /// The constants by name (the fields' names), for a plant whose thesis constants depart
    /// from the defaults.
    pub fn field_mut(&mut self, name: &str) -> Option<&mut f64> {
        Some(match name {
            "p_supply" => &mut self.p_supply,
            "p_return" => &mut self.p_return,
            "temperature" => &mut self.temperature,
            "gamma" => &mut self.gamma,
            "r_gas" => &mut self.r_gas,
            "k_cd" => &mut self.k_cd,
            "i_offset" => &mut self.i_offset,
            "omega_cd" => &mut self.omega_cd,
            "k_m" => &mut self.k_m,
            "omega_1" => &mut self.omega_1,
            "omega_2" => &mut self.omega_2,
            "zeta_2" => &mut self.zeta_2,
            "x_jp_sat" => &mut self.x_jp_sat,
            "f_jp_sat" => &mut self.f_jp_sat,
            "x_jp_offset" => &mut self.x_jp_offset,
            "d_jp" => &mut self.d_jp,
            "c_d" => &mut self.c_d,
            "c_dm_a_lpp" => &mut self.c_dm_a_lpp,
            "c_db_a_lpp" => &mut self.c_db_a_lpp,
            "l_cyl" => &mut self.l_cyl,
            "l_p" => &mut self.l_p,
            "l_s" => &mut self.l_s,
            "l_sup" => &mut self.l_sup,
            "l_spring0" => &mut self.l_spring0,
            "d_cyl" => &mut self.d_cyl,
            "k_spring" => &mut self.k_spring,
            _ => return None,
        })
    }
}

// ---------------------------------------------------------------------------------------------
// Geometry: circle overlaps (own closed forms, checked against grid integration in the tests)
// ---------------------------------------------------------------------------------------------

/// Overlap of two circles of equal radius `r` whose centres are `d` apart: r²(θ − sin θ),
/// θ the central angle of the common chord.
pub(crate) fn lens_equal(d: f64, r: f64) -> f64 {
    let d = d.abs();
    if d >= 2.0 * r {
        return 0.0;
    }
    let theta = 2.0 * (d / (2.0 * r)).acos();
    r * r * (theta - theta.sin())
}

/// Overlap of a circle of radius `a` with a circle of radius `b ≥ a`, centres `d` apart: the sum
/// of the two circular segments cut by the common chord, each r²(φ − sin φ cos φ) with φ the
/// half angle seen from its centre.
pub(crate) fn lens_general(d: f64, a: f64, b: f64) -> f64 {
    let d = d.abs();
    if d >= a + b {
        return 0.0;
    }
    if d <= b - a {
        return PI * a * a;
    }
    let ca = ((d * d + a * a - b * b) / (2.0 * d * a)).clamp(-1.0, 1.0);
    let cb = ((d * d + b * b - a * a) / (2.0 * d * b)).clamp(-1.0, 1.0);
    let (pa, pb) = (ca.acos(), cb.acos());
    a * a * (pa - pa.sin() * ca) + b * b * (pb - pb.sin() * cb)
}

/// Supply and return areas of ports 1 and 2 at jet pipe absolute position `x`:
/// (A_s1, A_r1, A_s2, A_r2).
pub(crate) fn port_areas(x: f64, d_jp: f64) -> (f64, f64, f64, f64) {
    let r = 0.5 * d_jp;
    let a_port = PI * r * r;
    let (d1, d2) = (x - d_jp, x + d_jp);
    let a_s1 = lens_equal(d1, r);
    let a_s2 = lens_equal(d2, r);
    let a_r1 = (a_port - lens_general(d1, r, 3.0 * r)).max(0.0);
    let a_r2 = (a_port - lens_general(d2, r, 3.0 * r)).max(0.0);
    (a_s1, a_r1, a_s2, a_r2)
}

// ---------------------------------------------------------------------------------------------
// Model
// ---------------------------------------------------------------------------------------------

pub(crate) const NS: usize = 22;
pub(crate) type State = [f64; NS];
pub(crate) const S_I: usize = 0; // coil current
pub(crate) const S_X1: usize = 1; // output of the first-order jet pipe lag
pub(crate) const S_XJP: usize = 2; // jet pipe position (before offset)
pub(crate) const S_VJP: usize = 3; // its velocity
pub(crate) const S_Z: usize = 4; // Bouc–Wen hysteresis state
pub(crate) const S_P1: usize = 5;
pub(crate) const S_P2: usize = 6;
pub(crate) const S_T1: usize = 7;
pub(crate) const S_T2: usize = 8;
pub(crate) const S_PD1: usize = 9; // dead volume pressures
pub(crate) const S_PD2: usize = 10;
pub(crate) const S_PPL: usize = 11; // supply plenum pressure
pub(crate) const S_XL: usize = 12; // output of the extra jet pipe lag (undeclared)
pub(crate) const S_FF: usize = 13; // force sensor lag output (undeclared)
pub(crate) const S_DEL: usize = 14; // piston-stopper contact deflection (undeclared)
pub(crate) const S_PL1: usize = 15; // port 1 line pressure upstream of the restriction (undeclared)
pub(crate) const S_FF2: usize = 16; // force sensor second-order filter output (undeclared)
pub(crate) const S_FF2_RATE: usize = 17; // and its rate
pub(crate) const S_PF1: usize = 18; // pressure transducer 1 second-order filter output (undeclared)
pub(crate) const S_PF1_RATE: usize = 19; // and its rate
pub(crate) const S_CF: usize = 20; // command second-order filter output (undeclared)
pub(crate) const S_CF_RATE: usize = 21; // and its rate

/// Integration step (s): 50 steps per 1 ms command/log period.
pub(crate) const H: f64 = 20e-6;
pub(crate) const SAMPLE: f64 = 1e-3;
/// Below this pressure difference the orifice law is the secant line through zero.
pub(crate) const DP_LIN: f64 = 20.0;
pub(crate) const M_DOT_NOMINAL: f64 = 2.0e-4;
pub(crate) const PLENUM_VOLUME: f64 = 2e-6;
pub(crate) const LINE_TAU: f64 = 1e-3;
pub(crate) const TAU_ISO: f64 = 0.5e-3;
/// Atmosphere into which the undeclared chamber leak vents (Pa).
pub(crate) const P_ATM: f64 = 101_325.0;
/// Line volume between receiver port 1 and the undeclared restriction (m³), enlarged only
/// when RK4 would need it.
pub(crate) const LINE1_VOLUME: f64 = 3e-6;
/// Relaxation time of the piston on its contact compliance (s): mass and seal damping.
pub(crate) const TAU_CONTACT: f64 = 0.5e-3;

pub(crate) struct Model {
    pub(crate) p: BenchParams,
    pub(crate) e: BenchEffects,
    pub(crate) a_p: f64,
    /// The piston's area over its nominal `a_p` at the time last evaluated (the bore drift).
    pub(crate) area_scale: std::cell::Cell<f64>,
    pub(crate) l_dead: f64, // L_p + L_s + L_sup
    pub(crate) r_crit: f64,
    pub(crate) c1: f64,
    pub(crate) c2: f64,
    pub(crate) inv_gamma: f64,
    // effects
    pub(crate) hyst: bool,
    pub(crate) bw_a: f64,
    pub(crate) bw_beta: f64,
    pub(crate) bw_gamma: f64,
    pub(crate) heat: bool,
    pub(crate) inv_tau_th: f64,
    pub(crate) dead1: bool,
    pub(crate) dead2: bool,
    pub(crate) g_line1: f64, // 1/R_line
    pub(crate) g_line2: f64,
    pub(crate) supply: bool,
    pub(crate) cda_supply: f64,
    pub(crate) v_plenum: f64,
    // undeclared mechanisms
    pub(crate) cmd_limit: bool,
    pub(crate) slew: bool,
    pub(crate) jp_lag: bool,
    pub(crate) leak1: bool,
    pub(crate) viscous: bool,
    pub(crate) contact: bool,
    pub(crate) f_lag: bool,
    pub(crate) ret_bp: bool,
    pub(crate) rcv_off: bool,
    pub(crate) blend: bool,
    pub(crate) ret_area: bool,
    pub(crate) line1: bool,
    pub(crate) v_line1: f64,
}

impl Model {
    pub(crate) fn new(p: &BenchParams, e: &BenchEffects) -> Self {
        let g = p.gamma;
        let rt = p.r_gas * p.temperature;
        let a_p = PI * p.d_cyl * p.d_cyl / 4.0;
        let w = e.hysteresis_width;
        let hyst = w > 0.0;
        let heat = e.heat_transfer > 0.0;
        let alpha = e.heat_transfer.clamp(0.0, 1.0);
        let inv_tau_th = if heat {
            alpha / (TAU_ISO * 1000f64.powf(1.0 - alpha))
        } else {
            0.0
        };
        let dead1 = e.dead_volume_1 > 0.0;
        let dead2 = e.dead_volume_2 > 0.0;
        let g_line = |v: f64| if v > 0.0 { v / (g * rt * LINE_TAU) } else { 0.0 };
        let supply = e.supply_resistance > 0.0;
        let rho_s = p.p_supply / rt;
        let cda_supply = if supply {
            (M_DOT_NOMINAL / (rho_s * e.supply_resistance)).sqrt()
        } else {
            0.0
        };
        // Plenum: 2 cm³, or larger if the linear-zone conductances would make RK4 marginal.
        let rho_max = p.p_supply.max(p.p_return) / rt;
        let slope = |cda: f64| cda * (2.0 * rho_max / DP_LIN).sqrt();
        let port_max = p.c_d * PI * p.d_jp * p.d_jp / 4.0;
        let v_needed = g * rt * H * (slope(cda_supply) + 2.0 * slope(port_max)) / 1.0;
        let v_plenum = PLENUM_VOLUME.max(v_needed);
        let cda_line1 = e.undeclared.port_1_restriction.max(0.0);
        let v_line1 = LINE1_VOLUME.max(g * rt * H * (slope(cda_line1) + 2.0 * slope(port_max)));
        Self {
            p: p.clone(),
            e: e.clone(),
            a_p,
            area_scale: std::cell::Cell::new(1.0),
            l_dead: p.l_p + p.l_s + p.l_sup,
            r_crit: (2.0 / (g + 1.0)).powf(g / (g - 1.0)),
            c1: (g / p.r_gas * (2.0 / (g + 1.0)).powf((g + 1.0) / (g - 1.0))).sqrt(),
            c2: (g / p.r_gas * (2.0 / (g - 1.0))).sqrt(),
            inv_gamma: 1.0 / g,
            hyst,
            bw_a: 0.5,
            bw_beta: if hyst { 0.75 / w } else { 0.0 },
            bw_gamma: if hyst { 0.25 / w } else { 0.0 },
            heat,
            inv_tau_th,
            dead1,
            dead2,
            g_line1: g_line(e.dead_volume_1),
            g_line2: g_line(e.dead_volume_2),
            supply,
            cda_supply,
            v_plenum,
            cmd_limit: e.undeclared.command_limit > 0.0,
            slew: e.undeclared.current_slew_limit > 0.0,
            jp_lag: e.undeclared.jet_pipe_lag > 0.0,
            leak1: e.undeclared.chamber_leak_1 > 0.0,
            viscous: e.undeclared.viscous_friction > 0.0,
            contact: e.undeclared.contact_stiffness > 0.0,
            f_lag: e.undeclared.force_sensor_lag > 0.0,
            ret_bp: e.undeclared.return_back_pressure != 0.0,
            rcv_off: e.undeclared.receiver_offset != 0.0,
            blend: e.undeclared.jet_pipe_curve_blend != 0.0,
            ret_area: e.undeclared.return_area_reduction != 0.0,
            line1: e.undeclared.port_1_restriction > 0.0,
            v_line1,
        }
    }

    /// Command as the current driver sees it (after the undeclared D/A limit).
    #[inline]
    pub(crate) fn driver_input(&self, v: f64) -> f64 {
        let q = self.e.undeclared.command_quantum;
        let v = if q > 0.0 { (v / q).round() * q } else { v };
        let d = self.e.undeclared.command_dead_zone;
        let v = if d > 0.0 {
            v.signum() * (v.abs() - d).max(0.0)
        } else {
            v
        };
        let v = if self.e.undeclared.command_upper_limit > 0.0 {
            v.min(self.e.undeclared.command_upper_limit)
        } else {
            v
        };
        if self.cmd_limit {
            let l = self.e.undeclared.command_limit;
            v.clamp(-l, l)
        } else {
            v
        }
    }

    /// Compressible orifice flow (2.18)–(2.22) from `pu` to `pd` (pu > pd), ≥ 0.
    #[inline]
    pub(crate) fn flow_down(&self, cda: f64, pu: f64, tu: f64, pd: f64) -> f64 {
        let r = pd / pu;
        let k = cda * pu / tu.sqrt();
        if r <= self.r_crit {
            k * self.c1
        } else {
            // r^(2/γ) − r^((γ+1)/γ) = a (a − r), a = r^(1/γ)
            let a = r.powf(self.inv_gamma);
            k * self.c2 * (a * (a - r)).max(0.0).sqrt()
        }
    }

    /// [`Self::orifice`] for a valve orifice of C_d·A = `cda` at the thesis's C_d: with
    /// `discharge_ratio_rise` s, C_d grows by the factor 1 + s (1 − r)², r = P_down/P_up.
    #[inline]
    pub(crate) fn valve_orifice(&self, cda: f64, pa: f64, ta: f64, pb: f64, tb: f64) -> f64 {
        let s = self.e.undeclared.discharge_ratio_rise;
        if s == 0.0 {
            return self.orifice(cda, pa, ta, pb, tb);
        }
        let r = if pa.max(pb) > 0.0 { pa.min(pb) / pa.max(pb) } else { 1.0 };
        self.orifice(cda * (1.0 + s * (1.0 - r) * (1.0 - r)), pa, ta, pb, tb)
    }

    /// Signed mass flow from side a to side b through C_d·A = `cda`, regularised near Δp = 0.
    #[inline]
    pub(crate) fn orifice(&self, cda: f64, pa: f64, ta: f64, pb: f64, tb: f64) -> f64 {
        if cda <= 0.0 {
            return 0.0;
        }
        let (pu, tu, pd, s) = if pa >= pb {
            (pa, ta, pb, 1.0)
        } else {
            (pb, tb, pa, -1.0)
        };
        let dp = pu - pd;
        if dp >= DP_LIN {
            s * self.flow_down(cda, pu, tu, pd)
        } else {
            s * self.flow_down(cda, pu, tu, pu - DP_LIN) * (dp / DP_LIN)
        }
    }

    /// The piston's area at the time last evaluated.
    pub(crate) fn area(&self) -> f64 {
        self.a_p * self.area_scale.get()
    }

    pub(crate) fn volumes(&self, xs: f64) -> (f64, f64) {
        let xp = xs - self.l_dead;
        let v1 = self.area() * xp + 0.0;
        let v2 = self.area() * (self.p.l_cyl - xp - self.p.l_p);
        (v1, v2)
    }

    pub(crate) fn static_position(&self, i: f64) -> f64 {
        if self.blend {
            let u = self.p.k_m * i / self.p.f_jp_sat;
            let b = self.e.undeclared.jet_pipe_curve_blend;
            return self.p.x_jp_sat * ((1.0 - b) * u.tanh() + b * u / (1.0 + u * u).sqrt());
        }
        self.p.x_jp_sat * (self.p.k_m * i / self.p.f_jp_sat).tanh()
    }

    pub(crate) fn spring_force(&self, xs: f64) -> f64 {
        self.p.k_spring * (self.p.l_spring0 - (xs - self.p.l_s - self.p.l_p))
    }

    pub(crate) fn friction(&self, v: f64) -> f64 {
        let fc = self.e.friction_coulomb;
        if fc <= 0.0 {
            return 0.0;
        }
        let smoothing = self.e.undeclared.friction_smoothing_velocity;
        if smoothing > 0.0 {
            return fc * (v / smoothing).tanh();
        }
        let fs = 1.5 * fc;
        let (v_s, v_eps, b) = (5e-3, 0.2e-3, fc * 1.0);
        (fc + (fs - fc) * (-(v / v_s) * (v / v_s)).exp()) * (v / v_eps).tanh() + b * v
    }

    /// True actuator force (2.36)–(2.38) with friction.
    pub(crate) fn force(&self, y: &State, xs: f64, xs_dot: f64) -> f64 {
        self.force_moving(y, xs, xs_dot, 0.0)
    }

    /// The actuator force with the stopper accelerating at `xs_acc`: a moving mass between
    /// piston and sensor takes m · xs_acc of the pressure force.
    pub(crate) fn force_moving(&self, y: &State, xs: f64, xs_dot: f64, xs_acc: f64) -> f64 {
        let mut fp = self.area() * (y[S_P1] - y[S_P2]) - self.friction(xs_dot);
        if self.viscous {
            fp -= self.e.undeclared.viscous_friction * xs_dot;
        }
        let u = &self.e.undeclared;
        if u.quadratic_damping != 0.0 {
            fp -= u.quadratic_damping * xs_dot * xs_dot.abs();
        }
        if u.friction_band != 0.0 {
            let band = 0.5 * (((xs - 0.060) / 0.5e-3).tanh() - ((xs - 0.066) / 0.5e-3).tanh());
            fp -= u.friction_band * band * (xs_dot / 0.2e-3).tanh();
        }
        if u.seal_pressure_friction != 0.0 {
            // seals pressed harder by the chambers' gauge pressures; v_ε as the Coulomb seal's
            let gauge = y[S_P1] + y[S_P2] - 2.0 * self.p.p_return;
            fp -= u.seal_pressure_friction * gauge * (xs_dot / 0.2e-3).tanh();
        }
        if u.moving_mass != 0.0 {
            fp -= u.moving_mass * xs_acc;
        }
        if u.position_sign_force != 0.0 {
            fp += u.position_sign_force * (xs - u.position_sign_origin) * (xs_dot / 1e-3).tanh();
        }
        if u.direction_friction_out != 0.0 || u.direction_friction_in != 0.0 {
            let s = (xs_dot / 0.2e-3).tanh();
            fp -= u.direction_friction_out * s.max(0.0) + u.direction_friction_in * s.min(0.0);
        }
        if u.chamber_1_pressure_force != 0.0 {
            fp += u.chamber_1_pressure_force * (y[S_P1] - self.p.p_return);
        }
        fp.max(self.spring_force(xs))
    }

    /// Time derivatives.
    /// `p_src` is the supply pressure at the source (the thesis constant unless an undeclared
    /// supply drift or ripple is on).
    /// `t_gas` is the gas temperature (the thesis constant unless an undeclared drift is on).
    #[allow(clippy::too_many_arguments)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn rhs(
        &self,
        y: &State,
        v_cmd: f64,
        xs: f64,
        xs_dot: f64,
        p_src: f64,
        t_gas: f64,
        offset_ripple: f64,
        dy: &mut State,
    ) {
        let p = &self.p;
        let t0 = t_gas;
        let rt = p.r_gas * t0;
        // current driver (2.1)–(2.3)
        let i = y[S_I];
        let mut v_cmd = self.driver_input(v_cmd);
        let command_filter = self.e.undeclared.command_filter_frequency;
        if command_filter > 0.0 {
            let (rate, acceleration) = second_order(
                command_filter,
                self.e.undeclared.command_filter_damping,
                v_cmd,
                y[S_CF],
                y[S_CF_RATE],
            );
            dy[S_CF] = rate;
            dy[S_CF_RATE] = acceleration;
            v_cmd = y[S_CF];
        } else {
            dy[S_CF] = 0.0;
            dy[S_CF_RATE] = 0.0;
        }
        let mut offset = p.i_offset + offset_ripple;
        if self.e.undeclared.current_offset_direction != 0.0 {
            offset += self.e.undeclared.current_offset_direction * (xs_dot / 0.5e-3).tanh();
        }
        let mut di = p.omega_cd * (p.k_cd * v_cmd + offset - i);
        if self.slew {
            let s = self.e.undeclared.current_slew_limit;
            di = di.clamp(-s, s);
        }
        dy[S_I] = di;
        // static jet pipe curve f3 and hysteresis
        let u = p.k_m * i / p.f_jp_sat;
        let th = u.tanh();
        let mut xbar = p.x_jp_sat * th;
        // slope dx̄/du / x_sat
        let mut slope = 1.0 - th * th;
        if self.blend {
            // undeclared: static curve blended towards the algebraic sigmoid
            let b = self.e.undeclared.jet_pipe_curve_blend;
            let q = 1.0 / (1.0 + u * u).sqrt();
            xbar = p.x_jp_sat * ((1.0 - b) * th + b * u * q);
            slope = (1.0 - b) * slope + b * q * q * q;
        }
        let mut target = xbar;
        if self.hyst {
            let xbar_dot = p.x_jp_sat * slope * p.k_m * di / p.f_jp_sat;
            let z = y[S_Z];
            dy[S_Z] = self.bw_a * xbar_dot - self.bw_beta * xbar_dot.abs() * z - self.bw_gamma * xbar_dot * z.abs();
            target -= z;
        } else {
            dy[S_Z] = 0.0;
        }
        // undeclared extra lag between f3 and the jet pipe dynamics
        if self.jp_lag {
            dy[S_XL] = (target - y[S_XL]) / self.e.undeclared.jet_pipe_lag;
            target = y[S_XL];
        } else {
            dy[S_XL] = 0.0;
        }
        // jet pipe: first-order lag then second-order mode, unity DC gain
        dy[S_X1] = p.omega_1 * (target - y[S_X1]);
        dy[S_XJP] = y[S_VJP];
        dy[S_VJP] = p.omega_2 * p.omega_2 * (y[S_X1] - y[S_XJP]) - 2.0 * p.zeta_2 * p.omega_2 * y[S_VJP];
        // orifice areas
        let x_abs = if self.rcv_off {
            y[S_XJP] + (p.x_jp_offset + self.e.undeclared.receiver_offset)
        } else {
            y[S_XJP] + p.x_jp_offset
        };
        let (a_s1, mut a_r1, a_s2, mut a_r2) = port_areas(x_abs, p.d_jp);
        if self.ret_area {
            let f = 1.0 - self.e.undeclared.return_area_reduction;
            a_r1 *= f;
            a_r2 *= f;
        }
        let (p1, p2) = (y[S_P1], y[S_P2]);
        let (t1, t2) = if self.heat { (y[S_T1], y[S_T2]) } else { (t0, t0) };
        let ps = if self.supply { y[S_PPL] } else { p_src };
        let pr = if self.ret_bp {
            p.p_return + self.e.undeclared.return_back_pressure
        } else {
            p.p_return
        };
        // with the undeclared port 1 restriction, port 1 feeds a line at temperature T
        let (p1v, t1v) = if self.line1 { (y[S_PL1], t0) } else { (p1, t1) };
        let m_s1 = self.valve_orifice(p.c_d * a_s1, ps, t0, p1v, t1v);
        let m_r1 = self.valve_orifice(p.c_d * a_r1, p1v, t1v, pr, t0);
        // line → chamber 1 through the restriction
        let m_ln = if self.line1 {
            let m = self.orifice(self.e.undeclared.port_1_restriction, p1v, t0, p1, t1);
            dy[S_PL1] = p.gamma * rt * (m_s1 - m_r1 - m) / self.v_line1;
            m
        } else {
            dy[S_PL1] = 0.0;
            0.0
        };
        let m_s2 = self.valve_orifice(p.c_d * a_s2, ps, t0, p2, t2);
        let m_r2 = self.valve_orifice(p.c_d * a_r2, p2, t2, pr, t0);
        // leakage past the piston (2.23), positive 1 → 2
        let (pu, pd) = if p1 >= p2 { (p1, p2) } else { (p2, p1) };
        let cda_l = (p.c_dm_a_lpp * (pd / pu) + p.c_db_a_lpp).max(0.0);
        let m_l = self.orifice(cda_l, p1, t1, p2, t2);
        // dead volumes (side branches), positive chamber → branch
        let m_d1 = if self.dead1 {
            (p1 - y[S_PD1]) * self.g_line1
        } else {
            0.0
        };
        let m_d2 = if self.dead2 {
            (p2 - y[S_PD2]) * self.g_line2
        } else {
            0.0
        };
        dy[S_PD1] = if self.dead1 {
            p.gamma * rt * m_d1 / self.e.dead_volume_1
        } else {
            0.0
        };
        dy[S_PD2] = if self.dead2 {
            p.gamma * rt * m_d2 / self.e.dead_volume_2
        } else {
            0.0
        };
        // supply plenum
        if self.supply {
            let m_in = self.orifice(self.cda_supply, p_src, t0, ps, t0);
            dy[S_PPL] = p.gamma * rt * (m_in - m_s1 - m_s2) / self.v_plenum;
        } else {
            dy[S_PPL] = 0.0;
        }
        // undeclared leak of chamber 1 to the atmosphere, positive outwards
        let m_a1 = if self.leak1 {
            self.orifice(self.e.undeclared.chamber_leak_1, p1, t1, P_ATM, t0)
        } else {
            0.0
        };
        // undeclared compliance between piston and stopper: the piston sits δ beyond the
        // stopper, δ relaxing to F/k
        let (x_pist, x_pist_dot) = if self.contact {
            let f = self.force(y, xs, xs_dot);
            let tau = if self.e.undeclared.contact_lag > 0.0 {
                self.e.undeclared.contact_lag
            } else {
                TAU_CONTACT
            };
            let dd = (f / self.e.undeclared.contact_stiffness - y[S_DEL]) / tau;
            dy[S_DEL] = dd;
            (xs + y[S_DEL], xs_dot + dd)
        } else {
            dy[S_DEL] = 0.0;
            (xs, xs_dot)
        };
        // undeclared force sensor lag
        dy[S_FF] = if self.f_lag {
            (self.force(y, xs, xs_dot) - y[S_FF]) / self.e.undeclared.force_sensor_lag
        } else {
            0.0
        };
        // undeclared second-order filters of the force sensor (after its lag) and of
        // pressure transducer 1
        let u = &self.e.undeclared;
        if u.force_sensor_filter_frequency > 0.0 {
            let input = if self.f_lag { y[S_FF] } else { self.force(y, xs, xs_dot) };
            let (rate, acceleration) = second_order(
                u.force_sensor_filter_frequency,
                u.force_sensor_filter_damping,
                input,
                y[S_FF2],
                y[S_FF2_RATE],
            );
            dy[S_FF2] = rate;
            dy[S_FF2_RATE] = acceleration;
        } else {
            dy[S_FF2] = 0.0;
            dy[S_FF2_RATE] = 0.0;
        }
        if u.pressure_sensor_filter_1 > 0.0 {
            let (rate, acceleration) = second_order(
                u.pressure_sensor_filter_1,
                u.pressure_sensor_filter_damping_1,
                y[S_P1],
                y[S_PF1],
                y[S_PF1_RATE],
            );
            dy[S_PF1] = rate;
            dy[S_PF1_RATE] = acceleration;
        } else {
            dy[S_PF1] = 0.0;
            dy[S_PF1_RATE] = 0.0;
        }
        // chambers
        let (v1, v2) = self.volumes(x_pist);
        let (dv1, dv2) = (self.area() * x_pist_dot, -self.area() * x_pist_dot);
        let mut m1 = if self.line1 {
            m_ln - m_l - m_d1
        } else {
            m_s1 - m_r1 - m_l - m_d1
        };
        if self.leak1 {
            m1 -= m_a1;
        }
        let u = &self.e.undeclared;
        // undeclared chamber leaks beyond the orifice to atmosphere: an orifice from the
        // supply into chamber 2, a laminar path from chamber 1 to atmosphere, one from the
        // supply into chamber 2, one from chamber 1 into chamber 2; and a flow into chamber 2
        // alone in proportion to P1 − P2, which chamber 1 does not lose
        let m_sl2 = if u.supply_leak_2 > 0.0 {
            self.orifice(u.supply_leak_2, ps, t0, p2, t2)
        } else {
            0.0
        };
        let m_lam1 = u.laminar_leak_1 * (p1 - P_ATM);
        let m_lsl2 = u.laminar_supply_leak_2 * (ps - p2);
        let m_lx = u.laminar_cross_leak * (p1 - p2);
        m1 -= m_lam1 + m_lx;
        let m_di2 = u.difference_inflow_2 * (p1 - p2);
        let m2 = m_s2 - m_r2 + m_l - m_d2 + m_sl2 + m_lsl2 + m_lx + m_di2;
        if !self.heat {
            dy[S_P1] = p.gamma / v1 * (rt * m1 - p1 * dv1);
            dy[S_P2] = p.gamma / v2 * (rt * m2 - p2 * dv2);
            dy[S_T1] = 0.0;
            dy[S_T2] = 0.0;
        } else {
            // enthalpy flux Σ ṁ_k T_k,up (inflows at their source temperature, outflows at T_i)
            let up = |m: f64, t_src: f64, t_own: f64| if m > 0.0 { m * t_src } else { m * t_own };
            let mut h1 = if self.line1 {
                up(m_ln, t0, t1) + up(-m_l, t2, t1) + up(-m_d1, t0, t1)
            } else {
                up(m_s1, t0, t1) + up(-m_r1, t0, t1) + up(-m_l, t2, t1) + up(-m_d1, t0, t1)
            };
            if self.leak1 {
                h1 += up(-m_a1, t0, t1);
            }
            h1 += up(-m_lam1, t0, t1) + up(-m_lx, t2, t1);
            let h2 = up(m_s2, t0, t2) + up(-m_r2, t0, t2) + up(m_l, t1, t2) + up(-m_d2, t0, t2) + up(m_sl2, t0, t2);
            let h2 = h2 + up(m_lsl2, t0, t2) + up(m_lx, t1, t2) + up(m_di2, t0, t2);
            let chamber = |pc: f64, tc: f64, v: f64, dv: f64, m: f64, h: f64| {
                let dp = p.gamma / v * (p.r_gas * h - pc * dv) + pc * (t0 - tc) / tc * self.inv_tau_th;
                let dt = tc * (dp / pc + dv / v) - p.r_gas * tc * tc * m / (pc * v);
                (dp, dt)
            };
            let (dp1, dt1) = chamber(p1, t1, v1, dv1, m1, h1);
            let (dp2, dt2) = chamber(p2, t2, v2, dv2, m2, h2);
            dy[S_P1] = dp1;
            dy[S_P2] = dp2;
            dy[S_T1] = dt1;
            dy[S_T2] = dt2;
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Protocol (bench/README.md)
// ---------------------------------------------------------------------------------------------

/// y'' = ω² (u − y) − 2ζω y' of a unit-gain second-order low-pass filter of natural
/// frequency f (Hz) and damping ζ (1/√2 when 0): (y', y'').
pub(crate) fn second_order(frequency: f64, damping: f64, input: f64, y: f64, rate: f64) -> (f64, f64) {
    let omega = 2.0 * std::f64::consts::PI * frequency;
    let zeta = if damping > 0.0 {
        damping
    } else {
        std::f64::consts::FRAC_1_SQRT_2
    };
    (rate, omega * omega * (input - y) - 2.0 * zeta * omega * rate)
}

#[cfg(test)]
mod tests {
    use super::BenchParams;
    use crate::{BenchEffects, UndeclaredEffects};

    #[test]
    fn a_smoothed_friction_is_the_coulomb_level_times_tanh_of_the_speed_over_its_scale() {
        let smooth = BenchEffects {
            friction_coulomb: 2.0,
            undeclared: UndeclaredEffects {
                friction_smoothing_velocity: 0.01,
                ..UndeclaredEffects::default()
            },
            ..BenchEffects::default()
        };
        let plant = super::Model::new(&BenchParams::default(), &smooth);
        for v in [-0.05, -0.01, -0.002, 0.0, 0.005, 0.01, 0.03] {
            let expected = 2.0 * (v / 0.01_f64).tanh();
            assert!(
                (plant.friction(v) - expected).abs() < 1e-12,
                "v = {v}: {}",
                plant.friction(v)
            );
        }
        // The Stribeck curve without the smoothing: 1.5 F_c of stiction at a crawl.
        let stribeck = super::Model::new(
            &BenchParams::default(),
            &BenchEffects {
                friction_coulomb: 2.0,
                ..BenchEffects::default()
            },
        );
        assert!(
            (stribeck.friction(0.002) - 2.9).abs() < 0.1,
            "{}",
            stribeck.friction(0.002)
        );
    }

    #[test]
    fn every_constant_is_found_by_its_own_name_and_no_other() {
        let names = [
            "p_supply",
            "p_return",
            "temperature",
            "gamma",
            "r_gas",
            "k_cd",
            "i_offset",
            "omega_cd",
            "k_m",
            "omega_1",
            "omega_2",
            "zeta_2",
            "x_jp_sat",
            "f_jp_sat",
            "x_jp_offset",
            "d_jp",
            "c_d",
            "c_dm_a_lpp",
            "c_db_a_lpp",
            "l_cyl",
            "l_p",
            "l_s",
            "l_sup",
            "l_spring0",
            "d_cyl",
            "k_spring",
        ];
        let mut changed = vec![];
        for name in names {
            let mut p = BenchParams::default();
            *p.field_mut(name).unwrap() = -12345.0;
            assert_ne!(p, BenchParams::default(), "{name}");
            assert!(!changed.contains(&p), "{name} sets another's field");
            changed.push(p);
        }
        assert!(BenchParams::default().field_mut("k_spring ").is_none());
        assert!(BenchParams::default().field_mut("spring").is_none());
    }
}
