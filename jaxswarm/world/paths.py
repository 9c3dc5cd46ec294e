"""Padded paths: the common ``Solution`` type, validity, length, node <-> (x, y) conversion.

A path is an ``i32[L]`` array of node indices from start to goal followed by ``NO_NODE`` (-1)
padding. All array functions here are pure ``jax.numpy`` (jittable, vmappable over paths);
:func:`as_node` and :func:`trim` are host-side helpers.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.world.graph import NO_NODE, Graph
from jaxswarm.world.lattice import total_length


@dataclasses.dataclass(frozen=True)
class Solution:
    """A planner's answer (a JAX pytree).

    Attributes:
      path: i32[L] node indices start..goal, -1 padded; all -1 when nothing was found.
      cost: f[] path length (float32 from JAX planners, float64 from the host exact planners);
        inf when nothing was found.
      found: bool[] whether ``path`` reaches the goal.
      stats: planner-specific statistics (e.g. :class:`jaxswarm.exact.SearchStats`) or None.
    """

    path: Any
    cost: Any
    found: Any
    stats: Any = None

    def nodes(self) -> np.ndarray:
        """The path without padding, as a host i32 array."""
        return trim(self.path)


jax.tree_util.register_dataclass(
    Solution, data_fields=["path", "cost", "found", "stats"], meta_fields=[]
)


def node_index(graph: Graph, x, y):
    """i32[...]: node index of grid cell(s) (x, y); jittable, no bounds check (see as_node)."""
    _require_grid(graph)
    width = graph.shape[1]
    return (jnp.asarray(y, jnp.int32) * width + jnp.asarray(x, jnp.int32)).astype(jnp.int32)


def node_xy(graph: Graph, nodes) -> jax.Array:
    """f32[..., 2]: coordinates (x, y) of nodes; NaN for padding (-1)."""
    nodes = jnp.asarray(nodes)
    xy = graph.xy[jnp.where(nodes >= 0, nodes, 0)]
    return jnp.where((nodes >= 0)[..., None], xy, jnp.nan)


def as_node(graph: Graph, point, *, name: str = "node", require_free: bool = True) -> int:
    """Host-side: turn ``point`` into a node index, with a clear error if it is unusable.

    Args:
      graph: the map.
      point: an (x, y) pair (grid cell, or exact coordinates of a general graph's node) or an int
        node index.
      name: what the point is ("start", "goal"), for error messages.
      require_free: raise if the node is an obstacle.

    Returns:
      The node index as a Python int.

    Raises:
      ValueError: off the map, not a node, or blocked.
    """
    n = graph.num_nodes
    if np.ndim(point) == 0:
        node = int(point)
        if not 0 <= node < n:
            raise ValueError(f"{name} node {node} is off the map (nodes 0..{n - 1})")
    else:
        if np.size(point) != 2:
            raise ValueError(f"{name} must be an (x, y) pair or a node index, got {point!r}")
        x, y = (float(v) for v in np.asarray(point).reshape(-1))
        if graph.is_grid:
            height, width = graph.shape
            if not (x == int(x) and y == int(y) and 0 <= x < width and 0 <= y < height):
                raise ValueError(f"{name} {tuple(point)} is off the {width}x{height} map")
            node = int(y) * width + int(x)
        else:
            matches = np.nonzero(np.all(np.asarray(graph.xy) == (x, y), axis=1))[0]
            if len(matches) != 1:
                raise ValueError(f"{name} {tuple(point)} names {len(matches)} nodes; pass an index")
            node = int(matches[0])
    if require_free and not np.asarray(graph.free)[node]:
        raise ValueError(f"{name} {point!r} is blocked (an obstacle)")
    return node


def trim(path) -> np.ndarray:
    """Host-side: i32[M] the nodes of a padded path, padding removed."""
    path = np.asarray(path)
    return path[path >= 0]


def pad(nodes, length: int) -> np.ndarray:
    """Host-side: i32[length] the node sequence followed by -1 padding."""
    nodes = np.asarray(nodes, dtype=np.int32).reshape(-1)
    if len(nodes) > length:
        raise ValueError(f"path of {len(nodes)} nodes does not fit a buffer of {length}")
    out = np.full(length, NO_NODE, dtype=np.int32)
    out[: len(nodes)] = nodes
    return out


@jax.jit
def step_slots(graph: Graph, path) -> jax.Array:
    """i32[L-1]: for each step ``path[t] -> path[t+1]`` the neighbour slot it uses.

    -1 where the step is padding or where ``path[t+1]`` is not a lattice neighbour of ``path[t]``.
    """
    path = jnp.asarray(path)
    here, there = path[:-1], path[1:]
    rows = graph.nbr[jnp.where(here >= 0, here, 0)]  # [L-1, K]
    match = (rows == there[:, None]) & (here >= 0)[:, None] & (there >= 0)[:, None]
    return jnp.where(match.any(axis=1), jnp.argmax(match, axis=1), NO_NODE)


@jax.jit
def path_length(graph: Graph, path) -> jax.Array:
    """f32[]: sum of the edge lengths along a padded path (by :func:`jaxswarm.world.lattice.total_length`,
    as the swarms' walks are measured); inf if a step is not an edge.

    A path of one node (start == goal) has length 0; an all-padding path has length inf.
    """
    path = jnp.asarray(path)
    slots = step_slots(graph, path)
    is_step = (path[:-1] >= 0) & (path[1:] >= 0)
    here = jnp.where(path[:-1] >= 0, path[:-1], 0)
    broken = jnp.any(is_step & (slots < 0)) | (path[0] < 0)
    return jnp.where(broken, jnp.inf, total_length(graph, here, jnp.where(is_step, slots, -1)))


@jax.jit
def is_valid_path(graph: Graph, path, start=None, goal=None) -> jax.Array:
    """bool[]: every step is a valid edge of the current map (see ``Graph.valid_edges``).

    Also checks that the padding is a suffix (no holes), that the first node is free, and, when
    given, that the path begins at node ``start`` and ends at node ``goal``.
    """
    path = jnp.asarray(path)
    real = path >= 0
    contiguous = jnp.all(real[:-1] | ~real[1:]) & real[0]
    slots = step_slots(graph, path)
    is_step = real[:-1] & real[1:]
    valid = graph.valid_edges()
    here = jnp.where(real[:-1], path[:-1], 0)
    step_ok = valid[here, jnp.where(slots >= 0, slots, 0)] & (slots >= 0)
    ok = contiguous & graph.free[jnp.where(real[0], path[0], 0)] & jnp.all(step_ok | ~is_step)
    if start is not None:
        ok &= path[0] == start
    if goal is not None:
        last = path[jnp.maximum(jnp.sum(real) - 1, 0)]
        ok &= last == goal
    return ok


def _require_grid(graph: Graph) -> None:
    if not graph.is_grid:
        raise ValueError("this map is a general graph, not a grid: use node indices")
