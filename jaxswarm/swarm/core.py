"""The swarm protocol (:class:`Swarm`, :class:`Task`, :class:`StepInfo`, :class:`Trace`) and the
run loop with its stop conditions (:func:`run_loop`, which :mod:`jaxswarm.swarm.executor` runs);
the names of the swarms are in :mod:`jaxswarm.swarm.registry`.

A swarm is a bundle of pure functions built by a factory that closes over a static, hashable
``Config`` (sizes and switches); the numbers a sweep varies live in a traced ``Params`` pytree; the
memory that persists between iterations (altitudes, pheromone) lives in a pytree ``State``::

    swarm = jaxswarm.swarm.make("rfd_star", num_agents=256)
    task = make_task(world, start=(0, 0), goal=(19, 19))
    state, trace = jaxswarm.swarm.run(swarm, key, world, task, swarm.default_params)
    swarm.best(state)  # Solution(path, cost, found)

The run loop is jitted (the swarm and the iteration budget are static), so it vmaps over keys and
over params and compiles once per map shape. The world (a graph or a plane) is an argument, never
stored in the state, so a batch of runs shares one copy.
"""
# Annotations are evaluated here (no postponed annotations): WalkingConfig's ``walker`` field
# then holds the class itself, which its subclasses in other modules resolve without importing it.
import dataclasses
import functools
from typing import Any, Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.walking.log import all_same
from jaxswarm.swarm.walking.options import WalkerOptions
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution, as_node
from jaxswarm.world.plane import Plane, check_point

World = Graph | Plane
"""What a swarm plans in: a graph (the walkers) or a plane of rectangles (the bees)."""


class Task(NamedTuple):
    """Where to go (a pytree of traced arrays: moving the goal is data, not a new shape).

    Attributes:
      start: the start: i32[] node of a graph, f32[2] point (x, y) of a plane.
      goal: the goal, likewise.
    """

    start: jax.Array
    goal: jax.Array


def make_task(world: World, start, goal) -> Task:
    """Host-side: a Task from (x, y) cells or node indices of a graph, or (x, y) points of a
    plane, checked like the exact planners'.

    Raises:
      ValueError: start or goal off the map or blocked.
    """
    if isinstance(world, Plane):
        return Task(start=jnp.asarray(check_point(world, start, name="start"), jnp.float32),
                    goal=jnp.asarray(check_point(world, goal, name="goal"), jnp.float32))
    return Task(start=jnp.int32(as_node(world, start, name="start")),
                goal=jnp.int32(as_node(world, goal, name="goal")))


def require_world(swarm: "Swarm", world) -> None:
    """Host-side: raise a ValueError when ``swarm`` does not plan in a world of ``world``'s kind
    (a graph swarm given a plane, the bees given a graph)."""
    if not isinstance(world, swarm.world):
        raise ValueError(f"{swarm.name} plans on a {swarm.world.__name__}, got a "
                         f"{type(world).__name__}")


class StepInfo(NamedTuple):
    """What one iteration did (returned by ``Swarm.step``).

    Attributes:
      iteration_cost: f32[] cost of this iteration's best arrived agent (inf if none arrived).
      arrived: f32[] share of agents that reached the goal.
      converged: bool[] every agent arrived along one and the same path.
      moves: i32[] moves the agents made (the useful work of the walk).
      lane_steps: i32[] lane-steps the walk's loop executed (a batch of runs shares one loop,
        so under ``vmap`` each run gets the batch's total); None for a swarm that does not walk
        (its trace counts 0).
      evaluations: i32[] fitness calls: complete paths whose length was evaluated (the agents
        that arrived; the IWD paper's "fitness function calls"), guided-function evaluations of
        the bees.
      overflowed: bool[] the walk's log had no room for all its moves (:mod:`~jaxswarm.swarm.
        walking.log`): what the iteration did is wrong, and the run must be made again with
        more room (:func:`~jaxswarm.swarm.executor.run` does).
    """

    iteration_cost: jax.Array
    arrived: jax.Array
    converged: jax.Array
    moves: jax.Array
    evaluations: jax.Array
    lane_steps: Any = None
    overflowed: Any = np.False_


@dataclasses.dataclass(frozen=True, eq=False)
class Swarm:
    """A swarm algorithm: pure functions over (State, World, Task, Params).

    Hashable by identity (it is a static argument of the run loop); factories are cached per
    Config, so equal configs give the same Swarm and share compiled code. ``init`` and ``step``
    are jitted, so stepping a swarm by hand (one iteration at a time, from Python) compiles once
    per map shape too. What else a family offers is declared where it is used, keyed by the
    swarm's name: how its memory is drawn (:mod:`jaxswarm.plot.memory`), how it adapts to a
    change (:mod:`jaxswarm.dynamic.rules`), how a batch of its runs is scheduled
    (:mod:`jaxswarm.swarm.executor`).

    Attributes:
      name: registry name.
      config: the static Config it was built with.
      init: ``(key, world, task, params) -> State``.
      step: ``(state, world, task, params) -> (State, StepInfo)``: all agents walk once, then the
        memory is updated (the bees: the vehicle takes one step).
      best: ``(state) -> Solution``: the best path found so far (on a plane: waypoints
        f32[L, 2], NaN padded).
      default_params: Params that work on the paper maps.
      check_params: ``(params) -> None``, host-side; raises
        :class:`~jaxswarm.swarm.core.ParamError` (a ValueError) whose ``field`` names the bad
        param.
      world: the kind of world it plans in, :class:`~jaxswarm.world.graph.Graph` or
        :class:`~jaxswarm.world.plane.Plane`.
    """

    name: str
    config: Any
    init: Callable
    step: Callable
    best: Callable
    default_params: Any
    check_params: Callable
    world: type = Graph

    def params_with(self, **values: float):
        """The swarm's default params with the named ones set to ``values`` (NumPy float32
        scalars): how a stored setting (a sweep row, a run record, a point of a spec's grid)
        becomes params. An unknown name raises ValueError."""
        return self.default_params._replace(**{
            name: np.float32(value) for name, value in values.items()})


@dataclasses.dataclass(frozen=True)
class Trace:
    """Per-iteration record of a run (a pytree); entries after the stop are NaN (0 for the
    counts).

    Attributes:
      best_cost: f32[T] best cost found so far, after each iteration.
      iteration_cost: f32[T] cost of each iteration's best agent (inf if none arrived).
      arrived: f32[T] share of agents that reached the goal in each iteration.
      iterations: i32[] iterations actually run (<= T).
      moves: i32[T] moves the agents made in each iteration.
      lane_steps: i32[T] lane-steps of each iteration's walk (see
        :class:`~jaxswarm.swarm.core.StepInfo`).
      evaluations: i32[T] fitness calls in each iteration (see
        :class:`~jaxswarm.swarm.core.StepInfo`).
      overflowed: bool[] a walk's log had no room for its moves (see
        :class:`~jaxswarm.swarm.core.StepInfo`): the run is wrong and the executor makes it
        again with more room; set only in the trace of a run mapped by its caller.
    """

    best_cost: jax.Array
    iteration_cost: jax.Array
    arrived: jax.Array
    iterations: jax.Array
    moves: jax.Array
    lane_steps: jax.Array
    evaluations: jax.Array
    overflowed: Any = None


jax.tree_util.register_dataclass(
    Trace, data_fields=["best_cost", "iteration_cost", "arrived", "iterations", "moves",
                        "lane_steps", "evaluations", "overflowed"], meta_fields=[])


def check_run(swarm: Swarm, world: World, params, iterations: int,
              patience: int | None) -> int | None:
    """Host-side checks of a run's arguments (see :func:`jaxswarm.swarm.executor.run`): the
    patience the run loop takes, None where ``patience`` cannot stop a run early (at least
    ``iterations``). Params are checked in range only when concrete (outside ``jit``).

    Raises:
      TypeError: params that are not the swarm's Params, or a param that is not a real number.
      ValueError: an iteration budget or a patience below 1, a world of the wrong kind, a param
        of another shape than its default's, or concrete params out of range.
    """
    if iterations < 1:
        raise ValueError(f"iterations must be at least 1, got {iterations}")
    if patience is not None and patience < 1:
        raise ValueError(f"patience must be at least 1, got {patience}")
    require_world(swarm, world)
    check_params_form(swarm, params)
    if not any(isinstance(leaf, jax.core.Tracer) for leaf in jax.tree_util.tree_leaves(params)):
        swarm.check_params(params)
    return effective_patience(iterations, patience)


def effective_patience(iterations: int, patience: int | None) -> int | None:
    """The patience the run loop takes: None where ``patience`` cannot stop a run of
    ``iterations`` early (it is at least ``iterations``), so such runs share None's program."""
    return None if patience is not None and patience >= iterations else patience


def check_params_form(swarm: Swarm, params) -> None:
    """Host-side: raise unless ``params`` has the form of ``swarm.default_params``: the same
    type and fields, every field a real number of its default's shape (f32[] for every
    registered swarm's param: one run's). Checks types and shapes only, so traced params (a run
    under ``vmap`` or ``jit``) are checked too. A swarm built by hand without default params
    declares no form, and its params are not checked.

    Raises:
      TypeError: another type than the swarm's Params (a dict, another swarm's Params), or a
        field that is not a real number; the message names the field.
      ValueError: a field of another shape; the message names the field and the shape expected.
    """
    default = swarm.default_params
    if default is None:
        return
    if type(params) is not type(default):
        raise TypeError(f"params of {swarm.name} must be {type(default).__name__}, got "
                        f"{type(params).__name__}: pass swarm.default_params or "
                        "swarm.params_with(name=value, ...)")
    # One level down: each field whole (a list or None in a field is named, not flattened).
    fields = jax.tree_util.tree_flatten_with_path(params, is_leaf=lambda x: x is not params)[0]
    defaults = jax.tree_util.tree_leaves(default, is_leaf=lambda x: x is not default)
    for (path, value), wanted in zip(fields, defaults):
        field = f"params{jax.tree_util.keystr(path)}"
        dtype = value.dtype if hasattr(value, "dtype") else np.asarray(value).dtype
        if not (np.issubdtype(dtype, np.floating) or np.issubdtype(dtype, np.integer)):
            raise TypeError(f"{field} of {swarm.name} must be a real number, got {value!r}")
        if np.shape(value) != np.shape(wanted):
            scalar = " (a scalar)" if np.shape(wanted) == () else ""
            raise ValueError(f"{field} of {swarm.name} has shape {np.shape(value)}, expected "
                             f"{np.shape(wanted)}{scalar} for a single run; a batch of runs "
                             "maps run over params (jax.vmap)")


@functools.partial(jax.jit, static_argnames=("swarm", "iterations", "patience"))
def run_loop(swarm: Swarm, key: jax.Array, world: World, task: Task, params, state,
             budget: jax.Array, *, iterations: int, patience: int | None):
    """The run loop of :func:`jaxswarm.swarm.executor.run` (see there for the stop rules and
    the arguments, checked by :func:`check_run`): ``(state, trace)``, the trace's
    ``overflowed`` set where a walk had no room in its log (the executor makes such a run
    again). ``state`` None: fresh memory; ``budget`` i32[].
    """
    if state is None:
        state = swarm.init(key, world, task, params)
    else:
        state = dataclasses.replace(state, key=key)
    nan = jnp.full((iterations,), jnp.nan, jnp.float32)
    counts = jnp.zeros((iterations,), jnp.int32)
    trace = Trace(best_cost=nan, iteration_cost=nan, arrived=nan, iterations=jnp.int32(0),
                  moves=counts, lane_steps=counts, evaluations=counts,
                  overflowed=jnp.array(False))
    limit = iterations if patience is None else patience

    def keep_going(carry):
        _, trace, stale, converged = carry
        return ((trace.iterations < jnp.minimum(iterations, budget)) & (stale < limit)
                & ~converged)

    def one_iteration(carry):
        state, trace, stale, _ = carry
        before = swarm.best(state).cost
        # Under vmap every run of the batch goes through this body until the last one stops,
        # and a stopped run's result is dropped. Starting its walk at the goal makes the walk
        # empty, so the walker's lanes go to the runs still going (the goal stays as it is:
        # work that depends on it alone is hoisted out of the loop).
        going = keep_going(carry)
        state, info = swarm.step(state, world, task._replace(
            start=jnp.where(going, task.start, task.goal)), params)
        after = swarm.best(state).cost
        t = trace.iterations
        trace = Trace(best_cost=trace.best_cost.at[t].set(after),
                      iteration_cost=trace.iteration_cost.at[t].set(info.iteration_cost),
                      arrived=trace.arrived.at[t].set(info.arrived),
                      iterations=t + 1, moves=trace.moves.at[t].set(info.moves),
                      lane_steps=(trace.lane_steps if info.lane_steps is None
                                  else trace.lane_steps.at[t].set(info.lane_steps)),
                      evaluations=trace.evaluations.at[t].set(info.evaluations),
                      overflowed=trace.overflowed | info.overflowed)
        stale = jnp.where((after < before) | ~jnp.isfinite(after), 0, stale + 1)
        return state, trace, stale, info.converged

    state, trace, _, _ = jax.lax.while_loop(
        keep_going, one_iteration, (state, trace, jnp.int32(0), jnp.array(False)))
    return state, trace


@dataclasses.dataclass(frozen=True)
class SwarmConfig:
    """The static sizes every swarm has; a swarm's own Config adds its switches.

    Attributes:
      num_agents: agents (drops, ants) per iteration.
      max_steps: step budget of one walk (paths hold max_steps + 1 nodes); None = N - 1 (the
        longest walk without revisits) on general graphs and min(N - 1, 8 (H + W)) on grids.
    """

    num_agents: int = 256
    max_steps: int | None = None

    def __post_init__(self):
        check_sizes(self.num_agents, self.max_steps)


@dataclasses.dataclass(frozen=True)
class WalkingConfig(SwarmConfig):
    """The Config of a swarm whose agents walk the walker (:mod:`jaxswarm.swarm.walking`).

    Attributes:
      walker: how its walks are run, handed to the walker unread
        (:class:`~jaxswarm.swarm.walking.options.WalkerOptions`); changes no result.
    """

    walker: WalkerOptions = WalkerOptions()

    def __post_init__(self):
        super().__post_init__()
        if not isinstance(self.walker, WalkerOptions):
            raise TypeError(f"walker must be WalkerOptions, got {type(self.walker).__name__}")


def default_params(params_type, **values):
    """A Params tuple of NumPy float32 scalars, not JAX arrays: importing a swarm must not start
    JAX's backend (see :func:`jaxswarm.runtime.cpu.configure`); jit and vmap take them as f32
    arrays."""
    return params_type(**{name: np.float32(value) for name, value in values.items()})


def best_solution(state) -> Solution:
    """The best path so far of a swarm state with ``best_path`` i32[L] and ``best_cost`` f32[]
    (inf until an agent arrived), as a Solution."""
    return Solution(path=state.best_path, cost=state.best_cost,
                    found=jnp.isfinite(state.best_cost))


def check_sizes(num_agents: int, max_steps: int | None) -> None:
    """Static config check shared by the swarms: at least one agent and one step."""
    if num_agents < 1:
        raise ValueError(f"num_agents must be at least 1, got {num_agents}")
    if max_steps is not None and max_steps < 1:
        raise ValueError(f"max_steps must be at least 1, got {max_steps}")


def keep_best(walk, best_path, best_cost, *, ties: bool = False, paths=None, lengths=None):
    """The bookkeeping every swarm does after its agents walked.

    Args:
      walk: the iteration's :class:`jaxswarm.swarm.walking.Walk`.
      best_path: i32[L] the best path so far; best_cost: f32[] its length.
      ties: take this iteration's best also when it only equals the best so far.
      paths: i32[A, L] the agents' paths when the swarm changed them after the walk (IWD_PG
        smooths them), with their ``lengths`` f32[A]; None: the walk's.

    Returns:
      ``(best_path, best_cost, StepInfo)`` updated with this iteration's best arrived agent.
    """
    costs = jnp.where(walk.arrived, walk.length if lengths is None else lengths, jnp.inf)
    winner = jnp.argmin(costs)
    cost = costs[winner]
    better = ((cost <= best_cost) & jnp.isfinite(cost)) if ties else cost < best_cost
    # Comparing the paths costs a pass over the moves: only when every agent arrived.
    all_arrived = jnp.all(walk.arrived)
    if paths is None:
        same_path = jax.lax.cond(all_arrived, all_same, lambda log: jnp.array(False), walk.log)
    else:
        same_path = jax.lax.cond(all_arrived, lambda p: jnp.all(p == p[:1]),
                                 lambda p: jnp.array(False), paths)
    info = StepInfo(iteration_cost=cost,
                    arrived=jnp.mean(walk.arrived.astype(jnp.float32)),
                    converged=all_arrived & same_path, moves=jnp.sum(walk.moves),
                    lane_steps=walk.lane_steps, evaluations=jnp.sum(walk.arrived, dtype=jnp.int32),
                    overflowed=walk.log.overflowed)
    path = walk.agent_path(winner) if paths is None else paths[winner]
    return jnp.where(better, path, best_path), jnp.where(better, cost, best_cost), info


class ParamError(ValueError):
    """A param's value out of range, raised by a swarm's ``check_params``.

    Attributes:
      field: the param's name (the Params field); the message starts with it.
    """

    def __init__(self, field: str, problem: str):
        super().__init__(f"{field} {problem}")
        self.field = field


def check_positive(name: str, value, *, allow_zero: bool = False) -> None:
    """Host-side check of a scalar (or array) param: finite and positive (or non-negative).

    Raises:
      ParamError: naming ``name`` and the value as NumPy prints it.
    """
    array = np.asarray(value, dtype=np.float64)
    if not np.all(np.isfinite(array)):
        raise ParamError(name, f"must be finite, got {shown(value)}")
    if np.any(array < 0) or (not allow_zero and np.any(array == 0)):
        bound = "non-negative" if allow_zero else "positive"
        raise ParamError(name, f"must be {bound}, got {shown(value)}")


def shown(value) -> str:
    """A param's value as a message shows it: ``-0.5`` for ``np.float32(-0.5)``, ``[1. 2.]``
    for an array."""
    return str(np.asarray(value))


_MOVED = {"run": "run", "with_room": "with_room", "again_with_room": "retried"}
"""Names that moved to :mod:`jaxswarm.swarm.executor` (forwarded until 0.12.0)."""


def __getattr__(name: str):
    if name in _MOVED:
        import warnings

        from jaxswarm.swarm import executor
        warnings.warn(f"jaxswarm.swarm.core.{name} is jaxswarm.swarm.executor.{_MOVED[name]} "
                      "(this name goes in 0.12.0)", DeprecationWarning, stacklevel=2)
        return getattr(executor, _MOVED[name])
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
