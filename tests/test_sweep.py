"""The sweep runner: specs, results store, resume after a kill, sharding, plots."""
import json
import shutil
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import matplotlib
import matplotlib.image
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
import sizes

from jaxswarm.exact import dijkstra, optimal_length
from jaxswarm.exact.visibility import shortest_path
from jaxswarm.maps.entry import resolve
from jaxswarm.maps.paper import paper_map
from jaxswarm.maps.planes import paper_plane
from jaxswarm.plot.sweep import heatmap_figure, line_figure, plot_sweep, summary
import jaxswarm
from jaxswarm import cli
from jaxswarm.swarm import definition, make, make_task, registered, run
from jaxswarm.sweep import (SpecError, StoreMismatchError, load_spec, read_results, run_sweep,
                            spec_from_dict)
from jaxswarm.sweep.replay import replay_row
from jaxswarm.sweep.store import ResultsStore
from jaxswarm.sweep import runner
from jaxswarm.swarm.executor import group_size
from jaxswarm.swarm.walking import WalkerOptions
from jaxswarm.sweep.batches import RunBatches
from jaxswarm.swarm.fingerprint import hex_fingerprint, run_fingerprint
from jaxswarm.swarm.rfd.river import gradients

REPO = Path(__file__).resolve().parents[1]

OUTCOME_COLUMNS = ["map", "run", "seed", "p_base", "alpha", "cost", "found", "iterations",
                   "moves", "fingerprint"]
"""What a run decides, without its timing: equal wherever and however the runs are batched."""


def tiny(**changes):
    """A small spec document: 2 x 2 params x 3 seeds on one paper map and one random map, at the
    shared size of ``tests/sizes.py``. Both maps are 20 x 20, so every chunk (5 runs, the width
    of test_tune.py's calls too) is one compiled program, and a row's run alone is the
    conformance checks' run of rfd_star."""
    document = {
        "sweep": {"name": "tiny", "algorithm": "rfd_star",
                  "maps": ["mosaic20", {"random": 20, "seed": 4}], "seeds": 3,
                  "iterations": sizes.ITERATIONS, "chunk_size": 5},
        "config": dict(sizes.CONFIG),
        "params": {"p_base": [5.0, 20.0], "alpha": {"start": 2, "stop": 8, "num": 2}},
    }
    for section, values in changes.items():
        document[section] = dict(document.get(section, {}), **values)
    return document


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep") / "tiny"
    spec = spec_from_dict(tiny())
    return spec, out, run_sweep(spec, out, progress=False, log=lambda _: None)


def test_spec_grid_ranges_and_seeds():
    spec = spec_from_dict(tiny(params={"erosion": {"start": 0.5, "stop": 50, "num": 3,
                                                   "log": True},
                                       "sediment": {"start": 0.5, "stop": 2.0, "step": 0.5}}))
    assert spec.params["alpha"] == (2.0, 8.0)
    np.testing.assert_allclose(spec.params["erosion"], [0.5, 5.0, 50.0])
    assert spec.params["sediment"] == (0.5, 1.0, 1.5)
    assert spec.seeds == (0, 1, 2)
    grid = spec.grid()
    assert len(grid) == 2 * 2 * 3 * 3 and spec.num_runs == len(grid) * 3
    assert grid[0] == dict(p_base=5.0, alpha=2.0, erosion=0.5, sediment=0.5)
    assert grid[1]["sediment"] == 1.0  # the last param varies fastest


@pytest.mark.parametrize("changes, message", [
    (dict(sweep={"algorithm": "bees"}), "sweep.algorithm: unknown algorithm 'bees'"),
    (dict(params={"p_bse": [1.0]}), "params.p_bse: unknown param of rfd_star; known: p_base"),
    (dict(params={"alpha": []}), "params.alpha: empty list"),
    (dict(params={"alpha": {"start": 5, "stop": 1, "step": 1}}), "params.alpha: step 1 does"),
    (dict(params={"p_base": [float("nan")]}), "params.p_base: p_base must be finite"),
    (dict(params={"sediment": [-1.0]}), "params.sediment: sediment must be non-negative"),
    (dict(sweep={"maps": ["mosaic30"]}), r"sweep.maps\[0\]: unknown map 'mosaic30'"),
    (dict(sweep={"maps": [{"random": 20}]}), r"sweep.maps\[0\]: seed = None"),
    (dict(sweep={"maps": [{"movingai": "x.map", "start": [0, 0]}]}),
     r"sweep.maps\[0\]: goal = None: must be \[x, y\]"),
    (dict(sweep={"seeds": 0}), "sweep.seeds: must be at least 1"),
    (dict(sweep={"iterations": 0}), "sweep.iterations: must be a positive integer"),
    (dict(sweep={"vmap_size": 0}), "sweep.vmap_size: must be a positive integer"),
    (dict(sweep={"colour": "red"}), "sweep.colour: unknown key"),
    (dict(config={"num_ants": 4}), "config.num_ants: unknown config of rfd_star"),
    (dict(config={"num_agents": 0}), r"\[config\]: num_agents must be at least 1"),
    (dict(extra={"x": 1}), "extra: unknown section"),
    (dict(sweep={"maps": [{"plane": "map3"}]}), r"sweep.maps\[0\]: plane = 'map3': one of map1"),
    (dict(sweep={"maps": [{"plane": "random"}]}), r"sweep.maps\[0\]: seed = None: a random"),
    (dict(sweep={"maps": ["mosaic20", {"plane": "map1"}]}),
     r"sweep.maps\[1\]: rfd_star plans on a Graph, this map is a Plane"),
    (dict(sweep={"algorithm": "cabc"}, config={"num_agents": 8}, params={"w1": [1.0]}),
     r"sweep.maps\[0\]: cabc plans on a Plane, this map is a Graph"),
])
def test_bad_specs_name_the_key(changes, message):
    with pytest.raises(SpecError, match=message):
        spec_from_dict(tiny(**changes), source="study.toml")


def test_bad_toml_names_the_line_and_fails_before_any_compute(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('[sweep]\nalgorithm = "rfd_star"\nmaps = = ["mosaic20"]\n')
    with pytest.raises(SpecError, match=r"bad.toml: not valid TOML: .*line 3"):
        load_spec(bad)
    unknown = tmp_path / "unknown.toml"
    unknown.write_text('[sweep]\nalgorithm = "rfd_star"\nmaps = ["atlantis"]\nseeds = 2\n')
    out = tmp_path / "results"
    with pytest.raises(SystemExit) as exited:
        cli.main(["sweep", str(unknown), "--out", str(out)])
    assert exited.value.code == 2
    assert "unknown.toml: sweep.maps[0]: unknown map 'atlantis'" in capsys.readouterr().err
    assert not out.exists()  # nothing was started


def _tiny_movingai(folder):
    """A Moving AI map of the shared 20 x 20 shape, open but for one obstacle at (2, 0), on which
    the second scenario row starts."""
    rows = ["..@" + "." * 17] + ["." * 20] * 19
    (folder / "tiny.map").write_text("type octile\nheight 20\nwidth 20\nmap\n"
                                     + "\n".join(rows) + "\n")
    (folder / "tiny-even-1.scen").write_text(
        "version 1\n0\ttiny.map\t20\t20\t0\t0\t2\t1\t2.41421356\n"
        "0\ttiny.map\t20\t20\t2\t0\t0\t1\t2.0\n")
    (folder / "tiny-random-1.scen").write_text(
        "version 1\n0\ttiny.map\t20\t20\t2\t1\t0\t0\t2.41421356\n")


@pytest.mark.parametrize("entry, message", [
    ({"movingai": "tiny.map", "scenario": 1},
     r"sweep.maps\[1\] = .*tiny-even-1.scen, line 3: start \(2, 0\) is an obstacle"),
    ({"movingai": "tiny.map", "scenario": 9}, r"sweep.maps\[1\] = .*scenario 9 out of range"),
    ({"movingai": "nowhere.map", "scenario": 0},
     r"sweep.maps\[1\] = .*Moving AI map 'nowhere.map' not found"),
    ({"movingai": "tiny.map", "scenario": 0, "scenario_file": "odd"},
     r"sweep.maps\[1\] = .*no scenario file odd beside it"),
])
def test_a_bad_map_entry_is_named_and_leaves_nothing_on_disk(tmp_path, monkeypatch, entry,
                                                             message):
    _tiny_movingai(tmp_path)
    monkeypatch.setenv("JAXSWARM_MOVINGAI", str(tmp_path))
    spec = spec_from_dict(tiny(sweep={"maps": ["mosaic20", entry]}))
    out = tmp_path / "out"
    with pytest.raises(ValueError, match=message):
        run_sweep(spec, out, progress=False)
    assert not out.exists()


def test_a_moving_ai_entry_chooses_its_scenario_file(tmp_path, monkeypatch):
    _tiny_movingai(tmp_path)
    monkeypatch.setenv("JAXSWARM_MOVINGAI", str(tmp_path))
    entries = [{"movingai": "tiny.map", "scenario": 0},
               {"movingai": "tiny.map", "scenario": 0, "scenario_file": "random"}]
    spec = spec_from_dict(tiny(sweep={"maps": entries, "seeds": 1},
                               params={"p_base": [5.0], "alpha": [2.0]}))
    frame = run_sweep(spec, tmp_path / "out", progress=False, log=lambda _: None)
    assert list(frame["map"]) == ["tiny#0", "tiny#0"]
    # even row 0 goes (0, 0) -> (2, 1), random row 0 (2, 1) -> (0, 0): the same optimum.
    np.testing.assert_allclose(frame["optimum"], 1 + np.sqrt(2), rtol=1e-6)
    metadata = json.loads((tmp_path / "out" / "metadata.json").read_text())
    assert [m["start"] for m in metadata["maps"]] == [[0, 0], [2, 1]]


def test_rows_are_tidy_and_match_single_runs(finished):
    spec, out, frame = finished
    assert len(frame) == 2 * spec.num_runs == 24
    assert not frame.duplicated(["map", "run"]).any()
    assert set(frame.columns) >= {"map", "algorithm", "seed", "p_base", "alpha", "cost",
                                  "optimum", "gap", "found", "success", "iterations", "chunk",
                                  "chunk_seconds"}
    # One wall time per chunk, repeated in each of its rows.
    assert (frame.groupby(["map", "chunk"])["chunk_seconds"].nunique() == 1).all()
    assert (frame["chunk_seconds"] > 0).all()
    chosen = paper_map("mosaic20")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    optimum = dijkstra(graph, chosen.start, chosen.goal).cost
    rows = frame[frame["map"] == "mosaic20"]
    np.testing.assert_allclose(rows["optimum"], optimum, rtol=1e-6)
    # The optimum is measured as swarm paths are (the float32 field gives 18.656853 here, a
    # path of the optimal moves 18.656855): an optimal run has gap 0, never a negative one.
    assert (rows["optimum"] == optimal_length(graph, chosen.start, chosen.goal)).all()
    assert (frame["gap"][frame["found"]] >= 0).all()
    swarm = make("rfd_star", **sizes.CONFIG)
    for _, row in rows.iloc[[0, 7, 11]].iterrows():  # a row equals run() with key(seed)
        params = swarm.default_params._replace(p_base=jnp.float32(row.p_base),
                                               alpha=jnp.float32(row.alpha))
        state, trace = run(swarm, jax.random.key(int(row.seed)), graph, task, params,
                           iterations=sizes.ITERATIONS)
        assert float(swarm.best(state).cost) == pytest.approx(row.cost, rel=0, abs=0)
        assert int(trace.iterations) == row.iterations
    # The store is a Parquet dataset pandas reads directly, with a metadata record.
    direct = pd.read_parquet(out / "runs")
    assert len(direct) == len(frame)
    metadata = json.loads((out / "metadata.json").read_text())
    assert metadata["spec"]["params"]["p_base"] == [5.0, 20.0]
    assert metadata["jax"] == jax.__version__ and metadata["seeds"] == [0, 1, 2]
    assert spec.vmap_size is None and metadata["vmap_size"] == min(
        group_size(spec.config["num_agents"]), spec.chunk_size)  # the walker's lanes filled
    assert {"git_commit", "jaxswarm", "devices", "config", "maps"} <= set(metadata)


@jax.jit
def _gradients_alone_and_batched(graph, altitudes):
    """RFD's gradients (eq. 2) of each row of ``altitudes`` f32[R, N] on ``graph``: one run at a
    time (``lax.map``, as ``run`` computes them alone) and the R runs under ``vmap`` sharing the
    graph (as the runner's groups do), each f32[R, K, N]."""
    def one(altitude):
        return gradients(graph, altitude)[1]
    return jax.lax.map(one, altitudes), jax.vmap(one)(altitudes)


def test_the_gradients_a_drop_draws_from_are_the_same_alone_and_in_a_batch():
    """The log-weights of the RFD swarms are the same bits alone and in a sweep's batch. XLA
    compiles a division by an operand the batch shares (the map's distances) as a multiplication
    by its reciprocal, up to 1.5 ulp away from the quotient on diagonal edges: in
    benchmarks/sweep.py, 2 of 1,280 rows at 16 drops and 4 at 64 made other moves than the same
    runs alone; here 1,714 of the 9,600 entries differed."""
    graph, _ = sizes.maze()
    altitudes = np.random.default_rng(sizes.SEED).uniform(
        0.0, 1e4, (sizes.RUNS, graph.num_nodes)).astype(np.float32)
    alone, batched = jax.device_get(_gradients_alone_and_batched(graph, altitudes))
    np.testing.assert_array_equal(alone.view(np.int32), batched.view(np.int32))
    # Eq. 2 in NumPy's float32 on every edge (a slot without a neighbour holds any value), as
    # the docstring of gradients writes it.
    nbr, cost = np.asarray(graph.nbr), np.asarray(graph.cost)
    drop = altitudes[:, :, None] - altitudes[:, np.maximum(nbr, 0)]
    expected = drop * (np.float32(1.0) / np.where(nbr >= 0, cost, np.float32(1.0)))
    edges = np.broadcast_to(nbr >= 0, expected.shape)
    np.testing.assert_array_equal(alone.transpose(0, 2, 1)[edges].view(np.int32),
                                  expected[edges].view(np.int32))


@pytest.mark.slow  # programs of a cramped log and of a roomy one, about 60 s cold
def test_a_chunk_whose_walk_overflowed_its_log_is_made_again_with_room(finished, tmp_path,
                                                                     monkeypatch):
    """Twin in the default tier: test_log.py's run and batch made again with room (the retry this
    runner shares). The swarm's walks get one block of room per drop, as no spec can ask."""
    _, _, frame = finished
    messages = []

    def cramped_batches(algorithm, config, *args, **kwargs):
        return RunBatches(algorithm, {**config, "walker": WalkerOptions(log_moves=16)}, *args,
                          **kwargs)

    monkeypatch.setattr(runner, "RunBatches", cramped_batches)
    cramped = run_sweep(spec_from_dict(tiny()), tmp_path / "out", progress=False,
                        log=messages.append)
    assert any("no room for its moves" in message for message in messages)
    pd.testing.assert_frame_equal(cramped[OUTCOME_COLUMNS], frame[OUTCOME_COLUMNS])


def test_batches_of_a_swarm_that_does_not_walk_need_no_room():
    # Twin of the slow bees sweeps: the program with room is made only after an overflow.
    batches = RunBatches("cabc", {}, 2, None, 4, log=lambda _: None)
    assert batches.group >= 1 and batches.call_size(3) == 4


def test_a_bees_spec_checks_its_params():
    document = {"sweep": {"algorithm": "cabc", "maps": [{"plane": "map1"}], "seeds": 1},
                "params": {"inner_iterations": [2, 1.5]}}
    with pytest.raises(SpecError, match="params.inner_iterations: inner_iterations must be a "
                                        "whole number"):
        spec_from_dict(document, source="bees.toml")


@pytest.mark.slow  # compiles the bees' chunk and a run: about 12 s
def test_a_bees_sweep_over_planes_carries_the_visibility_graph_optimum(tmp_path):
    document = {"sweep": {"name": "bees", "algorithm": "cabc", "maps": [{"plane": "map2"}],
                          "seeds": 2, "iterations": 200, "chunk_size": 4},
                "params": {"w3": [0.0, 0.03]}}
    frame = run_sweep(spec_from_dict(document), tmp_path / "out", progress=False,
                      log=lambda _: None)
    chosen = paper_plane("map2")
    optimum, _ = shortest_path(chosen.plane, chosen.start, chosen.goal)
    assert len(frame) == 4 and (frame["optimum"] == optimum).all()
    assert (frame["gap"][frame["found"]] >= 0).all() and (frame["evaluations"] > 0).all()
    swarm = make("cabc")
    task = make_task(chosen.plane, chosen.start, chosen.goal)
    for _, row in frame.iloc[[1, 2]].iterrows():  # a row equals run() with key(seed)
        params = swarm.default_params._replace(w3=np.float32(row.w3))
        state, trace = run(swarm, jax.random.key(int(row.seed)), chosen.plane, task, params,
                           iterations=200)
        assert float(swarm.best(state).cost) == row.cost
        assert int(trace.iterations) == row.iterations
        assert int(np.sum(trace.moves)) == row.moves
    metadata = json.loads((tmp_path / "out" / "metadata.json").read_text())
    assert metadata["maps"] == [dict(label="map2", start=[3.0, 3.0], goal=[47.0, 47.0],
                                     size="50x50")]


@pytest.mark.slow  # programs of a 40-iteration run with patience, about 40 s cold
def test_a_sweep_with_patience_stops_its_runs_as_run_does(tmp_path):
    """Twin in the default tier: test_the_runner_takes_the_specs_stop_rules."""
    spec = spec_from_dict(tiny(sweep={"maps": ["mosaic20"], "seeds": 2, "iterations": 40,
                                      "patience": 3},
                               params={"p_base": [20.0], "alpha": [8.0]}))
    frame = run_sweep(spec, tmp_path / "out", progress=False, log=lambda _: None)
    chosen = paper_map("mosaic20")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make("rfd_star", **sizes.CONFIG)
    params = swarm.default_params._replace(p_base=np.float32(20.0), alpha=np.float32(8.0))
    for _, row in frame.iterrows():
        state, trace = run(swarm, jax.random.key(int(row.seed)), graph, task, params,
                           iterations=40, patience=3)
        assert row.iterations == int(trace.iterations) and row.cost == float(state.best_cost)
    assert (frame["iterations"] < 40).all()  # patience, not the budget, stopped them


def test_the_runner_takes_the_specs_stop_rules(tmp_path, monkeypatch):
    asked = {}

    class Asked(Exception):
        pass

    def batches(algorithm, config, iterations, patience, *_):
        asked.update(iterations=iterations, patience=patience)
        raise Asked

    monkeypatch.setattr(runner, "RunBatches", batches)
    spec = spec_from_dict(tiny(sweep={"iterations": 40, "patience": 3}))
    with pytest.raises(Asked):
        run_sweep(spec, tmp_path / "out", progress=False, log=lambda _: None)
    assert asked == {"iterations": 40, "patience": 3}


def test_same_spec_resumes_without_recomputing_and_other_spec_is_refused(finished):
    spec, out, frame = finished
    stamps = {p.name: p.stat().st_mtime_ns for p in (out / "runs").glob("*.parquet")}
    messages = []
    again = run_sweep(spec, out, progress=False, log=messages.append)
    assert {p.name: p.stat().st_mtime_ns for p in (out / "runs").glob("*.parquet")} == stamps
    assert messages == [f"resuming {out}: 6 of 6 chunks already finished"]
    pd.testing.assert_frame_equal(again, frame)
    with pytest.raises(StoreMismatchError, match="differs in: seeds"):
        run_sweep(spec_from_dict(tiny(sweep={"seeds": 4})), out, progress=False)


def _rewrite_metadata(out, change):
    path = out / "metadata.json"
    metadata = json.loads(path.read_text())
    change(metadata)
    path.write_text(json.dumps(metadata))


def test_a_store_records_the_swarms_definition_and_refuses_another(finished, tmp_path):
    spec, out, _ = finished
    metadata = json.loads((out / "metadata.json").read_text())
    assert metadata["swarm"] == definition(make("rfd_star", **sizes.CONFIG))
    assert metadata["swarm"]["config"]["erosion_law"] == "linear"
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    # The same name under another definition (here: a default param changed since).
    _rewrite_metadata(copy, lambda m: m["swarm"]["default_params"].update(alpha=12.0))
    with pytest.raises(StoreMismatchError, match=r"another definition of 'rfd_star' .*"
                                                 r"differs in: default_params.alpha"):
        run_sweep(spec, copy, progress=False)


def test_a_store_of_0_6_0_is_not_resumed(finished, tmp_path):
    spec, out, _ = finished
    old = tmp_path / "old"
    shutil.copytree(out, old)
    _rewrite_metadata(old, lambda m: m.update(jaxswarm="0.6.0"))  # same definition, older results
    with pytest.raises(StoreMismatchError, match=r"written by jaxswarm 0\.6\.0; 'rfd_star' gives "
                                                 r"the same results since jaxswarm 0\.7\.0"):
        run_sweep(spec, old, progress=False)


def test_a_store_of_0_7_resumes_for_a_swarm_whose_results_stayed(finished, tmp_path):
    spec, out, _ = finished
    old = tmp_path / "old"
    shutil.copytree(out, old)
    _rewrite_metadata(old, lambda m: m.update(jaxswarm="0.7.1"))  # rfd_star is as it was in 0.7
    assert run_sweep(spec, old, progress=False).equals(read_results(out))


@pytest.mark.parametrize("name", ["ant_system", "iwd", "max_min_aco", "rfd"])
def test_a_store_of_0_7_is_refused_for_a_swarm_calibrated_in_0_8(tmp_path, name):
    # Same definition as recorded (a store that recorded today's defaults under 0.7.1 cannot
    # exist, but the version alone refuses it): its results changed with 0.8.0's defaults.
    metadata = dict(jaxswarm="0.7.1", swarm=definition(make(name)))
    ResultsStore(tmp_path, {"sweep": 1}, metadata)
    with pytest.raises(StoreMismatchError, match=rf"0\.7\.1; '{name}' gives the same results "
                                                 r"since jaxswarm 0\.8\.0"):
        ResultsStore(tmp_path, {"sweep": 1}, dict(metadata, jaxswarm="0.8.0"))


def test_a_store_of_0_1_0s_rfd_star_is_not_resumed(finished, tmp_path):
    spec, out, _ = finished
    old = tmp_path / "old"
    shutil.copytree(out, old)

    def as_written_by_0_1_0(metadata):  # 0.1.0 recorded no definition
        del metadata["swarm"]
        metadata["jaxswarm"] = "0.1.0"

    _rewrite_metadata(old, as_written_by_0_1_0)
    stamps = sorted(p.name for p in (old / "runs").iterdir())
    with pytest.raises(StoreMismatchError, match=r"written by jaxswarm 0\.1\.0, which did not "
                                                 r"record the definition of 'rfd_star'; "
                                                 r"'rfd_star' gives the same results since "
                                                 r"jaxswarm 0\.7\.0"):
        run_sweep(spec, old, progress=False)
    assert sorted(p.name for p in (old / "runs").iterdir()) == stamps  # nothing written


@pytest.mark.slow  # about 30-40 s
def test_the_vmap_size_changes_no_row_and_a_store_resumes_with_another(finished, tmp_path):
    spec, out, frame = finished
    # Chunks of 5 runs in groups of 2: two full groups and a remainder of one per chunk.
    grouped = spec_from_dict(tiny(sweep={"vmap_size": 2}))
    messages = []
    rows = run_sweep(grouped, tmp_path / "grouped", progress=False, log=messages.append)
    assert any("2 at a time" in message for message in messages)
    pd.testing.assert_frame_equal(rows[OUTCOME_COLUMNS], frame[OUTCOME_COLUMNS])
    messages = []
    run_sweep(grouped, out, progress=False, log=messages.append)
    assert messages == [f"resuming {out}: 6 of 6 chunks already finished"]


def test_plots_are_written_next_to_the_results(finished):
    spec, out, frame = finished
    paths = plot_sweep(frame, ["p_base", "alpha"], out)
    assert [p.name for p in paths] == ["heatmap_success_alpha_vs_p_base.png",
                                       "heatmap_gap_alpha_vs_p_base.png", "line_p_base.png",
                                       "line_alpha.png"]
    for path in paths:
        image = matplotlib.image.imread(path)
        assert image.ndim == 3 and image[..., :3].std() > 0.05  # a drawing, not a blank page
    with pytest.raises(ValueError, match="no column 'rho'"):
        plot_sweep(frame, ["rho"], out)


def test_summary_aggregates_over_seeds_and_leaves_runs_without_a_path_out_of_the_gap(finished):
    _, _, frame = finished
    frame = frame.copy()
    frame.loc[0, ["cost", "gap", "found", "success"]] = [np.inf, np.inf, False, False]
    table = summary(frame, ["map", "p_base"])
    for (name, p_base), rows in frame.groupby(["map", "p_base"]):
        cell = table[(table["map"] == name) & (table["p_base"] == p_base)].iloc[0]
        gaps = rows["gap"][np.isfinite(rows["gap"])]
        assert cell.runs == len(rows) == 6
        assert cell.success == pytest.approx(rows["success"].mean())
        assert cell.found == pytest.approx(rows["found"].mean())
        assert cell.gap == pytest.approx(gaps.mean()) and np.isfinite(cell.gap)
        assert cell.gap_std == pytest.approx(gaps.std(ddof=0))
    assert table["found"].min() == pytest.approx(5 / 6)  # the row without a path


def test_figures_draw_log_ranges_on_a_log_axis_with_labelled_colour_bars(finished):
    spec, _, frame = finished
    assert spec.log_scale == frozenset()  # alpha is a linear range, p_base a list
    logged = spec_from_dict(tiny(params={"p_base": {"start": 2, "stop": 200, "num": 3,
                                                    "log": True}}))
    assert logged.log_scale == {"p_base"}
    for log in (False, True):
        fig = line_figure(frame, "p_base", log=log)
        assert {ax.get_xscale() for ax in fig.axes[::2]} == {"log" if log else "linear"}
        plt.close(fig)
    fig = heatmap_figure(frame, "p_base", "alpha", "gap")
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(bars) == 2 and all(bar.get_ylabel() == "mean gap to the optimum" for bar in bars)
    fig.canvas.draw()
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    renderer = fig.canvas.get_renderer()
    # The first colour bar's label ends before the second map's panel begins.
    assert bars[0].get_tightbbox(renderer).x1 < panels[1].get_tightbbox(renderer).x0
    plt.close(fig)


SLOW_SPEC = """
[sweep]
name = "killed"
algorithm = "rfd_star"
maps = ["mosaic50"]
seeds = 24
iterations = 40
chunk_size = 2

[config]
num_agents = 64
"""


def sweep_command(spec: Path, out: Path):
    return [sys.executable, "-c", "from jaxswarm.cli import main; raise SystemExit(main())",
            "sweep", str(spec), "--out", str(out), "--no-progress", "--no-plots"]


@pytest.mark.slow  # about 30-40 s
def test_a_killed_sweep_resumes_without_losing_or_repeating_a_chunk(tmp_path):
    spec = tmp_path / "killed.toml"
    spec.write_text(SLOW_SPEC)
    out = tmp_path / "killed"
    process = subprocess.Popen(sweep_command(spec, out), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 300
    while not list(out.glob("runs/part-*.parquet")):
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "no chunk finished in time"
        time.sleep(0.02)
    process.send_signal(signal.SIGKILL)
    process.wait()
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes())
              for p in (out / "runs").glob("part-*.parquet")}
    assert 0 < len(before) < 12, "the sweep must be killed mid-way"
    # Only whole chunks are visible; anything half-written is a hidden temporary file.
    assert len(read_results(out)) == 2 * len(before)
    assert all(p.name.startswith((".", "part-")) for p in (out / "runs").iterdir())

    finished = subprocess.run(sweep_command(spec, out), capture_output=True, text=True,
                              timeout=600)
    assert finished.returncode == 0, finished.stderr
    assert f"{len(before)} of 12 chunks already finished" in finished.stdout
    after = {p.name: (p.stat().st_mtime_ns, p.read_bytes())
             for p in (out / "runs").glob("part-*.parquet")}
    assert len(after) == 12 and all(after[name] == before[name] for name in before)
    frame = read_results(out)
    assert sorted(frame["run"]) == list(range(24))
    assert not any(p.name.startswith(".") for p in (out / "runs").iterdir())


SHARDED = textwrap.dedent("""
    import sys, jax
    from jaxswarm.sweep import spec_from_dict, run_sweep
    sys.path.insert(0, {tests!r})
    from test_sweep import tiny
    frame = run_sweep(spec_from_dict(tiny()), {out!r}, progress=False, log=print)
    print("devices", len(jax.devices()))
""")


@pytest.mark.slow  # about 30-40 s
def test_sharding_over_four_cpu_devices_gives_identical_rows(finished, tmp_path):
    _, _, frame = finished
    out = tmp_path / "sharded"
    env = dict(os.environ, XLA_FLAGS="--xla_force_host_platform_device_count=4")
    done = subprocess.run([sys.executable, "-c", SHARDED.format(tests=str(REPO / "tests"),
                                                                 out=str(out))],
                          capture_output=True, text=True, timeout=600, env=env, cwd=REPO)
    assert done.returncode == 0, done.stderr
    assert "devices 4" in done.stdout and "on 4 device(s)" in done.stdout
    sharded = read_results(out)
    pd.testing.assert_frame_equal(sharded[OUTCOME_COLUMNS], frame[OUTCOME_COLUMNS])


@pytest.mark.slow
def test_ten_thousand_runs_on_a_50x50_map_fit_in_memory(tmp_path):
    spec = spec_from_dict({
        "sweep": {"name": "ten_thousand", "algorithm": "rfd_star", "maps": ["mosaic50"],
                  "seeds": 100, "iterations": 5, "chunk_size": 1000},
        "config": {"num_agents": 8},
        "params": {"p_base": {"start": 2, "stop": 200, "num": 10, "log": True},
                   "alpha": {"start": 1, "stop": 20, "num": 10}}})
    frame = run_sweep(spec, tmp_path / "big", progress=False)
    assert len(frame) == 10_000 and not frame.duplicated(["run"]).any()
    assert (frame["gap"][frame["found"]] > -1e-6).all()


@pytest.mark.parametrize("path", sorted((REPO / "sweeps").glob("*.toml")), ids=lambda p: p.name)
def test_bundled_studies_are_valid_and_explain_themselves(path):
    spec = load_spec(path)
    assert spec.name == path.stem and len(spec.grid()) > 1
    assert path.read_text().startswith("#")  # a comment saying what the study asks


MULTI_HOST = textwrap.dedent("""
    import sys, jax
    jax.config.update("jax_cpu_collectives_implementation", "gloo")
    jax.distributed.initialize({address!r}, num_processes=2, process_id=int(sys.argv[1]))
    sys.path.insert(0, {tests!r})
    from test_sweep import tiny
    from jaxswarm.sweep import spec_from_dict, run_sweep
    run_sweep(spec_from_dict(tiny()), {out!r}, progress=False, log=print)
    print("processes", jax.process_count(), "devices", len(jax.devices()))
""")


@pytest.mark.slow
def test_two_processes_with_jax_distributed_give_identical_rows(finished, tmp_path):
    import socket
    with socket.socket() as probe:
        probe.bind(("localhost", 0))
        port = probe.getsockname()[1]
    _, _, frame = finished
    out = tmp_path / "multihost"
    script = MULTI_HOST.format(address=f"localhost:{port}", tests=str(REPO / "tests"),
                               out=str(out))
    env = dict(os.environ, XLA_FLAGS="--xla_force_host_platform_device_count=2")
    processes = [subprocess.Popen([sys.executable, "-c", script, str(i)], env=env, cwd=REPO,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                 for i in range(2)]
    outputs = [p.communicate(timeout=600) for p in processes]
    assert all(p.returncode == 0 for p in processes), outputs
    assert all("processes 2 devices 4" in stdout for stdout, _ in outputs)
    pd.testing.assert_frame_equal(read_results(out)[OUTCOME_COLUMNS], frame[OUTCOME_COLUMNS])


ONE_KEY = textwrap.dedent("""
    import sys
    from jaxswarm.runtime.cpu import configure
    configure(threads=int(sys.argv[1]), devices=int(sys.argv[2]))
    import jax
    from jaxswarm.sweep import spec_from_dict, run_sweep
    run_sweep(spec_from_dict({document!r}), sys.argv[3], progress=False, log=print)
    print("devices", len(jax.devices()))
""")
"""A sweep run in a process of its own, with the threads and devices its arguments name."""


def one_key_document(name: str) -> dict:
    """A sweep of ``name`` over 4 seeds in chunks of 4 (2 runs a device on 2 devices) at the
    shared size on the shared maze (the bees on plane map1), whose runs alone are the slow
    conformance checks' programs (iwd's, with drops that change the soil as they walk, the
    hooked walk's)."""
    on_plane = make(name).world is not jaxswarm.Graph
    config = sizes.CONFIG | ({"local_updates": "while_walking"} if name == "iwd" else {})
    return {"sweep": {"name": f"one_key_{name}", "algorithm": name, "seeds": 4,
                      "maps": [{"plane": "map1"}] if on_plane else [sizes.MAP],
                      "iterations": sizes.ITERATIONS, "chunk_size": 4},
            "config": config}


@pytest.mark.slow  # processes of their own at their own sizes
@pytest.mark.parametrize("name", registered())
def test_a_row_is_the_run_alone_on_any_thread_and_device_count_and_process(name, tmp_path):
    """Twins in the default tier: a row is its run alone in this process
    (test_rows_are_tidy_and_match_single_runs), and a batch of walks whose drops change the soil
    as they walk is each run alone (test_conformance.py's hooked walk)."""
    # iwd walks with drops that change the soil as they walk, the walker's hardest case.
    document = one_key_document(name)
    fingerprints = []
    # Each setting is a process of its own; the slow cases take only the one unlike the test's.
    settings = ((1, 1), (2, 2)) if name == "iwd" else ((2, 2),)
    for threads, devices in settings:
        out = tmp_path / f"{threads}-{devices}"
        done = subprocess.run(
            [sys.executable, "-c", ONE_KEY.format(document=document), str(threads),
             str(devices), str(out)], capture_output=True, text=True, timeout=600, cwd=REPO)
        assert done.returncode == 0, done.stderr
        assert f"devices {devices}" in done.stdout
        fingerprints.append(list(read_results(out)["fingerprint"]))
    spec = spec_from_dict(document)
    swarm = make(name, **spec.config)
    sweep_map = resolve(spec.maps[0])
    task = make_task(sweep_map.world, sweep_map.start, sweep_map.goal)
    alone = [hex_fingerprint(run_fingerprint(*run(
        swarm, jax.random.key(seed), sweep_map.world, task, swarm.default_params,
        iterations=spec.iterations))) for seed in spec.seeds]
    assert fingerprints == [alone] * len(settings)


def test_a_replayed_row_gives_the_stored_figures_bit_for_bit(finished, tmp_path, capsys):
    _, out, frame = finished
    for row in (0, 7, 23):
        replayed = replay_row(out, row)
        assert replayed.reproduced, replayed.differences
        assert replayed.figures["fingerprint"] == frame["fingerprint"][row]
    figure = tmp_path / "figures"
    assert cli.main(["replay", str(out), "13", "--out", str(figure)]) == 0
    assert "reproduced bit for bit" in capsys.readouterr().out
    assert (figure / "row13.png").is_file()


def test_a_replay_that_differs_says_which_figure_and_a_bad_row_is_named(finished, tmp_path):
    _, out, _ = finished
    copy = tmp_path / "tampered"
    shutil.copytree(out, copy)
    part = sorted((copy / "runs").glob("part-*.parquet"))[0]
    rows = pd.read_parquet(part)
    rows.loc[0, "moves"] += 1
    rows.to_parquet(part)
    replayed = replay_row(copy, 0)
    assert not replayed.reproduced and [d.split(":")[0] for d in replayed.differences] == ["moves"]
    with pytest.raises(ValueError, match="rows 0 to 23, not row 24"):
        replay_row(out, 24)
    with pytest.raises(ValueError, match="not a sweep store"):
        replay_row(tmp_path, 0)


@pytest.mark.slow  # about a minute
def test_twenty_random_rows_of_a_thousand_run_store_replay_bit_for_bit(tmp_path):
    spec = spec_from_dict({
        "sweep": {"name": "thousand", "algorithm": "aco_star", "maps": ["mosaic20"],
                  "seeds": 100, "iterations": 6, "chunk_size": 500},
        "config": {"num_agents": 16},
        "params": {"rho": {"start": 0.05, "stop": 0.5, "num": 10}}})
    frame = run_sweep(spec, tmp_path / "store", progress=False, log=lambda _: None)
    assert len(frame) == 1000
    for row in np.random.default_rng(0).choice(1000, 20, replace=False):
        replayed = replay_row(tmp_path / "store", int(row))
        assert replayed.reproduced, (row, replayed.differences)
