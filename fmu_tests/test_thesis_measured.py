"""Issue 30: presets/thesis_measured.json, the effects that reproduce the thesis's measured
figures, checked through the packaged FMU by independent masters (the Python P controller of
§4.1.1, the open-loop sine dwells of §3.3.2, slow ramps of §3.2.1). The figures are the thesis's
(MODEL.md, §3.2.1, §3.3.2, §4.1.1); the tolerances are the issue's.

Not reproduced, hence not asserted: the jet-pipe step's 0.07 s settling (Fig. 3.11), the
open-loop bandwidth's rise with amplitude (Fig. 3.16) and the offset removed by the feedforward
(§4.1.2); docs/validation.md gives the figures and why."""

import struct

import numpy as np
import pytest

import validation as V
from jetpipe_fmu import make_slave, release
from scenarios import step_scenario
from validation_fixtures import vctx  # noqa: F401  (fixture)

REFERENCE = V.ROOT / "tests" / "reference" / "fmu_outputs_standard.csv"


@pytest.fixture(scope="module")
def preset():
    return V.load_preset()


@pytest.fixture(scope="module")
def pctx(fmu_path, preset):
    ctx = V.FmuContext(fmu_path, preset=preset)
    yield ctx
    ctx.close()


@pytest.fixture(scope="module")
def closed_loop(pctx):
    return {(amp, xs): V.closed_loop_response(pctx, amp, xs, V.CL_FREQS_FAST) for amp, xs in V.CL_CASES}


def test_the_preset_names_only_fmu_parameters_and_the_fmu_accepts_every_value(model_description, preset):
    parameters = {v.name for v in model_description.modelVariables if v.causality == "parameter"}
    assert set(preset) <= parameters, set(preset) - parameters
    assert preset["hysteresis_width"] == pytest.approx(0.16e-3)  # the measured loop (§3.2.1)


def test_the_preset_scales_the_three_identified_flow_constants_by_one_factor(preset, defaults):
    """C_d and the two leakage products move together: the one direction the static fit of
    §3.3.1 cannot see (next test), so Table 3.1's statics stay as identified."""
    scales = [preset[n] / defaults[n] for n in ("C_d", "C_db_A_lpp", "C_dm_A_lpp")]
    assert np.ptp(scales) < 1e-3, scales


def test_one_factor_on_every_orifice_and_leakage_leaves_the_static_force_unchanged(vctx, preset, defaults):
    """Every flow of (2.18)-(2.25) is proportional to its C_d·A, so equilibria (zero net flow in
    each chamber) do not move when all of them scale together."""
    scaled = {n: preset[n] for n in ("C_d", "C_db_A_lpp", "C_dm_A_lpp")}
    v = np.linspace(-2.0, 6.0, 9)
    thesis = V.static_force(vctx, v)["F"]
    with_scale = V.static_force(vctx, v, parameters=scaled)["F"]
    assert np.max(np.abs(with_scale - thesis)) < 1e-6 * np.max(thesis)
    assert np.ptp(thesis) > 50.0  # the grid spans the curve, not only its floor


def test_with_the_preset_the_1_N_closed_loop_bandwidth_is_within_30_percent_of_25_Hz(closed_loop):
    bw = closed_loop[(1.0, 0.054)]["bw_rel_Hz"]
    assert 0.7 * 25.0 <= bw <= 1.3 * 25.0, bw


def test_with_the_preset_the_5_N_closed_loop_bandwidth_is_within_20_percent_of_80_Hz(closed_loop):
    bw = closed_loop[(5.0, 0.054)]["bw_rel_Hz"]
    assert 0.8 * 80.0 <= bw <= 1.2 * 80.0, bw


@pytest.mark.parametrize("amp", [1.0, 5.0])
def test_with_the_preset_the_40_mm_bandwidth_is_within_25_percent_of_the_54_mm_one(closed_loop, amp):
    """Fig. 4.1b: "little difference in dynamic response as a function of stopper position"."""
    at54, at40 = closed_loop[(amp, 0.054)]["bw_rel_Hz"], closed_loop[(amp, 0.040)]["bw_rel_Hz"]
    assert abs(at40 - at54) <= 0.25 * at54, (at54, at40)


def test_with_the_preset_small_inputs_have_the_lower_bandwidth_and_low_frequencies_track(closed_loop):
    """§4.1.1: small inputs show lower bandwidth and more damping; at low frequencies the loop
    is linear (within 1.5 dB of the P loop's k_p k/(1 + k_p k))."""
    small, medium = closed_loop[(1.0, 0.054)], closed_loop[(5.0, 0.054)]
    assert small["bw_rel_Hz"] < 0.5 * medium["bw_rel_Hz"]
    assert small["peak_dB"] - small["low_dB"] < medium["peak_dB"] - medium["low_dB"]
    for d in (small, medium):
        assert d["low_dB"] > -1.5, d["low_dB"]


def test_with_the_preset_the_open_loop_bandwidth_lies_in_the_measured_range_and_rises_with_mean(pctx):
    freqs = np.geomspace(0.05, 20.0, 12)
    bws = [V.open_loop_response(pctx, m, 0.01, freqs)["bw_Hz"] for m in V.MEANS_5]
    assert all(0.8 <= b <= 2.8 for b in bws), bws
    assert bws[-1] > bws[0], bws


def test_with_the_preset_the_slow_jet_pipe_loop_has_branches_0_16_mm_apart(pctx):
    """§3.2.1: the halves of the position/current major loop are ≈ 0.16 mm apart."""
    sep = V.loop_separations(V.ramp_loop(pctx, 0.054, 10.0))["x_jp_m"]
    assert sep == pytest.approx(0.16e-3, rel=0.05)


def test_without_the_preset_the_slow_jet_pipe_loop_has_no_branches(vctx):
    sep = V.loop_separations(V.ramp_loop(vctx, 0.054, 10.0))["x_jp_m"]
    assert abs(sep) < 0.01e-3, sep


def reference_rows():
    lines = REFERENCE.read_text().splitlines()
    return [[struct.unpack("<d", bytes.fromhex(h)[::-1])[0] for h in line.split(",")[1:6]] for line in lines[2:]]


def standard_run(unzipdir, model_description, vrs, set_parameters):
    fmu = make_slave(unzipdir, model_description)
    try:
        fmu.setupExperiment()
        fmu.enterInitializationMode()
        set_parameters(fmu)
        fmu.setReal([vrs["v_DA"], vrs["x_s"]], [2.5, 0.054])
        fmu.exitInitializationMode()
        out = step_scenario(fmu, vrs, 0.01)
    finally:
        release(fmu)
    return np.column_stack([out[n] for n in ("F_act", "P1", "P2", "i", "x_jp")])


def test_with_the_preset_turned_off_in_the_importer_the_fmu_is_the_thesis_model(unzipdir, model_description,
                                                                                 vrs, preset, defaults):
    """An importer that sets the preset and then every one of its parameters back to the model
    description's start value runs the thesis model: the standard scenario's outputs are those
    of an instance that never saw the preset, bit for bit, and the reference outputs of
    tests/reference (made through the C ABI; this master's run of the defaults differs from them
    in the last bits, below 1e-14 of each output's range)."""
    vr = [vrs[n] for n in preset]

    def on_then_off(fmu):
        fmu.setReal(vr, list(preset.values()))
        fmu.setReal(vr, [defaults[n] for n in preset])

    off = standard_run(unzipdir, model_description, vrs, on_then_off)
    untouched = standard_run(unzipdir, model_description, vrs, lambda fmu: None)
    assert np.array_equal(off, untouched)
    want = np.array(reference_rows())
    assert off.shape == want.shape
    scale = np.max(np.abs(want), axis=0)
    assert np.all(np.abs(off - want) <= 1e-12 * scale)


def test_with_the_preset_the_standard_scenario_differs_from_the_reference(unzipdir, model_description, vrs, preset):
    """The converse, so that the previous test can fail: the preset does change the outputs."""
    vr = [vrs[n] for n in preset]
    with_preset = standard_run(unzipdir, model_description, vrs, lambda fmu: fmu.setReal(vr, list(preset.values())))
    want = np.array(reference_rows())
    assert np.max(np.abs(with_preset[:, 0] - want[:, 0])) > 1.0


def test_fmpy_takes_the_preset_file_as_start_values(fmu_path, unzipdir, model_description, vrs, preset):
    """The README's use: fmpy.simulate_fmu(..., start_values=json.load(...)) runs the same model
    as an instance whose parameters this master sets itself."""
    import json

    import fmpy

    with open(V.PRESET_PATH) as f:
        start_values = json.load(f)
    u = np.array([(0.0, 2.5, 0.054), (1.0, 2.5, 0.054)], dtype=[("time", float), ("v_DA", float), ("x_s", float)])
    r = fmpy.simulate_fmu(str(fmu_path), stop_time=1.0, input=u, output_interval=0.01, start_values=start_values,
                          output=["F_act"])
    own = standard_run(unzipdir, model_description, vrs, lambda fmu: fmu.setReal([vrs[n] for n in preset],
                                                                                   list(preset.values())))
    # Both start at the equilibrium of v_DA = 2.5 V, x_s = 54 mm with the preset's parameters.
    assert r["F_act"][0] == pytest.approx(own[0, 0], abs=1e-9)
    thesis = standard_run(unzipdir, model_description, vrs, lambda fmu: None)
    assert abs(r["F_act"][0] - thesis[0, 0]) > 0.5
