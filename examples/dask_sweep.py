"""A parameter sweep of the JetPipeActuator FMU through FMPy on a dask.distributed cluster.

usage:
    python examples/dask_sweep.py [--fmu dist/JetPipeActuator.fmu] [--scheduler tcp://HOST:8786]
                                  [--workers 2] [--param C_d=0.6:0.75:8 ...] [--duration 10]
                                  [--step 0.01] [--out sweep_dask.csv] [--no-single-worker]

Each task simulates the standard scenario (fmu_tests/scenarios.py: inputs sampled every 10 ms
and held, v_DA = 2.5 + 3 sin(2π·0.3 t) + 0.5 sin(2π·6 t) V, x_s = 0.054 + 0.01 sin(2π·0.1 t) m)
with one parameter set and returns summary figures (RMS, max, min and final force, final
pressures, CPU and wall time of the task).

Without --scheduler a LocalCluster on the loopback interface is started: --workers worker
processes with one thread each (processes, not threads: each FMPy call holds the GIL while it
converts its arguments, so threads in one process would serialise on it). With --scheduler
the sweep goes to that cluster; the FMU is sent to the workers as bytes (scattered once, not
once per task) and this file is uploaded to them, so they need FMPy and NumPy installed but
no shared file system.

Per worker process the FMU is extracted and its shared library loaded once (cached by the
FMU's SHA-256); one FMU2Slave per worker thread is reused across tasks through fmi2Reset,
which restores every start value, so a task sees exactly what a fresh instance would.

--param takes NAME=START:STOP:N (N evenly spaced values, both ends included), NAME=V1,V2,...
or NAME=V, with NAME a Real parameter of the FMU; several --param give their Cartesian
product (last one fastest), as in `jetpipe sweep`.

After the sweep on every worker it runs the same sweep with every task pinned to one worker
and prints runs/s for both, the speed-up and the parallel efficiency; both timings start
after a warm-up task on each worker, so they leave out extraction and library loading
(printed separately). The pinned run must give bit-identical figures, which it checks.
"""

from __future__ import annotations

import argparse
import atexit
import csv
import hashlib
import io
import itertools
import math
import os
import shutil
import sys
import tempfile
import threading
import time
import zipfile
from ctypes import byref
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SAMPLE = 0.01  # s, the standard scenario's sample period
SUMMARY_FIELDS = ("rms_F_act", "max_F_act", "min_F_act", "final_F_act", "final_P1", "final_P2")

# ----------------------------------------------------------------------------------------
# Worker side: everything a task needs, in this one file (uploaded to remote workers).
# ----------------------------------------------------------------------------------------


def v_da_sample(k: int) -> float:
    t = SAMPLE * k
    return 2.5 + 3.0 * math.sin(2 * math.pi * 0.3 * t) + 0.5 * math.sin(2 * math.pi * 6 * t)


def x_s_sample(k: int) -> float:
    t = SAMPLE * k
    return 0.054 + 0.01 * math.sin(2 * math.pi * 0.1 * t)


class _LoadedFmu:
    """An FMU extracted once in this process: its directory, model description and VRs."""

    def __init__(self, fmu_bytes: bytes):
        import fmpy

        self.directory = tempfile.mkdtemp(prefix="jetpipe-dask-fmu-")
        atexit.register(shutil.rmtree, self.directory, True)
        with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as z:
            z.extractall(self.directory)
        self.model_description = fmpy.read_model_description(self.directory)
        self.vrs = {v.name: v.valueReference for v in self.model_description.modelVariables}
        self.real_parameters = {
            v.name for v in self.model_description.modelVariables if v.causality == "parameter" and v.type == "Real"
        }


_FMUS: dict[str, _LoadedFmu] = {}
_FMUS_LOCK = threading.Lock()
_THREAD = threading.local()
_LOGGERS: dict[int, list] = {}
_LOGGER_IDS = itertools.count(1)


def _loaded(digest: str, fmu) -> _LoadedFmu:
    """The FMU with this SHA-256, extracted on first use in this process. `fmu` is its bytes
    or a path (read only on first use)."""
    with _FMUS_LOCK:
        if digest not in _FMUS:
            data = fmu if isinstance(fmu, (bytes, bytearray)) else Path(fmu).read_bytes()
            _FMUS[digest] = _LoadedFmu(bytes(data))
        return _FMUS[digest]


def _log_dispatch(env, instance_name, status, category, message):
    _LOGGERS.setdefault(int(env or 0), []).append(message.decode("utf-8", "replace") if message else "")


def _slave(digest: str, fmu):
    """This thread's FMU2Slave of this FMU: instantiated once, fmi2Reset before every reuse.
    FMU log messages go to a list per instance (FMPy's proxy formats the printf arguments)."""
    from fmpy import calloc, free
    from fmpy.fmi2 import (
        FMU2Slave,
        fmi2CallbackAllocateMemoryTYPE,
        fmi2CallbackFreeMemoryTYPE,
        fmi2CallbackFunctions,
        fmi2CallbackLoggerTYPE,
    )
    from fmpy.logging import addLoggerProxy

    slaves = getattr(_THREAD, "slaves", None)
    if slaves is None:
        slaves = _THREAD.slaves = {}
    if digest in slaves:
        slave, log = slaves[digest]
        slave.reset()
        log.clear()
        return slave, log
    loaded = _loaded(digest, fmu)
    env_id = next(_LOGGER_IDS)
    log = _LOGGERS.setdefault(env_id, [])
    callbacks = fmi2CallbackFunctions()
    # The ctypes callbacks must outlive the instance: keep them on it.
    callbacks.logger = fmi2CallbackLoggerTYPE(_log_dispatch)
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    callbacks.componentEnvironment = env_id
    keep_alive = (callbacks.logger, callbacks.allocateMemory, callbacks.freeMemory)
    addLoggerProxy(byref(callbacks))
    md = loaded.model_description
    slave = FMU2Slave(
        guid=md.guid,
        unzipDirectory=loaded.directory,
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=f"dask_{os.getpid()}_{env_id}",
    )
    slave.instantiate(callbacks=callbacks, loggingOn=True)
    slave._jetpipe_keep_alive = keep_alive
    slave.loaded = loaded
    slaves[digest] = (slave, log)
    return slave, log


def simulate(digest: str, fmu, params: dict, duration: float = 10.0, step: float = SAMPLE, trace: bool = False) -> dict:
    """Run the standard scenario for `duration` s with the Real parameters `params` set.

    The FMPy calls are those of fmu_tests/scenarios.py's step_scenario (inputs set at each
    10 ms sample, communication points t_k + j·step), so the figures are bitwise those of a
    serial loop over fresh instances. Raises ValueError naming the parameter and value the
    FMU rejected, with the FMU's own message.
    """
    wall0, cpu0 = time.perf_counter(), time.thread_time()
    slave, log = _slave(digest, fmu)
    vrs, loaded = slave.loaded.vrs, slave.loaded
    m = round(SAMPLE / step)
    if m < 1 or abs(m * step - SAMPLE) > 1e-12:
        raise ValueError(f"step = {step} s is invalid: must divide the {SAMPLE} s sample period")
    samples = round(duration / SAMPLE)
    if samples < 1 or abs(samples * SAMPLE - duration) > 1e-9:
        raise ValueError(f"duration = {duration} s is invalid: must be a positive multiple of {SAMPLE} s")

    slave.setupExperiment(startTime=0.0, stopTime=samples * SAMPLE)
    slave.enterInitializationMode()
    for name, value in params.items():
        if name not in loaded.real_parameters:
            raise ValueError(f"{name} is not a Real parameter of the FMU (value {value!r})")
        try:
            slave.setReal([vrs[name]], [float(value)])
        except Exception as e:
            raise ValueError(f"the FMU rejected {name} = {value!r}: {' | '.join(log) or e}") from None
    in_vrs = [vrs["v_DA"], vrs["x_s"]]
    out_vrs = [vrs["F_act"], vrs["P1"], vrs["P2"]]
    slave.setReal(in_vrs, [v_da_sample(0), x_s_sample(0)])
    try:
        slave.exitInitializationMode()
    except Exception as e:
        raise ValueError(f"initialisation failed with {params}: {' | '.join(log) or e}") from None

    forces = [slave.getReal(out_vrs[:1])[0]]
    for k in range(samples):
        tk = SAMPLE * k
        slave.setReal(in_vrs, [v_da_sample(k), x_s_sample(k)])
        for j in range(m):
            t = tk + j * step
            t_next = SAMPLE * (k + 1) if j == m - 1 else tk + (j + 1) * step
            try:
                slave.doStep(currentCommunicationPoint=t, communicationStepSize=t_next - t)
            except Exception as e:
                raise RuntimeError(f"doStep at t = {t} s failed with {params}: {' | '.join(log) or e}") from None
        forces.append(slave.getReal(out_vrs[:1])[0])
    f_final, p1, p2 = slave.getReal(out_vrs)
    slave.terminate()

    # Plain Python sums, in sample order: the same figures whatever NumPy's pairwise
    # summation would do with another length.
    result = {
        "params": dict(params),
        "rms_F_act": math.sqrt(sum(f * f for f in forces) / len(forces)),
        "max_F_act": max(forces),
        "min_F_act": min(forces),
        "final_F_act": f_final,
        "final_P1": p1,
        "final_P2": p2,
        "cpu_s": time.thread_time() - cpu0,
        "wall_s": time.perf_counter() - wall0,
        "pid": os.getpid(),
    }
    if trace:
        result["F_act"] = forces
    return result


def warm_up(digest: str, fmu) -> float:
    """Extract and load the FMU in this worker (a 10 ms run); returns the seconds it took."""
    t0 = time.perf_counter()
    simulate(digest, fmu, {}, duration=SAMPLE)
    return time.perf_counter() - t0


# ----------------------------------------------------------------------------------------
# Client side
# ----------------------------------------------------------------------------------------


def parse_param(spec: str, real_parameters) -> tuple[str, list[float]]:
    """NAME=START:STOP:N, NAME=V1,V2,... or NAME=V; errors name the parameter and value."""
    name, sep, values = spec.partition("=")
    name = name.strip()
    if not sep:
        raise ValueError(f"--param {spec!r} is invalid: expected NAME=START:STOP:N or NAME=V1,V2,...")
    if name not in real_parameters:
        hint = [p for p in real_parameters if p.lower() == name.lower()]
        raise ValueError(
            f"--param {spec}: {name!r} is not a Real parameter of the FMU"
            + (f" (did you mean {hint[0]}?)" if hint else "")
            + f"; parameters: {', '.join(sorted(real_parameters))}"
        )

    def number(text):
        try:
            x = float(text)
        except ValueError:
            raise ValueError(f"--param {spec}: {name} = {text.strip()!r} is not a number") from None
        if not math.isfinite(x):
            raise ValueError(f"--param {spec}: {name} = {x} is invalid: must be finite")
        return x

    if ":" in values:
        parts = values.split(":")
        if len(parts) != 3:
            raise ValueError(f"--param {spec}: a grid is START:STOP:N, got {len(parts)} fields")
        start, stop = number(parts[0]), number(parts[1])
        try:
            n = int(parts[2])
        except ValueError:
            n = 0
        if n < 1:
            raise ValueError(f"--param {spec}: the number of values N = {parts[2]!r} must be an integer >= 1")
        # Same formula as `jetpipe sweep`: the last value exactly STOP.
        grid = [start + (stop - start) * k / (n - 1) for k in range(n - 1)] + [stop] if n > 1 else [start]
        return name, grid
    return name, [number(v) for v in values.split(",")]


def grid_points(axes: list[tuple[str, list[float]]]) -> list[dict]:
    names = [a[0] for a in axes]
    if len(set(names)) != len(names):
        raise ValueError(f"a parameter is given twice in --param: {names}")
    return [dict(zip(names, values)) for values in itertools.product(*(a[1] for a in axes))]


def fmu_digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def run_sweep(client, digest, fmu_ref, points, duration, step, workers=None, trace=False):
    """Map `simulate` over `points` (optionally pinned to `workers`); results in point order
    and the wall time from submission to the last result."""
    t0 = time.perf_counter()
    pin = {} if workers is None else {"workers": workers, "allow_other_workers": False}
    futures = client.map(
        simulate,
        [digest] * len(points),
        [fmu_ref] * len(points),
        points,
        [duration] * len(points),
        [step] * len(points),
        [trace] * len(points),
        pure=False,  # identical arguments must still run again (the 1-worker timing)
        **pin,
    )
    results = client.gather(futures)
    return results, time.perf_counter() - t0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fmu", default=str(REPO / "dist" / "JetPipeActuator.fmu"))
    parser.add_argument("--scheduler", help="address of a running dask scheduler (default: a LocalCluster)")
    parser.add_argument("--workers", type=int, default=2, help="worker processes of the LocalCluster (default 2)")
    parser.add_argument("--param", action="append", default=None, metavar="NAME=VALUES",
                        help="parameter grid (default C_d=0.6:0.75:8)")
    parser.add_argument("--duration", type=float, default=10.0, help="simulated seconds per run (default 10)")
    parser.add_argument("--step", type=float, default=SAMPLE, help="communication step (default 0.01 s)")
    parser.add_argument("--out", help="write one CSV row per run here")
    parser.add_argument("--no-single-worker", action="store_true", help="skip the 1-worker timing")
    args = parser.parse_args(argv)

    fmu_path = Path(args.fmu)
    if not fmu_path.is_file():
        print(f"dask_sweep: FMU not found: {fmu_path} (cargo run --release --bin jetpipe -- package)",
              file=sys.stderr)
        return 1
    if args.scheduler is None and args.workers < 1:
        print(f"dask_sweep: --workers {args.workers} is invalid: must be >= 1", file=sys.stderr)
        return 1

    import fmpy
    from dask.distributed import Client, LocalCluster

    md = fmpy.read_model_description(str(fmu_path))
    real_parameters = {v.name for v in md.modelVariables if v.causality == "parameter" and v.type == "Real"}
    try:
        axes = [parse_param(s, real_parameters) for s in (args.param or ["C_d=0.6:0.75:8"])]
        points = grid_points(axes)
    except ValueError as e:
        print(f"dask_sweep: {e}", file=sys.stderr)
        return 1

    data = fmu_path.read_bytes()
    digest = fmu_digest(data)
    if args.scheduler:
        cluster = None
        client = Client(args.scheduler)
    else:
        # Loopback only, no dashboard: nothing listens beyond this machine.
        cluster = LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None)
        client = Client(cluster)
    try:
        # Workers import `simulate` from this file by name, so its per-process caches live in
        # a module that stays loaded. Run as a script, this file is __main__, whose functions
        # dask would pickle by value (with fresh caches, and a thread-local it cannot pickle):
        # so everything sent to the workers comes from the module `dask_sweep` instead.
        client.upload_file(__file__)
        import dask_sweep as module

        workers = sorted(client.scheduler_info()["workers"])
        fmu_ref = client.scatter(data, broadcast=True)  # once per worker, not once per task
        load_s = client.run(module.warm_up, digest, data)
        print(f"dask_sweep: {len(points)} runs of the standard scenario ({args.duration:g} s, step {args.step:g} s) "
              f"on {len(workers)} workers ({'scheduler ' + args.scheduler if args.scheduler else 'LocalCluster, 1 thread each'})")
        print(f"  load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}; "
              f"extract + load + 10 ms run per worker: "
              f"{', '.join(f'{s * 1e3:.0f} ms' for s in load_s.values())}")
        try:
            results, wall = module.run_sweep(client, digest, fmu_ref, points, args.duration, args.step)
        except (ValueError, RuntimeError) as e:
            print(f"dask_sweep: {e}", file=sys.stderr)
            return 1
        rate = len(points) / wall
        cpu = sum(r["cpu_s"] for r in results)
        print(f"  {len(workers)} workers: wall {wall:.3f} s, {rate:.2f} runs/s, "
              f"{rate * args.duration:.1f} simulated s per wall s, task CPU {cpu:.3f} s "
              f"({cpu / len(points) * 1e3:.1f} ms per run)")
        if len(workers) > 1 and not args.no_single_worker:
            single, wall1 = module.run_sweep(client, digest, fmu_ref, points, args.duration, args.step,
                                                workers=workers[:1])
            rate1 = len(points) / wall1
            speedup = rate / rate1
            same = all(all(a[f] == b[f] for f in SUMMARY_FIELDS) for a, b in zip(results, single))
            print(f"  1 worker:  wall {wall1:.3f} s, {rate1:.2f} runs/s")
            print(f"  speed-up {speedup:.2f} on {len(workers)} workers, parallel efficiency "
                  f"{100 * speedup / len(workers):.0f} % ({os.cpu_count()} cores on this machine)")
            # Cores the tasks actually had (task CPU over wall): below 1 per worker, they waited
            # for a core, i.e. other processes shared the machine, and the speed-up says as much
            # about that load as about dask.
            cpu1 = sum(r["cpu_s"] for r in single)
            print(f"  cores used by the tasks: {cpu / wall:.2f} with {len(workers)} workers, {cpu1 / wall1:.2f} with 1")
            print(f"  1-worker figures bit-identical to the {len(workers)}-worker figures: {'yes' if same else 'NO'}")
            if not same:
                return 1
        names = [a[0] for a in axes]
        for r in results[: min(len(results), 8)]:
            print("   ", ", ".join(f"{n} = {r['params'][n]:g}" for n in names),
                  f"-> F_act RMS {r['rms_F_act']:.4f} N, max {r['max_F_act']:.4f} N")
        if len(results) > 8:
            print(f"    ... {len(results) - 8} more")
        if args.out:
            with open(args.out, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(["run", *names, *SUMMARY_FIELDS, "cpu_s", "wall_s"])
                for k, r in enumerate(results):
                    w.writerow([k, *(repr(r["params"][n]) for n in names), *(repr(r[x]) for x in SUMMARY_FIELDS),
                                f"{r['cpu_s']:.6f}", f"{r['wall_s']:.6f}"])
            print(f"  wrote {args.out}")
        return 0
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


if __name__ == "__main__":
    sys.exit(main())
