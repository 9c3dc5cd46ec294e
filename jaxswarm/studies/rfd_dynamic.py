"""The RFD paper's dynamic scenarios (Tables 2-5) on our rebuilds of its nine maps: the paper's
figures (``PAPER_DYNAMIC_LENGTH``, ``PAPER_DYNAMIC_MS``, its new goals) and each change as a
:class:`Scenario` (:func:`paper_scenario`), which ``sweeps/rfd_paper_dynamic.py`` and
``benchmarks/dynamic.py`` run.

The paper moves the goal (Table 2), adds obstacles that cut the static path (Table 3), removes
obstacles to open a shorter one (Table 4), and makes a major change (Table 5: the mosaic goals
move far, the alleys and mazes lose a large share of their obstacles). Its goal cells are given;
its edited cells are only drawn (Figures 4-6), not listed. Here:

* **goal moves** (Table 2, and Table 5 on the mosaics) go to the paper's cell, or, where that cell
  is an obstacle on our map, to the nearest free cell reachable from the start (both are kept);
* **added obstacles** (Table 3): a single cell, or a 3 x 3 plug, on the static optimal path, the
  one whose new optimum comes closest to the paper's (scaled, below);
* **removed obstacles** (Table 4): a single obstacle cell, or a small block of them (a 4-connected
  group of at most ``MAX_BLOCK`` cells), chosen the same way;
* **a major removal** (Table 5, alleys and mazes): every obstacle within a disc around the start,
  its radius the one whose new optimum comes closest to the paper's.

Our maps are not the paper's, so a target is the paper's new optimum scaled by our static optimum
over the paper's (Table 1): ``ours_static * paper_after / paper_static``. The candidates are
evaluated exactly, by one D* Lite planner repaired after each trial edit, and ties go to the
candidate found first (cells in node order): every scenario is deterministic.
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np

from jaxswarm.dynamic.events import Event, make_event
from jaxswarm.exact import dijkstra, replanner
from jaxswarm.maps.paper import PAPER_MAPS, PAPER_OPTIMA, by_map, paper_map
from jaxswarm.world.edits import block_cells, unblock_cells
from jaxswarm.world.graph import Graph

TABLES = (2, 3, 4, 5)
"""The paper's dynamic tables."""

_NA = None
PAPER_DYNAMIC_LENGTH: dict[int, dict[str, dict[str, float | None]]] = {
    2: by_map({
        "Dijkstra": (20.07, 34.31, 77.79, 50.79, 83.21, 227.28, 117.76, 171.66, 509.32),
        "A*": (20.07, 34.31, 77.79, 50.79, 83.21, 227.28, 117.76, 171.66, 509.32),
        "ACO": (60.45, 135.32, _NA, 471.88, 1175.75, _NA, 2651.17, 5458.90, _NA),
        "ACO*": (20.07, 64.83, _NA, 69.52, 210.56, _NA, 241.62, 380.73, _NA),
        "RFD": (28.42, 98.16, _NA, 295.24, 798.88, _NA, 2133.11, 3824.62, _NA)}),
    3: by_map({
        "Dijkstra": (19.48, 34.31, 82.62, 51.45, 83.62, 232.52, 118.59, 172.91, 514.56),
        "A*": (19.48, 34.31, 82.62, 51.45, 83.62, 232.52, 118.59, 172.91, 514.56),
        "ACO": (49.54, 112.01, _NA, 438.39, 1075.32, _NA, 2690.44, 5370.58, _NA),
        "ACO*": (19.48, 124.74, _NA, 127.35, 257.26, _NA, 296.22, 331.62, _NA),
        "RFD": (53.88, 105.43, _NA, 301.66, 810.58, _NA, 1856.91, 3788.83, _NA)}),
    4: by_map({
        "Dijkstra": (17.82, 32.07, 76.62, 48.97, 79.14, 224.52, 115.28, 167.59, 504.56),
        "A*": (17.82, 32.07, 76.62, 48.97, 79.14, 224.52, 115.28, 167.59, 504.56),
        "ACO": (37.72, 127.66, _NA, 429.91, 1106.74, _NA, 2717.84, 5129.76, _NA),
        "ACO*": (18.65, 169.39, _NA, 68.48, 237.54, _NA, 289.69, 295.25, _NA),
        "RFD": (30.21, 117.12, _NA, 383.1, 839.24, _NA, 2196.57, 4070.42, _NA),
        "RFD*": (17.82, 32.07, 76.62, 48.97, 79.14, 224.52, 115.28, 167.59, 504.56)}),
    5: by_map({
        "Dijkstra": (21.31, 13, 58.97, 55.11, 29, 167.7, 117.5, 52, 359.11),
        "A*": (21.31, 13, 58.97, 55.11, 29, 167.7, 117.5, 52, 359.11),
        "ACO": (85.6, 238.48, _NA, 506.03, 1468.16, _NA, 2481.27, 6085.31, _NA),
        "ACO*": (21.31, 65.19, _NA, 60.53, 239.12, _NA, 187.095, 281.45, _NA),
        "RFD": (176.27, 54.01, _NA, 1319.55, 128.43, _NA, _NA, 2616.64, _NA),
        "RFD*": (21.31, 13, 58.97, 55.11, 29, 167.7, 117.5, 52, 359.11)}),
}
"""The paper's Tables 2-5, mean path length per algorithm and map after the change; None where
the paper says n/a. Tables 2 and 3 have no RFD* length row in the paper's text."""

PAPER_DYNAMIC_MS: dict[int, dict[str, dict[str, float | None]]] = {
    2: by_map({
        "Dijkstra": (4.658, 4.655, 6.215, 55.931, 62.062, 45.988, 513.412, 751.669, 443.453),
        "A*": (1.953, 4.375, 6.326, 25.148, 56.548, 47.941, 320.462, 654.803, 442.611),
        "ACO": (652.73, 685.97, _NA, 11139.51, 10873.72, _NA, 130845.01, 132885.49, _NA),
        "ACO*": (557.349, 775.123, _NA, 3966.235, 6183.59, _NA, 35302.022, 28573.663, _NA),
        "RFD": (197.364, 201.56, _NA, 183.474, 355.38, _NA, 1040.421, 981.498, _NA),
        "RFD*": (4.351, 5.234, 5.102, 10.299, 14.446, 15.103, 70.356, 90.322, 121.452)}),
    3: by_map({
        "Dijkstra": (5.518, 4.601, 5.654, 67.314, 85.992, 57.822, 557.943, 753.041, 440.751),
        "A*": (2.037, 4.938, 5.936, 28.153, 55.631, 47.522, 362.752, 637.612, 434.634),
        "ACO": (642.97, 669.38, _NA, 10900.92, 10048.88, _NA, 131001.71, 133701.91, _NA),
        "ACO*": (61.851, 730.941, _NA, 4928.543, 6028.818, _NA, 34866.798, 30177.845, _NA),
        "RFD": (120.677, 581.521, _NA, 804.213, 1184.2, _NA, 4772.492, 5204.32, _NA),
        "RFD*": (6.166, 6.921, 5.989, 11.319, 19.662, 15.926, 81.774, 92.482, 101.404)}),
    4: by_map({
        "Dijkstra": (4.593, 4.794, 5.642, 56.846, 71.968, 58.254, 541.029, 757.242, 438.629),
        "A*": (1.092, 4.429, 5.328, 20.467, 57.568, 48.106, 338.702, 665.238, 440.981),
        "ACO": (643.59, 667.04, _NA, 10873.22, 10183.79, _NA, 130503.92, 132996.64, _NA),
        "ACO*": (62.35, 769.54, _NA, 4814.421, 5924.835, _NA, 32334.028, 21751.601, _NA),
        "RFD": (205.739, 471.739, _NA, 838.274, 747.91, _NA, 2572.473, 1942.22, _NA),
        "RFD*": (5.183, 7.511, 8.181, 9.371, 11.482, 12.669, 47.429, 50.163, 70.171)}),
    5: by_map({
        "Dijkstra": (2.858, 2.296, 3.515, 30.237, 30.966, 28.663, 226.148, 305.574, 229.698),
        "A*": (0.988, 0.592, 3.359, 11.637, 3.618, 28.475, 112.069, 16.251, 226.841),
        "ACO": (460.031, 449.92, _NA, 4368.948, 4326.924, _NA, 33090.306, 33682.913, _NA),
        "ACO*": (68.041, 786.81, _NA, 3303.432, 5728.462, _NA, 32817.862, 22746.026, _NA),
        "RFD": (686.816, 966.442, _NA, 4935.295, 4919.252, _NA, _NA, 22889.838, _NA),
        "RFD*": (35.498, 26.229, 412.697, 105.466, 60.564, 622.767, 466.014, 124.209,
                 1067.273)}),
}
"""The paper's Tables 2-5, computation time [ms] after the change (C#, Intel i7-3770)."""

TABLE2_GOALS: dict[str, tuple[int, int]] = {
    "maze20": (19, 17), "mosaic20": (19, 8), "alley20": (14, 9), "maze50": (49, 46),
    "mosaic50": (47, 22), "alley50": (35, 24), "maze100": (99, 96), "mosaic100": (99, 54),
    "alley100": (72, 49)}
"""The paper's new goals of Table 2, (x, y)."""

TABLE5_GOALS: dict[str, tuple[int, int]] = {
    "mosaic20": (19, 17), "mosaic50": (47, 45), "mosaic100": (99, 85)}
"""The paper's new goals of Table 5 (the mosaics; the other maps lose obstacles)."""

MAX_BLOCK = 16
"""Largest group of obstacle cells removed at once for Table 4."""


@dataclasses.dataclass(frozen=True)
class Scenario:
    """One change of one paper map.

    Attributes:
      map: the paper map's name.
      table: the paper's table (2-5).
      kind: "goal", "added", "removed" or "major removal".
      paper_goal: the paper's new goal cell (x, y), or None.
      goal: our new goal (x, y) (the paper's, or the nearest free cell), or None.
      block: cells (x, y) that become obstacles.
      unblock: cells (x, y) that become free.
      target: the new optimum aimed at (the paper's, scaled to our map).
      static_optimum: our optimum before the change.
      optimum: our optimum after it (Dijkstra).
    """

    map: str
    table: int
    kind: str
    paper_goal: tuple[int, int] | None
    goal: tuple[int, int] | None
    block: tuple[tuple[int, int], ...]
    unblock: tuple[tuple[int, int], ...]
    target: float
    static_optimum: float
    optimum: float

    def event(self, graph: Graph, size: int | None = None) -> Event:
        """The change as an :class:`~jaxswarm.dynamic.events.Event` on ``graph`` (the map's graph)."""
        return make_event(graph, goal=self.goal, block=self.block, unblock=self.unblock,
                          size=size)

    def obstacles(self) -> np.ndarray:
        """bool[H, W] the map's obstacles after the change."""
        obstacles = paper_map(self.map).obstacles.copy()
        for x, y in self.block:
            obstacles[y, x] = True
        for x, y in self.unblock:
            obstacles[y, x] = False
        return obstacles


@functools.lru_cache(maxsize=None)
def paper_scenario(name: str, table: int) -> Scenario:
    """The scenario of the paper's ``table`` (2-5) on paper map ``name`` (see the module
    docstring; computed once per process).

    Raises:
      ValueError: an unknown map or table.
    """
    if name not in PAPER_MAPS:
        raise ValueError(f"unknown paper map {name!r}; choose one of {', '.join(PAPER_MAPS)}")
    if table not in TABLES:
        raise ValueError(f"the paper's dynamic tables are 2-5, got {table}")
    chosen = paper_map(name)
    graph = chosen.graph()
    static = float(dijkstra(graph, chosen.start, chosen.goal).cost)
    target = static * PAPER_DYNAMIC_LENGTH[table]["Dijkstra"][name] / PAPER_OPTIMA[name]
    common = dict(map=name, table=table, target=target, static_optimum=static)
    if table == 2 or (table == 5 and name in TABLE5_GOALS):
        paper_goal = (TABLE2_GOALS if table == 2 else TABLE5_GOALS)[name]
        goal = nearest_free(graph, chosen.start, paper_goal)
        return Scenario(kind="goal", paper_goal=paper_goal, goal=goal, block=(), unblock=(),
                        optimum=float(dijkstra(graph, chosen.start, goal).cost), **common)
    if table == 3:
        block, optimum = _closest(graph, chosen, _plugs(graph, chosen), target, block_cells)
        return Scenario(kind="added", paper_goal=None, goal=None, block=block, unblock=(),
                        optimum=optimum, **common)
    if table == 4:
        unblock, optimum = _closest(graph, chosen, _obstacle_groups(chosen.obstacles), target,
                                    unblock_cells)
    else:  # a disc that grows clears ever more: the optimum only shrinks
        unblock, optimum = _closest(graph, chosen, _discs(chosen), target, unblock_cells,
                                    shrinking=True)
    return Scenario(kind="removed" if table == 4 else "major removal", paper_goal=None,
                    goal=None, block=(), unblock=unblock, optimum=optimum, **common)


def nearest_free(graph: Graph, start: tuple[int, int], cell: tuple[int, int]) -> tuple[int, int]:
    """``cell`` if it is free and reachable from ``start``, else the nearest such cell
    (Euclidean distance; ties to the smaller node index)."""
    height, width = graph.shape
    free = np.asarray(graph.free).reshape(height, width)
    ys, xs = np.nonzero(free)
    order = np.lexsort((ys * width + xs, np.hypot(xs - cell[0], ys - cell[1])))
    for i in order:
        candidate = (int(xs[i]), int(ys[i]))
        if dijkstra(graph, start, candidate).found:
            return candidate
    raise ValueError(f"no cell reachable from {start} on this map")


def _closest(graph, chosen, candidates, target, edit, *, shrinking=False):
    """The candidate cell group whose edit (``block_cells`` or ``unblock_cells``) gives the new
    optimum closest to ``target`` (a changed, finite one): ``(cells, optimum)``. One D* Lite
    planner evaluates them all, each trial edit replacing the last. ``shrinking``: the
    candidates' optima only decrease, so the search stops at the first one below the target."""
    width = graph.shape[1]
    planner = replanner(graph, chosen.start, chosen.goal)
    static = float(planner.solve().cost)
    best, best_cells, best_cost = np.inf, None, None
    for cells in candidates:
        if not cells:
            continue
        nodes = np.asarray([y * width + x for x, y in cells], np.int32)
        cost = float(planner.update(edit(graph, nodes)).cost)
        if np.isfinite(cost) and abs(cost - static) > 1e-9 and abs(cost - target) < best:
            best, best_cells, best_cost = abs(cost - target), tuple(cells), cost
        if shrinking and cost < target:
            break
    if best_cells is None:
        raise ValueError(f"{chosen.name}: no candidate edit changes the optimum")
    return best_cells, best_cost


def _plugs(graph, chosen):
    """Cells of the static optimal path (not its ends), each alone and as a 3 x 3 plug of the
    free cells around it (the start, the goal and their neighbours never)."""
    height, width = graph.shape
    nodes = dijkstra(graph, chosen.start, chosen.goal).nodes()
    ends = {chosen.start, chosen.goal}
    keep_free = {(x + dx, y + dy) for x, y in ends for dx in (-1, 0, 1) for dy in (-1, 0, 1)}
    free = ~chosen.obstacles
    for node in nodes[1:-1]:
        x, y = int(node % width), int(node // width)
        if (x, y) in keep_free:
            continue
        yield [(x, y)]
        yield [(x + dx, y + dy) for dy in (-1, 0, 1) for dx in (-1, 0, 1)
               if 0 <= x + dx < width and 0 <= y + dy < height and free[y + dy, x + dx]
               and (x + dx, y + dy) not in keep_free]


def _obstacle_groups(obstacles):
    """Each obstacle cell next to a free one, alone; then each 4-connected group of obstacle
    cells of at most ``MAX_BLOCK`` cells, whole."""
    height, width = obstacles.shape
    padded = np.pad(~obstacles, 1)
    touches = np.zeros_like(obstacles)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            touches |= padded[1 + dy:1 + dy + height, 1 + dx:1 + dx + width]
    for y, x in zip(*np.nonzero(obstacles & touches)):
        yield [(int(x), int(y))]
    seen = np.zeros_like(obstacles)
    for y0, x0 in zip(*np.nonzero(obstacles)):
        if seen[y0, x0]:
            continue
        group, stack = [], [(int(y0), int(x0))]
        seen[y0, x0] = True
        while stack:
            y, x = stack.pop()
            group.append((x, y))
            for ny, nx in ((y + 1, x), (y - 1, x), (y, x + 1), (y, x - 1)):
                if 0 <= ny < height and 0 <= nx < width and obstacles[ny, nx] and not seen[ny, nx]:
                    seen[ny, nx] = True
                    stack.append((ny, nx))
        if 1 < len(group) <= MAX_BLOCK:
            yield sorted(group, key=lambda cell: (cell[1], cell[0]))


def _discs(chosen):
    """Every obstacle within distance r of the start, for r = 1, 2, ... up to the map's
    diagonal."""
    height, width = chosen.obstacles.shape
    ys, xs = np.nonzero(chosen.obstacles)
    distance = np.hypot(xs - chosen.start[0], ys - chosen.start[1])
    for radius in range(1, int(np.hypot(height, width)) + 1):
        inside = distance <= radius
        yield [(int(x), int(y)) for x, y in zip(xs[inside], ys[inside])]
