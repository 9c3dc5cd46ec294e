import re

import jax.numpy as jnp
import matplotlib
import pytest

matplotlib.use("Agg")

from jaxswarm.cli import main  # noqa: E402


def test_demo_prints_every_planner_and_writes_figures(tmp_path, capsys):
    out = tmp_path / "demo.png"
    assert main(["demo", "--map", "maze20", "--repeats", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    lengths = {}
    exact = ("Dijkstra", "A*", "bidirectional A*")
    swarms = ("RFD (paper)", "RFD* (paper)", "RFD graded (ours)", "Ant System (paper)",
              "ACO* (paper)", "Max-Min ACO (paper)", "Improved Max-Min ACO (paper)")
    for planner in exact + swarms:
        row = re.search(rf"^{re.escape(planner)}\s+(\S+)\s+(\S+)", text, re.MULTILINE)
        assert row, f"no row for {planner} in:\n{text}"
        lengths[planner] = row.group(1)
        gap = row.group(2)
        if planner in exact:
            assert gap == "+0.00%"
        else:
            assert gap == "-" or not gap.startswith("-")  # no swarm beats the optimum
    assert len({lengths[planner] for planner in exact}) == 1
    assert "(paper): the paper's algorithm as written; (ours): jaxswarm's own" in text
    names = ("rfd", "rfd_star", "rfd_graded", "ant_system", "aco_star", "max_min_aco",
             "improved_max_min_aco")
    for png in (out, *(tmp_path / f"demo_{name}.png" for name in names)):
        assert png.read_bytes()[:4] == b"\x89PNG"


def test_demo_rejects_unknown_map_with_exit_status_2(capsys):
    try:
        main(["demo", "--map", "nowhere"])
    except SystemExit as stop:
        assert stop.code == 2
    assert "--map must be one of" in capsys.readouterr().err


def test_threads_option_names_a_bad_count_or_a_late_call(capsys):
    jnp.ones(1).block_until_ready()  # JAX has started: a valid count comes too late
    for count, message in (("0", "threads must be a whole number of at least 1"),
                           ("1", "before JAX's first computation")):
        with pytest.raises(SystemExit) as stop:
            main(["--threads", count, "demo", "--map", "maze20"])
        assert stop.value.code == 2
        error = capsys.readouterr().err
        assert "error: --threads:" in error and message in error
