"""Invalid inputs, parameters, steps and call sequences are rejected with fmi2Error and a log
message naming the variable and the offending value; the instance can be recovered."""

import math

import numpy as np
import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import fmi2Error

import scenarios
from jetpipe_fmu import initialize, mentions_value

T_BAD = 1.0


def expect_error(fmu, call, *args, **kwargs):
    """Run call, expect FMPy to raise for status fmi2Error; return the messages logged meanwhile."""
    n = len(fmu.log)
    with pytest.raises(FMICallException) as info:
        call(*args, **kwargs)
    assert info.value.status == fmi2Error, f"{info.value.function} returned status {info.value.status}, expected fmi2Error"
    return fmu.log.since(n)


def assert_logged(messages, *needles, value=None):
    errors = [m for m in messages if m.status >= fmi2Error]
    assert errors, f"no error message logged; messages: {[str(m) for m in messages]}"
    text = " | ".join(m.message for m in errors)
    for needle in needles:
        assert needle.lower() in text.lower(), f"log message does not mention {needle!r}: {text}"
    if value is not None:
        assert mentions_value(text, value), f"log message does not show the value {value!r}: {text}"
    print(text)


@pytest.fixture(scope="module")
def reference(unzipdir, model_description, vrs):
    """The standard scenario from T_BAD to T_BAD + 0.5 s on an instance that never saw an error."""
    from jetpipe_fmu import make_slave, release

    fmu = make_slave(unzipdir, model_description)
    try:
        initialize(fmu, vrs, inputs=scenarios.held_input(0.0))
        scenarios.step_scenario(fmu, vrs, 1e-2, t_stop=T_BAD, record_start=False)
        res = scenarios.step_scenario(fmu, vrs, 1e-2, t_start=T_BAD, t_stop=T_BAD + 0.5)
        return np.stack([res[n] for n in scenarios.OUTPUTS])
    finally:
        release(fmu)


@pytest.mark.parametrize(
    "name,value",
    [("v_DA", math.nan), ("v_DA", math.inf), ("x_s", 0.02), ("x_s", math.nan), ("x_s", 0.1)],
    ids=["v_DA-nan", "v_DA-inf", "x_s-0.02", "x_s-nan", "x_s-0.1"],
)
def test_bad_input_rejected_and_recoverable(init_fmu, vrs, reference, name, value):
    fmu = init_fmu(inputs=scenarios.held_input(0.0))
    scenarios.step_scenario(fmu, vrs, 1e-2, t_stop=T_BAD, record_start=False)
    state = fmu.getFMUstate()
    messages = expect_error(fmu, fmu.setReal, [vrs[name]], [value])
    assert_logged(messages, name, value=value)

    # restored with fmi2SetFMUstate, the instance continues exactly as if nothing had happened
    fmu.setFMUstate(state)
    fmu.freeFMUstate(state)
    res = scenarios.step_scenario(fmu, vrs, 1e-2, t_start=T_BAD, t_stop=T_BAD + 0.5)
    got = np.stack([res[n] for n in scenarios.OUTPUTS])
    assert np.array_equal(got, reference), "run after fmi2SetFMUstate differs from an undisturbed run"


def test_bad_input_then_reset(init_fmu, vrs):
    fmu = init_fmu(inputs=(2.5, 0.054))
    fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    expect_error(fmu, fmu.setReal, [vrs["v_DA"]], [math.nan])
    fmu.reset()
    initialize(fmu, vrs, inputs=(2.5, 0.054))
    fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    assert all(math.isfinite(x) for x in fmu.getReal([vrs[n] for n in scenarios.OUTPUTS]))


@pytest.mark.parametrize("h", [0.0, -1e-3])
def test_non_positive_step(init_fmu, vrs, h):
    fmu = init_fmu(inputs=(2.5, 0.054))
    fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    messages = expect_error(fmu, fmu.doStep, currentCommunicationPoint=0.01, communicationStepSize=h)
    assert_logged(messages, "step", value=h)


@pytest.mark.parametrize("name,value", [("P_s", -1e5), ("C_d", -0.5), ("D_cyl", 0.0)])
def test_bad_parameter_before_initialisation(make_fmu, vrs, name, value):
    fmu = make_fmu()
    n = len(fmu.log)
    failed_at = None
    try:
        fmu.setReal([vrs[name]], [value])
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setReal([vrs["v_DA"], vrs["x_s"]], [2.5, 0.054])
        fmu.exitInitializationMode()
    except FMICallException as e:
        failed_at = e
    assert failed_at is not None, f"{name} = {value} was accepted through initialisation"
    assert failed_at.status == fmi2Error, f"{failed_at.function} returned {failed_at.status}"
    print(f"{name} = {value} rejected by {failed_at.function}")
    assert_logged(fmu.log.since(n), name, value=value)

    # the instance can be reset and used with valid parameters
    fmu.reset()
    initialize(fmu, vrs, inputs=(2.5, 0.054))
    fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)


def test_do_step_before_initialisation(make_fmu):
    fmu = make_fmu()
    messages = expect_error(fmu, fmu.doStep, currentCommunicationPoint=0.0, communicationStepSize=0.01)
    assert_logged(messages)


def test_set_fixed_parameter_after_initialisation(init_fmu, vrs):
    fmu = init_fmu(inputs=(2.5, 0.054))
    messages = expect_error(fmu, fmu.setReal, [vrs["P_s"]], [600000.0])
    assert_logged(messages, "P_s")


def test_set_output(init_fmu, vrs):
    fmu = init_fmu(inputs=(2.5, 0.054))
    messages = expect_error(fmu, fmu.setReal, [vrs["F_act"]], [1.0])
    assert_logged(messages, "F_act")


def test_wrong_guid(make_fmu):
    with pytest.raises(Exception, match="Failed to instantiate"):
        make_fmu(guid="{00000000-0000-0000-0000-000000000000}")
