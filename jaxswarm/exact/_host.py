"""Host-side forms of a Graph for the exact planners, cached per Graph object.

The compiled planners read :class:`EdgeArrays` (CSR arrays of the valid edges); the readable
heapq planners of :mod:`jaxswarm.exact.reference` read :class:`HostGraph` (Python lists of the
valid edges). Graphs are immutable and compare by identity, so an edit (which returns a new
Graph) is a new cache entry.
"""
from __future__ import annotations

import dataclasses
import math
import weakref

import numpy as np

from jaxswarm.exact import kernels
from jaxswarm.world.graph import Graph

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


@dataclasses.dataclass(frozen=True, eq=False)
class EdgeArrays:
    """Edges of a Graph as CSR arrays, for the compiled planners: the valid ones
    (:func:`edge_arrays`), or every lattice edge (:func:`lattice_arrays`, D* Lite's).

    Attributes:
      indptr: i64[N + 1]; the edges out of ``u`` are ``indptr[u]:indptr[u + 1]``, in slot order.
      heads: i32[E] each edge's head.
      lengths: f64[E] each edge's length.
      rev_indptr: i64[N + 1]; the edges into ``v`` are ``rev_indptr[v]:rev_indptr[v + 1]``.
      rev_tails: i32[E] their tails.
      rev_edge: i64[E] their index into ``heads`` and ``lengths``.
      rev_lengths: f64[E] their lengths (``lengths[rev_edge]``).
      x, y: f64[N] node coordinates.
      free: bool[N] passable nodes.
    """

    indptr: np.ndarray
    heads: np.ndarray
    lengths: np.ndarray
    rev_indptr: np.ndarray
    rev_tails: np.ndarray
    rev_edge: np.ndarray
    rev_lengths: np.ndarray
    x: np.ndarray
    y: np.ndarray
    free: np.ndarray

    @property
    def num_nodes(self) -> int:
        return self.indptr.shape[0] - 1


_HOST: "weakref.WeakKeyDictionary[Graph, HostGraph]" = weakref.WeakKeyDictionary()
_ARRAYS: "weakref.WeakKeyDictionary[Graph, EdgeArrays]" = weakref.WeakKeyDictionary()


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


def edge_arrays(graph: Graph) -> EdgeArrays:
    """The cached EdgeArrays of ``graph`` (built on first use, O(N K))."""
    cached = _ARRAYS.get(graph)
    if cached is None:
        cached = _ARRAYS[graph] = _csr(graph, np.asarray(graph.valid_edges()))
    return cached


def lattice_arrays(graph: Graph) -> EdgeArrays:
    """EdgeArrays of every lattice edge of ``graph`` (valid now or not), with their lengths: the
    structure a planner that follows edits keeps (D* Lite). Not cached."""
    return _csr(graph, np.asarray(graph.nbr) >= 0)


def _csr(graph: Graph, selected: np.ndarray) -> EdgeArrays:
    """EdgeArrays of the edge slots ``selected`` (bool[N, K]), in row-major (node, slot) order."""
    nbr = np.asarray(graph.nbr)
    xy = np.asarray(graph.xy, dtype=np.float64)
    rows, slots = np.nonzero(selected)
    heads = nbr[rows, slots]
    if graph.is_grid:
        # Grid edge lengths are exactly the distance between cell centres (1 or sqrt 2); taking
        # them from the geometry avoids float32 rounding of sqrt 2 in the exact planners.
        lengths = np.hypot(*(xy[heads] - xy[rows]).T)
    else:
        lengths = np.asarray(graph.cost, dtype=np.float64)[rows, slots]
    n = graph.num_nodes
    order = np.argsort(heads, kind="stable")
    return EdgeArrays(indptr=_indptr(rows, n), heads=heads.astype(np.int32), lengths=lengths,
                      rev_indptr=_indptr(heads[order], n),
                      rev_tails=rows[order].astype(np.int32), rev_edge=order.astype(np.int64),
                      rev_lengths=lengths[order],
                      x=np.ascontiguousarray(xy[:, 0]), y=np.ascontiguousarray(xy[:, 1]),
                      free=np.asarray(graph.free))


def _indptr(sorted_keys: np.ndarray, n: int) -> np.ndarray:
    return np.searchsorted(sorted_keys, np.arange(n + 1)).astype(np.int64)


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
