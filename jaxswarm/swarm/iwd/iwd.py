"""Intelligent Water Drops (``iwd``): the IWD_PG paper's baseline, Shah-Hosseini's IWD on a grid.

Each iteration ``num_agents`` drops leave the start with the initial velocity and no soil, and
walk to the goal never revisiting a node (the visited set VC). At every step each drop chooses by
the soil it finds and the goal's nearness, speeds up, takes soil from the edge it crosses and
carries it (:mod:`.soil`, through the walker's per-step hook: the soil changes while the drops
walk). After the iteration the path of its best drop gets the global update, and the best path so
far is kept. The paper's nodes sit at cell corners with 8 moves and Euclidean lengths; on our
grids the cells are the nodes, the same kind of graph.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.core import (Swarm, SwarmConfig, Task, best_solution, check_positive,
                                 default_params, keep_best)
from jaxswarm.swarm.iwd.soil import CARRIED, SOIL, global_update, goal_log_desirability
from jaxswarm.swarm.walking import Walk, edge_table, step_budget, walk
from jaxswarm.world.graph import Graph


@dataclasses.dataclass(frozen=True)
class IWDConfig(SwarmConfig):
    """Static sizes of IWD: ``num_agents`` drops per iteration (50 by default)."""

    num_agents: int = 50


class IWDParams(NamedTuple):
    """Numbers of IWD (f32 scalars, traced; the standard values in brackets).

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


DEFAULT_IWD = default_params(IWDParams, alpha=1.0, beta=1.0, eps_s=0.01, a_v=1.0, b_v=0.01,
                             c_v=1.0, initial_velocity=200.0, a_s=1.0, b_s=0.01, c_s=1.0,
                             eps_v=1e-4, rho_n=0.9, rho_iwd=0.9, initial_soil=10_000.0)
"""Shah-Hosseini's standard values, which the paper cites; ``eps_v`` is ours (the paper's text
lost it)."""


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
      ValueError: naming the bad value.
    """
    for name in ("alpha", "beta", "a_v", "c_v", "a_s", "c_s", "initial_soil"):
        check_positive(name, getattr(params, name), allow_zero=True)
    for name in ("eps_s", "b_v", "initial_velocity", "b_s", "eps_v", "rho_n"):
        check_positive(name, getattr(params, name))
    check_positive("rho_iwd", params.rho_iwd, allow_zero=True)
    for name in ("rho_n", "rho_iwd"):
        if np.any(np.asarray(getattr(params, name)) > 1):
            raise ValueError(f"{name} must be at most 1, got {getattr(params, name)}")


def initial_soil(graph: Graph, params: IWDParams) -> jax.Array:
    """f32[N, K] every edge slot's soil at the start, ``initial_soil``."""
    return jnp.full(graph.nbr.shape, params.initial_soil, jnp.float32)


def drop_walk(key, graph: Graph, task: Task, soil, params: IWDParams, *, num_agents: int,
              max_steps: int | None) -> Walk:
    """One iteration's drops walking from ``task.start`` over ``soil`` (f32[N, K]), which they
    change as they go (the walker's soil hook); the Walk's ``memory`` is the soil after them."""
    table = edge_table(graph, params.beta * goal_log_desirability(graph, task.goal))
    return walk(key, graph, table, task.start, task.goal, num_agents=num_agents,
                max_steps=step_budget(graph, max_steps), hook=SOIL, memory=soil,
                hook_params=params)


def soil_after_best(graph: Graph, drops: Walk, paths, costs, params: IWDParams) -> jax.Array:
    """f32[N, K] the soil after ``drops`` walked and the global update of the shortest of their
    ``paths`` (i32[A, L]; ``costs`` f32[A], inf for a drop that did not arrive); no global
    update when none arrived."""
    winner = jnp.argmin(costs)
    return jnp.where(jnp.isfinite(costs[winner]),
                     global_update(graph, drops.memory, paths[winner],
                                   drops.state[winner, CARRIED], params),
                     drops.memory)


def soil_per_node(state) -> jax.Array:
    """f32[N] the mean soil on each node's edge slots (the figures' view of the memory)."""
    return jnp.mean(state.soil, axis=-1)


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
                          num_agents=config.num_agents, max_steps=config.max_steps)
        best_path, best_cost, info = keep_best(drops, state.best_path, state.best_cost)
        costs = jnp.where(drops.arrived, drops.length, jnp.inf)
        soil = soil_after_best(graph, drops, drops.path, costs, params)
        return IWDState(key=key, soil=soil, best_path=best_path, best_cost=best_cost), info

    return Swarm(name="iwd", config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=DEFAULT_IWD, check_params=check_iwd,
                 memory=soil_per_node, memory_label=SOIL_LABEL, adapt=soil_rule)
