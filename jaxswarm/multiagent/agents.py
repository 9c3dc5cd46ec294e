"""The agents of a multi-agent instance: checked endpoints, MAPF benchmark instances, hop fields.

Time is counted in steps: every agent moves along one edge or waits in each step, whatever the
edge's length, so distances here are hop counts. :func:`hop_fields` computes them for all agents
in one batched call of :func:`jaxswarm.exact.distance_field` (vmapped over the goals), on the
graph with every edge length set to 1.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.exact import distance_field
from jaxswarm.maps.movingai import MovingAIFormatError, load_scenarios, read_map
from jaxswarm.world.graph import Graph, grid_graph
from jaxswarm.world.paths import as_node

UNREACHABLE = np.iinfo(np.int32).max
"""Hop distance of a node that cannot reach the goal (i32)."""


@dataclasses.dataclass(frozen=True)
class Instance:
    """A multi-agent instance on a map.

    Attributes:
      graph: the map; its valid edges are the moves (MAPF maps are loaded 4-connected).
      starts, goals: lists of (x, y) cells, one per agent.
      name: where the instance came from (for tables and messages).
    """

    graph: Graph
    starts: list
    goals: list
    name: str = ""


def agent_nodes(graph: Graph, starts, goals) -> tuple[np.ndarray, np.ndarray]:
    """Node indices of the agents' starts and goals, checked.

    Args:
      graph: the map.
      starts, goals: sequences of (x, y) cells (or node indices), one per agent.

    Returns:
      ``(starts i32[A], goals i32[A])``.

    Raises:
      ValueError: no agents, different numbers of starts and goals, a start or goal off the map
        or on an obstacle, or two agents with one start or one goal; the message names the
        agents.
    """
    if len(starts) != len(goals):
        raise ValueError(f"{len(starts)} starts but {len(goals)} goals")
    if len(starts) == 0:
        raise ValueError("no agents: starts and goals are empty")
    nodes = []
    for kind, points in (("start", starts), ("goal", goals)):
        indices = np.array([as_node(graph, point, name=f"agent {a}'s {kind}")
                            for a, point in enumerate(points)], np.int32)
        first = {}
        for agent, node in enumerate(indices.tolist()):
            if node in first:
                raise ValueError(f"agents {first[node]} and {agent} have one {kind} "
                                 f"{place(graph, node)}")
            first[node] = agent
        nodes.append(indices)
    return nodes[0], nodes[1]


def place(graph: Graph, node: int) -> str:
    """A node as messages name it: ``(x, y)`` on a grid, ``node i`` elsewhere."""
    if graph.is_grid:
        return f"({node % graph.shape[1]}, {node // graph.shape[1]})"
    return f"node {node}"


def hop_graph(graph: Graph) -> Graph:
    """``graph`` with every edge length 1 (one step per move)."""
    return dataclasses.replace(graph, cost=(graph.nbr >= 0).astype(jnp.float32))


@jax.jit
def _fields(graph: Graph, goals: jax.Array) -> jax.Array:
    return jax.vmap(distance_field, in_axes=(None, 0))(graph, goals)


def distance_fields(graph: Graph, goals) -> np.ndarray:
    """f32[A, N]: the shortest distance (edge lengths) from every node to each goal, inf where
    it cannot be reached; one batched JAX call over all goals.

    Args:
      graph: the map.
      goals: i32[A] goal node indices.
    """
    return np.asarray(_fields(graph, jnp.asarray(goals, jnp.int32)))


def hop_fields(graph: Graph, goals) -> np.ndarray:
    """i32[A, N]: the number of steps from every node to each agent's goal, ``UNREACHABLE``
    where the goal cannot be reached (:func:`~jaxswarm.multiagent.agents.distance_fields` on
    :func:`~jaxswarm.multiagent.agents.hop_graph`).

    Args:
      graph: the map.
      goals: i32[A] goal node indices.
    """
    fields = distance_fields(hop_graph(graph), goals)
    steps = np.full(fields.shape, UNREACHABLE, np.int32)
    reachable = np.isfinite(fields)
    steps[reachable] = fields[reachable]
    return steps


def lower_bound(graph: Graph, starts, goals) -> int:
    """The sum of each agent's own shortest number of steps, a lower bound on the sum of costs
    (``UNREACHABLE`` if some agent cannot reach its goal).

    Args:
      graph: the map.
      starts, goals: (x, y) cells or node indices, one per agent.
    """
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    steps = hop_fields(graph, goal_nodes)[np.arange(len(start_nodes)), start_nodes]
    return UNREACHABLE if (steps == UNREACHABLE).any() else int(steps.sum())


def load_instance(map_path, scen_path, agents: int) -> Instance:
    """The MAPF benchmark instance of the first ``agents`` rows of a ``.scen`` file, on the map
    loaded 4-connected (the benchmark's convention: unit moves, no diagonals).

    Raises:
      MovingAIFormatError: a malformed file, or fewer than ``agents`` rows.
      ValueError: ``agents`` below 1.
    """
    if agents < 1:
        raise ValueError(f"agents must be at least 1, got {agents}")
    obstacles = read_map(map_path)
    rows = load_scenarios(scen_path, obstacles)
    if len(rows) < agents:
        raise MovingAIFormatError(scen_path, len(rows) + 1,
                                  f"{agents} agents asked for, the file has {len(rows)} rows")
    rows = rows[:agents]
    return Instance(grid_graph(obstacles, connectivity=4), [r.start for r in rows],
                    [r.goal for r in rows], f"{Path(map_path).stem} ({agents} agents)")
