"""fmi2GetFMUstate/SetFMUstate and serialisation: exact replay in process and in a fresh process,
rejection of corrupted serialized states."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2Error

import scenarios
from jetpipe_fmu import initialize

T_SAVE, T_END = 3.0, 5.0
HERE = Path(__file__).resolve().parent


def stack(res):
    return np.stack([res["time"]] + [res[n] for n in scenarios.OUTPUTS])


def assert_identical(a, b, what):
    if np.array_equal(a, b):
        return
    diff = np.nanmax(np.abs(a - b), axis=1)
    pytest.fail(f"{what}: not bit-identical; max abs diff per row (time, {', '.join(scenarios.OUTPUTS)}): {diff}")


@pytest.fixture
def saved(init_fmu, vrs):
    """An instance stepped to T_SAVE, its state there, the serialized state, and the run to T_END."""
    fmu = init_fmu(inputs=scenarios.held_input(0.0))
    scenarios.step_scenario(fmu, vrs, 1e-2, t_stop=T_SAVE, record_start=False)
    state = fmu.getFMUstate()
    blob = fmu.serializeFMUstate(state)
    ref = stack(scenarios.step_scenario(fmu, vrs, 1e-2, t_start=T_SAVE, t_stop=T_END))
    yield fmu, state, blob, ref
    try:
        fmu.freeFMUstate(state)
    except Exception:
        pass


def test_get_set_state_replays_exactly(saved, vrs):
    fmu, state, _, ref = saved
    fmu.setFMUstate(state)
    again = stack(scenarios.step_scenario(fmu, vrs, 1e-2, t_start=T_SAVE, t_stop=T_END))
    assert_identical(again, ref, "re-run after fmi2SetFMUstate")
    # and a second time, to show the state is not consumed by setting it
    fmu.setFMUstate(state)
    third = stack(scenarios.step_scenario(fmu, vrs, 1e-2, t_start=T_SAVE, t_stop=T_END))
    assert_identical(third, ref, "second re-run after fmi2SetFMUstate")


def test_serialized_state_in_fresh_process(saved, unzipdir, tmp_path):
    _, _, blob, ref = saved
    assert len(blob) > 0
    state_file = tmp_path / "state.bin"
    state_file.write_bytes(blob)
    out = tmp_path / "out.npy"
    proc = subprocess.run(
        [sys.executable, str(HERE / "state_worker.py"), str(unzipdir), str(state_file), str(out), repr(T_SAVE), repr(T_END)],
        capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL,
    )
    assert proc.returncode == 0, f"worker failed:\n{proc.stdout}\n{proc.stderr}"
    other = np.load(out)
    assert other.shape == ref.shape
    assert_identical(other, ref, "run restored from the serialized state in a fresh process")
    assert [repr(x) for x in other[1]] == [repr(x) for x in ref[1]]


def corruptions(blob):
    flipped = bytearray(blob)
    flipped[len(flipped) // 2] ^= 0xFF
    rng = np.random.default_rng(20240613)
    return {
        "flipped middle byte": bytes(flipped),
        "truncated to half": blob[: len(blob) // 2],
        "truncated by one byte": blob[:-1],
        "random bytes": rng.bytes(len(blob)),
    }


@pytest.mark.parametrize("kind", ["flipped middle byte", "truncated to half", "truncated by one byte", "random bytes"])
def test_corrupted_state_is_rejected(saved, vrs, kind):
    fmu, state, blob, ref = saved
    bad = corruptions(blob)[kind]
    assert bad != blob
    n = len(fmu.log)
    with pytest.raises(FMICallException) as info:
        new_state = fmu.deSerializeFMUstate(bad)
        fmu.freeFMUstate(new_state)
    assert info.value.status == fmi2Error, f"status {info.value.status}"
    errors = [m for m in fmu.log.since(n) if m.status >= fmi2Error]
    assert errors, f"no error message logged for a {kind} state; log:\n{fmu.log.text(n)}"
    print(f"{kind}: {errors[-1]}")

    # the instance continues from its own state ...
    fmu.setFMUstate(state)
    again = stack(scenarios.step_scenario(fmu, vrs, 1e-2, t_start=T_SAVE, t_stop=T_END))
    assert_identical(again, ref, f"run from the saved state after rejecting a {kind} state")

    # ... and can be reset and used again
    fmu.reset()
    initialize(fmu, vrs, inputs=scenarios.held_input(0.0))
    res = scenarios.step_scenario(fmu, vrs, 1e-2, t_stop=0.5)
    assert np.all(np.isfinite(res["F_act"]))
