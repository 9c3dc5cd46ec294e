"""The reproduction of results/: what the table scripts share (jaxswarm.studies: provenance,
argument checks, timed runs, the success rule), every table script's provenance header at a tiny
size, the path-map table beside the Max-Min ACO paper's (sweeps/aco_pathmaps.py), the results
index, and the Makefile's reproduce targets."""
from __future__ import annotations

import argparse
import ast
import csv
import importlib.metadata
import json
import math
import os
import platform
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

import jax
import numpy as np
import pytest

from repo_scripts import ROOT, load_script

import jaxswarm.sweep
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import check_counts, names_argument, numbers_argument
from jaxswarm.studies.success import SUCCESS_GAP, at_optimum
from jaxswarm.studies.timing import compile_then_time, median_milliseconds, seed_keys
from jaxswarm.sweep.replay import replay_row

pathmaps = load_script("sweeps/aco_pathmaps.py")
robot_study = load_script("sweeps/robot_study.py")


def make_commands(target: str, *variables: str) -> list[list[str]]:
    """The script commands ``make -n TARGET`` would run (the venv set-up lines left out), each
    as [script, arguments...]."""
    if shutil.which("make") is None:
        pytest.skip("make is not installed")
    done = subprocess.run(["make", "-n", target, *variables], cwd=ROOT, capture_output=True,
                          text=True, check=True, timeout=60)
    commands = [shlex.split(line) for line in done.stdout.splitlines() if " sweeps/" in line]
    return [words[1:] for words in commands]  # without the interpreter


def out_folders(commands: list[list[str]]) -> list[str]:
    """The --out of each table command and the folder the last one (the index) is given."""
    *tables, index = commands
    assert index[0] == "sweeps/index_results.py"
    return [words[words.index("--out") + 1] for words in tables] + [index[1]]

TABLES = ["rfd_paper_table1", "rfd_static", "aco_pathmaps", "rfd_paper_dynamic", "robot_study",
          "iwd_paper_maps", "iwd_pg_experiments", "bees_tables", "bees_inverse", "exact_study",
          "mapf_study", "calibration"]
"""The folders of results/, in the order ``make reproduce`` writes them."""


def git_head() -> str | None:
    """HEAD of the repository, asked of git independently of the helper (None without one)."""
    try:
        return subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                              text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """``make reproduce-quick`` into a scratch folder, each command as make would run it (the
    tiny sizes of the Makefile's ``*_QUICK`` variables), once for every test that reads a table:
    ``(folder, {table: (script, arguments)}, {table: seconds measured here})``. About three
    minutes: the tests that read it are slow checks."""
    folder = tmp_path_factory.mktemp("results")
    commands = make_commands("reproduce-quick", f"QUICK_OUT={folder}")
    runs, seconds = {}, {}
    for script, *argv in commands:
        began = time.perf_counter()
        assert load_script(script).main(argv) == 0, script
        if script != "sweeps/index_results.py":
            name = Path(argv[argv.index("--out") + 1]).name
            runs[name] = (script, argv)
            seconds[name] = time.perf_counter() - began
    return folder, runs, seconds


def read_csv(path) -> list[dict]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def test_command_is_relative_to_the_root_and_quoted():
    script = str(ROOT / "sweeps" / "rfd_static.py")
    assert provenance.command(script, ["--maps", "maze20,alley20", "--out", "a b"]) == (
        "python sweeps/rfd_static.py --maps maze20,alley20 --out 'a b'")


def test_cpu_model_comes_from_cpuinfo(tmp_path):
    cpuinfo = tmp_path / "cpuinfo"
    cpuinfo.write_text("processor\t: 0\nvendor_id\t: Made Up\nmodel name\t: Test CPU 9000 @ 1GHz\n"
                       "processor\t: 1\nmodel name\t: Test CPU 9000 @ 1GHz\n")
    assert provenance.cpu_model(cpuinfo) == "Test CPU 9000 @ 1GHz"
    assert provenance.cpu_model(tmp_path / "missing") == (platform.processor() or "unknown")


@pytest.mark.parametrize("seconds, text", [
    (None, "unknown"), (0.4, "0 s"), (119, "119 s"), (750, "12.5 min"), (9000, "2.50 h")])
def test_format_seconds(seconds, text):
    assert provenance.format_seconds(seconds) == text


def test_versions_name_the_installed_packages():
    versions = provenance.versions()
    assert versions["jaxswarm"] == importlib.metadata.version("jaxswarm")
    assert (versions["jax"], versions["numpy"], versions["python"]) == (
        jax.__version__, np.__version__, platform.python_version())
    # The source tree's version is named only when it differs from the installed one.
    source = provenance.source_version()
    assert ("jaxswarm (pyproject.toml)" in versions) == (source != versions["jaxswarm"])


def test_git_state_names_the_checkout_commit():
    commit, dirty = provenance.git_state()
    if git_head() is None:
        assert (commit, dirty) == (None, None)
        return
    assert commit == git_head() and len(commit) == 40
    assert not any(path.startswith("results/") for path in dirty)  # the tables being written
    assert provenance.describe_tree([]) == "working tree clean"
    assert "2 paths differ" in provenance.describe_tree(["a.py", "b.py"])


@pytest.mark.slow  # the quick fixture runs the eleven table scripts: about three minutes
def test_every_table_starts_with_its_provenance(quick):
    folder, runs, seconds = quick
    commit = git_head()
    assert list(runs) == TABLES
    for name, (script, argv) in runs.items():
        text = (folder / name / "table.md").read_text(encoding="utf-8")
        record = json.loads((folder / name / "provenance.json").read_text(encoding="utf-8"))
        command = shlex.join(["python", script, *argv])
        assert record["command"] == command
        assert text.startswith(f"# {record['title']}\n\nGenerated by `{command}`"), name
        header = text.split("\n\n")[2]  # the provenance table, right under the command
        assert f"| commit | {commit or 'unknown'}" in header, name
        for package in ("jax", "jaxlib", "numpy", "python"):
            assert f"{package} {record['versions'][package]}" in header, (name, package)
        assert f"{os.cpu_count()} cores" in header
        assert record["commit"] == commit and record["started"] in text
        assert 0 < record["seconds"] <= seconds[name] + 1, name
        assert record["about"] and record["about"] in text


@pytest.mark.slow
def test_index_lists_every_table_in_the_order_they_ran(quick):
    folder, _, _ = quick
    text = (folder / "README.md").read_text(encoding="utf-8")
    sections = [line for line in text.splitlines() if line.startswith("## ")]
    assert [line.split("`")[1] for line in sections] == [f"{name}/" for name in TABLES]
    records = [provenance.load(folder / name) for name in TABLES]
    for record in records:
        assert f"* command: `{record['command']}`" in text
    total = sum(record["seconds"] for record in records)
    assert f"took {provenance.format_seconds(total)} in all" in text
    assert "except `rfd_graded`" in text


def test_index_of_a_folder_without_tables_is_an_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        provenance.main([str(tmp_path)])
    assert exit_info.value.code == 2
    assert "nothing to index" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


@pytest.mark.slow
def test_path_map_ratios_are_to_ant_system(quick):
    folder, _, _ = quick
    rows = read_csv(folder / "aco_pathmaps" / "results.csv")
    assert [(r["map"], r["algorithm"]) for r in rows] == [
        ("10x10", label) for label in pathmaps.ALGORITHMS]
    baseline = rows[0]
    for r in rows:
        optimum, minimum = float(r["optimum"]), float(r["min_length"])
        assert minimum >= optimum * (1 - 1e-6)
        assert float(r["min_ratio"]) == pytest.approx(minimum / optimum)
        assert int(r["found"]) <= int(r["runs"]) == 2
        for column, ours in (("min", "min_length"), ("mean", "mean_length"),
                             ("seconds", "mean_seconds")):
            assert float(r[f"{column}_vs_ant_system"]) == pytest.approx(
                float(r[ours]) / float(baseline[ours]))


@pytest.mark.slow
def test_robot_study_walks_every_row_to_the_goal_and_draws_it(quick):
    folder, _, _ = quick
    rows = read_csv(folder / "robot_study" / "runs.csv")
    labels = [row.label for row in robot_study.ROWS]
    assert [r["algorithm"] for r in rows] == labels
    for r in rows:
        # Two hidden blocks on the way: at least one re-plan, never shorter than full knowledge.
        assert r["reached"] == "True" and int(r["plans"]) >= 2
        assert float(r["travelled"]) >= float(r["optimum"]) * (1 - 1e-6)
        assert float(r["ratio"]) == pytest.approx(float(r["travelled"]) / float(r["optimum"]))
    table = (folder / "robot_study" / "table.md").read_text()
    assert all(f"| {label} | 1/1 |" in table for label in labels)
    assert "What keeping the pheromone buys" in table
    assert (folder / "robot_study" / "robot.gif").read_bytes()[:3] == b"GIF"
    assert (folder / "robot_study" / "walks.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.slow
def test_iwd_table_counts_fitness_calls_and_never_beats_the_optimum(quick):
    folder, _, _ = quick
    rows = read_csv(folder / "iwd_paper_maps" / "runs.csv")
    variants = ("paper", "while_walking", "backtrack", "hud20")  # every reading, in order
    assert [(r["map"], r["variant"], r["seed"]) for r in rows] == [
        ("maze20", variant, seed) for variant in variants for seed in ("0", "1")]
    for r in rows:
        assert float(r["cost"]) >= float(r["optimum"]) * (1 - 1e-6)
        # At most one fitness call per drop and iteration.
        assert 0 <= int(r["evaluations"]) <= 8 * int(r["iterations"])
        assert (r["found"] == "True") == (int(r["evaluations"]) > 0)
    table = (folder / "iwd_paper_maps" / "table.md").read_text()
    assert all(f"| maze20 | {variant} | 78.00 |" in table for variant in variants)


@pytest.mark.slow
def test_iwd_pg_experiment_compares_both_sides_with_the_same_seeds(quick):
    folder, _, _ = quick
    rows = read_csv(folder / "iwd_pg_experiments" / "runs.csv")
    assert [(r["experiment"], r["variant"], r["seed"]) for r in rows] == [
        ("1", "IWD + memory", "0"), ("1", "+ smoothing", "0")]
    for r in rows:
        assert float(r["optimum"]) == pytest.approx(29.2132, abs=1e-4)
        assert float(r["cost"]) >= float(r["optimum"]) * (1 - 1e-6)
        assert int(r["evaluations"]) <= 8 * int(r["iterations"])  # drops only: no operator
    table = (folder / "iwd_pg_experiments" / "table.md").read_text()
    assert "## 1. Smoothing" in table and "| + smoothing | 1 |" in table


@pytest.mark.slow
def test_bees_tables_put_both_variants_beside_the_paper_and_the_optimum(quick):
    folder, _, _ = quick
    rows = read_csv(folder / "bees_tables" / "runs.csv")
    assert [(r["variant"], r["cycles"]) for r in rows] == [
        (variant, cycles) for variant in ("cabc", "cabc, forbid_crossing")
        for cycles in ("0", "1", "2", "5", "8", "10")]
    for r in rows:
        assert (r["map"], (r["w1"], r["w2"], r["w3"])) == ("map1", ("1.0", "0.2", "0.03"))
        assert r["turn_unit"] == "degrees"
        assert float(r["optimum"]) == pytest.approx(63.3667, abs=1e-4)
        assert float(r["length"]) >= float(r["optimum"])  # inf when not reached
        assert (r["reached"] == "True") == math.isfinite(float(r["length"]))
        assert int(r["evaluations"]) >= 20 * int(r["steps"]) and float(r["seconds"]) > 0
        assert r["clipped"] == "False" or r["variant"] == "cabc"
    table = (folder / "bees_tables" / "table.md").read_text()
    # Table 6 read as (stdP, avgP, target): the paper's best is 2 cycles, as its text says.
    assert "| 0 | paper | 30 | 137 | 34 |" in table and "| 10 | cabc, forbid_crossing |" in table
    assert "the paper's 2 cycles (target 30, avgP 126; tied on target with 0 cycles" in table
    assert (folder / "bees_tables" / "map1.png").is_file()


@pytest.mark.slow
def test_the_inverse_problem_spends_equal_budgets_and_rescores_on_fresh_seeds(quick):
    folder, _, _ = quick
    landscape = read_csv(folder / "bees_inverse" / "landscape.csv")
    search = read_csv(folder / "bees_inverse" / "search.csv")
    fresh = read_csv(folder / "bees_inverse" / "fresh.csv")
    assert len(landscape) == len(search) == 2  # one seed each: equal budgets of runs
    for r in landscape + search + fresh:
        target, objective = int(r["target"]), float(r["objective"])
        if target:
            assert objective == pytest.approx(float(r["avg_length"]) / (1 + target), rel=1e-5)
        else:
            assert objective == pytest.approx(201 * 2 / math.sqrt(2), rel=1e-5)
    assert [(r["setting"], r["remember"], r["seeds"]) for r in fresh] == [
        (setting, remember, "1") for remember in ("False", "True")
        for setting in ("grid best", "optax best", "paper")]
    table = (folder / "bees_inverse" / "table.md").read_text()
    assert "w = (1.05, 0.2, 0.03), target 30/30, avgP 108" in table
    assert (folder / "bees_inverse" / "map1.png").is_file()


@pytest.mark.slow
def test_path_map_table_has_the_papers_values_beside_ours(quick):
    folder, _, _ = quick
    rows = {(r["map"], r["algorithm"]): r for r in read_csv(folder / "aco_pathmaps" /
                                                            "results.csv")}
    improved = rows["10x10", "Improved Max-Min ACO"]
    assert (float(improved["paper_min_length"]), float(improved["paper_mean_length"]),
            float(improved["paper_seconds"])) == (289.7, 297.9, 1.17)
    assert float(improved["paper_mean_vs_ant_system"]) == pytest.approx(297.9 / 352.3)
    assert float(improved["paper_seconds_vs_ant_system"]) == pytest.approx(1.17 / 14.6)
    lines = (folder / "aco_pathmaps" / "table.md").read_text(encoding="utf-8").splitlines()
    assert any(line.startswith("| Improved Max-Min ACO | paper | 289.7 | 297.9 | 0.825 | 0.846 |")
               for line in lines)
    assert any("compare ratios, not lengths" in line for line in lines)


def test_a_map_the_paper_did_not_run_has_no_paper_values():
    rows = [dict(map="4x3", algorithm=label, optimum=5.0, min_length=length, mean_length=length,
                 mean_seconds=seconds, min_ratio=length / 5, mean_ratio=length / 5, found=1,
                 runs=1, mean_populations=3.0)
            for label, length, seconds in zip(pathmaps.ALGORITHMS, (8.0, 6.0, math.inf),
                                              (2.0, 1.0, 0.5))]
    rows = pathmaps.add_ratios(rows)
    assert [r["mean_vs_ant_system"] for r in rows[:2]] == [1.0, 0.75]
    assert math.isnan(rows[2]["min_vs_ant_system"])  # no path found: no ratio
    assert rows[2]["seconds_vs_ant_system"] == 0.25
    assert {r["paper_mean_length"] for r in rows} == {r["paper_seconds_vs_ant_system"]
                                                      for r in rows} == {""}
    lines = pathmaps.map_table(rows)
    assert "| Max-Min ACO | paper |" + " - |" * 10 in lines
    assert lines[lines.index("| Max-Min ACO | paper |" + " - |" * 10) + 1].startswith(
        "| Improved Max-Min ACO | ours | n/a | n/a | n/a | n/a |")


def test_paper_values_cover_the_papers_three_maps_and_algorithms():
    assert list(pathmaps.PAPER_TABLE1) == ["10x10", "20x20", "40x25"]
    for values in pathmaps.PAPER_TABLE1.values():
        assert list(values) == list(pathmaps.ALGORITHMS)
        assert all(len(v) == 3 and min(v) > 0 for v in values.values())


def test_bad_sizes_are_an_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        pathmaps.main(["--sizes", "10x10,20by20", "--out", str(tmp_path)])
    assert exit_info.value.code == 2
    assert "expected WIDTHxHEIGHT, got '20by20'" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())


def test_a_script_run_from_the_root_finds_the_helper(tmp_path):
    # python sweeps/NAME.py: the way make reproduce runs them (sweeps/ first on sys.path).
    done = subprocess.run([sys.executable, "sweeps/exact_study.py", "--sizes", "10",
                           "--grids", "1", "--out", str(tmp_path)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    record = provenance.load(tmp_path)
    assert record["command"] == shlex.join(["python", "sweeps/exact_study.py", "--sizes", "10",
                                            "--grids", "1", "--out", str(tmp_path)])


def test_reproduce_writes_results_and_the_quick_target_never_does():
    full, quick = make_commands("reproduce"), make_commands("reproduce-quick")
    assert [words[0] for words in full] == [words[0] for words in quick]
    assert out_folders(full) == [*(f"results/{name}" for name in TABLES), "results"]
    assert out_folders(quick) == [*(f"out/reproduce-quick/{name}" for name in TABLES),
                                  "out/reproduce-quick"]
    # The full target spells out the paper-size arguments it runs.
    assert full[0][1:full[0].index("--out")] == ["--maps", "all", "--seeds", "20",
                                                 "--iterations", "100", "--agents", "256"]


@pytest.mark.slow
def test_the_quick_target_writes_every_table_and_the_index(quick):
    folder, _, seconds = quick
    assert sorted(p.name for p in folder.iterdir()) == sorted([*TABLES, "README.md"])
    for name in TABLES:
        assert 0 < provenance.load(folder / name)["seconds"] <= seconds[name] + 1
        assert (folder / name / "table.md").read_text(encoding="utf-8").startswith("# ")


def test_no_function_of_a_script_is_longer_than_60_lines():
    long = []
    for script in sorted((ROOT / "sweeps").glob("*.py")):
        for node in ast.walk(ast.parse(script.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                lines = node.end_lineno - node.lineno + 1
                if lines > 60:
                    long.append(f"{script.name}:{node.lineno} {node.name}: {lines} lines")
    assert not long, "\n".join(long)


def test_scripts_reach_the_package_without_editing_sys_path():
    for script in sorted((ROOT / "sweeps").glob("*.py")):
        assert "sys.path" not in script.read_text(encoding="utf-8"), script.name


def test_a_count_below_one_stops_the_script_naming_the_option(capsys):
    parser = argparse.ArgumentParser()
    parser.add_argument("--max-plans", type=int)
    with pytest.raises(SystemExit) as exit_info:
        check_counts(parser, parser.parse_args(["--max-plans", "0"]), "max_plans")
    assert exit_info.value.code == 2
    assert "--max-plans must be at least 1, got 0" in capsys.readouterr().err


def test_number_lists_are_sorted_once_each_and_checked():
    numbers = numbers_argument(range(1, 8))
    assert numbers("4,1,4") == [1, 4]
    for bad in ("0", "1,8", "1,x", ""):
        with pytest.raises(argparse.ArgumentTypeError, match="expected numbers from 1, 2, "):
            numbers(bad)


def test_name_lists_keep_their_order_and_name_the_unknown():
    names = names_argument(("map1", "map2", "map3"))
    assert names("all") == ("map1", "map2", "map3")
    assert names("map3, map1,map3") == ("map3", "map1")
    with pytest.raises(argparse.ArgumentTypeError, match="unknown map9; choose from all or map1"):
        names("map1,map9")
    with pytest.raises(argparse.ArgumentTypeError, match="no name given"):
        names(",")


def test_success_is_the_sweeps_rule():
    assert SUCCESS_GAP is jaxswarm.sweep.SUCCESS_GAP
    assert at_optimum(10 * (1 + SUCCESS_GAP / 2), 10.0)
    assert not at_optimum(10 * (1 + 2 * SUCCESS_GAP), 10.0)
    assert not at_optimum(math.inf, 10.0)


def test_the_first_input_runs_once_more_to_compile_and_every_run_is_timed():
    calls = []

    def double(value):
        calls.append(value)
        return 2 * value

    timed = compile_then_time(double, [3, 5])
    assert [result for result, _ in timed] == [6, 10] and calls == [3, 3, 5]
    assert all(seconds >= 0 for _, seconds in timed)
    assert median_milliseconds([0.001, 0.003, 0.002]) == pytest.approx(2.0)


def test_seed_keys_split_the_seed_key():
    assert (jax.random.key_data(seed_keys(3, seed=7))
            == jax.random.key_data(jax.random.split(jax.random.key(7), 3))).all()


@pytest.mark.slow
@pytest.mark.parametrize("table", ["rfd_paper_table1", "rfd_static", "iwd_paper_maps"])
def test_a_tables_swarm_rows_replay_alone_bit_for_bit(quick, table):
    folder, _, _ = quick
    rows = read_csv(folder / table / "runs.csv")
    replayable = [index for index, row in enumerate(rows) if row["run_record"]]
    assert replayable, f"{table}: no row has a run record"
    for index in {replayable[0], replayable[-1]}:
        replayed = replay_row(folder / table, index)
        assert replayed.reproduced, (table, index, replayed.differences)


@pytest.mark.slow
def test_iwd_pg_rows_on_its_own_fields_say_they_cannot_be_replayed(quick):
    folder, _, _ = quick
    fields = load_script("sweeps/iwd_pg_experiments.py").IWD_PG_MAPS
    rows = read_csv(folder / "iwd_pg_experiments" / "runs.csv")
    assert rows and all((row["run_record"] == "") == (row["map"] in fields) for row in rows)
    first = next(index for index, row in enumerate(rows) if row["map"] in fields)
    with pytest.raises(ValueError, match="no run record"):
        replay_row(folder / "iwd_pg_experiments", first)


@pytest.mark.slow  # a 256-drop program compiled (20-30 s cold), then one run of 100 iterations
def test_a_committed_table_row_replays_bit_for_bit():
    # results/rfd_static was made with this release's arithmetic (SAME_RESULTS_SINCE): a row of
    # it runs again alone to the same cost and fingerprint.
    rows = read_csv(ROOT / "results" / "rfd_static" / "runs.csv")
    row = next(index for index, row in enumerate(rows)
               if (row["map"], row["algorithm"], row["seed"]) == ("maze20", "rfd_star", "3"))
    replayed = replay_row(ROOT / "results" / "rfd_static", row)
    assert replayed.reproduced, replayed.differences


@pytest.mark.slow  # the same row's program on the lanes, in a process of its own (the walker's
# implementation is read when a program is traced)
def test_a_committed_table_row_replays_bit_for_bit_on_the_lanes(tmp_path):
    rows = read_csv(ROOT / "results" / "rfd_static" / "runs.csv")
    row = next(index for index, row in enumerate(rows)
               if (row["map"], row["algorithm"], row["seed"]) == ("maze20", "rfd_star", "3"))
    done = subprocess.run(
        [sys.executable, "-m", "jaxswarm.cli", "replay", str(ROOT / "results" / "rfd_static"),
         str(row), "--walker", "lanes", "--out", str(tmp_path)],
        capture_output=True, text=True, check=False, cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "(walker: lanes)" in done.stdout and "reproduced bit for bit" in done.stdout
