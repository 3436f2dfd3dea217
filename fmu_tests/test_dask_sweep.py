"""examples/dask_sweep.py on a 2-worker LocalCluster gives bitwise the figures of a plain
serial FMPy loop over fresh instances (scenarios.step_scenario), applies every run's
parameters, and reports a parameter the FMU rejects by name and value."""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import pytest

import scenarios
from jetpipe_fmu import initialize

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
sys.path.insert(0, str(EXAMPLES))

import dask_sweep  # noqa: E402

DURATION = 2.0  # s of the standard scenario per run: short, but both sines and a stopper move
C_D = [0.6, 0.65, 0.7, 0.75]

# Each scheduler also serves HTTP (on 127.0.0.1, as every port here); a second cluster finds
# 8787 taken and moves to another port, with this warning.
pytestmark = pytest.mark.filterwarnings("ignore:Port 8787 is already in use")


@pytest.fixture(scope="module")
def client():
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       host="127.0.0.1", dashboard_address=None)
    c = distributed.Client(cluster)
    # The workers import dask_sweep by name, as examples/dask_sweep.py arranges for itself.
    c.upload_file(dask_sweep.__file__)
    yield c
    c.close()
    cluster.close()


def serial_figures(make_fmu, vrs, params):
    """The standard scenario on a fresh instance, stepped by the test suite's own loop."""
    fmu = make_fmu()
    initialize(fmu, vrs, inputs=(scenarios.v_da_sample(0), scenarios.x_s_sample(0)), parameters=params,
               stop_time=DURATION)
    r = scenarios.step_scenario(fmu, vrs, scenarios.SAMPLE, t_stop=DURATION, outputs=("F_act", "P1", "P2"))
    return [float(f) for f in r["F_act"]], float(r["P1"][-1]), float(r["P2"][-1])


def test_cluster_sweep_equals_serial_loop(client, fmu_path, make_fmu, vrs):
    data = fmu_path.read_bytes()
    digest = dask_sweep.fmu_digest(data)
    fmu_ref = client.scatter(data, broadcast=True)
    points = dask_sweep.grid_points([("C_d", C_D)])
    results, _ = dask_sweep.run_sweep(client, digest, fmu_ref, points + points, DURATION, scenarios.SAMPLE, trace=True)
    # Worker processes, not this one; 8 tasks on 2 workers, so at least one worker reused its
    # instance (fmi2Reset) 3 times. (Which worker ran what is the scheduler's choice.)
    pids = {r["pid"] for r in results}
    assert os.getpid() not in pids and 1 <= len(pids) <= 2, pids

    for k, p in enumerate(points):
        forces, p1, p2 = serial_figures(make_fmu, vrs, p)
        for r in (results[k], results[k + len(points)]):
            assert r["params"] == p
            assert r["F_act"] == forces, f"C_d = {p['C_d']}: force trace differs from the serial loop"
            assert (r["final_P1"], r["final_P2"]) == (p1, p2)
            assert r["final_F_act"] == forces[-1]
            assert r["max_F_act"] == max(forces) and r["min_F_act"] == min(forces)
            assert math.isclose(r["rms_F_act"], math.sqrt(sum(f * f for f in forces) / len(forces)), rel_tol=1e-12)

    # Each run's C_d was applied: more discharge, more force, strictly.
    rms = [r["rms_F_act"] for r in results[: len(points)]]
    assert all(a < b for a, b in zip(rms, rms[1:])), rms


def test_rejected_parameter_is_named(client, fmu_path):
    data = fmu_path.read_bytes()
    digest = dask_sweep.fmu_digest(data)
    with pytest.raises(ValueError) as e:
        dask_sweep.run_sweep(client, digest, str(fmu_path), [{"C_d": -0.5}], 0.1, scenarios.SAMPLE)
    assert "C_d" in str(e.value) and "-0.5" in str(e.value), str(e.value)
    with pytest.raises(ValueError, match="'Cd' is not a Real parameter"):
        dask_sweep.parse_param("Cd=0.6:0.7:3", {"C_d"})
    with pytest.raises(ValueError, match="C_d = 'x' is not a number"):
        dask_sweep.parse_param("C_d=0.6,x", {"C_d"})


def test_script_prints_speedup(fmu_path, capsys):
    """The command line end to end: its own LocalCluster, the 1-worker comparison."""
    pytest.importorskip("distributed")
    rc = dask_sweep.main(["--fmu", str(fmu_path), "--param", "C_d=0.6:0.75:4", "--duration", "1"])
    out = capsys.readouterr().out
    assert rc == 0, out
    for expected in ("runs/s", "speed-up", "parallel efficiency", "bit-identical to the 2-worker figures: yes"):
        assert expected in out, out
