"""D* Lite (Koenig and Likhachev 2002, the optimised version of their Fig. 4): an incremental
planner that follows a moving start and repairs its search when edges change.

It searches backwards, from the goal, keeping for every node ``g`` (its distance to the goal as
last settled) and ``rhs`` (the one-step lookahead ``min over successors of c + g``); a node whose
two differ is queued by ``(min(g, rhs) + h(start, node) + km, min(g, rhs))``. When the start moves,
``km`` grows by the heuristic between the old and the new start, so queued keys stay valid
without re-keying the queue; when edges change, only their tails are re-evaluated, and the search
goes on until the start is consistent again. A moved goal is a different search tree: the
planner then restarts from scratch (the Solution's ``stats.touched`` counts all it labelled).

The search loops are compiled (numba, like :mod:`jaxswarm.exact.kernels`, whose indexed heap they
share); the edges are every lattice edge of the map, valid or not, so an edit changes lengths
(``inf`` for an edge not valid now), never the structure.

    from jaxswarm.exact import replanner
    planner = replanner(graph, (0, 0), (9, 9))
    planner.solve()                                  # a Solution, like astar's
    planner.update(edited, start=(1, 1))             # after an edit and a move
"""
from __future__ import annotations

import dataclasses
import time
import weakref

import numpy as np

from jaxswarm.exact import kernels
from jaxswarm.exact.host import default_heuristic, heuristic_code
from jaxswarm.exact.stats import SearchStats, make_solution
from jaxswarm.world.edges import EdgeArrays, lattice_arrays
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution, as_node

jit, inline = kernels.jit, kernels.inline

KEY_TOLERANCE = 1e-9
"""Relative difference below which a queued first key counts as equal to the start's."""


def replanner(graph: Graph, start, goal, *, heuristic: str | None = None,
              max_len: int | None = None) -> "DStarLite":
    """A D* Lite planner on ``graph`` from ``start`` to ``goal``.

    Args:
      graph: the map.
      start, goal: (x, y) cells or node indices.
      heuristic: "octile" (default on grids), "euclidean" (default on general graphs) or "zero";
        it must be consistent (both defaults are, on the maps they are meant for).
      max_len: length L of the returned paths' buffers (default N).

    Returns:
      A :class:`~jaxswarm.exact.dstar_lite.DStarLite`; call ``solve()`` for the first Solution
      and ``update(...)`` after every change.

    Raises:
      ValueError: start or goal off the map or blocked; unknown heuristic.
    """
    return DStarLite(graph, start, goal, heuristic=heuristic, max_len=max_len)


class DStarLite:
    """A D* Lite search kept between calls (see the module docstring).

    Not thread-safe: one planner is one search. Each call's Solution carries
    :class:`~jaxswarm.exact.SearchStats` of that call's work: queue pops (``iterations``), nodes
    whose ``g`` changed (``expanded``), nodes queued or re-keyed (``generated``) and the nodes
    whose ``g`` or ``rhs`` the call changed (``touched``).
    """

    def __init__(self, graph: Graph, start, goal, *, heuristic: str | None = None,
                 max_len: int | None = None):
        self._kind = heuristic_code(default_heuristic(graph, heuristic))
        self._max_len = max_len or graph.num_nodes
        self._graph = graph
        self._lattice = _Lattice(graph)
        self._start = as_node(graph, start, name="start")
        self._call = 0  # counts the calls: a node's mark is the last call that touched it
        self._restart(as_node(graph, goal, name="goal"))
        self._solution: Solution | None = None

    @property
    def graph(self) -> Graph:
        """The map as last given."""
        return self._graph

    def solve(self) -> Solution:
        """The shortest path from the current start to the goal (searching only as far as the
        last change requires; nothing when nothing changed since the last call)."""
        if self._solution is None:
            self._call += 1
            self._solution = self._search(time.perf_counter(), 0)
        return self._solution

    def update(self, graph: Graph | None = None, *, start=None, goal=None) -> Solution:
        """Take an edited map (the same map's shape and lattice, other open cells or edges)
        and/or a new start or goal, and return the new shortest path.

        Args:
          graph: the map after the change (``None``: unchanged).
          start: the new start, (x, y) or node index (``None``: unchanged); the robot's position.
          goal: the new goal (``None``: unchanged); a new goal restarts the search.

        Raises:
          ValueError: a graph of another shape or lattice; a start or goal off the map or blocked
            (on the new map).
        """
        began = time.perf_counter()
        graph = self._graph if graph is None else graph
        if graph is not self._graph:
            self._lattice.check_same_map(graph)
        new_start = self._start if start is None else as_node(graph, start, name="start")
        new_goal = self._goal if goal is None else as_node(graph, goal, name="goal")
        as_node(graph, new_start, name="start")  # still free after the edit?
        as_node(graph, new_goal, name="goal")
        self._call += 1
        touched = 0
        if new_goal != self._goal:
            self._graph, self._start = graph, new_start
            self._lattice.set_costs(graph)
            self._restart(new_goal)
        else:
            if new_start != self._start:
                lattice = self._lattice
                self._km += kernels.heuristic(self._kind, lattice.x, lattice.y, self._start,
                                              lattice.x[new_start], lattice.y[new_start])
                self._start = new_start
            if graph is not self._graph:
                self._graph = graph
                touched = self._repair(graph)
        self._solution = self._search(began, touched)
        return self._solution

    def _restart(self, goal: int) -> None:
        n = self._graph.num_nodes
        self._goal = goal
        self._km = 0.0
        self._g = np.full(n, np.inf)
        self._rhs = np.full(n, np.inf)
        self._heap = np.empty((n + 1, 3))
        self._position = np.full(n, -1, np.int32)
        self._mark = np.zeros(n, np.int32)  # the call that last touched each node
        self._rhs[goal] = 0.0
        lattice = self._lattice
        self._size = kernels.heap_set(
            self._heap, self._position, 0, False, goal,
            kernels.heuristic(self._kind, lattice.x, lattice.y, goal, lattice.x[self._start],
                              lattice.y[self._start]), 0.0)

    def _state(self):
        return self._g, self._rhs, self._heap, self._position, self._mark

    def _repair(self, graph: Graph) -> int:
        """New edge costs from ``graph``: every changed edge's tail re-evaluated; returns the
        number of nodes touched."""
        changed, old = self._lattice.set_costs(graph)
        lattice = self._lattice
        self._size, touched = repair(lattice.edges(), lattice.x, lattice.y, self._kind,
                                     self._state(), self._call, self._size, self._start,
                                     self._goal, self._km, changed, old)
        return touched

    def _search(self, began: float, touched: int) -> Solution:
        lattice = self._lattice
        self._size, *counts = compute_shortest_path(
            lattice.edges(), lattice.x, lattice.y, self._kind, self._state(), self._call,
            self._size, self._start, self._goal, self._km)
        *counts, newly = counts
        nodes = None
        if np.isfinite(self._g[self._start]) or self._start == self._goal:
            out = np.empty(self._graph.num_nodes, np.int32)
            count, cost = follow(lattice.edges(), self._g, self._start, self._goal, out)
            nodes = out[:count] if count > 0 else None
        else:
            cost = np.inf
        stats = SearchStats(*counts, wall_time=time.perf_counter() - began,
                            touched=touched + newly)
        return make_solution(nodes, cost if nodes is not None else np.inf, stats,
                             self._max_len)


@dataclasses.dataclass(frozen=True, eq=False)
class _Structure:
    """A map's lattice, cached per Graph: ``arrays`` every lattice edge (valid or not,
    :func:`~jaxswarm.world.edges.lattice_arrays`), ``edge[i, k]`` slot k's edge index (-1
    without neighbour), ``nbr`` the lattice it was built from, ``valid`` bool[N, K] the graph's
    valid edges and ``cost`` f64[E] the lengths of the valid ones, ``inf`` elsewhere (a planner's
    starting costs)."""

    arrays: EdgeArrays
    edge: np.ndarray
    nbr: np.ndarray
    valid: np.ndarray
    cost: np.ndarray


_STRUCTURES: "weakref.WeakKeyDictionary[Graph, _Structure]" = weakref.WeakKeyDictionary()


def _structure(graph: Graph) -> _Structure:
    cached = _STRUCTURES.get(graph)
    if cached is not None:
        return cached
    arrays = lattice_arrays(graph)
    nbr = np.asarray(graph.nbr)
    rows, slots = np.nonzero(nbr >= 0)  # the order of the arrays' edges
    edge = np.full(nbr.shape, -1, np.int64)
    edge[rows, slots] = np.arange(rows.shape[0])
    valid = np.asarray(graph.valid_edges())
    cached = _STRUCTURES[graph] = _Structure(
        arrays=arrays, edge=edge, nbr=nbr, valid=valid,
        cost=np.where(valid[rows, slots], arrays.lengths, np.inf))
    return cached


class _Lattice:
    """A planner's edges: a map's :class:`_Structure` with its own current costs (``inf`` where
    an edge is not valid now)."""

    def __init__(self, graph: Graph):
        structure = _structure(graph)
        self.source = graph
        self.structure = structure
        self.x, self.y = structure.arrays.x, structure.arrays.y
        self.valid = structure.valid
        self.cost = structure.cost.copy()

    def check_same_map(self, graph: Graph) -> None:
        if graph.nbr is self.source.nbr:  # an edit (jaxswarm.world.edits) keeps the lattice's array
            return
        nbr = np.asarray(graph.nbr)
        if nbr.shape != self.structure.nbr.shape or not np.array_equal(nbr, self.structure.nbr):
            raise ValueError("update takes an edit of the same map (same shape and lattice); "
                             "for another map make a new replanner")

    def set_costs(self, graph: Graph) -> tuple[np.ndarray, np.ndarray]:
        """Take ``graph``'s valid edges: ``(i64 indices of the edges that changed, their old
        costs)``."""
        valid = np.asarray(graph.valid_edges())
        flips = np.flatnonzero(valid != self.valid)  # flat: much faster than 2-D nonzero
        self.valid = valid
        changed = self.structure.edge.reshape(-1)[flips]
        old = self.cost[changed]
        self.cost[changed] = np.where(valid.reshape(-1)[flips],
                                      self.structure.arrays.lengths[changed], np.inf)
        return changed, old

    def edges(self):
        a = self.structure.arrays
        return (a.indptr, a.heads, self.cost, a.rev_indptr, a.rev_tails, a.rev_edge)


@inline
def _key(g, rhs, x, y, kind, s, start, km):
    """D* Lite's key of node ``s``: ``(min(g, rhs) + h(start, s) + km, min(g, rhs))``."""
    low = min(g[s], rhs[s])
    return low + kernels.heuristic(kind, x, y, s, x[start], y[start]) + km, low


@inline
def _lookahead(indptr, heads, cost, g, s):
    """``min over the successors s' of s of c(s, s') + g(s')``."""
    best = np.inf
    for e in range(indptr[s], indptr[s + 1]):
        through = cost[e] + g[heads[e]]
        if through < best:
            best = through
    return best


@inline
def _touch(mark, call, s):
    """1 the first time ``s`` changes in this call, else 0."""
    if mark[s] == call:
        return 0
    mark[s] = call
    return 1


@inline
def _update_vertex(g, rhs, heap, position, x, y, kind, size, s, start, km):
    """Queue ``s`` with its key if it is inconsistent, or take it off the queue if it is
    consistent; returns ``(size, 1 if it was queued or re-keyed)``."""
    queued = position[s] >= 0
    if g[s] != rhs[s]:
        first, second = _key(g, rhs, x, y, kind, s, start, km)
        return kernels.heap_set(heap, position, size, queued, s, first, second), 1
    if queued:
        return kernels.heap_remove(heap, position, size, s), 0
    return size, 0


@jit
def compute_shortest_path(edges, x, y, kind, state, call, size, start, goal, km):
    """D* Lite's ComputeShortestPath: pop until the start is consistent and no queued key is
    below its key. Two departures from the paper's optimised version, both because keys are
    sums in floating point and a node of the shortest path may key a rounding error above the
    start: first keys within ``KEY_TOLERANCE`` of the start's count as equal, and the loop runs
    until the start is consistent, not only until it is not under-consistent. Both only add
    pops. Returns ``(size, iterations, expanded, generated, touched)``."""
    indptr, heads, cost, rev_indptr, rev_tails, rev_edge = edges
    g, rhs, heap, position, mark = state
    iterations, expanded, generated, touched = 0, 0, 0, 0
    while True:
        start_first, start_second = _key(g, rhs, x, y, kind, start, start, km)
        if size == 0:
            break
        top_first, top_second = heap[0, 0], heap[0, 1]
        # A first key within rounding of the start's counts as equal (the heuristic is exact
        # along straight stretches, so ties are common): the second key decides.
        slack = KEY_TOLERANCE * max(1.0, abs(start_first))
        below = top_first < start_first or (top_first <= start_first + slack
                                            and top_second < start_second)
        if not below and rhs[start] == g[start]:
            break
        iterations += 1
        u = np.int64(heap[0, 2])
        first, second = _key(g, rhs, x, y, kind, u, start, km)
        if top_first < first or (top_first == first and top_second < second):
            size = kernels.heap_set(heap, position, size, True, u, first, second)
            continue
        expanded += 1
        touched += _touch(mark, call, u)
        if g[u] > rhs[u]:  # over-consistent: settle u, improve its predecessors
            g[u] = rhs[u]
            size = kernels.heap_remove(heap, position, size, u)
            for e in range(rev_indptr[u], rev_indptr[u + 1]):
                s = rev_tails[e]
                through = cost[rev_edge[e]] + g[u]
                if s != goal and through < rhs[s]:
                    rhs[s] = through
                    touched += _touch(mark, call, s)
                    size, queued = _update_vertex(g, rhs, heap, position, x, y, kind, size, s,
                                                  start, km)
                    generated += queued
        else:  # under-consistent: raise u, re-evaluate the predecessors that went through it
            old = g[u]
            g[u] = np.inf
            for e in range(rev_indptr[u], rev_indptr[u + 1]):
                s = rev_tails[e]
                if s != goal and rhs[s] == cost[rev_edge[e]] + old:
                    rhs[s] = _lookahead(indptr, heads, cost, g, s)
                    touched += _touch(mark, call, s)
                    size, queued = _update_vertex(g, rhs, heap, position, x, y, kind, size, s,
                                                  start, km)
                    generated += queued
            size, queued = _update_vertex(g, rhs, heap, position, x, y, kind, size, u, start,
                                          km)
            generated += queued
    return size, iterations, expanded, generated, touched


@jit
def repair(edges, x, y, kind, state, call, size, start, goal, km, changed, old):
    """Edge costs changed (``edges``' costs are the new ones; ``old`` f64[C] the costs of the
    ``changed`` edges i64[C] before): re-evaluate each changed edge's tail. Returns ``(size,
    nodes touched)``."""
    indptr, heads, cost, rev_indptr, rev_tails, rev_edge = edges
    g, rhs, heap, position, mark = state
    tails = np.searchsorted(indptr, changed, side="right") - 1
    touched = 0
    for i in range(changed.shape[0]):
        e, u = changed[i], tails[i]
        if u == goal:
            continue
        v = heads[e]
        if old[i] > cost[e]:
            if cost[e] + g[v] < rhs[u]:
                rhs[u] = cost[e] + g[v]
                touched += _touch(mark, call, u)
        elif rhs[u] == old[i] + g[v]:
            rhs[u] = _lookahead(indptr, heads, cost, g, u)
            touched += _touch(mark, call, u)
        size, _ = _update_vertex(g, rhs, heap, position, x, y, kind, size, u, start, km)
    return size, touched


@jit
def follow(edges, g, start, goal, out):
    """The path from ``start``: at each node the successor minimising ``c + g`` (the first in
    slot order on ties), until the goal. Writes the nodes into ``out``; returns ``(count,
    length)``, count 0 when the walk does not reach the goal within N nodes."""
    indptr, heads, cost = edges[0], edges[1], edges[2]
    node, count, length = start, 1, 0.0
    out[0] = start
    while node != goal:
        best, step, best_cost = np.inf, -1, 0.0
        for e in range(indptr[node], indptr[node + 1]):
            through = cost[e] + g[heads[e]]
            if through < best:
                best, step, best_cost = through, heads[e], cost[e]
        if step < 0 or count == out.shape[0]:
            return 0, np.inf
        out[count] = step
        count += 1
        length += best_cost
        node = step
    return count, length
