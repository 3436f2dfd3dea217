"""Model Exchange through FMPy's CVODE at a range of tolerances (issue 80): the input signals
that reach each regime, the runs, and CVODE's work. Used by `test_tolerance_sweep.py` (a
subset) and `scripts/bench_tolerance.sh` (the whole sweep).

Two ways to give FMPy 0.3.32 an input, and what its Model Exchange loop does with each:

* **held** (`hold=True`): each sample is held until the next (a zero-order hold, what a D/A
  converter gives and what Co-Simulation does between communication points), written as two
  rows at each sample time. FMPy makes every change an input event: the input is constant
  between events, and the right-hand side is a function of time and state.
* **interpolated** (`hold=False`): one row per sample, which FMPy interpolates linearly. Its
  CVODE loop sets the inputs only in the root function (`CVodeSolver.g`) and after each
  output step, not in the right-hand side (`CVodeSolver.f`): a derivative at time t is
  evaluated with the input of the last root-function call, up to a step earlier. CVODE's
  error test sees that as an error it cannot reduce but by shortening the step; the current
  driver (7050 rad/s, driven by v_DA) makes it the limit.
* **smooth** (`model_exchange(..., law=...)`): the input's own law (not samples) set at the
  time of each right-hand side and root function, as a Modelica tool's generated equations
  compute a source: how the model itself is measured, with no input event and no kink. It is
  compared with Co-Simulation of the law held every `HOLD` s after delaying it by `HOLD`/2
  (`delayed`): to first order a zero-order hold is a delay of half its period.
"""

from __future__ import annotations

import io
import json
import math
import time as wall_clock
from contextlib import contextmanager, redirect_stdout
from ctypes import POINTER, byref, c_double, c_long, c_uint, c_void_p

import fmpy
import fmpy.sundials as sundials
import numpy as np
from fmpy.sundials.libraries import sundials_cvode
from pathlib import Path

OUTPUTS = ["F_act", "P1", "P2", "i", "x_jp", "F_meas", "P1_meas", "P2_meas"]
HOLD = 1e-4  # s: the inputs' sample period
DTYPE = [("time", np.float64), ("v_DA", np.float64), ("x_s", np.float64)]

sundials_cvode.CVodeGetNumSteps.argtypes = [c_void_p, POINTER(c_long)]
sundials_cvode.CVodeGetNumSteps.restype = int

# The gas volumes behind restrictions and the lagging stopper mount: the states beyond (4.1).
VOLUMES_AND_MOUNT = {
    "supply_restriction_area": 2e-6, "supply_plenum_volume": 5e-6,
    "port_restriction_area_1": 0.5e-6, "port_line_volume_1": 1e-6,
    "stopper_compliance": 2e-5, "stopper_mount_lag": 2e-3,
}


def _v_slow_sine(t, t_end):
    """The issue's 2 Hz sine about 2.5 V."""
    return 2.5 + math.sin(2 * math.pi * 2.0 * t), 0.054


def _v_fast_sine(t, t_end):
    """40 Hz, ±3 V about 0.5 V: the jet pipe across its centre (a tangency of the orifice
    geometry)."""
    return 0.5 + 3.0 * math.sin(2 * math.pi * 40.0 * t), 0.054


def _v_chirp(t, t_end):
    """1 to 100 Hz over the run (linear chirp), ±3 V about 0.5 V."""
    f0, f1 = 1.0, 100.0
    return 0.5 + 3.0 * math.sin(2 * math.pi * (f0 * t + (f1 - f0) * t * t / (2 * t_end))), 0.054


FULL_COMMAND = 9.99


def _v_full_steps(t, t_end):
    """Full-scale steps, switching every 50 ms: the jet pipe over a port, chamber 1 towards the
    supply and chamber 2 towards the return, then the other way. ±9.99 V, as the figures of
    docs/importing.md were measured (the FMU now takes FMPy's rounding of ±10 V, 10.000000000000002
    V at some instants, as the range's end: test_tolerance_sweep.py's last test)."""
    return (FULL_COMMAND if int(t / 0.05) % 2 == 0 else -FULL_COMMAND), 0.054


def _v_preset_sine(t, t_end):
    """20 Hz, ±1.5 V about 2.5 V: the static tip position sweeps 0.22 mm peak to peak, beyond
    the measured preset's 0.16 mm loop, and the current reverses twice a period (where the
    preset's hysteresis memory moves)."""
    return 2.5 + 1.5 * math.sin(2 * math.pi * 20.0 * t), 0.054


def _v_preset_sine_and_steps(t, t_end):
    """The 20 Hz sine plus ±1 V steps every 30 ms: the current reverses at some of the steps
    too."""
    step = 1.0 if int(t / 0.03) % 2 == 0 else -1.0
    return _v_preset_sine(t, t_end)[0] + step, 0.054


def _v_moving_stopper(t, t_end):
    """The stopper from 54 mm to 30 mm, to 78 mm and back at 5 Hz under −0.3 V, where the
    pressure force is near the spring's: the force crosses the spring floor (2.38) both ways,
    and the compression drives chamber 1 above the supply (its supply flow reverses, P1/P_s
    through 1) and chamber 2's pressure above chamber 1's and back (the leakage reverses)."""
    return -0.3, 0.054 - 0.024 * math.sin(2 * math.pi * 5.0 * t)


SIGNALS = {
    "slow_sine": _v_slow_sine,
    "fast_sine": _v_fast_sine,
    "chirp": _v_chirp,
    "full_steps": _v_full_steps,
    "moving_stopper": _v_moving_stopper,
    "volumes_and_mount": _v_slow_sine,
    # the compliant stopper's law switches in the right-hand side where the force meets the
    # spring floor (event indicator z0): the moving stopper with the volumes and the mount
    "moving_stopper_volumes": _v_moving_stopper,
    # presets/thesis_measured.json, its Bouc-Wen hysteresis among its terms
    "measured_preset": _v_preset_sine_and_steps,
    "measured_preset_sine": _v_preset_sine,
    # the lags and second-order filters that are states of Model Exchange (`LAGS_AND_FILTERS`)
    "command_lag": _v_preset_sine_and_steps,
    "command_filter": _v_preset_sine_and_steps,
    "transducers": _v_preset_sine_and_steps,
    "transport_delay_pade": _v_preset_sine_and_steps,
}

# The command stage's lag, its filter (each alone: with both on, Co-Simulation feeds the
# filter the lag's output held over each communication step, see docs/importing.md), the
# transducers' lags and filters, and the transport delay's Pade chain, as start values.
LAGS_AND_FILTERS = {
    "command_lag": {"command_lag": 3e-3},
    "command_filter": {"command_filter_frequency": 150.0, "command_filter_damping": 0.5},
    "transducers": {"force_sensor_lag": 2e-3, "force_sensor_filter_frequency": 200.0,
                    "force_sensor_filter_damping": 0.4, "p1_sensor_lag": 3e-3,
                    "p2_sensor_filter_frequency": 60.0},
    # a 1 ms transport delay, in Model Exchange as a chain of eight Pade sections (Co-Simulation
    # ignores the count and keeps its exact delay)
    "transport_delay_pade": {"command_delay": 1e-3, "command_delay_pade_sections": 8},
}

PRESET = json.loads((Path(__file__).resolve().parent.parent / "presets" / "thesis_measured.json").read_text())


def delayed(law, delay: float = HOLD / 2):
    """`law` delayed by `delay` (held at its start before): what a zero-order hold of period
    2·`delay` gives to first order."""
    return lambda t, t_end: law(max(t - delay, 0.0), t_end)


def start_values(name: str) -> dict:
    if name.startswith("measured_preset"):
        return dict(PRESET)
    if name in LAGS_AND_FILTERS:
        return dict(LAGS_AND_FILTERS[name])
    return dict(VOLUMES_AND_MOUNT) if name in ("volumes_and_mount", "moving_stopper_volumes") else {}


def signal(name: str, t_end: float, sample: float = HOLD, hold: bool = True) -> np.ndarray:
    """The inputs of `name` sampled every `sample` s over [0, t_end], held (two rows at each
    sample time where a value changes: an input event there and nowhere else) or one row per
    sample (interpolated by FMPy)."""
    law = SIGNALS[name]
    n = int(round(t_end / sample))
    values = [law(k * sample, t_end) for k in range(n + 1)]
    if not hold:
        return np.array([(k * sample, *values[k]) for k in range(n + 1)], dtype=DTYPE)
    rows = [(0.0, *values[0])]
    for k in range(1, n):
        if values[k] != values[k - 1]:
            rows.append((k * sample, *values[k - 1]))
            rows.append((k * sample, *values[k]))
    rows.append((t_end, *values[n - 1]))
    return np.array(rows, dtype=DTYPE)


class Work:
    """CVODE's work over a run: accepted steps, right-hand sides (every `fmi2GetDerivatives`,
    the difference-quotient Jacobian's included) and restarts (events)."""

    def __init__(self):
        self.steps = 0
        self.rhs = 0
        self.restarts = 0
        self._since_restart = 0


@contextmanager
def counting(law=None, t_end=None, value_references=None):
    """Count CVODE's work in FMPy's Model Exchange runs made inside; with `law`, set v_DA and
    x_s to `law(t, t_end)` in every right-hand side and root function, at their own time t, and
    at the time each step reaches, where FMPy reads the outputs."""
    work = Work()
    solver = sundials.CVodeSolver
    original = (solver.f, solver.g, solver.step, solver.reset)

    def set_inputs(self, t):
        if law is not None:
            fmu = self.input.fmu
            values = (c_double * 2)(*law(t, t_end))
            refs = (c_uint * 2)(*value_references)
            if hasattr(fmu, "fmi3SetFloat64"):
                fmu.fmi3SetFloat64(fmu.component, refs, 2, values, 2)
            else:
                fmu.fmi2SetReal(fmu.component, refs, 2, values)

    def f(self, t, y, ydot, user_data):
        work.rhs += 1
        set_inputs(self, t)
        return original[0](self, t, y, ydot, user_data)

    def g(self, t, y, gout, user_data):
        set_inputs(self, t)
        return original[1](self, t, y, gout, user_data)

    def step(self, t, t_next):
        try:
            reached = original[2](self, t, t_next)
            # the inputs at the time reached, where FMPy reads the outputs and the states
            set_inputs(self, reached[2])
            return reached
        finally:
            n = c_long(0)
            sundials_cvode.CVodeGetNumSteps(self.cvode_mem, byref(n))
            work._since_restart = n.value

    def reset(self, time):
        work.steps += work._since_restart
        work._since_restart = 0
        work.restarts += 1
        return original[3](self, time)

    solver.f, solver.g, solver.step, solver.reset = f, g, step, reset
    try:
        yield work
    finally:
        solver.f, solver.g, solver.step, solver.reset = original
        work.steps += work._since_restart
        work._since_restart = 0


def _simulate(fmu, **kwargs):
    # FMPy prints a warning for the input a_s that no signal gives (it stays at its start, 0)
    with redirect_stdout(io.StringIO()):
        return fmpy.simulate_fmu(str(fmu), output=OUTPUTS, **kwargs)


def model_exchange(fmu, inputs, t_end, rtol, interval=1e-3, start=None, law=None):
    """FMPy's CVODE on the Model Exchange interface: (result or None, error text, Work, wall s).
    `inputs` as FMPy takes them, or `law` (a function of t and t_end giving v_DA and x_s) set
    at the time of each right-hand side (the smooth way, see the module's text)."""
    start = dict(start or {})
    refs = None
    if law is not None:
        md = fmpy.read_model_description(str(fmu))
        names = {v.name: v.valueReference for v in md.modelVariables}
        refs = (names["v_DA"], names["x_s"])
        start["v_DA"], start["x_s"] = law(0.0, t_end)
    began = wall_clock.perf_counter()
    with counting(law, t_end, refs) as work:
        try:
            result = _simulate(fmu, fmi_type="ModelExchange", solver="CVode", stop_time=t_end, input=inputs,
                               output_interval=interval, relative_tolerance=rtol, record_events=True,
                               start_values=start)
            error = ""
        except Exception as e:  # CVODE's failures arrive as exceptions
            result, error = None, str(e)
    return result, error, work, wall_clock.perf_counter() - began


def co_simulation(fmu, inputs, t_end, interval, start=None):
    return _simulate(fmu, fmi_type="CoSimulation", stop_time=t_end, input=inputs, output_interval=interval,
                     start_values=dict(start or {}))


def before_events(me, times):
    """The rows of `me` at `times`, the first of each instant (the value before its event):
    FMPy's Co-Simulation records an output at an input change before the new input acts."""
    idx = np.searchsorted(me["time"], times - 1e-12, side="left")
    idx = np.minimum(idx, len(me) - 1)
    assert np.allclose(me["time"][idx], times, atol=1e-9, rtol=0), "Model Exchange lacks an output instant"
    return me[idx]


def force_rms(cs, me):
    return float(np.sqrt(np.mean((cs["F_act"] - before_events(me, cs["time"])["F_act"]) ** 2)))
