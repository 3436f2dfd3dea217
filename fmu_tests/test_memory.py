"""Issue 5, memory: no leak and no invalid memory access, from a C importer and from the Rust
call-sequence fuzzer.

* fmu_tests/c/leak_cycles.c loops instantiate / initialise / step / FMU-state round trip / free
  with error paths on the way (illegal calls, rejected values, corrupted state bytes, freed
  handles, repeated fmi2FreeInstance, failed fmi2Instantiate):
  - 1000 cycles under LeakSanitizer (gcc -fsanitize=address) -- JETPIPE_LEAK_CYCLES;
  - under Valgrind memcheck (every read of the uninstrumented Rust library is checked):
    JETPIPE_VALGRIND_CYCLES cycles, 150 in CI (about 15 s), 1000 for the full form;
  - a negative control (one instance deliberately not freed) shows each checker sees the
    FMU's allocations.
* the C driver of test_c_driver.py (1 s at 1 ms) under Valgrind;
* fmu_tests/c/leak_cycles_fmi3.c, the same for the FMI 3.0 functions of the library in
  dist/JetPipeActuator-fmi3.fmu (Co-Simulation and Model Exchange instances each cycle): under
  LeakSanitizer (JETPIPE_LEAK_CYCLES) and Valgrind (JETPIPE_VALGRIND_CYCLES), with its negative
  control;
* the Rust call-sequence fuzzer (tests/fmi_call_fuzz/, FMI 2.0 and 3.0), bounded, under Valgrind.

gcc and valgrind are on the CI image; the tests skip (saying which) only when one is missing.
"""

import json
import os
import re
import shutil
import subprocess
import time
from pathlib import Path

import fmpy
import pytest

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
FMI_HEADERS = Path(fmpy.__file__).resolve().parent / "c-code"

LEAK_CYCLES = int(os.environ.get("JETPIPE_LEAK_CYCLES", "1000"))
VALGRIND_CYCLES = int(os.environ.get("JETPIPE_VALGRIND_CYCLES", "150"))
VALGRIND_FUZZ_SEQUENCES = os.environ.get("JETPIPE_VALGRIND_FUZZ_SEQUENCES", "3")

VALGRIND_ARGS = ["--leak-check=full", "--errors-for-leak-kinds=definite,indirect", "--error-exitcode=99",
                 "--track-origins=no"]


def tool(name):
    path = shutil.which(name)
    if path is None:
        pytest.skip(f"{name} is not installed")
    return path


@pytest.fixture(scope="module")
def gcc():
    return tool("gcc")


@pytest.fixture(scope="module")
def valgrind():
    return tool("valgrind")


def build(gcc, source, exe, extra=()):
    cmd = [gcc, "-std=c99", "-O1", "-g", "-Wall", "-Wextra", "-Werror", *extra, f"-I{FMI_HEADERS}", str(source),
           "-o", str(exe), "-ldl"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stderr}"
    return exe


@pytest.fixture(scope="module")
def leak_cycles(gcc, tmp_path_factory):
    return build(gcc, HERE / "c" / "leak_cycles.c", tmp_path_factory.mktemp("leak") / "leak_cycles")


@pytest.fixture(scope="module")
def leak_cycles_asan(gcc, tmp_path_factory):
    return build(gcc, HERE / "c" / "leak_cycles.c", tmp_path_factory.mktemp("leak_asan") / "leak_cycles_asan",
                 extra=("-fsanitize=address", "-fno-omit-frame-pointer"))


@pytest.fixture(scope="module")
def fmi3_library(tmp_path_factory):
    """The x86_64-linux library of dist/JetPipeActuator-fmi3.fmu ($JETPIPE_FMU3) and its token."""
    path = Path(os.environ.get("JETPIPE_FMU3", REPO / "dist" / "JetPipeActuator-fmi3.fmu"))
    if not path.is_file():
        pytest.fail(f"{path} not found (bash scripts/package.sh)", pytrace=False)
    d = Path(fmpy.extract(str(path), str(tmp_path_factory.mktemp("fmu3"))))
    return d / "binaries" / "x86_64-linux" / "JetPipeActuator.so", fmpy.read_model_description(str(path)).guid


@pytest.fixture(scope="module")
def leak_cycles_fmi3(gcc, tmp_path_factory):
    return build(gcc, HERE / "c" / "leak_cycles_fmi3.c", tmp_path_factory.mktemp("leak3") / "leak_cycles_fmi3")


@pytest.fixture(scope="module")
def leak_cycles_fmi3_asan(gcc, tmp_path_factory):
    return build(gcc, HERE / "c" / "leak_cycles_fmi3.c", tmp_path_factory.mktemp("leak3_asan") / "leak_cycles_fmi3_asan",
                 extra=("-fsanitize=address", "-fno-omit-frame-pointer"))


def run(cmd, timeout=900, env=None):
    t0 = time.perf_counter()
    proc = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, timeout=timeout,
                          stdin=subprocess.DEVNULL, env=env)
    return proc, time.perf_counter() - t0


def valgrind_summary(stderr):
    """(errors, definitely lost bytes, indirectly lost bytes) from Valgrind's summary."""
    errors = re.findall(r"ERROR SUMMARY: ([\d,]+) errors", stderr)
    assert errors, f"no Valgrind ERROR SUMMARY in:\n{stderr[-3000:]}"

    def lost(kind):
        m = re.search(rf"{kind} lost: ([\d,]+) bytes", stderr)
        return int(m.group(1).replace(",", "")) if m else 0  # absent: "All heap blocks were freed"

    return int(errors[-1].replace(",", "")), lost("definitely"), lost("indirectly")


def test_leak_cycles_lsan(leak_cycles_asan, unzipdir, model_description):
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0")
    proc, wall = run([leak_cycles_asan, unzipdir, model_description.guid, LEAK_CYCLES], env=env)
    print(proc.stdout.strip(), f"(AddressSanitizer + LeakSanitizer, {wall:.1f} s)")
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout}\n{proc.stderr[-5000:]}"
    assert "Sanitizer" not in proc.stderr, proc.stderr[-5000:]
    assert f"cycles={LEAK_CYCLES}" in proc.stdout


def test_lsan_sees_a_deliberate_leak(leak_cycles_asan, unzipdir, model_description):
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1")
    proc, _ = run([leak_cycles_asan, unzipdir, model_description.guid, 3, "--leak-one"], env=env)
    assert proc.returncode != 0 and "detected memory leaks" in proc.stderr, (
        f"LeakSanitizer did not report the instance leaked on purpose (exit {proc.returncode}):\n{proc.stderr[-3000:]}")


def test_leak_cycles_valgrind(valgrind, leak_cycles, unzipdir, model_description):
    proc, wall = run([valgrind, *VALGRIND_ARGS, leak_cycles, unzipdir, model_description.guid, VALGRIND_CYCLES])
    errors, definite, indirect = valgrind_summary(proc.stderr)
    print(proc.stdout.strip(), f"(Valgrind: {errors} errors, definitely lost {definite} B, "
          f"indirectly lost {indirect} B, {wall:.1f} s)")
    assert proc.returncode == 0 and errors == 0 and definite == 0 and indirect == 0, proc.stderr[-6000:]


def test_valgrind_sees_a_deliberate_leak(valgrind, leak_cycles, unzipdir, model_description):
    proc, _ = run([valgrind, *VALGRIND_ARGS, leak_cycles, unzipdir, model_description.guid, 2, "--leak-one"])
    _, definite, indirect = valgrind_summary(proc.stderr)
    assert proc.returncode == 99 and definite + indirect > 0, proc.stderr[-3000:]


def test_fmi3_leak_cycles_lsan(leak_cycles_fmi3_asan, fmi3_library):
    library, token = fmi3_library
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=0")
    proc, wall = run([leak_cycles_fmi3_asan, library, token, LEAK_CYCLES], env=env)
    print(proc.stdout.strip(), f"(FMI 3.0, AddressSanitizer + LeakSanitizer, {wall:.1f} s)")
    assert proc.returncode == 0, f"exit {proc.returncode}\n{proc.stdout}\n{proc.stderr[-5000:]}"
    assert "Sanitizer" not in proc.stderr, proc.stderr[-5000:]
    assert f"cycles={LEAK_CYCLES}" in proc.stdout


def test_lsan_sees_a_deliberate_leak_of_an_fmi3_instance(leak_cycles_fmi3_asan, fmi3_library):
    library, token = fmi3_library
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1")
    proc, _ = run([leak_cycles_fmi3_asan, library, token, 3, "--leak-one"], env=env)
    assert proc.returncode != 0 and "detected memory leaks" in proc.stderr, (
        f"LeakSanitizer did not report the instance leaked on purpose (exit {proc.returncode}):\n{proc.stderr[-3000:]}")


def test_fmi3_leak_cycles_valgrind(valgrind, leak_cycles_fmi3, fmi3_library):
    library, token = fmi3_library
    proc, wall = run([valgrind, *VALGRIND_ARGS, leak_cycles_fmi3, library, token, VALGRIND_CYCLES])
    errors, definite, indirect = valgrind_summary(proc.stderr)
    print(proc.stdout.strip(), f"(FMI 3.0 under Valgrind: {errors} errors, definitely lost {definite} B, "
          f"indirectly lost {indirect} B, {wall:.1f} s)")
    assert proc.returncode == 0 and errors == 0 and definite == 0 and indirect == 0, proc.stderr[-6000:]


def test_valgrind_sees_a_deliberate_leak_of_an_fmi3_instance(valgrind, leak_cycles_fmi3, fmi3_library):
    library, token = fmi3_library
    proc, _ = run([valgrind, *VALGRIND_ARGS, leak_cycles_fmi3, library, token, 2, "--leak-one"])
    _, definite, indirect = valgrind_summary(proc.stderr)
    assert proc.returncode == 99 and definite + indirect > 0, proc.stderr[-3000:]


def test_c_driver_under_valgrind(valgrind, gcc, tmp_path, unzipdir, model_description):
    exe = build(gcc, HERE / "c" / "driver.c", tmp_path / "driver")
    proc, wall = run([valgrind, *VALGRIND_ARGS, exe, unzipdir, model_description.guid])
    errors, definite, indirect = valgrind_summary(proc.stderr)
    print(f"C driver (1 s at 1 ms) under Valgrind: {errors} errors, definitely lost {definite} B, {wall:.1f} s")
    assert proc.returncode == 0 and errors == 0 and definite == 0 and indirect == 0, (
        f"{proc.stdout[-2000:]}\n{proc.stderr[-6000:]}")


def fuzz_binary():
    cargo = shutil.which("cargo")
    if cargo is None:
        pytest.skip("cargo is not installed (needed to find the Rust fuzz test binary)")
    proc = subprocess.run([cargo, "test", "--release", "--test", "fmi_call_fuzz", "--no-run", "--message-format=json"],
                          cwd=REPO, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    for line in proc.stdout.splitlines():
        try:
            msg = json.loads(line)
        except json.JSONDecodeError:
            continue
        if msg.get("reason") == "compiler-artifact" and msg.get("target", {}).get("name") == "fmi_call_fuzz" \
                and msg.get("executable"):
            return msg["executable"]
    pytest.fail("cargo did not report the fmi_call_fuzz test executable")


def test_rust_call_fuzz_under_valgrind(valgrind):
    exe = fuzz_binary()
    env = dict(os.environ, JETPIPE_FUZZ_SEQUENCES=VALGRIND_FUZZ_SEQUENCES, JETPIPE_FUZZ_CALLS="150")
    # the libtest harness keeps one thread handle "possibly lost": only definite/indirect count
    proc, wall = run([valgrind, *VALGRIND_ARGS, exe, "--test-threads=1", "--nocapture",
                      "generated_call_sequences_follow_the_state_table", "repeated_free_and_use_after_free",
                      "generated_fmi3_call_sequences"], env=env)
    errors, definite, indirect = valgrind_summary(proc.stderr)
    summary = [l[l.index("call fuzz"):] for l in proc.stdout.splitlines() if "call fuzz" in l]
    print(*summary, f"(under Valgrind: {errors} errors, definitely lost {definite} B, {wall:.1f} s)")
    assert proc.returncode == 0 and errors == 0 and definite == 0 and indirect == 0, (
        f"{proc.stdout[-3000:]}\n{proc.stderr[-6000:]}")
