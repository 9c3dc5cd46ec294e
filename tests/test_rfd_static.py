"""The static RFD / RFD* table script (sweeps/rfd_static.py) at a tiny size: the rows it writes
agree with Dijkstra and with each other, and its table summarises them."""
from __future__ import annotations

import csv
import math

import pytest

from jaxswarm.exact import dijkstra
from jaxswarm.maps.paper import paper_map
from repo_scripts import load_script

MAP, SEEDS, ITERATIONS, AGENTS = "maze20", 2, 4, 16

script = load_script("sweeps/rfd_static.py")


@pytest.fixture(scope="module")
def out(tmp_path_factory):
    """The output folder of one tiny run of the script."""
    folder = tmp_path_factory.mktemp("rfd_static")
    assert script.main(["--maps", MAP, "--seeds", str(SEEDS), "--iterations", str(ITERATIONS),
                        "--agents", str(AGENTS), "--out", str(folder)]) == 0
    return folder


def test_rows_carry_the_dijkstra_optimum_and_a_consistent_gap(out):
    with open(out / "runs.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [(r["algorithm"], int(r["seed"])) for r in rows] == [
        (algorithm, seed) for algorithm in script.ALGORITHMS for seed in range(SEEDS)]
    chosen = paper_map(MAP)
    optimum = dijkstra(chosen.graph(), chosen.start, chosen.goal).cost
    for r in rows:
        cost, gap = float(r["cost"]), float(r["gap"])
        assert float(r["optimum"]) == pytest.approx(optimum)
        assert cost >= optimum * (1 - 1e-6)  # no drop beats Dijkstra
        if math.isfinite(cost):
            assert gap == pytest.approx((cost - optimum) / optimum, abs=1e-9)
        assert (r["success"] == "True") == (gap < script.SUCCESS_GAP)
        assert 1 <= int(r["iterations"]) <= ITERATIONS
        first = r["first_optimal_iteration"]
        assert (first != "") == (r["success"] == "True")
        if first:
            assert 1 <= int(first) <= int(r["iterations"])
    # RFD* walks maze20's single corridor to the optimum at its first arrival.
    assert all(r["success"] == "True" for r in rows if r["algorithm"] == "rfd_star")


def test_table_summarises_the_rows(out):
    with open(out / "runs.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    lines = (out / "table.md").read_text().splitlines()
    assert len(lines) == 3 and lines[2].startswith(f"| {MAP} | ")
    cells = [c.strip() for c in lines[2].strip("|").split("|")]
    for i, algorithm in enumerate(script.ALGORITHMS):
        mine = [r for r in rows if r["algorithm"] == algorithm]
        wins = sum(r["success"] == "True" for r in mine)
        assert cells[2 + 3 * i + 1] == f"{wins}/{SEEDS}"


@pytest.mark.parametrize("argv, message", [
    (["--maps", "maze20,atlantis"], "atlantis"),
    (["--maps", "maze20", "--seeds", "0"], "--seeds must be at least 1"),
])
def test_bad_arguments_stop_before_any_run(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as exit_info:
        script.main([*argv, "--out", str(tmp_path)])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
