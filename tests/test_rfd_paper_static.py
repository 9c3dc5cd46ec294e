"""The RFD paper's Table 1 script (sweeps/rfd_paper_static.py) at a tiny size, with the rows it
runs (jaxswarm.studies.rfd_table1): its files, its rows (the variants of ACO and of RFD*), the
costs it reports, the best paths it draws, its provenance and its transcription of the paper.

The script's run compiles programs of its own sizes, so the tests that read it are in the slow
tier; their twins in the default tier check the rows it runs (the eta and travelled rows), its
paper cells and its arguments, and each swarm's runs in test_conformance.py."""
from __future__ import annotations

import csv
import dataclasses
import json
import math

import matplotlib.image
import numpy as np
import pytest

from jaxswarm.maps.paper import PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS, paper_map
from jaxswarm.studies import rfd_table1
from jaxswarm.studies.success import SUCCESS_GAP
from jaxswarm.world.paths import as_node, is_valid_path, path_length
from repo_scripts import load_script

# The Makefile's TABLE1_QUICK (make reproduce-quick): the slow tier compiles one set of programs.
MAP, SEEDS, ITERATIONS, AGENTS = "mosaic20", 2, 3, 16
EXACT = ("Dijkstra", "A*")
# Row label -> what runs (runs.csv's planner column) and the paper's Table 1 row beside it.
SWARMS = {
    "ACO (paper, eq. 7)": ("ant_system", "ACO"),
    "ACO with eta (beta=1)": ("ant_system beta=1", "ACO"),
    "ACO*": ("aco_star", "ACO*"),
    "RFD": ("rfd", "RFD"),
    "RFD* (paper)": ("rfd_star", "RFD*"),
    "RFD* (paper, all travelled paths)": ("rfd_star erode=travelled", "RFD*"),
    "RFD graded (ours)": ("rfd_graded", "RFD*"),
}

script = load_script("sweeps/rfd_paper_static.py")


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    """The output folder of one tiny run of the script."""
    folder = tmp_path_factory.mktemp("rfd_paper_static")
    assert script.main(["--maps", MAP, "--seeds", str(SEEDS), "--iterations", str(ITERATIONS),
                        "--agents", str(AGENTS), "--out", str(folder)]) == 0
    return folder


@pytest.fixture(scope="module")
def rows(out):
    with open(out / "runs.csv", newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        assert tuple(reader.fieldnames) == script.COLUMNS
        return list(reader)


@pytest.mark.slow  # the script's run at its own sizes (fixture out), about 75 s cold
def test_one_row_per_algorithm_and_seed(rows):
    assert sorted((r["map"], r["algorithm"], int(r["seed"])) for r in rows) == sorted(
        (MAP, a, s) for a in (*EXACT, *SWARMS) for s in range(SEEDS))
    assert rfd_table1.ALGORITHMS == (*EXACT, *SWARMS)  # the paper's order, variants after
    for r in rows:
        assert float(r["seconds"]) > 0
        assert r["planner"] == (SWARMS[r["algorithm"]][0] if r["algorithm"] in SWARMS
                                else {"Dijkstra": "dijkstra", "A*": "astar"}[r["algorithm"]])
        if r["algorithm"] in SWARMS:
            assert 1 <= int(r["iterations"]) <= ITERATIONS
        else:
            assert r["iterations"] == ""


@pytest.mark.slow  # the script's run at its own sizes (fixture out), about 75 s cold
def test_costs_against_the_optimum(rows):
    optimum = {float(r["optimum"]) for r in rows}
    assert len(optimum) == 1
    optimum = optimum.pop()
    assert optimum == pytest.approx(18.65685, abs=1e-5)  # 13 straight + 4 diagonal moves
    for r in rows:
        cost, gap, found = float(r["cost"]), float(r["gap"]), r["found"] == "True"
        assert math.isfinite(cost) == found, r
        if r["algorithm"] in EXACT:
            assert found and cost == pytest.approx(optimum, rel=1e-12), r
        else:
            # Swarm costs are float32 sums of edge lengths: allow their rounding below the optimum.
            assert cost >= optimum * (1 - 1e-6), r
        if found:
            assert gap == pytest.approx((cost - optimum) / optimum), r
        else:
            assert gap == math.inf, r


@pytest.mark.slow  # the script's run at its own sizes (fixture out), about 75 s cold
def test_markdown_has_ours_beside_the_papers(out, rows):
    lines = (out / "table.md").read_text(encoding="utf-8").splitlines()
    ours = f"| Dijkstra | ours | {float(rows[0]['optimum']):.2f} ({SEEDS}/{SEEDS}) |"
    assert lines.count(ours) == 1
    assert lines[lines.index(ours) + 1] == "| Dijkstra | paper (Dijkstra) | 18.65 |"
    # Both variants sit beside the paper's row they reproduce, in both halves.
    for label, (_, paper) in SWARMS.items():
        for values in (PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS):
            value = values[paper][MAP]
            cell = f"{value:.2f}" if values is PAPER_TABLE1_LENGTH else str(value)
            assert f"| {label} | paper ({paper}) | {cell} |" in lines, (label, cell)
    assert "| RFD graded (ours) | paper (RFD*) | 59.548 |" in lines  # the time half
    for algorithm in (*EXACT, *SWARMS):
        # Path length, runs at the optimum, time.
        assert sum(line.startswith(f"| {algorithm} | ours | ") for line in lines) == 3


@pytest.mark.slow  # the script's run at its own sizes (fixture out), about 75 s cold
def test_markdown_counts_the_runs_that_reach_the_optimum(out, rows):
    lines = (out / "table.md").read_text(encoding="utf-8").splitlines()
    section = lines.index(next(line for line in lines if line.startswith("## Runs that reach")))
    for algorithm in (*EXACT, *SWARMS):
        optimal = sum(float(r["gap"]) < SUCCESS_GAP for r in rows
                      if r["algorithm"] == algorithm)
        line = next(line for line in lines[section:]
                    if line.startswith(f"| {algorithm} | ours | "))
        assert line == f"| {algorithm} | ours | {optimal}/{SEEDS} |"


@pytest.mark.slow  # the script's run at its own sizes (fixture out), about 75 s cold
def test_markdown_and_json_carry_the_provenance(out):
    text = (out / "table.md").read_text(encoding="utf-8")
    record = json.loads((out / "provenance.json").read_text(encoding="utf-8"))
    assert text.startswith(f"# {script.TITLE}\n\nGenerated by `{record['command']}`")
    assert record["command"].startswith("python sweeps/rfd_paper_static.py --maps mosaic20 ")
    assert record["commit"] is None or record["commit"] in text
    assert f"jax {record['versions']['jax']}" in text
    assert record["details"]["arguments"]["seeds"] == SEEDS
    # The eta row's params are Ant System's defaults with beta = 1; the paper's row keeps beta 0.
    params = {label: entry.get("params") for label, entry in record["details"]["rows"].items()}
    assert params["ACO with eta (beta=1)"] == {**params["ACO (paper, eq. 7)"], "beta": 1.0}
    assert params["ACO (paper, eq. 7)"]["beta"] == 0.0
    assert params["Dijkstra"] is None
    configs = {label: entry.get("config") for label, entry in record["details"]["rows"].items()}
    assert configs["RFD* (paper, all travelled paths)"] == {
        **configs["RFD* (paper)"], "erode": "travelled"}


def test_a_row_without_a_paper_counterpart_shows_a_dash():
    mine = rfd_table1.Row("ours only", None, "rfd_graded")
    assert script.paper_cells(mine, ("mosaic20", "alley20"), PAPER_TABLE1_LENGTH, str) == [
        "-", "-"]
    # A paper row with no value (the paper's ACO found no path on maze20) shows n/a.
    eta = rfd_table1.BY_LABEL["ACO with eta (beta=1)"]
    assert script.paper_cells(eta, ("mosaic20", "maze20"), PAPER_TABLE1_LENGTH, str) == [
        "51.68", "n/a"]


def test_the_eta_row_runs_ant_system_with_beta_one():
    plain_swarm, plain = rfd_table1.row_swarm(rfd_table1.BY_LABEL["ACO (paper, eq. 7)"], 8)
    eta_swarm, eta = rfd_table1.row_swarm(rfd_table1.BY_LABEL["ACO with eta (beta=1)"], 8)
    assert eta_swarm is plain_swarm and plain == plain_swarm.default_params
    assert float(plain.beta) == 0.0 and float(eta.beta) == 1.0
    assert eta._replace(beta=plain.beta) == plain
    assert eta.beta.dtype == np.float32


def test_the_travelled_row_runs_rfd_star_eroding_every_path():
    paper_swarm, paper = rfd_table1.row_swarm(rfd_table1.BY_LABEL["RFD* (paper)"], 8)
    travelled_swarm, travelled = rfd_table1.row_swarm(
        rfd_table1.BY_LABEL["RFD* (paper, all travelled paths)"], 8)
    assert paper_swarm.config.erode == "arrived" and travelled_swarm.config.erode == "travelled"
    assert travelled_swarm.config == dataclasses.replace(paper_swarm.config, erode="travelled")
    assert travelled == paper == paper_swarm.default_params
    assert rfd_table1.BY_SWARM["rfd_star"].label == "RFD* (paper)"


@pytest.mark.slow  # the script's run at its own sizes (fixture out), about 75 s cold
def test_figure_and_no_temporary_files(out):
    assert sorted(p.name for p in out.iterdir()) == [
        "best_paths.png", "provenance.json", "runs.csv", "table.md"]
    image = matplotlib.image.imread(out / "best_paths.png")
    assert image.ndim == 3 and min(image.shape[:2]) > 100


@pytest.mark.slow  # the script's run at its own sizes (fixture out), about 75 s cold
def test_best_paths_are_valid_and_match_the_rows(out):
    # out: the compiled runs are cached, so this second solve is quick.
    rows, best = script.solve_map(MAP, SEEDS, iterations=ITERATIONS, agents=AGENTS)
    chosen = paper_map(MAP)
    graph = chosen.graph()
    start, goal = (as_node(graph, p) for p in (chosen.start, chosen.goal))
    assert list(best) == list(rfd_table1.ALGORITHMS)
    for algorithm, solution in best.items():
        costs = [r["cost"] for r in rows if r["algorithm"] == algorithm]
        assert float(solution.cost) == min(costs)
        if bool(solution.found):
            assert bool(is_valid_path(graph, solution.path, start, goal)), algorithm
            assert float(path_length(graph, solution.path)) == pytest.approx(
                float(solution.cost), rel=1e-5), algorithm
        else:
            assert (np.asarray(solution.path) == -1).all(), algorithm


def test_every_row_has_the_papers_values_beside_it():
    assert list(PAPER_TABLE1_LENGTH) == list(PAPER_TABLE1_MS)
    assert [row.paper for row in rfd_table1.ROWS] == [
        "Dijkstra", "A*", *(paper for _, paper in SWARMS.values())]
    # No paper row left out.
    assert set(PAPER_TABLE1_LENGTH) == {row.paper for row in rfd_table1.ROWS}


@pytest.mark.parametrize("argv, message", [
    (["--maps", "mosaic20,nowhere"], "nowhere"),
    (["--maps", "mosaic20", "--seeds", "0"], "--seeds must be at least 1, got 0"),
    (["--maps", "mosaic20", "--agents", "-2"], "--agents must be at least 1, got -2"),
])
def test_bad_arguments_stop_before_any_run(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as exit_info:
        script.main([*argv, "--out", str(tmp_path)])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
