"""The RFD paper's Table 1 (static environment), reproduced on our nine paper maps.

The paper's six algorithms, with two of them in two variants, beside the paper's values:

* Dijkstra and A* (exact);
* "ACO (paper, eq. 7)": Ant System as the paper's eq. 7 writes it (``ant_system``, pheromone
  only: beta = 0), and "ACO with eta (beta=1)": the same with the edge-length heuristic eta
  weighted by beta = 1; both beside the paper's ACO row;
* ACO* (``aco_star``, eq. 7 over the goal distance) and RFD (``rfd``, eqs. 1-5);
* "RFD* (paper)": the paper's RFD*, eq. 6 with the paper's erosion eqs. 4-5 (``rfd_star``), and
  "RFD graded (ours)": this project's law, RFD*'s transitions over a graded river bed
  (``rfd_graded``, registered as ``rfd_star`` until jaxswarm 0.2.0); both beside the paper's RFD*.

Each swarm runs once per seed (``--seeds``, default 20) for up to ``--iterations`` iterations
(default 100; a run stops earlier only when every agent of an iteration follows the same path)
with ``--agents`` drops or ants (default 256) and the swarm's default parameters (beta replaced
by 1 in the eta row). Runs are jitted once per map and row (a warm-up run, compile excluded) and
then timed one by one. The exact planners are deterministic: they run once per seed too, as
repeats, and their time is the search time they report themselves (``SearchStats.wall_time``).

Reported per map and row, beside the paper's row it reproduces (C#, Intel i7-3770, on the
paper's own, unpublished maps, whose optima differ slightly from our reconstructions):

* path length: the mean best length over the seeds that found a path ("n/a" if none did), with the
  count of those seeds;
* runs that reach the optimum (relative gap below 1e-4; not in the paper);
* time: the median wall time of one run [ms].

Written to ``--out`` (default ``out/rfd_paper_static``; ``make reproduce`` uses
``results/rfd_paper_table1``), each file atomically:

* ``runs.csv``: one row per map, row and seed (map, algorithm: the row's label, planner: the
  planner or registered swarm and any param it replaces, seed, optimum, cost, gap, found,
  iterations, seconds); ``cost`` and ``gap`` are inf when no path was found, ``iterations`` is
  the number of swarm iterations run (empty for the exact planners);
* ``table.md``: the provenance (:mod:`provenance`), then the halves of Table 1 (rows = algorithm,
  ours and the paper's; columns = maps);
* ``provenance.json``: the provenance, the arguments and each row's config and params;
* ``best_paths.png``: the maps (3 per row) with each row's best path (its best seed's).

Run from the repository root::

    python sweeps/rfd_paper_static.py                      # all nine maps, 20 seeds
    python sweeps/rfd_paper_static.py --maps mosaic20,alley20,maze20 --seeds 5
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

import jax
import matplotlib
import numpy as np

matplotlib.use("Agg")
from matplotlib import pyplot as plt
from matplotlib.figure import Figure

from jaxswarm.exact import astar, dijkstra
from jaxswarm.maps.paper import (
    PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS, PaperMap, paper_map, paper_maps_argument)
from jaxswarm.plot.graph import draw_map, draw_paths, save_png
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.swarm import Swarm, definition, make, make_task, run
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution
from jaxswarm.studies import provenance



class Row(NamedTuple):
    """One row of our Table 1: an exact planner (``swarm`` None) or a registered swarm."""

    label: str
    """The row's label in our table."""
    paper: str | None
    """The paper's Table 1 row it reproduces (a key of ``PAPER_TABLE1_LENGTH``), None if none."""
    swarm: str | None = None
    """The registered swarm; None for an exact planner (``PLANNERS[label]``)."""
    params: tuple[tuple[str, float], ...] = ()
    """(name, value) of the swarm params that replace its defaults."""

    def planner(self) -> str:
        """What runs: the planner, or the registered swarm with the params it replaces."""
        if self.swarm is None:
            return PLANNERS[self.label].__name__
        return " ".join([self.swarm, *(f"{name}={value:g}" for name, value in self.params)])


PLANNERS = {"Dijkstra": dijkstra, "A*": astar}
"""Exact planners: Table 1 row label -> planner."""
ROWS = (
    Row("Dijkstra", "Dijkstra"),
    Row("A*", "A*"),
    Row("ACO (paper, eq. 7)", "ACO", "ant_system"),
    Row("ACO with eta (beta=1)", "ACO", "ant_system", (("beta", 1.0),)),
    Row("ACO*", "ACO*", "aco_star"),
    Row("RFD", "RFD", "rfd"),
    Row("RFD* (paper)", "RFD*", "rfd_star"),
    Row("RFD graded (ours)", "RFD*", "rfd_graded"),
)
"""The rows, in the paper's order, each variant after the one the paper writes."""
BY_LABEL = {row.label: row for row in ROWS}
"""Row label -> Row."""
ALGORITHMS = tuple(BY_LABEL)
"""Row labels, in table order."""
COLORS = dict(zip(ALGORITHMS, ("tab:blue", "tab:cyan", "tab:orange", "tab:brown", "tab:red",
                               "tab:purple", "tab:olive", "tab:green")))
"""Path colour of each row in the figure."""
COLUMNS = ("map", "algorithm", "planner", "seed", "optimum", "cost", "gap", "found", "iterations",
           "seconds")
"""Columns of runs.csv."""
OPTIMAL_GAP = 1e-4
"""A run reaches the optimum when its relative gap to it is below this."""
TITLE = "RFD paper, Table 1 (static environment): ours beside the paper's"
"""Title of table.md."""
ABOUT = (
    "Rows: Dijkstra and A* (exact); \"ACO (paper, eq. 7)\" is the RFD paper's Ant System "
    "(`ant_system`, pheromone only, beta = 0) and \"ACO with eta (beta=1)\" the same with the "
    "edge-length heuristic weighted by beta = 1; ACO* (`aco_star`) and RFD (`rfd`) are the "
    "paper's; \"RFD* (paper)\" is the paper's RFD* as written (`rfd_star`: eq. 6 with the "
    "erosion of eqs. 4-5). \"RFD graded (ours)\" (`rfd_graded`) is not the paper's algorithm but "
    "this project's law (RFD*'s transitions over a graded river bed; registered as `rfd_star` "
    "until jaxswarm 0.2.0). Under each row, the paper's values of the row it reproduces: both "
    "ACO rows the paper's ACO, both RFD* rows the paper's RFD*.")
"""What the rows are (the paragraph under the provenance)."""


def make_row(name: str, row: Row, seed: int, optimum: float, solution: Solution,
             iterations: int | str, seconds: float) -> dict:
    """One runs.csv row for one run of ``row`` and its best ``solution`` (cost f[],
    found bool[])."""
    cost = float(solution.cost)
    return dict(map=name, algorithm=row.label, planner=row.planner(), seed=seed, optimum=optimum,
                cost=cost, gap=(cost - optimum) / optimum, found=bool(solution.found),
                iterations=iterations, seconds=seconds)


def run_planner(row: Row, chosen: PaperMap, graph: Graph, seeds: int,
                optimum: float) -> tuple[list[dict], Solution]:
    """Run the exact planner of ``row`` on paper map ``chosen`` (its ``graph``) ``seeds`` times.

    Returns:
      (one row per repeat, timed by the planner's own ``stats.wall_time``; the last Solution,
      path i32[N] -1 padded; every repeat gives the same one).
    """
    rows = []
    for seed in range(seeds):
        solution = PLANNERS[row.label](graph, chosen.start, chosen.goal)
        rows.append(make_row(chosen.name, row, seed, optimum, solution, "",
                             solution.stats.wall_time))
    return rows, solution


def row_swarm(row: Row, agents: int) -> tuple[Swarm, tuple]:
    """The swarm of ``row`` with ``agents`` drops or ants, and its params: the defaults with the
    row's replacements (float32 scalars)."""
    swarm = make(row.swarm, num_agents=agents)
    params = swarm.default_params._replace(
        **{name: np.float32(value) for name, value in row.params})
    return swarm, params


def run_swarm(row: Row, chosen: PaperMap, graph: Graph, seeds: int, optimum: float, *,
              iterations: int, agents: int) -> tuple[list[dict], Solution]:
    """Run the swarm of ``row`` on paper map ``chosen`` (its ``graph``) once per seed, with
    keys split from key 0.

    The run is compiled by a warm-up call first; each seed's run is then timed alone.

    Returns:
      (one row per seed; the Solution of the seed with the lowest cost, path i32[L] -1 padded).
    """
    task = make_task(graph, chosen.start, chosen.goal)
    swarm, params = row_swarm(row, agents)

    def one_run(key):
        return run(swarm, key, graph, task, params, iterations=iterations)

    keys = jax.random.split(jax.random.key(0), seeds)
    jax.block_until_ready(one_run(keys[0]))  # compile
    rows, best = [], None
    for seed, key in enumerate(keys):
        began = time.perf_counter()
        state, trace = jax.block_until_ready(one_run(key))
        seconds = time.perf_counter() - began
        solution = swarm.best(state)
        rows.append(make_row(chosen.name, row, seed, optimum, solution, int(trace.iterations),
                             seconds))
        if best is None or float(solution.cost) < float(best.cost):
            best = solution
    return rows, best


def solve_map(name: str, seeds: int, *, iterations: int,
              agents: int) -> tuple[list[dict], dict[str, Solution]]:
    """Run every row's algorithm on paper map ``name``, printing one progress line per row.

    Returns:
      (the runs.csv rows, row label -> its best Solution over the seeds).
    """
    chosen = paper_map(name)
    graph = chosen.graph()
    optimum = float(dijkstra(graph, chosen.start, chosen.goal).cost)
    rows, best = [], {}
    for row in ROWS:
        began = time.perf_counter()
        if row.swarm is None:
            mine, best[row.label] = run_planner(row, chosen, graph, seeds, optimum)
        else:
            mine, best[row.label] = run_swarm(row, chosen, graph, seeds, optimum,
                                              iterations=iterations, agents=agents)
        rows += mine
        print(f"{name:10} {row.label:22} found {sum(r['found'] for r in mine):2d}/{seeds} "
              f"best {float(best[row.label].cost):8.2f} (optimum {optimum:.2f}, "
              f"{time.perf_counter() - began:.0f} s)", flush=True)
    return rows, best


def length_cell(runs: list[dict]) -> str:
    """Mean cost over the runs that found a path ("n/a" if none did) and the found count."""
    found = [r["cost"] for r in runs if r["found"]]
    mean = f"{statistics.mean(found):.2f}" if found else "n/a"
    return f"{mean} ({len(found)}/{len(runs)})"


def optimal_cell(runs: list[dict]) -> str:
    """How many of the runs reach the optimum (relative gap below ``OPTIMAL_GAP``)."""
    return f"{sum(r['gap'] < OPTIMAL_GAP for r in runs)}/{len(runs)}"


def time_cell(runs: list[dict]) -> str:
    """Median wall time of one run, in ms."""
    return f"{1e3 * statistics.median(r['seconds'] for r in runs):.2f}"


def paper_cells(row: Row, maps: tuple[str, ...], paper: dict[str, dict[str, float | None]],
                paper_format: Callable[[float], str]) -> list[str]:
    """The paper's values of the row ``row`` reproduces, one cell per map: "-" when the row has
    no counterpart in the paper, "n/a" where the paper has no value."""
    if row.paper is None:
        return ["-"] * len(maps)
    return ["n/a" if paper[row.paper][m] is None else paper_format(paper[row.paper][m])
            for m in maps]


def half_table(rows: list[dict], maps: tuple[str, ...], ours: Callable[[list[dict]], str],
               paper: dict[str, dict[str, float | None]] | None = None,
               paper_format: Callable[[float], str] = str) -> list[str]:
    """Markdown lines of one part of Table 1: per row a line of ours and, if ``paper`` is given,
    one of the paper's values of the row it reproduces.

    ``ours`` turns one map's and row's runs into a cell; ``paper_format`` a paper value.
    """
    lines = ["| algorithm | source | " + " | ".join(maps) + " |",
             "| --- | --- |" + " ---: |" * len(maps)]
    for label in sorted({r["algorithm"] for r in rows}, key=ALGORITHMS.index):
        row = BY_LABEL[label]
        mine = [ours([r for r in rows if r["map"] == m and r["algorithm"] == label])
                for m in maps]
        lines.append(f"| {label} | ours | " + " | ".join(mine) + " |")
        if paper is not None:
            source = f"paper ({row.paper})" if row.paper else "paper"
            lines.append(f"| {label} | {source} | "
                         + " | ".join(paper_cells(row, maps, paper, paper_format)) + " |")
    return lines


def table(rows: list[dict], maps: tuple[str, ...], *, seeds: int, iterations: int,
          agents: int) -> str:
    """The Markdown body of the report: path length, runs at the optimum and time per run, ours
    beside the paper's Table 1."""
    return "\n".join([
        f"{seeds} seeds, at most {iterations} iterations, {agents} drops/ants per iteration. "
        "The paper's values are for its own maps (C#, Intel i7-3770); ours are reconstructions, "
        "so the optima (the Dijkstra rows) differ slightly.",
        "",
        "## Path length: mean over the seeds that found a path (seeds that found one)",
        "",
        *half_table(rows, maps, length_cell, PAPER_TABLE1_LENGTH, lambda v: f"{v:.2f}"),
        "",
        f"## Runs that reach the optimum (relative gap below {OPTIMAL_GAP:g}; not in the paper)",
        "",
        *half_table(rows, maps, optimal_cell),
        "",
        "## Time per run [ms]: median over the seeds (compile excluded)",
        "",
        *half_table(rows, maps, time_cell, PAPER_TABLE1_MS, str),
    ]) + "\n"


def row_definitions(agents: int) -> dict[str, dict]:
    """Row label -> what ran: the paper row it reproduces, and for a swarm its name, config and
    the params used (JSON-ready)."""
    definitions = {}
    for row in ROWS:
        entry = dict(paper=row.paper, planner=row.planner())
        if row.swarm is not None:
            swarm, params = row_swarm(row, agents)
            entry.update(config=definition(swarm)["config"],
                         params={k: float(v) for k, v in params._asdict().items()})
        definitions[row.label] = entry
    return definitions


def figure(best: dict[str, dict[str, Solution]]) -> Figure:
    """The maps, three per row (a 3 x 3 grid for all nine), each with every row's best path over
    it, labelled with its cost.

    Args:
      best: map name -> row label -> Solution (path i32[L], -1 padded; empty if not found).

    Returns:
      The figure (close it with ``plt.close(fig)``).
    """
    rows, columns = math.ceil(len(best) / 3), min(len(best), 3)
    fig, axes = plt.subplots(rows, columns, figsize=(5 * columns, 5.9 * rows), squeeze=False,
                             layout="constrained")
    for ax in axes.flat[len(best):]:
        ax.set_visible(False)
    for (name, solutions), ax in zip(best.items(), axes.flat):
        chosen = paper_map(name)
        graph = chosen.graph()
        draw_map(ax, graph, start=chosen.start, goal=chosen.goal, title=name)
        # Thick lines first, so paths that coincide (Dijkstra and A*, or an optimal swarm) all show.
        for thinner, (label, solution) in enumerate(solutions.items()):
            cost = f"{float(solution.cost):.2f}" if bool(solution.found) else "no path"
            draw_paths(ax, graph, [solution], [f"{label} ({cost})"],
                       colors=[COLORS[label]], linewidth=5 - 0.55 * thinner)
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.03), ncols=2, frameon=False,
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
    parser.add_argument("--out", type=Path, default=Path("out/rfd_paper_static"),
                        help="output folder (make reproduce: results/rfd_paper_table1)")
    args = parser.parse_args(argv)
    for option in ("seeds", "iterations", "agents"):
        if getattr(args, option) < 1:
            parser.error(f"--{option} must be at least 1, got {getattr(args, option)}")
    record = provenance.begin(__file__, argv)
    rows, best = [], {}
    for name in args.maps:
        mine, best[name] = solve_map(name, args.seeds, iterations=args.iterations,
                                     agents=args.agents)
        rows += mine
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args),
                  rows=row_definitions(args.agents))
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    markdown = record.publish(args.out, table(rows, args.maps, seeds=args.seeds,
                                              iterations=args.iterations, agents=args.agents))
    fig = figure(best)
    save_png(fig, args.out / "best_paths.png")
    plt.close(fig)
    print("\n" + markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
