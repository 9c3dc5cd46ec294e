"""Runs of one swarm as the rows of a sweep or a tune: a sweep's runs through the executor's calls
over the devices (:class:`~jaxswarm.swarm.executor.ShardedRuns`), each run summed up as a row's
outputs (its cost, its fingerprint, when it came within reach of the optimum).

A run with seed ``s`` uses ``jax.random.key(s)``, so its outputs equal ``run(swarm,
jax.random.key(s), ...)`` bit for bit whatever the batch it is in
(:mod:`jaxswarm.runtime.arithmetic`).
"""
from __future__ import annotations

import functools
import math
import jax.numpy as jnp
import numpy as np

from jaxswarm.maps.entry import ResolvedMap
from jaxswarm.swarm import make, make_task
from jaxswarm.swarm.executor import ShardedRuns
from jaxswarm.swarm.fingerprint import run_fingerprint
from jaxswarm.sweep.spec import SEED_LIMIT

SUCCESS_GAP = 1e-4
"""A run succeeds when its relative gap to the optimum is below this."""

OUTPUTS = ("cost", "iterations", "moves", "evaluations", "fingerprint", "target_iterations",
           "target_evaluations")
"""What :meth:`RunBatches.run` returns per run (see there)."""


class RunBatches:
    """One swarm's runs on sweep maps, as rows' outputs (see the module docstring): the
    registered swarm ``algorithm`` built with ``config`` (static keyword arguments of its
    factory), run by the executor's :class:`~jaxswarm.swarm.executor.ShardedRuns`, to which
    ``running`` goes (``iterations``, ``patience``, ``chunk_size``, ``vmap_size``, ``log``,
    ``fit_calls``, as there).

    Attributes:
      swarm: the swarm built.
      group: runs vmapped together on one device.
    """

    def __init__(self, algorithm: str, config: dict, *running, **keywords):
        self.swarm = make(algorithm, **config)
        self._runs = ShardedRuns(self.swarm, functools.partial(_summary, self.swarm), *running,
                                 **keywords)
        self.group = self._runs.group

    @property
    def default_params(self):
        """The swarm's default params (a NamedTuple of floats)."""
        return self.swarm.default_params

    def run(self, sweep_map: ResolvedMap, seeds: np.ndarray, params: dict[str, np.ndarray],
            optimum: float = np.inf) -> dict[str, np.ndarray]:
        """Run ``seeds`` (int[C], each in ``[0, SEED_LIMIT)``) with ``params`` (name -> f64[C];
        params not named keep the swarm's defaults) on ``sweep_map``, whose optimum is
        ``optimum`` (:meth:`~jaxswarm.maps.entry.ResolvedMap.optimum`), ``chunk_size`` runs a
        call.

        Returns:
          name -> array[C]: ``cost`` (f64, inf without a path), ``iterations`` (i32, used),
          ``moves`` and ``evaluations`` (i64, all iterations), ``fingerprint`` (u32[C, 2],
          :func:`~jaxswarm.swarm.fingerprint.run_fingerprint`), ``target_iterations`` and
          ``target_evaluations`` (i32 and i64: the iterations, and the evaluations they made,
          until the best cost was within :data:`SUCCESS_GAP` of ``optimum``, the rule of
          :func:`jaxswarm.dynamic.events.first_iteration_at`; -1 where it never was), and
          ``seconds`` (f64: the wall time of the call the run was part of, compile excluded).

        Raises:
          ValueError: a seed outside ``[0, SEED_LIMIT)``, where seeds give distinct keys.
        """
        seeds = np.asarray(seeds)
        if seeds.size and (seeds.min() < 0 or seeds.max() >= SEED_LIMIT):
            raise ValueError(f"seeds must be integers from 0 to {SEED_LIMIT - 1} (2^32 - 1), "
                             f"got {seeds.min()} to {seeds.max()}")
        stacked = _stacked_params(self.swarm.default_params, params, len(seeds))
        task = make_task(sweep_map.world, sweep_map.start, sweep_map.goal)
        return self._runs.run(seeds.astype(np.uint32), stacked, sweep_map.world, task,
                              jnp.float32(optimum), label=sweep_map.label)

    def call_size(self, count: int) -> int:
        """The runs of a call that holds ``count`` runs
        (:meth:`~jaxswarm.swarm.executor.ShardedRuns.call_size`)."""
        return self._runs.call_size(count)


def _summary(swarm, state, trace, optimum) -> dict:
    """A run of ``swarm``'s outputs (:data:`OUTPUTS`) on a map whose optimum is ``optimum``
    (f32[])."""
    # The relative gap of first_iteration_at and of the rows' success (NaN after the stop).
    reached = (trace.best_cost - optimum) / optimum < SUCCESS_GAP
    first = jnp.argmax(reached)
    found = reached[first]
    evaluations = jnp.cumsum(trace.evaluations)
    return dict(cost=swarm.best(state).cost, iterations=trace.iterations,
                moves=jnp.sum(trace.moves), evaluations=jnp.sum(trace.evaluations),
                fingerprint=run_fingerprint(state, trace),
                target_iterations=jnp.where(found, first + 1, -1),
                target_evaluations=jnp.where(found, evaluations[first], -1))


def _stacked_params(defaults, params: dict[str, np.ndarray], count: int):
    """The swarm's params with leaves f32[count]: ``params[name]`` where given, else the
    default."""
    return defaults._replace(**{
        name: np.asarray(params[name], np.float32) if name in params
        else np.full(count, np.float32(value)) for name, value in defaults._asdict().items()})


def run_outcomes(cost: np.ndarray, optimum: float) -> dict[str, np.ndarray]:
    """The outcome columns of runs whose best paths cost ``cost`` (f64[C], inf without a path)
    on a map whose optimum is ``optimum``: ``gap`` (f64, relative; NaN without a path or a
    positive finite optimum), ``found`` and ``success`` (bool: within :data:`SUCCESS_GAP`)."""
    cost = np.asarray(cost, np.float64)
    found = np.isfinite(cost)
    gap = ((cost - optimum) / optimum if math.isfinite(optimum) and optimum > 0
           else np.full(cost.shape, np.nan))
    return dict(gap=gap, found=found, success=found & (gap < SUCCESS_GAP))
