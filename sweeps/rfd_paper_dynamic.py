"""The RFD paper's Tables 2-5 (dynamic environment), reproduced on our nine paper maps.

The rows of Table 1 (:mod:`jaxswarm.studies.rfd_table1`, the same labels, swarms and params) plus
"D* Lite (repair)", a row the paper lacks. Per map, each swarm first solves the static map once per
seed (keys split from key 0, ``--iterations`` iterations, like Table 1): its Table 1 state. Then
for each of the paper's changes (:func:`jaxswarm.studies.rfd_dynamic.paper_scenario`: Table 2 the
goal moves, 3 obstacles added, 4 removed, 5 a major change) the swarm continues from that state:
:func:`jaxswarm.dynamic.events.change` applies the change and the swarm's memory rule, then ``run``
continues (``--iterations`` at most, patience ``--patience``; key ``fold_in(seed key, table)``).

Timed per run, compile excluded (each program runs once first):

* **time to stop**: from the change to the run's own stop;
* **time to target**: from the change to the first iteration whose best path is the new
  optimum (replayed with ``budget``; the run never sees the optimum); none if never reached.
  For the exact planners both are their one search.

Dijkstra and A* solve the changed map from scratch (their own ``stats.wall_time``; the map's
host arrays are built outside it); D* Lite repairs its search of the static map (the ``update``
call timed; a goal move restarts it).

Written to ``--out`` (default ``out/rfd_paper_dynamic``; ``make reproduce`` uses
``results/rfd_paper_dynamic``), each file atomically: ``runs.csv`` (one row per map, table, row
and seed), ``table.md`` (the provenance, then per table: path length, runs at the new optimum,
time to stop and time to target, ours beside the paper's values), ``provenance.json`` and
``table<T>.png`` (each map after the change, the changed cells marked, the optimal path before
the change dashed, each row's best path after it).

Run from the repository root::

    python sweeps/rfd_paper_dynamic.py
    python sweeps/rfd_paper_dynamic.py --maps mosaic20,alley20,maze20 --seeds 3
"""
from __future__ import annotations

import argparse
import time

import jax
import matplotlib

matplotlib.use("Agg")

from jaxswarm.dynamic.events import apply_event, check_events, first_iteration_at, replan
from jaxswarm.exact import astar, replanner
from jaxswarm.maps.named import named_map
from jaxswarm.maps.paper import paper_maps_argument
from jaxswarm.plot.graph import draw_map, draw_paths
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.runtime.programs import release_if_crowded
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts, numbers_argument
from jaxswarm.studies.figures import panel_grid, write_png
from jaxswarm.studies.rfd_dynamic import (PAPER_DYNAMIC_LENGTH, PAPER_DYNAMIC_MS, TABLES,
                                          paper_scenario)
from jaxswarm.studies.rfd_table1 import (ABOUT as TABLE1_ABOUT, ALGORITHMS as TABLE1_LABELS,
                                         PLANNERS, ROWS, draw_best_paths, length_cell,
                                         optimal_cell, row_definitions, row_swarm, time_cell)
from jaxswarm.studies.success import SUCCESS_GAP, relative_gap
from jaxswarm.studies.timing import median_milliseconds, seed_keys, timed_call
from jaxswarm.swarm import make_task, run
from jaxswarm.world.graph import grid_graph

DSTAR = "D* Lite (repair)"
LABELS = TABLE1_LABELS[:2] + (DSTAR,) + TABLE1_LABELS[2:]
"""Row labels in table order: Table 1's, with D* Lite after the exact planners."""
COLUMNS = ("map", "table", "algorithm", "planner", "seed", "optimum", "cost", "gap", "found",
           "iterations", "seconds", "target_iterations", "target_seconds")
"""Columns of runs.csv (``seconds``: time to stop; ``target_*``: to the new optimum)."""
TITLE = "RFD paper, Tables 2-5 (dynamic environment): ours beside the paper's"
ABOUT = TABLE1_ABOUT + (
    " \"D* Lite (repair)\" is not in the paper: D* Lite (`jaxswarm.exact.replanner`) repairing "
    "its search of the static map. Each swarm continues from its own Table 1 state, its memory "
    "adapted by its rule (`jaxswarm.dynamic.events`).")
PAPER_ROW = {**{row.label: row.paper for row in ROWS}, DSTAR: None}
"""Row label -> the paper's row beside it (None: no counterpart)."""


def exact_runs(name, chosen, graph, scenario, table, seeds):
    """Dijkstra and A* on the changed map, D* Lite repairing the static search: rows, best."""
    fresh = grid_graph(scenario.obstacles())
    goal = scenario.goal or chosen.goal
    rows, best = [], {}
    for label in TABLE1_LABELS[:2]:
        planner = PLANNERS[label]
        planner(fresh, chosen.start, goal)  # host arrays
        for seed in range(seeds):
            solution = planner(fresh, chosen.start, goal)
            seconds = solution.stats.wall_time
            rows.append(csv_row(name, table, label, planner.__name__, seed, scenario, solution,
                                "", seconds, (None, seconds)))
        best[label] = solution
    edited = apply_event(scenario.event(graph), graph, make_task(graph, chosen.start,
                                                                 chosen.goal))[0]
    for seed in range(seeds):
        planner = replanner(graph, chosen.start, chosen.goal)
        planner.solve()
        solution, seconds = timed_call(planner.update, edited, goal=scenario.goal)
        rows.append(csv_row(name, table, DSTAR, "replanner", seed, scenario, solution, "",
                            seconds, (None, seconds)))
    best[DSTAR] = solution
    return rows, best


def csv_row(name, table, label, planner, seed, scenario, solution, iterations, seconds,
            target=(None, None)):
    """One runs.csv row; ``target`` is (iterations, seconds) to the new optimum, or Nones."""
    cost = float(solution.cost)
    return dict(map=name, table=table, algorithm=label, planner=planner, seed=seed,
                optimum=scenario.optimum, cost=cost,
                gap=relative_gap(cost, scenario.optimum), found=bool(solution.found),
                iterations=iterations, seconds=seconds, target_iterations=target[0] or "",
                target_seconds="" if target[1] is None else target[1])


def swarm_runs(name, chosen, graph, row, tables, *, seeds, iterations, patience, agents):
    """One swarm row on one map: its Table 1 states, then each table's change continued."""
    task = make_task(graph, chosen.start, chosen.goal)
    swarm, params = row_swarm(row, agents)
    keys = seed_keys(seeds)
    states = [run(swarm, key, graph, task, params, iterations=iterations)[0] for key in keys]
    rows, best = [], {}
    for table in tables:
        scenario = paper_scenario(name, table)
        event = scenario.event(graph)
        check_events(graph, task, event)

        @jax.jit
        def replay(state, key, budget, event=event):
            state, trace = replan(swarm, key, state, event, graph, task, params,
                                  iterations=iterations, patience=patience, budget=budget)
            return swarm.best(state), trace

        for seed, (key, state) in enumerate(zip(keys, states)):
            key = jax.random.fold_in(key, table)
            if seed == 0:
                release_if_crowded()
                jax.block_until_ready(replay(state, key, iterations))  # compile
            (solution, trace), seconds = timed_call(replay, state, key, iterations)
            first = first_iteration_at(trace, scenario.optimum, gap=SUCCESS_GAP)
            target = (None, None) if first is None else (
                first, timed_call(replay, state, key, first)[1])
            rows.append(csv_row(name, table, row.label, row.planner(), seed, scenario, solution,
                                int(trace.iterations), seconds, target))
            if table not in best or float(solution.cost) < float(best[table].cost):
                best[table] = solution
    return rows, best


def solve_map(name, tables, **options):
    """Every row on paper map ``name``: (rows, table -> row label -> best Solution)."""
    chosen = named_map(name)
    graph = chosen.graph
    rows, best = [], {table: {} for table in tables}
    for table in tables:
        mine, solutions = exact_runs(name, chosen, graph, paper_scenario(name, table), table,
                                     options["seeds"])
        rows += mine
        best[table].update(solutions)
    for row in ROWS[2:]:
        began = time.perf_counter()
        mine, solutions = swarm_runs(name, chosen, graph, row, tables, **options)
        rows += mine
        for table, solution in solutions.items():
            best[table][row.label] = solution
        print(f"{name:10} {row.label:22} {time.perf_counter() - began:.0f} s", flush=True)
    return rows, best


def cells(rows, maps, label, table, ours):
    """One cell per map: ``ours`` of the runs of row ``label`` after the change of ``table``."""
    return [ours([r for r in rows if r["map"] == m and r["table"] == table
                  and r["algorithm"] == label]) for m in maps]


def target_cell(runs):
    """Median time to the new optimum [ms] over the runs that reached it (count)."""
    hit = [r["target_seconds"] for r in runs if r["target_seconds"] != ""]
    median = f"{median_milliseconds(hit):.2f}" if hit else "-"
    return f"{median} ({len(hit)}/{len(runs)})"


def half(rows, maps, table, ours, paper=None):
    """Markdown lines: a row of ours per algorithm, and the paper's where ``paper`` is given."""
    lines = ["| algorithm | source | " + " | ".join(maps) + " |",
             "| --- | --- |" + " ---: |" * len(maps)]
    for label in LABELS:
        lines.append(f"| {label} | ours | " + " | ".join(cells(rows, maps, label, table, ours))
                     + " |")
        if paper is not None and PAPER_ROW[label] is not None:
            values = paper[table].get(PAPER_ROW[label])
            shown = ["" if values is None else "n/a" if values[m] is None else f"{values[m]:g}"
                     for m in maps]
            lines.append(f"| {label} | paper ({PAPER_ROW[label]}) | " + " | ".join(shown)
                         + " |")
    return lines


def markdown(rows, maps, tables, args):
    """The Markdown body: the set-up, then per table its changes and its four halves (path
    length, runs at the new optimum, time to stop, time to target)."""
    parts = [f"{args.seeds} seeds; each swarm continues from its Table 1 state ({args.agents} "
             f"agents, {args.iterations} iterations at most, patience {args.patience}). Times "
             "in ms (compile excluded); the paper's are C# on its own maps. An empty paper cell: "
             "the paper's text has no such row."]
    for table in tables:
        changes = ", ".join(f"{m}: {_describe(paper_scenario(m, table))}" for m in maps)
        parts += ["", f"## Table {table}", "", f"Changes: {changes}.", "",
                  "### Path length: mean over the seeds that found a path", "",
                  *half(rows, maps, table, length_cell, PAPER_DYNAMIC_LENGTH), "",
                  "### Runs at the new optimum", "", *half(rows, maps, table, optimal_cell),
                  "", "### Time to stop [ms]: median", "",
                  *half(rows, maps, table, time_cell, PAPER_DYNAMIC_MS), "",
                  "### Time to target [ms]: median over the runs that reached the new optimum", "",
                  *half(rows, maps, table, target_cell)]
    return "\n".join(parts) + "\n"


def _describe(scenario):
    if scenario.kind == "goal":
        return (f"goal to {scenario.goal} (paper {scenario.paper_goal}), optimum "
                f"{scenario.optimum:.2f}")
    cells_ = len(scenario.block) + len(scenario.unblock)
    return f"{cells_} cells {scenario.kind}, optimum {scenario.optimum:.2f}"


def figure(best, table):
    """Each map after the change of ``table``, changed cells marked, each row's best path."""
    fig, axes = panel_grid(len(best), columns=3, width=5, height=5.9)
    for name, ax in zip(best, axes):
        scenario, chosen = paper_scenario(name, table), named_map(name)
        graph = grid_graph(scenario.obstacles())
        draw_map(ax, graph, start=chosen.start, goal=scenario.goal or chosen.goal, title=name)
        for cells_, marker in ((scenario.block, "s"), (scenario.unblock, "D")):
            if cells_:
                xs, ys = zip(*cells_)
                ax.scatter(xs, ys, marker=marker, s=12, color="tab:pink", zorder=3)
        before = astar(chosen.graph, chosen.start, chosen.goal)
        label = f"before: optimal ({scenario.static_optimum:.2f})"
        (line,) = draw_paths(ax, graph, [before], [label], colors=["dimgrey"], linewidth=1.5)
        line.set(linestyle=(0, (2, 2)), zorder=6)
        if scenario.goal is not None:
            ax.plot(*chosen.goal, marker="x", color="dimgrey", markersize=8, zorder=6,
                    linestyle="none", label="before: goal")
        draw_best_paths(ax, graph, best[name][table], thinning=0.5)
    fig.suptitle(f"RFD paper, Table {table}: the map after the change (pink: cells blocked "
                 "(squares) or opened (diamonds)),\nthe optimal path before it (dashed) and each "
                 "algorithm's best path after it")
    return fig


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument, default="all")
    parser.add_argument("--tables", type=numbers_argument(TABLES), default="2,3,4,5",
                        help=f"the paper's dynamic tables, from {', '.join(map(str, TABLES))}")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--patience", type=int, default=30)
    parser.add_argument("--agents", type=int, default=256)
    add_out_argument(parser, "rfd_paper_dynamic")
    args = parser.parse_args(argv)
    check_counts(parser, args, "seeds", "iterations", "patience", "agents")
    record = provenance.begin(__file__, argv)
    rows, best = [], {}
    for name in args.maps:
        mine, best[name] = solve_map(name, args.tables, seeds=args.seeds,
                                     iterations=args.iterations, patience=args.patience,
                                     agents=args.agents)
        rows += mine
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args),
                  rows=row_definitions(args.agents))
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    text = record.publish(args.out, markdown(rows, args.maps, args.tables, args))
    for table in args.tables:
        write_png(figure(best, table), args.out / f"table{table}.png")
    print("\n" + text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
