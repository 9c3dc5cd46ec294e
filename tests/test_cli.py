import re

import matplotlib

matplotlib.use("Agg")

from jaxswarm.cli import main  # noqa: E402


def test_demo_prints_every_planner_and_writes_figures(tmp_path, capsys):
    out = tmp_path / "demo.png"
    assert main(["demo", "--map", "maze20", "--repeats", "1", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    lengths = {}
    for planner in ("Dijkstra", "A\\*", "bidirectional A\\*", "RFD\\*", "ACO\\*"):
        row = re.search(rf"^{planner}\s+(\S+)\s+(\S+)", text, re.MULTILINE)
        assert row, f"no row for {planner} in:\n{text}"
        lengths[planner] = row.group(1)
        if planner not in ("RFD\\*", "ACO\\*"):
            assert row.group(2) == "+0.00%"
    assert len({lengths["Dijkstra"], lengths["A\\*"], lengths["bidirectional A\\*"]}) == 1
    for swarm in ("RFD", "ACO"):
        gap = re.search(rf"^{swarm}\*\s+\S+\s+(\S+)", text, re.MULTILINE).group(1)
        assert gap == "-" or not gap.startswith("-")  # no swarm beats the optimum
    for png in (out, tmp_path / "demo_rfd_star.png", tmp_path / "demo_aco_star.png"):
        assert png.read_bytes()[:4] == b"\x89PNG"


def test_demo_rejects_unknown_map_with_exit_status_2(capsys):
    try:
        main(["demo", "--map", "nowhere"])
    except SystemExit as stop:
        assert stop.code == 2
    assert "--map must be one of" in capsys.readouterr().err
