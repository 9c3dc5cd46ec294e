"""The tuner: specs and their errors, the search space, iterated racing and the other methods on
a planted objective, and a real tune on small maps that resumes after a kill to the same race."""
import argparse
import json
import types
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import sizes
from repo_scripts import load_script

from jaxswarm.cli import main
from jaxswarm.maps.entry import resolve
from jaxswarm.runtime.evolution import antithetic_gradient, centred_ranks
from jaxswarm.sweep.batches import RunBatches
from jaxswarm.swarm import make
from jaxswarm.sweep.store import SAME_RESULTS_SINCE, ResultsStore
from jaxswarm.tune import TuneSpecError, load_tune_spec, tune, tune_spec_from_dict
from jaxswarm.tune.evaluate import Setting
from jaxswarm.tune.race import iterated_race
from jaxswarm.tune.search import es_search, grid_search, random_search
from jaxswarm.tune.spec import smallest_budget
from jaxswarm.tune.space import Choice, Integer, Real, Space, Tied, from_unit, to_unit
from jaxswarm.tune.tuner import baseline_values, default_values

REPO = Path(__file__).resolve().parents[1]


def document(**changes):
    """A small tune spec document: RFD*'s alpha (erosion tied to it) and p_base on two 20 x 20
    paper maps, held out on a third, at the shared size of ``tests/sizes.py``.

    Every call of its runs holds at most 5 (at most 5 settings race on an instance, 2 are held
    out), so it is padded to a quarter of the chunk of 20: 5 runs, the chunk of test_sweep.py's
    sweeps, whose compiled program the two files share."""
    tune_table = {"name": "tiny", "algorithm": "rfd_star", "method": "race", "budget": 72,
                  "objective": "gap", "iterations": sizes.ITERATIONS, "seed": 3,
                  "chunk_size": 20,
                  "training": {"maps": ["maze20", "mosaic20"], "seeds": 6},
                  "held_out": {"maps": ["alley20"], "seeds": [100, 101]},
                  "race": {"first_test": 3}}
    doc = {"tune": tune_table, "config": dict(sizes.CONFIG),
           "params": {"alpha": {"low": 1.0, "high": 100.0}, "erosion": {"tied": "alpha"},
                      "p_base": {"low": 1.5, "high": 1000.0, "log": True}}}
    for section, values in changes.items():
        doc[section] = dict(doc.get(section, {}), **values)
    return doc


def test_a_spec_becomes_a_space_with_ties_and_fixed_values():
    spec = tune_spec_from_dict(document(params={"sediment": 0.5}))
    assert spec.space.free == ["alpha", "p_base"]
    assert spec.space.domains["erosion"] == Tied("alpha")
    assert spec.space.domains["p_base"] == Real(1.5, 1000.0, True)
    assert spec.fixed == {"sediment": 0.5}
    assert spec.training.pairs[:2] == [(0, 0), (0, 1)] and len(spec.training.pairs) == 12
    assert spec.held_out.seeds == (100, 101)
    assert json.loads(json.dumps(spec.as_dict()))["space"]["erosion"] == {"kind": "Tied",
                                                                           "to": "alpha"}


@pytest.mark.parametrize("changes, message", [
    (dict(tune={"budgett": 3}), "tune.budgett: unknown key"),
    (dict(tune={"method": "bayes"}), "tune.method: must be one of race, random, grid, es"),
    (dict(tune={"objective": "speed"}), "tune.objective: must be one of"),
    (dict(tune={"algorithm": "bees"}), "tune.algorithm: unknown algorithm 'bees'"),
    (dict(tune={"held_out": {"maps": ["maze20"]}}), "tune.held_out.seeds: missing"),
    (dict(tune={"training": {"maps": ["maze21"], "seeds": 2}}), "tune.training.maps[0]"),
    (dict(tune={"race": {"alpha": 2}}), "tune.race.alpha: must be a number in (0, 1)"),
    (dict(params={"alpha": {"low": 4, "high": 1}}), "params.alpha: low and high must be"),
    (dict(params={"erosion": {"tied": "gamma"}}),
     "params.erosion.tied: 'gamma' is not a searched"),
    (dict(params={"p_base": {"low": 0, "high": 1, "log": True}}), "params.p_base: log must be"),
    (dict(params={"rho": {"low": 0.1, "high": 0.5}}), "params.rho: unknown param of rfd_star"),
    (dict(params={"sediment": {"low": -1.0, "high": 1.0}}),
     "params.sediment: -1.0 is not a valid"),
    (dict(config={"num_agents": {"choices": [8, -1]}}), "[config]"),
    (dict(config={"agents": 8}), "config.agents: unknown config of rfd_star"),
    (dict(unknown={}), "unknown: unknown section"),
    (dict(tune={"baseline": 3}), "tune.baseline: must be a table"),
    (dict(tune={"baseline": {"erosion": 1.0}}), "tune.baseline.erosion: not a searched param of "
                                                "this spec; searched: alpha, p_base"),
    (dict(tune={"baseline": {"alpha": 900.0}}), "tune.baseline.alpha: must be a number in [1.0, "
                                                "100.0], got 900.0"),
    (dict(tune={"held_out": {"maps": ["mosaic20"], "seeds": [5, 100]}}),
     "tune.held_out: 1 instance(s) are also training instances (e.g. map 'mosaic20' with seed 5)"),
])
def test_a_bad_spec_names_its_key(changes, message):
    with pytest.raises(TuneSpecError) as error:
        tune_spec_from_dict(document(**changes), source="spec.toml")
    assert str(error.value).startswith("spec.toml: ")
    assert message in str(error.value)


def test_nothing_to_tune_is_an_error():
    fixed = document()
    fixed["params"] = {"alpha": 1.0}
    with pytest.raises(TuneSpecError, match=r"\[params\]: nothing to tune"):
        tune_spec_from_dict(fixed)


def test_the_space_draws_within_its_domains_on_their_scales():
    space = Space({"a": Real(1e-3, 1e3, log=True), "n": Integer(1, 9), "c": Choice((0.5, 2.0)),
                   "b": Tied("a")})
    settings = space.uniform(np.random.default_rng(0), 400)
    a = np.array([s["a"] for s in settings])
    assert np.all((1e-3 <= a) & (a <= 1e3)) and all(s["b"] == s["a"] for s in settings)
    assert 0.3 < np.mean(a < 1.0) < 0.7  # log-uniform: half the draws below the geometric mean
    assert {s["n"] for s in settings} == set(range(1, 10))
    assert {s["c"] for s in settings} == {0.5, 2.0}
    assert len(space.grid(3)) == 3 * 3 * 2
    assert sorted({s["a"] for s in space.grid(3)}) == pytest.approx([1e-3, 1.0, 1e3])
    for domain, value in ((Real(2.0, 6.0), 5.0), (Real(0.01, 100.0, True), 1.0)):
        assert from_unit(domain, to_unit(domain, value)) == pytest.approx(value)
    assert to_unit(Real(0.01, 100.0, True), 1.0) == pytest.approx(0.5)


class PlantedEvaluator:
    """Scores settings of one param ``x`` by ``(x - 0.3)^2`` plus instance noise, counting
    runs as the real evaluator does."""

    def __init__(self, spec):
        self.spec = spec
        self.runs_spent = 0
        self.batches = []

    def score(self, settings, instances, *, phase="training", iteration=0):
        self.runs_spent += len(settings) * len(instances)
        self.batches.append((len(settings), len(instances)))
        noise = np.array([np.random.default_rng(1000 + 7 * m + s).normal(0, 0.01)
                          for m, s in instances])
        return np.array([[(setting.values["alpha"] - 1.3) ** 2 + n for n in noise]
                         for setting in settings])


def planted(method, budget=600):
    spec = tune_spec_from_dict(document(
        tune={"method": method, "budget": budget, "training": {"maps": ["maze20"],
                                                                "seeds": 40}},
        params={"alpha": {"low": 0.5, "high": 4.0}, "erosion": 1.0, "p_base": 50.0}))
    return spec, PlantedEvaluator(spec)


def test_a_race_drops_settings_worse_than_the_best_and_closes_in_on_the_optimum():
    spec, evaluator = planted("race")
    result = iterated_race(evaluator, spec.space, {"alpha": 1.0}, np.random.default_rng(0))
    assert evaluator.runs_spent <= spec.budget
    assert result.settings[0].values == {"alpha": 1.0}  # the defaults race first
    dropped = result.log[result.log["dropped"] != ""]
    assert len(dropped) > 0 and set(dropped["dropped"]) <= {"conover"}
    first = result.log[result.log["iteration"] == 1]
    assert first["step"].min() == 1
    assert (first.groupby("setting")["step"].max() >= spec.first_test).all()  # no early drop
    worst = max(result.settings.values(), key=lambda s: abs(s.values["alpha"] - 1.3))
    assert worst.number in set(dropped["setting"])  # the setting planted furthest is dropped
    assert abs(result.elites[0].values["alpha"] - 1.3) < 0.15
    assert result.log["iteration"].max() >= 2  # new settings drawn around the elites


def test_a_race_is_the_same_race_from_the_same_key():
    runs = []
    for _ in range(2):
        spec, evaluator = planted("race")
        runs.append(iterated_race(evaluator, spec.space, {"alpha": 1.0},
                                  np.random.default_rng(5)))
    pd.testing.assert_frame_equal(runs[0].log, runs[1].log)


@pytest.mark.parametrize("method", ["random", "grid", "es"])
def test_the_other_methods_keep_to_the_budget_and_find_better_than_the_default(method):
    spec, evaluator = planted(method)
    rng = np.random.default_rng(0)
    if method == "random":
        result = random_search(evaluator, spec.space, {"alpha": 1.0}, rng)
    elif method == "grid":
        result = grid_search(evaluator, spec.space, rng)
    else:
        result = es_search(evaluator, spec.space, {"alpha": 1.0}, rng)
    assert 0 < evaluator.runs_spent <= spec.budget
    assert abs(result.best[0].values["alpha"] - 1.3) < abs(1.0 - 1.3)


def test_the_es_gradient_points_downhill_from_centred_ranks():
    np.testing.assert_allclose(centred_ranks(np.array([3.0, 1.0, 2.0, 2.0])),
                               [0.5, -0.5, 0.0, 0.0])
    eps = np.array([[1.0, 0.0], [0.0, 1.0]])
    # Loss falls along +x, rises along +y: the gradient is -x, +y.
    gradient = antithetic_gradient(eps, np.array([0.0, 3.0, 2.0, 1.0]), sigma=0.5)
    assert gradient[0] < 0 < gradient[1]


def test_a_baseline_is_where_the_search_starts_and_what_the_best_is_judged_beside(tmp_path):
    spec = tune_spec_from_dict(document(tune={"baseline": {"alpha": 2.0}, "budget": 72}))
    p_base = float(make("rfd_star").default_params.p_base)
    assert baseline_values(spec) == {"alpha": 2.0, "erosion": 2.0,
                                     "p_base": pytest.approx(p_base)}
    # A store records the baseline; a spec without one records itself as before the key.
    assert spec.as_dict()["baseline"] == {"alpha": 2.0}
    assert "baseline" not in tune_spec_from_dict(document()).as_dict()
    result = tune(spec, tmp_path / "tune", log=lambda _: None)
    first = result.held_out.iloc[0]
    assert first["label"] == "baseline" and first["alpha"] == first["erosion"] == 2.0
    runs = pd.read_parquet(tmp_path / "tune" / "runs")
    assert (runs.loc[runs["setting"] == 0, "param.alpha"] == 2.0).all()


def test_a_calibrated_setting_is_the_default_exactly_where_it_is_at_least_as_good_everywhere():
    # results/calibration/defaults.csv: per paper swarm, the best setting against the defaults
    # it started from, overall and on every held-out map; the registry's defaults today must be
    # the best setting where (and only where) both hold.
    folder = REPO / "results" / "calibration"
    table = pd.read_csv(folder / "defaults.csv")
    assert set(table["algorithm"]) == {path.stem for path in (REPO / "tunes").glob("*.toml")}
    adopted = set()
    for row in table.itertuples():
        spec = load_tune_spec(REPO / "tunes" / f"{row.algorithm}.toml")
        best = json.loads((folder / row.algorithm / "best.json").read_text())
        registered = default_values(spec)
        is_default = all(np.float32(registered[name]) == np.float32(value)
                         for name, value in best.items())
        assert is_default == row.adopted == (row.overall and row.every_map), row.algorithm
        if is_default:
            adopted.add(row.algorithm)
            assert baseline_values(spec) != registered  # the study still starts where it did
    # and their stores of 0.7 are refused (their defaults changed in 0.8)
    assert adopted == {name for name, since in SAME_RESULTS_SINCE.items() if since == (0, 8)}


@pytest.fixture(scope="module")
def finished_tune(tmp_path_factory):
    out = tmp_path_factory.mktemp("tune") / "tiny"
    spec = tune_spec_from_dict(document())
    return spec, out, tune(spec, out, log=lambda _: None)


def test_a_tune_rescores_the_best_beside_its_baseline_on_held_out_instances(finished_tune):
    spec, out, result = finished_tune
    assert 0 < result.runs_spent <= spec.budget
    table = result.held_out
    assert list(table["label"][:2]) == ["baseline", "best"]
    assert table["alpha"].iloc[0] == float(make("rfd_star").default_params.alpha)  # no baseline
    assert (table["runs"] == 2).all()
    assert (table["low"] <= table["objective"]).all() and (
        table["objective"] <= table["high"]).all()
    assert table["alpha"].iloc[1] == result.best["alpha"] == result.best["erosion"]
    for name in ("held_out.csv", "race.csv", "race.png", "best.json", "metadata.json"):
        assert (out / name).is_file()
    runs = pd.read_parquet(out / "runs")
    assert (runs["phase"] == "training").sum() == result.runs_spent
    held = runs[runs["phase"] == "held_out"]
    assert set(held["seed"]) == {100, 101} and set(held["map"]) == {"alley20"}
    # The held-out rows are what the table reports: a gap's mean per setting.
    default = held[held["setting"] == -1]
    assert table["objective"].iloc[0] == pytest.approx(default["loss"].mean())
    assert (runs["loss"] == np.where(runs["found"], runs["gap"], spec.unsolved_gap)).all()
    # Per held-out map (one here): each setting's rows of that map, labelled as in the table.
    maps = result.held_out_maps
    assert list(maps["label"]) == list(table["label"]) and set(maps["map"]) == {"alley20"}
    np.testing.assert_allclose(maps["objective"], table["objective"])
    assert (maps["runs"] == 2).all() and (out / "held_out_maps.csv").is_file()


def test_a_killed_tune_resumes_to_the_same_race_running_only_what_was_lost(
        finished_tune, tmp_path, monkeypatch):
    spec, out, result = finished_tune
    killed = tmp_path / "killed"
    real_write = ResultsStore.write_chunk
    written = []

    def write_then_die(self, map_index, chunk_index, rows):
        if len(written) == 3:
            raise KeyboardInterrupt
        written.append(chunk_index)
        return real_write(self, map_index, chunk_index, rows)

    monkeypatch.setattr(ResultsStore, "write_chunk", write_then_die)
    with pytest.raises(KeyboardInterrupt):
        tune(spec, killed, log=lambda _: None)
    monkeypatch.setattr(ResultsStore, "write_chunk", real_write)
    real_run = RunBatches.run
    made = []

    def counted(self, sweep_map, seeds, params, optimum=np.inf):
        made.append(len(seeds))
        return real_run(self, sweep_map, seeds, params, optimum)

    monkeypatch.setattr(RunBatches, "run", counted)
    resumed = tune(spec, killed, log=lambda _: None)
    pd.testing.assert_frame_equal(resumed.race, result.race)
    pd.testing.assert_frame_equal(resumed.held_out, result.held_out)
    before = pd.read_parquet(out / "runs").drop(columns="seconds")
    after = pd.read_parquet(killed / "runs").drop(columns="seconds")
    pd.testing.assert_frame_equal(after, before)
    stored_before_kill = sum(len(pd.read_parquet(path)) for path in
                             sorted((killed / "runs").glob("part-*.parquet"))[:3])
    assert sum(made) == len(before) - stored_before_kill


def test_a_store_of_another_tune_is_refused(finished_tune):
    spec, out, _ = finished_tune
    other = tune_spec_from_dict(document(tune={"seed": 4}))
    with pytest.raises(ValueError, match="different sweep"):
        tune(other, out, log=lambda _: None)


def test_the_tune_command_prints_its_help_and_names_a_bad_key(tmp_path, capsys):
    with pytest.raises(SystemExit) as done:
        main(["tune", "--help"])
    assert done.value.code == 0 and "held-out" in capsys.readouterr().out
    bad = tmp_path / "bad.toml"
    bad.write_text('[tune]\nalgorithm = "iwd"\nbudget = 0\n')
    with pytest.raises(SystemExit) as done:
        main(["tune", str(bad)])
    assert done.value.code == 2
    assert f"{bad}: tune.training: missing" in capsys.readouterr().err
    with pytest.raises(SystemExit) as done:
        main(["--devices", "0", "tune", str(bad)])
    assert done.value.code == 2 and "--devices: devices must be" in capsys.readouterr().err


def test_a_small_call_is_fitted_to_a_share_of_the_chunk():
    assert RunBatches("iwd", {"num_agents": 8}, 3, None, 16, fit_calls=True).call_size(3) == 4
    assert RunBatches("iwd", {"num_agents": 8}, 3, None, 16).call_size(3) == 16


@pytest.mark.slow  # programs of both call sizes, about 60 s cold
def test_a_small_call_fitted_to_a_share_of_the_chunk_gives_the_same_runs():
    """Twin in the default tier: the call sizes above (a call's width is another batch width,
    whose one-key promise the conformance checks keep at width 3)."""
    sweep_map = resolve("maze20")
    seeds, params = np.array([3, 4, 5]), {"alpha": np.array([1.0, 2.0, 3.0])}
    outputs = [RunBatches("iwd", {"num_agents": 8}, 3, None, 16, log=lambda _: None,
                          fit_calls=fit).run(sweep_map, seeds, params)
               for fit in (False, True)]
    for name in ("cost", "iterations", "moves", "fingerprint", "target_iterations"):
        np.testing.assert_array_equal(outputs[0][name], outputs[1][name])


def test_every_paper_swarm_has_a_committed_spec_and_twins_of_the_same_space():
    from jaxswarm.swarm import registry
    paper = {name for name in registry.registered() if registry.entry(name).faithful}
    specs = {path.stem: load_tune_spec(path) for path in sorted((REPO / "tunes").glob("*.toml"))}
    assert set(specs) == paper and all(spec.algorithm == name for name, spec in specs.items())
    for name, spec in specs.items():
        quick = load_tune_spec(REPO / "tunes" / "quick" / f"{name}.toml")
        assert quick.algorithm == spec.algorithm and quick.objective == spec.objective
        assert {k: type(d) for k, d in quick.space.domains.items()} == {
            k: type(d) for k, d in spec.space.domains.items()}  # cabc's limit scales with N
        assert quick.budget < spec.budget
        assert not set(spec.space.domains) & set(spec.fixed)
    for path in sorted((REPO / "tunes" / "compare").glob("*.toml")):  # the tuner comparison's
        twin = load_tune_spec(path)
        assert twin.space.domains == specs[path.stem].space.domains
        assert twin.objective == specs[path.stem].objective and twin.method == "race"


@pytest.mark.slow  # two quick calibrations and their comparison: about four minutes
def test_the_calibration_script_writes_its_tables(tmp_path, monkeypatch):
    monkeypatch.chdir(REPO)
    calibration = load_script("sweeps/calibration.py")
    out = tmp_path / "calibration"
    calibration.main(["--specs", "tunes/quick/iwd.toml", "tunes/quick/aco_star.toml",
                      "--compare", "--methods", "race,random,grid", "--tuner-seeds", "1",
                      "--out", str(out), "--stores", str(tmp_path / "stores")])
    held_out = pd.read_csv(out / "held_out.csv")
    assert set(held_out["algorithm"]) == {"iwd", "aco_star"}
    assert set(held_out["label"]) >= {"baseline", "best"}
    defaults = pd.read_csv(out / "defaults.csv").set_index("algorithm")
    assert not defaults["adopted"].any()  # a quick race's best is no swarm's default
    comparison = pd.read_csv(out / "comparison.csv")
    assert len(comparison) == 2 * 3
    assert (comparison["runs"] <= comparison["budget"]).all()
    specs = {"iwd": "tunes/quick/iwd.toml", "aco_star": "tunes/quick/aco_star.toml"}
    for algorithm, rows in comparison.groupby("algorithm"):  # each spec's grid sets the budgets
        spec = load_tune_spec(specs[algorithm])
        budget = rows.set_index("method")["budget"]
        grid_runs = rows.loc[rows["method"] == "grid", "runs"].min()
        assert budget["grid"] == 3 * spec.budget and budget["random"] == grid_runs // 3
        # the race gets a third of the grid's runs, or irace's least where a third falls short
        assert budget["race"] == max(grid_runs // 3, smallest_budget(spec))
    assert "near_grid" in (out / "comparison.md").read_text()
    for name in ("table.md", "comparison.md", "provenance.json", "iwd/race.png",
                 "aco_star/best.json"):
        assert (out / name).is_file()


@pytest.mark.parametrize("objective, race, grid, random, race_runs, near, not_worse", [
    ("gap", 1.005, 1.0, 1.2, 60, True, True),      # within 1 % of the grid at a third
    ("gap", 1.02, 1.0, 1.2, 60, False, True),      # 2 % worse than the grid
    ("gap", 1.0, 1.0, 0.9, 61, False, False),      # more than a third; random better
    ("success", 0.595, 0.6, 0.5, 60, True, True),  # success: higher is better, 1 pp of slack
    ("success", 0.58, 0.6, 0.59, 60, False, False),
])
def test_the_comparison_verdicts(objective, race, grid, random, race_runs, near, not_worse):
    calibration = load_script("sweeps/calibration.py")
    summary = pd.DataFrame(dict(method=["race", "grid", "random"], median=[race, grid, random],
                                runs=[race_runs, 180, 60], objective_name=objective))
    verdict = calibration._verdict("iwd", summary)
    assert verdict["near_grid"] is near and verdict["not_worse_than_random"] is not_worse
    assert verdict["runs_share"] == pytest.approx(race_runs / 180)
    alone = calibration._verdict("iwd", summary[summary["method"] == "race"])
    assert "near_grid" not in alone and alone["race_median"] == race


def test_the_per_map_table_sets_the_baseline_against_the_best_in_the_objectives_direction():
    calibration = load_script("sweeps/calibration.py")
    per_map = pd.DataFrame(dict(
        algorithm=["iwd"] * 4 + ["bees"] * 2, map=["a", "a", "b", "b", "p", "p"],
        label=["baseline", "best"] * 3, objective=[2.0, 1.0, 0.5, 0.7, 0.4, 0.6],
        found=[0.5, 1.0, 1.0, 1.0, 0.4, 0.6],
        objective_name=["gap"] * 4 + ["success"] * 2))
    table = calibration._baseline_against_best(per_map)
    assert list(zip(table["algorithm"], table["map"])) == [("iwd", "a"), ("iwd", "b"),
                                                          ("bees", "p")]
    assert list(table["at_least_as_good"]) == [True, False, True]
    assert list(table["best"]) == [1.0, 0.7, 0.6] and list(table["baseline_found"]) == [0.5, 1.0,
                                                                                      0.4]
    assert table["paper_gap"].isna().all() and table["reaches_paper"].isna().all()


def test_the_per_map_table_says_where_the_rfd_papers_claim_is_not_reached():
    calibration = load_script("sweeps/calibration.py")
    per_map = pd.DataFrame(dict(
        algorithm=["rfd_star"] * 4 + ["ant_system"] * 2,
        map=["maze100", "maze100", "mosaic100", "mosaic100", "alley100", "alley100"],
        label=["baseline", "best"] * 3, objective=[10.0, 10.0, 0.3, 5e-5, 10.0, 25.0],
        found=[0.0, 0.0, 1.0, 1.0, 0.0, 1.0], objective_name="gap"))
    table = calibration._baseline_against_best(per_map).set_index("map")
    # RFD* claims the optimum on every 100 x 100 map; its ACO 5435.08 on alley100 (optimum
    # 170.42): a gap of 30.9 that a best setting at 25 with every run finding a path reaches.
    assert table.loc["maze100", "paper_gap"] == pytest.approx(0.0)
    assert table.loc["alley100", "paper_gap"] == pytest.approx(5435.08 / 170.42 - 1)
    assert list(table["reaches_paper"]) == [False, True, True]


def test_the_comparison_gives_the_other_methods_a_third_of_what_the_grid_spent(
        tmp_path, monkeypatch):
    calibration = load_script("sweeps/calibration.py")
    asked = []

    def fake_tune(spec, out):  # the grid fills 440 of its 450 runs on seed 0, 449 on seed 1
        asked.append((spec.method, spec.budget))
        spent = {0: 440, 1: 449}[spec.seed] if spec.method == "grid" else spec.budget
        held_out = pd.DataFrame(dict(label=["baseline", "best"], objective=[1.0, 0.5]))
        return types.SimpleNamespace(runs_spent=spent, held_out=held_out)

    monkeypatch.setattr(calibration, "tune", fake_tune)
    args = argparse.Namespace(methods="race,random,grid,es", tuner_seeds=2, grid_budget=3.0,
                              stores=tmp_path)
    rows = calibration._compare(document(tune={"budget": 150}), "spec.toml", args)
    assert asked == [("grid", 450)] * 2 + [(m, 440 // 3) for m in ("race", "random", "es")
                                           for _ in range(2)]
    assert [row["best"] for row in rows] == [0.5] * 8
