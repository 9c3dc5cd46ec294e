"""Enhanced CBS (Barer, Sharon, Stern and Felner, SoCS 2014): bounded-suboptimal, within a factor
w of the least sum of costs; and Explicit Estimation CBS (Li, Ruml and Koenig, AAAI 2021).

Both levels of :func:`ecbs` are focal searches: the low level plans one agent under its CBS
constraints, preferring among the states within w of the least f the path that collides least,
and returns a lower bound on the agent's cost; the high level splits, among the nodes within w
of the least sum of those bounds (LB), the one with the fewest colliding pairs. The first node
without collisions costs at most w times the least LB, itself at most the optimum
(``stats["lower_bound"]``). :func:`eecbs` keeps the low level and replaces the high level's
focal list by explicit estimation search (Thayer and Ruml, IJCAI 2011) with errors learnt online,
without the CBS improvements its paper adds. ``docs/papers.md`` details both levels.
"""
from __future__ import annotations

import dataclasses
import heapq
import itertools
import time

import numpy as np

from jaxswarm.multiagent.agents import UNREACHABLE, agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.conflicts import pair_collisions
from jaxswarm.multiagent.constraints import Constraints, earliest_collision, forbid
from jaxswarm.multiagent.limits import check_count, check_number, check_seconds
from jaxswarm.multiagent.plan import Plan, pack
from jaxswarm.multiagent.spacetime import occupancy
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import Graph


@dataclasses.dataclass(frozen=True)
class ECBSConfig:
    """The options of :func:`ecbs` and :func:`eecbs`, checked when made.

    Attributes:
      w: the bound: the sum of costs is at most w times the optimum (at least 1).
      max_nodes: give up after splitting this many constraint-tree nodes (at least 1).
      time_limit: give up after this many seconds (positive).

    Raises:
      TypeError, ValueError: a ``w`` that is not a number of at least 1, a ``time_limit`` that
        is not a positive number or a ``max_nodes`` that is not a whole number of at least 1,
        naming it.
    """

    w: float = 1.2
    max_nodes: int = 100_000
    time_limit: float = 60.0

    def __post_init__(self):
        check_number("w", self.w, least=1)
        check_seconds("time_limit", self.time_limit)
        check_count("max_nodes", self.max_nodes)


def ecbs(graph: Graph, starts, goals, **options) -> Plan:
    """Enhanced CBS with suboptimality bound ``w`` (the arguments and result of
    :func:`eecbs`, ``planner="ecbs"``)."""
    return _bounded(graph, starts, goals, ECBSConfig(**options), explicit=False)


def eecbs(graph: Graph, starts, goals, **options) -> Plan:
    """Explicit Estimation CBS with suboptimality bound ``w``.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      **options: those of :class:`~jaxswarm.multiagent.ecbs.ECBSConfig` (``w``, ``max_nodes``,
        ``time_limit``).

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner="eecbs"``); not solved when an
      agent's goal cannot be reached (naming it) or at a limit. ``stats``: ``lower_bound`` (the
      least LB open when it stopped: no solution costs less), ``w``, ``nodes``, ``expanded``,
      ``cost_error`` and ``collision_error`` (e_h and e_d as learnt), ``seconds``.

    Raises:
      TypeError, ValueError: a bad option (see :class:`~jaxswarm.multiagent.ecbs.ECBSConfig`),
        naming it, before any search.
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`).
    """
    return _bounded(graph, starts, goals, ECBSConfig(**options), explicit=True)


def _bounded(graph: Graph, starts, goals, config: ECBSConfig, *, explicit: bool) -> Plan:
    """ECBS, or with ``explicit`` EECBS (see :func:`eecbs`)."""
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    search = _Search(graph, start_nodes, goal_nodes, hop_fields(graph, goal_nodes), config.w,
                     began, explicit)
    blocked = cut_off(graph, search.fields, start_nodes, goal_nodes)
    if blocked is not None:
        return search.stop([np.array([s]) for s in start_nodes], False, blocked[1], blocked[0])
    return search.run(config.max_nodes, config.time_limit)


@dataclasses.dataclass(eq=False)
class _Node:
    """A constraint-tree node: per agent its path, its cost's lower bound and its constraints
    (``(vertex, edge)`` as CBS's), and the pairs' first collisions."""

    paths: list
    bounds: list
    constraints: list
    collisions: np.ndarray

    @property
    def cost(self) -> int:
        return sum(len(path) - 1 for path in self.paths)

    @property
    def lower_bound(self) -> int:
        return sum(self.bounds)

    @property
    def colliding_pairs(self) -> int:
        return int((self.collisions >= 0).sum()) // 2


class _Search:
    """One ECBS or EECBS search (see the module docstring)."""

    def __init__(self, graph, start_nodes, goal_nodes, fields, w: float, began: float,
                 explicit: bool):
        arrays = edge_arrays(graph)
        self.moves = [arrays.heads[arrays.indptr[u]:arrays.indptr[u + 1]].tolist() + [u]
                      for u in range(graph.num_nodes)]
        self.graph, self.starts, self.goals = graph, start_nodes, goal_nodes
        self.fields, self.w, self.began = fields, w, began
        self.counts = {"expanded": 0, "nodes": 0, "lower_bound": 0, "w": w}
        self.explicit = explicit
        if explicit:
            self.counts.update(cost_error=0.0, collision_error=0.0)
        self.errors = [0.0, 0.0, 0]  # the one-step errors' sums (cost, collisions), expansions

    def run(self, max_nodes: int, time_limit: float) -> Plan:
        agents = len(self.starts)
        constraints = [Constraints()] * agents
        paths, bounds = [], []
        for a in range(agents):
            path, bound = self.plan_agent(a, constraints[a], paths)
            paths.append(path)
            bounds.append(bound)
        root = _Node(paths, bounds, constraints, pair_collisions(pack(paths)[0]))
        open_ = [root]
        last = None
        while open_:
            node = self.choose(open_)
            collision = earliest_collision(node.collisions)
            if collision is None:
                return self.stop(node.paths, True)
            last, step = collision
            if self.counts["nodes"] >= max_nodes or time.perf_counter() - self.began > time_limit:
                limit = (f"{max_nodes} nodes" if self.counts["nodes"] >= max_nodes
                         else f"the time limit ({time_limit:g} s)")
                return self.stop(node.paths, False, f"reached {limit} while resolving a "
                                 f"collision of agents {last[0]} and {last[1]}", last[1])
            open_.remove(node)
            self.counts["nodes"] += 1
            children = self.children(node, last, step)
            if self.explicit and children:
                self.learn(node, children)
            open_ += children
        return self.stop(root.paths, False, "no solution exists: every way of resolving the "
                         f"collisions of agents {last[0]} and {last[1]} failed", last[1])

    def choose(self, open_: list[_Node]) -> _Node:
        """The node to split next (ECBS's focal choice, or EECBS's, see the module docstring);
        records the least LB open."""
        least = min(node.lower_bound for node in open_)
        self.counts["lower_bound"] = least
        if not self.explicit:
            return min((n for n in open_ if n.cost <= self.w * least),
                       key=lambda n: (n.colliding_pairs, n.cost))
        cost_error, collision_error = self.counts["cost_error"], self.counts["collision_error"]
        left = {id(n): n.colliding_pairs / (1.0 - collision_error) for n in open_}
        estimate = {id(n): n.cost + cost_error * left[id(n)] for n in open_}
        best = min(open_, key=lambda n: (estimate[id(n)], left[id(n)]))
        focal = min((n for n in open_ if estimate[id(n)] <= self.w * estimate[id(best)]),
                    key=lambda n: (left[id(n)], estimate[id(n)]))
        for candidate in (focal, best):
            if candidate.cost <= self.w * least:
                return candidate
        return min(open_, key=lambda n: (n.lower_bound, n.cost))

    def learn(self, node: _Node, children: list[_Node]) -> None:
        """Add the one-step errors of an expansion, from its child with the fewest colliding
        pairs: the cost it adds, and the pairs beyond one fewer; update e_h and e_d, their
        means (e_h at least 0, e_d in [0, 0.99])."""
        child = min(children, key=lambda n: (n.colliding_pairs, n.cost))
        self.errors[0] += child.cost - node.cost
        self.errors[1] += child.colliding_pairs - (node.colliding_pairs - 1)
        self.errors[2] += 1
        self.counts["cost_error"] = max(0.0, self.errors[0] / self.errors[2])
        self.counts["collision_error"] = min(0.99, max(0.0, self.errors[1] / self.errors[2]))

    def children(self, node: _Node, pair: tuple[int, int], step: int) -> list[_Node]:
        """One child per agent of the colliding ``pair``: the collision forbidden to it, the
        agent re-planned (none where it then has no path)."""
        padded = pack(node.paths)[0]
        out = []
        for agent, other in (pair, pair[::-1]):
            constraints = forbid(node.constraints[agent], padded, agent, other, step)
            found = self.plan_agent(agent, constraints, node.paths)
            if found is None:
                continue
            paths, bounds, all_constraints = list(node.paths), list(node.bounds), \
                list(node.constraints)
            paths[agent], bounds[agent] = found
            all_constraints[agent] = constraints
            collisions = node.collisions.copy()
            changed = pair_collisions(pack(paths)[0], [agent])[0]
            collisions[agent, :] = collisions[:, agent] = changed
            out.append(_Node(paths, bounds, all_constraints, collisions))
        return out

    def plan_agent(self, agent: int, constraints: Constraints, paths: list):
        """``(path i32[T], lower bound on its cost)`` of the low-level focal search, or None."""
        vertex, edge = constraints.vertex, constraints.edge
        others = [path for a, path in enumerate(paths) if a != agent]
        occupied = occupancy(pack(others)[0] if others else np.zeros((0, 1), np.int32),
                             self.graph.num_nodes)
        horizon = max([t + 1 for t, _ in vertex] + [t + 1 for t, _, _ in edge]
                      + [len(occupied)])
        goal, field = int(self.goals[agent]), self.fields[agent]
        keep_from = max([t + 1 for t, v in vertex if v == goal] + [0])
        return _focal_search(self.moves, int(self.starts[agent]), goal, field, vertex, edge,
                             occupied, horizon + self.graph.num_nodes, keep_from, self.w,
                             self.counts)

    def stop(self, paths, solved: bool, reason: str = "", agent=None) -> Plan:
        return Plan(*pack(paths, self.goals), solved=solved,
                    planner="eecbs" if self.explicit else "ecbs", reason=reason,
                    agent=agent,
                    stats={**self.counts, "seconds": time.perf_counter() - self.began})


def _focal_search(moves, start, goal, field, vertex, edge, occupied, limit, keep_from, w,
                  counts):
    """The low level: the focal search of the module docstring over ``(node, step)``; a state
    past the other paths' last step sees them resting. ``(path, least f)`` or None."""
    last = len(occupied) - 1
    tiebreak = itertools.count()
    h0 = int(field[start])
    best = {(start, 0): 0}  # state -> least collisions of a path to it; -1 once expanded
    parent = {(start, 0): None}
    by_f = {h0: [(start, 0)]}  # f -> the states generated with it (f = step + steps to go)
    open_count = {h0: 1}
    f_heap = [h0]
    focal = [(0, h0, 0, next(tiebreak), start)]
    bound = w * h0
    while focal:
        conflicts, f, back, _, v = heapq.heappop(focal)
        t = -back
        state = (v, t)
        if best[state] != conflicts:
            continue  # expanded already, or reached with fewer collisions since
        best[state] = -1
        open_count[f] -= 1
        counts["expanded"] += 1
        least = _least_open(f_heap, open_count)
        if v == goal and t >= keep_from:
            return _path(parent, state), f if least is None else min(least, f)
        if t < limit:
            for u in moves[v]:
                if (t + 1, u) in vertex or (t, v, u) in edge or field[u] >= UNREACHABLE:
                    continue
                g = t + 1 + int(field[u])
                c = conflicts + int(occupied[min(t + 1, last)][u])
                known = best.get((u, t + 1))
                if known is not None and (known < 0 or known <= c):
                    continue
                best[(u, t + 1)], parent[(u, t + 1)] = c, state
                if known is None:
                    if not open_count.get(g):  # (a value dropped from the heap comes back)
                        heapq.heappush(f_heap, g)
                    open_count[g] = open_count.get(g, 0) + 1
                    by_f.setdefault(g, []).append((u, t + 1))
                if g <= bound:
                    heapq.heappush(focal, (c, g, -(t + 1), next(tiebreak), u))
            least = _least_open(f_heap, open_count)
        if least is not None and w * least > bound:  # states newly within the bound
            for g in sorted(by_f):
                if bound < g <= w * least:
                    focal += [(best[s], g, -s[1], next(tiebreak), s[0]) for s in by_f[g]
                              if best[s] >= 0]
            heapq.heapify(focal)
            bound = w * least
    return None


def _least_open(f_heap: list, open_count: dict) -> int | None:
    """The least f of an open state (dropping the f values with none open left)."""
    while f_heap and open_count[f_heap[0]] == 0:
        heapq.heappop(f_heap)
    return f_heap[0] if f_heap else None


def _path(parent: dict, state) -> np.ndarray:
    out = []
    while state is not None:
        out.append(state[0])
        state = parent[state]
    return np.array(out[::-1], np.int32)
