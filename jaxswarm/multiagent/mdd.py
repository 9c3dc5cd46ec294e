"""Multi-value decision diagrams, and the cardinality of a collision (Boyarski et al., IJCAI 2015).

An agent's MDD of cost c under its constraints holds, for every step t = 0..c, the nodes it can
be on at t on some path that reaches its goal at step c, moving or waiting one step at a time and
keeping its constraints (no ``(t, v)`` vertex, no ``(t, u, v)`` move). After step c it rests at
its goal, so its level there is the goal alone. A parked constraint ``(t, v)`` keeps it off
``v`` from step t on (target reasoning's, on another agent's goal).

A collision of two agents is *cardinal* for an agent when every path of its cost passes it (its
level at the collision is the colliding node alone; for a swap, both ends of the move): then
forbidding it costs that agent a step. A collision cardinal for both agents raises the cost of
both children, semi-cardinal for one, non-cardinal for none. CBS that splits on cardinal
collisions first raises its lower bound soonest.
"""
from __future__ import annotations

import numpy as np

CARDINAL, SEMI_CARDINAL, NON_CARDINAL = 0, 1, 2
"""Collision classes, the one to split on first the lowest."""


def mdd(indptr: np.ndarray, heads: np.ndarray, start: int, goal: int, cost: int,
        field: np.ndarray, vertex: frozenset = frozenset(), edge: frozenset = frozenset(),
        parked: frozenset = frozenset()) -> list[frozenset]:
    """The agent's MDD of ``cost``: its levels 0..cost (empty when no path of that cost keeps
    the constraints).

    Args:
      indptr, heads: the map's moves as CSR arrays (:func:`jaxswarm.world.edges.edge_arrays`).
      start, goal: node indices.
      cost: the steps of the paths.
      field: i32[N] steps from every node to ``goal`` (the pruning: a node with more steps to go
        than are left is on no such path).
      vertex: ``(t, v)``: not on ``v`` at step ``t``.
      edge: ``(t, u, v)``: not along ``u -> v`` from step ``t``.
      parked: ``(t, v)``: not on ``v`` at step ``t`` or later.
    """
    parked_from = {}
    for t, v in parked:
        parked_from[v] = min(t, parked_from.get(v, t))
    forward = [{start} if (0, start) not in vertex and parked_from.get(start, 1) > 0 else set()]
    for t in range(1, cost + 1):
        level = set()
        for u in forward[-1]:
            for v in heads[indptr[u]:indptr[u + 1]].tolist() + [u]:
                if (field[v] <= cost - t and (t, v) not in vertex
                        and (t - 1, u, v) not in edge and parked_from.get(v, t + 1) > t):
                    level.add(v)
        forward.append(level)
    levels = [frozenset()] * (cost + 1)
    levels[cost] = frozenset({goal} & forward[cost])
    for t in range(cost - 1, -1, -1):
        after = levels[t + 1]
        levels[t] = frozenset(
            u for u in forward[t]
            if any((v in after and (t, u, v) not in edge)
                   for v in heads[indptr[u]:indptr[u + 1]].tolist() + [u]))
    if not levels[0]:
        return [frozenset()] * (cost + 1)
    return levels


def level(levels: list[frozenset], goal: int, step: int) -> frozenset:
    """The nodes of an MDD at ``step`` (the goal alone after its last level)."""
    return levels[step] if step < len(levels) else frozenset({goal})


def cardinal_for(levels: list[frozenset], goal: int, step: int, here: int, before: int) -> bool:
    """Whether a collision at ``step`` is cardinal for an agent of MDD ``levels``: on ``here``
    at ``step`` (a vertex collision: ``before`` is ignored as equal to ``here``), or moving
    ``before -> here`` into ``step`` (a swap)."""
    if level(levels, goal, step) != {here}:
        return False
    return before == here or level(levels, goal, step - 1) == {before}


def classify(for_a: bool, for_b: bool) -> int:
    """The class of a collision cardinal (or not) for each of its two agents."""
    return CARDINAL if for_a and for_b else SEMI_CARDINAL if for_a or for_b else NON_CARDINAL
