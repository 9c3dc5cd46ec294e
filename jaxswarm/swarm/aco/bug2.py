"""The Bug2-like first ant of the Improved Max-Min ACO paper: a depth-first walk with a memory.

The paper replicates Bug2 (head along the line to the goal, follow an obstacle's edge until the
line is free again) with an ant whose heuristic weight is high (5) and which "knows its old
positions": it never enters a node it has been to, and backs out of a dead end to the node
before and tries another way. On a graph that is a depth-first walk: at each node the ant draws
one admissible unvisited neighbour by the colony's transition weights (or, ``greedy``, takes the
most likely one), and pops back when it has none. It reaches the goal whenever a path exists,
entering each node at most once, and its path is what remains on the stack: the way it went,
without the dead ends it backed out of. On thin-wall path maps an obstacle is a closed edge.
"""
from __future__ import annotations

import functools

import jax
import jax.numpy as jnp

from jaxswarm.swarm.walking import heads, sample_masked
from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.paths import path_length


def direction_cosine(graph: Graph, goal) -> jax.Array:
    """f32[N, K]: cosine of the angle between each move and the straight line to ``goal``
    (1 = straight at it, -1 = straight away; 1 for moves from the goal itself)."""
    move = graph.xy[heads(graph)] - graph.xy[:, None, :]
    aim = (graph.xy[goal] - graph.xy)[:, None, :]
    norms = jnp.linalg.norm(move, axis=-1) * jnp.linalg.norm(aim, axis=-1)
    return jnp.where(norms > 0, jnp.sum(move * aim, axis=-1) / jnp.where(norms > 0, norms, 1.0),
                     1.0)


@functools.partial(jax.jit, static_argnames="greedy")
def first_ant_path(key: jax.Array, graph: Graph, log_weights: jax.Array, start, goal, *,
                   greedy: bool = False):
    """The first ant's depth-first walk from ``start`` to ``goal`` (node indices, may be traced).

    Args:
      key: PRNG key of its draws (unused when ``greedy``).
      graph: the map.
      log_weights: f32[N, K] the transition log-weights (``-inf``: not admissible).
      start, goal: i32[] node indices.
      greedy: take the most likely admissible move (the first of equals) instead of drawing one.

    Returns:
      ``(path i32[N], cost f32[], found bool[])``: the path without its backed-out dead ends,
      -1 padded (all -1 and cost inf when the goal cannot be reached).
    """
    n = graph.num_nodes
    stack = jnp.full((n,), NO_NODE, jnp.int32).at[0].set(start)
    visited = jnp.zeros((n,), bool).at[start].set(True)

    def searching(carry):
        stack, _, depth, _ = carry
        return (depth > 0) & (stack[jnp.maximum(depth - 1, 0)] != goal)

    def advance(carry):
        stack, visited, depth, move = carry
        here = stack[depth - 1]
        heads = jnp.where(graph.nbr[here] >= 0, graph.nbr[here], 0)
        options = jnp.where(visited[heads], -jnp.inf, log_weights[here])
        if greedy:
            best = jnp.argmax(options)
            can_move = options[best] > -jnp.inf
        else:
            uniform = jax.random.uniform(jax.random.fold_in(key, move), (1,))
            choice, has_choice = sample_masked(uniform, options[None], jnp.ones_like(
                options, bool)[None])
            best, can_move = jnp.maximum(choice[0], 0), has_choice[0]
        there = heads[best]
        stack = jnp.where(can_move, stack.at[depth].set(there, mode="drop"),
                          stack.at[depth - 1].set(NO_NODE))
        visited = visited.at[there].set(visited[there] | can_move)
        return stack, visited, jnp.where(can_move, depth + 1, depth - 1), move + 1

    stack, _, depth, _ = jax.lax.while_loop(
        searching, advance, (stack, visited, jnp.int32(1), jnp.int32(0)))
    found = depth > 0
    path = jnp.where(found, stack, NO_NODE)
    return path, jnp.where(found, path_length(graph, path), jnp.inf), found


def bug2_path(graph: Graph, start, goal):
    """The deterministic first ant: always the admissible move closest to the goal's direction
    (:func:`first_ant_path` with ``greedy`` over :func:`direction_cosine`).

    Returns:
      ``(path i32[N], cost f32[], found bool[])`` as :func:`first_ant_path`.
    """
    preference = jnp.where(graph.valid_edges(), direction_cosine(graph, goal), -jnp.inf)
    return first_ant_path(jax.random.key(0), graph, preference, start, goal, greedy=True)
