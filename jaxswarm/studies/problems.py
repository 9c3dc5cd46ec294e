"""The problems the tables plan on: a map, its start-goal task and the optimum the runs are
reported against."""
from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any, NamedTuple

from jaxswarm.exact import dijkstra
from jaxswarm.maps.entry import MOVINGAI_DATA, ResolvedMap, resolve
from jaxswarm.maps.movingai import load_scenarios
from jaxswarm.maps.named import named_entry
from jaxswarm.studies import provenance
from jaxswarm.swarm import Task, make_task
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution


class Problem(NamedTuple):
    """A map with its query.

    Attributes:
      label: the map's name in the tables.
      graph: the map's Graph.
      start, goal: (x, y) cells.
      task: the swarms' Task (start and goal as node indices, i32[] each).
      optimum: the exact planner's path length (a Python float).
      entry: the map entry that builds the same graph, start and goal again
        (:mod:`jaxswarm.maps.entry`), or None for a map built otherwise.
    """

    label: str
    graph: Graph
    start: tuple[int, int]
    goal: tuple[int, int]
    task: Task
    optimum: float
    entry: Any = None


def make_problem(label: str, graph: Graph, start: tuple[int, int], goal: tuple[int, int], *,
                 planner: Callable[..., Solution] = dijkstra, entry=None) -> Problem:
    """The problem of ``graph`` from ``start`` to ``goal``, its optimum found by ``planner``
    (an exact planner of :mod:`jaxswarm.exact`); ``entry``: the map entry that builds it."""
    return Problem(label, graph, start, goal, make_task(graph, start, goal),
                   float(planner(graph, start, goal).cost), entry)


def named_problem(name: str, *, seed: int = 0,
                  planner: Callable[..., Solution] = dijkstra) -> Problem:
    """The problem of the map ``name`` (a paper map or ``pathmapWxH`` seeded by ``seed``, see
    :func:`jaxswarm.maps.named.named_entry`) with its own start and goal, labelled ``name``."""
    entry = named_entry(name, seed=seed)
    return _resolved_problem(name, resolve(entry), entry, planner)


def movingai_folder() -> Path:
    """The folder of the Moving AI MAPF maps and scenarios: ``$JAXSWARM_MOVINGAI/mapf``, else
    ``../shared/benchdata/movingai/mapf`` beside the repository."""
    named = os.environ.get(MOVINGAI_DATA)
    if named:
        return Path(named) / "mapf"
    return provenance.ROOT.parent / "shared" / "benchdata" / "movingai" / "mapf"


def scenario_problem(folder: Path, name: str, *,
                     planner: Callable[..., Solution] = dijkstra) -> Problem:
    """The problem of Moving AI map ``name`` (``folder/name.map``) from the mid-length row of its
    even scenario file (``name-even-1.scen``): of the rows with a path, sorted by their
    published optimum, the middle one (the upper of two). Its optimum is ``planner``'s.

    Raises:
      ValueError: the map or its scenario file is missing, or no row has a path.
    """
    map_path, scenario_path = folder / f"{name}.map", folder / f"{name}-even-1.scen"
    for path in (map_path, scenario_path):
        if not path.is_file():
            raise ValueError(f"Moving AI file {path} not found")
    scenarios = load_scenarios(scenario_path)
    rows = sorted((index for index, row in enumerate(scenarios)
                   if math.isfinite(row.optimal_length)),
                  key=lambda index: scenarios[index].optimal_length)
    if not rows:
        raise ValueError(f"{scenario_path}: no row has a path")
    index = rows[len(rows) // 2]
    entry = dict(movingai=_entry_path(map_path), scenario=index,
                 scenario_file=scenario_path.name)
    return _resolved_problem(name, resolve(entry, base_dir=movingai_folder().parent), entry,
                             planner)


def _resolved_problem(label: str, resolved: ResolvedMap, entry,
                      planner: Callable[..., Solution]) -> Problem:
    """The problem of a resolved map entry, labelled ``label``, its optimum ``planner``'s."""
    optimum = float(planner(resolved.world, resolved.start, resolved.goal).cost)
    return Problem(label, resolved.world, resolved.start, resolved.goal, resolved.task, optimum,
                   entry)


def _entry_path(map_path: Path) -> str:
    """``map_path`` as a map entry names it: relative to the Moving AI folder (the parent of
    :func:`movingai_folder`, which ``$JAXSWARM_MOVINGAI`` names to a sweep) where it lies
    there, so that the entry holds on another machine; else absolute."""
    folder = movingai_folder().parent.resolve()
    if map_path.resolve().is_relative_to(folder):
        return str(map_path.resolve().relative_to(folder))
    return str(map_path.resolve())
