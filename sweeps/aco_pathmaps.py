"""Ant System vs Max-Min ACO vs Improved Max-Min ACO on random thin-wall path maps (the set-up of
the Max-Min ACO paper's Table 1), beside the paper's Table 1.

For each map size (10x10, 20x20, 40x25 by default) one seeded random path map is generated
(:func:`jaxswarm.maps.random.random_path_map`), start in the top-left cell and goal in the
bottom-right one. Each algorithm runs with its default params ``--runs`` times (10 in the paper)
with populations of ``--ants`` ants (50, as in the paper), until convergence (every ant of a
population on one path, or no improvement for ``--patience`` populations) or ``--max-ants`` ants
in all. Reported per map and algorithm: the minimum and average best path length over the runs,
the average time per run (jitted once, compile excluded), the optimum from Dijkstra, the ratios
to it and to Ant System, and the paper's values with their ratios to its Ant System ("ACO").

The paper's maps are not published and its lengths are in pixels of its drawings, so only ratios
between algorithms compare, not lengths; its finding is that Improved Max-Min ACO finds shorter
paths and converges faster than the other two on the 10x10 and 20x20 maps.

Written to ``--out`` (default ``out/aco_pathmaps``; ``make reproduce`` uses
``results/aco_pathmaps``), each file atomically: ``results.csv`` (one row per map and algorithm,
ours and the paper's values), ``table.md`` (the provenance, then one table per map) and
``provenance.json``.

Run from the repository root::

    python sweeps/aco_pathmaps.py
    python sweeps/aco_pathmaps.py --sizes 10x10 --runs 3
"""
from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from jaxswarm.runtime.atomic import write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts
from jaxswarm.studies.problems import Problem, named_problem
from jaxswarm.studies.timing import seed_keys, timed_runs
from jaxswarm.swarm import definition, make

ALGORITHMS = {"Ant System": "ant_system", "Max-Min ACO": "max_min_aco",
              "Improved Max-Min ACO": "improved_max_min_aco"}
"""Row label -> registered swarm, in table order; the first is the baseline of the ratios."""
PARAMS = {"Ant System": {"beta": 1.0}}
"""Params a row changes from its swarm's defaults: the Max-Min ACO paper's basic "ACO" (after
Hsiao et al.) weighs the distance heuristic too, where the RFD paper's eq. 7 has ``beta = 0``."""
BASELINE = "Ant System"
"""The row every ratio "vs Ant System" divides by (the paper's "ACO")."""
PAPER_TABLE1: dict[str, dict[str, tuple[float, float, float]]] = {
    "10x10": {"Ant System": (351.1, 352.3, 14.6), "Max-Min ACO": (351.1, 352.3, 1.36),
              "Improved Max-Min ACO": (289.7, 297.9, 1.17)},
    "20x20": {"Ant System": (737.4, 823.9, 33.1), "Max-Min ACO": (737.4, 753.7, 8.27),
              "Improved Max-Min ACO": (636.0, 670.1, 5.05)},
    "40x25": {"Ant System": (1082.3, 1161.7, 52.7), "Max-Min ACO": (1127.1, 1154.2, 9.86),
              "Improved Max-Min ACO": (1098.8, 1153.7, 7.06)},
}
"""The Max-Min ACO paper's Table 1: map -> row -> (minimum length, average length, time per run
[s]), over 10 runs with populations of 50 ants; lengths in the paper's pixel units. The paper
calls Ant System "ACO"."""
COLUMNS = ("map", "algorithm", "optimum", "min_length", "mean_length", "min_ratio",
           "mean_ratio", "found", "runs", "mean_populations", "mean_seconds",
           "min_vs_ant_system", "mean_vs_ant_system", "seconds_vs_ant_system",
           "paper_min_length", "paper_mean_length", "paper_seconds",
           "paper_min_vs_ant_system", "paper_mean_vs_ant_system", "paper_seconds_vs_ant_system")
"""Columns of results.csv (``*_ratio``: to the optimum; the paper's columns are empty for a map
size the paper did not run)."""
TITLE = "Max-Min ACO paper, Table 1 (random path maps): ours beside the paper's"
"""Title of table.md."""
ABOUT = (
    "Rows: the Max-Min ACO paper's three algorithms, none of them ours: Ant System "
    "(`ant_system` with the edge-length heuristic weighted by beta = 1, the paper's \"ACO\" "
    "after Hsiao et al.), Max-Min ACO (`max_min_aco`) and Improved Max-Min ACO "
    "(`improved_max_min_aco`, the paper's Algorithm 1), the other two with their defaults. The "
    "paper's lengths are in its own pixel units on its own (unpublished) maps: compare the ratios "
    "between algorithms (\"vs AS\", to Ant System on the same map), not the lengths.")
"""What the rows are (the paragraph under the provenance)."""


def parse_sizes(text: str) -> list[tuple[int, int]]:
    """An argparse ``type``: ``"10x10,20x20"`` -> [(10, 10), (20, 20)] (width, height)."""
    sizes = []
    for part in text.split(","):
        width, _, height = part.partition("x")
        if not (width.isdigit() and height.isdigit()):
            raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, got {part!r}")
        sizes.append((int(width), int(height)))
    return sizes


def ratio(value: float, baseline: float) -> float:
    """``value / baseline``; NaN unless both are finite and the baseline is positive."""
    if math.isfinite(value) and math.isfinite(baseline) and baseline > 0:
        return value / baseline
    return math.nan


def run_algorithm(label: str, problem: Problem, *, seed: int, runs: int, ants: int,
                  max_ants: int, patience: int) -> dict:
    """Run the algorithm ``label`` ``runs`` times on ``problem`` (keys split from key
    ``seed``), compiled first, each run timed alone; its results.csv row without the ratios."""
    swarm = make(ALGORITHMS[label], num_agents=ants)
    params = swarm.default_params._replace(
        **{name: np.float32(value) for name, value in PARAMS.get(label, {}).items()})
    timed = timed_runs(swarm, seed_keys(runs, seed), problem.graph, problem.task, params,
                       iterations=max(max_ants // ants, 1), patience=patience)
    lengths = [float(swarm.best(one.state).cost) for one in timed]
    found = [length for length in lengths if math.isfinite(length)]
    mean = statistics.mean(found) if found else math.inf
    optimum = problem.optimum
    return dict(map=problem.label.removeprefix("pathmap"), algorithm=label, optimum=optimum,
                min_length=min(lengths), mean_length=mean, min_ratio=min(lengths) / optimum,
                mean_ratio=mean / optimum, found=len(found), runs=runs,
                mean_populations=statistics.mean(int(one.trace.iterations) for one in timed),
                mean_seconds=statistics.mean(one.seconds for one in timed))


def compare(width: int, height: int, *, seed: int, **options) -> list[dict]:
    """One row per algorithm on the random path map of ``width`` x ``height`` cells drawn by
    ``seed``, with the ratios to Ant System and the paper's values (``options``: those of
    :func:`run_algorithm`)."""
    problem = named_problem(f"pathmap{width}x{height}", seed=seed)
    return add_ratios([run_algorithm(label, problem, seed=seed, **options)
                       for label in ALGORITHMS])


def add_ratios(rows: list[dict]) -> list[dict]:
    """Add to one map's rows their ratios to the Ant System row and the paper's values with
    their ratios (empty where the paper did not run the map size); returns the rows."""
    baseline = next(row for row in rows if row["algorithm"] == BASELINE)
    paper = PAPER_TABLE1.get(rows[0]["map"])
    for row in rows:
        for ours, column in (("min_length", "min"), ("mean_length", "mean"),
                             ("mean_seconds", "seconds")):
            row[f"{column}_vs_ant_system"] = ratio(row[ours], baseline[ours])
        values = paper[row["algorithm"]] if paper else ("", "", "")
        row.update(paper_min_length=values[0], paper_mean_length=values[1],
                   paper_seconds=values[2])
        for index, column in enumerate(("min", "mean", "seconds")):
            row[f"paper_{column}_vs_ant_system"] = (
                values[index] / paper[BASELINE][index] if paper else "")
    return rows


def number(value, digits: int) -> str:
    """A table cell: ``value`` with ``digits`` decimals; "-" for an empty value (no paper
    counterpart), "n/a" for inf or NaN."""
    if value == "":
        return "-"
    return f"{value:.{digits}f}" if math.isfinite(value) else "n/a"


def map_table(rows: list[dict]) -> list[str]:
    """Markdown lines of one map's table: per algorithm a line of ours and one of the paper's."""
    first = rows[0]
    lines = [f"### {first['map']} (optimum {first['optimum']:.2f}, {first['runs']} runs)", "",
             "| algorithm | source | min length | avg length | min vs AS | avg vs AS "
             "| min / optimum | avg / optimum | found | populations | s per run | time vs AS |",
             "| --- | --- |" + " ---: |" * 10]
    for row in rows:
        ours = [number(row["min_length"], 2), number(row["mean_length"], 2),
                number(row["min_vs_ant_system"], 3), number(row["mean_vs_ant_system"], 3),
                number(row["min_ratio"], 3), number(row["mean_ratio"], 3),
                f"{row['found']}/{row['runs']}", f"{row['mean_populations']:.1f}",
                number(row["mean_seconds"], 3), number(row["seconds_vs_ant_system"], 3)]
        paper = [number(row["paper_min_length"], 1), number(row["paper_mean_length"], 1),
                 number(row["paper_min_vs_ant_system"], 3),
                 number(row["paper_mean_vs_ant_system"], 3), "-", "-", "-", "-",
                 number(row["paper_seconds"], 2), number(row["paper_seconds_vs_ant_system"], 3)]
        lines += [f"| {row['algorithm']} | ours | " + " | ".join(ours) + " |",
                  f"| {row['algorithm']} | paper | " + " | ".join(paper) + " |"]
    return lines


def table(rows: list[dict], *, ants: int, max_ants: int, patience: int, seed: int) -> str:
    """The Markdown body: the set-up, then one table per map."""
    lines = [f"Populations of {ants} ants, at most {max_ants} ants per run, stopped after "
             f"{patience} populations without gain; map seed {seed}. \"vs AS\": the ratio to "
             "Ant System on the same map (ours to ours, the paper's to the paper's); the paper's "
             "lengths are in its own pixel units, so compare ratios, not lengths.", ""]
    for name in dict.fromkeys(row["map"] for row in rows):
        lines += [*map_table([row for row in rows if row["map"] == name]), ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=parse_sizes, default="10x10,20x20,40x25",
                        help="WIDTHxHEIGHT list (default: the paper's 10x10,20x20,40x25)")
    parser.add_argument("--runs", type=int, default=10, help="runs per map and algorithm")
    parser.add_argument("--ants", type=int, default=50, help="ants per population")
    parser.add_argument("--max-ants", type=int, default=5000, help="ants per run at most")
    parser.add_argument("--patience", type=int, default=20, help="populations without gain")
    parser.add_argument("--seed", type=int, default=0, help="seed of the maps and the runs")
    add_out_argument(parser, "aco_pathmaps")
    args = parser.parse_args(argv)
    check_counts(parser, args, "runs", "ants", "max_ants", "patience")
    record = provenance.begin(__file__, argv)
    rows = []
    for width, height in args.sizes:
        began = time.perf_counter()
        rows += compare(width, height, seed=args.seed, runs=args.runs, ants=args.ants,
                        max_ants=args.max_ants, patience=args.patience)
        print(f"{width}x{height}: {time.perf_counter() - began:.0f} s", flush=True)
    swarms = {label: dict(definition(make(name, num_agents=args.ants)),
                          params=PARAMS.get(label, {}))
              for label, name in ALGORITHMS.items()}
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args), swarms=swarms)
    write_csv(args.out / "results.csv", rows, COLUMNS)
    markdown = table(rows, ants=args.ants, max_ants=args.max_ants, patience=args.patience,
                     seed=args.seed)
    record.publish(args.out, markdown)
    print("\n" + markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
