"""The constraints of conflict-based search: what one agent may not do, how a collision adds
one, and the low-level reservation table that enforces them.

A collision of agents ``a`` and ``b`` arriving at step t is split into two children, each
forbidding it to one of them: the node they share at t (a vertex constraint), or, where they
swap, the agent's move into its node at t (an edge constraint). With target reasoning (Li, Gange,
Harabor, Stuckey, Ma and Koenig, ICAPS 2020), a vertex collision on the goal of an agent that
already stays there is split by when that agent finishes: either it finishes after t (a length
constraint on it), or it finishes by t (a length constraint the other way) and the other may never
be on that goal from t on. Every solution keeps the constraints of one of the two children, and
none keeps both, so the split keeps CBS complete and optimal; it ends in one split what vertex
constraints resolve a step at a time.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from jaxswarm.multiagent.agents import UNREACHABLE
from jaxswarm.multiagent.spacetime import FORBIDDEN, Reservations


class Constraints(NamedTuple):
    """One agent's constraints (hashable: they key caches).

    Attributes:
      vertex: ``(t, v)``: not on node ``v`` at step ``t``.
      edge: ``(t, u, v)``: not along ``u -> v`` from step ``t``.
      parked: ``(t, v)``: not on node ``v`` at step ``t`` or any later one.
      finish_after: the agent does not stay at its goal for good from a step at or before this
        one (its cost is larger); -1: no such constraint.
      finish_by: the agent stays at its goal for good from this step or an earlier one (its
        cost is at most this); UNREACHABLE: no such constraint.
    """

    vertex: frozenset = frozenset()
    edge: frozenset = frozenset()
    parked: frozenset = frozenset()
    finish_after: int = -1
    finish_by: int = UNREACHABLE


def earliest_collision(collisions: np.ndarray) -> tuple[tuple[int, int], int] | None:
    """``((a, b), step)``: the first step at which two agents collide and the lowest such pair
    (``a < b``), from ``collisions`` i32[A, A]
    (:func:`~jaxswarm.multiagent.conflicts.pair_collisions`); None when no pair collides."""
    if not (collisions >= 0).any():
        return None
    pair = np.argwhere(collisions == collisions[collisions >= 0].min())[0]
    return (int(pair[0]), int(pair[1])), int(collisions[pair[0], pair[1]])


def forbid(constraints: Constraints, padded: np.ndarray, agent: int, other: int, step: int,
           resting_from: np.ndarray | None = None) -> Constraints:
    """``agent``'s constraints plus one against its collision with ``other`` arriving at
    ``step``.

    Args:
      constraints: the agent's constraints so far.
      padded: i32[A, T] the node's paths (each resting at its goal after its end).
      agent, other: the colliding agents (rows of ``padded``).
      step: the step the collision arrives at.
      resting_from: i32[A] for target reasoning (None: without it), the step from which each
        agent's path stays at its goal as CBS counts it (its length - 1; a path may end with
        waits at its goal, which CBS's low level only makes under a length constraint).
    """
    here = int(padded[agent, step])
    if here != padded[other, step]:
        return constraints._replace(
            edge=constraints.edge | {(step - 1, int(padded[agent, step - 1]), here)})
    if resting_on(padded, other, agent, step, resting_from):
        return constraints._replace(parked=constraints.parked | {(step, here)})
    if resting_on(padded, agent, other, step, resting_from):
        return constraints._replace(finish_after=max(constraints.finish_after, step))
    return constraints._replace(vertex=constraints.vertex | {(step, here)})


def resting_on(padded: np.ndarray, resting: int, other: int, step: int,
               resting_from: np.ndarray | None) -> bool:
    """Whether the collision of agents ``resting`` and ``other`` (rows of ``padded``, i32[A,
    T]) arriving at ``step`` is a target collision on ``resting``'s goal: both on one node,
    ``resting`` staying at its goal from ``resting_from[resting]`` (as :func:`forbid` takes
    it; None: without target reasoning, never) at or before ``step``."""
    return (resting_from is not None and padded[resting, step] == padded[other, step]
            and step >= resting_from[resting])


def split_collision(constraints: tuple[Constraints, Constraints], padded: np.ndarray, step: int,
                    resting_from: np.ndarray | None = None) -> tuple[tuple, tuple]:
    """The two children of the collision of agents 0 and 1 arriving at ``step``: child ``i``
    holds both agents' constraints, the collision forbidden to agent ``i`` (:func:`forbid`).
    With target reasoning (``resting_from``, as :func:`forbid` takes it), where agent ``i`` is
    kept off the goal the other rests on from ``step`` on, the other must also finish by
    ``step`` in that child, so that no solution keeps both children.

    Args:
      constraints: the two agents' constraints so far.
      padded: i32[2, T] their paths (each resting at its goal after its end).
      step: the step their collision arrives at.
      resting_from: optional i32[2] the steps from which they rest at their goals.
    """
    children = []
    for i in (0, 1):
        both = list(constraints)
        both[i] = forbid(constraints[i], padded, i, 1 - i, step, resting_from)
        if resting_on(padded, 1 - i, i, step, resting_from):
            both[1 - i] = both[1 - i]._replace(finish_by=min(both[1 - i].finish_by, step))
        children.append(tuple(both))
    return children[0], children[1]


def reservations(num_nodes: int, constraints: Constraints) -> Reservations:
    """The low-level table of one agent's constraints: FORBIDDEN (t, v) entries, banned moves,
    nodes parked from a step on and the earliest finish, over enough steps that the world is
    static after them."""
    steps = max([t + 1 for t, _ in constraints.vertex]
                + [t + 1 for t, _, _ in constraints.edge]
                + [t + 1 for t, _ in constraints.parked] + [constraints.finish_after + 1, 0])
    table = Reservations.empty(num_nodes, steps)
    for t, v in constraints.vertex:
        table.holder[t, v] = FORBIDDEN
    for t, v in constraints.parked:
        table.parked_from[v] = min(table.parked_from[v], t)
    if constraints.edge:
        table.banned = np.array(sorted(constraints.edge), np.int32)
    table.earliest_finish = constraints.finish_after + 1
    table.latest_finish = constraints.finish_by
    return table
