import os
from pathlib import Path

import pytest
from jaxswarm.runtime.cpu import THREADS_VARIABLE

SHARED = Path(os.environ.get("JAXSWARM_SHARED", Path(__file__).resolve().parents[2] / "shared"))
MOVINGAI = SHARED / "benchdata" / "movingai"
# Where the library looks for Moving AI maps named in sweep specs (it never guesses a folder).
os.environ.setdefault("JAXSWARM_MOVINGAI", str(MOVINGAI))
# Each pytest-xdist worker gets its share of the cores for XLA's thread pool (by default each
# would take one thread per core, and the workers' threads would take turns on the same cores);
# the scripts and notebooks a worker starts inherit it.
if "PYTEST_XDIST_WORKER_COUNT" in os.environ:
    os.environ.setdefault(THREADS_VARIABLE, str(max(
        1, (os.cpu_count() or 1) // int(os.environ["PYTEST_XDIST_WORKER_COUNT"]))))


@pytest.fixture(scope="session")
def movingai_dir():
    if not MOVINGAI.is_dir():
        if os.environ.get("CI"):
            pytest.fail(f"Moving AI data not found at {MOVINGAI} (CI must have ../shared)")
        pytest.skip(f"Moving AI data not found at {MOVINGAI}")
    return MOVINGAI
