"""Iterated racing (irace; López-Ibáñez et al., Operations Research Perspectives 3, 2016).

:func:`iterated_race` makes ``N_iter = floor(2 + log2 d)`` iterations for ``d`` free params. Each
races settings over the training instances, taken one after another in one shuffled order, the
settings alive as one batch of runs: the tune's baseline and uniform draws in the first, the
elites of the race before and settings drawn around them later. From the ``first_test``-th
instance on, the Friedman test and Conover's comparisons against the best drop the worse
settings (:func:`jaxswarm.tune.stats.race_step`); a race's survivors are the next elites. A new
setting draws each number from a truncated normal around an elite picked by rank, on its range's
unit scale, and each choice from probabilities that move towards the elite's value.
``docs/tuning.md`` (The methods) gives the budgets, the formulas and where this differs from
irace.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd

from jaxswarm.tune.evaluate import Evaluator, Setting, instance_order
from jaxswarm.tune.space import Choice, Space, from_unit, to_unit
from jaxswarm.tune.spec import race_iterations
from jaxswarm.tune.stats import race_step, ranks


@dataclasses.dataclass
class RaceResult:
    """What a race tune found.

    Attributes:
      elites: the last race's survivors, best first (each with its values).
      log: one row per (iteration, instance, setting alive on it): ``iteration``, ``step``
        (the instance's place in the race, from 1), ``instance``, ``setting``, ``loss``, and
        ``dropped`` (the test that dropped the setting after this instance, else "").
      settings: every setting made, by number.
    """

    elites: list[Setting]
    log: pd.DataFrame
    settings: dict


def iterated_race(evaluator: Evaluator, space: Space, baseline: dict,
                  rng: np.random.Generator) -> RaceResult:
    """Run an iterated race within ``evaluator.spec.budget`` training runs.

    Args:
      evaluator: scores settings on the training instances (:mod:`jaxswarm.tune.evaluate`).
      space: the search space.
      baseline: the tune's baseline, a value for every param of the space (the first setting).
      rng: the tuner's generator (draws and the instance order).
    """
    spec = evaluator.spec
    order = instance_order(spec.training.pairs, rng)
    dimension = max(len(space.free), 1)
    iterations = survivors = race_iterations(dimension)
    made: dict[int, Setting] = {}
    losses: dict[tuple[int, int], float] = {}  # (setting, place in the order) -> loss
    choice_probabilities: dict[int, dict] = {}
    log_rows = []
    elites: list[Setting] = []
    deviation = 0.5

    def new_setting(values: dict) -> Setting:
        setting = Setting(len(made), space.complete(values))
        made[setting.number] = setting
        return setting

    for j in range(1, iterations + 1):
        remaining = spec.budget - evaluator.runs_spent
        budget = remaining / (iterations - j + 1)
        # At least one new setting while the iteration's budget pays for a race of them all
        # (irace would stop at a budget this small; a tune spends what it was given).
        size = max(int(budget // (spec.first_test + min(5, j))), len(elites) + 1)
        if remaining <= 0 or budget < size:
            break
        fresh = size - len(elites)
        if j == 1:
            first = new_setting({name: baseline[name] for name in space.free})
            candidates = [first] + [new_setting({n: s[n] for n in space.free})
                                    for s in space.uniform(rng, fresh - 1)]
        else:
            deviation *= (1.0 / fresh) ** (1.0 / dimension)
            candidates = elites + [
                _child(space, rng, elites, choice_probabilities, j, iterations, deviation,
                       new_setting) for _ in range(fresh)]
        elites = _race(evaluator, candidates, order, losses, budget, survivors, j, log_rows)
    return RaceResult(elites=elites, log=pd.DataFrame(log_rows), settings=made)


def _race(evaluator: Evaluator, candidates: list[Setting], order: list, losses: dict,
          budget: float, survivors: int, iteration: int, log_rows: list) -> list[Setting]:
    """One race of ``candidates`` over ``order``; returns the survivors, best mean rank first
    (at most ``survivors``)."""
    spec = evaluator.spec
    alive = list(candidates)
    began = evaluator.runs_spent
    seen = 0
    for place, instance in enumerate(order):
        todo = [s for s in alive if (s.number, place) not in losses]
        if evaluator.runs_spent - began + len(todo) > budget and seen >= 1:
            break
        if todo:
            scored = evaluator.score(todo, [instance], iteration=iteration)
            for setting, loss in zip(todo, scored[:, 0]):
                losses[setting.number, place] = float(loss)
        seen = place + 1
        table = np.array([[losses[s.number, p] for s in alive] for p in range(seen)])
        decision = race_step(table, spec.alpha, spec.first_test)
        keep = decision.keep if decision is not None else np.ones(len(alive), bool)
        for s, setting in enumerate(alive):
            log_rows.append(dict(iteration=iteration, step=seen, instance=place,
                                 setting=setting.number, loss=losses[setting.number, place],
                                 dropped="" if keep[s] else decision.test))
        alive = [setting for setting, kept in zip(alive, keep) if kept]
        if len(alive) <= survivors:
            break
    table = np.array([[losses[s.number, p] for s in alive] for p in range(seen)])
    mean_rank = _mean_ranks(table)
    ranked = [alive[i] for i in np.argsort(mean_rank, kind="stable")]
    return ranked[:survivors]


def _mean_ranks(table: np.ndarray) -> np.ndarray:
    """f64[S] each setting's mean rank over the rows of ``table`` (f64[I, S], lower better;
    ties share their mean rank)."""
    return ranks(table).mean(axis=0)


def _child(space: Space, rng: np.random.Generator, elites: list[Setting],
           probabilities: dict, iteration: int, iterations: int, deviation: float,
           new_setting) -> Setting:
    """A setting drawn around an elite picked by rank (see the module docstring)."""
    count = len(elites)
    weights = np.arange(count, 0, -1, dtype=np.float64)
    parent = elites[rng.choice(count, p=weights / weights.sum())]
    values = {}
    inherited = {}
    for name in space.free:
        domain = space.domains[name]
        if isinstance(domain, Choice):
            before = probabilities.get(parent.number, {}).get(
                name, np.full(len(domain.values), 1.0 / len(domain.values)))
            shift = (iteration - 1) / iterations
            updated = before * (1 - shift) + shift * np.array(
                [value == parent.values[name] for value in domain.values], np.float64)
            updated = updated / updated.sum()
            values[name] = domain.values[rng.choice(len(domain.values), p=updated)]
            inherited[name] = updated
        else:
            centre = to_unit(domain, parent.values[name])
            values[name] = from_unit(domain, _truncated_normal(rng, centre, deviation))
    child = new_setting(values)
    probabilities[child.number] = inherited
    return child


def _truncated_normal(rng: np.random.Generator, centre: float, deviation: float) -> float:
    """A draw of a normal around ``centre`` truncated to ``[0, 1]`` (by rejection; the centre
    after 100 rejections, which only a deviation far below the range's needs)."""
    for _ in range(100):
        value = rng.normal(centre, deviation)
        if 0.0 <= value <= 1.0:
            return value
    return centre
