"""Pure, shape-preserving map edits.

Each edit returns a new :class:`~jaxswarm.world.graph.Graph` whose ``free`` or ``open`` array
differs; no shape changes, so a jitted planner called on the edited map does not recompile. The node
and slot arguments may be traced arrays (the edits are jittable and vmappable).
"""
from __future__ import annotations

import dataclasses

import jax.numpy as jnp

from jaxswarm.world.graph import Graph


def block_cells(graph: Graph, nodes) -> Graph:
    """Mark nodes as obstacles.

    Args:
      graph: the map.
      nodes: int or i32[M] node indices (see :func:`jaxswarm.world.paths.node_index`).

    Returns:
      The map with ``free[nodes] = False``; every edge touching them (and every diagonal squeezing
      past them when corner cutting is forbidden) becomes invalid.
    """
    return dataclasses.replace(graph, free=graph.free.at[jnp.asarray(nodes)].set(False))


def unblock_cells(graph: Graph, nodes) -> Graph:
    """Mark nodes as passable (``free[nodes] = True``); the inverse of :func:`block_cells`."""
    return dataclasses.replace(graph, free=graph.free.at[jnp.asarray(nodes)].set(True))


def close_edges(graph: Graph, nodes, slots) -> Graph:
    """Put thin walls on edges: ``nodes[m] -> nbr[nodes[m], slots[m]]`` and its reverse edge.

    Args:
      graph: the map.
      nodes: int or i32[M] source nodes.
      slots: int or i32[M] neighbour slots (grid direction indices, see
        :data:`jaxswarm.world.lattice.DIRECTIONS`).

    Returns:
      The map with both directions of each edge closed. Slots without a neighbour, and nodes
      outside ``0..N-1`` (padding), are ignored.
    """
    return _set_edges(graph, nodes, slots, False)


def open_edges(graph: Graph, nodes, slots) -> Graph:
    """Remove thin walls from edges (both directions); the inverse of :func:`close_edges`.

    Slots without a neighbour stay closed, so an edit never creates an edge off the lattice.
    """
    return _set_edges(graph, nodes, slots, True)


def _set_edges(graph: Graph, nodes, slots, value: bool) -> Graph:
    nodes, slots = jnp.broadcast_arrays(jnp.asarray(nodes), jnp.asarray(slots))
    n = graph.num_nodes
    on_map = (nodes >= 0) & (nodes < n)
    rows = jnp.where(on_map, nodes, 0)
    target = graph.nbr[rows, slots]
    back_slot = graph.rev[rows, slots]
    exists = on_map & (target >= 0)
    # Indices of n (out of bounds) are dropped: JAX would wrap -1 to the last node.
    fwd_rows = jnp.where(exists, nodes, n)
    back_rows = jnp.where(exists & (back_slot >= 0), target, n)
    is_open = graph.open.at[fwd_rows, slots].set(value, mode="drop")
    is_open = is_open.at[back_rows, back_slot].set(value, mode="drop")
    return dataclasses.replace(graph, open=is_open)
