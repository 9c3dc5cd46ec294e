"""The MAPF study script (sweeps/mapf_study.py) at a tiny size: its files, and the properties its
tables rely on (every planner present, ratios at least 1 against an independent lower bound,
CBS never beaten, the summaries are the rows'), and what it does with a crash or a bad plan."""
from __future__ import annotations

import csv
import time
from collections import defaultdict, deque
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest

from jaxswarm.maps.movingai import read_map
from jaxswarm.multiagent import Plan, load_instance, pack, pibt, prioritized, registry
from jaxswarm.world.paths import as_node
from repo_scripts import load_script

study = load_script("sweeps/mapf_study.py")

MAPS = ("random-32-32-10", "room-32-32-4")
AGENTS = 5
ARGV = ["--maps", ",".join(MAPS), "--scenarios", "random", "--agents", str(AGENTS), "--seeds",
        "1", "--time-limit", "5"]
SETS = tuple(f"{name} (random)" for name in MAPS)


def _read_csv(path):
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        return reader.fieldnames, list(reader)


@pytest.fixture(scope="module")
def outputs(tmp_path_factory, movingai_dir):
    out = tmp_path_factory.mktemp("mapf_study")
    assert study.main([*ARGV, "--out", str(out)]) == 0
    columns, runs = _read_csv(out / "runs.csv")
    summary_columns, summary = _read_csv(out / "summary.csv")
    return {"dir": out, "columns": columns, "runs": runs, "summary_columns": summary_columns,
            "summary": summary, "data": movingai_dir / "mapf"}


def _bfs_lower_bound(map_path: Path, scen_path: Path, agents: int) -> int:
    """Sum of the first ``agents`` scenario rows' 4-connected distances: a breadth-first search
    per row on the map's obstacle grid, with the .scen columns read here (not by the library)."""
    blocked = np.asarray(read_map(map_path), bool)  # [height, width], True = obstacle
    height, width = blocked.shape
    total = 0
    rows = [line.split("\t") for line in scen_path.read_text().splitlines()[1:agents + 1]]
    for row in rows:
        start, goal = (int(row[4]), int(row[5])), (int(row[6]), int(row[7]))
        seen = {start: 0}
        queue = deque([start])
        while queue:
            x, y = queue.popleft()
            for nx, ny in ((x + 1, y), (x - 1, y), (x, y + 1), (x, y - 1)):
                if (0 <= nx < width and 0 <= ny < height and not blocked[ny, nx]
                        and (nx, ny) not in seen):
                    seen[nx, ny] = seen[x, y] + 1
                    queue.append((nx, ny))
        total += seen[goal]
    return total


def test_runs_csv_has_every_planner_on_every_instance(outputs):
    assert tuple(outputs["columns"]) == study.RUN_COLUMNS
    keys = [(r["map"], r["scenario"], int(r["agents"]), r["planner"], r["seed"])
            for r in outputs["runs"]]
    assert keys == [(m, "random", AGENTS, p, "0" if p == study.RANDOM else "")
                    for m in MAPS for p in study.PLANNERS]  # pymapf is a test extra
    for row in outputs["runs"]:
        assert float(row["seconds"]) > 0 and row["error"] == "False", row


def test_solved_rows_have_ratios_of_at_least_one_against_an_independent_bound(outputs):
    bounds = {m: _bfs_lower_bound(outputs["data"] / f"{m}.map",
                                  outputs["data"] / f"{m}-random-1.scen", AGENTS) for m in MAPS}
    for row in outputs["runs"]:
        assert int(row["lower_bound"]) == bounds[row["map"]], row
        if row["solved"] == "True":
            soc, makespan = int(row["sum_of_costs"]), int(row["makespan"])
            assert float(row["ratio"]) == pytest.approx(soc / int(row["lower_bound"]))
            assert float(row["ratio"]) >= 1.0 and row["reason"] == ""
            assert soc / AGENTS <= makespan <= soc
        else:  # not solved: the planner's reason, no costs
            assert row["reason"] and row["sum_of_costs"] == row["ratio"] == "", row


def test_cbs_solves_five_agents_no_planner_beats_it_and_pymapf_agrees(outputs):
    by_instance = defaultdict(list)
    for row in outputs["runs"]:
        by_instance[row["map"]].append(row)
    for map_name, rows in by_instance.items():
        optimal = {r["planner"]: r for r in rows
                   if r["planner"] in (*study.OPTIMAL, "pymapf cbs")}
        assert all(r["solved"] == "True" for r in optimal.values()), optimal
        # pymapf's CBS, an implementation we did not write, finds the same optimum.
        assert len({r["sum_of_costs"] for r in optimal.values()}) == 1
        for row in rows:
            if row["solved"] == "True":
                assert int(optimal["cbs"]["sum_of_costs"]) <= int(row["sum_of_costs"]), row


def test_rows_are_the_planners_answers(outputs):
    # The recorded sum of costs of a deterministic row is what the planner gives on its own.
    for row in outputs["runs"]:
        if row["planner"] == "prioritized (distance)":
            data = outputs["data"]
            instance = load_instance(data / f"{row['map']}.map",
                                     data / f"{row['map']}-random-1.scen", AGENTS)
            plan = prioritized(instance.graph, instance.starts, instance.goals, order="distance")
            assert str(plan.solved) == row["solved"]
            assert plan.sum_of_costs == int(row["sum_of_costs"])


def test_summary_is_the_rows_over_all_maps_then_per_map(outputs):
    assert tuple(outputs["summary_columns"]) == study.SUMMARY_COLUMNS
    summary = outputs["summary"]
    assert [(e["map"], e["planner"]) for e in summary] == [
        (m, p) for m in (study.ALL_MAPS, *SETS) for p in study.PLANNERS]
    for entry in summary:
        group = [r for r in outputs["runs"] if r["planner"] == entry["planner"]
                 and entry["map"] in (study.ALL_MAPS, f"{r['map']} (random)")]
        solved = [r for r in group if r["solved"] == "True"]
        assert int(entry["runs"]) == len(group) and int(entry["solved"]) == len(solved)
        assert float(entry["success_rate"]) == pytest.approx(len(solved) / len(group))
        if solved:
            assert float(entry["mean_ratio"]) == pytest.approx(
                np.mean([float(r["ratio"]) for r in solved]))
            assert float(entry["mean_makespan"]) == pytest.approx(
                np.mean([int(r["makespan"]) for r in solved]))
        assert float(entry["median_seconds"]) == pytest.approx(
            np.median([float(r["seconds"]) for r in group]))
        assert int(entry["errors"]) == 0


def test_markdown_is_both_summaries_under_the_provenance(outputs):
    text = (outputs["dir"] / "table.md").read_text(encoding="utf-8")
    assert text.startswith(f"# {study.TITLE}\n\nGenerated by `python sweeps/mapf_study.py "
                           f"{' '.join(ARGV)} --out {outputs['dir']}`")
    assert "| commit |" in text and study.ABOUT in text
    assert "## Over all maps" in text and "## Per map" in text
    assert "## Published LaCAM figures beside ours" in text and "about 0.031 s" in text
    assert "Runs that raised" not in text
    for entry in outputs["summary"]:
        label = study.LABELS[entry["planner"]]
        cells = (f"| {label} | {entry['solved']}/{entry['runs']} | "
                 f"{100 * float(entry['success_rate']):.0f}% |")
        line = (f"| {AGENTS} {cells}" if entry["map"] == study.ALL_MAPS
                else f"| {entry['map']} | {AGENTS} {cells}")
        assert line in text, line


def test_figure_is_a_readable_png_and_no_temporary_files_are_left(outputs):
    figure = outputs["dir"] / "mapf_study.png"
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    height, width, _ = matplotlib.image.imread(figure).shape
    assert width > 2 * height  # three panels side by side
    assert sorted(p.name for p in outputs["dir"].iterdir()) == [
        "mapf_study.png", "provenance.json", "runs.csv", "summary.csv", "table.md"]
    # Every row has its own marker (zip would drop the rows beyond the markers).
    assert len(set(study.MARKERS)) >= len(study.PLANNERS) <= len(study.STYLES)


def test_a_study_in_parts_resumes_to_the_rows_of_one_run(outputs, tmp_path):
    # Two parts side by side (a planner each on one map, then the rest on the other), joined
    # by a third that resumes from both: every run once, the kept ones untouched.
    one, two, joined = (tmp_path / name for name in ("one", "two", "joined"))
    argv = ["--scenarios", "random", "--agents", str(AGENTS), "--seeds", "1", "--time-limit",
            "5", "--no-pymapf"]
    assert study.main([*argv, "--maps", MAPS[0], "--planners", "pibt", "--out", str(one)]) == 0
    assert study.main([*argv, "--maps", MAPS[1], "--out", str(two)]) == 0
    kept = study.read_runs(one / "runs.csv") + study.read_runs(two / "runs.csv")
    assert study.main([*argv, "--maps", ",".join(MAPS), "--resume", str(one), str(two),
                       "--out", str(joined)]) == 0
    rows = study.read_runs(joined / "runs.csv")
    keys = [study.run_key(row) for row in rows]
    assert len(keys) == len(set(keys)) == 2 * (len(study.PLANNERS) - 2)
    assert keys == [study.run_key(row) for row in study.read_runs(outputs["dir"] / "runs.csv")
                    if not row["planner"].startswith("pymapf")]
    by_key = {study.run_key(row): row for row in rows}
    assert all(by_key[study.run_key(row)] == row for row in kept)  # kept, not run again
    assert "runs (" in (joined / "table.md").read_text()
    # Resuming a finished study runs nothing new and changes no row.
    assert study.main([*argv, "--maps", ",".join(MAPS), "--resume", "--out", str(joined)]) == 0
    assert study.read_runs(joined / "runs.csv") == rows


def test_resuming_loads_no_instance_whose_runs_are_all_kept_or_capped(outputs, tmp_path,
                                                                        monkeypatch):
    # The rows above a planner's cap do not exist; they must not make a resume load the map and
    # warm up (minutes for the report's distance fields on a 256 x 256 map).
    monkeypatch.setitem(study.MAX_AGENTS, "lacam", AGENTS - 1)
    argv = [*ARGV, "--no-pymapf", "--out", str(tmp_path)]
    assert study.main([*argv, "--planners", "pibt,lacam"]) == 0
    monkeypatch.setattr(study, "load_instance", None)  # any load would raise
    assert study.main([*argv, "--planners", "pibt,lacam", "--resume"]) == 0
    assert {row["planner"] for row in study.read_runs(tmp_path / "runs.csv")} == {"pibt"}


def test_read_runs_types_the_rows_as_the_study_makes_them(outputs):
    rows = study.read_runs(outputs["dir"] / "runs.csv")
    assert [study.run_key(row) for row in rows] == [
        (r["map"], r["scenario"], int(r["agents"]), r["planner"], int(r["seed"]) if r["seed"]
         else "") for r in outputs["runs"]]
    assert all(isinstance(row["solved"], bool) and isinstance(row["seconds"], float)
               for row in rows)
    # The summary of the rows read back is the one written from the rows made.
    assert [{key: str(value) for key, value in entry.items()}
            for entry in study.summarise(rows)] == outputs["summary"]


@pytest.mark.parametrize("make, message", [
    (lambda folder: None, "--resume: no "),
    (lambda folder: (folder / "runs.csv").write_text("map,agents\nx,3\n"), "are not this "
                                                                              "study's"),
])
def test_a_resume_from_a_missing_or_foreign_runs_csv_is_an_error(make, message, tmp_path,
                                                                 capsys, movingai_dir):
    folder = tmp_path / "earlier"
    folder.mkdir()
    make(folder)
    with pytest.raises(SystemExit) as exit_info:
        study.main(["--maps", "empty-32-32", "--resume", str(folder), "--out",
                    str(tmp_path / "out")])
    assert exit_info.value.code == 2 and message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_run_in_two_resumed_folders_is_an_error(outputs, tmp_path, capsys):
    with pytest.raises(SystemExit):
        study.main(["--maps", MAPS[0], "--resume", str(outputs["dir"]), str(outputs["dir"]),
                    "--out", str(tmp_path / "out")])
    assert "is in both" in capsys.readouterr().err


WHERE = dict(map="empty-32-32", scenario="random", agents=3)


@pytest.fixture(scope="module")
def instance(movingai_dir):
    data = movingai_dir / "mapf"
    return load_instance(data / "empty-32-32.map", data / "empty-32-32-random-1.scen", 3)


def test_a_planner_that_raises_is_recorded_and_the_study_goes_on(instance, monkeypatch):
    def broken(graph, starts, goals, **options):
        raise IndexError("list index out of range")

    monkeypatch.setitem(registry.REGISTRY, "report",
                        registry.entry("report")._replace(plan=broken))
    monkeypatch.setattr(study, "warm_up", lambda instance: None)
    rows = study.run_instance(instance, WHERE, study.planner_calls(1, 5, 1.2, False), 5)
    report = rows[0]
    assert (report["planner"], report["solved"], report["error"]) == ("report", False, True)
    assert report["reason"] == "raised IndexError: list index out of range"
    assert all(r["solved"] and not r["error"] for r in rows[1:])
    summary = study.summarise(rows)
    planners = len({row["planner"] for row in rows})
    assert [e["errors"] for e in summary if e["map"] == study.ALL_MAPS] == [1] + [0] * (
        planners - 1)
    assert "## Runs that raised\n\n1 runs raised" in study.summary_markdown(summary, rows)


def test_an_invalid_solved_plan_raises(instance, monkeypatch):
    def teleport(graph, starts, goals, **options):
        # "Solved" by jumping from start to goal in one step: moves along no edge.
        nodes = [[as_node(graph, s), as_node(graph, g)] for s, g in zip(starts, goals)]
        return Plan(*pack(nodes), solved=True, planner="prioritized")

    monkeypatch.setitem(registry.REGISTRY, "prioritized",
                        registry.entry("prioritized")._replace(plan=teleport))
    monkeypatch.setattr(study, "warm_up", lambda instance: None)
    with pytest.raises(study.InvalidPlan, match="prioritized \\(given\\) on empty-32-32 .*"
                                                "violations: agent 0 jumps"):
        study.run_instance(instance, WHERE, study.planner_calls(1, 5, 1.2, False), 5)


def test_a_plan_beating_cbs_raises():
    rows = [{"planner": "prioritized (given)", "solved": True, "sum_of_costs": 9, "seed": ""},
            {"planner": "cbs", "solved": True, "sum_of_costs": 10, "seed": ""}]
    with pytest.raises(study.InvalidPlan, match="below the optimum 10"):
        study.check_optimal(rows, "x")
    rows[0]["solved"] = False
    study.check_optimal(rows, "x")  # an unsolved run does not count
    rows.append({"planner": "icbs", "solved": True, "sum_of_costs": 11, "seed": ""})
    with pytest.raises(study.InvalidPlan, match="different optima"):
        study.check_optimal(rows, "x")


def test_slow_runs_fail_and_a_failed_planner_is_not_run_at_larger_counts(movingai_dir,
                                                                         monkeypatch):
    def slow(graph, starts, goals):
        time.sleep(0.3)
        return pibt(graph, starts, goals)

    monkeypatch.setattr(study, "warm_up", lambda instance: None)
    calls = [("pibt", None, pibt), ("lacam", None, slow)]
    rows = study.run_study([("empty-32-32", "random")], [2, 3, 100_000], calls, 0.2,
                           movingai_dir / "mapf", log=None)
    assert [(r["agents"], r["planner"], r["solved"]) for r in rows] == [
        (2, "pibt", True), (2, "lacam", False), (3, "pibt", True), (3, "lacam", False)]
    assert rows[1]["reason"].startswith("solved in 0.") and "over the 0.2 s limit" in \
        rows[1]["reason"]
    assert rows[3]["reason"] == "not run: not solved at 2 agents" and rows[3]["seconds"] == ""


def test_planners_are_capped_at_their_scale(instance, monkeypatch):
    monkeypatch.setattr(study, "warm_up", lambda instance: None)
    calls = study.planner_calls(1, 5, 1.2, False)
    rows = study.run_instance(instance, dict(WHERE, agents=150), calls, 5)
    assert {r["planner"] for r in rows} == {p for p in study.PLANNERS[:-2]
                                            if study.MAX_AGENTS.get(p, 150) >= 150}


@pytest.mark.parametrize("argv, message", [
    (["--seeds", "0"], "--seeds must be at least 1"),
    (["--scenarios", "odd"], "scenarios are random, even"),
    (["--time-limit", "0"], "--time-limit must be positive"),
    (["--agents", "5,0"], "agent counts must be at least 1"),
    (["--maps", "no-such-map"], "no-such-map.map"),
    (["--planners", "cbs,astar"], "unknown astar; choose from all or report,"),
])
def test_bad_arguments_are_an_error(argv, message, tmp_path, capsys, movingai_dir):
    with pytest.raises(SystemExit) as exit_info:
        study.main([*argv, "--out", str(tmp_path / "out")])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
