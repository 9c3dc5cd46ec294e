import os
from pathlib import Path

import pytest
import sizes
from jaxswarm.runtime.cpu import THREADS_VARIABLE
from jaxswarm.runtime.programs import release_if_crowded

pytest_plugins = ["compile_ledger"]

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


@pytest.fixture(autouse=True)
def _room_for_programs():
    """A worker compiles hundreds of programs; XLA's code pages would exhaust the process's
    memory mappings (:mod:`jaxswarm.runtime.programs`), so each test ends by letting them go once
    the worker holds half its limit."""
    yield
    release_if_crowded()


@pytest.fixture(scope="session")
def movingai_dir():
    if not MOVINGAI.is_dir():
        if os.environ.get("CI"):
            pytest.fail(f"Moving AI data not found at {MOVINGAI} (CI must have ../shared)")
        pytest.skip(f"Moving AI data not found at {MOVINGAI}")
    return MOVINGAI


@pytest.fixture(scope="session")
def swarm_run(request) -> sizes.SharedRun:
    """The run alone of the registered swarm that ``request.param`` names (indirect
    parametrization: ``@pytest.mark.parametrize("swarm_run", ["rfd"], indirect=True)``) at the
    shared size (:func:`sizes.shared_run`), made once per worker for every test outside its
    conformance checks that needs a run of that swarm (the figures drawn of it, its memory's
    shape). Its conformance checks compile the same program and replay its golden record
    themselves: the compile ledger forgets a process's programs around a session fixture, so
    reading the fixture there would load the program twice more."""
    return sizes.shared_run(request.param)
