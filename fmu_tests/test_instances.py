"""Several instances of one binary, fmi2Reset and fmi2GetRealStatus(fmi2LastSuccessfulTime)."""

import threading

import numpy as np
import pytest
from fmpy.fmi2 import fmi2LastSuccessfulTime

import scenarios
from jetpipe_fmu import initialize

T_STOP = 3.0
STEP = 1e-3

RUNS = {
    "scenario": scenarios.held_input,
    "constant": scenarios.constant_input(1.0, 0.060),
}


def stack(res):
    return np.stack([res[n] for n in scenarios.OUTPUTS])


def run(fmu, vrs, inputs, t_stop=T_STOP, step=STEP):
    initialize(fmu, vrs, inputs=inputs(0.0))
    return stack(scenarios.step_scenario(fmu, vrs, step, t_stop=t_stop, inputs=inputs))


def test_two_instances_in_threads(make_fmu, vrs):
    # one after the other
    sequential = {name: run(make_fmu(), vrs, inputs) for name, inputs in RUNS.items()}
    assert not np.array_equal(sequential["scenario"], sequential["constant"])

    # both at once, each in its own thread (ctypes releases the GIL during FMU calls)
    fmus = {name: make_fmu() for name in RUNS}
    results, errors = {}, {}
    barrier = threading.Barrier(len(RUNS))

    def worker(name):
        try:
            barrier.wait()
            results[name] = run(fmus[name], vrs, RUNS[name])
        except BaseException as e:  # noqa: BLE001 - reported below
            errors[name] = e

    threads = [threading.Thread(target=worker, args=(name,)) for name in RUNS]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=300)
    assert not errors, f"thread errors: {errors}"
    for name in RUNS:
        assert np.array_equal(results[name], sequential[name]), f"{name}: threaded run differs from the sequential one"
        # no message of one instance ended up in the other's log
        assert all(m.instance == fmus[name].instanceName for m in fmus[name].log.messages)


def test_reset_gives_fresh_results(make_fmu, vrs):
    fresh = run(make_fmu(), vrs, scenarios.held_input, t_stop=2.0, step=1e-2)

    fmu = make_fmu()
    first = run(fmu, vrs, scenarios.constant_input(4.0, 0.070), t_stop=2.0, step=1e-2)
    assert not np.array_equal(first, fresh)
    fmu.reset()
    again = run(fmu, vrs, scenarios.held_input, t_stop=2.0, step=1e-2)
    assert np.array_equal(again, fresh), f"after fmi2Reset: max abs diff {np.max(np.abs(again - fresh), axis=1)}"


def test_reset_restores_parameter_defaults(make_fmu, vrs):
    fresh = run(make_fmu(), vrs, scenarios.held_input, t_stop=0.5, step=1e-2)
    fmu = make_fmu()
    fmu.setReal([vrs["P_s"]], [500000.0])
    changed = run(fmu, vrs, scenarios.held_input, t_stop=0.5, step=1e-2)
    assert not np.array_equal(changed, fresh), "setting P_s before initialisation had no effect"
    fmu.reset()
    again = run(fmu, vrs, scenarios.held_input, t_stop=0.5, step=1e-2)
    assert np.array_equal(again, fresh), "fmi2Reset did not restore the parameters' start values"


def test_last_successful_time(init_fmu, vrs):
    fmu = init_fmu(inputs=(2.5, 0.054))
    t = 0.0
    for h in (1e-3, 0.0123, 0.25, 1e-5, 0.1):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t = t + h
        got = fmu.getRealStatus(fmi2LastSuccessfulTime)
        assert got == t, f"fmi2LastSuccessfulTime {got!r}, expected {t!r}"
