"""Benchmarks of the JetPipeActuator FMU (issue 6): what a co-simulation costs through FMPy,
how much of it is the model and how much the importer, and memory per instance.

usage: python fmu_tests/bench_fmu.py [--fmu dist/JetPipeActuator.fmu] [--repeat 3]
                                     [--lockstep 4] [--instances 1000]

A script, not a test: it prints figures and fails only if a run fails.

Scenarios
  standard     fmu_tests/scenarios.py: 10 s, inputs sampled every 10 ms and held, one
               fmi2DoStep of 10 ms per sample (1000 steps), with fmi2SetReal of both inputs
               before and fmi2GetReal of F_act after each step, as step_scenario does it.
  closed loop  500 Hz proportional force control by the master: every 2 ms (5000 steps,
               10 s) read F_act, set v_DA = v_ff + k_p (F_ref(t) - F_act) with v_ff = 2.5 V,
               k_p = 0.1 V/N, clamped to +-10 V, x_s = 0.054 m fixed, and step 2 ms.
               F_ref: 20 N until 2 s, 60 N until 4 s, 35 N until 6 s, then
               40 + 20 sin(2 pi 0.5 (t - 6)) N. A proportional loop leaves a steady-state
               error (printed as the RMS tracking error); it is a load pattern for the
               importer (3 FMI calls per 2 ms), not a controller design.

Measurements (each scenario; best of --repeat runs, the median beside it)
  FMPy         an FMU2Slave stepped by a Python loop; wall and process CPU time, and the
               time inside doStep and inside setReal/getReal (perf_counter around each call).
  FMPy dry     the same loop and FMPy calls, with doStep replaced by getRealStatus, an FMPy
               call of the same kind that does no work in the FMU: the cost of the loop and
               of FMPy's call wrappers (ctypes argument conversion, status checks) alone.
  C            fmu_tests/c/bench_driver.c (compiled here with gcc -O2), the same calls from
               C: the model's own cost. With --lockstep N, N instances stepped side by side.
  model vs overhead: the C driver's CPU time is the model's; the FMPy run's CPU time minus it
               is the importer's (FMPy, ctypes and the Python loop).
  memory       the C driver creates --instances instances (instantiate, setup, initialise,
               one 10 ms step) and reads VmRSS/VmHWM from /proc/self/status before and after.

Timings on a shared or loaded machine are noisy: the load average is printed with them.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import fmpy  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402

import scenarios  # noqa: E402

FMI_HEADERS = Path(fmpy.__file__).resolve().parent / "c-code"
FMI2_LAST_SUCCESSFUL_TIME = 2  # fmi2StatusKind

CL_STEP, CL_STEPS, CL_V_FF, CL_KP = 0.002, 5000, 2.5, 0.1


def closed_loop_reference(t: float) -> float:
    """Same expressions as bench_driver.c, so C and Python runs agree to the bit."""
    if t < 2.0:
        return 20.0
    if t < 4.0:
        return 60.0
    if t < 6.0:
        return 35.0
    return 40.0 + 20.0 * math.sin(2 * math.pi * 0.5 * (t - 6.0))


def closed_loop_command(t: float, force: float) -> float:
    v = CL_V_FF + CL_KP * (closed_loop_reference(t) - force)
    return 10.0 if v > 10.0 else (-10.0 if v < -10.0 else v)


def load() -> str:
    return " ".join(f"{x:.2f}" for x in os.getloadavg())


class Run:
    """Times of one FMPy run, seconds."""

    def __init__(self):
        self.wall = self.cpu = self.step = self.setget = 0.0
        self.steps = self.calls = 0
        self.final = None
        self.figure = None  # RMS force or RMS tracking error


def fmpy_run(unzipdir, md, vrs, scenario: str, dry: bool) -> Run:
    """One run of `scenario` through FMPy; `dry` replaces doStep by getRealStatus."""
    slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="bench")
    slave.instantiate()
    v_da, x_s, f_act, p1, p2 = (vrs[n] for n in ("v_DA", "x_s", "F_act", "P1", "P2"))
    pc = time.perf_counter
    r = Run()
    if scenario == "standard":
        stop, u0 = scenarios.T_END, (scenarios.v_da_sample(0), scenarios.x_s_sample(0))
    else:
        stop, u0 = CL_STEPS * CL_STEP, (CL_V_FF, 0.054)
    slave.setupExperiment(startTime=0.0, stopTime=stop)
    slave.enterInitializationMode()
    slave.setReal([v_da, x_s], list(u0))
    slave.exitInitializationMode()

    in_vrs, f_vr = [v_da, x_s], [f_act]
    def dry_step(currentCommunicationPoint, communicationStepSize):  # noqa: ARG001
        slave.getRealStatus(FMI2_LAST_SUCCESSFUL_TIME)

    step = dry_step if dry else slave.doStep
    sq = 0.0
    cpu0, wall0 = time.process_time(), pc()
    if scenario == "standard":
        for k in range(scenarios.N_SAMPLES):
            t, t_next = scenarios.sample_time(k), scenarios.sample_time(k + 1)
            a = pc()
            slave.setReal(in_vrs, [scenarios.v_da_sample(k), scenarios.x_s_sample(k)])
            b = pc()
            step(currentCommunicationPoint=t, communicationStepSize=t_next - t)
            c = pc()
            f = slave.getReal(f_vr)[0]
            d = pc()
            r.setget += (b - a) + (d - c)
            r.step += c - b
            sq += f * f
        n = scenarios.N_SAMPLES
    else:
        f = slave.getReal(f_vr)[0]
        v_vr = [v_da]
        for k in range(CL_STEPS):
            t = k * CL_STEP
            a = pc()
            slave.setReal(v_vr, [closed_loop_command(t, f)])
            b = pc()
            step(currentCommunicationPoint=t, communicationStepSize=CL_STEP)
            c = pc()
            f = slave.getReal(f_vr)[0]
            d = pc()
            r.setget += (b - a) + (d - c)
            r.step += c - b
            e = closed_loop_reference(t + CL_STEP) - f
            sq += e * e
        n = CL_STEPS
    r.wall, r.cpu = pc() - wall0, time.process_time() - cpu0
    r.steps, r.calls = n, 3 * n
    r.figure = math.sqrt(sq / n)
    r.final = tuple(slave.getReal([f_act, p1, p2]))
    slave.terminate()
    slave.freeInstance()
    slave.freeLibrary()
    return r


def best_and_median(runs, key):
    values = [key(r) for r in runs]
    return min(values), statistics.median(values)


def compile_driver(workdir: Path) -> Path:
    gcc = shutil.which("gcc")
    if gcc is None:
        raise SystemExit("bench_fmu: gcc is not installed (apt-get install gcc)")
    exe = workdir / "bench_driver"
    cmd = [gcc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", f"-I{FMI_HEADERS}",
           str(HERE / "c" / "bench_driver.c"), "-o", str(exe), "-ldl", "-lm"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"bench_fmu: {' '.join(cmd)} failed:\n{proc.stderr}")
    return exe


def c_run(exe, unzipdir, guid, mode, n) -> dict:
    proc = subprocess.run([str(exe), str(unzipdir), guid, mode, str(n)], capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, timeout=1800)
    if proc.returncode != 0:
        raise SystemExit(f"bench_fmu: bench_driver {mode} {n} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
    values = {}
    for line in proc.stdout.splitlines():
        key, _, value = line.partition("=")
        try:
            values[key] = float(value)
        except ValueError:
            values[key] = value
    return values


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], epilog=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--fmu", default=str(HERE.parent / "dist" / "JetPipeActuator.fmu"))
    parser.add_argument("--repeat", type=int, default=3, help="runs of each measurement (default 3)")
    parser.add_argument("--lockstep", type=int, default=4, help="instances stepped side by side in C (default 4)")
    parser.add_argument("--instances", type=int, default=1000, help="instances for the memory figure (default 1000)")
    args = parser.parse_args(argv)
    if args.repeat < 1 or args.lockstep < 1 or args.instances < 1:
        parser.error("--repeat, --lockstep and --instances must be >= 1")
    fmu = Path(args.fmu)
    if not fmu.is_file():
        print(f"bench_fmu: FMU not found: {fmu} (cargo run --release --bin jetpipe -- package)", file=sys.stderr)
        return 1

    workdir = Path(tempfile.mkdtemp(prefix="jetpipe-bench-"))
    try:
        unzipdir = fmpy.extract(str(fmu), str(workdir / "fmu"))
        md = fmpy.read_model_description(str(fmu))
        vrs = {v.name: v.valueReference for v in md.modelVariables}
        exe = compile_driver(workdir)
        print(f"bench_fmu: {fmu} ({fmu.stat().st_size} bytes), FMPy {fmpy.__version__}, Python "
              f"{sys.version.split()[0]}, {os.cpu_count()} cores, load average {load()}")

        summary = []
        for scenario, label in (("standard", "standard scenario, 10 ms steps"),
                                ("closedloop", "closed loop, 500 Hz (2 ms steps)")):
            real = [fmpy_run(unzipdir, md, vrs, scenario, dry=False) for _ in range(args.repeat)]
            dry = [fmpy_run(unzipdir, md, vrs, scenario, dry=True) for _ in range(args.repeat)]
            c1 = [c_run(exe, unzipdir, md.guid, scenario, 1) for _ in range(args.repeat)]
            cn = c_run(exe, unzipdir, md.guid, scenario, args.lockstep)
            sim = real[0].steps * (scenarios.SAMPLE if scenario == "standard" else CL_STEP)
            wall, wall_med = best_and_median(real, lambda r: r.wall)
            cpu, _ = best_and_median(real, lambda r: r.cpu)
            step, _ = best_and_median(real, lambda r: r.step)
            setget, _ = best_and_median(real, lambda r: r.setget)
            dry_wall, dry_med = best_and_median(dry, lambda r: r.wall)
            dry_cpu, _ = best_and_median(dry, lambda r: r.cpu)
            c_cpu, c_med = best_and_median(c1, lambda v: v["cpu_s"])
            c_wall, _ = best_and_median(c1, lambda v: v["wall_s"])
            n = real[0].steps
            # The split uses CPU time: on a busy machine wall time also counts the time the
            # process waited for a core, which belongs to neither the model nor FMPy.
            overhead = cpu - c_cpu
            same = real[0].final == (c1[0]["F_act"], c1[0]["P1"], c1[0]["P2"])
            print(f"\n{label}: {sim:g} s simulated, {n} doStep, {real[0].calls} FMI calls in the loop "
                  f"(load average {load()})")
            print(f"  FMPy     CPU {cpu * 1e3:8.1f} ms, wall {wall * 1e3:.1f} ms (median {wall_med * 1e3:.1f}): "
                  f"{cpu / sim * 1e3:.2f} ms CPU per simulated s, {n / wall:,.0f} doStep/s, "
                  f"{sim / wall:,.1f}x real time")
            print(f"           wall in doStep {step * 1e3:.1f} ms ({step / n * 1e6:.1f} us per call), in "
                  f"setReal/getReal {setget * 1e3:.1f} ms ({setget / (2 * n) * 1e6:.1f} us per call), Python loop "
                  f"{(wall - step - setget) * 1e3:.1f} ms")
            print(f"  FMPy dry CPU {dry_cpu * 1e3:8.1f} ms, wall {dry_wall * 1e3:.1f} ms (median {dry_med * 1e3:.1f}): "
                  f"the loop and FMPy's wrappers alone, {dry_cpu / real[0].calls * 1e6:.1f} us CPU per FMI call")
            print(f"  C        CPU {c_cpu * 1e3:8.1f} ms (median {c_med * 1e3:.1f}), wall {c_wall * 1e3:.1f} ms: "
                  f"{c_cpu / sim * 1e3:.2f} ms CPU per simulated s, {n / c_wall:,.0f} doStep/s")
            print(f"  C, {args.lockstep} instances in lockstep: {cn['cpu_per_simulated_s_per_instance'] * 1e3:.2f} ms CPU "
                  f"per simulated s per instance")
            print(f"  model {100 * c_cpu / cpu:.0f} % of the FMPy CPU time; FMPy and the Python loop "
                  f"{100 * overhead / cpu:.0f} % ({overhead * 1e3:.1f} ms, {overhead / real[0].calls * 1e6:.1f} us "
                  f"per FMI call; the dry run alone: {dry_cpu * 1e3:.1f} ms)")
            fig = "RMS F_act" if scenario == "standard" else "RMS tracking error"
            print(f"  {fig} {real[0].figure:.4f} N; final F_act {real[0].final[0]:.6f} N; "
                  f"FMPy and C final outputs bit-identical: {'yes' if same else 'no'}")
            summary.append((label, cpu / sim, c_cpu / sim, 100 * overhead / cpu))

        mem = c_run(exe, unzipdir, md.guid, "memory", args.instances)
        print(f"\nmemory: {args.instances} instances alive (instantiate, setup, initialise, one 10 ms step), "
              f"C driver")
        print(f"  VmRSS {mem['rss_before'] / 1024:.0f} KiB -> {mem['rss_with_instances'] / 1024:.0f} KiB: "
              f"{mem['rss_bytes_per_instance']:.0f} bytes per instance (VmHWM: {mem['hwm_bytes_per_instance']:.0f}); "
              f"the loaded library itself {mem['rss_library_loaded'] / 1024:.0f} KiB")
        print(f"  instantiate + setup + initialise + one step: {mem['setup_s_per_instance'] * 1e6:.0f} us per instance")

        print(f"\nsummary (load average {load()}):")
        for label, fmpy_cpu, c_cpu, share in summary:
            print(f"  {label:34s} FMPy {fmpy_cpu * 1e3:6.2f} ms CPU/sim-s, C {c_cpu * 1e3:6.2f} ms CPU/sim-s, "
                  f"importer share of CPU {share:.0f} %")
        print(f"  memory {mem['rss_bytes_per_instance']:.0f} bytes per instance")
        return 0
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
