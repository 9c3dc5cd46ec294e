"""Exact planners against pyastar2d and networkx on Moving AI maps.

What is measured
----------------
For the Moving AI maps ``maze-128-128-10``, ``den312d`` and ``Berlin_1_256`` (256 x 256),
``--scenarios N`` rows spread evenly over each map's ``-random-1.scen`` file are solved, in one
process, in four parts.

Compile and first-call time, reported apart. :func:`jaxswarm.exact.warm_up` runs first and its
seconds are printed on their own line (it compiles every numba planner, or loads it from numba's
on-disk cache). Then, per map, before any timing: one ``astar`` call (it builds the map's cached
host arrays), one D* Lite solve (it builds the map's cached D* Lite lattice) and one single-cell
edit with its D* Lite repair and A* (JAX compiles the edit and the edited map's valid edges for
that map's shape); their seconds are printed per map and excluded from the timings below.

1. Per query, on the N rows, planners interleaved within each of ``--repeats R`` passes:

   * jaxswarm (:mod:`jaxswarm.exact`, numba-compiled) ``dijkstra``, ``astar`` (octile heuristic,
     the default on grids), ``astar`` with ``heuristic="euclidean"``, ``bidirectional_astar``
     (the A* report's), ``balanced_bidirectional_astar`` and D* Lite's first solve,
     ``replanner(graph, start, goal).solve()`` (building the planner included), all on a Graph
     loaded once per map;
   * ``pyastar2d.astar_path`` on float32 weights (1 on free cells, inf on obstacles), with
     ``allow_diagonal=True``. pyastar2d lets a diagonal move cut a blocked corner, so its
     lengths differ from the others': it is timed, its lengths are not checked;
   * networkx ``astar_path`` (octile heuristic) and ``dijkstra_path``, each plus ``path_weight``
     for its length, on a networkx graph built once per map from the same ``.map`` file with the
     same convention (8-connected, diagonal weight sqrt 2, no corner cutting: a diagonal move
     only when both orthogonal cells are free). On maps listed in ``NETWORKX_ROWS``
     (``Berlin_1_256``: 10) networkx runs on that many of the N rows, spread evenly, as it is
     slow there; the table says on how many rows each planner ran.

   Each query is timed from the wall clock (``time.perf_counter``) around the call, so the
   figures include each library's per-call overhead (endpoint checks, ``Solution`` packing,
   path reconstruction). Per (map, planner) the table gives ``total s``, the median over the
   R passes of the total time of its rows; ``mean ms/q``, that total divided by its rows;
   ``median ms/q``, the median over its rows of each row's median time over the passes;
   ``expanded``, the mean nodes expanded (jaxswarm's ``stats.expanded``; "-" for the others);
   ``/pyastar2d``, its total divided by pyastar2d's total over the same rows (> 1 means slower
   than pyastar2d); and, for the jaxswarm planners, whether that ratio meets the goal "within
   3x" of pyastar2d. A line under the table gives Dijkstra's expansions over A*'s per map:
   Dijkstra explores more nodes than any A* by design.

2. A batch: ``shortest_lengths(graph, starts, goals)`` on the N rows in one call, against
   ``pyastar2d.astar_path`` looped in Python over the same rows, interleaved in each of the R
   passes; the wall clock around the call (or the loop) gives queries per second (median over
   the passes), with the search alone (``stats.wall_time``) beside it, and the time ratio
   ours / pyastar2d.

3. D* Lite repair after a single-cell change. For each of the N rows whose path has at least 5
   nodes, in each pass: ``planner = replanner(graph, start, goal)``, ``sol = planner.solve()``,
   the middle node of ``sol.nodes()`` blocked by ``jaxswarm.world.edits.block_cells`` (not timed);
   then ``planner.update(edited)`` (the repair), ``astar(edited, start, goal)`` a first time (A*
   from scratch: it builds the edited map's host arrays, as every new Graph needs) and a second
   time (the search alone). Printed per map: the median over rows of each row's median over the
   passes, in ms, of the three; the median ``stats.touched`` of the repair and of the first
   solve; and the goal "a D* Lite repair after a single-cell change well below A* from scratch"
   (met when the repair's median is below half of A* from scratch's).

4. Lengths. Every jaxswarm planner, D* Lite, networkx and the batch must return the ``.scen``
   file's optimal length on every row (relative error < 1e-6), and each repair the cost of A*
   on the edited map (relative error < 1e-9, or both not found); the script says so per map and
   its exit status is 1 on any mismatch.

How to run
----------
From the repository root (defaults take about 35 s on 2 cores, plus about 30 s of numba
compilation when its cache is cold)::

    python -m benchmarks.exact                    # 50 rows per map, 3 repeats
    python benchmarks/exact.py --scenarios 200 --repeats 5
    python benchmarks/exact.py --data /path/to/shared

``--data`` is the ``shared`` directory holding ``benchdata/movingai/mapf`` (default: ``../shared``
next to the repository root).
"""
from __future__ import annotations

import argparse
import importlib.metadata
import math
import os
import platform
import sys
import time
from pathlib import Path
from typing import Callable

import jax
import networkx as nx
import numba
import numpy as np
import pyastar2d

from jaxswarm.exact import (astar, balanced_bidirectional_astar, bidirectional_astar, dijkstra,
                            replanner, shortest_lengths, warm_up)
from jaxswarm.maps.movingai import Scenario, load_map, load_scenarios, read_map
from jaxswarm.runtime.cpu import cpu_model
from jaxswarm.world.edits import block_cells

REPO = Path(__file__).resolve().parents[1]

MAPS = ("maze-128-128-10", "den312d", "Berlin_1_256")
NETWORKX_ROWS = {"Berlin_1_256": 10}
"""Maps on which networkx runs on at most this many of the rows (it is slow there)."""
SQRT2 = math.sqrt(2.0)
REL_TOL = 1e-6
REPAIR_TOL = 1e-9
GOAL_RATIO = 3.0
MIN_REPAIR_NODES = 5
MAPF_DIR = Path("benchdata", "movingai", "mapf")

PYASTAR = "pyastar2d"
DIJKSTRA, ASTAR = "jaxswarm dijkstra", "jaxswarm astar"

Result = tuple[float | None, int | None]
"""A timed call's (path length or None when not checked, nodes expanded or None)."""


def machine_line() -> str:
    """Where the figures come from: platform, CPU, core count, library versions."""
    return (f"machine: {platform.platform()} | {cpu_model()} | {os.cpu_count()} CPUs | "
            f"python {platform.python_version()} | jax {jax.__version__} "
            f"({jax.default_backend()}) | numba {numba.__version__} | "
            f"pyastar2d {importlib.metadata.version('pyastar2d')} | networkx {nx.__version__} | "
            f"numpy {np.__version__}")


def pick_scenarios(rows: list[Scenario], n: int) -> list[Scenario]:
    """``n`` reachable rows spread evenly over the file (first and last included)."""
    reachable = [row for row in rows if row.reachable]
    return [reachable[i] for i in spread(len(reachable), n)]


def spread(count: int, n: int) -> list[int]:
    """``min(n, count)`` indices spread evenly over ``range(count)`` (first and last included)."""
    if n >= count:
        return list(range(count))
    return np.linspace(0, count - 1, n).round().astype(int).tolist()


def networkx_grid(obstacles: np.ndarray) -> nx.Graph:
    """Undirected networkx graph of the free cells, nodes (x, y), attribute ``weight``.

    8-connected, diagonal weight sqrt 2, no corner cutting (the Moving AI and jaxswarm rule).
    """
    free = ~np.asarray(obstacles, dtype=bool)
    height, width = free.shape
    graph = nx.Graph()
    for y, x in zip(*np.nonzero(free)):
        x, y = int(x), int(y)
        graph.add_node((x, y))
        # Each undirected edge once: E, S, and the two downward diagonals SE, SW.
        for dx, dy in ((1, 0), (0, 1), (1, 1), (-1, 1)):
            tx, ty = x + dx, y + dy
            if not (0 <= tx < width and 0 <= ty < height and free[ty, tx]):
                continue
            if dx and dy and not (free[y, tx] and free[ty, x]):
                continue  # the move would cut a blocked corner
            graph.add_edge((x, y), (tx, ty), weight=SQRT2 if dx and dy else 1.0)
    return graph


def octile(a: tuple[int, int], b: tuple[int, int]) -> float:
    """Octile distance between two cells: exact on an empty 8-connected grid."""
    dx, dy = abs(a[0] - b[0]), abs(a[1] - b[1])
    return max(dx, dy) + (SQRT2 - 1.0) * min(dx, dy)


def pyastar_weights(obstacles: np.ndarray) -> np.ndarray:
    """pyastar2d's f32[H, W] cell weights, indexed [y, x]: 1 on free cells, inf on obstacles."""
    return np.where(~np.asarray(obstacles, dtype=bool), 1.0, np.inf).astype(np.float32)


def pyastar(weights: np.ndarray, s: Scenario):
    """pyastar2d's path (an array of (row, col), or None) of a row; corners may be cut."""
    return pyastar2d.astar_path(weights, s.start[::-1], s.goal[::-1], allow_diagonal=True)


def planners(graph, nx_graph, weights) -> dict[str, Callable[[Scenario], Result]]:
    """Name -> function(scenario) -> (length, expanded), for every planner timed per query."""
    def ours(solve):
        def run(s: Scenario) -> Result:
            solution = solve(s)
            return float(solution.cost), int(solution.stats.expanded)
        return run

    def untimed_length(s: Scenario) -> Result:
        pyastar(weights, s)  # its path may cut corners: its length is not compared
        return None, None

    def theirs(find_path):
        def run(s: Scenario) -> Result:
            return nx.path_weight(nx_graph, find_path(s), weight="weight"), None
        return run

    return {
        DIJKSTRA: ours(lambda s: dijkstra(graph, s.start, s.goal)),
        ASTAR: ours(lambda s: astar(graph, s.start, s.goal)),
        "jaxswarm astar euclidean": ours(
            lambda s: astar(graph, s.start, s.goal, heuristic="euclidean")),
        "jaxswarm bidirectional_astar": ours(lambda s: bidirectional_astar(graph, s.start, s.goal)),
        "jaxswarm balanced bidirectional": ours(
            lambda s: balanced_bidirectional_astar(graph, s.start, s.goal)),
        "jaxswarm D* Lite solve": ours(lambda s: replanner(graph, s.start, s.goal).solve()),
        PYASTAR: untimed_length,
        "networkx astar_path": theirs(
            lambda s: nx.astar_path(nx_graph, s.start, s.goal, heuristic=octile, weight="weight")),
        "networkx dijkstra_path": theirs(
            lambda s: nx.dijkstra_path(nx_graph, s.start, s.goal, weight="weight")),
    }


def rel_diff(a: float, b: float) -> float:
    """|a - b| relative to |b| (or absolute below 1); 0 when both are inf."""
    if a == b:
        return 0.0
    return abs(a - b) / max(abs(b), 1.0)


def median_total(seconds: np.ndarray, rows: list[int]) -> float:
    """Median over the passes (axis 0) of the total seconds of ``rows``."""
    return float(np.median(seconds[:, rows].sum(axis=1)))


def median_ms(seconds: np.ndarray) -> float:
    """Median over rows of each row's median over the passes, in ms (``seconds`` [R, rows])."""
    return 1e3 * float(np.median(np.median(seconds, axis=0)))


def warm_map(graph, query: Scenario) -> str:
    """First calls on a map, timed: host arrays, D* Lite lattice, an edit and its repair."""
    began = time.perf_counter()
    astar(graph, query.start, query.goal)
    host_s = time.perf_counter() - began
    began = time.perf_counter()
    planner = replanner(graph, query.start, query.goal)
    nodes = planner.solve().nodes()
    lattice_s = time.perf_counter() - began
    began = time.perf_counter()
    edited = block_cells(graph, int(nodes[len(nodes) // 2]))
    planner.update(edited)
    astar(edited, query.start, query.goal)
    edit_s = time.perf_counter() - began
    return (f"first calls: astar (host arrays) {host_s:.2f} s, D* Lite solve (lattice) "
            f"{lattice_s:.2f} s, edit + repair + A* on the edited map {edit_s:.2f} s")


def bench_queries(name: str, run: dict, queries: list[Scenario], repeats: int):
    """Part 1 on one map: returns (table rows, expansions per planner, lengths per planner,
    rows per planner)."""
    rows_of = {p: list(range(len(queries))) for p in run}
    for planner in ("networkx astar_path", "networkx dijkstra_path"):
        rows_of[planner] = spread(len(queries), NETWORKX_ROWS.get(name, len(queries)))
    seconds = {p: np.zeros((repeats, len(queries))) for p in run}
    results: dict[str, list[Result]] = {}
    for r in range(repeats):
        for planner, fn in run.items():
            results[planner] = []
            for i in rows_of[planner]:
                began = time.perf_counter()
                results[planner].append(fn(queries[i]))
                seconds[planner][r, i] = time.perf_counter() - began

    table, expanded = [], {}
    for planner, rows in rows_of.items():
        total = median_total(seconds[planner], rows)
        counts = [e for _, e in results[planner] if e is not None]
        expanded[planner] = float(np.mean(counts)) if counts else None
        ratio = total / median_total(seconds[PYASTAR], rows)
        goal = None
        if planner.startswith("jaxswarm"):
            goal = "met" if ratio <= GOAL_RATIO else "NOT met"
        table.append((name, planner, len(rows), total, 1e3 * total / len(rows),
                      median_ms(seconds[planner][:, rows]), expanded[planner], ratio, goal))
    lengths = {p: [length for length, _ in results[p]] for p in run if p != PYASTAR}
    return table, expanded, lengths, rows_of


def bench_batch(name: str, graph, weights, queries: list[Scenario], repeats: int):
    """Part 2 on one map: returns (table row, batch lengths)."""
    starts = np.array([q.start for q in queries])
    goals = np.array([q.goal for q in queries])
    ours, search, theirs = [], [], []
    for _ in range(repeats):
        began = time.perf_counter()
        result = shortest_lengths(graph, starts, goals)
        ours.append(time.perf_counter() - began)
        search.append(result.stats.wall_time)
        began = time.perf_counter()
        for query in queries:
            pyastar(weights, query)
        theirs.append(time.perf_counter() - began)
    ours_s, search_s, theirs_s = (float(np.median(t)) for t in (ours, search, theirs))
    count = len(queries)
    row = (name, count, count / ours_s, count / search_s, count / theirs_s, ours_s / theirs_s)
    return row, result.cost.tolist()


def bench_repair(name: str, graph, queries: list[Scenario], repeats: int):
    """Part 3 on one map: returns (table row, worst relative difference of a repaired cost to
    A*'s on the edited map)."""
    cases = []
    for query in queries:
        nodes = replanner(graph, query.start, query.goal).solve().nodes()
        if len(nodes) >= MIN_REPAIR_NODES:
            cases.append((query, int(nodes[len(nodes) // 2])))
    seconds = np.zeros((3, repeats, len(cases)))
    touched = np.zeros((2, len(cases)))
    worst = 0.0
    for r in range(repeats):
        for i, (query, node) in enumerate(cases):
            planner = replanner(graph, query.start, query.goal)
            first = planner.solve()
            edited = block_cells(graph, node)
            solutions = []
            for k, solve in enumerate((lambda: planner.update(edited),
                                       lambda: astar(edited, query.start, query.goal),
                                       lambda: astar(edited, query.start, query.goal))):
                began = time.perf_counter()
                solutions.append(solve())
                seconds[k, r, i] = time.perf_counter() - began
            repaired, scratch = solutions[0], solutions[1]
            touched[:, i] = repaired.stats.touched, first.stats.touched
            if bool(repaired.found) != bool(scratch.found):
                worst = math.inf
            elif repaired.found:
                worst = max(worst, rel_diff(float(repaired.cost), float(scratch.cost)))
    repair_ms, scratch_ms, search_ms = (median_ms(s) for s in seconds)
    row = (name, len(cases), repair_ms, scratch_ms, search_ms,
           float(np.median(touched[0])), float(np.median(touched[1])),
           "met" if repair_ms < 0.5 * scratch_ms else "NOT met")
    return row, worst


def check_lengths(lengths: dict[str, list[float]], rows_of: dict[str, list[int]],
                  queries: list[Scenario]) -> bool:
    """Every planner's lengths against the .scen optima; prints the verdict and any mismatch."""
    worst, bad = 0.0, []
    for planner, found in lengths.items():
        for i, length in zip(rows_of[planner], found):
            diff = rel_diff(length, queries[i].optimal_length)
            worst = max(worst, diff)
            if diff >= REL_TOL:
                bad.append(f"    {planner}: line {queries[i].line} {queries[i].start}->"
                           f"{queries[i].goal}: scen {queries[i].optimal_length:.8f}, "
                           f"got {length:.8f}")
    print(f"  lengths: {len(lengths)} planners (pyastar2d not checked) "
          f"{'match' if not bad else 'DO NOT MATCH'} the .scen optimal lengths on "
          f"{len(queries)} queries (max rel. diff {worst:.1e})")
    for line in bad:
        print(line)
    return not bad


def bench_map(name: str, mapf: Path, n: int, repeats: int) -> tuple[dict, bool]:
    """All parts on one map; returns (table rows per part, whether every length is right)."""
    map_path = mapf / f"{name}.map"
    queries = pick_scenarios(load_scenarios(mapf / f"{name}-random-1.scen"), n)

    began = time.perf_counter()
    graph = load_map(map_path)
    load_s = time.perf_counter() - began
    obstacles = read_map(map_path)
    began = time.perf_counter()
    nx_graph = networkx_grid(obstacles)
    nx_build_s = time.perf_counter() - began
    weights = pyastar_weights(obstacles)
    run = planners(graph, nx_graph, weights)

    print(f"\n{name}: {graph.shape[1]}x{graph.shape[0]}, {int(np.asarray(graph.free).sum())} free "
          f"cells, {len(queries)} queries x {repeats} repeats | jaxswarm load_map {load_s:.2f} s "
          f"| networkx graph built once in {nx_build_s:.2f} s "
          f"({nx_graph.number_of_nodes()} nodes, {nx_graph.number_of_edges()} edges)")
    print(f"  {warm_map(graph, queries[0])}")
    run["networkx astar_path"](queries[0])
    run[PYASTAR](queries[0])

    table, expanded, lengths, rows_of = bench_queries(name, run, queries, repeats)
    if len(rows_of["networkx astar_path"]) < len(queries):
        print(f"  networkx timed on {len(rows_of['networkx astar_path'])} of the "
              f"{len(queries)} rows (spread evenly; it is slow on this map)")
    batch_row, lengths["jaxswarm shortest_lengths"] = bench_batch(name, graph, weights, queries,
                                                                  repeats)
    rows_of["jaxswarm shortest_lengths"] = list(range(len(queries)))
    repair_row, worst_repair = bench_repair(name, graph, queries, repeats)

    ok = check_lengths(lengths, rows_of, queries)
    repairs_ok = worst_repair < REPAIR_TOL
    print(f"  D* Lite repairs: cost {'equals' if repairs_ok else 'DIFFERS FROM'} A*'s on the "
          f"edited map on {repair_row[1]} rows (max rel. diff {worst_repair:.1e})")
    dijkstra_over_astar = expanded[DIJKSTRA] / expanded[ASTAR]
    return {"queries": table, "batch": [batch_row], "repair": [repair_row],
            "dijkstra": [(name, dijkstra_over_astar)]}, ok and repairs_ok


def print_queries(rows: list[tuple], dijkstra_rows: list[tuple]) -> None:
    """Part 1's table, with the line on Dijkstra's expansions under it."""
    header = ("map", "planner", "rows", "total s", "mean ms/q", "median ms/q", "expanded",
              "/pyastar2d", "within 3x")
    fmt = "{:<16} {:<34} {:>4} {:>8} {:>9} {:>11} {:>9} {:>10} {:>9}"
    print("\nPer query\n" + fmt.format(*header))
    for name, planner, count, total, mean_ms, median, expanded, ratio, goal in rows:
        print(fmt.format(name, planner, count, f"{total:.3f}", f"{mean_ms:.2f}", f"{median:.2f}",
                         "-" if expanded is None else f"{expanded:.0f}", f"{ratio:.2f}x",
                         goal or "-"))
    print("total s = median over repeats of the time for the planner's rows; /pyastar2d = that "
          "total over pyastar2d's on the same rows (> 1 means slower than pyastar2d).")
    ratios = ", ".join(f"{name} {ratio:.1f}x" for name, ratio in dijkstra_rows)
    print(f"Dijkstra expands more nodes than A* (octile) by design (no heuristic): {ratios}.")


def print_batch(rows: list[tuple]) -> None:
    """Part 2's table."""
    header = ("map", "queries", "ours q/s", "search q/s", "pyastar2d q/s", "time ours/pyastar2d")
    fmt = "{:<16} {:>7} {:>9} {:>10} {:>13} {:>19}"
    print("\nBatch: shortest_lengths in one call against pyastar2d in a Python loop\n"
          + fmt.format(*header))
    for name, count, ours, search, theirs, ratio in rows:
        print(fmt.format(name, count, f"{ours:.0f}", f"{search:.0f}", f"{theirs:.0f}",
                         f"{ratio:.2f}x"))
    print("q/s = queries / median wall time over repeats; search q/s counts the compiled search "
          "alone (stats.wall_time); > 1x means ours is slower.")


def print_repair(rows: list[tuple]) -> None:
    """Part 3's table and its goal."""
    header = ("map", "rows", "repair ms", "A* scratch ms", "A* search ms", "touched repair",
              "touched solve", "goal")
    fmt = "{:<16} {:>4} {:>9} {:>13} {:>12} {:>14} {:>13} {:>7}"
    print("\nD* Lite repair after blocking the middle cell of the path\n" + fmt.format(*header))
    for name, count, repair, scratch, search, touched, solve_touched, goal in rows:
        print(fmt.format(name, count, f"{repair:.2f}", f"{scratch:.2f}", f"{search:.2f}",
                         f"{touched:.0f}", f"{solve_touched:.0f}", goal))
    print("medians over rows of each row's median over repeats; A* scratch = astar's first call "
          "on the edited map (its host arrays built), A* search = its second call. Goal: a D* "
          "Lite repair after a single-cell change well below A* from scratch (met: under half).")


def main(argv: list[str] | None = None) -> int:
    """Parse the options, run every part on every map, print the tables; 1 on a length error."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenarios", type=int, default=50, metavar="N",
                        help="scenario rows per map, spread evenly over the file (default 50)")
    parser.add_argument("--repeats", type=int, default=3, metavar="R",
                        help="timed passes over the queries; medians are reported (default 3)")
    parser.add_argument("--data", type=Path, default=REPO.parent / "shared",
                        help="the shared directory holding benchdata/movingai/mapf "
                             "(default: ../shared next to the repository)")
    args = parser.parse_args(argv)
    if args.scenarios < 1 or args.repeats < 1:
        parser.error("--scenarios and --repeats must be at least 1")
    mapf = args.data / MAPF_DIR
    if not mapf.is_dir():
        parser.error(f"no Moving AI MAPF maps in {mapf} (use --data)")

    print(machine_line())
    began = time.perf_counter()
    print(f"compile: jaxswarm.exact.warm_up() {warm_up():.2f} s (numba compiles every planner, "
          f"or loads it from its cache)")
    tables: dict[str, list] = {}
    all_ok = True
    for name in MAPS:
        rows, ok = bench_map(name, mapf, args.scenarios, args.repeats)
        for part, part_rows in rows.items():
            tables.setdefault(part, []).extend(part_rows)
        all_ok &= ok
    print_queries(tables["queries"], tables["dijkstra"])
    print_batch(tables["batch"])
    print_repair(tables["repair"])
    verdict = ("every planner matches the .scen optima and every repair A*" if all_ok
               else "MISMATCH (see above)")
    print(f"\nlengths: {verdict} | benchmark took {time.perf_counter() - began:.0f} s")
    return 0 if all_ok else 1


if __name__ == "__main__":
    sys.exit(main())
