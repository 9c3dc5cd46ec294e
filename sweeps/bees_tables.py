"""The bees paper's Tables 1-7: cABC on maps #1 and #2, ours beside the paper's.

Every row is a number of runs (seeds 0, 1, ...) of ``cabc`` with the paper's M = 200 steps:

* **Tables 1-5**: the paper's weight settings (Table 1: ``w1, w2``; Tables 2-3: ``w1, w3``;
  Tables 4-5: all three), 8 colony cycles a step (the paper's "number of cABC runs during each
  iteration equals to 8"), ``--runs`` runs a row (20: the paper's "we performed 20
  experiments"; its targets there are counts of 20).
* **Tables 6-7**: 0 to 10 colony cycles a step; the paper does not say with which weights: we
  use its best of Tables 4 and 5 (:data:`FIGURE_WEIGHTS`). ``--cycle-runs`` runs a row (30): the
  paper does not say how many runs these tables have, but Table 6, read as its text implies
  (:data:`PAPER_CYCLES`), counts a target of 30, which needs at least 30 runs (our inference);
  30 is also the K of the paper's inverse problem. Table 7's counts (at most 19) fit 20 or 30:
  it is the same study on map #2 and gets the same 30.

Columns: target (runs that reached the goal), the mean and standard deviation of the path length
of those runs (avgP, stdP) and of one run's wall time (avgT, stdT: each run timed alone after a
warm-up compile), then ours only: the vehicle's steps and the bee evaluations per run (means),
the runs whose trajectory passes through an obstacle (the paper's vehicle checks only where it
lands, so it may clip a corner; shapely-free check: :func:`jaxswarm.world.plane.crossings`) and
the best length found against the visibility-graph optimum. Each table has the paper's variant
(``cabc``) and the one that also forbids moves through obstacles (``forbid_crossing``); Tables
2-5, whose rows vary ``w3``, also have ``cabc`` with f3's other unit (the option ``turn_unit``,
see :mod:`jaxswarm.swarm.bees.guided`). Tables 6-7 name their best row by the rule of the
paper's text (the most targets, then the shorter path), the paper's and ours.

Written to ``--out`` (default ``out/bees_tables``; ``make reproduce`` uses
``results/bees_tables``), each file atomically: ``runs.csv`` (one row per run), ``table.md``,
``provenance.json`` and ``map1.png``, ``map2.png`` (the first runs of the paper's best weights,
with the sensor windows they saw, beside the shortest path; drawn when a table that runs them,
4 to 7, is asked for).

Run from the repository root (about 10 minutes on 2 cores)::

    python sweeps/bees_tables.py
    python sweeps/bees_tables.py --tables 1,6 --runs 4 --cycle-runs 4
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import jax
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from jaxswarm.exact.visibility import shortest_path  # noqa: E402
from jaxswarm.maps.planes import paper_plane  # noqa: E402
from jaxswarm.plot.plane import draw_plane, draw_trajectory  # noqa: E402
from jaxswarm.runtime.atomic import write_csv  # noqa: E402
from jaxswarm.studies import provenance  # noqa: E402
from jaxswarm.studies.arguments import (add_out_argument, check_counts,  # noqa: E402
                                        numbers_argument)
from jaxswarm.studies.figures import write_png  # noqa: E402
from jaxswarm.studies.timing import timed_call  # noqa: E402
from jaxswarm.swarm import definition, make, make_task, run  # noqa: E402
from jaxswarm.swarm.bees.guided import TURN_UNITS  # noqa: E402
from jaxswarm.world.plane import crossings  # noqa: E402


STEPS = 200
"""The paper's M: the most vehicle steps of a run."""
CYCLES = 8
"""Colony cycles per step in Tables 1-5."""
UNIT = make("cabc").config.turn_unit
"""f3's unit in ``cabc``'s default."""
OTHER_UNIT = next(unit for unit in TURN_UNITS if unit != UNIT)
"""f3's other unit, the row ``cabc, f3 in ...`` of Tables 2-5."""
VARIANTS = {"cabc": {}, f"cabc, f3 in {OTHER_UNIT}": {"turn_unit": OTHER_UNIT},
            "cabc, forbid_crossing": {"forbid_crossing": True}}
"""Row label -> the options of ``cabc`` it sets."""
UNIT_TABLES = (2, 3, 4, 5)
"""The tables with the row of f3's other unit: their rows vary ``w3``."""
FIGURE_WEIGHTS = {"map1": (1.0, 0.2, 0.03), "map2": (0.8, 0.1, 0.03)}
"""The paper's best weights per map (Tables 4 and 5; Tables 6-7 use them too): their runs with
8 cycles, from whichever table ran them first, are drawn."""

PAPER = {
    # table: (map, [(w1, w2, w3, target, avgP, stdP, avgT, stdT)])
    1: ("map1", [(0.7, 0.3, 0.0, 5, 113, 31, 1.9, 0.98), (0.9, 0.1, 0.0, 17, 68, 0.8, 0.4, 0.06),
                 (1.0, 0.0, 0.0, 16, 66, 1.9, 0.35, 0.05)]),
    2: ("map1", [(0.5, 0.0, 0.05, 6, 141, 32, 0.92, 0.3), (0.6, 0.0, 0.05, 5, 201, 30, 1.5, 0.3),
                 (0.7, 0.0, 0.03, 17, 118, 44, 0.96, 0.6), (0.7, 0.0, 0.1, 5, 153, 53, 1.0, 0.53),
                 (0.8, 0.0, 0.05, 12, 155, 57, 1.1, 0.6), (0.9, 0.0, 0.1, 3, 180, 58, 1.2, 0.6),
                 (0.9, 0.0, 0.05, 12, 155, 51, 1.23, 0.7)]),
    3: ("map2", [(0.6, 0.0, 0.01, 1, 94.6, 0.0, 0.27, 0.0), (0.7, 0.0, 0.03, 14, 166, 53, 0.5, 0.2),
                 (0.7, 0.0, 0.1, 10, 178, 61, 0.36, 0.2), (0.8, 0.0, 0.05, 13, 179, 46, 0.4, 0.1),
                 (0.9, 0.0, 0.1, 8, 188, 83, 0.4, 0.2), (0.9, 0.0, 0.05, 10, 154, 35, 0.35, 0.1),
                 (1.0, 0.0, 0.05, 14, 173, 70, 0.4, 0.2)]),
    4: ("map1", [(0.8, 0.1, 0.05, 16, 146, 39, 1.1, 0.5), (0.8, 0.2, 0.1, 9, 186, 50, 1.4, 0.5),
                 (0.8, 0.3, 0.2, 7, 164, 30, 1.2, 0.3), (0.9, 0.2, 0.05, 14, 171, 41, 1.6, 0.5),
                 (0.9, 0.1, 0.1, 6, 133, 25, 0.95, 0.3), (0.9, 0.3, 0.03, 17, 105, 30, 0.9, 0.4),
                 (1.0, 0.1, 0.1, 7, 168, 48, 1.2, 0.5), (1.0, 0.2, 0.03, 17, 90, 30, 0.7, 0.4),
                 (1.2, 0.1, 0.05, 17, 132, 36, 1.1, 0.5)]),
    5: ("map2", [(0.8, 0.1, 0.05, 11, 141, 41, 0.8, 0.4), (0.8, 0.2, 0.05, 5, 195, 50, 1.4, 0.4),
                 (0.8, 0.3, 0.05, 10, 203, 53, 1.43, 0.4), (0.9, 0.2, 0.05, 14, 165, 58, 1.2, 0.5),
                 (0.9, 0.1, 0.03, 12, 153, 55, 1.3, 0.6), (0.8, 0.1, 0.03, 16, 183, 54, 1.5, 0.6),
                 (0.7, 0.1, 0.03, 14, 166, 60, 1.3, 0.6), (1.0, 0.1, 0.05, 14, 187, 55, 1.4, 0.5),
                 (1.2, 0.1, 0.05, 13, 146, 34, 1.1, 0.3)]),
}
"""The paper's Tables 1-5 as printed (Tables 2-3 weigh f1 and f3: their w2 is 0)."""

PAPER_CYCLES = {
    # table: (map, weights, the printed columns as we read them, [(cycles, *printed values)])
    6: ("map1", FIGURE_WEIGHTS["map1"], ("stdP", "avgP", "target"),
        [(0, 34, 137, 30), (1, 32, 120, 28), (2, 32, 126, 30), (5, 32, 125, 26),
         (8, 24, 132, 20), (10, 24, 116, 12)]),
    7: ("map2", FIGURE_WEIGHTS["map2"], ("avgP", "stdP", "target"),
        [(0, 205, 72, 13), (1, 200, 60, 15), (2, 202, 50, 14), (3, 146, 60, 17),
         (5, 137, 36, 19), (8, 142, 37, 14)]),
}
"""The paper's Tables 6-7, values in their printed order. Both print the header "avgP stdP
target". Table 7's values read so. Table 6's first two columns are swapped: read as printed, its
avgP would be 24 to 34, below the shortest path of map #1 (its Table 1's best avgP is 66), and
its stdP above 100. Read as (stdP, avgP, target), its targets are 30/28/30/26/20/12 and its text
holds: "the best target value was obtained when 2 iteration of cABC were executed inside each
independent R_i due to the shorter path" (0 and 2 cycles tie at 30; 2 cycles has avgP 126, 0
cycles 137). Table 7's text follows the same rule: "The best results are obtained for five cABC
iterations which produced the smallest average path length" (5 cycles: target 19, avgP 137)."""

TITLE = "The bees paper's Tables 1-7: cABC on maps #1 and #2"
ABOUT = ("`cabc` is the paper's constrained ABC local planner as written (eqs. 1-10, Deb's "
         "rules; the sizes the paper leaves open are ours: 20 sources, a window of side 2, a "
         "tolerance of 0.5; f2 and f3 as `jaxswarm.swarm.bees.guided` defines them, f3 in "
         f"{UNIT}). `cabc, f3 in {OTHER_UNIT}` (Tables 2-5) measures f3's turn in {OTHER_UNIT}: "
         "the text lost f3's formula and its unit, and the module docstring of "
         "`jaxswarm.swarm.bees.guided` says which unit is the default and why. "
         "`cabc, forbid_crossing` is the default with moves through an obstacle forbidden too. "
         "Maps #1 and #2 are ours, built in the spirit of the paper's figures "
         "(`jaxswarm.maps.planes`). The paper's values are quoted beside ours; its Table 6 with "
         "its first two columns swapped, as its text implies (see Table 6).")

RUN_COLUMNS = ["table", "map", "variant", "turn_unit", "w1", "w2", "w3", "cycles", "seed",
               "reached", "length", "optimum", "steps", "evaluations", "clipped", "seconds"]


def settings(table: int) -> tuple[str, list[tuple[float, float, float, int]]]:
    """A table's map and its rows as ``(w1, w2, w3, cycles)``."""
    if table in PAPER:
        name, rows = PAPER[table]
        return name, [(w1, w2, w3, CYCLES) for w1, w2, w3, *_ in rows]
    name, weights, _, rows = PAPER_CYCLES[table]
    return name, [(*weights, cycles) for cycles, *_ in rows]


def variants(table: int) -> list[str]:
    """The row labels of a table's variants (f3's other unit in :data:`UNIT_TABLES` only)."""
    return [label for label, options in VARIANTS.items()
            if "turn_unit" not in options or table in UNIT_TABLES]


def swarm_of(variant: str):
    """The ``cabc`` swarm of a row label."""
    return make("cabc", **VARIANTS[variant])


def study(table: int, variant: str, runs: int) -> tuple[list[dict], np.ndarray]:
    """Every run of a table's rows for one variant: all rows and seeds in one vmapped program
    for the outcomes, then each run again alone for its wall time. Returns the rows and the
    trajectories (f32[rows, M + 2, 2])."""
    name, rows = settings(table)
    chosen = paper_plane(name)
    swarm = swarm_of(variant)
    task = make_task(chosen.plane, chosen.start, chosen.goal)
    optimum, _ = shortest_path(chosen.plane, chosen.start, chosen.goal)
    grid = [(row, seed) for row in rows for seed in range(runs)]
    params = jax.tree_util.tree_map(lambda value: np.full(len(grid), value, np.float32),
                                    swarm.default_params)._replace(**{
        field: np.asarray([row[i] for row, _ in grid], np.float32)
        for i, field in enumerate(("w1", "w2", "w3", "inner_iterations"))})
    keys = jax.vmap(jax.random.key)(np.asarray([seed for _, seed in grid]))
    batch = jax.jit(jax.vmap(lambda key, p: run(swarm, key, chosen.plane, task, p,
                                                iterations=STEPS)))
    states, traces = jax.device_get(batch(keys, params))
    solutions = jax.device_get(jax.vmap(swarm.best)(states))
    clipped = np.asarray(jax.vmap(lambda w: crossings(chosen.plane, w[:-1], w[1:]).sum())(
        states.waypoints)) > 0
    out = []
    for i, (row, seed) in enumerate(grid):
        one = jax.tree_util.tree_map(lambda leaf: leaf[i], params)
        out.append(dict(table=table, map=name, variant=variant,
                        turn_unit=swarm.config.turn_unit, w1=row[0], w2=row[1],
                        w3=row[2], cycles=row[3], seed=seed,
                        reached=bool(solutions.found[i]),
                        length=float(solutions.cost[i]), optimum=optimum,
                        steps=int(traces.moves[i].sum()),
                        evaluations=int(traces.evaluations[i].sum()),
                        clipped=bool(clipped[i]),
                        seconds=time_alone(swarm, seed, chosen, task, one)))
    return out, np.asarray(states.waypoints)


def time_alone(swarm, seed: int, chosen, task, params) -> float:
    """The wall time of one run on its own (compiled by the first call of the variant)."""
    return timed_call(run, swarm, jax.random.key(seed), chosen.plane, task, params,
                      iterations=STEPS)[1]


def warm_up(variant: str) -> None:
    """Compile the variant's unbatched run (one compile serves both maps: same shapes)."""
    chosen = paper_plane("map1")
    swarm = swarm_of(variant)
    time_alone(swarm, 0, chosen, make_task(chosen.plane, chosen.start, chosen.goal),
               swarm.default_params)


def summarise(runs: list[dict]) -> tuple[str, ...]:
    """Our cells of a row: target, avgP, stdP, avgT, stdT, steps, evaluations, clipped."""
    lengths = [r["length"] for r in runs if r["reached"]]
    seconds = [r["seconds"] for r in runs]
    return (f"{len(lengths)}/{len(runs)}", _mean(lengths), _std(lengths), _mean(seconds, 3),
            _std(seconds, 3), f"{statistics.mean(r['steps'] for r in runs):.0f}",
            f"{statistics.mean(r['evaluations'] for r in runs):.0f}",
            f"{sum(r['clipped'] for r in runs)}")


def table_lines(table: int, rows: list[dict]) -> list[str]:
    """The Markdown of one table: per setting, the paper's row, then ours per variant (Tables
    6-7: then the best rows by the rule of the paper's text)."""
    name, settings_ = settings(table)
    optimum = rows[0]["optimum"]
    best = min((r["length"] for r in rows if r["reached"]), default=float("inf"))
    key = "w1 | w2 | w3" if table in PAPER else "cycles"
    lines = [f"Map {name[-1]}: shortest path {optimum:.2f}; the best of our runs "
             f"{best:.2f}.", "",
             f"| {key} | rows | target | avgP | stdP | avgT (s) | stdT (s) | steps | "
             "evaluations | clipped |",
             "| " + " | ".join(["---"] * (3 if table in PAPER else 1)) + " | --- |"
             + " ---: |" * 8]
    for i, setting in enumerate(settings_):
        label = (" | ".join(f"{w:g}" for w in setting[:3]) if table in PAPER
                 else f"{setting[3]}")
        lines.append(f"| {label} | paper | " + " | ".join(paper_cells(table, i)) + " | | | |")
        for variant in variants(table):
            lines.append(f"| {label} | {variant} | "
                         + " | ".join(summarise(of_setting(rows, variant, setting))) + " |")
    if table in PAPER_CYCLES:
        lines += ["", *cycles_notes(table, rows)]
    return lines


def of_setting(rows: list[dict], variant: str, setting: tuple) -> list[dict]:
    """The runs of ``rows`` of one variant and one ``(w1, w2, w3, cycles)`` setting."""
    return [r for r in rows if r["variant"] == variant
            and (r["w1"], r["w2"], r["w3"], r["cycles"]) == setting]


def paper_cycle_row(table: int, i: int) -> dict:
    """Row ``i`` of the paper's Table 6 or 7 as ``{"cycles", "target", "avgP", "stdP"}``, its
    printed values read in the column order of :data:`PAPER_CYCLES`."""
    _, _, columns, rows = PAPER_CYCLES[table]
    cycles, *values = rows[i]
    return dict(cycles=cycles, **dict(zip(columns, values, strict=True)))


def best_by_text(rows: list[dict]) -> dict:
    """The best of rows with ``target`` and ``avgP`` by the rule of the paper's text on Tables
    6-7: the most targets, then the shorter path (the first of equals)."""
    return min(rows, key=lambda row: (-row["target"], row["avgP"]))


def cycles_notes(table: int, rows: list[dict]) -> list[str]:
    """The lines under Table 6 or 7: how the paper's values are read, our runs a row, and the
    best row of the paper's and of ``cabc`` by :func:`best_by_text`."""
    _, settings_ = settings(table)
    paper = [paper_cycle_row(table, i) for i in range(len(settings_))]
    best = best_by_text(paper)
    ties = [str(row["cycles"]) for row in paper
            if row["target"] == best["target"] and row is not best]
    tied = (f"; tied on target with {', '.join(ties)} cycles, it has the shorter path"
            if ties else "")
    ours = []
    for setting in settings_:
        lengths = [r["length"] for r in of_setting(rows, "cabc", setting) if r["reached"]]
        ours.append(dict(cycles=setting[3], target=len(lengths),
                         avgP=statistics.mean(lengths) if lengths else float("inf")))
    mine = best_by_text(ours)
    runs = len(of_setting(rows, "cabc", settings_[0]))
    ours_best = (f"`cabc`'s {mine['cycles']} cycles (target {mine['target']}/{runs}, avgP "
                 f"{mine['avgP']:.1f})" if mine["target"] else "no run of `cabc` arrived")
    return [f"The paper prints the header avgP, stdP, target; its values are read as "
            f"{', '.join(PAPER_CYCLES[table][2])}. It does not say how many runs a row has "
            "(Table 6's target of 30 needs at least 30: our inference); ours are "
            f"{runs} a row. The best row by the rule of the paper's text (the most targets, "
            f"then the shorter path): the paper's {best['cycles']} cycles (target "
            f"{best['target']}, avgP {best['avgP']:g}{tied}); {ours_best}."]


def paper_cells(table: int, i: int) -> tuple[str, ...]:
    """The paper's target, avgP, stdP, avgT, stdT of row ``i`` ("" where it gives none; Tables
    6-7 do not say their runs, so their targets are bare counts)."""
    if table in PAPER:
        *_, target, avg, std, seconds, spread = PAPER[table][1][i]
        return f"{target}/20", f"{avg:g}", f"{std:g}", f"{seconds:g}", f"{spread:g}"
    row = paper_cycle_row(table, i)
    return f"{row['target']}", f"{row['avgP']:g}", f"{row['stdP']:g}", "", ""


def trajectory_figure(path: Path, name: str, rows: list[dict], waypoints: np.ndarray) -> None:
    """The trajectories of ``rows`` (at most four) on map ``name`` with the sensor windows they
    saw every 5th step, and the shortest path dashed."""
    chosen = paper_plane(name)
    first = rows[0]
    weights = (first["w1"], first["w2"], first["w3"])
    fig, ax = plt.subplots(figsize=(6.4, 6.4))
    draw_plane(ax, chosen.plane, start=chosen.start, goal=chosen.goal,
               title=f"{name}: cabc, w = {weights}, {first['cycles']} cycles a step")
    optimum, shortest = shortest_path(chosen.plane, chosen.start, chosen.goal)
    draw_trajectory(ax, shortest, color="k", linestyle="--", label=f"shortest path {optimum:.1f}")
    window = float(make("cabc").default_params.window)
    for row, points in zip(rows[:4], waypoints[:4]):
        draw_trajectory(ax, points, window=window, every=5,
                        label=f"seed {row['seed']}: " + (f"reached, {row['length']:.1f}"
                                                         if row["reached"] else "stopped"))
    ax.legend(loc="lower right", fontsize=7)
    write_png(fig, path)


def _mean(values, digits: int = 1) -> str:
    """The mean of ``values`` with ``digits`` decimals, "-" for none."""
    return f"{statistics.mean(values):.{digits}f}" if values else "-"


def _std(values, digits: int = 1) -> str:
    """The population standard deviation of ``values`` with ``digits`` decimals, "-" for none."""
    return f"{statistics.pstdev(values):.{digits}f}" if values else "-"


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tables", type=numbers_argument(range(1, 8)), default="1,2,3,4,5,6,7",
                        help="comma-separated, from 1-7")
    parser.add_argument("--runs", type=int, default=20,
                        help="runs (seeds) per row of Tables 1-5 (the paper's 20)")
    parser.add_argument("--cycle-runs", type=int, default=30,
                        help="runs (seeds) per row of Tables 6-7 (30: the paper does not say; "
                             "Table 6's target of 30 needs at least 30 runs)")
    add_out_argument(parser, "bees_tables")
    args = parser.parse_args(argv)
    check_counts(parser, args, "runs", "cycle_runs")
    record = provenance.begin(__file__, argv)
    rows, sections, drawn = [], [], set()
    for variant in dict.fromkeys(v for table in args.tables for v in variants(table)):
        warm_up(variant)
    for table in args.tables:
        began = time.perf_counter()
        mine = []
        for variant in variants(table):
            found, waypoints = study(table, variant,
                                     args.runs if table in PAPER else args.cycle_runs)
            mine += found
            name = found[0]["map"]
            best = [i for i, r in enumerate(found) if (r["w1"], r["w2"], r["w3"], r["cycles"])
                    == (*FIGURE_WEIGHTS[name], CYCLES)]
            if variant == "cabc" and best and name not in drawn:
                trajectory_figure(args.out / f"{name}.png", name, [found[i] for i in best],
                                  waypoints[best])
                drawn.add(name)
        rows += mine
        what = {1: "f1 and f2", 2: "f1 and f3", 3: "f1 and f3", 4: "f1, f2 and f3",
                5: "f1, f2 and f3"}.get(table, "colony cycles per step")
        sections.append((f"Table {table}: {what}, map #{settings(table)[0][-1]}",
                         table_lines(table, mine)))
        print(f"table {table}: {time.perf_counter() - began:.0f} s", flush=True)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args),
                  swarm=definition(make("cabc")))
    write_csv(args.out / "runs.csv", rows, RUN_COLUMNS)
    print("\n" + record.publish(args.out, provenance.join_sections(sections)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
