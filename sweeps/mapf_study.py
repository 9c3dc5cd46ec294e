"""The A* report's multi-robot scheme, prioritised planning and Conflict-Based Search on the Moving
AI MAPF benchmark.

On each map of ``--maps`` (default: ``empty-32-32``, ``random-32-32-10``, ``room-32-32-4``,
``maze-32-32-2``, ``den312d``) and each count k of ``--agents`` (default 5, 10, 20, 50, 100), the
instance is the first k rows of the map's ``<map>-random-1.scen``
(:func:`jaxswarm.multiagent.load_instance`). Rows, the planners of :mod:`jaxswarm.multiagent`:

* ``report``: :func:`~jaxswarm.multiagent.report_scheme`, the A* report's scheme (A* per robot,
  then side-steps, waits and "one robot moves first" at collisions; the report has two robots,
  the pairwise extension to more is jaxswarm's choice);
* ``prioritized (given)``, ``prioritized (distance)``: :func:`~jaxswarm.multiagent.prioritized`
  (space-time A* around a reservation table) with the agents in the file's order, or farthest
  from its goal first;
* ``prioritized (random)``: the same in a random order, once per seed 0 .. ``--seeds`` - 1;
* ``cbs``: :func:`~jaxswarm.multiagent.cbs` (optimal sum of costs) with ``--cbs-time-limit``
  seconds per instance (default 30). It runs out of time at the larger counts: that is a result,
  recorded as not solved with CBS's reason.

Conventions (the MAPF benchmark's): the maps are 4-connected, every move or wait takes one step,
and an agent's cost is the step from which it stays at its goal for good (waits before that
count, waits at the goal afterwards do not); the sum of costs adds them, the makespan is the
largest. The lower bound is the sum of each agent's own shortest 4-connected distance to its
goal (:func:`~jaxswarm.multiagent.lower_bound`), ignoring the others; the ``.scen`` files' last
column is an 8-connected optimum and is **not** used. Every solved plan is checked by
:func:`~jaxswarm.multiagent.validate` (an invalid one raises :class:`InvalidPlan`: a planner bug),
its sum of costs must be at least the lower bound, and no planner may beat a solved CBS plan on the
same instance (else :class:`InvalidPlan` too). A planner that raises is recorded as not solved,
with the exception as its reason and ``error`` set; the study goes on, writes its files and
exits with status 1.

Per run (map, agents, planner, seed) ``runs.csv`` holds: solved, sum of costs, lower bound, their
ratio, makespan (blank when not solved), time (s, wall time of the planner call, after a warm-up
that leaves out numba's and JAX's one-off compilation), the reason when not solved, and the
planner's counters (low-level expansions, CBS nodes, the report's repairs).

Outputs (in ``--out``, default ``out/mapf_study/``, each written atomically):

* ``runs.csv``: one row per run;
* ``summary.csv``: per planner and agent count over all maps (``map`` = ``all``), then per map,
  agent count and planner: runs, solved, success rate, mean SoC / lower bound and mean makespan
  over the solved runs, median time over all runs, runs that raised;
* ``table.md``: the provenance (:mod:`jaxswarm.studies.provenance`), then both summaries as
  Markdown tables;
* ``mapf_study.png``: success rate, mean SoC / lower bound and median time against the number of
  agents, one line per planner (over all maps);
* ``provenance.json``: the provenance and the arguments.

``make reproduce`` writes them to ``results/mapf_study/``. The full default run took 8.8 minutes
on 2 cores (AMD EPYC, shared, load 2-3): mostly CBS at its time limit (13 of the 25 instances,
6.5 min) and the report's scheme repairing collisions at 50 and 100 agents (up to about 20 s an
instance); prioritised planning takes well under a second an instance. The tiny run of
``make reproduce-quick`` takes seconds.

The maps are read from ``--data`` (default: ``$JAXSWARM_MOVINGAI/mapf`` if that variable is set,
else ``../shared/benchdata/movingai/mapf`` beside the repository). Run from the repository root::

    python sweeps/mapf_study.py
    python sweeps/mapf_study.py --maps room-32-32-4,maze-32-32-2 --agents 5,10 --seeds 1 \\
        --cbs-time-limit 2 --out out/mapf_quick
"""
from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path
from typing import Callable

import numpy as np
from matplotlib.figure import Figure

from jaxswarm.multiagent import (Instance, cbs, load_instance, lower_bound, prioritized,
                                 report_scheme, validate)
from jaxswarm.runtime.atomic import atomic_path, write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts
from jaxswarm.studies.problems import movingai_folder


MAPS = ("empty-32-32", "random-32-32-10", "room-32-32-4", "maze-32-32-2", "den312d")
"""The default maps (all: ``--maps all``)."""
AGENTS = (5, 10, 20, 50, 100)
"""The default agent counts."""
PLANNERS = ("report", "prioritized (given)", "prioritized (distance)", "prioritized (random)",
            "cbs")
"""The rows, in the order they run on every instance."""
RANDOM = "prioritized (random)"
"""The row run once per seed."""
SCENARIO = "{map}-random-1.scen"
"""The scenario file of a map: its first k rows are the k agents."""
RUN_COLUMNS = ("map", "agents", "planner", "seed", "solved", "sum_of_costs", "lower_bound",
               "ratio", "makespan", "seconds", "reason", "error", "expanded", "nodes", "repairs")
SUMMARY_COLUMNS = ("map", "agents", "planner", "runs", "solved", "success_rate", "mean_ratio",
                   "mean_makespan", "median_seconds", "errors")
ALL_MAPS = "all"
"""The ``map`` of summary rows over every map."""
TITLE = "Multi-agent path finding on Moving AI MAPF maps: the A* report's scheme, prioritised " \
        "planning and CBS"
"""Title of table.md."""
ABOUT = (
    "Rows: the A* report's two-robot scheme (`report_scheme`; its pairwise extension to more "
    "robots is jaxswarm's choice), prioritised planning with space-time A* (Silver 2005; "
    "`prioritized`) in the scenario's order, farthest-first and seeded random orders, and "
    "Conflict-Based Search (Sharon et al. 2015; `cbs`, optimal sum of costs, with a time limit "
    "per instance). Instances: the first k rows of each map's `-random-1.scen`, 4-connected, "
    "unit moves, an agent's cost is the step from which it stays at its goal. SoC / LB is the "
    "sum of costs over the sum of the agents' own 4-connected distances (the `.scen` optimum "
    "column is 8-connected and not used); it and the makespan are means over the solved runs "
    "only, so planners that solve different instances are not compared on the same ones. "
    "Every solved plan passed `validate`.")
"""What the rows are (the paragraph under the provenance)."""
LABELS = {"report": "report's scheme", "prioritized (given)": "prioritized (given)",
          "prioritized (distance)": "prioritized (distance)",
          "prioritized (random)": "prioritized (random)", "cbs": "CBS"}


class InvalidPlan(RuntimeError):
    """A planner's solved plan breaks a rule (validate, the lower bound or CBS's optimality)."""


def parse_maps(text: str) -> list[str]:
    """``"all"`` or a comma list of map names (without ``.map``)."""
    if text.strip() == "all":
        return list(MAPS)
    maps = [name.strip() for name in text.split(",") if name.strip()]
    if not maps:
        raise argparse.ArgumentTypeError(f"expected map names or 'all', got {text!r}")
    return maps


def parse_agents(text: str) -> list[int]:
    """A comma list of agent counts (each at least 1), e.g. ``"5,10,20"``."""
    try:
        counts = [int(part) for part in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a comma list of integers, got {text!r}")
    if not counts or min(counts) < 1:
        raise argparse.ArgumentTypeError(f"agent counts must be at least 1, got {text!r}")
    return counts


def planner_calls(seeds: int, cbs_time_limit: float) -> list[tuple[str, int | None, Callable]]:
    """``(planner, seed or None, call(graph, starts, goals) -> Plan)`` in the order they run."""
    calls = [("report", None, report_scheme),
             ("prioritized (given)", None,
              lambda g, s, t: prioritized(g, s, t, order="given")),
             ("prioritized (distance)", None,
              lambda g, s, t: prioritized(g, s, t, order="distance"))]
    calls += [(RANDOM, seed, lambda g, s, t, seed=seed: prioritized(g, s, t, order="random",
                                                                   seed=seed))
              for seed in range(seeds)]
    calls.append(("cbs", None, lambda g, s, t: cbs(g, s, t, time_limit=cbs_time_limit)))
    return calls


def warm_up(instance: Instance) -> None:
    """Leave the one-off compilation out of the timings: numba's kernels (loaded from its cache
    once per process) on two agents, and the JAX programs compiled per map and agent count
    (the hop fields, the report's distance fields: a report run that stops before any repair)."""
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    lower_bound(graph, starts, goals)
    report_scheme(graph, starts, goals, max_repairs=0)
    prioritized(graph, starts[:2], goals[:2])
    cbs(graph, starts[:2], goals[:2], time_limit=1.0)


def run_instance(instance: Instance, map_name: str, agents: int, seeds: int,
                 cbs_time_limit: float) -> list[dict]:
    """Every planner on one instance; one row per run.

    Raises:
      InvalidPlan: a solved plan fails ``validate``, is below the lower bound, or beats CBS.
    """
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    bound = lower_bound(graph, starts, goals)
    warm_up(instance)
    rows = []
    for planner, seed, call in planner_calls(seeds, cbs_time_limit):
        began = time.perf_counter()
        try:
            plan = call(graph, starts, goals)
            error = None
        except Exception as exc:  # noqa: BLE001 - a crash is recorded, the study goes on
            plan, error = None, f"raised {type(exc).__name__}: {exc}"
        seconds = time.perf_counter() - began
        row = {"map": map_name, "agents": agents, "planner": planner,
               "seed": "" if seed is None else seed, "solved": bool(plan is not None
                                                                    and plan.solved),
               "sum_of_costs": "", "lower_bound": bound, "ratio": "", "makespan": "",
               "seconds": seconds, "reason": error or (plan.reason if plan else ""),
               "error": error is not None, "expanded": "", "nodes": "", "repairs": ""}
        if plan is not None:
            for key in ("expanded", "nodes", "repairs"):
                row[key] = plan.stats.get(key, "")
        if row["solved"]:
            where = f"{planner} on {instance.name}" + ("" if seed is None else f", seed {seed}")
            violations = validate(graph, plan.paths, starts, goals, plan.lengths)
            if violations:
                shown = "; ".join(map(str, violations[:5]))
                raise InvalidPlan(f"{where}: a solved plan with {len(violations)} violations: "
                                  f"{shown}")
            if plan.sum_of_costs < bound:
                raise InvalidPlan(f"{where}: sum of costs {plan.sum_of_costs} below the lower "
                                  f"bound {bound}")
            row.update(sum_of_costs=plan.sum_of_costs, makespan=plan.makespan,
                       ratio=plan.sum_of_costs / bound if bound > 0 else math.nan)
        rows.append(row)
    check_cbs_optimal(rows, instance.name)
    return rows


def check_cbs_optimal(rows: list[dict], name: str) -> None:
    """Raise :class:`InvalidPlan` if a solved run of one instance has a smaller sum of costs
    than a solved CBS run (CBS's is the least)."""
    optimum = [row["sum_of_costs"] for row in rows if row["planner"] == "cbs" and row["solved"]]
    if not optimum:
        return
    for row in rows:
        if row["solved"] and row["sum_of_costs"] < optimum[0]:
            raise InvalidPlan(f"{row['planner']} on {name} (seed {row['seed']}): sum of costs "
                              f"{row['sum_of_costs']} below CBS's optimum {optimum[0]}")


def run_study(maps, agent_counts, seeds: int, cbs_time_limit: float, data: Path, *,
              log: Callable[[str], None] | None = print) -> list[dict]:
    """Run every planner on every (map, agent count); the tidy rows.

    Args:
      maps: map names (files ``data / NAME.map`` and ``data / NAME-random-1.scen``).
      agent_counts: numbers of agents (the first rows of the scenario file).
      seeds: runs of the random order (seeds 0 .. seeds - 1).
      cbs_time_limit: CBS's seconds per instance.
      data: the folder of the maps.
      log: called with one progress line per instance (None: silent).
    """
    rows = []
    began = time.perf_counter()
    for map_name in maps:
        for agents in agent_counts:
            instance = load_instance(data / f"{map_name}.map",
                                     data / SCENARIO.format(map=map_name), agents)
            instance_began = time.perf_counter()
            new = run_instance(instance, map_name, agents, seeds, cbs_time_limit)
            rows += new
            if log is not None:
                solved = {}
                for row in new:
                    done, runs = solved.get(row["planner"], (0, 0))
                    solved[row["planner"]] = (done + row["solved"], runs + 1)
                took = time.perf_counter() - instance_began
                log(f"{map_name:>16} {agents:>4} agents: {took:6.1f} s (elapsed "
                    f"{time.perf_counter() - began:6.1f} s) | solved "
                    + ", ".join(f"{LABELS[p]} {d}/{n}" for p, (d, n) in solved.items()))
    return rows


def _group(rows: list[dict], key: tuple) -> dict:
    entry = {"map": key[0], "agents": key[1], "planner": key[2], "runs": len(rows)}
    solved = [row for row in rows if row["solved"]]
    entry["solved"] = len(solved)
    entry["success_rate"] = len(solved) / len(rows)
    entry["mean_ratio"] = (float(np.mean([row["ratio"] for row in solved])) if solved
                           else math.nan)
    entry["mean_makespan"] = (float(np.mean([row["makespan"] for row in solved])) if solved
                              else math.nan)
    entry["median_seconds"] = float(statistics.median(row["seconds"] for row in rows))
    entry["errors"] = sum(bool(row["error"]) for row in rows)
    return entry


def summarise(rows: list[dict]) -> list[dict]:
    """Per (agents, planner) over all maps (``map`` = :data:`ALL_MAPS`), then per (map, agents,
    planner): runs, solved, success rate, mean ratio and makespan over the solved runs, median
    seconds over all runs, errors. Sorted by map (all first), agents, then planner order."""
    order = {name: i for i, name in enumerate(PLANNERS)}
    maps = list(dict.fromkeys(row["map"] for row in rows))
    overall: dict[tuple, list[dict]] = {}
    each: dict[tuple, list[dict]] = {}
    for row in rows:
        overall.setdefault((ALL_MAPS, row["agents"], row["planner"]), []).append(row)
        each.setdefault((row["map"], row["agents"], row["planner"]), []).append(row)

    def sort_key(item):
        (map_name, agents, planner), _ = item
        return (-1 if map_name == ALL_MAPS else maps.index(map_name), agents,
                order.get(planner, 99))

    return [_group(group, key) for key, group in sorted([*overall.items(), *each.items()],
                                                        key=sort_key)]


def _number(value: float, digits: int) -> str:
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) \
        else f"{value:.{digits}f}"


def summary_markdown(summary: list[dict], rows: list[dict]) -> str:
    """Both summaries as Markdown tables: over all maps, then per map (with the reason of the
    first run not solved)."""
    head = ("| agents | planner | solved | success | SoC / LB | makespan | median time s |",
            "| ---: | --- | ---: | ---: | ---: | ---: | ---: |")

    def cells(e):
        return (f"{e['solved']}/{e['runs']} | {100 * e['success_rate']:.0f}% | "
                f"{_number(e['mean_ratio'], 3)} | {_number(e['mean_makespan'], 1)} | "
                f"{e['median_seconds']:.3f}")

    overall = [*head] + [f"| {e['agents']} | {LABELS[e['planner']]} | {cells(e)} |"
                         for e in summary if e["map"] == ALL_MAPS]
    reasons = {}
    for row in rows:
        if not row["solved"]:
            reasons.setdefault((row["map"], row["agents"], row["planner"]), row["reason"])
    per_map = ["| map | agents | planner | solved | success | SoC / LB | makespan | "
               "median time s | first reason not solved |",
               "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | --- |"]
    for e in summary:
        if e["map"] == ALL_MAPS:
            continue
        reason = reasons.get((e["map"], e["agents"], e["planner"]), "").replace("|", "\\|")
        per_map.append(f"| {e['map']} | {e['agents']} | {LABELS[e['planner']]} | {cells(e)} | "
                       f"{reason} |")
    errors = sum(e["errors"] for e in summary if e["map"] == ALL_MAPS)
    sections = [("Over all maps", overall), ("Per map", per_map)]
    if errors:
        sections.append(("Runs that raised", [
            f"{errors} runs raised an exception (recorded as not solved; the `error` column of "
            "`runs.csv`, the reason says which)."]))
    return provenance.join_sections(sections)


def format_summary(summary: list[dict]) -> str:
    """The over-all-maps summary as a fixed-width text table."""
    fmt = "{:>6} {:<24} {:>8} {:>8} {:>9} {:>9} {:>10}"
    lines = [fmt.format("agents", "planner", "solved", "success", "SoC/LB", "makespan",
                        "median s")]
    for e in summary:
        if e["map"] == ALL_MAPS:
            lines.append(fmt.format(e["agents"], LABELS[e["planner"]],
                                    f"{e['solved']}/{e['runs']}",
                                    f"{100 * e['success_rate']:.0f}%",
                                    _number(e["mean_ratio"], 3),
                                    _number(e["mean_makespan"], 1),
                                    f"{e['median_seconds']:.3f}"))
    return "\n".join(lines)


def plot_summary(summary: list[dict], path) -> None:
    """Three panels against the number of agents, one line per planner, over all maps: success
    rate, mean SoC / lower bound over the solved runs, median time. Saved as PNG, atomically."""
    panels = (("success_rate", "success rate"), ("mean_ratio", "mean SoC / lower bound (solved)"),
              ("median_seconds", "median time (s)"))
    overall = [e for e in summary if e["map"] == ALL_MAPS]
    counts = sorted({e["agents"] for e in overall})
    fig = Figure(figsize=(15, 4.5), layout="constrained")
    axes = fig.subplots(1, len(panels))
    for ax, (metric, title) in zip(axes, panels):
        for planner, marker, style in zip(PLANNERS, "osD^v", ("-", "-", "--", ":", "-")):
            entries = sorted((e for e in overall if e["planner"] == planner),
                             key=lambda e: e["agents"])
            if entries:  # markers and dashes tell apart the lines that coincide
                ax.plot([e["agents"] for e in entries], [e[metric] for e in entries],
                        marker=marker, markersize=5, linestyle=style, label=LABELS[planner],
                        alpha=0.85)
        ax.set_xscale("log")
        ax.set_xticks(counts, [str(c) for c in counts])
        ax.minorticks_off()
        ax.set_title(title)
        ax.set_xlabel("agents")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylim(-0.05, 1.05)
    axes[2].set_yscale("log")
    axes[0].legend()
    maps = list(dict.fromkeys(e["map"] for e in summary if e["map"] != ALL_MAPS))
    fig.suptitle(f"MAPF planners on {len(maps)} Moving AI map{'s' * (len(maps) > 1)} "
                 f"({', '.join(maps)})")
    with atomic_path(path) as temporary:
        fig.savefig(temporary, format="png", dpi=120)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--maps", type=parse_maps, default=list(MAPS),
                        help="comma list of MAPF map names or 'all' (default all: "
                             + ", ".join(MAPS) + ")")
    parser.add_argument("--agents", type=parse_agents, default=list(AGENTS),
                        help="comma list of agent counts (default 5,10,20,50,100)")
    parser.add_argument("--seeds", type=int, default=5,
                        help="runs of the random priority order, seeds 0.. (default 5)")
    parser.add_argument("--cbs-time-limit", type=float, default=30.0,
                        help="CBS's seconds per instance (default 30)")
    parser.add_argument("--data", type=Path, default=movingai_folder(),
                        help="the folder of the MAPF .map and .scen files (default "
                             "$JAXSWARM_MOVINGAI/mapf, else ../shared/benchdata/movingai/mapf)")
    add_out_argument(parser, "mapf_study")
    args = parser.parse_args(argv)
    check_counts(parser, args, "seeds")
    if args.cbs_time_limit <= 0:
        parser.error("--cbs-time-limit must be positive")
    for name in args.maps:
        for path in (args.data / f"{name}.map", args.data / SCENARIO.format(map=name)):
            if not path.is_file():
                parser.error(f"no {path} (see --data)")

    record = provenance.begin(__file__, argv)
    instances = len(args.maps) * len(args.agents)
    print(f"MAPF study: {len(args.maps)} maps x agents {args.agents}, {args.seeds} random "
          f"orders, CBS limit {args.cbs_time_limit:g} s -> {args.out}")
    print(f"at most about {instances * args.cbs_time_limit / 60:.1f} min of CBS "
          f"({instances} instances), plus the report's repairs (up to ~20 s an instance at "
          "100 agents)")

    began = time.perf_counter()
    rows = run_study(args.maps, args.agents, args.seeds, args.cbs_time_limit, args.data)
    summary = summarise(rows)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args))
    write_csv(args.out / "runs.csv", rows, RUN_COLUMNS)
    write_csv(args.out / "summary.csv", summary, SUMMARY_COLUMNS)
    plot_summary(summary, args.out / "mapf_study.png")
    record.publish(args.out, summary_markdown(summary, rows))

    print("\n" + format_summary(summary))
    print(f"\n{len(rows)} runs in {time.perf_counter() - began:.0f} s; every solved plan "
          f"passed validate. Wrote {args.out / 'runs.csv'}, {args.out / 'summary.csv'}, "
          f"{args.out / 'mapf_study.png'}, {args.out / 'table.md'}")
    errors = sum(bool(row["error"]) for row in rows)
    if errors:  # a planner that raises is a bug: the files are written, the run fails
        print(f"\nERROR: {errors} runs raised an exception (see the error and reason columns "
              "of runs.csv)", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
