"""Runs of a swarm on one machine: a run, a batch of runs, a run stepped by hand, and the retry
with room that each makes when a walk overflowed its log.

Every entry checks its arguments on the host (:func:`~jaxswarm.swarm.core.check_run`), runs a
program compiled once per (swarm, statics, world shape, batch form) by ``jit``, and when a walk
had no room in its log for its moves (:mod:`jaxswarm.swarm.walking.log`) makes the call again
with the swarm built with room for every move (:func:`with_room`): the log's size changes no
move, so the result is the one a larger log would have given, at the cost of one more program.
How a batch of a swarm's runs is scheduled is declared here too (:data:`ONE_AT_A_TIME`).
"""
from __future__ import annotations

import dataclasses
import functools
from typing import Callable

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.batching import one_at_a_time
from jaxswarm.swarm import registry
from jaxswarm.swarm.core import Swarm, Task, World, check_run, run_loop
from jaxswarm.swarm.walking.log import known_overflowed

ONE_AT_A_TIME: set[str] = {"iwd_pg"}
"""Swarms whose ``vmap`` of runs goes through the batch's members one after another
(:func:`~jaxswarm.runtime.batching.one_at_a_time`) instead of in lockstep: those whose
iterations branch on each run's own state, where lockstep would take every branch for every run
(IWD_PG's memory operators). The results are the same either way; add a name to schedule a new
swarm so."""


def run(swarm: Swarm, key: jax.Array, world: World, task: Task, params, *,
        iterations: int = 100, patience: int | None = None, state=None, budget=None):
    """Iterate a swarm until a stop condition holds, from fresh memory or from ``state``.

    Stops after ``iterations`` iterations, or when the best cost has not improved for ``patience``
    iterations (if given) since a first path was found, or when every agent of an iteration
    followed the same path. Iterations before the first path do not count towards patience (the
    RFD paper's "solution not improved in the last n loops" needs a solution): a swarm that needs
    40 iterations to reach the goal is not stopped at 30, and an unreachable goal uses the whole
    budget.

    Args:
      swarm: the algorithm (static).
      key: PRNG key; the same key and inputs give bit-identical results.
      world: a Graph, or a Plane for the swarms that plan on one (``swarm.world``).
      task: start and goal (see :func:`~jaxswarm.swarm.core.make_task`).
      params: the swarm's Params (traced: vmap over them, or sweep without recompiling).
      iterations: the iteration budget T (static).
      patience: stop after this many iterations without improvement of a path found
        (static; None = never). A patience of ``iterations`` or more cannot stop a run early, so
        it runs the program of None.
      state: a State to continue from (the memory of an earlier run, after
        :func:`jaxswarm.dynamic.events.change` when the map or the task changed); its key is
        replaced by ``key``, which drives the continuation. None: fresh memory (``swarm.init``).
        The iteration count and the patience count start again either way.
      budget: i32[] stop after at most this many iterations (traced, so runs of different
        budgets share one compiled program: replaying a run up to the iteration where something
        happened); None: ``iterations``.

    Returns:
      ``(state, trace)``: the final State and a :class:`~jaxswarm.swarm.core.Trace`. Called
      with concrete inputs, a run whose walk overflowed its log is made again with room for
      every move; mapped or traced by its caller, its trace says so (``Trace.overflowed``).

    Raises:
      TypeError: params that are not the swarm's Params, or a param that is not a real number.
      ValueError: a world of the wrong kind, a param of another shape than its default's (a
        scalar: a batch of runs maps ``run`` over params), or concrete params out of range
        (checked on the host, outside jit).
    """
    patience = check_run(swarm, world, params, iterations, patience)
    budget = jnp.int32(iterations if budget is None else budget)
    return retried(
        lambda swarm: run_program(swarm, iterations, patience)(key, world, task, params, state,
                                                              budget),
        swarm, lambda result: result[1].overflowed)


def run_batch(swarm: Swarm, keys: jax.Array, world: World, task: Task, params, *,
              iterations: int, patience: int | None = None):
    """``vmap`` of :func:`run` over ``keys`` (key[R]) and ``params`` (a Params tuple of f32[R]
    leaves) in one world and task: ``(state, trace)`` with a leading axis R on every leaf, each
    row bit for bit the run of its key alone. One program per (swarm, R, statics, world shape).

    Raises:
      ValueError, TypeError: as :func:`run`, for params of the form of one row.
    """
    patience = check_run(swarm, world, first_row(params), iterations, patience)
    return retried(
        lambda swarm: _run_batch(swarm, keys, world, task, params, iterations=iterations,
                                 patience=patience),
        swarm, lambda result: result[1].overflowed)


@functools.partial(jax.jit, static_argnames=("swarm", "iterations", "patience"))
def _run_batch(swarm: Swarm, keys, world, task, params, *, iterations: int,
               patience: int | None):
    program = run_program(swarm, iterations, patience)
    budget = jnp.int32(iterations)
    return jax.vmap(lambda key, p: program(key, world, task, p, None, budget))(keys, params)


def first_row(params):
    """The params of the first run of a batch (leaves [R, ...]): NumPy rows of concrete leaves
    (no program runs), traced rows of traced ones."""
    return jax.tree_util.tree_map(
        lambda leaf: leaf[0] if isinstance(leaf, jax.core.Tracer) else np.asarray(leaf)[0],
        params)


def steps(swarm: Swarm, state, world: World, task: Task, params, *, iterations: int,
          record: Callable):
    """Step a swarm ``iterations`` times from ``state`` (static count, no stop rule) and keep
    ``record(state)`` after each step: ``(state, records)``, each leaf of ``records`` with a
    leading axis of ``iterations + 1``, the first row ``record`` of the state given. Jittable;
    called with concrete inputs, stepped again with room for every move where a walk
    overflowed its log."""
    def stepped(swarm):
        def one(state, _):
            state, info = swarm.step(state, world, task, params)
            return state, (record(state), info.overflowed)

        after, (records, overflowed) = jax.lax.scan(one, state, None, length=iterations)
        first = jax.tree_util.tree_map(lambda leaf: leaf[None], record(state))
        return after, jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a, b]), first,
                                             records), jnp.any(overflowed)

    after, records, _ = retried(stepped, swarm, lambda result: result[2])
    return after, records


def run_program(swarm: Swarm, iterations: int, patience: int | None):
    """``(key, world, task, params, state, budget) -> (state, trace)``: the run loop
    (:func:`~jaxswarm.swarm.core.run_loop`) with these statics, whose ``vmap`` goes through a
    batch one run at a time for a swarm in :data:`ONE_AT_A_TIME`. For programs of one's own
    that run a swarm inside ``jit`` (check the arguments with
    :func:`~jaxswarm.swarm.core.check_run` first, and call them through :func:`retried`)."""
    if swarm.name in ONE_AT_A_TIME:
        return _run_alone(swarm, iterations, patience)
    return functools.partial(run_loop, swarm, iterations=iterations, patience=patience)


@functools.lru_cache(maxsize=None)
def _run_alone(swarm: Swarm, iterations: int, patience: int | None):
    """The run loop with these statics, whose ``vmap`` runs the batch's members one after
    another. Jitted, so that a run called alone is traced once per shape (a ``custom_vmap``
    function called outside ``jit`` is traced again at every call)."""
    def run_one(key, world, task, params, state, budget):
        return run_loop(swarm, key, world, task, params, state, budget, iterations=iterations,
                        patience=patience)
    return jax.jit(one_at_a_time(run_one))


def retried(call: Callable, swarm: Swarm, overflowed: Callable):
    """``call(swarm)``, made again as ``call(with_room(swarm))`` when ``overflowed(result)``
    (bool[...], concrete) says a walk had no room in its log; a traced flag is left to the
    caller. How a program of one's own that runs a swarm keeps no overflowed result (its
    result carries the runs' ``Trace.overflowed``)."""
    result = call(swarm)
    if known_overflowed(overflowed(result)):
        return call(with_room(swarm))
    return result


def with_room(swarm: Swarm) -> Swarm:
    """``swarm`` with room in its walks' logs for every agent's whole step budget, so that no
    walk overflows; the same results, one more compiled program.

    Raises:
      ValueError: ``swarm`` was not built by the registry (it cannot be built again), or it
        does not walk.
    """
    if not hasattr(swarm.config, "walker"):
        raise ValueError(f"swarm {swarm.name!r} does not walk the walker, so its walks cannot "
                         "overflow")
    return registry.built_again(
        swarm, dataclasses.replace(swarm.config, walker=swarm.config.walker.with_room()))
