"""The package's shape: the import contract of ``pyproject.toml`` (``lint-imports``: imports only
go down the rooms' layers, no import cycles inside a sub-package), a short package root, short
functions and a light top level."""
from __future__ import annotations

import ast
import dataclasses
import importlib
import importlib.metadata
import json
import subprocess
import sys
import tomllib
from pathlib import Path

import jaxswarm
from jaxswarm.swarm.bees import CABCConfig
from jaxswarm.swarm.core import Swarm

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "jaxswarm"
MAX_ROOT_MODULES = 8
"""Modules at the package root besides ``__init__.py`` and ``cli.py``: fewer than this."""
MAX_FUNCTION_LINES = 60
"""From ``def`` to the function's last line, docstring included."""
TOP_LEVEL = {
    **dict.fromkeys(["make", "run", "make_task", "registered", "Task"], "jaxswarm.swarm"),
    "Graph": "jaxswarm.world.graph", "Plane": "jaxswarm.world.plane",
    "paper_map": "jaxswarm.maps.paper", "load_map": "jaxswarm.maps.movingai",
    "paper_plane": "jaxswarm.maps.planes", "random_grid": "jaxswarm.maps.random",
    **dict.fromkeys(["dijkstra", "astar", "bidirectional_astar", "optimal_length", "replanner"],
                    "jaxswarm.exact"),
}
"""What ``jaxswarm.__all__`` offers besides ``__version__``, each name's home."""
LINT_IMPORTS = ("import sys; from importlinter.cli import lint_imports_command; "
                "sys.exit(lint_imports_command())")
"""The ``lint-imports`` command, run by the interpreter of the tests (its script is beside it)."""


def test_the_import_contract_is_kept():
    done = subprocess.run([sys.executable, "-c", LINT_IMPORTS, "--no-cache"], cwd=ROOT,
                          capture_output=True, text=True, timeout=300, check=False)
    assert done.returncode == 0, f"lint-imports:\n{done.stdout}\n{done.stderr}"
    assert "0 broken" in done.stdout


def test_the_contract_places_every_room():
    """Each sub-package has its layer (the layers contract is also exhaustive)."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    layers = next(c for c in config["contracts"] if c["type"] == "layers")["layers"]
    placed = {name.strip() for layer in layers for name in layer.split("|")}
    rooms = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    assert rooms <= placed, f"sub-packages without a layer: {sorted(rooms - placed)}"


def test_the_package_root_holds_few_modules():
    modules = sorted(p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py",
                                                                             "cli.py"))
    assert len(modules) < MAX_ROOT_MODULES, f"modules at the package root: {modules}"


def test_no_function_is_longer_than_60_lines():
    long = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    where = f"{path.relative_to(ROOT)}:{node.lineno}"
                    long.append(f"{where} {node.name}: {lines} lines")
    assert not long, (f"{len(long)} functions longer than {MAX_FUNCTION_LINES} lines:\n"
                      + "\n".join(long))


RUNNING = ("LANES", "lanes_for", "log_moves", "EVERY_MOVE", "room_blocks", "with_room")
"""The walker's log capacity and lane count, and the retry with room: named only in
``swarm/walking/`` and the executor (``swarm/executor/``)."""


def test_only_the_walker_and_the_executor_name_log_room_and_lanes():
    named = []
    for path in sorted(PACKAGE.rglob("*.py")):
        inside = path.relative_to(PACKAGE).parts[:2]
        if inside in (("swarm", "walking"), ("swarm", "executor")):
            continue
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            name = node.id if isinstance(node, ast.Name) else getattr(node, "attr", None)
            if isinstance(node, ast.alias):
                name = node.name
            if name in RUNNING:
                named.append(f"{path.relative_to(ROOT)}:{node.lineno} {name}")
    assert not named, "\n".join(named)


def test_a_swarm_is_five_functions_and_its_name_config_and_world():
    fields = [field.name for field in dataclasses.fields(Swarm)]
    assert fields == ["name", "config", "init", "step", "best", "default_params",
                      "check_params", "world"]
    assert "walker" not in {field.name for field in dataclasses.fields(CABCConfig)}


def test_importing_jaxswarm_starts_no_backend():
    """``jaxswarm.runtime.cpu.configure`` must still work after ``import jaxswarm`` (it refuses
    once JAX has started its backends)."""
    probe = ("import json, jaxswarm; from jaxswarm.runtime.cpu import configure; "
             "configure(threads=1); print(json.dumps(sorted(jaxswarm.__all__)))")
    done = subprocess.run([sys.executable, "-c", probe], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.strip().splitlines()[-1]) == sorted(jaxswarm.__all__)


def test_the_top_level_offers_the_first_names_from_their_homes():
    assert sorted(jaxswarm.__all__) == sorted([*TOP_LEVEL, "__version__"])
    for name, home in TOP_LEVEL.items():
        assert getattr(jaxswarm, name) is getattr(importlib.import_module(home), name), name
    assert jaxswarm.__version__ == importlib.metadata.version("jaxswarm")


def test_the_package_ships_its_type_marker():
    assert (PACKAGE / "py.typed").is_file()
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert "py.typed" in setuptools["package-data"]["jaxswarm"]
