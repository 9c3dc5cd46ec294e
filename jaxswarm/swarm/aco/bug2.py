"""The Bug2-like first ant of the Improved Max-Min ACO paper: a depth-first walk with a memory.

The paper replicates Bug2 (head along the line to the goal, follow an obstacle's edge until the
line is free again) with an ant whose heuristic weight is high (5) and which "knows its old
positions": it never enters a node it has been to, and backs out of a dead end to the node
before and tries another way. That is the walker's depth-first walk
(:mod:`jaxswarm.swarm.walking.backtrack`) over the colony's transition weights. On thin-wall path
maps an obstacle is a closed edge.
"""
from __future__ import annotations

import functools

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking import heads
from jaxswarm.swarm.walking.backtrack import DepthFirstRule, depth_first_walk
from jaxswarm.swarm.walking.native import implementation as chosen_implementation
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import path_length


def direction_cosine(graph: Graph, goal) -> jax.Array:
    """f32[N, K]: cosine of the angle between each move and the straight line to ``goal``
    (1 = straight at it, -1 = straight away; 1 for moves from the goal itself)."""
    move = graph.xy[heads(graph)] - graph.xy[:, None, :]
    aim = (graph.xy[goal] - graph.xy)[:, None, :]
    norms = jnp.linalg.norm(move, axis=-1) * jnp.linalg.norm(aim, axis=-1)
    return jnp.where(norms > 0, jnp.sum(move * aim, axis=-1) / jnp.where(norms > 0, norms, 1.0),
                     1.0)


def first_ant_path(key: jax.Array, graph: Graph, log_weights: jax.Array, start, goal, *,
                   greedy: bool = False, implementation: str | None = None):
    """The first ant's depth-first walk from ``start`` to ``goal`` (node indices, may be traced;
    :func:`~jaxswarm.swarm.walking.backtrack.depth_first_walk` over a fixed table), jitted.

    Args:
      key: PRNG key of its draws (unused when ``greedy``).
      graph: the map.
      log_weights: f32[N, K] the transition log-weights (``-inf``: not admissible).
      start, goal: i32[] node indices.
      greedy: take the most likely admissible move (the first of equals) instead of drawing one.
      implementation: ``"lanes"`` (XLA), ``"native"`` or None: resolved now
        (:func:`~jaxswarm.swarm.walking.native.implementation`, which reads the environment),
        not when the program was first traced. Both give the same path, bit for bit.

    Returns:
      ``(path i32[N], cost f32[], found bool[])``: the path without its backed-out dead ends,
      -1 padded (all -1 and cost inf when the goal cannot be reached).
    """
    return _first_ant_path(key, graph, log_weights, start, goal, greedy=greedy,
                           implementation=chosen_implementation(requested=implementation))


@functools.partial(jax.jit, static_argnames=("greedy", "implementation"))
def _first_ant_path(key: jax.Array, graph: Graph, log_weights: jax.Array, start, goal, *,
                    greedy: bool, implementation: str):
    """:func:`first_ant_path` with its implementation resolved (static)."""
    walked = depth_first_walk(key, graph, DepthFirstRule(log_weights), start, goal,
                              max_nodes=graph.num_nodes, greedy=greedy,
                              implementation=implementation)
    return (walked.path, jnp.where(walked.found, path_length(graph, walked.path), jnp.inf),
            walked.found)


def bug2_path(graph: Graph, start, goal):
    """The deterministic first ant: always the admissible move closest to the goal's direction
    (:func:`first_ant_path` with ``greedy`` over :func:`direction_cosine`).

    Returns:
      ``(path i32[N], cost f32[], found bool[])`` as :func:`first_ant_path`.
    """
    preference = jnp.where(graph.valid_edges(), direction_cosine(graph, goal), -jnp.inf)
    return first_ant_path(jax.random.key(0), graph, preference, start, goal, greedy=True)
