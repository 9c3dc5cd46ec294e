"""Intelligent Water Drops (``iwd``, the IWD_PG paper's baseline) on the RFD paper's nine maps,
beside the optimum: its quality reported as it is, not tuned.

Per map, ``--seeds`` runs (keys split from key 0) of ``iwd`` with its standard params, ``--drops``
drops per iteration, at most ``--iterations`` iterations, stopped after ``--patience`` iterations
without gain once a path was found; each run compiled first, then timed alone. Reported per map:
runs that found a path and runs at the optimum (A*; relative gap below 1e-4,
:mod:`jaxswarm.studies.success`), the mean and best length and mean gap over the runs that found
one, iterations, fitness calls (complete paths evaluated: the IWD paper's measure of cost) and the
median time.

Written to ``--out`` (default ``out/iwd_paper_maps``; ``make reproduce`` uses
``results/iwd_paper_maps``), each file atomically: ``runs.csv`` (one row per map and seed),
``table.md`` (the provenance, then the table) and ``provenance.json``.

Run from the repository root::

    python sweeps/iwd_paper_maps.py
    python sweeps/iwd_paper_maps.py --maps maze20,mosaic20 --seeds 3
"""
from __future__ import annotations

import argparse
import statistics
import time

from jaxswarm.exact import astar
from jaxswarm.maps.paper import paper_maps_argument
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts
from jaxswarm.studies.problems import named_problem
from jaxswarm.studies.success import reaches_optimum, relative_gap
from jaxswarm.studies.timing import median_milliseconds, seed_keys, timed_runs
from jaxswarm.swarm import definition, make

COLUMNS = ("map", "seed", "optimum", "cost", "gap", "found", "optimal", "iterations",
           "evaluations", "seconds")
"""Columns of runs.csv (``evaluations``: complete paths evaluated, all iterations)."""
TITLE = "Intelligent Water Drops (the IWD_PG paper's baseline) on the RFD paper's maps"
"""Title of table.md."""
ABOUT = ("`iwd` is Shah-Hosseini's IWD with its standard values, as the IWD_PG paper uses it "
         "(eqs. 1-6); the goal desirability h(j) = 1 / d_j is ours (the paper gives no "
         "formula). The optimum is A*'s.")
"""What the rows are (the paragraph under the provenance)."""


def study_map(name: str, *, seeds: int, drops: int, iterations: int,
              patience: int) -> list[dict]:
    """The runs.csv rows of map ``name``: ``iwd`` with its standard params once per seed (keys
    split from key 0), compiled first, each run timed alone."""
    problem = named_problem(name, planner=astar)
    swarm = make("iwd", num_agents=drops)
    runs = timed_runs(swarm, seed_keys(seeds), problem.graph, problem.task, swarm.default_params,
                      iterations=iterations, patience=patience)
    rows = []
    for seed, one in enumerate(runs):
        cost = float(swarm.best(one.state).cost)
        gap = relative_gap(cost, problem.optimum)
        rows.append(dict(map=name, seed=seed, optimum=problem.optimum, cost=cost, gap=gap,
                         found=cost != float("inf"), optimal=reaches_optimum(gap),
                         iterations=int(one.trace.iterations),
                         evaluations=int(one.trace.evaluations.sum()), seconds=one.seconds))
    return rows


def markdown(rows: list[dict], maps, args) -> str:
    """The Markdown body: the set-up, then one line per map."""
    lines = [f"{args.seeds} seeds, {args.drops} drops per iteration, at most {args.iterations} "
             f"iterations, patience {args.patience}. Length, gap: over the runs that found a "
             "path. Fitness calls: complete paths evaluated per run, mean.", "",
             "| map | optimum | found | optimal | length: mean | length: best | gap: mean | "
             "iterations: mean | fitness calls: mean | time [ms]: median |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for name in maps:
        runs = [r for r in rows if r["map"] == name]
        found = [r for r in runs if r["found"]]
        length = (f"{statistics.mean(r['cost'] for r in found):.2f} | "
                  f"{min(r['cost'] for r in found):.2f} | "
                  f"{100 * statistics.mean(r['gap'] for r in found):.1f} %"
                  if found else "- | - | -")
        lines.append(
            f"| {name} | {runs[0]['optimum']:.2f} | {len(found)}/{len(runs)} | "
            f"{sum(r['optimal'] for r in runs)}/{len(runs)} | {length} | "
            f"{statistics.mean(r['iterations'] for r in runs):.1f} | "
            f"{statistics.mean(r['evaluations'] for r in runs):.0f} | "
            f"{median_milliseconds(r['seconds'] for r in runs):.1f} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument, default="all")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--drops", type=int, default=50)
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--patience", type=int, default=30)
    add_out_argument(parser, "iwd_paper_maps")
    args = parser.parse_args(argv)
    check_counts(parser, args, "seeds", "drops", "iterations", "patience")
    record = provenance.begin(__file__, argv)
    rows = []
    for name in args.maps:
        began = time.perf_counter()
        rows += study_map(name, seeds=args.seeds, drops=args.drops, iterations=args.iterations,
                          patience=args.patience)
        print(f"{name:10} {time.perf_counter() - began:.0f} s", flush=True)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args),
                  swarm=definition(make("iwd", num_agents=args.drops)))
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    print("\n" + record.publish(args.out, markdown(rows, args.maps, args)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
