"""Issue 3, chapter 3 of the thesis: scenarios 1-5 on the packaged FMU (see docs/validation.md).

Reference values: MODEL.md, table "What the thesis reports, to reproduce"."""

import math

import numpy as np
import pytest

import validation as V
from scenarios import spring_force
from validation_fixtures import vctx  # noqa: F401  (fixture)

T = V.THESIS


def rel(a, b):
    return abs(a - b) / abs(b)


# ---- Scenario 1: current driver, first order with a 1122 Hz corner (§3.1.2, Fig. 3.2) ----


@pytest.fixture(scope="module")
def s1(vctx):
    return V.scenario_1(vctx)


def test_1_current_driver_is_first_order_with_1122_Hz_corner(s1):
    assert rel(s1["f_corner_step_Hz"], T["f_cd_Hz"]) < 0.01, s1["f_corner_step_Hz"]
    assert rel(s1["f_corner_sweep_Hz"], T["f_cd_Hz"]) < 0.01, s1["f_corner_sweep_Hz"]
    # First order: no overshoot, the exponential fits the whole step, -45 degrees at the corner.
    assert s1["overshoot"] < 1e-6 and s1["fit_residual"] < 1e-3
    k = int(np.argmin(np.abs(s1["freqs"] - 1122.0)))
    assert abs(math.degrees(np.angle(s1["resp"][k])) + 45.0) < 1.0
    # Static gain k_cd = 0.04 A/V at low frequency.
    assert rel(abs(s1["resp"][0]), s1["k_cd"] * (1 / math.sqrt(1 + (50 / 1122.0) ** 2))) < 1e-3


# ---- Scenario 2: jet pipe step and third-order fit (§3.2.3, Figs. 3.10, 3.11) ----


@pytest.fixture(scope="module")
def s2(vctx):
    return V.scenario_2(vctx)


def test_2_frequency_response_fit_recovers_thesis_parameters(s2):
    assert rel(s2["omega_1"], T["omega_1"]) < 0.02, s2["omega_1"]
    assert rel(s2["omega_2"], T["omega_2"]) < 0.02, s2["omega_2"]
    assert rel(s2["zeta_2"], T["zeta_2"]) < 0.02, s2["zeta_2"]
    assert s2["fit_rms"] < 0.01  # the third-order model explains the simulated response
    assert rel(s2["K"], s2["K_expected"]) < 0.01  # DC gain = k_m x_jp_sat / F_jp_sat (slope of f3)


def test_2_step_rise_and_settling(s2):
    # Thesis: rise 0.002 s (quoted to one digit: 0-100 % rise between 1.5 and 2.5 ms).
    assert 0.0015 <= s2["rise100_s"] <= 0.0025, s2["rise100_s"]
    # 5 % settling: the thesis's 0.07 s was read off a measured step; the FMU must give what the
    # linear driver + third-order model gives (0.062 s), i.e. it is the thesis model exactly.
    assert rel(s2["settle5_s"], s2["settle5_ref_s"]) < 0.02
    assert 0.05 < s2["settle5_s"] < 0.08
    assert s2["overshoot"] > 0.2  # highly underdamped


# ---- Scenario 3: static force/current loop at 40, 54, 70 mm (§3.3.1, Fig. 3.13) ----


@pytest.fixture(scope="module")
def s3(vctx):
    return V.scenario_3(vctx)


def test_3_static_force_independent_of_stopper_position(s3):
    st = s3["static"]
    a, b, c = (st[x]["F"] for x in V.STOPPERS_3)
    above = (a > 5.0) & (b > 5.0) & (c > 5.0)  # above every spring floor
    assert above.sum() > 40
    assert np.max(np.abs(a - b)[above]) < 1e-3 and np.max(np.abs(c - b)[above]) < 1e-3


def test_3_slow_ramps_agree_across_stopper_positions(s3):
    """Ramps of 0.5 V/s: the curves at the three positions agree within 1 % of the force range."""
    span = s3["F_max"][0.054] - s3["floor"][0.054]
    ref = s3["ramp"][0.054]
    for xs in (0.040, 0.070):
        for leg in ("up", "down"):
            r = s3["ramp"][xs][leg]
            other = np.interp(r[:, 0], ref[leg][:, 0] if leg == "up" else ref[leg][::-1, 0],
                              ref[leg][:, 1] if leg == "up" else ref[leg][::-1, 1])
            above = (r[:, 1] > 5.0) & (other > 5.0)
            assert np.max(np.abs(r[above, 1] - other[above])) < 0.01 * span, (xs, leg)


def test_3_loop_width_is_ramp_lag_not_hysteresis(vctx, s3):
    """The model has no hysteresis: the up/down separation halves when the ramp is twice as slow."""
    def width(r):
        i = np.linspace(-0.2, 0.2, 401)
        return np.max(np.abs(np.interp(i, r["up"][:, 0], r["up"][:, 1])
                             - np.interp(i, r["down"][::-1, 0], r["down"][::-1, 1])))
    w40 = width(s3["ramp"][0.054])
    w80 = width(V.ramp_loop(vctx, 0.054, 2 * s3["t_ramp"]))
    assert w40 > 0.2
    assert 0.4 < w80 / w40 < 0.6, (w40, w80)


def test_3_floor_is_spring_force_and_maximum_is_consistent_with_table_2_1(s3):
    for xs in V.STOPPERS_3:
        assert abs(s3["floor"][xs] - float(spring_force(xs))) < 1e-9
    # Ideal maximum A_p (P_s - P_r) at 551.6 kPa gauge within 2 % of the rated 111.25 N.
    assert rel(s3["F_ideal"], T["F_rated"]) < 0.02
    for xs in V.STOPPERS_3:
        assert s3["F_max"][xs] < s3["F_ideal"]
    # What keeps the model below it is the leakage past the piston: without it the chambers reach
    # supply and return pressure at full command.
    assert abs(s3["F_max_no_leak"] - s3["F_ideal"]) < 1e-3
    # Slope near 45 N ≈ 550 N/A (§4.2.1)
    assert rel(s3["k_static_45N"], T["k_static"]) < 0.05


# ---- Scenario 4: unpressurised rod force = spring law (§3.3.1) ----


@pytest.fixture(scope="module")
def s4(vctx):
    return V.scenario_4(vctx)


def test_4_unpressurised_force_is_spring_law(s4):
    g = s4["grid"]
    compressed = g[:, 0] < V.SPRING_FREE_X_S
    assert np.max(np.abs(g[compressed, 2] - spring_force(g[compressed, 0]))) < 1e-9
    assert np.all(g[~compressed, 2] == 0.0)  # spring free beyond 84.1 mm, no pressure force
    assert rel(s4["slope"], T["k_spring"]) < 1e-6
    assert np.max(np.abs(g[:, 3:5] - s4["P_atm"])) < 1e-6  # no pressure in either chamber


def test_4_spring_law_holds_while_the_stopper_moves(s4):
    m = s4["moving"]
    assert np.max(np.abs(m[:, 2] - spring_force(m[:, 0]))) < 1e-9
    assert np.max(np.abs(m[:, 3:5] - s4["P_atm"])) < 1000.0  # pressures stay within 1 kPa of ambient


# ---- Scenario 5: open-loop F/I frequency response at 54 mm (§3.3.2, Figs. 3.15, 3.16) ----


@pytest.fixture(scope="module")
def s5(vctx):
    return V.scenario_5(vctx)


def test_5_open_loop_bandwidth_in_thesis_range(s5):
    lo, hi = T["open_loop_bw_range_Hz"]
    for group in ("means", "amps"):
        for key, r in s5[group].items():
            assert lo <= r["bw_Hz"] <= hi, (group, key, r["bw_Hz"])
            # low-pass approaching an integrator: -20 dB/decade well above the corner
            slope = (V.db(r["H"][-1]) - V.db(r["H"][-3])) / math.log10(s5["freqs"][-1] / s5["freqs"][-3])
            assert -24.0 < slope < -16.0, (group, key, slope)


def test_5_bandwidth_rises_with_amplitude(s5):
    bw = [s5["amps"][a]["bw_Hz"] for a in V.AMPS_5]
    assert all(b2 > b1 for b1, b2 in zip(bw, bw[1:])), bw


def test_5_bandwidth_versus_mean_follows_the_linearisation(s5):
    """The thesis saw the bandwidth rise with the mean current; in the model it falls between 20 and
    55 N at 54 mm, as the small-signal -3 dB bandwidth of the linearisation does (docs/validation.md)."""
    bw = [s5["means"][m]["bw_Hz"] for m in V.MEANS_5]
    assert all(b2 < b1 for b1, b2 in zip(bw, bw[1:])), bw
    for m in V.MEANS_5:
        lin = V.linearize(s5["F_mean"][m], 0.054)
        assert rel(s5["means"][m]["bw_Hz"], lin["bandwidth_Hz"]) < 0.05, (m, lin["bandwidth_Hz"])
