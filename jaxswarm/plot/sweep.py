"""Figures from a sweep's results: heat maps over two params, lines over one, faceted by map,
and one replayed row (:func:`plot_replay`).

The figures of many runs take the DataFrame of :func:`jaxswarm.sweep.read_results` (one row per
run with the swept params as columns) and aggregate over seeds (and over any params not drawn).
"""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib import patheffects

from jaxswarm.plot.graph import draw_trace, plot_swarm_run, save_png
from jaxswarm.plot.memory import memory_view
from jaxswarm.plot.plane import draw_plane, draw_trajectory
from jaxswarm.sweep.replay import Replayed
from jaxswarm.world.plane import Plane

METRICS = {"success": "success rate", "gap": "mean gap to the optimum"}


def _check_columns(frame: pd.DataFrame, *columns: str) -> None:
    missing = [c for c in columns if c not in frame.columns]
    if missing:
        raise ValueError(f"no column {', '.join(map(repr, missing))} in the results (columns: "
                         f"{', '.join(frame.columns)})")


def summary(frame: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    """Per group of ``by`` columns: runs, success rate, mean and std of the gap (inf gaps, i.e.
    runs without a path, count as failures and are left out of the gap), found rate."""
    _check_columns(frame, *by, "success", "gap", "found")
    finite = frame.assign(gap=frame["gap"].where(np.isfinite(frame["gap"])))
    grouped = finite.groupby(by, sort=True)
    return pd.DataFrame(dict(runs=grouped.size(), success=grouped["success"].mean(),
                             found=grouped["found"].mean(), gap=grouped["gap"].mean(),
                             gap_std=grouped["gap"].std(ddof=0))).reset_index()


def heatmap_figure(frame: pd.DataFrame, x: str, y: str, metric: str = "success"):
    """A figure with one heat map per map: ``metric`` (``"success"`` or ``"gap"``) over params
    ``x`` (columns) and ``y`` (rows), each cell annotated with its value."""
    if metric not in METRICS:
        raise ValueError(f"metric must be one of {', '.join(METRICS)}, got {metric!r}")
    table = summary(frame, ["map", y, x])
    maps = list(dict.fromkeys(frame["map"]))
    fig, axes = plt.subplots(1, len(maps), figsize=(4.4 * len(maps), 3.8), squeeze=False,
                             layout="constrained")  # keeps each colour bar clear of the next map
    for ax, name in zip(axes[0], maps):
        grid = table[table["map"] == name].pivot(index=y, columns=x, values=metric)
        image = ax.imshow(grid.to_numpy(dtype=float), origin="lower", aspect="auto",
                          cmap="viridis" if metric == "success" else "magma_r",
                          vmin=0.0 if metric == "success" else None,
                          vmax=1.0 if metric == "success" else None)
        ax.set_xticks(range(grid.shape[1]), [f"{v:g}" for v in grid.columns], rotation=45)
        ax.set_yticks(range(grid.shape[0]), [f"{v:g}" for v in grid.index])
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.set_title(f"{name}: {METRICS[metric]}", fontsize=10)
        for (row, col), value in np.ndenumerate(grid.to_numpy(dtype=float)):
            ax.text(col, row, "n/a" if np.isnan(value) else f"{value:.2f}", ha="center",
                    va="center", fontsize=7, color="black",
                    path_effects=[patheffects.withStroke(linewidth=2, foreground="white")])
        fig.colorbar(image, ax=ax, shrink=0.8, label=METRICS[metric])
    return fig


def line_figure(frame: pd.DataFrame, x: str, *, log: bool = False):
    """A figure with one panel per map: the mean gap over param ``x`` (on a log axis if
    ``log``) with a band of one standard deviation over seeds, and the success rate on a second
    axis."""
    table = summary(frame, ["map", x])
    maps = list(dict.fromkeys(frame["map"]))
    fig, axes = plt.subplots(1, len(maps), figsize=(4.4 * len(maps), 3.4), squeeze=False,
                             layout="constrained")
    for ax, name in zip(axes[0], maps):
        rows = table[table["map"] == name]
        ax.plot(rows[x], rows["gap"], marker="o", color="tab:blue", label="mean gap")
        ax.fill_between(rows[x], rows["gap"] - rows["gap_std"], rows["gap"] + rows["gap_std"],
                        color="tab:blue", alpha=0.2)
        ax.set_xlabel(x)
        if log:
            ax.set_xscale("log")
        ax.set_ylabel("gap to the optimum", color="tab:blue")
        rate = ax.twinx()
        rate.plot(rows[x], rows["success"], marker="s", color="tab:green", label="success")
        rate.set_ylim(-0.05, 1.05)
        rate.set_ylabel("success rate", color="tab:green")
        ax.set_title(name, fontsize=10)
    return fig


def plot_sweep(frame: pd.DataFrame, params: list[str], out_dir,
               log_scale=frozenset()) -> list[Path]:
    """Write the standard figures of a sweep next to its results and return their paths:
    heat maps of success and gap over the first two swept ``params`` (if two or more), and one
    line figure per swept param (on a log axis for those in ``log_scale``, e.g. the spec's)."""
    out_dir = Path(out_dir)
    for name in params:
        _check_columns(frame, name)
    written = []
    if len(params) >= 2:
        x, y = params[0], params[1]
        for metric in METRICS:
            path = out_dir / f"heatmap_{metric}_{y}_vs_{x}.png"
            _save(heatmap_figure(frame, x, y, metric), path)
            written.append(path)
    for name in params:
        path = out_dir / f"line_{name}.png"
        _save(line_figure(frame, name, log=name in log_scale), path)
        written.append(path)
    return written


def plot_replay(replayed: Replayed, path) -> Path:
    """Write the figure of a replayed row to ``path`` (PNG) and return it: on a graph the
    swarm's memory with its best path, on a plane the best trajectory; beside it the run's
    convergence, titled with whether the replay reproduced the row."""
    row, world = replayed.row, replayed.sweep_map.world
    solution = replayed.swarm.best(replayed.state)
    verdict = "reproduces the row" if replayed.reproduced else "differs from the row"
    title = f"{replayed.title}: {verdict}"
    start, goal = replayed.sweep_map.start, replayed.sweep_map.goal
    if isinstance(world, Plane):
        fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.5))
        draw_plane(left, world, start=start, goal=goal)
        draw_trajectory(left, solution.path, label=f"best ({float(solution.cost):.2f})",
                        color="tab:red")
        left.legend(loc="upper right")
        draw_trace(right, replayed.trace, optimum=row.get("optimum"))
        fig.suptitle(title)
    else:
        view = memory_view(replayed.swarm)
        fig = plot_swarm_run(world, view.of(replayed.state), solution, replayed.trace,
                             start=start, goal=goal, optimum=row.get("optimum"),
                             field_label=view.label, title=title)
    _save(fig, Path(path))
    return Path(path)


def _save(fig, path: Path) -> None:
    try:
        save_png(fig, path)
    finally:
        plt.close(fig)
