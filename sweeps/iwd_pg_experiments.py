"""The IWD_PG paper's six experiments, and IWD_PG beside IWD on the RFD paper's maps.

Every comparison runs both sides with the same seeds (keys split from key 0); each variant is
compiled once, then its runs are timed one by one. The operators are switched by ``iwd_pg``'s
Config (see ``jaxswarm.swarm.iwd.iwd_pg``); "IWD + memory" below is ``iwd_pg`` with every
operator off (the memory alone changes nothing IWD does).

1. **Smoothing** (Table 3): ``--runs-smooth`` runs on the field map with the global smooth
   operator and without it (no other operator either way): best, mean and worst length.
2. **First intersection operator** (Figure 9): ``--runs`` runs with smoothing and the first
   operator (its children improved by local search), and with smoothing alone: the mean best
   length per iteration.
3. **Second intersection operator** (Figure 11): the same with the second operator.
4. **Fuzzy section scores** (Table 4): the scores of the three best remembered paths over four
   sections along x, on the field map: the memory of the first of ``--runs`` runs with
   smoothing alone (the operators' children replace their parents, so a full run's memory
   often holds fewer distinct paths) that remembers three.
5. **Fuzzy scores against uniform sections** (Table 5, Figure 13): ``--runs`` full IWD_PG runs
   with the fuzzy scores choosing where local search works and with a uniform choice; the best
   length reached within equal budgets of fitness calls.
6. **The complex map** (Table 6, in the spirit of SPset07): ``--runs-complex`` full IWD_PG
   runs: success (the exact optimum reached) and the fitness calls it took; the paper reports
   100 % success and the optimum by about 2,600 calls.
7. **The RFD paper's maps of sizes 20 and 50**: ``iwd`` and ``iwd_pg`` over ``--runs`` seeds
   each: success rate and fitness calls, beside the optimum.

Maps: ``jaxswarm.maps.iwd_pg`` (field, complex: ours, drawn from the paper's words) and
``jaxswarm.maps.paper``; every optimum is Dijkstra's, and a run reaches it within a relative gap
of 1e-4 (:mod:`jaxswarm.studies.success`). Written to ``--out`` (default
``out/iwd_pg_experiments``; ``make reproduce`` uses ``results/iwd_pg_experiments``), each file
atomically: ``runs.csv`` (one row per run), ``curves.csv`` (best length after each iteration
and the fitness calls so far, per run of experiments 2, 3 and 5), ``scores.csv`` (experiment
4), ``table.md``, ``provenance.json`` and one figure per experiment.

Run from the repository root (about 40 minutes on 2 cores)::

    python sweeps/iwd_pg_experiments.py
    python sweeps/iwd_pg_experiments.py --experiments 1,4 --runs-smooth 3 --iterations 10
"""
from __future__ import annotations

import argparse
import statistics
import time
from typing import NamedTuple

import jax
import jax.numpy as jnp
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from jaxswarm.dynamic.events import first_iteration_at  # noqa: E402
from jaxswarm.maps.iwd_pg import iwd_pg_map  # noqa: E402
from jaxswarm.maps.paper import paper_maps_argument  # noqa: E402
from jaxswarm.plot.graph import draw_map, draw_paths  # noqa: E402
from jaxswarm.runtime.atomic import write_csv  # noqa: E402
from jaxswarm.studies import provenance  # noqa: E402
from jaxswarm.studies.arguments import (add_out_argument, check_counts,  # noqa: E402
                                        numbers_argument)
from jaxswarm.studies.figures import write_png  # noqa: E402
from jaxswarm.studies.problems import Problem, make_problem, named_problem  # noqa: E402
from jaxswarm.studies.success import SUCCESS_GAP, at_optimum  # noqa: E402
from jaxswarm.sweep.run_record import COLUMNS as REPLAY_COLUMNS  # noqa: E402
from jaxswarm.studies.timing import TimedRun, seed_keys, timed_runs  # noqa: E402
from jaxswarm.swarm import Swarm, definition, make  # noqa: E402
from jaxswarm.swarm.iwd import fuzzy  # noqa: E402

OFF = dict(smooth=False, first_intersection=False, second_intersection=False,
           local_search=False)
"""IWD_PG with every operator off: IWD and the memory."""
VARIANTS = {
    "IWD + memory": OFF,
    "+ smoothing": dict(OFF, smooth=True),
    "+ smoothing, first intersection": dict(OFF, smooth=True, first_intersection=True,
                                            local_search=True, fuzzy=False),
    "+ smoothing, second intersection": dict(OFF, smooth=True, second_intersection=True,
                                             local_search=True, fuzzy=False),
    "IWD_PG, uniform sections": dict(fuzzy=False),
    "IWD_PG": {},
}
"""The ``iwd_pg`` options of each variant compared."""
EXPERIMENTS = {
    1: ("smoothing", "field", ("IWD + memory", "+ smoothing")),
    2: ("first intersection", "field", ("+ smoothing", "+ smoothing, first intersection")),
    3: ("second intersection", "field", ("+ smoothing", "+ smoothing, second intersection")),
    5: ("fuzzy scores", "field", ("IWD_PG, uniform sections", "IWD_PG")),
    6: ("complex map", "complex", ("IWD_PG",)),
}
"""Experiment -> (name, map, variants) of the experiments that compare runs."""
CURVES = (2, 3, 5)
"""The experiments whose runs' curves are written and drawn."""
IWD_PG_MAPS = ("field", "complex")
"""The maps of :mod:`jaxswarm.maps.iwd_pg`."""
PAPER_MAPS = ("mosaic20", "alley20", "maze20", "mosaic50", "alley50", "maze50")
"""The RFD paper's maps of experiment 7 (default)."""
RUN_COLUMNS = ("experiment", "map", "variant", "seed", "optimum", "cost", "optimal",
               "iterations", "evaluations", "evaluations_to_optimum", "seconds", *REPLAY_COLUMNS)
"""Columns of runs.csv (``run_record`` and ``fingerprint``: what ``jaxswarm replay`` needs to
run the row again; ``run_record`` empty on the paper's own field maps, which no map entry
names)."""
CURVE_COLUMNS = ("experiment", "variant", "seed", "iteration", "best_cost", "evaluations")
"""Columns of curves.csv."""
SCORE_COLUMNS = ("path", "length", "section", "spl", "ospl", "score")
"""Columns of scores.csv."""
TITLE = "The IWD_PG paper's experiments"
"""Title of table.md."""
ABOUT = ("`iwd_pg` is the IWD_PG paper's algorithm with each operator a switch; where the paper's "
         "figures, membership functions, rules and maps did not survive, ours are documented in "
         "`jaxswarm.swarm.iwd` and `jaxswarm.maps.iwd_pg`. `iwd` is its baseline. In both, only "
         "the drops that reach the goal change the soil, after the walk (the paper: \"feasible "
         "solution removes some soil of graph and therefore guides next generation drops\"; "
         "`local_updates=\"arrived\"`). Optima are Dijkstra's.")
"""What the rows are (the paragraph under the provenance)."""


class Outcome(NamedTuple):
    """What one experiment adds to the files: rows of runs.csv, curves.csv and scores.csv, and
    its section of table.md (title, Markdown lines)."""

    rows: list[dict]
    curves: list[dict]
    scores: list[dict]
    section: tuple[str, list[str]]


class Study(NamedTuple):
    """The runs of one variant on one map: runs.csv and curves.csv rows, the final states and
    the problem."""

    rows: list[dict]
    curves: list[dict]
    states: list
    problem: Problem


def load_problem(name: str) -> Problem:
    """The problem of map ``name``: an IWD_PG map (:data:`IWD_PG_MAPS`) or a paper map."""
    if name in IWD_PG_MAPS:
        chosen = iwd_pg_map(name)
        return make_problem(name, chosen.graph(), chosen.start, chosen.goal)
    return named_problem(name)


def run_rows(experiment: int, problem: Problem, variant: str, seed: int, swarm: Swarm,
             one: TimedRun) -> tuple[dict, list[dict]]:
    """The runs.csv row of one timed run and its curves.csv rows (one per iteration run)."""
    used = int(one.trace.iterations)
    best = np.asarray(one.trace.best_cost)[:used]
    calls = np.cumsum(np.asarray(one.trace.evaluations)[:used])
    first = first_iteration_at(one.trace, problem.optimum, gap=SUCCESS_GAP)
    cost = float(swarm.best(one.state).cost)
    row = dict(experiment=experiment, map=problem.label, variant=variant, seed=seed,
               optimum=problem.optimum, cost=cost, optimal=at_optimum(cost, problem.optimum),
               iterations=used, evaluations=int(calls[-1]) if used else 0,
               evaluations_to_optimum="" if first is None else int(calls[first - 1]),
               seconds=one.seconds, **one.replay)
    curves = [dict(experiment=experiment, variant=variant, seed=seed, iteration=t + 1,
                   best_cost=float(best[t]), evaluations=int(calls[t])) for t in range(used)]
    return row, curves


def study(experiment: int, map_name: str, swarm_name: str, variant: str, options: dict, *,
          runs: int, iterations: int, drops: int) -> Study:
    """``runs`` seeds (keys split from key 0) of one variant (``swarm_name`` with the Config
    ``options``) on one map, compiled first, each run timed alone."""
    problem = load_problem(map_name)
    swarm = make(swarm_name, num_agents=drops, **options)
    timed = timed_runs(swarm, seed_keys(runs), problem.graph, problem.task, swarm.default_params,
                       iterations=iterations, entry=problem.entry)
    rows, curves = [], []
    for seed, one in enumerate(timed):
        row, curve = run_rows(experiment, problem, variant, seed, swarm, one)
        rows.append(row)
        curves += curve
    return Study(rows, curves, [one.state for one in timed], problem)


def lengths_table(rows, variants) -> list[str]:
    """Markdown lines: per variant, paths found, optima reached, lengths and fitness calls."""
    lines = ["| variant | runs | found | optimal | best | mean | worst | fitness calls: mean "
             "| fitness calls to the optimum: mean |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for variant in variants:
        mine = [r for r in rows if r["variant"] == variant]
        found = [r["cost"] for r in mine if np.isfinite(r["cost"])]
        to_optimum = [r["evaluations_to_optimum"] for r in mine if r["optimal"]]
        lengths = (f"{min(found):.2f} | {statistics.mean(found):.2f} | {max(found):.2f}"
                   if found else "- | - | -")
        reach = f"{statistics.mean(to_optimum):.0f}" if to_optimum else "-"
        lines.append(f"| {variant} | {len(mine)} | {len(found)} | "
                     f"{sum(r['optimal'] for r in mine)} | {lengths} | "
                     f"{statistics.mean(r['evaluations'] for r in mine):.0f} | {reach} |")
    return lines


def budget_table(curves, variants) -> list[str]:
    """Markdown lines: per variant, the best length within four budgets of fitness calls
    (quartiles of the calls the runs made), mean over the runs with a path and worst."""
    calls = sorted({c["evaluations"] for c in curves})
    budgets = [int(b) for b in np.quantile(calls, [0.25, 0.5, 0.75, 1.0])]
    lines = ["Best length within a budget of fitness calls (mean over the runs with a path / "
             "worst; inf: no path yet):", "",
             "| variant | " + " | ".join(f"{b} calls" for b in budgets) + " |",
             "| --- |" + " ---: |" * len(budgets)]
    for variant in variants:
        cells = []
        for column in best_within(curves, variant, budgets).T:
            finite = column[np.isfinite(column)]
            mean = f"{np.mean(finite):.2f}" if finite.size else "inf"
            cells.append(f"{mean} / {np.max(column):.2f}")
        lines.append(f"| {variant} | " + " | ".join(cells) + " |")
    return lines


def mean_curve(curves, variant, iterations, key="iteration"):
    """Per iteration, the mean over runs of the best length so far (runs that stopped early
    keep their last value; inf until a path was found: a mean over runs with a path)."""
    runs = sorted({c["seed"] for c in curves if c["variant"] == variant})
    table = np.full((len(runs), iterations), np.inf)
    for c in curves:
        if c["variant"] == variant:
            table[runs.index(c["seed"]), c["iteration"] - 1] = c["best_cost"]
    for t in range(1, iterations):
        stopped = ~np.isfinite(table[:, t]) & np.isfinite(table[:, t - 1])
        table[stopped, t] = table[stopped, t - 1]
    with np.errstate(invalid="ignore"):
        return np.array([np.mean(col[np.isfinite(col)]) if np.isfinite(col).any() else np.nan
                         for col in table.T])


def best_within(curves, variant, budgets):
    """Per budget of fitness calls, each run's best length within it (inf before a path)."""
    out = {}
    for seed in sorted({c["seed"] for c in curves if c["variant"] == variant}):
        mine = [c for c in curves if c["variant"] == variant and c["seed"] == seed]
        out[seed] = [min([c["best_cost"] for c in mine if c["evaluations"] <= b],
                         default=np.inf) for b in budgets]
    return np.array(list(out.values()))


def curve_figure(path, curves, variants, iterations, optimum, title):
    """The mean best length per iteration of each variant (:func:`mean_curve`) beside the
    optimum, written as a PNG to ``path``."""
    fig, ax = plt.subplots(figsize=(6, 4))
    for variant in variants:
        ax.plot(np.arange(1, iterations + 1), mean_curve(curves, variant, iterations),
                label=variant)
    ax.axhline(optimum, color="k", linestyle=":", label="optimum")
    ax.set(xlabel="iteration", ylabel="best length (mean over runs)", title=title)
    ax.legend()
    write_png(fig, path)


def fuzzy_example(states, graph, sections: int = 4):
    """Experiment 4: the scores of the three best remembered paths of the first run that
    remembers three (else of the first run)."""
    full = [s for s in states if bool(jnp.isfinite(s.memory.costs[2]))]
    memory = (full or states)[0].memory
    paths = memory.paths[:3]
    lengths = jax.vmap(lambda p: fuzzy.section_lengths(graph, p, 0, sections))(paths)
    present = jnp.isfinite(memory.costs[:3])
    scores = np.asarray(fuzzy.section_scores(lengths, present))
    lengths = np.asarray(lengths)
    rows = [dict(path=p + 1, length=float(memory.costs[p]), section=s + 1,
                 spl=float(lengths[p, s]), ospl=float(lengths[p].sum() - lengths[p, s]),
                 score=float(scores[p, s]))
            for p in range(3) for s in range(sections) if bool(present[p])]
    return rows, np.asarray(paths)


def fuzzy_scores_experiment(args: argparse.Namespace) -> Outcome:
    """Experiment 4: the fuzzy section scores of three remembered paths (Table 4), their
    figure written to ``args.out``."""
    found = study(4, "field", "iwd_pg", "+ smoothing", VARIANTS["+ smoothing"], runs=args.runs,
                  iterations=args.iterations, drops=args.drops)
    graph = found.problem.graph
    scores, paths = fuzzy_example(found.states, graph)
    table = ["| path | length | " + " | ".join(f"section {s}" for s in range(1, 5)) + " |",
             "| --- | ---: |" + " ---: |" * 4]
    for p in sorted({r["path"] for r in scores}):
        mine = [r for r in scores if r["path"] == p]
        table.append(f"| {p} | {mine[0]['length']:.2f} | "
                     + " | ".join(f"{r['score']:.3f}" for r in mine) + " |")
    fig, ax = plt.subplots(figsize=(5, 5))
    draw_map(ax, graph, start=found.problem.start, goal=found.problem.goal,
             title="experiment 4: three remembered paths, four sections")
    draw_paths(ax, graph, [p for p in paths if p[0] >= 0],
               [f"path {i + 1}" for i in range(len(paths)) if paths[i][0] >= 0])
    for s in range(1, 4):
        ax.axvline(s * graph.shape[1] / 4 - 0.5, color="grey", linestyle="--")
    ax.legend(loc="lower right", fontsize=7)
    write_png(fig, args.out / "experiment4.png")
    return Outcome([], [], scores, ("4. Fuzzy section scores (Table 4)", table))


def paper_maps_experiment(args: argparse.Namespace) -> Outcome:
    """Experiment 7: IWD and IWD_PG on the RFD paper's maps ``args.maps``."""
    rows = [row for name in args.maps for swarm_name in ("iwd", "iwd_pg")
            for row in study(7, name, swarm_name, swarm_name.upper(), {}, runs=args.runs,
                             iterations=args.iterations, drops=args.drops).rows]
    table = ["| map | optimum | " + " | ".join(
        f"{v}: {what}" for v in ("IWD", "IWD_PG")
        for what in ("found", "optimal", "mean length", "fitness calls")) + " |",
        "| --- | ---: |" + " ---: |" * 8]
    for name in args.maps:
        cells = []
        for v in ("IWD", "IWD_PG"):
            runs = [r for r in rows if r["map"] == name and r["variant"] == v]
            found = [r["cost"] for r in runs if np.isfinite(r["cost"])]
            cells += [f"{len(found)}/{len(runs)}",
                      f"{sum(r['optimal'] for r in runs)}/{len(runs)}",
                      f"{statistics.mean(found):.2f}" if found else "-",
                      f"{statistics.mean(r['evaluations'] for r in runs):.0f}"]
        optimum = [r for r in rows if r["map"] == name][0]["optimum"]
        table.append(f"| {name} | {optimum:.2f} | " + " | ".join(cells) + " |")
    return Outcome(rows, [], [], ("7. IWD and IWD_PG on the RFD paper's maps", table))


def comparison_experiment(experiment: int, args: argparse.Namespace) -> Outcome:
    """Experiments 1, 2, 3, 5 and 6: the variants of :data:`EXPERIMENTS` side by side on one
    map, the curve figure of 2, 3 and 5 written to ``args.out``."""
    name, map_name, variants = EXPERIMENTS[experiment]
    runs = {1: args.runs_smooth, 6: args.runs_complex}.get(experiment, args.runs)
    rows, curves = [], []
    for variant in variants:
        found = study(experiment, map_name, "iwd_pg", variant, VARIANTS[variant], runs=runs,
                      iterations=args.iterations, drops=args.drops)
        rows += found.rows
        curves += found.curves
    optimum = rows[0]["optimum"]
    table = [f"Map {map_name} (optimum {optimum:.2f}), {runs} runs per variant, "
             f"{args.iterations} iterations at most, {args.drops} drops.", ""]
    table += lengths_table(rows, variants)
    if experiment == 5:
        table += [""] + budget_table(curves, variants)
    if experiment in CURVES:
        curve_figure(args.out / f"experiment{experiment}.png", curves, variants,
                     args.iterations, optimum, f"experiment {experiment}: {name}")
    return Outcome(rows, curves if experiment in CURVES else [], [],
                   (f"{experiment}. {name.capitalize()}", table))


def parse_arguments(argv: list[str] | None) -> argparse.Namespace:
    """The checked command-line arguments (see the module docstring)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiments", type=numbers_argument(range(1, 8)),
                        default="1,2,3,4,5,6,7", help="comma-separated, from 1-7")
    parser.add_argument("--runs-smooth", type=int, default=50)
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--runs-complex", type=int, default=15)
    parser.add_argument("--iterations", type=int, default=50)
    parser.add_argument("--drops", type=int, default=50)
    parser.add_argument("--maps", type=paper_maps_argument, default=",".join(PAPER_MAPS),
                        help="the RFD paper's maps of experiment 7")
    add_out_argument(parser, "iwd_pg_experiments")
    args = parser.parse_args(argv)
    check_counts(parser, args, "runs_smooth", "runs", "runs_complex", "iterations", "drops")
    return args


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    args = parse_arguments(argv)
    record = provenance.begin(__file__, argv)
    outcomes = []
    for experiment in args.experiments:
        began = time.perf_counter()
        if experiment == 4:
            outcomes.append(fuzzy_scores_experiment(args))
        elif experiment == 7:
            outcomes.append(paper_maps_experiment(args))
        else:
            outcomes.append(comparison_experiment(experiment, args))
        print(f"experiment {experiment}: {time.perf_counter() - began:.0f} s", flush=True)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args),
                  swarm=definition(make("iwd_pg", num_agents=args.drops)))
    write_csv(args.out / "runs.csv", [r for o in outcomes for r in o.rows], RUN_COLUMNS)
    write_csv(args.out / "curves.csv", [c for o in outcomes for c in o.curves], CURVE_COLUMNS)
    write_csv(args.out / "scores.csv", [s for o in outcomes for s in o.scores], SCORE_COLUMNS)
    sections = [o.section for o in outcomes]
    print("\n" + record.publish(args.out, provenance.join_sections(sections)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
