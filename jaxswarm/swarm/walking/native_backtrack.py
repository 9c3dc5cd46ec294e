"""The depth-first walk (:mod:`.backtrack`) as one native kernel call on CPU (issue 67;
``docs/native.md``).

:func:`depth_first_walks` walks every walk of a call with the C++ handler ``backtrack.cc``
(:mod:`jaxswarm.runtime.native`), bit for bit the XLA implementation's walks: the same draws
(threefry2x32's ``fold_in`` and ``uniform``, from each walk's key data), the same choice rules
(a fixed table's row, or IWD's soil rule) and the same masked sampler, operation for operation.
:func:`.native.implementation` picks the implementation when a walk is traced.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime import native


def key_data(keys: jax.Array) -> jax.Array:
    """u32[..., 2] the data of threefry2x32 ``keys`` (typed or raw), as the kernel draws from.

    Raises:
      ValueError: the keys are of another PRNG implementation.
    """
    if str(jax.random.key_impl(keys)) != "threefry2x32":
        raise ValueError(f"the native depth-first walk draws from threefry2x32 keys only, got "
                         f"{jax.random.key_impl(keys)}")
    return jax.random.key_data(keys)


def depth_first_walks(keys: jax.Array, nbr: jax.Array, table: jax.Array, soil, alpha, eps_s,
                      start, goal, *, max_nodes: int, greedy: bool):
    """``W`` depth-first walks over one map and rule, one kernel call.

    Args:
      keys: u32[W, 2] each walk's key data (:func:`key_data`; its ``m``-th move draws from
        ``fold_in(key, m)``).
      nbr: i32[N, K] the map's neighbour table.
      table: f32[N, K] the rule's table (``-inf``: not admissible).
      soil: f32[N, K] IWD's soil (the rule adds ``alpha`` times ``-log(eps_s + g)``), or None:
        the rule is the table's row.
      alpha, eps_s: f32[] the soil rule's numbers (unused without ``soil``).
      start, goal: i32[] node indices.
      max_nodes: the longest path a walk may hold (static).
      greedy: take the most likely move, the first of equals, instead of drawing (static).

    Returns:
      ``(path i32[W, max_nodes], found bool[W], moves i32[W])`` as
      :func:`~.backtrack.depth_first_walk`'s. Under ``vmap`` the batch is one call
      (``vmap_method="broadcast_all"``: every input gets the batch axes, and the kernel walks
      each member's walks over its own map and rule).
    """
    native.register()
    walks = keys.shape[0]
    if soil is None:  # the kernel's sign for the table's rule: an empty soil
        soil, alpha, eps_s = jnp.zeros((0,) + table.shape[1:], jnp.float32), 0.0, 0.0
    shapes = (jax.ShapeDtypeStruct((walks, max_nodes), jnp.int32),  # path
              jax.ShapeDtypeStruct((walks,), jnp.bool_),  # found
              jax.ShapeDtypeStruct((walks,), jnp.int32))  # moves
    return jax.ffi.ffi_call(native.DEPTH_FIRST_TARGET, shapes, vmap_method="broadcast_all")(
        jnp.asarray(keys, jnp.uint32), jnp.asarray(table, jnp.float32),
        jnp.asarray(soil, jnp.float32), jnp.asarray(alpha, jnp.float32),
        jnp.asarray(eps_s, jnp.float32), jnp.asarray(nbr, jnp.int32),
        jnp.asarray(start, jnp.int32), jnp.asarray(goal, jnp.int32),
        greedy=np.int32(greedy),
        partitionable=np.int32(jax.config.jax_threefry_partitionable))
