"""Figures: what is drawn lands where the map says (checked on the artists' data, not by eye)."""
import os

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from jaxswarm.plot import graph as plot  # noqa: E402
from jaxswarm.exact import astar, dijkstra, distance_field  # noqa: E402
from jaxswarm.maps.random import random_path_map  # noqa: E402
from jaxswarm.world.graph import dense_graph, grid_graph, path_map_graph  # noqa: E402
from jaxswarm.world.lattice import DIRECTIONS  # noqa: E402
from jaxswarm.world.paths import pad  # noqa: E402

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

OBSTACLES = np.array([
    [0, 0, 0, 0, 0, 0],
    [0, 1, 1, 1, 1, 0],
    [0, 0, 0, 0, 1, 0],
    [1, 1, 1, 0, 1, 0],
    [0, 0, 0, 0, 0, 0],
], dtype=bool)  # H = 5, W = 6; not square, so a swapped x/y shows up


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture
def grid():
    return grid_graph(OBSTACLES)


def _axes():
    return plt.subplots()


def _segments_by_gid(ax, gid):
    (collection,) = [c for c in ax.collections if c.get_gid() == gid]
    return [np.asarray(s) for s in collection.get_segments()]


def _legend_texts(ax):
    return [t.get_text() for t in ax.get_legend().get_texts()]


def _walls_oracle(conn):
    """Set of frozensets {(x, y), (x2, y2)}: orthogonal neighbours closed in either direction."""
    height, width = conn.shape[:2]
    walls = set()
    for y in range(height):
        for x in range(width):
            for k in (0, 1, 2, 3):
                dx, dy = DIRECTIONS[k]
                nx, ny = x + dx, y + dy
                if 0 <= nx < width and 0 <= ny < height and not conn[y, x, k]:
                    walls.add(frozenset({(x, y), (nx, ny)}))
    return walls


def _wall_of_segment(segment):
    """The pair of cells a wall segment separates (inverse of the drawing rule)."""
    (x0, y0), (x1, y1) = segment
    if x0 == x1:  # vertical segment at x + 0.5 between (x, y) and (x + 1, y)
        assert abs(y1 - y0) == 1
        x, y = int(x0 - 0.5), int((y0 + y1) / 2)
        return frozenset({(x, y), (x + 1, y)})
    assert y0 == y1 and abs(x1 - x0) == 1
    x, y = int((x0 + x1) / 2), int(y0 - 0.5)
    return frozenset({(x, y), (x, y + 1)})


# --- draw_paths -----------------------------------------------------------------------------

def test_draw_paths_lines_follow_node_coordinates(grid):
    start, goal = (0, 0), (0, 4)
    solutions = [dijkstra(grid, start, goal), astar(grid, start, goal)]
    raw = pad([0, 1, 2], 10)  # a bare padded array: (0,0) -> (1,0) -> (2,0)
    fig, ax = _axes()
    lines = plot.draw_paths(ax, grid, [*solutions, raw], ["Dijkstra", "A*", "raw"],
                            colors=["red", "blue", "green"])
    assert len(lines) == 3
    xy = np.asarray(grid.xy)
    for line, path in zip(lines, [s.nodes() for s in solutions] + [np.array([0, 1, 2])]):
        np.testing.assert_array_equal(line.get_xdata(), xy[path, 0])
        np.testing.assert_array_equal(line.get_ydata(), xy[path, 1])
    # The path must go round the wall of row 3 through the gap at x = 3.
    assert (3.0, 3.0) in set(zip(lines[0].get_xdata(), lines[0].get_ydata()))
    np.testing.assert_array_equal(lines[2].get_xdata(), [0, 1, 2])
    np.testing.assert_array_equal(lines[2].get_ydata(), [0, 0, 0])
    assert [line.get_label() for line in lines] == ["Dijkstra", "A*", "raw"]
    assert [line.get_color() for line in lines] == ["red", "blue", "green"]
    ax.legend()
    assert _legend_texts(ax) == ["Dijkstra", "A*", "raw"]


def test_draw_paths_keeps_indices_for_empty_paths(grid):
    fig, ax = _axes()
    empty = np.full(8, -1, dtype=np.int32)
    lines = plot.draw_paths(ax, grid, [empty, pad([7], 8)], ["none", "one node"])
    assert len(lines) == 2
    assert len(lines[0].get_xdata()) == 0
    np.testing.assert_array_equal(lines[1].get_xdata(), [1])  # node 7 = (1, 1)
    np.testing.assert_array_equal(lines[1].get_ydata(), [1])


def test_draw_paths_rejects_bad_input(grid):
    fig, ax = _axes()
    with pytest.raises(ValueError, match="labels has 1 entries for 2 paths"):
        plot.draw_paths(ax, grid, [pad([0], 4), pad([1], 4)], ["only one"])
    with pytest.raises(ValueError, match="node 30"):
        plot.draw_paths(ax, grid, [pad([0, 30], 4)])


# --- draw_field -----------------------------------------------------------------------------

def test_draw_field_masks_obstacles(grid):
    values = np.arange(grid.num_nodes, dtype=np.float32)
    fig, ax = _axes()
    image = plot.draw_field(ax, grid, values, label="index")
    data = image.get_array()
    assert data.shape == OBSTACLES.shape
    np.testing.assert_array_equal(np.ma.getmaskarray(data),
                                  ~np.asarray(grid.free).reshape(OBSTACLES.shape))
    # Cell (x, y) holds values[y * W + x]: check a cell off the diagonal.
    assert data[4, 1] == 4 * 6 + 1
    assert image.colorbar.ax.get_ylabel() == "index"
    assert image.get_extent() == [-0.5, 5.5, 4.5, -0.5]


def test_draw_field_masks_non_finite_and_log_masks_non_positive(grid):
    field = np.array(distance_field(grid, 0))
    field[5] = np.nan  # a free cell
    fig, ax = _axes()
    shown = ~np.ma.getmaskarray(plot.draw_field(ax, grid, field).get_array()).reshape(-1)
    np.testing.assert_array_equal(shown, np.asarray(grid.free) & np.isfinite(field))
    assert not shown[5] and shown[0]
    log_shown = ~np.ma.getmaskarray(plot.draw_field(ax, grid, field, log=True).get_array())
    assert not log_shown.reshape(-1)[0]  # the goal's distance 0 has no logarithm
    np.testing.assert_array_equal(log_shown.reshape(-1), shown & (field > 0))


def test_draw_field_errors_name_the_problem(grid):
    fig, ax = _axes()
    with pytest.raises(ValueError, match=r"shape \(30,\).*got \(29,\)"):
        plot.draw_field(ax, grid, np.zeros(29))
    general = dense_graph(np.array([[0, 1], [1, 0]]))
    with pytest.raises(ValueError, match="general graph"):
        plot.draw_field(ax, general, np.zeros(2))


# --- draw_map -------------------------------------------------------------------------------

def test_draw_map_grid_image_orientation_and_endpoints(grid):
    fig, ax = _axes()
    plot.draw_map(ax, grid, start=(0, 0), goal=4 * 6 + 0, title="tiny")
    (image,) = ax.images
    np.testing.assert_array_equal(np.asarray(image.get_array()), ~OBSTACLES)
    assert image.origin == "upper"
    bottom, top = ax.get_ylim()
    assert bottom > top  # y grows downwards
    markers = {line.get_label(): (line.get_xdata()[0], line.get_ydata()[0]) for line in ax.lines}
    assert markers == {"start": (0.0, 0.0), "goal": (0.0, 4.0)}
    assert ax.lines[0].get_marker() != ax.lines[1].get_marker()
    assert ax.get_title() == "tiny"
    assert len(_segments_by_gid(ax, plot.WALL_GID)) == 0  # an occupancy grid has no thin walls


def test_draw_map_accepts_blocked_endpoints(grid):
    fig, ax = _axes()
    plot.draw_map(ax, grid, start=(1, 1), goal=7)  # both the blocked cell (1, 1)
    assert [(line.get_xdata()[0], line.get_ydata()[0]) for line in ax.lines] == [(1, 1), (1, 1)]


def test_draw_map_path_map_one_segment_per_wall():
    conn = np.ones((3, 4, 8), dtype=np.uint8)
    conn[0, 0, 0] = conn[0, 1, 2] = 0  # wall between (0, 0) and (1, 0)
    conn[2, 2, 3] = 0  # closed one way only, (2, 2) -> (2, 1) (slot N): still one wall
    conn[2, 3, 6] = conn[1, 2, 4] = 0  # a closed diagonal: not drawn
    fig, ax = _axes()
    plot.draw_map(ax, path_map_graph(conn, directed=True))
    raw = _segments_by_gid(ax, plot.WALL_GID)
    assert len(raw) == 2
    segments = {frozenset(map(tuple, s.tolist())) for s in raw}
    assert segments == {frozenset({(0.5, -0.5), (0.5, 0.5)}), frozenset({(1.5, 1.5), (2.5, 1.5)})}


def test_draw_map_random_path_map_matches_wall_oracle():
    conn = random_path_map(9, 7, seed=4, extra=0.3)
    fig, ax = _axes()
    plot.draw_map(ax, path_map_graph(conn))
    segments = _segments_by_gid(ax, plot.WALL_GID)
    expected = _walls_oracle(conn)
    assert len(expected) > 10
    assert len(segments) == len(expected)
    assert {_wall_of_segment(s) for s in segments} == expected


def test_draw_map_general_graph_draws_each_edge_once():
    weights = np.array([[0, 1, 0, 2],
                        [1, 0, 3, 0],
                        [0, 0, 0, 1],  # 2 -> 3 only; 1 -> 2 only
                        [2, 0, 1, 0]], dtype=float)
    xy = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    graph = dense_graph(weights, xy=xy)
    fig, ax = _axes()
    plot.draw_map(ax, graph, start=(0.0, 0.0), goal=2)
    segments = _segments_by_gid(ax, plot.EDGE_GID)
    drawn = {frozenset(map(tuple, s.tolist())) for s in segments}
    pairs = [(0, 1), (0, 3), (1, 2), (2, 3)]
    assert len(segments) == 4
    assert drawn == {frozenset({tuple(xy[i]), tuple(xy[j])}) for i, j in pairs}
    (dots,) = ax.collections[1:]
    np.testing.assert_array_equal(dots.get_offsets(), xy)
    assert ax.get_ylim()[0] < ax.get_ylim()[1]  # ordinary axes for general graphs
    assert [line.get_label() for line in ax.lines] == ["start", "goal"]


# --- plot_solutions -------------------------------------------------------------------------

def test_plot_solutions_writes_png_atomically(grid, tmp_path):
    start, goal = (0, 0), (0, 4)
    solutions = {"Dijkstra": dijkstra(grid, start, goal), "A*": astar(grid, start, goal)}
    target = tmp_path / "new" / "dir" / "paths.png"
    fig = plot.plot_solutions(grid, solutions, start=start, goal=goal, title="t", path=target)
    assert isinstance(fig, Figure)
    assert target.read_bytes()[:8] == PNG_SIGNATURE
    height, width = mpimg.imread(target).shape[:2]
    assert height > 0 and width > 0
    assert os.listdir(target.parent) == ["paths.png"]  # no temporary file left behind
    cost = float(solutions["A*"].cost)
    (ax,) = [a for a in fig.axes if a.get_legend() is not None]
    assert _legend_texts(ax) == [f"Dijkstra ({cost:.2f})", f"A* ({cost:.2f})", "start", "goal"]


def test_plot_solutions_field_and_no_path_label(grid, tmp_path):
    blocked = grid_graph(np.vstack([OBSTACLES[:3], np.ones((1, 6), bool), OBSTACLES[4:]]))
    solutions = {"Dijkstra": dijkstra(blocked, (0, 0), (0, 4))}
    assert not bool(solutions["Dijkstra"].found)
    field = np.asarray(distance_field(blocked, 0))
    fig = plot.plot_solutions(blocked, solutions, start=(0, 0), goal=(0, 4), field=field,
                              field_label="distance")
    main, colorbar = fig.axes
    assert _legend_texts(main) == ["Dijkstra (no path)", "start", "goal"]
    assert colorbar.get_ylabel() == "distance"
    (image,) = main.images
    assert np.ma.getmaskarray(image.get_array())[4].all()  # row 4 is unreachable: masked


def test_save_png_interrupted_leaves_old_file_and_no_temporary(tmp_path, monkeypatch):
    target = tmp_path / "figure.png"
    target.write_bytes(b"old")
    fig, ax = _axes()

    def broken_savefig(file, **kwargs):
        file.write(PNG_SIGNATURE + b"half")
        raise KeyboardInterrupt

    monkeypatch.setattr(fig, "savefig", broken_savefig)
    with pytest.raises(KeyboardInterrupt):
        plot.save_png(fig, target)
    assert target.read_bytes() == b"old"
    assert os.listdir(tmp_path) == ["figure.png"]


def test_draw_trace_plots_the_run_and_the_optimum():
    import jax.numpy as jnp

    from jaxswarm.plot.graph import draw_trace
    from jaxswarm.swarm import Trace

    nan = float("nan")
    trace = Trace(best_cost=jnp.array([jnp.inf, 12.0, 10.0, nan]),
                  iteration_cost=jnp.array([jnp.inf, 12.0, 10.5, nan]),
                  arrived=jnp.array([0.0, 0.2, 0.5, nan]), iterations=jnp.int32(3),
                  moves=jnp.array([40, 31, 30, 0]), lane_steps=jnp.array([64, 48, 48, 0]),
                  evaluations=jnp.array([0, 2, 5, 0]))
    fig, ax = plt.subplots()
    best, each, optimum = draw_trace(ax, trace, optimum=9.5)
    np.testing.assert_array_equal(best.get_xdata(), [1, 2, 3])
    np.testing.assert_array_equal(best.get_ydata(), [np.nan, 12.0, 10.0])  # inf: a gap
    np.testing.assert_array_equal(each.get_ydata(), [np.nan, 12.0, 10.5])
    assert optimum.get_ydata()[0] == 9.5
    plt.close(fig)


@pytest.mark.parametrize("swarm_run", ["rfd_star"], indirect=True)
def test_plot_swarm_run_writes_two_panels(swarm_run, tmp_path):
    from jaxswarm.plot.graph import plot_swarm_run

    swarm, graph, task, state, trace = swarm_run
    best = swarm.best(state)
    optimum = dijkstra(graph, int(task.start), int(task.goal)).cost
    out = tmp_path / "run.png"
    fig = plot_swarm_run(graph, state.altitude, best, trace, start=int(task.start),
                         goal=int(task.goal), optimum=optimum, field_label="altitude", path=out)
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    shown = fig.axes[0].get_images()[0].get_array()
    altitude = np.asarray(state.altitude)
    hidden = np.ma.getmaskarray(shown).ravel()
    np.testing.assert_array_equal(hidden, ~np.asarray(graph.free) | ~np.isfinite(altitude))
    np.testing.assert_allclose(shown.compressed(), altitude[~hidden], rtol=1e-6)
    trace_axes = [ax for ax in fig.axes if ax.get_xlabel() == "iteration"]
    assert len(trace_axes) == 1
    lines = trace_axes[0].get_lines()
    assert lines[0].get_ydata()[-1] == float(best.cost)
    assert lines[-1].get_ydata()[0] == optimum
    plt.close(fig)
