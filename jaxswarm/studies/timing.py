"""Timed runs for the tables: compile once, then time each run on its own.

A table reports the wall time of one run, compile excluded: the first input is run once to
compile (its result dropped), then every input is run again, alone and timed, with the host
waiting for the result (``jax.block_until_ready``) inside the timed span.
"""
from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Iterable, Sequence
from typing import Any, NamedTuple, TypeVar

import jax

from jaxswarm.runtime.programs import release_if_crowded
from jaxswarm.sweep.run_record import replay_columns, run_record
from jaxswarm.swarm import Swarm, Task, Trace, run
from jaxswarm.world.graph import Graph

Input = TypeVar("Input")
Result = TypeVar("Result")


class TimedRun(NamedTuple):
    """One timed swarm run: its final state, its trace, its wall time [s] and the columns that
    let it be replayed (:data:`jaxswarm.sweep.run_record.COLUMNS`)."""

    state: Any
    trace: Trace
    seconds: float
    replay: dict


def timed_call(call: Callable[..., Result], *arguments, **keywords) -> tuple[Result, float]:
    """``call(*arguments, **keywords)`` and its wall time [s], the result ready (blocked on)
    within it."""
    began = time.perf_counter()
    result = jax.block_until_ready(call(*arguments, **keywords))
    return result, time.perf_counter() - began


def compile_then_time(call: Callable[[Input], Result],
                      inputs: Sequence[Input]) -> list[tuple[Result, float]]:
    """Run ``call`` on ``inputs[0]`` once to compile it, then on each input alone, timed.
    A process that holds many compiled programs lets them go first
    (:func:`~jaxswarm.runtime.programs.release_if_crowded`).

    Returns:
      (result, wall seconds) per input, in order; each result is ready (blocked on).
    """
    release_if_crowded()
    jax.block_until_ready(call(inputs[0]))
    return [timed_call(call, one) for one in inputs]


def seed_keys(count: int, seed: int = 0) -> jax.Array:
    """The keys of ``count`` seeded runs: ``key(seed)`` split ``count`` ways (key[count])."""
    return jax.random.split(jax.random.key(seed), count)


def timed_runs(swarm: Swarm, keys: jax.Array, graph: Graph, task: Task, params, *,
               iterations: int, patience: int | None = None, entry=None) -> list[TimedRun]:
    """Run ``swarm`` once per key (key[R]) on ``graph`` from ``task.start`` to ``task.goal``,
    compiled by a first run, each run then timed alone (see :func:`compile_then_time`).

    Args:
      params: the swarm's Params (float32 leaves), the same for every run.
      iterations, patience: the stop rules of :func:`jaxswarm.swarm.run`.
      entry: the sweep-spec map entry that builds ``graph``, ``task.start`` and ``task.goal``
        again (:class:`~jaxswarm.studies.problems.Problem`'s ``entry``); None: the runs are not
        replayable (an empty ``run_record``).

    Returns:
      One :class:`TimedRun` per key, in order.
    """
    def one_run(key):
        return run(swarm, key, graph, task, params, iterations=iterations, patience=patience)

    return [TimedRun(state, trace, seconds, replay_columns(
                run_record(swarm, params, entry, key, iterations=iterations, patience=patience),
                state, trace))
            for key, ((state, trace), seconds) in zip(keys, compile_then_time(one_run, keys))]


def median_milliseconds(seconds: Iterable[float]) -> float:
    """The median of wall times given in seconds, in milliseconds."""
    return 1e3 * statistics.median(seconds)
