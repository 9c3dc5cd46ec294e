"""The tuner's other methods, at the same budget as the race: random search, the grid, and
evolution strategies stepped with optax.

* **random**: the tune's baseline and settings drawn uniformly (log-uniformly on log ranges),
  each run on the same first ``m`` training instances of the shuffled order, ``m`` the most
  instances that leave room for at least ``first_test + 5`` settings (all instances when the
  budget allows); the best mean loss wins.
* **grid**: every combination of ``grid_points`` values per numeric param (default: the most
  points whose grid fits the budget on ``first_test`` instances) and every value of each choice,
  each run on the same ``m`` instances (the most the budget allows for the whole grid).
* **es**: evolution strategies on the unit cube of the numeric params (log-scaled where the
  range is), from the tune's baseline: each step runs ``es_pairs`` antithetic pairs
  ``x +- es_sigma eps`` on the next ``first_test`` instances of the order (cycling; both members
  of a pair on the same instances), estimates the gradient of the mean loss from their centred
  ranks (:func:`jaxswarm.runtime.evolution.antithetic_gradient`) and steps ``optax.adam``
  (``es_learning_rate``), keeping ``x`` in the cube; choices stay at the baseline's. The last
  mean is the result.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import optax

from jaxswarm.runtime.evolution import antithetic_gradient
from jaxswarm.tune.evaluate import Evaluator, Setting, instance_order
from jaxswarm.tune.space import Space, from_unit, to_unit


@dataclasses.dataclass
class SearchResult:
    """What a search found: its settings, best first by the search's own measure, and every
    setting it made, by number."""

    best: list[Setting]
    settings: dict


def random_search(evaluator: Evaluator, space: Space, baseline: dict,
                  rng: np.random.Generator) -> SearchResult:
    """Random search (see the module docstring)."""
    spec = evaluator.spec
    order = instance_order(spec.training.pairs, rng)
    least = spec.first_test + 5
    count = min(len(order), max(1, spec.budget // least))
    settings = _numbered([{name: baseline[name] for name in space.free}]
                         + [{name: s[name] for name in space.free}
                            for s in space.uniform(rng, max(0, spec.budget // count - 1))],
                         space)
    return _best_of(evaluator, settings, order[:count])


def grid_search(evaluator: Evaluator, space: Space, rng: np.random.Generator) -> SearchResult:
    """The grid (see the module docstring)."""
    spec = evaluator.spec
    order = instance_order(spec.training.pairs, rng)
    points = spec.grid_points or space.most_points(spec.budget // spec.first_test)
    grid = space.grid(points)
    count = min(len(order), max(1, spec.budget // len(grid)))
    return _best_of(evaluator, _numbered(grid, space), order[:count])


def es_search(evaluator: Evaluator, space: Space, baseline: dict,
              rng: np.random.Generator) -> SearchResult:
    """Evolution strategies with ``optax.adam`` (see the module docstring)."""
    spec = evaluator.spec
    order = instance_order(spec.training.pairs, rng)
    numeric = space.numeric
    mean = np.array([min(max(to_unit(space.domains[n], baseline[n]), 0.0), 1.0)
                     for n in numeric])
    optimizer = optax.adam(spec.es_learning_rate)
    state = optimizer.init(mean)
    made: dict[int, Setting] = {}
    per_step = 2 * spec.es_pairs * spec.first_test
    start = 0

    def setting(unit: np.ndarray) -> Setting:
        values = {name: baseline[name] for name in space.free}
        values |= {name: from_unit(space.domains[name], u) for name, u in zip(numeric, unit)}
        made_setting = Setting(len(made), space.complete(values))
        made[made_setting.number] = made_setting
        return made_setting

    while evaluator.runs_spent + per_step <= spec.budget:
        eps = rng.standard_normal((spec.es_pairs, len(numeric)))
        tried = np.clip(np.concatenate([mean + spec.es_sigma * eps, mean - spec.es_sigma * eps]),
                        0.0, 1.0)
        instances = [order[(start + i) % len(order)] for i in range(spec.first_test)]
        start += spec.first_test
        losses = evaluator.score([setting(unit) for unit in tried], instances)
        gradient = antithetic_gradient(eps, losses.mean(axis=1), spec.es_sigma)
        updates, state = optimizer.update(gradient.astype(np.float64), state, mean)
        mean = np.clip(np.asarray(optax.apply_updates(mean, updates)), 0.0, 1.0)
    return SearchResult(best=[setting(mean)], settings=made)


def _numbered(values: list[dict], space: Space) -> list[Setting]:
    return [Setting(number, space.complete(v)) for number, v in enumerate(values)]


def _best_of(evaluator: Evaluator, settings: list[Setting], instances: list) -> SearchResult:
    """Every setting on every instance in one batch; best mean loss first (ties: the earlier
    setting)."""
    losses = evaluator.score(settings, instances)
    ranked = np.argsort(losses.mean(axis=1), kind="stable")
    return SearchResult(best=[settings[i] for i in ranked],
                        settings={s.number: s for s in settings})
