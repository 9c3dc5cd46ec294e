"""Sweep specifications: a TOML file that names what to run, checked before any compute.

Its ``[sweep]`` table names one algorithm of the swarm registry, the maps (the entries of
:mod:`jaxswarm.maps.entry`), the seeds, the iteration budget and optionally ``patience``,
``chunk_size`` and ``vmap_size``; ``[config]`` the swarm factory's static options; ``[params]``
a grid of traced params, the Cartesian product of lists and ranges (``{ start, stop, num }``,
with ``log = true`` for geometric spacing, or ``{ start, stop, step }``), every other param at
the swarm's default. ``docs/sweeps.md`` shows a spec and what each key means. :func:`load_spec`
reads a file, :func:`spec_from_dict` a parsed one; every mistake raises :class:`SpecError`
naming the file and the key, and a map whose file, scenario row, start or goal is wrong is named
with its entry when the sweep starts, before anything is written. Seeds run from 0 to
``SEED_LIMIT - 1``, and a sweep of more than ``max_runs`` runs (``DEFAULT_MAX_RUNS``, a
million, unless told otherwise) is refused before its grid is built.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from jaxswarm.maps import entry as map_entry
from jaxswarm.maps.entry import ResolvedMap
from jaxswarm.swarm import registry as swarm_registry
from jaxswarm.swarm.core import ParamError

SECTIONS = {"sweep", "config", "params"}
SWEEP_KEYS = {"name", "algorithm", "maps", "seeds", "iterations", "patience", "chunk_size",
              "vmap_size"}
DEFAULT_CHUNK_SIZE = 64

SEED_LIMIT = 2**32
"""Seeds run from 0 to ``SEED_LIMIT - 1``: ``jax.random.key`` keeps the low 32 bits of a seed
(64-bit integers are off), so seeds ``s`` and ``s + 2**32`` would be one key and one run."""

DEFAULT_MAX_RUNS = 1_000_000
"""Runs a sweep or a tune may ask for unless told otherwise (``max_runs``, ``--max-runs``): a spec
asking for more is refused before anything is built."""


class SpecError(ValueError):
    """A sweep spec that cannot run; the message names the file and the key."""


@dataclasses.dataclass(frozen=True)
class SweepSpec:
    """A checked sweep.

    Attributes:
      name: the sweep's name (the default results directory).
      algorithm: a registered swarm name.
      maps: map entries as written (str or dict), resolved by :mod:`jaxswarm.maps.entry`.
      seeds: the integer seeds; run ``s`` uses ``jax.random.key(s)``.
      iterations: iteration budget of each run.
      patience: stop after this many iterations without improvement since the first path
        (None = never; see :func:`jaxswarm.swarm.run`).
      chunk_size: runs per compiled batch (a chunk is also the unit the store writes and a
        resumed sweep skips).
      vmap_size: runs vmapped together on one device; a device goes through its share of a
        chunk that many at a time, the walks of a group sharing one queue of agents. None:
        enough runs to fill the walker's lanes (:func:`jaxswarm.swarm.executor.group_size`). It
        changes speed, never results.
      config: static keyword arguments of the swarm factory.
      params: param name -> tuple of float values (swept params only).
      source: the file it came from (or "<dict>").
      log_scale: the swept params given as a ``log = true`` range (figures draw them on a
        log axis).
    """

    name: str
    algorithm: str
    maps: tuple
    seeds: tuple[int, ...]
    iterations: int
    patience: int | None
    chunk_size: int
    config: dict
    params: dict
    source: str = "<dict>"
    vmap_size: int | None = None
    log_scale: frozenset = frozenset()

    def grid(self) -> list[dict[str, float]]:
        """Every combination of the swept params, in a fixed order (the last param varies
        fastest); ``[{}]`` when nothing is swept."""
        names = list(self.params)
        return [dict(zip(names, values)) for values in itertools.product(*self.params.values())]

    @property
    def num_combinations(self) -> int:
        """Combinations of the swept params (1 when nothing is swept), counted, not built."""
        return math.prod(len(values) for values in self.params.values())

    @property
    def num_runs(self) -> int:
        """Runs per map: combinations x seeds."""
        return self.num_combinations * len(self.seeds)

    def combination_values(self, combinations: np.ndarray) -> dict[str, np.ndarray]:
        """Each swept param's value in combinations ``combinations`` (int[C], positions in
        :meth:`grid`), name -> f64[C], without building the grid."""
        if not self.params:  # one combination, of no param (unravel_index takes no 0-d shape)
            return {}
        places = np.unravel_index(np.asarray(combinations, np.int64),
                                  [len(values) for values in self.params.values()])
        return {name: np.asarray(values, np.float64)[place]
                for (name, values), place in zip(self.params.items(), places)}

    def as_dict(self) -> dict:
        """JSON-ready form of what decides the rows (the store's metadata and its resume
        check); ``vmap_size``, which changes only the speed, is left out, so a sweep may be
        resumed with another."""
        return dict(name=self.name, algorithm=self.algorithm, maps=list(self.maps),
                    seeds=list(self.seeds), iterations=self.iterations, patience=self.patience,
                    chunk_size=self.chunk_size, config=dict(self.config),
                    params={k: list(v) for k, v in self.params.items()})


def load_spec(path, *, max_runs: int | None = DEFAULT_MAX_RUNS) -> SweepSpec:
    """Read and check a sweep file (see the module docstring).

    Args:
      path: the TOML file (UTF-8).
      max_runs: the most runs the sweep may make (maps x combinations x seeds); None: no limit.

    Raises:
      SpecError: unreadable or non-UTF-8 file, bad TOML, unknown section/key/algorithm/param/
        config/map, empty grid, bad numbers, seeds outside ``[0, SEED_LIMIT)``, more than
        ``max_runs`` runs; the message names the file and the key (and the line for TOML syntax
        and encoding).
    """
    path = Path(path)
    document = read_toml(path, "sweep", SpecError)
    return spec_from_dict(document, source=str(path), max_runs=max_runs)


def read_toml(path: Path, kind: str, error_type: type[ValueError]) -> dict:
    """The TOML document in the file ``path``, or ``error_type`` naming the file (and the line
    of a syntax error or of a byte that is not UTF-8); ``kind`` names the file in messages
    ("sweep", "tune")."""
    try:
        data = path.read_bytes()
    except OSError as error:
        raise error_type(f"{path}: cannot read the {kind} file ({error.strerror})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        line = data.count(b"\n", 0, error.start) + 1
        raise error_type(f"{path}: line {line}: not UTF-8 text (byte 0x{data[error.start]:02x}); "
                         "a TOML file is UTF-8") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise error_type(f"{path}: not valid TOML: {error}") from None


def spec_from_dict(document: dict, *, source: str = "<dict>",
                   max_runs: int | None = DEFAULT_MAX_RUNS) -> SweepSpec:
    """Check a parsed spec (the TOML document as a dict); see :func:`load_spec`.

    The checks go in the order a reader meets the spec: the sections and the [sweep] keys, the
    algorithm and name, the maps, the seeds, the run options, [config] (and whether the maps
    are the swarm's world), [params], the number of runs (counted, not built, against
    ``max_runs``), and last every combination's values; the first mistake raises.
    """
    def fail(key: str, problem: str):
        raise SpecError(f"{source}: {key}: {problem}")

    check_max_runs(max_runs)
    sweep = _sweep_table(document, fail)
    algorithm, name = algorithm_and_name(sweep, fail)
    maps = check_maps(sweep["maps"], fail)
    seeds = check_seeds(sweep["seeds"], fail, most=max_runs)
    options = _run_options(sweep, fail)
    config = document.get("config", {})
    swarm = configured_swarm(algorithm, config, fail)
    check_map_worlds(maps, swarm, algorithm, fail)
    params = document.get("params", {})
    checked = _params(params, swarm, algorithm, fail, max_runs)
    spec = SweepSpec(name=name, algorithm=algorithm, maps=tuple(maps), seeds=seeds, **options,
                     config=dict(config), params=checked, source=source,
                     log_scale=frozenset(k for k, v in params.items()
                                         if isinstance(v, dict) and v.get("log", False)))
    runs = len(spec.maps) * spec.num_runs
    if max_runs is not None and runs > max_runs:
        fail("sweep", f"{len(spec.maps)} map(s) x {spec.num_combinations:,} param "
             f"combination(s) x {len(spec.seeds):,} seed(s) = {runs:,} runs, "
             f"{too_many(max_runs)}")
    _check_grid(spec, swarm, fail)
    return spec


def check_max_runs(max_runs: Any) -> None:
    """``max_runs`` is a positive integer or None; else a TypeError or ValueError naming it."""
    if max_runs is None:
        return
    if isinstance(max_runs, bool) or not isinstance(max_runs, int):
        raise TypeError(f"max_runs must be an integer or None, got {max_runs!r}")
    if max_runs < 1:
        raise ValueError(f"max_runs must be at least 1, got {max_runs}")


def too_many(max_runs: int) -> str:
    """The end of a message refusing more runs than ``max_runs``: what to do if meant."""
    return (f"more than the limit of {max_runs:,} runs; if that is meant, raise the limit "
            "(--max-runs N on the command line, max_runs=N in Python)")


def spec_from_record(record: dict, *, source: str) -> SweepSpec:
    """The spec a store recorded (:meth:`SweepSpec.as_dict`, in its ``metadata.json``), checked
    again as :func:`spec_from_dict` checks a document (no limit on its runs: it was run);
    ``source`` names the record in errors."""
    sweep = {key: record[key] for key in ("name", "algorithm", "maps", "seeds", "iterations",
                                          "chunk_size")}
    if record.get("patience") is not None:
        sweep["patience"] = record["patience"]
    return spec_from_dict({"sweep": sweep, "config": record["config"],
                           "params": record["params"]}, source=source, max_runs=None)


def _sweep_table(document: dict, fail) -> dict:
    """The [sweep] table, once the document has only known sections and the table only known
    keys, among them the required ``algorithm``, ``maps`` and ``seeds``."""
    for section in document:
        if section not in SECTIONS:
            fail(section, f"unknown section; expected {', '.join(sorted(SECTIONS))}")
    sweep = document.get("sweep")
    if not isinstance(sweep, dict):
        fail("[sweep]", "missing section")
    for key in sweep:
        if key not in SWEEP_KEYS:
            fail(f"sweep.{key}", f"unknown key; expected one of {', '.join(sorted(SWEEP_KEYS))}")
    for key in ("algorithm", "maps", "seeds"):
        if key not in sweep:
            fail(f"sweep.{key}", "missing")
    return sweep


def algorithm_and_name(table: dict, fail, section: str = "sweep") -> tuple[str, str]:
    """``(algorithm, name)`` of a spec's ``[section]`` table: a registered swarm and the spec's
    name (default: the algorithm's), a non-empty string without '/' since it names a
    directory; ``fail(key, problem)`` raises."""
    algorithm = table["algorithm"]
    if algorithm not in swarm_registry.registered():
        fail(f"{section}.algorithm", f"unknown algorithm {algorithm!r}; registered: "
             f"{', '.join(swarm_registry.registered())}")
    name = table.get("name", algorithm)
    if not isinstance(name, str) or not name or "/" in name:
        fail(f"{section}.name", f"must be a non-empty string without '/', got {name!r}")
    return algorithm, name


def check_maps(maps: Any, fail, key: str = "sweep.maps") -> list:
    """The map entries at ``key``, a non-empty list of entries that
    :func:`jaxswarm.maps.entry.check` accepts; ``fail(key, problem)`` raises."""
    if not isinstance(maps, list) or not maps:
        fail(key, "must be a non-empty list")
    for i, entry in enumerate(maps):
        problem = map_entry.check(entry)
        if problem:
            fail(f"{key}[{i}]", problem)
    return maps


def _run_options(sweep: dict, fail) -> dict:
    """The [sweep] numbers that shape every run, as :class:`SweepSpec` fields: ``iterations``
    (default 100), ``patience`` (default None), ``chunk_size`` (default
    ``DEFAULT_CHUNK_SIZE``) and ``vmap_size`` (default None), each a positive integer."""
    iterations = positive_int(sweep.get("iterations", 100), "sweep.iterations", fail)
    patience = sweep.get("patience")
    if patience is not None:
        patience = positive_int(patience, "sweep.patience", fail)
    chunk_size = positive_int(sweep.get("chunk_size", DEFAULT_CHUNK_SIZE), "sweep.chunk_size",
                               fail)
    vmap_size = sweep.get("vmap_size")
    if vmap_size is not None:
        vmap_size = positive_int(vmap_size, "sweep.vmap_size", fail)
    return dict(iterations=iterations, patience=patience, chunk_size=chunk_size,
                vmap_size=vmap_size)


def configured_swarm(algorithm: str, config: Any, fail):
    """The swarm the [config] table builds: a table of the factory's options that it
    accepts; ``fail(key, problem)`` raises."""
    if not isinstance(config, dict):
        fail("[config]", "must be a table")
    accepted = swarm_registry.config_options(algorithm)
    for key in config:
        if key not in accepted:
            fail(f"config.{key}", f"unknown config of {algorithm}; accepted: "
                 f"{', '.join(accepted)}")
    try:
        return swarm_registry.make(algorithm, **config)
    except (TypeError, ValueError) as error:
        fail("[config]", str(error))


def check_map_worlds(maps: list, swarm, algorithm: str, fail, key: str = "sweep.maps") -> None:
    """Every map at ``key`` is of the world the swarm plans on (a graph or a plane)."""
    for i, entry in enumerate(maps):
        world = map_entry.world_kind(entry)
        if world is not swarm.world:
            fail(f"{key}[{i}]", f"{algorithm} plans on a {swarm.world.__name__}, this map "
                 f"is a {world.__name__}")


def resolve_maps(entries: list, key: str, source: str,
                 base_dir: Path | None = None) -> list[ResolvedMap]:
    """Every map entry of ``entries`` (a spec's list at ``key``) resolved, start and goal
    placed (:func:`jaxswarm.maps.entry.resolve`).

    Raises:
      ValueError: naming the spec file ``source``, the entry (``key[i] = ENTRY``) and the
        problem.
    """
    maps = []
    for i, entry in enumerate(entries):
        try:
            maps.append(map_entry.resolve(entry, base_dir=base_dir))
        except ValueError as error:
            raise ValueError(f"{source}: {key}[{i}] = {entry!r}: {error}") from None
    return maps


def file_digests(maps: list[ResolvedMap], key: str) -> dict:
    """What the rows of ``maps`` (a spec's list at ``key``) depend on outside the spec: the
    content of every file they were read from, ``"key[i].role"`` -> ``{"file": PATH, "sha256":
    HEX}``, for a store to record and compare
    (:class:`~jaxswarm.sweep.store.ResultsStore`'s ``depends_on``)."""
    return {f"{key}[{i}].{role}": dict(file=path, sha256=digest)
            for i, resolved in enumerate(maps) for role, (path, digest) in resolved.files.items()}


def _params(params: Any, swarm, algorithm: str, fail,
            most: int | None) -> dict[str, tuple[float, ...]]:
    """The [params] table checked: param name -> its values (at most ``most`` each), for params
    the swarm knows."""
    if not isinstance(params, dict):
        fail("[params]", "must be a table")
    known = swarm.default_params._fields
    checked = {}
    for key, value in params.items():
        if key not in known:
            fail(f"params.{key}", f"unknown param of {algorithm}; known: {', '.join(known)}")
        checked[key] = _values(value, f"params.{key}", fail, most)
    return checked


def _check_grid(spec: SweepSpec, swarm, fail) -> None:
    """Every combination of the grid is a valid set of params for the swarm, so an
    out-of-range value fails here, before any compute; the error names the param the swarm's
    check names (:class:`~jaxswarm.swarm.core.ParamError`). The swarms' checks take arrays, so
    the whole grid is checked at once; only a grid that fails is gone through combination by
    combination, to name the first that does."""
    every = spec.combination_values(np.arange(spec.num_combinations))
    try:
        swarm.check_params(swarm.params_with(**every))
        return
    except ValueError:
        pass
    for combination in spec.grid():
        try:
            swarm.check_params(swarm.params_with(**combination))
        except ParamError as error:
            fail(f"params.{error.field}", str(error))
        except ValueError as error:
            fail("[params]", str(error))


def check_seeds(value: Any, fail, key: str = "sweep.seeds",
                most: int | None = None) -> tuple[int, ...]:
    """The seeds at ``key``: a count (``range(count)``, at most ``most`` seeds) or an explicit
    list of distinct integers, each in ``[0, SEED_LIMIT)`` (where seeds give distinct keys)."""
    seed_range = f"seeds are integers from 0 to {SEED_LIMIT - 1:,} (2^32 - 1)"
    if isinstance(value, int) and not isinstance(value, bool):
        if value < 1:
            fail(key, f"must be at least 1, got {value}")
        if value > SEED_LIMIT:
            fail(key, f"{value:,} seeds run past the last seed: {seed_range}, beyond which "
                 "jax.random.key repeats its keys")
        if most is not None and value > most:
            fail(key, f"{value:,} seeds, {too_many(most)}")
        return tuple(range(value))
    if isinstance(value, list) and value and all(
            isinstance(s, int) and not isinstance(s, bool) for s in value):
        outside = [s for s in value if not 0 <= s < SEED_LIMIT]
        if outside:
            fail(key, f"seed {outside[0]} is out of range: {seed_range}, beyond which "
                 "jax.random.key repeats its keys (seed s + 2^32 is seed s)")
        if len(set(value)) != len(value):
            fail(key, "repeats a seed")
        if most is not None and len(value) > most:
            fail(key, f"{len(value):,} seeds, {too_many(most)}")
        return tuple(value)
    fail(key, f"must be a count or a non-empty list of integers from 0 to {SEED_LIMIT - 1:,}, "
         f"got {value!r}")


def positive_int(value: Any, key: str, fail) -> int:
    """``value`` when it is a positive integer; else ``fail(key, problem)``."""
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        fail(key, f"must be a positive integer, got {value!r}")
    return value


def _values(value: Any, key: str, fail, most: int | None = None) -> tuple[float, ...]:
    """A param's values: a number, a list of numbers, or a range table of at most ``most``
    values (counted before they are made)."""
    if is_number(value):
        return (float(value),)
    if isinstance(value, list):
        if not value:
            fail(key, "empty list: a sweep needs at least one value")
        if not all(is_number(v) for v in value):
            fail(key, f"values must be numbers, got {value!r}")
        return tuple(float(v) for v in value)
    if isinstance(value, dict):
        return _range(value, key, fail, most)
    fail(key, f"must be a number, a list or a range table, got {value!r}")


def _range(table: dict, key: str, fail, most: int | None) -> tuple[float, ...]:
    allowed = {"start", "stop", "num", "step", "log"}
    unknown = set(table) - allowed
    if unknown:
        fail(key, f"unknown range keys {sorted(unknown)}; use start, stop and num (with "
             "log = true for geometric spacing) or start, stop and step")
    if "start" not in table or "stop" not in table:
        fail(key, "a range needs start and stop")
    start, stop = table["start"], table["stop"]
    if not (is_number(start) and is_number(stop)):
        fail(key, "start and stop must be numbers")
    if ("num" in table) == ("step" in table):
        fail(key, "give exactly one of num (inclusive linspace) and step (arange)")
    if "num" in table:
        num = table["num"]
        if isinstance(num, bool) or not isinstance(num, int) or num < 1:
            fail(key, f"num must be a positive integer, got {num!r}")
        if most is not None and num > most:
            fail(key, f"num = {num:,} values make at least {num:,} runs, {too_many(most)}")
        if table.get("log", False):
            if start <= 0 or stop <= 0:
                fail(key, "a log range needs positive start and stop")
            values = np.geomspace(start, stop, num)
        else:
            values = np.linspace(start, stop, num)
    else:
        step = table["step"]
        if not is_number(step) or step == 0 or (stop - start) / step < 0:
            fail(key, f"step {step!r} does not lead from {start} to {stop}")
        count = (stop - start) / step  # np.arange makes ceil(count) values
        if most is not None and count > most:
            fail(key, f"about {count:,.0f} values make as many runs, {too_many(most)}")
        values = np.arange(start, stop, step)
    if len(values) == 0:
        fail(key, "the range is empty: a sweep needs at least one value")
    return tuple(float(v) for v in values)


def is_number(value: Any) -> bool:
    """Whether ``value`` is an int or a float (not a bool)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)
