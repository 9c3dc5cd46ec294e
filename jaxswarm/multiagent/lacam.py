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
of agents not resting at their goals through it (the "sum of loss");
a configuration reached again by a cheaper way passes the saving on to everything found from it
(a Dijkstra update, :mod:`jaxswarm.multiagent.explored`), and each configuration whose cost falls
below the best solution's is searched again (pushed back on the open stack, as the reference
implementation does), while configurations that cannot beat the best solution are dropped. With a
small probability a configuration generated again is replaced on the stack by the starts' (the
reference implementation's random restart). When the search runs out, no solution of a smaller
sum of loss exists (``stats["optimal"]``); the sum of costs, which also counts the steps an agent
rests at its goal before it leaves it again, may be above its least. LaCAM*'s other change,
its successor generator (``swap``: PIBT with the swap operation, which lets two agents meeting
head on in a corridor trade places where it widens), is a switch of its own.
"""
from __future__ import annotations

import collections
import dataclasses
import numbers
import time

import numpy as np

from jaxswarm.multiagent.agents import agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.explored import NONE, Explored
from jaxswarm.multiagent.limits import check_count, check_seconds
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


@dataclasses.dataclass
class _Tree:
    """A configuration's agents by priority (i32[A]) and the constraints of its tree not taken
    yet (breadth first); made when the configuration is first expanded."""

    order: np.ndarray
    constraints: collections.deque


_UNBOUNDED = np.iinfo(np.int64).max
"""The limit of the Dijkstra update before any solution is known."""


def lacam(graph: Graph, starts, goals, *, time_limit: float = 60.0, refine: float = 0.0,
          swap: bool = False, max_configurations: int = 10_000_000, seed: int = 0,
          restart_rate: float = 0.001) -> Plan:
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
      seed: the key of PIBT's tie-breaks and of the constraint trees' order (at least 0).
      restart_rate: LaCAM*'s random restarts while refining: when a known configuration is
        generated again, the starts' configuration is pushed in its place with this
        probability (the reference implementation's ``--restart_rate``, Kei18/lacam2, and its
        default), so that the search does not stay deep in one branch. The first solution is
        found without restarts, as LaCAM's.

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner``: ``lacam``, or ``lacam_star``
      with ``swap``). Not solved when an
      agent's goal cannot be reached (naming it), when every configuration reachable from the
      starts was explored without reaching the goals (a proof that there is no solution), or at
      a limit. ``stats``: ``configurations`` (high-level nodes), ``field_seconds`` (the distance
      fields), ``seconds`` (the search); with ``refine``, ``first_soc`` and
      ``first_sum_of_loss`` (the first solution's sum of costs and sum of loss),
      ``sum_of_loss`` (the solution's), ``improvements`` (``(seconds after the first
      solution, sum of loss, sum of costs)`` of every better solution, in order) and ``optimal``:
      true only when the search ran out, so that no solution of a smaller sum of loss exists.

    Raises:
      TypeError: a limit, ``seed`` or ``swap`` of the wrong type (naming it).
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`) or a
        limit out of its range (naming it).
    """
    _check_options(time_limit=time_limit, refine=refine, swap=swap,
                   max_configurations=max_configurations, seed=seed, restart_rate=restart_rate)
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
    search = _Search(Moves.build(graph, goal_nodes, fields), seed, swap, restart_rate)
    found, why = search.run(start_nodes, deadline=began + time_limit, refine=refine,
                            max_configurations=max_configurations)
    stats |= search.stats(refine > 0)
    if found is None:
        return Plan(*waiting, solved=False, planner=name, reason=why, stats=stats)
    paths = np.stack(found, axis=1)
    return Plan(paths, arrival_steps(paths, goal_nodes), solved=True, planner=name,
                stats=stats)


def _check_options(*, time_limit, refine, swap, max_configurations, seed, restart_rate):
    """Refuse, naming it, an option of :func:`lacam` of the wrong type or out of its range."""
    check_seconds("time_limit", time_limit)
    check_count("max_configurations", max_configurations)
    for name, value in (("refine", refine), ("restart_rate", restart_rate)):
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise TypeError(f"{name} must be a number, got {value!r}")
    if isinstance(seed, bool) or not isinstance(seed, numbers.Integral):
        raise TypeError(f"seed must be an integer, got {seed!r}")
    if not isinstance(swap, (bool, np.bool_)):
        raise TypeError(f"swap must be True or False, got {swap!r}")
    if not refine >= 0:
        raise ValueError(f"refine must be at least 0, got {refine}")
    if not 0 <= restart_rate <= 1:
        raise ValueError(f"restart_rate must be between 0 and 1, got {restart_rate}")
    if seed < 0:
        raise ValueError(f"seed must be at least 0, got {seed}")


class _Search:
    """One LaCAM (or LaCAM*) search over an instance's configurations."""

    def __init__(self, moves: Moves, seed: int, swap: bool, restart_rate: float):
        self.moves = moves
        self.swap = swap
        self.restart_rate = restart_rate
        self.work = Workspace(moves, seed)
        self.rng = np.random.default_rng(seed)
        self.explored = Explored(moves.goals)
        self.agents = np.arange(len(moves.goals))
        self.priorities: list[np.ndarray] = []  # f64[A] of each configuration, by id
        self.trees: list[_Tree | None] = []  # by id
        self.options: dict[int, list[int]] = {}  # by node, see _options
        self.began = time.perf_counter()
        self.first_soc: int | None = None
        self.first_loss: int | None = None
        self.loss: int | None = None
        self.improvements: list[tuple[float, int, int]] = []
        self.optimal = False

    def stats(self, refining: bool) -> dict:
        """The search's statistics (see :func:`lacam`)."""
        out = dict(configurations=self.explored.size,
                   seconds=time.perf_counter() - self.began)
        if refining and self.first_soc is not None:
            out |= dict(first_soc=self.first_soc, first_sum_of_loss=self.first_loss,
                        sum_of_loss=self.loss, improvements=self.improvements,
                        optimal=self.optimal)
        return out

    def run(self, starts: np.ndarray, *, deadline: float, refine: float,
            max_configurations: int) -> tuple[list | None, str]:
        """``(configurations from the starts to the goals, "")``, or ``(None, why not)``."""
        goals = self.moves.goals
        explored = self.explored
        root = self._add(starts, NONE, initial_priorities(self.moves, starts))
        open_ = [root]
        goal = NONE
        found_at = 0.0
        while open_:
            if time.perf_counter() > deadline or explored.size >= max_configurations:
                break
            node = open_[-1]
            if not self._promising(node, goal):
                open_.pop()
                continue
            if goal == NONE and np.array_equal(explored.nodes[node], goals):
                goal = node
                self.first_soc = _soc(explored.way(goal), goals)
                self.first_loss = int(explored.cost[goal])
                if refine <= 0:
                    return explored.way(goal), ""
                found_at = time.perf_counter()
                deadline = found_at + refine
                continue
            exhausted, following = self._next_of(node)
            if exhausted:
                open_.pop()
                continue
            if following is None:
                continue
            known = explored.find(following)
            if known == NONE:
                child = self._add(following, node,
                                  next_priorities(self.priorities[node], following == goals))
                if self._promising(child, goal):
                    open_.append(child)
                continue
            if refine > 0:
                again, known = self._rewire(node, known, goal, found_at, root)
                open_.extend(again)
            if self._promising(known, goal):
                open_.append(known)
        if goal != NONE:
            self.optimal = not open_
            self.loss = int(explored.cost[goal])
            return explored.way(goal), ""
        if not open_:
            return None, ("no solution: every configuration reachable from the starts "
                          f"({explored.size}) was explored")
        if time.perf_counter() > deadline:
            return None, f"reached the time limit after {explored.size} configurations"
        return None, f"reached the limit of {max_configurations} configurations"

    def _next_of(self, node: int) -> tuple[bool, np.ndarray | None]:
        """``(exhausted, configuration)``: the configuration that ``node``'s next constraint
        leads to (None where PIBT finds none under it), or ``exhausted`` when ``node`` has no
        constraint left; its constraint tree is made on first use."""
        tree = self.trees[node]
        if tree is None:
            tree = self.trees[node] = _Tree(by_priority(self.priorities[node]),
                                            collections.deque([_Constraint((), ())]))
        if not tree.constraints:
            return True, None
        constraint = tree.constraints.popleft()
        if constraint.depth < len(self.moves.goals):
            self._grow(node, tree, constraint)
        return False, self._successor(node, tree, constraint)

    def _rewire(self, node: int, known: int, goal: int, found_at: float,
                root: int) -> tuple[list[int], int]:
        """``(again, next)`` when the search meets ``known`` from ``node`` while refining: the
        step joins the explored graph and the Dijkstra update lowers costs through it;
        ``again`` the configurations whose cost fell below the best solution's (searched
        again), ``next`` the configuration to search on (``known``, or the starts' after a
        random restart). Records an improvement of the best solution."""
        explored = self.explored
        limit = explored.cost[goal] if goal != NONE else _UNBOUNDED
        again = explored.connect(node, known, limit)
        if goal == NONE:
            return [], known
        if explored.cost[goal] < limit:
            self.improvements.append((time.perf_counter() - found_at, int(explored.cost[goal]),
                                      _soc(explored.way(goal), self.moves.goals)))
        if self.rng.random() < self.restart_rate:
            known = root
        return again.tolist(), known

    def _promising(self, node: int, goal: int) -> bool:
        """Whether ``node`` may still lead to a solution cheaper than ``goal``'s (always, while
        no solution is known)."""
        explored = self.explored
        return goal == NONE or explored.cost[node] + explored.bound[node] < explored.cost[goal]

    def _add(self, nodes: np.ndarray, parent: int, priorities: np.ndarray) -> int:
        self.priorities.append(priorities)
        self.trees.append(None)
        return self.explored.add(nodes, parent, int(self.moves.fields[self.agents, nodes].sum()))

    def _grow(self, node: int, tree: "_Tree", constraint: _Constraint) -> None:
        """Add the children of ``constraint``: the next agent's candidates, keyed order."""
        agent = int(tree.order[constraint.depth])
        options = list(self._options(int(self.explored.nodes[node, agent])))
        self.rng.shuffle(options)
        who = constraint.who + (agent,)
        for v in options:
            tree.constraints.append(_Constraint(who, constraint.where + (v,)))

    def _options(self, here: int) -> list[int]:
        """The nodes an agent on ``here`` may go to next: its neighbours, then ``here``."""
        options = self.options.get(here)
        if options is None:
            moves = self.moves
            options = self.options[here] = (
                moves.heads[moves.indptr[here]:moves.indptr[here + 1]].tolist() + [here])
        return options

    def _successor(self, node: int, tree: "_Tree",
                   constraint: _Constraint) -> np.ndarray | None:
        current = self.explored.nodes[node]
        following = np.empty_like(current)
        ok = configuration(self.moves, self.work, current, tree.order,
                           np.array(constraint.who, np.int32),
                           np.array(constraint.where, np.int32), following, swap=self.swap)
        return following if ok else None


def _soc(configurations: list, goals: np.ndarray) -> int:
    return int(arrival_steps(np.stack(configurations, axis=1), goals).sum())
