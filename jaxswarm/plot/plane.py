"""Figures of planes (:mod:`jaxswarm.world.plane`): the rectangles, the start and the goal, the
shortest path, and vehicle trajectories with the sensor windows they saw (the bees)."""
from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PatchCollection
from matplotlib.patches import Rectangle

from jaxswarm.world.plane import Plane


def draw_plane(ax: Axes, plane: Plane, *, start=None, goal=None, title=None) -> Axes:
    """Draw the plane's rectangles (grey) on ``ax``, with the start (green) and the goal (red)
    if given as ``(x, y)``; equal axes spanning the plane."""
    boxes = plane.obstacles()
    ax.add_collection(PatchCollection(
        [Rectangle((x0, y0), x1 - x0, y1 - y0) for x0, y0, x1, y1 in boxes],
        facecolor="0.35", edgecolor="0.2", linewidth=0.5))
    width, height = np.asarray(plane.extent, np.float64)
    ax.set_xlim(0, width)
    ax.set_ylim(0, height)
    ax.set_aspect("equal")
    for point, color, label in ((start, "tab:green", "start"), (goal, "tab:red", "goal")):
        if point is not None:
            ax.plot(*point, "o", color=color, markersize=7, label=label, zorder=4)
    if title:
        ax.set_title(title)
    return ax


def draw_trajectory(ax: Axes, waypoints, *, label=None, color=None, window=None,
                    every: int = 1, linestyle="-") -> None:
    """Draw a trajectory f[L, 2] (NaN-padded rows are skipped) on ``ax``; with ``window`` (the
    sensor window's side) also the square the vehicle saw at every ``every``-th waypoint."""
    points = np.asarray(waypoints, np.float64)
    points = points[~np.isnan(points).any(axis=1)]
    (line,) = ax.plot(points[:, 0], points[:, 1], linestyle, color=color, label=label,
                      linewidth=1.3, marker="." if window else None, markersize=3, zorder=3)
    if window:
        half = window / 2
        ax.add_collection(PatchCollection(
            [Rectangle((x - half, y - half), window, window) for x, y in points[:-1:every]],
            facecolor="none", edgecolor=line.get_color(), linewidth=0.5, alpha=0.45))
