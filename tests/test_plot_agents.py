"""Figures of many agents (jaxswarm.plot.agents): paths drawn where the map says, GIFs with one
frame per step, written whole or not at all."""
import re

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from PIL import Image  # noqa: E402

from jaxswarm.plot import agents as agents_module  # noqa: E402
from jaxswarm.plot.agents import agent_colors, animate_plan, draw_plan  # noqa: E402
from jaxswarm.runtime.atomic import TEMPORARY_GLOB  # noqa: E402
from jaxswarm.world.graph import grid_graph  # noqa: E402

BLOCKED = np.array([[0, 0, 0, 0, 0],
                    [0, 1, 0, 1, 0],
                    [0, 0, 0, 0, 0]], bool)  # H = 3, W = 5: node y * 5 + x
# agent 0: (0, 0) -> (4, 0) along the top row; agent 1: (2, 2) -> (2, 0) up the middle column,
# waiting one step at (2, 1) to let agent 0 pass; padded by repeating the goal.
PATHS = np.array([[0, 1, 2, 3, 4, 4],
                  [12, 7, 7, 2, 2, 2]], np.int32)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture
def graph():
    return grid_graph(BLOCKED, connectivity=4)


def test_draw_plan_draws_each_path_start_and_goal_in_the_agents_colour(graph):
    ax = draw_plan(graph, PATHS, title="two agents")
    colors = agent_colors(2)
    lines = [line for line in ax.get_lines() if line.get_label().startswith("agent")]
    assert [line.get_label() for line in lines] == ["agent 0", "agent 1"]
    xy = np.asarray(graph.xy)
    for a, line in enumerate(lines):
        np.testing.assert_array_equal(np.stack(line.get_data(), axis=1), xy[PATHS[a]])
        assert matplotlib.colors.same_color(line.get_color(), colors[a])
    starts, goals = ax.collections[-2:]
    np.testing.assert_array_equal(starts.get_offsets(), [(0, 0), (2, 2)])
    np.testing.assert_array_equal(goals.get_offsets(), [(4, 0), (2, 0)])
    assert (goals.get_facecolors().size == 0 and  # hollow rings, edged in the agents' colours
            np.allclose(goals.get_edgecolors(), colors))
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["agent 0", "agent 1"]
    assert ax.get_title() == "two agents"


def test_draw_plan_takes_given_goals_and_axes(graph):
    fig, ax = plt.subplots()
    assert draw_plan(graph, PATHS[:, :2], ax, goals=[(4, 0), 2], legend=False) is ax
    np.testing.assert_array_equal(ax.collections[-1].get_offsets(), [(4, 0), (2, 0)])
    assert ax.get_legend() is None


@pytest.mark.parametrize("paths, goals, message", [
    (PATHS[0], None, "paths must be a non-empty integer [agents, steps] array"),
    (PATHS + 10, None, "paths must hold node indices 0..14"),
    (PATHS, [(4, 0)], "1 goals for 2 agents"),
    (PATHS, [(4, 0), (7, 7)], "agent 1's goal (7, 7) is off the 5x3 map"),
])
def test_draw_plan_names_bad_input(graph, paths, goals, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        draw_plan(graph, paths, goals=goals)


def test_animate_plan_writes_one_frame_per_step(graph, tmp_path):
    out = tmp_path / "deep" / "plan.gif"
    assert animate_plan(graph, PATHS, out, fps=5) == PATHS.shape[1]
    with Image.open(out) as gif:
        assert gif.format == "GIF" and gif.n_frames == PATHS.shape[1]
        assert gif.info["duration"] == 200
        frames = []
        for k in range(gif.n_frames):
            gif.seek(k)
            frames.append(np.asarray(gif.convert("RGB")))
    assert all((a != b).any() for a, b in zip(frames, frames[1:]))  # the title counts steps
    assert list(tmp_path.rglob(TEMPORARY_GLOB)) == []


def test_animate_plan_substeps_and_frame_cap(graph, tmp_path):
    out = tmp_path / "smooth.gif"
    assert animate_plan(graph, PATHS, out, substeps=3, trail=0) == 5 * 3 + 1
    with Image.open(out) as gif:
        assert gif.n_frames == 16
    assert animate_plan(graph, PATHS, out, substeps=3, max_frames=4) == 4
    with Image.open(out) as gif:
        assert gif.n_frames == 4


def test_animate_plan_draws_an_even_sample_of_many_agents(graph, tmp_path, monkeypatch):
    drawn = []
    real = agents_module._draw_goals

    def spy(ax, points, colors, size):
        drawn.append(len(points))
        return real(ax, points, colors, size)

    monkeypatch.setattr(agents_module, "_draw_goals", spy)
    out = tmp_path / "sample.gif"
    assert animate_plan(graph, PATHS, out, max_agents=1) == PATHS.shape[1]  # 1 of 2 drawn
    assert drawn == [1] and agents_module.drawn_agents(PATHS.shape[0], 1) == 1
    assert animate_plan(graph, PATHS, out) == PATHS.shape[1]
    assert drawn == [1, 2] and agents_module.drawn_agents(PATHS.shape[0]) == 2
    with pytest.raises(ValueError, match="max_agents must be at least 1"):
        animate_plan(graph, PATHS, out, max_agents=0)


def test_animate_plan_leaves_nothing_half_written_on_error(graph, tmp_path, monkeypatch):
    out = tmp_path / "plan.gif"
    out.write_bytes(b"the old animation")

    def broken_save(image, fp, *args, **kwargs):
        with open(fp, "wb") as f:
            f.write(b"GIF89a half")  # a partial file, then the disk fills up
        raise OSError("No space left on device")

    monkeypatch.setattr(Image.Image, "save", broken_save)
    with pytest.raises(OSError, match="No space left"):
        animate_plan(graph, PATHS, out)
    assert out.read_bytes() == b"the old animation"
    assert list(tmp_path.glob(TEMPORARY_GLOB)) == []
    monkeypatch.undo()
    with pytest.raises(ValueError, match="substeps must be at least 1"):
        animate_plan(graph, PATHS, tmp_path / "never.gif", substeps=0)
    assert not (tmp_path / "never.gif").exists()
    assert plt.get_fignums() == []  # the figure is closed on an error too
