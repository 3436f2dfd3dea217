//! Diagnosis of a bench recording: where is the thesis model wrong, and which of the
//! named effects (MODEL.md) explains it?
//!
//! 1. Replay the recording's inputs through the model and take the force residual.
//! 2. Optionally re-identify what the thesis identified from static loops (§3.3.1: jet
//!    pipe offset, C_d, leakage) by Levenberg–Marquardt instead of downhill simplex.
//! 3. Fit every candidate effect on the training half of the recording (alternating 2 s
//!    blocks) and score it on the other half; add the best if it lowers the held-out
//!    error by more than noise and the extra freedom explain; repeat.
//! 4. Report the errors before and after, the residual's structure, and the FMU start
//!    values that turn the added effects on.

use serde_json::{json, Value};

use crate::physics::actuator::Actuator;
use crate::physics::effects::EFFECT_NAMES;
use crate::physics::parameters::Parameters;
use crate::recording::Recording;
use crate::replay::{replay, replay_fast, Replay};

/// Length of the alternating training / held-out blocks.
pub const BLOCK_SECONDS: f64 = 2.0;
/// An effect is added only if it lowers the held-out RMS error by this fraction…
pub const MIN_RELATIVE_GAIN: f64 = 0.1;
/// …and by at least this many noise floors. Smaller gains are what any flexible term
/// buys where the recording's physics differs in form from the model's (measured on the
/// synthetic recordings: a supply plenum let friction and dead volume shave 0.3–0.4
/// noise floors each off the error of the algebraic supply drop).
pub const MIN_GAIN_IN_NOISE: f64 = 1.0;
/// Nothing is added once the held-out error is within this factor of the noise floor.
pub const EXPLAINED_WITHIN_NOISE: f64 = 1.2;
const MAX_EFFECTS: usize = 3;
const GOLDEN_ITERATIONS: usize = 12;

/// Errors of a force trace against the recording.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    pub rms: f64,
    pub nrmse: f64,
    pub train_rms: f64,
    pub heldout_rms: f64,
}

/// One effect's fit.
#[derive(Clone, Debug, PartialEq)]
pub struct CandidateFit {
    pub name: &'static str,
    pub parameters: Vec<(&'static str, f64)>,
    pub train_rms: f64,
    pub heldout_rms: f64,
    /// Relative reduction of the held-out RMS error against the model without it.
    pub score: f64,
}

/// What `jetpipe diagnose` reports.
#[derive(Clone, Debug)]
pub struct Diagnosis {
    pub samples: usize,
    pub noise_floor: f64,
    pub before: Errors,
    pub after: Errors,
    pub calibrated: Vec<(&'static str, f64)>,
    pub effects: Vec<(CandidateFit, String)>,
    pub candidates: Vec<CandidateFit>,
    pub residual_tests: Value,
    pub parameters: Parameters,
    pub before_force: Vec<f64>,
    pub after_force: Vec<f64>,
}

/// The sensor noise of a recording's force, from second differences (robust: the median
/// absolute deviation, so steps and fast transients do not count). For white noise of
/// σ, Δ²F has standard deviation √6 σ.
pub fn noise_floor(force: &[f64]) -> f64 {
    if force.len() < 3 {
        return 0.0;
    }
    let mut d: Vec<f64> = force.windows(3).map(|w| (w[2] - 2.0 * w[1] + w[0]).abs()).collect();
    let mid = d.len() / 2;
    let median = *d.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
    median / 0.674_489_75 / 6f64.sqrt()
}

/// Training samples: those in even-numbered blocks.
pub fn training_mask(time: &[f64]) -> Vec<bool> {
    let t0 = time.first().copied().unwrap_or(0.0);
    time.iter()
        .map(|t| ((t - t0) / BLOCK_SECONDS).floor() as i64 % 2 == 0)
        .collect()
}

fn rms_where(a: &[f64], b: &[f64], mask: &[bool], want: bool) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for ((x, y), &m) in a.iter().zip(b).zip(mask) {
        if m == want {
            sum += (x - y) * (x - y);
            n += 1;
        }
    }
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

fn errors(model: &[f64], recording: &Recording, mask: &[bool]) -> Errors {
    let all = vec![true; mask.len()];
    let rms = rms_where(model, &recording.force, &all, true);
    let (lo, hi) = recording
        .force
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &f| (a.min(f), b.max(f)));
    Errors {
        rms,
        nrmse: if hi > lo { rms / (hi - lo) } else { 0.0 },
        train_rms: rms_where(model, &recording.force, mask, true),
        heldout_rms: rms_where(model, &recording.force, mask, false),
    }
}

/// Golden-section search for the minimum of `objective` on [0, 1].
fn golden_section(objective: impl Fn(f64) -> f64, iterations: usize) -> f64 {
    let phi = (5f64.sqrt() - 1.0) / 2.0;
    let (mut a, mut b) = (0.0, 1.0);
    let mut c = b - phi * (b - a);
    let mut d = a + phi * (b - a);
    let (mut fc, mut fd) = (objective(c), objective(d));
    for _ in 0..iterations {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - phi * (b - a);
            fc = objective(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + phi * (b - a);
            fd = objective(d);
        }
    }
    if fc < fd {
        c
    } else {
        d
    }
}

/// How each effect's parameters are fitted.
enum FitMethod {
    /// Hysteresis width and dead band: golden sections on the width, the dead band as a
    /// fraction of it, and the width again.
    Hysteresis,
    /// One parameter on [0, upper], searched by golden section on √(value/upper) so
    /// that small values get as much resolution as large ones.
    Golden { parameter: &'static str, upper: f64 },
    /// Offset and gain of the force sensor: linear least squares on the model's force.
    SensorRegression,
    /// Coulomb friction: linear least squares on the sign of the stopper velocity.
    FrictionRegression,
}

fn fit_method(effect: &str) -> FitMethod {
    match effect {
        "jet_pipe_hysteresis" => FitMethod::Hysteresis,
        "piston_friction" => FitMethod::FrictionRegression,
        "dead_volume" => FitMethod::Golden {
            parameter: "dead_volume",
            upper: 20e-6,
        },
        "supply_pressure_drop" => FitMethod::Golden {
            parameter: "supply_resistance",
            upper: 2e9,
        },
        "heat_transfer" => FitMethod::Golden {
            parameter: "heat_transfer_fraction",
            upper: 1.0,
        },
        "transport_delay" => FitMethod::Golden {
            parameter: "command_delay",
            upper: 0.03,
        },
        _ => FitMethod::SensorRegression,
    }
}

/// Set an effect parameter by its FMU name ("dead_volume" sets both chambers).
fn set_parameter(p: &mut Parameters, name: &str, value: f64) {
    match name {
        "hysteresis_width" => p.hysteresis_width = value,
        "hysteresis_deadband" => p.hysteresis_deadband = value,
        "friction_coulomb" => p.friction_coulomb = value,
        "dead_volume" | "dead_volume_1" | "dead_volume_2" => {
            p.dead_volume_1 = value;
            p.dead_volume_2 = value;
        }
        "supply_resistance" => p.supply_resistance = value,
        "heat_transfer_fraction" => p.heat_transfer_fraction = value,
        "command_delay" => p.command_delay = value,
        "force_sensor_offset" => p.force_sensor_offset = value,
        "force_sensor_gain" => p.force_sensor_gain = value,
        "x_jp_offset" => p.x_jp_offset = value,
        "C_d" => p.c_d = value,
        "C_dm_A_lpp" => p.c_dm_a_lpp = value,
        "C_db_A_lpp" => p.c_db_a_lpp = value,
        other => unreachable!("no fitted parameter called {other}"),
    }
}

/// The FMU start values of a fitted effect parameter.
fn fmu_values(name: &'static str, value: f64) -> Vec<(&'static str, f64)> {
    if name == "dead_volume" {
        vec![("dead_volume_1", value), ("dead_volume_2", value)]
    } else {
        vec![(name, value)]
    }
}

/// Runs the fast replay and measures the training error.
struct Evaluator<'a> {
    recording: &'a Recording,
    mask: &'a [bool],
}

impl Evaluator<'_> {
    fn run(&self, p: &Parameters) -> Result<Replay, String> {
        let model = Actuator::new(p.clone())?;
        replay_fast(&model, self.recording, self.recording.len())
    }

    fn train_rms(&self, p: &Parameters) -> f64 {
        match self.run(p) {
            Ok(r) => rms_where(&r.force, &self.recording.force, self.mask, true),
            Err(_) => f64::INFINITY,
        }
    }

    fn fit(&self, effect: &'static str, base: &Parameters, base_replay: &Replay) -> Result<CandidateFit, String> {
        let rec = self.recording;
        let mut p = base.clone();
        let mut fitted = vec![];
        match fit_method(effect) {
            FitMethod::Hysteresis => {
                const UPPER: f64 = 0.6e-3;
                let objective = |width: f64, fraction: f64| {
                    let mut q = base.clone();
                    q.hysteresis_width = width;
                    q.hysteresis_deadband = fraction * width;
                    self.train_rms(&q)
                };
                let mut fraction = 0.5;
                let mut width =
                    UPPER * golden_section(|u| objective(UPPER * u * u, fraction), GOLDEN_ITERATIONS).powi(2);
                fraction = golden_section(|f| objective(width, f), GOLDEN_ITERATIONS);
                width = UPPER * golden_section(|u| objective(UPPER * u * u, fraction), GOLDEN_ITERATIONS).powi(2);
                p.hysteresis_width = width;
                p.hysteresis_deadband = fraction * width;
                fitted.push(("hysteresis_width", width));
                fitted.push(("hysteresis_deadband", fraction * width));
            }
            FitMethod::Golden { parameter, upper } => {
                let objective = |u: f64| {
                    let mut q = base.clone();
                    set_parameter(&mut q, parameter, upper * u * u);
                    self.train_rms(&q)
                };
                let u = golden_section(objective, GOLDEN_ITERATIONS);
                let value = upper * u * u;
                set_parameter(&mut p, parameter, value);
                fitted.extend(fmu_values(parameter, value));
            }
            FitMethod::SensorRegression => {
                // measured = offset + gain·F_meas(model): regress on training samples,
                // composing with any sensor error already in the base parameters.
                let (mut sx, mut sy, mut sxx, mut sxy, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
                for ((x, y), &m) in base_replay.force.iter().zip(&rec.force).zip(self.mask) {
                    if m {
                        sx += x;
                        sy += y;
                        sxx += x * x;
                        sxy += x * y;
                        n += 1.0;
                    }
                }
                let gain = (n * sxy - sx * sy) / (n * sxx - sx * sx);
                let offset = (sy - gain * sx) / n;
                if !(gain.is_finite() && gain > 0.0 && offset.is_finite()) {
                    return Err("the force does not vary enough to fit a sensor gain".to_string());
                }
                p.force_sensor_gain = base.force_sensor_gain * gain;
                p.force_sensor_offset = base.force_sensor_offset * gain + offset;
                fitted.push(("force_sensor_offset", p.force_sensor_offset));
                fitted.push(("force_sensor_gain", p.force_sensor_gain));
            }
            FitMethod::FrictionRegression => {
                // residual ≈ −F_c·sgn(ẋ_s) where the stopper moves.
                let (mut num, mut den) = (0.0, 0.0);
                for k in 1..rec.len() {
                    if !self.mask[k] {
                        continue;
                    }
                    let v = (rec.x_s[k] - rec.x_s[k - 1]) / (rec.time[k] - rec.time[k - 1]);
                    if v.abs() > 1e-9 {
                        num -= (rec.force[k] - base_replay.force[k]) * v.signum();
                        den += 1.0;
                    }
                }
                if den == 0.0 {
                    return Err("the stopper never moves: friction cannot be identified".to_string());
                }
                // F_meas scales friction by the sensor gain.
                let value = (num / den / base.force_sensor_gain).max(0.0) + base.friction_coulomb;
                p.friction_coulomb = value;
                fitted.push(("friction_coulomb", value));
            }
        }
        let r = self.run(&p)?;
        let e = errors(&r.force, rec, self.mask);
        Ok(CandidateFit {
            name: effect,
            parameters: fitted,
            train_rms: e.train_rms,
            heldout_rms: e.heldout_rms,
            score: 0.0,
        })
    }
}

/// Levenberg–Marquardt on the training residual for the parameters the thesis identified
/// from static loops (§3.3.1). Returns the calibrated parameters and their values.
fn calibrate(
    eval: &Evaluator,
    base: &Parameters,
    progress: &mut dyn FnMut(&str),
) -> (Parameters, Vec<(&'static str, f64)>) {
    let names: [&'static str; 4] = ["x_jp_offset", "C_d", "C_dm_A_lpp", "C_db_A_lpp"];
    let scales = [1e-4, 0.1, 0.05e-6, 0.05e-6];
    let get = |p: &Parameters| [p.x_jp_offset, p.c_d, p.c_dm_a_lpp, p.c_db_a_lpp];
    let with = |x: &[f64; 4]| {
        let mut p = base.clone();
        for (name, v) in names.iter().zip(x) {
            set_parameter(&mut p, name, *v);
        }
        p
    };
    let residuals = |x: &[f64; 4]| -> Option<Vec<f64>> {
        let p = with(x);
        p.validate().ok()?;
        let r = eval.run(&p).ok()?;
        // every 10th training sample is plenty for four parameters
        Some(
            r.force
                .iter()
                .zip(&eval.recording.force)
                .zip(eval.mask)
                .enumerate()
                .filter(|(k, (_, &m))| m && k % 10 == 0)
                .map(|(_, ((a, b), _))| a - b)
                .collect(),
        )
    };
    let mut x = get(base);
    let Some(mut r) = residuals(&x) else {
        return (base.clone(), vec![]);
    };
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut lambda = 1e-2;
    for iteration in 0..8 {
        progress(&format!(
            "calibration: iteration {} of at most 8, training RMS {:.4} N",
            iteration + 1,
            (cost(&r) / r.len() as f64).sqrt()
        ));
        let mut jac = nalgebra::DMatrix::<f64>::zeros(r.len(), 4);
        for j in 0..4 {
            let mut xp = x;
            xp[j] += 1e-3 * scales[j];
            let Some(rp) = residuals(&xp) else { continue };
            for i in 0..r.len() {
                jac[(i, j)] = (rp[i] - r[i]) / (1e-3 * scales[j]) * scales[j];
            }
        }
        let jt_j = jac.transpose() * &jac;
        let jt_r = jac.transpose() * nalgebra::DVector::from_vec(r.clone());
        let mut improved = false;
        for _ in 0..4 {
            let mut a = jt_j.clone();
            for j in 0..4 {
                a[(j, j)] += lambda * jt_j[(j, j)].max(1e-12);
            }
            let Some(step) = a.lu().solve(&(-&jt_r)) else { break };
            let mut xn = x;
            for j in 0..4 {
                xn[j] += step[j] * scales[j];
            }
            if let Some(rn) = residuals(&xn) {
                if cost(&rn) < cost(&r) {
                    x = xn;
                    r = rn;
                    lambda = (lambda / 3.0).max(1e-6);
                    improved = true;
                    break;
                }
            }
            lambda *= 10.0;
        }
        if !improved {
            break;
        }
    }
    (with(&x), names.iter().copied().zip(x).collect())
}

/// Correlation coefficient of two series.
fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    if n < 2.0 {
        return 0.0;
    }
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa == 0.0 || sbb == 0.0 {
        0.0
    } else {
        sab / (saa * sbb).sqrt()
    }
}

/// Signals a residual may follow, each tied to the effects it points at.
struct Features {
    names: Vec<&'static str>,
    values: Vec<Vec<f64>>,
}

fn features(rec: &Recording, model_force: &[f64], volume_1: &[f64]) -> Features {
    let n = rec.len();
    let mut reversal = vec![0.0; n];
    let mut command_rate = vec![0.0; n];
    let mut stopper_direction = vec![0.0; n];
    let mut force_rate = vec![0.0; n];
    // Direction of the command since its last reversal (a 50 mV dead band ignores noise
    // and D/A steps).
    let (mut direction, mut extreme) = (0.0, rec.v_da[0]);
    for k in 0..n {
        let v = rec.v_da[k];
        if direction >= 0.0 && v > extreme || direction < 0.0 && v < extreme {
            extreme = v;
        }
        if direction >= 0.0 && v < extreme - 0.05 {
            direction = -1.0;
            extreme = v;
        } else if direction <= 0.0 && v > extreme + 0.05 {
            direction = 1.0;
            extreme = v;
        }
        reversal[k] = direction;
        let (a, b) = (k.saturating_sub(10), (k + 10).min(n - 1));
        if b > a {
            let dt = rec.time[b] - rec.time[a];
            command_rate[k] = (rec.v_da[b] - rec.v_da[a]) / dt;
            force_rate[k] = (model_force[b] - model_force[a]) / dt;
        }
        if k > 0 {
            stopper_direction[k] = (rec.x_s[k] - rec.x_s[k - 1]).signum();
        }
    }
    Features {
        names: vec![
            "direction of the last command reversal",
            "command rate dv_DA/dt",
            "stopper direction sign(dx_s/dt)",
            "modelled force level",
            "modelled force rate dF/dt",
            "chamber 1 volume",
        ],
        values: vec![
            reversal,
            command_rate,
            stopper_direction,
            model_force.to_vec(),
            force_rate,
            volume_1.to_vec(),
        ],
    }
}

fn evidence(
    effect: &str,
    fit: &CandidateFit,
    residual: &[f64],
    f: &Features,
    noise: f64,
    before_heldout: f64,
) -> String {
    let corr = |name: &str| {
        let k = f.names.iter().position(|n| *n == name).expect("feature exists");
        correlation(residual, &f.values[k])
    };
    let params: Vec<String> = fit.parameters.iter().map(|(n, v)| format!("{n} = {v:.4e}")).collect();
    let gain = format!(
        "Fitted on the training blocks ({}), it lowers the held-out RMS error from {:.4} N to {:.4} N (noise floor {:.4} N)",
        params.join(", "),
        before_heldout,
        fit.heldout_rms,
        noise
    );
    let why = match effect {
        "jet_pipe_hysteresis" => format!(
            "the residual follows the direction of the last command reversal (correlation {:.2}): at equal command the force is lower on rising commands than on falling ones, a loop the thesis model cannot make (§3.2.1)",
            corr("direction of the last command reversal")
        ),
        "piston_friction" => format!(
            "the residual changes sign with the stopper's direction of motion (correlation {:.2} with sign(dx_s/dt)) and vanishes while the stopper is still",
            corr("stopper direction sign(dx_s/dt)")
        ),
        "sensor_offset_gain" => format!(
            "the residual is an affine function of the force level (correlation {:.2} with the modelled force), as an offset and gain error of the force sensor make it",
            corr("modelled force level")
        ),
        "transport_delay" => format!(
            "the residual follows the modelled force rate (correlation {:.2} with dF/dt): the model leads the measurement",
            corr("modelled force rate dF/dt")
        ),
        "supply_pressure_drop" => format!(
            "the residual grows with the force level (correlation {:.2}), largest where the supply flow is largest",
            corr("modelled force level")
        ),
        "dead_volume" => format!(
            "the residual follows the force rate (correlation {:.2} with dF/dt) and the chamber volume (correlation {:.2}): the chambers fill more slowly than the swept volumes alone allow",
            corr("modelled force rate dF/dt"),
            corr("chamber 1 volume")
        ),
        _ => format!(
            "the residual follows the force rate (correlation {:.2} with dF/dt): the chambers respond as if between isothermal and adiabatic",
            corr("modelled force rate dF/dt")
        ),
    };
    format!("{why}. {gain}.")
}

/// Ljung–Box statistic of the first `lags` autocorrelations, and the lag-1 autocorrelation.
fn whiteness(residual: &[f64], lags: usize) -> (f64, f64) {
    let n = residual.len();
    if n <= lags + 1 {
        return (0.0, 0.0);
    }
    let mean = residual.iter().sum::<f64>() / n as f64;
    let c0: f64 = residual.iter().map(|r| (r - mean).powi(2)).sum::<f64>();
    if c0 == 0.0 {
        return (0.0, 0.0);
    }
    let mut q = 0.0;
    let mut first = 0.0;
    for lag in 1..=lags {
        let c: f64 = (lag..n)
            .map(|k| (residual[k] - mean) * (residual[k - lag] - mean))
            .sum();
        let rho = c / c0;
        if lag == 1 {
            first = rho;
        }
        q += rho * rho / (n - lag) as f64;
    }
    (n as f64 * (n as f64 + 2.0) * q, first)
}

/// Diagnose a recording. `progress` receives one line per stage.
pub fn diagnose(
    recording: &Recording,
    base: &Parameters,
    calibrate_static: bool,
    progress: &mut dyn FnMut(&str),
) -> Result<Diagnosis, String> {
    let mask = training_mask(&recording.time);
    let noise = noise_floor(&recording.force);
    let eval = Evaluator { recording, mask: &mask };
    progress(&format!(
        "{} samples, force noise floor {:.4} N; replaying the thesis model",
        recording.len(),
        noise
    ));
    let before_model = Actuator::new(base.clone())?;
    let mut current = base.clone();
    let mut calibrated = vec![];
    if calibrate_static {
        let (p, values) = calibrate(&eval, base, progress);
        current = p;
        calibrated = values;
    }
    let mut current_replay = eval.run(&current)?;
    let mut current_errors = errors(&current_replay.force, recording, &mask);
    let mut effects: Vec<(CandidateFit, String)> = vec![];
    let mut all_candidates: Vec<CandidateFit> = vec![];
    let volume_1: Vec<f64> = recording
        .x_s
        .iter()
        .map(|&x| before_model.cylinder.volumes(x).0)
        .collect();
    for round in 0..MAX_EFFECTS {
        if current_errors.heldout_rms <= EXPLAINED_WITHIN_NOISE * noise {
            progress(&format!(
                "held-out error {:.4} N is within the noise: done",
                current_errors.heldout_rms
            ));
            break;
        }
        let remaining: Vec<&'static str> = EFFECT_NAMES
            .iter()
            .copied()
            .filter(|name| effects.iter().all(|(e, _)| e.name != *name))
            .collect();
        progress(&format!(
            "round {}: fitting {} candidate effects (held-out error {:.4} N)",
            round + 1,
            remaining.len(),
            current_errors.heldout_rms
        ));
        let fits: Vec<Result<CandidateFit, String>> = std::thread::scope(|scope| {
            let threads = std::thread::available_parallelism()
                .map_or(2, |n| n.get())
                .clamp(1, remaining.len().max(1));
            let chunks: Vec<Vec<&'static str>> = (0..threads)
                .map(|t| remaining.iter().copied().skip(t).step_by(threads).collect())
                .collect();
            let handles: Vec<_> = chunks
                .into_iter()
                .map(|chunk| {
                    let (eval, current, current_replay) = (&eval, &current, &current_replay);
                    scope.spawn(move || {
                        chunk
                            .into_iter()
                            .map(|e| eval.fit(e, current, current_replay))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            let mut by_name: Vec<(usize, Result<CandidateFit, String>)> = vec![];
            for (t, h) in handles.into_iter().enumerate() {
                for (j, fit) in h.join().unwrap_or_default().into_iter().enumerate() {
                    by_name.push((t + j * threads, fit));
                }
            }
            by_name.sort_by_key(|(k, _)| *k);
            by_name.into_iter().map(|(_, f)| f).collect()
        });
        let mut round_fits: Vec<CandidateFit> = fits
            .into_iter()
            .filter_map(Result::ok)
            .map(|mut f| {
                f.score = (current_errors.heldout_rms - f.heldout_rms) / current_errors.heldout_rms;
                f
            })
            .collect();
        round_fits.sort_by(|a, b| b.score.total_cmp(&a.score));
        for f in &round_fits {
            progress(&format!(
                "  {:<22} held-out {:.4} N  score {:+.3}",
                f.name, f.heldout_rms, f.score
            ));
        }
        if round == 0 {
            all_candidates = round_fits.clone();
        }
        let Some(best) = round_fits.first().cloned() else { break };
        let gain = current_errors.heldout_rms - best.heldout_rms;
        if best.score < MIN_RELATIVE_GAIN || gain < MIN_GAIN_IN_NOISE * noise {
            progress(&format!(
                "no candidate lowers the held-out error enough (best: {} by {:.4} N)",
                best.name, gain
            ));
            break;
        }
        let residual: Vec<f64> = recording
            .force
            .iter()
            .zip(&current_replay.force)
            .map(|(m, f)| m - f)
            .collect();
        let feats = features(recording, &current_replay.force, &volume_1);
        let words = evidence(best.name, &best, &residual, &feats, noise, current_errors.heldout_rms);
        progress(&format!("adding {}", best.name));
        for (name, value) in &best.parameters {
            set_parameter(&mut current, name, *value);
        }
        current_replay = eval.run(&current)?;
        current_errors = errors(&current_replay.force, recording, &mask);
        effects.push((best, words));
    }
    // The reported figures come from the accurate, error-controlled replay.
    progress("final replays with the error-controlled integrator");
    let final_model = Actuator::new(current.clone())?;
    let (before, after) = std::thread::scope(|scope| {
        let b = scope.spawn(|| replay(&before_model, recording, 1e-5, recording.len()));
        let a = replay(&final_model, recording, 1e-5, recording.len());
        (b.join().unwrap_or_else(|_| Err("replay panicked".to_string())), a)
    });
    let (before, after) = (before?, after?);
    let after_residual: Vec<f64> = recording.force.iter().zip(&after.force).map(|(m, f)| m - f).collect();
    let heldout_residual: Vec<f64> = after_residual
        .iter()
        .zip(&mask)
        .filter(|(_, &m)| !m)
        .map(|(r, _)| *r)
        .collect();
    let (ljung_box, lag1) = whiteness(&heldout_residual, 20);
    let feats = features(recording, &after.force, &volume_1);
    let mut correlations = serde_json::Map::new();
    for (name, values) in feats.names.iter().zip(&feats.values) {
        correlations.insert(name.to_string(), json!(correlation(&after_residual, values)));
    }
    // The recording's own pressure level and the stopper velocity, where they exist.
    let mean_pressure: Vec<f64> = after.p1.iter().zip(&after.p2).map(|(a, b)| 0.5 * (a + b)).collect();
    correlations.insert(
        "modelled mean chamber pressure".to_string(),
        json!(correlation(&after_residual, &mean_pressure)),
    );
    let stopper_velocity: Vec<f64> = (0..recording.len())
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(recording.len() - 1));
            if b > a {
                (recording.x_s[b] - recording.x_s[a]) / (recording.time[b] - recording.time[a])
            } else {
                0.0
            }
        })
        .collect();
    correlations.insert(
        "stopper velocity dx_s/dt".to_string(),
        json!(correlation(&after_residual, &stopper_velocity)),
    );
    // Errors by 10 s segment (the bench protocol's segments are 10–20 s long).
    let mut by_segment = vec![];
    let (t_first, t_last) = (recording.time[0], recording.time[recording.len() - 1]);
    let mut from = t_first;
    while from < t_last {
        let to = (from + 10.0).min(t_last + 1e-9);
        let inside: Vec<bool> = recording.time.iter().map(|&t| t >= from && t < to).collect();
        by_segment.push(json!({
            "from_s": from,
            "to_s": to,
            "before_rms_N": rms_where(&before.force, &recording.force, &inside, true),
            "after_rms_N": rms_where(&after.force, &recording.force, &inside, true),
        }));
        from = to;
    }
    let residual_tests = json!({
        "whiteness": {"lag1_autocorrelation": lag1, "ljung_box_q20": ljung_box, "white_at_5_percent": ljung_box < 31.41},
        "input_correlation": correlations,
        "by_segment": by_segment,
    });
    Ok(Diagnosis {
        samples: recording.len(),
        noise_floor: noise,
        before: errors(&before.force, recording, &mask),
        after: errors(&after.force, recording, &mask),
        calibrated,
        effects,
        candidates: all_candidates,
        residual_tests,
        parameters: current,
        before_force: before.force,
        after_force: after.force,
    })
}

impl Diagnosis {
    pub fn to_json(&self, recording_name: &str) -> Value {
        let err = |e: &Errors| json!({"force_rms_N": e.rms, "force_nrmse": e.nrmse});
        let mut start_values = serde_json::Map::new();
        for (name, value) in &self.calibrated {
            start_values.insert(name.to_string(), json!(value));
        }
        for (fit, _) in &self.effects {
            for (name, value) in &fit.parameters {
                start_values.insert(name.to_string(), json!(value));
            }
        }
        json!({
            "recording": recording_name,
            "samples": self.samples,
            "noise_floor_N": self.noise_floor,
            "before": err(&self.before),
            "after": err(&self.after),
            "heldout": {"before_rms_N": self.before.heldout_rms, "after_rms_N": self.after.heldout_rms},
            "calibrated": self.calibrated.iter().map(|(n, v)| (n.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
            "effects": self.effects.iter().map(|(fit, words)| json!({
                "name": fit.name,
                "parameters": fit.parameters.iter().map(|(n, v)| (n.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
                "evidence": words,
            })).collect::<Vec<_>>(),
            "candidates": self.candidates.iter().map(|c| json!({
                "name": c.name,
                "parameters": c.parameters.iter().map(|(n, v)| (n.to_string(), json!(v))).collect::<serde_json::Map<_, _>>(),
                "train_rms_N": c.train_rms,
                "heldout_rms_N": c.heldout_rms,
                "score": c.score,
            })).collect::<Vec<_>>(),
            "residual_tests": self.residual_tests,
            "fmu_start_values": start_values,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_floor_of_white_noise_is_its_sigma() {
        // deterministic pseudo-random normal samples (Box–Muller on an LCG)
        let mut state = 12345u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        let force: Vec<f64> = (0..20000)
            .map(|k| {
                let (a, b) = (uniform(), uniform());
                45.0 + 10.0 * (k as f64 * 1e-3).sin()
                    + 0.05 * (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
            })
            .collect();
        let sigma = noise_floor(&force);
        assert!((sigma - 0.05).abs() < 0.003, "{sigma}");
    }

    #[test]
    fn blocks_alternate_every_two_seconds() {
        let t: Vec<f64> = (0..8000).map(|k| k as f64 * 1e-3).collect();
        let m = training_mask(&t);
        assert!(m[0] && m[1999] && !m[2000] && !m[3999] && m[4000]);
    }
}
