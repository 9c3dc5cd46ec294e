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
``jaxswarm.maps.paper``; every optimum is Dijkstra's. Written to ``--out`` (default
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
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from jaxswarm.exact import dijkstra  # noqa: E402
from jaxswarm.maps.iwd_pg import iwd_pg_map  # noqa: E402
from jaxswarm.maps.paper import paper_map  # noqa: E402
from jaxswarm.plot.graph import draw_map, draw_paths, save_png  # noqa: E402
from jaxswarm.runtime.atomic import write_csv  # noqa: E402
from jaxswarm.swarm import definition, make, make_task, run  # noqa: E402
from jaxswarm.swarm.iwd import fuzzy  # noqa: E402
from jaxswarm.studies import provenance


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
PAPER_MAPS = ("mosaic20", "alley20", "maze20", "mosaic50", "alley50", "maze50")
RUN_COLUMNS = ("experiment", "map", "variant", "seed", "optimum", "cost", "optimal",
               "iterations", "evaluations", "evaluations_to_optimum", "seconds")
CURVE_COLUMNS = ("experiment", "variant", "seed", "iteration", "best_cost", "evaluations")
SCORE_COLUMNS = ("path", "length", "section", "spl", "ospl", "score")
OPTIMAL_GAP = 1e-4
"""A run reaches the optimum when its relative gap to it is below this."""
TITLE = "The IWD_PG paper's experiments"
ABOUT = ("`iwd_pg` is the IWD_PG paper's algorithm with each operator a switch; where the paper's "
         "figures, membership functions, rules and maps did not survive, ours are documented in "
         "`jaxswarm.swarm.iwd` and `jaxswarm.maps.iwd_pg`. `iwd` is its baseline. Optima are "
         "Dijkstra's.")


def load_map(name: str):
    chosen = iwd_pg_map(name) if name in ("field", "complex") else paper_map(name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    return graph, task, float(dijkstra(graph, task.start, task.goal).cost)


def study(experiment, map_name: str, swarm_name: str, variant: str, options: dict, *,
          runs: int, iterations: int, drops: int):
    """Rows of runs.csv and curves.csv, and the final states, of ``runs`` seeds of one
    variant on one map."""
    graph, task, optimum = load_map(map_name)
    swarm = make(swarm_name, num_agents=drops, **options)

    def one(key):
        return jax.block_until_ready(run(swarm, key, graph, task, swarm.default_params,
                                         iterations=iterations))

    keys = jax.random.split(jax.random.key(0), runs)
    one(keys[0])  # compile
    rows, curves, states = [], [], []
    for seed, key in enumerate(keys):
        began = time.perf_counter()
        state, trace = one(key)
        seconds = time.perf_counter() - began
        used = int(trace.iterations)
        best = np.asarray(trace.best_cost)[:used]
        calls = np.cumsum(np.asarray(trace.evaluations)[:used])
        reached = np.flatnonzero(best <= optimum * (1 + OPTIMAL_GAP))
        cost = float(swarm.best(state).cost)
        rows.append(dict(experiment=experiment, map=map_name, variant=variant, seed=seed,
                         optimum=optimum, cost=cost,
                         optimal=cost <= optimum * (1 + OPTIMAL_GAP), iterations=used,
                         evaluations=int(calls[-1]) if used else 0,
                         evaluations_to_optimum=int(calls[reached[0]]) if reached.size else "",
                         seconds=seconds))
        curves += [dict(experiment=experiment, variant=variant, seed=seed, iteration=t + 1,
                        best_cost=float(best[t]), evaluations=int(calls[t]))
                   for t in range(used)]
        states.append(state)
    return rows, curves, states, (graph, task)


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
    fig, ax = plt.subplots(figsize=(6, 4))
    for variant in variants:
        ax.plot(np.arange(1, iterations + 1), mean_curve(curves, variant, iterations),
                label=variant)
    ax.axhline(optimum, color="k", linestyle=":", label="optimum")
    ax.set(xlabel="iteration", ylabel="best length (mean over runs)", title=title)
    ax.legend()
    save_png(fig, path)
    plt.close(fig)


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


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--experiments", default="1,2,3,4,5,6,7",
                        help="comma-separated, from 1-7")
    parser.add_argument("--runs-smooth", type=int, default=50)
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--runs-complex", type=int, default=15)
    parser.add_argument("--iterations", type=int, default=50)
    parser.add_argument("--drops", type=int, default=50)
    parser.add_argument("--maps", default=",".join(PAPER_MAPS),
                        help="the RFD paper's maps of experiment 7")
    parser.add_argument("--out", type=Path, default=Path("out/iwd_pg_experiments"))
    args = parser.parse_args(argv)
    for option in ("runs_smooth", "runs", "runs_complex", "iterations", "drops"):
        if getattr(args, option) < 1:
            parser.error(f"--{option.replace('_', '-')} must be at least 1, "
                         f"got {getattr(args, option)}")
    try:
        chosen = sorted({int(e) for e in args.experiments.split(",")})
    except ValueError:
        parser.error(f"--experiments must be numbers from 1-7, got {args.experiments!r}")
    if not set(chosen) <= set(range(1, 8)):
        parser.error(f"--experiments must be numbers from 1-7, got {args.experiments!r}")
    record = provenance.begin(__file__, argv)
    rows, curves, scores, sections = [], [], [], []
    for experiment in chosen:
        began = time.perf_counter()
        if experiment == 4:
            _, _, states, (graph, task) = study(4, "field", "iwd_pg", "+ smoothing",
                                                VARIANTS["+ smoothing"], runs=args.runs,
                                                iterations=args.iterations, drops=args.drops)
            scores, paths = fuzzy_example(states, graph)
            table = ["| path | length | " + " | ".join(f"section {s}" for s in range(1, 5))
                     + " |", "| --- | ---: |" + " ---: |" * 4]
            for p in sorted({r["path"] for r in scores}):
                mine = [r for r in scores if r["path"] == p]
                table.append(f"| {p} | {mine[0]['length']:.2f} | "
                             + " | ".join(f"{r['score']:.3f}" for r in mine) + " |")
            fig, ax = plt.subplots(figsize=(5, 5))
            draw_map(ax, graph, start=task.start, goal=task.goal,
                     title="experiment 4: three remembered paths, four sections")
            draw_paths(ax, graph, [p for p in paths if p[0] >= 0],
                       [f"path {i + 1}" for i in range(len(paths)) if paths[i][0] >= 0])
            for s in range(1, 4):
                ax.axvline(s * graph.shape[1] / 4 - 0.5, color="grey", linestyle="--")
            ax.legend(loc="lower right", fontsize=7)
            save_png(fig, args.out / "experiment4.png")
            plt.close(fig)
            sections.append(("4. Fuzzy section scores (Table 4)", table))
        elif experiment == 7:
            mine = []
            for name in args.maps.split(","):
                for swarm_name in ("iwd", "iwd_pg"):
                    found, _, _, _ = study(7, name, swarm_name, swarm_name.upper(), {},
                                           runs=args.runs, iterations=args.iterations,
                                           drops=args.drops)
                    mine += found
            rows += mine
            table = ["| map | optimum | " + " | ".join(
                f"{v}: {what}" for v in ("IWD", "IWD_PG")
                for what in ("found", "optimal", "mean length", "fitness calls")) + " |",
                "| --- | ---: |" + " ---: |" * 8]
            for name in args.maps.split(","):
                cells = []
                for v in ("IWD", "IWD_PG"):
                    runs = [r for r in mine if r["map"] == name and r["variant"] == v]
                    found = [r["cost"] for r in runs if np.isfinite(r["cost"])]
                    cells += [f"{len(found)}/{len(runs)}",
                              f"{sum(r['optimal'] for r in runs)}/{len(runs)}",
                              f"{statistics.mean(found):.2f}" if found else "-",
                              f"{statistics.mean(r['evaluations'] for r in runs):.0f}"]
                optimum = [r for r in mine if r["map"] == name][0]["optimum"]
                table.append(f"| {name} | {optimum:.2f} | " + " | ".join(cells) + " |")
            sections.append(("7. IWD and IWD_PG on the RFD paper's maps", table))
        else:
            name, map_name, variants = EXPERIMENTS[experiment]
            runs = {1: args.runs_smooth, 6: args.runs_complex}.get(experiment, args.runs)
            mine, mine_curves = [], []
            for variant in variants:
                found, curve, _, _ = study(experiment, map_name, "iwd_pg", variant,
                                           VARIANTS[variant], runs=runs,
                                           iterations=args.iterations, drops=args.drops)
                mine += found
                mine_curves += curve
            rows += mine
            curves += [c for c in mine_curves if experiment in (2, 3, 5)]
            optimum = mine[0]["optimum"]
            table = [f"Map {map_name} (optimum {optimum:.2f}), {runs} runs per variant, "
                     f"{args.iterations} iterations at most, {args.drops} drops.", ""]
            table += lengths_table(mine, variants)
            if experiment == 5:
                table += [""] + budget_table(mine_curves, variants)
            if experiment in (2, 3, 5):
                curve_figure(args.out / f"experiment{experiment}.png", mine_curves, variants,
                             args.iterations, optimum, f"experiment {experiment}: {name}")
            sections.append((f"{experiment}. {name.capitalize()}", table))
        print(f"experiment {experiment}: {time.perf_counter() - began:.0f} s", flush=True)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args),
                  swarm=definition(make("iwd_pg", num_agents=args.drops)))
    write_csv(args.out / "runs.csv", rows, RUN_COLUMNS)
    write_csv(args.out / "curves.csv", curves, CURVE_COLUMNS)
    write_csv(args.out / "scores.csv", scores, SCORE_COLUMNS)
    print("\n" + record.publish(args.out, provenance.join_sections(sections)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
