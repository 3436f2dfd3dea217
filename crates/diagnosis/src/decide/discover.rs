//! Turning a fitted candidate into FMU parameters: a discovered term is added to the model
//! only as parameters the FMU has, so that the FMU with the report's `fmu_start_values`
//! is the model whose error the report gives.
//!
//! Terms that the fit applies on a measured channel (a transducer's offset, gain, curve or
//! drift, a force on the piston) are composed with what the model already reads there;
//! terms the FMU cannot carry (a constant modulated in time other than the supply's, the
//! jet pipe null's and the gas temperature's) and compositions that would not be exact give
//! `None`, and the candidate stays a located departure.

use crate::candidates::unit_of;
use crate::candidates::{parameter_value, Candidate, Mechanism, Modulation, Regressor};
use crate::fit::Problem;
use crate::replay::signals::{FORCE, P1, P2};
use crate::vocabulary::{Family, Place};
use jetpipe_model::physics::parameters::Parameters;

/// The FMU parameters (name, value) that put the fitted `values` of `terms` into the
/// model `base`, or `None` when the FMU cannot carry them exactly.
pub fn model_terms(
    candidate: &Candidate,
    values: &[f64],
    base: &Parameters,
    problem: &Problem,
) -> Option<Vec<(&'static str, f64)>> {
    if crate::candidates::curves::is_channel_curve(candidate) {
        return crate::candidates::curves::channel_model_terms(candidate, values, base);
    }
    let terms = &candidate.terms;
    let mut set: Vec<(&'static str, f64)> = candidate.settings.clone();
    // Coefficients of the force channel's regressors.
    let mut one = 0.0;
    let mut own = 0.0;
    let mut squared = 0.0;
    let mut cubed = 0.0;
    let mut ramp = 0.0;
    let mut sine: Option<(f64, f64, f64)> = None;
    let mut friction = 0.0;
    let mut viscous = 0.0;
    let mut position = 0.0;
    let mut acceleration = 0.0;
    let mut quadratic = 0.0;
    let mut sign_pressure = 0.0;
    // The product slots' coefficients (a slot's parameter, the fitted force).
    let mut products: Vec<(&'static str, f64)> = vec![];
    // Coefficients of the pressure channels' regressors: (one, own, ramp) per transducer.
    let mut transducer = [[0.0; 3]; 2];
    // Modulations of a constant: (parameter, ramp coefficient, sine, cosine, frequency).
    let mut modulated: Vec<(&'static str, f64, f64, f64, f64)> = vec![];
    for (term, &value) in terms.iter().zip(values) {
        match term.mechanism {
            Mechanism::Modulated { parameter, modulation } => {
                let k = match modulated.iter().position(|m| m.0 == parameter) {
                    Some(k) => k,
                    None => {
                        modulated.push((parameter, 0.0, 0.0, 0.0, 0.0));
                        modulated.len() - 1
                    }
                };
                let m = &mut modulated[k];
                match modulation {
                    Modulation::Ramp => m.1 += value,
                    Modulation::Sine(f) => {
                        m.2 += value;
                        m.4 = f;
                    }
                    Modulation::Cosine(f) => {
                        m.3 += value;
                        m.4 = f;
                    }
                }
            }
            m if m.model_parameter().is_some() => set.push((m.model_parameter()?, m.model_value(value))),
            // The seal's speed scale, a shape the FMU carries; one seal term at a time.
            Mechanism::Shape if term.name == "extra_force_sign_velocity" => {
                if base.extra_force_sign_pressure != 0.0 {
                    return None;
                }
                set.push((term.name, value));
            }
            // A second-order filter's damping ratio, with its frequency.
            Mechanism::Shape if term.name.ends_with("_sensor_filter_damping") => set.push((term.name, value)),
            Mechanism::OutputFilter { channel, filter } => {
                let name = filter.sensor_parameter(channel)?;
                if parameter_value(base, name) != 0.0 && value != 0.0 {
                    return None;
                }
                set.push((name, value));
            }
            Mechanism::Output { channel, regressor } if channel == P1 || channel == P2 => {
                let k = if channel == P1 { 0 } else { 1 };
                match regressor {
                    Regressor::One => transducer[k][0] += value,
                    Regressor::Own => transducer[k][1] += value,
                    Regressor::Ramp => transducer[k][2] += value,
                    _ => return None,
                }
            }
            Mechanism::Output {
                channel: FORCE,
                regressor,
            } => match regressor {
                Regressor::One => one += value,
                Regressor::Own => own += value,
                Regressor::OwnSquared => squared += value,
                Regressor::OwnCubed => cubed += value,
                Regressor::Ramp => ramp += value,
                Regressor::Sine(f) => {
                    let s = sine.get_or_insert((f, 0.0, 0.0));
                    s.1 += value;
                }
                Regressor::Cosine(f) => {
                    let s = sine.get_or_insert((f, 0.0, 0.0));
                    s.2 += value;
                }
                Regressor::Friction => friction += value,
                Regressor::SmoothFriction(_) | Regressor::Stribeck(..) => return None,
                Regressor::Viscous => viscous += value,
                Regressor::Position => position += value,
                Regressor::Acceleration => acceleration += value,
                Regressor::VelocitySquared => quadratic += value,
                Regressor::SignPressure(_) => sign_pressure += value,
                Regressor::Product { .. } => products.push((term.name, value)),
                Regressor::Segment { .. } => return None,
            },
            _ => return None,
        }
    }
    let p = base;
    // A constant varying in time: c(t) = c + ramp (t − t_mid)/span + a sin ωt + b cos ωt.
    for (parameter, ramp, a, b, f) in modulated {
        let (drift, ripple) = match parameter {
            "P_s" => ("supply_drift", true),
            "x_jp_offset" => ("x_jp_offset_drift", false),
            "T" => ("T_drift", false),
            _ => return None,
        };
        if ramp != 0.0 {
            if parameter_value(base, drift) != 0.0 {
                return None;
            }
            let at_mid = set
                .iter()
                .find(|(n, _)| *n == parameter)
                .map_or_else(|| parameter_value(base, parameter), |(_, v)| *v);
            set.retain(|(n, _)| *n != parameter);
            set.push((parameter, at_mid - ramp * problem.t_mid / problem.t_span));
            set.push((drift, ramp / problem.t_span));
        }
        if a != 0.0 || b != 0.0 {
            if !ripple || base.supply_ripple_sine != 0.0 || base.supply_ripple_cosine != 0.0 {
                return None;
            }
            set.push(("supply_ripple_sine", a));
            set.push(("supply_ripple_cosine", b));
            set.push(("supply_ripple_frequency", f));
        }
    }
    // A pressure transducer: new reading = (1 + own) s + one + ramp (t − t_mid)/span, with
    // s = offset + gain P + drift t the reading so far.
    for (k, &[one, own, ramp]) in transducer.iter().enumerate() {
        if one == 0.0 && own == 0.0 && ramp == 0.0 {
            continue;
        }
        let (offset, gain, drift) = if k == 0 {
            ("p1_sensor_offset", "p1_sensor_gain", "p1_sensor_drift")
        } else {
            ("p2_sensor_offset", "p2_sensor_gain", "p2_sensor_drift")
        };
        let m = 1.0 + own;
        let (t_mid, t_span) = (problem.t_mid, problem.t_span);
        set.push((offset, m * parameter_value(base, offset) + one - ramp * t_mid / t_span));
        if own != 0.0 {
            set.push((gain, m * parameter_value(base, gain)));
        }
        if ramp != 0.0 || parameter_value(base, drift) != 0.0 {
            set.push((drift, m * parameter_value(base, drift) + ramp / t_span));
        }
    }
    let g = p.force_sensor_gain;
    // Forces on the piston read through the sensor's gain.
    if friction != 0.0 {
        set.push(("friction_coulomb", p.friction_coulomb + friction / g));
    }
    if viscous != 0.0 {
        set.push(("viscous_friction", p.viscous_friction + viscous / g));
    }
    // The library's terms add to the force the sensor reads.
    if acceleration != 0.0 {
        set.push((
            "extra_force_acceleration",
            p.extra_force_acceleration + acceleration / g,
        ));
    }
    if quadratic != 0.0 {
        set.push((
            "extra_force_velocity_squared",
            p.extra_force_velocity_squared + quadratic / g,
        ));
    }
    if sign_pressure != 0.0 {
        set.push((
            "extra_force_sign_pressure",
            p.extra_force_sign_pressure + sign_pressure / g,
        ));
    }
    for (name, value) in products {
        if value != 0.0 {
            set.push((name, parameter_value(p, name) + value / g));
        }
    }
    if position != 0.0 {
        let (k0, x0) = (p.position_force_rate, p.position_force_reference);
        let k = position / g;
        if k0 + k == 0.0 {
            return None;
        }
        set.push(("position_force_rate", k0 + k));
        set.push((
            "position_force_reference",
            (k0 * x0 + k * problem.mean_position) / (k0 + k),
        ));
    }
    // The sensor: new reading = (1 + own) s + one + squared s² + cubed s³ + ramp r(t) +
    // pick-up, with s the reading so far, o + g F + …; exact when s is affine in F.
    let curve = squared != 0.0 || cubed != 0.0;
    let s_nonlinear = p.force_sensor_quadratic != 0.0
        || p.force_sensor_cubic != 0.0
        || p.force_sensor_drift != 0.0
        || p.force_sensor_ripple_sine != 0.0
        || p.force_sensor_ripple_cosine != 0.0;
    if curve && s_nonlinear {
        return None;
    }
    if one != 0.0 || own != 0.0 || curve || ramp != 0.0 {
        let o = p.force_sensor_offset;
        let m = 1.0 + own;
        let (t_mid, t_span) = (problem.t_mid, problem.t_span);
        set.push((
            "force_sensor_offset",
            m * o + one + squared * o * o + cubed * o * o * o - ramp * t_mid / t_span,
        ));
        set.push((
            "force_sensor_gain",
            m * g + 2.0 * squared * o * g + 3.0 * cubed * o * o * g,
        ));
        if curve || p.force_sensor_quadratic != 0.0 {
            set.push((
                "force_sensor_quadratic",
                m * p.force_sensor_quadratic + squared * g * g + 3.0 * cubed * o * g * g,
            ));
        }
        if cubed != 0.0 || p.force_sensor_cubic != 0.0 {
            set.push(("force_sensor_cubic", m * p.force_sensor_cubic + cubed * g * g * g));
        }
        if ramp != 0.0 || p.force_sensor_drift != 0.0 {
            set.push(("force_sensor_drift", m * p.force_sensor_drift + ramp / t_span));
        }
        if (p.force_sensor_ripple_sine != 0.0 || p.force_sensor_ripple_cosine != 0.0) && m != 1.0 && sine.is_none() {
            set.push(("force_sensor_ripple_sine", m * p.force_sensor_ripple_sine));
            set.push(("force_sensor_ripple_cosine", m * p.force_sensor_ripple_cosine));
        }
    }
    if let Some((f, a, b)) = sine {
        // a sin ωt + b cos ωt on top of what is there at the same frequency.
        let m = 1.0 + own;
        let (s0, c0) = (p.force_sensor_ripple_sine, p.force_sensor_ripple_cosine);
        if (s0 != 0.0 || c0 != 0.0) && p.force_sensor_ripple_frequency != f {
            return None;
        }
        set.push(("force_sensor_ripple_sine", m * s0 + a));
        set.push(("force_sensor_ripple_cosine", m * c0 + b));
        set.push(("force_sensor_ripple_frequency", f));
    }
    // A setting the fit refined appears twice: the last value holds.
    let mut unique: Vec<(&'static str, f64)> = vec![];
    for (name, value) in set {
        unique.retain(|(n, _)| *n != name);
        unique.push((name, value));
    }
    if unique.is_empty() {
        return None;
    }
    crate::candidates::command_curve::monotone_command(&mut unique);
    Some(unique)
}

/// One sentence on what was added: each parameter against its value in the model before.
pub fn reading(
    label: &str,
    location: Place,
    family: Family,
    set: &[(&'static str, f64)],
    before: &Parameters,
) -> String {
    if let Some(discharge) = crate::candidates::discharge::reading(set, before) {
        return discharge;
    }
    if let Some(flexible) = crate::candidates::flexible::reading(set) {
        return format!("At the {location} ({family}): {flexible}.");
    }
    if let Some(modulation) = crate::candidates::modulation::reading(set, before) {
        return format!("At the {location} ({family}): {modulation}.");
    }
    if let Some(filter) = second_order_reading(location, family, set) {
        return filter;
    }
    if let Some(quantiser) = crate::candidates::quantiser::reading(set) {
        return format!("At the {location} ({family}): {quantiser}");
    }
    if let Some(curve) = crate::candidates::curve_reading::reading(set) {
        return format!(
            "At the {location} ({}): {curve}",
            crate::candidates::curve_reading::family(Family::Nonlinearity, set)
        );
    }
    let parts: Vec<String> = set
        .iter()
        .map(|&(name, value)| {
            let was = parameter_value(before, name);
            let unit = unit_of(name);
            let side = match name {
                "command_upper_limit" => Some("above"),
                "command_lower_limit" => Some("below"),
                _ => None,
            };
            if let (Some(side), true) = (side, was.abs() >= 100.0) {
                format!("{name} = {value:.4e} {unit} (off before): the command the current driver sees saturates {side} {value:.3} V")
            } else if was == 0.0 {
                format!("{name} = {value:.4e} {unit} (0 before)")
            } else {
                format!(
                    "{name} = {value:.4e} {unit} instead of {was:.4e} ({:+.1} %)",
                    100.0 * (value / was - 1.0)
                )
            }
        })
        .collect();
    let physical: Vec<String> = set
        .iter()
        .filter_map(|&(name, value)| physical_reading(name, value - parameter_value(before, name)))
        .collect();
    // "The", not "a": labels name one thing ("supply pressure") or several ("dead volumes").
    let mut sentence = format!("At the {location} ({family}), the {label}: {}.", parts.join(", "));
    if let Some(products) = crate::candidates::products::reading(set, before) {
        sentence.push(' ');
        sentence.push_str(&products);
    }
    if let Some(flows) = crate::candidates::extra_flows::reading(set, before) {
        sentence.push(' ');
        sentence.push_str(&flows);
    }
    for p in physical {
        sentence.push(' ');
        sentence.push_str(&p);
    }
    sentence
}

/// A transducer's or the command's second-order filter in physical words: its natural
/// frequency, damping and −3 dB corner, f_n √(1 − 2ζ² + √((1 − 2ζ²)² + 1)).
fn second_order_reading(location: Place, family: Family, set: &[(&'static str, f64)]) -> Option<String> {
    let &(name, f_n) = set.iter().find(|(n, v)| n.ends_with("_filter_frequency") && *v > 0.0)?;
    let prefix = &name[..name.len() - "_filter_frequency".len()];
    let zeta = set
        .iter()
        .find(|(n, _)| n.strip_prefix(prefix) == Some("_filter_damping"))
        .map_or(std::f64::consts::FRAC_1_SQRT_2, |(_, v)| *v);
    let a = 1.0 - 2.0 * zeta * zeta;
    let corner = f_n * (a + (a * a + 1.0).sqrt()).sqrt();
    let reader = match prefix {
        "force_sensor" => "The force sensor reads",
        "p1_sensor" => "The chamber 1 pressure transducer reads",
        "command" => "The current driver sees the command",
        _ => "The chamber 2 pressure transducer reads",
    };
    let kind = if zeta < 0.6 {
        "underdamped: it rings on a step"
    } else if zeta <= 0.8 {
        "near Butterworth's 0.707"
    } else if zeta <= 1.05 {
        "near critical: two equal lags"
    } else {
        "overdamped: two unequal lags"
    };
    Some(format!(
        "At the {location} ({family}): {reader} through a second-order low-pass filter of natural frequency {f_n:.1} Hz and damping ratio {zeta:.2} ({kind}), its −3 dB corner at {corner:.1} Hz: {name} = {f_n:.4e} Hz, {prefix}_filter_damping = {zeta:.4}."
    ))
}

/// What an extra force on the piston of `added` times its signal is, in physical words.
fn physical_reading(name: &str, added: f64) -> Option<String> {
    if added == 0.0 {
        return None;
    }
    Some(match name {
        "extra_force_acceleration" if added < 0.0 => format!(
            "A force of {added:.3} kg × the stopper's acceleration acts on the piston: a moving mass of {:.0} g.",
            -added * 1e3
        ),
        "extra_force_acceleration" => format!(
            "A force of {added:.3} kg × the stopper's acceleration acts on the piston: it pushes with the acceleration, as no moving mass would."
        ),
        "extra_force_velocity_squared" if added < 0.0 => format!(
            "A force of {added:.4e} N·s²/m² × v|v| (v the stopper's velocity) acts on the piston: quadratic damping, {:.3} N at 0.1 m/s.",
            -added * 0.01
        ),
        "extra_force_velocity_squared" => {
            format!("A force of {added:.4e} N·s²/m² × v|v| (v the stopper's velocity) acts on the piston.")
        }
        "extra_force_sign_pressure" if added < 0.0 => format!(
            "A force of {added:.4e} m² × sign(v) (P1 + P2 − 2 P_r) acts on the piston: a seal friction that grows by {:.3} N per bar of pressure in the chambers.",
            -added * 1e5
        ),
        "extra_force_sign_pressure" => {
            format!("A force of {added:.4e} m² × sign(v) (P1 + P2 − 2 P_r) acts on the piston.")
        }
        "viscous_friction" if added > 0.0 => format!(
            "A force of {:.4e} N·s/m × the stopper's velocity acts on the piston: viscous friction, {:.3} N at 0.1 m/s.",
            -added,
            added * 0.1
        ),
        "k_spring" | "L_spring0" => format!(
            "The return spring holds the piston against the stopper with {} force than the model's while the pressures push less than it (2.37); a change of its rate and one of its free length give the same floor wherever the stopper stays put.",
            if added > 0.0 { "more" } else { "less" }
        ),
        "stopper_compliance" if added > 0.0 => format!(
            "The piston sits beyond the stopper by the force it carries over a stiffness of {:.3e} N/m: a compliant mount.",
            1.0 / added
        ),
        "stopper_mount_lag" if added > 0.0 => format!(
            "The mount follows the force through a lag of {:.2} ms (its own mass and damping).",
            added * 1e3
        ),
        "chamber_vent_1" | "chamber_vent_2" if added > 0.0 => format!(
            "Chamber {} leaks to the return pressure through an orifice of C_d·A {:.4} mm².",
            &name[name.len() - 1..],
            added * 1e6
        ),
        "chamber_supply_leak_1" | "chamber_supply_leak_2" if added > 0.0 => format!(
            "Chamber {} gains air from the supply through a leak of C_d·A {:.4} mm² (the orifice law).",
            &name[name.len() - 1..],
            added * 1e6
        ),
        "chamber_laminar_vent_1" | "chamber_laminar_vent_2" if added > 0.0 => format!(
            "Chamber {} loses {added:.3e} kg/(s·Pa) × its pressure above the return's through a laminar path: {:.2} mg/s at 3 bar.",
            &name[name.len() - 1..],
            added * 3e5 * 1e6
        ),
        "chamber_laminar_supply_leak_1" | "chamber_laminar_supply_leak_2" if added > 0.0 => format!(
            "Chamber {} gains {added:.3e} kg/(s·Pa) × the supply's pressure above its own through a laminar path: {:.2} mg/s at 3 bar of difference.",
            &name[name.len() - 1..],
            added * 3e5 * 1e6
        ),
        "chamber_laminar_cross_leak" if added > 0.0 => format!(
            "Chamber 1 passes {added:.3e} kg/(s·Pa) × its pressure above chamber 2's into it through a laminar path beside the piston's leakage: {:.2} mg/s at 3 bar of difference.",
            added * 3e5 * 1e6
        ),
        _ => return None,
    })
}
