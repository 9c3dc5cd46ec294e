"""The compile ledger: every distinct program a test run builds, by the test file that builds it.

Most of the suite's time is compiling (a swarm at a size, a batch width, a script at its own
sizes), so the programs are what the suite is budgeted in. Each test process records the
programs it builds (:mod:`program_hooks`: XLA programs by a fingerprint of their lowered module,
numba functions by dispatcher and signature), and so does every Python process a test starts.

A file's programs are the programs its tests use, whatever ran before them: the process forgets
its compiled programs when the next test is of another file and around each session fixture's
set-up (:func:`program_hooks.forget`: JAX keeps their traces and lowered modules and the on-disk
caches the programs, so forgetting costs a load, not a trace or a compile). A session fixture's
programs are counted for the file that defines it, whichever test first asks for it. So a
file's count is the same on any number of workers and in any order, and a test that adds a
program to a file adds it to that file's count.

The controller joins the workers' records (a program built in two workers is one program) and,
at the end of the run, prints the total and the ten files that built the most. In the default
tier (``-m 'not slow'``) each file has a budget, in :data:`BUDGETS`; a file over its budget fails
the run, named with the programs it built. ``--compile-ledger PATH`` writes every program, its
name and the files that built it to ``PATH`` (JSON).
"""
from __future__ import annotations

import collections
import inspect
import json
import os
import shutil
import sys
import tempfile
import tomllib
from pathlib import Path

import pytest

SITE = Path(__file__).parent / "site"
sys.path.insert(0, str(SITE))
import program_hooks  # noqa: E402 (from SITE)

BUDGETS = Path(__file__).parent / "compile_budgets.toml"
"""The default tier's table of programs per test file."""
DEFAULT_TIER = "not slow"
"""The marker expression of the default tier (``pyproject.toml``'s addopts)."""
SHOWN = 10
"""Files listed at the end of a run."""
LEDGER = pytest.StashKey["Ledger"]()
OVER = pytest.StashKey[list]()


class Ledger:
    """The programs one process (or, in the controller, the whole run) built, by owner: a test
    file, or the file defining a session fixture.

    Attributes:
      built: ``{owner: {fingerprint: [program name, seconds compiling or loading it]}}``.
      owner: where programs built now are counted.
      window: the test file whose programs the process holds in memory (None: none).
    """

    def __init__(self, root: Path):
        self.root = root
        self.built: dict[str, dict[str, list]] = {}
        self.owner = "(collection)"
        self.window: str | None = None
        self.outbox: Path | None = None

    def record(self, fingerprint: str, name: str, seconds: float = 0.0, owner: str | None = None
               ) -> None:
        """Count a program for ``owner`` (default :attr:`owner`)."""
        programs = self.built.setdefault(self.owner if owner is None else owner, {})
        programs.setdefault(fingerprint, [name, 0.0])[1] += seconds

    def join(self, built: dict[str, dict[str, list]]) -> None:
        for owner, programs in built.items():
            for fingerprint, (name, seconds) in programs.items():
                self.record(fingerprint, name, seconds, owner)

    def collect_subprocesses(self) -> None:
        """Count what the processes started since the last call built, for :attr:`owner`."""
        if self.outbox is None:
            return
        for written in sorted(self.outbox.glob("*.json")):
            for fingerprint, (name, seconds) in json.loads(written.read_text()).items():
                self.record(fingerprint, name, seconds)
            written.unlink()

    def relative(self, path: str) -> str:
        return os.path.relpath(path, self.root)


def pytest_addoption(parser):
    parser.addoption("--compile-ledger", metavar="PATH", default=None,
                     help="write every program the run built, and the files that built it, "
                          "to PATH (JSON)")


def _is_controller(config) -> bool:
    return not hasattr(config, "workerinput") and bool(getattr(config.option, "numprocesses", 0))


def pytest_configure(config):
    ledger = config.stash[LEDGER] = Ledger(Path(config.rootpath))
    if _is_controller(config):
        return
    program_hooks.install(ledger.record)
    ledger.outbox = Path(tempfile.mkdtemp(prefix="compile-ledger-"))
    os.environ[program_hooks.OUT_VARIABLE] = str(ledger.outbox)
    os.environ["PYTHONPATH"] = os.pathsep.join(
        [str(SITE), *filter(None, [os.environ.get("PYTHONPATH")])])


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item, nextitem):
    ledger = item.config.stash[LEDGER]
    file = item.nodeid.split("::")[0]
    if ledger.window != file:
        program_hooks.forget()
        ledger.window = file
    ledger.owner = file
    try:
        return (yield)
    finally:
        ledger.collect_subprocesses()
        ledger.owner = "(between tests)"


@pytest.hookimpl(wrapper=True)
def pytest_fixture_setup(fixturedef, request):
    if fixturedef.scope != "session":
        return (yield)
    ledger = request.config.stash[LEDGER]
    outer = ledger.owner
    ledger.collect_subprocesses()
    program_hooks.forget()
    ledger.owner = ledger.relative(inspect.getsourcefile(fixturedef.func))
    try:
        return (yield)
    finally:
        ledger.collect_subprocesses()
        program_hooks.forget()
        ledger.owner = outer


@pytest.hookimpl(tryfirst=True)
def pytest_sessionfinish(session):
    ledger = session.config.stash[LEDGER]
    if ledger.outbox is not None:
        shutil.rmtree(ledger.outbox, ignore_errors=True)
    if hasattr(session.config, "workerinput"):
        session.config.workeroutput["compile_ledger"] = ledger.built
        return
    if session.config.getoption("--compile-ledger"):
        _write(ledger, Path(session.config.getoption("--compile-ledger")))
    if _tier(session.config) == "default":
        over = _over_budget(ledger)
        session.config.stash[OVER] = over
        if over and session.exitstatus == pytest.ExitCode.OK:
            session.exitstatus = pytest.ExitCode.TESTS_FAILED


@pytest.hookimpl(optionalhook=True)  # pytest-xdist's hook: absent without it
def pytest_testnodedown(node, error):
    node.config.stash[LEDGER].join(getattr(node, "workeroutput", {}).get("compile_ledger", {}))


def _tier(config) -> str:
    expression = (config.option.markexpr or "").strip()
    return {DEFAULT_TIER: "default", "slow": "slow"}.get(expression, f"-m {expression!r}")


def budgets() -> dict[str, int]:
    """The default tier's budget of each test file (:data:`BUDGETS`); a file not named has 0."""
    return tomllib.loads(BUDGETS.read_text())["programs"]


def _over_budget(ledger: Ledger) -> list[str]:
    table = budgets()
    return [f"{owner} built {len(programs)} programs, over its budget of {table.get(owner, 0)} in "
            f"{ledger.relative(BUDGETS)}: " + ", ".join(sorted({n for n, _ in programs.values()}))
            for owner, programs in sorted(ledger.built.items())
            if len(programs) > table.get(owner, 0)]


def _write(ledger: Ledger, path: Path) -> None:
    programs: dict[str, dict] = {}
    for owner, built in ledger.built.items():
        for fingerprint, (name, seconds) in built.items():
            program = programs.setdefault(fingerprint, {"name": name, "files": {}})
            program["files"][owner] = round(seconds, 3)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"programs": programs,
                                "files": {o: len(b) for o, b in sorted(ledger.built.items())}},
                               indent=1, sort_keys=True))


def pytest_terminal_summary(terminalreporter, config):
    if not hasattr(config, "workerinput"):
        ledger = config.stash[LEDGER]
        writer = terminalreporter
        unique = {f for built in ledger.built.values() for f in built}
        xla = sum(f.startswith("xla:") for f in unique)
        writer.write_sep("=", f"compile ledger ({_tier(config)} tier): {len(unique)} programs "
                              f"({xla} XLA, {len(unique) - xla} numba)")
        shared = collections.Counter(f for built in ledger.built.values() for f in built)
        writer.write_line(f"{'programs':>9} {'own':>5} {'budget':>6} {'seconds':>8}  file (own: "
                          "built by no other file; seconds: XLA compiling or loading them)")
        table = budgets()
        busiest = sorted(ledger.built.items(), key=lambda item: (-len(item[1]), item[0]))
        for owner, built in busiest[:SHOWN]:
            own = sum(shared[f] == 1 for f in built)
            seconds = sum(s for _, s in built.values())
            writer.write_line(f"{len(built):>9} {own:>5} {table.get(owner, 0):>6} {seconds:>8.1f}"
                              f"  {owner}")
        for line in config.stash.get(OVER, []):
            writer.write_line(f"OVER BUDGET: {line}", red=True, bold=True)
