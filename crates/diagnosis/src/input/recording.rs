//! Bench recordings (docs/model.md, "CSV formats"): a CSV file with a header row and the
//! columns `time_s, v_da_V, x_s_m, force_N`, optionally `p1_Pa, p2_Pa`, in SI units.
//! Every problem is reported with its row (1-based, the header is row 1) and column.

use crate::policy::MAX_FAST_STEP;
use jetpipe_model::physics::parameters::Parameters;

/// A checked recording.
#[derive(Clone, Debug, PartialEq)]
pub struct Recording {
    pub time: Vec<f64>,
    pub v_da: Vec<f64>,
    pub x_s: Vec<f64>,
    pub force: Vec<f64>,
    pub p1: Option<Vec<f64>>,
    pub p2: Option<Vec<f64>>,
    /// For a recording that keeps only some rows of a longer one ([`Recording::rows_for_fits`]):
    /// the inputs at every sample of the longer one, which the replays integrate, and which of
    /// its samples the rows are. `None` for a recording as read.
    pub full_rate: Option<std::sync::Arc<FullRateInputs>>,
    /// How the fixed-step replays the fits use step ([`crate::replay::replay_fast`]): ROS2 with
    /// steps of at most [`crate::policy::MAX_FAST_STEP`], or the cheapest shorter or
    /// third-order stepping that agrees with the error-controlled replay where that one
    /// departs from it ([`crate::replay::agreement::fast_step_that_agrees`]).
    pub fast_replay: crate::input::recording::FastReplayMethod,
    /// The half-width T (s) of the stopper acceleration the replays give the model as its input
    /// a_s ([`crate::input::acceleration`]); 0 where the model forms it from the positions.
    pub acceleration_window: f64,
    /// Rows of the file that repeated the row before them exactly, time included, and were
    /// dropped: (1-based file row, time in s). Reported as glitches.
    pub repeated_rows: Vec<(usize, f64)>,
}

/// The inputs of a recording at every sample, and the samples a thinned view keeps.
#[derive(Clone, Debug, PartialEq)]
pub struct FullRateInputs {
    pub time: Vec<f64>,
    pub v_da: Vec<f64>,
    pub x_s: Vec<f64>,
    /// The sample of each kept row, increasing.
    pub rows: Vec<usize>,
    /// The stopper accelerations the replays give the model, at every sample, with the
    /// half-width they were formed over (s): formed once, where each replay formed its own
    /// (a 600 s recording's took 4.8 MB a replay).
    pub accelerations: Option<(f64, Vec<f64>)>,
}

/// The most rows the fits keep: a longer recording is fitted on whole stretches of it
/// ([`Recording::rows_for_fits`]). 100,000 rows keep an 80 s recording at 1 kHz whole.
pub const MAX_FIT_ROWS: usize = 100_000;
/// The stretches a long recording's fits keep: one training and one held-out block.
pub const FIT_STRETCH_SECONDS: f64 = 2.0 * crate::policy::BLOCK_SECONDS;

const REQUIRED: [&str; 4] = ["time_s", "v_da_V", "x_s_m", "force_N"];
const OPTIONAL: [&str; 2] = ["p1_Pa", "p2_Pa"];

/// How much more a stretch's mean-square departure, over the median stretch's, must be
/// than that of the kept stretch it replaces ([`Recording::rows_for_fits_where_departing`]):
/// four, twice the RMS.
pub const DEPARTING_STRETCH_RATIO: f64 = 4.0;

/// Each stretch's mean-square departure over the median stretch's, the largest over the
/// channels; 1 everywhere without departures.
fn departing_scores(stretch_of: &[usize], stretches: usize, departures: &[&[f64]]) -> Vec<f64> {
    let mut score = vec![1.0_f64; stretches];
    for departure in departures.iter().filter(|d| d.len() == stretch_of.len()) {
        let mut sum = vec![0.0; stretches];
        let mut count = vec![0usize; stretches];
        for (&j, &d) in stretch_of.iter().zip(departure.iter()) {
            if d.is_finite() {
                sum[j] += d * d;
                count[j] += 1;
            }
        }
        let mean: Vec<f64> = sum
            .iter()
            .zip(&count)
            .map(|(s, &c)| if c > 0 { s / c as f64 } else { 0.0 })
            .collect();
        let mut sorted = mean.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        if median > 0.0 {
            for (s, m) in score.iter_mut().zip(&mean) {
                *s = s.max(m / median);
            }
        }
    }
    score
}

/// The stopper positions the model is driven with ([`Recording::stopper_positions`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StopperPositions {
    /// Smoothed ([`Recording::with_stopper_smoothed`]) where the seven positions around leave
    /// at most `residual_limit` (m²) about their quadratic.
    Smoothed { residual_limit: f64 },
    /// As recorded: sampled too slowly for the smoothing.
    AsRecorded,
    /// As recorded: the force answers their rounding, with this correlation
    /// ([`force_answers_stopper_rounding`]).
    AnsweringTheirRounding { correlation: f64 },
}

impl StopperPositions {
    pub fn residual_limit(&self) -> Option<f64> {
        match self {
            StopperPositions::Smoothed { residual_limit } => Some(*residual_limit),
            _ => None,
        }
    }
}

/// The weights of the stopper smoothing at samples k − 3 ..= k + 3
/// ([`Recording::with_stopper_smoothed`]): the least-squares quadratic through seven
/// samples, read at its centre. They sum to one.
pub const STOPPER_SMOOTHING_WEIGHTS: [f64; 7] = [
    -2.0 / 21.0,
    3.0 / 21.0,
    6.0 / 21.0,
    7.0 / 21.0,
    6.0 / 21.0,
    3.0 / 21.0,
    -2.0 / 21.0,
];

/// The longest sampling interval (s) at which the stopper positions are smoothed
/// ([`Recording::with_stopper_smoothed`]): 1 kHz and faster.
pub const STOPPER_SMOOTHING_LONGEST_INTERVAL: f64 = 1.5e-3;

/// Whether the stopper positions of a recording sampled at `time` are smoothed: its
/// sampling interval (from its median) is at most [`STOPPER_SMOOTHING_LONGEST_INTERVAL`].
pub fn stopper_smoothing_applies(time: &[f64]) -> bool {
    time.len() > 1 && 1.0 / crate::input::recording::sample_rate(time) <= STOPPER_SMOOTHING_LONGEST_INTERVAL
}

/// The largest sum of squares (m²) the least-squares quadratic through seven stopper
/// positions may leave for the centre one to be smoothed ([`smoothed_stopper_positions`]):
/// three times what rounding leaves on average (four degrees of freedom of σ² each, σ² =
/// q²/12 for a quantisation step q), so q²; or, where the positions are not quantised,
/// twelve times the square of their noise floor. The smoothing undoes the rounding's jitter
/// in the velocity of a slow motion; a window holding a turn sharper than a quadratic (a
/// triangle's reversal between two samples) leaves far more, and there the recorded
/// positions are kept: at 2 kHz, with 7 µm a sample, the filter rounded such reversals and
/// left 4.9 force noise floors where the recorded positions left 2.9.
pub fn stopper_smoothing_residual_limit(x: &[f64]) -> f64 {
    match crate::input::noise::quantisation_step(x) {
        Some(step) => step * step,
        None => 12.0 * crate::input::noise::noise_floor(x).powi(2),
    }
}

/// Whether the force answers the rounding of the stopper positions `x`: the correlation,
/// where it is significant, between the change of slope the smoothing takes out of each
/// interval (its rounding, in a stopper moving smoothly) and the force's departure from the
/// least-squares quadratic through the seven samples around (its content at the sampling
/// rate). A bench whose stopper moves smoothly and whose log rounds it shows none: the
/// rounding is the log's, the force's noise the sensor's, and the two are independent, so
/// the correlation is within a few 1/√n of zero over n intervals that the smoothing
/// changes. A stopper that moves as it is logged, in steps of the rounding (a stepper, a
/// position command played out by the bench), drags a friction in its linear range from one
/// interval's slope to the next, and the force follows: −0.81 over 47,000 intervals on one
/// such recording at 2 kHz, where the smoothed positions left the friction's answer to the
/// steps, 0.2 N at the sampling rate, for noise. Significant means more than
/// [`crate::policy::STOPPER_ROUNDING_STANDARD_ERRORS`] times 1/√n.
pub fn force_answers_stopper_rounding(x: &[f64], force: &[f64], residual_limit: f64) -> Option<f64> {
    let n = x.len().min(force.len());
    if n < 16 {
        return None;
    }
    let smoothed = smoothed_stopper_positions(&x[..n], residual_limit);
    // The interval from k to k + 1 sets the velocity the model reads at sample k.
    let rounding_of_slope = |k: usize| (x[k + 1] - smoothed[k + 1]) - (x[k] - smoothed[k]);
    let quadratic_departure = |k: usize| {
        force[k]
            - STOPPER_SMOOTHING_WEIGHTS
                .iter()
                .zip(&force[k - 3..=k + 3])
                .map(|(w, f)| w * f)
                .sum::<f64>()
    };
    let samples = 3..n - 3;
    let rounding: Vec<f64> = samples.clone().map(rounding_of_slope).collect();
    let changed = rounding.iter().filter(|r| **r != 0.0).count();
    if changed < 100 {
        return None;
    }
    let departure: Vec<f64> = samples.map(quadratic_departure).collect();
    let r = crate::statistics::correlation(&rounding, &departure);
    (r.abs() > crate::policy::STOPPER_ROUNDING_STANDARD_ERRORS / (changed as f64).sqrt()).then_some(r)
}

/// The sum of squares the least-squares quadratic through the seven `deviations` (of the
/// positions at k − 3 ..= k + 3 from the one at k) leaves: the orthogonal polynomials 1, i
/// and i² − 4 on i = −3 ..= 3 have squared norms 7, 28 and 84.
fn quadratic_residual(deviations: &[f64]) -> f64 {
    let (mut sum, mut first, mut second, mut squares) = (0.0, 0.0, 0.0, 0.0);
    for (j, d) in deviations.iter().enumerate() {
        let i = j as f64 - 3.0;
        sum += d;
        first += i * d;
        second += (i * i - 4.0) * d;
        squares += d * d;
    }
    (squares - sum * sum / 7.0 - first * first / 28.0 - second * second / 84.0).max(0.0)
}

/// [`Recording::with_stopper_smoothed`]'s positions: the filter's value where the seven
/// samples around leave at most `residual_limit` about their quadratic, the recorded
/// position elsewhere.
pub fn smoothed_stopper_positions(x: &[f64], residual_limit: f64) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            if k < 3 || k + 3 >= n {
                return x[k];
            }
            // Deviations from x_k: a still stopper keeps its position to the bit.
            let deviations: Vec<f64> = x[k - 3..=k + 3].iter().map(|&xi| xi - x[k]).collect();
            if quadratic_residual(&deviations) > residual_limit {
                return x[k];
            }
            let deviation: f64 = STOPPER_SMOOTHING_WEIGHTS
                .iter()
                .zip(&deviations)
                .map(|(w, d)| w * d)
                .sum();
            x[k] + deviation
        })
        .collect()
}

impl Recording {
    pub fn len(&self) -> usize {
        self.time.len()
    }

    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// The recording with the stopper positions the model is driven with: at each sample k
    /// with three samples either side, the recorded positions at k − 3 ..= k + 3 weighted by
    /// [`STOPPER_SMOOTHING_WEIGHTS`] (a quadratic Savitzky–Golay filter); the recorded
    /// position itself at the first and last three samples. Where the force answers the
    /// positions' rounding, they are kept as recorded ([`Self::stopper_positions`]).
    ///
    /// The model moves the stopper linearly between samples and forms the velocity a
    /// velocity-dependent force (friction) reads from the slopes of the intervals. Positions
    /// are rounded (1 µm on the bench), so on the recorded positions an interval's slope comes
    /// in steps of 1 mm/s and is zero wherever the position stays within a step, around every
    /// reversal, where the moving stopper's friction is near its stiction. The filter averages
    /// the rounding (a slope's rounding noise falls to 0.30 of a raw difference's) and is
    /// exactly zero while the stopper is still. It keeps any quadratic motion to the
    /// rounding: a plain mean of the seven shrinks a sine by 2 (ω Δt)², which under a 2.5 Hz,
    /// 10 mm shake sampled at 250 Hz is 80 µm of stopper travel and 0.23 N of force, where
    /// the filter's departure is below a micrometre. The window is centred, so the positions
    /// do not lead or lag; an interval's slope is the velocity half an interval before its
    /// end, which the model carries to the sample with the acceleration
    /// (`jetpipe_model::physics::extra_force::velocity_at_sample`).
    ///
    /// Only at sampling intervals up to [`STOPPER_SMOOTHING_LONGEST_INTERVAL`], where a raw
    /// slope's rounding is 0.7 mm/s or more on a 1 µm log. Slower, the window spans 12 ms or
    /// more and rounds the corners of a stepped or triangular motion by tenths of a
    /// millimetre of stopper travel, which the chambers' volumes show: on recordings of an
    /// independent simulator at 250 Hz, the model that wrote them replayed with the smoothed
    /// positions left 1.2 to 1.7 noise floors of force and pressure, with the recorded ones
    /// 1.0; there the recorded slopes' rounding is 0.25 mm/s.
    ///
    /// The diagnosis replays these positions, so the FMU reproduces its errors when it is
    /// driven with them (`fmu_tests/test_diagnose_fmu.py` does the same filtering, as the
    /// report's `stopper_positions_smoothed` says).
    pub fn with_stopper_smoothed(&self) -> Recording {
        self.clone().into_stopper_smoothed()
    }

    /// [`Self::with_stopper_smoothed`], in place.
    pub fn into_stopper_smoothed(self) -> Recording {
        let positions = self.stopper_positions();
        self.into_driven_by(positions)
    }

    /// The recording with the stopper positions `positions` says ([`Self::stopper_positions`],
    /// already worked out).
    pub fn into_driven_by(mut self, positions: StopperPositions) -> Recording {
        if let Some(limit) = positions.residual_limit() {
            self.x_s = smoothed_stopper_positions(&self.x_s, limit);
        }
        self
    }

    /// Where [`Self::with_stopper_smoothed`] smooths the stopper positions, its residual
    /// limit ([`stopper_smoothing_residual_limit`]), m² ([`Self::stopper_positions`]).
    pub fn stopper_smoothing(&self) -> Option<f64> {
        self.stopper_positions().residual_limit()
    }

    /// Which stopper positions the model is driven with: smoothed at
    /// [`stopper_smoothing_applies`]'s rates, unless the force answers the positions'
    /// rounding ([`force_answers_stopper_rounding`]); as recorded otherwise.
    pub fn stopper_positions(&self) -> StopperPositions {
        if !stopper_smoothing_applies(&self.time) {
            return StopperPositions::AsRecorded;
        }
        let residual_limit = stopper_smoothing_residual_limit(&self.x_s);
        match force_answers_stopper_rounding(&self.x_s, &self.force, residual_limit) {
            Some(correlation) => StopperPositions::AnsweringTheirRounding { correlation },
            None => StopperPositions::Smoothed { residual_limit },
        }
    }

    /// The rows the fits work on: the whole recording when it has at most `max_rows` samples;
    /// otherwise the share `max_rows / n` of its stretches of [`FIT_STRETCH_SECONDS`] (each a
    /// training block and the held-out block after it), spread evenly from the first: stretch
    /// j is kept when ⌊(j + 1) f + 1 − f⌋ > ⌊j f + 1 − f⌋, f the share, so at most about
    /// `max_rows` rows. At
    /// f = 1/2 every second stretch; just over the limit nearly all of them (keeping one in two
    /// left out a stopper's moves that told a force sensor's delay from the command's).
    /// The stretches are spread over the whole recording, so slow changes stay visible, and
    /// each is contiguous at the full rate, so lags, delays, rates and spectral lines are seen
    /// as they are. The thinned recording carries the full-rate inputs: its replays integrate
    /// every sample and keep the outputs at its rows.
    pub fn rows_for_fits(&self, max_rows: usize) -> Recording {
        self.rows_for_fits_where_departing(max_rows, &[])
    }

    /// [`Self::rows_for_fits`], with the stretches where the starting model departs most
    /// kept in place of the evenly spread ones where it departs least. `departures` holds one
    /// series per measured channel, the starting model's error at every sample. A departure
    /// confined to a few seconds (a command saturating only in one segment) would otherwise
    /// be left out of every fit: a stretch left out whose mean square, over the median
    /// stretch's of its channel, exceeds [`DEPARTING_STRETCH_RATIO`] and that of the kept
    /// stretch departing least by as much, takes that stretch's place. The count of stretches
    /// stays, and so the rows but for a shorter last stretch moving in or out; where the
    /// departure is spread evenly nothing moves.
    pub fn rows_for_fits_where_departing(&self, max_rows: usize, departures: &[&[f64]]) -> Recording {
        let n = self.len();
        if n <= max_rows || n < 2 {
            return self.clone();
        }
        // In whole numbers, f = max_rows / n: no rounding decides a stretch.
        let at = |j: usize| (j * max_rows + n - max_rows) / n;
        let t0 = self.time[0];
        let stretch_of: Vec<usize> = self
            .time
            .iter()
            .map(|t| ((t - t0) / FIT_STRETCH_SECONDS).floor() as usize)
            .collect();
        let stretches = stretch_of[n - 1] + 1;
        let mut kept: Vec<bool> = (0..stretches).map(|j| at(j + 1) > at(j)).collect();
        let score = departing_scores(&stretch_of, stretches, departures);
        loop {
            let outside = (0..stretches)
                .filter(|&j| !kept[j])
                .max_by(|&a, &b| score[a].total_cmp(&score[b]));
            let inside = (0..stretches)
                .filter(|&j| kept[j])
                .min_by(|&a, &b| score[a].total_cmp(&score[b]));
            match (outside, inside) {
                (Some(o), Some(i))
                    if score[o] > DEPARTING_STRETCH_RATIO && score[o] > DEPARTING_STRETCH_RATIO * score[i].max(1.0) =>
                {
                    kept[o] = true;
                    kept[i] = false;
                }
                _ => break,
            }
        }
        let rows: Vec<usize> = (0..n).filter(|&k| kept[stretch_of[k]]).collect();
        let pick = |x: &[f64]| -> Vec<f64> { rows.iter().map(|&k| x[k]).collect() };
        Recording {
            time: pick(&self.time),
            v_da: pick(&self.v_da),
            x_s: pick(&self.x_s),
            force: pick(&self.force),
            p1: self.p1.as_deref().map(pick),
            p2: self.p2.as_deref().map(pick),
            full_rate: Some(std::sync::Arc::new(FullRateInputs {
                time: self.time.clone(),
                v_da: self.v_da.clone(),
                x_s: self.x_s.clone(),
                rows,
                accelerations: (self.acceleration_window > 0.0).then(|| {
                    (
                        self.acceleration_window,
                        crate::input::acceleration::smoothed_accelerations(
                            &self.time,
                            &self.x_s,
                            self.acceleration_window,
                        ),
                    )
                }),
            })),
            fast_replay: self.fast_replay,
            acceleration_window: self.acceleration_window,
            repeated_rows: self.repeated_rows.clone(),
        }
    }

    /// Samples per second: of the full-rate recording behind a thinned one.
    pub fn sample_rate(&self) -> f64 {
        let time = self.full_rate.as_ref().map_or(&self.time, |f| &f.time);
        let n = time.len();
        (n - 1) as f64 / (time[n - 1] - time[0]).max(1e-12)
    }

    /// Read and check a recording file.
    pub fn read(path: &std::path::Path, params: &Parameters) -> Result<Self, String> {
        let text = std::fs::read(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
        let text = String::from_utf8(text).map_err(|e| {
            format!(
                "{}: not a text file (invalid UTF-8 at byte {})",
                path.display(),
                e.utf8_error().valid_up_to()
            )
        })?;
        Self::parse(&text, params).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Parse and check CSV text.
    pub fn parse(text: &str, params: &Parameters) -> Result<Self, String> {
        let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines
            .next()
            .ok_or("the file is empty: expected a header row and samples")?;
        let names: Vec<&str> = header
            .trim_start_matches('\u{feff}')
            .split(',')
            .map(str::trim)
            .collect();
        let mut columns = [usize::MAX; 6];
        for (position, name) in names.iter().enumerate() {
            let slot = REQUIRED
                .iter()
                .chain(OPTIONAL.iter())
                .position(|c| c == name)
                .ok_or_else(|| {
                    format!(
                        "row 1: unknown column '{name}' (column {}); the columns are {} and optionally {}",
                        position + 1,
                        REQUIRED.join(", "),
                        OPTIONAL.join(", ")
                    )
                })?;
            if columns[slot] != usize::MAX {
                return Err(format!("row 1: column '{name}' appears twice"));
            }
            columns[slot] = position;
        }
        for (slot, name) in REQUIRED.iter().enumerate() {
            if columns[slot] == usize::MAX {
                return Err(format!("row 1: missing column '{name}' (found: {})", names.join(", ")));
            }
        }
        if (columns[4] == usize::MAX) != (columns[5] == usize::MAX) {
            return Err("row 1: give both p1_Pa and p2_Pa, or neither".to_string());
        }
        let has_pressures = columns[4] != usize::MAX;
        // Reserved for every line, so a long recording's columns are not left at up to twice
        // their length by the doubling of a growing vector (50 MB of capacity for 29 MB of
        // samples at 600 s and 1 kHz, under heaptrack).
        let rows = text.bytes().filter(|&b| b == b'\n').count() + 1;
        let mut data: [Vec<f64>; 6] = Default::default();
        for (slot, &position) in columns.iter().enumerate() {
            if position != usize::MAX {
                data[slot] = Vec::with_capacity(rows);
            }
        }
        for (index, line) in lines {
            let row = index + 1;
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            if cells.len() != names.len() {
                return Err(format!(
                    "row {row}: {} cells, the header has {}",
                    cells.len(),
                    names.len()
                ));
            }
            for (slot, &position) in columns.iter().enumerate() {
                if position == usize::MAX {
                    continue;
                }
                let name = if slot < 4 { REQUIRED[slot] } else { OPTIONAL[slot - 4] };
                let cell = cells[position];
                let value: f64 = cell
                    .parse()
                    .map_err(|_| format!("row {row}, column {name}: '{cell}' is not a number"))?;
                if !value.is_finite() {
                    return Err(format!("row {row}, column {name}: {cell} is not a finite number"));
                }
                data[slot].push(value);
            }
        }
        let [time, v_da, x_s, force, p1, p2] = data;
        if time.is_empty() {
            return Err("no samples after the header row".to_string());
        }
        let (time, v_da, x_s, force, p1, p2, repeated_rows) = without_repeated_rows([time, v_da, x_s, force, p1, p2])?;
        if time.len() < 2 {
            return Err(format!(
                "only one sample{}: a recording needs at least two",
                if repeated_rows.is_empty() {
                    String::new()
                } else {
                    format!(
                        " once {} rows repeating the row before exactly are dropped",
                        repeated_rows.len()
                    )
                }
            ));
        }
        let (lo, hi) = params.cylinder().stopper_range();
        // A stopper column in millimetres is the commonest unit slip: say so.
        let typical = {
            let mut sorted = x_s.clone();
            sorted.sort_by(|a, b| a.total_cmp(b));
            sorted[sorted.len() / 2]
        };
        if typical > 1000.0 * lo && typical < 1000.0 * hi {
            return Err(format!(
                "column x_s_m: values like {typical} look like millimetres; the recording must be in metres (e.g. {} m)",
                typical / 1000.0
            ));
        }
        for (k, &x) in x_s.iter().enumerate() {
            if x <= lo || x >= hi {
                return Err(format!(
                    "row {}, column x_s_m: stopper position {x} m is outside the cylinder ({lo} < x_s < {hi} m)",
                    k + 2
                ));
            }
        }
        if has_pressures {
            for (name, values) in [("p1_Pa", &p1), ("p2_Pa", &p2)] {
                if let Some(k) = values.iter().position(|&p| p <= 0.0) {
                    return Err(format!(
                        "row {}, column {name}: absolute pressure {} Pa is not positive (gauge pressure? the column must be absolute)",
                        k + 2,
                        values[k]
                    ));
                }
            }
        }
        Ok(Recording {
            time,
            v_da,
            x_s,
            force,
            p1: has_pressures.then_some(p1),
            p2: has_pressures.then_some(p2),
            full_rate: None,
            fast_replay: crate::input::recording::FastReplayMethod::default(),
            acceleration_window: 0.0,
            repeated_rows,
        })
    }
}

/// The columns without the rows that repeat the row before them exactly, time included (a
/// logger that wrote a row twice), and those rows (1-based file row, time). A time that does
/// not increase otherwise is refused: which of two different rows at one time is right
/// cannot be told.
#[allow(clippy::type_complexity)]
fn without_repeated_rows(
    mut data: [Vec<f64>; 6],
) -> Result<
    (
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<f64>,
        Vec<(usize, f64)>,
    ),
    String,
> {
    let mut repeated = vec![];
    {
        let time = &data[0];
        for k in 1..time.len() {
            if time[k] > time[k - 1] {
                continue;
            }
            let same = data.iter().all(|c| c.is_empty() || c[k] == c[k - 1]);
            if time[k] == time[k - 1] && same {
                repeated.push(k);
                continue;
            }
            return Err(format!(
                "row {}, column time_s: time {} s does not increase (previous row: {} s){}",
                k + 2,
                time[k],
                time[k - 1],
                if time[k] == time[k - 1] {
                    " and the two rows differ: which one is right cannot be told"
                } else {
                    ""
                }
            ));
        }
    }
    let rows: Vec<(usize, f64)> = repeated.iter().map(|&k| (k + 2, data[0][k])).collect();
    if !repeated.is_empty() {
        for column in data.iter_mut().filter(|c| !c.is_empty()) {
            let mut k = 0;
            let mut next = repeated.iter().peekable();
            column.retain(|_| {
                let drop = next.peek() == Some(&&k);
                if drop {
                    next.next();
                }
                k += 1;
                !drop
            });
        }
    }
    let [time, v_da, x_s, force, p1, p2] = data;
    Ok((time, v_da, x_s, force, p1, p2, rows))
}

/// Samples per second of a series sampled at `time`: from its span, or, when it has gaps
/// (the stretches of a recording thinned for the fits), from its median interval.
pub fn sample_rate(time: &[f64]) -> f64 {
    let n = time.len();
    if n < 2 {
        return 1.0;
    }
    let span = (time[n - 1] - time[0]).max(1e-12);
    let mean = span / (n - 1) as f64;
    if time.windows(2).all(|w| w[1] - w[0] <= 2.0 * mean) {
        return (n - 1) as f64 / span;
    }
    let mut intervals: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = intervals.len() / 2;
    1.0 / intervals
        .select_nth_unstable_by(mid, |a, b| a.total_cmp(b))
        .1
        .max(1e-12)
}

/// How `replay_fast` steps the chamber pressures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FastReplayMethod {
    /// The longest step, s: each sample interval is stepped in equal parts of at most this.
    pub step: f64,
    /// ROS34PW2 (order 3, five right-hand sides a step) instead of ROS2 (order 2, three).
    pub third_order: bool,
}

#[cfg(test)]
impl Recording {
    /// A recording of these columns without pressure channels, replayed with the default fast
    /// method: the unit tests' recordings.
    pub(crate) fn of(time: Vec<f64>, v_da: Vec<f64>, x_s: Vec<f64>, force: Vec<f64>) -> Recording {
        Recording {
            time,
            v_da,
            x_s,
            force,
            p1: None,
            p2: None,
            full_rate: None,
            fast_replay: FastReplayMethod::default(),
            acceleration_window: 0.0,
            repeated_rows: vec![],
        }
    }
}

impl Default for FastReplayMethod {
    fn default() -> Self {
        Self {
            step: MAX_FAST_STEP,
            third_order: false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Recording, String> {
        Recording::parse(text, &Parameters::default())
    }

    const GOOD: &str =
        "time_s,v_da_V,x_s_m,force_N,p1_Pa,p2_Pa\n0.000,1.0,0.054,10.0,3e5,2e5\n0.001,1.1,0.054,10.1,3e5,2e5\n";

    fn stopper_recording(time: Vec<f64>, x_s: Vec<f64>) -> Recording {
        let n = time.len();
        Recording {
            time,
            v_da: vec![1.0; n],
            x_s,
            force: vec![10.0; n],
            p1: None,
            p2: None,
            full_rate: None,
            fast_replay: crate::input::recording::FastReplayMethod::default(),
            acceleration_window: 0.0,
            repeated_rows: vec![],
        }
    }

    /// Positions logged to 1 µm.
    fn logged(x: f64) -> f64 {
        (x * 1e6).round() * 1e-6
    }

    #[test]
    fn a_force_that_answers_the_rounding_of_the_stopper_positions_has_them_driven_as_recorded() {
        // A triangle at 4.7 mm/s (2.35 µm a sample at 2 kHz), logged to 1 µm, under a friction
        // of 2 N that is linear up to 10 mm/s, with 0.02 N of sensor noise.
        let (rate, n) = (2000.0, 40_000);
        let time: Vec<f64> = (0..n).map(|k| k as f64 / rate).collect();
        let truth = |t: f64| 0.06 + 4.7e-3 * (2.5 - ((t % 5.0) - 2.5).abs());
        let x_s: Vec<f64> = time.iter().map(|&t| logged(truth(t))).collect();
        let noise = crate::input::noise::tests::normals(8, n);
        let friction = |v: f64| 2.0 * (v / 0.01).tanh();
        let force_from = |velocity: &dyn Fn(usize) -> f64| -> Vec<f64> {
            (0..n).map(|k| 40.0 + friction(velocity(k)) + 0.02 * noise[k]).collect()
        };
        let slope = |x: &dyn Fn(usize) -> f64, k: usize| (x((k + 1).min(n - 1)) - x(k)) * rate;
        // A stopper that moved in the logged steps: the friction reads their slopes.
        let mut stepped = stopper_recording(time.clone(), x_s.clone());
        stepped.force = force_from(&|k| slope(&|j| x_s[j], k));
        match stepped.stopper_positions() {
            StopperPositions::AnsweringTheirRounding { correlation } => {
                assert!(correlation.abs() > 0.5, "{correlation}")
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(stepped.with_stopper_smoothed().x_s, x_s);
        // One that moved smoothly, logged the same: the friction reads the true slope.
        let mut smooth = stopper_recording(time.clone(), x_s.clone());
        smooth.force = force_from(&|k| slope(&|j| truth(time[j]), k));
        assert_eq!(
            smooth.stopper_positions(),
            StopperPositions::Smoothed {
                residual_limit: stopper_smoothing_residual_limit(&x_s)
            }
        );
        // Sensor noise alone beside the logged steps.
        for seed in 20..30 {
            let mut still_force = stopper_recording(time.clone(), x_s.clone());
            let noise = crate::input::noise::tests::normals(seed, n);
            still_force.force = noise.iter().map(|e| 40.0 + 0.02 * e).collect();
            assert_eq!(
                force_answers_stopper_rounding(&x_s, &still_force.force, 1e-12),
                None,
                "seed {seed}"
            );
        }
    }

    #[test]
    fn the_stopper_is_smoothed_at_one_kilohertz_and_faster_and_driven_as_recorded_below() {
        // A ramp at 0.7 mm/s, logged to 1 µm.
        let recording_at = |rate: f64| -> Recording {
            let time: Vec<f64> = (0..2000).map(|k| k as f64 / rate).collect();
            let x_s = time.iter().map(|&t| logged(0.05 + 0.7e-3 * t)).collect();
            stopper_recording(time, x_s)
        };
        for rate in [250.0, 500.0] {
            let recording = recording_at(rate);
            assert!(!stopper_smoothing_applies(&recording.time), "{rate} Hz");
            assert_eq!(recording.with_stopper_smoothed().x_s, recording.x_s, "{rate} Hz");
        }
        for rate in [1000.0, 4000.0] {
            let recording = recording_at(rate);
            assert!(stopper_smoothing_applies(&recording.time), "{rate} Hz");
            let limit = stopper_smoothing_residual_limit(&recording.x_s);
            assert!((limit - 1e-12).abs() < 1e-15, "{limit} m² for a 1 µm step");
            assert_eq!(
                recording.with_stopper_smoothed().x_s,
                smoothed_stopper_positions(&recording.x_s, limit),
                "{rate} Hz"
            );
            assert_ne!(recording.with_stopper_smoothed().x_s, recording.x_s, "{rate} Hz");
        }
    }

    #[test]
    fn a_triangle_reversing_between_two_samples_keeps_its_recorded_corner_and_has_the_rounding_of_its_sides_averaged() {
        // 14.6 mm/s at 2 kHz (7.3 µm a sample), turning at 50.1 ms, logged to 1 µm.
        let rate = 2000.0;
        let line = |t: f64| 0.05 + 14.6e-3 * (0.0501 - (t - 0.0501).abs());
        let time: Vec<f64> = (0..200).map(|k| k as f64 / rate).collect();
        let x_s: Vec<f64> = time.iter().map(|&t| logged(line(t))).collect();
        let recording = stopper_recording(time.clone(), x_s.clone());
        let smoothed = recording.with_stopper_smoothed().x_s;
        // The seven windows holding the turn keep the recorded positions.
        for k in 98..=103 {
            assert_eq!(smoothed[k], x_s[k], "sample {k} beside the turn");
        }
        // Along the sides, the filter brings the positions nearer the true motion.
        let rms = |x: &[f64]| {
            let sides: Vec<usize> = (3..197).filter(|k| !(94..=106).contains(k)).collect();
            (sides.iter().map(|&k| (x[k] - line(time[k])).powi(2)).sum::<f64>() / sides.len() as f64).sqrt()
        };
        assert!(
            rms(&smoothed) < 0.6 * rms(&x_s),
            "{} against {} m",
            rms(&smoothed),
            rms(&x_s)
        );
        // Unfiltered, the turn would be rounded by more than the rounding: 2.4 µm at it.
        let rounded = smoothed_stopper_positions(&x_s, f64::INFINITY);
        assert!((rounded[100] - x_s[100]).abs() > 2e-6, "{} m", rounded[100] - x_s[100]);
    }

    #[test]
    fn the_stopper_smoothing_keeps_a_still_stopper_to_the_bit_and_a_quadratic_motion_exactly() {
        let still = vec![0.0537; 20];
        assert_eq!(smoothed_stopper_positions(&still, 1e-12), still);
        let quadratic: Vec<f64> = (0..40)
            .map(|k| 0.05 + 1e-4 * k as f64 - 2e-6 * (k * k) as f64)
            .collect();
        for (s, x) in smoothed_stopper_positions(&quadratic, 1e-12).iter().zip(&quadratic) {
            assert!((s - x).abs() < 1e-15, "{s} against {x}");
        }
        assert!((STOPPER_SMOOTHING_WEIGHTS.iter().sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn a_fast_shake_sampled_slowly_keeps_its_amplitude_through_the_stopper_filter() {
        // 2.5 Hz, 10 mm, at 250 Hz: a plain mean of seven samples shrinks it by 79 µm.
        let sine = |k: usize| 0.054 + 0.01 * (2.0 * std::f64::consts::PI * 2.5 * k as f64 / 250.0).sin();
        let x: Vec<f64> = (0..1000).map(sine).collect();
        let smoothed = smoothed_stopper_positions(&x, f64::INFINITY);
        let worst = (0..1000).map(|k| (smoothed[k] - sine(k)).abs()).fold(0.0, f64::max);
        assert!(worst < 0.1e-6, "{worst} m from the sine");
    }

    #[test]
    fn the_stopper_smoothing_averages_the_rounding_of_a_slow_ramp() {
        // 0.3 mm/s at 1 kHz rounded to 1 µm: the raw slopes are 0 or 1 mm/s.
        let x: Vec<f64> = (0..2000).map(|k| logged(0.054 + 0.3e-3 * k as f64 * 1e-3)).collect();
        let smoothed = smoothed_stopper_positions(&x, stopper_smoothing_residual_limit(&x));
        for k in 3..1996 {
            let slope = (smoothed[k + 1] - smoothed[k]) / 1e-3;
            assert!((slope - 0.3e-3).abs() < 0.2e-3, "slope {slope} m/s at sample {k}");
        }
    }

    #[test]
    fn reads_a_good_file_with_any_column_order() {
        let r = parse(GOOD).unwrap();
        assert_eq!(r.len(), 2);
        assert_eq!(r.p1.as_ref().unwrap()[1], 3e5);
        let r = parse("force_N,time_s,x_s_m,v_da_V\n1,0,0.05,2\n2,0.1,0.05,2\n").unwrap();
        assert_eq!((r.force[1], r.time[1], r.v_da[0]), (2.0, 0.1, 2.0));
        assert!(r.p1.is_none());
    }

    #[test]
    fn every_bad_file_gets_a_message_with_row_and_column() {
        let cases = [
            ("", "empty"),
            ("time_s,v_da_V,x_s_m,force_N\n", "no samples"),
            (
                "time_s,v_da_V,x_s_m,force\n0,1,0.054,1\n0.1,1,0.054,1\n",
                "unknown column 'force'",
            ),
            ("time_s,v_da_V,x_s_m\n0,1,0.054\n", "missing column 'force_N'"),
            (
                "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0.1,abc,0.054,1\n",
                "row 3, column v_da_V: 'abc'",
            ),
            (
                "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0.1,1,0.054,NaN\n",
                "row 3, column force_N",
            ),
            (
                "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0,1,0.054,2\n",
                "row 3, column time_s: time 0 s does not increase (previous row: 0 s) and the two rows differ",
            ),
            (
                "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0.1,1,0.054,1\n0.05,1,0.054,1\n",
                "row 4, column time_s",
            ),
            (
                "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0,1,0.054,1\n",
                "only one sample",
            ),
            (
                "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0.1,1,0.12,1\n",
                "row 3, column x_s_m",
            ),
            ("time_s,v_da_V,x_s_m,force_N\n0,1,54,1\n0.1,1,54,1\n", "millimetres"),
            (
                "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0.1,1,0.054\n",
                "row 3: 3 cells",
            ),
            ("time_s,v_da_V,x_s_m,force_N,p1_Pa\n0,1,0.054,1,1e5\n", "p2_Pa"),
        ];
        for (text, expected) in cases {
            let e = parse(text).unwrap_err();
            assert!(e.contains(expected), "{text:?}: {e}");
        }
    }

    #[test]
    fn a_row_written_twice_is_dropped_and_its_row_kept_for_the_report() {
        let text = "time_s,v_da_V,x_s_m,force_N\n0,1,0.054,1\n0.001,1,0.054,2\n0.001,1,0.054,2\n0.002,1,0.054,3\n";
        let r = Recording::parse(text, &Parameters::default()).unwrap();
        assert_eq!(r.time, vec![0.0, 0.001, 0.002]);
        assert_eq!(r.force, vec![1.0, 2.0, 3.0]);
        assert_eq!(r.repeated_rows, vec![(4, 0.001)]);
    }
}
