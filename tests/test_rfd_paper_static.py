"""The RFD paper's Table 1 script (sweeps/rfd_paper_static.py) at a tiny size: its files, the
costs it reports, the best paths it draws, and its transcription of the paper."""
from __future__ import annotations

import csv
import math

import matplotlib.image
import numpy as np
import pytest

from jaxswarm.maps.paper import PAPER_TABLE1_LENGTH, PAPER_TABLE1_MS, paper_map
from jaxswarm.paths import as_node, is_valid_path, path_length
from repo_scripts import load_script

MAP, SEEDS, ITERATIONS, AGENTS = "mosaic20", 2, 3, 16
EXACT = ("Dijkstra", "A*")
SWARMS = ("ACO", "ACO*", "RFD", "RFD*")

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


def test_one_row_per_algorithm_and_seed(rows):
    assert sorted((r["map"], r["algorithm"], int(r["seed"])) for r in rows) == sorted(
        (MAP, a, s) for a in EXACT + SWARMS for s in range(SEEDS))
    for r in rows:
        assert float(r["seconds"]) > 0
        if r["algorithm"] in SWARMS:
            assert 1 <= int(r["iterations"]) <= ITERATIONS
        else:
            assert r["iterations"] == ""


def test_costs_against_the_optimum(rows):
    optimum = {float(r["optimum"]) for r in rows}
    assert len(optimum) == 1
    optimum = optimum.pop()
    assert optimum == pytest.approx(18.65685, abs=1e-5)  # 14 + 4 * (sqrt(2) - 1) on our map
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


def test_markdown_has_ours_beside_the_papers(out, rows):
    lines = (out / "table.md").read_text(encoding="utf-8").splitlines()
    ours = f"| Dijkstra | ours | {float(rows[0]['optimum']):.2f} ({SEEDS}/{SEEDS}) |"
    assert lines.count(ours) == 1
    assert lines[lines.index(ours) + 1] == "| Dijkstra | paper | 18.65 |"
    assert "| RFD* | paper | 59.548 |" in lines  # the time half
    for algorithm in EXACT + SWARMS:
        assert sum(line.startswith(f"| {algorithm} | ours | ") for line in lines) == 2


def test_figure_and_no_temporary_files(out):
    assert sorted(p.name for p in out.iterdir()) == ["best_paths.png", "runs.csv", "table.md"]
    image = matplotlib.image.imread(out / "best_paths.png")
    assert image.ndim == 3 and min(image.shape[:2]) > 100


def test_best_paths_are_valid_and_match_the_rows(out):
    # out: the compiled runs are cached, so this second solve is quick.
    rows, best = script.solve_map(MAP, SEEDS, iterations=ITERATIONS, agents=AGENTS)
    chosen = paper_map(MAP)
    graph = chosen.graph()
    start, goal = (as_node(graph, p) for p in (chosen.start, chosen.goal))
    assert list(best) == list(script.ALGORITHMS)
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
    assert list(PAPER_TABLE1_LENGTH) == list(PAPER_TABLE1_MS) == list(script.ALGORITHMS)


def test_unknown_map_is_an_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        script.main(["--maps", "mosaic20,nowhere", "--out", str(tmp_path)])
    assert exit_info.value.code == 2
    assert "nowhere" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
