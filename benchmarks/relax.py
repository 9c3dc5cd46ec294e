"""Time of the two relaxations to a fixpoint: the batched distance field and rfd_graded's settling.

Both run Jacobi sweeps over each node's cheapest neighbour (:func:`jaxswarm.world.relax.relax`):

* ``distance_field``: the distance from every node to the goal of each paper map (``--maps``),
  the optimum each sweep row carries;
* ``settle``: rfd_graded's sediment settling on one realistic iteration of maze100: the altitudes
  after ``--iterations`` iterations of rfd_graded (seed 1), plus the sediment the drops of one more
  walk leave where they did not arrive, settled until no filled node is a pit.

Each is jitted, called once to compile, then timed ``--repeats`` times; the median is printed.

Run from the repository root::

    python benchmarks/relax.py
    python benchmarks/relax.py --maps maze100 --repeats 50
"""
from __future__ import annotations

import argparse
import os
import platform
import statistics
import time

import jax
import jax.numpy as jnp

from jaxswarm.exact import distance_field
from jaxswarm.maps.paper import paper_map, paper_maps_argument
from jaxswarm.swarm import make, make_task, rfd, run
from jaxswarm.swarm.walking import step_budget, visited_nodes, walk
from jaxswarm.world.paths import node_index


def median_ms(function, *args, repeats: int) -> float:
    """Median wall time [ms] of ``function(*args)`` over ``repeats`` calls, after a warm-up."""
    jax.block_until_ready(function(*args))
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        jax.block_until_ready(function(*args))
        times.append(time.perf_counter() - began)
    return 1e3 * statistics.median(times)


def settling_input(iterations: int):
    """maze100's graph, rfd_graded's params and the altitudes one iteration settles (f32[N])."""
    chosen = paper_map("maze100")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make("rfd_graded")
    params = swarm.default_params
    state, _ = jax.jit(lambda key: run(swarm, key, graph, task, params,
                                       iterations=iterations))(jax.random.key(1))
    table = rfd.graded_transition(graph, task, state.altitude, params)
    drops = walk(jax.random.key(5), graph, table, task.start, task.goal,
                 num_agents=swarm.config.num_agents,
                 max_steps=step_budget(graph, swarm.config.max_steps),
                 greedy_agents=swarm.config.greedy_drops)
    failed = visited_nodes(drops, graph.num_nodes, ~drops.arrived)
    plateau = state.altitude >= params.initial_height
    return graph, params, state.altitude + jnp.where(failed & plateau, params.sediment, 0.0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=paper_maps_argument,
                        default="maze50,maze100,mosaic100,alley100",
                        help="comma-separated paper maps for the distance field, or all")
    parser.add_argument("--iterations", type=int, default=40,
                        help="rfd_graded iterations before the settled one")
    parser.add_argument("--repeats", type=int, default=30)
    args = parser.parse_args(argv)
    print(f"machine: {platform.platform()} | {os.cpu_count()} CPUs | python "
          f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()})")
    print(f"{'what':32} {'median ms':>10}")
    for name in args.maps:
        chosen = paper_map(name)
        graph = chosen.graph()
        goal = node_index(graph, *chosen.goal)
        ms = median_ms(distance_field, graph, goal, repeats=args.repeats)
        print(f"{'distance_field ' + name:32} {ms:>10.2f}", flush=True)
    graph, params, altitude = settling_input(args.iterations)
    settle = jax.jit(lambda a: rfd.settle(graph, a, params))
    ms = median_ms(settle, altitude, repeats=args.repeats)
    print(f"{'settle maze100 iteration ' + str(args.iterations + 1):32} {ms:>10.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
