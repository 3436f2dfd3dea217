//! The design: a protocol on which the closest two explanations differ most.
//!
//! The criterion is the smallest of the explanations' pairwise differences, each the RMS over
//! the protocol of their predicted readings' difference, channel by channel in the report's
//! noise floors (force, and each pressure where the recording had them), summed over the
//! channels in quadrature. Rival models are compared as the report fitted them, not refitted
//! to each other's predictions on the new protocol: a difference that a refit would absorb
//! (a constant shift of the force, say) counts here, so the figures are upper bounds on what
//! a diagnosis of the new recording will see (Atkinson and Fedorov's T-optimal design refits;
//! this is its first step).
//!
//! The protocol is built greedily, a segment at a time: each segment is the best of a few
//! random draws ([`Segment::draw`]), every explanation simulated by the model (error
//! controlled, the command held from sample to sample and the stopper linear between them)
//! from the state the segments before left it in.

use crate::propose::explanations::{rivals, Explanation};
use crate::propose::protocol::{Draws, Protocol, Segment, STOPPER_HOME};
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::simulation::{Simulation, DEFAULT_RELATIVE_TOLERANCE};
use serde_json::Value;

/// The explanations a proposal separates at most: the report's model and three rivals.
pub const MOST_EXPLANATIONS: usize = 4;
/// A segment's length, s: long enough for the chambers and a slow swing of the stopper to
/// show, short enough for the design to change its mind eight times in 40 s.
const SEGMENT_SECONDS: f64 = 5.0;

/// What to propose.
#[derive(Clone, Debug)]
pub struct ProposeOptions {
    pub seconds: f64,
    pub rate: f64,
    /// Random draws tried for each segment.
    pub draws_per_segment: usize,
    pub seed: u64,
    pub jobs: usize,
}

impl Default for ProposeOptions {
    fn default() -> Self {
        ProposeOptions {
            seconds: 40.0,
            rate: 1000.0,
            draws_per_segment: 24,
            seed: 1,
            jobs: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// The predicted difference between two explanations.
#[derive(Clone, Debug)]
pub struct Difference {
    pub first: usize,
    pub second: usize,
    /// In noise floors, the channels summed in quadrature.
    pub noise_floors: f64,
    /// Each channel's RMS difference in its own noise floors.
    pub by_channel: Vec<f64>,
}

/// A proposed protocol with what it separates.
#[derive(Clone, Debug)]
pub struct Proposal {
    pub protocol: Protocol,
    pub explanations: Vec<Explanation>,
    /// The channels compared ("force_N", "p1_Pa", "p2_Pa") and their noise floors.
    pub channels: Vec<&'static str>,
    pub noise: Vec<f64>,
    pub differences: Vec<Difference>,
    /// Each segment, as a reader names it, with its start time.
    pub segments: Vec<(f64, String)>,
    /// Each explanation's predicted readings, by channel, at every sample.
    pub predicted: Vec<Vec<Vec<f64>>>,
    /// The places the report ties, and whether it explains the recording.
    pub tied: Vec<String>,
    pub explained: bool,
}

impl Proposal {
    /// The closest pair: the figure the design maximised.
    pub fn smallest(&self) -> &Difference {
        self.differences
            .iter()
            .min_by(|a, b| a.noise_floors.total_cmp(&b.noise_floors))
            .expect("a proposal separates at least two explanations")
    }
}

/// Every explanation played over one segment.
struct Played {
    simulations: Vec<Simulation>,
    /// [explanation][channel][sample], the samples after the segment's start (and the start
    /// itself on the first segment).
    readings: Vec<Vec<Vec<f64>>>,
    /// Each pair's sum of squared differences, in noise floors, by channel.
    pair_squares: Vec<Vec<f64>>,
    /// The segment's samples after its start: time, command, stopper.
    time: Vec<f64>,
    v_da: Vec<f64>,
    x_s: Vec<f64>,
}

fn pairs(n: usize) -> Vec<(usize, usize)> {
    (0..n).flat_map(|a| (a + 1..n).map(move |b| (a, b))).collect()
}

fn record(readings: &mut [Vec<f64>], simulation: &Simulation) {
    let y = simulation.outputs().readings();
    for (channel, series) in readings.iter_mut().enumerate() {
        series.push(y[channel]);
    }
}

/// `segment` played from `start` (each explanation's simulation where the protocol stands),
/// or from rest at its first inputs; `from` is the stopper's position, `t0` the time.
fn play(
    models: &[Actuator],
    start: Option<&[Simulation]>,
    segment: &Segment,
    (t0, from, rate): (f64, f64, f64),
    noise: &[f64],
) -> Result<Played, String> {
    let (time, v_da, x_s) = segment.samples(rate, t0, from);
    let first_command = segment.first_command();
    let channels = noise.len();
    let mut simulations = vec![];
    let mut readings = vec![];
    for (k, model) in models.iter().enumerate() {
        let mut series = vec![Vec::with_capacity(time.len() + 1); channels];
        let mut simulation = match start {
            Some(s) => s[k].clone(),
            None => {
                let s = Simulation::at_equilibrium(model.clone(), first_command, from, t0, DEFAULT_RELATIVE_TOLERANCE)?;
                record(&mut series, &s);
                s
            }
        };
        let (mut x_before, mut t_before) = (from, t0);
        let mut v_before = start.map_or(first_command, |s| s[k].v_da());
        for j in 0..time.len() {
            let dt = time[j] - t_before;
            simulation.set_stopper_rate((x_s[j] - x_before) / dt)?;
            simulation.set_command(v_before)?;
            simulation.step(dt).map_err(|e| format!("{e:?}"))?;
            simulation.land_stopper_at(x_s[j]);
            if j + 1 < time.len() {
                simulation.set_stopper_rate((x_s[j + 1] - x_s[j]) * rate)?;
            }
            record(&mut series, &simulation);
            (x_before, t_before, v_before) = (x_s[j], time[j], v_da[j]);
        }
        // The command the next segment's first interval holds.
        simulation.set_command(v_before)?;
        simulations.push(simulation);
        readings.push(series);
    }
    let pair_squares = pairs(models.len())
        .into_iter()
        .map(|(a, b)| {
            (0..channels)
                .map(|c| {
                    let scale = 1.0 / noise[c];
                    readings[a][c]
                        .iter()
                        .zip(&readings[b][c])
                        .map(|(p, q)| ((p - q) * scale).powi(2))
                        .sum()
                })
                .collect()
        })
        .collect();
    Ok(Played {
        simulations,
        readings,
        pair_squares,
        time,
        v_da,
        x_s,
    })
}

type PlayedSegment = Result<Played, String>;

/// Every segment of `tried` played over `jobs` threads, in order. A simulation keeps caches
/// that one thread at a time may use: each thread plays from its own copy of `start`.
fn play_each(
    models: &[Actuator],
    start: Option<&[Simulation]>,
    tried: &[Segment],
    at: (f64, f64, f64),
    noise: &[f64],
    jobs: usize,
) -> Vec<PlayedSegment> {
    let jobs = jobs.clamp(1, tried.len().max(1));
    let mut out: Vec<(usize, PlayedSegment)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..jobs)
            .map(|j| {
                let copy: Option<Vec<Simulation>> = start.map(<[Simulation]>::to_vec);
                scope.spawn(move || {
                    (j..tried.len())
                        .step_by(jobs)
                        .map(|k| (k, play(models, copy.as_deref(), &tried[k], at, noise)))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a proposal's worker panicked"))
            .collect()
    });
    out.sort_by_key(|(k, _)| *k);
    out.into_iter().map(|(_, p)| p).collect()
}

/// The protocol `report` asks for (module docs).
pub fn propose(report: &Value, options: &ProposeOptions, progress: &mut dyn FnMut(&str)) -> Result<Proposal, String> {
    if !(5.0..=120.0).contains(&options.seconds) {
        return Err(format!(
            "--seconds {} is invalid: must be within 5–120 s",
            options.seconds
        ));
    }
    if !(250.0..=4000.0).contains(&options.rate) {
        return Err(format!(
            "--rate {} is invalid: must be within 250–4000 Hz",
            options.rate
        ));
    }
    let rivals = rivals(report, MOST_EXPLANATIONS)?;
    let models = rivals
        .explanations
        .iter()
        .map(|e| Actuator::new(e.parameters.clone()).map_err(|m| format!("{}: {m}", e.label)))
        .collect::<Result<Vec<_>, _>>()?;
    let channels = ["force_N", "p1_Pa", "p2_Pa"][..rivals.noise.len()].to_vec();
    let segment_count = (options.seconds / SEGMENT_SECONDS).round().max(1.0) as usize;
    let seconds = options.seconds / segment_count as f64;
    let mut protocol = Protocol {
        rate: options.rate,
        ..Protocol::default()
    };
    let mut simulations: Option<Vec<Simulation>> = None;
    let mut totals = vec![vec![0.0; channels.len()]; pairs(models.len()).len()];
    let mut predicted = vec![vec![vec![]; channels.len()]; models.len()];
    let mut segments = vec![];
    let (mut t0, mut from) = (0.0, STOPPER_HOME);
    for s in 0..segment_count {
        let mut draws = Draws::new(options.seed.wrapping_mul(0x2545_f491_4f6c_dd1d).wrapping_add(s as u64));
        let tried: Vec<Segment> = (0..options.draws_per_segment.max(1))
            .map(|_| Segment::draw(&mut draws, seconds))
            .collect();
        let played = play_each(
            &models,
            simulations.as_deref(),
            &tried,
            (t0, from, options.rate),
            &rivals.noise,
            options.jobs,
        );
        let score = |p: &Played| {
            p.pair_squares
                .iter()
                .zip(&totals)
                .map(|(seg, total)| seg.iter().zip(total).map(|(a, b)| a + b).sum::<f64>())
                .fold(f64::INFINITY, f64::min)
        };
        let mut failures = vec![];
        let mut best: Option<(usize, f64)> = None;
        for (k, result) in played.iter().enumerate() {
            match result {
                Ok(p) if best.map_or(true, |(_, b)| score(p) > b) => best = Some((k, score(p))),
                Ok(_) => {}
                Err(e) => failures.push(e.clone()),
            }
        }
        let Some((chosen, _)) = best else {
            return Err(format!(
                "no draw of segment {} could be simulated for every explanation: {}",
                s + 1,
                failures.first().map_or("", String::as_str)
            ));
        };
        let p = played
            .into_iter()
            .nth(chosen)
            .expect("chosen among the played")
            .expect("chosen was Ok");
        let (time, v_da, x_s) = (&p.time, &p.v_da, &p.x_s);
        if s == 0 {
            protocol.time.push(0.0);
            protocol.v_da.push(tried[chosen].first_command());
            protocol.x_s.push(from);
        }
        protocol.time.extend(time);
        protocol.v_da.extend(v_da);
        protocol.x_s.extend(x_s);
        for (total, seg) in totals.iter_mut().zip(&p.pair_squares) {
            total.iter_mut().zip(seg).for_each(|(a, b)| *a += b);
        }
        for (mine, series) in predicted.iter_mut().zip(&p.readings) {
            mine.iter_mut().zip(series).for_each(|(a, b)| a.extend(b));
        }
        segments.push((t0, tried[chosen].describe()));
        progress(&format!(
            "segment {} of {segment_count}: {}",
            s + 1,
            tried[chosen].describe()
        ));
        (t0, from) = (*time.last().unwrap_or(&t0), *x_s.last().unwrap_or(&from));
        simulations = Some(p.simulations);
    }
    protocol.check()?;
    let samples = protocol.len() as f64;
    let differences = pairs(models.len())
        .into_iter()
        .zip(&totals)
        .map(|((first, second), total)| Difference {
            first,
            second,
            noise_floors: (total.iter().sum::<f64>() / samples).sqrt(),
            by_channel: total.iter().map(|t| (t / samples).sqrt()).collect(),
        })
        .collect();
    Ok(Proposal {
        protocol,
        explanations: rivals.explanations,
        channels,
        noise: rivals.noise,
        differences,
        segments,
        predicted,
        tied: rivals.tied,
        explained: rivals.explained,
    })
}
