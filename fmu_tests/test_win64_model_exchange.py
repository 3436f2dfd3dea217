"""Model Exchange of the win64 binary under wine (issue 44): a C importer compiled with
MinGW-w64 against the standard FMI 2.0 headers (fmu_tests/c/model_exchange_driver.c) integrates
the first second of the standard scenario through the Model Exchange calls of
binaries/win64, and must give what the same importer compiled with gcc gives with
binaries/linux64 to 1e-9 relative; the linux64 run follows the Co-Simulation importer
(fmu_tests/c/scenario_driver.c) within 0.005 N RMS."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

from test_win64 import HERE, WINE, binaries, read, tool  # noqa: F401

DRIVER = HERE / "c" / "model_exchange_driver.c"
FMI_HEADERS = Path(__import__("fmpy").__file__).resolve().parent / "c-code"


def compile_driver(compiler: str, source: Path, out: Path, libs: list[str]) -> Path:
    cmd = [compiler, "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", f"-I{FMI_HEADERS}", str(source), "-o", str(out),
           *libs]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stderr}"
    return out


def test_model_exchange_of_win64_under_wine_gives_the_linux64_outputs_and_follows_co_simulation(
        binaries, model_description, tmp_path):  # noqa: F811
    guid = model_description.guid
    so = str(binaries / "linux64" / "JetPipeActuator.so")
    linux_driver = compile_driver(tool("gcc"), DRIVER, tmp_path / "me_driver", ["-ldl", "-lm"])
    linux = subprocess.run([str(linux_driver), so, guid], capture_output=True, text=True, timeout=300)
    assert linux.returncode == 0, linux.stderr
    a = read(linux.stdout)
    assert a.shape == (100, 6)

    # against Co-Simulation (its first second, the outputs at the same samples)
    cs_driver = compile_driver(tool("gcc"), HERE / "c" / "scenario_driver.c", tmp_path / "cs_driver", ["-ldl", "-lm"])
    cs = subprocess.run([str(cs_driver), so, guid], capture_output=True, text=True, timeout=300)
    assert cs.returncode == 0, cs.stderr
    c = read(cs.stdout)[:100]
    assert np.allclose(a[:, 0], c[:, 0], rtol=0, atol=1e-12)
    rms = float(np.sqrt(np.mean((a[:, 1] - c[:, 1]) ** 2)))
    print(f"Model Exchange (RK4, 10 us) vs Co-Simulation from C, first second of the standard scenario: "
          f"F_act RMS {rms:.2e} N")
    assert rms < 0.005

    windows_driver = compile_driver(tool("x86_64-w64-mingw32-gcc"), DRIVER, tmp_path / "me_driver.exe", [])
    if not Path(WINE).exists():
        pytest.fail("wine64 is not installed (bash scripts/build_win64.sh installs it)", pytrace=False)
    env = dict(os.environ, WINEPREFIX=str(tmp_path / "wineprefix"), WINEDEBUG="-all")
    dll = binaries / "win64" / "JetPipeActuator.dll"
    windows = subprocess.run([WINE, str(windows_driver), "Z:" + str(dll).replace("/", "\\"), guid],
                             capture_output=True, text=True, timeout=600, env=env, cwd=tmp_path)
    assert windows.returncode == 0, f"wine64 exit {windows.returncode}\n{windows.stdout[-2000:]}\n{windows.stderr[-3000:]}"
    b = read(windows.stdout)
    assert b.shape == a.shape and np.array_equal(a[:, 0], b[:, 0])
    scale = np.maximum(np.maximum(np.abs(a[:, 1:]), np.abs(b[:, 1:])), 1e-12 * np.max(np.abs(a[:, 1:]), axis=0))
    rel = float((np.abs(a[:, 1:] - b[:, 1:]) / scale).max())
    print(f"Model Exchange, win64 under wine64 vs linux64: max relative difference {rel:.2e}")
    assert rel <= 1e-9
