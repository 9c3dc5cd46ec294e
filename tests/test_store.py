"""Stores that know what they hold: a resume after a map file changed, a stray file in runs/,
a second writer, a tuner's batch of other values, a metadata.json that is not JSON. Every
refusal here comes before any run: the stores are made without running a swarm (the runs are
stubbed), so the file compiles no program."""
import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest
import sizes

from jaxswarm import cli
from jaxswarm.sweep import StoreMismatchError, read_results, run_sweep, runner
from jaxswarm.maps.entry import ResolvedMap
from jaxswarm.sweep.spec import spec_from_dict
from jaxswarm.sweep.store import SAME_RESULTS_SINCE, ResultsStore
from jaxswarm.swarm import registered
from jaxswarm.tune import tune_spec_from_dict
from jaxswarm.tune.evaluate import Evaluator, Setting, StoreConflictError

ROOT = Path(__file__).resolve().parents[1]
SWARM = {"name": "rfd_star", "config": {}, "default_params": {}}
"""A swarm definition for stores opened directly (only its name is read)."""


def _movingai(folder, obstacle=(2, 0)):
    """A 20 x 20 Moving AI map (the shared shape), open but for one obstacle at ``obstacle``
    (x, y), with a scenario from (0, 0) to (2, 1)."""
    rows = [["."] * 20 for _ in range(20)]
    rows[obstacle[1]][obstacle[0]] = "@"
    (folder / "tiny.map").write_text("type octile\nheight 20\nwidth 20\nmap\n"
                                     + "\n".join("".join(row) for row in rows) + "\n")
    (folder / "tiny-even-1.scen").write_text(
        "version 1\n0\ttiny.map\t20\t20\t0\t0\t2\t1\t2.41421356\n")
    return folder / "tiny.map"


def _sweep(maps):
    """A sweep of one run per map at the shared size."""
    return spec_from_dict({
        "sweep": {"name": "store", "algorithm": "rfd_star", "maps": maps, "seeds": 1,
                  "iterations": sizes.ITERATIONS, "chunk_size": 5},
        "config": dict(sizes.CONFIG), "params": {"p_base": [5.0], "alpha": [2.0]}})


def _tune(training_maps):
    """A tune of RFD*'s alpha on ``training_maps``, held out on a paper map."""
    return tune_spec_from_dict({
        "tune": {"name": "store", "algorithm": "rfd_star", "method": "random", "budget": 4,
                 "objective": "gap", "iterations": sizes.ITERATIONS, "seed": 3,
                 "training": {"maps": training_maps, "seeds": 2},
                 "held_out": {"maps": ["alley20"], "seeds": [100]}},
        "config": dict(sizes.CONFIG), "params": {"alpha": {"low": 1.0, "high": 100.0}}})


@pytest.fixture
def no_runs(monkeypatch):
    """Sweeps and tunes that run nothing: a sweep's map writes a stand-in row per chunk, and a
    map's optimum is not measured."""
    def stand_in(chunks, map_index, sweep_map, todo, bar, pace):
        for chunk in todo:
            chunks.store.write_chunk(map_index, chunk, {"map": [sweep_map.label],
                                                        "map_index": [map_index], "run": [0]})

    monkeypatch.setattr(runner, "_run_map", stand_in)
    monkeypatch.setattr(ResolvedMap, "optimum", lambda self: 3.0)


def test_a_sweep_refuses_to_resume_after_its_map_file_changed(tmp_path, monkeypatch, no_runs):
    map_file = _movingai(tmp_path)
    monkeypatch.setenv("JAXSWARM_MOVINGAI", str(tmp_path))
    spec = _sweep(["mosaic20", {"movingai": "tiny.map", "scenario": 0}])
    out = tmp_path / "out"
    assert list(run_sweep(spec, out, progress=False, log=lambda _: None)["map"]) == [
        "mosaic20", "tiny#0"]
    _movingai(tmp_path, obstacle=(5, 5))  # the same name, another map
    with pytest.raises(StoreMismatchError, match=re.escape(f"{map_file} changed since {out}")):
        run_sweep(spec, out, progress=False, log=lambda _: None)
    _movingai(tmp_path)  # the file as the store's rows were computed on: resumed
    assert len(run_sweep(spec, out, progress=False, log=lambda _: None)) == 2
    recorded = json.loads((out / "metadata.json").read_text())["depends_on"]
    assert set(recorded) == {"sweep.maps[1].map", "sweep.maps[1].scenario"}
    assert recorded["sweep.maps[1].map"]["sha256"] == hashlib.sha256(
        map_file.read_bytes()).hexdigest()


def test_a_tune_refuses_to_resume_after_its_map_file_changed(tmp_path, monkeypatch, no_runs):
    map_file = _movingai(tmp_path)
    monkeypatch.setenv("JAXSWARM_MOVINGAI", str(tmp_path))
    spec = _tune(["maze20", {"movingai": "tiny.map", "scenario": 0}])
    Evaluator(spec, tmp_path / "out")
    (tmp_path / "tiny-even-1.scen").write_text(
        "version 1\n0\ttiny.map\t20\t20\t0\t0\t3\t1\t3.41421356\n")
    with pytest.raises(StoreMismatchError, match=re.escape(
            f"{map_file.with_name('tiny-even-1.scen')} changed since")):
        Evaluator(spec, tmp_path / "out")


def test_a_tune_refuses_a_store_of_another_tuner(tmp_path, no_runs):
    spec = _tune(["maze20"])
    out = tmp_path / "out"
    Evaluator(spec, out)
    metadata = json.loads((out / "metadata.json").read_text())
    metadata.setdefault("depends_on", {})["tuner"] = dict(version=1,
                                                          sampler="MT19937 of numpy 1.0")
    (out / "metadata.json").write_text(json.dumps(metadata))
    with pytest.raises(StoreMismatchError, match="depend on tuner = .*MT19937"):
        Evaluator(spec, out)
    Evaluator(spec, tmp_path / "fresh")
    tuner = json.loads((tmp_path / "fresh" / "metadata.json").read_text())["depends_on"]["tuner"]
    assert tuner["version"] >= 1 and tuner["sampler"].startswith("PCG64 of numpy ")


def test_a_stored_batch_of_other_param_values_is_refused(tmp_path, no_runs):
    spec = _tune(["maze20"])
    evaluator = Evaluator(spec, tmp_path / "out")
    settings = [Setting(0, {"alpha": 10.0}), Setting(1, {"alpha": 20.0})]
    instances = [(0, 0), (0, 1)]
    # The batch a tuner of another sampler stored: the same numbers, seeds and phase.
    evaluator.store.write_chunk(0, 0, {
        "batch": [0] * 4, "phase": ["training"] * 4, "iteration": [0] * 4,
        "setting": [0, 0, 1, 1], "param.alpha": [10.0, 10.0, 35.0, 35.0],
        "instance": [0, 1, 0, 1], "seed": [0, 1, 0, 1], "loss": [0.0] * 4})
    with pytest.raises(StoreConflictError, match=r"part-000-00000.parquet holds another batch "
                                                 r".*differs in: param.alpha"):
        evaluator.rows(settings, instances)


def test_a_stray_file_in_runs_is_refused_by_the_store_and_its_reader(tmp_path):
    ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM}).write_chunk(
        0, 0, {"map_index": [0, 0], "run": [0, 1], "cost": [1.0, 2.0]})
    stray = tmp_path / "runs" / "notes.parquet"
    pd.DataFrame({"other": [1, 2]}).to_parquet(stray)
    with pytest.raises(StoreMismatchError, match=re.escape(f"{stray}: not a chunk of the store")):
        ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM})
    with pytest.raises(StoreMismatchError, match=re.escape(f"{stray}: not a chunk")):
        read_results(tmp_path)
    stray.unlink()
    assert len(read_results(tmp_path)) == 2


def test_chunks_without_metadata_are_refused(tmp_path):
    ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM}).write_chunk(0, 0, {"run": [0]})
    (tmp_path / "metadata.json").unlink()
    with pytest.raises(StoreMismatchError, match="holds chunks but .*metadata.json is missing"):
        ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM})
    assert not (tmp_path / "metadata.json").exists()


def test_every_registered_swarm_has_the_release_since_which_its_results_are_the_same():
    assert set(SAME_RESULTS_SINCE) == set(registered())


@pytest.mark.parametrize("written_by, swarm, message", [
    ("0.6.0", SWARM, r"written by jaxswarm 0\.6\.0; 'rfd_star' gives the same results since "
                     r"jaxswarm 0\.7\.0 \(CHANGELOG\.md says what changed\)"),
    ("0.7.1", dict(SWARM, name="rfd"), r"written by jaxswarm 0\.7\.1; 'rfd' gives the same "
                                       r"results since jaxswarm 0\.8\.0 \(CHANGELOG\.md"),
    ("0.1.0", None, r"written by jaxswarm 0\.1\.0, which did not record the definition of "
                    r"'rfd_star'; 'rfd_star' gives the same results since jaxswarm 0\.7\.0 "
                    r"\(CHANGELOG\.md"),
    (None, dict(SWARM, name="rfd_flat"), r"no release is known since which 'rfd_flat' gives the "
                                         r"same results"),
], ids=["older release", "older than its swarm's", "no definition", "unlisted swarm"])
def test_a_store_of_a_release_before_its_swarms_results_is_refused(tmp_path, written_by, swarm,
                                                                     message):
    """The release that wrote the store and the one since which the swarm gives the same results
    (the same definition as recorded: the release alone refuses it); nothing is written."""
    today = swarm or SWARM
    ResultsStore(tmp_path, {"sweep": 1}, {"swarm": today}).write_chunk(0, 0, {"run": [0]})
    metadata = json.loads((tmp_path / "metadata.json").read_text())
    metadata.update(jaxswarm=written_by, swarm=swarm)
    (tmp_path / "metadata.json").write_text(json.dumps(metadata))
    before = sorted(tmp_path.rglob("*"))
    with pytest.raises(StoreMismatchError, match=message):
        ResultsStore(tmp_path, {"sweep": 1}, {"swarm": today})
    assert sorted(tmp_path.rglob("*")) == before


HOLDER = textwrap.dedent("""
    import os, sys
    from jaxswarm.sweep.store import ResultsStore
    store = ResultsStore(sys.argv[1], {"sweep": 1}, {"swarm": %r})
    writing = store.runs / f".part-000-00000.parquet.{os.getpid()}.0123456789ab.tmp"
    writing.write_text("half a chunk")
    print("writing", flush=True)
    sys.stdin.read()
""" % SWARM)


def test_one_writer_at_a_time_and_a_dead_writers_lock_and_files_are_recovered(tmp_path):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    holder = subprocess.Popen([sys.executable, "-c", HOLDER, str(tmp_path)], env=env,
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline() == "writing\n"
        writing = tmp_path / "runs" / f".part-000-00000.parquet.{holder.pid}.0123456789ab.tmp"
        with pytest.raises(ValueError, match=re.escape(f"{tmp_path} is being written by another "
                                                       f"process (pid {holder.pid} on ")):
            ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM})
        ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM}, writer=False)  # a reader
        assert writing.read_text() == "half a chunk"  # a live writer's file is left alone
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
        holder.stdout.close()
        holder.stdin.close()
    store = ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM})  # its lock died with it
    assert not writing.exists()  # and its half-written chunk is gone
    assert json.loads((tmp_path / ".lock").read_text())["pid"] == os.getpid()
    # The same process may open its store again (a resume while a traceback keeps the first).
    ResultsStore(tmp_path, {"sweep": 1}, {"swarm": SWARM})
    assert store.root == tmp_path


def test_garbage_metadata_is_named_by_the_cli_with_its_path(tmp_path, capsys):
    out = tmp_path / "out"
    (out / "runs").mkdir(parents=True)
    (out / "metadata.json").write_text('{"spec": oops}')
    spec = tmp_path / "study.toml"
    spec.write_text(textwrap.dedent(f"""
        [sweep]
        name = "study"
        algorithm = "rfd_star"
        maps = ["mosaic20"]
        seeds = 1
        iterations = {sizes.ITERATIONS}
        [config]
        num_agents = {sizes.AGENTS}
        [params]
        alpha = [2.0]
    """))
    with pytest.raises(SystemExit) as exited:
        cli.main(["sweep", str(spec), "--out", str(out), "--no-progress"])
    assert exited.value.code == 2
    assert f"{out / 'metadata.json'}: line 1 column 10: not valid JSON" in (
        capsys.readouterr().err)
