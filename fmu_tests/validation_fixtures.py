"""pytest fixture shared by the test_validation_*.py modules (import it by name)."""

import pytest

from validation import FmuContext


@pytest.fixture(scope="session")
def vctx(fmu_path):
    ctx = FmuContext(fmu_path)
    yield ctx
    ctx.close()
