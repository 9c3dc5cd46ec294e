"""Exact planners against networkx on Moving AI maps.

What is measured
----------------
For the Moving AI maps ``maze-128-128-10`` and ``den312d``, ``--scenarios N`` rows spread evenly
over each map's ``-random-1.scen`` file are solved, in one process, by

* jaxswarm ``astar`` (octile heuristic) and ``dijkstra``: the host heapq planners of
  :mod:`jaxswarm.exact`, called on a Graph loaded once per map. One warm-up call per map builds
  the cached host adjacency lists first, so the timings exclude that one-off cost (reported
  separately as "warm-up").
* networkx ``astar_path`` with an octile heuristic, plus ``path_weight`` for its length, on a
  networkx graph built once per map from the same ``.map`` file with the same convention
  (8-connected, diagonal weight sqrt 2, no corner cutting: a diagonal move only when both
  orthogonal cells are free). networkx ``dijkstra_path`` (+ ``path_weight``) is timed too, so
  each of our planners also has a like-for-like baseline.

Every query is timed from the wall clock (``time.perf_counter``) around the call, so the figures
include each library's per-call overhead (our endpoint checks and ``Solution`` packing, networkx's
path reconstruction). The N queries are run ``--repeats R`` times, the planners interleaved within
each repeat. Per (map, planner) the script prints

* ``total s``: the median over the R repeats of the total time of the N queries,
* ``mean ms/q``: that total divided by N,
* ``median ms/q``: the median over the N queries of each query's median time over the repeats,
* ``nx A*/ours``: networkx ``astar_path``'s total divided by this planner's total (> 1 means ours
  is faster), and ``nx same/ours``: the same against networkx's implementation of the same
  algorithm (``astar_path`` for A*, ``dijkstra_path`` for Dijkstra).

It then checks that all planners return the same length on every query (relative error < 1e-6)
and that these match the optimal lengths published in the ``.scen`` file, and says so; the exit
status is 1 if any length disagrees.

How to run
----------
From the repository root (defaults take well under two minutes on a laptop CPU)::

    python -m benchmarks.exact                    # 50 rows per map, 5 repeats
    python benchmarks/exact.py --scenarios 200 --repeats 3
    python benchmarks/exact.py --data /path/to/shared

``--data`` is the ``shared`` directory holding ``benchdata/movingai/mapf`` (default: ``../shared``
next to the repository root).
"""
from __future__ import annotations

import argparse
import math
import os
import platform
import sys
import time
from pathlib import Path
from typing import Callable

import jax
import networkx as nx
import numpy as np

from jaxswarm.exact import astar, dijkstra
from jaxswarm.maps.movingai import Scenario, load_map, load_scenarios, read_map

REPO = Path(__file__).resolve().parents[1]

MAPS = ("maze-128-128-10", "den312d")
SQRT2 = math.sqrt(2.0)
REL_TOL = 1e-6
MAPF_DIR = Path("benchdata", "movingai", "mapf")


def machine_line() -> str:
    """Where the figures come from: platform, CPU, core count, library versions."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return (f"machine: {platform.platform()} | {cpu} | {os.cpu_count()} CPUs | "
            f"python {platform.python_version()} | jax {jax.__version__} "
            f"({jax.default_backend()}) | networkx {nx.__version__} | numpy {np.__version__}")


def pick_scenarios(rows: list[Scenario], n: int) -> list[Scenario]:
    """``n`` reachable rows spread evenly over the file (first and last included)."""
    reachable = [row for row in rows if row.reachable]
    if n >= len(reachable):
        return reachable
    return [reachable[i] for i in np.linspace(0, len(reachable) - 1, n).round().astype(int)]


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


def planners(graph, nx_graph) -> dict[str, Callable[[Scenario], float]]:
    """Name -> function(scenario) -> path length, for every planner timed."""
    def nx_length(path):
        return nx.path_weight(nx_graph, path, weight="weight")

    return {
        "jaxswarm astar": lambda s: float(astar(graph, s.start, s.goal).cost),
        "jaxswarm dijkstra": lambda s: float(dijkstra(graph, s.start, s.goal).cost),
        "networkx astar_path": lambda s: nx_length(
            nx.astar_path(nx_graph, s.start, s.goal, heuristic=octile, weight="weight")),
        "networkx dijkstra_path": lambda s: nx_length(
            nx.dijkstra_path(nx_graph, s.start, s.goal, weight="weight")),
    }


BASELINE = {"jaxswarm astar": "networkx astar_path",
            "jaxswarm dijkstra": "networkx dijkstra_path"}


def time_queries(run: Callable[[Scenario], float], queries: list[Scenario]):
    """(lengths, per-query seconds) of one pass over the queries, wall clock around each call."""
    lengths, seconds = [], []
    for query in queries:
        began = time.perf_counter()
        length = run(query)
        seconds.append(time.perf_counter() - began)
        lengths.append(length)
    return lengths, seconds


def rel_diff(a: float, b: float) -> float:
    return abs(a - b) / max(abs(b), 1.0)


def bench_map(name: str, mapf: Path, n: int, repeats: int) -> tuple[list[tuple], bool]:
    """Time every planner on one map; returns (table rows, whether all lengths agree)."""
    map_path = mapf / f"{name}.map"
    queries = pick_scenarios(load_scenarios(mapf / f"{name}-random-1.scen"), n)

    began = time.perf_counter()
    graph = load_map(map_path)
    load_s = time.perf_counter() - began
    began = time.perf_counter()
    nx_graph = networkx_grid(read_map(map_path))
    nx_build_s = time.perf_counter() - began
    run = planners(graph, nx_graph)

    # Warm-up: the first jaxswarm call on a map builds its cached host adjacency lists.
    began = time.perf_counter()
    run["jaxswarm astar"](queries[0])
    warm_s = time.perf_counter() - began
    run["networkx astar_path"](queries[0])
    print(f"\n{name}: {graph.shape[1]}x{graph.shape[0]}, {int(np.asarray(graph.free).sum())} free "
          f"cells, {len(queries)} queries x {repeats} repeats | jaxswarm load_map {load_s:.2f} s, "
          f"warm-up (host adjacency) {warm_s:.2f} s | networkx graph built once in "
          f"{nx_build_s:.2f} s ({nx_graph.number_of_nodes()} nodes, "
          f"{nx_graph.number_of_edges()} edges)")

    times = {planner: np.zeros((repeats, len(queries))) for planner in run}
    lengths = {}
    for r in range(repeats):
        for planner, fn in run.items():
            lengths[planner], times[planner][r] = time_queries(fn, queries)

    totals = {planner: float(np.median(t.sum(axis=1))) for planner, t in times.items()}
    rows = []
    for planner, t in times.items():
        baseline = BASELINE.get(planner)
        rows.append((
            name, planner, totals[planner], 1e3 * totals[planner] / len(queries),
            1e3 * float(np.median(np.median(t, axis=0))),
            totals["networkx astar_path"] / totals[planner] if baseline else None,
            totals[baseline] / totals[planner] if baseline else None,
        ))

    # Lengths: every planner against the first, and against the published optimum.
    reference = lengths["jaxswarm astar"]
    worst_pair = max(rel_diff(lengths[p][i], reference[i])
                     for p in lengths for i in range(len(queries)))
    worst_scen = max(rel_diff(reference[i], q.optimal_length) for i, q in enumerate(queries))
    agree = worst_pair < REL_TOL
    matches = worst_scen < REL_TOL
    print(f"  lengths: {len(run)} planners {'agree' if agree else 'DISAGREE'} on "
          f"{len(queries)} queries (max rel. diff {worst_pair:.1e}); "
          f"{'match' if matches else 'DO NOT MATCH'} the .scen optimal lengths "
          f"(max rel. diff {worst_scen:.1e})")
    if not (agree and matches):
        for i, query in enumerate(queries):
            found = {p: lengths[p][i] for p in lengths}
            if max(rel_diff(v, query.optimal_length) for v in found.values()) >= REL_TOL:
                print(f"    line {query.line} {query.start}->{query.goal}: "
                      f"scen {query.optimal_length:.8f} {found}")
    return rows, agree and matches


def print_table(rows: list[tuple]) -> None:
    header = ("map", "planner", "total s", "mean ms/q", "median ms/q", "nx A*/ours",
              "nx same/ours")
    fmt = "{:<16} {:<23} {:>8} {:>10} {:>12} {:>11} {:>13}"
    print("\n" + fmt.format(*header))
    for name, planner, total, mean_ms, median_ms, ratio_astar, ratio_same in rows:
        print(fmt.format(name, planner, f"{total:.3f}", f"{mean_ms:.2f}", f"{median_ms:.2f}",
                         "-" if ratio_astar is None else f"{ratio_astar:.2f}x",
                         "-" if ratio_same is None else f"{ratio_same:.2f}x"))
    print("total s = median over repeats of the time for all queries; ratios are totals "
          "(networkx / ours; > 1 means ours is faster).")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenarios", type=int, default=50, metavar="N",
                        help="scenario rows per map, spread evenly over the file (default 50)")
    parser.add_argument("--repeats", type=int, default=5, metavar="R",
                        help="timed passes over the queries; medians are reported (default 5)")
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
    table, all_ok = [], True
    for name in MAPS:
        rows, ok = bench_map(name, mapf, args.scenarios, args.repeats)
        table += rows
        all_ok &= ok
    print_table(table)
    verdict = ("all planners agree with each other and with the .scen optima" if all_ok
               else "MISMATCH (see above)")
    print(f"lengths: {verdict} | benchmark took {time.perf_counter() - began:.0f} s")
    return 0 if all_ok else 1


if __name__ == "__main__":
    sys.exit(main())
