"""Ant colonies on the lockstep walker: Ant System, ACO* and Max-Min ACO.

Pheromone ``tau`` lives on edges (``f32[N, K]``, one value per neighbour slot, kept equal on an
edge and its reverse). Each iteration all ants walk from the start, choosing the next node ``j``
with probability proportional to

    tau_ij^alpha * eta_ij^beta / d_j^alpha_goal                 (RFD paper eq. 7, general form)

with ``eta_ij = 1 / length(i, j)`` and ``d_j`` the straight-line distance from ``j`` to the goal
(ACO* only; there the goal is taken whenever adjacent). Then

* Ant System: evaporation ``tau <- (1 - rho) tau`` (eq. 9) and, for every ant that reached the
  goal, a deposit ``Q / f(S)`` on each edge of its path ``S`` of length ``f(S)`` (eq. 8);
* Max-Min ACO: evaporation, a deposit by the best ant only (this iteration's or the best so far,
  a config switch), and ``tau`` kept within ``[tau_min, tau_max]``;
* Improved Max-Min ACO (the Max-Min ACO paper): ``eta_ij`` is the desirability of the move's
  direction given the direction of the goal, ``(1 + cos angle) / 2``; pheromone starts at
  ``tau0`` (one in the paper); the Bug2-like first ant (:mod:`jaxswarm.swarm.bug2`, the limit of
  a large heuristic weight) sets the first best path; after each population evaporation is
  floored at ``tau_min`` (the paper's ``minpher``) and the best path so far gains ``q`` (its
  ``delta``) on every edge.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.graph import Graph, straight_line
from jaxswarm.paths import Solution, step_slots
from jaxswarm.swarm.core import Swarm, Task, check_positive, check_sizes, keep_best, register
from jaxswarm.swarm.bug2 import bug2_path, direction_cosine
from jaxswarm.swarm.walk import FORCED, edge_table, step_budget, walk

DIRECTION_FLOOR = 1e-3
"""Added to the direction desirability so that a move straight away from the goal stays possible."""


@dataclasses.dataclass(frozen=True)
class ACOConfig:
    """Static sizes and switches.

    Attributes:
      num_agents: ants per iteration.
      max_steps: step budget of one walk; None = N - 1 on general graphs, min(N - 1, 8 (H + W))
        on grids.
      goal_heuristic: ACO*: divide each weight by ``d_j ** alpha_goal`` (goal taken when adjacent).
      max_min: Max-Min ACO (best ant deposits, pheromone bounds) instead of Ant System.
      global_best: Max-Min only: the best path so far deposits instead of this iteration's best.
      improved: Improved Max-Min ACO (direction heuristic, Bug2-like first ant, floor only).
      devices: spread each walk's ants over this many devices (see
        :func:`jaxswarm.swarm.walk.walk`); results are the same as with one.
    """

    num_agents: int = 256
    max_steps: int | None = None
    goal_heuristic: bool = False
    max_min: bool = False
    global_best: bool = False
    improved: bool = False
    devices: int = 1

    def __post_init__(self):
        check_sizes(self.num_agents, self.max_steps, self.devices)
        if self.global_best and not self.max_min:
            raise ValueError("global_best is a Max-Min ACO switch (max_min=True)")


class ACOParams(NamedTuple):
    """Numbers of the ant colonies (f32 scalars, traced).

    Attributes:
      rho: evaporation rate in (0, 1].
      q: Q, the deposit numerator (a path of length f deposits Q / f per edge).
      alpha: pheromone exponent.
      beta: exponent of eta = 1 / edge length.
      alpha_goal: ACO* exponent of the goal distance (unused otherwise).
      tau0: initial pheromone on every edge.
      tau_min, tau_max: Max-Min bounds (unused by Ant System).
    """

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    alpha_goal: jax.Array
    tau0: jax.Array
    tau_min: jax.Array
    tau_max: jax.Array


DEFAULT_ACO = ACOParams(*(np.float32(v) for v in (0.1, 1.0, 1.0, 1.0, 50.0, 1.0, 0.01, 10.0)))
DEFAULT_IMPROVED_ACO = DEFAULT_ACO._replace(q=np.float32(0.1))
"""Improved Max-Min ACO: delta = rho * tau0, so the best path's pheromone stays at tau0 while
every other edge decays to the floor (on alley20, 15/20 runs within 5 % against 9/20 with q = 1)."""


@dataclasses.dataclass(frozen=True)
class ACOState:
    """Memory of an ant colony run (a pytree).

    Attributes:
      key: PRNG key for the next iteration.
      pheromone: f32[N, K] tau on each edge slot (equal on an edge and its reverse).
      best_path: i32[L] best path found so far, -1 padded.
      best_cost: f32[] its length (inf before any ant arrived).
    """

    key: jax.Array
    pheromone: jax.Array
    best_path: jax.Array
    best_cost: jax.Array


jax.tree_util.register_dataclass(
    ACOState, data_fields=["key", "pheromone", "best_path", "best_cost"], meta_fields=[])


def transition_rule(config: ACOConfig, graph: Graph, task: Task, pheromone, params):
    """f32[N, K] log-weight of every edge (the walker's table): eq. 7 in its general form."""
    heads = jnp.where(graph.nbr >= 0, graph.nbr, 0)
    if config.improved:
        eta = (1.0 + direction_cosine(graph, task.goal)) / 2.0 + DIRECTION_FLOOR
    else:
        eta = 1.0 / jnp.where(graph.nbr >= 0, graph.cost, 1.0)
    logw = params.alpha * jnp.log(pheromone) + params.beta * jnp.log(eta)
    if config.goal_heuristic:
        to_goal = straight_line(graph, task.goal)
        logw = logw - params.alpha_goal * jnp.log(jnp.where(to_goal > 0, to_goal, 1.0))[heads]
        logw = jnp.where(heads == task.goal, FORCED, logw)
    return edge_table(graph, logw)


def _deposit(graph: Graph, pheromone, nodes, slots, amount):
    """Add ``amount[a]`` on every edge (nodes[a, t], slots[a, t]) and on its reverse edge."""
    moved = slots >= 0
    rows = jnp.where(moved, nodes, 0)
    cols = jnp.maximum(slots, 0).astype(jnp.int32)
    value = jnp.where(moved, amount[:, None], 0.0)
    heads = graph.nbr[rows, cols]
    back = graph.rev[rows, cols]
    pheromone = pheromone.at[rows, cols].add(value)
    # One-way edges have no reverse slot: their index n is out of bounds and dropped.
    return pheromone.at[jnp.where(back >= 0, heads, graph.num_nodes),
                        jnp.maximum(back, 0)].add(value, mode="drop")


def _reinforce(graph: Graph, pheromone, path, amount):
    """Add the scalar ``amount`` on every edge of one padded path, both directions."""
    return _deposit(graph, pheromone, path[None, :-1], step_slots(graph, path)[None],
                    amount[None])


def _build(config: ACOConfig, name: str) -> Swarm:
    def init(key, graph: Graph, task: Task, params) -> ACOState:
        length = step_budget(graph, config.max_steps) + 1
        pheromone = jnp.full(graph.nbr.shape, params.tau0, jnp.float32)
        if not config.improved:
            return ACOState(key=key, pheromone=pheromone,
                            best_path=jnp.full((length,), -1, jnp.int32),
                            best_cost=jnp.float32(jnp.inf))
        path, cost, found = bug2_path(graph, task.start, task.goal)
        fits = found & (jnp.sum(path >= 0) <= length)  # a longer first path cannot be stored
        path = jnp.where(fits, jnp.pad(path, (0, max(length - path.shape[0], 0)),
                                       constant_values=-1)[:length], -1)
        pheromone = _reinforce(graph, pheromone, path, jnp.where(fits, params.q, 0.0))
        return ACOState(key=key, pheromone=pheromone, best_path=path,
                        best_cost=jnp.where(fits, cost, jnp.inf).astype(jnp.float32))

    def step(state: ACOState, graph: Graph, task: Task, params):
        key, walk_key = jax.random.split(state.key)
        table = transition_rule(config, graph, task, state.pheromone, params)
        ants = walk(walk_key, graph, table, task.start, task.goal,
                    num_agents=config.num_agents,
                    max_steps=step_budget(graph, config.max_steps), devices=config.devices)
        # The Improved Max-Min ACO keeps the latest of equally short paths (its "<=").
        best_path, best_cost, info = keep_best(ants, state.best_path, state.best_cost,
                                               ties=config.improved)
        pheromone = (1.0 - params.rho) * state.pheromone
        if config.improved:
            pheromone = _reinforce(graph, jnp.maximum(pheromone, params.tau_min), best_path,
                                   jnp.where(jnp.isfinite(best_cost), params.q, 0.0))
        elif not config.max_min:
            pheromone = _deposit(graph, pheromone, ants.path[:, :-1], ants.slots,
                                 jnp.where(ants.arrived, params.q / ants.length, 0.0))
        else:
            winner = jnp.argmin(jnp.where(ants.arrived, ants.length, jnp.inf))
            path, cost = ((best_path, best_cost) if config.global_best
                          else (ants.path[winner], info.iteration_cost))
            amount = jnp.where(jnp.isfinite(cost), params.q / cost, 0.0)
            pheromone = jnp.clip(_reinforce(graph, pheromone, path, amount), params.tau_min,
                                 params.tau_max)
        return ACOState(key=key, pheromone=pheromone, best_path=best_path,
                        best_cost=best_cost), info

    def best(state: ACOState) -> Solution:
        return Solution(path=state.best_path, cost=state.best_cost,
                        found=jnp.isfinite(state.best_cost))

    return Swarm(name=name, config=config, init=init, step=step, best=best,
                 default_params=DEFAULT_IMPROVED_ACO if config.improved else DEFAULT_ACO,
                 check_params=_check,
                 memory=lambda state: state.pheromone.sum(axis=-1),
                 memory_label="pheromone on a node's edges")


@register("ant_system")
def ant_system(num_agents: int = 256, max_steps: int | None = None, devices: int = 1) -> Swarm:
    """Ant System (RFD paper eqs. 7-9)."""
    return _build(ACOConfig(num_agents, max_steps, devices=devices), "ant_system")


@register("aco_star")
def aco_star(num_agents: int = 256, max_steps: int | None = None, devices: int = 1) -> Swarm:
    """ACO*: Ant System with the goal-distance heuristic ``1 / d_j ** alpha_goal``."""
    return _build(ACOConfig(num_agents, max_steps, goal_heuristic=True, devices=devices),
                  "aco_star")


@register("max_min_aco")
def max_min_aco(num_agents: int = 256, max_steps: int | None = None,
                global_best: bool = False, devices: int = 1) -> Swarm:
    """Max-Min ACO: only the iteration-best (or, with ``global_best``, the best-so-far) path
    deposits, and pheromone stays within [tau_min, tau_max]."""
    return _build(ACOConfig(num_agents, max_steps, max_min=True, global_best=global_best,
                            devices=devices), "max_min_aco")


@register("improved_max_min_aco")
def improved_max_min_aco(num_agents: int = 50, max_steps: int | None = None,
                         devices: int = 1) -> Swarm:
    """Improved Max-Min ACO (the Max-Min ACO paper): direction heuristic, Bug2-like first ant,
    evaporation floored at ``tau_min`` and ``q`` added on the best path after each population
    of ``num_agents`` ants (50 in the paper)."""
    return _build(ACOConfig(num_agents, max_steps, improved=True, devices=devices),
                  "improved_max_min_aco")


def _check(params: ACOParams) -> None:
    check_positive("rho", params.rho)
    if float(params.rho) > 1:
        raise ValueError(f"rho must be at most 1, got {float(params.rho)}")
    check_positive("q", params.q)
    check_positive("alpha", params.alpha, allow_zero=True)
    check_positive("beta", params.beta, allow_zero=True)
    check_positive("alpha_goal", params.alpha_goal, allow_zero=True)
    check_positive("tau0", params.tau0)
    check_positive("tau_min", params.tau_min)
    check_positive("tau_max", params.tau_max)
    if float(params.tau_min) > float(params.tau_max):
        raise ValueError(f"tau_min ({float(params.tau_min)}) exceeds tau_max "
                         f"({float(params.tau_max)})")
