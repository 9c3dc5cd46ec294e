"""The Bug2-like first ant of the Improved Max-Min ACO paper, as a deterministic JAX search.

The paper's first ant heads along the line to the goal, follows obstacle edges until the line is
free again, and remembers where it has been so that it never loops. On a graph this is a
depth-first walk that always tries first the admissible neighbour whose direction is closest to
the direction of the goal (so it runs along the line when it can and along the obstacle's edge
when it cannot), never enters a visited node, and backs up from dead ends. It reaches the goal
whenever a path exists, visiting each node at most once.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.graph import NO_NODE, Graph
from jaxswarm.paths import path_length


def direction_cosine(graph: Graph, goal) -> jax.Array:
    """f32[N, K]: cosine of the angle between each move and the straight line to ``goal``
    (1 = straight at it, -1 = straight away; 1 for moves from the goal itself)."""
    heads = jnp.where(graph.nbr >= 0, graph.nbr, 0)
    move = graph.xy[heads] - graph.xy[:, None, :]
    aim = (graph.xy[goal] - graph.xy)[:, None, :]
    norms = jnp.linalg.norm(move, axis=-1) * jnp.linalg.norm(aim, axis=-1)
    return jnp.where(norms > 0, jnp.sum(move * aim, axis=-1) / jnp.where(norms > 0, norms, 1.0),
                     1.0)


@jax.jit
def bug2_path(graph: Graph, start, goal):
    """The Bug2-like ant's path from ``start`` to ``goal`` (node indices, may be traced).

    Returns:
      ``(path i32[N], cost f32[], found bool[])``: the path without its backed-out dead ends,
      -1 padded (all -1 and cost inf when the goal cannot be reached).
    """
    n = graph.num_nodes
    valid = graph.valid_edges()
    preference = jnp.where(valid, direction_cosine(graph, goal), -jnp.inf)
    stack = jnp.full((n,), NO_NODE, jnp.int32).at[0].set(start)
    visited = jnp.zeros((n,), bool).at[start].set(True)

    def searching(carry):
        stack, _, depth = carry
        return (depth > 0) & (stack[jnp.maximum(depth - 1, 0)] != goal)

    def advance(carry):
        stack, visited, depth = carry
        here = stack[depth - 1]
        heads = jnp.where(graph.nbr[here] >= 0, graph.nbr[here], 0)
        options = jnp.where(visited[heads], -jnp.inf, preference[here])
        best = jnp.argmax(options)
        can_move = options[best] > -jnp.inf
        there = heads[best]
        stack = jnp.where(can_move, stack.at[depth].set(there, mode="drop"),
                          stack.at[depth - 1].set(NO_NODE))
        visited = visited.at[there].set(visited[there] | can_move)
        return stack, visited, jnp.where(can_move, depth + 1, depth - 1)

    stack, _, depth = jax.lax.while_loop(searching, advance, (stack, visited, jnp.int32(1)))
    found = depth > 0
    path = jnp.where(found, stack, NO_NODE)
    return path, jnp.where(found, path_length(graph, path), jnp.inf), found
