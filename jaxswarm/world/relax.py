"""The min-plus relaxation: every node's cheapest way to a neighbour, swept to a fixpoint.

The distance field of the exact planners (:mod:`jaxswarm.exact.field`) and ``rfd_graded``'s
settling and bank erosion are all this one operation with another update rule.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import jax
import jax.numpy as jnp

from jaxswarm.world.lattice import DIRECTIONS

if TYPE_CHECKING:
    from jaxswarm.world.graph import Graph


def lowest_neighbour(graph: Graph, values: jax.Array, extra: jax.Array) -> jax.Array:
    """f32[N]: ``min_k values[nbr[:, k]] + extra[:, k]``, the cheapest way to a neighbour.

    Args:
      graph: the map.
      values: f32[N] a value per node.
      extra: f32[N, K] a cost per edge slot; put ``inf`` where a slot must not count (no
        neighbour, or an edge not valid now), since ``values`` is read there arbitrarily.

    Returns:
      f32[N]; ``inf`` for a node whose slots are all ``inf``.

    On grids and path maps the neighbour of slot ``k`` is the cell shifted by ``DIRECTIONS[k]``,
    so the values are read by slicing the [H, W] array; on general graphs by one gather per
    slot. Both are several times faster on CPU than gathering the f32[N, K] table at once.
    To apply it over and over, use :func:`relax` (it keeps the values in that layout).
    """
    return _lowest(graph, _pack(graph, values), _by_slot(graph, extra)).reshape(-1)


def relax(graph: Graph, values: jax.Array, extra: jax.Array, update, *, max_sweeps: int,
          sweeps_per_check: int = 1):
    """Sweep ``values <- update(values, lowest_neighbour(graph, values, extra))`` until a
    sweep changes nothing or ``max_sweeps`` sweeps have run.

    Every sweep updates all nodes at once (Jacobi). The values stay in the layout the
    neighbours are read from (on grids an [H + 2, W + 2] array with a border, updated in place),
    which makes a sweep about twice as fast as calling :func:`lowest_neighbour` each time.

    Args:
      graph: the map.
      values: f32[N] start values.
      extra: f32[N, K] cost per edge slot, ``inf`` where a slot must not count.
      update: ``(values, lowest) -> (new_values, changed)``, elementwise on arrays of one shape
        (``[H, W]`` on grids, ``[N]`` otherwise): the new values and where they changed.
      max_sweeps: most sweeps (static).
      sweeps_per_check: sweeps between two tests of whether anything changed (static); the
        extra sweeps after the last change change nothing.

    Returns:
      ``(f32[N] values, i32[] sweeps run)``.
    """
    by_slot = _by_slot(graph, extra)

    def sweep(carry):
        packed, sweeps, _ = carry
        changed = False
        for _ in range(sweeps_per_check):
            here = _interior(graph, packed)
            new, moved = update(here, _lowest(graph, packed, by_slot))
            packed = _with_interior(graph, packed, new)
            changed = changed | jnp.any(moved)
        return packed, sweeps + sweeps_per_check, changed

    def unsettled(carry):
        _, sweeps, changed = carry
        return changed & (sweeps < max_sweeps)

    packed, sweeps, _ = jax.lax.while_loop(
        unsettled, sweep, (_pack(graph, values), jnp.int32(0), jnp.array(True)))
    return _unpack(graph, packed), sweeps


def _pack(graph: Graph, values):
    """Node values in the layout neighbours are read from: [H + 2, W + 2] (0 border) on grids,
    [N] otherwise."""
    return jnp.pad(values.reshape(graph.shape), 1) if graph.is_grid else values


def _interior(graph: Graph, packed):
    return packed[1:-1, 1:-1] if graph.is_grid else packed


def _with_interior(graph: Graph, packed, values):
    return packed.at[1:-1, 1:-1].set(values) if graph.is_grid else values


def _unpack(graph: Graph, packed):
    return _interior(graph, packed).reshape(-1)


def _by_slot(graph: Graph, extra):
    """Per-slot costs f32[N, K] in the layout of :func:`_lowest`: [K, H, W] on grids."""
    return extra.T.reshape(-1, *graph.shape) if graph.is_grid else extra


def _lowest(graph: Graph, packed, by_slot):
    """``min_k`` (value of the slot-k neighbour + its cost), shaped like ``_interior``."""
    if graph.is_grid:
        height, width = graph.shape

        def at_slot(k):
            dx, dy = DIRECTIONS[k]
            return packed[1 + dy:1 + dy + height, 1 + dx:1 + dx + width] + by_slot[k]
    else:
        heads = jnp.where(graph.nbr >= 0, graph.nbr, 0)

        def at_slot(k):
            return packed[heads[:, k]] + by_slot[:, k]

    lowest = at_slot(0)
    for k in range(1, graph.max_degree):
        lowest = jnp.minimum(lowest, at_slot(k))
    return lowest
