"""Ant colonies on the lockstep walker: Ant System and ACO* (the RFD paper), Max-Min ACO and
Improved Max-Min ACO (the Max-Min ACO paper).

Pheromone ``tau`` lives on edges (``f32[N, K]``, one value per neighbour slot, kept equal on an
edge and its reverse). Each iteration (a population) all ants walk from the start, never
revisiting a node, choosing the next node ``j`` with probability proportional to

    tau_ij^alpha * eta_ij^beta / d_j^alpha_goal

* ``ant_system`` (RFD paper eqs. 7-9): ``tau_ij`` alone (eq. 7: ``alpha = 1``, ``beta = 0``;
  ``eta_ij = 1 / length(i, j)`` with ``beta > 0`` is an option). After the walk, evaporation
  ``tau <- (1 - rho) tau`` (eq. 9) and, for every ant that reached the goal, ``Q / f(S)`` on each
  edge of its path ``S`` of length ``f(S)`` (eq. 8).
* ``aco_star`` (the RFD paper's ACO*): Ant System divided by ``d_j ** alpha_goal``, the
  straight-line distance from ``j`` to the goal "as in the denominator of eq. 6"; it divides by
  ``d_goal = 0``, so the goal is taken whenever adjacent.
* ``max_min_aco`` (as the Max-Min ACO paper uses it, after Han et al.): ``eta_ij = 1 /
  length(i, j)`` weighted evenly with the pheromone (``alpha = beta = 1``); after each
  population evaporation, a floor ``tau_min`` ("not allowed to decrease below a minimum
  level"), and ``Q / f`` on the path of the population's best ant. Switches of ours:
  ``global_best`` (the best path so far deposits instead) and ``upper_bound`` (also cap
  ``tau`` at ``tau_max``, as in Stuetzle and Hoos's MMAS; off by default).
* ``improved_max_min_aco`` (the paper's Algorithm 1): ``eta_ij`` is the desirability of the
  move's direction given the goal's. The paper gives no formula; ours is
  ``(1 + cos angle) / 2 + DIRECTION_FLOOR``, 1 straight at the goal, falling to the floor
  straight away from it. Pheromone starts at ``tau0`` (one in the paper). The first ant of the
  first population walks with heuristic weight ``beta_first`` (5) and a memory of where it has
  been (:mod:`jaxswarm.swarm.bug2`): its path is the first best path. Every later ant walks with
  ``alpha = beta = 1``. After each population: evaporation, the floor ``tau_min`` (the paper's
  ``minpher``), and ``q`` (its ``delta``) added on every edge of the best path so far, which a
  path as short replaces (the paper's ``<=``). Our walker runs the first ant before the first
  population of ``num_agents`` ants, so that population has one ant more than the others.
  Switch: ``first_ant="greedy"`` makes the first ant always take its most likely move (the
  deterministic depth-first ant of jaxswarm 0.1.0).

Pheromone updates of the Max-Min colonies follow Algorithm 1's order: evaporate, floor,
reinforce.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.graph import Graph, straight_line
from jaxswarm.paths import step_slots
from jaxswarm.swarm.bug2 import direction_cosine, first_ant_path
from jaxswarm.swarm.core import (Swarm, SwarmConfig, Task, best_solution, check_positive,
                                 keep_best)
from jaxswarm.swarm.walk import FORCED, edge_table, step_budget, walk

DIRECTION_FLOOR = 1e-3
"""Added to the direction desirability so that a move straight away from the goal stays possible."""

FIRST_ANTS = ("weighted", "greedy")
"""How Improved Max-Min ACO's first ant chooses among its admissible moves: drawn by its weights
(the paper), or always the most likely one."""


AntSystemConfig = SwarmConfig
"""Ant System and ACO* have only the sizes (``num_agents``: ants per iteration)."""


@dataclasses.dataclass(frozen=True)
class MaxMinConfig(SwarmConfig):
    """Static switches of Max-Min ACO (the defaults are the paper's use of it).

    Attributes:
      global_best: ours: the best path so far deposits instead of the population's best.
      upper_bound: ours: also keep ``tau`` at most ``tau_max``.
    """

    global_best: bool = False
    upper_bound: bool = False


@dataclasses.dataclass(frozen=True)
class ImprovedConfig(SwarmConfig):
    """Static switches of Improved Max-Min ACO, whose populations are of 50 ants (the paper's).

    Attributes:
      first_ant: one of ``FIRST_ANTS``.
    """

    num_agents: int = 50
    first_ant: str = "weighted"

    def __post_init__(self):
        super().__post_init__()
        if self.first_ant not in FIRST_ANTS:
            raise ValueError(f"unknown first_ant {self.first_ant!r}; "
                             f"choose one of {', '.join(FIRST_ANTS)}")


class AntSystemParams(NamedTuple):
    """Numbers of Ant System (f32 scalars, traced).

    Attributes:
      rho: evaporation rate in (0, 1] (eq. 9).
      q: Q, the deposit numerator (eq. 8: a path of length f deposits Q / f per edge).
      alpha: pheromone exponent (1 in eq. 7).
      beta: exponent of eta = 1 / edge length (0 in eq. 7).
      tau0: initial pheromone on every edge.
    """

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    tau0: jax.Array


class ACOStarParams(NamedTuple):
    """Numbers of ACO*: Ant System's and ``alpha_goal``, the exponent of the goal distance."""

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    alpha_goal: jax.Array
    tau0: jax.Array


class MaxMinParams(NamedTuple):
    """Numbers of Max-Min ACO: Ant System's, the floor ``tau_min`` and the cap ``tau_max``
    (read only with ``upper_bound``)."""

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    tau0: jax.Array
    tau_min: jax.Array
    tau_max: jax.Array


class ImprovedParams(NamedTuple):
    """Numbers of Improved Max-Min ACO.

    Attributes:
      rho: evaporation rate in (0, 1].
      q: delta, added on every edge of the best path after each population.
      alpha: pheromone exponent of the later ants (1).
      beta: heuristic exponent of the later ants (1).
      beta_first: heuristic exponent of the first ant (5, the paper's ``hweight``).
      tau0: initial pheromone (1).
      tau_min: the floor (the paper's ``minpher``).
    """

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    beta_first: jax.Array
    tau0: jax.Array
    tau_min: jax.Array


def _f32(params_type, **values):
    # NumPy scalars: importing the module must not start JAX's backend (jaxswarm.cpu).
    return params_type(**{name: np.float32(value) for name, value in values.items()})


DEFAULT_ANT_SYSTEM = _f32(AntSystemParams, rho=0.1, q=1.0, alpha=1.0, beta=0.0, tau0=1.0)
DEFAULT_ACO_STAR = _f32(ACOStarParams, rho=0.1, q=1.0, alpha=1.0, beta=0.0, alpha_goal=50.0,
                        tau0=1.0)
DEFAULT_MAX_MIN = _f32(MaxMinParams, rho=0.1, q=1.0, alpha=1.0, beta=1.0, tau0=1.0,
                       tau_min=0.01, tau_max=10.0)
DEFAULT_IMPROVED = _f32(ImprovedParams, rho=0.1, q=0.1, alpha=1.0, beta=1.0, beta_first=5.0,
                        tau0=1.0, tau_min=0.01)
"""The papers give alpha, beta, beta_first and tau0 (eq. 7; Algorithm 1); the rest are ours.
Improved: delta = rho * tau0, so the best path's pheromone stays at tau0 while every other edge
decays to the floor."""


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


def transition_rule(graph: Graph, task: Task, pheromone, params, *, direction: bool = False,
                    goal_distance: bool = False, beta=None):
    """f32[N, K] log-weight table ``alpha log tau + beta log eta (- alpha_goal log d_j)``.

    Args:
      graph, task: the map and the goal.
      pheromone: f32[N, K] tau.
      params: the colony's Params (``alpha``, ``beta``; ``alpha_goal`` with ``goal_distance``).
      direction: eta is the direction desirability (Improved Max-Min) instead of 1 / length.
      goal_distance: ACO*: divide by ``d_j ** alpha_goal``, the goal forced whenever adjacent.
      beta: the heuristic exponent, if not ``params.beta`` (the Improved first ant's).
    """
    heads = jnp.where(graph.nbr >= 0, graph.nbr, 0)
    if direction:
        eta = (1.0 + direction_cosine(graph, task.goal)) / 2.0 + DIRECTION_FLOOR
    else:
        eta = 1.0 / jnp.where(graph.nbr >= 0, graph.cost, 1.0)
    beta = params.beta if beta is None else beta
    logw = params.alpha * jnp.log(pheromone) + beta * jnp.log(eta)
    if goal_distance:
        to_goal = straight_line(graph, task.goal)
        logw = logw - params.alpha_goal * jnp.log(jnp.where(to_goal > 0, to_goal, 1.0))[heads]
        logw = jnp.where(heads == task.goal, FORCED, logw)
    return edge_table(graph, logw)


def deposit(graph: Graph, pheromone, nodes, slots, amount):
    """f32[N, K] ``pheromone`` with ``amount[a]`` added on every edge (nodes[a, t], slots[a, t])
    (i32[A, T], -1 slots skipped) and on its reverse edge."""
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


def reinforce(graph: Graph, pheromone, path, amount):
    """f32[N, K] ``pheromone`` with the scalar ``amount`` added on every edge of one padded path
    (i32[L]), both directions."""
    return deposit(graph, pheromone, path[None, :-1], step_slots(graph, path)[None],
                   amount[None])


def _colony(name: str, config, *, default_params, update, init_best=None, direction=False,
            goal_distance=False, ties=False) -> Swarm:
    """A colony Swarm: walk, keep the best, then ``update(graph, pheromone, ants, best_path,
    best_cost, info, params) -> pheromone``. ``init_best(key, graph, task, pheromone, params)``
    gives a first best path (i32[L], cost) before the first population."""
    def init(key, graph: Graph, task: Task, params) -> ACOState:
        length = step_budget(graph, config.max_steps) + 1
        pheromone = jnp.full(graph.nbr.shape, params.tau0, jnp.float32)
        best_path, best_cost = jnp.full((length,), -1, jnp.int32), jnp.float32(jnp.inf)
        if init_best is not None:
            key, first_key = jax.random.split(key)
            best_path, best_cost = init_best(first_key, graph, task, pheromone, params, length)
        return ACOState(key=key, pheromone=pheromone, best_path=best_path, best_cost=best_cost)

    def step(state: ACOState, graph: Graph, task: Task, params):
        key, walk_key = jax.random.split(state.key)
        table = transition_rule(graph, task, state.pheromone, params, direction=direction,
                                goal_distance=goal_distance)
        ants = walk(walk_key, graph, table, task.start, task.goal,
                    num_agents=config.num_agents,
                    max_steps=step_budget(graph, config.max_steps), devices=config.devices)
        best_path, best_cost, info = keep_best(ants, state.best_path, state.best_cost,
                                               ties=ties)
        pheromone = update(graph, state.pheromone, ants, best_path, best_cost, info, params)
        return ACOState(key=key, pheromone=pheromone, best_path=best_path,
                        best_cost=best_cost), info

    return Swarm(name=name, config=config, init=jax.jit(init), step=jax.jit(step),
                 best=best_solution, default_params=default_params, check_params=_check,
                 memory=lambda state: state.pheromone.sum(axis=-1),
                 memory_label="pheromone on a node's edges")


def _ant_system_update(graph, pheromone, ants, best_path, best_cost, info, params):
    """Eq. 9, then eq. 8 for every ant that arrived."""
    return deposit(graph, (1.0 - params.rho) * pheromone, ants.path[:, :-1], ants.slots,
                   jnp.where(ants.arrived, params.q / ants.length, 0.0))


def build_ant_system(config: AntSystemConfig) -> Swarm:
    """Ant System (RFD paper eqs. 7-9), with :class:`AntSystemParams`."""
    return _colony("ant_system", config, default_params=DEFAULT_ANT_SYSTEM,
                   update=_ant_system_update)


def build_aco_star(config: AntSystemConfig) -> Swarm:
    """ACO*: Ant System with the goal-distance heuristic, with :class:`ACOStarParams`."""
    return _colony("aco_star", config, default_params=DEFAULT_ACO_STAR,
                   update=_ant_system_update, goal_distance=True)


def build_max_min_aco(config: MaxMinConfig) -> Swarm:
    """Max-Min ACO as the Max-Min ACO paper uses it, with :class:`MaxMinParams`."""
    def update(graph, pheromone, ants, best_path, best_cost, info, params):
        if config.global_best:
            path, cost = best_path, best_cost
        else:
            winner = jnp.argmin(jnp.where(ants.arrived, ants.length, jnp.inf))
            path, cost = ants.path[winner], info.iteration_cost
        pheromone = jnp.maximum((1.0 - params.rho) * pheromone, params.tau_min)
        pheromone = reinforce(graph, pheromone, path,
                              jnp.where(jnp.isfinite(cost), params.q / cost, 0.0))
        return jnp.minimum(pheromone, params.tau_max) if config.upper_bound else pheromone

    return _colony("max_min_aco", config, default_params=DEFAULT_MAX_MIN, update=update)


def build_improved_max_min_aco(config: ImprovedConfig) -> Swarm:
    """Improved Max-Min ACO (the Max-Min ACO paper's Algorithm 1), with :class:`ImprovedParams`."""
    def init_best(key, graph, task, pheromone, params, length):
        table = transition_rule(graph, task, pheromone, params, direction=True,
                                beta=params.beta_first)
        path, cost, found = first_ant_path(key, graph, table, task.start, task.goal,
                                           greedy=config.first_ant == "greedy")
        fits = found & (jnp.sum(path >= 0) <= length)  # a longer first path cannot be stored
        path = jnp.pad(path, (0, max(length - path.shape[0], 0)), constant_values=-1)[:length]
        return jnp.where(fits, path, -1), jnp.where(fits, cost, jnp.inf).astype(jnp.float32)

    def update(graph, pheromone, ants, best_path, best_cost, info, params):
        pheromone = jnp.maximum((1.0 - params.rho) * pheromone, params.tau_min)
        return reinforce(graph, pheromone, best_path,
                         jnp.where(jnp.isfinite(best_cost), params.q, 0.0))

    return _colony("improved_max_min_aco", config, default_params=DEFAULT_IMPROVED,
                   update=update, init_best=init_best, direction=True, ties=True)


_RULES = {"rho": "positive", "q": "positive", "alpha": "non-negative", "beta": "non-negative",
          "beta_first": "non-negative", "alpha_goal": "non-negative", "tau0": "positive",
          "tau_min": "positive", "tau_max": "positive"}


def _check(params) -> None:
    for name, value in params._asdict().items():
        check_positive(name, value, allow_zero=_RULES[name] == "non-negative")
    if np.any(np.asarray(params.rho) > 1):
        raise ValueError(f"rho must be at most 1, got {params.rho}")
    if "tau_max" in params._fields and np.any(np.asarray(params.tau_min)
                                              > np.asarray(params.tau_max)):
        raise ValueError(f"tau_min ({params.tau_min}) exceeds tau_max ({params.tau_max})")
