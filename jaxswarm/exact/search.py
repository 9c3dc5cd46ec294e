"""The compiled planners' host side: endpoints checked, buffers reused, Solutions packaged.

A :class:`Workspace` holds the per-node labels and heaps of one map's searches. Its labels are
valid where ``seen`` equals the current stamp, so a new query starts by taking a new stamp instead
of clearing N entries. Workspaces are cached per :class:`~jaxswarm.world.edges.EdgeArrays` (per
map), and are not shared between threads: a search from another thread gets its own.
"""
from __future__ import annotations

import dataclasses
import threading
import time
import weakref

import numpy as np

from jaxswarm.exact import kernels
from jaxswarm.exact.host import default_heuristic, heuristic_code
from jaxswarm.exact.stats import SearchStats, make_solution
from jaxswarm.world.edges import EdgeArrays, edge_arrays
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution, as_node


def side_buffers(arrays: EdgeArrays) -> tuple:
    """Labels and heap of one search direction, as :func:`~jaxswarm.exact.kernels.best_first`
    takes them: ``(g f64[N], parent i32[N], seen i32[N], heap f64[N + 1, 3], position i32[N])``."""
    n = arrays.num_nodes
    return (np.empty(n), np.full(n, -1, np.int32), np.zeros(n, np.int32), np.empty((n + 1, 3)),
            np.full(n, -1, np.int32))


@dataclasses.dataclass
class Workspace:
    """Both directions' buffers (see :func:`side_buffers`) and the last stamp used."""

    forward: tuple
    backward: tuple
    stamp: int = 0

    def take(self, count: int = 1) -> int:
        """The first of ``count`` fresh stamps (the labels are cleared once the i32 stamps
        run out)."""
        if self.stamp + count >= np.iinfo(np.int32).max:
            for side in (self.forward, self.backward):
                side[2][:] = 0
            self.stamp = 0
        first = self.stamp + 1
        self.stamp += count
        return first


_WORKSPACES = threading.local()


def workspace(arrays: EdgeArrays) -> Workspace:
    """This thread's cached Workspace for a map's EdgeArrays."""
    cache = getattr(_WORKSPACES, "cache", None)
    if cache is None:
        cache = _WORKSPACES.cache = weakref.WeakKeyDictionary()
    found = cache.get(arrays)
    if found is None:
        found = cache[arrays] = Workspace(side_buffers(arrays), side_buffers(arrays))
    return found


def path_to(parent: np.ndarray, node: int) -> np.ndarray:
    """i32 nodes from the root of ``parent`` (parent -1) to ``node``."""
    out = np.empty(parent.shape[0], np.int32)
    count = kernels.walk_back(parent, node, out)
    return out[:count][::-1]


def endpoints(graph: Graph, arrays: EdgeArrays, start, goal) -> tuple[int, int]:
    """Checked start and goal node indices (ValueError naming a bad one)."""
    return _node(graph, arrays, start, "start"), _node(graph, arrays, goal, "goal")


def _node(graph: Graph, arrays: EdgeArrays, point, name: str) -> int:
    """:func:`~jaxswarm.world.paths.as_node`, with a shortcut for the common case (a free grid cell
    given as a pair of ints) that reads the cached host arrays instead of the graph's."""
    if graph.is_grid and isinstance(point, tuple) and len(point) == 2 and all(
            isinstance(v, (int, np.integer)) for v in point):
        height, width = graph.shape
        x, y = point
        if 0 <= x < width and 0 <= y < height and arrays.free[y * width + x]:
            return int(y * width + x)
    return as_node(graph, point, name=name)  # any other form, and the errors


def best_first_search(graph: Graph, start, goal, *, heuristic: str | None,
                      max_len: int | None) -> Solution:
    """A* with ``heuristic`` (``"zero"``: Dijkstra) as a Solution with
    :class:`~jaxswarm.exact.stats.SearchStats`."""
    arrays = edge_arrays(graph)
    source, target = endpoints(graph, arrays, start, goal)
    kind = heuristic_code(default_heuristic(graph, heuristic))
    work = workspace(arrays)
    began = time.perf_counter()
    cost, *counts = kernels.best_first(arrays.indptr, arrays.heads, arrays.lengths, arrays.x,
                                       arrays.y, source, target, kind, work.forward, work.take())
    nodes = path_to(work.forward[1], target) if np.isfinite(cost) else None
    stats = SearchStats(*counts, wall_time=time.perf_counter() - began)
    return make_solution(nodes, cost, stats, max_len or graph.num_nodes)


def bidirectional_search(graph: Graph, start, goal, *, heuristic: str | None,
                         max_len: int | None, balanced: bool) -> Solution:
    """Bidirectional A* (``balanced``: the balanced variant) as a Solution with
    :class:`~jaxswarm.exact.stats.SearchStats` (both directions counted)."""
    arrays = edge_arrays(graph)
    source, target = endpoints(graph, arrays, start, goal)
    kind = heuristic_code(default_heuristic(graph, heuristic))
    work = workspace(arrays)
    began = time.perf_counter()
    cost, meet, *counts = kernels.bidirectional(
        (arrays.indptr, arrays.heads, arrays.lengths),
        (arrays.rev_indptr, arrays.rev_tails, arrays.rev_lengths), arrays.x, arrays.y, source,
        target, kind, work.forward, work.backward, work.take(), balanced)
    nodes = None
    if meet >= 0 and source == target:
        nodes = np.array([source], np.int32)
    elif meet >= 0:
        nodes = np.concatenate([path_to(work.forward[1], meet),
                                path_to(work.backward[1], meet)[::-1][1:]])
    stats = SearchStats(*counts, wall_time=time.perf_counter() - began)
    return make_solution(nodes, cost, stats, max_len or graph.num_nodes)
