"""Run dist/AntagonisticJoint.ssp through FMPy's SSP master, and measure what comes out.

The master is FMPy's own `fmpy.ssp.simulation.simulate_ssp` (a fixed-step Jacobi master: every
FMU steps from the outputs of the others at the start of the step), with the parameter set that
the .ssp binds on its components (`simulate_ssp` reads no binding itself; it applies the
`parameter_set` it is given before each FMU's initialisation). One thing is changed, and only
for the duration of a call. FMPy 0.3.32 sets every connector to 0.0 before it instantiates the
FMUs, never reads an output after initialisation, and applies the connections only after every
component has stepped, so in the first step every connected input is set to 0.0, whatever the
.ssd holds (connector start values, bindings, the order of components or connections). That
would put the actuators' stoppers at x_s = 0 m, outside their cylinders, and the actuator
refuses it (fmi2SetReal returns fmi2Error and FMPy raises): no .ssd or FMU change can avoid
that without accepting an invalid x_s, which the actuator must not
(`test_ssp_masters.py::test_fmpy_unpatched_hands_zero_to_the_stoppers_and_the_actuator_refuses_it`
shows the unpatched run stopping there and nowhere else). `connectors_start_at_fmu_values`
wraps FMPy's `instantiate_fmu` so that after each FMU's initialisation its connectors hold the
FMU's own values (inputs: the start values the parameter set gave them; outputs: the initial
outputs), as a master that propagates initial values does. Everything else,
including the stepping and the connection order, is FMPy's.

The .ssp steps its reference by itself (the controller's theta_step at t_step). For other
references, `simulate(theta_ref, ...)` sets theta_step to 0 and sets the controller's theta_ref
(no connector of the .ssp) to theta_ref(t) of the previous step's start (0 in the first step)
before each controller step, which is what FMPy did when the reference was a system input.
"""

from __future__ import annotations

import contextlib
import os
import time as _time
from pathlib import Path

import numpy as np
import fmpy.ssp.simulation as ssp_simulation
from fmpy.ssp.ssd import Parameter, ParameterSet, read_ssd

REPO = Path(__file__).resolve().parents[2]
STEP_SIZE = 1e-3


def default_ssp_path() -> Path:
    env = os.environ.get("JETPIPE_SSP")
    return Path(env) if env else REPO / "dist" / "AntagonisticJoint.ssp"


@contextlib.contextmanager
def connectors_start_at_fmu_values():
    original = ssp_simulation.instantiate_fmu

    def instantiate(component, *args, **kwargs):
        original(component, *args, **kwargs)
        for connector in component.connectors:
            connector.value = ssp_simulation.get_value(component, connector.name)

    ssp_simulation.instantiate_fmu = instantiate
    try:
        yield
    finally:
        ssp_simulation.instantiate_fmu = original


def parameter_set(ssp, overrides=None):
    """The start values the .ssp binds on its components, as the one parameter set FMPy's
    `simulate_ssp` takes ("component.name" = value), with `overrides` ({"component.name": value})."""
    ssd = read_ssd(str(ssp))
    pset = ParameterSet(name="start", parameters=[])
    for component in ssd.system.elements:
        for binding in component.parameterBindings:
            for values in binding.parameterValues:
                for p in values.parameters:
                    pset.parameters.append(Parameter(name=f"{component.name}.{p.name}", type=p.type, value=p.value))
    for name, value in (overrides or {}).items():
        for p in pset.parameters:
            if p.name == name:
                p.value = str(value)
                break
        else:
            pset.parameters.append(Parameter(name=name, type="Real", value=str(value)))
    return pset


@contextlib.contextmanager
def controller_reference(theta_ref, step_size):
    """Drive controller.theta_ref with theta_ref(t - step_size) before each controller step."""
    if theta_ref is None:
        yield
        return
    original = ssp_simulation.do_step

    def do_step(component, time, h):
        if component.name == "controller":
            value = theta_ref(time - step_size) if time >= step_size * 0.5 else 0.0
            ssp_simulation.set_value(component, "theta_ref", value)
        return original(component, time, h)

    ssp_simulation.do_step = do_step
    try:
        yield
    finally:
        ssp_simulation.do_step = original


def simulate(theta_ref, stop_time, ssp=None, step_size=STEP_SIZE, overrides=None):
    """Simulate the system with the joint reference `theta_ref(t)`, or with the .ssp's own step
    if `theta_ref` is None.

    Returns (result, seconds): FMPy's structured array (one row per step; the outputs in a row
    are those at the END of the step, t + step_size) and the wall time of the call.
    """
    ssp = ssp or default_ssp_path()
    if theta_ref is not None:
        overrides = {"controller.theta_step": 0.0, **(overrides or {})}
    pset = parameter_set(ssp, overrides)
    started = _time.perf_counter()
    with connectors_start_at_fmu_values(), controller_reference(theta_ref, step_size):
        result = ssp_simulation.simulate_ssp(str(ssp), stop_time=stop_time, step_size=step_size, parameter_set=pset)
    return result, _time.perf_counter() - started


def output_time(result, step_size=STEP_SIZE):
    """The time of the outputs in each row (FMPy records them after the step)."""
    return result["time"] + step_size


def step_metrics(t, theta, t_step, theta0, theta1):
    """Overshoot (% of the step), 10-90 % rise time, 5 % settling time after t_step, final error."""
    after = t >= t_step
    ts, y = t[after] - t_step, theta[after]
    span = theta1 - theta0
    overshoot = max(0.0, (np.max(y) - theta1) / span * 100.0)
    rise = ts[np.argmax(y >= theta0 + 0.9 * span)] - ts[np.argmax(y >= theta0 + 0.1 * span)]
    outside = np.nonzero(np.abs(y - theta1) > 0.05 * abs(span))[0]
    settling = ts[outside[-1] + 1] if len(outside) and outside[-1] + 1 < len(ts) else (0.0 if not len(outside) else np.inf)
    tail = ts >= ts[-1] - 0.1
    final_error = float(np.mean(y[tail]) - theta1)
    return {"overshoot_pct": overshoot, "rise_s": rise, "settling_s": settling, "final_error_rad": final_error}


def sine_response(t, y, f, t_from):
    """Amplitude, phase (rad) and mean of the component of y at f, by least squares over whole
    periods from t_from to the end."""
    periods = int((t[-1] - t_from) * f)
    t_end = t_from + periods / f
    m = (t >= t_from) & (t < t_end)
    w = 2 * np.pi * f
    basis = np.column_stack([np.sin(w * t[m]), np.cos(w * t[m]), np.ones(m.sum())])
    (a, b, c), *_ = np.linalg.lstsq(basis, y[m], rcond=None)
    return float(np.hypot(a, b)), float(np.arctan2(b, a)), float(c)


def frequency_point(f, amplitude=0.1, ssp=None, settle=0.4, periods=2, offset=0.0, step_size=STEP_SIZE):
    """θ/θ_ref at f: gain, phase (deg), the run, its wall time."""
    stop = settle + periods / f
    ref = lambda t: offset + amplitude * np.sin(2 * np.pi * f * t)  # noqa: E731
    result, seconds = simulate(ref, stop, ssp=ssp, step_size=step_size)
    t = output_time(result, step_size)
    # The reference as it was at those times (not as the controller saw it one step earlier).
    a_ref, p_ref, _ = sine_response(t, ref(t), f, settle)
    a, p, _ = sine_response(t, result["joint.theta"], f, settle)
    phase = np.degrees(p - p_ref)
    phase = (phase + 180.0) % 360.0 - 180.0
    return a / a_ref, phase, result, seconds


def bandwidth(frequencies, gains):
    """The first frequency where the gain falls below 1/√2, interpolated linearly in dB
    between the measured points (None if it never does)."""
    db = 20 * np.log10(np.asarray(gains))
    target = -20 * np.log10(np.sqrt(2))
    for k in range(1, len(frequencies)):
        if db[k] < target <= db[k - 1]:
            f0, f1 = frequencies[k - 1], frequencies[k]
            return f0 + (f1 - f0) * (db[k - 1] - target) / (db[k - 1] - db[k])
    return None
