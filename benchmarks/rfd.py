"""Wall time of ``rfd_graded`` (ours) to solve each paper map, beside the RFD paper's RFD* times.

Each map is solved by ``rfd_graded`` once per seed (``--seeds``, default 20): at most 100
iterations, and a run stops after ``--patience`` iterations without improvement (default 30) or when every drop
follows the same path. Runs are jitted once per map (compile excluded) and timed one by one; the
script prints the median wall time per run next to the paper's RFD* time (C#, Intel i7-3770, one
drop at a time), the speed-up, how many seeds reached the optimum (relative gap < 1e-4), the
drops' moves per second of wall time (all iterations, settling and carving included) and the
share of the walker's lane-steps that were moves (``busy``).

Shared machines are noisy: with ``--repeats R`` the seeds of each map are timed R times over and
the script prints the median of the R medians and their range. The runs themselves are
deterministic, so a repeat whose paths differ from the first stops the script.

XLA:CPU runs each run on ``--threads`` intra-op threads (default 1; see :mod:`jaxswarm.runtime.cpu`: a
run is thousands of tiny kernels in a row, and a second thread mostly adds hand-offs between the
cores).

Run from the repository root::

    python benchmarks/rfd.py
    python benchmarks/rfd.py --maps mosaic100,alley100,maze100 --seeds 5
    python benchmarks/rfd.py --maps maze100 --repeats 5 --threads 2
"""
from __future__ import annotations

import argparse
import importlib.util
import os
import platform
import statistics
from pathlib import Path

import jax

from jaxswarm.maps.paper import PAPER_TABLE1_MS, paper_map_names
from jaxswarm.runtime.cpu import configure
from jaxswarm.studies.problems import named_problem


def _rfd_static():
    path = Path(__file__).resolve().parents[1] / "sweeps" / "rfd_static.py"
    spec = importlib.util.spec_from_file_location("rfd_static", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", default="all", help="comma-separated paper maps, or all")
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--patience", type=int, default=30)
    parser.add_argument("--agents", type=int, default=256)
    parser.add_argument("--threads", type=int, default=1,
                        help="XLA:CPU intra-op threads (jaxswarm.runtime.cpu.configure)")
    parser.add_argument("--repeats", type=int, default=1,
                        help="time each map's seeds this many times (median and range)")
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    # Before JAX's first computation.
    try:
        configure(threads=args.threads)
    except ValueError as error:
        parser.error(str(error))
    try:
        maps = paper_map_names(args.maps)
    except ValueError as error:
        parser.error(f"--maps: {error}")

    paper_ms = PAPER_TABLE1_MS["RFD*"]  # the paper's Table 1, RFD* time [ms], static
    run_algorithm = _rfd_static().run_algorithm
    print(f"machine: {platform.platform()} | {os.cpu_count()} CPUs | jax {jax.__version__} "
          f"({jax.default_backend()}, {args.threads} XLA thread(s))")
    print(f"{'map':10} {'paper ms':>9} {'ours ms':>9} {'speed-up':>9} {'optimal':>8} "
          f"{'mean iterations':>16} {'range ms':>12} {'M moves/s':>9} {'busy':>5}")
    for name in maps:
        problem = named_problem(name)
        medians, first = [], None
        for _ in range(args.repeats):
            rows = run_algorithm(problem, "rfd_graded", args.seeds, iterations=100,
                                 patience=args.patience, num_agents=args.agents)
            medians.append(1e3 * statistics.median(r["seconds"] for r in rows))
            outcome = [(r["cost"], r["iterations"]) for r in rows]
            if first is not None and outcome != first:
                raise SystemExit(f"{name}: a repeat found other paths than the first run")
            first = outcome
        ours = statistics.median(medians)
        print(f"{name:10} {paper_ms[name]:>9.0f} {ours:>9.0f} "
              f"{paper_ms[name] / ours:>8.1f}x "
              f"{sum(r['success'] for r in rows):>5}/{len(rows):<2} "
              f"{statistics.mean(r['iterations'] for r in rows):>16.1f} "
              f"{min(medians):>5.0f}-{max(medians):<6.0f} "
              f"{sum(r['moves'] for r in rows) / sum(r['seconds'] for r in rows) / 1e6:>9.1f} "
              f"{sum(r['moves'] for r in rows) / sum(r['lane_steps'] for r in rows):>5.2f}",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
