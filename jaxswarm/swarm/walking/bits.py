"""Visited sets as packed bits: row ``a`` of a u32[A, ceil(N / 32)] array is agent ``a``'s set,
bit ``n % 32`` of word ``n // 32`` node ``n``."""
from __future__ import annotations

import jax
import jax.numpy as jnp


def mark(bits: jax.Array, agents: jax.Array, nodes: jax.Array) -> jax.Array:
    """u32[A, W] ``bits`` with bit ``nodes[a]`` set in row ``agents[a]`` (i32[a] each)."""
    words = nodes >> 5
    updated = bits[agents, words] | (jnp.uint32(1) << (nodes & 31).astype(jnp.uint32))
    return bits.at[agents, words].set(updated)


def is_marked(bits: jax.Array, nodes: jax.Array) -> jax.Array:
    """bool[A, K]: whether node ``nodes[a, k]`` (i32[A, K]) is in agent ``a``'s set."""
    words = jnp.take_along_axis(bits, nodes >> 5, axis=1)
    return ((words >> (nodes & 31).astype(jnp.uint32)) & 1).astype(bool)


def union(bits: jax.Array, num_nodes: int, which: jax.Array | None = None) -> jax.Array:
    """bool[N]: the union of the sets of the agents selected by ``which`` (bool[A]; all agents
    when None)."""
    words = bits if which is None else jnp.where(which[:, None], bits, 0)
    merged = jax.lax.reduce(words, jnp.uint32(0), jax.lax.bitwise_or, (0,))
    per_node = (merged[:, None] >> jnp.arange(32, dtype=jnp.uint32)) & 1
    return per_node.reshape(-1)[:num_nodes].astype(bool)


def pack(mask: jax.Array) -> jax.Array:
    """u32[A, ceil(N / 32)] the sets of ``mask`` (bool[A, N]: node ``n`` is in set ``a``)."""
    num_sets, num_nodes = mask.shape
    words = (num_nodes + 31) // 32
    padded = jnp.zeros((num_sets, words * 32), jnp.uint32).at[:, :num_nodes].set(mask)
    shifted = padded.reshape(num_sets, words, 32) << jnp.arange(32, dtype=jnp.uint32)
    return jax.lax.reduce(shifted, jnp.uint32(0), jax.lax.bitwise_or, (2,))
