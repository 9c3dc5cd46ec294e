"""Intelligent Water Drops (``iwd``, the IWD_PG paper's baseline) on the RFD paper's nine maps,
beside the optimum: its quality reported as it is, not tuned.

Per map, ``--seeds`` runs (keys split from key 0) of ``iwd`` with its standard params,
``--drops`` drops per iteration, at most ``--iterations`` iterations, stopped after
``--patience`` iterations without gain once a path was found; each run compiled first, then
timed alone. Reported per map: runs that found a path and runs at the optimum (A*), the mean and
best length and mean gap over the runs that found one, iterations, fitness calls (complete paths
evaluated: the IWD paper's measure of cost) and the median time.

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
import sys
import time
from pathlib import Path

import jax

from jaxswarm.exact import astar
from jaxswarm.maps.paper import paper_map, paper_maps_argument
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.swarm import definition, make, make_task, run
from jaxswarm.studies import provenance


COLUMNS = ("map", "seed", "optimum", "cost", "gap", "found", "optimal", "iterations",
           "evaluations", "seconds")
"""Columns of runs.csv (``evaluations``: complete paths evaluated, all iterations)."""
OPTIMAL_GAP = 1e-4
"""A run reaches the optimum when its relative gap to it is below this."""
TITLE = "Intelligent Water Drops (the IWD_PG paper's baseline) on the RFD paper's maps"
ABOUT = ("`iwd` is Shah-Hosseini's IWD with its standard values, as the IWD_PG paper uses it "
         "(eqs. 1-6); the goal desirability h(j) = 1 / d_j is ours (the paper gives no "
         "formula). The optimum is A*'s.")


def study_map(name: str, *, seeds: int, drops: int, iterations: int,
              patience: int) -> list[dict]:
    """The runs.csv rows of map ``name``."""
    chosen = paper_map(name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    optimum = float(astar(graph, chosen.start, chosen.goal).cost)
    swarm = make("iwd", num_agents=drops)

    def one(key):
        return jax.block_until_ready(run(swarm, key, graph, task, swarm.default_params,
                                         iterations=iterations, patience=patience))

    keys = jax.random.split(jax.random.key(0), seeds)
    one(keys[0])  # compile
    rows = []
    for seed, key in enumerate(keys):
        began = time.perf_counter()
        state, trace = one(key)
        seconds = time.perf_counter() - began
        cost = float(swarm.best(state).cost)
        gap = (cost - optimum) / optimum
        rows.append(dict(map=name, seed=seed, optimum=optimum, cost=cost, gap=gap,
                         found=cost != float("inf"), optimal=gap < OPTIMAL_GAP,
                         iterations=int(trace.iterations),
                         evaluations=int(trace.evaluations.sum()), seconds=seconds))
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
            f"{1e3 * statistics.median(r['seconds'] for r in runs):.1f} |")
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument, default="all")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--drops", type=int, default=50)
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--patience", type=int, default=30)
    parser.add_argument("--out", type=Path, default=Path("out/iwd_paper_maps"))
    args = parser.parse_args(argv)
    for option in ("seeds", "drops", "iterations", "patience"):
        if getattr(args, option) < 1:
            parser.error(f"--{option} must be at least 1, got {getattr(args, option)}")
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
