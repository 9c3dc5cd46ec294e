"""Ant System vs Max-Min ACO vs Improved Max-Min ACO on random thin-wall path maps (the set-up of
the Max-Min ACO paper's Table 1).

For each map size (10x10, 20x20, 40x25 by default) one seeded random path map is generated
(:func:`jaxswarm.maps.random.random_path_map`), start in the top-left cell and goal in the
bottom-right one. Each algorithm runs ``--runs`` times (10 in the paper) with populations of
``--ants`` ants (50), until convergence (every ant of a population on one path, or no improvement
for ``--patience`` populations) or ``--max-ants`` ants in all. Printed per map and algorithm: the
minimum and average best path length over the runs, the average time per run (jitted once,
compile excluded), the optimum from Dijkstra and the ratios to it. Written to ``--out`` (default
``out/aco_pathmaps``) as ``results.csv``.

The paper's maps and units are not published (its lengths are in pixels of its drawings), so
only the shape of its finding carries over: Improved Max-Min ACO finds shorter average paths and
converges faster than the other two on the 10x10 and 20x20 maps.

Run from the repository root::

    python sweeps/aco_pathmaps.py
    python sweeps/aco_pathmaps.py --sizes 10x10 --runs 3
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import jax

from jaxswarm.atomic import write_csv
from jaxswarm.exact import dijkstra
from jaxswarm.graph import path_map_graph
from jaxswarm.maps.random import random_path_map
from jaxswarm.swarm import make, make_task, run

ALGORITHMS = {"Ant System": "ant_system", "Max-Min ACO": "max_min_aco",
              "Improved Max-Min ACO": "improved_max_min_aco"}
COLUMNS = ("map", "algorithm", "optimum", "min_length", "mean_length", "min_ratio",
           "mean_ratio", "found", "runs", "mean_populations", "mean_seconds")


def compare(width: int, height: int, *, seed: int, runs: int, ants: int, max_ants: int,
            patience: int) -> list[dict]:
    """One row per algorithm on one random path map."""
    graph = path_map_graph(random_path_map(width, height, seed))
    start, goal = 0, graph.num_nodes - 1
    task = make_task(graph, start, goal)
    optimum = dijkstra(graph, start, goal).cost
    rows = []
    for label, registry_name in ALGORITHMS.items():
        swarm = make(registry_name, num_agents=ants)

        def one_run(key):
            return run(swarm, key, graph, task, swarm.default_params,
                       iterations=max(max_ants // ants, 1), patience=patience)

        keys = jax.random.split(jax.random.key(seed), runs)
        jax.block_until_ready(one_run(keys[0]))  # compile
        lengths, populations, seconds = [], [], []
        for key in keys:
            began = time.perf_counter()
            state, trace = jax.block_until_ready(one_run(key))
            seconds.append(time.perf_counter() - began)
            lengths.append(float(swarm.best(state).cost))
            populations.append(int(trace.iterations))
        found = [length for length in lengths if length != float("inf")]
        rows.append(dict(
            map=f"{width}x{height}", algorithm=label, optimum=optimum,
            min_length=min(lengths), mean_length=statistics.mean(found) if found else float("inf"),
            min_ratio=min(lengths) / optimum,
            mean_ratio=(statistics.mean(found) / optimum) if found else float("inf"),
            found=len(found), runs=runs, mean_populations=statistics.mean(populations),
            mean_seconds=statistics.mean(seconds)))
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="10x10,20x20,40x25", help="WIDTHxHEIGHT list")
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--ants", type=int, default=50, help="ants per population")
    parser.add_argument("--max-ants", type=int, default=5000, help="ants per run at most")
    parser.add_argument("--patience", type=int, default=20, help="populations without gain")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("out/aco_pathmaps"))
    args = parser.parse_args(argv)
    rows = []
    print(f"{'map':7} {'algorithm':22} {'optimum':>8} {'min':>8} {'mean':>8} {'min/opt':>8} "
          f"{'mean/opt':>9} {'found':>6} {'populations':>12} {'s/run':>7}")
    for size in args.sizes.split(","):
        width, height = (int(v) for v in size.split("x"))
        for row in compare(width, height, seed=args.seed, runs=args.runs, ants=args.ants,
                           max_ants=args.max_ants, patience=args.patience):
            rows.append(row)
            print(f"{row['map']:7} {row['algorithm']:22} {row['optimum']:8.2f} "
                  f"{row['min_length']:8.2f} {row['mean_length']:8.2f} {row['min_ratio']:8.3f} "
                  f"{row['mean_ratio']:9.3f} {row['found']:>3}/{row['runs']:<2} "
                  f"{row['mean_populations']:12.1f} {row['mean_seconds']:7.3f}", flush=True)
    write_csv(args.out / "results.csv", rows, COLUMNS)
    print(f"written to {args.out / 'results.csv'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
