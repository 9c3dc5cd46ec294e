"""The conformance suite every swarm must pass, shipped so that anyone writing a swarm can run
it: ``check_swarm(make("my_swarm", num_agents=32), graph, task, optimum)``.

Each check raises ``AssertionError`` naming what failed:

* :func:`check_reproducible`: the same key gives bit-identical results, ``vmap`` over keys
  equals a loop over them, and another key gives another run.
* :func:`check_valid_results`: the best path is a valid path from start to goal, its cost is
  its length measured as :func:`jaxswarm.world.paths.path_length` measures it, never below the
  optimum; the trace's best cost never rises; the memory stays finite. On a plane the path is a
  trajectory of waypoints: it starts at the start, ends at the goal, no waypoint lies inside a
  rectangle, and its cost is :func:`jaxswarm.world.plane.trajectory_length`.
* :func:`check_unreachable_goal`: on a graph whose goal cannot be reached, a run ends as a
  clean "not found": no path, an infinite cost, no agent arrived, and it runs its whole budget
  (the convergence stop needs arrivals).
* :func:`check_compiles_once`: a ``vmap`` of runs over valid values of a param compiles once,
  and new values of the same shapes do not compile again.
* :func:`check_batch_invariant`: one key, one result: a run alone equals the same key in
  batches of 1, 3 and 64 runs, every leaf bit for bit. Threads, devices and processes are set
  when a process starts, so they are checked across processes: a sweep's rows
  (:func:`jaxswarm.sweep.run_sweep`) carry each run's fingerprint
  (:func:`jaxswarm.swarm.fingerprint.run_fingerprint`) to compare with the run alone.

The first three checks share two programs per swarm: one run, and one batch of ``runs`` runs
with their keys and params batched (:func:`~jaxswarm.swarm.executor.run_batch`);
:func:`check_batch_invariant` adds one batch program per width.
:class:`Compilations` counts the programs JAX builds while it is open, for checks of one's own
(a change of the map that must not recompile, a grid of params).

Use a small map every agent reaches within a few iterations (the project's own suite uses the
RFD paper's maze20 with 32 agents, 8 iterations and batches of 8 runs, and for the bees a 6 x 6
plane).
"""
from __future__ import annotations

import dataclasses
import functools

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.core import Swarm, Task, World
from jaxswarm.swarm.executor import ONE_AT_A_TIME, run, run_batch
from jaxswarm.world.paths import is_valid_path, path_length
from jaxswarm.world.plane import Plane, in_plane, trajectory_length, violations


COMPILE_EVENT = "/jax/core/compile/jaxpr_to_mlir_module_duration"
"""The ``jax.monitoring`` event JAX records each time it lowers a program for XLA."""


class Compilations:
    """A context that counts the programs JAX builds while it is open: one per call of a jitted
    function with static arguments, shapes or dtypes it has not seen (nested jitted functions are
    part of their caller's program). A program the persistent compilation cache holds still
    counts: JAX lowers it to look it up. Eager operations count too (each primitive on new shapes
    is a small program), so run them before the context opens::

        with Compilations() as built:
            sweep(grid)
            sweep(other_grid)
        assert built.count == 1, built.names

    Attributes:
      count: programs built so far.
      names: the name of each program's function, in order.
    """

    def __init__(self):
        self.count = 0
        self.names: list[str] = []

    def _listen(self, event: str, duration: float, **metadata) -> None:
        del duration
        if event == COMPILE_EVENT:
            self.count += 1
            self.names.append(str(metadata.get("fun_name", "?")))

    def __enter__(self) -> Compilations:
        jax.monitoring.register_event_duration_secs_listener(self._listen)
        return self

    def __exit__(self, *exc_info) -> None:
        jax.monitoring.unregister_event_duration_listener(self._listen)


def batched_params(params, runs: int):
    """``params`` (a Params tuple of scalars) repeated ``runs`` times: f32[runs] leaves."""
    return jax.tree_util.tree_map(lambda x: jnp.full((runs,), x, jnp.float32), params)


def leaves_equal(a, b) -> bool:
    """Whether two pytrees have bit-identical leaves (NaNs equal)."""
    return all(np.array_equal(np.asarray(x), np.asarray(y), equal_nan=True)
               for x, y in zip(jax.tree_util.tree_leaves(a), jax.tree_util.tree_leaves(b)))


def differing_leaves(a, b) -> list[str]:
    """The paths (:func:`jax.tree_util.keystr`) of the leaves in which two pytrees differ, sorted:
    a leaf one of them lacks, or another shape, dtype or bytes (PRNG keys compared as their
    data; stricter than :func:`leaves_equal`: NaN payloads and the sign of zero count)."""
    def by_path(tree):
        return {jax.tree_util.keystr(path): np.asarray(leaf)
                for path, leaf in jax.tree_util.tree_leaves_with_path(key_data(tree))}

    x, y = by_path(a), by_path(b)
    return sorted(name for name in x.keys() | y.keys()
                  if name not in x or name not in y or x[name].shape != y[name].shape
                  or x[name].dtype != y[name].dtype or x[name].tobytes() != y[name].tobytes())


def key_data(tree):
    """``tree`` with its PRNG keys turned into their raw data (comparable arrays)."""
    return jax.tree_util.tree_map(
        lambda x: jax.random.key_data(x) if jnp.issubdtype(x.dtype, jax.dtypes.prng_key) else x,
        tree)


def outcome(result):
    """A run's ``(state, trace)`` as NumPy arrays, with its PRNG keys as data and without the
    trace's ``lane_steps``: what the run decided, the same alone or in a batch (a batch's walks
    share one loop, whose lane-steps each run reports). NumPy, so that picking a batch's row
    and comparing are not JAX operations (each a program of its own outside ``jit``)."""
    state, trace = result
    return jax.device_get(key_data((state, dataclasses.replace(trace, lane_steps=None))))


def check_reproducible(swarm: Swarm, graph: World, task: Task, *, iterations: int = 8,
                       keys: int = 3, runs: int = 8) -> None:
    """Same key, same result; the first ``keys`` rows of a batch of ``runs`` runs
    (:func:`~jaxswarm.swarm.executor.run_batch`, every run another key) equal those runs one at a
    time (see :func:`outcome`); keys differ. For a swarm whose ``vmap`` runs its members one at a
    time (:data:`~jaxswarm.swarm.executor.ONE_AT_A_TIME`), each row's walks were its own: their
    lane-steps are those of the run alone (in lockstep they are the batch's)."""
    split = jax.random.split(jax.random.key(7), runs)
    params = swarm.default_params
    one = [run(swarm, k, graph, task, params, iterations=iterations) for k in split[:keys]]
    again = run(swarm, split[0], graph, task, params, iterations=iterations)
    assert leaves_equal(key_data(one[0]), key_data(again)), f"{swarm.name}: same key differs"
    batch = run_batch(swarm, split, graph, task, batched_params(params, runs),
                      iterations=iterations)
    rows = outcome(batch)
    for i in range(keys):
        assert leaves_equal(jax.tree_util.tree_map(lambda x: x[i], rows), outcome(one[i])), (
            f"{swarm.name}: vmap row {i} differs from run")
        if swarm.name in ONE_AT_A_TIME:
            assert np.array_equal(np.asarray(batch[1].lane_steps)[i], one[i][1].lane_steps), (
                f"{swarm.name}: vmap row {i} did not walk alone")
    # Another key walks other agents: the memory or the share that arrived differs.
    assert not leaves_equal((dataclasses.replace(one[0][0], key=None), one[0][1].arrived),
                            (dataclasses.replace(one[1][0], key=None), one[1][1].arrived)), (
        f"{swarm.name}: two keys gave the same run")


def check_valid_results(swarm: Swarm, graph: World, task: Task, optimum: float, *,
                        iterations: int = 8) -> None:
    """One run's best path is found, valid, measured right and never below ``optimum`` (the
    optimum measured as swarm paths are, see :func:`jaxswarm.exact.optimal_length`), and the
    state's float arrays are finite (remembered path lengths, ``costs``, may be +inf where no
    path is held yet, and a trajectory's ``waypoints`` are NaN after its end)."""
    state, trace = run(swarm, jax.random.key(0), graph, task, swarm.default_params,
                       iterations=iterations)
    solution = swarm.best(state)
    assert bool(solution.found), f"{swarm.name}: no path within {iterations} iterations"
    for where, leaf in jax.tree_util.tree_leaves_with_path(state):
        if not (jnp.issubdtype(leaf.dtype, jnp.floating) and leaf.ndim > 0):
            continue
        values = np.asarray(leaf)
        # Path lengths (``costs``) are +inf where a memory slot holds no path yet; waypoints
        # are NaN after the trajectory's end.
        if jax.tree_util.keystr(where).endswith("costs"):
            values = values[values != np.inf]
        if jax.tree_util.keystr(where).endswith("waypoints"):
            values = values[~np.isnan(values).all(axis=-1)]
        assert np.isfinite(values).all(), (
            f"{swarm.name}: memory not finite at {jax.tree_util.keystr(where)}")
    ran = int(trace.iterations)
    assert 1 <= ran <= iterations
    best = np.asarray(trace.best_cost)
    assert np.isnan(best[ran:]).all(), f"{swarm.name}: trace entries after the stop"
    assert (best[1:ran] <= best[:ran - 1]).all(), f"{swarm.name}: best cost rose"
    if isinstance(graph, Plane):
        _check_trajectory(swarm, graph, task, solution)
    else:
        assert bool(is_valid_path(graph, solution.path, task.start, task.goal)), (
            f"{swarm.name}: invalid path")
        assert float(path_length(graph, solution.path)) == float(solution.cost), (
            f"{swarm.name}: cost is not the path's length")
    assert float(solution.cost) >= optimum, f"{swarm.name}: beats the optimum {optimum}"
    assert float(solution.cost) == best[ran - 1], f"{swarm.name}: trace and state disagree"


def check_unreachable_goal(swarm: Swarm, graph: World, task: Task, *,
                           iterations: int = 8) -> None:
    """A run on ``graph``, whose ``task.goal`` cannot be reached from ``task.start``, finds no
    path: ``found`` is false, the cost infinite, the path all -1, no agent arrived in any
    iteration, and the run used all ``iterations`` (no agent arrived, so no iteration
    converged; patience counts only from the first path, which
    :func:`~jaxswarm.swarm.executor.run` applies alike to every swarm)."""
    state, trace = run(swarm, jax.random.key(0), graph, task, swarm.default_params,
                       iterations=iterations)
    solution = swarm.best(state)
    assert not bool(solution.found), f"{swarm.name}: found a path to an unreachable goal"
    assert np.isinf(float(solution.cost)), f"{swarm.name}: a finite cost without a path"
    assert (np.asarray(solution.path) == -1).all(), f"{swarm.name}: a path of nodes without a path found"
    assert (np.asarray(trace.arrived) == 0).all(), f"{swarm.name}: agents arrived"
    assert int(trace.iterations) == iterations, (
        f"{swarm.name}: stopped after {int(trace.iterations)} of {iterations} iterations")


def _check_trajectory(swarm: Swarm, plane: Plane, task: Task, solution) -> None:
    """A found trajectory runs from start to goal, every waypoint on the plane and in no
    rectangle, and its cost is its length."""
    waypoints = np.asarray(solution.path)
    points = waypoints[~np.isnan(waypoints).any(axis=-1)]
    assert np.isnan(waypoints[len(points):]).all(), f"{swarm.name}: gaps in the trajectory"
    assert np.array_equal(points[0], np.asarray(task.start)), f"{swarm.name}: not from start"
    assert np.array_equal(points[-1], np.asarray(task.goal)), f"{swarm.name}: not to the goal"
    assert bool(np.all(in_plane(plane, points))), f"{swarm.name}: a waypoint off the plane"
    assert not np.any(violations(plane, points)), f"{swarm.name}: a waypoint in an obstacle"
    assert float(trajectory_length(solution.path)) == float(solution.cost), (
        f"{swarm.name}: cost is not the trajectory's length")


def check_compiles_once(swarm: Swarm, graph: World, task: Task, *, iterations: int = 8,
                        runs: int = 8) -> None:
    """A batch of ``runs`` runs (:func:`~jaxswarm.swarm.executor.run_batch`) over valid values of
    the first param builds at most one program (none if an earlier check built it), and new
    values of the same shapes build none."""
    first = swarm.default_params._fields[0]
    values = float(getattr(swarm.default_params, first)) * np.linspace(0.5, 1.0, runs)
    for value in values:  # valid values: every run of the sweep is one the swarm accepts
        swarm.check_params(swarm.params_with(**{first: value}))
    grid = batched_params(swarm.default_params, runs)
    grid = grid._replace(**{first: jnp.asarray(values, jnp.float32)})
    other = grid._replace(**{first: jnp.asarray(values * 0.9, jnp.float32)})
    keys = jax.random.split(jax.random.key(0), runs)
    with Compilations() as built:
        state, _ = run_batch(swarm, keys, graph, task, grid, iterations=iterations)
    assert built.count <= 1, f"{swarm.name}: one batch built {built.names}"
    with Compilations() as rebuilt:
        run_batch(swarm, keys, graph, task, other, iterations=iterations)
    assert rebuilt.count == 0, f"{swarm.name}: new values built {rebuilt.names}"
    assert jax.vmap(swarm.best)(state).cost.shape == (runs,)


WIDTHS = (1, 3, 64)
"""The batch widths :func:`check_batch_invariant` runs each key in by default."""


def check_batch_invariant(swarm: Swarm, world: World, task: Task, *, iterations: int = 8,
                          widths: tuple[int, ...] = WIDTHS, keys: int | None = None) -> None:
    """One key, one result: each of ``keys`` keys (default the widest width) run alone equals the
    same key in vmapped batches (:func:`~jaxswarm.swarm.executor.run_batch`) of each of
    ``widths``, every leaf of its final state and trace bit for bit (:func:`outcome`). A width's
    last batch is filled up with the last key."""
    count = max(widths) if keys is None else keys
    split = jax.random.split(jax.random.key(11), count)
    params = swarm.default_params
    runs = [outcome(run(swarm, key, world, task, params, iterations=iterations))
            for key in split]
    for width in widths:
        for first in range(0, count, width):
            rows = np.minimum(np.arange(first, first + width), count - 1)
            batch = outcome(run_batch(swarm, split[rows], world, task,
                                      batched_params(params, width), iterations=iterations))
            for row in range(min(width, count - first)):
                assert leaves_equal(jax.tree_util.tree_map(lambda x: x[row], batch),
                                    runs[first + row]), (
                    f"{swarm.name}: key {first + row} alone differs from the same key in a "
                    f"batch of {width}")


def check_swarm(swarm: Swarm, graph: World, task: Task, optimum: float) -> None:
    """Every check of this module that runs on a reachable goal, with their defaults (for
    :func:`check_unreachable_goal`, give it a graph whose goal cannot be reached)."""
    check_reproducible(swarm, graph, task)
    check_batch_invariant(swarm, graph, task)
    check_valid_results(swarm, graph, task, optimum)
    check_compiles_once(swarm, graph, task)
