"""Scoring settings on instances: the runs a tuner asks for, made once and stored.

:class:`Evaluator` runs each request of a tune (settings x instances) as one numbered batch
through the swarm's compiled batches (:class:`~jaxswarm.sweep.batches.RunBatches`) and writes its
rows to the tune's store (:class:`~jaxswarm.sweep.store.ResultsStore`, one Parquet file per
batch). A batch the store holds is read back instead of run, once checked to hold the same
settings on the same instances, so a killed tune resumes without losing or repeating a run; the
store refuses a resume across a change of the tuner (:func:`tuner_record`) or of a map file
(:func:`~jaxswarm.sweep.spec.file_digests`). Per run, the loss (:func:`run_losses`; lower is
better) is ``success`` (0 within 1e-4 of the optimum, else 1), ``gap`` (``unsolved_gap`` without
a path), ``time_to_target`` (the iterations until within the gap, twice the budget when never)
or ``evaluations`` (the same in fitness evaluations); ``docs/tuning.md`` defines each.
"""
from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from jaxswarm.swarm import definition
from jaxswarm.swarm.fingerprint import hex_fingerprint
from jaxswarm.sweep.batches import RunBatches, run_outcomes
from jaxswarm.sweep.runner import provenance
from jaxswarm.sweep.spec import file_digests, resolve_maps
from jaxswarm.sweep.store import ResultsStore
from jaxswarm.tune.spec import TuneSpec

TRAINING, HELD_OUT = "training", "held_out"
"""The two phases of a tune: the search, on training instances, and the rescoring of its best
settings on held-out ones."""


TUNER_VERSION = 1
"""The version of the tuner's decisions: raise it when a tuner of the same spec, given the same
results, asks for other settings or in another order (:mod:`jaxswarm.tune.race`,
:mod:`jaxswarm.tune.search`, :mod:`jaxswarm.tune.space`), so that a store of the old tuner is
not resumed."""


def tuner_record() -> dict:
    """What a tune's settings follow from besides its spec and results, as its store records
    it: ``{"version": TUNER_VERSION, "sampler": "<bit generator> of numpy <major.minor>"}`` (a
    NumPy feature release may change the streams of ``numpy.random.Generator``'s methods)."""
    generator = type(np.random.default_rng(0).bit_generator).__name__
    numpy_release = ".".join(np.__version__.split(".")[:2])
    return dict(version=TUNER_VERSION, sampler=f"{generator} of numpy {numpy_release}")


class StoreConflictError(ValueError):
    """A tune's store holds another batch where this tune asks for one."""


@dataclasses.dataclass(frozen=True)
class Setting:
    """A setting a tuner made: its number (in the order the tuner made them) and its values
    (name -> value of every param of the space)."""

    number: int
    values: dict


def instance_order(instances: list, rng: np.random.Generator) -> list:
    """``instances`` in the order the tuner's generator shuffles them (every method's: a race
    and the searches of one tuner seed take the same order)."""
    return [instances[i] for i in rng.permutation(len(instances))]


def run_losses(spec: TuneSpec, rows: pd.DataFrame, num_agents: int) -> np.ndarray:
    """f64[C] each row's loss under ``spec.objective`` (see the module docstring)."""
    if spec.objective == "success":
        return 1.0 - rows["success"].to_numpy(np.float64)
    if spec.objective == "gap":
        return np.where(rows["found"], rows["gap"], spec.unsolved_gap).astype(np.float64)
    if spec.objective == "time_to_target":
        reached = rows["target_iterations"].to_numpy()
        return np.where(reached >= 0, reached, 2 * spec.iterations).astype(np.float64)
    reached = rows["target_evaluations"].to_numpy()
    return np.where(reached >= 0, reached,
                    2 * spec.iterations * num_agents).astype(np.float64)


def reported(spec: TuneSpec, losses: np.ndarray) -> float:
    """The objective as reported from losses: the success rate for ``success``, else the mean
    loss."""
    mean = float(np.mean(losses))
    return 1.0 - mean if spec.objective == "success" else mean


class Evaluator:
    """A tune's runs: settings scored on instances, batch by batch, through its store.

    Attributes:
      spec: the tune.
      maps: the training and held-out maps, resolved (phase -> list of
        :class:`~jaxswarm.maps.entry.ResolvedMap`).
      runs_spent: training runs made or read back so far (the budget counts these).
    """

    def __init__(self, spec: TuneSpec, out, log: Callable[[str], None] = print):
        """Resolve every map of ``spec`` (naming the entry that fails, before anything is
        written) and open (or resume) the store at ``out``.

        Raises:
          ValueError: a map cannot be resolved.
          StoreMismatchError: ``out`` holds another tune, another definition of the swarm, runs
            on another content of a map file or of another tuner (:func:`tuner_record`).
          StoreBusyError: another process is writing ``out``.
        """
        self.spec = spec
        self.log = log
        base_dir = Path(spec.source).parent if spec.source != "<dict>" else None
        self.maps = {phase: resolve_maps(instances.maps, f"tune.{phase}.maps", spec.source,
                                         base_dir)
                     for phase, instances in ((TRAINING, spec.training),
                                              (HELD_OUT, spec.held_out))}
        self._batches: dict = {}
        swarm = self._batches_for({}).swarm
        depends_on = {key: record for phase, maps in self.maps.items()
                      for key, record in file_digests(maps, f"tune.{phase}.maps").items()}
        self.store = ResultsStore(Path(out), spec.as_dict(),
                                  dict(provenance(), swarm=definition(swarm)),
                                  depends_on=dict(depends_on, tuner=tuner_record()))
        self._optimum = {phase: [m.optimum() for m in maps] for phase, maps in self.maps.items()}
        self.runs_spent = 0
        self._next = 0

    def score(self, settings: list[Setting], instances: list[tuple[int, int]], *,
              phase: str = TRAINING, iteration: int = 0) -> np.ndarray:
        """f64[len(settings), len(instances)] the losses of every setting on every instance
        (``(map index, seed)`` of ``phase``'s maps): :meth:`rows`' ``loss``."""
        rows = self.rows(settings, instances, phase=phase, iteration=iteration)
        return rows["loss"].to_numpy(np.float64).reshape(len(settings), len(instances))

    def rows(self, settings: list[Setting], instances: list[tuple[int, int]], *,
             phase: str = TRAINING, iteration: int = 0) -> pd.DataFrame:
        """The runs of every setting on every instance (setting-major), as one numbered batch
        of the store: read back when the store holds it, else run and written. ``iteration``
        (the race's) is recorded with the rows."""
        number = self._next
        self._next += 1
        if self.store.finished(0, number):
            rows = pd.read_parquet(self.store.chunk_path(0, number))
            _check_same(rows, settings, instances, phase, self.store.chunk_path(0, number))
        else:
            rows = self._run(settings, instances, phase, iteration, number)
            self.store.write_chunk(0, number, {name: column.to_numpy()
                                               for name, column in rows.items()})
        if phase == TRAINING:
            self.runs_spent += len(rows)
        return rows

    def _run(self, settings, instances, phase, iteration, number) -> pd.DataFrame:
        """The rows of every setting on every instance, setting-major: one call of the swarm's
        batches per instance and value of the static params."""
        spec = self.spec
        static = spec.space.static
        groups: dict = {}
        for s, setting in enumerate(settings):
            groups.setdefault(tuple(setting.values[name] for name in static), []).append(s)
        parts = []
        for key, members in groups.items():
            batches = self._batches_for(dict(zip(static, key)))
            params = {name: np.array([float(settings[s].values[name]) for s in members])
                      for name in spec.space.domains if name not in static}
            params |= {name: np.full(len(members), value) for name, value in spec.fixed.items()}
            for i, (map_index, seed) in enumerate(instances):
                sweep_map, optimum = self.maps[phase][map_index], self._optimum[phase][map_index]
                outputs = batches.run(sweep_map, np.full(len(members), seed), params, optimum)
                cost = np.asarray(outputs["cost"], np.float64)
                parts.append(pd.DataFrame(dict(
                    position=members, instance=i, map=sweep_map.label, map_index=map_index,
                    seed=seed, cost=cost, optimum=optimum, **run_outcomes(cost, optimum),
                    fingerprint=[hex_fingerprint(f) for f in outputs["fingerprint"]],
                    num_agents=batches.swarm.config.num_agents,
                    **{name: outputs[name] for name in _COUNTS})))
        runs = pd.concat(parts).sort_values(["position", "instance"], kind="stable")
        values = pd.DataFrame([{f"param.{k}": float(v) for k, v in setting.values.items()}
                               for setting in settings])
        rows = pd.concat([
            pd.DataFrame(dict(batch=number, phase=phase, iteration=iteration,
                              setting=[settings[p].number for p in runs["position"]])),
            values.iloc[runs["position"]].reset_index(drop=True),
            runs.drop(columns=["position", "num_agents"]).reset_index(drop=True)], axis=1)
        rows["loss"] = run_losses(spec, rows, runs["num_agents"].to_numpy())
        return rows

    def _batches_for(self, static: dict) -> RunBatches:
        """The compiled batches of the swarm with the static params ``static``."""
        key = tuple(sorted(static.items()))
        if key not in self._batches:
            spec = self.spec
            self._batches[key] = RunBatches(spec.algorithm, {**spec.config, **static},
                                            spec.iterations, spec.patience, spec.chunk_size,
                                            log=self.log, fit_calls=True)
        return self._batches[key]


_COUNTS = ("iterations", "moves", "evaluations", "target_iterations", "target_evaluations",
           "seconds")
"""The outputs of :meth:`~jaxswarm.sweep.batches.RunBatches.run` a row keeps as they are."""


def _check_same(rows: pd.DataFrame, settings, instances, phase, path) -> None:
    """The stored batch ``rows`` holds ``settings`` (their numbers and param values) on
    ``instances`` of ``phase``.

    Raises:
      StoreConflictError: naming the batch's file and the first column that differs.
    """
    want = dict(setting=[setting.number for setting in settings for _ in instances],
                instance=[i for _ in settings for i in range(len(instances))],
                phase=[phase] * (len(settings) * len(instances)),
                seed=[seed for _ in settings for _, seed in instances])
    for name in settings[0].values if settings else ():
        want[f"param.{name}"] = [float(setting.values[name]) for setting in settings
                                 for _ in instances]
    differs = [name for name, values in want.items()
               if name not in rows or list(rows[name]) != values]
    if differs:
        raise StoreConflictError(
            f"{path} holds another batch than this tune asks for (differs in: {differs[0]}; a "
            "tune's batches follow from its spec and tuner: was the store written by another "
            "version?); choose another --out or delete it")
