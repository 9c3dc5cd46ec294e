"""Tune specifications: a TOML file that names a swarm, its search space, the instances, a
budget, an objective and a method, checked before any compute.

Its tables: ``[tune]`` (``name``, ``algorithm``, ``method`` of :data:`METHODS`, ``budget``,
``objective`` of :data:`OBJECTIVES`, ``iterations``, ``patience``, ``seed``, ``chunk_size``,
``grid_points``, ``es_pairs``, ``es_sigma``, ``es_learning_rate``, ``unsolved_gap``),
``[tune.training]`` and ``[tune.held_out]`` (``maps``, ``seeds``), ``[tune.race]``
(``first_test``, ``alpha``, ``elitist``, ``new_instances``, ``elitist_limit``, ``soft_restart``,
``spend_remaining``), ``[tune.baseline]``, ``[config]`` (the swarm factory's static
options) and ``[params]`` (traced; a domain ``{ low, high }`` with ``log`` or ``integer``,
``{ choices }``, ``{ tied }``, or a number). ``docs/tuning.md`` shows a spec and what each key
means. :func:`load_tune_spec` reads a file, :func:`tune_spec_from_dict` a parsed one; every
mistake raises :class:`TuneSpecError` naming the file and the key, among them a budget too small
for the method (:func:`smallest_budget`), a grid larger than the budget, and a tune of more than
``max_runs`` runs (training and held-out; ``DEFAULT_MAX_RUNS``, a million, unless told
otherwise), all before anything is built.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path
from typing import Any

from jaxswarm.sweep.spec import (DEFAULT_CHUNK_SIZE, DEFAULT_MAX_RUNS, algorithm_and_name,
                                 check_map_worlds, check_maps, check_max_runs, check_seeds,
                                 configured_swarm, is_number, positive_int, read_toml,
                                 too_many)
from jaxswarm.swarm import registry as swarm_registry
from jaxswarm.tune.space import Choice, Integer, Real, Space, Tied

METHODS = ("race", "random", "grid", "es")
"""The search methods (:mod:`jaxswarm.tune.race`, :mod:`jaxswarm.tune.search`)."""

OBJECTIVES = ("success", "gap", "time_to_target", "evaluations")
"""What a tune scores each run by (:mod:`jaxswarm.tune.evaluate`)."""

TUNE_KEYS = {"name", "algorithm", "method", "budget", "objective", "iterations", "patience",
             "seed", "chunk_size", "training", "held_out", "race", "grid_points", "es_pairs",
             "es_sigma", "es_learning_rate", "unsolved_gap", "baseline"}
RACE_KEYS = {"first_test", "alpha", "elitist", "new_instances", "elitist_limit", "soft_restart",
             "spend_remaining"}
INSTANCE_KEYS = {"maps", "seeds"}
DOMAIN_KEYS = {"low", "high", "log", "integer", "choices", "tied"}

HELD_OUT_SETTINGS = 4
"""The most settings a tune rescores on each held-out instance: the baseline and three best."""


class TuneSpecError(ValueError):
    """A tune spec that cannot run; the message names the file and the key."""


@dataclasses.dataclass(frozen=True)
class Instances:
    """Instances of a tune: every (map, seed) pair.

    Attributes:
      maps: map entries as written (resolved by :mod:`jaxswarm.maps.entry`).
      seeds: the seeds; run ``s`` uses ``jax.random.key(s)``.
    """

    maps: tuple
    seeds: tuple[int, ...]

    @property
    def pairs(self) -> list[tuple[int, int]]:
        """``(map index, seed)`` of every instance, map-major."""
        return list(itertools.product(range(len(self.maps)), self.seeds))


@dataclasses.dataclass(frozen=True)
class TuneSpec:
    """A checked tune (see the module docstring for each field's meaning)."""

    name: str
    algorithm: str
    method: str
    budget: int
    objective: str
    iterations: int
    patience: int | None
    seed: int
    chunk_size: int
    training: Instances
    held_out: Instances
    config: dict
    fixed: dict
    space: Space
    first_test: int = 5
    alpha: float = 0.05
    elitist: bool = True
    new_instances: int = 1
    elitist_limit: int = 2
    soft_restart: bool = True
    spend_remaining: bool = True
    grid_points: int | None = None
    es_pairs: int = 4
    es_sigma: float = 0.1
    es_learning_rate: float = 0.05
    unsolved_gap: float = 10.0
    baseline: dict = dataclasses.field(default_factory=dict)
    source: str = "<dict>"

    def as_dict(self) -> dict:
        """JSON-ready form of everything that decides the tune's runs (its store's resume
        check)."""
        record = dataclasses.asdict(self)
        record["space"] = {name: dict(kind=type(domain).__name__, **dataclasses.asdict(domain))
                           for name, domain in self.space.domains.items()}
        record.pop("source")
        if not self.baseline:  # the swarm's defaults: the record of a spec without the key
            record.pop("baseline")
        return record


def load_tune_spec(path, *, max_runs: int | None = DEFAULT_MAX_RUNS) -> TuneSpec:
    """Read and check a tune file (see the module docstring).

    Args:
      path: the TOML file (UTF-8).
      max_runs: the most runs the tune may make (its budget and its held-out runs); None: no
        limit.

    Raises:
      TuneSpecError: unreadable or non-UTF-8 file, bad TOML, an unknown section or key, a bad
        value, a budget too small for the method, more than ``max_runs`` runs; the message
        names the file and the key (and the line for TOML syntax and encoding).
    """
    path = Path(path)
    document = read_toml(path, "tune", TuneSpecError)
    return tune_spec_from_dict(document, source=str(path), max_runs=max_runs)


def tune_spec_from_dict(document: dict, *, source: str = "<dict>",
                        max_runs: int | None = DEFAULT_MAX_RUNS) -> TuneSpec:
    """Check a parsed tune spec (the TOML document as a dict); see :func:`load_tune_spec`."""
    def fail(key: str, problem: str):
        raise TuneSpecError(f"{source}: {key}: {problem}")

    check_max_runs(max_runs)
    for section in document:
        if section not in ("tune", "config", "params"):
            fail(section, "unknown section; expected tune, config, params")
    tune = _table(document.get("tune"), "[tune]", TUNE_KEYS, fail)
    for key in ("algorithm", "budget", "training", "held_out"):
        if key not in tune:
            fail(f"tune.{key}", "missing")
    algorithm, name = algorithm_and_name(tune, fail, "tune")
    method = _one_of(tune.get("method", "race"), METHODS, "tune.method", fail)
    objective = _one_of(tune.get("objective", "success"), OBJECTIVES, "tune.objective", fail)
    config, static = _config(document.get("config", {}), algorithm, fail)
    swarm = configured_swarm(algorithm, config, fail)
    training = _instances(tune["training"], "tune.training", swarm, algorithm, fail, max_runs)
    held_out = _instances(tune["held_out"], "tune.held_out", swarm, algorithm, fail, max_runs)
    shared = [(entry, seed) for entry in held_out.maps for seed in held_out.seeds
              if entry in training.maps and seed in training.seeds]
    if shared:
        fail("tune.held_out", f"{len(shared)} instance(s) are also training instances (e.g. map "
             f"{shared[0][0]!r} with seed {shared[0][1]}): a setting would be judged on runs "
             "like those that chose it")
    fixed, domains = _params(document.get("params", {}), swarm, algorithm, fail)
    space = Space({**domains, **static})
    if not space.free:
        fail("[params]", "nothing to tune: give at least one range or choice")
    race = _race_keys(tune.get("race", {}), method, training, fail)
    patience = tune.get("patience")
    spec = TuneSpec(
        name=name, algorithm=algorithm, method=method,
        budget=positive_int(tune["budget"], "tune.budget", fail), objective=objective,
        iterations=positive_int(tune.get("iterations", 100), "tune.iterations", fail),
        patience=None if patience is None else positive_int(patience, "tune.patience", fail),
        seed=_natural(tune.get("seed", 0), "tune.seed", fail),
        chunk_size=positive_int(tune.get("chunk_size", DEFAULT_CHUNK_SIZE), "tune.chunk_size",
                                fail),
        training=training, held_out=held_out, config=config, fixed=fixed, space=space,
        **race,
        grid_points=(None if "grid_points" not in tune
                     else positive_int(tune["grid_points"], "tune.grid_points", fail)),
        es_pairs=positive_int(tune.get("es_pairs", 4), "tune.es_pairs", fail),
        es_sigma=_positive(tune.get("es_sigma", 0.1), "tune.es_sigma", fail),
        es_learning_rate=_positive(tune.get("es_learning_rate", 0.05), "tune.es_learning_rate",
                                   fail),
        unsolved_gap=_positive(tune.get("unsolved_gap", 10.0), "tune.unsolved_gap", fail),
        baseline=_baseline(tune.get("baseline", {}), space, fail), source=source)
    _check_runs(spec, fail, max_runs)
    _check_corners(spec, fail)
    return spec


def race_iterations(free: int) -> int:
    """irace's ``N_iter = floor(2 + log2 d)`` for ``d = free`` params (at least one): the
    iterations of a race, and the most settings one iteration keeps."""
    return int(2 + math.log2(max(free, 1)))


def smallest_budget(spec: TuneSpec) -> int:
    """The least budget with which ``spec``'s method searches at all.

    race: irace's least (``computeMinimumBudget``), ``(N_min + 1) N_iter T`` with ``N_min =
    N_iter = floor(2 + log2 d)``: every iteration races one setting more than it keeps over
    ``T`` instances, ``first_test + 1`` and ``max(1, new_instances)`` more for each later
    iteration (past the fifth irace adds ``new_instances`` alone), or ``first_test + 5``
    without elitism; es: one step, ``2 es_pairs first_test`` runs; random: the baseline and one
    drawn setting; grid: every setting of its grid once (at ``grid_points``, else at 2 points
    per param).
    """
    if spec.method == "race":
        iterations = race_iterations(len(spec.space.free))
        new = max(1, spec.new_instances)
        if not spec.elitist:
            per_race = spec.first_test + 5
        elif iterations <= 5:
            per_race = spec.first_test + 1 + (iterations - 1) * new
        else:
            per_race = spec.first_test + 1 + (iterations - 5) * spec.new_instances + 5 * new
        return (iterations + 1) * iterations * per_race
    if spec.method == "es":
        return 2 * spec.es_pairs * spec.first_test
    if spec.method == "random":
        return 2
    return spec.space.grid_size(spec.grid_points or 2)


def _check_runs(spec: TuneSpec, fail, max_runs: int | None) -> None:
    """The budget pays for the method's search (:func:`smallest_budget`), and the budget and the
    held-out runs together are at most ``max_runs``; counted, not built."""
    least = smallest_budget(spec)
    if spec.budget < least:
        if spec.method == "grid":
            points = spec.grid_points or 2
            fail("tune.grid_points" if spec.grid_points else "tune.budget",
                 f"a grid of {points:,} points per param has {least:,} settings, more than the "
                 f"budget of {spec.budget:,} runs; the smallest budget for it is {least:,}"
                 + (" (or fewer grid_points)" if spec.grid_points else ""))
        fail("tune.budget", f"a budget of {spec.budget:,} runs is too small for method "
             f"{spec.method}: the smallest is {least:,} ({_why_least(spec)})")
    held_out = HELD_OUT_SETTINGS * len(spec.held_out.pairs)
    if max_runs is not None and spec.budget + held_out > max_runs:
        fail("tune.budget", f"{spec.budget:,} training runs and up to {held_out:,} held-out "
             f"runs ({HELD_OUT_SETTINGS} settings on {len(spec.held_out.pairs):,} instances) are "
             f"{spec.budget + held_out:,} runs, {too_many(max_runs)}")


def _why_least(spec: TuneSpec) -> str:
    """Why :func:`smallest_budget` is what it is for ``spec``'s method, in a few words."""
    if spec.method == "race":
        iterations = race_iterations(len(spec.space.free))
        return (f"irace's least: {iterations} iterations, each racing {iterations + 1} settings "
                f"on at least first_test + 1 = {spec.first_test + 1} instances and the "
                "instances the iterations before it added")
    if spec.method == "es":
        return (f"one step: {spec.es_pairs} antithetic pairs on first_test = {spec.first_test} "
                "instances")
    return "the baseline and one drawn setting"


def _table(value: Any, key: str, allowed: set, fail) -> dict:
    """``value``, a table of only ``allowed`` keys."""
    if not isinstance(value, dict):
        fail(key, "missing section" if value is None else "must be a table")
    for name in value:
        if name not in allowed:
            fail(f"{key.strip('[]')}.{name}",
                 f"unknown key; expected one of {', '.join(sorted(allowed))}")
    return value


def _race_keys(table: Any, method: str, training: Instances, fail) -> dict:
    """The ``[tune.race]`` table's settings (irace's defaults where absent): ``first_test``, the
    instances before the first test, at least 2 (the tests compare settings on two instances or
    more) and, for a race, at most the training instances; ``alpha``, the tests' level, in
    (0, 1); ``elitist``, ``new_instances`` (a natural number), ``elitist_limit`` (a natural
    number, 0 for none), ``soft_restart`` and ``spend_remaining`` (see :mod:`.race`)."""
    race = _table(table, "tune.race", RACE_KEYS, fail)
    alpha = race.get("alpha", 0.05)
    if not is_number(alpha) or not 0 < alpha < 1:
        fail("tune.race.alpha", f"must be a number in (0, 1), got {alpha!r}")
    first_test = positive_int(race.get("first_test", 5), "tune.race.first_test", fail)
    if first_test < 2:
        fail("tune.race.first_test", f"must be at least 2 (the tests after an instance compare "
             f"settings on two instances or more), got {first_test}")
    if method == "race" and first_test > len(training.pairs):
        fail("tune.race.first_test", f"{first_test} is more than the {len(training.pairs)} "
             "training instances: no test would ever drop a setting")
    switches = {}
    for key in ("elitist", "soft_restart", "spend_remaining"):
        switches[key] = race.get(key, True)
        if not isinstance(switches[key], bool):
            fail(f"tune.race.{key}", f"must be true or false, got {switches[key]!r}")
    return dict(first_test=first_test, alpha=float(alpha), **switches,
                new_instances=_natural(race.get("new_instances", 1), "tune.race.new_instances",
                                       fail),
                elitist_limit=_natural(race.get("elitist_limit", 2), "tune.race.elitist_limit",
                                       fail))


def _one_of(value: Any, allowed: tuple, key: str, fail) -> str:
    if value not in allowed:
        fail(key, f"must be one of {', '.join(allowed)}, got {value!r}")
    return value


def _natural(value: Any, key: str, fail) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        fail(key, f"must be a non-negative integer, got {value!r}")
    return value


def _positive(value: Any, key: str, fail) -> float:
    if not is_number(value) or value <= 0:
        fail(key, f"must be a positive number, got {value!r}")
    return float(value)


def _instances(table: Any, key: str, swarm, algorithm: str, fail,
               most: int | None) -> Instances:
    """The instances at ``key``: maps of the swarm's world and seeds (at most ``most``)."""
    table = _table(table, key, INSTANCE_KEYS, fail)
    for name in INSTANCE_KEYS:
        if name not in table:
            fail(f"{key}.{name}", "missing")
    maps = check_maps(table["maps"], fail, f"{key}.maps")
    check_map_worlds(maps, swarm, algorithm, fail, f"{key}.maps")
    return Instances(maps=tuple(maps),
                     seeds=check_seeds(table["seeds"], fail, f"{key}.seeds", most))


def _config(config: Any, algorithm: str, fail) -> tuple[dict, dict]:
    """``(fixed, static)``: the [config] values the swarm's factory accepts, and the tuned ones
    as static choices, each value of which builds a swarm."""
    if not isinstance(config, dict):
        fail("[config]", "must be a table")
    fixed = {name: value for name, value in config.items() if not isinstance(value, dict)}
    static = {}
    for name, value in config.items():
        if isinstance(value, dict):
            if set(value) != {"choices"}:
                fail(f"config.{name}", "a tuned config value is { choices = [...] }")
            static[name] = Choice(tuple(_choices(value["choices"], f"config.{name}", fail)),
                                  static=True)
            for choice in static[name].values:
                configured_swarm(algorithm, {**fixed, name: choice}, fail)
    return fixed, static


def _choices(values: Any, key: str, fail) -> list:
    if not isinstance(values, list) or len(values) < 2:
        fail(key, f"choices must be a list of at least two values, got {values!r}")
    if len(set(map(repr, values))) != len(values):
        fail(key, "repeats a choice")
    return values


def _params(params: Any, swarm, algorithm: str, fail) -> tuple[dict, dict]:
    """``(fixed, domains)``: the [params] table's fixed values and searched domains, for
    params the swarm knows; a tied param names a searched one."""
    if not isinstance(params, dict):
        fail("[params]", "must be a table")
    known = swarm.default_params._fields
    fixed, domains = {}, {}
    for name, value in params.items():
        key = f"params.{name}"
        if name not in known:
            fail(key, f"unknown param of {algorithm}; known: {', '.join(known)}")
        if is_number(value):
            fixed[name] = float(value)
        elif isinstance(value, dict):
            domains[name] = _domain(value, key, fail)
        else:
            fail(key, f"must be a number or a table, got {value!r}")
    for name, domain in domains.items():
        if isinstance(domain, Tied) and not isinstance(domains.get(domain.to),
                                                       (Real, Integer, Choice)):
            fail(f"params.{name}.tied", f"{domain.to!r} is not a searched param of this spec")
    return fixed, domains


def _domain(table: dict, key: str, fail):
    """A param's domain from its table."""
    unknown = set(table) - DOMAIN_KEYS
    if unknown:
        fail(key, f"unknown keys {sorted(unknown)}; a range is low, high (log, integer), a "
             "choice is choices, a tie is tied")
    if "tied" in table:
        if len(table) != 1 or not isinstance(table["tied"], str):
            fail(key, "a tie is { tied = \"OTHER\" } alone")
        return Tied(table["tied"])
    if "choices" in table:
        if len(table) != 1:
            fail(key, "a choice is { choices = [...] } alone")
        values = _choices(table["choices"], key, fail)
        if not all(is_number(v) for v in values):
            fail(key, f"choices of a param must be numbers, got {values!r}")
        return Choice(tuple(float(v) for v in values))
    if "low" not in table or "high" not in table:
        fail(key, "a range needs low and high")
    low, high = table["low"], table["high"]
    if not (is_number(low) and is_number(high)) or not low < high:
        fail(key, f"low and high must be numbers with low < high, got {low!r} and {high!r}")
    log = table.get("log", False)
    if not isinstance(log, bool) or (log and low <= 0):
        fail(key, "log must be true or false, and a log range needs low > 0")
    if table.get("integer", False):
        if not (float(low).is_integer() and float(high).is_integer()):
            fail(key, "an integer range needs integer low and high")
        return Integer(int(low), int(high), log)
    return Real(float(low), float(high), log)


def _baseline(table: Any, space: Space, fail) -> dict:
    """The ``[tune.baseline]`` values: searched params only, each inside its domain."""
    if not isinstance(table, dict):
        fail("tune.baseline", "must be a table")
    baseline = {}
    for name, value in table.items():
        key = f"tune.baseline.{name}"
        domain = space.domains.get(name)
        if domain is None or isinstance(domain, Tied):
            fail(key, "not a searched param of this spec; searched: " + ", ".join(space.free))
        if isinstance(domain, Choice):
            if value not in domain.values:
                fail(key, f"must be one of the choices {list(domain.values)}, got {value!r}")
        elif not is_number(value) or not domain.low <= value <= domain.high:
            fail(key, f"must be a number in [{domain.low}, {domain.high}], got {value!r}")
        elif isinstance(domain, Integer) and not float(value).is_integer():
            fail(key, f"must be an integer, got {value!r}")
        baseline[name] = value if isinstance(domain, Choice) and domain.static else float(value)
    return baseline


def _check_corners(spec: TuneSpec, fail) -> None:
    """The lowest and highest value of every searched param (the others at the swarm's
    defaults or fixed values) is a valid setting of the swarm, so an out-of-range bound fails
    here, before any compute."""
    swarm = swarm_registry.make(spec.algorithm, **spec.config)
    for name in spec.space.numeric:
        domain = spec.space.domains[name]
        for bound in (domain.low, domain.high):
            setting = {**spec.fixed, name: float(bound)}
            for other, tie in spec.space.domains.items():
                if isinstance(tie, Tied) and tie.to == name:
                    setting[other] = float(bound)
            try:
                swarm.check_params(swarm.params_with(**setting))
            except ValueError as error:
                field = getattr(error, "field", name)  # a fixed param's value may be at fault
                if field != name:
                    fail(f"params.{field}", str(error))
                fail(f"params.{name}", f"{bound} is not a valid value: {error}")
