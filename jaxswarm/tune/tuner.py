"""``jaxswarm tune``: search a swarm's open constants on training instances, then rescore the
best settings beside its baseline (the swarm's defaults, or the spec's ``[tune.baseline]``) on
held-out instances.

A tune writes to its directory (``out/tune/<name>`` by default)::

    metadata.json   the spec, versions, machine, git commit, the swarm's definition
    runs/           every run: one Parquet file per batch the tuner asked for (see
                    :mod:`jaxswarm.tune.evaluate`: a killed tune resumes from it)
    race.csv        the race's log (method race): who ran on which instance, who was dropped
                    after which instance and by which test
    race.png        the race drawn: each setting's life over the instances
    held_out.csv    the baseline and the best settings on the held-out instances: the objective
                    with a 95 % bootstrap interval over the instances
    held_out_maps.csv  the same per held-out map
    best.json       the best setting's values

The search never sees a held-out run: the best setting is chosen on training runs alone.
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from jaxswarm.runtime.atomic import write_atomically
from jaxswarm.swarm import registry as swarm_registry
from jaxswarm.sweep.runner import check_folder
from jaxswarm.tune.evaluate import HELD_OUT, Evaluator, Setting, reported
from jaxswarm.tune.figures import race_figure
from jaxswarm.tune.race import iterated_race
from jaxswarm.tune.search import es_search, grid_search, random_search
from jaxswarm.tune.spec import TuneSpec

BOOTSTRAP_SAMPLES = 2000
"""Resamples of the held-out instances behind each interval."""


@dataclasses.dataclass
class TuneResult:
    """A finished tune.

    Attributes:
      best: the best setting's values (name -> value).
      held_out: one row per rescored setting (``label``: ``baseline``, ``best``, ``elite 2``
        ...; its values; ``objective``, ``low`` and ``high`` of the 95 % interval, ``found``
        and ``success``: the shares of its runs that found a path and that were within the
        success gap of the optimum, ``runs``).
      held_out_maps: the same per held-out map (``label``, ``map``, ``objective``, ``found``,
        ``success``, ``runs``): where a setting gains or loses.
      race: the race's log (method race; else None).
      runs_spent: training runs the search made.
      out: the tune's directory.
    """

    best: dict
    held_out: pd.DataFrame
    held_out_maps: pd.DataFrame
    race: pd.DataFrame | None
    runs_spent: int
    out: Path


def default_tune_out(spec: TuneSpec) -> Path:
    """``out/tune/<name>``: where a tune writes unless told otherwise."""
    return Path("out") / "tune" / spec.name


def tune(spec: TuneSpec, out=None, *, log: Callable[[str], None] = print) -> TuneResult:
    """Run (or resume) a tune and rescore its best settings on the held-out instances.

    Args:
      spec: a checked spec (:func:`jaxswarm.tune.load_tune_spec`).
      out: the tune's directory (default :func:`default_tune_out`).
      log: where one-line messages go (compiles).

    Raises:
      ValueError: a map cannot be resolved or ``out`` is a file (before any compute); ``out``
        holds another tune, runs on a map file that changed since, or batches of another
        tuner or sampler
        (:class:`~jaxswarm.sweep.store.StoreMismatchError`,
        :class:`~jaxswarm.tune.evaluate.StoreConflictError`); another process is writing
        ``out`` (:class:`~jaxswarm.sweep.store.StoreBusyError`).
    """
    out = Path(out) if out is not None else default_tune_out(spec)
    check_folder(out, "out")
    evaluator = Evaluator(spec, out, log)
    rng = np.random.default_rng(spec.seed)
    baseline = baseline_values(spec)
    space = spec.space
    race = None
    if spec.method == "race":
        result = iterated_race(evaluator, space, baseline, rng)
        best, race = result.elites, result.log
    elif spec.method == "random":
        best = random_search(evaluator, space, baseline, rng).best
    elif spec.method == "grid":
        best = grid_search(evaluator, space, rng).best
    else:
        best = es_search(evaluator, space, baseline, rng).best
    spent = evaluator.runs_spent
    rescored = [Setting(-1, baseline)] + best[:3]
    labels = ["baseline", "best"] + [f"elite {i}" for i in range(2, len(rescored))]
    rows = evaluator.rows(rescored, spec.held_out.pairs, phase=HELD_OUT)
    held_out = _held_out_table(spec, rescored, labels, rows)
    held_out_maps = _per_map(spec, labels, rows)
    _write(out, held_out, held_out_maps, race, best[0].values)
    if race is not None:
        race_figure(race, out / "race.png", title=f"{spec.name}: {spec.algorithm}, "
                    f"{spec.objective}")
    return TuneResult(best=best[0].values, held_out=held_out, held_out_maps=held_out_maps,
                      race=race, runs_spent=spent, out=out)


def default_values(spec: TuneSpec) -> dict:
    """The value of every param of the space the swarm has without the tune: its default
    params (or the spec's fixed values) and its factory's default config."""
    swarm = swarm_registry.make(spec.algorithm, **spec.config)
    values = dict(swarm.default_params._asdict()) | spec.fixed
    values |= {name: getattr(swarm.config, name) for name in spec.space.static}
    return {name: values[name] for name in spec.space.domains}


def baseline_values(spec: TuneSpec) -> dict:
    """The setting a tune starts from and rescores beside its best: :func:`default_values`
    with the spec's ``[tune.baseline]`` over them (a tied param follows its param)."""
    values = default_values(spec) | spec.baseline
    return spec.space.complete({name: values[name] for name in spec.space.free})


def _held_out_table(spec: TuneSpec, settings: list[Setting], labels: list[str],
                    rows: pd.DataFrame) -> pd.DataFrame:
    """One row per setting: its label, values, objective and 95 % bootstrap interval over the
    held-out instances, and its share of runs that found a path and that succeeded (``rows``
    the held-out runs, setting-major)."""
    rng = np.random.default_rng(0)
    count = len(rows) // len(settings)
    draws = rng.integers(count, size=(BOOTSTRAP_SAMPLES, count))
    table = []
    for s, (label, setting) in enumerate(zip(labels, settings)):
        runs = rows.iloc[s * count:(s + 1) * count]
        losses = runs["loss"].to_numpy(np.float64)
        low, high = np.percentile([reported(spec, losses[d]) for d in draws], [2.5, 97.5])
        table.append(dict(label=label, **setting.values, objective=reported(spec, losses),
                          low=float(low), high=float(high), found=float(runs["found"].mean()),
                          success=float(runs["success"].mean()), runs=count))
    return pd.DataFrame(table)


def _per_map(spec: TuneSpec, labels: list[str], rows: pd.DataFrame) -> pd.DataFrame:
    """One row per setting and held-out map: its objective, shares of runs that found a path
    and that succeeded, and runs (``rows`` the held-out runs, setting-major)."""
    count = len(rows) // len(labels)
    labelled = rows.assign(label=np.repeat(labels, count))
    table = [dict(label=label, map=map_name,
                  objective=reported(spec, runs["loss"].to_numpy(np.float64)),
                  found=float(runs["found"].mean()), success=float(runs["success"].mean()),
                  runs=len(runs))
             for (label, map_name), runs in labelled.groupby(["label", "map"], sort=False)]
    return pd.DataFrame(table)


def _write(out: Path, held_out: pd.DataFrame, held_out_maps: pd.DataFrame,
           race: pd.DataFrame | None, best: dict) -> None:
    write_atomically(out / "held_out.csv", held_out.to_csv(index=False))
    write_atomically(out / "held_out_maps.csv", held_out_maps.to_csv(index=False))
    if race is not None:
        write_atomically(out / "race.csv", race.to_csv(index=False))
    write_atomically(out / "best.json", json.dumps(best, indent=2, default=float))
