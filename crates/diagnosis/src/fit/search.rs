//! One-dimensional searches of a cost for the terms a fit searches instead of solving for
//! them (a limit, a delay, an orifice's area): a grid over the range, then Brent's search
//! between the best grid point's neighbours.

/// (√5 − 1)/2: the share of its bracket a golden-section step keeps.
const GOLDEN_SHARE: f64 = 0.618_033_988_749_894_9;

/// Golden-section search of `steps` steps on [a, b]: the best point and its cost.
pub(crate) fn golden(a: f64, b: f64, steps: usize, f: &mut dyn FnMut(f64) -> f64) -> (f64, f64) {
    let phi = GOLDEN_SHARE;
    let (mut a, mut b) = (a, b);
    let mut c = b - phi * (b - a);
    let mut d = a + phi * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..steps {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - phi * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + phi * (b - a);
            fd = f(d);
        }
    }
    if fc < fd {
        (c, fc)
    } else {
        (d, fd)
    }
}

/// A search of a cost on u ∈ [0, 1] that may have more than one valley: the cost on a grid
/// of `grid` points (the ends included), then Brent's search (parabolas through the three
/// best points, golden-section steps where a parabola is not to be trusted) between the best
/// grid point's neighbours, seeded with the grid's three points there, to the bracket that
/// `steps` golden-section steps leave of the whole range (0.618^steps), and with no more
/// evaluations than a golden-section search to that bracket takes. A cost with one valley
/// has its minimum between the best grid point's neighbours; with several valleys the search
/// follows the deepest the grid sees. A smooth valley is nearly a parabola near its bottom,
/// where Brent's search converges in a few evaluations where golden sections take ten. The
/// best u found and its cost: never worse than the best grid point.
pub(crate) fn search_from_grid(grid: usize, steps: usize, f: &mut dyn FnMut(f64) -> f64) -> (f64, f64) {
    if grid < 3 {
        return golden(0.0, 1.0, steps, f);
    }
    let h = 1.0 / (grid - 1) as f64;
    let costs: Vec<f64> = (0..grid).map(|i| f(i as f64 * h)).collect();
    // (a NaN cost never becomes the best)
    let mut best = 0;
    for (i, c) in costs.iter().enumerate() {
        if *c < costs[best] || costs[best].is_nan() {
            best = i;
        }
    }
    let at = |i: usize| (i as f64 * h, costs[i]);
    let (a, b) = ((best as f64 * h - h).max(0.0), (best as f64 * h + h).min(1.0));
    let neighbours = match (best.checked_sub(1), (best + 1 < grid).then(|| best + 1)) {
        (Some(l), Some(r)) if costs[r] < costs[l] => [at(r), at(l)],
        (Some(l), Some(r)) => [at(l), at(r)],
        (Some(l), None) => [at(l), at(l)],
        (None, Some(r)) => [at(r), at(r)],
        (None, None) => return at(best),
    };
    let width = GOLDEN_SHARE.powi(steps as i32);
    let most = golden_steps_within(b - a, steps) + 2;
    brent(a, b, at(best), neighbours, width, most, f)
}

/// Brent's minimisation on [a, b] from the best point `x` so far and the next best two
/// (`seconds`: w, then v), until the bracket is within `width` or `most` evaluations are
/// spent: the best point and its cost.
fn brent(
    mut a: f64,
    mut b: f64,
    x: (f64, f64),
    seconds: [(f64, f64); 2],
    width: f64,
    most: usize,
    f: &mut dyn FnMut(f64) -> f64,
) -> (f64, f64) {
    const GOLDEN_STEP: f64 = 1.0 - GOLDEN_SHARE;
    let ((mut x, mut fx), (mut w, mut fw), (mut v, mut fv)) = (x, seconds[0], seconds[1]);
    // The last two moves; a parabola must move less than half the one before last.
    let (mut d, mut e) = (0.0f64, b - a);
    let tol = 0.25 * width;
    for _ in 0..most {
        let middle = 0.5 * (a + b);
        if (x - middle).abs() <= 2.0 * tol - 0.5 * (b - a) {
            break;
        }
        let mut parabolic = false;
        if e.abs() > tol {
            let r = (x - w) * (fx - fv);
            let q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            let mut q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let before_last = e;
            // (false for a NaN or infinite cost among the three)
            if p.abs() < (0.5 * q * before_last).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < 2.0 * tol || b - u < 2.0 * tol {
                    d = tol.copysign(middle - x);
                }
                parabolic = true;
            }
        }
        if !parabolic {
            e = if x >= middle { a - x } else { b - x };
            d = GOLDEN_STEP * e;
        }
        let u = if d.abs() >= tol { x + d } else { x + tol.copysign(d) };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

/// The golden-section steps that shrink a bracket of `width` (of the whole range 1) at least
/// as far as `steps` steps shrink the whole range.
fn golden_steps_within(width: f64, steps: usize) -> usize {
    let saved = (width.ln() / GOLDEN_SHARE.ln()).floor().max(0.0) as usize;
    steps.saturating_sub(saved)
}

#[cfg(test)]
mod tests {
    use super::search_from_grid;

    /// The grid search's evaluations of `cost` and where it ended.
    fn searched(grid: usize, steps: usize, cost: impl Fn(f64) -> f64) -> (f64, f64, usize) {
        let mut evaluations = 0;
        let (u, c) = search_from_grid(grid, steps, &mut |u| {
            evaluations += 1;
            cost(u)
        });
        (u, c, evaluations)
    }

    #[test]
    fn a_cost_with_one_valley_is_searched_to_the_bracket_its_steps_give_with_fewer_evaluations_than_two_searches() {
        let phi: f64 = (5f64.sqrt() - 1.0) / 2.0;
        for (grid, steps) in [(5, 10), (9, 16)] {
            for minimum in [0.0, 0.03, 0.31, 0.5, 0.77, 0.999, 1.0] {
                // A smooth valley that is no parabola, and a kink, which no parabola fits.
                for (shape, cost) in [
                    (
                        "smooth",
                        Box::new(move |u: f64| 1.0 - (-((u - minimum) / 0.3).powi(2)).exp()) as Box<dyn Fn(f64) -> f64>,
                    ),
                    ("kinked", Box::new(move |u: f64| (u - minimum).abs())),
                ] {
                    let (u, _, evaluations) = searched(grid, steps, &cost);
                    assert!(
                        (u - minimum).abs() <= phi.powi(steps as i32),
                        "{shape}, grid {grid}, {steps} steps: the minimum at {minimum} was found at {u}"
                    );
                    // A golden-section search over the whole range takes steps + 2 evaluations; with
                    // the grid after it, steps + 2 + grid at the least.
                    assert!(
                        evaluations < steps + 2 + grid,
                        "{shape}, grid {grid}, {steps} steps: {evaluations} evaluations"
                    );
                }
            }
        }
    }

    #[test]
    fn a_smooth_valley_takes_fewer_evaluations_than_golden_sections_between_the_grid_points() {
        // Golden sections between an inner grid point's neighbours take a fixed count: the
        // grid, then two points and a step for each 0.618 of the bracket left to shrink
        // (9 of 10 for the 5-point grid's half range, 14 of 16 for the 9-point grid's quarter).
        let phi: f64 = (5f64.sqrt() - 1.0) / 2.0;
        for (grid, steps, golden_count) in [(5, 10, 5 + 9 + 2), (9, 16, 9 + 14 + 2)] {
            let mut worst = 0;
            for minimum in [0.03, 0.31, 0.47, 0.77, 0.96] {
                let cost = move |u: f64| 1.0 - (-((u - minimum) / 0.3).powi(2)).exp();
                let (u, _, evaluations) = searched(grid, steps, cost);
                assert!((u - minimum).abs() <= phi.powi(steps as i32), "{minimum}: {u}");
                worst = worst.max(evaluations);
            }
            assert!(
                worst + 4 <= golden_count,
                "grid {grid}: {worst} evaluations against {golden_count}"
            );
        }
    }

    #[test]
    fn of_two_valleys_the_search_follows_the_deeper_one_the_grid_sees() {
        // A shallow valley at 0.3 and a deeper one at 0.9: a golden-section search over the whole
        // range follows the shallow one (its first points cost −0.84 at 0.38 and −0.14 at 0.62);
        // the grid sees the deeper one at its end (−1.28 at 1 against −0.94 at 0.25).
        let cost = |u: f64| -(-((u - 0.3) / 0.2).powi(2)).exp() - 2.0 * (-((u - 0.9) / 0.15).powi(2)).exp();
        let (u, c, _) = searched(5, 10, cost);
        assert!((u - 0.9).abs() < 0.01 && c < -1.9, "ended at {u} ({c})");
        // Never worse than the best grid point, and a cost that is infinite everywhere but on one
        // grid point ends there.
        let (u, c, _) = searched(5, 10, |u| if (u - 0.75).abs() < 1e-12 { 1.0 } else { f64::INFINITY });
        assert_eq!((u, c), (0.75, 1.0));
    }
}
