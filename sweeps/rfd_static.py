"""RFD, RFD* and RFD graded on the nine paper maps, static environment (the RFD paper's Table 1
set-up).

Three rows per map, the three RFD rows of the RFD paper's Table 1 as
:mod:`jaxswarm.studies.rfd_table1` runs them: the RFD paper's RFD (``rfd``, eqs. 1-5) and RFD*
(``rfd_star``, eq. 6 with the erosion of eqs. 4-5), and this project's own law ``rfd_graded``
(RFD*'s transitions over a graded river bed).
Each runs with its default params once per seed (``--seeds``, default 20) for at most 100
iterations (``--iterations``; a run also stops when every drop follows the same path, and, if
``--patience`` is given, after that many iterations without improvement). Each run is jitted once
per map and algorithm and then timed on its own (compile excluded). Reported per map and
algorithm: the optimum (Dijkstra), the mean best length over the seeds, the success count
(relative gap < 1e-4 to the optimum, :mod:`jaxswarm.studies.success`) and the median wall time
of one run. Written to ``--out`` (default ``out/rfd_static``; ``make reproduce`` uses
``results/rfd_static``), each file atomically: ``runs.csv`` (one row per map, algorithm and
seed), ``table.md`` (the provenance, then the table) and ``provenance.json``.

Run from the repository root::

    python sweeps/rfd_static.py                         # all nine maps, 20 seeds
    python sweeps/rfd_static.py --maps mosaic20,maze20 --seeds 5
"""
from __future__ import annotations

import argparse
import statistics
import time

from jaxswarm.dynamic.events import first_iteration_at
from jaxswarm.maps.paper import paper_maps_argument
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts
from jaxswarm.studies.problems import Problem, named_problem
from jaxswarm.sweep.run_record import COLUMNS as REPLAY_COLUMNS
from jaxswarm.studies.rfd_table1 import BY_SWARM, run_swarm_row
from jaxswarm.studies.success import SUCCESS_GAP, reaches_optimum, relative_gap
from jaxswarm.studies.timing import median_milliseconds
from jaxswarm.swarm import definition, make

SOURCES = {"rfd": "RFD paper", "rfd_star": "RFD paper", "rfd_graded": "ours"}
"""Registered swarm -> where its algorithm comes from, in table order."""
ALGORITHMS = tuple(SOURCES)
"""The registered swarms of the table, in order."""
COLUMNS = ("map", "algorithm", "seed", "optimum", "cost", "gap", "success", "iterations",
           "first_optimal_iteration", "seconds", "moves", "lane_steps", *REPLAY_COLUMNS)
"""Columns of runs.csv (``moves``: the drops' moves in all iterations; ``lane_steps``: the
walker's lane-steps, so ``moves / lane_steps`` is the share of its work that moved a drop;
``run_record`` and ``fingerprint``: what ``jaxswarm replay`` needs to run the row again)."""
TITLE = "RFD, RFD* and RFD graded on the RFD paper's nine maps (static environment)"
"""Title of table.md."""
ABOUT = (
    "Rows: `rfd` (the RFD paper's RFD, eqs. 1-5) and `rfd_star` (the paper's RFD*: eq. 6 with "
    "the erosion of eqs. 4-5, as written) are the paper's algorithms; `rfd_graded` is ours, not "
    "the paper's: RFD*'s transitions over a graded river bed. Each runs with its default "
    "params; success means a best length within a relative 1e-4 of the optimum (Dijkstra).")
"""What the rows are (the paragraph under the provenance)."""


def run_algorithm(problem: Problem, algorithm: str, seeds: int, *, iterations: int,
                  patience: int | None, num_agents: int) -> list[dict]:
    """Run ``algorithm`` (its Table 1 row) on ``problem`` once per seed; one row per seed."""
    swarm, runs = run_swarm_row(BY_SWARM[algorithm], problem, seeds, iterations=iterations,
                                agents=num_agents, patience=patience)
    rows = []
    for seed, one in enumerate(runs):
        cost = float(swarm.best(one.state).cost)
        gap = relative_gap(cost, problem.optimum)
        first = first_iteration_at(one.trace, problem.optimum, gap=SUCCESS_GAP)
        rows.append(dict(map=problem.label, algorithm=algorithm, seed=seed,
                         optimum=problem.optimum, cost=cost, gap=gap,
                         success=reaches_optimum(gap), iterations=int(one.trace.iterations),
                         moves=int(one.trace.moves.sum()),
                         lane_steps=int(one.trace.lane_steps.sum()),
                         first_optimal_iteration="" if first is None else first,
                         seconds=one.seconds, **one.replay))
    return rows


def summary_cells(runs: list[dict]) -> list[str]:
    """Mean length (of the runs that found a path; "n/a" if none did, with the found count if
    some did not), success count and median time [ms] of one map's and algorithm's runs."""
    finite = [r["cost"] for r in runs if r["cost"] != float("inf")]
    mean = f"{statistics.mean(finite):.2f}" if finite else "n/a"
    if finite and len(finite) < len(runs):
        mean += f" ({len(finite)} found)"
    return [mean, f"{sum(r['success'] for r in runs)}/{len(runs)}",
            f"{median_milliseconds(r['seconds'] for r in runs):.0f}"]


def table(rows: list[dict], maps: tuple[str, ...]) -> str:
    """Markdown table: per map and algorithm, the optimum, mean length, success and time."""
    lines = ["| map | optimum | algorithm | source | mean length | success | median ms |",
             "| --- | ---: | --- | --- | ---: | ---: | ---: |"]
    for name in maps:
        for algorithm in ALGORITHMS:
            mine = [r for r in rows if r["map"] == name and r["algorithm"] == algorithm]
            cells = [name, f"{mine[0]['optimum']:.2f}", algorithm, SOURCES[algorithm],
                     *summary_cells(mine)]
            lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument, default="all",
                        help="comma-separated paper maps, or all")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--patience", type=int, default=None,
                        help="also stop after this many iterations without improvement "
                             "(default: never, the paper's plain 100 iterations)")
    parser.add_argument("--agents", type=int, default=256, help="drops per iteration")
    add_out_argument(parser, "rfd_static")
    args = parser.parse_args(argv)
    check_counts(parser, args, "seeds", "iterations", "agents")
    record = provenance.begin(__file__, argv)
    rows = []
    for name in args.maps:
        problem = named_problem(name)
        for algorithm in ALGORITHMS:
            began = time.perf_counter()
            mine = run_algorithm(problem, algorithm, args.seeds, iterations=args.iterations,
                                 patience=args.patience, num_agents=args.agents)
            rows += mine
            print(f"{name:10} {algorithm:10} success {sum(r['success'] for r in mine):2d}/"
                  f"{args.seeds} ({time.perf_counter() - began:.0f} s)", flush=True)
    swarms = {a: definition(make(a, num_agents=args.agents)) for a in ALGORITHMS}
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args), swarms=swarms)
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    markdown = table(rows, args.maps)
    record.publish(args.out, markdown)
    print("\n" + markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
