"""Corridor reasoning for CBS (Li, Gange, Harabor, Stuckey, Ma and Koenig, ICAPS 2020; Li,
Harabor, Stuckey and Koenig, AIJ 2021): one split for two agents meeting head-on in a corridor.

A corridor is a maximal chain of nodes with exactly two neighbours each, between two endpoints
``e1`` and ``e2`` that are not in it, ``k`` moves apart along it. Two agents that collide inside
it while crossing it in opposite directions, ``a`` from ``e1`` to ``e2`` and ``b`` from ``e2`` to
``e1``, cannot both be inside at once, so one of them crosses first. Plain CBS learns that one
step of waiting at a time; corridor reasoning splits once on the order:

* ``a`` is not on ``e2`` at any step in ``[0, min(t'_a - 1, t_b + k)]``, or
* ``b`` is not on ``e1`` at any step in ``[0, min(t'_b - 1, t_a + k)]``,

where ``t_a`` is the fewest steps from ``a``'s start to ``e2`` and ``t'_a`` the fewest that
avoid the corridor, both under ``a``'s constraints (as CBSH2-RTC takes them: a range learnt at
one split makes the next split's ranges longer; :meth:`Corridors.arrival` gives a lower bound of
each, which keeps the split sound), and the same for ``b`` and ``e1``. Every solution keeps one
of the two: before ``t'_a`` an agent reaches ``e2`` only through the corridor, and if ``a``
crosses first, ``b`` enters only after ``a`` has left ``e2``, so ``b`` reaches ``e1`` after
``t_a + k`` (and the other way round). Both ranges are vertex constraints, so the low level and
the MDDs need nothing new. The split is taken only where both agents are crossing the same
corridor at the collision (in it, or just out of it), in opposite directions, their starts and
goals are outside it, and both ranges forbid their current paths; otherwise CBS splits as usual.
"""
from __future__ import annotations

import numpy as np

from jaxswarm.multiagent.agents import UNREACHABLE, breadth_first
from jaxswarm.multiagent.constraints import Constraints, reservations
from jaxswarm.multiagent.spacetime import LIMIT, search
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import Graph

ARRIVAL_EXPANSIONS = 100_000
"""The space-time states :meth:`Corridors.arrival` expands before it settles for the distance."""


class Corridors:
    """The corridors of a map and the distances corridor reasoning needs (cached).

    Attributes:
      chain: i32[N] the corridor each node is in (-1: none).
      ends: per corridor, its endpoints ``(e1, e2)``.
      length: per corridor, ``k``: the moves from ``e1`` to ``e2`` along it.
    """

    def __init__(self, graph: Graph):
        self.graph = graph
        self.arrays = edge_arrays(graph)
        indptr, heads = self.arrays.indptr, self.arrays.heads
        degree = np.diff(indptr)
        self.chain = np.full(graph.num_nodes, -1, np.int32)
        self.ends, self.length, self._fields, self._arrivals = [], [], {}, {}
        for node in np.flatnonzero(degree == 2).tolist():
            if self.chain[node] >= 0:
                continue
            cells, ends = [node], []
            for first in heads[indptr[node]:indptr[node + 1]].tolist():
                previous, here, run = node, first, []
                while degree[here] == 2 and here != node:
                    run.append(here)
                    previous, here = here, next(v for v in heads[indptr[here]:indptr[here + 1]]
                                                .tolist() if v != previous)
                if here == node:  # a ring of two-neighbour nodes: no endpoints
                    ends = []
                    break
                cells += run
                ends.append(here)
            if len(ends) == 2 and ends[0] != ends[1]:
                self.chain[cells] = len(self.ends)
                self.ends.append(tuple(ends))
                self.length.append(len(cells) + 1)

    def field(self, target: int, avoiding: int = -1) -> np.ndarray:
        """i32[N]: fewest moves from every node to ``target``, avoiding the nodes of corridor
        ``avoiding`` (-1: none); UNREACHABLE where there is no way (cached)."""
        key = (target, avoiding)
        if key not in self._fields:
            blocked = (self.chain == avoiding) if avoiding >= 0 else np.zeros(len(self.chain),
                                                                              bool)
            self._fields[key] = breadth_first(self.arrays.rev_indptr, self.arrays.rev_tails,
                                              target, blocked)
        return self._fields[key]

    def arrival(self, constraints: Constraints, source: int, target: int,
                avoiding: int = -1) -> int:
        """A lower bound of the first step an agent under ``constraints`` can be on
        ``target`` from ``source``, avoiding corridor ``avoiding`` (-1: none); UNREACHABLE
        where there is no way (cached).

        The space-time search's goal must be kept from its arrival on, so of the vertex
        constraints on ``target`` only those of steps 0, 1, ... without a gap stay (any
        arrival is after them); dropping the others only lowers the bound.
        """
        key = (constraints, source, target, avoiding)
        if key not in self._arrivals:
            field = self.field(target, avoiding)
            banned = {t for t, v in constraints.vertex if v == target}
            run = 0
            while run in banned:
                run += 1
            kept = constraints._replace(
                vertex=frozenset((t, v) for t, v in constraints.vertex if v != target or t < run),
                finish_after=-1, finish_by=UNREACHABLE)
            table = reservations(self.graph.num_nodes, kept)
            if avoiding >= 0:
                table.parked_from[self.chain == avoiding] = 0
            path, _, outcome = search(self.graph, source, target, field, table,
                                      max_expansions=ARRIVAL_EXPANSIONS)
            self._arrivals[key] = (len(path) - 1 if path is not None
                                   else int(field[source]) if outcome == LIMIT else UNREACHABLE)
        return self._arrivals[key]

    def split(self, constraints: tuple[Constraints, Constraints], paths, step: int,
              padded: np.ndarray) -> tuple[Constraints, Constraints] | None:
        """Both children's constraints for a head-on collision of two agents in a corridor,
        or None where the corridor split does not apply.

        Args:
          constraints: the two agents' constraints so far.
          paths: their node lists i32[T_0], i32[T_1] (each from its start to its goal).
          step: the step their collision arrives at.
          padded: i32[2, T] the two paths, each resting at its goal after its end.
        """
        crossings = [self._crossing(padded[i], step) for i in (0, 1)]
        if None in crossings or crossings[0][0] != crossings[1][0]:
            return None
        corridor = crossings[0][0]
        exits = [crossing[1] for crossing in crossings]
        ends = [int(path[0]) for path in paths] + [int(path[-1]) for path in paths]
        if exits[0] == exits[1] or any(self.chain[v] == corridor for v in ends):
            return None
        k = self.length[corridor]
        earliest = [self.arrival(constraints[i], int(paths[i][0]), exits[i]) for i in (0, 1)]
        children = []
        for i in (0, 1):
            around = self.arrival(constraints[i], int(paths[i][0]), exits[i], avoiding=corridor)
            last = min(around - 1, earliest[1 - i] + k)
            if not 0 <= _first_visit(padded[i], exits[i]) <= last:
                return None  # the range would not forbid the current path
            children.append(constraints[i]._replace(
                vertex=constraints[i].vertex | {(t, exits[i]) for t in range(last + 1)}))
        return children[0], children[1]

    def _crossing(self, path: np.ndarray, step: int) -> tuple[int, int] | None:
        """``(corridor, exit)`` where a padded path (i32[T]) is crossing a corridor at
        ``step`` (inside it then, or just out of it): its visit to the corridor enters through
        one endpoint and leaves through the other, ``exit``; else None."""
        inside = step if self.chain[path[step]] >= 0 else step - 1
        corridor = int(self.chain[path[inside]])
        if corridor < 0:
            return None
        first, last = inside, inside
        while first > 0 and self.chain[path[first - 1]] == corridor:
            first -= 1
        while last + 1 < len(path) and self.chain[path[last + 1]] == corridor:
            last += 1
        if first == 0 or last + 1 == len(path):
            return None  # starts or ends in the corridor
        entry, exit_ = int(path[first - 1]), int(path[last + 1])
        return (corridor, exit_) if entry != exit_ else None


def _first_visit(path: np.ndarray, node: int) -> int:
    """The first step of a padded path (i32[T]) on ``node``, or UNREACHABLE."""
    hits = np.flatnonzero(path == node)
    return int(hits[0]) if hits.size else UNREACHABLE
