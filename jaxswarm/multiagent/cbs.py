"""Conflict-Based Search (Sharon, Stern, Felner and Sturtevant, 2015): optimal sum of costs.

:func:`cbs` searches constraint trees best first: a node holds each agent's constraints and its
fewest-steps path under them (space-time A*, :mod:`jaxswarm.multiagent.spacetime`), and the node
of the least sum of costs splits on its earliest collision into two children, each forbidding it
to one agent. The improvements, each a switch (:data:`SWITCHES`), keep it optimal: ``prioritize``
(cardinal collisions first, from MDDs, :mod:`jaxswarm.multiagent.mdd`) and ``bypass`` (Boyarski
et al., IJCAI 2015); ``avoid`` (a conflict avoidance table breaks the low level's ties); ``wdg``
(the weighted dependency graph heuristic, Li et al., IJCAI 2019,
:mod:`jaxswarm.multiagent.dependency`); ``target`` and ``corridor`` (Li et al., ICAPS 2020,
:mod:`jaxswarm.multiagent.constraints`, :mod:`jaxswarm.multiagent.corridor`); ``rectangle`` (Li
et al., AAAI 2019, :mod:`jaxswarm.multiagent.rectangle`). ``docs/papers.md`` says how each
works here. The nodes grow exponentially with the collisions to resolve, so CBS is for few
agents: ``max_nodes`` and ``time_limit`` end it with a clean "not solved".
"""
from __future__ import annotations

import dataclasses
import heapq
import itertools
import time
from typing import NamedTuple

import numpy as np

from jaxswarm.multiagent import dependency, mdd
from jaxswarm.multiagent.agents import agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.conflicts import pair_collision_steps, pair_collisions
from jaxswarm.multiagent.constraints import (Constraints, earliest_collision, reservations,
                                             resting_on, split_collision)
from jaxswarm.multiagent.corridor import Corridors
from jaxswarm.multiagent.limits import check_count, check_seconds, check_switch
from jaxswarm.multiagent.plan import Plan, pack
from jaxswarm.multiagent.rectangle import Rectangles
from jaxswarm.multiagent.spacetime import occupancy, search
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import Graph


SWITCHES = ("prioritize", "bypass", "avoid", "wdg", "target", "corridor", "rectangle")
"""The improvements of :class:`~jaxswarm.multiagent.cbs.CBSConfig`, each a switch (see the module
docstring)."""


@dataclasses.dataclass(frozen=True)
class CBSConfig:
    """The options of :func:`cbs`, checked when made.

    Attributes:
      max_nodes: give up after expanding this many constraint-tree nodes (at least 1).
      time_limit: give up after this many seconds (positive).
      max_expansions: the limit on expanded space-time states per low-level search (at least 1).
      prioritize: split on cardinal collisions first, then semi-cardinal (from MDDs).
      bypass: take a child's path instead of splitting where it costs no more, collides less.
      avoid: of an agent's shortest paths, take the one meeting the fewest other agents.
      wdg: expand the node of the least sum of costs plus its weighted dependency graph's
        vertex cover first.
      target: split a collision on a resting agent's goal by when that agent finishes.
      corridor: split a head-on collision in a corridor by which agent crosses first.
      rectangle: split a collision of two agents crossing a rectangle by barriers.

    Raises:
      TypeError, ValueError: a limit that is not a positive number (``time_limit``) or a whole
        number of at least 1 (``max_nodes``, ``max_expansions``), or a switch that is not True
        or False, naming it.
    """

    max_nodes: int = 100_000
    time_limit: float = 60.0
    max_expansions: int = 10_000_000
    prioritize: bool = False
    bypass: bool = False
    avoid: bool = False
    wdg: bool = False
    target: bool = False
    corridor: bool = False
    rectangle: bool = False

    def __post_init__(self):
        check_seconds("time_limit", self.time_limit)
        check_count("max_nodes", self.max_nodes)
        check_count("max_expansions", self.max_expansions)
        for switch in SWITCHES:
            check_switch(switch, getattr(self, switch))


def cbs(graph: Graph, starts, goals, **options) -> Plan:
    """Conflict-Based Search.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      **options: those of :class:`~jaxswarm.multiagent.cbs.CBSConfig` (limits and improvements).

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner``: ``cbs``, ``icbs`` with
      ``prioritize``, ``bypass`` and ``avoid``, ``cbsh`` with ``wdg`` too, and ``cbsh_`` with
      ``r``, ``t`` and ``c`` for ``rectangle``, ``target`` and ``corridor`` on top, as in
      ``cbsh_rtc``, else ``cbs`` and ``+name`` per switch) with the least sum of costs; not
      solved when an agent's goal cannot be reached (naming it), when no solution exists (the
      tree runs out), or at a limit (naming the agents of the collision it was resolving).
      ``stats``: ``expanded`` space-time states, ``nodes`` split, ``bypasses``, ``mdds``
      built, ``pairs`` two-agent problems solved for the heuristic, ``corridors`` corridor
      splits, ``rectangles`` rectangle splits, ``lower_bound`` the
      least sum of costs plus heuristic left (the optimum when solved), ``seconds``.

    Raises:
      TypeError, ValueError: a bad option (see :class:`~jaxswarm.multiagent.cbs.CBSConfig`), naming
        it, before any search.
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`).
    """
    config = CBSConfig(**options)
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    agents = len(start_nodes)
    instance = _Instance(graph, start_nodes, goal_nodes, hop_fields(graph, goal_nodes),
                         max_expansions=config.max_expansions, began=began,
                         name=_name(*(getattr(config, switch) for switch in SWITCHES)),
                         avoid=config.avoid, wdg=config.wdg, target=config.target,
                         corridors=Corridors(graph) if config.corridor else None,
                         rectangles=Rectangles(graph) if config.rectangle else None)
    blocked = cut_off(graph, instance.fields, start_nodes, goal_nodes)
    if blocked is not None:
        return instance.stop([np.array([s], np.int32) for s in start_nodes], False, blocked[1],
                             blocked[0])
    return _search(instance, agents, config.max_nodes, config.time_limit, config.prioritize,
                   config.bypass)


def _search(instance: "_Instance", agents: int, max_nodes: int, time_limit: float,
            prioritize: bool, bypass: bool) -> Plan:
    """The high-level best-first search of :func:`cbs` from the root."""
    choose = (instance.prioritized_collision if prioritize
              else lambda node: earliest_collision(node.collisions))
    tiebreak = itertools.count()
    frontier = [_root(instance, agents, next(tiebreak))]
    last = None
    while frontier:
        node = heapq.heappop(frontier)
        if not node.informed:
            # The heuristic is computed for the nodes that reach the top of the frontier
            # only: most generated nodes never do. One it raises goes back to wait its turn.
            informed = instance.bounded(node)
            if informed.bound > node.bound:
                heapq.heappush(frontier, informed)
                continue
            node = informed
        instance.counts["lower_bound"] = node.bound
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
            heapq.heappush(frontier, child._replace(bound=max(node.bound, child.cost)))
    waiting = [np.array([s], np.int32) for s in instance.start_nodes]
    return instance.stop(waiting, False, "no solution exists: every way of resolving the "
                                         f"collisions of agents {last[0]} and {last[1]} "
                                         "failed", last[1] if last else None)


class _Node(NamedTuple):
    """A constraint-tree node, as a heap entry ordered by its first three fields.

    Attributes:
      bound: a lower bound of the sum of costs below it: at least its parent's bound and
        ``cost``, and, once ``informed``, with ``wdg`` at least ``cost`` plus the heuristic.
      colliding_pairs: how many pairs of agents collide.
      order: its creation number, the oldest first at equal bound and pairs.
      cost: the sum of costs of its paths.
      paths: per agent, its node list i32[T_a].
      constraints: per agent, its :class:`~jaxswarm.multiagent.constraints.Constraints`.
      collisions: i32[A, A] as :func:`pair_collisions` gives them for ``paths``.
      padded: i32[A, T] ``paths`` padded (each resting at its goal after its end).
      classes: ``(a, b)``: ``(class, kind, step)`` of the collision of agents a < b to
        split on first (:meth:`_Instance.ranked`), filled as ``prioritize`` needs them; a
        child keeps those of the pairs without its re-planned agent.
      informed: whether ``bound`` holds the heuristic (with ``wdg``; computed when the node
        first reaches the top of the frontier).
    """

    bound: int
    colliding_pairs: int
    order: int
    cost: int
    paths: list
    constraints: list
    collisions: np.ndarray
    padded: np.ndarray
    classes: dict
    informed: bool = False


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
      weights: the dependency weights found, by the pair and its two agents' constraints.
      searched: the paths found without an avoidance table (the two-agent problems' searches),
        by the agent and its constraints: sibling nodes pose the same ones again.
    """

    graph: Graph
    start_nodes: np.ndarray
    goal_nodes: np.ndarray
    fields: np.ndarray
    max_expansions: int
    began: float
    counts: dict = dataclasses.field(
        default_factory=lambda: {"expanded": 0, "nodes": 0, "bypasses": 0, "mdds": 0,
                                 "pairs": 0, "corridors": 0, "rectangles": 0,
                                 "lower_bound": 0})
    mdds: dict = dataclasses.field(default_factory=dict)
    name: str = "cbs"
    avoid: bool = False
    wdg: bool = False
    target: bool = False
    corridors: Corridors | None = None
    rectangles: Rectangles | None = None
    weights: dict = dataclasses.field(default_factory=dict)
    searched: dict = dataclasses.field(default_factory=dict)

    def plan_agent(self, agent: int, constraints: Constraints, others=None):
        """The agent's fewest-steps path (i32[T]) under its ``constraints``, or None; with
        ``avoid`` and ``others`` (i32[B, T] the padded paths of the other agents, or, at the
        root, of those planned so far), the one meeting the fewest of them."""
        table = (occupancy(others, self.graph.num_nodes)
                 if self.avoid and others is not None else None)
        key = (agent, constraints)
        if table is None and key in self.searched:
            return self.searched[key]
        path, expanded, _ = search(self.graph, int(self.start_nodes[agent]),
                                   int(self.goal_nodes[agent]), self.fields[agent],
                                   reservations(self.graph.num_nodes, constraints),
                                   max_expansions=self.max_expansions, avoid=table)
        self.counts["expanded"] += expanded
        if table is None:
            self.searched[key] = path
        return path

    def agent_mdd(self, agent: int, path, constraints: Constraints) -> list[frozenset]:
        """The agent's MDD at its path's cost under its constraints (cached)."""
        key = (agent, len(path) - 1, constraints)
        levels = self.mdds.get(key)
        if levels is None:
            arrays = edge_arrays(self.graph)
            levels = self.mdds[key] = mdd.mdd(
                arrays.indptr, arrays.heads, int(self.start_nodes[agent]),
                int(self.goal_nodes[agent]), len(path) - 1, self.fields[agent],
                constraints.vertex, constraints.edge, constraints.parked)
            self.counts["mdds"] += 1
        return levels

    def prioritized_collision(self, node: "_Node") -> tuple[tuple[int, int], int] | None:
        """``((a, b), step)``: of every collision of every colliding pair, a cardinal one
        first, then a semi-cardinal one, then any; at equal class a target collision, then
        a corridor one (:meth:`ranked`), then, with ``wdg``, that of the pair of the largest
        dependency weight, then the earliest (then the lowest pair); None when none
        collides."""
        pairs = _colliding_pairs(node.collisions)
        if not pairs:
            return None
        for a, b in pairs:
            if (a, b) not in node.classes:
                node.classes[a, b] = min(self.ranked(node, a, b, step)
                                         for step in pair_collision_steps(node.padded, a, b))
        # At equal class and kind, the pair of the largest dependency weight: the heuristic
        # found it the costliest to resolve (jaxswarm's tie-break; CBSH2-RTC draws at random).
        weight = ((lambda a, b: self.pair_weight(node, a, b)) if self.wdg
                  else (lambda a, b: 0))
        best = min((*node.classes[a, b][:2], -weight(a, b), node.classes[a, b][2], a, b)
                   for a, b in pairs)
        return (best[4], best[5]), best[3]

    def ranked(self, node: "_Node", a: int, b: int, step: int) -> tuple[int, int, int]:
        """``(class, kind, step)`` of the collision of agents ``a`` and ``b`` arriving at
        ``step``: its :func:`mdd.classify` class, and its kind, 0 where one of them rests on
        its goal (with ``target``), 1 where a corridor split resolves it (with ``corridor``),
        else 2 (CBSH2-RTC's order of conflict types)."""
        padded = node.padded
        swap = _swap(padded, a, b, step)
        sides = [mdd.cardinal_for(self.agent_mdd(x, node.paths[x], node.constraints[x]),
                                  int(self.goal_nodes[x]), step, int(padded[x, step]),
                                  int(padded[x, step - 1]) if swap else int(padded[x, step]))
                 for x in (a, b)]
        pair, resting_from = padded[[a, b]], self.resting_from((node.paths[a], node.paths[b]))
        if any(resting_on(pair, i, 1 - i, step, resting_from) for i in (0, 1)):
            kind = 0
        elif self.corridors is not None and self.corridors.split(
                (node.constraints[a], node.constraints[b]), (node.paths[a], node.paths[b]), step,
                pair) is not None:
            kind = 1
        else:
            kind = 2
        return mdd.classify(*sides), kind, step

    def split(self, constraints: tuple, paths: tuple, step: int) -> tuple[tuple, tuple]:
        """The two children of the collision of two agents (their ``constraints`` and node
        lists ``paths``) arriving at ``step``, each both agents' constraints, child ``i``
        re-planning agent ``i``: a corridor split, else a rectangle split, where they are on
        and apply, else :func:`~jaxswarm.multiagent.constraints.split_collision` (with target
        reasoning if on)."""
        padded = pack(list(paths))[0]
        for reasoning, count in ((self.corridors, "corridors"), (self.rectangles, "rectangles")):
            both = reasoning.split(constraints, paths, step, padded) if reasoning else None
            if both is not None:
                self.counts[count] += 1
                return (both[0], constraints[1]), (constraints[0], both[1])
        return split_collision(constraints, padded, step, self.resting_from(paths))

    def resting_from(self, paths: tuple) -> np.ndarray | None:
        """With ``target``, i32[2] the steps from which two agents' node lists ``paths`` rest
        at their goals (their lengths - 1), as target reasoning takes them; else None."""
        return np.array([len(path) - 1 for path in paths]) if self.target else None

    def bounded(self, node: "_Node") -> "_Node":
        """``node`` informed: with ``wdg``, its bound raised to its cost plus the vertex cover
        of its colliding pairs' dependency weights where that is larger."""
        if not self.wdg:
            return node._replace(informed=True)
        weights = {}
        for a, b in _colliding_pairs(node.collisions):
            weights[a, b] = self.pair_weight(node, a, b)
        return node._replace(bound=max(node.bound, node.cost + dependency.vertex_cover(weights)),
                             informed=True)

    def pair_weight(self, node: "_Node", a: int, b: int) -> int:
        """The dependency weight of agents ``a`` and ``b`` under ``node``'s constraints
        (cached by the constraints)."""
        key = (a, b, node.constraints[a], node.constraints[b])
        if key not in self.weights:
            self.counts["pairs"] += 1
            self.weights[key] = dependency.pair_extra_cost(
                (node.paths[a], node.paths[b]), (node.constraints[a], node.constraints[b]),
                lambda i, constraints: self.plan_agent((a, b)[i], constraints),
                self.split)
        return self.weights[key]

    def stop(self, paths, solved: bool, reason: str = "", agent=None) -> Plan:
        """The search's :class:`~jaxswarm.multiagent.plan.Plan` of ``paths`` (one node list
        per agent)."""
        return Plan(*pack(paths, self.goal_nodes), solved=solved, planner=self.name, reason=reason,
                    agent=agent,
                    stats={**self.counts, "seconds": time.perf_counter() - self.began})


def _name(prioritize: bool, bypass: bool, avoid: bool, wdg: bool, target: bool,
          corridor: bool, rectangle: bool) -> str:
    """The planner's name in a Plan: ``icbs`` with the first three switches, ``cbsh`` with
    ``wdg`` too, then ``_`` and ``r``, ``t``, ``c`` for the symmetry reasoning on top (as Li et
    al. name the variants of CBSH2: ``cbsh_rtc``), ``cbs`` and ``+name`` per switch
    otherwise."""
    if prioritize and bypass and avoid and not (target or corridor or rectangle or wdg):
        return "icbs"
    if prioritize and bypass and avoid and wdg:
        reasoning = "r" * rectangle + "t" * target + "c" * corridor
        return "cbsh" + (f"_{reasoning}" if reasoning else "")
    return "cbs" + "".join(f"+{name}" for name, on in (
        ("prioritize", prioritize), ("bypass", bypass), ("avoid", avoid), ("wdg", wdg),
        ("target", target), ("corridor", corridor), ("rectangle", rectangle)) if on)


def _colliding_pairs(collisions: np.ndarray) -> list[list[int]]:
    """The pairs ``[a, b]`` (a < b) that collide, from ``collisions`` i32[A, A]
    (:func:`pair_collisions`)."""
    return np.argwhere(np.triu(collisions >= 0, 1)).tolist()


def _swap(padded: np.ndarray, a: int, b: int, step: int) -> bool:
    """Whether agents ``a`` and ``b`` of ``padded`` (i32[A, T]) collide at ``step`` by
    swapping rather than on one node."""
    return bool(padded[a, step] != padded[b, step])


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
    children = []
    splits = instance.split(tuple(node.constraints[a] for a in pair),
                            tuple(node.paths[a] for a in pair), step)
    for i, (agent, both) in enumerate(zip(pair, splits)):
        path = instance.plan_agent(agent, both[i], others=np.delete(node.padded, agent, axis=0))
        if path is not None:
            children.append(_child(node, agent, path, dict(zip(pair, both)), next(tiebreak)))
    return children


def _root(instance: _Instance, agents: int, order: int) -> _Node:
    """The constraint tree's root: every agent's path without constraints (with ``avoid``,
    meeting the fewest of those planned before it)."""
    no_constraints = [Constraints()] * agents
    paths = []
    for a in range(agents):
        paths.append(instance.plan_agent(a, no_constraints[a],
                                         others=pack(paths)[0] if paths else None))
    padded = pack(paths)[0]
    return _node(paths, no_constraints, pair_collisions(padded), padded, {}, order)


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
    return [_child(node, agent, taken.paths[agent], {agent: node.constraints[agent]},
                   next(tiebreak))]


def _child(node: _Node, agent: int, path, constraints: dict, order: int) -> _Node:
    """``node`` with ``agent`` on ``path`` (i32[T]) and the agents of ``constraints`` (agent:
    :class:`Constraints`) under theirs (the other agents' paths keep them)."""
    paths = list(node.paths)
    paths[agent] = path
    all_constraints = list(node.constraints)
    for other, held in constraints.items():
        all_constraints[other] = held
    steps = node.padded.shape[1]
    padded = np.empty((len(paths), max(steps, len(path))), np.int32)
    padded[:, :steps] = node.padded
    padded[:, steps:] = node.padded[:, -1:]
    padded[agent, :len(path)] = path
    padded[agent, len(path):] = path[-1]
    # Only the re-planned agent's collisions change.
    collisions = node.collisions.copy()
    changed = pair_collisions(padded, [agent])[0]
    collisions[agent, :] = changed
    collisions[:, agent] = changed
    classes = {pair: kind for pair, kind in node.classes.items() if agent not in pair}
    return _node(paths, all_constraints, collisions, padded, classes, order)


def _node(paths, constraints, collisions: np.ndarray, padded: np.ndarray, classes: dict,
          order: int) -> _Node:
    """The node of ``paths`` (node lists; ``padded`` i32[A, T]), ``constraints``, their
    ``collisions`` i32[A, A] (as :func:`pair_collisions` gives them) and the ``classes`` of
    those already known, made ``order``-th."""
    cost = sum(len(path) - 1 for path in paths)
    return _Node(cost, int((collisions >= 0).sum()) // 2, order, cost, paths, constraints,
                 collisions, padded, classes)
