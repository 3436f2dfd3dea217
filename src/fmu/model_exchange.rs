//! The actuator as an FMI 2.0 Model Exchange model: thirty-one states, the six of (4.1)
//! with the chambers' air in place of their pressures, [i, x_jp, ẋ_jp, ẍ_jp, Q1, Q2] (see
//! the stopper's paragraph below), then the pressures of the four gas volumes behind
//! restrictions and the lagging stopper mount's load, then the lags and second-order filters
//! of the command stage and of the three transducers (module `filters`: three states each),
//! then the eight sections of the transport delay's optional Padé chain (every state beyond
//! the six constant while its effect is off); their derivatives from
//! `Actuator::derivatives`, `Actuator::pressure_rates_with_volumes` and the lag and filter
//! equations of `physics::sensors` (the equations the Co-Simulation step integrates or
//! solves in closed form), and event indicators where the right-hand side is not smooth.
//!
//! The jet pipe's hysteresis (`jet_pipe_hysteresis`, either law: plays or Bouc–Wen) is a
//! discrete state, its memory, as in Co-Simulation: the operator is rate-independent, and
//! its output after the static position x̄ = f3(k_m i) has moved monotonically from the
//! memory's is `Hysteresis::output_after(memory, x̄)`, the function the Co-Simulation step
//! evaluates along its closed-form current. x̄ moves monotonically while the current does, so
//! the memory needs advancing (`Hysteresis::advance`) only where di/dt changes sign: event
//! indicator z7 = ī − i (ī the static current of the command, (2.3)) stops the solver
//! there, and `fmi2NewDiscreteStates` advances it. It is advanced also at every
//! `fmi2CompletedIntegratorStep` (exact while x̄ is monotone; an importer that ignores the
//! event indicators then errs by a step's reversal at most) and at every other event (an
//! input's jump reverses the current at once). The right-hand side is the one Co-Simulation
//! integrates, with the same law and the same memory: what differs is only where the
//! reversal is put, CVODE's root of z7 in place of the closed form's turning point.
//!
//! What Model Exchange does not have, and why (the `REFUSED` table gives each reason in the
//! message that refuses it, when a parameter is set and when initialisation ends; all stay
//! available in Co-Simulation):
//! * the transport delay (`command_delay`) and the transducers' delays: a pure delay
//!   y(t) = u(t − d) is not an ODE; its state at t is the whole of u over (t − d, t], which no
//!   finite set of continuous states holds. For the transport delay its closest state form is
//!   offered instead: with `command_delay_pade_sections` = n (1 to 8; Model Exchange only,
//!   Co-Simulation keeps its exact delay) a chain of n first-order Padé sections
//!   (`filters::delayed_command`, `filters::chain_rates`); without it `command_delay` is
//!   refused when initialisation ends (not when set: importers set the parameters in the
//!   model description's order, the delay before the count);
//! * the command stage's slew limit: the limited command follows
//!   ds/dt = sign(u − s)·S until it reaches u, then s = u, a right-hand side that jumps where
//!   s meets u and holds s there on a sliding surface; exact only as a hybrid state (a ramp or
//!   a hold, switched at events), which this FMU does not have;
//! * the transducers' plays: a play is a rate-independent operator whose output holds until
//!   its input has moved half its width from it, a memory moved at the input's reversals, not
//!   an ODE (the FMU has such a memory, with its events, for the jet pipe's hysteresis only);
//! * the forces that read the stopper's motion, formed from its positions at the last
//!   communication points, and the modulation and flexible slots, held over each
//!   communication step (a flexible slot's lags advanced from step to step);
//! * the constants that vary in time (not yet part of Model Exchange).
//!
//! The stopper, and why the chambers' states are their air, not their pressures: FMI has no
//! input derivatives in Model Exchange, so the right-hand side cannot know ẋ_s, and (2.29)
//! with P as the state needs it (its term −γ P V̇/V). The state Q_i = P_i (V_i/V_ref,i)^γ, the
//! pressure chamber i's air would have brought with no flow to its volume at mid-stroke
//! (`P1_at_mid_stroke`, `P2_at_mid_stroke`), moves with the flows alone
//! (`chambers::reference_pressure_rate`): a stopper that an importer moves, at events or
//! continuously in continuous-time mode, changes the pressures read from the states
//! (`Actuator::pressures_from_reference`, with the piston where a compliant stopper or a
//! lagging mount puts it) and leaves the states as they are, as the air in each chamber is
//! conserved while the volume jumps. The instance keeps the pressures, and an x_s set moves
//! them along their adiabats at once (the same jump Co-Simulation makes at an x_s it is given
//! without a rate).

use super::ActuatorFmu;
use crate::variables::{me_vr, vr};
use fmi2::model::{EventUpdate, ModelExchangeModel};
use jetpipe_model::physics::actuator::{index, Actuator, Inputs, State};
use jetpipe_model::physics::chambers::{pressure_after_volume_jump, reference_pressure_rate};
use jetpipe_model::physics::current_driver;
use jetpipe_model::physics::effects::PLAY_OPERATORS;
use jetpipe_model::physics::jet_pipe;
use jetpipe_model::physics::parameters::{table_start, variable_name, Parameters};
use jetpipe_model::physics::restrictions::{node, PRESSURES_WITH_VOLUMES};
use jetpipe_model::physics::sensors::{Channel, SensorLaw};
use jetpipe_model::physics::time_varying;
use jetpipe_model::physics::{flexible, modulation};
use jetpipe_model::simulation::Simulation;

mod filters;
pub(super) use filters::{filters_of, seen_command, PADE_SECTIONS};
use filters::{Chain, Filters};

/// The number of event indicators (see [`event_indicators`]).
pub const EVENT_INDICATORS: usize = 8;

/// The jet_pipe_hysteresis operator's memory (see `Hysteresis`): its plays, or the Bouc–Wen
/// law's input and output where it was last advanced.
pub(super) type Memory = [f64; PLAY_OPERATORS];

/// The number of continuous states: the six of (4.1), the [`node::STATES`] beyond them and
/// the [`filters::STATES`] of the lags and filters.
pub const STATES: usize = 6 + node::STATES + filters::STATES + filters::PADE_SECTIONS;

/// Where the lags' and filters' states start in the state vector.
const FILTERS: usize = 6 + node::STATES;

/// Where the transport delay's Padé chain starts in the state vector.
const CHAIN: usize = FILTERS + filters::STATES;

/// The states beyond the six of (4.1), in the order of [`node`]: the volumes' pressures, the
/// mount's load.
pub(super) type Nodes = [f64; node::STATES];

/// The states beyond the six of a simulation: the places' pressures (the state where a place
/// has a volume, else its quasi-static or valve-side pressure, which stays constant in Model
/// Exchange), the mount's load (its state when it lags, else the load it carries).
pub(super) fn nodes_of(simulation: &Simulation) -> Nodes {
    let mut nodes = [0.0; node::STATES];
    nodes[..node::COUNT].copy_from_slice(&simulation.node_pressures());
    let s = simulation.state();
    nodes[node::MOUNT] = simulation.stopper_mount_state().unwrap_or_else(|| {
        simulation
            .model()
            .mount_load(s[index::P1], s[index::P2], simulation.x_s())
    });
    nodes
}

/// A running Model Exchange instance: the model built when initialisation ended, the time and
/// the states the importer set.
#[derive(Clone, Debug)]
pub(super) struct MeState {
    model: Actuator,
    time: f64,
    x: State,
    nodes: Nodes,
    /// The lags' and filters' states (module `filters`).
    filters: Filters,
    /// The transport delay's Padé chain, its first `sections` states in use (0: no delay).
    chain: Chain,
    sections: usize,
    /// The hysteresis memory when the effect is on (see the module's text).
    memory: Option<Memory>,
    /// Where the stopper is: the last x_s set that is inside the cylinder (see
    /// [`ActuatorFmu::exit_initialization_model_exchange`]).
    x_s: f64,
    /// How the chambers' air and pressures convert with the stopper at `x_s`.
    scale: AirScale,
}

/// How the chambers' air and pressures convert at a stopper position. On a rigid stopper the
/// volumes move with x_s alone, so the factors (V_i/V_mid,i)^γ are worked out when it moves,
/// not at every right-hand side (two powers of the four they cost, about 90 ns of 245; the
/// same expressions as the general path's, so the air and its rates keep their bits);
/// elsewhere the piston moves with the pressures or the mount, and each call works out the
/// volumes where it sits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum AirScale {
    Rigid([f64; 2]),
    PistonMoves,
}

impl AirScale {
    pub(super) fn at(model: &Actuator, x_s: f64) -> AirScale {
        if !model.stopper_is_rigid() {
            return AirScale::PistonMoves;
        }
        let (v1, v2) = model.cylinder.volumes(x_s);
        let (r1, r2) = reference_volumes(model);
        let n = model.polytropic_exponent;
        AirScale::Rigid([(v1 / r1).powf(n), (v2 / r2).powf(n)])
    }
}

/// Where the mount's state is in the state vector.
const MOUNT_STATE: usize = 6 + node::MOUNT;

/// The volumes at which the chambers' air is stated (see the module's text): each chamber's
/// with the stopper at the middle of its range.
fn reference_volumes(model: &Actuator) -> (f64, f64) {
    let (low, high) = model.cylinder.stopper_range();
    model.cylinder.volumes(0.5 * (low + high))
}

/// The chambers' states: their air as pressures at [`reference_volumes`], for the pressures
/// in `x`, the mount's state in `nodes` and the stopper at `x_s`.
fn air_states(model: &Actuator, x: &State, nodes: &Nodes, x_s: f64, scale: AirScale) -> [f64; 2] {
    let (p1, p2) = (x[index::P1], x[index::P2]);
    if let AirScale::Rigid(factor) = scale {
        return [p1 * factor[0], p2 * factor[1]];
    }
    let (v1, v2) = model.chamber_volumes(p1, p2, nodes[node::MOUNT], x_s);
    let (r1, r2) = reference_volumes(model);
    let n = model.polytropic_exponent;
    [
        pressure_after_volume_jump(n, p1, v1, r1),
        pressure_after_volume_jump(n, p2, v2, r2),
    ]
}

/// The chambers' pressures for their air `air` ([`air_states`]).
fn pressures_of_air(model: &Actuator, air: [f64; 2], nodes: &Nodes, x_s: f64, scale: AirScale) -> [f64; 2] {
    match scale {
        AirScale::Rigid(factor) => [air[0] / factor[0], air[1] / factor[1]],
        AirScale::PistonMoves => model.pressures_from_reference(air, reference_volumes(model), nodes[node::MOUNT], x_s),
    }
}

/// Why an effect is refused in Model Exchange, and the parameters that switch it on.
struct Refused {
    effect: &'static str,
    why: &'static str,
    parameters: &'static [u32],
}

const DELAY: &str = "a pure delay y(t) = u(t - d) is not an ODE: its state is the whole of u over the last d seconds, which no finite set of continuous states holds";

/// The transport delay's reason, with the option.
const TRANSPORT_DELAY: &str = "a pure delay y(t) = u(t - d) is not an ODE: its state is the whole of u over the last d seconds, which no finite set of continuous states holds; set command_delay_pade_sections (1 to 8) first for its closest state form, a chain of Pade sections";

/// The effects that Model Exchange refuses, each with its parameters (any of them away from
/// its default switches the effect on).
const REFUSED: &[Refused] = &[
    Refused {
        effect: "transport_delay",
        why: TRANSPORT_DELAY,
        parameters: &[vr::COMMAND_DELAY],
    },
    Refused {
        effect: "the command stage's slew limit",
        why: "the slew-limited command moves at +-current_slew_limit/k_cd towards the command until it reaches it, then holds it: a right-hand side that jumps where the two meet and holds them together on a sliding surface, exact only as a hybrid state (a ramp or a hold switched at events), which this FMU does not have",
        parameters: &[vr::CURRENT_SLEW_LIMIT],
    },
    Refused {
        effect: "the transducers' delays",
        why: DELAY,
        parameters: &[vr::FORCE_SENSOR_DELAY, vr::P1_SENSOR_DELAY, vr::P2_SENSOR_DELAY],
    },
    Refused {
        effect: "the force sensor's play",
        why: "a play (backlash) is a rate-independent operator whose output holds until its input has moved half its width away: a memory moved where its input reverses, not an ODE, and this FMU has such a memory with its event indicator for the jet pipe's hysteresis only",
        parameters: &[vr::FORCE_SENSOR_PLAY],
    },
    Refused {
        effect: "piston_friction and the forces on the stopper's motion",
        why: "it is not an ODE: the stopper's velocity and acceleration are formed from its positions at the last communication points",
        parameters: &[
            vr::FRICTION_COULOMB,
            vr::FRICTION_STRIBECK,
            vr::VISCOUS_FRICTION,
            vr::EXTRA_FORCE_ACCELERATION,
            vr::EXTRA_FORCE_VELOCITY_SQUARED,
            vr::EXTRA_FORCE_SIGN_PRESSURE,
            vr::EXTRA_FORCE_PRODUCT_1_COEFFICIENT,
            vr::EXTRA_FORCE_PRODUCT_2_FIRST + 3,
            vr::EXTRA_FORCE_PRODUCT_3_FIRST + 3,
        ],
    },
    Refused {
        effect: "the constants that vary in time",
        why: "they are not yet part of Model Exchange",
        parameters: &[
            vr::SUPPLY_DRIFT,
            vr::SUPPLY_RIPPLE_SINE,
            vr::SUPPLY_RIPPLE_COSINE,
            vr::X_JP_OFFSET_DRIFT,
            vr::T_DRIFT,
        ],
    },
    Refused {
        effect: "the modulation slots",
        why: "a slot's constant is held over each communication step at the signals at its start",
        parameters: &[vr::MODULATION_1_PARAMETER, vr::MODULATION_2_PARAMETER],
    },
    Refused {
        effect: "the flexible slots",
        why: "a slot's constant is held over each communication step at the signals at its start, and its lags are advanced from step to step",
        parameters: &[vr::FLEXIBLE_1_PARAMETER, vr::FLEXIBLE_2_PARAMETER],
    },
];

fn refusal_message(r: &Refused, switched_on: &str) -> String {
    format!(
        "{switched_on} switches on {} ({}), which Model Exchange does not have ({}); use the Co-Simulation interface of this FMU for it",
        r.effect,
        r.parameters
            .iter()
            .map(|&v| variable_name(v))
            .collect::<Vec<_>>()
            .join(", "),
        r.why
    )
}

/// Whether setting `value_reference` to `value` switches on an effect Model Exchange refuses:
/// the message that names it.
///
/// `command_delay` is taken when set and refused when initialisation ends if
/// `command_delay_pade_sections` is still 0 then: an importer sets the parameters in the model
/// description's order, in which the delay comes first.
pub(super) fn refused_setting(value_reference: u32, value: f64) -> Result<(), String> {
    if value_reference == vr::COMMAND_DELAY {
        return Ok(());
    }
    for r in REFUSED {
        if r.parameters.contains(&value_reference) && value != table_start(value_reference) {
            let what = format!("{} = {value}", variable_name(value_reference));
            return Err(refusal_message(r, &what));
        }
    }
    Ok(())
}

/// The effects a model has that Model Exchange refuses, named with the parameters that
/// switch them on; also what the model's own flags say is on (whatever parameter did it).
fn refused_effects(model: &Actuator, pade_sections: usize) -> Result<(), String> {
    let p = &model.params;
    let mut problems = Vec::new();
    for r in REFUSED {
        if pade_sections > 0 && r.parameters == [vr::COMMAND_DELAY] {
            continue;
        }
        let on: Vec<String> = r
            .parameters
            .iter()
            .filter_map(|&v| {
                let value = p.get(v)?;
                (value != table_start(v)).then(|| format!("{} = {value}", variable_name(v)))
            })
            .collect();
        if !on.is_empty() {
            problems.push(refusal_message(r, &on.join(", ")));
        }
    }
    let flags = [
        (p.command_delay != 0.0 && pade_sections == 0, "transport_delay"),
        (p.current_slew_limit > 0.0, "the command stage's slew limit"),
        (
            Channel::ALL.iter().any(|&c| {
                let law = SensorLaw::of(p, c);
                law.delay > 0.0 || law.play > 0.0
            }),
            "a transducer's delay or play",
        ),
        (model.reads_stopper_motion, "a force on the stopper's motion"),
        (time_varying::varies(p), "constants that vary in time"),
        (flexible::any_on(p), "a flexible slot"),
        (modulation::any_on(p), "a modulation slot"),
    ];
    if problems.is_empty() {
        if let Some((_, what)) = flags.iter().find(|(on, _)| *on) {
            problems.push(format!(
                "the parameters switch on {what}, which Model Exchange does not have; use the Co-Simulation interface of this FMU"
            ));
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "Model Exchange refuses these parameters: {}",
            problems.join("; ")
        ))
    }
}

/// The inputs of the right-hand side: v_DA through the command stage (its static part, then
/// its lag and filter from their states; its slew limit is refused) and the transport delay's
/// Padé chain when it is on, the stopper held, the hysteresis memory.
fn inputs(at: &At<'_>, memory: Option<&Memory>) -> Inputs {
    let command = filters::seen_command(&at.model.params, at.v_da, at.filters);
    Inputs {
        v_da: filters::delayed_command(at.sections, command, at.chain),
        x_s: at.x_s,
        x_s_rate: 0.0,
        plays: memory.copied(),
    }
}

/// `command_delay_pade_sections` when set: from 0 to [`filters::PADE_SECTIONS`] (a whole
/// number, checked when initialisation ends, as the curves' knot counts are).
pub(super) fn check_pade_sections(value: f64) -> Result<f64, String> {
    if (0.0..=filters::PADE_SECTIONS as f64).contains(&value) {
        Ok(value)
    } else {
        Err(format!(
            "command_delay_pade_sections = {value} is invalid: must be a whole number from 0 to {}",
            filters::PADE_SECTIONS
        ))
    }
}

/// `command_delay_pade_sections` as a number of sections: a whole number from 0 to
/// [`filters::PADE_SECTIONS`].
pub(super) fn pade_sections(value: f64) -> Result<usize, String> {
    check_pade_sections(value)?;
    if value.fract() == 0.0 {
        Ok(value as usize)
    } else {
        Err(format!(
            "command_delay_pade_sections = {value} is invalid: must be a whole number from 0 to {}",
            filters::PADE_SECTIONS
        ))
    }
}

/// The memory advanced to the static position of `current`: exact when the current has moved
/// monotonically since the memory was last advanced (see the module's text).
pub(super) fn advance_memory(model: &Actuator, memory: &mut Option<Memory>, current: f64) {
    if let Some(memory) = memory {
        model.hysteresis.advance(memory, model.static_jet_position(current));
    }
}

/// The event indicators: where the right-hand side or the force is not smooth.
/// * z0 = P1 − P2 − F_spring/A_p: the spring floor of the force (2.38) (and the switch of a
///   compliant stopper's law);
/// * z1 = P1 − P2: the leakage past the piston reverses (2.23), √|Δp| there;
/// * z2, z3 = P_s − P1, P_s − P2: a supply flow reverses (2.18);
/// * z4, z5 = P1 − P_r, P2 − P_r: a return flow reverses;
/// * z6 = sin(π x_abs/D_jp): the jet pipe crosses a tangency of the orifice geometry, where
///   the areas (2.8)–(2.17) stop being analytic (every multiple of D_jp);
/// * z7 = ī − i, with the hysteresis on (else 1): the current, and so f3's output, reverses
///   (di/dt = ω_cd (ī − i), (2.1)–(2.3), ī the static current of the command the driver
///   sees, after the command stage's lag and filter), where the hysteresis memory is advanced.
fn event_indicators(at: &At<'_>, z: &mut [f64]) {
    let At {
        model, x, x_s, memory, ..
    } = *at;
    // (the places' pressures with restrictions do not reverse the flows the valve sees
    // between them and the chambers: the same indicators)
    let p = &model.params;
    let (p1, p2) = (x[index::P1], x[index::P2]);
    let floor = model.spring_force(x_s) / model.piston_area;
    let x_abs = jet_pipe::absolute_position(x[index::JET_POSITION], p.x_jp_offset);
    let values = [
        p1 - p2 - floor,
        p1 - p2,
        p.p_s - p1,
        p.p_s - p2,
        p1 - p.p_r,
        p2 - p.p_r,
        (std::f64::consts::PI * x_abs / p.d_jp).sin(),
        match memory {
            Some(_) => {
                let command = inputs(at, None).v_da;
                current_driver::static_current(p.k_cd, p.i_offset, command) - x[index::CURRENT]
            }
            None => 1.0,
        },
    ];
    z.copy_from_slice(&values);
}

/// A point of the right-hand side: the model, the states, the inputs, the time and the
/// hysteresis memory.
#[derive(Clone, Copy)]
pub(super) struct At<'a> {
    pub model: &'a Actuator,
    pub x: &'a State,
    pub nodes: &'a Nodes,
    pub filters: &'a Filters,
    pub chain: &'a Chain,
    pub sections: usize,
    pub v_da: f64,
    pub x_s: f64,
    /// [`AirScale::at`] the model and `x_s`.
    pub scale: AirScale,
    pub time: f64,
    pub memory: Option<&'a Memory>,
}

impl MeState {
    fn at(&self, v_da: f64) -> At<'_> {
        At {
            model: &self.model,
            x: &self.x,
            nodes: &self.nodes,
            filters: &self.filters,
            chain: &self.chain,
            sections: self.sections,
            v_da,
            x_s: self.x_s,
            scale: self.scale,
            time: self.time,
            memory: self.memory.as_ref(),
        }
    }
}

/// The rates of the [`STATES`] states: (4.1) from `Actuator::derivatives`, the chambers'
/// air's from their pressures' (`chambers::reference_pressure_rate`); with gas volumes
/// behind restrictions or a lagging mount, the pressures' from
/// `Actuator::pressure_rates_with_volumes` (the law the Co-Simulation step integrates them
/// with), else 0 for the volumes and the mount; the lags' and filters' from `filters::rates`
/// at the transducers' static readings at the time (0 for those off). The jet pipe's input
/// is f3's output through the hysteresis from the memory when that is on.
fn rates(at: &At<'_>) -> [f64; STATES] {
    let At {
        model,
        x,
        nodes,
        filters,
        chain,
        sections,
        v_da,
        x_s,
        scale,
        time,
        memory,
    } = *at;
    let d = model.derivatives(x, &inputs(at, memory));
    let mut out = [0.0; STATES];
    out[..6].copy_from_slice(d.as_slice());
    if model.has_volume_states() {
        let mut p = [0.0; PRESSURES_WITH_VOLUMES];
        p[0] = x[index::P1];
        p[1] = x[index::P2];
        p[2..].copy_from_slice(nodes);
        let r = model.pressure_rates_with_volumes(&model.areas(x[index::JET_POSITION]), &p, x_s, 0.0);
        out[index::P1..FILTERS].copy_from_slice(&r);
    }
    if filters::any_on(&model.params) {
        let y = model.outputs_at(x, x_s, 0.0, time);
        out[FILTERS..CHAIN].copy_from_slice(&filters::rates(&model.params, v_da, &y, filters));
    }
    if sections > 0 {
        let command = filters::seen_command(&model.params, v_da, filters);
        out[CHAIN..].copy_from_slice(&filters::chain_rates(
            model.params.command_delay,
            sections,
            command,
            chain,
        ));
    }
    // The chambers' air from their pressures' rates, with the volumes' rates these imply
    // (the piston moving with a compliant stopper or a lagging mount; the stopper held).
    if let AirScale::Rigid(factor) = scale {
        out[index::P1] *= factor[0];
        out[index::P2] *= factor[1];
        return out;
    }
    let (p1, p2) = (x[index::P1], x[index::P2]);
    let (v1, v2) = model.chamber_volumes(p1, p2, nodes[node::MOUNT], x_s);
    let offset_rate = model.piston_offset_rate(p1, p2, x_s, out[index::P1], out[index::P2], out[MOUNT_STATE]);
    let (dv1, dv2) = model.cylinder.volume_rates(offset_rate);
    let (r1, r2) = reference_volumes(model);
    let n = model.polytropic_exponent;
    out[index::P1] = reference_pressure_rate(n, p1, out[index::P1], v1, dv1, r1);
    out[index::P2] = reference_pressure_rate(n, p2, out[index::P2], v2, dv2, r2);
    out
}

/// The value of a variable of Model Exchange (a state or a derivative beyond the table's
/// outputs) at a point; `None` for any other value reference.
pub(super) fn state_variable(at: &At<'_>, value_reference: u32) -> Option<f64> {
    if let Some(k) = me_vr::STATES.iter().position(|&v| v == value_reference) {
        return Some(if k < node::STATES {
            at.nodes[k]
        } else if k < node::STATES + filters::STATES {
            at.filters[k - node::STATES]
        } else {
            at.chain[k - node::STATES - filters::STATES]
        });
    }
    if let Some(k) = me_vr::DERIVATIVES.iter().position(|&v| v == value_reference) {
        return Some(rates(at)[k]);
    }
    match value_reference {
        me_vr::X_JP_VELOCITY => Some(at.x[index::JET_VELOCITY]),
        me_vr::X_JP_ACCELERATION => Some(at.x[index::JET_ACCELERATION]),
        me_vr::P1_AT_MID_STROKE => Some(air_states(at.model, at.x, at.nodes, at.x_s, at.scale)[0]),
        me_vr::P2_AT_MID_STROKE => Some(air_states(at.model, at.x, at.nodes, at.x_s, at.scale)[1]),
        _ => None,
    }
}

impl ActuatorFmu {
    /// `fmi2ExitInitializationMode` of Model Exchange: the refusals, then the state the
    /// Co-Simulation would start from (the same equilibrium, or P1_start and P2_start). As in
    /// Co-Simulation, an x_s outside the cylinder set during initialisation (an importer that
    /// starts its connectors at 0) leaves the stopper at the last valid x_s set (or the start
    /// value), and the derivatives are refused until a valid x_s is set.
    pub(super) fn exit_initialization_model_exchange(&mut self) -> Result<(), String> {
        refused_effects(&Actuator::new(self.params.clone())?, pade_sections(self.pade_sections)?)?;
        let me = match self.params.check_stopper(self.x_s) {
            Ok(()) => self.initial_me_state()?,
            Err(e) => {
                let mut fallback = self.clone();
                fallback.x_s = self.x_s_valid;
                fallback.params.check_stopper(fallback.x_s).map_err(|_| e)?;
                fallback.initial_me_state()?
            }
        };
        self.me = Some(me);
        Ok(())
    }

    /// An error while the x_s set during initialisation is outside the cylinder.
    fn check_stopper_set(&self, me: &MeState) -> Result<(), String> {
        if self.x_s == me.x_s {
            return Ok(());
        }
        match self.params.check_stopper(self.x_s) {
            Err(e) => Err(format!(
                "{e} (the x_s set during initialisation; set a valid x_s in event mode)"
            )),
            Ok(()) => Ok(()),
        }
    }

    /// The Model Exchange state at the end of initialisation.
    fn initial_me_state(&self) -> Result<MeState, String> {
        let simulation = self.initial_simulation()?;
        let filters = filters::filters_of(&simulation);
        Ok(MeState {
            model: simulation.model().clone(),
            time: self.start_time,
            x: *simulation.state(),
            nodes: nodes_of(&simulation),
            filters,
            chain: [filters::seen_command(&simulation.model().params, simulation.v_da(), &filters);
                filters::PADE_SECTIONS],
            sections: pade_sections(self.pade_sections)?,
            memory: simulation.hysteresis_memory(),
            x_s: simulation.x_s(),
            scale: AirScale::at(simulation.model(), simulation.x_s()),
        })
    }

    /// The running state, or (before initialisation has ended) the one it would start from.
    fn me_view(&self) -> Result<std::borrow::Cow<'_, MeState>, String> {
        match &self.me {
            Some(me) => Ok(std::borrow::Cow::Borrowed(me)),
            None => self.initial_me_state().map(std::borrow::Cow::Owned),
        }
    }

    /// `fmi2GetReal` of a running Model Exchange instance: the states, the outputs at them and
    /// the inputs; `None` for what the parameters answer.
    pub(super) fn me_real(&self, value_reference: u32) -> Option<f64> {
        let me = self.me.as_ref()?;
        let x = &me.x;
        Some(match value_reference {
            vr::V_DA => self.v_da,
            vr::X_S => me.x_s,
            vr::P1 => x[index::P1],
            vr::P2 => x[index::P2],
            vr::I => x[index::CURRENT],
            vr::X_JP => x[index::JET_POSITION],
            vr::F_ACT | vr::F_MEAS | vr::P1_MEAS | vr::P2_MEAS => {
                let y = filters::filtered_outputs(
                    &me.model.params,
                    me.model.outputs_at(x, me.x_s, 0.0, me.time),
                    &me.filters,
                );
                match value_reference {
                    vr::F_ACT => y.f_act,
                    vr::F_MEAS => y.f_meas,
                    vr::P1_MEAS => y.p1_meas,
                    _ => y.p2_meas,
                }
            }
            _ => return state_variable(&me.at(self.v_da), value_reference),
        })
    }

    /// A new x_s in a running Model Exchange instance, in any mode: checked against the
    /// cylinder, and the stopper moved at once as in Co-Simulation (the pressures jump along
    /// their adiabats; the states, the chambers' air, stay).
    pub(super) fn move_stopper_model_exchange(&mut self, x_s: f64) -> Result<(), String> {
        self.params.check_stopper(x_s)?;
        if let Some(me) = self.me.as_mut() {
            if x_s != me.x_s {
                let (p1, p2) = (me.x[index::P1], me.x[index::P2]);
                let [p1, p2] = me
                    .model
                    .pressures_after_stopper_jump(p1, p2, me.nodes[node::MOUNT], me.x_s, x_s);
                me.x[index::P1] = p1;
                me.x[index::P2] = p2;
            }
            me.x_s = x_s;
            me.scale = AirScale::at(&me.model, x_s);
        }
        self.x_s = x_s;
        Ok(())
    }

    pub(super) fn me_time(&self) -> Option<f64> {
        self.me.as_ref().map(|me| me.time)
    }

    /// The Model Exchange part of the serialized state: the interface, then (when running)
    /// time, states, the stopper and the hysteresis memory.
    pub(super) fn serialize_model_exchange(&self, w: &mut fmi2::state_bytes::ByteWriter) {
        w.bool(self.model_exchange);
        w.f64(self.pade_sections);
        match &self.me {
            None => w.bool(false),
            Some(me) => {
                w.bool(true);
                w.f64(me.time);
                w.f64s(me.x.as_slice());
                w.f64s(&me.nodes);
                w.f64s(&me.filters);
                w.f64s(&me.chain);
                w.f64(me.x_s);
                w.bool(me.memory.is_some());
                w.f64s(me.memory.as_ref().map_or(&[][..], |m| &m[..]));
            }
        }
    }

    /// Read what [`Self::serialize_model_exchange`] wrote into `restored` (whose parameters
    /// are already read).
    /// (The layer refuses an FMU state of the other interface before the bytes reach here.)
    pub(super) fn deserialize_model_exchange(
        r: &mut fmi2::state_bytes::ByteReader<'_>,
        restored: &mut ActuatorFmu,
    ) -> Result<(), String> {
        restored.model_exchange = r.bool("modelExchange")?;
        restored.pade_sections = check_pade_sections(r.f64()?)?;
        if r.bool("modelExchangeRunning")? {
            let time = r.f64()?;
            let values = r.f64s_at_most(6, "continuous states")?;
            let node_values = r.f64s_at_most(node::STATES, "states beyond the six")?;
            if values.len() != 6 || node_values.len() != node::STATES {
                return Err(format!(
                    "{} + {} continuous states, not 6 + {}",
                    values.len(),
                    node_values.len(),
                    node::STATES
                ));
            }
            let mut nodes = [0.0; node::STATES];
            nodes.copy_from_slice(&node_values);
            let filter_values = r.f64s_at_most(filters::STATES, "states of the lags and filters")?;
            if filter_values.len() != filters::STATES {
                return Err(format!(
                    "{} states of the lags and filters, not {} (an FMU state of another version of the model)",
                    filter_values.len(),
                    filters::STATES
                ));
            }
            let mut filter_states = [0.0; filters::STATES];
            filter_states.copy_from_slice(&filter_values);
            let chain_values = r.f64s_at_most(filters::PADE_SECTIONS, "states of the Pade chain")?;
            let sections = pade_sections(restored.pade_sections)?;
            if chain_values.len() != filters::PADE_SECTIONS {
                return Err(format!(
                    "{} states of the Pade chain, not {} (an FMU state of another version of the model)",
                    chain_values.len(),
                    filters::PADE_SECTIONS
                ));
            }
            let mut chain = [0.0; filters::PADE_SECTIONS];
            chain.copy_from_slice(&chain_values);
            let x_s = r.f64()?;
            restored.params.check_stopper(x_s)?;
            let model = Actuator::new(restored.params.clone())?;
            let has_memory = r.bool("hysteresisMemory")?;
            let memory_values = r.f64s_at_most(PLAY_OPERATORS, "hysteresis memory")?;
            let memory = match (has_memory, model.hysteresis.is_active()) {
                (true, true) if memory_values.len() == PLAY_OPERATORS => {
                    if let Some(v) = memory_values.iter().find(|v| !v.is_finite()) {
                        return Err(format!("a hysteresis memory value is {v}"));
                    }
                    let mut memory = [0.0; PLAY_OPERATORS];
                    memory.copy_from_slice(&memory_values);
                    Some(memory)
                }
                (false, false) if memory_values.is_empty() => None,
                _ => {
                    return Err(format!(
                        "a hysteresis memory of {} values for parameters whose hysteresis is {}",
                        memory_values.len(),
                        if model.hysteresis.is_active() { "on" } else { "off" }
                    ))
                }
            };
            let scale = AirScale::at(&model, x_s);
            restored.me = Some(MeState {
                model,
                time,
                x: State::from_column_slice(&values),
                nodes,
                filters: filter_states,
                chain,
                sections,
                memory,
                x_s,
                scale,
            });
        }
        Ok(())
    }
}

impl ModelExchangeModel for ActuatorFmu {
    fn set_time(&mut self, time: f64) -> Result<(), String> {
        match self.me.as_mut() {
            Some(me) => {
                me.time = time;
                Ok(())
            }
            None => Err("the model is not initialised".to_string()),
        }
    }

    fn continuous_states(&self, x: &mut [f64]) -> Result<(), String> {
        let me = self.me_view()?;
        x[..6].copy_from_slice(me.x.as_slice());
        let air = air_states(&me.model, &me.x, &me.nodes, me.x_s, me.scale);
        x[index::P1..index::P1 + 2].copy_from_slice(&air);
        x[6..FILTERS].copy_from_slice(&me.nodes);
        x[FILTERS..CHAIN].copy_from_slice(&me.filters);
        x[CHAIN..].copy_from_slice(&me.chain);
        Ok(())
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        let me = self
            .me
            .as_mut()
            .ok_or_else(|| "the model is not initialised".to_string())?;
        for k in [index::P1, index::P2] {
            if x[k] <= 0.0 || !x[k].is_finite() {
                return Err(format!(
                    "x[{k}] = {} Pa is not an absolute pressure of {} (must be > 0)",
                    x[k],
                    if k == index::P1 {
                        "P1_at_mid_stroke"
                    } else {
                        "P2_at_mid_stroke"
                    }
                ));
            }
        }
        let mut nodes = [0.0; node::STATES];
        nodes.copy_from_slice(&x[6..FILTERS]);
        let pressures = pressures_of_air(&me.model, [x[index::P1], x[index::P2]], &nodes, me.x_s, me.scale);
        if let Some(p) = pressures.iter().find(|p| !(p.is_finite() && **p > 0.0)) {
            return Err(format!(
                "the chambers' air {:?} Pa at mid-stroke gives the pressure {p} Pa with the stopper at x_s = {} m (the mount's state {} Pa): not an absolute pressure",
                [x[index::P1], x[index::P2]],
                me.x_s,
                nodes[node::MOUNT]
            ));
        }
        me.x = State::from_column_slice(&x[..6]);
        me.x[index::P1] = pressures[0];
        me.x[index::P2] = pressures[1];
        me.nodes = nodes;
        me.filters.copy_from_slice(&x[FILTERS..CHAIN]);
        me.chain.copy_from_slice(&x[CHAIN..]);
        Ok(())
    }

    fn derivatives(&self, dx: &mut [f64]) -> Result<(), String> {
        let me = self.me_view()?;
        self.check_stopper_set(&me)?;
        let d = rates(&me.at(self.v_da));
        if let Some(k) = d.iter().position(|v| !v.is_finite()) {
            return Err(format!(
                "the derivative of state {k} is {} at the states {:?}",
                d[k],
                me.x.as_slice()
            ));
        }
        dx.copy_from_slice(&d);
        Ok(())
    }

    fn event_indicators(&self, z: &mut [f64]) -> Result<(), String> {
        let me = self.me_view()?;
        self.check_stopper_set(&me)?;
        event_indicators(&me.at(self.v_da), z);
        Ok(())
    }

    fn nominals(&self, nominals: &mut [f64]) {
        // The scales of the Co-Simulation's tolerances: 0.1 A, 0.1 mm and its natural-frequency
        // derivatives, 1 bar (also for the volumes' pressures and the mount's load); the lags'
        // and filters' of `filters::scales`.
        let scales = match Actuator::new(self.params.clone()) {
            Ok(model) => model.state_scales(),
            Err(_) => Actuator::new(Parameters::default()).map_or(State::repeat(1.0), |m| m.state_scales()),
        };
        nominals[..6].copy_from_slice(scales.as_slice());
        nominals[6..FILTERS].iter_mut().for_each(|n| *n = scales[index::P1]);
        nominals[FILTERS..CHAIN].copy_from_slice(&filters::scales(&self.params));
        nominals[CHAIN..].iter_mut().for_each(|n| *n = 1.0);
    }

    /// Every event (a reversal of the current, z7, among them) advances the hysteresis
    /// memory; no continuous state changes at one (a stopper moved leaves the air as it is).
    fn new_discrete_states(&mut self) -> Result<EventUpdate, String> {
        if let Some(me) = self.me.as_mut() {
            advance_memory(&me.model, &mut me.memory, me.x[index::CURRENT]);
        }
        Ok(EventUpdate::default())
    }

    /// The hysteresis memory advanced to the accepted step's end.
    fn completed_integrator_step(&mut self) -> Result<bool, String> {
        if let Some(me) = self.me.as_mut() {
            advance_memory(&me.model, &mut me.memory, me.x[index::CURRENT]);
        }
        Ok(false)
    }
}

#[cfg(test)]
mod filter_tests;
#[cfg(test)]
mod tests;
