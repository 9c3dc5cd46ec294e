"""The bees paper's inverse problem (section VI, eq. 11): the weights ``w = (w1, w2, w3)`` that
make ``cabc`` best on a map.

``J(w) = avgP(w) / (1 + target(w))`` over K runs (seeds) of the direct problem: ``target`` counts
the runs whose vehicle arrived and ``avgP`` is the mean length of their trajectories. A weight
setting whose vehicle never arrives has no ``avgP``: it scores :func:`worst_objective`, the length
of the longest trajectory a vehicle can make, which is more than any setting with an arrival can
score (``avgP <= worst`` and ``1 + target >= 2``), so the order of eq. 11 is kept and the value
stays finite for the gradient estimate.

Two searches, counted in direct-problem runs (one run = one seed of one weight setting):

* :func:`grid_search` is the paper's brute force over a grid.
* :func:`es_search` steps ``optax.adam`` on an evolution-strategies estimate of the gradient of J:
  J is piecewise constant in ``w`` for fixed seeds (an arrival count and a mean of trajectories
  whose every step is a discrete choice), so it has no useful derivative, but its Gaussian
  smoothing does; antithetic pairs ``w +- sigma eps`` share their seeds (common random numbers)
  and their objectives enter as centred ranks, so the step does not depend on J's scale.
"""
from __future__ import annotations

import math
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import optax

from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.runtime.evolution import antithetic_gradient
from jaxswarm.swarm.core import Swarm, Task, run_loop
from jaxswarm.world.plane import Plane

WEIGHTS = ("w1", "w2", "w3")
"""The weights the inverse problem searches, in the order of a weight vector."""


def weight_grid(ranges, counts) -> np.ndarray:
    """f32[G, 3]: every combination of ``counts[i]`` values evenly spaced over ``ranges[i]`` (a
    ``(low, high)`` pair, both ends included) of w1, w2 and w3; w1 varies slowest."""
    axes = [np.linspace(low, high, count, dtype=np.float32)
            for (low, high), count in zip(ranges, counts, strict=True)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(WEIGHTS))


class Score(NamedTuple):
    """Eq. 11 per weight setting: ``avg_length`` f32[W] (NaN where no run arrived), ``target``
    i32[W] and ``objective`` f32[W]."""

    avg_length: jax.Array
    target: jax.Array
    objective: jax.Array


def worst_objective(swarm: Swarm, params) -> float:
    """The score of a setting that never arrives: ``M`` moves of the longest step the window
    allows (``window / sqrt 2``), plus that step again for the last one onto the goal."""
    return float((swarm.config.max_steps + 1) * np.asarray(params.window) / math.sqrt(2))


def objective(lengths: jax.Array, reached: jax.Array, worst: float) -> Score:
    """Eq. 11 from runs: ``lengths`` f32[..., K] (inf where a run did not arrive) and ``reached``
    bool[..., K] -> :class:`Score` over the leading axes."""
    target = jnp.sum(reached, axis=-1, dtype=jnp.int32)
    total = ordered_sum(jnp.where(reached, lengths, 0.0))
    avg = jnp.where(target > 0, total / jnp.maximum(target, 1), jnp.nan)
    return Score(avg_length=avg, target=target,
                 objective=jnp.where(target > 0, avg / (1.0 + target), worst))


def make_scorer(swarm: Swarm, plane: Plane, task: Task, params, seeds, *,
                iterations: int = 200) -> Callable[[jax.Array], Score]:
    """``score(weights f32[W, 3]) -> Score``: every weight setting run on every seed of
    ``seeds`` (i32[K]) in one jitted ``vmap`` (W x K runs), the other params as ``params``."""
    keys = jax.vmap(jax.random.key)(jnp.asarray(seeds, jnp.int32))
    worst = worst_objective(swarm, params)

    def one(key, weights):
        chosen = params._replace(**{name: weights[i] for i, name in enumerate(WEIGHTS)})
        state, _ = run_loop(swarm, key, plane, task, chosen, None, jnp.int32(iterations),
                            iterations=iterations, patience=None)
        solution = swarm.best(state)
        return solution.cost, solution.found

    @jax.jit
    def score(weights):
        lengths, reached = jax.vmap(lambda w: jax.vmap(lambda k: one(k, w))(keys))(
            jnp.asarray(weights, jnp.float32))
        return objective(lengths, reached, worst)

    return score


class Search(NamedTuple):
    """A search's record: every weight setting it scored, in order.

    Attributes:
      weights: f32[E, 3] the settings.
      score: :class:`Score` of each (leaves [E]).
      step: i32[E] the search step that scored it (0 for the grid).
      runs: direct-problem runs spent (E x K).
      path: f32[S + 1, 3] the search's mean before each step and after the last (the grid: no
        rows).
    """

    weights: np.ndarray
    score: Score
    step: np.ndarray
    runs: int
    path: np.ndarray

    def best(self) -> np.ndarray:
        """f32[3]: the setting with the least objective (the first of equals)."""
        return self.weights[int(np.argmin(self.score.objective))]


def grid_search(score: Callable[[jax.Array], Score], grid: np.ndarray, seeds: int) -> Search:
    """The paper's brute force: every setting of ``grid`` (f32[G, 3]) scored once."""
    grid = np.asarray(grid, np.float32)
    return Search(weights=grid, score=jax.device_get(score(grid)),
                  step=np.zeros(len(grid), np.int32), runs=len(grid) * seeds,
                  path=np.zeros((0, 3), np.float32))


def es_search(key: jax.Array, score: Callable[[jax.Array], Score], start, seeds: int, *,
              steps: int, pairs: int, sigma: float = 0.05,
              learning_rate: float = 0.05) -> Search:
    """Evolution strategies with ``optax.adam``: each step scores ``pairs`` antithetic pairs
    ``w +- sigma eps`` (``eps`` standard normal, f32[pairs, 3]) on the same seeds, estimates the
    gradient of the smoothed objective from their centred ranks, and moves the mean ``w`` (kept
    non-negative). Spends ``steps x 2 pairs x seeds`` runs.

    Args:
      key: PRNG key of the perturbations.
      score: as :func:`make_scorer` returns.
      start: f32[3] the first mean.
      seeds: K, the seeds ``score`` runs (for the count of runs).
      steps, pairs: the search's size.
      sigma: the perturbations' standard deviation.
      learning_rate: Adam's step size.
    """
    optimizer = optax.adam(learning_rate)
    mean = jnp.asarray(start, jnp.float32)
    state = optimizer.init(mean)
    weights, scores, at, path = [], [], [], [np.asarray(mean)]
    for step in range(steps):
        key, noise_key = jax.random.split(key)
        eps = jax.random.normal(noise_key, (pairs, 3))
        tried = jnp.maximum(jnp.concatenate([mean + sigma * eps, mean - sigma * eps]), 0.0)
        result = jax.device_get(score(tried))
        gradient = jnp.asarray(antithetic_gradient(np.asarray(eps), np.asarray(result.objective),
                                                   sigma))
        updates, state = optimizer.update(gradient, state, mean)
        mean = jnp.maximum(optax.apply_updates(mean, updates), 0.0)
        path.append(np.asarray(mean))
        weights.append(np.asarray(tried))
        scores.append(result)
        at.append(np.full(2 * pairs, step + 1, np.int32))
    return Search(weights=np.concatenate(weights),
                  score=jax.tree_util.tree_map(lambda *leaves: np.concatenate(leaves), *scores),
                  step=np.concatenate(at), runs=steps * 2 * pairs * seeds, path=np.stack(path))

