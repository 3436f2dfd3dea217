//! Constants that vary in time (all off by default): the supply pressure with a drift and
//! a ripple, the jet pipe null with a drift, and the gas temperature T of §2.6 with a drift
//! (the supply air warming up): T enters the orifice flows, (2.20)–(2.21), through 1/√T and
//! the chambers, (2.29), through R T. A simulation holds each over a
//! communication step (a replay, over a sample interval) at its mid-step value: the
//! chambers see it change at the rate of the communication points, which at the bench's
//! 1 kHz resolves a ripple well above the chambers' bandwidth.

use super::actuator::Actuator;
use super::parameters::Parameters;
use crate::variables::{self, vr};

/// Whether any constant varies.
pub fn varies(p: &Parameters) -> bool {
    p.supply_drift != 0.0
        || p.supply_ripple_sine != 0.0
        || p.supply_ripple_cosine != 0.0
        || p.x_jp_offset_drift != 0.0
        || p.t_drift != 0.0
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

/// The gas temperature at time `t`.
pub fn gas_temperature(p: &Parameters, t: f64) -> f64 {
    p.temperature + p.t_drift * t
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
    // Untouched without a drift: the thesis's T to the last bit.
    if nominal.t_drift != 0.0 {
        let temperature = gas_temperature(nominal, t);
        variables::check(vr::T_GAS, temperature).map_err(|e| {
            format!(
                "the gas temperature reaches {temperature} K at t = {t} s (T = {} K, T_drift = {} K/s): {e}",
                nominal.temperature, nominal.t_drift
            )
        })?;
        current.temperature = temperature;
    }
    Ok(())
}

/// [`set_at`] on a model's parameters and on what its construction derived from them: the
/// orifice flows' 1/√T, when the gas temperature drifts.
pub fn set_model_at(model: &mut Actuator, nominal: &Parameters, t: f64) -> Result<(), String> {
    set_at(&mut model.params, nominal, t)?;
    if nominal.t_drift != 0.0 {
        model.flow.inv_sqrt_temperature = 1.0 / model.params.temperature.sqrt();
    }
    Ok(())
}

/// Undo [`set_model_at`].
pub fn reset_model(model: &mut Actuator, nominal: &Parameters) {
    reset(&mut model.params, nominal);
    if nominal.t_drift != 0.0 {
        model.flow.inv_sqrt_temperature = 1.0 / nominal.temperature.sqrt();
    }
}

/// Undo [`set_at`]: the varying constants of `current` back at their nominal values, the
/// rest untouched (cheaper than a copy of every constant once per step).
pub fn reset(current: &mut Parameters, nominal: &Parameters) {
    current.p_s = nominal.p_s;
    current.x_jp_offset = nominal.x_jp_offset;
    current.temperature = nominal.temperature;
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
            t_drift: 0.25,
            ..Parameters::default()
        };
        let mut q = p.clone();
        set_at(&mut q, &p, 2.5).unwrap();
        assert_eq!(q.temperature, p.temperature + 0.625);
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

    #[test]
    fn a_gas_temperature_drifting_to_zero_kelvin_is_refused_with_the_variable_the_value_and_the_limit() {
        let p = Parameters {
            t_drift: -2.0,
            ..Parameters::default()
        };
        let mut q = p.clone();
        assert!(set_at(&mut q, &p, 100.0).is_ok());
        assert!((q.temperature - (p.temperature - 200.0)).abs() < 1e-9);
        let e = set_at(&mut q, &p, 150.0).unwrap_err();
        assert!(
            e.contains("T_drift = -2 K/s") && e.contains("T = -6.85") && e.contains("(0, 1000] K"),
            "{e}"
        );
    }

    #[test]
    fn a_model_at_a_drifted_temperature_has_the_orifice_constants_of_that_temperature() {
        let p = Parameters {
            t_drift: 1.5,
            ..Parameters::default()
        };
        let mut model = Actuator::new(p.clone()).unwrap();
        set_model_at(&mut model, &p, 20.0).unwrap();
        let warm = Actuator::new(Parameters {
            temperature: p.temperature + 30.0,
            ..p.clone()
        })
        .unwrap();
        assert_eq!(model.flow, warm.flow);
        reset_model(&mut model, &p);
        assert_eq!(model.flow, Actuator::new(p).unwrap().flow);
    }
}
