"""Replay one row of a sweep store, or of a table of ``results/``, alone, and check that it
reproduces the stored figures.

A store's ``metadata.json`` holds the spec, so a row's run is known from the row itself: its map
(``map_index`` into the spec's maps), its params (the swept columns, every other param the
swarm's default) and its key (``jax.random.key(seed)``). A table's ``runs.csv`` row carries its
own ``run_record`` (:mod:`jaxswarm.sweep.run_record`: swarm, params, map entry, key data, stop
rules). :func:`replay_row` runs the row once, alone, and compares its figures with the stored
ones, bit for bit: for a store cost, iterations, moves, evaluations and the fingerprint of the
final state and trace (:func:`jaxswarm.swarm.fingerprint.run_fingerprint`); for a table cost and
fingerprint. The replay holds the run's state, so its memory and best path can be drawn
(:func:`jaxswarm.plot.sweep.plot_replay`); ``jaxswarm replay STORE ROW`` does both. A row is
checked before it runs: a tune's store, or a row whose figures are not a finished run's (NaN, a
missing value), is refused with the store, the row and the column named.
"""
from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path
from typing import Any

import jax
import numpy as np
import pandas as pd

from jaxswarm.maps.entry import ResolvedMap, resolve
from jaxswarm.sweep.run_record import read_run_record
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.core import Swarm, Task, Trace
from jaxswarm.swarm.fingerprint import hex_fingerprint, run_fingerprint
from jaxswarm.sweep.spec import SEED_LIMIT, spec_from_record
from jaxswarm.sweep.store import ResultsStore, read_results

CHECKED = ("cost", "iterations", "moves", "evaluations", "fingerprint")
"""The stored figures a replay of a store's row must reproduce bit for bit."""
TABLE_CHECKED = ("cost", "fingerprint")
"""The stored figures a replay of a table's row must reproduce bit for bit."""


@dataclasses.dataclass(frozen=True)
class Replayed:
    """One row of a store run again alone.

    Attributes:
      row: the stored row (column -> value).
      swarm: the swarm the store's spec makes.
      sweep_map: the row's map, resolved again.
      task: its start and goal as the swarm's Task.
      state, trace: what the replayed run returned.
      figures: the replayed values of the checked figures (:data:`CHECKED` for a store's row,
        :data:`TABLE_CHECKED` for a table's).
      differences: ``"column: stored X, replayed Y"`` for every figure that differs (empty when
        the replay reproduces the row).
    """

    row: dict
    swarm: Swarm
    sweep_map: ResolvedMap
    task: Task
    state: Any
    trace: Trace
    figures: dict
    differences: list[str]

    @property
    def reproduced(self) -> bool:
        """Whether every checked figure is the stored one, bit for bit."""
        return not self.differences

    @property
    def title(self) -> str:
        """``"SWARM on MAP, seed S"`` (``run R`` too for a store's row)."""
        run_index = f", run {self.row['run']}" if "map_index" in self.row else ""
        return (f"{self.swarm.name} on {self.sweep_map.label}{run_index}, "
                f"seed {self.row.get('seed', '?')}")


def replay_row(store, row: int) -> Replayed:
    """Run row ``row`` of a sweep store or of a results table again, alone, and compare it with
    the row.

    Args:
      store: a store directory (:func:`jaxswarm.sweep.run_sweep`'s ``out``), or a folder of
        ``results/`` whose ``runs.csv`` has a ``run_record`` column.
      row: the row's position (from 0) in :func:`jaxswarm.sweep.read_results` of the store, or
        in ``runs.csv``.

    Raises:
      ValueError: ``store`` is neither (a tune's store among them), ``row`` is not one of its
        rows, a table's row has no run record, or a figure or input of the row is not a
        finished run's (NaN, missing); each before the run.
    """
    store = Path(store)
    if not (store / "metadata.json").is_file() and (store / "runs.csv").is_file():
        return _replay_table_row(store / "runs.csv", row)
    metadata_path = store / "metadata.json"
    if not metadata_path.is_file():
        raise ValueError(f"{store} is not a sweep store (it has no metadata.json), nor a "
                         "results folder with a runs.csv")
    record = _sweep_record(metadata_path)
    frame = read_results(store)
    if frame.empty:
        raise ValueError(f"{store} is a sweep store without finished rows yet")
    stored = _stored_row(frame, row, store)
    spec = spec_from_record(record, source=str(metadata_path))
    source = f"{store} row {row}"
    _check_integer(stored, "map_index", range(len(spec.maps)), source)
    _check_integer(stored, "seed", range(SEED_LIMIT), source)
    for name in spec.params:
        _check_number(stored, name, source, finite=True)
    _check_figures(stored, CHECKED, source)
    swarm = make(spec.algorithm, **spec.config)
    params = swarm.params_with(**{name: stored[name] for name in spec.params})
    return _replayed(stored, swarm, params, resolve(spec.maps[int(stored["map_index"])]),
                     jax.random.key(int(stored["seed"])), spec.iterations, spec.patience,
                     CHECKED)


def _replay_table_row(table: Path, row: int) -> Replayed:
    """Row ``row`` of a results table (``runs.csv``) replayed from its ``run_record``."""
    frame = pd.read_csv(table, dtype={"run_record": str, "fingerprint": str},
                        keep_default_na=False)
    missing = [name for name in ("run_record", *TABLE_CHECKED) if name not in frame]
    if missing:
        raise ValueError(f"{table} has no {', '.join(missing)} column: its rows are not "
                         "replayable")
    stored = _stored_row(frame, row, table)
    record = read_run_record(stored["run_record"], source=f"{table} row {row}")
    _check_figures(stored, TABLE_CHECKED, f"{table} row {row}")
    return _replayed(stored, record.swarm, record.params, resolve(record.entry), record.key,
                     record.iterations, record.patience, TABLE_CHECKED)


def _sweep_record(metadata_path: Path) -> dict:
    """The sweep spec a store's ``metadata.json`` records, or a ValueError naming the file:
    not a JSON object (:meth:`~jaxswarm.sweep.store.ResultsStore.read_metadata`), a tune's
    store (its spec names a method and training instances), or no spec."""
    record = ResultsStore.read_metadata(metadata_path.parent).get("spec")
    if isinstance(record, dict) and "training" in record and "method" in record:
        raise ValueError(f"{metadata_path.parent} is a tune's store (jaxswarm tune), not a "
                         "sweep's: replay takes a sweep's store or a results folder with a "
                         "runs.csv")
    needed = ("name", "algorithm", "maps", "seeds", "iterations", "chunk_size", "config",
              "params")
    missing = [key for key in needed if not isinstance(record, dict) or key not in record]
    if missing:
        raise ValueError(f"{metadata_path}: holds no sweep spec (\"spec\" lacks "
                         f"{', '.join(missing)})")
    return record


def _check_figures(stored: dict, checked: tuple[str, ...], source: str) -> None:
    """The stored figures a replay compares are a finished run's: ``cost`` a number (inf for
    no path, never NaN), the counts non-negative integers, the fingerprint 16 hex digits."""
    for name in checked:
        if name == "cost":
            _check_number(stored, name, source, finite=False)
        elif name == "fingerprint":
            value = stored.get(name)
            if not isinstance(value, str) or not re.fullmatch(r"[0-9a-f]{16}", value):
                raise ValueError(f"{source}: {name} is {value!r}, not 16 hex digits: not a "
                                 "finished run's figure, so the row cannot be replayed")
        else:
            _check_integer(stored, name, None, source)


def _check_number(stored: dict, name: str, source: str, *, finite: bool) -> None:
    """``stored[name]`` is a number, not NaN (and finite when ``finite``)."""
    value = stored.get(name)
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if math.isnan(number) or (finite and math.isinf(number)):
        raise ValueError(f"{source}: {name} is {value!r}, not a finished run's value, so the "
                         "row cannot be replayed")


def _check_integer(stored: dict, name: str, allowed: range | None, source: str) -> None:
    """``stored[name]`` is a non-negative integer (in ``allowed`` when given)."""
    value = stored.get(name)
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not number.is_integer() or number < 0 or (allowed is not None
                                                 and int(number) not in allowed):
        where = "" if allowed is None else f" in {allowed.start} to {allowed.stop - 1}"
        raise ValueError(f"{source}: {name} is {value!r}, not an integer{where} of a finished "
                         "run, so the row cannot be replayed")


def _stored_row(frame: pd.DataFrame, row: int, source: Path) -> dict:
    """Row ``row`` of ``frame`` as a dict, or a ValueError naming ``source``'s rows."""
    if not 0 <= row < len(frame):
        raise ValueError(f"{source} has rows 0 to {len(frame) - 1}, not row {row}")
    return frame.iloc[row].to_dict()


def _replayed(stored: dict, swarm: Swarm, params, sweep_map: ResolvedMap, key: jax.Array,
              iterations: int, patience: int | None, checked: tuple[str, ...]) -> Replayed:
    """Run ``swarm`` alone on ``sweep_map`` with ``key`` and compare ``checked`` figures with
    the ``stored`` row."""
    task = make_task(sweep_map.world, sweep_map.start, sweep_map.goal)
    state, trace = run(swarm, key, sweep_map.world, task, params, iterations=iterations,
                       patience=patience)
    figures = dict(cost=float(swarm.best(state).cost), iterations=int(trace.iterations),
                   moves=int(np.sum(np.asarray(trace.moves), dtype=np.int64)),
                   evaluations=int(np.sum(np.asarray(trace.evaluations), dtype=np.int64)),
                   fingerprint=hex_fingerprint(run_fingerprint(state, trace)))
    figures = {name: figures[name] for name in checked}
    return Replayed(row=stored, swarm=swarm, sweep_map=sweep_map, task=task, state=state,
                    trace=trace, figures=figures,
                    differences=[f"{name}: stored {stored[name]!r}, replayed {figures[name]!r}"
                                 for name in checked if not _same(stored[name], figures[name])])


def _same(stored, replayed) -> bool:
    """Equal bit for bit as stored (a cost as float64 of a float32; inf equals inf)."""
    if isinstance(replayed, float):
        return float(stored) == replayed or (math.isnan(float(stored)) and math.isnan(replayed))
    return stored == replayed
