"""What a table row needs to be run again alone: ``jaxswarm replay results/NAME ROW``.

A table script that runs a swarm from its first memory writes, beside its own columns, the
:data:`COLUMNS`: ``run_record``, a JSON record of everything the run depended on (the swarm's name,
every Config field and every param, the map as a sweep-spec map entry
(:mod:`jaxswarm.maps.entry`), the key's data, the iteration budget and the patience), and
``fingerprint``, the 64-bit fingerprint of its final state and trace
(:func:`jaxswarm.swarm.fingerprint.run_fingerprint`). :func:`jaxswarm.sweep.replay.replay_row`
reads them back. A row whose map has no entry (a map built by the script itself) has an empty
``run_record``.
"""
from __future__ import annotations

import json
from typing import Any, NamedTuple

import jax
import numpy as np

from jaxswarm.maps.entry import check as check_map_entry
from jaxswarm.swarm import Swarm, make
from jaxswarm.swarm.fingerprint import hex_fingerprint, run_fingerprint
from jaxswarm.swarm.registry import config_record

COLUMNS = ("run_record", "fingerprint")
"""The columns a replayable table row carries."""
FIELDS = ("algorithm", "config", "params", "map", "key", "iterations", "patience")
"""The keys of a run record."""


class RunRecord(NamedTuple):
    """A run record read back.

    Attributes:
      swarm: the swarm, made again from its name and Config fields.
      params: its Params (float32 leaves), as the run had them.
      entry: the map entry (:func:`jaxswarm.maps.entry.resolve` builds the map again).
      key: the run's PRNG key (key[]).
      iterations, patience: the stop rules of :func:`jaxswarm.swarm.run`.
    """

    swarm: Swarm
    params: Any
    entry: Any
    key: jax.Array
    iterations: int
    patience: int | None


def run_record(swarm: Swarm, params, entry, key: jax.Array, *, iterations: int,
               patience: int | None) -> str:
    """The ``run_record`` column of one run: JSON (see the module docstring).

    Args:
      swarm, params: the swarm and its Params (scalar leaves).
      entry: the map's sweep-spec entry; None gives "" (the row is not replayable).
      key: the run's key (key[], any derivation: its data is kept).
      iterations, patience: the stop rules the run had.
    """
    if entry is None:
        return ""
    return json.dumps(dict(
        algorithm=swarm.name, config=config_record(swarm.config),
        params={name: float(np.asarray(value)) for name, value in params._asdict().items()},
        map=entry, key=np.asarray(jax.random.key_data(key)).tolist(),
        iterations=int(iterations), patience=patience), separators=(",", ":"))


def replay_columns(record: str, state, trace) -> dict:
    """The :data:`COLUMNS` of a finished run: ``record`` (:func:`run_record`) and the
    fingerprint of its final ``state`` and ``trace``."""
    return dict(run_record=record, fingerprint=hex_fingerprint(run_fingerprint(state, trace)))


def read_run_record(text: str, *, source: str) -> RunRecord:
    """A ``run_record`` column read back; ``source`` names the row in errors.

    Raises:
      ValueError: empty (the row is not replayable), not JSON, a missing field, an unknown
        swarm or option, or a malformed map entry.
    """
    if not isinstance(text, str) or not text:
        raise ValueError(f"{source}: no run record (its map was built by the table script, or "
                         "the row is an exact planner's)")
    try:
        record = json.loads(text)
    except json.JSONDecodeError as error:
        raise ValueError(f"{source}: the run record is not JSON ({error})") from None
    missing = [name for name in FIELDS if name not in record]
    if missing:
        raise ValueError(f"{source}: the run record lacks {', '.join(missing)}")
    problem = check_map_entry(record["map"])
    if problem:
        raise ValueError(f"{source}: {problem}")
    swarm = make(record["algorithm"], **record["config"])
    params = swarm.params_with(**record["params"])
    key = jax.random.wrap_key_data(np.asarray(record["key"], np.uint32))
    return RunRecord(swarm, params, record["map"], key, int(record["iterations"]),
                     record["patience"])
