//! The command's static curve kept non-decreasing (the command the driver sees does not fall as
//! the logged one rises), and refitted with its interior knots free.

use crate::candidates::curves::command_value_term;
use jetpipe_model::physics::static_curve::MAX_KNOTS;

use crate::candidates::curves::variable_name;
use crate::candidates::Candidate;
use crate::candidates::Mechanism;
use crate::candidates::Term;
use crate::vocabulary::Family;
use crate::vocabulary::Place;

/// Make the command curve's knot values in `set` non-decreasing: adjacent knots that fall
/// are pooled to their mean (pool-adjacent-violators), the least-squares non-decreasing
/// sequence, where a running maximum would lift a whole stretch to one noisy high knot.
pub fn monotone_command(set: &mut [(&'static str, f64)]) {
    let names: Vec<String> = (1..=MAX_KNOTS).map(|k| format!("command_curve_y_{k}")).collect();
    let at: Vec<usize> = names
        .iter()
        .filter_map(|name| set.iter().position(|(n, _)| n == name))
        .collect();
    let values: Vec<f64> = at.iter().map(|&i| set[i].1).collect();
    for (&i, v) in at.iter().zip(pooled_non_decreasing(&values)) {
        set[i].1 = v;
    }
}

/// The non-decreasing sequence nearest `values` in least squares (pool-adjacent-violators).
pub fn pooled_non_decreasing(values: &[f64]) -> Vec<f64> {
    // Blocks of (mean, count), merged backwards while a block's mean falls below the last.
    let mut blocks: Vec<(f64, usize)> = Vec::with_capacity(values.len());
    for &v in values {
        let mut block = (v, 1usize);
        while let Some(&(mean, count)) = blocks.last() {
            if mean <= block.0 {
                break;
            }
            blocks.pop();
            let total = count + block.1;
            block = ((mean * count as f64 + block.0 * block.1 as f64) / total as f64, total);
        }
        blocks.push(block);
    }
    blocks.into_iter().flat_map(|(mean, count)| vec![mean; count]).collect()
}

/// The command's fitted curve in `set` as a candidate whose knot abscissae are free as well
/// as its values: the knots were placed on a first-order proxy of the model (the force's
/// residual through its sensitivity to the command), so a dead zone's corners sit a little
/// off where the model puts them. Each interior abscissa moves within the half-gaps to its
/// neighbours, so the knots stay in order; the fit starts from `set` itself (every term's
/// neutral value is its value there). `None` when `set` holds no command curve with an
/// interior knot.
pub fn command_curve_with_free_knots(set: &[(&'static str, f64)]) -> Option<Candidate> {
    let get = |name: &str| set.iter().find(|(n, _)| *n == name).map(|(_, v)| *v);
    let n = get("command_curve_knots")? as usize;
    if !(3..=MAX_KNOTS).contains(&n) {
        return None;
    }
    let mut x = Vec::with_capacity(n);
    let mut y = Vec::with_capacity(n);
    for k in 1..=n {
        x.push(get(&format!("command_curve_x_{k}"))?);
        y.push(get(&format!("command_curve_y_{k}"))?);
    }
    let mut terms: Vec<Term> = (0..n).map(|k| command_value_term(k, y[k])).collect();
    for k in 1..n - 1 {
        let name = variable_name(&format!("command_curve_x_{}", k + 1));
        let (below, above) = (x[k] - x[k - 1], x[k + 1] - x[k]);
        terms.push(Term {
            name,
            unit: "V",
            mechanism: Mechanism::Parameter(name),
            neutral: x[k],
            step: 0.01 * below.min(above),
            lower: x[k] - 0.45 * below,
            upper: x[k] + 0.45 * above,
        });
    }
    Some(Candidate {
        label: "command static curve",
        location: Place::Command,
        family: Family::Nonlinearity,
        named: None,
        terms,
        settings: set.to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooling_adjacent_violators_gives_the_nearest_non_decreasing_sequence() {
        // The nearest non-decreasing sequence is constant on blocks, each at its values' mean.
        let values = [1.0, 3.0, 2.0, 2.5, 0.5, 4.0];
        let pooled = pooled_non_decreasing(&values);
        assert!(pooled.windows(2).all(|w| w[0] <= w[1]), "{pooled:?}");
        // 3, 2, 2.5, 0.5 pool to their mean 2.0, which is above 1.0 and below 4.0.
        let expected = [1.0, 2.0, 2.0, 2.0, 2.0, 4.0];
        for (a, b) in pooled.iter().zip(expected) {
            assert!((a - b).abs() < 1e-12, "{pooled:?}");
        }
        // Non-decreasing input is left as it is; a running maximum would give 3 for the dip.
        assert_eq!(pooled_non_decreasing(&[0.0, 1.0, 1.0, 2.0]), vec![0.0, 1.0, 1.0, 2.0]);
        let dip = pooled_non_decreasing(&[0.0, 3.0, 1.0]);
        assert!((dip[1] - 2.0).abs() < 1e-12 && (dip[2] - 2.0).abs() < 1e-12, "{dip:?}");
    }

    #[test]
    fn a_command_curve_with_free_knots_keeps_its_ends_and_its_knots_in_order() {
        let d = [
            ("command_curve_knots", 4.0),
            ("command_curve_x_1", -8.0),
            ("command_curve_y_1", -7.6),
            ("command_curve_x_2", -0.5),
            ("command_curve_y_2", 0.0),
            ("command_curve_x_3", 0.3),
            ("command_curve_y_3", 0.0),
            ("command_curve_x_4", 8.0),
            ("command_curve_y_4", 7.6),
        ];
        let c = command_curve_with_free_knots(&d).expect("a command curve");
        let abscissae: Vec<&Term> = c.terms.iter().filter(|t| t.name.contains("_x_")).collect();
        // Only the two interior knots move; the ends stay where the data's range put them.
        assert_eq!(
            abscissae.iter().map(|t| t.name).collect::<Vec<_>>(),
            vec!["command_curve_x_2", "command_curve_x_3"]
        );
        // Each moves at most to just short of the midpoint with its neighbours: never past.
        assert!(abscissae[0].lower > -8.0 && abscissae[0].upper < abscissae[1].lower);
        assert!(abscissae[1].upper < 8.0);
        assert!(abscissae.iter().all(|t| t.lower < t.neutral && t.neutral < t.upper));
        assert_eq!(c.terms.len(), 6);
        assert!(command_curve_with_free_knots(&d[..3]).is_none());
    }
}
