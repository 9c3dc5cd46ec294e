"""The robot that finds blocked paths as it goes (the Max-Min ACO paper's Algorithm 1): planners
compared on seeded random path maps and on the RFD paper's nine maps.

Per map and seed, a world: the map the robot knows and ``--blocks`` hidden blocks it does not
(:func:`jaxswarm.dynamic.robot.hidden_blocks`: each on the shortest path of the world so far, so the
robot meets them; passages with a thin wall on path maps, cells on the paper maps; fewer where
no more keep the goal reachable, as on a perfect maze's single way, counted in ``blocks``).
Path maps are the Max-Min ACO paper's sizes (10x10, 20x20, 40x25), one random map per seed
(``pathmapWxH`` of :func:`jaxswarm.maps.named.named_map`, map seed = seed), from the top-left cell
to the bottom-right one; the paper maps are fixed, their blocks drawn per seed.

Rows: Improved Max-Min ACO as the paper has it (its pheromone kept at every re-plan, its Bug2-like
first ant walking again from where the robot stands), the same with its memory wiped at every
re-plan (what keeping the pheromone buys: the paper's claim), ``rfd_star`` (the RFD paper's
RFD*, altitudes kept), ``rfd_graded`` (ours) and D* Lite repairing its search. Each plan of a
swarm is a run of at most ``--iterations`` iterations with patience ``--patience``, continuing
its memory (:func:`jaxswarm.dynamic.robot.swarm_robot`); the robot stops at the goal or after
``--max-plans`` plans.

Measured per run: whether the robot reached the goal, the length it travelled against the
optimum with full knowledge, the plans it made, and the planning time: a swarm's whole robot
program (planning and walking, one jitted call, compiled once per map shape first), D* Lite's
``solve`` and ``update`` calls.

Written to ``--out`` (default ``out/robot_study``; ``make reproduce`` uses
``results/robot_study``), each file atomically: ``runs.csv`` (one row per map, row and seed),
``table.md`` (the provenance, one table per map, then keeping against wiping the memory),
``provenance.json``, ``walks.png`` (seed 0's walk of Improved Max-Min ACO on every map) and
``robot.gif`` (that walk on the 20x20 path map, or the first map).

Run from the repository root::

    python sweeps/robot_study.py
    python sweeps/robot_study.py --maps pathmap10x10,maze20 --seeds 3
"""
from __future__ import annotations

import argparse
import statistics
import time
from typing import NamedTuple

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure

from jaxswarm.dynamic.events import Event
from jaxswarm.dynamic.robot import check_world, dstar_robot, hidden_blocks, swarm_robot
from jaxswarm.maps.named import named_map
from jaxswarm.maps.paper import PAPER_MAPS
from jaxswarm.plot.robot import animate_robot, draw_robot
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts, names_argument
from jaxswarm.studies.figures import panel_grid, write_png
from jaxswarm.studies.timing import compile_then_time, median_milliseconds, seed_keys
from jaxswarm.swarm import definition, make, make_task
from jaxswarm.world.graph import Graph


class Row(NamedTuple):
    """One planner of the table: a registered swarm and what its memory does at a re-plan, or
    None for D* Lite."""

    label: str
    swarm: str | None
    memory: str = "keep"


ROWS = (Row("Improved Max-Min ACO (paper: pheromone kept)", "improved_max_min_aco"),
        Row("Improved Max-Min ACO (memory wiped)", "improved_max_min_aco", "wipe"),
        Row("RFD* (paper)", "rfd_star"),
        Row("RFD graded (ours)", "rfd_graded"),
        Row("D* Lite (repair)", None))
"""The planners, in table order; the first is drawn."""
PATH_MAPS = ("pathmap10x10", "pathmap20x20", "pathmap40x25")
"""Random path maps of the Max-Min ACO paper's sizes."""
MAPS = (*PATH_MAPS, *PAPER_MAPS)
"""The maps ``--maps all`` names."""
COLUMNS = ("map", "algorithm", "planner", "memory", "seed", "blocks", "optimum", "travelled",
           "ratio", "reached", "plans", "iterations", "moves", "seconds")
"""Columns of runs.csv (``ratio``: travelled / optimum; ``seconds``: planning time)."""
TITLE = "The robot that finds blocked paths as it goes (Max-Min ACO paper, Algorithm 1)"
"""Title of table.md."""
ABOUT = ("\"Improved Max-Min ACO (paper: pheromone kept)\" is the Max-Min ACO paper's planner and "
         "re-planning rule; \"(memory wiped)\" is the same with fresh pheromone at every "
         "re-plan, the paper's point of comparison. \"RFD* (paper)\" is the RFD paper's RFD*, "
         "its altitudes kept by the RFD paper's rule; \"RFD graded (ours)\" is this project's "
         "river law with its own memory rule; \"D* Lite (repair)\" is not in the paper.")
"""What the rows are (the paragraph under the provenance)."""


class World(NamedTuple):
    """One robot's world: the map it knows, its start and goal, the blocks it does not know,
    and the optimum with full knowledge."""

    known: Graph
    start: tuple[int, int]
    goal: tuple[int, int]
    hidden: Event
    optimum: float


def world(name: str, seed: int, blocks: int) -> World:
    """The world of map ``name`` (a path map, drawn by ``seed``, or a paper map) for ``seed``."""
    _, known, start, goal = named_map(name, seed=seed)
    for count in range(blocks, 0, -1):  # a perfect maze's way may hold fewer detours
        try:
            hidden = hidden_blocks(known, start, goal, count=count, seed=seed)
            break
        except ValueError:
            if count == 1:
                raise
    optimum = check_world(known, start, goal, hidden, name=f"{name} seed {seed}")
    return World(known, start, goal, hidden, optimum)


def run_row(row: Row, worlds: list[World], *, iterations: int, patience: int,
            max_plans: int) -> list[tuple]:
    """``(walk, seconds)`` of ``row`` in each world (a swarm's program compiled first)."""
    if row.swarm is None:
        runs = [dstar_robot(w.known, w.start, w.goal, w.hidden, max_plans=max_plans)
                for w in worlds[:1] + worlds]
        return runs[1:]  # the first compiled the kernels
    swarm = make(row.swarm)

    def walk(world_task_key):
        w, task, key = world_task_key
        return swarm_robot(swarm, key, w.known, task, w.hidden, swarm.default_params,
                           iterations=iterations, patience=patience, max_plans=max_plans,
                           memory=row.memory)

    return compile_then_time(walk, [(w, make_task(w.known, w.start, w.goal), key)
                                    for w, key in zip(worlds, seed_keys(len(worlds)))])


def study_map(name: str, *, seeds: int, blocks: int, **options) -> tuple[list[dict], dict]:
    """Every row on map ``name``: (runs.csv rows, label -> seed 0's (world, walk))."""
    worlds = [world(name, seed, blocks) for seed in range(seeds)]
    rows, example = [], {}
    for row in ROWS:
        began = time.perf_counter()
        for seed, (w, (walk, seconds)) in enumerate(zip(worlds, run_row(row, worlds,
                                                                        **options))):
            travelled = float(walk.travelled)
            placed = int((w.hidden.block >= 0).sum() + (w.hidden.close[:, 0] >= 0).sum())
            rows.append(dict(map=name, algorithm=row.label, planner=row.swarm or "replanner",
                             memory=row.memory, seed=seed, blocks=placed, optimum=w.optimum,
                             travelled=travelled, ratio=travelled / w.optimum,
                             reached=bool(walk.reached), plans=int(walk.plans),
                             iterations=int(walk.iterations), moves=int(walk.moves),
                             seconds=seconds))
            if seed == 0:
                example[row.label] = (w, walk)
        print(f"{name:13} {row.label:45} {time.perf_counter() - began:.0f} s", flush=True)
    return rows, example


def map_table(rows: list[dict], name: str, blocks: int) -> list[str]:
    """Markdown lines: one map's table (``blocks`` hidden blocks asked for)."""
    mine = [r for r in rows if r["map"] == name]
    optimum = statistics.mean(r["optimum"] for r in mine)
    fewer = sorted({(r["seed"], r["blocks"]) for r in mine if r["blocks"] < blocks})
    note = ("" if not fewer else " Fewer hidden blocks where no more kept the goal reachable: "
            + ", ".join(f"seed {seed} {count}" for seed, count in fewer) + ".")
    if len(fewer) == len({r["seed"] for r in mine}) and len({c for _, c in fewer}) == 1:
        note = f" {fewer[0][1]} hidden block(s) in every world: no more kept the goal reachable."
    lines = [f"### {name}", "", f"Mean optimum with full knowledge: {optimum:.2f}.{note}", "",
             "| algorithm | reached | travelled / optimum: mean (max) | plans: mean | "
             "planning time [ms]: median | iterations: mean |",
             "| --- | ---: | ---: | ---: | ---: | ---: |"]
    for row in ROWS:
        runs = [r for r in mine if r["algorithm"] == row.label]
        if not runs:
            continue
        ratios = [r["ratio"] for r in runs if r["reached"]]
        ratio = f"{statistics.mean(ratios):.3f} ({max(ratios):.3f})" if ratios else "-"
        lines.append(
            f"| {row.label} | {sum(r['reached'] for r in runs)}/{len(runs)} | {ratio} | "
            f"{statistics.mean(r['plans'] for r in runs):.2f} | "
            f"{median_milliseconds(r['seconds'] for r in runs):.2f} | "
            + (f"{statistics.mean(r['iterations'] for r in runs):.1f} |" if row.swarm else "- |"))
    return lines


def memory_table(rows: list[dict], maps) -> list[str]:
    """Markdown lines: Improved Max-Min ACO keeping its pheromone against wiping it."""
    keep, wipe = ROWS[0].label, ROWS[1].label
    lines = ["## What keeping the pheromone buys (Improved Max-Min ACO, same worlds and seeds)",
             "", "| map | planning time kept / wiped: median of the ratios | "
             "iterations kept / wiped: mean | travelled kept - wiped: mean |",
             "| --- | ---: | ---: | ---: |"]
    for name in maps:
        pairs = [(a, b) for a in rows for b in rows
                 if a["map"] == b["map"] == name and a["seed"] == b["seed"]
                 and a["algorithm"] == keep and b["algorithm"] == wipe]
        if not pairs:
            continue
        time_ratio = statistics.median(a["seconds"] / b["seconds"] for a, b in pairs)
        iterations = (statistics.mean(a["iterations"] for a, _ in pairs)
                      / max(statistics.mean(b["iterations"] for _, b in pairs), 1e-9))
        travelled = statistics.mean(a["travelled"] - b["travelled"] for a, b in pairs)
        lines.append(f"| {name} | {time_ratio:.2f} | {iterations:.2f} | {travelled:+.2f} |")
    return lines


def markdown(rows: list[dict], maps, args) -> str:
    """The Markdown body: the set-up, one table per map, then kept against wiped memory."""
    parts = [f"{args.seeds} seeds, {args.blocks} hidden blocks per world, each plan at most "
             f"{args.iterations} iterations with patience {args.patience}, at most "
             f"{args.max_plans} plans. \"reached\": runs that reached the goal; travelled / "
             "optimum over those runs (1 = what a robot that knew the blocks would walk). "
             "Planning time: a swarm's whole robot program (compile excluded), D* Lite's "
             "solve and update calls.", ""]
    for name in maps:
        parts += [*map_table(rows, name, args.blocks), ""]
    parts += memory_table(rows, maps)
    return "\n".join(parts) + "\n"


def walks_figure(examples: dict) -> Figure:
    """Seed 0's walk of the first row on every map (``examples``: map -> row label -> (World,
    walk)), four maps a row."""
    fig, axes = panel_grid(len(examples), columns=4, width=4.5, height=5.2)
    label = ROWS[0].label
    for name, ax in zip(examples, axes):
        w, walk = examples[name][label]
        draw_robot(ax, w.known, w.hidden, walk, start=w.start, goal=w.goal,
                   title=f"{name}: {float(walk.travelled):.2f} (optimum {w.optimum:.2f})")
    fig.suptitle(f"{label}, seed 0: the walk, the plan it ended on and the blocks it found")
    return fig


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=names_argument(MAPS), default="all",
                        help=f"comma-separated, from {', '.join(MAPS)} (default all)")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--blocks", type=int, default=2, help="hidden blocks per world")
    parser.add_argument("--iterations", type=int, default=100, help="iterations per plan")
    parser.add_argument("--patience", type=int, default=30)
    parser.add_argument("--max-plans", type=int, default=8)
    add_out_argument(parser, "robot_study")
    args = parser.parse_args(argv)
    maps = args.maps
    check_counts(parser, args, "seeds", "blocks", "iterations", "patience", "max_plans")
    record = provenance.begin(__file__, argv)
    rows, examples = [], {}
    for name in maps:
        mine, examples[name] = study_map(name, seeds=args.seeds, blocks=args.blocks,
                                         iterations=args.iterations, patience=args.patience,
                                         max_plans=args.max_plans)
        rows += mine
    swarms = {row.label: dict(definition(make(row.swarm)), memory=row.memory)
              for row in ROWS if row.swarm}
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args), swarms=swarms)
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    text = record.publish(args.out, markdown(rows, maps, args))
    write_png(walks_figure(examples), args.out / "walks.png")
    shown = "pathmap20x20" if "pathmap20x20" in maps else maps[0]
    w, walk = examples[shown][ROWS[0].label]
    animate_robot(w.known, w.hidden, walk, args.out / "robot.gif", start=w.start, goal=w.goal,
                  title=f"{shown}, {ROWS[0].label.split(' (')[0]}: plan {{plan}}, move {{move}}")
    print("\n" + text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
