"""LaCAM*'s graph of explored configurations and its Dijkstra update (Okumura, IJCAI 2023).

Every configuration the search finds keeps its cost from the starts (``g``), a lower bound of its
cost to the goals (``h``), its parent on the cheapest way known, and its neighbours: the
configurations generated from it, each once, with the cost of the step to them. A step costs the
agents not resting at their goals through it (on their goals before and after): the *sum of
loss*, LaCAM*'s objective. When a known configuration is generated again, the edge is added and
the saving, if any, is passed on to every configuration reached more cheaply through it (a
Dijkstra update over the known edges); those whose cost now falls below the best solution's must
be searched again, as the reference implementation (Kei18/lacam2, ``Planner::rewrite``) pushes
them back on the open stack.

The configurations are rows of growing arrays and each one's neighbours a linked list of edges,
so the update is one compiled call (numba, as :mod:`jaxswarm.multiagent.pibt`).
"""
from __future__ import annotations

import heapq

import numpy as np

from jaxswarm.exact.kernels import jit

NONE = -1
"""No configuration (the root's parent), or no edge (the end of a neighbour list)."""


class Explored:
    """The configurations of one search, their costs, parents and neighbour sets.

    Attributes:
      goals: i32[A] the agents' goals.
      size: the number of configurations; ids are 0..size-1 in the order they were found.
      nodes: i32[capacity, A] each configuration's nodes (rows below ``size``).
      cost: i64[capacity] each configuration's cost from the starts (``g``), sum of loss.
      bound: i64[capacity] a lower bound of its cost to the goals (``h``).
      parent: i64[capacity] the previous configuration on its cheapest known way (NONE: root).
      first: i64[capacity] its first edge (NONE: no neighbours yet).
      edge_next: i64[edge capacity] the next edge of the same configuration (NONE: last).
      edge_head: i64[edge capacity] the configuration an edge leads to.
      edge_cost: i64[edge capacity] the edge's step cost.
      edges: the number of edges.
    """

    def __init__(self, goals: np.ndarray, capacity: int = 1024):
        self.goals = np.ascontiguousarray(goals, np.int32)
        self.size = 0
        self.edges = 0
        self.nodes = np.empty((capacity, len(goals)), np.int32)
        self.cost = np.empty(capacity, np.int64)
        self.bound = np.empty(capacity, np.int64)
        self.parent = np.empty(capacity, np.int64)
        self.first = np.empty(capacity, np.int64)
        self.edge_next = np.empty(capacity, np.int64)
        self.edge_head = np.empty(capacity, np.int64)
        self.edge_cost = np.empty(capacity, np.int64)
        self._settled = np.empty(capacity, np.int64)
        self._ids: dict[bytes, int] = {}
        self._linked: set[tuple[int, int]] = set()

    def find(self, nodes: np.ndarray) -> int:
        """The id of configuration ``nodes`` (i32[A]), or NONE if it was not found yet."""
        return self._ids.get(nodes.tobytes(), NONE)

    def add(self, nodes: np.ndarray, parent: int, bound: int) -> int:
        """Add configuration ``nodes`` (i32[A], new), reached from ``parent`` (an id, or NONE for
        the root) with lower bound ``bound`` to the goals; the edge from the parent is added.
        Returns its id."""
        if self.size == len(self.cost):
            self.nodes, self.cost, self.bound, self.parent, self.first, self._settled = (
                _doubled(a) for a in (self.nodes, self.cost, self.bound, self.parent, self.first,
                                      self._settled))
        new = self.size
        self.size += 1
        self.nodes[new] = nodes
        self.bound[new] = bound
        self.parent[new] = parent
        self.first[new] = NONE
        self.cost[new] = 0
        self._ids[nodes.tobytes()] = new
        if parent != NONE:
            self.cost[new] = self.cost[parent] + self._link(parent, new)
        return new

    def connect(self, source: int, target: int, limit: int) -> np.ndarray:
        """Record that ``target`` (an id) was generated from ``source`` again, and pass any saving
        on (the Dijkstra update).

        Args:
          source, target: ids of known configurations.
          limit: the best solution's cost (or a larger number while none is known).

        Returns:
          i64[M] the configurations whose cost fell and whose cost plus bound is now below
          ``limit``, cheapest first: the ones to search again.
        """
        if source == target or (source, target) in self._linked:
            return self._settled[:0]
        self._link(source, target)
        count = _update(self.cost, self.bound, self.parent, self.first, self.edge_next,
                        self.edge_head, self.edge_cost, source, limit, self._settled)
        return self._settled[:count]

    def way(self, last: int) -> list[np.ndarray]:
        """The configurations (i32[A] each) from the root to ``last`` along the parents."""
        out = []
        while last != NONE:
            out.append(self.nodes[last].copy())
            last = int(self.parent[last])
        return out[::-1]

    def _link(self, source: int, target: int) -> int:
        """Add the edge ``source -> target``; returns its step cost."""
        if self.edges == len(self.edge_head):
            self.edge_next, self.edge_head, self.edge_cost = (
                _doubled(a) for a in (self.edge_next, self.edge_head, self.edge_cost))
        self._linked.add((source, target))
        step = _step_cost(self.nodes[source], self.nodes[target], self.goals)
        edge = self.edges
        self.edges += 1
        self.edge_head[edge] = target
        self.edge_cost[edge] = step
        self.edge_next[edge] = self.first[source]
        self.first[source] = edge
        return step


def _doubled(array: np.ndarray) -> np.ndarray:
    grown = np.empty((2 * len(array),) + array.shape[1:], array.dtype)
    grown[:len(array)] = array
    return grown


def _step_cost(before: np.ndarray, after: np.ndarray, goals: np.ndarray) -> int:
    """Agents not resting at their goals through one step (LaCAM*'s sum of loss); i32[A] each.
    Computed once per edge, when it is added."""
    return int(np.count_nonzero((before != goals) | (after != goals)))


@jit
def _update(cost, bound, parent, first, edge_next, edge_head, edge_cost, source, limit, settled):
    """Dijkstra from ``source`` over the known edges, lowering costs and moving parents; writes
    the configurations whose cost fell with cost plus bound below ``limit`` to ``settled``, in
    the order they are settled, and returns their number."""
    queue = [(cost[source], source)]
    count = 0
    while queue:
        here_cost, here = heapq.heappop(queue)
        if here_cost != cost[here]:
            continue  # a stale entry: lowered again since
        if here != source and here_cost + bound[here] < limit:
            settled[count] = here
            count += 1
        edge = first[here]
        while edge != -1:
            there = edge_head[edge]
            through = here_cost + edge_cost[edge]
            if through < cost[there]:
                cost[there] = through
                parent[there] = here
                heapq.heappush(queue, (through, there))
            edge = edge_next[edge]
    return count
