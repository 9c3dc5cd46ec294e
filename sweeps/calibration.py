"""The papers' open constants calibrated: every tune spec of ``tunes/`` raced, its best setting
rescored beside the swarm's defaults on held-out instances; and, with ``--compare``, racing
against random search, the grid and evolution strategies at the same budgets.

Per spec (``--specs``, default every ``tunes/*.toml``; ``--quick``: ``tunes/quick/*.toml``), one
tune (:func:`jaxswarm.tune.tune`, its store under ``--stores``): the race, then the defaults and the
best settings on the spec's held-out instances, the objective with a 95 % bootstrap interval over
them, and the shares of runs that found a path and that reached the optimum. With ``--compare``,
each spec is tuned by every method of ``--methods`` with ``--tuner-seeds`` tuner seeds each
(the spec's budget each time), and each tune's best setting is rescored on the held-out instances.

Written to ``--out`` (default ``out/calibration``; ``results/calibration`` for the committed
tables), each file atomically: ``held_out.csv`` (one row per spec and rescored setting),
``table.md`` (the provenance, then the table), ``provenance.json`` and per spec its race's
``race.png``, ``race.csv`` and ``best.json``; with ``--compare``, ``comparison.csv`` and
``comparison.md`` (per spec and method: the median, lowest and highest held-out objective over
the tuner seeds and the runs spent).

Run from the repository root::

    python sweeps/calibration.py --quick
    python sweeps/calibration.py --specs tunes/iwd.toml --out results/calibration
    python sweeps/calibration.py --quick --compare --tuner-seeds 5
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import tomllib
from pathlib import Path

import pandas as pd

from jaxswarm.runtime.atomic import write_atomically
from jaxswarm.runtime.cpu import backends_started, configure
from jaxswarm.studies import provenance
from jaxswarm.tune import tune, tune_spec_from_dict
from jaxswarm.tune.spec import METHODS

ROOT = Path(__file__).resolve().parents[1]
"""The repository root: spec paths are relative to it."""
TITLE = "The papers' open constants, raced and judged on held-out instances"
"""Title of table.md."""
ABOUT = ("Each row is a setting of a paper swarm on its spec's held-out instances (maps and "
         "seeds the search never ran on): `default` is the swarm as registered (the paper's "
         "values where it gives them, ours where it does not), `best` and `elite k` the race's "
         "survivors on the training instances (`tunes/<swarm>.toml` names the constants each "
         "paper leaves open and the ranges searched). `objective` is the spec's objective "
         "(lower is better for a gap, higher for a success rate) with a 95 % bootstrap "
         "interval over the held-out instances; `found` and `success` are the shares of runs "
         "that found a path and that reached the optimum (relative gap below 1e-4). A tune "
         "resumed from its store (`--stores`) reads its runs back, so the run time of a table "
         "made from stores is that of the rescoring alone; `training_runs` counts the runs.")
"""What the rows are."""


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--specs", nargs="*", help="tune specs (default: tunes/*.toml)")
    parser.add_argument("--quick", action="store_true", help="the quick specs of tunes/quick/")
    parser.add_argument("--compare", action="store_true",
                        help="also every method of --methods at the same budget")
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--tuner-seeds", type=int, default=5)
    parser.add_argument("--out", type=Path, default=Path("out/calibration"))
    parser.add_argument("--stores", type=Path, default=Path("out/calibration/stores"),
                        help="where the tunes' run stores go (resumable; not committed)")
    parser.add_argument("--devices", type=int, default=os.cpu_count(),
                        help="JAX CPU devices the runs are shared out over (default: one per "
                             "core; ignored when JAX has already started)")
    args = parser.parse_args(argv)
    if not backends_started():
        configure(devices=args.devices)
    record = provenance.begin(__file__, argv)
    paths = args.specs or sorted(str(path.relative_to(ROOT)) for path in (
        ROOT / "tunes" / ("quick" if args.quick else "")).glob("*.toml"))
    held_out, comparison = [], []
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
        if args.compare:
            comparison += _compare(document, path, args)
    frame = pd.concat(held_out, ignore_index=True)
    args.out.mkdir(parents=True, exist_ok=True)
    write_atomically(args.out / "held_out.csv", frame.to_csv(index=False))
    record.finish(title=TITLE, about=ABOUT, specs=paths)
    write_atomically(args.out / "table.md", record.document(_table(frame)))
    record.write(args.out)
    if comparison:
        compared = pd.DataFrame(comparison)
        write_atomically(args.out / "comparison.csv", compared.to_csv(index=False))
        write_atomically(args.out / "comparison.md", record.document(_comparison(compared)))
    return 0


def _found(path: str) -> Path:
    """``path``, or where it lies below the repository root when it is relative and not found
    from the working directory."""
    given = Path(path)
    return given if given.exists() or given.is_absolute() else ROOT / given


def _compare(document: dict, path: str, args) -> list[dict]:
    """Every method of ``args.methods`` with ``args.tuner_seeds`` tuner seeds on the spec
    ``document``: one row per tune, its best setting's and the defaults' held-out objective."""
    rows = []
    for method in args.methods.split(","):
        for seed in range(args.tuner_seeds):
            changed = dict(document, tune=dict(document["tune"], method=method, seed=seed,
                                               name=f"{document['tune'].get('name', 'tune')}"
                                                    f"_{method}_{seed}"))
            spec = tune_spec_from_dict(changed, source=path)
            result = tune(spec, args.stores / spec.name)
            table = result.held_out.set_index("label")
            rows.append(dict(spec=path, algorithm=spec.algorithm, method=method, seed=seed,
                             runs=result.runs_spent, budget=spec.budget,
                             objective_name=spec.objective,
                             best=float(table.loc["best", "objective"]),
                             default=float(table.loc["default", "objective"])))
    return rows


def _table(frame: pd.DataFrame) -> str:
    columns = ["algorithm", "label", "objective_name", "objective", "low", "high", "found",
               "success", "runs", "training_runs"]
    return _markdown(frame[columns])


def _comparison(frame: pd.DataFrame) -> str:
    summary = frame.groupby(["algorithm", "method"], sort=False).agg(
        budget=("budget", "first"), runs=("runs", "median"),
        median=("best", statistics.median), lowest=("best", "min"), highest=("best", "max"),
        default=("default", "first")).reset_index()
    return ("Held-out objective of each method's best setting over the tuner seeds (median, "
            "lowest and highest), beside the defaults'.\n\n" + _markdown(summary))


def _markdown(frame: pd.DataFrame) -> str:
    header = "| " + " | ".join(frame.columns) + " |\n|" + " --- |" * len(frame.columns) + "\n"
    return header + "".join(
        "| " + " | ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in row) + " |\n"
        for row in frame.itertuples(index=False))


if __name__ == "__main__":
    raise SystemExit(main())
