"""The sizes the tests share. Every new combination of a swarm, a map shape, an agent count and
an iteration count is a new XLA program (seconds to a minute of compiling), so a test that does
not need sizes of its own takes these, and varies a run's length through ``run``'s traced
``budget`` rather than its static ``iterations``."""
from typing import Any, NamedTuple

import jax
import numpy as np

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import Swarm, Task, Trace, make, make_task, run
from jaxswarm.world.graph import Graph, grid_graph
from jaxswarm.world.plane import Plane, make_plane

MAP = "maze20"
"""The RFD paper's 20 x 20 maze: every swarm finds a path on it within a few iterations."""
AGENTS = 32
"""Drops, ants or bees of one iteration (with 16, IWD finds no path on maze20 within
:data:`ITERATIONS` iterations)."""
ITERATIONS = 8
"""The static iteration budget T of a run."""
RUNS = 3
"""Runs of a vmapped batch (keys or params): one of the one-key check's widths, so the
conformance checks of a swarm share that program."""
CONFIG = dict(num_agents=AGENTS)
"""The swarm options of the shared size: ``make(name, **CONFIG)``."""
SEED = 0
"""The key of a shared run: the first golden record of each swarm (``tests/golden``)."""


def maze() -> tuple[Graph, Task]:
    """``(graph, task)``: the walkers' shared world, the paper map :data:`MAP` from its start to
    its goal."""
    chosen = paper_map(MAP)
    graph = chosen.graph()
    return graph, make_task(graph, chosen.start, chosen.goal)


def cut_out(free) -> Graph:
    """A grid of the shared map's shape whose only free cells are ``free`` (bool[h, w], set in its
    top-left corner): a small hand-made map on which a swarm runs the shared size's programs."""
    free = np.asarray(free, bool)
    obstacles = np.ones(maze()[0].shape, bool)
    obstacles[:free.shape[0], :free.shape[1]] = ~free
    return grid_graph(obstacles)


def plane() -> tuple[Plane, tuple[float, float], tuple[float, float]]:
    """``(plane, start, goal)``: the bees' shared world, a 6 x 6 plane with one rectangle beside
    the straight way from start to goal."""
    return make_plane([(2.5, 3.0, 3.5, 5.0)], (6.0, 6.0)), (0.5, 2.5), (5.5, 2.5)


def world_of(name: str) -> tuple[Graph | Plane, Task]:
    """``(world, task)``: the conformance world of the registered swarm ``name``, the plane of
    :func:`plane` for the bees, the maze of :func:`maze` for the walkers."""
    if make(name).world is Plane:
        field, start, goal = plane()
        return field, make_task(field, start, goal)
    return maze()


class SharedRun(NamedTuple):
    """One run alone of a registered swarm at the shared size on its conformance world, from
    ``jax.random.key(SEED)`` with its default params: what :func:`shared_run` returns."""

    swarm: Swarm
    world: Graph | Plane
    task: Task
    state: Any
    trace: Trace


def shared_run(name: str) -> SharedRun:
    """The run alone of the registered swarm ``name`` that the tests share (``swarm_run``,
    a session fixture of ``tests/conftest.py``): ``make(name, **CONFIG)`` on
    :func:`world_of` for :data:`ITERATIONS` iterations from key :data:`SEED`, the program its
    conformance checks and golden records compile."""
    swarm = make(name, **CONFIG)
    world, task = world_of(name)
    state, trace = run(swarm, jax.random.key(SEED), world, task, swarm.default_params,
                       iterations=ITERATIONS)
    return SharedRun(swarm, world, task, state, trace)
