"""A C importer (fmu_tests/c/driver.c) built with gcc against the standard FMI 2.0 headers, and
the compatibility of the cbindgen header with fmi2Functions.h."""

import math
import shutil
import subprocess
from pathlib import Path

import pytest
import fmpy

import scenarios
from jetpipe_fmu import initialize

HERE = Path(__file__).resolve().parent
REPO = HERE.parent
FMI_HEADERS = Path(fmpy.__file__).resolve().parent / "c-code"
GENERATED_HEADER = REPO / "target" / "include" / "jetpipe_fmi2.h"


@pytest.fixture(scope="module")
def gcc():
    path = shutil.which("gcc")
    if path is None:
        pytest.skip("gcc is not installed")
    return path


@pytest.fixture(scope="module")
def driver(gcc, tmp_path_factory):
    exe = tmp_path_factory.mktemp("cdriver") / "driver"
    cmd = [gcc, "-std=c99", "-O1", "-Wall", "-Wextra", "-Werror", f"-I{FMI_HEADERS}",
           str(HERE / "c" / "driver.c"), "-o", str(exe), "-ldl"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"{' '.join(cmd)}\n{proc.stderr}"
    return exe


def parse(stdout):
    values = {}
    for line in stdout.splitlines():
        if "=" in line and not line.startswith("["):
            key, _, value = line.partition("=")
            values[key.strip()] = float(value)
    return values


def test_c_driver(driver, unzipdir, model_description, make_fmu, vrs, defaults):
    proc = subprocess.run([str(driver), str(unzipdir), model_description.guid],
                          capture_output=True, text=True, timeout=120, stdin=subprocess.DEVNULL)
    print(proc.stdout)
    assert proc.returncode == 0, f"driver failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}"
    values = parse(proc.stdout)
    assert values["early_doStep_status"] == 3
    F, P1, P2 = values["F_act"], values["P1"], values["P2"]

    p = defaults
    A_p = math.pi * p["D_cyl"] ** 2 / 4
    spring = float(scenarios.spring_force(0.054, p["k_spring"], p["L_spring0"], p["L_s"], p["L_p"]))
    assert spring <= F <= A_p * (p["P_s"] - p["P_r"]), f"F_act {F} outside [{spring}, {A_p * (p['P_s'] - p['P_r'])}]"

    # the same run through FMPy: same steps, same accumulation of time
    fmu = make_fmu()
    initialize(fmu, vrs, inputs=(2.5, 0.054), stop_time=1.0)
    t = 0.0
    for _ in range(1000):
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=1e-3)
        t += 1e-3
    F_py, P1_py, P2_py = fmu.getReal([vrs["F_act"], vrs["P1"], vrs["P2"]])
    for name, c_val, py_val in (("F_act", F, F_py), ("P1", P1, P1_py), ("P2", P2, P2_py)):
        assert math.isclose(c_val, py_val, rel_tol=1e-9), f"{name}: C driver {c_val!r}, FMPy {py_val!r}"


def test_generated_header_compatible(gcc, tmp_path):
    if not GENERATED_HEADER.is_file():
        pytest.skip(f"{GENERATED_HEADER.relative_to(REPO)} does not exist (the Rust build did not generate it)")
    tu = tmp_path / "check_header.c"
    tu.write_text('#include "fmi2Functions.h"\n#include "jetpipe_fmi2.h"\nint main(void) { return 0; }\n')
    cmd = [gcc, "-std=c99", "-Wall", "-Werror", "-fsyntax-only", f"-I{FMI_HEADERS}", f"-I{GENERATED_HEADER.parent}", str(tu)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    assert proc.returncode == 0, f"the generated header conflicts with fmi2Functions.h:\n{proc.stderr}"
