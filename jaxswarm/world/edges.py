"""A Graph's edges as CSR arrays on the host, for the compiled planners that walk them (the exact
planners, the multi-agent planners), cached per Graph object.

:func:`edge_arrays` gives the valid edges; :func:`lattice_arrays` every lattice edge, valid now or
not (the structure a planner that follows edits keeps). Graphs are immutable and compare by
identity, so an edit (which returns a new Graph) is a new cache entry.
"""
from __future__ import annotations

import dataclasses
import weakref

import numpy as np

from jaxswarm.world.graph import Graph


@dataclasses.dataclass(frozen=True, eq=False)
class EdgeArrays:
    """Edges of a Graph as CSR arrays: the valid ones (:func:`edge_arrays`), or every lattice
    edge (:func:`lattice_arrays`).

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
        """N, the graph's node count."""
        return self.indptr.shape[0] - 1


_ARRAYS: "weakref.WeakKeyDictionary[Graph, EdgeArrays]" = weakref.WeakKeyDictionary()


def edge_arrays(graph: Graph) -> EdgeArrays:
    """The cached EdgeArrays of the valid edges of ``graph`` (built on first use, O(N K)).

    An edge is valid as :meth:`~jaxswarm.world.graph.Graph.valid_edges` says; the edges out of
    a node are in slot order. Grid edge lengths are the distance between cell centres in float64
    (1 or sqrt 2 as float64 gives them); other graphs' are ``graph.cost`` in float64.
    """
    cached = _ARRAYS.get(graph)
    if cached is None:
        cached = _ARRAYS[graph] = _csr(graph, np.asarray(graph.valid_edges()))
    return cached


def lattice_arrays(graph: Graph) -> EdgeArrays:
    """EdgeArrays of every lattice edge of ``graph`` (``nbr >= 0``, valid now or not), with
    their lengths as in :func:`edge_arrays`: the structure a planner that follows edits keeps
    (D* Lite). Not cached."""
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
    """i64[n + 1]: where each key 0..n-1 starts in ``sorted_keys`` (and the end)."""
    return np.searchsorted(sorted_keys, np.arange(n + 1)).astype(np.int64)
