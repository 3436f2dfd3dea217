//! Constants that vary in time (all off by default): the supply pressure with a drift and
//! a ripple, and the jet pipe null with a drift. A simulation holds each over a
//! communication step (a replay, over a sample interval) at its mid-step value: the
//! chambers see it change at the rate of the communication points, which at the bench's
//! 1 kHz resolves a ripple well above the chambers' bandwidth.

use super::parameters::Parameters;

/// Whether any constant varies.
pub fn varies(p: &Parameters) -> bool {
    p.supply_drift != 0.0 || p.supply_ripple_sine != 0.0 || p.supply_ripple_cosine != 0.0 || p.x_jp_offset_drift != 0.0
}

/// The supply pressure at time `t`.
pub fn supply_pressure(p: &Parameters, t: f64) -> f64 {
    let mut p_s = p.p_s + p.supply_drift * t;
    if p.supply_ripple_sine != 0.0 || p.supply_ripple_cosine != 0.0 {
        let phase = 2.0 * std::f64::consts::PI * p.supply_ripple_frequency * t;
        p_s += p.supply_ripple_sine * phase.sin() + p.supply_ripple_cosine * phase.cos();
    }
    p_s
}

/// The jet pipe null at time `t`.
pub fn jet_pipe_offset(p: &Parameters, t: f64) -> f64 {
    p.x_jp_offset + p.x_jp_offset_drift * t
}

/// `nominal` with its varying constants at their values at time `t`, written into
/// `current`; an error when the supply would fall to the return pressure.
pub fn set_at(current: &mut Parameters, nominal: &Parameters, t: f64) -> Result<(), String> {
    let p_s = supply_pressure(nominal, t);
    if p_s <= nominal.p_r {
        return Err(format!(
            "the supply pressure reaches {p_s} Pa at t = {t} s (P_s = {} Pa, supply_drift = {} Pa/s, supply_ripple_sine = {} Pa, supply_ripple_cosine = {} Pa): it must stay above P_r = {} Pa",
            nominal.p_s, nominal.supply_drift, nominal.supply_ripple_sine, nominal.supply_ripple_cosine, nominal.p_r
        ));
    }
    current.p_s = p_s;
    current.x_jp_offset = jet_pipe_offset(nominal, t);
    Ok(())
}

/// Undo [`set_at`]: the varying constants of `current` back at their nominal values, the
/// rest untouched (cheaper than a copy of every constant once per step).
pub fn reset(current: &mut Parameters, nominal: &Parameters) {
    current.p_s = nominal.p_s;
    current.x_jp_offset = nominal.x_jp_offset;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn with_nothing_varying_the_constants_are_the_nominal_ones_at_any_time() {
        let p = Parameters::default();
        let mut q = p.clone();
        set_at(&mut q, &p, 37.5).unwrap();
        assert_eq!(q, p);
        assert!(!varies(&p));
    }

    #[test]
    fn reset_undoes_set_at() {
        let p = Parameters {
            supply_drift: -400.0,
            supply_ripple_sine: 15e3,
            x_jp_offset_drift: 4e-6,
            ..Parameters::default()
        };
        let mut q = p.clone();
        set_at(&mut q, &p, 2.5).unwrap();
        assert_ne!(q, p);
        reset(&mut q, &p);
        assert_eq!(q, p);
    }

    #[test]
    fn a_drifting_supply_that_would_fall_to_the_return_pressure_is_refused() {
        let p = Parameters {
            supply_drift: -1e4,
            ..Parameters::default()
        };
        let mut q = p.clone();
        assert!(set_at(&mut q, &p, 10.0).is_ok());
        assert!((q.p_s - (p.p_s - 1e5)).abs() < 1e-9);
        let e = set_at(&mut q, &p, 100.0).unwrap_err();
        assert!(e.contains("supply_drift") && e.contains("P_r"), "{e}");
    }
}
