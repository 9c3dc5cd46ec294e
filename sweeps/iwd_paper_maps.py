"""Intelligent Water Drops (``iwd``, the IWD_PG paper's baseline) on the RFD paper's nine maps and
on Moving AI maps it was never tuned on, beside the optimum: its quality reported as it is, not
tuned, for each reading of when the drops change the soil.

Per map and variant, ``--seeds`` runs (``--movingai-seeds`` on a Moving AI map; keys split from key
0) of ``iwd`` with its standard params, ``--drops`` drops per iteration, at most ``--iterations``
iterations, stopped after ``--patience`` iterations without gain once a path was found (``--patience
0``: never); each run compiled first, then timed alone. The variants (``--variants``,
:data:`VARIANTS`): the paper's reading (only drops that arrive change the soil, after the walk),
every drop changing the soil as it walks, drops that back out of dead ends (ours), and HUD at 20
times the edge length. The Moving AI maps (``--movingai``, :data:`MOVINGAI_MAPS`; none with
``--movingai none``) are planned from the mid-length row of their even scenario file
(:func:`jaxswarm.studies.problems.scenario_problem`). Reported per map and variant: runs that found
a path and runs at the optimum (A*; relative gap below 1e-4, :mod:`jaxswarm.studies.success`), the
mean and best length and mean gap over the runs that found one, iterations, fitness calls (complete
paths evaluated: the IWD paper's measure of cost) and the median time.

Written to ``--out`` (default ``out/iwd_paper_maps``; ``make reproduce`` uses
``results/iwd_paper_maps``), each file atomically: ``runs.csv`` (one row per map, variant and
seed), ``table.md`` (the provenance, then the table) and ``provenance.json``.

Run from the repository root::

    python sweeps/iwd_paper_maps.py
    python sweeps/iwd_paper_maps.py --maps maze20,mosaic20 --seeds 3 --movingai none
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path
from typing import NamedTuple

from jaxswarm.exact import astar
from jaxswarm.maps.paper import paper_maps_argument
from jaxswarm.runtime.atomic import write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts
from jaxswarm.studies.problems import (Problem, movingai_folder, named_problem,
                                       scenario_problem)
from jaxswarm.studies.success import reaches_optimum, relative_gap
from jaxswarm.sweep.run_record import COLUMNS as REPLAY_COLUMNS
from jaxswarm.studies.timing import median_milliseconds, seed_keys, timed_runs
from jaxswarm.swarm import definition, make

COLUMNS = ("map", "variant", "seed", "optimum", "cost", "gap", "found", "optimal", "iterations",
           "evaluations", "seconds", *REPLAY_COLUMNS)
"""Columns of runs.csv (``evaluations``: complete paths evaluated, all iterations;
``run_record`` and ``fingerprint``: what ``jaxswarm replay`` needs to run the row again)."""
TITLE = "Intelligent Water Drops (the IWD_PG paper's baseline) on the RFD paper's maps"
"""Title of table.md."""
ABOUT = ("`iwd` is Shah-Hosseini's IWD with its standard values, as the IWD_PG paper uses it "
         "(eqs. 1-6): only the drops that reach the goal change the soil, after the walk (the "
         "paper: \"feasible solution removes some soil of graph and therefore guides next "
         "generation drops\"). `while_walking`: every drop changes the soil as it walks, stuck "
         "ones too. `backtrack` (ours): a stuck drop backs out of its dead end. `hud20`: HUD is "
         "20 times the edge length, so the soil a drop takes depends on the length. The goal "
         "desirability h(j) = 1 / d_j is ours (the paper gives no formula). The optimum is A*'s; "
         "the Moving AI rows use the mid-length row of each map's even scenario file.")
"""What the rows are (the paragraph under the provenance)."""


class Variant(NamedTuple):
    """A reading of IWD: its config options and the params it replaces."""

    config: dict
    params: dict


VARIANTS = {"paper": Variant({}, {}),
            "while_walking": Variant({"local_updates": "while_walking"}, {}),
            "backtrack": Variant({"backtrack": True}, {}),
            "hud20": Variant({}, {"hud_scale": 20.0})}
"""The rows of each map, by name."""
MOVINGAI_MAPS = ("den312d", "random-64-64-10", "room-64-64-8", "maze-128-128-10",
                 "warehouse-10-20-10-2-1", "ost003d")
"""Moving AI maps of 64 x 64 to 194 x 194 cells that no IWD setting was chosen on."""


def variants_argument(text: str) -> list[str]:
    """``"all"`` or a comma list of :data:`VARIANTS` names."""
    names = list(VARIANTS) if text.strip() == "all" else [n.strip() for n in text.split(",")]
    unknown = [n for n in names if n not in VARIANTS]
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown variant {unknown[0]!r}; choose from "
                                         f"{', '.join(VARIANTS)} or all")
    return names


def study_map(problem: Problem, variant: str, *, seeds: int, drops: int, iterations: int,
              patience: int | None) -> list[dict]:
    """The runs.csv rows of one problem and variant: ``iwd`` once per seed (keys split from key
    0), compiled first, each run timed alone."""
    chosen = VARIANTS[variant]
    swarm = make("iwd", num_agents=drops, **chosen.config)
    params = swarm.default_params._replace(**{
        name: type(getattr(swarm.default_params, name))(value)
        for name, value in chosen.params.items()})
    runs = timed_runs(swarm, seed_keys(seeds), problem.graph, problem.task, params,
                      iterations=iterations, patience=patience, entry=problem.entry)
    rows = []
    for seed, one in enumerate(runs):
        cost = float(swarm.best(one.state).cost)
        gap = relative_gap(cost, problem.optimum)
        rows.append(dict(map=problem.label, variant=variant, seed=seed, optimum=problem.optimum,
                         cost=cost, gap=gap, found=cost != float("inf"),
                         optimal=reaches_optimum(gap), iterations=int(one.trace.iterations),
                         evaluations=int(one.trace.evaluations.sum()), seconds=one.seconds,
                         **one.replay))
    return rows


def markdown(rows: list[dict], maps: list[str], args) -> str:
    """The Markdown body: the set-up, one line per map and variant, then the found counts per
    variant over the Moving AI maps."""
    patience = args.patience or "none"
    lines = [f"{args.seeds} seeds ({args.movingai_seeds} on a Moving AI map), {args.drops} drops "
             f"per iteration, at most {args.iterations} "
             f"iterations, patience {patience}. Length, gap: over the runs that found a path. "
             "Fitness calls: complete paths evaluated per run, mean.", "",
             "| map | variant | optimum | found | optimal | length: mean | length: best | "
             "gap: mean | iterations: mean | fitness calls: mean | time [ms]: median |",
             "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for name in maps:
        for variant in args.variants:
            runs = [r for r in rows if r["map"] == name and r["variant"] == variant]
            found = [r for r in runs if r["found"]]
            length = (f"{statistics.mean(r['cost'] for r in found):.2f} | "
                      f"{min(r['cost'] for r in found):.2f} | "
                      f"{100 * statistics.mean(r['gap'] for r in found):.1f} %"
                      if found else "- | - | -")
            lines.append(
                f"| {name} | {variant} | {runs[0]['optimum']:.2f} | {len(found)}/{len(runs)} | "
                f"{sum(r['optimal'] for r in runs)}/{len(runs)} | {length} | "
                f"{statistics.mean(r['iterations'] for r in runs):.1f} | "
                f"{statistics.mean(r['evaluations'] for r in runs):.0f} | "
                f"{median_milliseconds(r['seconds'] for r in runs):.1f} |")
    unseen = [r for r in rows if r["map"] in MOVINGAI_MAPS]
    if unseen:
        lines += ["", "On the Moving AI maps, runs that found a path: " + ", ".join(
            f"{variant} {sum(r['found'] for r in unseen if r['variant'] == variant)}/"
            f"{sum(r['variant'] == variant for r in unseen)}" for variant in args.variants)
            + "."]
    return "\n".join(lines) + "\n"


def problems(args) -> list[Problem]:
    """The paper maps' problems, then the Moving AI maps' (none when ``--movingai none``)."""
    chosen = [named_problem(name, planner=astar) for name in args.maps]
    if args.movingai.lower() != "none":
        folder = movingai_folder() if args.movingai == "default" else Path(args.movingai)
        chosen += [scenario_problem(folder, name, planner=astar) for name in MOVINGAI_MAPS]
    return chosen


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument, default="all")
    parser.add_argument("--variants", type=variants_argument, default="all",
                        help=f"comma list of {', '.join(VARIANTS)}, or all (default)")
    parser.add_argument("--movingai", default="default",
                        help="the folder of the Moving AI MAPF maps (default: "
                             "$JAXSWARM_MOVINGAI/mapf, else ../shared/benchdata/movingai/mapf), "
                             "or none")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--movingai-seeds", type=int, default=6,
                        help="seeds on each Moving AI map (default 6)")
    parser.add_argument("--drops", type=int, default=50)
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--patience", type=int, default=30, help="0: none")
    add_out_argument(parser, "iwd_paper_maps")
    args = parser.parse_args(argv)
    check_counts(parser, args, "seeds", "movingai_seeds", "drops", "iterations")
    if args.patience < 0:
        parser.error(f"--patience must be at least 0, got {args.patience}")
    try:
        chosen = problems(args)
    except ValueError as error:
        parser.error(str(error))
    record = provenance.begin(__file__, argv)
    rows = []
    for problem in chosen:
        began = time.perf_counter()
        seeds = args.movingai_seeds if problem.label in MOVINGAI_MAPS else args.seeds
        for variant in args.variants:
            rows += study_map(problem, variant, seeds=seeds, drops=args.drops,
                              iterations=args.iterations, patience=args.patience or None)
        print(f"{problem.label:24} {time.perf_counter() - began:.0f} s", flush=True)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args),
                  swarm=definition(make("iwd", num_agents=args.drops)))
    write_csv(args.out / "runs.csv", rows, COLUMNS)
    print("\n" + record.publish(args.out, markdown(rows, [p.label for p in chosen], args)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
