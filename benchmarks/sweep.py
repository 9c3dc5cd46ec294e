"""Throughput and memory of the batched sweep runner beside the same runs done one at a time.

For each agent count of ``--agents`` (default 16 and 64: the small swarms of parameter studies),
an rfd_graded sweep of ``p_base`` x ``alpha`` (``--values`` x ``--values`` values: ``p_base``
geometric from 2 to 200, ``alpha`` linear from 1 to 20) x ``--seeds`` seeds on ``--map``
(default mosaic50, 8 x 8 x 20 = 1,280 runs of 100 iterations) is run by
:func:`jaxswarm.sweep.run_sweep` into a fresh temporary store, then the same runs are done one at
a time by :func:`jaxswarm.swarm.run` in a Python loop, in the same process. The CPU is split into
``--devices`` JAX devices (default: one per core, each with one XLA thread; see
:mod:`jaxswarm.runtime.cpu`), so the sweep runs one shard of each chunk per core. Both are done
by each of the walker's implementations of ``--implementations`` (default ``lanes,native``: the
XLA lanes, the reference, and the native kernels, :mod:`jaxswarm.swarm.walking.native`), named
in the swarm's config (``walker=WalkerOptions(implementation=...)``, which the sweep runner
builds its swarm with), one after the other in the same process. Printed per agent count and
implementation (``walker``), one row each:

* ``sweep``: one timed call of ``run_sweep`` (not repeated: it takes a while). Its compile time
  (``compile s``) is the runner's own ``compiled ... in X s`` log line (the persistent
  compilation cache is switched off, so every program is compiled); the wall time and runs/s
  exclude it (they still include the map's optimum, the chunks' inputs and the Parquet writes).
  Before it, a sweep of a quarter of the seeds is run, so that the peak resident memory
  (``ru_maxrss``) after each shows whether memory grows with the number of runs (the process's
  peak so far: a row's includes the rows before it).
* ``loop``: ``run`` called per (params, seed) with ``jax.random.key(seed)`` and blocked on, after
  one warm-up call (params are traced, so the loop compiles once; that compile is excluded), on
  the first device. With ``--loop-runs N`` below the total only N runs, spread over the grid and
  the seeds, are timed and the loop's wall time is extrapolated to all runs; the output says so.
* the speed-up (loop wall / sweep wall, compile excluded on both sides) against the goal (5x for
  16 agents, 1.5x for 64), the peak memory against 4 GiB, the moves per second of each (the
  agents' moves of all runs, counted by the runs' traces), and a correctness check (``same
  result``): the sweep's row of every run measured in both equals the loop's run, its cost (bit
  for bit, float32), its moves and its fingerprint (the whole final state and trace,
  :func:`jaxswarm.swarm.fingerprint.run_fingerprint`, taken after the timed loop). A run that
  differs is listed below the table with its seed and params. ``as lanes``: the runs whose
  sweep rows (cost, moves and fingerprint) equal the lanes' sweep's (``-`` on the lanes' row,
  or when ``lanes`` is not measured).

Run from the repository root::

    python benchmarks/sweep.py
    python benchmarks/sweep.py --agents 16 --loop-runs 64
    python benchmarks/sweep.py --values 2 --seeds 4 --iterations 5 --agents 16 --loop-runs 4
    python benchmarks/sweep.py --implementations native   # the native walker alone
"""
from __future__ import annotations

import argparse
import os
import platform
import re
import resource
import tempfile
import time

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.maps.paper import paper_map
from jaxswarm.runtime.cpu import configure
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.fingerprint import hex_fingerprint, run_fingerprint
from jaxswarm.sweep import run_sweep, spec_from_dict
from jaxswarm.swarm.walking.native import check_implementations
from jaxswarm.swarm.walking.options import IMPLEMENTATIONS, WalkerOptions
from jaxswarm.sweep.spec import DEFAULT_CHUNK_SIZE

GiB = 2 ** 30
MiB = 2 ** 20
GOAL_SPEEDUP = {16: 5.0, 64: 1.5}
GOAL_MEMORY = 4 * GiB


def machine() -> str:
    return (f"{platform.platform()} | {os.cpu_count()} CPUs | python "
            f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()}, "
            f"{len(jax.devices())} device(s))")


def sweep_document(args, agents: int, seeds: int, implementation: str) -> dict:
    """The sweep's document (as :func:`~jaxswarm.sweep.spec_from_dict` reads it): runs of
    ``agents`` agents, ``seeds`` seeds, walked by the walker's ``implementation``."""
    sweep = {"name": "bench", "algorithm": "rfd_graded", "maps": [args.map], "seeds": seeds,
             "iterations": args.iterations, "chunk_size": args.chunk_size}
    if args.vmap_size is not None:
        sweep["vmap_size"] = args.vmap_size
    return {"sweep": sweep,
            "config": {"num_agents": agents,
                       "walker": WalkerOptions(implementation=implementation)},
            "params": {"p_base": {"start": 2, "stop": 200, "num": args.values, "log": True},
                       "alpha": {"start": 1, "stop": 20, "num": args.values}}}


def peak_rss() -> int:
    """The process's peak resident memory so far, in bytes (``ru_maxrss`` is KiB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def device_memory() -> dict | None:
    try:
        return jax.devices()[0].memory_stats()
    except Exception:  # noqa: BLE001 - not every backend implements it
        return None


def time_sweep(spec) -> dict:
    lines = []

    with tempfile.TemporaryDirectory(prefix="jaxswarm-bench-sweep-") as out:
        began = time.perf_counter()
        frame = run_sweep(spec, out, progress=False, log=lines.append)
        wall = time.perf_counter() - began
    compiles = [float(m.group(1)) for line in lines
                for m in [re.search(r"compiled .* in ([\d.]+) s", line)] if m]
    compile_seconds = sum(compiles)
    frame = frame.sort_values("run").reset_index(drop=True)
    chunk_seconds = float(frame.groupby(["map", "chunk"])["chunk_seconds"].first().sum())
    return dict(frame=frame, wall=wall, compile=compile_seconds, compiles=len(compiles),
                chunk_seconds=chunk_seconds, rss=peak_rss(), device=device_memory())


def loop_runs(total: int, num_combinations: int, num_seeds: int, wanted: int | None) -> list[int]:
    """Run indices (combination-major, as the runner numbers them) for the loop: all of them,
    or ``wanted`` spread evenly over the combinations with the seeds cycling."""
    if wanted is None or wanted >= total:
        return list(range(total))
    chosen = {(i * num_combinations // wanted) * num_seeds + i % num_seeds for i in range(wanted)}
    return sorted(chosen)


def time_loop(spec, map_name: str, runs: list[int]) -> dict:
    swarm = make(spec.algorithm, **spec.config)
    chosen = paper_map(map_name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    grid, seeds = spec.grid(), spec.seeds

    def params_of(r: int):
        return swarm.default_params._replace(
            **{name: jnp.float32(value) for name, value in grid[r // len(seeds)].items()})

    def one(r: int):
        state, trace = run(swarm, jax.random.key(seeds[r % len(seeds)]), graph, task,
                           params_of(r), iterations=spec.iterations)
        return jax.block_until_ready((swarm.best(state).cost, jnp.sum(trace.moves), state,
                                      trace))

    began = time.perf_counter()
    one(runs[0])  # warm-up: the loop's only compile
    compile_seconds = time.perf_counter() - began
    results = {}
    began = time.perf_counter()
    for r in runs:
        results[r] = one(r)
    wall = time.perf_counter() - began
    fingerprint = jax.jit(run_fingerprint)
    return dict(costs={r: np.float32(result[0]) for r, result in results.items()},
                moves={r: int(result[1]) for r, result in results.items()},
                fingerprints={r: hex_fingerprint(fingerprint(*result[2:]))
                              for r, result in results.items()},
                wall=wall, compile=compile_seconds)


def measure(args, agents: int, implementation: str) -> dict:
    """The quarter sweep, the sweep and the loop for runs of ``agents`` agents walked by
    ``implementation``."""
    quarter = spec_from_dict(sweep_document(args, agents, max(1, args.seeds // 4),
                                            implementation))
    time_sweep(quarter)
    quarter_rss = peak_rss()
    spec = spec_from_dict(sweep_document(args, agents, args.seeds, implementation))
    total = spec.num_runs
    sweep = time_sweep(spec)
    runs = loop_runs(total, len(spec.grid()), len(spec.seeds), args.loop_runs)
    loop = time_loop(spec, args.map, runs)
    by_run = sweep["frame"].set_index("run")
    mismatches = [by_run.loc[r] for r in runs
                  if not np.array_equal(np.float32(by_run["cost"].loc[r]), loop["costs"][r])
                  or by_run["moves"].loc[r] != loop["moves"][r]
                  or by_run["fingerprint"].loc[r] != loop["fingerprints"][r]]
    sweep_wall = sweep["wall"] - sweep["compile"]
    loop_wall = loop["wall"] * total / len(runs)
    return dict(total=total, sweep_wall=sweep_wall, loop_wall=loop_wall,
                compile=sweep["compile"], measured=len(runs), mismatches=mismatches,
                quarter_rss=quarter_rss, rss=sweep["rss"],
                iterations=float(sweep["frame"]["iterations"].mean()),
                moves=int(sweep["frame"]["moves"].sum()),
                rows=by_run[["cost", "moves", "fingerprint"]])


def same_rows(rows, lanes) -> int:
    """How many runs have the same cost (bit for bit), moves and fingerprint in two sweeps'
    rows (indexed by run)."""
    return int(((rows["cost"].to_numpy(np.float32).view(np.uint32)
                 == lanes["cost"].to_numpy(np.float32).view(np.uint32))
                & (rows["moves"] == lanes["moves"]).to_numpy()
                & (rows["fingerprint"] == lanes["fingerprint"]).to_numpy()).sum())


def print_row(agents: int, implementation: str, r: dict, lanes) -> None:
    """One row of the table (see the module docstring); ``lanes``: the lanes' sweep rows of
    the same agents, or None (no ``as lanes`` count)."""
    speedup = r["loop_wall"] / r["sweep_wall"]
    goal = GOAL_SPEEDUP.get(agents)
    met = "" if goal is None else ("met" if speedup >= goal else "NOT met")
    as_lanes = "-" if lanes is None else f"{same_rows(r['rows'], lanes)}/{r['total']}"
    print(f"{agents:>6} {implementation:6} {r['total']:>6} {r['sweep_wall']:>8.2f} "
          f"{r['loop_wall']:>8.2f}{'*' if r['measured'] < r['total'] else ' '} {speedup:>8.2f}x "
          f"{met:>5} {r['compile']:>9.1f} {r['quarter_rss'] / GiB:>11.2f} "
          f"{r['rss'] / GiB:>8.2f} {r['measured'] - len(r['mismatches']):>5}/"
          f"{r['measured']:<5} {as_lanes:>11} {r['iterations']:>10.1f} "
          f"{r['moves'] / r['sweep_wall'] / 1e6:>12.2f} / "
          f"{r['moves'] / r['loop_wall'] / 1e6:<7.2f}", flush=True)
    for row in r["mismatches"]:
        print(f"  differs from the loop: run {row.name}, seed {int(row.seed)}, "
              f"p_base {float(row.p_base)!r}, alpha {float(row.alpha)!r}", flush=True)


def chosen_implementations(text: str, parser: argparse.ArgumentParser) -> list[str]:
    """The walker's implementations ``--implementations`` names, checked
    (:func:`~jaxswarm.swarm.walking.native.check_implementations`: the native kernels built or
    loaded, so that no compile time below includes that)."""
    try:
        return check_implementations(text.split(","))
    except ValueError as error:
        parser.error(f"--implementations: {error}")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="mosaic50", help="a paper map")
    parser.add_argument("--agents", default="16,64", help="comma-separated agents per run")
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--values", type=int, default=8,
                        help="values per param (the grid is values x values)")
    parser.add_argument("--chunk-size", type=int, default=DEFAULT_CHUNK_SIZE,
                        help="runs per sweep chunk (default: the sweep spec's default)")
    parser.add_argument("--vmap-size", type=int, default=None,
                        help="runs vmapped together (default: the runner's, from the agents)")
    parser.add_argument("--devices", type=int, default=os.cpu_count(),
                        help="JAX CPU devices, one XLA thread each (default: one per core)")
    parser.add_argument("--loop-runs", type=int, default=None,
                        help="time only this many loop runs and extrapolate (default: all)")
    parser.add_argument("--implementations", default=",".join(IMPLEMENTATIONS),
                        help=f"comma-separated walker implementations, from "
                             f"{', '.join(IMPLEMENTATIONS)}")
    args = parser.parse_args(argv)
    # Before JAX's first computation; compile seconds are measured, so no cached programs.
    jax.config.update("jax_enable_compilation_cache", False)
    configure(devices=args.devices, threads=args.devices)
    implementations = chosen_implementations(args.implementations, parser)

    print(f"machine: {machine()}")
    print(f"rfd_graded on {args.map}: p_base x alpha = {args.values} x {args.values} values x "
          f"{args.seeds} seeds, {args.iterations} iterations, chunks of {args.chunk_size}, "
          f"groups of {args.vmap_size or 'the runner default'}")
    print(f"{'agents':>6} {'walker':6} {'runs':>6} {'sweep s':>8} {'loop s':>8} "
          f"{'speed-up':>9} {'goal':>5} {'compile s':>9} {'RSS 1/4 GiB':>11} {'RSS GiB':>8} "
          f"{'same result':>11} {'as lanes':>11} {'iterations':>10} "
          f"{'M moves/s sweep / loop':>22}", flush=True)
    for agents in (int(part) for part in args.agents.split(",")):
        lanes = None
        for implementation in implementations:
            r = measure(args, agents, implementation)
            print_row(agents, implementation, r, None if implementation == "lanes" else lanes)
            lanes = r["rows"] if implementation == "lanes" else lanes
    print("* loop extrapolated from --loop-runs runs" if args.loop_runs else "")
    print(f"goals: speed-up {', '.join(f'{v}x at {k} agents' for k, v in GOAL_SPEEDUP.items())}; "
          f"peak memory below {GOAL_MEMORY / GiB:.0f} GiB and flat in the number of runs")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
