"""The command stage's and the transducers' lags and second-order filters in Model Exchange
(issue 80): continuous states whose rates are the equations Co-Simulation solves in closed
form over each communication step. FMPy's CVODE at relative tolerances 1e-4 to 1e-8, both
archives, follows Co-Simulation within the input hold (0.02 N RMS, and 100 Pa for a pressure,
0.02 N over the piston area; inputs every 0.1 ms, held as a D/A converter holds them) on a
20 Hz sine with ±1 V steps every 30 ms (`tolerance_sweep.LAGS_AND_FILTERS`). The transport
delay, which is not an ODE, as its closest state form: a chain of eight Padé sections
(`command_delay_pade_sections`, Model Exchange only) against Co-Simulation's exact delay.
"""

from __future__ import annotations

import numpy as np
import pytest

import tolerance_sweep as ts
from test_tolerance_sweep import RMS_LIMIT_N, T_END, archive_path, reference

PRESSURE_LIMIT_PA = 100.0  # RMS_LIMIT_N over the piston area, 1.98 cm²


def rms(cs, me, name):
    return float(np.sqrt(np.mean((cs[name] - ts.before_events(me, cs["time"])[name]) ** 2)))


def run(archive, name, rtol):
    inputs = ts.signal(name, T_END, ts.HOLD, hold=True)
    me, error, work, wall = ts.model_exchange(archive_path(archive), inputs, T_END, rtol,
                                              start=ts.start_values(name))
    assert me is not None, f"{archive} {name} rtol {rtol:g}: {error}"
    assert me["time"][-1] == pytest.approx(T_END, abs=1e-9)
    cs = reference(archive, name)
    errors = {k: rms(cs, me, k) for k in ("F_act", "F_meas", "P1_meas", "P2_meas")}
    print(f"{archive} {name} rtol {rtol:g}: RMS ME - CS " + ", ".join(f"{k} {v:.2e}" for k, v in errors.items())
          + f"; {work.steps / T_END:.0f} steps/s, {work.rhs / T_END:.0f} RHS/s, {wall:.1f} s")
    return errors


@pytest.mark.parametrize("archive", ["fmi2", "fmi3"])
@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
@pytest.mark.parametrize("name", ["command_lag", "command_filter"])
def test_the_command_stage_s_lag_or_filter_in_model_exchange_follows_co_simulation_within_the_input_hold(
        archive, rtol, name):
    errors = run(archive, name, rtol)
    assert errors["F_act"] <= RMS_LIMIT_N and errors["F_meas"] <= RMS_LIMIT_N


@pytest.mark.parametrize("archive", ["fmi2", "fmi3"])
@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_the_transducers_lags_and_filters_in_model_exchange_follow_co_simulation_within_the_input_hold(
        archive, rtol):
    errors = run(archive, "transducers", rtol)
    assert errors["F_meas"] <= RMS_LIMIT_N
    assert errors["P1_meas"] <= PRESSURE_LIMIT_PA and errors["P2_meas"] <= PRESSURE_LIMIT_PA


@pytest.mark.parametrize("archive", ["fmi2", "fmi3"])
@pytest.mark.parametrize("rtol", [1e-4, 1e-6, 1e-8])
def test_the_transport_delay_as_a_pade_chain_in_model_exchange_follows_co_simulation_s_exact_delay(archive, rtol):
    errors = run(archive, "transport_delay_pade", rtol)
    assert errors["F_act"] <= RMS_LIMIT_N


@pytest.mark.parametrize("name, output, limit", [("transport_delay_pade", "F_act", RMS_LIMIT_N),
                                                 ("command_lag", "F_act", RMS_LIMIT_N),
                                                 ("command_filter", "F_act", RMS_LIMIT_N),
                                                 ("transducers", "F_meas", RMS_LIMIT_N),
                                                 ("transducers", "P1_meas", PRESSURE_LIMIT_PA),
                                                 ("transducers", "P2_meas", PRESSURE_LIMIT_PA)])
def test_each_lag_or_filter_moves_its_output_by_far_more_than_the_agreement_asked_for(name, output, limit):
    """Co-Simulation with and without the terms differ by over ten times the limit: a Model
    Exchange run that dropped them would fail the tests above."""
    held = ts.signal(name, T_END, ts.HOLD, hold=True)
    plain = ts.co_simulation(archive_path("fmi2"), held, T_END, ts.HOLD)[:: int(round(1e-3 / ts.HOLD))]
    difference = rms(reference("fmi2", name), plain, output)
    print(f"{name}: {output} RMS, Co-Simulation with - without: {difference:.3g}")
    assert difference > 10 * limit
