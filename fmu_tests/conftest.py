"""Fixtures of the FMU test suite.

The FMU is taken from $JETPIPE_FMU or ../dist/JetPipeActuator.fmu (relative to this folder),
extracted once per session; the model description is read once.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import fmpy
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))

import jetpipe_fmu  # noqa: E402
from jetpipe_fmu import initialize, make_slave, release, vr_map  # noqa: E402


def pytest_configure(config):
    config.addinivalue_line("markers", "broad: a case of a broad sweep, run by scripts/bench_cases.sh "
                            "(JETPIPE_BROAD=1), not by the test command")


def pytest_collection_modifyitems(config, items):
    if os.environ.get("JETPIPE_BROAD") == "1":
        return
    skip = pytest.mark.skip(reason="a broad case: scripts/bench_cases.sh runs every case (JETPIPE_BROAD=1)")
    for item in items:
        if "broad" in item.keywords:
            item.add_marker(skip)


@pytest.fixture(scope="session")
def fmu_path() -> Path:
    env = os.environ.get("JETPIPE_FMU")
    path = Path(env) if env else jetpipe_fmu.default_fmu_path()
    if not path.is_file():
        pytest.fail(f"FMU not found at {path} (build it with `cargo run --release --bin jetpipe -- package` "
                    "or point JETPIPE_FMU at it)", pytrace=False)
    return path.resolve()


@pytest.fixture(scope="session")
def unzipdir(fmu_path, tmp_path_factory) -> Path:
    return Path(fmpy.extract(str(fmu_path), str(tmp_path_factory.mktemp("fmu"))))


@pytest.fixture(scope="session")
def model_description(fmu_path):
    return fmpy.read_model_description(str(fmu_path))


@pytest.fixture(scope="session")
def vrs(model_description) -> dict:
    return vr_map(model_description)


@pytest.fixture(scope="session")
def defaults(model_description) -> dict:
    """Start values of the Real parameters, as floats."""
    return {
        v.name: float(v.start)
        for v in model_description.modelVariables
        if v.causality == "parameter" and v.type == "Real"
    }


@pytest.fixture
def make_fmu(unzipdir, model_description):
    """Factory: make_fmu(**kwargs) -> instantiated FMU2Slave with a recording logger in `.log`.

    Every instance made through it is freed at the end of the test.
    """
    made = []

    def factory(**kwargs):
        fmu = make_slave(unzipdir, model_description, **kwargs)
        made.append(fmu)
        return fmu

    yield factory
    for fmu in made:
        release(fmu)


@pytest.fixture
def init_fmu(make_fmu, vrs):
    """Factory: init_fmu(inputs=(v_DA, x_s), **initialize_kwargs) -> initialised instance."""

    def factory(inputs=(0.0, 0.054), instance_kwargs=None, **kwargs):
        fmu = make_fmu(**(instance_kwargs or {}))
        initialize(fmu, vrs, inputs=inputs, **kwargs)
        return fmu

    return factory
