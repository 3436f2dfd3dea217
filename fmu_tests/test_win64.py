"""binaries/win64 of dist/JetPipeActuator.fmu (issue 21), built by scripts/build_win64.sh, run
under Debian's wine64 by a C importer compiled with MinGW-w64 against the standard FMI 2.0
headers (fmu_tests/c/scenario_driver.c): the standard scenario must give the outputs of
binaries/linux64, run by the same importer compiled with gcc, to 1e-9 relative."""

from __future__ import annotations

import csv
import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest

HERE = Path(__file__).resolve().parent
FMI_HEADERS = Path(fmpy.__file__).resolve().parent / "c-code"
DRIVER = HERE / "c" / "scenario_driver.c"
WINE = shutil.which("wine64") or "/usr/lib/wine/wine64"


def tool(name: str) -> str:
    path = shutil.which(name)
    if path is None:
        pytest.fail(f"{name} is not installed (bash scripts/build_win64.sh installs it)", pytrace=False)
    return path


def compile_driver(compiler: str, out: Path, libs: list[str]) -> Path:
    cmd = [compiler, "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", f"-I{FMI_HEADERS}", str(DRIVER), "-o", str(out), *libs]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stderr}"
    return out


def read(stdout: str) -> np.ndarray:
    rows = list(csv.reader(stdout.splitlines()))
    assert rows[0] == ["t", "F_act", "P1", "P2", "i", "x_jp"], rows[0]
    return np.array([[float(x) for x in r] for r in rows[1:]])


@pytest.fixture(scope="module")
def binaries(fmu_path, tmp_path_factory):
    d = tmp_path_factory.mktemp("win64")
    with zipfile.ZipFile(fmu_path) as zf:
        names = set(zf.namelist())
        assert "binaries/win64/JetPipeActuator.dll" in names, "no binaries/win64 in the FMU (scripts/build_win64.sh)"
        zf.extract("binaries/win64/JetPipeActuator.dll", d)
        zf.extract("binaries/linux64/JetPipeActuator.so", d)
    return d / "binaries"


def test_win64_gives_the_linux64_outputs(binaries, model_description, tmp_path):
    linux_driver = compile_driver(tool("gcc"), tmp_path / "driver", ["-ldl", "-lm"])
    windows_driver = compile_driver(tool("x86_64-w64-mingw32-gcc"), tmp_path / "driver.exe", [])
    if not Path(WINE).exists():
        pytest.fail("wine64 is not installed (bash scripts/build_win64.sh installs it)", pytrace=False)
    guid = model_description.guid

    linux = subprocess.run([str(linux_driver), str(binaries / "linux64" / "JetPipeActuator.so"), guid],
                           capture_output=True, text=True, timeout=300)
    assert linux.returncode == 0, linux.stderr
    env = dict(os.environ, WINEPREFIX=str(tmp_path / "wineprefix"), WINEDEBUG="-all")
    dll = binaries / "win64" / "JetPipeActuator.dll"
    windows = subprocess.run([WINE, str(windows_driver), "Z:" + str(dll).replace("/", "\\"), guid],
                             capture_output=True, text=True, timeout=600, env=env, cwd=tmp_path)
    assert windows.returncode == 0, f"wine64 exit {windows.returncode}\n{windows.stdout[-2000:]}\n{windows.stderr[-3000:]}"

    a, b = read(linux.stdout), read(windows.stdout)
    assert a.shape == b.shape == (1000, 6)
    assert np.array_equal(a[:, 0], b[:, 0])
    # Relative to the larger of the two values, with a floor of 1e-12 of the output's range
    # for the values that cross zero (i, x_jp).
    scale = np.maximum(np.maximum(np.abs(a[:, 1:]), np.abs(b[:, 1:])), 1e-12 * np.max(np.abs(a[:, 1:]), axis=0))
    rel = np.abs(a[:, 1:] - b[:, 1:]) / scale
    print(f"win64 under wine64 vs linux64, standard scenario: max relative difference {rel.max():.2e} "
          f"(F_act at 10 s: {b[-1, 1]:.12g} N vs {a[-1, 1]:.12g} N)")
    assert rel.max() <= 1e-9
    # Not vacuous: the outputs move over the scenario.
    assert np.ptp(a[:, 1]) > 10.0
