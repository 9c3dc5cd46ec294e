"""Max-Min ACO as the Max-Min ACO paper uses it (after Han et al.).

Each ant weighs ``tau_ij^alpha * eta_ij^beta`` with ``eta_ij = 1 / length(i, j)``, the two
"weighted evenly" (``alpha = beta = 1``). After each population: evaporation ``(1 - rho) tau``,
a floor ``tau_min`` ("not allowed to decrease below a minimum level"), then ``Q / f`` on the path
of the population's best ant (Algorithm 1's order: evaporate, floor, reinforce).

Switches of ours, off by default:

* ``global_best``: the best path so far deposits instead of the population's best (the usual
  alternative of Stuetzle and Hoos's MMAS).
* ``upper_bound``: also keep ``tau`` at most ``tau_max``, as MMAS does; the paper names only the
  floor.
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.swarm.aco.colony import colony, reinforce
from jaxswarm.swarm.core import Swarm, WalkingConfig, default_params


@dataclasses.dataclass(frozen=True)
class MaxMinConfig(WalkingConfig):
    """Static switches of Max-Min ACO (the defaults are the paper's use of it).

    Attributes:
      global_best: ours: the best path so far deposits instead of the population's best.
      upper_bound: ours: also keep ``tau`` at most ``tau_max``.
    """

    global_best: bool = False
    upper_bound: bool = False


class MaxMinParams(NamedTuple):
    """Numbers of Max-Min ACO (f32 scalars, traced).

    Attributes:
      rho: evaporation rate in (0, 1].
      q: Q, the deposit numerator (the best path of length f gains Q / f per edge).
      alpha: pheromone exponent (1).
      beta: exponent of eta = 1 / edge length (1).
      tau0: initial pheromone on every edge.
      tau_min: the floor.
      tau_max: the cap (read only with ``upper_bound``).
    """

    rho: jax.Array
    q: jax.Array
    alpha: jax.Array
    beta: jax.Array
    tau0: jax.Array
    tau_min: jax.Array
    tau_max: jax.Array


DEFAULT_MAX_MIN = default_params(MaxMinParams, rho=0.82448196, q=21.296747, alpha=1.0, beta=1.0,
                                 tau0=1.0, tau_min=0.0048365803, tau_max=10.0)
"""alpha = beta = 1 and tau0 = 1 as the paper; rho, Q and tau_min the setting Max-Min ACO's
calibration found with the paper's 50 ants (``tunes/max_min_aco.toml``, ``results/calibration``:
on held-out maps at least as good as rho = 0.1, Q = 1, tau_min = 0.01 everywhere, a mean gap of
8.43 against 8.70); tau_max (read only with ``upper_bound``) is ours."""


def build_max_min_aco(config: MaxMinConfig) -> Swarm:
    """Max-Min ACO as the Max-Min ACO paper uses it, with :class:`MaxMinParams`."""
    def update(graph, pheromone, ants, best_path, best_cost, info, params):
        if config.global_best:
            path, cost = best_path, best_cost
        else:
            winner = jnp.argmin(jnp.where(ants.arrived, ants.length, jnp.inf))
            path, cost = ants.agent_path(winner), info.iteration_cost
        pheromone = jnp.maximum((1.0 - params.rho) * pheromone, params.tau_min)
        pheromone = reinforce(graph, pheromone, path,
                              jnp.where(jnp.isfinite(cost), params.q / cost, 0.0))
        return jnp.minimum(pheromone, params.tau_max) if config.upper_bound else pheromone

    return colony("max_min_aco", config, default_params=DEFAULT_MAX_MIN, update=update)
