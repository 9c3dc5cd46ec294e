"""Throughput and memory of the batched sweep runner beside the same runs done one at a time.

An rfd_graded sweep of ``p_base`` x ``alpha`` (``--values`` x ``--values`` values: ``p_base``
geometric from 2 to 200, ``alpha`` linear from 1 to 20) x ``--seeds`` seeds on ``--map``
(default mosaic50, 8 x 8 x 20 = 1,280 runs of 100 iterations with 64 agents) is run by
:func:`jaxswarm.sweep.run_sweep` into a fresh temporary store, then the same runs are done one at
a time by :func:`jaxswarm.swarm.run` in a Python loop, in the same process. Printed:

* ``sweep``: one timed call of ``run_sweep`` (it takes minutes, so it is not repeated). Its
  compile time is the runner's own ``compiled ... in X s`` log line; the wall time and runs/s
  exclude it (they still include the map's optimum, the chunks' inputs and the Parquet writes).
  The sum of the chunks' compute times (the rows' ``chunk_seconds``) is printed beside it.
* ``loop``: ``run`` called per (params, seed) with ``jax.random.key(seed)`` and blocked on, after
  one warm-up call (params are traced, so the loop compiles once; that compile is printed and
  excluded). With ``--loop-runs N`` below the total only N runs, spread over the grid and the
  seeds, are timed and the loop's wall time is extrapolated to all runs; the output says so.
* the speed-up (loop wall / sweep wall, compile excluded on both sides), the process's peak
  resident memory after the sweep (``ru_maxrss``) and XLA's device memory stats when the backend
  has them (the CPU backend usually has none), and whether the goals hold: sweep >= 20x the loop,
  peak memory < 4 GiB.
* a correctness check: the sweep's cost equals the loop's cost (bit for bit, float32) for every
  run measured in both; the number of mismatches is printed.

Run from the repository root::

    python benchmarks/sweep.py
    python benchmarks/sweep.py --loop-runs 64
    python benchmarks/sweep.py --values 2 --seeds 2 --iterations 5 --agents 16 --loop-runs 4
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
from jaxswarm.swarm import make, make_task, run
from jaxswarm.sweep import run_sweep, spec_from_dict
from jaxswarm.sweep.spec import DEFAULT_CHUNK_SIZE, DEFAULT_VMAP_SIZE

GiB = 2 ** 30
MiB = 2 ** 20
GOAL_SPEEDUP = 20.0
GOAL_MEMORY = 4 * GiB


def machine() -> str:
    return (f"{platform.platform()} | {os.cpu_count()} CPUs | python "
            f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()}, "
            f"{len(jax.devices())} device(s))")


def sweep_document(args) -> dict:
    return {"sweep": {"name": "bench", "algorithm": "rfd_graded", "maps": [args.map],
                      "seeds": args.seeds, "iterations": args.iterations,
                      "chunk_size": args.chunk_size, "vmap_size": args.vmap_size},
            "config": {"num_agents": args.agents},
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

    def log(line: str):
        lines.append(line)
        print(f"  [run_sweep] {line}", flush=True)

    with tempfile.TemporaryDirectory(prefix="jaxswarm-bench-sweep-") as out:
        began = time.perf_counter()
        frame = run_sweep(spec, out, progress=False, log=log)
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
        return jax.block_until_ready((swarm.best(state).cost, trace.iterations))

    began = time.perf_counter()
    one(runs[0])  # warm-up: the loop's only compile
    compile_seconds = time.perf_counter() - began
    results = {}
    began = time.perf_counter()
    for r in runs:
        results[r] = one(r)
    wall = time.perf_counter() - began
    costs = {r: np.float32(cost) for r, (cost, _) in results.items()}
    iterations = [int(used) for _, used in results.values()]
    return dict(costs=costs, wall=wall, compile=compile_seconds, iterations=iterations)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="mosaic50", help="a paper map")
    parser.add_argument("--agents", type=int, default=64)
    parser.add_argument("--iterations", type=int, default=100)
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--values", type=int, default=8,
                        help="values per param (the grid is values x values)")
    parser.add_argument("--chunk-size", type=int, default=DEFAULT_CHUNK_SIZE,
                        help="runs per sweep chunk (default: the sweep spec's default)")
    parser.add_argument("--vmap-size", type=int, default=DEFAULT_VMAP_SIZE,
                        help="runs vmapped together (default: the sweep spec's default)")
    parser.add_argument("--loop-runs", type=int, default=None,
                        help="time only this many loop runs and extrapolate (default: all)")
    args = parser.parse_args(argv)
    spec = spec_from_dict(sweep_document(args))
    total = spec.num_runs
    combinations = len(spec.grid())

    print(f"machine: {machine()}")
    print(f"rfd_graded on {args.map}: p_base x alpha = {args.values} x {args.values} values x "
          f"{args.seeds} seeds = {total} runs, {args.iterations} iterations, {args.agents} agents, "
          f"chunks of {args.chunk_size}, vmapped {args.vmap_size} at a time")
    print("sweep: one timed run_sweep into a fresh store (single run, not repeated: too long)",
          flush=True)
    sweep = time_sweep(spec)
    sweep_wall = sweep["wall"] - sweep["compile"]

    runs = loop_runs(total, combinations, len(spec.seeds), args.loop_runs)
    measured = len(runs)
    extrapolated = measured < total
    print(f"loop: run() one at a time, {measured} of {total} runs after one warm-up call",
          flush=True)
    loop = time_loop(spec, args.map, runs)
    loop_wall = loop["wall"] * total / measured

    frame = sweep["frame"]
    sweep_costs = frame.set_index("run")["cost"]
    mismatches = [r for r in runs
                  if not np.array_equal(np.float32(sweep_costs.loc[r]), loop["costs"][r])]
    speedup = loop_wall / sweep_wall
    memory_ok = sweep["rss"] < GOAL_MEMORY

    print()
    print(f"{'mode':6} {'runs':>6} {'wall s':>10} {'runs/s':>9} {'compile s':>10}")
    print(f"{'sweep':6} {total:>6} {sweep_wall:>10.2f} {total / sweep_wall:>9.2f} "
          f"{sweep['compile']:>10.2f}")
    print(f"{'loop':6} {total:>6} {loop_wall:>10.2f} {total / loop_wall:>9.2f} "
          f"{loop['compile']:>10.2f}" + ("  (extrapolated)" if extrapolated else ""))
    print()
    print(f"sweep: run_sweep wall {sweep['wall']:.2f} s including {sweep['compile']:.2f} s "
          f"compile ({sweep['compiles']} compile(s)); chunks' compute alone "
          f"{sweep['chunk_seconds']:.2f} s ({total / sweep['chunk_seconds']:.2f} runs/s)")
    used = frame.groupby("chunk")["iterations"]
    print(f"iterations used: sweep mean {frame['iterations'].mean():.1f}, but a vmapped group "
          f"runs as long as its slowest run (max per chunk: "
          f"{', '.join(str(int(v)) for v in used.max())}); loop mean "
          f"{np.mean(loop['iterations']):.1f} over its {measured} runs")
    if extrapolated:
        print(f"loop: measured {measured} of {total} runs, extrapolated "
              f"({loop['wall']:.2f} s for {measured} runs, {loop['wall'] / measured:.3f} s/run)")
    else:
        print(f"loop: measured all {total} runs ({loop['wall'] / measured:.3f} s/run)")
    print(f"peak RSS after the sweep: {sweep['rss'] / MiB:.0f} MiB "
          f"({sweep['rss'] / GiB:.2f} GiB)")
    stats = sweep["device"]
    if stats:
        shown = {k: v for k, v in stats.items() if "bytes" in k}
        print("XLA device memory stats: " + ", ".join(
            f"{k} {v / MiB:.0f} MiB" for k, v in sorted(shown.items())))
    else:
        print("XLA device memory stats: not available on this backend")
    print(f"correctness: sweep cost == loop cost on {measured - len(mismatches)} of {measured} "
          f"runs measured in both; {len(mismatches)} mismatch(es)"
          + (f" (runs {mismatches[:10]}{' ...' if len(mismatches) > 10 else ''})"
             if mismatches else ""))
    print()
    print(f"speed-up sweep vs loop: {speedup:.2f}x "
          f"(goal >= {GOAL_SPEEDUP:.0f}x: {'met' if speedup >= GOAL_SPEEDUP else 'NOT met'}"
          f"{', loop extrapolated' if extrapolated else ''})")
    print(f"peak memory: {sweep['rss'] / GiB:.2f} GiB "
          f"(goal < 4 GiB: {'met' if memory_ok else 'NOT met'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
