"""A new MAPF planner in one file (docs/extending.md): each agent walks one of its own shortest
paths, agent i after waiting ``stagger * i`` steps at its start. No other coordination, so the
plan is a solution only where the waits keep the agents apart; it says which two collide
otherwise."""
from __future__ import annotations

import dataclasses

import numpy as np

from jaxswarm.multiagent.agents import agent_nodes, cut_off, hop_fields
from jaxswarm.multiagent.conflicts import pair_collisions
from jaxswarm.multiagent.limits import check_count
from jaxswarm.multiagent.plan import Plan, pack
from jaxswarm.multiagent.registry import Entry, Style, register
from jaxswarm.world.graph import Graph


@dataclasses.dataclass(frozen=True)
class StaggeredConfig:
    """The options of :func:`staggered`, checked when made.

    Attributes:
      stagger: the steps agent i waits per agent before it, ``stagger * i`` (at least 0).
    """

    stagger: int = 0

    def __post_init__(self):
        check_count("stagger", self.stagger, least=0)


def staggered(graph: Graph, starts, goals, **options) -> Plan:
    """Each agent's shortest path after its wait (see the module docstring).

    Args:
      graph: the map; its valid edges are the moves, one step each.
      starts, goals: (x, y) cells (or node indices), one per agent, all distinct.
      **options: those of :class:`StaggeredConfig`.

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``paths`` i32[A, T], ``lengths`` i32[A]);
      not solved when a goal cannot be reached or two agents collide, naming them.
    """
    config = StaggeredConfig(**options)
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    fields = hop_fields(graph, goal_nodes)  # i32[A, N] steps to each agent's goal
    blocked = cut_off(graph, fields, start_nodes, goal_nodes)
    if blocked is not None:
        return Plan(start_nodes[:, None], np.zeros(len(start_nodes), np.int32), False,
                    "staggered", reason=blocked[1], agent=blocked[0])
    nbr, valid = np.asarray(graph.nbr), np.asarray(graph.valid_edges())
    paths = []
    for a, goal in enumerate(goal_nodes.tolist()):
        path = [int(start_nodes[a])] * (1 + config.stagger * a)
        while path[-1] != goal:  # down the hop field: one step nearer each move
            here = path[-1]
            path.append(min(nbr[here][valid[here]].tolist(), key=lambda v: fields[a, v]))
        paths.append(path)
    padded, lengths = pack(paths, goal_nodes)
    collisions = pair_collisions(padded)  # i32[A, A] the first step two agents meet, -1: never
    pairs = np.argwhere(np.triu(collisions >= 0, 1))
    if pairs.size:
        a, b = pairs[0].tolist()
        return Plan(padded, lengths, False, "staggered", agent=b,
                    reason=f"agents {a} and {b} collide at step {collisions[a, b]}")
    return Plan(padded, lengths, True, "staggered")


register("staggered", Entry(StaggeredConfig, staggered, label="staggered (example)",
                            source="docs/extending.md: shortest paths, started in turn",
                            faithful=False, style=Style("1", "-.")))
