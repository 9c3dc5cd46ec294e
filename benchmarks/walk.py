"""Throughput and memory of the lockstep walker with the rfd_graded and ACO* transition rules, on
maze100.

For each swarm (``--swarms``, default rfd_graded and ACO*) and each total agent count (agents x
seeds: 64 = 64 x 1, 1,024 = 256 x 4, 16,384 = 256 x 64 by default) one walk per seed is run under
``vmap`` from the swarm's initial memory (flat altitudes, uniform pheromone), jitted, after one
warm-up call (compile excluded). Printed per configuration, as the median over ``--repeats``
runs:

* ``lockstep steps``: iterations of the walk's ``while_loop`` (under ``vmap`` every lane runs
  until the slowest lane's agents have all stopped),
* ``agent-steps/s``: total agents x lockstep steps / wall time (the rate at which the batch
  steps; the last steps of a walk run on a compacted batch once few agents still walk),
* ``moves/s``: moves actually made by agents / wall time (agents that stopped early idle),
* ``peak MiB``: XLA's buffer estimate for the compiled walk (arguments + outputs + temporaries),
  and the process's peak resident memory so far.

Run from the repository root::

    python benchmarks/walk.py
    python benchmarks/walk.py --layouts 256x1,256x16 --repeats 3
"""
from __future__ import annotations

import argparse
import functools
import os
import platform
import resource
import statistics
import time

import jax
import jax.numpy as jnp

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import make, make_task
from jaxswarm.swarm import aco, rfd
from jaxswarm.swarm.walking import step_budget, walk

MiB = 2 ** 20


def machine() -> str:
    return (f"{platform.platform()} | {os.cpu_count()} CPUs | python "
            f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()})")


TRANSITION_RULES = {
    "rfd_graded": rfd.graded_transition,
    "aco_star": functools.partial(aco.transition_rule, goal_distance=True),
}
"""The walks measured: each swarm's transition table of its memory."""


def make_walks(swarm_name: str, map_name: str, drops: int, seeds: int):
    """A jitted function keys -> Walk (vmapped over ``seeds`` keys) and its inputs."""
    chosen = paper_map(map_name)
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make(swarm_name, num_agents=drops)
    params = swarm.default_params
    steps = step_budget(graph, swarm.config.max_steps)
    rule = TRANSITION_RULES[swarm_name]

    def one(key):
        state = swarm.init(key, graph, task, params)
        memory = state.altitude if swarm_name == "rfd_graded" else state.pheromone
        table = rule(graph, task, memory, params)
        return walk(key, graph, table, task.start, task.goal, num_agents=drops, max_steps=steps)

    walks = jax.jit(jax.vmap(one))
    keys = jax.random.split(jax.random.key(0), seeds)
    return walks, keys


def measure(swarm_name: str, map_name: str, drops: int, seeds: int, repeats: int) -> dict:
    walks, keys = make_walks(swarm_name, map_name, drops, seeds)
    compiled = walks.lower(keys).compile()
    memory = compiled.memory_analysis()
    buffers = (memory.argument_size_in_bytes + memory.output_size_in_bytes
               + memory.temp_size_in_bytes) if memory is not None else float("nan")
    jax.block_until_ready(walks(keys))  # warm-up
    times, steps, moves = [], [], []
    for repeat in range(repeats):
        fresh = jax.random.split(jax.random.key(repeat + 1), seeds)
        began = time.perf_counter()
        result = jax.block_until_ready(walks(fresh))
        times.append(time.perf_counter() - began)
        steps.append(int(jnp.max(result.steps)))
        moves.append(int(jnp.sum(result.slots >= 0)))
    seconds = statistics.median(times)
    agents = drops * seeds
    return dict(agents=agents, drops=drops, seeds=seeds, seconds=seconds,
                steps=statistics.median(steps),
                agent_steps=agents * statistics.median(steps) / seconds,
                moves=statistics.median(moves) / seconds, buffers=buffers / MiB,
                rss=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--map", default="maze100")
    parser.add_argument("--swarms", default="rfd_graded,aco_star",
                        help=f"comma-separated, from {', '.join(TRANSITION_RULES)}")
    parser.add_argument("--layouts", default="64x1,256x4,256x64",
                        help="comma-separated DROPSxSEEDS")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    print(f"machine: {machine()}")
    print(f"walks on {args.map} from the initial memory, median of {args.repeats} runs "
          "after a warm-up compile")
    print(f"{'swarm':9} {'agents':>7} {'per x seeds':>12} {'ms':>9} {'lockstep steps':>15} "
          f"{'agent-steps/s':>14} {'moves/s':>11} {'XLA MiB':>8} {'peak RSS MiB':>13}")
    for swarm_name in args.swarms.split(","):
        for layout in args.layouts.split(","):
            drops, seeds = (int(part) for part in layout.split("x"))
            r = measure(swarm_name, args.map, drops, seeds, args.repeats)
            print(f"{swarm_name:9} {r['agents']:>7} {f'{drops} x {seeds}':>12} "
                  f"{1e3 * r['seconds']:>9.1f} {r['steps']:>15.0f} "
                  f"{r['agent_steps'] / 1e6:>12.1f} M {r['moves'] / 1e6:>9.1f} M "
                  f"{r['buffers']:>8.0f} {r['rss']:>13.0f}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
