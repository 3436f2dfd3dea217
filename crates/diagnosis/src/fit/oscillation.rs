//! A constant oscillating at a spectral line: where the line comes from, and the outputs'
//! answer to it through the model.
//!
//! A sinusoid faster than the chambers answer is not screened as the constant's sensitivity
//! times sin and cos (that reads the increment as acting at once: the waveform right and
//! the phase wrong, and blind to a saturation that clips it). The model is replayed with
//! the constant oscillating in a modulation slot, once in sine and once in cosine; the two
//! answers are exact to first order, lags and clipping included.

use crate::candidates::modulation::{free_slots, slot_parameter, value_reference};
use crate::fit::normal::Normal;
use crate::fit::{Problem, Sensitivity};
use crate::replay::signals::CHANNELS;
use crate::replay::Replay;
use jetpipe_model::physics::modulation::ModulationSignal;

/// The outputs' answer through the model to `constant` oscillating at `hz`: the base model
/// with `step`·sin(2π hz t), then `step`·cos(2π hz t), added to the constant in a free
/// modulation slot, each replayed once and divided by the step. `None` without a free slot
/// or when a replay fails.
pub fn responses(
    problem: &Problem,
    replay: &Replay,
    constant: &'static str,
    step: f64,
    hz: f64,
) -> Option<[Sensitivity; 2]> {
    let slot = *free_slots(problem.base).first()?;
    let answer = |signal: ModulationSignal| {
        let settings = [
            (slot_parameter(slot, "parameter"), value_reference(constant)),
            (slot_parameter(slot, "signal"), f64::from(signal.code())),
            (slot_parameter(slot, "frequency"), hz),
            (slot_parameter(slot, "knots"), 2.0),
            (slot_parameter(slot, "x_1"), -1.0),
            (slot_parameter(slot, "x_2"), 1.0),
            (slot_parameter(slot, "y_1"), -step),
            (slot_parameter(slot, "y_2"), step),
        ];
        problem.sensitivity_to(&settings, step, replay)
    };
    Some([answer(ModulationSignal::Sine)?, answer(ModulationSignal::Cosine)?])
}

/// A sinusoidal modulation at a line, screened on the model's answers to it ([`responses`])
/// against a constant shift (the constant's sensitivity): the knots (−1 and 1 of the sine,
/// then of the cosine), the amplitudes of sine and cosine and the penalised held-out sum of
/// squares; `None` when the constant shift does as well.
pub fn screen_periodic(
    problem: &Problem,
    residual: &[Vec<f64>; CHANNELS],
    sensitivity: &Sensitivity,
    answers: &[Sensitivity; 2],
    penalty: f64,
) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    let mut normal = Normal::new(3);
    for (k, &block) in problem.blocks.iter().enumerate() {
        if !block.is_used() {
            continue;
        }
        for c in 0..CHANNELS {
            if residual[c].is_empty() || sensitivity[c].is_empty() || answers[0][c].is_empty() {
                continue;
            }
            let w = problem.weights[c];
            let row = [
                w * f64::from(sensitivity[c][k]),
                w * f64::from(answers[0][c][k]),
                w * f64::from(answers[1][c][k]),
            ];
            normal.add(block, &row, residual[c][k]);
        }
    }
    let (_, constant_ss) = normal.solve_in(&[vec![1.0], vec![0.0], vec![0.0]])?;
    let (y, ss) = normal.solve_in(&[vec![0.0, 0.0], vec![1.0, 0.0], vec![0.0, 1.0]])?;
    let scored = ss + 2.0 * penalty;
    (scored < constant_ss + penalty).then(|| (vec![-1.0, 1.0, -1.0, 1.0], y, scored))
}

/// The spectral line of a constant's increment traced over short windows (the least-squares
/// increment of each window, shrunk where the constant barely moves the outputs), if it has
/// a clear one above the slowest wander the time knots follow.
pub fn traced_line(problem: &Problem, residual: &[Vec<f64>; CHANNELS], sensitivity: &Sensitivity) -> Option<f64> {
    let time = &problem.recording.time;
    let n = time.len();
    let rate = crate::input::recording::sample_rate(time);
    let window = ((TRACE_WINDOW_S * rate).round() as usize).max(MIN_TRACE_SAMPLES);
    let mut centres = vec![];
    let mut sums = vec![];
    let mut k = 0;
    while k + window <= n {
        let (mut rs, mut ss) = (0.0, 0.0);
        for j in k..k + window {
            if !problem.blocks[j].is_used() {
                continue;
            }
            for c in 0..CHANNELS {
                if residual[c].is_empty() || sensitivity[c].is_empty() {
                    continue;
                }
                let s = problem.weights[c] * f64::from(sensitivity[c][j]);
                rs += residual[c][j] * s;
                ss += s * s;
            }
        }
        if ss > 0.0 {
            centres.push(0.5 * (time[k] + time[k + window - 1]));
            sums.push((rs, ss));
        }
        k += window;
    }
    if sums.len() < 32 {
        return None;
    }
    let mut information: Vec<f64> = sums.iter().map(|s| s.1).collect();
    information.sort_by(|a, b| a.total_cmp(b));
    let shrink = 0.1 * information[information.len() / 2];
    let trace: Vec<f64> = sums.iter().map(|(rs, ss)| rs / (ss + shrink)).collect();
    let line = crate::replay::signature::spectrum(&centres, &trace);
    (line.peak_over_median > TRACE_LINE_OVER_MEDIAN
        && line.peak_hz > TRACE_LOWEST_HZ
        && !carried_by_inputs(problem, line.peak_hz))
    .then_some(line.peak_hz)
}

/// Whether the command or the stopper position carries a line at `hz` (its power there a
/// hundred times that at ±10 % and ±20 %): a constant's increment that follows it is the
/// plant's answer to that input, not a disturbance (a shaken stopper's 2.5 Hz).
pub fn carried_by_inputs(problem: &Problem, hz: f64) -> bool {
    let recording = problem.recording;
    let rate = crate::input::recording::sample_rate(&recording.time);
    [&recording.v_da, &recording.x_s].iter().any(|x| {
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let centred: Vec<f64> = x.iter().map(|v| v - mean).collect();
        let at = crate::input::lines::power_at(&centred, hz, rate);
        let around = [0.8, 0.9, 1.1, 1.2]
            .iter()
            .map(|k| crate::input::lines::power_at(&centred, k * hz, rate))
            .fold(0.0, f64::max);
        at > 100.0 * around
    })
}

/// Windows of the traced increment ([`traced_line`]), s, and at least this many samples.
const TRACE_WINDOW_S: f64 = 0.005;
const MIN_TRACE_SAMPLES: usize = 8;
/// A traced line must stand this far above the median of the spectrum…
const TRACE_LINE_OVER_MEDIAN: f64 = 50.0;
/// …and lie above this frequency (Hz): slower ones are the time knots' wander.
const TRACE_LOWEST_HZ: f64 = 0.15;
