"""A run's fingerprint: 64 bits that change when any bit of what the run decided changes.

A sweep stores one per row, so a row replayed alone (:mod:`jaxswarm.sweep.replay`) or run on
another thread or device count can be checked against the stored run bit for bit without
storing its state. Each leaf's words (floats and integers by their bits, booleans as 0 or 1, PRNG
keys by their data) are mixed with their position in the flattened tree (MurmurHash3's finaliser)
and summed as unsigned integers, which adds exactly in any order, so the fingerprint is the same
alone and in any batch whenever the bits are.
"""
from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.core import Trace
from jaxswarm.swarm.walking.streams import fmix32

_SALTS = (np.uint32(0x9E3779B9), np.uint32(0x7F4A7C15))
"""One salt per half of the fingerprint."""


def fingerprint(tree) -> jax.Array:
    """u32[2]: the fingerprint of every leaf of ``tree`` (a pytree of arrays; PRNG keys
    allowed). Two trees with the same structure, shapes and bits have the same fingerprint; a
    change of any bit changes it but with probability about 2^-64."""
    words = jnp.concatenate([_words(leaf) for leaf in jax.tree_util.tree_leaves(tree)] or
                            [jnp.zeros((0,), jnp.uint32)])
    position = jnp.arange(words.shape[0], dtype=jnp.uint32)
    return jnp.stack([jnp.sum(fmix32(words ^ fmix32(position * np.uint32(2) + salt)),
                              dtype=jnp.uint32) for salt in _SALTS])


def run_fingerprint(state, trace: Trace) -> jax.Array:
    """u32[2]: the :func:`fingerprint` of a run's final ``state`` and its ``trace`` but for the
    trace's ``lane_steps`` (the walker's work, shared by the runs of a batch) and
    ``overflowed`` (a run whose walk overflowed is made again)."""
    return fingerprint((state, dataclasses.replace(trace, lane_steps=None, overflowed=None)))


def hex_fingerprint(value) -> str:
    """The 16 hex digits of a fingerprint (u32[2], on the host or the device)."""
    high, low = (int(v) for v in np.asarray(value, np.uint32))
    return f"{high:08x}{low:08x}"


def _words(leaf) -> jax.Array:
    """u32[n]: a leaf's elements as 32-bit words (keys: their data; narrower types widened
    exactly, booleans as 0 or 1; 64-bit types split)."""
    leaf = jnp.asarray(leaf)
    if jnp.issubdtype(leaf.dtype, jax.dtypes.prng_key):
        leaf = jax.random.key_data(leaf)
    if leaf.dtype == jnp.bool_:
        leaf = leaf.astype(jnp.uint32)
    elif leaf.dtype.itemsize < 4:  # exactly, as float32 or int32
        leaf = leaf.astype(jnp.float32 if jnp.issubdtype(leaf.dtype, jnp.floating)
                           else jnp.int32)
    return jax.lax.bitcast_convert_type(leaf.reshape(-1), jnp.uint32).reshape(-1)
