"""The agents of a multi-agent instance: checked endpoints, MAPF benchmark instances, hop fields.

Time is counted in steps: every agent moves along one edge or waits in each step, whatever the
edge's length, so distances here are hop counts. :func:`hop_fields` computes them for all agents
by a compiled breadth-first search per goal (numba, as :mod:`jaxswarm.exact.kernels`): O(N) per
agent, where the batched relaxation of :func:`jaxswarm.exact.distance_field` takes a sweep per
step of the longest path (``docs/performance.md`` compares them).
:func:`distance_fields` keeps the batched JAX call for fields in edge lengths.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.exact import distance_field
from jaxswarm.exact.kernels import jit
from jaxswarm.maps.movingai import MovingAIFormatError, load_scenarios, read_map
from jaxswarm.world.edges import edge_arrays
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
    where the goal cannot be reached (a breadth-first search back from each goal along the
    valid edges).

    Args:
      graph: the map.
      goals: i32[A] goal node indices.
    """
    arrays = edge_arrays(graph)
    goals = np.ascontiguousarray(np.asarray(goals).reshape(-1), np.int32)
    return _hop_fields(arrays.rev_indptr, arrays.rev_tails, goals,
                       np.zeros(graph.num_nodes, np.bool_))


@jit
def breadth_first(rev_indptr, rev_tails, goal, blocked):
    """i32[N] steps from every node to ``goal`` along the edges (CSR of their reverse:
    ``rev_indptr`` i64[N + 1], ``rev_tails`` i32[E]) avoiding the ``blocked`` nodes (bool[N]),
    ``UNREACHABLE`` where there is no way."""
    n = rev_indptr.shape[0] - 1
    dist = np.full(n, UNREACHABLE, np.int32)
    queue = np.empty(n, np.int64)
    dist[goal] = 0
    queue[0] = goal
    head, tail = 0, 1
    while head < tail:
        v = queue[head]
        head += 1
        for e in range(rev_indptr[v], rev_indptr[v + 1]):
            u = rev_tails[e]
            if not blocked[u] and dist[u] == UNREACHABLE:
                dist[u] = dist[v] + 1
                queue[tail] = u
                tail += 1
    return dist


@jit
def _hop_fields(rev_indptr, rev_tails, goals, blocked):
    out = np.empty((goals.shape[0], rev_indptr.shape[0] - 1), np.int32)
    for a in range(goals.shape[0]):
        out[a] = breadth_first(rev_indptr, rev_tails, goals[a], blocked)
    return out


def cut_off(graph: Graph, fields: np.ndarray, start_nodes: np.ndarray,
            goal_nodes: np.ndarray) -> tuple[int, str] | None:
    """``(agent, reason)`` of the first agent whose goal cannot be reached from its start at
    all, the reason naming it; None when every agent can reach its goal.

    Args:
      graph: the map.
      fields: i32[A, N] the agents' hop fields (:func:`hop_fields`).
      start_nodes, goal_nodes: i32[A] node indices.
    """
    unreachable = np.nonzero(fields[np.arange(len(start_nodes)), start_nodes] == UNREACHABLE)[0]
    if not unreachable.size:
        return None
    a = int(unreachable[0])
    return a, (f"agent {a} cannot reach its goal {place(graph, goal_nodes[a])} from "
               f"{place(graph, start_nodes[a])}")


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
