"""Simulation of the standard scenario: physical bounds, step independence, equilibrium start,
and the tolerance given to fmi2SetupExperiment."""

import numpy as np
import pytest
import fmpy

import scenarios
from jetpipe_fmu import initialize, make_slave, release


def run_steps(unzipdir, model_description, vrs, step, tolerance=None, t_stop=scenarios.T_END,
              inputs=scenarios.held_input):
    fmu = make_slave(unzipdir, model_description)
    try:
        initialize(fmu, vrs, inputs=inputs(0.0), tolerance=tolerance)
        return scenarios.step_scenario(fmu, vrs, step, t_stop=t_stop, inputs=inputs)
    finally:
        release(fmu)


@pytest.fixture(scope="module")
def run_10ms(unzipdir, model_description, vrs):
    return run_steps(unzipdir, model_description, vrs, 1e-2)


@pytest.fixture(scope="module")
def run_100us(unzipdir, model_description, vrs):
    return run_steps(unzipdir, model_description, vrs, 1e-4)


@pytest.fixture(scope="module")
def run_simulate_fmu(unzipdir):
    result = fmpy.simulate_fmu(
        str(unzipdir),
        start_time=0.0,
        stop_time=scenarios.T_END,
        input=scenarios.input_signal(),
        output=list(scenarios.OUTPUTS),
        output_interval=0.01,
    )
    return {name: np.asarray(result[name]) for name in result.dtype.names}


def x_s_during_last_step(times):
    """x_s that was held during the step ending at each output instant (x_s(0) at t = 0)."""
    return np.array([scenarios.held_input(max(t - 1e-6, 0.0))[1] for t in times])


def check_physical(res, defaults, label):
    for name in scenarios.OUTPUTS:
        assert np.all(np.isfinite(res[name])), f"{label}: non-finite {name}"
    P_s, P_r = defaults["P_s"], defaults["P_r"]
    for name in ("P1", "P2"):
        p = res[name]
        assert p.min() >= P_r - 1.0, f"{label}: {name} min {p.min()} below P_r = {P_r}"
        assert p.max() <= P_s + 1.0, f"{label}: {name} max {p.max()} above P_s = {P_s}"
    spring = scenarios.spring_force(
        x_s_during_last_step(res["time"]), defaults["k_spring"], defaults["L_spring0"], defaults["L_s"], defaults["L_p"]
    )
    margin = res["F_act"] - spring
    k = int(np.argmin(margin))
    assert margin[k] >= -1e-9, f"{label}: F_act {res['F_act'][k]} below the spring force {spring[k]} at t = {res['time'][k]}"
    print(f"{label}: F_act {res['F_act'].min():.4f}..{res['F_act'].max():.4f} N, "
          f"P1 {res['P1'].min():.0f}..{res['P1'].max():.0f} Pa, P2 {res['P2'].min():.0f}..{res['P2'].max():.0f} Pa")


def test_standard_scenario_simulate_fmu(run_simulate_fmu, run_10ms, defaults):
    res = run_simulate_fmu
    check_physical(res, defaults, "simulate_fmu")
    # simulate_fmu and the stepping helper do the same thing at 10 ms steps: compare at 10 ms.
    t_ref = run_10ms["time"]
    idx = np.searchsorted(res["time"], t_ref - 1e-9)
    assert np.allclose(res["time"][idx], t_ref, rtol=0, atol=1e-9), "simulate_fmu missed output instants"
    for name in scenarios.OUTPUTS:
        a, b = res[name][idx], run_10ms[name]
        diff = np.max(np.abs(a - b))
        scale = max(np.max(np.abs(b)), 1e-12)
        print(f"simulate_fmu vs stepping, {name}: max abs diff {diff:.3e}")
        assert diff <= 1e-9 * scale, f"{name}: simulate_fmu and the stepping helper differ by {diff}"


def test_standard_scenario_stepping(run_10ms, run_100us, defaults):
    assert len(run_10ms["time"]) == scenarios.N_SAMPLES + 1
    check_physical(run_10ms, defaults, "step 1e-2")
    check_physical(run_100us, defaults, "step 1e-4")


def test_step_independence(run_10ms, run_100us):
    assert np.array_equal(run_10ms["time"], run_100us["time"])
    diff = np.abs(run_10ms["F_act"] - run_100us["F_act"])
    k = int(np.argmax(diff))
    print(f"F_act, step 1e-4 vs 1e-2: max abs diff {diff[k]:.3e} N at t = {run_10ms['time'][k]:.2f} s")
    for name in ("P1", "P2"):
        print(f"{name}, step 1e-4 vs 1e-2: max abs diff {np.max(np.abs(run_10ms[name] - run_100us[name])):.3e} Pa")
    assert diff[k] <= 1e-4, f"F_act depends on the communication step: {diff[k]} N at t = {run_10ms['time'][k]}"


@pytest.mark.parametrize("step", [1e-3, 1e-2])
def test_equilibrium_start(unzipdir, model_description, vrs, step):
    res = run_steps(unzipdir, model_description, vrs, step, t_stop=1.0,
                    inputs=scenarios.constant_input(2.5, 0.054))
    for name in ("F_act", "P1", "P2"):
        y = res[name]
        dev = np.max(np.abs(y - y[0])) / abs(y[0])
        print(f"{name}: start {y[0]!r}, max relative drift over 1 s {dev:.3e}")
        assert dev <= 1e-6, f"{name} drifts from its initial value by {dev:.3e} (relative) with constant inputs"


def test_tolerance_is_honoured(unzipdir, model_description, vrs):
    t_stop = 3.0
    ref = run_steps(unzipdir, model_description, vrs, 1e-2, tolerance=1e-9, t_stop=t_stop)
    tight = run_steps(unzipdir, model_description, vrs, 1e-2, tolerance=1e-8, t_stop=t_stop)
    loose = run_steps(unzipdir, model_description, vrs, 1e-2, tolerance=1e-3, t_stop=t_stop)
    err_tight = np.max(np.abs(tight["F_act"] - ref["F_act"]))
    err_loose = np.max(np.abs(loose["F_act"] - ref["F_act"]))
    print(f"F_act error against tolerance 1e-9: {err_tight:.3e} N at 1e-8, {err_loose:.3e} N at 1e-3")
    assert not np.array_equal(loose["F_act"], tight["F_act"]), "tolerance 1e-3 and 1e-8 give identical results"
    assert err_tight < err_loose, "a tighter tolerance is not more accurate"


def test_start_from_given_pressures(init_fmu, vrs):
    """start_at_equilibrium = false: the chambers start at P1_start and P2_start and then move."""
    fmu = init_fmu(inputs=(2.5, 0.054), booleans={"start_at_equilibrium": False},
                   parameters={"P1_start": 200000.0, "P2_start": 150000.0})
    P1, P2 = fmu.getReal([vrs["P1"], vrs["P2"]])
    assert (P1, P2) == (200000.0, 150000.0), f"initial pressures {P1}, {P2}"
    res = scenarios.step_scenario(fmu, vrs, 1e-2, t_stop=0.5, inputs=scenarios.constant_input(2.5, 0.054))
    assert abs(res["P1"][-1] - 200000.0) > 1000.0, "P1 does not move from a non-equilibrium start"
