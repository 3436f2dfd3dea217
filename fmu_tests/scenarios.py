"""The standard scenario of the jet-pipe actuator FMU, and a helper that steps an FMU through it.

Standard scenario: 10 s; the inputs change only at t_k = 0.01*k (k = 0..999) and are held
until the next sample:

    v_DA(t_k) = 2.5 + 3.0*sin(2*pi*0.3*t_k) + 0.5*sin(2*pi*6*t_k)   [V]
    x_s(t_k)  = 0.054 + 0.01*sin(2*pi*0.1*t_k)                      [m]
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

T_END = 10.0
SAMPLE = 0.01
N_SAMPLES = 1000  # k = 0..999

OUTPUTS = ("F_act", "P1", "P2", "i", "x_jp")
INPUTS = ("v_DA", "x_s")


def sample_time(k: int) -> float:
    """t_k = 0.01*k, computed the same way everywhere."""
    return SAMPLE * k


def v_da_sample(k: int) -> float:
    t = sample_time(k)
    return 2.5 + 3.0 * math.sin(2 * math.pi * 0.3 * t) + 0.5 * math.sin(2 * math.pi * 6 * t)


def x_s_sample(k: int) -> float:
    t = sample_time(k)
    return 0.054 + 0.01 * math.sin(2 * math.pi * 0.1 * t)


def sample_index(t: float) -> int:
    """Index of the 10 ms sample that holds at time t (robust against rounding of t)."""
    k = int(math.floor(t / SAMPLE + 1e-9))
    return min(max(k, 0), N_SAMPLES - 1)


def held_input(t: float) -> tuple[float, float]:
    """(v_DA, x_s) of the standard scenario at time t (zero-order hold of the samples)."""
    k = sample_index(t)
    return v_da_sample(k), x_s_sample(k)


def constant_input(v_da: float, x_s: float) -> Callable[[float], tuple[float, float]]:
    """An input function with the same signature as held_input that never changes."""
    return lambda t: (v_da, x_s)


def input_signal() -> np.ndarray:
    """The standard scenario as a structured array for fmpy.simulate_fmu.

    Each sample instant after the first appears twice (value before and after the step), which
    FMPy treats as a step change at that instant.
    """
    dtype = [("time", np.float64), ("v_DA", np.float64), ("x_s", np.float64)]
    rows = [(0.0, v_da_sample(0), x_s_sample(0))]
    for k in range(1, N_SAMPLES):
        t = sample_time(k)
        rows.append((t, v_da_sample(k - 1), x_s_sample(k - 1)))
        rows.append((t, v_da_sample(k), x_s_sample(k)))
    rows.append((T_END, v_da_sample(N_SAMPLES - 1), x_s_sample(N_SAMPLES - 1)))
    return np.array(rows, dtype=dtype)


def spring_force(x_s, k_spring=88.14, L_spring0=0.0691, L_s=0.007, L_p=0.008):
    """F_spring = k_spring (L_spring0 - (x_s - L_s - L_p)), (2.37) as given in MODEL.md."""
    return k_spring * (L_spring0 - (np.asarray(x_s) - L_s - L_p))


def step_scenario(
    fmu,
    vrs: dict,
    step: float,
    t_start: float = 0.0,
    t_stop: float = T_END,
    inputs: Callable[[float], tuple[float, float]] = held_input,
    outputs: Sequence[str] = OUTPUTS,
    record_start: bool = True,
):
    """Step an initialised fmpy.fmi2.FMU2Slave from t_start to t_stop.

    The communication step must divide the 10 ms sample period (step = 0.01/m, m integer) and
    t_start must be a sample instant. Inputs are set only when a new 10 ms sample starts, to the
    held value at the start of that sample (also at the very first step). Communication points
    are computed as t_k + j*step so that every sample instant is hit exactly as 0.01*k.

    Returns a dict with "time" and one array per output, sampled every 10 ms (including t_start
    when record_start is True). The outputs at a sample instant are read after the step that
    ends there and before the inputs of the next sample are set.
    """
    m = SAMPLE / step
    if abs(m - round(m)) > 1e-9 or round(m) < 1:
        raise ValueError(f"step {step} does not divide the sample period {SAMPLE}")
    m = int(round(m))
    k0 = int(round(t_start / SAMPLE))
    if abs(k0 * SAMPLE - t_start) > 1e-12:
        raise ValueError(f"t_start {t_start} is not a sample instant")
    k1 = int(round(t_stop / SAMPLE))

    in_vrs = [vrs["v_DA"], vrs["x_s"]]
    out_vrs = [vrs[name] for name in outputs]

    times = []
    rows = []
    if record_start:
        times.append(sample_time(k0))
        rows.append(fmu.getReal(out_vrs))
    for k in range(k0, k1):
        tk = sample_time(k)
        fmu.setReal(in_vrs, list(inputs(tk)))
        for j in range(m):
            t = tk + j * step
            t_next = sample_time(k + 1) if j == m - 1 else tk + (j + 1) * step
            fmu.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
        times.append(sample_time(k + 1))
        rows.append(fmu.getReal(out_vrs))
    values = np.array(rows, dtype=np.float64).reshape(len(rows), len(out_vrs))
    result = {"time": np.array(times)}
    for i, name in enumerate(outputs):
        result[name] = values[:, i]
    return result
