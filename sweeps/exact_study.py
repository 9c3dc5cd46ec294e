"""Dijkstra vs A* vs bidirectional A* on random grids: the A*/bidirectional-A* report's experiment.

The report (shared/papers/004, section 4) generates 1000 random square grids per size, from 10 to
100 cells a side in steps of 5, with the start and goal in opposite corners and a guaranteed path,
diagonal moves allowed, and plots main-loop iterations, visited nodes and running time of
Dijkstra, A* and bidirectional A* against the grid size (mean and spread).

Here each grid is :func:`jaxswarm.maps.random.random_grid` (obstacles with probability
``--density``, then a random monotone staircase from (0, 0) to (size-1, size-1) is cleared) turned
into a :func:`jaxswarm.world.graph.grid_graph` (8-connected, diagonal sqrt 2, no corner cutting).
The seed of grid ``index`` of a given ``size`` is derived from ``(--seed, size, index)`` by numpy's
``SeedSequence``, so any row can be regenerated on its own. For every grid the report's three
planners of :mod:`jaxswarm.exact`, and balanced bidirectional A* in its own row, record, from their
``SearchStats``:

* ``iterations``: priority-queue pops (the compiled planners re-key queued nodes, so no stale
  entries are popped),
* ``expanded``: nodes expanded, the report's "visited nodes" (both directions for bidirectional A*),
* ``generated``: nodes pushed onto a queue,
* ``time_ms``: wall time of the search alone (the cached host adjacency is built outside it),
* ``cost``: the path length; all must agree (they are exact), else :class:`CostMismatch`.

Outputs (in ``--out``, default ``out/exact_study/``, each written atomically):

* ``runs.csv``: one row per (size, grid, planner),
* ``summary.csv``: per (size, planner) the mean and sample standard deviation (ddof=1) of
  iterations, expanded, generated and time_ms,
* ``exact_study.png``: three panels (iterations, visited nodes, time in ms against grid size), a
  mean line and a shaded +-1 std band per planner;
* ``table.md``: the provenance (:mod:`jaxswarm.studies.provenance`), then the summary as a
  Markdown table;
* ``provenance.json``: the provenance and the arguments.

``make reproduce`` writes them to ``results/exact_study/``.

The planners are compiled (numba): the full default run (19 sizes x 1000 grids, four planners)
took about 4 minutes on 2 cores; an estimate is printed first. ``--grids 20`` takes seconds.

Run from the repository root::

    python sweeps/exact_study.py --grids 20
    python sweeps/exact_study.py --sizes 10:50:10 --grids 100 --density 0.25 --out out/d25
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from typing import Callable

import numpy as np
from matplotlib.figure import Figure

from jaxswarm.exact import astar, balanced_bidirectional_astar, bidirectional_astar, dijkstra
from jaxswarm.maps.random import random_grid
from jaxswarm.runtime.atomic import atomic_path, write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts
from jaxswarm.world.graph import grid_graph


PLANNERS: dict[str, Callable] = {
    "dijkstra": dijkstra,
    "astar": astar,
    "bidirectional_astar": bidirectional_astar,
    "balanced_bidirectional_astar": balanced_bidirectional_astar,
}
"""The planners, in the order they run on every grid."""
RUN_COLUMNS = ("size", "grid", "seed", "density", "planner", "iterations", "expanded",
               "generated", "time_ms", "cost")
METRICS = ("iterations", "expanded", "generated", "time_ms")
SUMMARY_COLUMNS = ("size", "planner", "grids") + tuple(
    f"{metric}_{stat}" for metric in METRICS for stat in ("mean", "std"))
COST_RTOL = 1e-9
LABELS = {"dijkstra": "Dijkstra", "astar": "A*", "bidirectional_astar": "Bidirectional A*",
          "balanced_bidirectional_astar": "Balanced bidirectional A* (not the report's)"}
TITLE = "Dijkstra vs A* vs bidirectional A* on random grids (the A* report's study)"
"""Title of table.md."""
ABOUT = (
    "Rows: the report's three exact planners of `jaxswarm.exact` (Dijkstra, A*, bidirectional "
    "A*) and, in its own row, balanced bidirectional A* (Ikeda et al. 1994; published, not the "
    "report's, none of this project's own) on random 8-connected grids with a guaranteed "
    "corner-to-corner path. Per grid size and planner: the mean +- sample standard deviation "
    "over the grids of the main-loop iterations (queue pops), the expanded (visited) nodes, the "
    "generated (pushed) nodes and the search time; the planners' path costs agree on every "
    "grid.")
"""What the rows are (the paragraph under the provenance)."""


class CostMismatch(RuntimeError):
    """The exact planners disagree on a grid's shortest-path cost (a planner bug)."""


def parse_sizes(text: str) -> list[int]:
    """``"10:100:5"`` (start:stop:step, stop included) or ``"10,20,40"`` -> list of sizes."""
    if ":" in text:
        start, stop, step = (int(part) for part in text.split(":"))
        if step <= 0:
            raise ValueError(f"size step must be positive, got {step}")
        sizes = list(range(start, stop + 1, step))
    else:
        sizes = [int(part) for part in text.split(",")]
    if not sizes or min(sizes) < 2:
        raise ValueError(f"sizes must be a non-empty list of integers >= 2, got {text!r}")
    return sizes


def grid_seed(seed: int, size: int, index: int) -> int:
    """The seed of grid ``index`` of side ``size``: independent of which other grids are run."""
    return int(np.random.SeedSequence((seed, size, index)).generate_state(1)[0])


def run_grid(size: int, index: int, density: float, seed: int) -> list[dict]:
    """Run every planner on one random grid; one row per planner.

    Raises:
      CostMismatch: a planner found no path, or the costs differ (relative tolerance 1e-9).
    """
    this_seed = grid_seed(seed, size, index)
    task = random_grid(size, this_seed, density=density)
    graph = grid_graph(task.obstacles)
    rows = []
    for name, planner in PLANNERS.items():
        solution = planner(graph, task.start, task.goal)
        stats = solution.stats
        rows.append({
            "size": size, "grid": index, "seed": this_seed, "density": density, "planner": name,
            "iterations": stats.iterations, "expanded": stats.expanded,
            "generated": stats.generated, "time_ms": 1e3 * stats.wall_time,
            "cost": float(solution.cost),
        })
    costs = [row["cost"] for row in rows]
    if not all(math.isfinite(c) for c in costs) or not all(
            math.isclose(c, costs[0], rel_tol=COST_RTOL) for c in costs):
        found = {row["planner"]: row["cost"] for row in rows}
        raise CostMismatch(f"size {size}, grid {index} (seed {this_seed}, density {density}): "
                           f"exact planners disagree: {found}")
    return rows


def run_study(sizes, grids: int, density: float = 0.3, seed: int = 0, *,
              log: Callable[[str], None] | None = print) -> list[dict]:
    """Run the experiment; returns the tidy rows (one per size, grid and planner).

    Args:
      sizes: grid sides to test.
      grids: random grids per size.
      density: obstacle probability passed to ``random_grid``.
      seed: base seed (see :func:`grid_seed`).
      log: called with one progress line per size (None: silent).
    """
    if grids < 1:
        raise ValueError(f"grids must be at least 1, got {grids}")
    rows = []
    began = time.perf_counter()
    for done, size in enumerate(sizes, start=1):
        size_began = time.perf_counter()
        size_rows = [row for index in range(grids) for row in run_grid(size, index, density, seed)]
        rows += size_rows
        if log is not None:
            means = {name: np.mean([r["expanded"] for r in size_rows if r["planner"] == name])
                     for name in PLANNERS}
            log(f"[{done:>2}/{len(sizes)}] size {size:>3}: {grids} grids in "
                f"{time.perf_counter() - size_began:6.1f} s "
                f"(elapsed {time.perf_counter() - began:6.1f} s)"
                " | mean expanded " + ", ".join(f"{LABELS[n]} {m:.0f}" for n, m in means.items()))
    return rows


def estimate_seconds(sizes, grids: int, density: float, seed: int) -> float:
    """Rough wall time of :func:`run_study`, from timing grid 0 at the smallest and largest size.

    Each size is timed twice: the first grid of a size pays a one-off cost (JAX converting its
    first Graph of that shape), the second gives the per-grid cost. Per-grid time is modelled as
    ``a + b * size**2``. The one-off work done here is not repeated by the study itself.
    """
    def timed(size):
        began = time.perf_counter()
        run_grid(size, 0, density, seed)
        return time.perf_counter() - began

    small, large = min(sizes), max(sizes)
    first_small, per_small = timed(small), timed(small)
    first_large, per_large = ((timed(large), timed(large)) if large != small
                              else (first_small, per_small))
    one_off = max(0.0, (first_small - per_small + first_large - per_large) / 2)
    b = (per_large - per_small) / (large**2 - small**2) if large != small else 0.0
    b = max(b, 0.0)
    a = max(per_small - b * small**2, 0.0)
    return sum(one_off + grids * (a + b * size**2) for size in sizes)


def summarise(rows: list[dict]) -> list[dict]:
    """Per (size, planner): grid count, mean and sample std (ddof=1; NaN for one grid) of
    iterations, expanded, generated and time_ms. Sorted by size, then planner order."""
    groups: dict[tuple[int, str], list[dict]] = {}
    for row in rows:
        groups.setdefault((row["size"], row["planner"]), []).append(row)
    order = {name: i for i, name in enumerate(PLANNERS)}
    summary = []
    for (size, planner), group in sorted(groups.items(),
                                         key=lambda item: (item[0][0], order.get(item[0][1], 99))):
        entry = {"size": size, "planner": planner, "grids": len(group)}
        for metric in METRICS:
            values = np.array([row[metric] for row in group], dtype=float)
            entry[f"{metric}_mean"] = float(values.mean())
            entry[f"{metric}_std"] = float(values.std(ddof=1)) if len(values) > 1 else math.nan
        summary.append(entry)
    return summary


def plot_summary(summary: list[dict], path) -> None:
    """Three panels (iterations, visited nodes, time in ms vs grid size): mean line and a shaded
    +-1 std band per planner. Saved as PNG to ``path``, atomically."""
    panels = (("iterations", "main-loop iterations"), ("expanded", "visited (expanded) nodes"),
              ("time_ms", "time (ms)"))
    fig = Figure(figsize=(15, 4.5), layout="constrained")
    axes = fig.subplots(1, len(panels))
    for ax, (metric, title) in zip(axes, panels):
        for planner in PLANNERS:
            entries = [e for e in summary if e["planner"] == planner]
            if not entries:
                continue
            size = np.array([e["size"] for e in entries])
            mean = np.array([e[f"{metric}_mean"] for e in entries])
            std = np.nan_to_num(np.array([e[f"{metric}_std"] for e in entries]))
            (line,) = ax.plot(size, mean, marker="o", markersize=3, label=LABELS[planner])
            ax.fill_between(size, mean - std, mean + std, color=line.get_color(), alpha=0.2,
                            linewidth=0)
        ax.set_title(title)
        ax.set_xlabel("grid size (cells per side)")
        ax.grid(True, alpha=0.3)
    axes[0].legend()
    grids = sorted({e["grids"] for e in summary})
    fig.suptitle(f"Exact planners on random grids (mean +- 1 std over {'/'.join(map(str, grids))} "
                 "grids per size)")
    with atomic_path(path) as temporary:
        fig.savefig(temporary, format="png", dpi=120)


def format_summary(summary: list[dict]) -> str:
    """The summary as a fixed-width text table."""
    fmt = "{:>5} {:<20} {:>5} {:>17} {:>17} {:>17}"
    lines = [fmt.format("size", "planner", "grids", "iterations", "expanded", "time ms")]
    for e in summary:
        cells = [f"{e[f'{m}_mean']:.1f} +- {e[f'{m}_std']:.1f}" for m in ("iterations", "expanded")]
        cells.append(f"{e['time_ms_mean']:.3f} +- {e['time_ms_std']:.3f}")
        lines.append(fmt.format(e["size"], e["planner"], e["grids"], *cells))
    return "\n".join(lines)


def summary_markdown(summary: list[dict]) -> str:
    """The summary as a Markdown table (mean +- std per size and planner)."""
    lines = ["| size | planner | grids | iterations | expanded | generated | time ms |",
             "| ---: | --- | ---: | ---: | ---: | ---: | ---: |"]
    for e in summary:
        cells = [f"{e[f'{m}_mean']:.1f} +- {e[f'{m}_std']:.1f}"
                 for m in ("iterations", "expanded", "generated")]
        cells.append(f"{e['time_ms_mean']:.3f} +- {e['time_ms_std']:.3f}")
        lines.append(f"| {e['size']} | {LABELS[e['planner']]} | {e['grids']} | "
                     + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", type=parse_sizes, default=parse_sizes("10:100:5"),
                        help="grid sides, start:stop:step (stop included) or a comma list "
                             "(default 10:100:5)")
    parser.add_argument("--grids", type=int, default=1000,
                        help="random grids per size (default 1000)")
    parser.add_argument("--density", type=float, default=0.3,
                        help="obstacle probability before the path is cleared (default 0.3)")
    parser.add_argument("--seed", type=int, default=0, help="base seed (default 0)")
    add_out_argument(parser, "exact_study")
    args = parser.parse_args(argv)
    check_counts(parser, args, "grids")
    if not 0.0 <= args.density < 1.0:
        parser.error("--density must be in [0, 1)")

    record = provenance.begin(__file__, argv)
    sizes = args.sizes
    print(f"exact study: sizes {sizes[0]}..{sizes[-1]} ({len(sizes)} sizes) x {args.grids} grids, "
          f"density {args.density}, seed {args.seed} -> {args.out}")
    estimate = estimate_seconds(sizes, args.grids, args.density, args.seed)
    print(f"estimated run time: {estimate / 60:.1f} min ({estimate:.0f} s)")

    began = time.perf_counter()
    rows = run_study(sizes, args.grids, args.density, args.seed)
    summary = summarise(rows)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args))
    write_csv(args.out / "runs.csv", rows, RUN_COLUMNS)
    write_csv(args.out / "summary.csv", summary, SUMMARY_COLUMNS)
    plot_summary(summary, args.out / "exact_study.png")
    record.publish(args.out, summary_markdown(summary))

    print("\n" + format_summary(summary))
    print(f"\n{len(rows)} runs in {time.perf_counter() - began:.0f} s; costs of the planners "
          f"agree on every grid. Wrote {args.out / 'runs.csv'}, {args.out / 'summary.csv'}, "
          f"{args.out / 'exact_study.png'}, {args.out / 'table.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
