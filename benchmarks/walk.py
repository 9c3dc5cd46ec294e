"""Moves per second of the walker with the rfd_graded and ACO* transition rules on maze100,
beside a scalar C loop of the same rule.

For each swarm (``--swarms``), each memory (``initial``: the swarm's first altitudes or pheromone;
``converged``: its memory after ``--converge`` iterations of a run, when most agents follow a
river) and each total agent count (``--layouts`` DROPSxSEEDS: 1,024 = 256 x 4 and 16,384 =
256 x 64 by default) the walks of every seed run under ``vmap`` (so all their agents share one
queue over the walker's lanes), jitted, after one warm-up call (compile excluded). Printed, the
median over ``--repeats`` runs:

(ACO* finds no path on maze100 in 30 iterations, so its pheromone stays uniform up to a
factor and both memories give the same walks.)

* ``moves``: moves agents made (one agent changing node is one move), and ``busy``: the share
  of the loop's lane-steps that were moves (the rest idled: an agent that stopped waits for its
  lane's next refill, and the last agents' lanes wait for the slowest),
* ``M moves/s``: moves / wall time,
* ``ref 1 / all``: the scalar reference's moves/s on one core and on all cores
  (``benchmarks/scalar/walk.c``, built here with ``cc -O3 -march=native -fopenmp``, agents
  shared out over threads; it fills a path buffer with -1 and writes each path's nodes into it,
  as the walker does), and ``share``: ours as a share of the reference on all cores. The
  reference draws the walker's uniforms, so it walks the same paths: ``same`` counts the agents
  whose paths are identical (a last-bit difference between C's ``expf`` and XLA's ``exp`` may
  send an agent elsewhere at a tie of cumulative weights).

Water drops (``iwd``) change their soil at every step through the walker's hook, so the table
is not fixed and the scalar reference does not apply: a second table times IWD's walks (soil at
its start) beside ACO*'s (pheromone at its start) on the same map and layouts, and prints IWD's
moves per second as a share of ACO*'s (``iwd / aco``: what the hook costs).

Run from the repository root::

    python benchmarks/walk.py
    python benchmarks/walk.py --layouts 256x1,256x16 --repeats 3 --swarms rfd_graded
"""
from __future__ import annotations

import argparse
import ctypes
import functools
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import aco, make, make_task, rfd, run
from jaxswarm.swarm.iwd.soil import SOIL, goal_log_desirability
from jaxswarm.swarm.walking import edge_table, step_budget, walk
from jaxswarm.world.lattice import slot_offsets

SCALAR_SOURCE = Path(__file__).parent / "scalar" / "walk.c"

TRANSITION_RULES = {
    "rfd_graded": (rfd.graded_transition, lambda state: state.altitude),
    "aco_star": (functools.partial(aco.transition_rule, goal_distance=True),
                 lambda state: state.pheromone),
}
"""The walks measured: each swarm's transition table of its memory, and its memory."""


def machine() -> str:
    return (f"{platform.platform()} | {os.cpu_count()} CPUs | python "
            f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()})")


def build_scalar(directory: str) -> ctypes.CDLL:
    """The scalar reference, compiled into ``directory``; exits naming the compiler's error."""
    library = Path(directory) / "walk.so"
    command = [os.environ.get("CC", "cc"), "-O3", "-march=native", "-fopenmp", "-shared",
               "-fPIC", str(SCALAR_SOURCE), "-o", str(library), "-lm"]
    try:
        subprocess.run(command, check=True, capture_output=True, text=True)
    except (OSError, subprocess.CalledProcessError) as error:
        detail = getattr(error, "stderr", "") or error
        sys.exit(f"cannot build the scalar reference with {' '.join(command)}: {detail}")
    scalar = ctypes.CDLL(str(library))
    pointer, i32, u32 = ctypes.c_void_p, ctypes.c_int32, ctypes.c_uint32
    scalar.walk_all.argtypes = [pointer, i32, i32, pointer, i32, i32, i32, i32, u32, u32,
                                pointer, pointer]
    scalar.walk_all.restype = ctypes.c_int64
    scalar.set_threads.argtypes = [i32]
    return scalar


def memories(swarm_name: str, graph, task, drops: int, converge: int) -> dict:
    """The swarm's memory at its start and after ``converge`` iterations of a run (key 0)."""
    swarm = make(swarm_name, num_agents=drops)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    later, _ = run(swarm, jax.random.key(0), graph, task, params, iterations=converge)
    _, memory = TRANSITION_RULES[swarm_name]
    return {"initial": memory(state), "converged": memory(later)}


def measure(scalar, swarm_name: str, graph, task, memory, drops: int, seeds: int,
            repeats: int) -> dict:
    params = make(swarm_name, num_agents=drops).default_params
    rule, _ = TRANSITION_RULES[swarm_name]
    table = rule(graph, task, memory, params)
    steps = step_budget(graph, None)

    @jax.jit
    def walks(keys):
        return jax.vmap(lambda key: walk(key, graph, table, task.start, task.goal,
                                         num_agents=drops, max_steps=steps))(keys)

    keys = jax.random.split(jax.random.key(1), seeds)
    jax.block_until_ready(walks(keys))  # warm-up
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        result = jax.block_until_ready(walks(keys))
        times.append(time.perf_counter() - began)
    seconds = statistics.median(times)
    moves = int(result.moves.sum())

    # The walker's per-walk seeds: two words drawn from each walk's key.
    words = np.asarray(jax.vmap(lambda key: jax.random.bits(key, (1, 2), jnp.uint32))(keys))
    flat_table = np.ascontiguousarray(np.asarray(table, np.float32))
    offsets = np.ascontiguousarray(np.asarray(slot_offsets(graph), np.int32))
    scalar_moves = np.zeros((seeds, drops), np.int32)
    paths = np.full((seeds, drops, steps + 1), -1, np.int32)

    def run_scalar(threads: int) -> float:
        scalar.set_threads(threads)
        began = time.perf_counter()
        paths.fill(-1)  # padded paths, as the walker returns them
        for s in range(seeds):
            scalar.walk_all(
                flat_table.ctypes.data, graph.num_nodes, graph.max_degree, offsets.ctypes.data,
                int(task.start), int(task.goal), drops, steps, int(words[s, 0, 0]),
                int(words[s, 0, 1]), scalar_moves[s].ctypes.data,
                paths[s].ctypes.data)
        return time.perf_counter() - began

    reference = {}
    for threads in (1, os.cpu_count()):
        wall = statistics.median(run_scalar(threads) for _ in range(repeats))
        reference[threads] = scalar_moves.sum() / wall
    same = int(np.all(paths == np.asarray(result.path), axis=-1).sum())
    return dict(agents=drops * seeds, seconds=seconds, moves=moves,
                busy=moves / int(result.lane_steps[0]), rate=moves / seconds,
                one_core=reference[1], all_cores=reference[os.cpu_count()], same=same)


def timed_walks(walks, keys, repeats: int) -> tuple[float, int]:
    """``(median seconds, moves)`` of ``walks(keys)`` over ``repeats`` runs after a warm-up."""
    jax.block_until_ready(walks(keys))
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        result = jax.block_until_ready(walks(keys))
        times.append(time.perf_counter() - began)
    return statistics.median(times), int(result.moves.sum())


def measure_drops(graph, task, drops: int, seeds: int, repeats: int) -> dict:
    """Moves per second of IWD's walks (the soil hook) and of ACO*'s, same keys and layout."""
    steps = step_budget(graph, None)
    keys = jax.random.split(jax.random.key(1), seeds)
    iwd_swarm, aco_swarm = make("iwd", num_agents=drops), make("aco_star", num_agents=drops)
    soil = iwd_swarm.init(jax.random.key(0), graph, task, iwd_swarm.default_params).soil
    drop_table = edge_table(graph, iwd_swarm.default_params.beta
                            * goal_log_desirability(graph, task.goal))
    aco_params = aco_swarm.default_params
    pheromone = aco_swarm.init(jax.random.key(0), graph, task, aco_params).pheromone
    ant_table = aco.transition_rule(graph, task, pheromone, aco_params, goal_distance=True)

    @jax.jit
    def drop_walks(keys):
        return jax.vmap(lambda key: walk(key, graph, drop_table, task.start, task.goal,
                                         num_agents=drops, max_steps=steps, hook=SOIL,
                                         memory=soil, hook_params=iwd_swarm.default_params))(keys)

    @jax.jit
    def ant_walks(keys):
        return jax.vmap(lambda key: walk(key, graph, ant_table, task.start, task.goal,
                                         num_agents=drops, max_steps=steps))(keys)

    rates = {}
    for name, walks in (("iwd", drop_walks), ("aco_star", ant_walks)):
        seconds, moves = timed_walks(walks, keys, repeats)
        rates[name] = (seconds, moves, moves / seconds)
    return rates


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="maze100")
    parser.add_argument("--swarms", default="rfd_graded,aco_star",
                        help=f"comma-separated, from {', '.join(TRANSITION_RULES)}")
    parser.add_argument("--layouts", default="256x4,256x64", help="comma-separated DROPSxSEEDS")
    parser.add_argument("--converge", type=int, default=30,
                        help="iterations run for the converged memory")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    chosen = paper_map(args.map)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    layouts = [tuple(int(part) for part in layout.split("x"))
               for layout in args.layouts.split(",")]
    print(f"machine: {machine()}")
    print(f"walks on {args.map}, median of {args.repeats} runs after a warm-up compile; "
          f"reference: {SCALAR_SOURCE.name} on 1 and {os.cpu_count()} cores")
    print(f"{'swarm':10} {'memory':9} {'agents':>7} {'ms':>8} {'moves':>9} {'busy':>5} "
          f"{'M moves/s':>9} {'ref 1 / all':>12} {'share':>6} {'same':>12}")
    with tempfile.TemporaryDirectory() as directory:
        scalar = build_scalar(directory)
        for swarm_name in args.swarms.split(","):
            states = memories(swarm_name, graph, task, layouts[0][0], args.converge)
            for memory_name, memory in states.items():
                for drops, seeds in layouts:
                    r = measure(scalar, swarm_name, graph, task, memory, drops, seeds,
                                args.repeats)
                    print(f"{swarm_name:10} {memory_name:9} {r['agents']:>7} "
                          f"{1e3 * r['seconds']:>8.1f} {r['moves']:>9} {r['busy']:>5.2f} "
                          f"{r['rate'] / 1e6:>9.1f} "
                          f"{r['one_core'] / 1e6:>5.1f} / {r['all_cores'] / 1e6:<5.1f} "
                          f"{r['rate'] / r['all_cores']:>6.2f} "
                          f"{r['same']:>6}/{r['agents']:<5}", flush=True)
    print(f"\nwater drops (iwd, soil hook) beside ACO* on {args.map}, from their initial memory")
    print(f"{'agents':>7} {'iwd ms':>8} {'moves':>9} {'M moves/s':>9} {'aco ms':>8} "
          f"{'moves':>9} {'M moves/s':>9} {'iwd / aco':>9}")
    for drops, seeds in layouts:
        r = measure_drops(graph, task, drops, seeds, args.repeats)
        (iwd_s, iwd_moves, iwd_rate), (aco_s, aco_moves, aco_rate) = r["iwd"], r["aco_star"]
        print(f"{drops * seeds:>7} {1e3 * iwd_s:>8.1f} {iwd_moves:>9} {iwd_rate / 1e6:>9.2f} "
              f"{1e3 * aco_s:>8.1f} {aco_moves:>9} {aco_rate / 1e6:>9.2f} "
              f"{iwd_rate / aco_rate:>9.2f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
