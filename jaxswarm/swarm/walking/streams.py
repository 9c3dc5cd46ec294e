"""The walker's random streams: one uniform per (agent, move), whoever walks the agent."""
from __future__ import annotations

import jax
import jax.numpy as jnp


def uniforms(seed: jax.Array, agent: jax.Array, move: jax.Array) -> jax.Array:
    """f32[...] in [0, 1): the uniform of agent ``agent``'s move ``move`` (i32[...] each) in a
    walk keyed by ``seed`` (u32[..., 2]).

    A counter-based hash (MurmurHash3's 32-bit finaliser, twice, keyed by the two seed words),
    so a draw depends on the agent and the move only, never on the lane that makes it; about a
    tenth of the arithmetic of a Threefry draw.
    """
    counter = (agent.astype(jnp.uint32) * jnp.uint32(0x9E3779B1)) ^ move.astype(jnp.uint32)
    mixed = fmix32(fmix32(counter ^ seed[..., 0]) ^ seed[..., 1])
    return (mixed >> 8).astype(jnp.float32) * jnp.float32(2.0 ** -24)


def fmix32(x: jax.Array) -> jax.Array:
    """u32[...]: MurmurHash3's 32-bit finaliser, a bijection in which every input bit flips each
    output bit with probability about 1/2."""
    x = x ^ (x >> 16)
    x = x * jnp.uint32(0x85EBCA6B)
    x = x ^ (x >> 13)
    x = x * jnp.uint32(0xC2B2AE35)
    return x ^ (x >> 16)
