"""The sizes the tests share. Every new combination of a swarm, a map shape, an agent count and
an iteration count is a new XLA program (seconds to a minute of compiling), so a test that does
not need sizes of its own takes these, and varies a run's length through ``run``'s traced
``budget`` rather than its static ``iterations``."""
from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import Task, make_task
from jaxswarm.world.graph import Graph
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


def maze() -> tuple[Graph, Task]:
    """``(graph, task)``: the walkers' shared world, the paper map :data:`MAP` from its start to
    its goal."""
    chosen = paper_map(MAP)
    graph = chosen.graph()
    return graph, make_task(graph, chosen.start, chosen.goal)


def plane() -> tuple[Plane, tuple[float, float], tuple[float, float]]:
    """``(plane, start, goal)``: the bees' shared world, a 6 x 6 plane with one rectangle beside
    the straight way from start to goal."""
    return make_plane([(2.5, 3.0, 3.5, 5.0)], (6.0, 6.0)), (0.5, 2.5), (5.5, 2.5)
