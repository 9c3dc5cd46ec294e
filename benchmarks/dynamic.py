"""What a re-plan costs: swarms continuing from their memory after the RFD paper's changes,
beside A* from scratch and D* Lite's repair.

For each map of ``--maps`` (default: the three 100 x 100 paper maps) and each of the paper's
dynamic tables 2-5 (:func:`jaxswarm.studies.rfd_dynamic.paper_scenario`: the goal moves, obstacles
are added, removed, or a major change), and for each swarm of ``--swarms`` (default ``rfd_star``,
``rfd_graded``, ``aco_star``; ``--agents`` agents, default params) and each of ``--seeds`` seeds:

1. the swarm solves the static map from fresh memory (``run`` with ``jax.random.key(seed)``,
   100 iterations at most, patience 30): its Table 1 state;
2. the change is applied to that state (:func:`jaxswarm.dynamic.events.change`: the swarm's memory
   rule, an invalidated best path forgotten) and the run continues from it
   (``run(..., state=...)``, key ``seed + 1000``, 100 iterations at most, patience 30). Timed
   from the change to the run's own stop: **time to stop**;
3. the first iteration whose best path is the new optimum (relative gap below 1e-4; Dijkstra on
   the changed map) is read from the continued run's trace; the same change and continuation is
   timed again, stopped after that iteration (``budget``, the same draws): **time to target**.
   The run never sees the optimum; a seed that never reaches it has no time to target.

Per (map, table, swarm) the script prints the median time to target and time to stop, their
median iterations, and how many seeds reached the new optimum; beside them, in the same run,
A* from scratch on the changed map (its host arrays built, as a new map needs, and the search
alone) and D* Lite repairing the static map's search (for Table 2, a goal move, D* Lite
restarts). Compile time is excluded: every program is run once before timing.

Goal: ``rfd_graded`` reaches the new optimum after the changes of Tables 2-4 in at
least 19 of 20 seeds, median time to target at most 20 ms (the paper's RFD*: 47-121 ms).

Run from the repository root::

    python benchmarks/dynamic.py                       # 20 seeds, the 100 x 100 maps
    python benchmarks/dynamic.py --maps maze20 --seeds 3 --swarms rfd_graded
"""
from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import jax

from jaxswarm.dynamic.events import apply_event, check_events, first_iteration_at, replan
from jaxswarm.exact import astar, dijkstra, replanner
from jaxswarm.maps.paper import paper_map, paper_map_names
from jaxswarm.runtime.cpu import configure
from jaxswarm.studies.rfd_dynamic import TABLES, paper_scenario
from jaxswarm.swarm import make, make_task, run
from jaxswarm.sweep.batches import SUCCESS_GAP
from jaxswarm.world.graph import grid_graph

ITERATIONS = 100
PATIENCE = 30
GOAL_SEEDS, GOAL_MS = 19, 20.0


def timed(fn):
    """``(result, seconds)`` of ``fn()``, blocked on."""
    began = time.perf_counter()
    result = jax.block_until_ready(fn())
    return result, time.perf_counter() - began


def replan_rows(swarm, graph, task, scenario, seeds: int):
    """Per seed: (reached, ms to target, iterations to target, ms to stop, iterations)."""
    event = scenario.event(graph)
    check_events(graph, task, event)
    params = swarm.default_params

    @jax.jit
    def replay(state, key, budget):
        return replan(swarm, key, state, event, graph, task, params, iterations=ITERATIONS,
                      patience=PATIENCE, budget=budget)

    rows = []
    for seed in range(seeds):
        state, _ = run(swarm, jax.random.key(seed), graph, task, params, iterations=ITERATIONS,
                       patience=PATIENCE)
        key = jax.random.key(seed + 1000)
        if not rows:
            jax.block_until_ready(replay(state, key, ITERATIONS))  # compile
        (_, trace), to_stop = timed(lambda: replay(state, key, ITERATIONS))
        used = int(trace.iterations)
        first = first_iteration_at(trace, scenario.optimum, gap=SUCCESS_GAP)
        if first is not None:
            _, to_target = timed(lambda: replay(state, key, first))
            rows.append((True, 1e3 * to_target, first, 1e3 * to_stop, used))
        else:
            rows.append((False, None, None, 1e3 * to_stop, used))
    return rows


def exact_rows(chosen, graph, task, scenario, repeats: int = 5):
    """Medians in ms of A* from scratch on the changed map (a new Graph: its host arrays built),
    of that A*'s search alone, and of D* Lite repairing its search of the static map."""
    edited, new_task = apply_event(scenario.event(graph), graph, task)
    start, goal = int(new_task.start), int(new_task.goal)
    assert abs(dijkstra(edited, start, goal).cost - scenario.optimum) < 1e-6
    scratch, search, repair = [], [], []
    for _ in range(repeats):
        fresh = grid_graph(scenario.obstacles())
        scratch.append(timed(lambda: astar(fresh, start, goal))[1])
        search.append(timed(lambda: astar(fresh, start, goal))[1])
        planner = replanner(graph, chosen.start, chosen.goal)
        planner.solve()
        repair.append(timed(lambda: planner.update(edited, goal=goal))[1])
    return tuple(1e3 * statistics.median(v) for v in (scratch, search, repair))


def median_or_dash(values, fmt="{:.1f}"):
    values = [v for v in values if v is not None]
    return fmt.format(statistics.median(values)) if values else "-"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", default="mosaic100,alley100,maze100")
    parser.add_argument("--tables", default="2,3,4,5")
    parser.add_argument("--swarms", default="rfd_star,rfd_graded,aco_star")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--agents", type=int, default=256)
    args = parser.parse_args(argv)
    configure(threads=1)
    maps = paper_map_names(args.maps)
    tables = [int(t) for t in args.tables.split(",")]
    if any(t not in TABLES for t in tables):
        parser.error(f"--tables: the paper's dynamic tables are {TABLES}")
    print(f"machine: {platform.platform()} | {os.cpu_count()} CPUs | jax {jax.__version__} "
          f"({jax.default_backend()}, 1 XLA thread)")
    print(f"{args.seeds} seeds, {args.agents} agents, {ITERATIONS} iterations at most, "
          f"patience {PATIENCE}; times in ms, medians over the seeds")
    header = (f"{'map':10} {'table':>5} {'planner':12} {'reached':>8} {'to target':>10} "
              f"{'it':>4} {'to stop':>9} {'it':>4}")
    print(header)
    began = time.perf_counter()
    for name in maps:
        chosen = paper_map(name)
        graph = chosen.graph()
        task = make_task(graph, chosen.start, chosen.goal)
        for table in tables:
            scenario = paper_scenario(name, table)
            for swarm_name in args.swarms.split(","):
                swarm = make(swarm_name, num_agents=args.agents)
                rows = replan_rows(swarm, graph, task, scenario, args.seeds)
                reached = sum(r[0] for r in rows)
                print(f"{name:10} {table:>5} {swarm_name:12} {reached:>5}/{len(rows):<2} "
                      f"{median_or_dash([r[1] for r in rows]):>10} "
                      f"{median_or_dash([r[2] for r in rows], '{:.0f}'):>4} "
                      f"{median_or_dash([r[3] for r in rows]):>9} "
                      f"{median_or_dash([r[4] for r in rows], '{:.0f}'):>4}", flush=True)
            scratch, search, repair = exact_rows(chosen, graph, task, scenario)
            print(f"{name:10} {table:>5} {'A* scratch':12} {'-':>8} {scratch:>10.2f} "
                  f"(search alone {search:.2f}); D* Lite repair {repair:.2f}", flush=True)
    print(f"goal: rfd_graded reaches the new optimum in at least {GOAL_SEEDS} of 20 seeds after "
          f"Tables 2-4, median time to target at most {GOAL_MS:.0f} ms | took "
          f"{time.perf_counter() - began:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
