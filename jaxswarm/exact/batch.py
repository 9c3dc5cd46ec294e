"""Many shortest-path queries on one map in one compiled call (the case of every study here).

    from jaxswarm.exact import shortest_lengths
    result = shortest_lengths(graph, starts, goals)   # starts, goals: i[Q, 2] cells or i[Q] nodes
    result.cost, result.found, result.stats.expanded  # f64[Q], bool[Q], i64[Q]

The endpoints are checked at once, then one call of :func:`jaxswarm.exact.kernels.many` runs A*
for every query over reused buffers: no Python per query. The lengths, and the statistics, equal
:func:`~jaxswarm.exact.astar`'s (or :func:`~jaxswarm.exact.dijkstra`'s with ``heuristic="zero"``)
query by query; the paths are not kept.
"""
from __future__ import annotations

import time
from typing import NamedTuple

import numpy as np

from jaxswarm.exact import kernels
from jaxswarm.exact.host import default_heuristic, heuristic_code
from jaxswarm.exact.search import workspace
from jaxswarm.exact.stats import SearchStats
from jaxswarm.world.edges import EdgeArrays, edge_arrays
from jaxswarm.world.graph import Graph


class Lengths(NamedTuple):
    """Answers of a batch of queries.

    Attributes:
      cost: f64[Q] shortest-path lengths (inf where the goal cannot be reached).
      found: bool[Q] whether each goal was reached.
      stats: :class:`~jaxswarm.exact.stats.SearchStats` with i64[Q] ``iterations``, ``expanded``
        and ``generated`` per query and ``wall_time`` the seconds of the whole batch.
    """

    cost: np.ndarray
    found: np.ndarray
    stats: SearchStats


def shortest_lengths(graph: Graph, starts, goals, *, heuristic: str | None = None) -> Lengths:
    """Shortest-path lengths of Q queries on one map, by A*.

    Args:
      graph: the map.
      starts, goals: i[Q, 2] (x, y) cells of a grid or path map, or i[Q] node indices.
      heuristic: as :func:`~jaxswarm.exact.astar` ("zero": Dijkstra).

    Returns:
      :class:`Lengths`.

    Raises:
      ValueError: shapes that do not match; a start or goal off the map or blocked (naming
        the first such query); unknown heuristic.
    """
    arrays = edge_arrays(graph)
    sources = _nodes(graph, arrays, starts, "starts")
    targets = _nodes(graph, arrays, goals, "goals")
    if sources.shape != targets.shape:
        raise ValueError(f"starts and goals must hold as many queries, got {sources.shape[0]} "
                         f"and {targets.shape[0]}")
    kind = heuristic_code(default_heuristic(graph, heuristic))
    work = workspace(arrays)
    count = sources.shape[0]
    cost = np.empty(count)
    counts = np.zeros((count, 3), np.int64)
    began = time.perf_counter()
    kernels.many(arrays.indptr, arrays.heads, arrays.lengths, arrays.x, arrays.y, sources,
                 targets, kind, work.forward, work.take(count), cost, counts)
    stats = SearchStats(iterations=counts[:, 0], expanded=counts[:, 1], generated=counts[:, 2],
                        wall_time=time.perf_counter() - began)
    return Lengths(cost=cost, found=np.isfinite(cost), stats=stats)


def _nodes(graph: Graph, arrays: EdgeArrays, points, name: str) -> np.ndarray:
    """i64[Q] node indices of ``points`` (i[Q, 2] cells or i[Q] nodes), checked."""
    points = np.asarray(points)
    if points.ndim == 2 and points.shape[1] == 2 and graph.is_grid:
        if not np.issubdtype(points.dtype, np.integer):
            raise ValueError(f"{name} must be integer (x, y) cells, got dtype {points.dtype}")
        height, width = graph.shape
        x, y = points[:, 0], points[:, 1]
        off = (x < 0) | (x >= width) | (y < 0) | (y >= height)
        if off.any():
            q = int(np.argmax(off))
            raise ValueError(f"{name}[{q}] {tuple(points[q].tolist())} is off the "
                             f"{width}x{height} map")
        nodes = (y * width + x).astype(np.int64)
    elif points.ndim == 1 and np.issubdtype(points.dtype, np.integer):
        nodes = points.astype(np.int64)
        off = (nodes < 0) | (nodes >= graph.num_nodes)
        if off.any():
            q = int(np.argmax(off))
            raise ValueError(f"{name}[{q}] node {nodes[q]} is off the map "
                             f"(nodes 0..{graph.num_nodes - 1})")
    else:
        raise ValueError(f"{name} must be i[Q, 2] (x, y) cells of a grid or i[Q] node indices, "
                         f"got shape {points.shape}")
    blocked = ~arrays.free[nodes]
    if blocked.any():
        q = int(np.argmax(blocked))
        raise ValueError(f"{name}[{q}] {points[q].tolist()} is blocked (an obstacle)")
    return nodes
