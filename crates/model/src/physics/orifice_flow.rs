//! Compressible orifice flow, (2.18)–(2.22), and the leakage past the piston, (2.23).

use crate::polynomial::{Piecewise, DEGREE};

mod pair;
pub use pair::mass_flow_and_leakage;

/// Width of the band of pressure ratios next to 1 in which the √(1 − r) law of (2.22) is
/// replaced by a C¹ cubic through zero. The exact law has an infinite slope at equal
/// pressures, which no implicit integrator can use; inside the band the pressure
/// difference is below 1e-5 of the upstream pressure (≈ 1 Pa at atmospheric pressure,
/// ≈ 2e-4 N of piston force), and outside it the flow is the thesis's to the last bit.
pub const REGULARISATION_RATIO_BAND: f64 = 1e-5;

/// Constants of (2.19)–(2.21) for one gas, precomputed once.
#[derive(Clone, Debug, PartialEq)]
pub struct FlowConstants {
    pub gamma: f64,
    /// Critical pressure ratio r_c, (2.19).
    pub critical_ratio: f64,
    /// C1 of (2.20) (choked flow).
    pub c1: f64,
    /// C2 of (2.21) (unchoked flow).
    pub c2: f64,
    /// 1/√T of the upstream gas (constant temperature, §2.6).
    pub inv_sqrt_temperature: f64,
    band_edge_f2: f64,
    /// f2(r)/√(1 − r) on the unchoked range, tabulated (2.3 kB).
    unchoked: FactorTable,
}

impl FlowConstants {
    pub fn new(gamma: f64, r_gas: f64, temperature: f64) -> Self {
        let critical_ratio = (2.0 / (gamma + 1.0)).powf(gamma / (gamma - 1.0));
        let c1 = (gamma / r_gas * (2.0 / (gamma + 1.0)).powf((gamma + 1.0) / (gamma - 1.0))).sqrt();
        let c2 = (gamma / r_gas * (2.0 / (gamma - 1.0))).sqrt();
        let band_edge_f2 = f2_exact(gamma, 1.0 - REGULARISATION_RATIO_BAND);
        Self {
            gamma,
            critical_ratio,
            c1,
            c2,
            inv_sqrt_temperature: 1.0 / temperature.sqrt(),
            band_edge_f2,
            unchoked: FactorTable::for_gas(gamma, critical_ratio),
        }
    }

    /// f2 of (2.22), regularised in the band next to r = 1.
    #[inline(always)]
    pub fn f2(&self, ratio: f64) -> f64 {
        // Outside the band (1 − r ≥ band), tested without a division.
        if 1.0 - ratio >= REGULARISATION_RATIO_BAND {
            // √(1 − r) and the tabulated factor are independent: the root overlaps the
            // polynomial instead of following it.
            match self.unchoked.value(ratio) {
                Some(g) => (1.0 - ratio).sqrt() * g,
                None => f2_exact(self.gamma, ratio),
            }
        } else {
            // g(s) = (5s − s³)/4: g(0) = 0, g(1) = 1, g'(1) = 1/2 = d√s/ds at s = 1.
            let s = ((1.0 - ratio) / REGULARISATION_RATIO_BAND).clamp(0.0, 1.0);
            self.band_edge_f2 * (1.25 * s - 0.25 * s * s * s)
        }
    }
}

/// f2 of (2.22): √(r^{2/γ} − r^{(γ+1)/γ}), computed as √(a (a − r)) with a = r^{1/γ}:
/// one power instead of two (the flow is evaluated millions of times per simulation).
pub fn f2_exact(gamma: f64, ratio: f64) -> f64 {
    let a = ratio.powf(1.0 / gamma);
    (a * (a - ratio)).max(0.0).sqrt()
}

/// Where an instance's [`UnchokedFactor`] lives: air's (γ = 1.4, the default) is built once
/// per process in static memory and shared by every instance; another gas's is owned by the
/// instance and shared with its clones. No process-wide cache on the heap: an FMU is
/// unloaded with dlclose, and the heap a static pointed to would then leak.
#[derive(Clone, Debug)]
pub enum FactorTable {
    Air(&'static UnchokedFactor),
    Owned(std::sync::Arc<UnchokedFactor>),
}

/// γ of air, whose table is shared.
const AIR_GAMMA: f64 = 1.4;

impl FactorTable {
    pub fn for_gas(gamma: f64, critical_ratio: f64) -> Self {
        if gamma == AIR_GAMMA {
            static AIR: crate::compat::OnceLock<UnchokedFactor> = crate::compat::OnceLock::new();
            Self::Air(AIR.get_or_init(|| UnchokedFactor::new(gamma, critical_ratio)))
        } else {
            Self::Owned(std::sync::Arc::new(UnchokedFactor::new(gamma, critical_ratio)))
        }
    }
}

impl std::ops::Deref for FactorTable {
    type Target = UnchokedFactor;
    fn deref(&self) -> &UnchokedFactor {
        match self {
            Self::Air(table) => table,
            Self::Owned(table) => table,
        }
    }
}

impl PartialEq for FactorTable {
    fn eq(&self, other: &Self) -> bool {
        **self == **other
    }
}

/// Pieces of [`UnchokedFactor`].
const UNCHOKED_PIECES: usize = 32;

/// g(r) = f2(r)/√(1 − r) for r in [r_c, 1], by piecewise polynomials built once per gas.
///
/// The flow law evaluates f2 in every unchoked orifice, several times per right-hand side
/// and millions of times per simulation, on the integrator's critical path: r^{1/γ} by
/// `powf` takes ~18 ns before the root can start. g is analytic on [r_c, 1] (f2 vanishes
/// like √(1 − r) at r = 1), so f2 = √(1 − r)·g(r) with g a degree-8 polynomial on each of
/// 32 pieces, evaluated by Estrin's scheme while the root is computed. The interpolation
/// nodes use g = √(a r expm1((1/γ − 1) ln r)/(1 − r)), a = r^{1/γ}, which has none of the
/// cancellation of a − r near r = 1: the table is accurate to a few units in the last
/// place where (2.22) as written loses digits like 1/(1 − r). Its truncation error is
/// below (w/c)^9 for pieces of half-width w centred at c; when that bound is not below
/// 1e-16 (for γ above about 1.72, beyond a monatomic gas's 5/3, where r_c is small) `value`
/// returns `None` and the caller uses (2.22) directly.
#[derive(Clone, Debug, PartialEq)]
pub struct UnchokedFactor {
    gamma: f64,
    accurate: bool,
    pieces: Piecewise<UNCHOKED_PIECES>,
}

/// g(r) = f2(r)/√(1 − r) without cancellation near r = 1, for building the table and testing.
pub fn unchoked_factor(gamma: f64, ratio: f64) -> f64 {
    if ratio == 1.0 {
        // a − r ≈ (1 − 1/γ)(1 − r) as r → 1.
        return (1.0 - 1.0 / gamma).sqrt();
    }
    let a = ratio.powf(1.0 / gamma);
    let a_minus_r = ratio * ((1.0 / gamma - 1.0) * (ratio - 1.0).ln_1p()).exp_m1();
    (a * a_minus_r / (1.0 - ratio)).max(0.0).sqrt()
}

impl UnchokedFactor {
    pub fn new(gamma: f64, critical_ratio: f64) -> Self {
        let pieces = Piecewise::interpolating(critical_ratio, 1.0, |r| unchoked_factor(gamma, r));
        let half = 0.5 * (1.0 - critical_ratio) / UNCHOKED_PIECES as f64;
        let worst_ratio = half / (critical_ratio + half);
        Self {
            gamma,
            accurate: worst_ratio.powi(DEGREE as i32 + 1) < 1e-16,
            pieces,
        }
    }

    /// The pieces, when they are accurate (see the type's text).
    pub(crate) fn table(&self) -> Option<&Piecewise<UNCHOKED_PIECES>> {
        self.accurate.then_some(&self.pieces)
    }

    /// g(r), or `None` outside [r_c, 1], for NaN, and when the table is not accurate.
    #[inline]
    pub fn value(&self, ratio: f64) -> Option<f64> {
        if !self.accurate {
            return None;
        }
        self.pieces.value(ratio)
    }
}

/// Mass flow (kg/s) through an orifice of effective area `cd_area` (C_d·A, m²) between
/// pressures `p_from` and `p_to`, (2.18): positive from `p_from` to `p_to`, negative when
/// the pressure difference is reversed; choked below the critical ratio.
#[inline]
pub fn mass_flow(k: &FlowConstants, cd_area: f64, p_from: f64, p_to: f64) -> f64 {
    mass_flow_inline(k, cd_area, p_from, p_to)
}

/// [`mass_flow`] inlined wherever it is called: for the thesis model's right-hand side, which
/// evaluates it five times (where the compiler would otherwise keep one out-of-line copy).
#[inline(always)]
pub fn mass_flow_inline(k: &FlowConstants, cd_area: f64, p_from: f64, p_to: f64) -> f64 {
    // A closed orifice first: two of the valve's four are closed over the operating range.
    if cd_area == 0.0 {
        return 0.0;
    }
    let (p_up, p_down, sign) = if p_from >= p_to {
        (p_from, p_to, 1.0)
    } else {
        (p_to, p_from, -1.0)
    };
    if p_up <= 0.0 {
        return 0.0;
    }
    flow_from_upstream(k, cd_area, p_up, p_down / p_up, sign)
}

/// (2.18) from the upstream pressure and the pressure ratio, with the direction's `sign`.
#[inline(always)]
fn flow_from_upstream(k: &FlowConstants, cd_area: f64, p_up: f64, ratio: f64, sign: f64) -> f64 {
    let scale = cd_area * p_up * k.inv_sqrt_temperature;
    let flow = if ratio <= k.critical_ratio {
        scale * k.c1
    } else {
        scale * k.c2 * k.f2(ratio)
    };
    sign * flow
}

/// Effective area C_d,lpp·A_lpp of the leakage past the piston, (2.23): the discharge
/// coefficient depends on the pressure ratio across the long, narrow ring.
pub fn leakage_cd_area(c_dm_a_lpp: f64, c_db_a_lpp: f64, p1: f64, p2: f64) -> f64 {
    let (p_up, p_down) = if p1 >= p2 { (p1, p2) } else { (p2, p1) };
    if p_up <= 0.0 {
        return 0.0;
    }
    (c_dm_a_lpp * (p_down / p_up) + c_db_a_lpp).max(0.0)
}

/// [`leakage_flow`] inlined, for the thesis model's right-hand side: the pressure ratio that
/// sets (2.23)'s discharge coefficient is the flow's own, divided once.
#[inline(always)]
pub fn leakage_flow_inline(k: &FlowConstants, c_dm_a_lpp: f64, c_db_a_lpp: f64, p1: f64, p2: f64) -> f64 {
    let (p_up, p_down, sign) = if p1 >= p2 { (p1, p2, 1.0) } else { (p2, p1, -1.0) };
    if p_up <= 0.0 {
        return 0.0;
    }
    let ratio = p_down / p_up;
    let cd_area = (c_dm_a_lpp * ratio + c_db_a_lpp).max(0.0);
    if cd_area == 0.0 {
        return 0.0;
    }
    flow_from_upstream(k, cd_area, p_up, ratio, sign)
}

/// Leakage mass flow from chamber 1 to chamber 2 (negative when P2 > P1).
pub fn leakage_flow(k: &FlowConstants, c_dm_a_lpp: f64, c_db_a_lpp: f64, p1: f64, p2: f64) -> f64 {
    mass_flow(k, leakage_cd_area(c_dm_a_lpp, c_db_a_lpp, p1, p2), p1, p2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn f2_with_one_power_equals_the_thesis_form() {
        for gamma in [1.4, 1.3, 1.2] {
            for k in 0..=1000 {
                let r = k as f64 / 1000.0 * (1.0 - 1e-5);
                let thesis = (r.powf(2.0 / gamma) - r.powf((gamma + 1.0) / gamma)).max(0.0).sqrt();
                let fast = f2_exact(gamma, r);
                // Both forms subtract numbers near 1 as r → 1: rounding grows like ε/(1 − r).
                let bound = 1e-13 + 1e-15 / (1.0 - r);
                assert!(
                    (fast - thesis).abs() <= bound * thesis.max(1e-3),
                    "γ {gamma} r {r}: {fast} vs {thesis}"
                );
            }
        }
    }

    fn air() -> FlowConstants {
        FlowConstants::new(1.4, 287.0, 293.15)
    }

    #[test]
    fn constants_of_2_19_to_2_21() {
        let k = air();
        assert!((k.critical_ratio - 0.5283).abs() < 1e-4, "r_c = {}", k.critical_ratio);
        assert!((k.c1 - 0.040418).abs() < 1e-5, "C1 = {}", k.c1);
        assert!((k.c2 - 0.156174).abs() < 1e-5, "C2 = {}", k.c2);
    }

    #[test]
    fn flow_is_continuous_and_smooth_at_the_choke_point() {
        // At r = r_c the unchoked law must equal the choked one: C2 f2(r_c) = C1.
        let k = air();
        let (cda, pu) = (0.5e-6, 6e5);
        let at = |r: f64| mass_flow(&k, cda, pu, r * pu);
        let below = at(k.critical_ratio * (1.0 - 1e-12));
        let above = at(k.critical_ratio * (1.0 + 1e-12));
        assert!((below - above).abs() < 1e-9 * below, "{below} vs {above}");
        // The slope is continuous too: the unchoked flow has its maximum at r_c, so just
        // above r_c it is flat compared with its slope at r = 0.8.
        let slope = |r: f64, h: f64| (at(r + h) - at(r)) / h;
        let near = slope(k.critical_ratio + 1e-7, 1e-8).abs();
        let far = slope(0.8, 1e-6).abs();
        assert!(near < 1e-3 * far, "slope near r_c {near}, at 0.8 {far}");
    }

    #[test]
    fn flow_reverses_with_the_pressure_difference_and_vanishes_at_equal_pressures() {
        let k = air();
        let forward = mass_flow(&k, 0.5e-6, 3e5, 2e5);
        let backward = mass_flow(&k, 0.5e-6, 2e5, 3e5);
        assert!(forward > 0.0);
        // Reversed flow has the upstream pressure 3e5 too: equal magnitude.
        assert!((forward + backward).abs() < 1e-18);
        assert_eq!(mass_flow(&k, 0.5e-6, 2e5, 2e5), 0.0);
    }

    #[test]
    fn regularisation_is_continuous_at_the_band_edge_and_monotone_inside() {
        let k = air();
        let edge = 1.0 - REGULARISATION_RATIO_BAND;
        let exact = f2_exact(1.4, edge);
        assert!((k.f2(edge) - exact).abs() < 1e-9 * exact);
        assert!((k.f2(edge + 1e-13) - exact).abs() < 1e-7 * exact);
        let mut last = 0.0;
        for j in 0..=100 {
            let r = 1.0 - REGULARISATION_RATIO_BAND * j as f64 / 100.0;
            let v = k.f2(r);
            assert!(v >= last);
            last = v;
        }
        // Outside the band the law is the thesis's, to rounding.
        assert!((k.f2(0.9) - f2_exact(1.4, 0.9)).abs() <= 1e-14 * f2_exact(1.4, 0.9));
    }

    #[test]
    fn tabulated_f2_matches_2_22() {
        for gamma in [1.4, 1.67, 1.3, 1.1, 1.01] {
            let k = FlowConstants::new(gamma, 287.0, 293.15);
            assert!(k.unchoked.accurate, "γ {gamma}");
            let (mut worst_factor, mut worst_f2) = (0.0f64, 0.0f64);
            for j in 0..=100_000 {
                let r = k.critical_ratio + (1.0 - k.critical_ratio) * j as f64 / 100_000.0;
                let accurate = unchoked_factor(gamma, r);
                let tabulated = k.unchoked.value(r).expect("inside the tabulated range");
                worst_factor = worst_factor.max((tabulated - accurate).abs() / (accurate * f64::EPSILON));
                if r < 1.0 - REGULARISATION_RATIO_BAND {
                    // (2.22) as written, √(a (a − r)), loses digits as r → 1: a relative error δ
                    // in a becomes δ (2a − r)/(2(a − r)) in f2; δ ≤ 1e-15 for powf.
                    let exact = f2_exact(gamma, r);
                    let a = r.powf(1.0 / gamma);
                    let bound = 1e-15 * (1.0 + (2.0 * a - r) / (a - r));
                    worst_f2 = worst_f2.max((k.f2(r) - exact).abs() / exact / bound);
                }
            }
            // Interpolation plus the conversion to monomials: a few units in the last place.
            assert!(worst_factor <= 16.0, "γ {gamma}: g off by {worst_factor} ulp");
            assert!(
                worst_f2 < 1.0,
                "γ {gamma}: f2 off by {worst_f2} rounding bounds of (2.22)"
            );
        }
        let k = air();
        assert_eq!(k.unchoked.value(0.3), None);
        assert_eq!(k.unchoked.value(f64::NAN), None);
        assert_eq!(k.unchoked.value(1.0 + 1e-9), None);
        // Every instance for air shares one static table; another gas's is shared by clones.
        assert!(std::ptr::eq(&*k.unchoked, &*air().unchoked));
        assert!(matches!(k.unchoked, FactorTable::Air(_)));
        let helium = FlowConstants::new(1.67, 2077.0, 293.15);
        assert!(std::ptr::eq(&*helium.unchoked, &*helium.clone().unchoked));
        assert!(!std::ptr::eq(
            &*helium.unchoked,
            &*FlowConstants::new(1.67, 2077.0, 293.15).unchoked
        ));
        // A large γ (small r_c) falls back to (2.22) rather than lose digits.
        let k = FlowConstants::new(5.0, 287.0, 293.15);
        assert_eq!(k.unchoked.value(0.9), None);
        assert_eq!(k.f2(0.9), f2_exact(5.0, 0.9));
    }

    #[test]
    fn leakage_coefficient_follows_2_23() {
        // C_d,lpp A_lpp = −0.0475 (P_d/P_u) + 0.0971 mm², Table 3.1.
        let a = leakage_cd_area(-0.0475e-6, 0.0971e-6, 5e5, 2.5e5);
        assert!((a - (0.0971e-6 - 0.0475e-6 * 0.5)).abs() < 1e-20);
        assert_eq!(a, leakage_cd_area(-0.0475e-6, 0.0971e-6, 2.5e5, 5e5));
        let k = air();
        assert!(leakage_flow(&k, -0.0475e-6, 0.0971e-6, 5e5, 2.5e5) > 0.0);
        assert!(leakage_flow(&k, -0.0475e-6, 0.0971e-6, 2.5e5, 5e5) < 0.0);
    }
}
