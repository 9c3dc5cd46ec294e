"""CBS's weighted pairwise dependency graph heuristic (WDG; Li, Felner, Boyarski, Koenig and
Koenig's CBSH, IJCAI 2019).

At a constraint-tree node, two colliding agents *depend* on each other when no pair of their paths
under the node's constraints is free of collisions at the cost of their own paths: the edge's
weight is how much more the pair's best collision-free paths cost (the optimum of the two-agent
problem under their constraints, from a small CBS) than the two paths now. Any solution below
the node raises the sum of costs by at least the graph's edge-weighted minimum vertex cover: the
least sum of nonnegative integers ``x_a``, one per agent, with ``x_a + x_b >= w_ab`` on every
edge. That cover is an admissible heuristic: added to a node's sum of costs it orders the
high-level search and keeps CBS optimal.

Both parts are bounded: a two-agent CBS that reaches its node limit gives the least cost left in
its frontier (a lower bound of the pair's optimum, so still admissible), and a connected
component of the graph with more than :data:`EXACT_VERTICES` agents gets a matching's weight
(each matched edge needs its own weight, so a matching is covered by no less) instead of the exact
cover.
"""
from __future__ import annotations

import functools
import heapq
import itertools
from typing import Callable

import numpy as np

from jaxswarm.multiagent.conflicts import pair_collisions
from jaxswarm.multiagent.plan import pack

EXACT_VERTICES = 12
"""The largest connected component whose cover is found exactly (a branch and bound)."""
PAIR_NODES = 64
"""The constraint-tree nodes a two-agent CBS expands before it settles for its lower bound."""


def pair_extra_cost(paths: tuple, constraints: tuple,
                    replan: Callable[[int, tuple], np.ndarray | None],
                    split: Callable[[tuple, tuple, int], tuple],
                    max_nodes: int | None = None) -> int:
    """The dependency weight of two agents: their least collision-free sum of costs under their
    constraints minus the costs of ``paths`` (a lower bound of it after ``max_nodes`` nodes).

    Args:
      paths: the two agents' shortest paths under their constraints, i32[T_0] and i32[T_1].
      constraints: the two agents' constraints (as CBS keeps them,
        :class:`~jaxswarm.multiagent.constraints.Constraints`).
      replan: ``replan(i, constraints_i)``: agent ``i``'s (0 or 1) shortest path under
        ``constraints_i``, or None when it has none.
      split: ``split(constraints, paths, step)``: the two children of the agents' collision
        arriving at ``step`` (``paths``: their two node lists), each both agents' constraints,
        child ``i`` re-planning agent ``i``, as CBS splits it.
      max_nodes: the nodes of the two-agent CBS to expand at most.

    Returns:
      The weight (0 when the paths do not collide, or when the pair has no solution, which the
      whole search finds by itself).
    """
    max_nodes = PAIR_NODES if max_nodes is None else max_nodes
    base = sum(len(path) - 1 for path in paths)
    order = itertools.count()
    frontier = [(base, next(order), tuple(paths), tuple(constraints))]
    for _ in range(max_nodes):
        if not frontier:
            return 0
        cost, _, pair, held = heapq.heappop(frontier)
        step = int(pair_collisions(pack(list(pair))[0], [0])[0, 1])
        if step < 0:
            return cost - base
        for agent, both in enumerate(split(held, pair, step)):
            path = replan(agent, both[agent])
            if path is not None:
                child = list(pair)
                child[agent] = path
                heapq.heappush(frontier, (cost - len(pair[agent]) + len(path), next(order),
                                          tuple(child), tuple(both)))
    return frontier[0][0] - base if frontier else 0


def vertex_cover(weights: dict[tuple[int, int], int]) -> int:
    """The edge-weighted minimum vertex cover of a graph: the least sum of nonnegative integers
    ``x_a`` with ``x_a + x_b >= w`` for every edge ``(a, b): w`` of ``weights`` (w > 0);
    exact on components of at most :data:`EXACT_VERTICES` vertices, a matching's weight (a lower
    bound) on larger ones."""
    neighbours: dict[int, dict[int, int]] = {}
    for (a, b), weight in weights.items():
        if weight > 0:
            neighbours.setdefault(a, {})[b] = weight
            neighbours.setdefault(b, {})[a] = weight
    total, seen = 0, set()
    for vertex in neighbours:
        if vertex in seen:
            continue
        component = _component(neighbours, vertex)
        seen |= component
        total += _component_cover(tuple(sorted((a, b, w) for a in component
                                               for b, w in neighbours[a].items() if a < b)))
    return total


@functools.lru_cache(maxsize=1 << 16)
def _component_cover(edges: tuple[tuple[int, int, int], ...]) -> int:
    """The cover of one connected component, given as its sorted edges ``(a, b, w)`` (cached:
    a constraint-tree node's children share most of its components)."""
    neighbours: dict[int, dict[int, int]] = {}
    for a, b, weight in edges:
        neighbours.setdefault(a, {})[b] = weight
        neighbours.setdefault(b, {})[a] = weight
    component = set(neighbours)
    return (_exact_cover(component, neighbours) if len(component) <= EXACT_VERTICES
            else _matching(component, neighbours))


def _component(neighbours: dict, vertex: int) -> set[int]:
    """The vertices connected to ``vertex``."""
    found, stack = {vertex}, [vertex]
    while stack:
        for other in neighbours[stack.pop()]:
            if other not in found:
                found.add(other)
                stack.append(other)
    return found


def _matching(vertices, neighbours: dict, fixed: dict | None = None) -> int:
    """A lower bound of the cover of ``vertices``: the weight of a greedy matching (heaviest
    edges first) among those not in ``fixed``, or, if larger, what the fixed values still
    demand of their free neighbours."""
    fixed = fixed or {}
    free = [v for v in vertices if v not in fixed]
    edges = sorted(((w, a, b) for a in free for b, w in neighbours[a].items()
                    if a < b and b not in fixed), reverse=True)
    used, matched = set(), 0
    for weight, a, b in edges:
        if a not in used and b not in used:
            used |= {a, b}
            matched += weight
    demanded = sum(max([w - fixed[u] for u, w in neighbours[v].items() if u in fixed] + [0])
                   for v in free)
    return max(matched, demanded)


def _exact_cover(component: set[int], neighbours: dict) -> int:
    """The exact cover of one component: a branch and bound over the vertices (most
    neighbours first), each taking the least value its fixed neighbours leave it up to its
    heaviest edge, pruned by :func:`_matching`."""
    order = sorted(component, key=lambda v: (-len(neighbours[v]), v))
    best = sum(max(neighbours[v].values()) for v in order)  # each at its heaviest: a cover
    fixed: dict[int, int] = {}

    def branch(index: int, total: int) -> None:
        nonlocal best
        if total + _matching(order[index:], neighbours, fixed) >= best:
            return
        if index == len(order):
            best = total
            return
        vertex = order[index]
        least = max([w - fixed[u] for u, w in neighbours[vertex].items() if u in fixed] + [0])
        for value in range(least, max(neighbours[vertex].values()) + 1):
            fixed[vertex] = value
            branch(index + 1, total + value)
        del fixed[vertex]

    branch(0, 0)
    return best
