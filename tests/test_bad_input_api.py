"""Bad input to the Python API and to the ``demo``, ``mapf`` and ``robot`` commands: each is
refused with a message naming the argument, the option, the field or the file and line (a
ValueError or TypeError from Python, exit status 2 from the command), before any compute, so
that these tests compile nothing (the robot's unreachable goal excepted: finding that the goal
cannot be reached is a search of the map)."""
import dataclasses
import math

import jax
import numpy as np
import pytest

from jaxswarm.cli import main
from jaxswarm.maps.movingai import MovingAIFormatError, load_scenarios, read_map
from jaxswarm.multiagent import registry
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.registry import REGISTRY
from jaxswarm.tune import load_tune_spec
from jaxswarm.world.graph import grid_graph

WALLED = ("type octile\nheight 3\nwidth 5\nmap\n"
          "..@..\n"
          "..@..\n"
          "..@..\n")
"""A 5 x 3 map whose middle column walls the left half off from the right half."""


def _refused(capsys, argv: list[str]) -> str:
    """The last line the command wrote to stderr, after checking it exited with status 2 and
    printed no traceback."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    error = capsys.readouterr().err
    assert stop.value.code == 2, error
    assert "Traceback" not in error
    return error.splitlines()[-1]


@pytest.mark.parametrize("command", ["demo", "robot"])
def test_demo_and_robot_refuse_a_start_equal_to_the_goal(command, capsys):
    line = _refused(capsys, [command, "--map", "maze20", "--start", "0,2", "--goal", "0,2"])
    assert line.endswith("--start (0, 2) and --goal (0, 2) are the same cell: there is nothing "
                         "to plan")


def test_mapf_refuses_a_gif_path_that_is_a_folder_before_planning(movingai_dir, tmp_path,
                                                                  capsys, monkeypatch):
    def no_planning(*args, **kwargs):
        raise AssertionError("the instance was loaded before --gif was checked")

    monkeypatch.setattr("jaxswarm.cli.load_instance", no_planning)
    mapf = movingai_dir / "mapf"
    line = _refused(capsys, ["mapf", str(mapf / "empty-32-32.map"),
                             str(mapf / "empty-32-32-even-1.scen"), "--gif", str(tmp_path)])
    assert "--gif" in line and str(tmp_path) in line and "folder" in line


@pytest.mark.parametrize("command", ["demo", "robot"])
def test_demo_and_robot_refuse_an_out_path_that_is_a_folder(command, tmp_path, capsys):
    line = _refused(capsys, [command, "--map", "maze20", "--out", str(tmp_path)])
    assert f"--out {tmp_path} is a folder" in line


def test_a_negative_rho_n_is_named_not_the_searched_param(tmp_path):
    spec = tmp_path / "iwd.toml"
    spec.write_text('[tune]\nname = "x"\nalgorithm = "iwd"\nmethod = "random"\nbudget = 10\n'
                    'objective = "gap"\niterations = 10\n'
                    '[tune.training]\nmaps = ["maze20"]\nseeds = 2\n'
                    '[tune.held_out]\nmaps = ["maze20"]\nseeds = [5]\n'
                    '[params]\nalpha = { low = 0.5, high = 4.0 }\nrho_n = -0.5\n')
    with pytest.raises(ValueError) as error:
        load_tune_spec(spec)
    message = str(error.value)
    assert "params.rho_n" in message and "params.alpha" not in message
    assert "rho_n must be positive, got -0.5" in message  # the value as written, no NumPy repr


def test_a_non_ascii_byte_in_a_map_is_named_with_its_file_and_line(tmp_path):
    path = tmp_path / "accent.map"
    path.write_text("type octile\nheight 3\nwidth 5\nmap\n..@..\n.\u00e9@..\n..@..\n",
                    encoding="utf-8")
    with pytest.raises(MovingAIFormatError) as error:
        read_map(path)
    assert error.value.line == 6
    assert str(error.value) == (f"{path}, line 6: byte 0xc3 at column 2 is not ASCII (Moving "
                                "AI files are plain ASCII)")


def test_a_non_ascii_byte_in_a_scenario_is_named_with_its_file_and_line(tmp_path):
    path = tmp_path / "accent.scen"
    path.write_bytes(b"version 1\n0\twalled.map\t5\t3\t0\t0\t1\t0\t1\n"
                     b"0\tw\xa0lled.map\t5\t3\t0\t0\t1\t0\t1\n")
    with pytest.raises(MovingAIFormatError, match=r"line 3: byte 0xa0 at column 4 is not ASCII"):
        load_scenarios(path)


def test_robot_says_the_goal_is_unreachable_on_the_map_itself(tmp_path, capsys):
    path = tmp_path / "walled.map"
    path.write_text(WALLED)
    line = _refused(capsys, ["robot", "--map", str(path), "--start", "0,0", "--goal", "4,0"])
    assert "hidden blocks" not in line
    assert "the goal (4, 0) cannot be reached from the start (0, 0) on the map itself" in line


@pytest.mark.parametrize("options, error, message", [
    (dict(num_agents=8.5), TypeError, "num_agents of rfd must be an integer, got 8.5 (float)"),
    (dict(num_agents="8"), TypeError, "num_agents of rfd must be an integer, got '8' (str)"),
    (dict(num_agents=True), TypeError, "num_agents of rfd must be an integer, got True (bool)"),
    (dict(max_steps=2.0), TypeError, "max_steps of rfd must be an integer or None, got 2.0"),
    (dict(num_agents=0), ValueError,
     "num_agents must be at least 1, got 0 (a config option of rfd)"),
])
def test_make_names_the_swarm_and_the_option_of_a_bad_config(options, error, message):
    with pytest.raises(error) as raised:
        make("rfd", **options)
    assert str(raised.value).startswith(message)


@pytest.mark.parametrize("name, options, message", [
    ("rfd_star", dict(fill_blind_alleys=1), "fill_blind_alleys of rfd_star must be True or False"),
    ("rfd_star", dict(erosion_law=2), "erosion_law of rfd_star must be a string, got 2 (int)"),
    ("rfd_star", dict(max_climb="1"), "max_climb of rfd_star must be a number or None"),
    ("cabc", dict(max_steps=None), "max_steps of cabc must be an integer, got None"),
])
def test_make_checks_the_type_of_every_kind_of_option(name, options, message):
    with pytest.raises(TypeError) as raised:
        make(name, **options)
    assert str(raised.value).startswith(message)


@pytest.mark.parametrize("name", sorted(REGISTRY))
def test_make_takes_every_option_of_every_swarm_at_its_default(name):
    # Every Config field's annotation is one make knows how to check.
    defaults = {field.name: field.default for field in dataclasses.fields(REGISTRY[name].config)}
    assert make(name, **defaults) is make(name)


def test_make_takes_numpy_integers_as_the_same_config():
    assert make("rfd", num_agents=np.int64(8)) is make("rfd", num_agents=8)


@pytest.fixture(scope="module")
def corridor():
    """A 3 x 1 corridor and its end-to-end task (NumPy and eager transfers only)."""
    graph = grid_graph(np.zeros((1, 3), bool))
    return graph, make_task(graph, (0, 0), (2, 0))


def test_run_refuses_params_given_as_a_dict(corridor):
    swarm = make("rfd", num_agents=2)
    with pytest.raises(TypeError) as error:
        run(swarm, jax.random.key(0), *corridor, dict(swarm.default_params._asdict()))
    message = str(error.value)
    assert "params of rfd must be RFDParams, got dict" in message
    assert "params_with" in message


def test_run_refuses_the_params_of_another_swarm(corridor):
    iwd_params = make("iwd").default_params
    with pytest.raises(TypeError, match="params of rfd must be RFDParams, got IWDParams"):
        run(make("rfd", num_agents=2), jax.random.key(0), *corridor, iwd_params)


def test_run_names_a_param_of_the_wrong_shape_and_the_shape_expected(corridor):
    swarm = make("rfd", num_agents=2)
    params = swarm.default_params._replace(erosion=np.ones(3, np.float32))
    with pytest.raises(ValueError) as error:
        run(swarm, jax.random.key(0), *corridor, params)
    assert str(error.value).startswith("params.erosion of rfd has shape (3,), expected () (a "
                                       "scalar) for a single run")


def test_run_names_a_param_that_is_not_a_number(corridor):
    swarm = make("rfd", num_agents=2)
    with pytest.raises(TypeError, match=r"params.erosion of rfd must be a real number, got 'x'"):
        run(swarm, jax.random.key(0), *corridor, swarm.default_params._replace(erosion="x"))


def test_run_names_a_bad_param_inside_vmap_before_compiling(corridor):
    swarm = make("rfd", num_agents=2)
    batch = jax.tree_util.tree_map(lambda x: np.full(2, x, np.float32), swarm.default_params)
    batch = batch._replace(erosion=np.ones((2, 3), np.float32))
    keys = jax.random.split(jax.random.key(0), 2)
    with pytest.raises(ValueError, match=r"params.erosion of rfd has shape \(3,\), expected \(\)"):
        jax.vmap(lambda key, p: run(swarm, key, *corridor, p))(keys, batch)


@pytest.mark.parametrize("planner", ["cbs", "icbs", "ecbs", "eecbs"])
@pytest.mark.parametrize("limit, value, error, message", [
    ("time_limit", -1, ValueError, "time_limit must be positive, got -1"),
    ("time_limit", 0, ValueError, "time_limit must be positive, got 0"),
    ("time_limit", math.nan, ValueError, "time_limit must be positive, got nan"),
    ("time_limit", "5", TypeError, "time_limit must be a number of seconds, got '5'"),
    ("max_nodes", 0, ValueError, "max_nodes must be at least 1, got 0"),
    ("max_nodes", 2.5, TypeError, "max_nodes must be an integer, got 2.5"),
])
def test_cbs_and_ecbs_check_their_limits_as_the_command_does(corridor, planner, limit, value,
                                                             error, message):
    graph = corridor[0]
    with pytest.raises(error) as raised:
        registry.planner_functions()[planner](graph, [(0, 0)], [(2, 0)], **{limit: value})
    assert str(raised.value) == message
