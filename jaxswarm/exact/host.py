"""What the exact planners share on the host: the heuristics by name (as Python functions for
the readable heapq planners of :mod:`jaxswarm.exact.reference`, as codes for the compiled ones of
:mod:`jaxswarm.exact.kernels`) and :class:`HostGraph`, the valid edges of a Graph as Python lists
(the heapq planners'), cached per Graph object like :func:`jaxswarm.world.edges.edge_arrays`, the
compiled planners' CSR arrays it is built from.
"""
from __future__ import annotations

import dataclasses
import math
import weakref

import numpy as np

from jaxswarm.exact import kernels
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import Graph

SQRT2 = math.sqrt(2.0)


@dataclasses.dataclass(frozen=True)
class HostGraph:
    """Valid edges of a Graph as Python lists.

    Attributes:
      succ: succ[u] = [(v, w), ...] valid edges u -> v with length w (float64).
      pred: pred[v] = [(u, w), ...] the same edges seen from their head (for backward search).
      x, y: N floats each, the node coordinates.
      free: bool[N] passable nodes.
      is_grid: whether the map is a grid or path map.
    """

    succ: list
    pred: list
    x: list
    y: list
    free: np.ndarray
    is_grid: bool


_HOST: "weakref.WeakKeyDictionary[Graph, HostGraph]" = weakref.WeakKeyDictionary()


def host_graph(graph: Graph) -> HostGraph:
    """The cached HostGraph of ``graph`` (built on first use, O(N K))."""
    cached = _HOST.get(graph)
    if cached is None:
        arrays = edge_arrays(graph)
        rows = np.repeat(np.arange(arrays.num_nodes), np.diff(arrays.indptr))
        heads, lengths = arrays.heads, arrays.lengths
        n = graph.num_nodes
        order = np.argsort(heads, kind="stable")
        cached = _HOST[graph] = HostGraph(
            succ=_group(rows, heads, lengths, n),
            pred=_group(heads[order], rows[order], lengths[order], n),
            x=arrays.x.tolist(), y=arrays.y.tolist(), free=arrays.free,
            is_grid=graph.is_grid)
    return cached


def _group(keys: np.ndarray, values: np.ndarray, lengths: np.ndarray, n: int) -> list:
    """Lists of (value, length) pairs per key; ``keys`` must be sorted."""
    pairs = list(zip(values.tolist(), lengths.tolist()))
    bounds = np.searchsorted(keys, np.arange(n + 1)).tolist()
    return [pairs[bounds[i]:bounds[i + 1]] for i in range(n)]


def default_heuristic(graph: Graph, kind: str | None) -> str:
    """The heuristic a planner uses: ``kind``, or octile on grids and euclidean otherwise."""
    if kind is None:
        return "octile" if graph.is_grid else "euclidean"
    return kind


def heuristic(kind: str, host: HostGraph, target: int):
    """A function node -> lower bound on the distance to ``target``.

    Args:
      kind: "octile" (8-connected grids: exact on an empty grid), "euclidean" (any graph whose
        edge lengths are at least the straight-line distance), or "zero" (Dijkstra).
      host: the host graph (for coordinates).
      target: the node the bound is measured to.
    """
    tx, ty, xs, ys = host.x[target], host.y[target], host.x, host.y
    if kind == "zero":
        return lambda v: 0.0
    if kind == "euclidean":
        def euclidean(v):  # the compiled planners' very floats (not math.hypot's)
            dx, dy = xs[v] - tx, ys[v] - ty
            return math.sqrt(dx * dx + dy * dy)
        return euclidean
    if kind == "octile":
        diagonal_extra = SQRT2 - 1.0

        def octile(v):  # max(dx, dy) + (sqrt 2 - 1) min(dx, dy), without call overhead
            dx, dy = abs(xs[v] - tx), abs(ys[v] - ty)
            return dx + diagonal_extra * dy if dx > dy else dy + diagonal_extra * dx
        return octile
    raise _unknown(kind)


HEURISTIC_CODES = {"zero": kernels.ZERO, "euclidean": kernels.EUCLIDEAN, "octile": kernels.OCTILE}
"""The compiled planners' heuristic codes (:mod:`jaxswarm.exact.kernels`)."""


def heuristic_code(kind: str) -> int:
    """The kernels' code of a heuristic name (see :func:`heuristic`)."""
    if kind not in HEURISTIC_CODES:
        raise _unknown(kind)
    return HEURISTIC_CODES[kind]


def _unknown(kind) -> ValueError:
    return ValueError(f"unknown heuristic {kind!r}: choose 'octile', 'euclidean' or 'zero'")
