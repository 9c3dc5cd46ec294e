"""Bad input to sweeps, tunes and replays (issue 65): seeds that would repeat a key, sizes nobody
asked for, and the messages of the sweep, tune and replay commands. Every case is refused before
any JAX program is compiled (this file has no budget in tests/compile_budgets.toml): from Python
with a ValueError naming the key or argument, from the CLI with exit status 2."""
import json
import math
import re

import jax
import numpy as np
import pytest
import sizes

from jaxswarm.cli import main
from jaxswarm.swarm import definition, make
from jaxswarm.sweep import SpecError, load_spec, run_sweep, spec_from_dict
from jaxswarm.sweep.batches import RunBatches
from jaxswarm.maps.entry import resolve
from jaxswarm.sweep.replay import replay_row
from jaxswarm.sweep.runner import _Pace
from jaxswarm.sweep.spec import SEED_LIMIT
from jaxswarm.sweep.store import ResultsStore
from jaxswarm.tune import TuneSpecError, load_tune_spec, tune, tune_spec_from_dict
from jaxswarm.tune.space import Choice, Integer, Real, Space

LIMIT_NAMED = "seeds are integers from 0 to 4,294,967,295"


def sweep_document(**changes):
    """A small sweep: 2 x 2 params x 3 seeds on one paper map (12 runs)."""
    document = {"sweep": {"name": "small", "algorithm": "rfd_star", "maps": ["mosaic20"],
                          "seeds": 3, "iterations": sizes.ITERATIONS, "chunk_size": 5},
                "config": dict(sizes.CONFIG),
                "params": {"p_base": [5.0, 20.0], "alpha": [2.0, 8.0]}}
    for section, values in changes.items():
        document[section] = dict(document.get(section, {}), **values)
    return document


def tune_document(**changes):
    """A small race: RFD*'s alpha and p_base on 12 training instances, 2 held out."""
    tune = {"name": "small", "algorithm": "rfd_star", "method": "race", "budget": 72,
            "objective": "gap", "iterations": sizes.ITERATIONS, "seed": 3, "chunk_size": 20,
            "training": {"maps": ["maze20", "mosaic20"], "seeds": 6},
            "held_out": {"maps": ["alley20"], "seeds": [100, 101]},
            "race": {"first_test": 3}}
    document = {"tune": tune, "config": dict(sizes.CONFIG),
                "params": {"alpha": {"low": 1.0, "high": 100.0},
                           "p_base": {"low": 1.5, "high": 1000.0, "log": True}}}
    for section, values in changes.items():
        document[section] = dict(document.get(section, {}), **values)
    return document


def toml(document: dict) -> str:
    """``document`` (tables of tables, strings, numbers, lists of those) as TOML text."""
    def value(v):
        if isinstance(v, str):
            return json.dumps(v)
        if isinstance(v, bool):
            return str(v).lower()
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        return repr(v)

    lines = []
    for section, table in document.items():
        lines.append(f"[{section}]")
        lines += [f"{key} = {value(v)}" for key, v in table.items()]
    return "\n".join(lines) + "\n"


def exit_message(argv, capsys) -> str:
    """The error line of ``jaxswarm ARGV``, which must exit with status 2."""
    with pytest.raises(SystemExit) as done:
        main(argv)
    assert done.value.code == 2
    return capsys.readouterr().err


# Seeds -----------------------------------------------------------------------------------------

def test_the_seed_limit_is_where_jax_random_key_starts_repeating_keys():
    """64-bit integers are off, so jax.random.key keeps a seed's low 32 bits: 2^32 is seed 0."""
    def data(seed):
        return np.asarray(jax.random.key_data(jax.random.key(seed)))

    np.testing.assert_array_equal(data(SEED_LIMIT), data(0))
    np.testing.assert_array_equal(data(SEED_LIMIT + 1), data(1))
    assert len({tuple(data(s)) for s in (0, 1, 2**31 - 1, 2**31, SEED_LIMIT - 1)}) == 5


@pytest.mark.parametrize("seeds, named", [
    ([0, 2**32], "seed 4294967296 is out of range"),  # would be seed 0's run twice
    ([1, 2**32 + 1], "seed 4294967297 is out of range"),
    ([2**64], "seed 18446744073709551616 is out of range"),  # crashed after compiling
    ([-1], "seed -1 is out of range"),
    (2**32 + 1, "4,294,967,297 seeds run past the last seed"),
])
def test_a_sweep_refuses_seeds_that_would_repeat_a_key_naming_the_range(seeds, named):
    with pytest.raises(SpecError) as error:
        spec_from_dict(sweep_document(sweep={"seeds": seeds}), source="study.toml")
    assert f"study.toml: sweep.seeds: {named}" in str(error.value)
    assert LIMIT_NAMED in str(error.value)


def test_the_last_seeds_of_the_range_are_accepted():
    spec = spec_from_dict(sweep_document(sweep={"seeds": [0, 2**31, SEED_LIMIT - 1]}))
    assert spec.seeds == (0, 2**31, SEED_LIMIT - 1)


@pytest.mark.parametrize("phase", ["training", "held_out"])
def test_a_tune_refuses_seeds_that_would_repeat_a_key(phase):
    instances = {"maps": ["alley20"], "seeds": [7, 2**32 + 7]}
    with pytest.raises(TuneSpecError) as error:
        tune_spec_from_dict(tune_document(tune={phase: instances}), source="t.toml")
    assert f"t.toml: tune.{phase}.seeds: seed 4294967303 is out of range" in str(error.value)


def test_the_batches_refuse_a_seed_outside_the_range_before_compiling():
    batches = RunBatches("rfd_star", dict(sizes.CONFIG), sizes.ITERATIONS, None, 5,
                         log=lambda _: None)
    with pytest.raises(ValueError, match="seeds must be integers from 0 to 4294967295"):
        batches.run(resolve("mosaic20"), np.array([0, 2**32]), {})


# Sizes -----------------------------------------------------------------------------------------

THOUSAND = {"start": 1.0, "stop": 100.0, "num": 1000}


def test_a_grid_of_a_billion_combinations_is_refused_before_it_is_built():
    document = sweep_document(params={"p_base": THOUSAND, "alpha": THOUSAND, "erosion": THOUSAND})
    with pytest.raises(SpecError) as error:
        spec_from_dict(document, source="huge.toml")
    assert ("huge.toml: sweep: 1 map(s) x 1,000,000,000 param combination(s) x 3 seed(s) = "
            "3,000,000,000 runs, more than the limit of 1,000,000 runs") in str(error.value)
    assert "--max-runs N" in str(error.value) and "max_runs=N" in str(error.value)


def test_max_runs_sets_the_limit_of_a_sweep():
    assert spec_from_dict(sweep_document(), max_runs=12).num_runs == 12
    with pytest.raises(SpecError, match="= 12 runs, more than the limit of 11 runs"):
        spec_from_dict(sweep_document(), max_runs=11)
    with pytest.raises(SpecError, match="sweep.seeds: 20 seeds, more than the limit of 11"):
        spec_from_dict(sweep_document(sweep={"seeds": 20}), max_runs=11)
    with pytest.raises(SpecError, match="params.alpha: num = 50 values make at least 50 runs"):
        spec_from_dict(sweep_document(params={"alpha": {"start": 1, "stop": 2, "num": 50}}),
                       max_runs=11)
    with pytest.raises(ValueError, match="max_runs must be at least 1, got 0"):
        spec_from_dict(sweep_document(), max_runs=0)
    with pytest.raises(TypeError, match="max_runs must be an integer or None, got '5'"):
        spec_from_dict(sweep_document(), max_runs="5")


def test_the_sweep_command_refuses_a_billion_combinations_naming_max_runs(tmp_path, capsys):
    spec = tmp_path / "huge.toml"
    spec.write_text(toml(sweep_document(params={"p_base": THOUSAND, "alpha": THOUSAND,
                                                "erosion": THOUSAND})))
    out = tmp_path / "out"
    error = exit_message(["sweep", str(spec), "--out", str(out)], capsys)
    assert f"{spec}: sweep: 1 map(s) x 1,000,000,000 param combination(s)" in error
    assert "--max-runs N" in error
    assert not out.exists()
    small = tmp_path / "small.toml"
    small.write_text(toml(sweep_document()))
    assert "= 12 runs, more than the limit of 11 runs" in exit_message(
        ["sweep", str(small), "--out", str(out), "--max-runs", "11"], capsys)
    assert "argument --max-runs: expected a positive integer, got 0" in exit_message(
        ["sweep", str(small), "--max-runs", "0"], capsys)
    assert not out.exists()


def test_a_combination_is_the_grid_s_without_building_the_grid():
    spec = spec_from_dict(sweep_document(params={"p_base": [5.0, 20.0, 40.0],
                                                 "alpha": {"start": 2, "stop": 8, "num": 4},
                                                 "erosion": [0.5, 1.0]}))
    grid = spec.grid()
    assert spec.num_combinations == len(grid) == 24 and spec.num_runs == 24 * 3
    values = spec.combination_values(np.arange(len(grid)))
    for name in spec.params:
        np.testing.assert_array_equal(values[name], [combination[name] for combination in grid])
    unswept = spec_from_dict({**sweep_document(), "params": {}})
    assert unswept.grid() == [{}] and unswept.combination_values(np.arange(3)) == {}


@pytest.mark.parametrize("changes, message", [
    (dict(tune={"method": "grid", "grid_points": 1000}, params={
        "alpha": {"low": 1.0, "high": 100.0}, "p_base": {"low": 1.5, "high": 1000.0},
        "erosion": {"low": 0.5, "high": 50.0}}),
     "t.toml: tune.grid_points: a grid of 1,000 points per param has 1,000,000,000 settings, "
     "more than the budget of 72 runs; the smallest budget for it is 1,000,000,000"),
    (dict(tune={"budget": 2_000_000}),
     "t.toml: tune.budget: 2,000,000 training runs and up to 8 held-out runs (4 settings on 2 "
     "instances) are 2,000,008 runs, more than the limit of 1,000,000 runs"),
    (dict(tune={"training": {"maps": ["maze20"], "seeds": 10**8}}),
     "t.toml: tune.training.seeds: 100,000,000 seeds, more than the limit of 1,000,000 runs"),
])
def test_a_tune_of_more_runs_than_it_may_make_is_refused(changes, message):
    with pytest.raises(TuneSpecError) as error:
        tune_spec_from_dict(tune_document(**changes), source="t.toml")
    assert message in str(error.value)


def test_max_runs_sets_the_limit_of_a_tune(tmp_path, capsys):
    assert tune_spec_from_dict(tune_document(), max_runs=80).budget == 72
    with pytest.raises(TuneSpecError, match="are 80 runs, more than the limit of 79 runs"):
        tune_spec_from_dict(tune_document(), max_runs=79)
    spec = tmp_path / "t.toml"
    spec.write_text(toml(tune_document()))
    assert "are 80 runs, more than the limit of 79 runs" in exit_message(
        ["tune", str(spec), "--max-runs", "79", "--out", str(tmp_path / "out")], capsys)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("space", [
    Space({"a": Real(0.1, 10.0, log=True), "b": Real(0.0, 1.0)}),
    Space({"a": Real(0.0, 1.0), "c": Choice((1.0, 2.0, 3.0))}),
    Space({"n": Integer(1, 9), "m": Integer(2, 5)}),
    Space({"n": Integer(1, 40, log=True), "a": Real(0.0, 1.0)}),
    Space({"c": Choice((1.0, 2.0))}),
])
def test_grids_are_counted_as_they_are_built(space):
    """The counts against the grids themselves, and the most points that fit against a search
    that builds every grid (the tuner's before issue 65, cut at 200 points: past the values its
    integer ranges hold a grid stops growing, and that search went on for ever)."""
    for points in (2, 3, 7):
        assert space.grid_size(points) == len(space.grid(points))
    for most in (1, 4, 30, 99, 500):
        built = 2
        while built < 200 and len(space.grid(built + 1)) <= most:
            built += 1
        counted = space.most_points(most)
        if built < 200:
            assert counted == built
        else:
            assert space.grid_size(counted) == len(space.grid(built))


def test_a_sweep_says_after_its_first_chunk_how_long_the_rest_takes():
    said = []
    pace = _Pace(chunks=1 + 1500, log=said.append)
    pace.first_chunk(64, 12.0)
    pace.first_chunk(64, 99.0)  # said once
    assert said == ["first chunk: 64 runs in 12.0 s; the 1,500 chunk(s) left take about 5.0 h "
                    "at its pace (plus a compile per other map shape)"]
    quiet = []
    _Pace(chunks=1, log=quiet.append).first_chunk(3, 1.0)
    assert quiet == []  # nothing left to estimate


# Messages --------------------------------------------------------------------------------------

def test_a_budget_too_small_to_race_is_refused_naming_the_smallest():
    """Two free params: irace's least, (N_min + 1) N_iter T with N_min = N_iter = 3 and T =
    first_test + 1 + (N_iter - 1) new instances = 3 + 1 + 2: 4 x 3 x 6 = 72 runs."""
    with pytest.raises(TuneSpecError) as error:
        tune_spec_from_dict(tune_document(tune={"budget": 71}), source="t.toml")
    assert ("t.toml: tune.budget: a budget of 71 runs is too small for method race: the "
            "smallest is 72") in str(error.value)
    assert tune_spec_from_dict(tune_document(tune={"budget": 72})).budget == 72
    # Without elitism irace's least is (N_min + 1) N_iter (first_test + 5): 4 x 3 x 8 = 96.
    with pytest.raises(TuneSpecError, match="the smallest is 96"):
        tune_spec_from_dict(tune_document(tune={"race": {"first_test": 3, "elitist": False}}))


@pytest.mark.parametrize("method, budget, least", [("es", 23, 24), ("random", 1, 2)])
def test_a_budget_too_small_for_the_other_methods_is_refused(method, budget, least):
    with pytest.raises(TuneSpecError, match=f"tune.budget: a budget of {budget} runs is too "
                                            f"small for method {method}: the smallest is {least}"):
        tune_spec_from_dict(tune_document(tune={"method": method, "budget": budget}))


@pytest.mark.parametrize("first_test, message", [
    (1, "tune.race.first_test: must be at least 2"),
    (13, "tune.race.first_test: 13 is more than the 12 training instances"),
])
def test_the_race_keys_are_checked_up_front(first_test, message):
    with pytest.raises(TuneSpecError, match=message):
        tune_spec_from_dict(tune_document(tune={"race": {"first_test": first_test}}))


@pytest.mark.parametrize("command, document, error_type", [
    ("sweep", sweep_document(), SpecError), ("tune", tune_document(), TuneSpecError)])
def test_a_spec_that_is_not_utf8_is_named_with_its_line(tmp_path, capsys, command, document,
                                                       error_type):
    spec = tmp_path / "latin1.toml"
    text = toml(document)
    spec.write_bytes(text.replace('"small"', '"sm\xe5ll"').encode("latin-1"))
    load = load_spec if command == "sweep" else load_tune_spec
    with pytest.raises(error_type) as error:
        load(spec)
    assert str(error.value) == (f"{spec}: line 2: not UTF-8 text (byte 0xe5); a TOML file "
                                "is UTF-8")
    assert f"{spec}: line 2: not UTF-8 text" in exit_message([command, str(spec)], capsys)


@pytest.mark.parametrize("command, document", [("sweep", sweep_document()),
                                               ("tune", tune_document())])
@pytest.mark.parametrize("inside", [False, True])
def test_out_naming_a_file_is_refused_and_the_file_kept(tmp_path, capsys, command, document,
                                                         inside):
    spec = tmp_path / "spec.toml"
    spec.write_text(toml(document))
    file = tmp_path / "results.txt"
    file.write_text("mine")
    out = file / "sub" if inside else file
    error = exit_message([command, str(spec), "--out", str(out)], capsys)
    where = f"lies in {file}, a file" if inside else "is a file"
    assert f"--out: {out} {where}, not a folder" in error
    assert file.read_text() == "mine"


@pytest.mark.parametrize("command", ["sweep", "tune"])
def test_the_python_entry_points_refuse_out_naming_a_file(tmp_path, command):
    file = tmp_path / "results.txt"
    file.write_text("mine")
    with pytest.raises(ValueError, match=f"out: {file} is a file, not a folder"):
        if command == "sweep":
            run_sweep(spec_from_dict(sweep_document()), file, progress=False)
        else:
            tune(tune_spec_from_dict(tune_document()), file)
    assert file.read_text() == "mine"


def _store_with_rows(out, spec_record: dict, metadata: dict, rows: dict) -> None:
    """A store at ``out`` holding one chunk of hand-made ``rows`` (no run is made)."""
    ResultsStore(out, spec_record, metadata).write_chunk(0, 0, rows)


def test_replay_of_a_tune_s_store_says_so(tmp_path, capsys):
    spec = tune_spec_from_dict(tune_document())
    out = tmp_path / "tune"
    _store_with_rows(out, spec.as_dict(), dict(swarm=definition(make("rfd_star", **spec.config))),
                     dict(batch=[0], phase=["training"], setting=[0], instance=[0],
                          map_index=[0], seed=[0], cost=[30.0], loss=[0.1]))
    with pytest.raises(ValueError, match=f"{out} is a tune's store .jaxswarm tune., not a "
                                         "sweep's"):
        replay_row(out, 0)
    assert f"{out} is a tune's store" in exit_message(["replay", str(out), "0"], capsys)


def test_replay_of_a_store_whose_metadata_is_not_json_names_the_file_and_line(tmp_path, capsys):
    out = tmp_path / "store"
    (out / "runs").mkdir(parents=True)
    (out / "metadata.json").write_text('{"spec": [')
    expected = f"{out / 'metadata.json'}: line 1 column 11: not valid JSON"
    with pytest.raises(ValueError, match=re.escape(expected)):
        replay_row(out, 0)
    assert expected in exit_message(["replay", str(out), "0"], capsys)


ROW = dict(map=["mosaic20"], map_index=[0], run=[0], algorithm=["rfd_star"], seed=[0],
           p_base=[5.0], alpha=[2.0], cost=[31.0], iterations=[8], moves=[100],
           evaluations=[32], fingerprint=["0123456789abcdef"], chunk=[0])


@pytest.mark.parametrize("changes, named", [
    (dict(map_index=[math.nan], seed=[math.nan], cost=[math.nan]), "map_index is nan"),
    (dict(cost=[math.nan]), "cost is nan"),
    (dict(iterations=[math.nan]), "iterations is nan"),
    (dict(seed=[2.0**32]), "seed is 4294967296.0, not an integer in 0 to 4294967295"),
    (dict(fingerprint=[None]), "fingerprint is None, not 16 hex digits"),
])
def test_replay_of_a_row_whose_figures_are_not_a_run_s_names_the_column(tmp_path, capsys,
                                                                       changes, named):
    spec = spec_from_dict(sweep_document())
    out = tmp_path / "sweep"
    _store_with_rows(out, spec.as_dict(), dict(swarm=definition(make("rfd_star", **spec.config))),
                     {**ROW, **changes})
    with pytest.raises(ValueError, match=f"{out} row 0: {named}"):
        replay_row(out, 0)
    assert f"{out} row 0: {named}" in exit_message(["replay", str(out), "0"], capsys)
