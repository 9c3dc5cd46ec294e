"""Maps as dense, padded adjacency tensors.

An ``N``-node map whose nodes have at most ``K`` neighbours is stored as fixed-shape arrays
(``nbr``, ``cost``, ``xy``, ``free``, ``open``, ``corner``, ``rev``). Whether an edge can be used is
derived on the fly by :meth:`Graph.valid_edges`, so blocking a cell or closing a thin wall is a
write into ``free`` or ``open`` and never changes a shape (see :mod:`jaxswarm.world.edits`).

Direction slots and move lengths are in :mod:`jaxswarm.world.lattice`, the min-plus relaxation over
neighbours in :mod:`jaxswarm.world.relax`. Conventions follow the Moving AI benchmark: 8-connected,
diagonal cost sqrt(2), no corner cutting.
"""
from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.world.lattice import DIRECTIONS, OPPOSITE

NO_NODE = -1
"""Sentinel for 'no neighbour' in ``nbr``, ``corner`` and ``rev``, and for padding in paths."""
MAX_DENSE_NODES = 4096


@dataclasses.dataclass(frozen=True, eq=False)
class Graph:
    """A map as padded adjacency tensors (a JAX pytree; ``shape`` is static metadata).

    Attributes:
      nbr: i32[N, K] neighbour node of each slot, ``NO_NODE`` (-1) where the lattice has none.
      cost: f32[N, K] edge length (on grids and path maps the length of the slot's move, 1 or
        sqrt 2, see :func:`jaxswarm.world.lattice.slot_lengths`; any positive weight on dense graphs);
        0 where ``nbr`` is -1.
      xy: f32[N, 2] node coordinates, x = column, y = row for grids.
      free: bool[N] passable nodes (edited at run time).
      open: bool[N, K] passable edges, i.e. no thin wall (edited at run time).
      corner: i32[N, K, 2] the two cells a diagonal move squeezes between, which must be free for
        the move to be valid; -1 where nothing is required (orthogonal moves, corner cutting
        allowed, non-grid graphs).
      rev: i32[N, K] slot of the reverse edge in ``nbr[nbr[i, k]]``, -1 if the edge is one-way.
      shape: static ``(H, W)`` of a grid or path map, ``None`` for a general graph.

    Graphs compare by identity (``eq=False``) so host-side caches can key on them.
    """

    nbr: jax.Array
    cost: jax.Array
    xy: jax.Array
    free: jax.Array
    open: jax.Array
    corner: jax.Array
    rev: jax.Array
    shape: tuple[int, int] | None = None

    @property
    def num_nodes(self) -> int:
        """N, the number of nodes (static)."""
        return self.nbr.shape[-2]

    @property
    def max_degree(self) -> int:
        """K, the number of neighbour slots per node (static)."""
        return self.nbr.shape[-1]

    @property
    def is_grid(self) -> bool:
        """True for occupancy grids and path maps, whose node ``i`` is cell ``(i % W, i // W)``."""
        return self.shape is not None

    def valid_edges(self) -> jax.Array:
        """bool[N, K]: edges usable now (lattice edge, open, both ends free, corners free)."""
        return _valid_edges(self)

    def to_dense(self) -> np.ndarray:
        """f64[N, N] weight matrix of the valid edges: 0 on the diagonal, inf where no edge.

        Meant for small graphs (at most ``MAX_DENSE_NODES`` nodes); raises ValueError above that.
        """
        n = self.num_nodes
        if n > MAX_DENSE_NODES:
            raise ValueError(f"to_dense() is for small graphs: {n} nodes > {MAX_DENSE_NODES}")
        valid = np.asarray(self.valid_edges())
        rows, slots = np.nonzero(valid)
        dense = np.full((n, n), np.inf)
        # Several slots may point at one neighbour in a general graph: keep the cheapest.
        np.minimum.at(dense, (rows, np.asarray(self.nbr)[rows, slots]),
                      np.asarray(self.cost, dtype=np.float64)[rows, slots])
        np.fill_diagonal(dense, 0.0)
        return dense


@jax.jit
def _valid_edges(graph: Graph) -> jax.Array:
    has_nbr = graph.nbr >= 0
    target_free = jnp.take(graph.free, jnp.where(has_nbr, graph.nbr, 0), axis=-1)
    corner_free = jnp.take(graph.free, jnp.where(graph.corner >= 0, graph.corner, 0), axis=-1)
    corners_ok = jnp.all((graph.corner < 0) | corner_free, axis=-1)
    return has_nbr & graph.open & graph.free[..., :, None] & target_free & corners_ok


jax.tree_util.register_dataclass(
    Graph,
    data_fields=["nbr", "cost", "xy", "free", "open", "corner", "rev"],
    meta_fields=["shape"],
)


def grid_graph(obstacles, *, connectivity: int = 8, corner_cutting: bool = False) -> Graph:
    """Graph of an occupancy grid.

    Args:
      obstacles: bool[H, W] (or 0/1 ints), True where a cell is blocked; indexed ``[y, x]``.
      connectivity: 8 (default; diagonal cost sqrt 2) or 4 (K = 4, orthogonal moves only).
      corner_cutting: allow a diagonal move between two blocked orthogonal cells (default False,
        the Moving AI convention).

    Returns:
      A Graph with N = H * W nodes (node ``y * W + x``) and K = ``connectivity``.
    """
    blocked = _as_bool_grid(obstacles, "obstacles")
    if connectivity not in (4, 8):
        raise ValueError(f"connectivity must be 4 or 8, got {connectivity!r}")
    height, width = blocked.shape
    nbr, cost, corner = _lattice(height, width, connectivity)
    if corner_cutting:
        corner = np.full_like(corner, NO_NODE)
    return _assemble(nbr, cost, _grid_xy(height, width), ~blocked.reshape(-1), nbr >= 0,
                     corner, shape=(height, width))


def path_map_graph(connections, *, directed: bool = False) -> Graph:
    """Graph of a thin-wall "path map" (the Max-Min ACO paper's x * y * 8 matrix).

    Every cell is passable; ``connections[y, x, k]`` is 1 where the move in direction slot ``k``
    (this module's ``DIRECTIONS`` order) is open and 0 where a thin wall closes it. Diagonal moves
    are not subject to the corner rule (walls are between cells, not cells).

    Args:
      connections: bool or 0/1 array [H, W, 8].
      directed: if False (default) an edge is open only when both of its ends say so, so a wall
        blocks both ways; if True each direction is taken as given.

    Returns:
      A Graph with N = H * W nodes, K = 8, all nodes free.
    """
    conn = np.asarray(connections)
    if conn.ndim != 3 or conn.shape[2] != 8:
        raise ValueError(f"connections must have shape [H, W, 8], got {conn.shape}")
    if conn.shape[0] == 0 or conn.shape[1] == 0:
        raise ValueError(f"connections must be non-empty, got shape {conn.shape}")
    if not np.isin(conn, (0, 1)).all():
        raise ValueError("connections must hold only 0/1 (or booleans)")
    height, width = conn.shape[:2]
    nbr, cost, _ = _lattice(height, width, 8)
    flat = conn.reshape(height * width, 8).astype(bool)
    is_open = flat & (nbr >= 0)
    if not directed:
        back = flat[np.where(nbr >= 0, nbr, 0), OPPOSITE[None, :]]
        is_open &= back
    no_corner = np.full(nbr.shape + (2,), NO_NODE, dtype=np.int32)
    return _assemble(nbr, cost, _grid_xy(height, width), np.ones(height * width, bool), is_open,
                     no_corner, shape=(height, width))


def dense_graph(weights, xy=None) -> Graph:
    """Graph of a small general graph given by an N x N weight matrix.

    Args:
      weights: f[N, N]; ``weights[i, j]`` is the length of the directed edge i -> j. Entries that
        are 0 or inf mean "no edge"; the diagonal is ignored. Negative or NaN entries are errors.
      xy: optional f[N, 2] node coordinates (used by plots and A*'s heuristics); zeros if omitted,
        which makes the geometric heuristics zero (A* then behaves as Dijkstra).

    Returns:
      A Graph with K = the largest out-degree (at least 1), all nodes free, ``shape=None``.
    """
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 2 or w.shape[0] != w.shape[1] or w.shape[0] == 0:
        raise ValueError(f"weights must be a non-empty square matrix, got shape {w.shape}")
    if np.isnan(w).any():
        raise ValueError("weights contain NaN")
    if (w < 0).any():
        raise ValueError("weights must be non-negative (0 or inf = no edge)")
    n = w.shape[0]
    if n > MAX_DENSE_NODES:
        raise ValueError(f"dense_graph is for small graphs: {n} nodes > {MAX_DENSE_NODES}")
    is_edge = (w > 0) & np.isfinite(w)
    np.fill_diagonal(is_edge, False)
    k = max(int(is_edge.sum(axis=1).max()), 1)
    nbr = np.full((n, k), NO_NODE, dtype=np.int32)
    cost = np.zeros((n, k), dtype=np.float32)
    for i in range(n):
        targets = np.nonzero(is_edge[i])[0]
        nbr[i, : len(targets)] = targets
        cost[i, : len(targets)] = w[i, targets]
    if xy is None:
        coords = np.zeros((n, 2), dtype=np.float32)
    else:
        coords = np.asarray(xy, dtype=np.float32)
        if coords.shape != (n, 2):
            raise ValueError(f"xy must have shape ({n}, 2), got {coords.shape}")
    no_corner = np.full((n, k, 2), NO_NODE, dtype=np.int32)
    return _assemble(nbr, cost, coords, np.ones(n, bool), nbr >= 0, no_corner, shape=None)


def _as_bool_grid(array, name: str) -> np.ndarray:
    grid = np.asarray(array)
    if grid.ndim != 2 or grid.shape[0] == 0 or grid.shape[1] == 0:
        raise ValueError(f"{name} must be a non-empty 2-D array [H, W], got shape {grid.shape}")
    if grid.dtype != bool and not np.isin(grid, (0, 1)).all():
        raise ValueError(f"{name} must hold booleans or 0/1")
    return grid.astype(bool)


def _grid_xy(height: int, width: int) -> np.ndarray:
    ys, xs = np.divmod(np.arange(height * width), width)
    return np.stack([xs, ys], axis=1).astype(np.float32)


def _lattice(height: int, width: int, connectivity: int):
    """Neighbour, cost and corner tables of an H x W lattice (numpy, host side)."""
    moves = DIRECTIONS[:connectivity]
    ys, xs = np.divmod(np.arange(height * width), width)
    nx = xs[:, None] + moves[None, :, 0]
    ny = ys[:, None] + moves[None, :, 1]

    def index(cx, cy):
        inside = (cx >= 0) & (cx < width) & (cy >= 0) & (cy < height)
        return np.where(inside, cy * width + cx, NO_NODE).astype(np.int32)

    nbr = index(nx, ny)
    diagonal = (moves[:, 0] != 0) & (moves[:, 1] != 0)
    cost = np.where(diagonal, math.sqrt(2.0), 1.0)[None, :] * (nbr >= 0)
    # A diagonal move (dx, dy) squeezes between (x + dx, y) and (x, y + dy).
    same_y = np.broadcast_to(ys[:, None], ny.shape)
    same_x = np.broadcast_to(xs[:, None], nx.shape)
    corner = np.stack([index(nx, same_y), index(same_x, ny)], axis=-1)
    corner = np.where(diagonal[None, :, None], corner, NO_NODE)
    corner = np.where((nbr >= 0)[..., None], corner, NO_NODE).astype(np.int32)
    return nbr, cost.astype(np.float32), corner


def _reverse_slots(nbr: np.ndarray) -> np.ndarray:
    """i32[N, K]: for each edge i -> j (slot k), the slot k' with nbr[j, k'] == i, else -1."""
    n, k = nbr.shape
    rev = np.full((n, k), NO_NODE, dtype=np.int32)
    rows, slots = np.nonzero(nbr >= 0)
    targets = nbr[rows, slots]
    back = nbr[targets] == rows[:, None]  # [E, K]
    has_back = back.any(axis=1)
    rev[rows[has_back], slots[has_back]] = back[has_back].argmax(axis=1)
    return rev


def _assemble(nbr, cost, xy, free, is_open, corner, *, shape) -> Graph:
    return Graph(
        nbr=jnp.asarray(nbr, dtype=jnp.int32),
        cost=jnp.asarray(cost, dtype=jnp.float32),
        xy=jnp.asarray(xy, dtype=jnp.float32),
        free=jnp.asarray(free, dtype=bool),
        open=jnp.asarray(is_open, dtype=bool),
        corner=jnp.asarray(corner, dtype=jnp.int32),
        rev=jnp.asarray(_reverse_slots(np.asarray(nbr)), dtype=jnp.int32),
        shape=shape,
    )
