//! `--calibrate`: re-identify what the thesis identified from static loops (§3.3.1: the
//! jet pipe offset, C_d and the leakage coefficients) by Levenberg–Marquardt on the
//! training blocks, and say for each value how far it moved from the thesis's, whether
//! that is plausible, and whether it is the same on both halves of the recording and for
//! both signs of the command: a value that differs between them is absorbing a drift or an
//! asymmetry that calibration would otherwise hide.

use crate::input::recording::Recording;
use crate::replay::replay_fast;
use jetpipe_model::physics::actuator::Actuator;
use jetpipe_model::physics::parameters::Parameters;

use crate::candidates::{parameter_value, set_parameter};
use crate::input::blocks::Block;

pub const NAMES: [&str; 4] = ["x_jp_offset", "C_d", "C_dm_A_lpp", "C_db_A_lpp"];
const SCALES: [f64; 4] = [1e-4, 0.1, 0.05e-6, 0.05e-6];
/// A shift beyond this (in units of SCALES) is implausible for a re-identification.
const IMPLAUSIBLE: [f64; 4] = [1.5, 1.5, 4.0, 4.0];
/// Values found on two halves that differ by more than this (in units of SCALES) are flagged.
const DIFFERENT_HALVES: [f64; 4] = [0.1, 0.1, 0.4, 0.4];

/// One re-identified parameter against the thesis.
#[derive(Clone, Debug)]
pub struct Calibrated {
    pub name: &'static str,
    pub value: f64,
    pub thesis: f64,
    /// Values on the first and second half of the recording, and for commands below and
    /// above the median.
    pub halves_in_time: (f64, f64),
    pub halves_in_command: (f64, f64),
    pub flags: Vec<String>,
}

/// Levenberg–Marquardt on the force residual of the samples in `rows` (every 10th is
/// plenty for four parameters). Returns the four values.
fn fit(recording: &Recording, base: &Parameters, rows: &[bool]) -> [f64; 4] {
    let with = |x: &[f64; 4]| -> Option<Parameters> {
        let mut p = base.clone();
        for (name, v) in NAMES.iter().zip(x) {
            set_parameter(&mut p, name, *v).ok()?;
        }
        p.validate().ok()?;
        Some(p)
    };
    let residuals = |x: &[f64; 4]| -> Option<Vec<f64>> {
        let model = Actuator::new(with(x)?).ok()?;
        let r = replay_fast(&model, recording, recording.len()).ok()?;
        Some(
            (0..recording.len())
                .filter(|&k| rows[k] && k % 10 == 0)
                .map(|k| r.force[k] - recording.force[k])
                .collect(),
        )
    };
    let mut x = NAMES.map(|n| parameter_value(base, n));
    let Some(mut r) = residuals(&x) else { return x };
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let mut lambda = 1e-2;
    for _ in 0..8 {
        let mut jac = nalgebra::DMatrix::<f64>::zeros(r.len(), 4);
        for j in 0..4 {
            let mut xp = x;
            xp[j] += 1e-3 * SCALES[j];
            let Some(rp) = residuals(&xp) else { continue };
            for i in 0..r.len() {
                jac[(i, j)] = (rp[i] - r[i]) / 1e-3;
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
                xn[j] += step[j] * SCALES[j];
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
    x
}

/// Calibrate on the training blocks; check the values on halves of them.
pub fn calibrate(recording: &Recording, base: &Parameters, blocks: &[Block]) -> (Parameters, Vec<Calibrated>) {
    let thesis = Parameters::default();
    let n = recording.len();
    let mid_time = 0.5 * (recording.time[0] + recording.time[n - 1]);
    let mut commands = recording.v_da.clone();
    let mid = commands.len() / 2;
    let median_command = *commands.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
    let subset = |keep: &dyn Fn(usize) -> bool| -> Vec<bool> {
        (0..n).map(|k| blocks[k] == Block::Training && keep(k)).collect()
    };
    let rows = [
        subset(&|_| true),
        subset(&|k| recording.time[k] < mid_time),
        subset(&|k| recording.time[k] >= mid_time),
        subset(&|k| recording.v_da[k] < median_command),
        subset(&|k| recording.v_da[k] >= median_command),
    ];
    let values: Vec<[f64; 4]> = std::thread::scope(|scope| {
        let handles: Vec<_> = rows
            .iter()
            .map(|r| scope.spawn(move || fit(recording, base, r)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|_| NAMES.map(|n| parameter_value(base, n))))
            .collect()
    });
    let mut p = base.clone();
    let mut report = vec![];
    for j in 0..4 {
        let value = values[0][j];
        let _ = set_parameter(&mut p, NAMES[j], value);
        let reference = parameter_value(&thesis, NAMES[j]);
        let mut flags = vec![];
        let shift = (value - reference) / SCALES[j];
        if shift.abs() > IMPLAUSIBLE[j] {
            flags.push(format!(
                "implausible: {} moved from the thesis's {reference:.4e} to {value:.4e}, further than a re-identification of the same valve should; it is likely absorbing an effect the model lacks",
                NAMES[j]
            ));
        }
        let (t0, t1) = (values[1][j], values[2][j]);
        if ((t1 - t0) / SCALES[j]).abs() > DIFFERENT_HALVES[j] {
            flags.push(format!(
                "not constant in time: {} is {t0:.4e} on the first half of the recording and {t1:.4e} on the second (a drift, or an effect the model lacks that the halves' commands expose differently)",
                NAMES[j]
            ));
        }
        let (c0, c1) = (values[3][j], values[4][j]);
        if ((c1 - c0) / SCALES[j]).abs() > DIFFERENT_HALVES[j] {
            flags.push(format!(
                "not the same for both command ranges: {} is {c0:.4e} for commands below the median ({median_command:.2} V) and {c1:.4e} above it (an asymmetry, or a nonlinearity the constant is absorbing)",
                NAMES[j]
            ));
        }
        report.push(Calibrated {
            name: NAMES[j],
            value,
            thesis: reference,
            halves_in_time: (t0, t1),
            halves_in_command: (c0, c1),
            flags,
        });
    }
    if p.validate().is_err() {
        return (base.clone(), report);
    }
    (p, report)
}
