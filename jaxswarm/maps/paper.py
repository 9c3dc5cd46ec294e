"""The RFD paper's nine test maps, rebuilt: maze, mosaic and alley at 20x20, 50x50 and 100x100.

The paper (section 3, Figure 3, Table 1) published only its maps' kind, size, start and goal and
the optimal (Dijkstra) path lengths. :func:`paper_map` builds our own maps in the spirit of its
Figure 3, with the paper's start and goal cells and optima of the same order as the paper's
(:data:`PAPER_OPTIMA`): a seeded perfect **maze** of one-cell corridors with a few loops, a
staggered **mosaic** of square blocks between two-cell lanes, and **alley** walls across the
map, each with one opening, alternately above and below the start-goal row (``docs/papers.md``
says how each is laid out). ``obstacles`` is bool[H, W] indexed [y, x], True = blocked; points
are (x, y), 0-based from the top-left; the optima are for 8-connected moves of cost 1 and
sqrt(2) without corner cutting. Everything is deterministic (a seeded
``numpy.random.default_rng``, no global state).
"""
from __future__ import annotations

import argparse
import dataclasses
import math

import numpy as np

from jaxswarm.world.graph import Graph, grid_graph

PAPER_MAPS: tuple[str, ...] = (
    "mosaic20", "alley20", "maze20",
    "mosaic50", "alley50", "maze50",
    "mosaic100", "alley100", "maze100",
)
"""The nine maps in the column order of the paper's Table 1."""


def by_map(rows: dict[str, tuple]) -> dict[str, dict[str, float | None]]:
    """algorithm -> map -> value, from one tuple per algorithm in the order of PAPER_MAPS."""
    return {algorithm: dict(zip(PAPER_MAPS, values, strict=True))
            for algorithm, values in rows.items()}


PAPER_TABLE1_LENGTH: dict[str, dict[str, float | None]] = by_map({
    "Dijkstra": (18.65, 33.48, 78.62, 50.62, 81.97, 228.52, 116.94, 170.42, 510.56),
    "A*": (18.65, 33.48, 78.62, 50.62, 81.97, 228.52, 116.94, 170.42, 510.56),
    "ACO": (51.68, 138.98, None, 450.65, 1158.61, None, 2749.60, 5435.08, None),
    "ACO*": (18.65, 87.49, None, 55.16, 181.56, None, 211.98, 379.15, None),
    "RFD": (30.21, 117.12, None, 383.1, 839.24, None, 2196.57, 4070.42, None),
    "RFD*": (18.65, 33.48, 78.62, 50.62, 81.97, 228.52, 116.94, 170.42, 510.56),
})
"""The paper's Table 1 (static environment), mean path length per algorithm and map; None where
the paper says n/a (no path found)."""

PAPER_TABLE1_MS: dict[str, dict[str, float | None]] = by_map({
    "Dijkstra": (6.051, 5.787, 6.534, 57.876, 59.333, 46.316, 542.385, 753.503, 445.556),
    "A*": (1.601, 4.453, 6.265, 24.173, 56.662, 48.895, 335.751, 661.118, 448.542),
    "ACO": (650.16, 681.82, None, 10118.72, 10086.02, None, 131071.05, 132445.70, None),
    "ACO*": (71.481, 662.063, None, 4005.241, 6078.251, None, 38630.724, 29628.093, None),
    "RFD": (1213.59, 1279.466, None, 8121.88, 8704.5, None, 33653.09, 46341.6, None),
    "RFD*": (59.548, 103.421, 84.211, 268.349, 291.77, 337.529, 4172.388, 5934.1, 5108.49),
})
"""The paper's Table 1, computation time [ms] (C#, Intel i7-3770); None where it says n/a."""

PAPER_OPTIMA: dict[str, float] = PAPER_TABLE1_LENGTH["Dijkstra"]
"""The paper's published Dijkstra path lengths (Table 1) on its own, unpublished maps."""

# (start, goal) of each map as (x, y), from the paper's section 3.
_ENDPOINTS: dict[str, tuple[tuple[int, int], tuple[int, int]]] = {
    "maze20": ((0, 0), (19, 19)), "mosaic20": ((1, 9), (18, 9)), "alley20": ((3, 9), (16, 9)),
    "maze50": ((0, 0), (49, 49)), "mosaic50": ((2, 24), (46, 24)), "alley50": ((9, 24), (38, 24)),
    "maze100": ((0, 0), (99, 99)), "mosaic100": ((2, 54), (97, 54)),
    "alley100": ((23, 49), (75, 49)),
}

# Maze: one seed and loop probability for all sizes. Optima: maze20 78, maze50 218,
# maze100 518 (paper: 78.62, 228.52, 510.56).
_MAZE_SEED = 146
_MAZE_LOOP_PROBABILITY = 0.02

# Mosaic: size -> (block side, row of the first block in the unshifted columns); the lanes are
# two cells wide and the first block column starts right after the start cell. Optima:
# mosaic20 18.66, mosaic50 50.14, mosaic100 118.21 (paper: 18.65, 50.62, 116.94).
_MOSAIC_LANE = 2
_MOSAIC_LAYOUT: dict[int, tuple[int, int]] = {20: (2, 2), 50: (3, 2), 100: (4, 3)}

# Alley: size -> (walls between start and goal, rows from the start-goal row to the openings).
# Openings are three cells tall; a spur leaves each wall every fourth row. Optima: alley20 32.90,
# alley50 83.87, alley100 170.33 (paper: 33.48, 81.97, 170.42).
_ALLEY_LAYOUT: dict[int, tuple[int, int]] = {20: (3, 5), 50: (4, 8), 100: (5, 15)}
_ALLEY_OPENING = 3
_ALLEY_SPUR_EVERY = 4


@dataclasses.dataclass(frozen=True)
class PaperMap:
    """One of the paper's test maps and its query.

    Attributes:
      name: the map's name, one of ``PAPER_MAPS`` (e.g. "maze20").
      obstacles: bool[H, W], True = blocked, indexed [y, x]; read-only.
      start: the start cell (x, y), free.
      goal: the goal cell (x, y), free and reachable from the start.
    """

    name: str
    obstacles: np.ndarray
    start: tuple[int, int]
    goal: tuple[int, int]

    def graph(self, **grid_options) -> Graph:
        """The map's Graph (8-connected, no corner cutting unless ``grid_options`` say so)."""
        return grid_graph(self.obstacles, **grid_options)


def paper_map_names(text: str) -> tuple[str, ...]:
    """The paper maps named by a command-line list: ``"all"`` or comma-separated names
    (``"mosaic20,maze100"``), in the order given, repeats dropped.

    Raises:
      ValueError: naming the unknown maps, or if the list names none.
    """
    if text.strip() == "all":
        return PAPER_MAPS
    names = tuple(dict.fromkeys(name.strip() for name in text.split(",") if name.strip()))
    unknown = [name for name in names if name not in PAPER_MAPS]
    if unknown or not names:
        problem = f"unknown paper maps {unknown}" if unknown else "no paper map named"
        raise ValueError(f"{problem}; choose from all or {', '.join(PAPER_MAPS)}")
    return names


def paper_maps_argument(text: str) -> tuple[str, ...]:
    """An argparse ``type`` for a ``--maps`` option of the scripts: the paper maps ``text`` names
    (see :func:`paper_map_names`); a bad list is reported as the option's error."""
    try:
        return paper_map_names(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def paper_map(name: str) -> PaperMap:
    """The paper's map ``name`` (one of ``PAPER_MAPS``), built afresh, deterministically.

    Raises:
      ValueError: if ``name`` is not one of ``PAPER_MAPS``.
    """
    if name not in _ENDPOINTS:
        raise ValueError(f"unknown paper map {name!r}; valid names: {', '.join(PAPER_MAPS)}")
    start, goal = _ENDPOINTS[name]
    kind = name.rstrip("0123456789")
    size = int(name[len(kind):])
    if kind == "maze":
        obstacles = _maze(size)
    elif kind == "mosaic":
        obstacles = _mosaic(size, start)
    else:
        obstacles = _alley(size, start, goal)
    obstacles.setflags(write=False)
    return PaperMap(name=name, obstacles=obstacles, start=start, goal=goal)


def _maze(size: int) -> np.ndarray:
    """A size x size maze (size even) from (0, 0) to (size - 1, size - 1), corridors 1 cell wide.

    The (size / 2)^2 lattice cells sit at even (x, y); the walls between them are at odd
    coordinates. The lattice spans rows and columns 0 .. size - 2; the last row and column are
    blocked except the goal and the cell linking it to the last lattice cell.
    """
    rng = np.random.default_rng(_MAZE_SEED)
    lattice = _carve_dfs(size // 2, rng)
    y, x = np.indices(lattice.shape)
    wall_between_cells = lattice & ((x + y) % 2 == 1)
    lattice &= ~(wall_between_cells & (rng.random(lattice.shape) < _MAZE_LOOP_PROBABILITY))
    obstacles = np.ones((size, size), dtype=bool)
    obstacles[: size - 1, : size - 1] = lattice
    obstacles[size - 1, size - 2:] = False  # below the last lattice cell, then the goal
    return obstacles


def _carve_dfs(n: int, rng: np.random.Generator) -> np.ndarray:
    """bool[2n - 1, 2n - 1] (True = blocked) of a perfect maze on n x n cells by randomized DFS.

    Cell (cx, cy) is grid cell (2 cx, 2 cy); carving from cell a to its neighbour b clears b and
    the wall cell between them. The search starts at cell (0, 0).
    """
    blocked = np.ones((2 * n - 1, 2 * n - 1), dtype=bool)
    visited = np.zeros((n, n), dtype=bool)
    visited[0, 0], blocked[0, 0] = True, False
    stack = [(0, 0)]
    while stack:
        cy, cx = stack[-1]
        unvisited = [(cy + dy, cx + dx) for dy, dx in ((0, 1), (1, 0), (0, -1), (-1, 0))
                     if 0 <= cy + dy < n and 0 <= cx + dx < n and not visited[cy + dy, cx + dx]]
        if not unvisited:
            stack.pop()
            continue
        ny, nx = unvisited[rng.integers(len(unvisited))]
        visited[ny, nx] = True
        blocked[2 * ny, 2 * nx] = blocked[cy + ny, cx + nx] = False
        stack.append((ny, nx))
    return blocked


def _mosaic(size: int, start: tuple[int, int]) -> np.ndarray:
    """A size x size staggered field of square blocks separated by two-cell lanes.

    Block columns start one cell right of the start (so the start sits in a vertical lane);
    every odd block column is shifted down by half a period.
    """
    block, first_row = _MOSAIC_LAYOUT[size]
    period = block + _MOSAIC_LANE
    y, x = np.indices((size, size))
    column = (x - start[0] - 1) // period
    in_block_column = (x - start[0] - 1) % period < block
    in_block_row = (y - first_row - (column % 2) * (period // 2)) % period < block
    return in_block_column & in_block_row


def _alley(size: int, start: tuple[int, int], goal: tuple[int, int]) -> np.ndarray:
    """A size x size field of long vertical walls with alternating openings, plus spurs.

    Walls are evenly spaced so that start and goal (on one row) sit mid-corridor, and repeat
    over the whole map. Wall i has one opening, ``offset`` rows above the start-goal row for
    even i and below it for odd i. Spurs half a corridor long leave every wall on every fourth
    row (never the start-goal row), alternately to the right and to the left; the spurs in front
    of an opening are cleared.
    """
    walls_between, offset = _ALLEY_LAYOUT[size]
    (start_x, row), step = start, (goal[0] - start[0]) / walls_between
    spur = (int(step) - 1) // 2
    spur_rows = np.arange((row + _ALLEY_SPUR_EVERY // 2) % _ALLEY_SPUR_EVERY, size,
                          _ALLEY_SPUR_EVERY)
    obstacles = np.zeros((size, size), dtype=bool)
    for i in range(-math.ceil(start_x / step), math.ceil((size - start_x) / step)):
        x = start_x + math.floor((i + 0.5) * step + 0.5)
        if not 0 < x < size - 1:
            continue
        obstacles[:, x] = True
        obstacles[spur_rows[0::2], x + 1: x + 1 + spur] = True
        obstacles[spur_rows[1::2], max(x - spur, 0): x] = True
        opening = (row - offset if i % 2 == 0 else row + offset) - _ALLEY_OPENING // 2
        obstacles[opening: opening + _ALLEY_OPENING, max(x - spur, 0): x + 1 + spur] = False
    return obstacles
