"""The FMI 3.0 archive's binaries from C (issue 44): an FMI 3.0 importer compiled with gcc and with
MinGW-w64 against the standard FMI 3.0 headers (fmu_tests/c/fmi3_driver.c) runs Co-Simulation (the
standard scenario, 10 s) and Model Exchange (RK4, the first second) through binaries/x86_64-linux
and, under Debian's wine64, binaries/x86_64-windows of dist/JetPipeActuator-fmi3.fmu. x86_64-linux
must give what the FMI 2.0 importers (scenario_driver.c, model_exchange_driver.c) give through the
same library's fmi2 functions, bit for bit; x86_64-windows must give the x86_64-linux outputs to
1e-9 relative."""

from __future__ import annotations

import os
import subprocess
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest

from test_win64 import HERE, WINE, read, tool

FMI_HEADERS = Path(fmpy.__file__).resolve().parent / "c-code"
DRIVER3 = HERE / "c" / "fmi3_driver.c"
REPO = HERE.parent


def build(compiler, source, out, libs):
    cmd = [compiler, "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", f"-I{FMI_HEADERS}", str(source), "-o", str(out), *libs]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stderr}"
    return out


@pytest.fixture(scope="module")
def fmi3_binaries(tmp_path_factory):
    path = Path(os.environ.get("JETPIPE_FMU3", REPO / "dist" / "JetPipeActuator-fmi3.fmu"))
    if not path.is_file():
        pytest.fail(f"{path} not found (bash scripts/package.sh)", pytrace=False)
    d = tmp_path_factory.mktemp("fmi3bin")
    with zipfile.ZipFile(path) as zf:
        names = set(zf.namelist())
        assert "binaries/x86_64-windows/JetPipeActuator.dll" in names, \
            "no binaries/x86_64-windows in the FMI 3.0 archive (JETPIPE_WIN64=1 bash scripts/package.sh)"
        zf.extract("binaries/x86_64-windows/JetPipeActuator.dll", d)
        zf.extract("binaries/x86_64-linux/JetPipeActuator.so", d)
        token = fmpy.read_model_description(str(path)).guid
    return d / "binaries", token


@pytest.mark.parametrize("mode, fmi2_driver", [("cs", "scenario_driver.c"), ("me", "model_exchange_driver.c")])
def test_fmi3_from_c_on_x86_64_linux_is_fmi2_bit_for_bit_and_x86_64_windows_under_wine_follows_it(
        fmi3_binaries, tmp_path, mode, fmi2_driver):
    binaries, token = fmi3_binaries
    so = str(binaries / "x86_64-linux" / "JetPipeActuator.so")
    linux3 = build(tool("gcc"), DRIVER3, tmp_path / "fmi3_driver", ["-ldl", "-lm"])
    run = subprocess.run([str(linux3), so, token, mode], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    a = read(run.stdout)
    linux2 = build(tool("gcc"), HERE / "c" / fmi2_driver, tmp_path / "fmi2_driver", ["-ldl", "-lm"])
    run2 = subprocess.run([str(linux2), so, token], capture_output=True, text=True, timeout=600)
    assert run2.returncode == 0, run2.stderr
    b2 = read(run2.stdout)
    assert a.shape == b2.shape == ((1000, 6) if mode == "cs" else (100, 6))
    assert np.array_equal(a, b2), f"{mode}: FMI 3.0 and FMI 2.0 differ by {np.max(np.abs(a - b2)):.3e}"
    assert np.ptp(a[:, 1]) > 1.0  # the force moves

    windows = build(tool("x86_64-w64-mingw32-gcc"), DRIVER3, tmp_path / "fmi3_driver.exe", [])
    if not Path(WINE).exists():
        pytest.fail("wine64 is not installed (bash scripts/build_win64.sh installs it)", pytrace=False)
    env = dict(os.environ, WINEPREFIX=str(tmp_path / "wineprefix"), WINEDEBUG="-all")
    dll = binaries / "x86_64-windows" / "JetPipeActuator.dll"
    run = subprocess.run([WINE, str(windows), "Z:" + str(dll).replace("/", "\\"), token, mode],
                         capture_output=True, text=True, timeout=900, env=env, cwd=tmp_path)
    assert run.returncode == 0, f"wine64 exit {run.returncode}\n{run.stdout[-2000:]}\n{run.stderr[-3000:]}"
    b = read(run.stdout)
    assert b.shape == a.shape and np.array_equal(a[:, 0], b[:, 0])
    scale = np.maximum(np.maximum(np.abs(a[:, 1:]), np.abs(b[:, 1:])), 1e-12 * np.max(np.abs(a[:, 1:]), axis=0))
    rel = float((np.abs(a[:, 1:] - b[:, 1:]) / scale).max())
    print(f"FMI 3.0 {mode}: x86_64-windows under wine64 vs x86_64-linux: max relative difference {rel:.2e}")
    assert rel <= 1e-9
