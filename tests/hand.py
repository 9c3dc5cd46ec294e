"""Hand-side helpers for tests/test_equations.py: grid geometry written out independently of
the library (slot order, neighbours, lengths), and a hand-built Walk.

Nothing here calls the code under test to compute an expected number; the library's graph is
only read to check that it agrees with the geometry written here.
"""
from __future__ import annotations

import math

import numpy as np
from jitted import rows_log

from jaxswarm.swarm.walking import Walk

# Slot order of the library's grids, written out by hand: E S W N SE SW NW NE, y grows down.
SLOTS = [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1)]
E, S, W, N, SE, SW, NW, NE = range(8)
R2 = math.sqrt(2.0)


def xy(node: int, width: int = 3) -> tuple[int, int]:
    return node % width, node // width


def node(x: int, y: int, width: int = 3) -> int:
    return y * width + x


def slot(i: int, j: int, width: int = 3) -> int:
    """The slot of the move i -> j between two lattice neighbours."""
    (xi, yi), (xj, yj) = xy(i, width), xy(j, width)
    return SLOTS.index((xj - xi, yj - yi))


def step_length(i: int, j: int, width: int = 3) -> float:
    (xi, yi), (xj, yj) = xy(i, width), xy(j, width)
    return math.hypot(xj - xi, yj - yi)


def moves(i: int, width: int = 3, height: int = 3, blocked=()) -> dict[int, int]:
    """{slot: neighbour} of the valid moves out of node i on an 8-connected grid without corner
    cutting (a diagonal needs both orthogonal cells it squeezes between free)."""
    blocked = set(blocked)
    x, y = xy(i, width)
    out = {}
    if i in blocked:
        return out
    for k, (dx, dy) in enumerate(SLOTS):
        nx, ny = x + dx, y + dy
        if not (0 <= nx < width and 0 <= ny < height) or node(nx, ny, width) in blocked:
            continue
        if dx and dy and (node(x + dx, y, width) in blocked or node(x, y + dy, width) in blocked):
            continue
        out[k] = node(nx, ny, width)
    return out


def distance(i: int, j: int, width: int = 3) -> float:
    """Straight-line distance between the cells of two nodes."""
    (xi, yi), (xj, yj) = xy(i, width), xy(j, width)
    return math.hypot(xj - xi, yj - yi)


def check_lattice(graph, width: int, height: int, blocked=()) -> None:
    """Assert the library's graph has exactly the valid moves written out in :func:`moves`."""
    nbr = np.asarray(graph.nbr)
    valid = np.asarray(graph.valid_edges())
    for i in range(width * height):
        expected = moves(i, width, height, blocked)
        got = {k: int(nbr[i, k]) for k in range(nbr.shape[1]) if valid[i, k]}
        assert got == expected, (i, got, expected)


def probabilities(row) -> dict[int, float]:
    """{slot: probability} of a log-weight row: softmax over its finite entries (float64)."""
    row = np.asarray(row, np.float64)
    finite = np.isfinite(row)
    top = row[finite].max()
    weights = np.where(finite, np.exp(np.where(finite, row - top, 0.0)), 0.0)
    return {k: weights[k] / weights.sum() for k in range(row.shape[0]) if finite[k]}




def fake_walk(paths, num_nodes: int, *, arrived, stuck, width: int = 3, budget: int | None = None
              ) -> Walk:
    """A Walk of the given node paths (one list per agent), slots and lengths computed here; its
    fields are NumPy arrays but for the log, for the jitted functions under test to read."""
    longest = max(len(p) for p in paths)
    columns = (budget if budget is not None else longest - 1) + 1
    agents = len(paths)
    path = np.full((agents, columns), -1, np.int32)
    slots = np.full((agents, columns - 1), -1, np.int16)
    visited = np.zeros((agents, (num_nodes + 31) // 32), np.uint32)
    lengths = np.zeros(agents, np.float32)
    for a, nodes in enumerate(paths):
        path[a, :len(nodes)] = nodes
        for t in range(len(nodes) - 1):
            slots[a, t] = slot(nodes[t], nodes[t + 1], width)
            lengths[a] += step_length(nodes[t], nodes[t + 1], width)
        for v in nodes:
            visited[a, v // 32] |= np.uint32(1 << (v % 32))
    moves = np.array([len(p) - 1 for p in paths], np.int32)
    log = rows_log(path, slots, moves, paths[0][0], columns - 1)
    return Walk(log=log, length=lengths, arrived=np.array(arrived, bool),
                stuck=np.array(stuck, bool),
                position=np.array([p[-1] for p in paths], np.int32), visited=visited,
                moves=moves, lane_steps=np.int32(agents * (longest - 1)))
