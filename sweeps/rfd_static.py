"""RFD and RFD* on the nine paper maps, static environment (the RFD paper's Table 1 set-up).

For every map, each algorithm runs once per seed (``--seeds``, default 20) for at most 100
iterations (``--iterations``; a run also stops when every drop follows the same path, and, if
``--patience`` is given, after that many iterations without improvement). Each run is jitted once
per map and algorithm and then timed on its own (compile excluded). Printed per map: the optimum
(Dijkstra), each algorithm's mean best length over the seeds, its success count (relative gap
< 1e-4 to the optimum) and the median wall time of one run. Written to ``--out`` (default
``out/rfd_static``): ``runs.csv`` (one row per map, algorithm and seed) and ``table.md``.

Run from the repository root::

    python sweeps/rfd_static.py                         # all nine maps, 20 seeds
    python sweeps/rfd_static.py --maps mosaic20,maze20 --seeds 5
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import jax

from jaxswarm.atomic import write_atomically, write_csv
from jaxswarm.exact import dijkstra
from jaxswarm.cli import paper_maps_argument
from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import make, make_task, run

ALGORITHMS = ("rfd", "rfd_star")
SUCCESS_GAP = 1e-4
COLUMNS = ("map", "algorithm", "seed", "optimum", "cost", "gap", "success", "iterations",
           "first_optimal_iteration", "seconds")


def solve_map(name: str, algorithm: str, seeds: int, *, iterations: int, patience: int | None,
              num_agents: int, devices: int = 1) -> list[dict]:
    """Run ``algorithm`` on paper map ``name`` once per seed, with its drops spread over
    ``devices`` devices; one row per seed."""
    chosen = paper_map(name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    optimum = dijkstra(graph, chosen.start, chosen.goal).cost
    swarm = make(algorithm, num_agents=num_agents, devices=devices)

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
                         first_optimal_iteration=hits[0] if hits else "",
                         seconds=seconds))
    return rows


def table(rows: list[dict], maps: tuple[str, ...]) -> str:
    """Markdown table: per map, the optimum and each algorithm's mean length, success, time."""
    header = "| map | optimum | " + " | ".join(
        f"{a} mean length | {a} success | {a} median ms" for a in ALGORITHMS) + " |"
    lines = [header, "|" + " --- |" * (2 + 3 * len(ALGORITHMS))]
    for name in maps:
        cells = [name]
        for algorithm in ALGORITHMS:
            mine = [r for r in rows if r["map"] == name and r["algorithm"] == algorithm]
            if not cells[1:]:
                cells.append(f"{mine[0]['optimum']:.2f}")
            finite = [r["cost"] for r in mine if r["cost"] != float("inf")]
            mean = f"{statistics.mean(finite):.2f}" if finite else "n/a"
            if finite and len(finite) < len(mine):
                mean += f" ({len(finite)} found)"
            cells += [mean, f"{sum(r['success'] for r in mine)}/{len(mine)}",
                      f"{1e3 * statistics.median(r['seconds'] for r in mine):.0f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument, default="all",
                        help="comma-separated paper maps, or all")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--patience", type=int, default=None,
                        help="also stop after this many iterations without improvement "
                             "(default: never, the paper's plain 100 iterations)")
    parser.add_argument("--agents", type=int, default=256, help="drops per iteration")
    parser.add_argument("--out", type=Path, default=Path("out/rfd_static"))
    args = parser.parse_args(argv)
    if args.seeds < 1:
        parser.error("--seeds must be at least 1")
    rows = []
    for name in args.maps:
        for algorithm in ALGORITHMS:
            began = time.perf_counter()
            mine = solve_map(name, algorithm, args.seeds, iterations=args.iterations,
                             patience=args.patience, num_agents=args.agents)
            rows += mine
            print(f"{name:10} {algorithm:9} success {sum(r['success'] for r in mine):2d}/"
                  f"{args.seeds} ({time.perf_counter() - began:.0f} s)", flush=True)
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    markdown = table(rows, args.maps)
    write_atomically(args.out / "table.md", markdown + "\n")
    print("\n" + markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
