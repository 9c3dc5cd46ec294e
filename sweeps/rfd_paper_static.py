"""The RFD paper's Table 1 (static environment), reproduced on our nine paper maps.

Six algorithms, as in the paper: Dijkstra, A*, ACO (Ant System), ACO* (with the goal-distance
heuristic), RFD and RFD*. Each swarm runs once per seed (``--seeds``, default 20) for up to
``--iterations`` iterations (default 100; a run stops earlier only when every agent of an iteration
follows the same path) with ``--agents`` drops or ants (default 256) and the swarm's default
parameters. Runs are jitted once per map and swarm (a warm-up run, compile excluded) and then timed
one by one. The exact planners are deterministic: they run once per seed too, as repeats, and their
time is the search time they report themselves (``SearchStats.wall_time``).

Reported per map and algorithm, beside the paper's values (C#, Intel i7-3770, on the paper's own,
unpublished maps, whose optima differ slightly from our reconstructions):

* path length: the mean best length over the seeds that found a path ("n/a" if none did), with the
  count of those seeds;
* time: the median wall time of one run [ms].

Written to ``--out`` (default ``out/rfd_paper_static``), each file atomically:

* ``runs.csv``: one row per map, algorithm and seed (map, algorithm, seed, optimum, cost, gap,
  found, iterations, seconds); ``cost`` and ``gap`` are inf when no path was found, ``iterations``
  is the number of swarm iterations run (empty for the exact planners);
* ``table.md``: the two halves of Table 1 (rows = algorithm, ours and the paper's; columns = maps);
* ``best_paths.png``: the maps (3 per row) with each algorithm's best path (its best seed's).

Run from the repository root::

    python sweeps/rfd_paper_static.py                      # all nine maps, 20 seeds (long)
    python sweeps/rfd_paper_static.py --maps mosaic20,alley20,maze20 --seeds 5
"""
from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable
from pathlib import Path

import jax
import matplotlib

matplotlib.use("Agg")
from matplotlib import pyplot as plt
from matplotlib.figure import Figure

from jaxswarm.atomic import write_atomically, write_csv
from jaxswarm.cli import paper_maps_argument
from jaxswarm.exact import astar, dijkstra
from jaxswarm.graph import Graph
from jaxswarm.maps.paper import (
    PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS, PaperMap, paper_map)
from jaxswarm.paths import Solution
from jaxswarm.plot import draw_map, draw_paths, save_png
from jaxswarm.swarm import make, make_task, run

PLANNERS = {"Dijkstra": dijkstra, "A*": astar}
"""Exact planners: Table 1 row label -> planner."""
SWARMS = {"ACO": "ant_system", "ACO*": "aco_star", "RFD": "rfd", "RFD*": "rfd_star"}
"""Swarms: Table 1 row label -> registered swarm name."""
ALGORITHMS = (*PLANNERS, *SWARMS)
"""Row labels, in the paper's order."""
COLORS = {"Dijkstra": "tab:blue", "A*": "tab:cyan", "ACO": "tab:orange", "ACO*": "tab:red",
          "RFD": "tab:purple", "RFD*": "tab:green"}
"""Path colour of each algorithm in the figure."""
COLUMNS = ("map", "algorithm", "seed", "optimum", "cost", "gap", "found", "iterations", "seconds")
"""Columns of runs.csv."""


def make_row(name: str, algorithm: str, seed: int, optimum: float, solution: Solution,
             iterations: int | str, seconds: float) -> dict:
    """One runs.csv row for one run's best ``solution`` (cost f[], found bool[])."""
    cost = float(solution.cost)
    return dict(map=name, algorithm=algorithm, seed=seed, optimum=optimum, cost=cost,
                gap=(cost - optimum) / optimum, found=bool(solution.found),
                iterations=iterations, seconds=seconds)


def run_planner(algorithm: str, chosen: PaperMap, graph: Graph, seeds: int,
                optimum: float) -> tuple[list[dict], Solution]:
    """Run the exact planner ``algorithm`` on paper map ``chosen`` (its ``graph``) ``seeds`` times.

    Returns:
      (one row per repeat, timed by the planner's own ``stats.wall_time``; the last Solution,
      path i32[N] -1 padded; every repeat gives the same one).
    """
    rows = []
    for seed in range(seeds):
        solution = PLANNERS[algorithm](graph, chosen.start, chosen.goal)
        rows.append(make_row(chosen.name, algorithm, seed, optimum, solution, "",
                             solution.stats.wall_time))
    return rows, solution


def run_swarm(algorithm: str, chosen: PaperMap, graph: Graph, seeds: int, optimum: float, *,
              iterations: int, agents: int) -> tuple[list[dict], Solution]:
    """Run the swarm ``algorithm`` on paper map ``chosen`` (its ``graph``) once per seed, with
    keys split from key 0.

    The run is compiled by a warm-up call first; each seed's run is then timed alone.

    Returns:
      (one row per seed; the Solution of the seed with the lowest cost, path i32[L] -1 padded).
    """
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make(SWARMS[algorithm], num_agents=agents)

    def one_run(key):
        return run(swarm, key, graph, task, swarm.default_params, iterations=iterations)

    keys = jax.random.split(jax.random.key(0), seeds)
    jax.block_until_ready(one_run(keys[0]))  # compile
    rows, best = [], None
    for seed, key in enumerate(keys):
        began = time.perf_counter()
        state, trace = jax.block_until_ready(one_run(key))
        seconds = time.perf_counter() - began
        solution = swarm.best(state)
        rows.append(make_row(chosen.name, algorithm, seed, optimum, solution,
                             int(trace.iterations), seconds))
        if best is None or float(solution.cost) < float(best.cost):
            best = solution
    return rows, best


def solve_map(name: str, seeds: int, *, iterations: int,
              agents: int) -> tuple[list[dict], dict[str, Solution]]:
    """Run every algorithm on paper map ``name``, printing one progress line per algorithm.

    Returns:
      (the runs.csv rows, algorithm -> its best Solution over the seeds).
    """
    chosen = paper_map(name)
    graph = chosen.graph()
    optimum = float(dijkstra(graph, chosen.start, chosen.goal).cost)
    rows, best = [], {}
    for algorithm in ALGORITHMS:
        began = time.perf_counter()
        if algorithm in PLANNERS:
            mine, best[algorithm] = run_planner(algorithm, chosen, graph, seeds, optimum)
        else:
            mine, best[algorithm] = run_swarm(algorithm, chosen, graph, seeds, optimum,
                                              iterations=iterations, agents=agents)
        rows += mine
        print(f"{name:10} {algorithm:8} found {sum(r['found'] for r in mine):2d}/{seeds} "
              f"best {float(best[algorithm].cost):8.2f} (optimum {optimum:.2f}, "
              f"{time.perf_counter() - began:.0f} s)", flush=True)
    return rows, best


def length_cell(runs: list[dict]) -> str:
    """Mean cost over the runs that found a path ("n/a" if none did) and the found count."""
    found = [r["cost"] for r in runs if r["found"]]
    mean = f"{statistics.mean(found):.2f}" if found else "n/a"
    return f"{mean} ({len(found)}/{len(runs)})"


def time_cell(runs: list[dict]) -> str:
    """Median wall time of one run, in ms."""
    return f"{1e3 * statistics.median(r['seconds'] for r in runs):.2f}"


def half_table(rows: list[dict], maps: tuple[str, ...], ours: Callable[[list[dict]], str],
               paper: dict[str, dict[str, float | None]],
               paper_format: Callable[[float], str]) -> list[str]:
    """Markdown lines of one half of Table 1: per algorithm a row of ours and one of the paper's.

    ``ours`` turns one map's and algorithm's runs into a cell; ``paper_format`` a paper value.
    """
    lines = ["| algorithm | source | " + " | ".join(maps) + " |",
             "| --- | --- |" + " ---: |" * len(maps)]
    for algorithm in sorted({r["algorithm"] for r in rows}, key=ALGORITHMS.index):
        mine = [ours([r for r in rows if r["map"] == m and r["algorithm"] == algorithm])
                for m in maps]
        theirs = ["n/a" if paper[algorithm][m] is None else paper_format(paper[algorithm][m])
                  for m in maps]
        lines += [f"| {algorithm} | ours | " + " | ".join(mine) + " |",
                  f"| {algorithm} | paper | " + " | ".join(theirs) + " |"]
    return lines


def table(rows: list[dict], maps: tuple[str, ...], *, seeds: int, iterations: int,
          agents: int) -> str:
    """The Markdown report: path length and time per run, ours beside the paper's Table 1."""
    return "\n".join([
        "# RFD paper, Table 1 (static environment): ours beside the paper's",
        "",
        f"{seeds} seeds, at most {iterations} iterations, {agents} drops/ants per iteration. "
        "The paper's values are for its own maps (C#, Intel i7-3770); ours are reconstructions, "
        "so the optima (the Dijkstra rows) differ slightly.",
        "",
        "## Path length: mean over the seeds that found a path (seeds that found one)",
        "",
        *half_table(rows, maps, length_cell, PAPER_TABLE1_LENGTH, lambda v: f"{v:.2f}"),
        "",
        "## Time per run [ms]: median over the seeds (compile excluded)",
        "",
        *half_table(rows, maps, time_cell, PAPER_TABLE1_MS, str),
    ]) + "\n"


def figure(best: dict[str, dict[str, Solution]]) -> Figure:
    """The maps, three per row (a 3 x 3 grid for all nine), each with every algorithm's best
    path over it, labelled with its cost.

    Args:
      best: map name -> algorithm -> Solution (path i32[L], -1 padded; empty if not found).

    Returns:
      The figure (close it with ``plt.close(fig)``).
    """
    rows, columns = math.ceil(len(best) / 3), min(len(best), 3)
    fig, axes = plt.subplots(rows, columns, figsize=(5 * columns, 5.6 * rows), squeeze=False,
                             layout="constrained")
    for ax in axes.flat[len(best):]:
        ax.set_visible(False)
    for (name, solutions), ax in zip(best.items(), axes.flat):
        chosen = paper_map(name)
        graph = chosen.graph()
        draw_map(ax, graph, start=chosen.start, goal=chosen.goal, title=name)
        # Thick lines first, so paths that coincide (Dijkstra and A*, or an optimal swarm) all show.
        for thinner, (algorithm, solution) in enumerate(solutions.items()):
            cost = f"{float(solution.cost):.2f}" if bool(solution.found) else "no path"
            draw_paths(ax, graph, [solution], [f"{algorithm} ({cost})"],
                       colors=[COLORS[algorithm]], linewidth=4.5 - 0.6 * thinner)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.03), ncols=3, frameon=False,
                  fontsize="small")
    fig.suptitle("Best path of each algorithm over the seeds (RFD paper, static environment)")
    return fig


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument, default="all",
                        help="comma-separated paper maps, or all")
    parser.add_argument("--seeds", type=int, default=20, help="runs per map and algorithm")
    parser.add_argument("--iterations", type=int, default=100, help="iterations per swarm run")
    parser.add_argument("--agents", type=int, default=256, help="drops or ants per iteration")
    parser.add_argument("--out", type=Path, default=Path("out/rfd_paper_static"))
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error("--seeds must be at least 1")
    rows, best = [], {}
    for name in args.maps:
        mine, best[name] = solve_map(name, args.seeds, iterations=args.iterations,
                                     agents=args.agents)
        rows += mine
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    markdown = table(rows, args.maps, seeds=args.seeds, iterations=args.iterations,
                     agents=args.agents)
    write_atomically(args.out / "table.md", markdown)
    fig = figure(best)
    save_png(fig, args.out / "best_paths.png")
    plt.close(fig)
    print("\n" + markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
