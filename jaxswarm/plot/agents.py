"""Figures of many agents on one map (:mod:`jaxswarm.multiagent`): their paths, and a GIF of them
moving step by step.

Every agent has its own colour (:func:`agent_colors`). Its start is a filled square, its goal a
hollow ring and, in the animation, the agent itself a filled dot, so an agent that has arrived is
a dot inside its ring. Paths are ``i32[A, T]`` node indices, one row per agent and one column per
time step, as in :class:`jaxswarm.multiagent.Plan`. Coordinates follow :mod:`jaxswarm.plot.graph`:
cell ``(x, y)`` is centred at ``(x, y)``, with ``y`` growing downwards on grids.
"""
from __future__ import annotations

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from PIL import Image

from jaxswarm.plot.graph import draw_map
from jaxswarm.runtime.atomic import atomic_path
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import as_node

GIF_AGENTS = 100
"""The most agents :func:`animate_plan` draws by default (beyond, an even sample)."""

MAX_LEGEND = 10
"""Agents are named in a legend up to this many."""


def agent_colors(agents: int) -> np.ndarray:
    """f32[A, 4] RGBA colours, one per agent: ``tab10`` for up to 10 agents, ``tab20`` up to
    20, evenly spaced hues of ``hsv`` beyond."""
    if agents <= 10:
        return np.asarray(matplotlib.colormaps["tab10"](np.arange(agents)), np.float32)
    if agents <= 20:
        return np.asarray(matplotlib.colormaps["tab20"](np.arange(agents)), np.float32)
    return np.asarray(matplotlib.colormaps["hsv"](np.arange(agents) / agents), np.float32)


def draw_plan(graph: Graph, paths, ax: Axes | None = None, *, goals=None, colors=None,
              title: str | None = None, legend: bool | None = None) -> Axes:
    """Draw the map and every agent's path in its own colour, its start (filled square) and its
    goal (hollow ring).

    Args:
      graph: the map (N nodes).
      paths: i32[A, T] node indices, row a = agent a's node at steps 0..T-1 (a
        :class:`~jaxswarm.multiagent.Plan`'s ``paths``).
      ax: the axes to draw into (default: a new 6 x 6 inch figure's).
      goals: the agents' goals, (x, y) cells or node indices (default: each row's last node,
        which is the goal of a solved plan).
      colors: A matplotlib colours (default :func:`agent_colors`).
      title: the axes title.
      legend: name the agents in a legend (default: when there are at most ``MAX_LEGEND``).

    Returns:
      The axes (``ax.figure`` is the figure; close it with ``plt.close``).

    Raises:
      ValueError: ``paths`` is not [A, T] nodes of the map, or ``goals``/``colors`` has not one
        entry per agent.
    """
    paths, goals, colors = _checked(graph, paths, goals, colors)
    if ax is None:
        _, ax = plt.subplots(figsize=(6, 6), layout="constrained")
    xy = np.asarray(graph.xy)
    draw_map(ax, graph, title=title)
    size = _marker_size(ax, graph)
    for a, row in enumerate(paths):
        ax.plot(xy[row, 0], xy[row, 1], color=colors[a], linewidth=2, alpha=0.8, zorder=3,
                solid_capstyle="round", solid_joinstyle="round", label=f"agent {a}")
    ax.scatter(xy[paths[:, 0], 0], xy[paths[:, 0], 1], s=size, marker="s", c=colors,
               edgecolors="black", linewidths=0.5, zorder=4)
    _draw_goals(ax, xy[goals], colors, size)
    if legend if legend is not None else len(paths) <= MAX_LEGEND:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.02), ncols=5, frameon=False,
                  fontsize="small")
    return ax


def animate_plan(graph: Graph, paths, path, *, goals=None, colors=None, fps: float = 4,
                 trail: int = 3, substeps: int = 1, title: str = "step {step} of {steps}",
                 max_frames: int = 300, max_agents: int = GIF_AGENTS) -> int:
    """Write a GIF of the agents moving step by step, atomically: each agent a coloured dot, its
    goal a hollow ring of the same colour, its last ``trail`` moves a faint line.

    Frame ``k`` shows step ``k`` (and, with ``substeps`` > 1, ``substeps - 1`` frames in
    between, where each agent is part of the way along its move). Beyond ``max_frames`` frames,
    steps are skipped evenly (the first and the last step always show). Beyond ``max_agents``
    agents, an even sample of them is drawn (agents 0, k, 2k, ..., the last), and the title
    says how many of how many: hundreds of dots on a small map are not readable.

    Args:
      graph: the map (N nodes).
      paths: i32[A, T] node indices, as :func:`draw_plan`'s.
      path: the GIF to write (parent directories are created; an existing file is replaced
        only once the new one is complete, and nothing is left behind on an error).
      goals, colors: as :func:`draw_plan`'s.
      fps: frames per second.
      trail: how many past steps each agent's trail covers (0: none).
      substeps: frames per step (1: one frame per step, agents jump from node to node).
      title: the axes title, formatted with ``step`` (0-based) and ``steps`` (T - 1). Keep
        ``{step}`` in it: the GIF writer merges identical consecutive frames.
      max_frames: at most this many frames.
      max_agents: at most this many agents drawn.

    Returns:
      The number of frames written: ``(T - 1) * substeps + 1`` (or fewer, at ``max_frames``).

    Raises:
      ValueError: as :func:`draw_plan`, or ``fps`` not positive, ``substeps`` or
        ``max_agents`` below 1, ``max_frames`` below 2 or ``trail`` negative.
    """
    paths, goals, colors = _checked(graph, paths, goals, colors)
    _check_animation(fps, substeps, max_frames, trail)
    if max_agents < 1:
        raise ValueError(f"max_agents must be at least 1, got {max_agents}")
    agents = paths.shape[0]
    if agents > max_agents:
        drawn = np.unique(np.linspace(0, agents - 1, max_agents).round().astype(np.int64))
        paths, goals, colors = paths[drawn], goals[drawn], [colors[i] for i in drawn]
        title = f"{title}\n{len(drawn)} of {agents} agents drawn"
    times = _frame_times(paths.shape[1], substeps, max_frames)
    xy = np.asarray(graph.xy, np.float64)
    fig, ax = plt.subplots(figsize=(6, 6.3), layout="constrained")
    try:
        draw_map(ax, graph)
        size = _marker_size(ax, graph)
        _draw_goals(ax, xy[goals], colors, size)
        show, moving = _moving_agents(ax, xy, paths, colors, size, times, trail=trail,
                                      title=title, substeps=substeps)
        show(0)  # the title, for the layout
        _write_gif(fig, show, [*moving, ax.title], len(times), path, fps)
    finally:
        plt.close(fig)
    return len(times)


def drawn_agents(agents: int, max_agents: int = GIF_AGENTS) -> int:
    """How many of ``agents`` :func:`animate_plan` draws."""
    return min(agents, max_agents)


def _check_animation(fps: float, substeps: int, max_frames: int, trail: int) -> None:
    """Raise ValueError for an option of :func:`animate_plan` out of its range."""
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    for name, value, least in (("substeps", substeps, 1), ("max_frames", max_frames, 2),
                               ("trail", trail, 0)):
        if value < least:
            raise ValueError(f"{name} must be at least {least}, got {value}")


def _frame_times(steps: int, substeps: int, max_frames: int) -> np.ndarray:
    """f64[F] the (fractional) step each frame shows: ``substeps`` frames per step over
    ``steps`` steps, then, beyond ``max_frames``, evenly spaced ones keeping the first and the
    last moment."""
    times = np.linspace(0, steps - 1, (steps - 1) * substeps + 1)
    if len(times) > max_frames:
        keep = np.unique(np.round(np.linspace(0, len(times) - 1, max_frames)).astype(int))
        times = times[keep]
    return times


def _positions(xy: np.ndarray, paths: np.ndarray, t: float) -> np.ndarray:
    """f64[A, 2] the agents' positions at (fractional) step ``t``, part of the way between
    nodes mid-move. ``xy``: f64[N, 2] node coordinates; ``paths``: i64[A, T]."""
    steps = paths.shape[1]
    before = int(np.floor(t))
    after = min(before + 1, steps - 1)
    part = t - before
    return (1 - part) * xy[paths[:, before]] + part * xy[paths[:, after]]


def _moving_agents(ax: Axes, xy: np.ndarray, paths: np.ndarray, colors, size: float,
                   times: np.ndarray, *, trail: int, title: str, substeps: int):
    """Draw the agents (dots) and their trails at step 0, and say how to move them.

    Args:
      ax: the axes, its map and goals drawn.
      xy: f64[N, 2] node coordinates.
      paths: i64[A, T] node indices.
      colors: A matplotlib colours.
      size: the marker area (points^2).
      times: f64[F] the step each frame shows (:func:`_frame_times`).
      trail, title, substeps: as :func:`animate_plan`'s.

    Returns:
      ``(show, moving)``: ``show(k)`` puts the dots, the trails and the title at frame ``k``;
      ``moving``: the dots and the trails, the artists it changes besides the title.
    """
    steps = paths.shape[1]
    trails = [ax.plot([], [], color=colors[a], linewidth=2, alpha=0.45, zorder=3,
                      solid_capstyle="round")[0] for a in range(len(paths))]
    dots = ax.scatter(*_positions(xy, paths, 0).T, s=0.8 * size, c=colors, edgecolors="black",
                      linewidths=0.5, zorder=5)

    def show(k: int) -> None:
        t = times[k]
        now = _positions(xy, paths, t)
        dots.set_offsets(now)
        for a, line in enumerate(trails):
            if trail:
                past = xy[paths[a, max(0, int(np.ceil(t)) - trail):int(t) + 1]]
                line.set_data(*np.concatenate([past, now[a:a + 1]]).T)
        step = f"{t:.2f}" if substeps > 1 else str(int(t))
        ax.set_title(title.format(step=step, steps=steps - 1), fontsize="medium")

    return show, (dots, *trails)


def _write_gif(fig, show, animated, frames: int, path, fps: float) -> None:
    """Write ``frames`` frames as a GIF, atomically. ``show(k)`` sets up frame k, changing only
    the ``animated`` artists: the rest is drawn once and each frame restores that background
    and draws these on top (matplotlib's blitting), which is several times faster than a
    FuncAnimation drawing the whole figure three times a frame."""
    for artist in animated:
        artist.set_animated(True)
    fig.canvas.draw()
    background = fig.canvas.copy_from_bbox(fig.bbox)
    images = []
    for k in range(frames):
        fig.canvas.restore_region(background)
        show(k)
        for artist in animated:
            fig.draw_artist(artist)
        images.append(Image.fromarray(np.asarray(fig.canvas.buffer_rgba())).convert("RGB"))
    with atomic_path(path) as temporary:
        images[0].save(temporary, format="GIF", save_all=True, append_images=images[1:],
                       duration=max(1, round(1000 / fps)), loop=0)


def _checked(graph: Graph, paths, goals, colors):
    """(paths i32[A, T], goals i32[A], colors f[A, 4]) checked against the map."""
    paths = np.asarray(paths)
    if paths.ndim != 2 or paths.size == 0 or not np.issubdtype(paths.dtype, np.integer):
        raise ValueError(f"paths must be a non-empty integer [agents, steps] array, got "
                         f"shape {paths.shape} of {paths.dtype}")
    if paths.min() < 0 or paths.max() >= graph.num_nodes:
        raise ValueError(f"paths must hold node indices 0..{graph.num_nodes - 1}, got "
                         f"{paths.min()}..{paths.max()}")
    agents = paths.shape[0]
    if goals is None:
        goals = paths[:, -1]
    if len(goals) != agents:
        raise ValueError(f"{len(goals)} goals for {agents} agents")
    goals = np.array([as_node(graph, g, name=f"agent {a}'s goal", require_free=False)
                      for a, g in enumerate(goals)], np.int64)
    colors = agent_colors(agents) if colors is None else list(colors)
    if len(colors) != agents:
        raise ValueError(f"{len(colors)} colors for {agents} agents")
    return paths.astype(np.int64), goals, colors


def _draw_goals(ax: Axes, points: np.ndarray, colors, size: float) -> None:
    """Hollow rings in the agents' colours at ``points`` (f[A, 2])."""
    ax.scatter(points[:, 0], points[:, 1], s=1.6 * size, marker="o", facecolors="none",
               edgecolors=colors, linewidths=2, zorder=4)


def _marker_size(ax: Axes, graph: Graph) -> float:
    """A marker area (points^2) of about half a cell: the axes' width over the map's width."""
    xy = np.asarray(graph.xy)
    across = float(np.ptp(xy[:, 0])) + 1 if graph.is_grid else np.sqrt(graph.num_nodes)
    width_points = ax.get_position().width * ax.figure.get_figwidth() * 72
    return float(np.clip((0.55 * width_points / max(across, 1)) ** 2, 9, 400))
