"""The problems the tables plan on: a map, its start-goal task and the optimum the runs are
reported against."""
from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

from jaxswarm.exact import dijkstra
from jaxswarm.maps.named import named_map
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
