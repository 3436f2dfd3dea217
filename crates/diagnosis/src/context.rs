//! What every stage of a diagnosis reads: the recording, its blocks, the noise floors and the options.

use crate::input::blocks::Block;
use crate::input::noise::noise_floor;
use crate::input::noise::varying;
use crate::input::noise::VaryingNoise;
use crate::input::recording::Recording;
use crate::replay::replay_fast;
use crate::replay::signals::difference;
use crate::replay::signals::CHANNELS;
use crate::replay::signals::FORCE;
use crate::replay::Replay;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

/// Where a diagnosis shows how far its long phases are (the CLI draws progress bars).
pub trait ProgressBars: Send + Sync {
    /// A phase of `total` steps begins.
    fn start(&self, phase: &str, total: usize);
    /// One step of the phase is done (called from any worker thread).
    fn advance(&self);
    fn finish(&self);
}

/// Options of a diagnosis.
#[derive(Clone)]
pub struct Options {
    /// Re-identify the jet pipe offset, C_d and the leakage first (§3.3.1).
    pub calibrate: bool,
    /// Worker threads for the candidates.
    pub jobs: usize,
    pub bars: Option<std::sync::Arc<dyn ProgressBars>>,
    /// Try a flexible term where the readable ones leave a channel above its bar
    /// (`decide/flexible.rs`; `jetpipe diagnose --flexible`). Off by default until it has been
    /// measured on the practice batches and the kept cases.
    pub flexible: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            calibrate: false,
            jobs: std::thread::available_parallelism().map_or(2, |n| n.get()),
            bars: None,
            flexible: false,
        }
    }
}

/// What every stage of a diagnosis reads: the recording, its training blocks and the
/// channels' noise floors.
pub(crate) struct Context<'a> {
    /// The rows the fits work on: the whole recording, or stretches of a long one
    /// ([`Recording::rows_for_fits`]).
    pub(crate) recording: &'a Recording,
    /// Every sample: the noise floors and the errors reported are its.
    pub(crate) full: &'a Recording,
    pub(crate) options: &'a Options,
    /// What each of the fits' rows is for.
    pub(crate) blocks: Vec<Block>,
    /// From when (s) the model's starting state no longer shows.
    pub(crate) settled_from: f64,
    /// The spans (s) of the recording's glitches, whose samples are set aside.
    pub(crate) set_aside: Vec<(f64, f64)>,
    pub(crate) n: usize,
    pub(crate) noise: f64,
    pub(crate) pressure_noise: Option<[f64; 2]>,
    pub(crate) channel_noise: [f64; CHANNELS],
    /// The noise of the force against the pressures.
    pub(crate) mechanical_noise: f64,
    /// The piston's area, m², once known ([`Self::with_piston_area`]; 0 before).
    pub(crate) piston_area: f64,
    /// The stopper positions the replays drive the model with
    /// ([`crate::input::recording::Recording::stopper_positions`]).
    pub(crate) stopper_positions: crate::input::recording::StopperPositions,
    /// Which channels' noise is not steady ([`crate::input::noise::varying`]): their floors are
    /// the RMS of the local level, and stay so when taken again after an addition.
    pub(crate) noise_varies: [bool; CHANNELS],
}

impl<'a> Context<'a> {
    /// Estimate the channels' noise floors (step 1), and how long `model`'s starting state
    /// shows; a force channel rounded coarser than its noise gets a line in `input_checks`.
    pub(crate) fn measure(
        full: &'a Recording,
        recording: &'a Recording,
        model: &Actuator,
        options: &'a Options,
        set_aside: Vec<(f64, f64)>,
        input_checks: &mut Vec<String>,
        progress: &mut dyn FnMut(&str),
    ) -> Result<Self, String> {
        let n = recording.len();
        // The noise floors from every sample. A sharp line (a pick-up) is a departure to
        // find, not noise.
        let sample_rate = full.sample_rate();
        // A signal that curves within a few samples (a 20 Hz multisine or a shaken stopper
        // sampled at 250 Hz) lifts the floor of the recorded channel; the model follows most
        // of it, so the channel's departure from the model keeps the noise alone. A model far
        // off in fast motion lifts the departure's instead: each floor is the lower of the two.
        let modelled = replay_fast(model, full, full.len()).ok();
        // Noise whose level varies (growing with the signal, wandering in time) has for its
        // floor the RMS of its local level, where both the channel and its departure from
        // the model show the variation (a departure alone that varies is the model's error).
        let floor_of = |x: &[f64], channel: fn(&Replay) -> &Vec<f64>| -> (f64, Option<VaryingNoise>) {
            let recorded = crate::input::lines::without_lines(x, sample_rate, 3);
            let departure = match &modelled {
                Some(m) if channel(m).len() == x.len() => Some(crate::input::lines::without_lines(
                    &difference(x, channel(m)),
                    sample_rate,
                    3,
                )),
                _ => None,
            };
            let quantile = departure
                .as_ref()
                .map_or(noise_floor(&recorded), |d| noise_floor(&recorded).min(noise_floor(d)));
            let command = &full.v_da;
            let varies = match (
                varying(&recorded, x, command),
                departure.as_ref().map(|d| varying(d, x, command)),
            ) {
                (Some(r), None) => Some(r),
                (Some(r), Some(Some(d))) => Some(if d.rms < r.rms { d } else { r }),
                _ => None,
            };
            match varies {
                Some(v) if v.rms > quantile => (v.rms, Some(v)),
                _ => (quantile, None),
            }
        };
        let (noise, force_varies) = floor_of(&full.force, |m| &m.force);
        let mut varies = [force_varies, None, None];
        let pressure_noise = match (&full.p1, &full.p2) {
            (Some(a), Some(b)) => {
                let ((first, first_varies), (second, second_varies)) = (floor_of(a, |m| &m.p1), floor_of(b, |m| &m.p2));
                varies[1] = first_varies;
                varies[2] = second_varies;
                Some([first, second])
            }
            _ => None,
        };
        drop(modelled);
        for (name, unit, v) in [
            ("force", "N", varies[0]),
            ("P1", "Pa", varies[1]),
            ("P2", "Pa", varies[2]),
        ] {
            if let Some(v) = v {
                let message = format!(
                    "The {name} channel's noise is not steady: its local level runs from {:.4} to {:.4} {unit} (tenth to ninetieth percentile over 64-sample windows), {}; its noise floor is the RMS of that level, {:.4} {unit}, and explained means within 1.5 times it.",
                    v.lowest,
                    v.highest,
                    if v.follows_level { "growing with the channel's level" } else { "wandering in time" },
                    v.rms
                );
                progress(&message);
                input_checks.push(message);
            }
        }
        if n < full.len() {
            let message = format!(
                "The fits use {n} of the {} samples: stretches of {} s spread over the whole recording. The errors reported are of every sample, and so are the noise floors but for one taken again on the stretches after an addition.",
                full.len(),
                crate::input::recording::FIT_STRETCH_SECONDS
            );
            progress(&message);
            input_checks.push(message);
        }
        if let Some(q) = crate::input::noise::quantisation_step(&full.force) {
            if q > noise {
                input_checks.push(format!(
                    "The force channel is quantised in steps of {q:.4} N, coarser than its noise {noise:.4} N: errors below a step cannot be told from rounding."
                ));
            }
        }
        progress(&format!(
            "{n} samples, force noise floor {noise:.4} N{}",
            pressure_noise
                .map(|p| format!(", pressure noise floors {:.0} and {:.0} Pa", p[0], p[1]))
                .unwrap_or_default()
        ));
        let mut channel_noise = [noise, 0.0, 0.0];
        if let Some(p) = pressure_noise {
            channel_noise[1] = p[0];
            channel_noise[2] = p[1];
        }
        let settled_from = crate::replay::settling::settling_time(model, recording, channel_noise)?;
        let t0 = recording.time[0];
        if settled_from > t0 {
            progress(&format!(
                "the model's starting state shows until {:.2} s: the samples before are neither fitted nor scored",
                settled_from - t0
            ));
        }
        Ok(Self {
            recording,
            full,
            options,
            blocks: crate::input::blocks::blocks(&recording.time, &recording.x_s, settled_from, &set_aside),
            settled_from,
            set_aside,
            n,
            noise,
            pressure_noise,
            channel_noise,
            mechanical_noise: noise,
            piston_area: 0.0,
            stopper_positions: crate::input::recording::StopperPositions::AsRecorded,
            noise_varies: varies.map(|v| v.is_some()),
        })
    }

    /// The force against the pressures carries the pressures' noise through the piston area.
    pub(crate) fn with_piston_area(mut self, area: f64) -> Self {
        self.piston_area = area;
        self.set_mechanical_noise();
        self
    }

    pub(crate) fn set_mechanical_noise(&mut self) {
        let (noise, area) = (self.noise, self.piston_area);
        self.mechanical_noise = self
            .pressure_noise
            .map(|p| (noise * noise + area * area * (p[0] * p[0] + p[1] * p[1])).sqrt())
            .unwrap_or(noise);
    }

    /// After an addition, each channel's floor taken again from its departure from the model
    /// with `params`, where that is lower: a departure the model before could not follow (a
    /// friction's sharp turns at the reversals) lifted the first estimate as a fast signal
    /// lifts the recording's, and a floor too high reads an error left as noise. On a
    /// recording thinned for the fits, from the departure on its stretches: the floor is a
    /// median over windows of 64 samples, which the few windows across a gap do not move.
    pub(crate) fn lower_noise_to_departure(
        &mut self,
        params: &Parameters,
        replays: &mut usize,
        progress: &mut dyn FnMut(&str),
    ) -> Result<(), String> {
        let with = replay_fast(&Actuator::new(params.clone())?, self.recording, self.n)?;
        *replays += 1;
        let sample_rate = self.recording.sample_rate();
        let varies = self.noise_varies;
        let floor = |x: &[f64], m: &[f64], channel: usize| {
            let departure = crate::input::lines::without_lines(&difference(x, m), sample_rate, 3);
            let quantile = noise_floor(&departure);
            match varies[channel]
                .then(|| varying(&departure, x, &self.recording.v_da))
                .flatten()
            {
                Some(v) if v.rms > quantile => v.rms,
                _ => quantile,
            }
        };
        // Lower by a hundredth at least: the same floor again is no news.
        let force = floor(&self.recording.force, &with.force, FORCE);
        if force < 0.99 * self.noise {
            progress(&format!(
                "force noise floor {force:.4} N from the departure after the additions (was {:.4} N)",
                self.noise
            ));
            self.noise = force;
            self.channel_noise[FORCE] = force;
        }
        if let (Some(p), Some(p1), Some(p2)) = (self.pressure_noise.as_mut(), &self.recording.p1, &self.recording.p2) {
            for (c, (x, m)) in [(p1, &with.p1), (p2, &with.p2)].into_iter().enumerate() {
                let lower = floor(x, m, c + 1);
                if lower < 0.99 * p[c] {
                    p[c] = lower;
                    self.channel_noise[c + 1] = lower;
                }
            }
        }
        self.set_mechanical_noise();
        Ok(())
    }
}
