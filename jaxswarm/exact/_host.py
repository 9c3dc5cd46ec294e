"""Host-side adjacency lists of a Graph, cached per Graph object, for the heapq planners.

The exact planners are plain Python over lists (the fastest way to walk a heap on CPU); this
module turns the padded tensors into successor and predecessor lists once per map. Graphs are
immutable and compare by identity, so an edit (which returns a new Graph) is a new cache entry.
"""
from __future__ import annotations

import dataclasses
import math
import weakref

import numpy as np

from jaxswarm.graph import Graph

SQRT2 = math.sqrt(2.0)


@dataclasses.dataclass(frozen=True)
class HostGraph:
    """Valid edges of a Graph as Python lists.

    Attributes:
      succ: succ[u] = [(v, w), ...] valid edges u -> v with length w (float64).
      pred: pred[v] = [(u, w), ...] the same edges seen from their head (for backward search).
      x, y: node coordinates.
      free: bool[N] passable nodes.
      is_grid: whether the map is a grid or path map.
    """

    succ: list
    pred: list
    x: list
    y: list
    free: np.ndarray
    is_grid: bool


_CACHE: "weakref.WeakKeyDictionary[Graph, HostGraph]" = weakref.WeakKeyDictionary()


def host_graph(graph: Graph) -> HostGraph:
    """The cached HostGraph of ``graph`` (built on first use, O(N K))."""
    cached = _CACHE.get(graph)
    if cached is None:
        cached = _CACHE[graph] = _build(graph)
    return cached


def _build(graph: Graph) -> HostGraph:
    valid = np.asarray(graph.valid_edges())
    nbr = np.asarray(graph.nbr)
    xy = np.asarray(graph.xy, dtype=np.float64)
    rows, slots = np.nonzero(valid)
    heads = nbr[rows, slots]
    if graph.is_grid:
        # Grid edge lengths are exactly the distance between cell centres (1 or sqrt 2); taking
        # them from the geometry avoids float32 rounding of sqrt 2 in the exact planners.
        lengths = np.hypot(*(xy[heads] - xy[rows]).T)
    else:
        lengths = np.asarray(graph.cost, dtype=np.float64)[rows, slots]
    n = graph.num_nodes
    succ = _group(rows, heads, lengths, n)
    order = np.argsort(heads, kind="stable")
    pred = _group(heads[order], rows[order], lengths[order], n)
    return HostGraph(succ=succ, pred=pred, x=xy[:, 0].tolist(), y=xy[:, 1].tolist(),
                     free=np.asarray(graph.free), is_grid=graph.is_grid)


def _group(keys: np.ndarray, values: np.ndarray, lengths: np.ndarray, n: int) -> list:
    """Lists of (value, length) pairs per key; ``keys`` must be sorted."""
    pairs = list(zip(values.tolist(), lengths.tolist()))
    bounds = np.searchsorted(keys, np.arange(n + 1)).tolist()
    return [pairs[bounds[i]:bounds[i + 1]] for i in range(n)]


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
        return lambda v: math.hypot(xs[v] - tx, ys[v] - ty)
    if kind == "octile":
        diagonal_extra = SQRT2 - 1.0

        def octile(v):  # max(dx, dy) + (sqrt 2 - 1) min(dx, dy), without call overhead
            dx, dy = abs(xs[v] - tx), abs(ys[v] - ty)
            return dx + diagonal_extra * dy if dx > dy else dy + diagonal_extra * dx
        return octile
    raise ValueError(f"unknown heuristic {kind!r}: choose 'octile', 'euclidean' or 'zero'")
