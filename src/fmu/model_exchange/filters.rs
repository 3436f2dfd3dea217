//! The command stage's and the transducers' lags and second-order filters as continuous
//! states of Model Exchange: twelve states, three for each of four stages (the command
//! stage, the force sensor, the two pressure transducers), each [the lag's output, the
//! filter's output, the filter's rate] (constant, their rates 0, while the stage's lag or
//! filter is off). And the transport delay's optional Padé chain ([`delayed_command`],
//! [`chain_rates`]), after the command stage, as Co-Simulation delays the stage's output.
//!
//! The equations are the ones whose exact solutions the Co-Simulation step takes over each
//! communication interval, from `jetpipe_model::physics::sensors`: the lag τ y' = u − y
//! (`first_order_rate`), the filter y'' + 2ζω y' + ω² y = ω² u (`second_order_rates`), in
//! the order Co-Simulation applies them: the lag, then the filter of the lag's output (of the
//! stage's input without the lag).
//! * Command stage: u is `command_stage::static_map` of v_DA (`command_lag`,
//!   `command_filter_frequency`, `command_filter_damping`); the current driver sees the last
//!   term's output.
//! * Transducers: u is the static reading of the quantity at the time
//!   (`SensorLaw::static_reading`: offset, gain, curve, drift, pick-up) (`*_sensor_lag`,
//!   `*_sensor_filter_frequency`, `*_sensor_filter_damping`); `F_meas`, `P1_meas` and
//!   `P2_meas` are the last term's output.
//!
//! Where Co-Simulation and Model Exchange differ, by construction: Co-Simulation takes the
//! transducer's input linear between the points it records (every communication point, and
//! parts of at most 1 ms within a step), and the filter after the command lag takes the lag's
//! output held over each communication step; the driver sees the command stage's output as
//! chords between its exact values. Model Exchange follows them continuously. Neither
//! switches, so no event indicator is added: their right-hand sides are smooth but where
//! their inputs are not (the spring floor of F_act, z0; a transducer's static curve has a
//! corner at each knot, where the reading's rate jumps, which a solver steps over).

use jetpipe_model::physics::actuator::{Actuator, Outputs};
use jetpipe_model::physics::command_stage;
use jetpipe_model::physics::parameters::Parameters;
use jetpipe_model::physics::sensors::{first_order_rate, second_order_rates, Channel, SensorLaw};
use jetpipe_model::simulation::Simulation;

/// The number of states: three for each of the four stages.
pub const STATES: usize = 12;

/// The states, in the order of [`Stage::ALL`], each [lagged, filtered, filtered rate].
pub type Filters = [f64; STATES];

/// A stage with a lag and a filter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stage {
    Command,
    Sensor(Channel),
}

impl Stage {
    pub const ALL: [Stage; 4] = [
        Stage::Command,
        Stage::Sensor(Channel::Force),
        Stage::Sensor(Channel::Pressure1),
        Stage::Sensor(Channel::Pressure2),
    ];

    /// Where its three states start in [`Filters`].
    pub fn offset(self) -> usize {
        3 * Self::ALL.iter().position(|&s| s == self).unwrap_or(0)
    }

    /// Its lag (s, 0: off), filter frequency (Hz, 0: off) and damping ratio.
    fn law(self, p: &Parameters) -> (f64, f64, f64) {
        match self {
            Stage::Command => (p.command_lag, p.command_filter_frequency, p.command_filter_damping),
            Stage::Sensor(channel) => {
                let law = SensorLaw::of(p, channel);
                (law.lag, law.filter_frequency, law.filter_damping)
            }
        }
    }

    /// Whether its lag or filter is on (so that its states move).
    pub fn is_on(self, p: &Parameters) -> bool {
        let (lag, frequency, _) = self.law(p);
        lag > 0.0 || frequency > 0.0
    }

    /// The stage's output for its `input` at its states `s`: the filter's, the lag's, or the
    /// input itself.
    fn output(self, p: &Parameters, input: f64, s: &[f64]) -> f64 {
        let (lag, frequency, _) = self.law(p);
        if frequency > 0.0 {
            s[1]
        } else if lag > 0.0 {
            s[0]
        } else {
            input
        }
    }

    /// The rates of its states `s` for its `input` (0 for a term that is off).
    fn rates(self, p: &Parameters, input: f64, s: &[f64], out: &mut [f64]) {
        let (lag, frequency, damping) = self.law(p);
        out[..3].iter_mut().for_each(|r| *r = 0.0);
        let filter_input = if lag > 0.0 {
            out[0] = first_order_rate(lag, input, s[0]);
            s[0]
        } else {
            input
        };
        if frequency > 0.0 {
            let (rate, acceleration) = second_order_rates(frequency, damping, (s[1], s[2]), filter_input);
            out[1] = rate;
            out[2] = acceleration;
        }
    }

    /// The scales of its states for the importer's tolerances: 1 V, 10 N or 1 bar, and the
    /// filter's rate over 1/ω.
    fn scales(self, p: &Parameters) -> [f64; 3] {
        let (_, frequency, _) = self.law(p);
        let scale = match self {
            Stage::Command => 1.0,
            Stage::Sensor(Channel::Force) => 10.0,
            Stage::Sensor(_) => 1e5,
        };
        let omega = 2.0 * std::f64::consts::PI * frequency;
        [scale, scale, if omega > 0.0 { scale * omega } else { scale }]
    }
}

/// The command the current driver sees: v_DA through the command stage's static part, then
/// its lag and filter from their states.
pub fn seen_command(p: &Parameters, v_da: f64, filters: &Filters) -> f64 {
    let input = if command_stage::is_active(p) {
        command_stage::static_map(p, v_da)
    } else {
        v_da
    };
    let k = Stage::Command.offset();
    Stage::Command.output(p, input, &filters[k..k + 3])
}

/// The outputs with the transducers' readings through their lags and filters.
pub fn filtered_outputs(p: &Parameters, mut y: Outputs, filters: &Filters) -> Outputs {
    for (reading, stage) in y.readings_mut().into_iter().zip(&Stage::ALL[1..]) {
        let k = stage.offset();
        *reading = stage.output(p, *reading, &filters[k..k + 3]);
    }
    y
}

/// The rates of the [`STATES`] states, for the static readings of `static_outputs`.
pub fn rates(p: &Parameters, v_da: f64, static_outputs: &Outputs, filters: &Filters) -> Filters {
    let mut out = [0.0; STATES];
    let command = if command_stage::is_active(p) {
        command_stage::static_map(p, v_da)
    } else {
        v_da
    };
    let inputs = [
        command,
        static_outputs.f_meas,
        static_outputs.p1_meas,
        static_outputs.p2_meas,
    ];
    for (stage, input) in Stage::ALL.iter().zip(inputs) {
        if stage.is_on(p) {
            let k = stage.offset();
            stage.rates(p, input, &filters[k..k + 3], &mut out[k..k + 3]);
        }
    }
    out
}

/// Whether any stage's states move.
pub fn any_on(p: &Parameters) -> bool {
    Stage::ALL.iter().any(|s| s.is_on(p))
}

/// The states' scales (see [`Stage::scales`]).
pub fn scales(p: &Parameters) -> Filters {
    let mut out = [0.0; STATES];
    for stage in Stage::ALL {
        let k = stage.offset();
        out[k..k + 3].copy_from_slice(&stage.scales(p));
    }
    out
}

/// The states of a simulation: its command stage's and transducers' memories (a transducer
/// without one: its static reading, at rest).
pub fn filters_of(simulation: &Simulation) -> Filters {
    let mut out = [0.0; STATES];
    out[..3].copy_from_slice(&simulation.command_dynamics());
    let y = static_outputs(simulation.model(), simulation);
    for ((stage, channel), reading) in Stage::ALL[1..].iter().zip(Channel::ALL).zip(y.readings()) {
        let k = stage.offset();
        let s = simulation
            .transducer_dynamics(channel)
            .unwrap_or([reading, reading, 0.0]);
        out[k..k + 3].copy_from_slice(&s);
    }
    out
}

/// A simulation's outputs with the static readings of its transducers (no memory).
fn static_outputs(model: &Actuator, simulation: &Simulation) -> Outputs {
    model.outputs_at(simulation.state(), simulation.x_s(), 0.0, simulation.time())
}

/// The most sections of the transport delay's Padé chain.
pub const PADE_SECTIONS: usize = 8;

/// The chain's states, one a section (constant beyond the sections in use).
pub type Chain = [f64; PADE_SECTIONS];

/// The transport delay e^{−sd} as its closest state form, a chain of `sections` first-order
/// Padé sections (1 − sτ)/(1 + sτ), τ = d/(2n) (each the (1,1) Padé approximant of
/// e^{−s d/n}): section k is the lag τ x' = u_k − x (`first_order_rate`) with output
/// u_{k+1} = 2x − u_k. The command after the chain: what the current driver sees.
pub fn delayed_command(sections: usize, command: f64, chain: &Chain) -> f64 {
    chain[..sections].iter().fold(command, |u, &x| 2.0 * x - u)
}

/// The rates of the chain's states (0 beyond the `sections` in use).
pub fn chain_rates(delay: f64, sections: usize, command: f64, chain: &Chain) -> Chain {
    let mut out = [0.0; PADE_SECTIONS];
    if sections == 0 || delay <= 0.0 {
        return out;
    }
    let tau = delay / (2.0 * sections as f64);
    let mut u = command;
    for k in 0..sections {
        out[k] = first_order_rate(tau, u, chain[k]);
        u = 2.0 * chain[k] - u;
    }
    out
}
