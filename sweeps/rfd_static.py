"""RFD, RFD* and RFD graded on the nine paper maps, static environment (the RFD paper's Table 1
set-up).

Three rows per map: the RFD paper's RFD (``rfd``, eqs. 1-5) and RFD* (``rfd_star``, eq. 6 with the
erosion of eqs. 4-5), and this project's own law ``rfd_graded`` (RFD*'s transitions over a graded
river bed; registered as ``rfd_star`` until jaxswarm 0.2.0). Each runs with its default params once
per seed (``--seeds``, default 20) for at most 100 iterations (``--iterations``; a run also stops
when every drop follows the same path, and, if ``--patience`` is given, after that many iterations
without improvement). Each run is jitted once per map and algorithm and then timed on its own
(compile excluded). Reported per map and algorithm: the optimum (Dijkstra), the mean best length
over the seeds, the success count (relative gap < 1e-4 to the optimum) and the median wall time
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
import sys
import time
from pathlib import Path

import jax

from jaxswarm.exact import dijkstra
from jaxswarm.maps.paper import paper_map, paper_maps_argument
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.swarm import definition, make, make_task, run
from jaxswarm.studies import provenance


SOURCES = {"rfd": "RFD paper", "rfd_star": "RFD paper", "rfd_graded": "ours"}
"""Registered swarm -> where its algorithm comes from, in table order."""
ALGORITHMS = tuple(SOURCES)
"""The registered swarms of the table, in order."""
SUCCESS_GAP = 1e-4
"""A run succeeds when its relative gap to the optimum is below this."""
COLUMNS = ("map", "algorithm", "seed", "optimum", "cost", "gap", "success", "iterations",
           "first_optimal_iteration", "seconds", "moves", "lane_steps")
"""Columns of runs.csv (``moves``: the drops' moves in all iterations; ``lane_steps``: the
walker's lane-steps, so ``moves / lane_steps`` is the share of its work that moved a drop)."""
TITLE = "RFD, RFD* and RFD graded on the RFD paper's nine maps (static environment)"
"""Title of table.md."""
ABOUT = (
    "Rows: `rfd` (the RFD paper's RFD, eqs. 1-5) and `rfd_star` (the paper's RFD*: eq. 6 with "
    "the erosion of eqs. 4-5, as written) are the paper's algorithms; `rfd_graded` is ours, not "
    "the paper's: RFD*'s transitions over a graded river bed (registered as `rfd_star` until "
    "jaxswarm 0.2.0). Each runs with its default params; success means a best length within a "
    "relative 1e-4 of the optimum (Dijkstra).")
"""What the rows are (the paragraph under the provenance)."""


def solve_map(name: str, algorithm: str, seeds: int, *, iterations: int, patience: int | None,
              num_agents: int) -> list[dict]:
    """Run ``algorithm`` on paper map ``name`` once per seed; one row per seed."""
    chosen = paper_map(name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    optimum = dijkstra(graph, chosen.start, chosen.goal).cost
    swarm = make(algorithm, num_agents=num_agents)

    def one_run(key):
        return run(swarm, key, graph, task, swarm.default_params, iterations=iterations,
                   patience=patience)

    keys = jax.random.split(jax.random.key(0), seeds)
    jax.block_until_ready(one_run(keys[0]))  # compile
    rows = []
    for seed, key in enumerate(keys):
        began = time.perf_counter()
        state, trace = jax.block_until_ready(one_run(key))
        seconds = time.perf_counter() - began
        cost = float(swarm.best(state).cost)
        gap = (cost - optimum) / optimum
        hits = [t + 1 for t, best in enumerate(trace.best_cost[: int(trace.iterations)].tolist())
                if (best - optimum) / optimum < SUCCESS_GAP]
        rows.append(dict(map=name, algorithm=algorithm, seed=seed, optimum=optimum, cost=cost,
                         gap=gap, success=gap < SUCCESS_GAP, iterations=int(trace.iterations),
                         moves=int(trace.moves.sum()), lane_steps=int(trace.lane_steps.sum()),
                         first_optimal_iteration=hits[0] if hits else "",
                         seconds=seconds))
    return rows


def summary_cells(runs: list[dict]) -> list[str]:
    """Mean length (of the runs that found a path; "n/a" if none did, with the found count if
    some did not), success count and median time [ms] of one map's and algorithm's runs."""
    finite = [r["cost"] for r in runs if r["cost"] != float("inf")]
    mean = f"{statistics.mean(finite):.2f}" if finite else "n/a"
    if finite and len(finite) < len(runs):
        mean += f" ({len(finite)} found)"
    return [mean, f"{sum(r['success'] for r in runs)}/{len(runs)}",
            f"{1e3 * statistics.median(r['seconds'] for r in runs):.0f}"]


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
    parser.add_argument("--out", type=Path, default=Path("out/rfd_static"),
                        help="output folder (make reproduce: results/rfd_static)")
    args = parser.parse_args(argv)
    for option in ("seeds", "iterations", "agents"):
        if getattr(args, option) < 1:
            parser.error(f"--{option} must be at least 1, got {getattr(args, option)}")
    record = provenance.begin(__file__, argv)
    rows = []
    for name in args.maps:
        for algorithm in ALGORITHMS:
            began = time.perf_counter()
            mine = solve_map(name, algorithm, args.seeds, iterations=args.iterations,
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
