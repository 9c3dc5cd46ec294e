import re
from pathlib import Path

import jax.numpy as jnp
import matplotlib
import pytest
import sizes

matplotlib.use("Agg")

from jaxswarm.cli import main  # noqa: E402


def test_demo_of_one_swarm_prints_it_beside_the_exact_planners(tmp_path, capsys):
    out = tmp_path / "demo.png"
    # The shared size (tests/sizes.py): the demo's run is the conformance checks' program.
    assert main(["demo", "--map", sizes.MAP, "--repeats", "1", "--drops", str(sizes.AGENTS),
                 "--iterations", str(sizes.ITERATIONS), "--swarms", "rfd_graded",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    rows = {planner: re.search(rf"^{re.escape(planner)}\s+(\S+)\s+(\S+)", text, re.MULTILINE)
            for planner in ("Dijkstra", "A*", "bidirectional A*", "RFD graded (ours)")}
    assert all(rows.values()), text
    assert {row.group(2) for name, row in rows.items() if name != "RFD graded (ours)"} == {
        "+0.00%"}
    assert not rows["RFD graded (ours)"].group(2).startswith("-")
    assert "RFD (paper)" not in text
    for png in (out, tmp_path / "demo_rfd_graded.png"):
        assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow  # every swarm's compile, about 100 s
def test_demo_prints_every_planner_and_writes_figures(tmp_path, capsys):
    out = tmp_path / "demo.png"
    assert main(["demo", "--map", "maze20", "--repeats", "1", "--drops", "16", "--iterations", "5",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    lengths = {}
    exact = ("Dijkstra", "A*", "bidirectional A*")
    swarms = ("RFD (paper)", "RFD* (paper)", "RFD graded (ours)", "Ant System (paper)",
              "ACO* (paper)", "Max-Min ACO (paper)", "Improved Max-Min ACO (paper)",
              "IWD (paper)", "IWD_PG (paper)")
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
             "improved_max_min_aco", "iwd", "iwd_pg")
    for png in (out, *(tmp_path / f"demo_{name}.png" for name in names)):
        assert png.read_bytes()[:4] == b"\x89PNG"


@pytest.mark.slow  # the robot program's compile and a GIF, about 20 s
def test_robot_walks_a_path_map_with_a_swarm_and_dstar_and_writes_a_gif(tmp_path, capsys):
    out = tmp_path / "robot.gif"
    assert main(["robot", "--map", "pathmap10x10", "--swarm", "improved_max_min_aco",
                 "--iterations", "10", "--seed", "2", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    optimum = float(re.search(r"optimum with full knowledge (\S+)", text).group(1))
    for planner in ("Improved Max-Min ACO (paper), memory keep", "D* Lite (repair)"):
        row = re.search(rf"^{re.escape(planner)}\s+(\S+)\s+(\S+)\s+(\S+)\s+(\d+)", text,
                        re.MULTILINE)
        assert row, f"no row for {planner} in:\n{text}"
        reached, travelled, _, plans = row.groups()
        assert reached == "True" and float(travelled) >= optimum - 0.01 and int(plans) >= 1
    assert out.read_bytes()[:3] == b"GIF"
    assert out.with_suffix(".png").read_bytes()[:4] == b"\x89PNG"


def test_robot_names_a_bad_option_in_a_line(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["robot", "--map", "maze20", "--blocks", "0"])
    assert exit_.value.code == 2
    assert "jaxswarm robot: error: --blocks must be at least 1, got 0" in capsys.readouterr().err


@pytest.mark.parametrize("arguments, message", [
    (["--map", "nowhere"], "--map must be one of"),
    (["--map", "nosuch.map", "--start", "1,1", "--goal", "2,2"], "--map nosuch.map: no such file"),
    (["--map", "nosuch.map"], "--start and --goal are required with a .map file"),
    (["--map", "maze20", "--start", "25,0"], "start (25, 0) is off the 20x20 map"),
    (["--swarms", "rfd,bees"], "unknown swarms ['bees']; registered on graphs: aco_star"),
])
def test_demo_rejects_a_bad_map_or_swarm_in_a_line_with_exit_status_2(capsys, arguments, message):
    with pytest.raises(SystemExit) as stop:
        main(["demo", *arguments])
    assert stop.value.code == 2
    error = capsys.readouterr().err
    assert message in error.splitlines()[-1] and "Traceback" not in error


@pytest.mark.slow  # rfd_graded's programs on a 32 x 32 map, about 30 s cold
def test_demo_plans_on_a_moving_ai_map_between_given_cells(movingai_dir, tmp_path, capsys,
                                                          monkeypatch):
    """Twin in the default tier: the demo of one swarm on a paper map (the same command), and
    test_movingai.py's maps."""
    monkeypatch.chdir(tmp_path)
    assert main(["demo", "--map", str(movingai_dir / "mapf" / "empty-32-32.map"), "--start", "0,0",
                 "--goal", "5,3", "--repeats", "1", "--iterations", "3", "--drops", "8",
                 "--swarms", "rfd_graded"]) == 0
    out = tmp_path / "out" / "demo_empty-32-32.png"  # the figures carry the map's name
    text = capsys.readouterr().out
    assert text.startswith("map empty-32-32: 32x32, 1024 free cells, start (0, 0) -> goal (5, 3)")
    dijkstra_row = re.search(r"^Dijkstra\s+(\S+)\s+(\S+)", text, re.MULTILINE)
    assert dijkstra_row.groups() == (f"{2 + 3 * 2 ** 0.5:.2f}", "+0.00%")  # 3 diagonals, 2 east
    assert out.read_bytes()[:4] == b"\x89PNG"
    assert (tmp_path / "out" / "demo_empty-32-32_rfd_graded.png").is_file()


def test_an_interrupted_sweep_says_in_one_line_that_the_command_resumes(monkeypatch, capsys):
    import jaxswarm.sweep

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(jaxswarm.sweep, "run_sweep", interrupted)
    with pytest.raises(SystemExit) as stop:
        main(["sweep", str(Path(__file__).parents[1] / "sweeps" / "rfd_star_pbase_alpha.toml"),
              "--no-progress"])
    assert stop.value.code == 130
    error = capsys.readouterr().err
    assert error == ("jaxswarm sweep: interrupted; the finished chunks are kept: run the same "
                     "command again to resume\n")


def test_threads_option_names_a_bad_count_or_a_late_call(capsys):
    jnp.ones(1).block_until_ready()  # JAX has started: a valid count comes too late
    for count, message in (("0", "threads must be a whole number of at least 1"),
                           ("1", "before JAX's first computation")):
        with pytest.raises(SystemExit) as stop:
            main(["--threads", count, "demo", "--map", "maze20"])
        assert stop.value.code == 2
        error = capsys.readouterr().err
        assert "error: --threads:" in error and message in error


def _mapf_files(movingai_dir, map_name="empty-32-32", scen="even-1"):
    mapf = movingai_dir / "mapf"
    return str(mapf / f"{map_name}.map"), str(mapf / f"{map_name}-{scen}.scen")


def _mapf_row(text: str, planner: str) -> dict:
    header = ("planner", "solved", "sum of costs", "lower bound", "ratio", "makespan", "time [ms]",
              "violations")
    row = re.search(rf"^{planner}\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)\s+(\S+)$",
                    text, re.MULTILINE)
    assert row, f"no row for {planner} in:\n{text}"
    return dict(zip(header[1:], row.groups()))


@pytest.mark.parametrize("planner, options", [("report", []),
                                              ("prioritized", ["--order", "distance"]),
                                              ("cbs", ["--time-limit", "30"]),
                                              ("icbs", ["--time-limit", "30"]),
                                              ("cbsh", []), ("cbsh_tc", []),
                                              ("cbsh_rtc", ["--time-limit", "30"]),
                                              ("ecbs", ["--w", "1.1"]),
                                              ("eecbs", ["--w", "1.1"]),
                                              ("pibt", ["--seed", "2"]),
                                              ("lacam", ["--refine", "0.5"]),
                                              ("lacam_star", ["--seed", "1"])])
def test_mapf_plans_five_agents_with_each_planner(movingai_dir, capsys, planner, options):
    assert main(["mapf", *_mapf_files(movingai_dir), "--agents", "5", "--planner", planner,
                 *options, "--no-gif"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("map empty-32-32: 32x32, 1024 free cells, 5 agents from "
                           f"empty-32-32-even-1.scen, planner {planner}")
    row = _mapf_row(text, planner)
    assert row["solved"] == "True" and row["violations"] == "0"
    cost, bound = int(row["sum of costs"]), int(row["lower bound"])
    assert bound == 114 and cost >= bound  # the sum of the scenario's optimal lengths
    assert float(row["ratio"]) == pytest.approx(cost / bound, abs=1e-3)
    if planner in ("cbs", "icbs", "cbsh", "cbsh_tc", "cbsh_rtc", "ecbs", "eecbs"):
        assert cost == bound  # optimal (ECBS: within 1.1), and here no agent has to give way
    # The longest path is the makespan: at least the mean, at most the sum of the paths.
    assert cost / 5 <= int(row["makespan"]) <= cost
    assert 0 < float(row["time [ms]"]) < 30_000
    assert "GIF" not in text


def test_mapf_writes_a_gif_with_one_frame_per_step(movingai_dir, capsys, tmp_path,
                                                    monkeypatch):
    from PIL import Image

    monkeypatch.chdir(tmp_path)
    # The instance of the planners' test above: the same program checks the plans' conflicts.
    assert main(["mapf", *_mapf_files(movingai_dir), "--agents", "5",
                 "--planner", "prioritized", "--order", "random", "--seed", "3"]) == 0
    text = capsys.readouterr().out
    gif = tmp_path / "out" / "mapf_empty-32-32_prioritized.gif"  # the default place
    frames = int(re.search(r"GIF written to (\S+) \((\d+) frames\)", text).group(2))
    assert frames == int(_mapf_row(text, "prioritized")["makespan"]) + 1
    with Image.open(gif) as image:
        assert image.format == "GIF" and image.n_frames == frames
    out = tmp_path / "elsewhere" / "cbs.gif"
    assert main(["mapf", *_mapf_files(movingai_dir), "--agents", "5", "--planner", "cbs",
                 "--gif", str(out)]) == 0
    assert out.read_bytes()[:6] == b"GIF89a"


def test_mapf_names_the_agent_and_exits_1_when_not_solved(tmp_path, capsys):
    # A corridor (0, 0)..(4, 0) cut out of a 32 x 32 map, the shape of the Moving AI maps above
    # (the same programs), and two agents swapping its ends: impossible.
    rows = [".....".ljust(32, "@")] + ["@" * 32] * 31
    (tmp_path / "corridor.map").write_text("type octile\nheight 32\nwidth 32\nmap\n"
                                           + "".join(row + "\n" for row in rows))
    (tmp_path / "swap.scen").write_text("version 1\n"
                                        "0\tcorridor.map\t32\t32\t0\t0\t4\t0\t4\n"
                                        "0\tcorridor.map\t32\t32\t4\t0\t0\t0\t4\n")
    assert main(["mapf", str(tmp_path / "corridor.map"), str(tmp_path / "swap.scen"),
                 "--agents", "2", "--planner", "prioritized"]) == 1
    text = capsys.readouterr().out
    assert _mapf_row(text, "prioritized")["solved"] == "False"
    assert re.search(r"^not solved: agent 1 could not be planned", text, re.MULTILINE), text
    assert main(["mapf", str(tmp_path / "corridor.map"), str(tmp_path / "swap.scen"),
                 "--agents", "2", "--planner", "lacam"]) == 1
    assert re.search(r"^not solved: no solution: every configuration reachable from the starts",
                     capsys.readouterr().out, re.MULTILINE)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("arguments, message", [
    (["nosuch.map", "{scen}"], "MAP nosuch.map: no such file"),
    (["{map}", "nosuch.scen"], "SCEN nosuch.scen: no such file"),
    (["{map}", "{scen}", "--agents", "5000"], "5000 agents asked for, the file has"),
    (["{map}", "{scen}", "--agents", "0"], "--agents must be at least 1, got 0"),
    (["{map}", "{scen}", "--planner", "astar"], "argument --planner: invalid choice: 'astar'"),
    (["{map}", "{scen}", "--planner", "cbs", "--order", "random"],
     "--order applies to --planner prioritized, not cbs"),
    (["{map}", "{scen}", "--planner", "cbs", "--time-limit", "0"],
     "--time-limit must be positive, got 0.0"),
    (["{map}", "{scen}", "--planner", "cbs", "--refine", "1"],
     "--refine applies to --planner lacam or lacam_star, not cbs"),
    (["{map}", "{scen}", "--planner", "report", "--seed", "1"],
     "--seed applies to --planner prioritized or pibt or lacam or lacam_star, not report"),
    (["{map}", "{scen}", "--planner", "lacam", "--refine", "-1"],
     "--refine must be at least 0, got -1.0"),
    (["{map}", "{scen}", "--planner", "ecbs", "--w", "0.5"], "--w must be at least 1, got 0.5"),
    (["{map}", "{scen}", "--planner", "cbs", "--w", "1.5"],
     "--w applies to --planner ecbs or eecbs, not cbs"),
    (["{map}", "{scen}", "--gif", "a.gif", "--no-gif"], "--no-gif: not allowed with argument"),
])
def test_mapf_rejects_bad_input_in_a_line_with_exit_status_2(movingai_dir, capsys, arguments,
                                                              message):
    map_path, scen = _mapf_files(movingai_dir)
    with pytest.raises(SystemExit) as stop:
        main(["mapf", *(a.format(map=map_path, scen=scen) for a in arguments)])
    assert stop.value.code == 2
    error = capsys.readouterr().err
    assert message in error.splitlines()[-1] and "Traceback" not in error
