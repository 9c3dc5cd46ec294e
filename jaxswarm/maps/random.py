"""Seeded random maps.

* :func:`random_grid`: a square occupancy grid with the start and goal in opposite corners and a
  guaranteed path between them (the set-up of the A* / bidirectional A* report): random
  obstacles, then a random monotone staircase from corner to corner is cleared.
* :func:`random_path_map`: a thin-wall "path map" (the Max-Min ACO paper's x * y * 8 matrix): a
  random spanning tree of orthogonal passages (so every cell is reachable, as in the paper) plus
  extra random passages in all eight directions.

Both take an integer seed and are deterministic (numpy's PCG64 generator, no global state).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from jaxswarm.world.lattice import DIRECTIONS, OPPOSITE


@dataclasses.dataclass(frozen=True)
class RandomGrid:
    """A random occupancy grid and its query.

    Attributes:
      obstacles: bool[size, size], True = blocked, indexed [y, x].
      start: (0, 0); goal: (size - 1, size - 1), both (x, y).
    """

    obstacles: np.ndarray
    start: tuple[int, int]
    goal: tuple[int, int]


def random_grid(size: int, seed: int, *, density: float = 0.3) -> RandomGrid:
    """A size x size grid with about ``density`` of its cells blocked and a corner-to-corner path.

    Args:
      size: cells per side (>= 2).
      seed: integer seed.
      density: probability that a cell is an obstacle before the path is cleared, in [0, 1).

    Returns:
      RandomGrid with start (0, 0) and goal (size - 1, size - 1).
    """
    if size < 2:
        raise ValueError(f"size must be at least 2, got {size}")
    if not 0.0 <= density < 1.0:
        raise ValueError(f"density must be in [0, 1), got {density}")
    rng = np.random.default_rng(seed)
    obstacles = rng.random((size, size)) < density
    # A staircase of (size - 1) right and (size - 1) down moves in random order.
    moves = rng.permutation(np.repeat([0, 1], size - 1))
    xs = np.concatenate([[0], np.cumsum(moves == 0)])
    ys = np.concatenate([[0], np.cumsum(moves == 1)])
    obstacles[ys, xs] = False
    obstacles.setflags(write=False)
    return RandomGrid(obstacles=obstacles, start=(0, 0), goal=(size - 1, size - 1))


def random_path_map(width: int, height: int, seed: int, *, extra: float = 0.3) -> np.ndarray:
    """Connections u8[height, width, 8] of a random thin-wall path map (symmetric walls).

    Args:
      width, height: cells in x and y (each >= 1, at least 2 cells in all).
      seed: integer seed.
      extra: probability that each lattice edge not in the spanning tree is open too, in [0, 1].

    Returns:
      ``conn[y, x, k] == 1`` where the move in direction slot k
      (:data:`jaxswarm.world.lattice.DIRECTIONS`) is open; ``conn`` is symmetric (a move is open iff
      its reverse is) and connects every cell. Feed it to
      :func:`jaxswarm.world.graph.path_map_graph`.
    """
    if width < 1 or height < 1 or width * height < 2:
        raise ValueError(f"a path map needs at least 2 cells, got {width}x{height}")
    if not 0.0 <= extra <= 1.0:
        raise ValueError(f"extra must be in [0, 1], got {extra}")
    rng = np.random.default_rng(seed)
    conn = np.zeros((height, width, 8), dtype=np.uint8)
    for y in range(height):  # extra passages, drawn once per undirected edge (slots E, S, SE, SW)
        for x in range(width):
            for k in (0, 1, 4, 5):
                if rng.random() < extra:
                    _open(conn, x, y, k)
    _carve_spanning_tree(conn, rng)
    return conn


def _open(conn: np.ndarray, x: int, y: int, k: int) -> None:
    height, width = conn.shape[:2]
    nx, ny = x + DIRECTIONS[k, 0], y + DIRECTIONS[k, 1]
    if 0 <= nx < width and 0 <= ny < height:
        conn[y, x, k] = 1
        conn[ny, nx, OPPOSITE[k]] = 1


def _carve_spanning_tree(conn: np.ndarray, rng: np.random.Generator) -> None:
    """Open a random depth-first spanning tree of orthogonal passages (every cell reachable)."""
    height, width = conn.shape[:2]
    seen = np.zeros((height, width), dtype=bool)
    stack = [(int(rng.integers(width)), int(rng.integers(height)))]
    seen[stack[0][1], stack[0][0]] = True
    while stack:
        x, y = stack[-1]
        options = [k for k in range(4)
                   if 0 <= x + DIRECTIONS[k, 0] < width and 0 <= y + DIRECTIONS[k, 1] < height
                   and not seen[y + DIRECTIONS[k, 1], x + DIRECTIONS[k, 0]]]
        if not options:
            stack.pop()
            continue
        k = options[int(rng.integers(len(options)))]
        _open(conn, x, y, k)
        nx, ny = x + int(DIRECTIONS[k, 0]), y + int(DIRECTIONS[k, 1])
        seen[ny, nx] = True
        stack.append((nx, ny))
