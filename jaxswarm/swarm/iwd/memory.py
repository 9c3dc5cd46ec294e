"""IWD_PG's memory of the best distinct solutions, and the path surgery its operators share
(paths are i32[L], -1 padded).

The memory holds ``M`` paths (static) and their lengths, best first, inf (and all padding) where
a slot is empty. A candidate enters when it is shorter than the worst remembered path and no
remembered path is the same node sequence.
"""
from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.runtime.arithmetic import ordered_cumsum
from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.lattice import move_lengths
from jaxswarm.world.paths import step_slots


class Memory(NamedTuple):
    """The best distinct paths found so far (a pytree).

    Attributes:
      paths: i32[M, L] best first, -1 padded (all -1 where empty).
      costs: f32[M] their lengths (inf where empty).
    """

    paths: jax.Array
    costs: jax.Array


def empty_memory(size: int, length: int) -> Memory:
    """A memory of ``size`` empty slots for paths of ``length`` nodes."""
    return Memory(paths=jnp.full((size, length), NO_NODE, jnp.int32),
                  costs=jnp.full((size,), jnp.inf, jnp.float32))


def remember(memory: Memory, paths: jax.Array, costs: jax.Array) -> Memory:
    """The memory after offering it ``paths`` (i32[C, L]) of lengths ``costs`` (f32[C], inf for
    no path): the ``M`` shortest distinct paths among the remembered and the offered ones (ties
    broken by the order remembered first, then offered)."""
    pool_paths = jnp.concatenate([memory.paths, paths])
    pool_costs = jnp.concatenate([memory.costs, costs])
    order = jnp.argsort(pool_costs, stable=True)
    pool_paths, pool_costs = pool_paths[order], pool_costs[order]
    # A path equal to an earlier (so no longer) one in the pool is a duplicate.
    same = jnp.all(pool_paths[:, None, :] == pool_paths[None, :, :], axis=-1)
    earlier = jnp.tril(jnp.ones(same.shape, bool), k=-1)
    duplicate = jnp.any(same & earlier, axis=1) | ~jnp.isfinite(pool_costs)
    keep = jnp.argsort(duplicate, stable=True)[:memory.costs.shape[0]]
    kept_costs = jnp.where(duplicate[keep], jnp.inf, pool_costs[keep])
    kept_paths = jnp.where(duplicate[keep][:, None], NO_NODE, pool_paths[keep])
    return Memory(paths=kept_paths, costs=kept_costs)


def node_count(path: jax.Array) -> jax.Array:
    """i32[]: the nodes of a padded path."""
    return jnp.sum(path >= 0, dtype=jnp.int32)


def join(head: jax.Array, head_nodes, tail: jax.Array, tail_from) -> jax.Array:
    """i32[L]: the first ``head_nodes`` nodes of ``head`` followed by ``tail`` from position
    ``tail_from`` on (both i32[L], -1 padded); nodes past ``L`` are cut (the caller measures
    the result, and a cut path does not reach the goal)."""
    length = head.shape[0]
    position = jnp.arange(length)
    from_tail = tail[jnp.clip(position - head_nodes + tail_from, 0, length - 1)]
    beyond = position - head_nodes + tail_from >= length
    return jnp.where(position < head_nodes, head, jnp.where(beyond, NO_NODE, from_tail))


def splice(path: jax.Array, begin, end, middle: jax.Array) -> jax.Array:
    """i32[L]: ``path`` with its nodes from position ``begin`` to ``end`` (inclusive) replaced
    by the nodes of ``middle`` (i32[L], -1 padded, from ``path[begin]`` to ``path[end]``)."""
    return join(join(path, begin, middle, 0), begin + node_count(middle), path, end + 1)


def prefix_lengths(graph: Graph, path: jax.Array) -> jax.Array:
    """f32[L]: the length of ``path`` (i32[L], -1 padded) from its start to each position
    (constant past its end)."""
    moves = move_lengths(graph, path[:-1], step_slots(graph, path))
    return jnp.concatenate([jnp.zeros((1,), jnp.float32), ordered_cumsum(moves)])


def last_position(path: jax.Array) -> jax.Array:
    """i32[]: the position of the last node of a padded path."""
    return jnp.maximum(node_count(path) - 1, 0)


def reverse(path: jax.Array) -> jax.Array:
    """i32[L]: the nodes of a padded path in reverse order, -1 padded."""
    length = path.shape[0]
    position = last_position(path) - jnp.arange(length)
    return jnp.where(position >= 0, path[jnp.maximum(position, 0)], NO_NODE)
