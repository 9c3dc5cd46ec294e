"""Compiling the exact planners ahead of their first query."""
from __future__ import annotations

import time

import numpy as np

from jaxswarm.exact.astar import astar, bidirectional_astar
from jaxswarm.exact.batch import shortest_lengths
from jaxswarm.exact.dstar_lite import replanner
from jaxswarm.world.edits import block_cells
from jaxswarm.world.graph import grid_graph


def warm_up() -> float:
    """Compile every compiled planner (or load it from numba's on-disk cache, next to the
    package) by solving a 3 x 3 grid with each; returns the seconds it took. The first query of
    a session otherwise pays this (seconds on a first install, well under one from the cache)."""
    began = time.perf_counter()
    graph = grid_graph(np.zeros((3, 3), bool))
    astar(graph, (0, 0), (2, 2))
    bidirectional_astar(graph, (0, 0), (2, 2))
    shortest_lengths(graph, np.array([[0, 0]]), np.array([[2, 2]]))
    planner = replanner(graph, (0, 0), (2, 2))
    planner.solve()
    planner.update(block_cells(graph, 4), start=(1, 0))  # the centre closes: the repair loop
    return time.perf_counter() - began
