"""Intelligent Water Drops (``iwd``): the IWD_PG paper's baseline, Shah-Hosseini's IWD on a grid.

Each iteration ``num_agents`` drops leave the start with the initial velocity and no soil, and
walk to the goal never revisiting a node (the visited set VC). At every step each drop chooses by
the soil it finds and the goal's nearness (eqs. 1-3), speeds up, takes soil from the edge it
crosses and carries it (eqs. 4-6, :mod:`.soil`). After the iteration the path of its best drop
gets the global update, and the best path so far is kept. The paper's nodes sit at cell corners
with 8 moves and Euclidean lengths; on our grids the cells are the nodes, the same kind of graph.

Which drops change the soil is a reading (``IWDConfig.local_updates``). The IWD_PG paper:
"feasible solution removes some soil of graph and therefore guides next generation drops", and
of its reference [24]: it "obtains better solutions in early iteration by using a repair
mechanism for infeasible solutions". So by default only the drops that reach the goal change the
soil, after the walk (``"arrived"``). Most drops on a maze get stuck in a dead end; when they
too take soil as they go (``"while_walking"``), each leaves a trail of soil near -100 beside
edges near 10,000 (choice odds of about 10^5 : 1), and later drops re-walk the old dead ends.
``backtrack`` (ours, off) is a repair: a stuck drop backs out of its dead end.
"""
from __future__ import annotations

import dataclasses
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.swarm.core import (ParamError, Swarm, Task, WalkingConfig, best_solution,
                                 check_positive, default_params, keep_best, shown)
from jaxswarm.swarm.iwd.soil import (CARRIED, SOIL, SOIL_CHOICE, arrived_update, global_update,
                                     goal_log_desirability, walked_soil)
from jaxswarm.swarm.walking import (FORCED, Walk, WalkerOptions, edge_table, fold_agents,
                                   on_walk, step_budget, walk)
from jaxswarm.swarm.walking.backtrack import DepthFirstRule, backtracking_walk
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import slot_offsets


FEW_DROPS = 16
"""Up to this many drops a walk (IWD_PG's local searches' 10), the arrived drops' local updates
take one pass over every drop's walk (eq. 4 for all the drops at once, then eq. 5 drop by drop,
the drops that did not arrive changing nothing); with more, a fold over the arrived drops alone,
which costs more a drop but only for the drops that arrived (few of IWD's 50 on a maze). The
same bits either way."""

LOCAL_UPDATES = ("arrived", "while_walking")
"""When the drops' local soil updates (eqs. 4-6) apply: see :class:`IWDConfig`."""


@dataclasses.dataclass(frozen=True)
class IWDConfig(WalkingConfig):
    """Static sizes and switches of IWD (the defaults are the paper's algorithm).

    Attributes:
      num_agents: drops per iteration (50).
      local_updates: ``"arrived"``: only the drops that reach the goal change the soil, after
        the walk (the IWD_PG paper: "feasible solution removes some soil of graph and therefore
        guides next generation drops"), each arrived drop's moves applied in agent order, then
        move order, over the soil the drops met; ``"while_walking"``: every drop changes the
        soil at every move, stuck ones too, and the drops of an iteration read each other's
        changes (Shah-Hosseini's TSP drops, which all complete a tour).
      backtrack: ours: a drop with no admissible unvisited neighbour backs out to the node it
        came from and tries another way (the Improved Max-Min paper's first ant,
        :mod:`jaxswarm.swarm.walking.backtrack`) instead of stopping; its path is the way
        without the dead ends. Needs ``local_updates="arrived"``.
    """

    num_agents: int = 50
    local_updates: str = "arrived"
    backtrack: bool = False

    def __post_init__(self):
        super().__post_init__()
        if self.local_updates not in LOCAL_UPDATES:
            raise ValueError(f"unknown local_updates {self.local_updates!r}; "
                             f"choose one of {', '.join(LOCAL_UPDATES)}")
        if self.backtrack and self.local_updates != "arrived":
            raise ValueError("backtrack=True needs local_updates='arrived' (backing-out drops "
                             "walk one after another over the soil as it was)")


class IWDParams(NamedTuple):
    """Numbers of IWD (f32 scalars, traced; Shah-Hosseini's standard values in brackets, the
    calibrated defaults in ``DEFAULT_IWD``).

    Attributes:
      alpha, beta: weights of the soil term and of the goal desirability (1, 1; equal, as the
        paper says).
      eps_s: keeps ``f(soil)`` finite (0.01).
      a_v, b_v, c_v: the velocity update (1, 0.01, 1).
      initial_velocity: a drop's velocity at the start (200).
      a_s, b_s, c_s: the soil taken (1, 0.01, 1).
      eps_v: the smallest velocity a time is measured with (1e-4).
      rho_n: the local update's weight (0.9).
      rho_iwd: the global update's weight (0.9).
      initial_soil: every edge's soil at the start (10,000).
      hud_scale: ours: HUD(i, j) is this times the edge's length (1; see :mod:`.soil`).
    """

    alpha: jax.Array
    beta: jax.Array
    eps_s: jax.Array
    a_v: jax.Array
    b_v: jax.Array
    c_v: jax.Array
    initial_velocity: jax.Array
    a_s: jax.Array
    b_s: jax.Array
    c_s: jax.Array
    eps_v: jax.Array
    rho_n: jax.Array
    rho_iwd: jax.Array
    initial_soil: jax.Array
    hud_scale: jax.Array


STANDARD_IWD = default_params(IWDParams, alpha=1.0, beta=1.0, eps_s=0.01, a_v=1.0, b_v=0.01,
                              c_v=1.0, initial_velocity=200.0, a_s=1.0, b_s=0.01, c_s=1.0,
                              eps_v=1e-4, rho_n=0.9, rho_iwd=0.9, initial_soil=10_000.0,
                              hud_scale=1.0)
"""Shah-Hosseini's standard values, which the paper cites; ``eps_v`` and ``hud_scale`` are ours
(the paper's text lost the one and leaves the other open). IWD_PG's defaults, and IWD's before
its calibration."""

DEFAULT_IWD = STANDARD_IWD._replace(**{
    name: np.float32(value) for name, value in dict(
        alpha=3.3951166, beta=3.3951166, rho_n=0.040603284, rho_iwd=0.015212933,
        initial_soil=714.6093, hud_scale=3.5191534).items()})
"""IWD's defaults: the standard values where the paper fixes them (the velocity and soil
updates, the initial velocity, ``eps_s``), and where it leaves them open (alpha = beta, the two
updates' weights, the initial soil, ``hud_scale``) the setting its calibration found
(``tunes/iwd.toml``, ``results/calibration``: on held-out maps at least as good as the standard
values everywhere, a mean gap of 7.28 against 7.84)."""


@dataclasses.dataclass(frozen=True)
class IWDState:
    """Memory of an IWD run (a pytree).

    Attributes:
      key: PRNG key for the next iteration.
      soil: f32[N, K] soil on each directed edge slot.
      best_path: i32[L] best path so far, -1 padded.
      best_cost: f32[] its length (inf before any drop arrived).
    """

    key: jax.Array
    soil: jax.Array
    best_path: jax.Array
    best_cost: jax.Array


jax.tree_util.register_dataclass(
    IWDState, data_fields=["key", "soil", "best_path", "best_cost"], meta_fields=[])


def soil_rule(state: IWDState, before: Graph, after: Graph, old: Task, new: Task,
              params: IWDParams) -> IWDState:
    """IWD's memory rule for a change of the map or the goal: the soil is kept on every edge; an
    edge valid now that was not before starts at ``initial_soil``, as every edge did."""
    new_edges = after.valid_edges() & ~before.valid_edges()
    return dataclasses.replace(state, soil=jnp.where(new_edges, params.initial_soil, state.soil))


def check_iwd(params: IWDParams) -> None:
    """Host-side check of IWD's Params: every value finite and in range.

    Raises:
      ParamError: naming the bad value.
    """
    for name in ("alpha", "beta", "a_v", "c_v", "a_s", "c_s", "initial_soil"):
        check_positive(name, getattr(params, name), allow_zero=True)
    for name in ("eps_s", "b_v", "initial_velocity", "b_s", "eps_v", "rho_n", "hud_scale"):
        check_positive(name, getattr(params, name))
    check_positive("rho_iwd", params.rho_iwd, allow_zero=True)
    for name in ("rho_n", "rho_iwd"):
        if np.any(np.asarray(getattr(params, name)) > 1):
            raise ParamError(name, f"must be at most 1, got {shown(getattr(params, name))}")


def initial_soil(graph: Graph, params: IWDParams) -> jax.Array:
    """f32[N, K] every edge slot's soil at the start, ``initial_soil``."""
    return jnp.full(graph.nbr.shape, params.initial_soil, jnp.float32)


def drop_walk(key, graph: Graph, task: Task, soil, params: IWDParams, *, num_agents: int,
              max_steps: int | None, local_updates: str = "arrived",
              backtrack: bool = False, walker: WalkerOptions = WalkerOptions()) -> Walk:
    """One iteration's drops walking from ``task.start`` over ``soil`` (f32[N, K]) with their
    local updates (``local_updates`` and ``backtrack`` as in :class:`IWDConfig`, ``walker``
    as in :class:`~jaxswarm.swarm.core.WalkingConfig`).

    Returns:
      The :class:`~jaxswarm.swarm.walking.Walk`, its ``memory`` the soil after the local
      updates and its ``state`` f32[A, 2] each drop's velocity and carried soil at its end;
      when only arrived drops change the soil (``local_updates="arrived"``), NaN for the drops
      that did not arrive (their soil is not kept, so their walks are not followed further).
    """
    table = goal_table(graph, task.goal, params)
    budget = step_budget(graph, max_steps)
    if local_updates == "while_walking":
        return walk(key, graph, table, task.start, task.goal, num_agents=num_agents,
                    max_steps=budget, hook=SOIL, memory=soil, hook_params=params,
                    walker=walker)
    if backtrack:
        drops = backtracking_walk(key, graph, soil_choice(table, soil, params), task.start,
                                  task.goal, num_agents=num_agents, max_steps=budget,
                                  implementation=walker.implementation)
    else:
        drops = walk(key, graph, table, task.start, task.goal, num_agents=num_agents,
                     max_steps=budget, hook=SOIL_CHOICE, memory=soil, hook_params=params,
                     walker=walker)
    return _arrived_updates(graph, drops, soil, params)


def _arrived_updates(graph: Graph, drops: Walk, soil, params: IWDParams) -> Walk:
    """``drops`` with the local updates (the velocity update and eqs. 4-5) of those that
    arrived: ``memory`` the soil after them (``soil`` f32[N, K] as the drops met it, each drop's
    moves applied in agent order, then move order), ``state`` f32[A, 2] each drop's velocity
    and carried soil at its end (NaN for a drop that did not arrive). Up to
    :data:`FEW_DROPS` drops one pass over the walks written out at the width that holds the
    arrived drops' moves (:func:`~jaxswarm.swarm.walking.on_walk`, :func:`_arrived_soil`), else
    a fold over the arrived drops (:func:`~jaxswarm.swarm.walking.fold_agents`,
    :func:`_arrived_drop`)."""
    if drops.arrived.shape[-1] > FEW_DROPS:
        lost = jnp.full(drops.arrived.shape, jnp.nan, jnp.float32)
        memory, velocity, carried = fold_agents(_arrived_drop, drops.log, (soil, lost, lost),
                                                (soil, params), graph, used=drops.arrived)
        return drops._replace(memory=memory, state=jnp.stack([velocity, carried], axis=-1))
    memory, velocity, carried = on_walk(_arrived_soil, drops.log, (soil, params, drops.arrived),
                                        graph, used=drops.arrived)
    state = jnp.where(drops.arrived[:, None], jnp.stack([velocity, carried], axis=-1), jnp.nan)
    return drops._replace(memory=memory, state=state)


def _arrived_soil(rows, run, graph: Graph):
    """The local updates along the walks ``rows`` (``(path i32[A, W + 1], slots [A, W])``) of
    one run (``run``: ``(soil f32[N, K] as the drops met it, params, arrived bool[A])``):
    ``(soil f32[N, K], velocity f32[A], carried f32[A])``, the soil after each arrived drop's
    eq. 5 in agent order (:func:`~.soil.arrived_update`; a drop crosses an edge at most once,
    drops after it read its update), each drop's velocity at its end and the soil it carries.
    The soil each move took (eq. 4, :func:`~.soil.walked_soil`) depends on the soil the drops
    met only, so it is computed for all the drops at once; only eq. 5 goes drop by drop (the
    drops that did not arrive change nothing)."""
    path, slots = rows
    soil, params, arrived = run
    taken, velocity = walked_soil(graph, soil, path[:, :-1], slots, params)

    def one(agent, after):
        moved = jnp.where(arrived[agent], slots[agent], -1)
        return arrived_update(graph, after, path[agent, :-1], moved, taken[agent], params)

    after = jax.lax.fori_loop(0, arrived.shape[0], one, soil)
    return after, velocity, ordered_sum(taken, axis=1)


def goal_table(graph: Graph, goal, params: IWDParams) -> jax.Array:
    """f32[N, K] the drops' goal term, ``beta log h(j)`` of each valid slot's neighbour ``j``
    (:func:`~.soil.goal_log_desirability` through
    :func:`~jaxswarm.swarm.walking.edge_table`: ``-inf`` where the edge is not valid now), the
    same numbers. On grids and path maps each slot's column is a shifted slice of the nodes'
    values, not a gather, and ``log d_j`` is computed once a node: built
    as a gather of the nodes' values, XLA:CPU computed ``log d_j`` once a slot, or the table in
    slot-major layout and transposed it in every iteration of a run's loop."""
    if not graph.is_grid:
        return edge_table(graph, params.beta * goal_log_desirability(graph, goal))
    into_goal = _slot_columns(graph, jnp.arange(graph.num_nodes) == goal)
    log_h = _slot_columns(graph, -_log_distance(graph, goal))
    return jnp.where(graph.valid_edges(), params.beta * jnp.where(into_goal, FORCED, log_h),
                     -jnp.inf)


def _log_distance(graph: Graph, goal) -> jax.Array:
    """f32[N] :func:`~jaxswarm.swarm.walking.goal_log_distance` (``log d_j``, 0 where ``d_j`` is
    0), the same bits: ``jnp.linalg.norm`` of a node's two coordinate differences adds their two
    squares (in either order the same float), and so does this, without the norm's reduction
    (a slow kernel over an axis of two)."""
    apart = graph.xy - graph.xy[goal]
    to_goal = jnp.sqrt(apart[:, 0] * apart[:, 0] + apart[:, 1] * apart[:, 1])
    return jnp.log(jnp.where(to_goal > 0, to_goal, 1.0))


def _slot_columns(graph: Graph, values: jax.Array) -> jax.Array:
    """[N, K]: ``values[nbr[i, k]]`` of ``values`` ([N], any dtype) on a grid or path map, each
    slot's column a shifted slice of the padded values (some value of the array where slot k has
    no neighbour: mask it by the valid edges), as
    :func:`~jaxswarm.swarm.walking.neighbour_slots` builds them slot-major."""
    offsets = [int(offset) for offset in slot_offsets(graph)]
    margin = max(abs(offset) for offset in offsets)
    padded = jnp.pad(values, (margin, margin), mode="edge")
    n = graph.num_nodes
    return jnp.stack([padded[margin + offset:margin + offset + n] for offset in offsets],
                     axis=1)


def _arrived_drop(after, drop, row, run, graph: Graph):
    """The velocity update and eqs. 4-5 along the walk of drop ``drop`` (i32[], ``row`` its
    ``(path i32[W + 1], slots [W])``) that arrived, its soil taken from ``run``'s soil at the
    start of the walk (``(soil f32[N, K], params)``): ``after`` (``(soil f32[N, K], velocity
    f32[A], carried f32[A])``, the drops before it applied) with its local updates applied and
    its velocity and carried soil written (:func:`~.soil.walked_soil`,
    :func:`~.soil.arrived_update`); ``after`` as it was for a ``drop`` past the last."""
    path, slots = row
    soil, params = run
    after_soil, velocity, carried = after
    taken, velocity_at_end = walked_soil(graph, soil, path[None, :-1], slots[None], params)
    return (arrived_update(graph, after_soil, path[:-1], slots, taken[0], params),
            velocity.at[drop].set(velocity_at_end[0], mode="drop"),
            carried.at[drop].set(ordered_sum(taken, axis=1)[0], mode="drop"))


def soil_choice(table, soil, params: IWDParams) -> DepthFirstRule:
    """The drops' transition rule (eqs. 1-3) over fixed ``soil`` (f32[N, K]) and ``table``
    (f32[N, K], the goal term) as a :class:`~jaxswarm.swarm.walking.backtrack.DepthFirstRule`:
    over the admissible slots, the row plus :func:`~.soil.choice_log_weights`."""
    return DepthFirstRule(table=table, soil=soil, hook=SOIL_CHOICE, hook_params=params)


def soil_after_best(graph: Graph, drops: Walk, path_of: Callable, costs,
                    params: IWDParams) -> jax.Array:
    """f32[N, K] the soil after ``drops`` walked and the global update of the shortest of their
    paths (``path_of(a)``: i32[L] drop ``a``'s path; ``costs`` f32[A], inf for a drop that did
    not arrive); no global update when none arrived."""
    winner = jnp.argmin(costs)
    return jnp.where(jnp.isfinite(costs[winner]),
                     global_update(graph, drops.memory, path_of(winner),
                                   drops.state[winner, CARRIED], params),
                     drops.memory)


def _soil_after_walked_best(graph: Graph, drops: Walk, costs, params: IWDParams) -> jax.Array:
    """:func:`soil_after_best` of the drops' walked paths (``costs`` f32[A], inf for a drop that
    did not arrive), the same bits. On grids and path maps the best drop's moves are read from
    the walk's log at the width that holds them (:func:`~jaxswarm.swarm.walking.fold_agents`
    over that one drop), their slots the log's, not a path written out at the step budget and
    its slots searched again (a lattice neighbour has one slot)."""
    if not graph.is_grid:
        return soil_after_best(graph, drops, drops.agent_path, costs, params)
    winner = jnp.argmin(costs)
    best = (jnp.arange(costs.shape[0]) == winner) & jnp.isfinite(costs[winner])
    return fold_agents(_global_move_update, drops.log, drops.memory,
                       (drops.state[winner, CARRIED], params), graph, used=best)


def _global_move_update(soil, drop, row, run, graph: Graph):
    """:func:`~.soil.global_update` of the walk of drop ``drop`` (i32[], ``row`` its ``(path
    i32[W + 1], slots [W])``, ``W`` any width that holds its moves), which carried ``run``'s
    soil (``(carried f32[], params)``): ``soil`` (f32[N, K]) after it; ``soil`` as it was for a
    ``drop`` past the last (a row of no moves)."""
    path, slots = row
    carried, params = run
    on_path = slots >= 0
    rows = jnp.where(on_path, path[:-1], graph.num_nodes)
    columns = jnp.maximum(slots, 0).astype(jnp.int32)
    share = carried / jnp.maximum(jnp.sum(path >= 0) - 1, 1)
    updated = (1.0 + params.rho_iwd) * soil[jnp.minimum(rows, graph.num_nodes - 1), columns] \
        - params.rho_iwd * share
    return soil.at[rows, columns].set(updated, mode="drop")


def soil_per_node(state) -> jax.Array:
    """f32[N] the mean soil on each node's edge slots (the figures' view of the memory)."""
    return ordered_sum(state.soil) / state.soil.shape[-1]


SOIL_LABEL = "soil on a node's edges (mean)"
"""What :func:`soil_per_node` shows, for colorbars."""


def build_iwd(config: IWDConfig) -> Swarm:
    """Intelligent Water Drops (see the module docstring), with :class:`IWDParams`."""
    def init(key, graph: Graph, task: Task, params: IWDParams) -> IWDState:
        length = step_budget(graph, config.max_steps) + 1
        return IWDState(key=key, soil=initial_soil(graph, params),
                        best_path=jnp.full((length,), -1, jnp.int32),
                        best_cost=jnp.float32(jnp.inf))

    def step(state: IWDState, graph: Graph, task: Task, params: IWDParams):
        key, walk_key = jax.random.split(state.key)
        drops = drop_walk(walk_key, graph, task, state.soil, params,
                          num_agents=config.num_agents, max_steps=config.max_steps,
                          local_updates=config.local_updates, backtrack=config.backtrack,
                          walker=config.walker)
        best_path, best_cost, info = keep_best(drops, state.best_path, state.best_cost)
        costs = jnp.where(drops.arrived, drops.length, jnp.inf)
        soil = _soil_after_walked_best(graph, drops, costs, params)
        return IWDState(key=key, soil=soil, best_path=best_path, best_cost=best_cost), info

    return Swarm(name="iwd", config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=DEFAULT_IWD, check_params=check_iwd)
