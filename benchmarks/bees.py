"""Bee evaluations per second of ``cabc``, one run at a time and a weight sweep in one program.

On each plane of ``--maps`` (default the bees paper's maps #1 and #2 as ours, 50 x 50, from
(3, 3) to (47, 47)), ``cabc`` with its default config (20 food sources, at most 200 vehicle
steps) runs 200 iterations at most (one iteration is one vehicle step: a colony of 8 cycles in
the sensor window; a run stops when the vehicle arrives). Printed per map:

* ``single``: one unbatched run, seed 0, the default params (w1, w2, w3 = 1.0, 0.2, 0.03): the
  median wall time of ``--repeats`` calls after a warm-up call that compiles (``warm-up s``:
  that call, compile and one run).
* ``sweep``: ``--grid`` W1xW2xW3 runs (default 10 x 10 x 10 = 1,000): w1 linear in [0.7, 1.2],
  w2 in [0, 0.3], w3 in [0, 0.1], the other params at their defaults, one seed per run
  (``jax.random.key(run index)``), all in one compiled program: ``jax.jit(jax.vmap(run))`` over
  the stacked params, or with ``--batch B`` groups of B runs under ``vmap`` one after another
  (``jax.lax.map(..., batch_size=B)``). The median wall time of ``--sweep-repeats`` calls (3: a
  call of 1,000 runs takes half a minute on 2 cores) after the program is compiled ahead of time
  (``warm-up s``: ``jax.jit(...).lower(...).compile()``; the paper planes have the same shapes,
  so the second map reuses the first's programs and its warm-ups are short).

``evaluations`` are the bees' guided-function evaluations that the runs' traces count (N at the
start of a step, N employed and up to N onlookers per cycle, the scouts): the useful work. Under
``vmap`` a ``while_loop`` runs until its slowest run, so a run that stopped (its vehicle arrived)
computes on and its results are dropped, and a ``cond`` computes both branches (the scouts are
evaluated in every cycle); neither is counted. ``busy`` is the share of the sweep loop's
iterations that belonged to a run still going (the runs' iterations over runs x the iterations
of their group's slowest run). ``ratio`` is the sweep's evaluations/s over the single run's,
``reached`` the share of runs whose vehicle arrived, ``peak RSS`` the process's peak resident
memory (``ru_maxrss``) after each part.

XLA:CPU runs on ``--threads`` intra-op threads (default 1, as in ``benchmarks/rfd.py``; see
:mod:`jaxswarm.runtime.cpu`: on 2 cores one thread was faster for both parts).

Run from the repository root::

    python benchmarks/bees.py
    python benchmarks/bees.py --quick
    python benchmarks/bees.py --maps map2 --batch 250 --threads 2
"""
from __future__ import annotations

import argparse
import os
import platform
import resource
import statistics
import time

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.maps.planes import PAPER_PLANES, paper_plane
from jaxswarm.runtime.cpu import configure, cpu_model
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.bees.inverse import weight_grid

MiB = 2 ** 20
ITERATIONS = 200
WEIGHT_RANGES = {"w1": (0.7, 1.2), "w2": (0.0, 0.3), "w3": (0.0, 0.1)}
"""The swept weights and their ranges (linear, ends included)."""


def machine() -> str:
    """Where the figures come from: platform, CPU model, cores, python, jax and its devices."""
    return (f"{platform.platform()} | {cpu_model()} | {os.cpu_count()} CPUs | python "
            f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()}: "
            f"{', '.join(str(device) for device in jax.devices())})")


def peak_rss() -> int:
    """The process's peak resident memory so far, in bytes (``ru_maxrss`` is KiB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def seconds(call) -> tuple[float, object]:
    """``(wall seconds, result)`` of ``call()``, blocked on."""
    began = time.perf_counter()
    result = jax.block_until_ready(call())
    return time.perf_counter() - began, result


def timed(call, repeats: int) -> tuple[float, object]:
    """``(median wall seconds, last result)`` of ``repeats`` calls of ``call()``."""
    times, result = [], None
    for _ in range(repeats):
        wall, result = seconds(call)
        times.append(wall)
    return statistics.median(times), result


def weight_params(default_params, counts: tuple[int, int, int]):
    """The default params with (w1, w2, w3) over the grid of ``counts`` values (w1 slowest)
    and every other param repeated: f32[runs] leaves."""
    grid = weight_grid(WEIGHT_RANGES.values(), counts)
    params = default_params._replace(**{name: np.full(len(grid), value, np.float32)
                                        for name, value in default_params._asdict().items()})
    return params._replace(**{name: grid[:, i] for i, name in enumerate(WEIGHT_RANGES)})


def make_sweep(swarm, batch: int | None):
    """``sweep(keys, params, plane, task)``: jitted runs of stacked keys and params, all under
    one ``vmap``, or with ``batch`` in vmapped groups of that many, one group after another."""
    def one(key, params, plane, task):
        return run(swarm, key, plane, task, params, iterations=ITERATIONS)

    @jax.jit
    def sweep(keys, params, plane, task):
        if batch is None:
            return jax.vmap(one, in_axes=(0, 0, None, None))(keys, params, plane, task)
        return jax.lax.map(lambda pair: one(*pair, plane, task), (keys, params),
                           batch_size=batch)

    return sweep


def measure(swarm, sweep, map_name: str, counts, batch: int | None, repeats: int,
            sweep_repeats: int) -> dict:
    """The single run and the sweep (``make_sweep``'s, ``batch`` its group size) on one map:
    times, evaluations, the share of runs that arrived, busy, and the peak memory after each."""
    chosen = paper_plane(map_name)
    plane = chosen.plane
    task = make_task(plane, chosen.start, chosen.goal)

    def single():
        return run(swarm, jax.random.key(0), plane, task, swarm.default_params,
                   iterations=ITERATIONS)

    warm_up, _ = seconds(single)
    wall, (state, trace) = timed(single, repeats)
    single_row = dict(runs=1, warm_up=warm_up, wall=wall,
                      evaluations=int(trace.evaluations.sum()),
                      reached=float(state.reached), busy=1.0, rss=peak_rss())

    params = weight_params(swarm.default_params, counts)
    swarm.check_params(params)
    runs = params.w1.shape[0]
    arguments = (jax.vmap(jax.random.key)(jnp.arange(runs)), params, plane, task)
    warm_up, compiled = seconds(lambda: sweep.lower(*arguments).compile())
    wall, (state, trace) = timed(lambda: compiled(*arguments), sweep_repeats)
    iterations = np.asarray(trace.iterations)
    # lax.map's groups are consecutive runs, the remainder last.
    group = runs if batch is None else min(batch, runs)
    slowest = np.concatenate([np.full(len(part), part.max())
                              for part in np.split(iterations, range(group, runs, group))])
    sweep_row = dict(runs=runs, warm_up=warm_up, wall=wall,
                     evaluations=int(trace.evaluations.sum()),
                     reached=float(np.mean(state.reached)),
                     busy=iterations.sum() / slowest.sum(), rss=peak_rss())
    return dict(single=single_row, sweep=sweep_row)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", default=",".join(PAPER_PLANES),
                        help=f"comma-separated, from {', '.join(PAPER_PLANES)}")
    parser.add_argument("--grid", default="10x10x10",
                        help="values of w1 x w2 x w3 in the sweep (runs: their product)")
    parser.add_argument("--batch", type=int, default=None,
                        help="runs per vmapped group of the sweep (default: all in one vmap)")
    parser.add_argument("--repeats", type=int, default=5, help="timed calls of the single run")
    parser.add_argument("--sweep-repeats", type=int, default=3, help="timed calls of the sweep")
    parser.add_argument("--threads", type=int, default=1,
                        help="XLA:CPU intra-op threads (jaxswarm.runtime.cpu.configure)")
    parser.add_argument("--quick", action="store_true",
                        help="a smoke test: a 5x5x4 grid (100 runs), 2 repeats of each part")
    args = parser.parse_args(argv)
    if args.quick:
        args.grid, args.repeats, args.sweep_repeats = "5x5x4", 2, 2
    try:
        counts = tuple(int(part) for part in args.grid.split("x"))
    except ValueError:
        counts = ()
    if len(counts) != 3 or min(counts) < 1:
        parser.error(f"--grid must be W1xW2xW3 with whole numbers >= 1, got {args.grid!r}")
    for name in ("batch", "repeats", "sweep_repeats"):
        value = getattr(args, name)
        if value is not None and value < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1, got {value}")
    maps = args.maps.split(",")
    unknown = [name for name in maps if name not in PAPER_PLANES]
    if unknown:
        parser.error(f"--maps: unknown {', '.join(unknown)}; known: {', '.join(PAPER_PLANES)}")
    try:
        configure(threads=args.threads)  # before JAX's first computation
    except ValueError as error:
        parser.error(str(error))

    swarm = make("cabc")
    sweep = make_sweep(swarm, args.batch)
    print(f"machine: {machine()}, {args.threads} XLA thread(s)")
    print(f"cabc ({swarm.config.num_agents} sources, {ITERATIONS} steps at most); median of "
          f"{args.repeats} single runs, {args.sweep_repeats} sweeps; sweep: w1 x w2 x w3 = "
          f"{' x '.join(map(str, counts))} values in "
          f"{', '.join(f'[{low}, {high}]' for low, high in WEIGHT_RANGES.values())}, "
          f"{'one vmap' if args.batch is None else f'vmapped groups of {args.batch}'}")
    print(f"{'map':5} {'part':6} {'runs':>5} {'warm-up s':>9} {'wall s':>8} {'evaluations':>12} "
          f"{'M eval/s':>8} {'ratio':>6} {'reached':>7} {'busy':>5} {'peak RSS MiB':>12}",
          flush=True)
    for map_name in maps:
        r = measure(swarm, sweep, map_name, counts, args.batch, args.repeats,
                    args.sweep_repeats)
        single_rate = r["single"]["evaluations"] / r["single"]["wall"]
        for part, row in r.items():
            rate = row["evaluations"] / row["wall"]
            ratio = f"{rate / single_rate:>6.1f}" if part == "sweep" else f"{'':>6}"
            print(f"{map_name:5} {part:6} {row['runs']:>5} {row['warm_up']:>9.2f} "
                  f"{row['wall']:>8.3f} {row['evaluations']:>12,} {rate / 1e6:>8.2f} {ratio} "
                  f"{row['reached']:>7.2f} {row['busy']:>5.2f} {row['rss'] / MiB:>12.0f}",
                  flush=True)
    print("evaluations: the useful ones, counted by the traces (under vmap a while_loop runs "
          "until its slowest run; busy: the share of its iterations that were useful)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
