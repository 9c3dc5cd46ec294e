"""Prioritised planning: agents planned one by one with space-time A* around those before them.

Each agent in priority order gets its fewest-steps path (:func:`jaxswarm.multiagent.spacetime.
search`) avoiding the nodes and moves the agents planned before it hold, and then holds its own
path and, from its arrival on, its goal. Fast and usually good, but neither complete nor optimal:
an agent can find its way walled in by those before it, and the result depends on the order.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
import time
from collections.abc import Iterable

import numpy as np

from jaxswarm.multiagent.agents import UNREACHABLE, agent_nodes, hop_fields, place
from jaxswarm.multiagent.limits import OptionError, check_count, check_number
from jaxswarm.multiagent.plan import Plan, pack
from jaxswarm.multiagent.spacetime import LIMIT, Reservations, search
from jaxswarm.world.graph import Graph

ORDERS = ("given", "distance", "random")
"""Priority orders by name: as given, by distance (the farthest from its goal first, ties by
agent number) or a seeded random permutation."""


def priority_order(order, distances: np.ndarray, seed: int = 0) -> np.ndarray:
    """i32[A] the agents, first to last.

    Args:
      order: a name of ``ORDERS`` or a permutation of the agents.
      distances: i32[A] each agent's own fewest steps to its goal.
      seed: the seed of the "random" order (numpy's default generator).
    """
    agents = len(distances)
    if isinstance(order, str):
        if order == "given":
            return np.arange(agents, dtype=np.int32)
        if order == "distance":
            return np.lexsort((np.arange(agents), -distances.astype(np.int64))).astype(np.int32)
        if order == "random":
            return np.random.default_rng(seed).permutation(agents).astype(np.int32)
        raise ValueError(f"unknown order {order!r}; use one of {ORDERS} or a permutation")
    permutation = np.asarray(order)
    if sorted(permutation.tolist()) != list(range(agents)):
        raise ValueError(f"order must be a permutation of the {agents} agents, got {order!r}")
    return permutation.astype(np.int32)


@dataclasses.dataclass(frozen=True)
class PrioritizedConfig:
    """The options of :func:`prioritized`, checked when made.

    Attributes:
      order: "given", "distance", "random" (see ``ORDERS``) or a permutation of the agents (a
        sequence of integers, held as a tuple; that it is one of the instance's agents is
        checked with the instance).
      seed: the seed of the random order (at least 0).
      max_expansions: the per-agent limit on expanded space-time states (at least 1).
      time_limit: give up after this many seconds (checked between agents; at least 0,
        ``math.inf``: none).

    Raises:
      TypeError, ValueError: an option of the wrong type or out of its range, naming it.
    """

    order: str | tuple[int, ...] = "given"
    seed: int = 0
    max_expansions: int = 10_000_000
    time_limit: float = math.inf

    def __post_init__(self):
        if isinstance(self.order, str):
            if self.order not in ORDERS:
                raise OptionError("order", f"must be one of {', '.join(ORDERS)} or a "
                                           f"permutation of the agents, got {self.order!r}")
        elif (not isinstance(self.order, Iterable)
              or not all(isinstance(a, numbers.Integral) and not isinstance(a, bool)
                         for a in self.order)):
            raise TypeError(f"order must be one of {', '.join(ORDERS)} or a sequence of agents, "
                            f"got {self.order!r}")
        else:
            object.__setattr__(self, "order", tuple(int(a) for a in self.order))
        check_count("seed", self.seed, least=0)
        check_count("max_expansions", self.max_expansions)
        check_number("time_limit", self.time_limit, least=0)


def prioritized(graph: Graph, starts, goals, **options) -> Plan:
    """Prioritised planning with space-time A* and a reservation table.

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      **options: those of :class:`~jaxswarm.multiagent.prioritized.PrioritizedConfig` (``order``,
        ``seed``, ``max_expansions``, ``time_limit``).

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner="prioritized"``); not solved, naming
      the agent, when an agent's goal cannot be reached at all, or cannot be reached around the
      agents planned before it, or when the time limit is reached before its turn.

    Raises:
      TypeError, ValueError: a bad option (see
        :class:`~jaxswarm.multiagent.prioritized.PrioritizedConfig`), naming it, before any search.
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`) or an
        order that is not a permutation of its agents.
    """
    config = PrioritizedConfig(**options)
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    fields = hop_fields(graph, goal_nodes)
    agents = np.arange(len(start_nodes))
    distances = fields[agents, start_nodes]
    ranking = priority_order(config.order, distances, config.seed)
    table = Reservations.empty(graph.num_nodes)
    paths = [np.array([s], np.int32) for s in start_nodes]
    expanded = 0

    def stop(agent: int, why: str) -> Plan:
        return Plan(*pack(paths, goal_nodes), solved=False, planner="prioritized",
                    reason=f"agent {agent} {why}", agent=agent,
                    stats={"expanded": expanded, "seconds": time.perf_counter() - began,
                           "order": ranking})

    for a in agents[distances == UNREACHABLE].tolist():
        return stop(a, f"cannot reach its goal {place(graph, goal_nodes[a])} from "
                       f"{place(graph, start_nodes[a])}")
    for rank, a in enumerate(ranking.tolist()):
        if time.perf_counter() - began > config.time_limit:
            return stop(a, f"not planned (priority {rank}): reached the time limit "
                           f"({config.time_limit:g} s)")
        path, count, outcome = search(graph, int(start_nodes[a]), int(goal_nodes[a]), fields[a],
                                      table, max_expansions=config.max_expansions)
        expanded += count
        if path is None:
            why = ("reached the expansion limit" if outcome == LIMIT else "found no way")
            return stop(a, f"could not be planned (priority {rank}): {why} around the "
                           f"{rank} agents before it")
        paths[a] = path
        table.reserve(a, path)
    return Plan(*pack(paths, goal_nodes), solved=True, planner="prioritized",
                stats={"expanded": expanded, "seconds": time.perf_counter() - began,
                       "order": ranking})
