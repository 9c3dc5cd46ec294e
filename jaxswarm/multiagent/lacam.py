"""LaCAM: lazy constraint addition search over configurations (Okumura, AAAI 2023), and LaCAM*'s
anytime refinement (Okumura, IJCAI 2023).

A *configuration* is every agent's node at one step. The high level is a depth-first search over
configurations; each configuration's successors are made lazily by PIBT
(:mod:`jaxswarm.multiagent.pibt`) under *constraints*: a constraint tree per configuration whose
node at depth d fixes the next nodes of the first d agents (in the configuration's priority
order), and whose children are the d + 1-th agent's candidate nodes (its neighbours and its own,
in a keyed random order). Each time a configuration is visited, the next node of its tree is
taken, its constraints given to PIBT, and the resulting configuration pushed (or, if seen before,
pushed again). Since every tree enumerates every combination of moves in the end, the search
visits every configuration reachable from the starts: LaCAM is complete, and says "no solution"
only after it has explored them all.

LaCAM* (``refine``) keeps searching after the first solution, for a time budget: every
configuration keeps its neighbours and its cost from the starts, where one step costs the number
of agents not resting at their goals through it (the "sum of loss"); a configuration reached
again by a cheaper way passes the saving on to everything found from it (a Dijkstra update), and
configurations that cannot beat the best solution found are dropped. When the search runs out,
the solution is optimal in that cost (``stats["optimal"]``). LaCAM*'s other change, its
successor generator (``swap``: PIBT with the swap operation, which lets two agents meeting head
on in a corridor trade places where it widens), is a switch of its own.
"""
from __future__ import annotations

import collections
import dataclasses
import heapq
import time

import numpy as np

from jaxswarm.multiagent.agents import agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.pibt import (Moves, Workspace, by_priority, configuration,
                                      initial_priorities, next_priorities)
from jaxswarm.multiagent.plan import Plan, arrival_steps
from jaxswarm.world.graph import Graph


@dataclasses.dataclass
class _Constraint:
    """A node of a configuration's constraint tree: the next nodes of the first ``depth``
    agents of the configuration's order (``who[k]`` goes to ``where[k]``)."""

    who: tuple
    where: tuple

    @property
    def depth(self) -> int:
        return len(self.who)


@dataclasses.dataclass(eq=False)
class _Configuration:
    """A high-level node: a configuration, how it was reached and its constraint tree."""

    nodes: np.ndarray
    parent: "_Configuration | None"
    priorities: np.ndarray
    order: np.ndarray
    cost: int
    bound: int
    tree: collections.deque
    neighbours: list = dataclasses.field(default_factory=list)


def lacam(graph: Graph, starts, goals, *, time_limit: float = 60.0, refine: float = 0.0,
          swap: bool = False, max_configurations: int = 10_000_000, seed: int = 0) -> Plan:
    """LaCAM, and with ``refine`` and ``swap`` LaCAM*.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      time_limit: give up after this many seconds without a solution (distance fields
        included).
      refine: LaCAM*: after the first solution, keep lowering its sum of loss for this many
        more seconds (0: return the first solution).
      swap: LaCAM*'s successor generator: PIBT with the swap operation
        (:func:`~jaxswarm.multiagent.pibt.configuration`), for corridors.
      max_configurations: give up after this many configurations.
      seed: the key of PIBT's tie-breaks and of the constraint trees' order.

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner``: ``lacam``, or ``lacam_star``
      with ``swap``). Not solved when an
      agent's goal cannot be reached (naming it), when every configuration reachable from the
      starts was explored without reaching the goals (a proof that there is no solution), or at
      a limit. ``stats``: ``configurations`` (high-level nodes), ``field_seconds`` (the distance
      fields), ``seconds`` (the search), ``first_soc`` and ``optimal`` (with ``refine``).

    Raises:
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`) or limit.
    """
    if time_limit <= 0 or refine < 0 or max_configurations < 1:
        raise ValueError("time_limit must be positive, refine at least 0 and max_configurations "
                         f"at least 1; got {time_limit}, {refine}, {max_configurations}")
    name = "lacam_star" if swap else "lacam"
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    fields = hop_fields(graph, goal_nodes)
    stats = dict(field_seconds=time.perf_counter() - began)
    waiting = (start_nodes[:, None], np.zeros(len(start_nodes), np.int32))
    blocked = cut_off(graph, fields, start_nodes, goal_nodes)
    if blocked is not None:
        return Plan(*waiting, solved=False, planner=name, reason=blocked[1], agent=blocked[0],
                    stats=dict(stats, configurations=0, seconds=0.0))
    search = _Search(Moves.build(graph, goal_nodes, fields), seed, swap)
    found, why = search.run(start_nodes, deadline=began + time_limit, refine=refine,
                            max_configurations=max_configurations)
    stats |= search.stats(refine > 0)
    if found is None:
        return Plan(*waiting, solved=False, planner=name, reason=why, stats=stats)
    paths = np.stack(found, axis=1)
    return Plan(paths, arrival_steps(paths, goal_nodes), solved=True, planner=name,
                stats=stats)


class _Search:
    """One LaCAM (or LaCAM*) search over an instance's configurations."""

    def __init__(self, moves: Moves, seed: int, swap: bool):
        self.moves = moves
        self.swap = swap
        self.work = Workspace(moves, seed)
        self.rng = np.random.default_rng(seed)
        self.explored: dict[bytes, _Configuration] = {}
        self.began = time.perf_counter()
        self.first_soc: int | None = None
        self.optimal = False

    def stats(self, refining: bool) -> dict:
        """The search's statistics (see :func:`lacam`)."""
        out = dict(configurations=len(self.explored),
                   seconds=time.perf_counter() - self.began)
        if refining and self.first_soc is not None:
            out |= dict(first_soc=self.first_soc, optimal=self.optimal)
        return out

    def run(self, starts: np.ndarray, *, deadline: float, refine: float,
            max_configurations: int) -> tuple[list | None, str]:
        """``(configurations from the starts to the goals, "")``, or ``(None, why not)``."""
        goals = self.moves.goals
        priorities = initial_priorities(self.moves, starts)
        root = self._add(starts, None, priorities)
        open_ = [root]
        goal: _Configuration | None = None
        while open_:
            if time.perf_counter() > deadline or len(self.explored) >= max_configurations:
                break
            node = open_[-1]
            if goal is not None and node.cost + node.bound >= goal.cost:
                open_.pop()
                continue
            if goal is None and np.array_equal(node.nodes, goals):
                goal = node
                self.first_soc = _soc(_backtrack(goal), goals)
                if refine <= 0:
                    return _backtrack(goal), ""
                deadline = time.perf_counter() + refine
                continue
            if not node.tree:
                open_.pop()
                continue
            constraint = node.tree.popleft()
            if constraint.depth < len(node.nodes):
                self._grow(node, constraint)
            following = self._successor(node, constraint)
            if following is None:
                continue
            known = self.explored.get(following.tobytes())
            if known is None:
                child = self._add(following, node,
                                  next_priorities(node.priorities, following == goals))
                node.neighbours.append(child)
                open_.append(child)
                continue
            node.neighbours.append(known)
            if refine > 0:
                self._rewire(node)
            open_.append(known)
        if goal is not None:
            self.optimal = not open_
            return _backtrack(goal), ""
        if not open_:
            return None, ("no solution: every configuration reachable from the starts "
                          f"({len(self.explored)}) was explored")
        if time.perf_counter() > deadline:
            return None, f"reached the time limit after {len(self.explored)} configurations"
        return None, f"reached the limit of {max_configurations} configurations"

    def _add(self, nodes: np.ndarray, parent: _Configuration | None,
             priorities: np.ndarray) -> _Configuration:
        goals = self.moves.goals
        cost = 0 if parent is None else parent.cost + _step_cost(parent.nodes, nodes, goals)
        bound = int(self.moves.fields[np.arange(len(nodes)), nodes].sum())
        node = _Configuration(nodes=nodes, parent=parent, priorities=priorities,
                              order=by_priority(priorities), cost=cost, bound=bound,
                              tree=collections.deque([_Constraint((), ())]))
        self.explored[nodes.tobytes()] = node
        return node

    def _grow(self, node: _Configuration, constraint: _Constraint) -> None:
        """Add the children of ``constraint``: the next agent's candidates, keyed order."""
        agent = int(node.order[constraint.depth])
        here = int(node.nodes[agent])
        moves = self.moves
        options = np.append(moves.heads[moves.indptr[here]:moves.indptr[here + 1]], here)
        for v in self.rng.permutation(options).tolist():
            node.tree.append(_Constraint(constraint.who + (agent,), constraint.where + (v,)))

    def _successor(self, node: _Configuration, constraint: _Constraint) -> np.ndarray | None:
        following = np.empty_like(node.nodes)
        ok = configuration(self.moves, self.work, node.nodes, node.order,
                           np.array(constraint.who, np.int32),
                           np.array(constraint.where, np.int32), following, swap=self.swap)
        return following if ok else None

    def _rewire(self, start: _Configuration) -> None:
        """LaCAM*'s Dijkstra update from ``start`` over the known neighbours: every
        configuration reached more cheaply through it takes it as parent."""
        goals = self.moves.goals
        queue = [(start.cost, id(start), start)]
        while queue:
            cost, _, node = heapq.heappop(queue)
            if cost > node.cost:
                continue
            for other in node.neighbours:
                through = node.cost + _step_cost(node.nodes, other.nodes, goals)
                if through < other.cost:
                    other.cost, other.parent = through, node
                    heapq.heappush(queue, (through, id(other), other))


def _step_cost(before: np.ndarray, after: np.ndarray, goals: np.ndarray) -> int:
    """Agents not resting at their goals through one step (LaCAM*'s sum of loss)."""
    return int(np.count_nonzero((before != goals) | (after != goals)))


def _backtrack(node: _Configuration) -> list:
    """The configurations from the starts to ``node``."""
    out = []
    while node is not None:
        out.append(node.nodes)
        node = node.parent
    return out[::-1]


def _soc(configurations: list, goals: np.ndarray) -> int:
    return int(arrival_steps(np.stack(configurations, axis=1), goals).sum())
