"""Conflict-Based Search (Sharon, Stern, Felner and Sturtevant, 2015): optimal sum of costs.

The high level is a best-first search over constraint trees. A node holds, per agent, the
constraints "not on node v at step t" and "not along u -> v from step t", and the agents'
fewest-steps paths under them (space-time A*, :mod:`jaxswarm.multiagent.spacetime`). The node
with the lowest sum of costs (then the fewest colliding pairs, then the oldest) is expanded: its
earliest collision (:func:`jaxswarm.multiagent.conflicts.pair_collisions`; the lowest pair at
equal steps) splits it into two children, each forbidding the collision to one of the two agents
and re-planning only that agent. The first node without a collision is an optimal solution.

CBS is for few agents: the number of nodes grows exponentially with the number of collisions
that have to be resolved. ``max_nodes`` and ``time_limit`` end it with a clean "not solved".
"""
from __future__ import annotations

import heapq
import itertools
import time

import numpy as np

from jaxswarm.multiagent.agents import UNREACHABLE, agent_nodes, hop_fields, place
from jaxswarm.multiagent.conflicts import pair_collisions
from jaxswarm.multiagent.plan import Plan, pack
from jaxswarm.multiagent.spacetime import FORBIDDEN, Reservations, search
from jaxswarm.world.graph import Graph


def cbs(graph: Graph, starts, goals, *, max_nodes: int = 100_000, time_limit: float = 60.0,
        max_expansions: int = 10_000_000) -> Plan:
    """Conflict-Based Search.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      max_nodes: give up after expanding this many constraint-tree nodes.
      time_limit: give up after this many seconds.
      max_expansions: the limit on expanded space-time states per low-level search.

    Returns:
      A :class:`Plan` (``planner="cbs"``) with the least sum of costs; not solved when an
      agent's goal cannot be reached (naming it), when no solution exists (the tree runs out),
      or at a limit (naming the agents of the collision it was resolving).

    Raises:
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`).
    """
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    agents = len(start_nodes)
    fields = hop_fields(graph, goal_nodes)
    counts = {"expanded": 0, "nodes": 0}

    def plan_agent(agent: int, vertex: frozenset, edge: frozenset):
        path, expanded, _ = search(graph, int(start_nodes[agent]), int(goal_nodes[agent]),
                                   fields[agent], _reservations(graph.num_nodes, vertex, edge),
                                   max_expansions=max_expansions)
        counts["expanded"] += expanded
        return path

    def stop(paths, solved: bool, reason: str = "", agent=None) -> Plan:
        return Plan(*pack(paths, goal_nodes), solved=solved, planner="cbs", reason=reason,
                    agent=agent, stats={**counts, "seconds": time.perf_counter() - began})

    waiting = [np.array([s], np.int32) for s in start_nodes]
    unreachable = np.nonzero(fields[np.arange(agents), start_nodes] == UNREACHABLE)[0]
    if unreachable.size:
        a = int(unreachable[0])
        return stop(waiting, False, f"agent {a} cannot reach its goal "
                                    f"{place(graph, goal_nodes[a])} from "
                                    f"{place(graph, start_nodes[a])}", a)
    no_constraints = [(frozenset(), frozenset())] * agents
    root = [plan_agent(a, *no_constraints[a]) for a in range(agents)]
    tiebreak = itertools.count()
    frontier = [_node(root, no_constraints, pair_collisions(pack(root)[0]), next(tiebreak))]
    last = None
    while frontier:
        _, _, _, paths, constraints, first = heapq.heappop(frontier)
        if not (first >= 0).any():
            return stop(paths, True)
        pair = np.argwhere(first == first[first >= 0].min())[0]
        last = (int(pair[0]), int(pair[1]))
        if counts["nodes"] >= max_nodes or time.perf_counter() - began > time_limit:
            limit = (f"{max_nodes} nodes" if counts["nodes"] >= max_nodes
                     else f"the time limit ({time_limit:g} s)")
            return stop(paths, False, f"reached {limit} while resolving a collision of agents "
                                      f"{last[0]} and {last[1]}", last[1])
        counts["nodes"] += 1
        padded = pack(paths)[0]
        step = int(first[pair[0], pair[1]])
        for agent, other in (last, last[::-1]):
            vertex, edge = constraints[agent]
            here = int(padded[agent, step])
            if here == padded[other, step]:
                vertex = vertex | {(step, here)}
            else:
                edge = edge | {(step - 1, int(padded[agent, step - 1]), here)}
            path = plan_agent(agent, vertex, edge)
            if path is None:
                continue
            child_paths = list(paths)
            child_paths[agent] = path
            child_constraints = list(constraints)
            child_constraints[agent] = (vertex, edge)
            # Only the re-planned agent's collisions change.
            child_collisions = first.copy()
            changed = pair_collisions(pack(child_paths)[0], [agent])[0]
            child_collisions[agent, :] = changed
            child_collisions[:, agent] = changed
            heapq.heappush(frontier, _node(child_paths, child_constraints, child_collisions,
                                           next(tiebreak)))
    return stop(waiting, False, "no solution exists: every way of resolving the collisions of "
                                f"agents {last[0]} and {last[1]} failed",
                last[1] if last else None)


def _node(paths, constraints, collisions: np.ndarray, order: int) -> tuple:
    """A heap entry: (sum of costs, colliding pairs, order, paths, constraints, collisions
    i32[A, A] as :func:`pair_collisions` gives them)."""
    cost = sum(len(path) - 1 for path in paths)
    return cost, int((collisions >= 0).sum()) // 2, order, paths, constraints, collisions


def _reservations(num_nodes: int, vertex: frozenset, edge: frozenset) -> Reservations:
    """The low-level table of one agent's constraints: FORBIDDEN (t, v) entries and banned
    moves, over enough steps that the world is static after them."""
    steps = max([t + 1 for t, _ in vertex] + [t + 1 for t, _, _ in edge] + [0])
    table = Reservations.empty(num_nodes, steps)
    for t, v in vertex:
        table.holder[t, v] = FORBIDDEN
    if edge:
        table.banned = np.array(sorted(edge), np.int32)
    return table
