"""IWD_PG's local search: a small IWD run between two nodes of a path, spliced in when shorter
(:func:`connect_all` runs a batch of them as one, :func:`splice_if_shorter` splices).

The run is the ``iwd`` swarm itself with fewer drops and iterations and a memory of its own
(fresh soil, no IWD_PG memory), through the engine's run loop; its fitness calls count.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxswarm.swarm.core import Swarm, Task, run_loop
from jaxswarm.swarm.iwd.memory import prefix_lengths, splice
from jaxswarm.swarm.iwd.smooth import IMPROVEMENT
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import path_length


def connect(key, graph: Graph, here, there, params, *, swarm: Swarm, iterations: int):
    """The best path of a small IWD run from node ``here`` to ``there``: ``(path i32[L], cost
    f32[] (inf if no drop arrived), evaluations i32[], overflowed bool[])``, the last set where
    a walk of the run had no room in its log (the run is then wrong: its caller's run must be
    made again with room, as :class:`~jaxswarm.swarm.core.StepInfo` says)."""
    state, trace = run_loop(swarm, key, graph, Task(start=here, goal=there), params, None,
                            jnp.int32(iterations), iterations=iterations, patience=None)
    return state.best_path, state.best_cost, jnp.sum(trace.evaluations), trace.overflowed


def connect_all(keys, graph: Graph, heres, theres, params, *, swarm: Swarm, iterations: int):
    """Small IWD runs (one batch through the walker) from the nodes ``heres`` to ``theres``
    (i32[B]), with ``keys`` (key[B]): ``(paths i32[B, L], costs f32[B], evaluations i32[B],
    overflowed bool[B])`` as :func:`connect` gives them. A run's result does not depend on the
    others of its batch."""
    return jax.vmap(lambda k, here, there: connect(
        k, graph, here, there, params, swarm=swarm, iterations=iterations))(keys, heres, theres)


def splice_if_shorter(graph: Graph, path, begin, end, middle, middle_cost):
    """``path`` (i32[L]) with ``middle`` (a path from ``path[begin]`` to ``path[end]`` of length
    ``middle_cost``) spliced in when shorter than the sub-path it replaces.

    Returns:
      ``(path, cost, spliced bool[])``: the path, its length, whether it changed.
    """
    prefix = prefix_lengths(graph, path)
    better = (end > begin + 1) & (middle_cost < prefix[end] - prefix[begin] - IMPROVEMENT)
    new_path = jnp.where(better, splice(path, begin, end, middle), path)
    return new_path, path_length(graph, new_path), better
