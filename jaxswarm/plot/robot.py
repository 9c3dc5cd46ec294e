"""Figures of the robot of :mod:`jaxswarm.dynamic.robot`: its walk, its plans and the blocks it found.

What is drawn on the map the robot knew at the start: the hidden blocks, faint until found
(cells as squares, passages as crosses on their midpoint) and red once found, the plan it is
following (blue), the way it has walked and the robot itself (orange).
"""
from __future__ import annotations

import jax
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from jaxswarm.dynamic.events import Event
from jaxswarm.dynamic.robot import RobotWalk
from jaxswarm.plot.graph import draw_map, save_gif, save_png
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import trim

FOUND = "tab:red"
UNKNOWN = "#f4a6a6"


def robot_frames(walk: RobotWalk) -> list[tuple[int, int, int]]:
    """Host-side: the moments of a walk, as ``(plan, moves walked, plans whose findings are
    known)``: every node of every plan the robot walked, then, where a plan was blocked, the
    moment it found the block."""
    walk = jax.device_get(walk)
    frames, walked = [], 0
    for p in range(int(walk.plans)):
        plan = trim(walk.plan_paths[p])
        stand = int(walk.seen.start[p])
        stop = int(np.nonzero(plan == stand)[0][0]) if stand >= 0 else max(len(plan) - 1, 0)
        frames += [(p, walked + t, p) for t in range(stop + 1)]
        walked += stop
        if stand >= 0:
            frames.append((p, walked, p + 1))
    return frames


def draw_robot(ax: Axes, known: Graph, hidden: Event, walk: RobotWalk, *, start, goal,
               frame: tuple[int, int, int] | None = None, title: str | None = None):
    """Draw the robot's world at one moment (default: the end of the walk).

    Args:
      ax: the axes.
      known: the map the robot knew at the start.
      hidden: the hidden blocks of its world.
      walk: what it did.
      start, goal: its start and goal.
      frame: a moment of :func:`robot_frames`.
      title: the axes title.

    Returns:
      A function ``show(frame)`` that redraws the changing parts for another moment (for an
      animation), returning the artists it changed.
    """
    walk = jax.device_get(walk)
    xy = np.asarray(known.xy)
    draw_map(ax, known, start=start, goal=goal, title=title)
    markers = {"cells": "s", "passages": "X"}
    hidden_spots = _spots(known, hidden.block, hidden.close)
    found = {}
    for kind, spots in hidden_spots.items():
        if len(spots):
            ax.scatter(*spots.T, marker=markers[kind], s=30, color=UNKNOWN, zorder=3,
                       label=f"hidden {kind}")
            found[kind] = ax.scatter([], [], marker=markers[kind], s=30, color=FOUND, zorder=4,
                                     label=f"found {kind}")
    (plan_line,) = ax.plot([], [], color="tab:blue", linewidth=2, zorder=4, label="plan")
    (trail,) = ax.plot([], [], color="tab:orange", linewidth=2.5, zorder=5, label="walked")
    (robot,) = ax.plot([], [], marker="o", color="tab:orange", markeredgecolor="black",
                       markersize=9, linestyle="none", zorder=6, label="robot")
    trajectory = trim(walk.trajectory)
    seen = [_spots(known, walk.seen.block[p], walk.seen.close[p])
            for p in range(int(walk.plans))]

    def show(moment):
        plan, moves, known_plans = moment
        nodes = trim(walk.plan_paths[plan])
        plan_line.set_data(xy[nodes, 0], xy[nodes, 1])
        here = trajectory[:moves + 1]
        trail.set_data(xy[here, 0], xy[here, 1])
        robot.set_data(xy[here[-1:], 0], xy[here[-1:], 1])
        for kind, artist in found.items():
            artist.set_offsets(np.concatenate([np.zeros((0, 2))]
                                              + [spots[kind] for spots in seen[:known_plans]]))
        return plan_line, trail, robot, *found.values()

    frames = robot_frames(walk)
    show(frame or frames[-1])
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.03), ncols=3, frameon=False,
              fontsize="small")
    return show


def plot_robot(known: Graph, hidden: Event, walk: RobotWalk, *, start, goal, title=None,
               path=None) -> Figure:
    """A figure of the whole walk (see :func:`draw_robot`), saved as a PNG when ``path`` is
    given."""
    fig, ax = plt.subplots(figsize=(6, 6.6), layout="constrained")
    draw_robot(ax, known, hidden, walk, start=start, goal=goal, title=title)
    if path is not None:
        save_png(fig, path)
    return fig


def animate_robot(known: Graph, hidden: Event, walk: RobotWalk, path, *, start, goal,
                  title: str = "plan {plan}, move {move}", interval_ms: int = 150,
                  max_frames: int = 150) -> None:
    """Write a GIF of the robot walking, finding blocks and re-planning, atomically.

    Args:
      known, hidden, walk, start, goal: as :func:`draw_robot`.
      path: the GIF to write.
      title: the axes title, formatted with ``plan`` and ``move`` (1-based).
      interval_ms: time between frames.
      max_frames: at most this many frames: moves are skipped evenly beyond it, the moments a
        block is found never.
    """
    frames = robot_frames(walk)
    if len(frames) > max_frames:
        every = -(-len(frames) // max_frames)
        frames = [f for i, f in enumerate(frames)
                  if i % every == 0 or f[2] > f[0] or i == len(frames) - 1]
    fig, ax = plt.subplots(figsize=(6, 6.6), layout="constrained")
    show = draw_robot(ax, known, hidden, walk, start=start, goal=goal, frame=frames[0])

    def step(i):
        plan, moves, _ = frames[i]
        ax.set_title(title.format(plan=plan + 1, move=moves))
        return show(frames[i])

    save_gif(FuncAnimation(fig, step, frames=len(frames), interval=interval_ms, blit=False),
             path, interval_ms)
    plt.close(fig)


def _spots(known: Graph, cells, pairs) -> dict[str, np.ndarray]:
    """Where to draw blocks: ``cells`` (i32[M] nodes) at their centres, ``pairs`` (i32[E, 2]
    passages as (node, slot)) at their midpoints; -1 entries skipped. f[., 2] per kind."""
    xy = np.asarray(known.xy)
    cells, pairs = np.asarray(cells), np.asarray(pairs)
    pairs = pairs[pairs[:, 0] >= 0]
    heads = np.asarray(known.nbr)[pairs[:, 0], pairs[:, 1]]
    return {"cells": xy[cells[cells >= 0]], "passages": (xy[pairs[:, 0]] + xy[heads]) / 2}
