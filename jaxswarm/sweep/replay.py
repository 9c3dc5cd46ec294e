"""Replay one row of a sweep store alone, and check that it reproduces the stored figures.

A store's ``metadata.json`` holds the spec, so a row's run is known from the row itself: its map
(``map_index`` into the spec's maps), its params (the swept columns, every other param the
swarm's default) and its key (``jax.random.key(seed)``). :func:`replay_row` runs it once, alone,
and compares cost, iterations, moves, evaluations and the fingerprint of the final state and
trace (:func:`jaxswarm.swarm.fingerprint.run_fingerprint`) with the stored ones, bit for bit. The
replay holds the run's state, so its memory and best path can be drawn
(:func:`jaxswarm.plot.sweep.plot_replay`); ``jaxswarm replay STORE ROW`` does both.
"""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import jax
import numpy as np

from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.core import Swarm, Task, Trace
from jaxswarm.swarm.fingerprint import hex_fingerprint, run_fingerprint
from jaxswarm.sweep.maps import SweepMap, resolve_map
from jaxswarm.sweep.spec import spec_from_record
from jaxswarm.sweep.store import read_results

CHECKED = ("cost", "iterations", "moves", "evaluations", "fingerprint")
"""The stored figures a replay must reproduce bit for bit."""


@dataclasses.dataclass(frozen=True)
class Replayed:
    """One row of a store run again alone.

    Attributes:
      row: the stored row (column -> value).
      swarm: the swarm the store's spec makes.
      sweep_map: the row's map, resolved again.
      task: its start and goal as the swarm's Task.
      state, trace: what the replayed run returned.
      figures: the replayed values of :data:`CHECKED`.
      differences: ``"column: stored X, replayed Y"`` for every figure that differs (empty when
        the replay reproduces the row).
    """

    row: dict
    swarm: Swarm
    sweep_map: SweepMap
    task: Task
    state: Any
    trace: Trace
    figures: dict
    differences: list[str]

    @property
    def reproduced(self) -> bool:
        """Whether every figure of :data:`CHECKED` is the stored one, bit for bit."""
        return not self.differences


def replay_row(store, row: int) -> Replayed:
    """Run row ``row`` of the store at ``store`` again, alone, and compare it with the row.

    Args:
      store: a store directory (:func:`jaxswarm.sweep.run_sweep`'s ``out``).
      row: the row's position in :func:`jaxswarm.sweep.read_results` of the store (from 0).

    Raises:
      ValueError: ``store`` is not a store with rows, or ``row`` is not one of its rows.
    """
    store = Path(store)
    metadata_path = store / "metadata.json"
    frame = read_results(store)
    if not metadata_path.is_file() or frame.empty:
        raise ValueError(f"{store} is not a sweep store with finished rows")
    if not 0 <= row < len(frame):
        raise ValueError(f"{store} has rows 0 to {len(frame) - 1}, not row {row}")
    stored = frame.iloc[row].to_dict()
    spec = spec_from_record(json.loads(metadata_path.read_text())["spec"],
                            source=str(metadata_path))
    swarm = make(spec.algorithm, **spec.config)
    sweep_map = resolve_map(spec.maps[int(stored["map_index"])])
    task = make_task(sweep_map.world, sweep_map.start, sweep_map.goal)
    params = swarm.default_params._replace(**{
        name: np.float32(stored[name]) for name in spec.params})
    state, trace = run(swarm, jax.random.key(int(stored["seed"])), sweep_map.world, task, params,
                       iterations=spec.iterations, patience=spec.patience)
    figures = dict(cost=float(swarm.best(state).cost), iterations=int(trace.iterations),
                   moves=int(np.sum(np.asarray(trace.moves), dtype=np.int64)),
                   evaluations=int(np.sum(np.asarray(trace.evaluations), dtype=np.int64)),
                   fingerprint=hex_fingerprint(run_fingerprint(state, trace)))
    return Replayed(row=stored, swarm=swarm, sweep_map=sweep_map, task=task, state=state,
                    trace=trace, figures=figures,
                    differences=[f"{name}: stored {stored[name]!r}, replayed {figures[name]!r}"
                                 for name in CHECKED if not _same(stored[name], figures[name])])


def _same(stored, replayed) -> bool:
    """Equal bit for bit as stored (a cost as float64 of a float32; inf equals inf)."""
    if isinstance(replayed, float):
        return float(stored) == replayed or (math.isnan(float(stored)) and math.isnan(replayed))
    return stored == replayed
