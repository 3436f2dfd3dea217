//! A valve orifice's flow (2.18)–(2.22) and the leakage past the piston (2.23) at once, in
//! the two lanes of an SSE2 register: every x86-64 processor has them, and a lane's add,
//! multiply, divide and square root are the scalar instruction's, rounded alike, so each
//! lane gives the bits of [`mass_flow_inline`] and [`leakage_flow_inline`].
//!
//! The right-hand side's time goes mostly to floating-point work, not to waiting on its
//! chain of dependent operations: in the side-by-side benchmark, a build whose leakage was
//! a plain product instead of (2.23)'s flow took about 8 % less time a step (its outputs
//! not the model's: a measure, not kept). Of the five flows, two are closed over most
//! of the stroke and the return that is open vents a chamber to the atmosphere, choked
//! (a product, no f2); the open supply and the leakage are unchoked, each with a table
//! lookup and a square root. Those two go together, in one packed evaluation.
//!
//! The scalar law branches (a closed orifice, the flow's direction, choked or not, the band
//! next to r = 1); here both sides of each branch are worked out and each lane takes its
//! own. A lane that would leave the table (a ratio outside it, a NaN, a gas whose table is
//! not accurate) sends the pair to the scalar law, which handles those cases.

use super::{leakage_flow_inline, mass_flow_inline, FlowConstants, REGULARISATION_RATIO_BAND};

/// `[mass_flow_inline(k, cd_area, p_from, p_to), leakage_flow_inline(k, c_dm_a_lpp,
/// c_db_a_lpp, p1, p2)]`, to the bit.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
pub fn mass_flow_and_leakage(
    k: &FlowConstants,
    cd_area: f64,
    p_from: f64,
    p_to: f64,
    c_dm_a_lpp: f64,
    c_db_a_lpp: f64,
    p1: f64,
    p2: f64,
) -> [f64; 2] {
    #[cfg(target_arch = "x86_64")]
    if let Some(flows) = sse2::mass_flow_and_leakage(k, cd_area, [p_from, p1], [p_to, p2], c_dm_a_lpp, c_db_a_lpp) {
        return flows;
    }
    [
        mass_flow_inline(k, cd_area, p_from, p_to),
        leakage_flow_inline(k, c_dm_a_lpp, c_db_a_lpp, p1, p2),
    ]
}

#[cfg(target_arch = "x86_64")]
mod sse2 {
    use super::{FlowConstants, REGULARISATION_RATIO_BAND};
    use core::arch::x86_64::*;

    /// `if mask { a } else { b }`, lane by lane.
    #[inline(always)]
    unsafe fn select(mask: __m128d, a: __m128d, b: __m128d) -> __m128d {
        _mm_or_pd(_mm_and_pd(mask, a), _mm_andnot_pd(mask, b))
    }

    /// Lane 0 the valve orifice of area `cd_area`, lane 1 the leakage, whose area (2.23)
    /// follows the pressure ratio; `None` when a lane needs what only the scalar law does
    /// (see the module's text).
    #[inline(always)]
    pub(super) fn mass_flow_and_leakage(
        k: &FlowConstants,
        cd_area: f64,
        p_from: [f64; 2],
        p_to: [f64; 2],
        c_dm_a_lpp: f64,
        c_db_a_lpp: f64,
    ) -> Option<[f64; 2]> {
        let table = k.unchoked.table()?;
        let (start, end, pieces_per_unit, coefficients) = table.parts();
        let last_piece = (coefficients.len() - 1) as f64;
        // SAFETY: SSE2 is part of x86-64; the loads below index `coefficients` with piece
        // numbers clamped to 0..=last_piece.
        unsafe {
            let from = _mm_set_pd(p_from[1], p_from[0]);
            let to = _mm_set_pd(p_to[1], p_to[0]);
            let zero = _mm_setzero_pd();
            let one = _mm_set1_pd(1.0);
            // (p_up, p_down, sign) = if p_from >= p_to {(p_from, p_to, 1)} else {(p_to, p_from, −1)}
            let forward = _mm_cmpge_pd(from, to);
            let p_up = select(forward, from, to);
            let p_down = select(forward, to, from);
            let sign = select(forward, one, _mm_set1_pd(-1.0));
            let ratio = _mm_div_pd(p_down, p_up);
            // The leakage's C_d·A = max(c_dm r + c_db, 0), (2.23).
            let leakage_area = _mm_max_pd(
                _mm_add_pd(_mm_mul_pd(_mm_set1_pd(c_dm_a_lpp), ratio), _mm_set1_pd(c_db_a_lpp)),
                zero,
            );
            let area = _mm_move_sd(leakage_area, _mm_set_sd(cd_area));
            // A lane flows unless p_up <= 0 or its area is 0 (NaN flows, as in the scalar law).
            let flows = _mm_and_pd(_mm_cmpneq_pd(area, zero), _mm_cmpnle_pd(p_up, zero));
            if _mm_movemask_pd(_mm_and_pd(flows, _mm_cmpunord_pd(ratio, ratio))) != 0 {
                return None;
            }
            let scale = _mm_mul_pd(_mm_mul_pd(area, p_up), _mm_set1_pd(k.inv_sqrt_temperature));
            let choked = _mm_cmple_pd(ratio, _mm_set1_pd(k.critical_ratio));
            let below_one = _mm_sub_pd(one, ratio);
            let outside_band = _mm_cmpge_pd(below_one, _mm_set1_pd(REGULARISATION_RATIO_BAND));
            let tabulated = _mm_andnot_pd(choked, _mm_and_pd(flows, outside_band));
            let in_table = _mm_and_pd(
                _mm_cmpge_pd(ratio, _mm_set1_pd(start)),
                _mm_cmple_pd(ratio, _mm_set1_pd(end)),
            );
            if _mm_movemask_pd(_mm_andnot_pd(in_table, tabulated)) != 0 {
                return None;
            }
            // Piecewise::value: the piece ⌊position⌋ (at most the last), clamped to the table
            // for the lanes that do not use it.
            let position = _mm_mul_pd(_mm_sub_pd(ratio, _mm_set1_pd(start)), _mm_set1_pd(pieces_per_unit));
            let clamped = _mm_max_pd(_mm_min_pd(position, _mm_set1_pd(last_piece)), zero);
            let piece = _mm_cvttpd_epi32(clamped);
            let first = _mm_cvtsi128_si32(piece) as usize;
            let second = _mm_cvtsi128_si32(_mm_shuffle_epi32(piece, 0b01)) as usize;
            let (a, b) = (&coefficients[first], &coefficients[second]);
            let c = |j: usize| _mm_set_pd(b[j], a[j]);
            let u = _mm_sub_pd(
                _mm_mul_pd(_mm_set1_pd(2.0), _mm_sub_pd(position, _mm_cvtepi32_pd(piece))),
                one,
            );
            // polynomial::estrin, operation for operation.
            let u2 = _mm_mul_pd(u, u);
            let u4 = _mm_mul_pd(u2, u2);
            let pair = |low: usize| _mm_add_pd(c(low), _mm_mul_pd(c(low + 1), u));
            let low = _mm_add_pd(pair(0), _mm_mul_pd(u2, pair(2)));
            let high = _mm_add_pd(pair(4), _mm_mul_pd(u2, pair(6)));
            let factor = _mm_add_pd(low, _mm_mul_pd(u4, _mm_add_pd(high, _mm_mul_pd(u4, c(8)))));
            let f2_tabulated = _mm_mul_pd(_mm_sqrt_pd(below_one), factor);
            // The band next to r = 1, rare: band_edge_f2 (1.25 s − 0.25 s³), s = (1 − r)/band.
            let in_band = _mm_andnot_pd(outside_band, _mm_andnot_pd(choked, flows));
            let f2 = if _mm_movemask_pd(in_band) == 0 {
                f2_tabulated
            } else {
                let s = _mm_div_pd(below_one, _mm_set1_pd(REGULARISATION_RATIO_BAND));
                let s = _mm_max_pd(_mm_min_pd(s, one), zero);
                let s3 = _mm_mul_pd(_mm_mul_pd(_mm_mul_pd(_mm_set1_pd(0.25), s), s), s);
                let cubic = _mm_sub_pd(_mm_mul_pd(_mm_set1_pd(1.25), s), s3);
                select(
                    outside_band,
                    f2_tabulated,
                    _mm_mul_pd(_mm_set1_pd(k.band_edge_f2), cubic),
                )
            };
            let unchoked = _mm_mul_pd(_mm_mul_pd(scale, _mm_set1_pd(k.c2)), f2);
            let flow = select(choked, _mm_mul_pd(scale, _mm_set1_pd(k.c1)), unchoked);
            let signed = _mm_and_pd(flows, _mm_mul_pd(sign, flow));
            let mut out = [0.0; 2];
            _mm_storeu_pd(out.as_mut_ptr(), signed);
            Some(out)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// SplitMix64: pressures and areas spread over the law's branches, the same on every run.
    struct Draws(u64);

    impl Draws {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    fn same_bits(packed: [f64; 2], scalar: [f64; 2]) -> bool {
        packed[0].to_bits() == scalar[0].to_bits() && packed[1].to_bits() == scalar[1].to_bits()
    }

    #[test]
    fn the_packed_supply_and_leakage_are_the_scalar_laws_to_the_bit() {
        let (c_dm, c_db) = (-0.0475e-6, 0.0971e-6);
        let mut draws = Draws(29);
        for gas in [
            FlowConstants::new(1.4, 287.0, 293.15),
            FlowConstants::new(1.67, 2077.0, 313.0),
        ] {
            let mut branches = [0usize; 4];
            for case in 0..200_000 {
                let supply = 1e5 + 6e5 * draws.next();
                // Chamber pressures from below the return's to the supply's, and within a
                // few pascals of each other (the band next to r = 1) now and then.
                let p1 = supply * draws.next();
                let p2 = match case % 5 {
                    0 => p1 * (1.0 - 2e-5 * draws.next()),
                    1 => p1,
                    _ => supply * draws.next(),
                };
                let area = match case % 7 {
                    0 => 0.0,
                    _ => 1e-6 * draws.next(),
                };
                let (from, to) = if case % 3 == 0 { (p1, supply) } else { (supply, p1) };
                let packed = mass_flow_and_leakage(&gas, area, from, to, c_dm, c_db, p1, p2);
                let scalar = [
                    mass_flow_inline(&gas, area, from, to),
                    leakage_flow_inline(&gas, c_dm, c_db, p1, p2),
                ];
                assert!(
                    same_bits(packed, scalar),
                    "γ {} area {area:e} from {from} to {to}, p1 {p1} p2 {p2}: {packed:?} against {scalar:?}",
                    gas.gamma
                );
                let ratio = from.min(to) / from.max(to);
                let leak_ratio = p1.min(p2) / p1.max(p2);
                branches[0] += usize::from(area != 0.0 && ratio <= gas.critical_ratio);
                branches[1] += usize::from(area != 0.0 && ratio > gas.critical_ratio);
                branches[2] += usize::from(1.0 - leak_ratio < REGULARISATION_RATIO_BAND && leak_ratio < 1.0);
                branches[3] += usize::from(leak_ratio == 1.0);
            }
            // Every branch of the law was taken many times: choked, unchoked, the band, equal.
            assert!(branches.iter().all(|&n| n > 1_000), "γ {}: {branches:?}", gas.gamma);
        }
    }

    #[test]
    fn what_the_table_does_not_cover_goes_to_the_scalar_law() {
        let (c_dm, c_db) = (-0.0475e-6, 0.0971e-6);
        // A gas whose table is not accurate, NaN and infinite pressures, zero and negative
        // upstream pressures, a NaN area: the pair gives what the scalar laws give.
        let wide = FlowConstants::new(5.0, 287.0, 293.15);
        let air = FlowConstants::new(1.4, 287.0, 293.15);
        let cases = [
            (&wide, 0.5e-6, 6e5, 5e5, 4e5, 3.9e5),
            (&air, 0.5e-6, f64::NAN, 5e5, 4e5, 3.9e5),
            (&air, 0.5e-6, 6e5, 5e5, f64::NAN, 3.9e5),
            (&air, 0.5e-6, f64::INFINITY, 5e5, 4e5, f64::INFINITY),
            (&air, 0.5e-6, 0.0, 0.0, 0.0, 0.0),
            (&air, 0.5e-6, -1e5, -2e5, -3e5, -1e5),
            (&air, f64::NAN, 6e5, 5e5, 4e5, 3.9e5),
            (&air, -0.0, 6e5, 5e5, 4e5, 4e5),
        ];
        for (k, area, from, to, p1, p2) in cases {
            let packed = mass_flow_and_leakage(k, area, from, to, c_dm, c_db, p1, p2);
            let scalar = [
                mass_flow_inline(k, area, from, to),
                leakage_flow_inline(k, c_dm, c_db, p1, p2),
            ];
            let agree = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
            assert!(
                agree(packed[0], scalar[0]) && agree(packed[1], scalar[1]),
                "area {area} from {from} to {to}, p1 {p1} p2 {p2}: {packed:?} against {scalar:?}"
            );
        }
    }
}
