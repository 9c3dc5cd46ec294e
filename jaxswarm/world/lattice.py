"""Lattice geometry: the direction slots of grids and path maps, move lengths, straight lines.

Grid direction order (defined once, here): the four orthogonal moves first, then the diagonals,
with ``y`` growing downwards (row index)::

    k:   0  1  2  3   4   5   6   7
         E  S  W  N   SE  SW  NW  NE

so a 4-connected grid uses the first four slots and ``OPPOSITE[k]`` is the reverse move. On a
grid or path map a slot's neighbour and length are fixed (:func:`slot_offsets`,
:func:`slot_lengths`), and lengths are counted by kind of move (:func:`total_length`), so the same
moves in any order have bit-identical lengths.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.arithmetic import ordered_sum

if TYPE_CHECKING:
    from jaxswarm.world.graph import Graph

DIRECTIONS = np.array(
    [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1)], dtype=np.int32
)
"""i32[8, 2]: the (dx, dy) of each grid direction slot."""
DIRECTION_NAMES = ("E", "S", "W", "N", "SE", "SW", "NW", "NE")
ORTHOGONAL_SLOTS = 4
"""The first four slots are the orthogonal moves (length 1), the rest diagonal (sqrt 2)."""
SQRT2 = np.float32(math.sqrt(2.0))
OPPOSITE = np.array([2, 3, 0, 1, 6, 7, 4, 5], dtype=np.int32)
"""i32[8]: ``OPPOSITE[k]`` is the slot of the move that undoes move ``k``."""


def straight_line(graph: Graph, node) -> jax.Array:
    """f32[N]: the straight-line (Cartesian) distance from every node's ``xy`` to that of
    ``node`` (i32[], may be traced): the goal-distance heuristic of RFD* and ACO*."""
    return jnp.linalg.norm(graph.xy - graph.xy[node], axis=-1)


def slot_offsets(graph: Graph) -> np.ndarray:
    """i32[K] (static, host side): on a grid or path map, how far along the node numbering
    each slot's neighbour lies, ``dx + W dy``: node ``i``'s slot-``k`` neighbour, when the
    lattice has one, is node ``i + offsets[k]``."""
    require_lattice(graph)
    return (DIRECTIONS[:graph.max_degree] @ np.array([1, graph.shape[1]])).astype(np.int32)


def slot_lengths(graph: Graph) -> np.ndarray:
    """f32[K] (static, host side): on a grid or path map, the length of a move in each slot
    (1 orthogonal, sqrt 2 diagonal), the value of ``cost`` wherever the slot has a neighbour."""
    require_lattice(graph)
    return np.hypot(*DIRECTIONS[:graph.max_degree].T).astype(np.float32)


def move_lengths(graph: Graph, nodes: jax.Array, slots: jax.Array) -> jax.Array:
    """f32[...]: the length of each move, edge ``slots`` (i8/i16/i32, -1 for no move) out of
    ``nodes`` (i32, same shape); 0 where the slot is -1. On grids and path maps the length is
    looked up by slot alone (see :func:`slot_lengths`)."""
    slot = jnp.maximum(slots, 0).astype(jnp.int32)
    if graph.is_grid:
        length = jnp.asarray(slot_lengths(graph))[slot]
    else:
        length = graph.cost[nodes, slot]
    return jnp.where(slots >= 0, length, 0.0)


def total_length(graph: Graph, nodes: jax.Array, slots: jax.Array) -> jax.Array:
    """f32[...]: the summed length of the moves along the last axis of ``slots`` (i8/i16/i32
    [..., M], -1 for no move) out of ``nodes`` (i32[..., M]).

    On grids and path maps the orthogonal and the diagonal moves are counted (the orthogonal
    slots come first, see ``DIRECTIONS``) and the counts weighted by their lengths, so walks
    that make the same moves in another order (on an 8-connected grid, many shortest paths do)
    get bit-identical lengths, and a swarm never takes float rounding for an improvement. On
    general graphs the lengths are summed.
    """
    if not graph.is_grid:
        return ordered_sum(move_lengths(graph, nodes, slots), axis=-1)
    return lattice_length(jnp.sum(slots >= 0, axis=-1),
                          jnp.sum(slots >= ORTHOGONAL_SLOTS, axis=-1))


def lattice_length(moves: jax.Array, diagonal: jax.Array) -> jax.Array:
    """f32[...]: the length of ``moves`` (i32[...]) moves on a grid or path map, ``diagonal``
    (i32[...]) of them diagonal; equal counts give bit-identical lengths."""
    return (moves - diagonal).astype(jnp.float32) + diagonal.astype(jnp.float32) * SQRT2


def require_lattice(graph: Graph) -> None:
    """Raise ValueError unless ``graph`` is a grid or path map (its slots have fixed offsets)."""
    if not graph.is_grid:
        raise ValueError("this map is a general graph, not a grid or path map: its slots have "
                         "no fixed offsets or lengths")
