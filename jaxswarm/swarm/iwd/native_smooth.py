"""IWD_PG's global smooth operator (:mod:`.smooth`) as one native kernel call on CPU (issue 67;
``docs/native.md``).

:func:`smooth_rows` smooths every selected path of a batch with the C++ handler ``smooth.cc``
(:mod:`jaxswarm.runtime.native`), bit for bit the XLA passes' paths: the lengths of
:func:`~.smooth.lattice_costs` on grids and path maps and of :func:`~.smooth.graph_costs` on
other graphs, the same sums and threshold comparisons in the same order, passes until one
changes nothing. :func:`jaxswarm.swarm.walking.native.implementation` picks the implementation
when :func:`~.smooth.smooth_paths` is traced.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime import native
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import slot_lengths


def smooth_rows(graph: Graph, paths: jax.Array, which: jax.Array, improvement: float):
    """i32[A, W]: each path of ``paths`` (i32[A, W], -1 padded walks on the current map) where
    ``which`` (bool[A]) after passes of the smooth operator until one changes nothing, the
    others as they were; ``improvement`` the threshold (:data:`~.smooth.IMPROVEMENT`).

    The kernel takes the map's valid edges (bool[N, K]) and, on a general graph, its ``nbr``
    and ``cost`` (i32 and f32[N, K]); on a grid or path map an empty ``nbr`` (i32[0, K]), the
    slots' lengths (f32[1, K]) and the width (an attribute), from which it finds moves by the
    cells' coordinates as :func:`~.smooth.lattice_costs` does. Under ``vmap`` the batch is one
    call (``vmap_method="broadcast_all"``: every input gets the batch axes, and the kernel
    smooths each member's paths on its own map).
    """
    native.register()
    if graph.is_grid:
        width = graph.shape[1]
        nbr = jnp.zeros((0, graph.max_degree), jnp.int32)
        cost = jnp.asarray(slot_lengths(graph))[None]
    else:
        width, nbr, cost = 0, jnp.asarray(graph.nbr, jnp.int32), jnp.asarray(graph.cost,
                                                                             jnp.float32)
    return jax.ffi.ffi_call(native.SMOOTH_TARGET, jax.ShapeDtypeStruct(paths.shape, jnp.int32),
                            vmap_method="broadcast_all")(
        jnp.asarray(paths, jnp.int32), jnp.asarray(which, jnp.bool_), graph.valid_edges(), nbr,
        cost, width=np.int32(width), improvement=np.float32(improvement))
