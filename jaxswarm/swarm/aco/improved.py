"""Improved Max-Min ACO: the Max-Min ACO paper's Algorithm 1.

* The heuristic ``eta_ij`` is the desirability of the move's direction given the goal's
  (:mod:`jaxswarm.swarm.aco.colony`), weighted evenly with the pheromone (``alpha = beta = 1``).
* Pheromone starts at ``tau0`` (one in the paper).
* The first ant of the first population walks with heuristic weight ``beta_first`` (the paper's
  ``hweight = 5``) and a memory of where it has been (:mod:`jaxswarm.swarm.aco.bug2`): its path
  is the first best path. Our walker runs it before the first population of ``num_agents`` ants,
  so that population has one ant more than the later ones.
* After each population: evaporation, the floor ``tau_min`` (the paper's ``minpher``), and ``q``
  (its ``delta``) added on every edge of the best path so far, which a path as short replaces
  (the paper's ``<=``).

Switch: ``first_ant="greedy"`` makes the first ant always take its most likely move (a
deterministic depth-first ant) instead of drawing it.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.aco.bug2 import first_ant_path
from jaxswarm.swarm.aco.colony import colony, first_path_rule, reinforce, transition_rule
from jaxswarm.swarm.core import Swarm, WalkingConfig, default_params

FIRST_ANTS = ("weighted", "greedy")
"""How the first ant chooses among its admissible moves: drawn by its weights (the paper), or
always the most likely one."""


@dataclasses.dataclass(frozen=True)
class ImprovedConfig(WalkingConfig):
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


class ImprovedParams(NamedTuple):
    """Numbers of Improved Max-Min ACO (f32 scalars, traced).

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


DEFAULT_IMPROVED = default_params(ImprovedParams, rho=0.1, q=0.1, alpha=1.0, beta=1.0,
                                  beta_first=5.0, tau0=1.0, tau_min=0.01)
"""alpha, beta, beta_first and tau0 are the paper's; rho, delta = rho * tau0 (the best path's
pheromone stays at tau0 while every other edge decays to the floor) and tau_min are ours."""


def first_ant(config: ImprovedConfig):
    """The Bug2-like first ant of ``config``: ``(key, graph, task, pheromone f32[N, K], params,
    length) -> (path i32[length], cost f32[])``, its path and length (-1 and inf when it found
    none or its path is longer than ``length``)."""
    def init_best(key, graph, task, pheromone, params, length):
        table = transition_rule(graph, task, pheromone, params, direction=True,
                                beta=params.beta_first)
        path, cost, found = first_ant_path(key, graph, table, task.start, task.goal,
                                           greedy=config.first_ant == "greedy",
                                           implementation=config.walker.implementation)
        fits = found & (jnp.sum(path >= 0) <= length)  # a longer first path cannot be stored
        path = jnp.pad(path, (0, max(length - path.shape[0], 0)), constant_values=-1)[:length]
        return jnp.where(fits, path, -1), jnp.where(fits, cost, jnp.inf).astype(jnp.float32)

    return init_best


def build_improved_max_min_aco(config: ImprovedConfig) -> Swarm:
    """Improved Max-Min ACO (the Max-Min ACO paper's Algorithm 1), with :class:`ImprovedParams`."""
    def update(graph, pheromone, ants, best_path, best_cost, info, params):
        pheromone = jnp.maximum((1.0 - params.rho) * pheromone, params.tau_min)
        return reinforce(graph, pheromone, best_path,
                         jnp.where(jnp.isfinite(best_cost), params.q, 0.0))

    return colony("improved_max_min_aco", config, default_params=DEFAULT_IMPROVED,
                  update=update, init_best=first_ant(config), direction=True, ties=True)


def change_rule(config: ImprovedConfig):
    """Improved Max-Min ACO's rule for a change of the map or the task
    (:func:`~.colony.first_path_rule`): every re-plan begins with the first ant."""
    return first_path_rule(first_ant(config))
