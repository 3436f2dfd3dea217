//! The implicit integrators of the tendon and the joint reduce each substep to one scalar
//! equation g(v) = 0 in the new velocity, with g strictly increasing (mass/step + damping,
//! plus tension or limit terms that only grow with the velocity). Such an equation has
//! exactly one root; a Newton step kept inside a shrinking bracket finds it whatever the
//! kinks (slack, contact, friction).

/// The root of the strictly increasing `g` near `guess`. `scale` is a velocity scale for the
/// first bracket. Returns `None` only if no sign change is found (then `g` is not
/// increasing, or not finite) so the caller can report it instead of panicking.
pub fn increasing_root(g: impl Fn(f64) -> f64, guess: f64, scale: f64) -> Option<f64> {
    let mut width = scale.abs().max(1e-9);
    let (mut lo, mut hi) = (guess - width, guess + width);
    let mut g_lo = g(lo);
    let mut g_hi = g(hi);
    let mut expansions = 0;
    while !(g_lo <= 0.0 && g_hi >= 0.0) {
        if !(g_lo.is_finite() && g_hi.is_finite()) || expansions > 200 {
            return None;
        }
        width *= 4.0;
        if g_lo > 0.0 {
            lo -= width;
            g_lo = g(lo);
        }
        if g_hi < 0.0 {
            hi += width;
            g_hi = g(hi);
        }
        expansions += 1;
    }
    let mut x = guess.clamp(lo, hi);
    for _ in 0..100 {
        let gx = g(x);
        if gx == 0.0 {
            return Some(x);
        }
        if gx < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        if hi - lo <= 1e-14 * (1.0 + x.abs()) {
            break;
        }
        // Secant-free Newton with a one-sided difference: the kinks make the analytic
        // derivative a case analysis, and a bisection fallback keeps it safe anyway.
        let dx = 1e-9 * (1.0 + x.abs());
        let slope = (g(x + dx) - gx) / dx;
        let newton = x - gx / slope;
        x = if slope > 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_root_of_kinked_increasing_functions() {
        let g = |v: f64| 10.0 * v + 5.0 * v.max(0.0) + (v * 100.0).tanh() - 3.0;
        let r = increasing_root(g, -50.0, 1e-3).unwrap();
        assert!(g(r).abs() < 1e-10, "{r} {}", g(r));
        assert!(increasing_root(|v| v - 1e6, 0.0, 1.0).unwrap() - 1e6 < 1e-6);
    }

    #[test]
    fn reports_a_decreasing_function_instead_of_looping() {
        assert!(increasing_root(|v| -v - 1.0, 0.0, 1.0).is_none());
        assert!(increasing_root(|_| f64::NAN, 0.0, 1.0).is_none());
    }
}
