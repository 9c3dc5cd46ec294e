"""The papers' open constants calibrated: every tune spec of ``tunes/`` raced, its best setting
rescored beside its baseline (the swarm's defaults before the calibration) on held-out instances;
whether the best setting is now the swarm's default; and, with ``--compare`` or ``--compare-specs``,
racing against random search, the grid and evolution strategies.

Per spec (``--specs``, default every ``tunes/*.toml``; ``--quick``: ``tunes/quick/*.toml``), one
tune (:func:`jaxswarm.tune.tune`, its store under ``--stores``): the race, then the baseline and the
best settings on the spec's held-out instances, the objective with a 95 % bootstrap interval over
them, and the shares of runs that found a path and that reached the optimum. With ``--compare``,
each spec (or with ``--compare-specs`` each of those specs instead, e.g. the smaller twins of
``tunes/compare/``) is tuned by every method of ``--methods`` with ``--tuner-seeds`` tuner seeds
each: first the grid with ``--grid-budget`` times the spec's budget (3 by default), then the others
with the runs the grid spent divided by that factor (the race is judged against a grid that spent
three times as many runs), and each tune's best setting is rescored on the held-out instances; a
verdict per spec compares the race's median held-out objective with the grid's median (within ``1
pp`` of success, or ``1 %`` of the mean gap or the other mean objectives) and with random search's
(never worse, at the same budget).

Written to ``--out`` (default ``out/calibration``; ``results/calibration`` for the committed
tables), each file atomically: ``held_out.csv`` (one row per spec and rescored setting),
``held_out_maps.csv`` (per spec and held-out map, the baseline against the best setting and, where
the RFD paper reports runs on the map, its claim), ``defaults.csv`` (per spec, whether the best
setting is at least as good as the baseline overall and on every held-out map, and whether it is the
swarm's registered default), ``table.md`` (the provenance, then the three tables),
``provenance.json`` and per spec its race's ``race.png``, ``race.csv`` and ``best.json``; with a
comparison, ``comparison.csv`` and ``comparison.md`` (per spec and method: the median, lowest and
highest held-out objective over the tuner seeds and the runs spent; then the verdicts).

Run from the repository root::

    python sweeps/calibration.py --quick
    python sweeps/calibration.py --specs tunes/iwd.toml --out results/calibration
    python sweeps/calibration.py --quick --compare --tuner-seeds 5
    python sweeps/calibration.py --specs tunes/iwd.toml --compare-specs tunes/compare/*.toml
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import shutil
import statistics
import tomllib
from pathlib import Path

import math

import numpy as np
import pandas as pd

from jaxswarm.maps.paper import PAPER_OPTIMA, PAPER_TABLE1_LENGTH
from jaxswarm.runtime.atomic import write_atomically
from jaxswarm.runtime.cpu import backends_started, configure
from jaxswarm.studies import provenance
from jaxswarm.sweep.batches import SUCCESS_GAP
from jaxswarm.tune import tune, tune_spec_from_dict
from jaxswarm.tune.spec import METHODS, smallest_budget
from jaxswarm.tune.tuner import default_values

ROOT = Path(__file__).resolve().parents[1]
"""The repository root: spec paths are relative to it."""
TITLE = "The papers' open constants, raced and judged on held-out instances"
"""Title of table.md."""
ABOUT = ("Each row is a setting of a paper swarm on its spec's held-out instances (maps and "
         "seeds the search never ran on): `baseline` is the setting the race started from, the "
         "swarm's defaults before this calibration (the paper's values where it gives them, "
         "ours where it does not; a spec's `[tune.baseline]` pins them where the best setting "
         "has since become the default), `best` and `elite k` the race's "
         "survivors on the training instances (`tunes/<swarm>.toml` names the constants each "
         "paper leaves open and the ranges searched). `objective` is the spec's objective "
         "(lower is better for a gap, higher for a success rate) with a 95 % bootstrap "
         "interval over the held-out instances; `found` and `success` are the shares of runs "
         "that found a path and that reached the optimum (relative gap below 1e-4). A tune "
         "resumed from its store (`--stores`) reads its runs back, so the run time of a table "
         "made from stores is that of the rescoring alone; `training_runs` counts the runs.")
"""What the rows are."""


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if not backends_started():
        configure(devices=args.devices)
    record = provenance.begin(__file__, argv)
    paths = args.specs or sorted(str(path.relative_to(ROOT)) for path in (
        ROOT / "tunes" / ("quick" if args.quick else "")).glob("*.toml"))
    held_out, per_map, registered, comparison = [], [], [], []
    for path in paths:
        document = tomllib.loads(_found(path).read_text())
        spec = tune_spec_from_dict(document, source=path)
        result = tune(spec, args.stores / spec.name)
        folder = args.out / spec.algorithm
        folder.mkdir(parents=True, exist_ok=True)
        for name in ("race.png", "race.csv", "best.json"):
            if (result.out / name).is_file():
                shutil.copyfile(result.out / name, folder / name)
        held_out.append(result.held_out.assign(spec=path, algorithm=spec.algorithm,
                                               objective_name=spec.objective,
                                               training_runs=result.runs_spent))
        per_map.append(result.held_out_maps.assign(algorithm=spec.algorithm,
                                                   objective_name=spec.objective))
        registered.append(dict(algorithm=spec.algorithm,
                               adopted=_is_default(default_values(spec), result.best)))
        if args.compare and not args.compare_specs:
            comparison += _compare(document, path, args)
    for path in args.compare_specs:
        document = tomllib.loads(_found(path).read_text())
        comparison += _compare(document, path, args)
    record.finish(title=TITLE, about=ABOUT, specs=paths, compare_specs=args.compare_specs)
    _write(args.out, record, pd.concat(held_out, ignore_index=True),
           pd.concat(per_map, ignore_index=True), pd.DataFrame(registered), comparison)
    return 0


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--specs", nargs="*", help="tune specs (default: tunes/*.toml)")
    parser.add_argument("--quick", action="store_true", help="the quick specs of tunes/quick/")
    parser.add_argument("--compare", action="store_true",
                        help="also every method of --methods on each spec")
    parser.add_argument("--compare-specs", nargs="*", default=[],
                        help="compare the methods on these specs instead (implies --compare)")
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--tuner-seeds", type=int, default=5)
    parser.add_argument("--grid-budget", type=float, default=3.0,
                        help="the grid's budget as a multiple of the spec's (default 3)")
    parser.add_argument("--out", type=Path, default=Path("out/calibration"))
    parser.add_argument("--stores", type=Path, default=Path("out/calibration/stores"),
                        help="where the tunes' run stores go (resumable; not committed)")
    parser.add_argument("--devices", type=int, default=os.cpu_count(),
                        help="JAX CPU devices the runs are shared out over (default: one per "
                             "core; ignored when JAX has already started)")
    return parser


def _write(out: Path, record: provenance.Provenance, frame: pd.DataFrame, per_map: pd.DataFrame,
           registered: pd.DataFrame, comparison: list[dict]) -> None:
    """Every table of ``out`` (see the module docstring), each file atomically."""
    out.mkdir(parents=True, exist_ok=True)
    maps = _baseline_against_best(per_map)
    defaults = _defaults(frame, maps, registered)
    write_atomically(out / "held_out.csv", frame.to_csv(index=False))
    write_atomically(out / "held_out_maps.csv", maps.to_csv(index=False))
    write_atomically(out / "defaults.csv", defaults.to_csv(index=False))
    write_atomically(out / "table.md", record.document(
        _table(frame) + "\n" + PER_MAP + "\n\n" + _markdown(maps) + "\n" + DEFAULTS + "\n\n"
        + _markdown(defaults)))
    record.write(out)
    if comparison:
        compared = pd.DataFrame(comparison)
        write_atomically(out / "comparison.csv", compared.to_csv(index=False))
        write_atomically(out / "comparison.md", record.document(_comparison(compared)))


def _found(path: str) -> Path:
    """``path``, or where it lies below the repository root when it is relative and not found
    from the working directory."""
    given = Path(path)
    return given if given.exists() or given.is_absolute() else ROOT / given


def _compare(document: dict, path: str, args) -> list[dict]:
    """Every method of ``args.methods`` with ``args.tuner_seeds`` tuner seeds on the spec
    ``document``: one row per tune, its best setting's and the baseline's held-out objective.
    The grid runs first, with ``args.grid_budget`` times the spec's budget; the other methods
    then get the runs the grid spent (the least over its seeds) divided by that factor, so the
    race is judged against a grid that spent ``args.grid_budget`` times as many runs even
    where the grid's settings and instances do not fill its budget. A budget below the method's
    least (:func:`~jaxswarm.tune.spec.smallest_budget`: irace's for the race) is raised to it;
    the race then spends more than that share, and its ``near_grid`` verdict says so."""
    methods = args.methods.split(",")
    budget = document["tune"]["budget"]
    rows = []
    for method in sorted(methods, key=lambda m: m != "grid"):
        if method == "grid":
            method_budget = max(1, round(args.grid_budget * budget))
        elif "grid" in methods:
            grid_runs = min(row["runs"] for row in rows if row["method"] == "grid")
            method_budget = max(1, int(grid_runs // args.grid_budget))
        else:
            method_budget = budget
        for seed in range(args.tuner_seeds):
            changed = dict(document, tune=dict(
                document["tune"], method=method, seed=seed, budget=method_budget,
                name=f"{document['tune'].get('name', 'tune')}_{method}_{seed}"))
            spec = tune_spec_from_dict(dict(changed, tune=dict(changed["tune"], budget=budget)),
                                       source=path)
            spec = dataclasses.replace(spec, budget=max(method_budget, smallest_budget(spec)))
            result = tune(spec, args.stores / spec.name)
            table = result.held_out.set_index("label")
            rows.append(dict(spec=path, algorithm=spec.algorithm, method=method, seed=seed,
                             runs=result.runs_spent, budget=spec.budget,
                             objective_name=spec.objective,
                             best=float(table.loc["best", "objective"]),
                             baseline=float(table.loc["baseline", "objective"])))
    return rows


PER_MAP = ("Per held-out map: the baseline's objective and the best setting's, and whether the "
           "best does at least as well there (`at_least_as_good`; Moving AI maps are named "
           "with their scenario row, `map#row`). `paper_gap` is what the paper claims there: "
           "only the RFD paper reports runs on held-out maps (its Table 1 on the 100 x 100 "
           "maps, for `ant_system` (its ACO), `aco_star`, `rfd` and `rfd_star`), as the "
           "relative gap of its mean path to its Dijkstra path on its own maps (`nan` where it "
           "found none or reports nothing); `reaches_paper` holds when every run of the best "
           "setting found a path within that gap (plus 1e-4), and is empty where the paper "
           "claims nothing. A `False` there is the finding that the calibrated constants do "
           "not reach the paper's claim.")
"""What the per-map table shows."""

PAPER_ROWS = {"ant_system": "ACO", "aco_star": "ACO*", "rfd": "RFD", "rfd_star": "RFD*"}
"""The RFD paper's Table 1 row of each swarm it runs."""


def _baseline_against_best(per_map: pd.DataFrame) -> pd.DataFrame:
    """One row per swarm and held-out map: the baseline's and the best setting's objective and
    shares of runs that found a path, whether the best is at least as good (the objective's
    direction from its name: higher is better for ``success``), and the paper's claim there
    (:func:`_paper_gap`) with whether the best reaches it."""
    rows = []
    for (algorithm, map_name), group in per_map.groupby(["algorithm", "map"], sort=False):
        by_label = group.set_index("label")
        baseline, best = by_label.loc["baseline"], by_label.loc["best"]
        objective = group["objective_name"].iloc[0]
        claim = _paper_gap(algorithm, map_name)
        reaches = None if math.isnan(claim) or objective != "gap" else bool(
            best["found"] == 1.0 and best["objective"] <= claim + SUCCESS_GAP)
        rows.append(dict(
            algorithm=algorithm, map=map_name, objective_name=objective,
            baseline=float(baseline["objective"]), best=float(best["objective"]),
            baseline_found=float(baseline["found"]), best_found=float(best["found"]),
            at_least_as_good=_at_least_as_good(objective, best["objective"],
                                               baseline["objective"]),
            paper_gap=claim, reaches_paper=reaches))
    return pd.DataFrame(rows)


DEFAULTS = ("The defaults: a swarm's best setting became its default (jaxswarm 0.8.0) where it is "
            "at least as good as the baseline both overall (`overall`) and on every held-out "
            "map (`every_map`); elsewhere the defaults stayed as they were. `adopted` says "
            "whether the swarm's registered defaults are the best setting (equal as float32, "
            "the precision the swarms compute in).")
"""What the defaults table shows."""


def _defaults(frame: pd.DataFrame, maps: pd.DataFrame,
              registered: pd.DataFrame) -> pd.DataFrame:
    """One row per swarm: whether its best setting is at least as good as its baseline overall
    (``frame``, the held-out table) and on every held-out map (``maps``), and whether it is the
    registered default (``registered``: ``algorithm``, ``adopted``)."""
    rows = []
    for algorithm, table in frame.groupby("algorithm", sort=False):
        by_label = table.set_index("label")
        objective = table["objective_name"].iloc[0]
        rows.append(dict(
            algorithm=algorithm, objective_name=objective,
            baseline=float(by_label.loc["baseline", "objective"]),
            best=float(by_label.loc["best", "objective"]),
            overall=_at_least_as_good(objective, by_label.loc["best", "objective"],
                                      by_label.loc["baseline", "objective"]),
            every_map=bool(maps.loc[maps["algorithm"] == algorithm, "at_least_as_good"].all())))
    return pd.DataFrame(rows).merge(registered, on="algorithm")


def _is_default(defaults: dict, best: dict) -> bool:
    """Whether the swarm's registered ``defaults`` are the ``best`` setting (every number of the
    setting equal as float32, every other value equal)."""
    return all(np.float32(defaults[name]) == np.float32(value)
               if isinstance(value, (int, float)) else defaults[name] == value
               for name, value in best.items())


def _paper_gap(algorithm: str, map_name: str) -> float:
    """The relative gap the RFD paper's Table 1 reports for ``algorithm`` on ``map_name`` (its
    mean path over its Dijkstra path, less 1); NaN where it reports no path or nothing."""
    length = PAPER_TABLE1_LENGTH.get(PAPER_ROWS.get(algorithm, ""), {}).get(map_name)
    return math.nan if length is None else length / PAPER_OPTIMA[map_name] - 1.0


def _table(frame: pd.DataFrame) -> str:
    columns = ["algorithm", "label", "objective_name", "objective", "low", "high", "found",
               "success", "runs", "training_runs"]
    return _markdown(frame[columns])


def _comparison(frame: pd.DataFrame) -> str:
    summary = frame.groupby(["algorithm", "method"], sort=False).agg(
        budget=("budget", "first"), runs=("runs", "median"),
        median=("best", statistics.median), lowest=("best", "min"), highest=("best", "max"),
        baseline=("baseline", "first"), objective_name=("objective_name", "first")
    ).reset_index()
    verdicts = pd.DataFrame([_verdict(algorithm, rows)
                             for algorithm, rows in summary.groupby("algorithm", sort=False)])
    return ("Held-out objective of each method's best setting over the tuner seeds (median, "
            "lowest and highest), beside the baseline's.\n\n" + _markdown(summary)
            + "\n" + VERDICTS + "\n\n" + _markdown(verdicts))


VERDICTS = ("Verdicts: `near_grid` holds when the race's median is within 1 percentage point "
            "of success (or 1 % of a mean objective) of the grid's median while the race spent "
            "at most a third of the grid's runs; `not_worse_than_random` when the race's "
            "median is at least as good as random search's at the same budget. A method that "
            "did not run leaves its columns `nan`.")
"""What the verdict columns mean."""


def _verdict(algorithm: str, summary: pd.DataFrame) -> dict:
    """The race against the grid and random search for one algorithm's rows of the summary
    (one per method: ``median``, ``runs``); the objective's direction from its name."""
    by_method = summary.set_index("method")
    objective = summary["objective_name"].iloc[0]
    row = dict(algorithm=algorithm, objective_name=objective)
    if "race" not in by_method.index:
        return row
    race = by_method.loc["race"]
    row["race_median"] = float(race["median"])
    if "grid" in by_method.index:
        grid = by_method.loc["grid"]
        slack = 0.01 if objective == "success" else 0.01 * abs(float(grid["median"]))
        row |= dict(grid_median=float(grid["median"]),
                    runs_share=float(race["runs"]) / float(grid["runs"]),
                    near_grid=_at_least_as_good(objective, race["median"], grid["median"], slack)
                    and bool(3 * race["runs"] <= grid["runs"]))
    if "random" in by_method.index:
        random = by_method.loc["random"]
        row |= dict(random_median=float(random["median"]),
                    not_worse_than_random=_at_least_as_good(objective, race["median"],
                                                            random["median"]))
    return row


def _at_least_as_good(objective: str, value: float, other: float, slack: float = 0.0) -> bool:
    """Whether ``value`` of ``objective`` is at least as good as ``other`` less ``slack``
    (higher is better for a success rate, lower for every mean)."""
    if objective == "success":
        return bool(value >= other - slack)
    return bool(value <= other + slack)


def _markdown(frame: pd.DataFrame) -> str:
    header = "| " + " | ".join(frame.columns) + " |\n|" + " --- |" * len(frame.columns) + "\n"
    return header + "".join(
        "| " + " | ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in row) + " |\n"
        for row in frame.itertuples(index=False))


if __name__ == "__main__":
    raise SystemExit(main())
