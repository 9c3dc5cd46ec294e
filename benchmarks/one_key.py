"""What "one key, one result" costs: moves/s and evaluations/s of every registered swarm beside
a baseline version of jaxswarm without it (:mod:`jaxswarm.runtime.arithmetic`: XLA capped at
AVX, an ``exp`` of IEEE operations, sums in a fixed order; walkers whose hook writes memory
walk every agent at once).

Each swarm runs a vmapped batch of ``--runs`` runs (keys 0 ..) of ``--iterations`` iterations
with ``--agents`` agents (the bees their default colony) on a Moving AI map it was never tuned
on (``--map``, the mid-length row of its even scenario file; the bees on the plane ``map1``).
Each measurement is a process of its own, after a warm-up run (compile excluded), the median of
``--repeats`` timed runs; moves and evaluations are the runs' own counts (their traces). With
``--baseline REV`` the same processes run on a checkout of git revision ``REV`` (a temporary
worktree), alternating with this tree's, ``--rounds`` times, and the ratio of the medians is
printed (the machine's load changes both alike).

Run from the repository root::

    python benchmarks/one_key.py --baseline 93396b1
    python benchmarks/one_key.py --swarms aco_star,iwd --rounds 1
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

MEASURE = """
import json, statistics, sys, time
import jax
import numpy as np
from jaxswarm.maps.planes import paper_plane
from jaxswarm.studies.problems import movingai_folder, scenario_problem
from jaxswarm.swarm import make, make_task
from jaxswarm.swarm.executor import run_batch
from jaxswarm.swarm.testing import batched_params

name, map_name, runs, iterations, agents, repeats = sys.argv[1:7]
runs, iterations, agents, repeats = int(runs), int(iterations), int(agents), int(repeats)
if name == "cabc":
    swarm, chosen = make(name), paper_plane("map1")
    world, task = chosen.plane, make_task(chosen.plane, chosen.start, chosen.goal)
else:
    swarm = make(name, num_agents=agents)
    problem = scenario_problem(movingai_folder(), map_name)
    world, task = problem.graph, problem.task
keys = jax.random.split(jax.random.key(0), runs)
params = batched_params(swarm.default_params, runs)
def once():
    return jax.block_until_ready(run_batch(swarm, keys, world, task, params,
                                           iterations=iterations))
_, trace = once()
seconds = []
for _ in range(repeats):
    began = time.perf_counter()
    once()
    seconds.append(time.perf_counter() - began)
print(json.dumps(dict(seconds=statistics.median(seconds),
                      moves=int(np.sum(np.asarray(trace.moves), dtype=np.int64)),
                      evaluations=int(np.sum(np.asarray(trace.evaluations), dtype=np.int64)))))
"""
"""One measurement, in a process of its own: argv ``name map runs iterations agents repeats``."""


def measure(tree: Path, args, name: str) -> dict:
    """One measurement of swarm ``name`` with the jaxswarm of ``tree``: seconds (median),
    moves and evaluations of the batch."""
    # A baseline checkout has no ../shared beside it: both read this tree's Moving AI folder.
    env = dict(os.environ, PYTHONPATH=str(tree), PJRT_NPROC=str(args.threads),
               JAXSWARM_MOVINGAI=os.environ.get(
                   "JAXSWARM_MOVINGAI", str(REPO.parent / "shared" / "benchdata" / "movingai")))
    done = subprocess.run([sys.executable, "-c", MEASURE, name, args.map, str(args.runs),
                           str(args.iterations), str(args.agents), str(args.repeats)],
                          capture_output=True, text=True, env=env, cwd=tree, check=False)
    if done.returncode != 0:
        raise SystemExit(f"{name} on {tree} failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def rates(results: list[dict]) -> tuple[float, float]:
    """(moves/s, evaluations/s) of the median time of ``results`` (the same runs each)."""
    seconds = statistics.median(r["seconds"] for r in results)
    return results[0]["moves"] / seconds, results[0]["evaluations"] / seconds


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--swarms", default="aco_star,ant_system,max_min_aco,"
                        "improved_max_min_aco,rfd,rfd_star,rfd_graded,iwd,iwd_pg,cabc")
    parser.add_argument("--map", default="random-64-64-10")
    parser.add_argument("--runs", type=int, default=64)
    parser.add_argument("--iterations", type=int, default=30)
    parser.add_argument("--agents", type=int, default=32)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--rounds", type=int, default=2, help="alternations with the baseline")
    parser.add_argument("--threads", type=int, default=1, help="XLA threads of each process")
    parser.add_argument("--baseline", help="git revision to compare with")
    args = parser.parse_args(argv)
    print(f"machine: {platform.platform()} | {os.cpu_count()} CPUs | load "
          f"{os.getloadavg()[0]:.1f} | {args.runs} runs x {args.iterations} iterations, "
          f"{args.agents} agents, on {args.map} (cabc: plane map1), {args.threads} thread(s)")
    with tempfile.TemporaryDirectory() as scratch:
        trees = {"this tree": REPO}
        if args.baseline:
            baseline = Path(scratch) / "baseline"
            subprocess.run(["git", "worktree", "add", "--detach", str(baseline), args.baseline],
                           cwd=REPO, check=True, capture_output=True)
            trees[args.baseline] = baseline
        try:
            report(trees, args)
        finally:
            if args.baseline:
                subprocess.run(["git", "worktree", "remove", "--force", str(baseline)],
                               cwd=REPO, check=False, capture_output=True)
    return 0


def report(trees: dict, args) -> None:
    """Measure every swarm on every tree, alternating, and print one row per swarm."""
    header = f"{'swarm':<22}" + "".join(f"{label + ' moves/s':>24}{'evals/s':>12}"
                                         for label in trees)
    print(header + (f"{'ratio':>8}" if len(trees) > 1 else ""))
    for name in args.swarms.split(","):
        results = {label: [] for label in trees}
        for _ in range(args.rounds):
            for label, tree in trees.items():
                results[label].append(measure(tree, args, name))
        figures = {label: rates(r) for label, r in results.items()}
        row = f"{name:<22}" + "".join(f"{m:>24,.0f}{e:>12,.1f}" for m, e in figures.values())
        if len(trees) > 1:
            mine, theirs = figures["this tree"], figures[args.baseline]
            work = 0 if mine[0] and theirs[0] else 1  # the bees make no moves: evaluations
            row += f"{mine[work] / theirs[work]:>8.2f}"
        print(row, flush=True)


if __name__ == "__main__":
    began = time.perf_counter()
    status = main()
    print(f"({time.perf_counter() - began:.0f} s)")
    raise SystemExit(status)
