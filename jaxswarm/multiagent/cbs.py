"""Conflict-Based Search (Sharon, Stern, Felner and Sturtevant, 2015): optimal sum of costs.

The high level is a best-first search over constraint trees. A node holds, per agent, the
constraints "not on node v at step t" and "not along u -> v from step t", and the agents'
fewest-steps paths under them (space-time A*, :mod:`jaxswarm.multiagent.spacetime`). The node
with the lowest sum of costs (then the fewest colliding pairs, then the oldest) is expanded: its
earliest collision (:func:`jaxswarm.multiagent.conflicts.pair_collisions`; the lowest pair at
equal steps) splits it into two children, each forbidding the collision to one of the two agents
and re-planning only that agent. The first node without a collision is an optimal solution.

Improvements, each a switch: ``prioritize`` splits on a cardinal collision first, then a
semi-cardinal one, then the earliest (Boyarski et al., IJCAI 2015, from the agents' MDDs,
:mod:`jaxswarm.multiagent.mdd`; a pair's first collision stands for the pair); ``bypass`` takes a
child's path into its parent instead of splitting when the child costs no more and collides less
(ibid.); ``avoid`` has the low level break ties between shortest paths toward the one meeting the
fewest other agents (a conflict avoidance table, as CBS implementations do). All keep CBS
optimal.

CBS is for few agents: the number of nodes grows exponentially with the number of collisions
that have to be resolved. ``max_nodes`` and ``time_limit`` end it with a clean "not solved".
"""
from __future__ import annotations

import dataclasses
import heapq
import itertools
import time
from typing import NamedTuple

import numpy as np

from jaxswarm.exact._host import edge_arrays
from jaxswarm.multiagent import mdd
from jaxswarm.multiagent.agents import agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.conflicts import pair_collisions
from jaxswarm.multiagent.plan import Plan, pack
from jaxswarm.multiagent.spacetime import FORBIDDEN, Reservations, occupancy, search
from jaxswarm.world.graph import Graph


def cbs(graph: Graph, starts, goals, *, max_nodes: int = 100_000, time_limit: float = 60.0,
        max_expansions: int = 10_000_000, prioritize: bool = False, bypass: bool = False,
        avoid: bool = False) -> Plan:
    """Conflict-Based Search.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      max_nodes: give up after expanding this many constraint-tree nodes.
      time_limit: give up after this many seconds.
      max_expansions: the limit on expanded space-time states per low-level search.
      prioritize: split on cardinal collisions first, then semi-cardinal (from MDDs).
      bypass: take a child's path instead of splitting where it costs no more, collides less.
      avoid: of an agent's shortest paths, take the one meeting the fewest other agents.

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner``: ``cbs``, ``icbs`` with both
      improvements, ``cbs+prioritize`` or ``cbs+bypass`` with one) with the least sum of
      costs; not solved when an agent's goal cannot be reached (naming it), when no solution exists
      (the tree runs out), or at a limit (naming the agents of the collision it was resolving).
      ``stats``: ``expanded`` space-time states, ``nodes`` split, ``bypasses``, ``mdds`` built,
      ``seconds``.

    Raises:
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`).
    """
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    agents = len(start_nodes)
    instance = _Instance(graph, start_nodes, goal_nodes, hop_fields(graph, goal_nodes),
                         max_expansions=max_expansions, began=began,
                         name=_name(prioritize, bypass, avoid), avoid=avoid)
    choose = instance.prioritized_collision if prioritize else _earliest_collision_of
    waiting = [np.array([s], np.int32) for s in start_nodes]
    blocked = cut_off(graph, instance.fields, start_nodes, goal_nodes)
    if blocked is not None:
        return instance.stop(waiting, False, blocked[1], blocked[0])
    tiebreak = itertools.count()
    frontier = [_root(instance, agents, next(tiebreak))]
    last = None
    while frontier:
        node = heapq.heappop(frontier)
        collision = choose(node)
        if collision is None:
            return instance.stop(node.paths, True)
        last, step = collision
        limit = _reached_limit(instance, max_nodes, time_limit)
        if limit is not None:
            return instance.stop(node.paths, False, f"reached {limit} while resolving a "
                                                    f"collision of agents {last[0]} and "
                                                    f"{last[1]}", last[1])
        instance.counts["nodes"] += 1
        children = _children(instance, node, last, step, tiebreak)
        if bypass:
            children = _bypassed(instance, node, children, last, tiebreak)
        for child in children:
            heapq.heappush(frontier, child)
    return instance.stop(waiting, False, "no solution exists: every way of resolving the "
                                         f"collisions of agents {last[0]} and {last[1]} "
                                         "failed", last[1] if last else None)


class _Node(NamedTuple):
    """A constraint-tree node, as a heap entry ordered by its first three fields.

    Attributes:
      cost: the sum of costs of its paths.
      colliding_pairs: how many pairs of agents collide.
      order: its creation number, the oldest first at equal cost and pairs.
      paths: per agent, its node list i32[T_a].
      constraints: per agent, ``(vertex, edge)``: frozensets of ``(t, v)`` (not on ``v`` at
        step ``t``) and of ``(t, u, v)`` (not along ``u -> v`` from step ``t``).
      collisions: i32[A, A] as :func:`pair_collisions` gives them for ``paths``.
    """

    cost: int
    colliding_pairs: int
    order: int
    paths: list
    constraints: list
    collisions: np.ndarray


@dataclasses.dataclass
class _Instance:
    """One CBS instance, the low-level search's limit and the counters of its work.

    Attributes:
      graph: the map (N nodes).
      start_nodes, goal_nodes: i32[A] the agents' starts and goals.
      fields: i32[A, N] steps from every node to each agent's goal (:func:`hop_fields`).
      max_expansions: the limit on expanded space-time states per low-level search.
      began: ``time.perf_counter()`` when the search began.
      counts: ``expanded`` space-time states and constraint-tree ``nodes`` so far.
    """

    graph: Graph
    start_nodes: np.ndarray
    goal_nodes: np.ndarray
    fields: np.ndarray
    max_expansions: int
    began: float
    counts: dict = dataclasses.field(
        default_factory=lambda: {"expanded": 0, "nodes": 0, "bypasses": 0, "mdds": 0})
    mdds: dict = dataclasses.field(default_factory=dict)
    name: str = "cbs"
    avoid: bool = False

    def plan_agent(self, agent: int, vertex: frozenset, edge: frozenset, others: list = ()):
        """The agent's fewest-steps path (i32[T]) under its constraints, or None; with
        ``avoid``, the one meeting the fewest of ``others`` (the paths of the other agents,
        or, at the root, of those planned so far; the agent's own entry is skipped)."""
        table = (occupancy([path for a, path in enumerate(others) if a != agent],
                           self.graph.num_nodes) if self.avoid else None)
        path, expanded, _ = search(self.graph, int(self.start_nodes[agent]),
                                   int(self.goal_nodes[agent]), self.fields[agent],
                                   _reservations(self.graph.num_nodes, vertex, edge),
                                   max_expansions=self.max_expansions, avoid=table)
        self.counts["expanded"] += expanded
        return path

    def agent_mdd(self, agent: int, path, constraints: tuple) -> list[frozenset]:
        """The agent's MDD at its path's cost under its constraints (cached)."""
        key = (agent, len(path) - 1, *constraints)
        levels = self.mdds.get(key)
        if levels is None:
            arrays = edge_arrays(self.graph)
            levels = self.mdds[key] = mdd.mdd(
                arrays.indptr, arrays.heads, int(self.start_nodes[agent]),
                int(self.goal_nodes[agent]), len(path) - 1, self.fields[agent], *constraints)
            self.counts["mdds"] += 1
        return levels

    def prioritized_collision(self, node: "_Node") -> tuple[tuple[int, int], int] | None:
        """``((a, b), step)``: of every colliding pair's first collision, a cardinal one first,
        then a semi-cardinal one, then the earliest (then the lowest pair); None when none."""
        pairs = np.argwhere(np.triu(node.collisions >= 0, 1))
        if not pairs.size:
            return None
        padded = pack(node.paths)[0]
        best = None
        for a, b in pairs.tolist():
            step = int(node.collisions[a, b])
            sides = [mdd.cardinal_for(self.agent_mdd(x, node.paths[x], node.constraints[x]),
                                      int(self.goal_nodes[x]), step, int(padded[x, step]),
                                      int(padded[x, step - 1]) if _swap(padded, a, b, step)
                                      else int(padded[x, step]))
                     for x in (a, b)]
            key = (mdd.classify(*sides), step, a, b)
            best = key if best is None or key < best else best
        return (best[2], best[3]), best[1]

    def stop(self, paths, solved: bool, reason: str = "", agent=None) -> Plan:
        """The search's :class:`~jaxswarm.multiagent.plan.Plan` of ``paths`` (one node list
        per agent)."""
        return Plan(*pack(paths, self.goal_nodes), solved=solved, planner=self.name, reason=reason,
                    agent=agent,
                    stats={**self.counts, "seconds": time.perf_counter() - self.began})


def _name(prioritize: bool, bypass: bool, avoid: bool) -> str:
    """The planner's name in a Plan: ``icbs`` with every improvement, ``cbs`` with none."""
    if prioritize and bypass and avoid:
        return "icbs"
    return "cbs" + "".join(f"+{name}" for name, on in (
        ("prioritize", prioritize), ("bypass", bypass), ("avoid", avoid)) if on)


def _swap(padded: np.ndarray, a: int, b: int, step: int) -> bool:
    """Whether agents ``a`` and ``b`` of ``padded`` (i32[A, T]) collide at ``step`` by
    swapping rather than on one node."""
    return bool(padded[a, step] != padded[b, step])


def _earliest_collision_of(node: "_Node") -> tuple[tuple[int, int], int] | None:
    """CBS's choice: the earliest collision of the node (:func:`_earliest_collision`)."""
    return _earliest_collision(node.collisions)


def _earliest_collision(collisions: np.ndarray) -> tuple[tuple[int, int], int] | None:
    """``((a, b), step)``: the first step at which two agents collide and the lowest such
    pair (``a < b``), from ``collisions`` i32[A, A] (:func:`pair_collisions`); None when no
    pair collides."""
    if not (collisions >= 0).any():
        return None
    pair = np.argwhere(collisions == collisions[collisions >= 0].min())[0]
    return (int(pair[0]), int(pair[1])), int(collisions[pair[0], pair[1]])


def _reached_limit(instance: _Instance, max_nodes: int, time_limit: float) -> str | None:
    """The limit the search has reached, in words, or None: ``max_nodes`` expanded nodes,
    then ``time_limit`` seconds."""
    if instance.counts["nodes"] >= max_nodes:
        return f"{max_nodes} nodes"
    if time.perf_counter() - instance.began > time_limit:
        return f"the time limit ({time_limit:g} s)"
    return None


def _children(instance: _Instance, node: _Node, pair: tuple[int, int], step: int,
              tiebreak) -> list[_Node]:
    """Expand ``node`` at the collision of ``pair`` arriving at ``step``: one child per agent
    of the pair, forbidding the collision to that agent and re-planning it, none for an agent
    that then has no path. ``tiebreak`` numbers the children in the order they are made."""
    padded = pack(node.paths)[0]
    children = []
    for agent, other in (pair, pair[::-1]):
        constraints = _forbid(node.constraints[agent], padded, agent, other, step)
        path = instance.plan_agent(agent, *constraints, others=node.paths)
        if path is not None:
            children.append(_child(node, agent, path, constraints, next(tiebreak)))
    return children


def _root(instance: _Instance, agents: int, order: int) -> _Node:
    """The constraint tree's root: every agent's path without constraints (with ``avoid``,
    meeting the fewest of those planned before it)."""
    no_constraints = [(frozenset(), frozenset())] * agents
    paths = []
    for a in range(agents):
        paths.append(instance.plan_agent(a, *no_constraints[a], others=paths))
    return _node(paths, no_constraints, pair_collisions(pack(paths)[0]), order)


def _bypassed(instance: _Instance, node: _Node, children: list[_Node], pair: tuple[int, int],
              tiebreak) -> list[_Node]:
    """Bypassing: where a child costs no more than ``node`` and collides less, ``node`` with
    the child's path and its own constraints (the path keeps them: the child's include them)
    in place of the children."""
    taken = next((child for child in children if child.cost == node.cost
                  and child.colliding_pairs < node.colliding_pairs), None)
    if taken is None:
        return children
    agent = next(a for a in pair if taken.paths[a] is not node.paths[a])
    instance.counts["bypasses"] += 1
    return [_child(node, agent, taken.paths[agent], node.constraints[agent], next(tiebreak))]


def _forbid(constraints: tuple, padded: np.ndarray, agent: int, other: int,
            step: int) -> tuple[frozenset, frozenset]:
    """``agent``'s ``(vertex, edge)`` constraints, plus one against its collision with
    ``other`` arriving at ``step`` (``padded``: i32[A, T] the node's paths): the node they
    share at ``step``, or, where they swap, ``agent``'s move into its node at ``step``."""
    vertex, edge = constraints
    here = int(padded[agent, step])
    if here == padded[other, step]:
        return vertex | {(step, here)}, edge
    return vertex, edge | {(step - 1, int(padded[agent, step - 1]), here)}


def _child(node: _Node, agent: int, path, constraints: tuple, order: int) -> _Node:
    """``node`` with ``agent`` on ``path`` (i32[T]) under its new ``constraints``."""
    paths = list(node.paths)
    paths[agent] = path
    all_constraints = list(node.constraints)
    all_constraints[agent] = constraints
    # Only the re-planned agent's collisions change.
    collisions = node.collisions.copy()
    changed = pair_collisions(pack(paths)[0], [agent])[0]
    collisions[agent, :] = changed
    collisions[:, agent] = changed
    return _node(paths, all_constraints, collisions, order)


def _node(paths, constraints, collisions: np.ndarray, order: int) -> _Node:
    """The node of ``paths`` (node lists), ``constraints`` and their ``collisions`` i32[A, A]
    (as :func:`pair_collisions` gives them), made ``order``-th."""
    cost = sum(len(path) - 1 for path in paths)
    return _Node(cost, int((collisions >= 0).sum()) // 2, order, paths, constraints, collisions)


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
