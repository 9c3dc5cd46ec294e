"""IWD_PG's two intersection operators on a pair of remembered paths (Pseudo-codes 1 and 2 did
not survive the text; these follow its words).

* First: where the two paths share a node other than the start and the goal, the head of one
  joins the tail of the other there. Of all shared nodes, each child takes the one that makes
  it shortest.
* Second: where they share none, the closest pair of their inner nodes (straight-line distance)
  is joined by a local search (:func:`~.local.connect`), and the heads and tails are exchanged
  across that connection.

A child replaces its parent (the path whose head it keeps) only if it is shorter; the caller
applies local search to a first-operator child around the node where it was joined.
"""
from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.iwd.memory import join, last_position, prefix_lengths, reverse
from jaxswarm.swarm.walking import on_moves
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import path_length


class Children(NamedTuple):
    """Two children of a pair of paths ``(a, b)``.

    Attributes:
      paths: i32[2, L] the child with ``a``'s head, and the child with ``b``'s head.
      costs: f32[2] their lengths (inf where there is no child).
      joints: i32[2] the position in each child where the other parent's part begins.
    """

    paths: jax.Array
    costs: jax.Array
    joints: jax.Array


def _inner(path: jax.Array) -> jax.Array:
    """bool[L]: the positions of a path's nodes other than its first and last."""
    position = jnp.arange(path.shape[0])
    return (position > 0) & (position < last_position(path))


def first_intersection(graph: Graph, a: jax.Array, b: jax.Array) -> Children:
    """The first operator's children of paths ``a`` and ``b`` (i32[L], from one start to one
    goal); costs inf when they share no inner node."""
    n = graph.num_nodes
    length = a.shape[0]
    in_b = jnp.full((n + 1,), -1, jnp.int32).at[jnp.where(_inner(b), b, n)].set(
        jnp.arange(length, dtype=jnp.int32))[:n]
    j = jnp.where(_inner(a), in_b[jnp.maximum(a, 0)], -1)
    shared = j >= 0
    j_safe = jnp.maximum(j, 0)
    prefix_a, prefix_b = prefix_lengths(graph, a), prefix_lengths(graph, b)
    total_a, total_b = prefix_a[-1], prefix_b[-1]
    i = jnp.arange(length)
    head_a = jnp.argmin(jnp.where(shared, prefix_a + total_b - prefix_b[j_safe], jnp.inf))
    head_b = jnp.argmin(jnp.where(shared, prefix_b[j_safe] + total_a - prefix_a, jnp.inf))
    child_a = join(a, head_a, b, j_safe[head_a])
    child_b = join(b, j_safe[head_b], a, i[head_b])
    has = jnp.any(shared)
    costs = jnp.where(has, jnp.stack([path_length(graph, child_a), path_length(graph, child_b)]),
                      jnp.inf)
    return Children(paths=jnp.stack([child_a, child_b]), costs=costs,
                    joints=jnp.stack([head_a, j_safe[head_b]]).astype(jnp.int32))


def closest_inner_pair(graph: Graph, a: jax.Array, b: jax.Array):
    """``(i, j)``: the positions of the inner nodes of ``a`` and ``b`` nearest each other."""
    xy_a, xy_b = graph.xy[jnp.maximum(a, 0)], graph.xy[jnp.maximum(b, 0)]
    distance = jnp.sum((xy_a[:, None, :] - xy_b[None, :, :]) ** 2, axis=-1)
    distance = jnp.where(_inner(a)[:, None] & _inner(b)[None, :], distance, jnp.inf)
    flat = jnp.argmin(distance)
    return flat // b.shape[0], flat % b.shape[0]


def closest_inner_pairs(graph: Graph, a: jax.Array, others: jax.Array):
    """``(i, j)`` i32[P]: :func:`closest_inner_pair` of ``a`` (i32[L]) and each of ``others``
    (i32[P, L]), worked on the narrowest width that holds them all in the batch
    (:func:`~jaxswarm.swarm.walking.moves.on_moves`: the positions past their ends are not
    inner, and the first nearest pair in row-major order is the same on fewer columns)."""
    rows = jnp.concatenate([a[None], others])
    return on_moves(_closest_within, jnp.sum(rows >= 0, axis=1, dtype=jnp.int32), (rows,),
                    None, graph)


def _closest_within(columns, _, graph: Graph):
    """:func:`closest_inner_pairs` of the first of the paths ``columns`` (one i32[P + 1, W])
    and each of the others."""
    (rows,) = columns
    return jax.vmap(lambda b: closest_inner_pair(graph, rows[0], b))(rows[1:])


def second_intersection(graph: Graph, a, b, i, j, connection) -> Children:
    """The second operator's children of ``a`` and ``b`` joined by ``connection`` (i32[L], a
    path from ``a[i]`` to ``b[j]``, or all -1 when the local search found none)."""
    found = connection[0] >= 0
    steps = last_position(connection)
    child_a = join(join(a, i, connection, 0), i + steps + 1, b, j + 1)
    child_b = join(join(b, j, reverse(connection), 0), j + steps + 1, a, i + 1)
    costs = jnp.where(found, jnp.stack([path_length(graph, child_a),
                                        path_length(graph, child_b)]), jnp.inf)
    return Children(paths=jnp.stack([child_a, child_b]), costs=costs,
                    joints=jnp.stack([i, j]).astype(jnp.int32))
