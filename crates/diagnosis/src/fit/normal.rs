//! Least squares on a few columns accumulated sample by sample: the normal equations of a
//! screen, solved by elimination.

use crate::input::blocks::Block;

/// Normal equations of the columns w S(t) φ_j(s(t)) against the weighted residual, on the
/// training and the held-out samples.
pub(crate) struct Normal {
    size: usize,
    train: Vec<f64>,
    train_rhs: Vec<f64>,
    heldout: Vec<f64>,
    heldout_rhs: Vec<f64>,
    heldout_ss: f64,
}

impl Normal {
    pub(crate) fn new(size: usize) -> Self {
        Self {
            size,
            train: vec![0.0; size * size],
            train_rhs: vec![0.0; size],
            heldout: vec![0.0; size * size],
            heldout_rhs: vec![0.0; size],
            heldout_ss: 0.0,
        }
    }

    pub(crate) fn add(&mut self, block: Block, row: &[f64], target: f64) {
        let (matrix, rhs) = match block {
            Block::Training => (&mut self.train, &mut self.train_rhs),
            Block::HeldOut => {
                self.heldout_ss += target * target;
                (&mut self.heldout, &mut self.heldout_rhs)
            }
            Block::Settling | Block::SetAside => return,
        };
        for (i, &a) in row.iter().enumerate() {
            if a == 0.0 {
                continue;
            }
            rhs[i] += a * target;
            for (j, &b) in row.iter().enumerate() {
                matrix[i * self.size + j] += a * b;
            }
        }
    }

    /// The least-squares coefficients of the columns combined by `map` (size × m), and the
    /// held-out sum of squares they leave.
    pub(crate) fn solve_in(&self, map: &[Vec<f64>]) -> Option<(Vec<f64>, f64)> {
        let m = map[0].len();
        let project = |matrix: &[f64], rhs: &[f64]| {
            let mut a = vec![0.0; m * m];
            let mut b = vec![0.0; m];
            for p in 0..m {
                for i in 0..self.size {
                    b[p] += map[i][p] * rhs[i];
                }
                for q in 0..m {
                    let mut sum = 0.0;
                    for i in 0..self.size {
                        if map[i][p] == 0.0 {
                            continue;
                        }
                        for j in 0..self.size {
                            sum += map[i][p] * matrix[i * self.size + j] * map[j][q];
                        }
                    }
                    a[p * m + q] = sum;
                }
            }
            (a, b)
        };
        let (a, b) = project(&self.train, &self.train_rhs);
        let y = solve(a, b, m)?;
        let (h, hb) = project(&self.heldout, &self.heldout_rhs);
        let mut ss = self.heldout_ss;
        for p in 0..m {
            ss -= 2.0 * y[p] * hb[p];
            for q in 0..m {
                ss += y[p] * h[p * m + q] * y[q];
            }
        }
        Some((y, ss.max(0.0)))
    }
}

/// Solve the symmetric system `a y = b` (m × m) by Gaussian elimination with partial
/// pivoting and a small ridge; `None` when it is singular.
fn solve(mut a: Vec<f64>, mut b: Vec<f64>, m: usize) -> Option<Vec<f64>> {
    let trace: f64 = (0..m).map(|i| a[i * m + i]).sum();
    if trace.is_nan() || trace <= 0.0 {
        return None;
    }
    for i in 0..m {
        a[i * m + i] += 1e-10 * trace / m as f64;
    }
    for col in 0..m {
        let pivot = (col..m).max_by(|&i, &j| a[i * m + col].abs().total_cmp(&a[j * m + col].abs()))?;
        if a[pivot * m + col].abs() < 1e-300 {
            return None;
        }
        if pivot != col {
            for k in 0..m {
                a.swap(col * m + k, pivot * m + k);
            }
            b.swap(col, pivot);
        }
        for row in col + 1..m {
            let factor = a[row * m + col] / a[col * m + col];
            for k in col..m {
                a[row * m + k] -= factor * a[col * m + k];
            }
            b[row] -= factor * b[col];
        }
    }
    let mut y = vec![0.0; m];
    for row in (0..m).rev() {
        let mut sum = b[row];
        for k in row + 1..m {
            sum -= a[row * m + k] * y[k];
        }
        y[row] = sum / a[row * m + row];
    }
    y.iter().all(|v| v.is_finite()).then_some(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_elimination_solves_a_small_symmetric_system() {
        let a = vec![4.0, 1.0, 0.0, 1.0, 3.0, 1.0, 0.0, 1.0, 2.0];
        let y_true = [1.0, -2.0, 0.5];
        let b: Vec<f64> = (0..3).map(|i| (0..3).map(|j| a[i * 3 + j] * y_true[j]).sum()).collect();
        let y = solve(a, b, 3).unwrap();
        for (got, want) in y.iter().zip(y_true) {
            assert!((got - want).abs() < 1e-8, "{y:?}");
        }
    }
}
