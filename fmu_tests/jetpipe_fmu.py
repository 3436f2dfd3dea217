"""Helpers shared by the FMU tests, the subprocess worker and run_standard_scenario.py.

FMPy's native logger proxy (fmpy.logging.addLoggerProxy) formats the FMU's printf-style
message with its varargs before calling Python, but it keeps the Python logger in ONE global
pointer. So a single Python dispatcher is installed and every instance gets its own
fmi2CallbackFunctions whose componentEnvironment is a unique integer; the dispatcher files each
message under that integer (or, failing that, under the instance name).
"""

from __future__ import annotations

import itertools
import math
import re
import threading
from ctypes import byref
from dataclasses import dataclass, field
from pathlib import Path

import fmpy
from fmpy import calloc, free
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.logging import addLoggerProxy

MODEL_IDENTIFIER = "JetPipeActuator"
STATUS_LABELS = ["OK", "Warning", "Discard", "Error", "Fatal", "Pending"]


@dataclass
class LogMessage:
    status: int
    category: str
    message: str
    instance: str

    def __str__(self):
        label = STATUS_LABELS[self.status] if 0 <= self.status < len(STATUS_LABELS) else str(self.status)
        return f"[{label}] [{self.category}] {self.instance}: {self.message}"


@dataclass
class LogRecorder:
    messages: list = field(default_factory=list)

    def __len__(self):
        return len(self.messages)

    def since(self, n: int) -> list:
        return self.messages[n:]

    def text(self, start: int = 0) -> str:
        return "\n".join(str(m) for m in self.messages[start:])


_registry: dict[int, LogRecorder] = {}
_by_name: dict[str, LogRecorder] = {}
_lock = threading.Lock()
_ids = itertools.count(1)


def _dispatch(env, instance_name, status, category, message):
    inst = instance_name.decode("utf-8", "replace") if instance_name else ""
    msg = LogMessage(
        status=int(status),
        category=category.decode("utf-8", "replace") if category else "",
        message=message.decode("utf-8", "replace") if message else "",
        instance=inst,
    )
    rec = _registry.get(env) if env is not None else None
    if rec is None:
        rec = _by_name.get(inst)
    if rec is None:
        print(msg)
    else:
        rec.messages.append(msg)


# Kept alive for the life of the process: the C side holds a pointer to it.
_LOGGER = fmi2CallbackLoggerTYPE(_dispatch)
_ALLOCATE = fmi2CallbackAllocateMemoryTYPE(calloc)
_FREE = fmi2CallbackFreeMemoryTYPE(free)


def vr_map(model_description) -> dict:
    return {v.name: v.valueReference for v in model_description.modelVariables}


def make_slave(unzipdir, model_description, instance_name=None, guid=None, logging_on=True) -> FMU2Slave:
    """Load the binary and instantiate an FMU2Slave whose log messages land in `fmu.log`.

    `guid` overrides the GUID passed to fmi2Instantiate (for the wrong-GUID test). Raises
    (FMPy's "Failed to instantiate model") when fmi2Instantiate returns NULL.
    """
    with _lock:
        env_id = next(_ids)
    name = instance_name or f"jetpipe_{env_id}"
    fmu = FMU2Slave(
        guid=guid if guid is not None else model_description.guid,
        unzipDirectory=str(unzipdir),
        modelIdentifier=model_description.coSimulation.modelIdentifier,
        instanceName=name,
    )
    rec = LogRecorder()
    callbacks = fmi2CallbackFunctions()
    callbacks.logger = _LOGGER
    callbacks.allocateMemory = _ALLOCATE
    callbacks.freeMemory = _FREE
    callbacks.componentEnvironment = env_id
    addLoggerProxy(byref(callbacks))  # replaces callbacks.logger by the formatting proxy
    with _lock:
        _registry[env_id] = rec
        _by_name[name] = rec
    fmu.log = rec
    fmu.env_id = env_id
    try:
        fmu.instantiate(callbacks=callbacks, loggingOn=logging_on)
    except Exception:
        fmu.freeLibrary()
        raise
    return fmu


def initialize(fmu, vrs, inputs=None, parameters=None, booleans=None, tolerance=None, start_time=0.0, stop_time=None):
    """setupExperiment, enterInitializationMode, set parameters and inputs, exitInitializationMode."""
    fmu.setupExperiment(tolerance=tolerance, startTime=start_time, stopTime=stop_time)
    fmu.enterInitializationMode()
    if parameters:
        names = list(parameters)
        fmu.setReal([vrs[n] for n in names], [float(parameters[n]) for n in names])
    if booleans:
        names = list(booleans)
        fmu.setBoolean([vrs[n] for n in names], [bool(booleans[n]) for n in names])
    if inputs is not None:
        fmu.setReal([vrs["v_DA"], vrs["x_s"]], [float(inputs[0]), float(inputs[1])])
    fmu.exitInitializationMode()


def release(fmu):
    """Free an instance whatever state it is in (errors of terminate are ignored)."""
    if getattr(fmu, "component", None) is None:
        return
    try:
        fmu.terminate()
    except Exception:
        pass
    try:
        fmu.freeInstance()
    finally:
        fmu.component = None
        with _lock:
            _registry.pop(getattr(fmu, "env_id", None), None)


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def mentions_value(message: str, value: float) -> bool:
    """True when the message shows `value` (NaN/inf by name, finite values by any numeric token)."""
    low = message.lower()
    if math.isnan(value):
        return "nan" in low
    if math.isinf(value):
        return "inf" in low and (value > 0 or "-inf" in low)
    for token in _NUMBER.findall(message):
        try:
            x = float(token)
        except ValueError:
            continue
        if x == value or (value != 0 and abs(x - value) <= 1e-6 * abs(value)):
            return True
    return False


def default_fmu_path() -> Path:
    return Path(__file__).resolve().parent.parent / "dist" / "JetPipeActuator.fmu"


def read_model_description(path):
    return fmpy.read_model_description(str(path))
