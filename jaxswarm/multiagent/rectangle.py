"""Rectangle reasoning for CBS on 4-connected grids (after Li, Harabor, Stuckey, Ma and Koenig,
AAAI 2019, and Li et al., AIJ 2021): one split for two agents whose shortest paths cross a
rectangle, one from its bottom to its top and the other from its left to its right.

Such agents collide in the rectangle whichever of their equally short paths they take, so plain
CBS resolves the collision a cell at a time. :class:`Rectangles` splits once, with a *barrier*
per agent: vertex constraints along the side where that agent leaves the rectangle, each at the
step the agent would reach that cell on a shortest path. The papers time the barriers by the
agents' MDDs; here static distances time them, in a form whose split keeps every solution
(``docs/papers.md`` gives the argument). The split is taken only where both agents' current
paths break their barriers; otherwise CBS splits as usual.
"""
from __future__ import annotations

import numpy as np

from jaxswarm.multiagent.agents import breadth_first
from jaxswarm.multiagent.constraints import Constraints
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.graph import Graph


class Rectangles:
    """Rectangle reasoning on a grid and the distances it needs (cached).

    Attributes:
      shape: the grid's ``(H, W)`` (None for a graph that is not a grid).
      cells: i64[N, 2] each node's ``(x, y)`` cell (node ``y * W + x``) on a grid.
      usable: whether the map is a grid where every move is one cell up, down, left or right
        (otherwise no split applies).
    """

    def __init__(self, graph: Graph):
        self.arrays = edge_arrays(graph)
        self.shape, self.usable, self._fields = graph.shape, graph.is_grid, {}
        if self.usable:
            nodes = np.arange(graph.num_nodes)
            self.cells = np.stack([nodes % self.shape[1], nodes // self.shape[1]], axis=1)
            tails = np.repeat(nodes, np.diff(self.arrays.indptr))
            steps = np.abs(self.cells[self.arrays.heads] - self.cells[tails]).sum(axis=1)
            self.usable = bool(np.all(steps == 1))

    def distances(self, start: int, avoiding: int = -1) -> np.ndarray:
        """i32[N] the fewest steps from ``start`` to every node, avoiding node ``avoiding``
        (-1: none); ``UNREACHABLE`` where there is no way."""
        key = (start, avoiding)
        if key not in self._fields:
            blocked = np.zeros(len(self.cells), bool)
            if avoiding >= 0:
                blocked[avoiding] = True
            # Along the edges themselves: the distances from ``start`` rather than to it.
            self._fields[key] = breadth_first(self.arrays.indptr, self.arrays.heads, start,
                                              blocked)
        return self._fields[key]

    def split(self, constraints: tuple[Constraints, Constraints], paths, step: int,
              padded: np.ndarray) -> tuple[Constraints, Constraints] | None:
        """Both children's constraints (each agent's barrier added) for two agents colliding
        on one cell at ``step`` inside a rectangle, or None where the split does not apply.

        Args:
          constraints: the two agents' constraints so far.
          paths: their node lists i32[T_0], i32[T_1] (each from its start to its goal).
          step: the step their collision arrives at.
          padded: i32[2, T] the two paths, each resting at its goal after its end.
        """
        if not self.usable or padded[0, step] != padded[1, step]:
            return None
        starts = [int(path[0]) for path in paths]
        fields = [self.distances(s) for s in starts]
        if any(fields[i][padded[i, step]] != step for i in (0, 1)):
            return None  # an agent is not on a shortest path there
        runs = [_straight_run(self.cells[padded[i]], fields[i][padded[i]], step)
                for i in (0, 1)]
        sign = _common_sign([self.cells[padded[i, last]] - self.cells[padded[i, first]]
                             for i, (first, last) in enumerate(runs)])
        if sign is None:
            return None
        for vertical, horizontal in ((0, 1), (1, 0)):
            barriers = self._barriers(padded[[vertical, horizontal]],
                                      [runs[vertical], runs[horizontal]],
                                      [starts[vertical], starts[horizontal]],
                                      [fields[vertical], fields[horizontal]], sign)
            if barriers is not None:
                if vertical == 1:
                    barriers = barriers[::-1]
                return tuple(constraints[i]._replace(vertex=constraints[i].vertex | barriers[i])
                             for i in (0, 1))
        return None

    def _barriers(self, padded: np.ndarray, runs, starts, fields,
                  sign: np.ndarray) -> tuple[frozenset, frozenset] | None:
        """The barriers ``(vertical's, horizontal's)`` of the rectangle the two padded paths
        (i32[2, T]; their straight runs ``(first, last)`` steps around their collision, both
        moving by ``sign`` i64[2]; ``starts`` their start nodes, ``fields`` i32[N] the fewest
        steps from each) span with row 0 crossing it upward and row 1 rightward, or None where
        a current path does not break its barrier."""
        mirrored = [self.cells[padded[i]] * sign for i in (0, 1)]
        entry_v, entry_h = _entries(mirrored, runs)
        exit_v, exit_h = _exits(mirrored, runs)
        low = np.array([mirrored[0][entry_v, 0], mirrored[1][entry_h, 1]])
        high = np.array([mirrored[0][exit_v, 0], mirrored[1][exit_h, 1]])
        top = [(x, high[1]) for x in range(low[0], high[0] + 1)]
        right = [(high[0], y) for y in range(low[1], high[1] + 1)]
        barriers = []
        for row, (side, entry_step) in enumerate(((top, entry_v), (right, entry_h))):
            barrier = self._barrier(side, sign, int(padded[row, entry_step]), entry_step,
                                    starts[row], fields[row])
            crossing = int(np.flatnonzero((mirrored[row][:, 1 - row] == high[1 - row])
                                          & (np.arange(padded.shape[1]) >= entry_step))[0])
            if (crossing, int(padded[row, crossing])) not in barrier:
                return None
            barriers.append(barrier)
        return barriers[0], barriers[1]

    def _barrier(self, side, sign: np.ndarray, entry: int, entry_step: int, start: int,
                 field: np.ndarray) -> frozenset:
        """The vertex constraints ``(t, v)`` of one agent's barrier: the cells of ``side``
        (mirrored ``(x, y)`` cells; a blocked one is never reached) it reaches from its
        ``entry`` node, visited at ``entry_step``, on a shortest path, at the step it would,
        where every shortest path from its ``start`` passes ``entry``."""
        around = self.distances(start, avoiding=entry) if entry != start else None
        height, width = self.shape
        barrier = set()
        for cell in side:
            x, y = np.asarray(cell) * sign
            if not (0 <= y < height and 0 <= x < width):
                continue
            node = int(y * width + x)
            at = entry_step + int(np.abs(self.cells[node] - self.cells[entry]).sum())
            if field[node] == at and (around is None or around[node] > at):
                barrier.add((at, node))
        return frozenset(barrier)


def _straight_run(cells: np.ndarray, arrival: np.ndarray, step: int) -> tuple[int, int]:
    """``(first, last)``: the longest stretch of steps around ``step`` along which a padded path
    (its cells i64[T, 2], ``arrival`` i32[T] the fewest steps from its start to each) is at
    each cell at the fewest steps and moves without turning back on either axis (the path is at
    its cell at ``step`` on a shortest path)."""
    on_time = (arrival == np.arange(len(arrival))).tolist()
    moves = np.sign(np.diff(cells, axis=0)).tolist()
    first, last = step, step
    signs = [0, 0]
    while first > 0 and on_time[first - 1] and _keeps(signs, moves[first - 1]):
        first -= 1
    while last + 1 < len(cells) and on_time[last + 1] and _keeps(signs, moves[last]):
        last += 1
    return first, last


def _keeps(signs: list[int], move: list[int]) -> bool:
    """Whether a move (its signs per axis, -1, 0 or 1) goes the way of ``signs`` (0 on an axis
    not yet known) on both axes; records its signs in ``signs`` if so."""
    if move[0] * signs[0] < 0 or move[1] * signs[1] < 0:
        return False
    for axis in (0, 1):
        if move[axis]:
            signs[axis] = move[axis]
    return True


def _common_sign(moves) -> np.ndarray | None:
    """i64[2] the direction both straight runs (their displacements i64[2]) move on each axis,
    or None where they move opposite ways on an axis or neither moves on it."""
    sign = np.zeros(2, np.int64)
    for move in moves:
        moved = np.sign(move)
        if np.any(moved * sign < 0):
            return None
        sign[moved != 0] = moved[moved != 0]
    return sign if np.all(sign != 0) else None


def _entries(mirrored, runs) -> tuple[int, int]:
    """The steps of the vertical's (row 0 of ``mirrored``, i64[T, 2] cells moving right and up)
    and horizontal's entries: the earliest of their runs with the vertical's at or right of the
    horizontal's column and the horizontal's at or above the vertical's row (at worst both on
    their collision's cell)."""
    vertical, horizontal = runs[0][0], runs[1][0]
    while True:
        if mirrored[0][vertical, 0] < mirrored[1][horizontal, 0]:
            vertical += 1
        elif mirrored[1][horizontal, 1] < mirrored[0][vertical, 1]:
            horizontal += 1
        else:
            return vertical, horizontal


def _exits(mirrored, runs) -> tuple[int, int]:
    """The steps of the vertical's and horizontal's exits: the latest of their runs with the
    vertical's at or left of the horizontal's column and the horizontal's at or below the
    vertical's row (at worst both on their collision's cell)."""
    vertical, horizontal = runs[0][1], runs[1][1]
    while True:
        if mirrored[0][vertical, 0] > mirrored[1][horizontal, 0]:
            vertical -= 1
        elif mirrored[1][horizontal, 1] > mirrored[0][vertical, 1]:
            horizontal -= 1
        else:
            return vertical, horizontal
