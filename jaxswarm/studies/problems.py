"""The problems the tables plan on: a map, its start-goal task and the optimum the runs are
reported against."""
from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

from jaxswarm.exact import dijkstra
from jaxswarm.maps.movingai import load_map, load_scenarios
from jaxswarm.maps.named import named_map
from jaxswarm.studies import provenance
from jaxswarm.sweep.maps import MOVINGAI_DATA
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
    """

    label: str
    graph: Graph
    start: tuple[int, int]
    goal: tuple[int, int]
    task: Task
    optimum: float


def make_problem(label: str, graph: Graph, start: tuple[int, int], goal: tuple[int, int], *,
                 planner: Callable[..., Solution] = dijkstra) -> Problem:
    """The problem of ``graph`` from ``start`` to ``goal``, its optimum found by ``planner``
    (an exact planner of :mod:`jaxswarm.exact`)."""
    return Problem(label, graph, start, goal, make_task(graph, start, goal),
                   float(planner(graph, start, goal).cost))


def named_problem(name: str, *, seed: int = 0,
                  planner: Callable[..., Solution] = dijkstra) -> Problem:
    """The problem of the map ``name`` (a paper map or ``pathmapWxH`` seeded by ``seed``, see
    :func:`jaxswarm.maps.named.named_map`) with its own start and goal."""
    return make_problem(*named_map(name, seed=seed), planner=planner)


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
    rows = sorted((row for row in load_scenarios(scenario_path)
                   if math.isfinite(row.optimal_length)), key=lambda row: row.optimal_length)
    if not rows:
        raise ValueError(f"{scenario_path}: no row has a path")
    row = rows[len(rows) // 2]
    return make_problem(name, load_map(map_path), row.start, row.goal, planner=planner)
