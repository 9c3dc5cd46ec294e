"""LaCAM: lazy constraint addition search over configurations (Okumura, AAAI 2023), and LaCAM*'s
anytime refinement (Okumura, IJCAI 2023).

A *configuration* is every agent's node at one step. :func:`lacam` searches configurations depth
first, each one's successors made lazily by PIBT (:mod:`jaxswarm.multiagent.pibt`) under the
constraints its constraint tree enumerates; it is complete, saying "no solution" only after
every configuration reachable from the starts. ``refine`` (LaCAM*) keeps lowering the solution's
sum of loss (the steps of agents not resting at their goals) for a time budget, by Dijkstra
updates over the configurations found and random restarts; ``swap`` is LaCAM*'s successor
generator, PIBT with the swap operation. The search loop runs compiled (numba), a few hundred
steps a call over the arrays of :mod:`~jaxswarm.multiagent.explored` (the configurations) and
:mod:`~jaxswarm.multiagent.constraint_trees` (the trees), drawing from one NumPy ``Generator``
seeded with ``seed``; between calls Python checks the time, grows the arrays and records the
solutions. ``docs/papers.md`` explains the trees and the refinement.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from jaxswarm.exact.kernels import inline, jit
from jaxswarm.multiagent.agents import agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.constraint_trees import ConstraintTrees, gather, plant, take
from jaxswarm.multiagent.explored import NONE, Explored, add, connect, find, grown, spare
from jaxswarm.multiagent.limits import check_count, check_number, check_seconds, check_switch
from jaxswarm.multiagent.pibt import (Moves, Workspace, compiled_configuration, initial_priorities,
                                      next_priorities)
from jaxswarm.multiagent.plan import Plan, arrival_steps
from jaxswarm.world.graph import Graph


_UNBOUNDED = np.iinfo(np.int64).max
"""The limit of the Dijkstra update before any solution is known."""


@dataclasses.dataclass(frozen=True)
class LaCAMConfig:
    """The options of :func:`lacam`, checked when made.

    Attributes:
      time_limit: give up after this many seconds without a solution (distance fields
        included).
      refine: LaCAM*: after the first solution, keep lowering its sum of loss for this many
        more seconds (0: return the first solution).
      swap: LaCAM*'s successor generator: PIBT with the swap operation
        (:func:`~jaxswarm.multiagent.pibt.configuration`), for corridors.
      max_configurations: give up after this many configurations (at least 1).
      seed: the key of PIBT's tie-breaks and of the constraint trees' order (at least 0).
      restart_rate: LaCAM*'s random restarts while refining: when a known configuration is
        generated again, the starts' configuration is pushed in its place with this
        probability (the reference implementation's ``--restart_rate``, Kei18/lacam2, and its
        default), so that the search does not stay deep in one branch. The first solution is
        found without restarts, as LaCAM's.

    Raises:
      TypeError: a limit, ``seed`` or ``swap`` of the wrong type (naming it).
      ValueError: a limit out of its range (naming it).
    """

    time_limit: float = 60.0
    refine: float = 0.0
    swap: bool = False
    max_configurations: int = 10_000_000
    seed: int = 0
    restart_rate: float = 0.001

    def __post_init__(self):
        check_seconds("time_limit", self.time_limit)
        check_count("max_configurations", self.max_configurations)
        check_number("refine", self.refine, least=0)
        check_number("restart_rate", self.restart_rate, least=0, most=1)
        check_count("seed", self.seed, least=0)
        check_switch("swap", self.swap)


def lacam(graph: Graph, starts, goals, **options) -> Plan:
    """LaCAM, and with ``refine`` and ``swap`` LaCAM*.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      **options: those of :class:`~jaxswarm.multiagent.lacam.LaCAMConfig` (limits, ``refine``,
        ``swap``, ``seed``, ``restart_rate``).

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
      TypeError, ValueError: a bad option (see :class:`~jaxswarm.multiagent.lacam.LaCAMConfig`),
        naming it, before any search.
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`).
    """
    config = LaCAMConfig(**options)
    name = "lacam_star" if config.swap else "lacam"
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    fields = hop_fields(graph, goal_nodes)
    stats = dict(field_seconds=time.perf_counter() - began)
    waiting = (start_nodes[:, None], np.zeros(len(start_nodes), np.int32))
    blocked = cut_off(graph, fields, start_nodes, goal_nodes)
    if blocked is not None:
        return Plan(*waiting, solved=False, planner=name, reason=blocked[1], agent=blocked[0],
                    stats=dict(stats, configurations=0, seconds=0.0))
    search = _Search(Moves.build(graph, goal_nodes, fields), config.seed, config.swap,
                     config.restart_rate)
    found, why = search.run(start_nodes, deadline=began + config.time_limit,
                            refine=config.refine,
                            max_configurations=config.max_configurations)
    stats |= search.stats(config.refine > 0)
    if found is None:
        return Plan(*waiting, solved=False, planner=name, reason=why, stats=stats)
    paths = np.stack(found, axis=1)
    return Plan(paths, arrival_steps(paths, goal_nodes), solved=True, planner=name,
                stats=stats)


class _Search:
    """One LaCAM (or LaCAM*) search over an instance's configurations: the stores of
    :mod:`~jaxswarm.multiagent.explored` and :mod:`~jaxswarm.multiagent.constraint_trees`, each
    configuration's priorities and tree, and the open stack, which :func:`_steps` works on."""

    def __init__(self, moves: Moves, seed: int, swap: bool, restart_rate: float):
        agents = len(moves.goals)
        self.moves = moves
        self.swap = swap
        self.restart_rate = restart_rate
        self.work = Workspace(moves, seed)
        self.rng = np.random.default_rng(seed)
        self.explored = Explored(moves.goals)
        self.trees = ConstraintTrees(agents)
        capacity = len(self.explored.cost)
        self.priorities = np.empty((capacity, agents))  # f64[capacity, A] by configuration
        self.tree_of = np.empty(capacity, np.int64)  # i64[capacity] its tree (NONE: not yet)
        self.open = np.empty(capacity, np.int64)  # i64[capacity] the open stack's ids
        self.state = np.array([0, NONE], np.int64)  # the open stack's height, the goal's id
        self.scratch = (np.empty(agents, np.int32), np.empty(agents, np.int32),
                        np.empty(moves.candidates, np.int32))  # see _steps
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
        moves, explored = self.moves, self.explored
        root = explored.add_root(starts, int(moves.fields[np.arange(len(starts)), starts].sum()))
        self.priorities[root] = initial_priorities(moves, starts)
        self.tree_of[root] = NONE
        self.open[0] = root
        self.state[0] = 1
        pibt = (moves.indptr, moves.heads, moves.fields, moves.goals, self.work.occupied_now,
                self.work.occupied_next, self.work.stack, self.work.counts, self.work.keys,
                self.work.random)
        found_at = 0.0
        event = _RAN
        while time.perf_counter() <= deadline:
            self._reserve()
            event = _steps(pibt, explored.arrays, self.trees.arrays, self.priorities,
                           self.tree_of, self.open, self.state, self.scratch, self.rng,
                           self.swap, refine > 0, self.restart_rate, max_configurations, _STEPS)
            goal = int(self.state[1])
            if event == _FOUND:
                self.first_soc = _soc(explored.way(goal), moves.goals)
                self.first_loss = int(explored.cost[goal])
                if refine <= 0:
                    return explored.way(goal), ""
                found_at = time.perf_counter()
                deadline = found_at + refine
            elif event == _IMPROVED:
                self.improvements.append((time.perf_counter() - found_at,
                                          int(explored.cost[goal]),
                                          _soc(explored.way(goal), moves.goals)))
            elif event in (_EXHAUSTED, _LIMIT):
                break
        top, goal = (int(value) for value in self.state)
        if goal != NONE:
            self.optimal = top == 0
            self.loss = int(explored.cost[goal])
            return explored.way(goal), ""
        if top == 0:
            return None, ("no solution: every configuration reachable from the starts "
                          f"({explored.size}) was explored")
        if event == _LIMIT:
            return None, f"reached the limit of {max_configurations} configurations"
        return None, f"reached the time limit after {explored.size} configurations"

    def _reserve(self) -> None:
        """Grow the stores so that :func:`_steps` has room for ``_STEPS`` steps, and the open
        stack room for the next step."""
        explored = self.explored
        explored.reserve(_STEPS + 1, _STEPS)  # + 1: the spare row
        self.trees.reserve(_STEPS, _STEPS * (self.moves.candidates + 1))
        self.priorities = grown(self.priorities, len(explored.cost))
        self.tree_of = grown(self.tree_of, len(explored.cost))
        self.open = grown(self.open, self.state[0] + explored.size + 2)


_STEPS = 256
"""Steps of the search per call of :func:`_steps` (the time limit is checked between calls)."""

_RAN, _FOUND, _IMPROVED, _EXHAUSTED, _LIMIT, _FULL = range(6)
"""How a call of :func:`_steps` ended: it ran its steps; it found the first solution (the goal's
id in ``state[1]``); it lowered the solution's cost; the open stack ran out; the configurations
reached their limit; the open stack needs room."""


@jit
def _steps(pibt, explored, trees, priorities, tree_of, open_, state, scratch, rng, swap,
           refine, restart_rate, max_configurations, steps):
    """Up to ``steps`` steps of the search; returns how it ended (``_RAN`` ...).

    A step takes the configuration on top of the open stack: drops it when it cannot beat the
    solution known, or when its constraint tree has no constraint left; else it takes the next
    constraint and pushes the configuration PIBT makes under it (:func:`_successor`), new or
    known. While refining, a known one is connected (the Dijkstra update), those whose cost fell
    below the solution's are pushed again, and with probability ``restart_rate`` the starts'
    configuration is pushed in its place.

    Args:
      pibt: the arrays of :func:`~jaxswarm.multiagent.pibt.compiled_configuration`, its moves
        and its workspace.
      explored: :attr:`Explored.arrays`, with room for ``steps`` more configurations and edges.
      trees: :attr:`ConstraintTrees.arrays`, with room for ``steps`` more trees and their
        constraints.
      priorities, tree_of: f64[capacity, A] each configuration's PIBT priorities, i64[capacity]
        its tree (NONE: not made yet).
      open_: i64[H] the open stack (ids, the top last).
      state: i64[2] in and out: the open stack's height, the goal's id (NONE: none found).
      scratch: i32[A], i32[A], i32[C]: a constraint's agents, their nodes, and a tree's
        candidates.
      rng: the NumPy ``Generator`` of the trees' orders and of the restarts.
      swap, refine, restart_rate, max_configurations: :func:`lacam`'s (``refine``: a bool).
    """
    fields, goals = pibt[2], pibt[3]
    (_, nodes, cost, bound, _, _, _, _, _, _, _, _, sizes) = explored
    top, goal = state[0], state[1]
    event = _RAN
    for _ in range(steps):
        event = _halt(top, sizes[0], open_.shape[0], max_configurations)
        if event != _RAN:
            break
        node = open_[top - 1]
        if not _promising(cost, bound, node, goal):
            top -= 1
            continue
        if goal == NONE and _same(nodes[node], goals):
            goal, event = node, _FOUND
            break
        made = _successor(pibt, explored, trees, priorities, tree_of, node, scratch, rng, swap)
        if made == _NO_CONSTRAINT:
            top -= 1
            continue
        if made == _NO_CONFIGURATION:
            continue
        known, slot = find(explored)
        if known == NONE:
            known = _add(explored, slot, node, fields, priorities, tree_of)
        elif refine:
            known, top, event = _met_again(explored, open_, top, node, known, goal, rng,
                                           restart_rate)
        if _promising(cost, bound, known, goal):
            open_[top] = known
            top += 1
        if event == _IMPROVED:
            break
    state[0], state[1] = top, goal
    return event


_NO_CONSTRAINT, _NO_CONFIGURATION, _MADE = range(3)
"""What :func:`_successor` did: the tree had no constraint left; PIBT found no configuration
under the constraint taken; it wrote one to the spare row."""


@inline
def _successor(pibt, explored, trees, priorities, tree_of, node, scratch, rng, swap):
    """Take the next constraint of ``node``'s tree (planted on first use; its children queued)
    and write the configuration PIBT makes from ``node`` under it to the spare row of
    ``explored``; returns ``_MADE``, or why not."""
    (indptr, heads, fields, goals, occupied_now, occupied_next, stack, counts, keys,
     random) = pibt
    nodes = explored[1]
    who, where, options = scratch
    if tree_of[node] == NONE:
        tree_of[node] = plant(trees, priorities[node])
    tree = tree_of[node]
    taken = take(trees, tree, indptr, heads, nodes[node], options, rng)
    if taken == NONE:
        return _NO_CONSTRAINT
    fixed = gather(trees, taken, who, where)
    if compiled_configuration(indptr, heads, fields, goals, nodes[node], trees[0][tree],
                              who[:fixed], where[:fixed], spare(explored), occupied_now,
                              occupied_next, stack, counts, keys, random, swap):
        return _MADE
    return _NO_CONFIGURATION


@inline
def _met_again(explored, open_, top, node, known, goal, rng, restart_rate):
    """LaCAM*, refining: the search made ``known`` again, from ``node``. The step joins the
    explored graph and the Dijkstra update lowers costs through it; once a solution is known
    (``goal``), the configurations whose cost fell below its cost are pushed again on the open
    stack (of height ``top``) and with probability ``restart_rate`` the root takes the place of
    ``known``. Returns ``(the configuration to push, the new height, _IMPROVED or _RAN)``."""
    cost, settled = explored[2], explored[6]
    limit = cost[goal] if goal != NONE else _UNBOUNDED
    again = connect(explored, node, known, limit)
    if goal == NONE:
        return known, top, _RAN
    event = _IMPROVED if cost[goal] < limit else _RAN
    if rng.random() < restart_rate:
        known = 0  # the root
    open_[top:top + again] = settled[:again]
    return known, top + again, event


@inline
def _halt(top, size, height, max_configurations):
    """Why the search cannot take another step: the open stack is empty (``top``), the
    configurations (``size``) reached their limit, the open stack (``height`` long) may
    overflow; ``_RAN`` when it can."""
    if top == 0:
        return _EXHAUSTED
    if size >= max_configurations:
        return _LIMIT
    if top + size + 2 > height:  # a step pushes at most every configuration and one more
        return _FULL
    return _RAN


@inline
def _add(explored, slot, parent, fields, priorities, tree_of):
    """Add the new configuration in the spare row of ``explored`` (``slot``: its hash slot),
    found from ``parent``: its bound (the agents' distances to their goals, ``fields``
    i32[A, N]) and its priorities (``pibt.next_priorities`` of ``parent``'s). Returns its id."""
    goals, nodes = explored[0], explored[1]
    following = spare(explored)
    to_goals = 0
    for a in range(goals.shape[0]):
        to_goals += fields[a, following[a]]
    child = add(explored, slot, parent, to_goals)
    tree_of[child] = NONE
    next_priorities(priorities[parent], nodes[child], goals, priorities[child])
    return child


@inline
def _promising(cost, bound, node, goal):
    """Whether ``node`` may still lead to a solution cheaper than ``goal``'s (always, while
    no solution is known)."""
    return goal == NONE or cost[node] + bound[node] < cost[goal]


@inline
def _same(nodes, goals):
    for a in range(goals.shape[0]):
        if nodes[a] != goals[a]:
            return False
    return True


def _soc(configurations: list, goals: np.ndarray) -> int:
    return int(arrival_steps(np.stack(configurations, axis=1), goals).sum())
