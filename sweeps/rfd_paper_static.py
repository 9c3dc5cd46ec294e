"""The RFD paper's Table 1 (static environment), reproduced on our nine paper maps.

The paper's six algorithms, ACO in two variants and RFD* in three, beside the paper's values
(the rows of :mod:`jaxswarm.studies.rfd_table1`):

* Dijkstra and A* (exact);
* "ACO (paper, eq. 7)": Ant System as the paper's eq. 7 writes it (``ant_system``, pheromone
  only: beta = 0), and "ACO with eta (beta=1)": the same with the edge-length heuristic eta
  weighted by beta = 1; both beside the paper's ACO row;
* ACO* (``aco_star``, eq. 7 over the goal distance) and RFD (``rfd``, eqs. 1-5);
* "RFD* (paper)": the paper's RFD*, eq. 6 with the paper's erosion eqs. 4-5 on the paths of the
  drops that reached the goal (``rfd_star``, Algorithm 1's "complete paths"); "RFD* (paper, all
  travelled paths)": the same with every drop's path eroded (``rfd_star erode=travelled``, the
  text's "an erosion process is executed on all travelled paths"); and "RFD graded (ours)":
  this project's law, RFD*'s transitions over a graded river bed (``rfd_graded``); all three
  beside the paper's RFD*.

Each swarm runs once per seed (``--seeds``, default 20) for up to ``--iterations`` iterations
(default 100; a run stops earlier only when every agent of an iteration follows the same path)
with ``--agents`` drops or ants (default 256) and the swarm's default parameters (beta replaced
by 1 in the eta row) and options (``erode`` replaced in the travelled row). Runs are jitted once per map and row (a warm-up run, compile excluded) and
then timed one by one. The exact planners are deterministic: they run once per seed too, as
repeats, and their time is the search time they report themselves (``SearchStats.wall_time``).

Reported per map and row, beside the paper's row it reproduces (C#, Intel i7-3770, on the
paper's own, unpublished maps, whose optima differ slightly from our reconstructions):

* path length: the mean best length over the seeds that found a path ("n/a" if none did), with the
  count of those seeds;
* runs that reach the optimum (relative gap below 1e-4, :mod:`jaxswarm.studies.success`; not
  in the paper);
* time: the median wall time of one run [ms].

Written to ``--out`` (default ``out/rfd_paper_static``; ``make reproduce`` uses
``results/rfd_paper_table1``), each file atomically:

* ``runs.csv``: one row per map, row and seed (map, algorithm: the row's label, planner: the
  planner or registered swarm and any param it replaces, seed, optimum, cost, gap, found,
  iterations, seconds); ``cost`` and ``gap`` are inf when no path was found, ``iterations`` is
  the number of swarm iterations run (empty for the exact planners);
* ``table.md``: the provenance (:mod:`jaxswarm.studies.provenance`), then the halves of Table 1
  (rows = algorithm, ours and the paper's; columns = maps);
* ``provenance.json``: the provenance, the arguments and each row's config and params;
* ``best_paths.png``: the maps (3 per row) with each row's best path (its best seed's).

Run from the repository root::

    python sweeps/rfd_paper_static.py                      # all nine maps, 20 seeds
    python sweeps/rfd_paper_static.py --maps mosaic20,alley20,maze20 --seeds 5
"""
from __future__ import annotations

import argparse
import time
from collections.abc import Callable

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure

from jaxswarm.maps.named import named_map
from jaxswarm.maps.paper import PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS, paper_maps_argument
from jaxswarm.plot.graph import draw_map
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts
from jaxswarm.studies.figures import panel_grid, write_png
from jaxswarm.studies.problems import Problem, named_problem
from jaxswarm.sweep.run_record import COLUMNS as REPLAY_COLUMNS
from jaxswarm.studies.rfd_table1 import (ABOUT, ALGORITHMS, BY_LABEL, ROWS, Row, draw_best_paths,
                                         length_cell, optimal_cell, row_definitions,
                                         run_planner_row, run_swarm_row, time_cell)
from jaxswarm.studies.success import SUCCESS_GAP, relative_gap
from jaxswarm.world.paths import Solution

COLUMNS = ("map", "algorithm", "planner", "seed", "optimum", "cost", "gap", "found", "iterations",
           "seconds", *REPLAY_COLUMNS)
"""Columns of runs.csv (``run_record`` and ``fingerprint``: what ``jaxswarm replay`` needs to
run a swarm's row again; empty for an exact planner's)."""
TITLE = "RFD paper, Table 1 (static environment): ours beside the paper's"
"""Title of table.md."""


def make_row(problem: Problem, row: Row, seed: int, solution: Solution, iterations: int | str,
             seconds: float, replay: dict | None = None) -> dict:
    """One runs.csv row for one run of ``row`` on ``problem`` and its best ``solution`` (cost
    f[], found bool[]); ``replay``: a swarm run's replay columns."""
    cost = float(solution.cost)
    return dict(map=problem.label, algorithm=row.label, planner=row.planner(), seed=seed,
                optimum=problem.optimum, cost=cost, gap=relative_gap(cost, problem.optimum),
                found=bool(solution.found), iterations=iterations, seconds=seconds,
                **(replay or dict.fromkeys(REPLAY_COLUMNS, "")))


def solve_row(row: Row, problem: Problem, seeds: int, *, iterations: int,
              agents: int) -> tuple[list[dict], Solution]:
    """Run ``row`` on ``problem`` once per seed: an exact planner as repeats (timed by its own
    ``stats.wall_time``), a swarm with keys split from key 0 (compiled first, each run timed
    alone).

    Returns:
      (one runs.csv row per seed; the Solution of the first seed with the lowest cost, path
      i32[L] -1 padded).
    """
    if row.swarm is None:
        solutions = run_planner_row(row, problem, seeds)
        rows = [make_row(problem, row, seed, solution, "", solution.stats.wall_time)
                for seed, solution in enumerate(solutions)]
    else:
        swarm, runs = run_swarm_row(row, problem, seeds, iterations=iterations, agents=agents)
        solutions = [swarm.best(one.state) for one in runs]
        rows = [make_row(problem, row, seed, solution, int(one.trace.iterations), one.seconds,
                         one.replay)
                for seed, (solution, one) in enumerate(zip(solutions, runs))]
    return rows, min(solutions, key=lambda solution: float(solution.cost))


def solve_map(name: str, seeds: int, *, iterations: int,
              agents: int) -> tuple[list[dict], dict[str, Solution]]:
    """Run every row's algorithm on paper map ``name``, printing one progress line per row.

    Returns:
      (the runs.csv rows, row label -> its best Solution over the seeds).
    """
    problem = named_problem(name)
    rows, best = [], {}
    for row in ROWS:
        began = time.perf_counter()
        mine, best[row.label] = solve_row(row, problem, seeds, iterations=iterations,
                                          agents=agents)
        rows += mine
        print(f"{name:10} {row.label:22} found {sum(r['found'] for r in mine):2d}/{seeds} "
              f"best {float(best[row.label].cost):8.2f} (optimum {problem.optimum:.2f}, "
              f"{time.perf_counter() - began:.0f} s)", flush=True)
    return rows, best


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
        f"## Runs that reach the optimum (relative gap below {SUCCESS_GAP:g}; not in the paper)",
        "",
        *half_table(rows, maps, optimal_cell),
        "",
        "## Time per run [ms]: median over the seeds (compile excluded)",
        "",
        *half_table(rows, maps, time_cell, PAPER_TABLE1_MS, str),
    ]) + "\n"


def figure(best: dict[str, dict[str, Solution]]) -> Figure:
    """The maps, three per row (a 3 x 3 grid for all nine), each with every row's best path over
    it, labelled with its cost.

    Args:
      best: map name -> row label -> Solution (path i32[L], -1 padded; empty if not found).

    Returns:
      The figure (close it with ``plt.close(fig)``).
    """
    fig, axes = panel_grid(len(best), columns=3, width=5, height=5.9)
    for (name, solutions), ax in zip(best.items(), axes):
        chosen = named_map(name)
        draw_map(ax, chosen.graph, start=chosen.start, goal=chosen.goal, title=name)
        draw_best_paths(ax, chosen.graph, solutions, thinning=0.55)
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
    add_out_argument(parser, "rfd_paper_static", "rfd_paper_table1")
    args = parser.parse_args(argv)
    check_counts(parser, args, "seeds", "iterations", "agents")
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
    write_png(figure(best), args.out / "best_paths.png")
    print("\n" + markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
