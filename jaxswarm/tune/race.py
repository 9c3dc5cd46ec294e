"""Iterated racing as irace runs it (López-Ibáñez et al., Operations Research Perspectives 3,
2016; the rules of irace's code where the paper leaves them open; ``docs/tuning.md`` lists them
and where this differs).

:func:`iterated_race` makes at least ``N_iter = floor(2 + log2 d)`` iterations for ``d`` free
params, and more while the budget pays for a race (each extra one takes all that is left). An
iteration races settings over the training instances, the settings alive as one batch of runs,
and from the ``first_test``-th instance of the race on the Friedman test and Conover's comparisons
against the best drop the worse settings (:func:`jaxswarm.tune.stats.race_step`); the race's best
``N_min = floor(2 + log2 d)`` survivors are the elites. The training instances are taken in a keyed
random order, once: the first race runs them in that order, each later race (elitist, as irace's
default) starts with ``new_instances`` instances no race has seen, then the instances seen before
(in a new keyed order), then the unseen rest. Elites keep their results (a known (setting,
instance) is never run again) and cannot be dropped until the race has passed every instance they
were run on. New settings: an elite picked by rank, each number drawn from a truncated normal
around the elite's value with the elite's own deviation (shrunk by ``(1 / N_new)^(1 / d)`` an
iteration along its lineage), each choice from the elite's probabilities (moved towards its value
by ``(j - 1) / N_iter``, capped at ``0.2^(1 / d)``); when two settings of a race are nearly the
same, the models of their elites soft-restart and the new settings are drawn again.
"""
from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pandas as pd

from jaxswarm.tune.evaluate import Evaluator, Setting, instance_order
from jaxswarm.tune.space import Choice, Integer, Space, cell_unit, from_cell_unit
from jaxswarm.tune.spec import race_iterations
from jaxswarm.tune.stats import race_step, ranks

MOST_SETTINGS = 1024
"""irace's ``maxConfigurations``: the most settings one race takes."""

RESTART_THRESHOLD = 1e-4
"""irace's ``softRestartThreshold``: two numbers of a race's settings are nearly the same (a soft
restart's trigger) when they differ by at most this share of their range."""

PROBABILITY_CAP = 0.2
"""A choice's probability is capped at ``PROBABILITY_CAP ** (1 / d)`` after each update (irace's
elitist model update), then the probabilities are normalised again."""


@dataclasses.dataclass
class Model:
    """An elite's sampling model (irace's, one per elite, passed down its lineage).

    Attributes:
      deviation: name -> the standard deviation of each numeric param's normal, on its unit
        scale (:func:`~jaxswarm.tune.space.cell_unit`).
      probabilities: name -> f64[V] each choice's probabilities over its values.
    """

    deviation: dict
    probabilities: dict

    def copy(self) -> "Model":
        """A copy whose deviations and probabilities can change without changing these."""
        return Model(dict(self.deviation), {k: v.copy() for k, v in self.probabilities.items()})


@dataclasses.dataclass
class RaceResult:
    """What a race tune found.

    Attributes:
      elites: the last race's survivors, best first (each with its values).
      log: one row per (iteration, instance, setting alive on it): ``iteration``, ``step``
        (the instance's place in the race, from 1), ``instance`` (its place in the keyed order
        of the training instances), ``setting``, ``loss``, ``ran`` (whether it was run in this
        race: False for an elite's known result), and ``dropped`` (the test that dropped the
        setting after this instance, else "").
      settings: every setting made, by number.
      parents: setting number -> the elite it was drawn around (None for the first race's).
      models: elite number -> its model as the last iteration that sampled from it left it.
      restarts: the iterations whose models soft-restarted.
    """

    elites: list[Setting]
    log: pd.DataFrame
    settings: dict
    parents: dict
    models: dict
    restarts: list[int]


@dataclasses.dataclass
class _Race:
    """The race's memory across iterations."""

    order: list                      # the training instances, in the keyed order
    seen: int = 0                    # instances 0 .. seen - 1 of the order some race ran
    new_instances: int = 1           # irace's elitistNewInstances, set to 0 when it cannot pay
    losses: dict = dataclasses.field(default_factory=dict)  # (setting, instance) -> loss
    made: dict = dataclasses.field(default_factory=dict)
    parents: dict = dataclasses.field(default_factory=dict)
    models: dict = dataclasses.field(default_factory=dict)
    log_rows: list = dataclasses.field(default_factory=list)
    restarts: list = dataclasses.field(default_factory=list)

    def new_setting(self, space: Space, values: dict, parent: int | None) -> Setting:
        setting = Setting(len(self.made), space.complete(values))
        self.made[setting.number] = setting
        self.parents[setting.number] = parent
        return setting


def iterated_race(evaluator: Evaluator, space: Space, baseline: dict,
                  rng: np.random.Generator) -> RaceResult:
    """Run an iterated race within ``evaluator.spec.budget`` training runs.

    Args:
      evaluator: scores settings on the training instances (:mod:`jaxswarm.tune.evaluate`).
      space: the search space.
      baseline: the tune's baseline, a value for every param of the space (the first setting).
      rng: the tuner's generator (draws and the instance orders).
    """
    spec = evaluator.spec
    state = _Race(order=instance_order(spec.training.pairs, rng),
                  new_instances=spec.new_instances if spec.elitist else 0)
    dimension = max(len(space.free), 1)
    iterations = survivors = race_iterations(dimension)
    elites: list[Setting] = []
    for j in itertools.count(1):
        remaining = spec.budget - evaluator.runs_spent
        if remaining <= 0 or (j > iterations and not spec.spend_remaining):
            break
        iterations = max(iterations, j)  # an extra iteration takes all that is left
        budget = remaining // (iterations - j + 1)
        size = _race_size(spec, state, budget, len(elites), j, survivors)
        if size is None:
            break
        fresh = size - len(elites)
        if j == 1:
            candidates = [state.new_setting(space, {n: baseline[n] for n in space.free}, None)]
            candidates += [state.new_setting(space, {n: s[n] for n in space.free}, None)
                           for s in space.uniform(rng, fresh - 1)]
        else:
            _update_models(space, state, elites, j, iterations, fresh, dimension)
            candidates = elites + _children(space, rng, state, elites, fresh, dimension, j,
                                            spec.soft_restart)
        elites = _race(evaluator, state, candidates, rng, budget, survivors, j)
        if j == 1:
            state.models = {e.number: _initial_model(space) for e in elites}
    return RaceResult(elites=elites, log=pd.DataFrame(state.log_rows), settings=state.made,
                      parents=state.parents, models=state.models, restarts=state.restarts)


def _race_size(spec, state: _Race, budget: int, elites: int, j: int,
               survivors: int) -> int | None:
    """irace's ``N_j``, the settings iteration ``j`` races with ``budget`` runs and ``elites``
    elites (whose known results an elitist race counts as paid), or None where irace stops: no
    more settings than the race keeps (or than the elites), or a budget that cannot pay for the
    new settings' first ``first_test`` instances. An elitist race that cannot pay for its new
    instances gives them up, for good."""
    mu = spec.first_test
    known = elites if spec.elitist else 0
    old = state.seen if known else 0

    def count(iteration, mu, new):
        n = max(mu + min(5, iteration), old + new)
        return min((budget + known * old) // n, MOST_SETTINGS)

    size = count(j, mu, state.new_instances if known else 0)
    if known and size <= survivors and state.new_instances:
        state.new_instances = 0
        size = count(j, mu, 0)
    if known and size <= survivors:
        size = count(1, 1, 0)
    if size <= survivors or (elites and size <= elites):
        return None
    if (size - known) * mu + known * min(state.new_instances, mu) > budget:
        return None
    return size


def _race(evaluator: Evaluator, state: _Race, candidates: list[Setting],
          rng: np.random.Generator, budget: int, survivors: int, j: int) -> list[Setting]:
    """One race of ``candidates`` (the elites first) over :func:`_instances` within ``budget``
    runs; returns its survivors, best mean rank first (at most ``survivors``, a setting with the
    values of a better one left out)."""
    spec = evaluator.spec
    alive, raced = list(candidates), []
    # irace's countdown per elite: the instances it has a result for that the race has not passed.
    protected = {s.number: spec.elitist * sum((s.number, i) in state.losses
                                              for i in range(state.seen)) for s in candidates}
    began, quiet = evaluator.runs_spent, 0
    # irace tests whether to stop only once the race passed every instance an elite knows.
    before = state.seen if spec.elitist and j > 1 else 0
    for instance in _instances(state, rng, first=j == 1, elitist=spec.elitist):
        todo = [s for s in alive if (s.number, instance) not in state.losses]
        if evaluator.runs_spent - began + len(todo) > budget:
            break
        if todo:
            scored = evaluator.score(todo, [state.order[instance]], iteration=j)[:, 0]
            state.losses.update({(s.number, instance): float(x) for s, x in zip(todo, scored)})
        state.seen = max(state.seen, instance + 1)
        for s in alive:
            if s not in todo and protected[s.number] > 0:
                protected[s.number] -= 1
        raced.append(instance)
        keep, test = _test(spec, state, alive, raced, protected, tested=bool(todo))
        _log(state, alive, keep, test, todo, instance, len(raced), j)
        if test and not any(protected[s.number] > 0 for s in alive) \
                and len(raced) > spec.first_test:
            quiet = 0 if not keep.all() else quiet + 1
        alive = [s for s, kept in zip(alive, keep) if kept]
        if sum(i < before for i in raced) < before:
            continue
        if len(alive) <= survivors or (spec.elitist and 0 < spec.elitist_limit <= quiet):
            break
    return _ranked(state, alive, raced, survivors)


def _instances(state: _Race, rng: np.random.Generator, *, first: bool, elitist: bool):
    """The race's instances (places in the keyed order): the whole order for the first race;
    for a later elitist one ``new_instances`` unseen ones, then the seen ones in a new keyed
    order, then the unseen rest (with ``new_instances`` 0, and once every instance was seen, the
    seen ones come first); without elitism the unseen ones alone (all of them again, in a new
    keyed order, once every instance was seen: a run is a function of its setting and instance,
    so irace's fresh seeds for a recycled instance have no twin here)."""
    if first:
        yield from range(len(state.order))
        return
    if not elitist:
        fresh = range(state.seen, len(state.order))
        yield from fresh if len(fresh) else (int(i) for i in rng.permutation(len(state.order)))
        return
    seen, new = state.seen, min(state.new_instances, len(state.order) - state.seen)
    yield from range(seen, seen + new)
    yield from (int(i) for i in rng.permutation(seen))
    yield from range(seen + new, len(state.order))


def _results(state: _Race, settings: list[Setting], instances: list[int]) -> np.ndarray:
    """f64[I, S] the losses of ``settings`` on ``instances``."""
    return np.array([[state.losses[s.number, i] for s in settings] for i in instances])


def _test(spec, state: _Race, alive: list[Setting], raced: list[int], protected: dict, *,
          tested: bool):
    """``(keep bool[S], test)`` after the race's latest instance: the test of the alive settings
    on the race's instances so far (:func:`~.stats.race_step`; none where nothing was run on the
    instance, as irace skips it), no protected elite dropped; ``test`` "" where none was due."""
    decision = (race_step(_results(state, alive, raced), spec.alpha, spec.first_test)
                if tested else None)
    if decision is None:
        return np.ones(len(alive), bool), ""
    return decision.keep | np.array([protected[s.number] > 0 for s in alive]), decision.test


def _log(state: _Race, alive, keep, test, todo, instance, step, j) -> None:
    for s, kept in zip(alive, keep):
        state.log_rows.append(dict(iteration=j, step=step, instance=instance, setting=s.number,
                                   loss=state.losses[s.number, instance], ran=s in todo,
                                   dropped="" if kept else test))


def _ranked(state: _Race, alive: list[Setting], raced: list[int],
            survivors: int) -> list[Setting]:
    """The race's survivors by mean rank over its instances (ties: the earlier setting), a
    setting with the values of a better one left out (irace's elites are distinct), at most
    ``survivors``."""
    mean_rank = ranks(_results(state, alive, raced)).mean(axis=0)
    ranked, values = [], []
    for i in np.argsort(mean_rank, kind="stable"):
        if alive[i].values not in values:
            ranked.append(alive[i])
            values.append(alive[i].values)
    return ranked[:survivors]


def _initial_model(space: Space) -> Model:
    """irace's first model of an elite: half its range as every numeric param's deviation (an
    integer's range on its cells), uniform probabilities over every choice's values."""
    deviation, probabilities = {}, {}
    for name in space.free:
        domain = space.domains[name]
        if isinstance(domain, Choice):
            probabilities[name] = np.full(len(domain.values), 1.0 / len(domain.values))
        else:
            deviation[name] = _first_deviation(domain)
    return Model(deviation, probabilities)


def _first_deviation(domain) -> float:
    """Half a numeric param's range, on its unit scale: irace's ``(upper - lower) / 2`` (0.5
    on a log scale) over the sampled interval (``[low, high + 1)`` for an integer)."""
    if isinstance(domain, Integer) and not domain.log:
        return 0.5 * (domain.high - domain.low) / (domain.high + 1 - domain.low)
    return 0.5


def _update_models(space: Space, state: _Race, elites: list[Setting], j: int,
                   iterations: int, fresh: int, dimension: int) -> None:
    """irace's model update before iteration ``j`` draws ``fresh`` settings: each elite takes its
    own model, or its parent's as it was (a new elite), with every deviation shrunk by
    ``(1 / fresh)^(1 / d)`` and every choice's probabilities moved towards the elite's value by
    ``(j - 1) / N_iter``, capped at ``PROBABILITY_CAP^(1 / d)`` and normalised."""
    before = state.models
    shrink = (1.0 / fresh) ** (1.0 / dimension)
    shift = (j - 1) / iterations
    cap = PROBABILITY_CAP ** (1.0 / dimension)
    models = {}
    for elite in elites:
        model = before.get(elite.number) or before[state.parents[elite.number]]
        model = model.copy()
        for name in model.deviation:
            model.deviation[name] *= shrink
        for name, p in model.probabilities.items():
            values = space.domains[name].values
            p = _normalised(p * (1.0 - shift)
                            + shift * np.array([v == elite.values[name] for v in values]))
            model.probabilities[name] = _normalised(np.minimum(p, cap))
        models[elite.number] = model
    state.models = models


def _normalised(p: np.ndarray) -> np.ndarray:
    return p / p.sum()


def _children(space: Space, rng: np.random.Generator, state: _Race, elites: list[Setting],
              fresh: int, dimension: int, j: int, soft_restart: bool) -> list[Setting]:
    """``fresh`` new settings, each drawn around an elite picked by rank (with replacement);
    when two settings of the race would be nearly the same (:func:`_similar`), the models of the
    elites behind them soft-restart (:func:`_restart`) and the new settings are drawn again,
    once."""
    weights = np.arange(len(elites), 0, -1, dtype=np.float64)
    parents = [elites[i] for i in rng.choice(len(elites), size=fresh, p=weights / weights.sum())]
    drawn = [_draw(space, rng, state.models[p.number], p) for p in parents]
    if soft_restart:
        behind = _similar(space, [e.values for e in elites] + drawn,
                          [e.number for e in elites] + [p.number for p in parents])
        if behind:
            for number in behind:
                state.models[number] = _restart(space, state.models[number], fresh, dimension)
            state.restarts.append(j)
            drawn = [_draw(space, rng, state.models[p.number], p) for p in parents]
    return [state.new_setting(space, values, p.number) for values, p in zip(drawn, parents)]


def _draw(space: Space, rng: np.random.Generator, model: Model, parent: Setting) -> dict:
    """A setting's free values drawn around ``parent`` from its ``model``: each number from a
    normal around the parent's value with the model's deviation, truncated to the range, on the
    unit scale of :func:`~jaxswarm.tune.space.cell_unit`; each choice from the model's
    probabilities."""
    values = {}
    for name in space.free:
        domain = space.domains[name]
        if isinstance(domain, Choice):
            values[name] = domain.values[rng.choice(len(domain.values),
                                                    p=model.probabilities[name])]
        else:
            centre = cell_unit(domain, parent.values[name])
            values[name] = from_cell_unit(
                domain, _truncated_normal(rng, centre, model.deviation[name]))
    return values


def _similar(space: Space, settings: list[dict], elite_of: list[int]) -> set[int]:
    """The elites behind every pair of ``settings`` (free values; ``elite_of``: each one's elite,
    itself or its parent) that are nearly the same: every choice equal, every number within
    ``RESTART_THRESHOLD`` of its range."""
    behind = set()
    for a, b in itertools.combinations(range(len(settings)), 2):
        if all(_close(space.domains[n], settings[a][n], settings[b][n]) for n in space.free):
            behind |= {elite_of[a], elite_of[b]}
    return behind


def _close(domain, a, b) -> bool:
    if isinstance(domain, Choice):
        return a == b
    return abs(float(a) - float(b)) <= RESTART_THRESHOLD * (domain.high - domain.low)


def _restart(space: Space, model: Model, fresh: int, dimension: int) -> Model:
    """irace's soft restart of a model: every choice's probabilities smoothed towards their
    largest (``0.9 p + 0.1 max(p)``, normalised), every deviation widened to
    ``min(sd * fresh^(2 / d), first * (1 / fresh)^(1 / d))``."""
    model = model.copy()
    for name, p in model.probabilities.items():
        model.probabilities[name] = _normalised(0.9 * p + 0.1 * p.max())
    for name, deviation in model.deviation.items():
        first = _first_deviation(space.domains[name])
        model.deviation[name] = min(deviation * fresh ** (2.0 / dimension),
                                    first * (1.0 / fresh) ** (1.0 / dimension))
    return model


def _truncated_normal(rng: np.random.Generator, centre: float, deviation: float) -> float:
    """A draw of a normal around ``centre`` truncated to ``[0, 1]`` (by rejection; the centre
    after 100 rejections, which only a deviation far below the range's needs)."""
    for _ in range(100):
        value = rng.normal(centre, deviation)
        if 0.0 <= value <= 1.0:
            return value
    return centre
