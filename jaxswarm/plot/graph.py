"""Figures of maps, paths and per-node fields (matplotlib, object-oriented API only).

What is drawn:

* grids (``graph.shape == (H, W)``): the obstacles as an image (free cells white, blocked cells
  black) and every closed orthogonal edge (a thin wall, as in a path map or after an edge edit)
  as a short segment on the border between its two cells; closed diagonal edges are not drawn;
* general graphs (``graph.shape is None``): nodes as dots at ``graph.xy`` (blocked ones in grey)
  and valid edges as thin lines;
* paths as polylines through node centres, start and goal as markers, per-node fields (distance,
  altitude, pheromone) as heat maps with a colorbar.

Coordinate convention: data coordinates are ``graph.xy``, i.e. ``x`` = column and ``y`` = row on
grids, so cell ``(x, y)`` (node ``y * W + x``) is centred at ``(x, y)`` and covers
``[x - 0.5, x + 0.5] x [y - 0.5, y + 0.5]``. Grid axes put ``y = 0`` at the top and let ``y`` grow
downwards, like the row index of the map; general graphs keep ordinary axes (``y`` upwards).

Nothing here selects a backend or shows a window; callers own the figures they get (close them with
``plt.close(fig)``).
"""
from __future__ import annotations

import tempfile
from collections.abc import Mapping
from pathlib import Path

import matplotlib
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.image import AxesImage
from matplotlib.lines import Line2D

from jaxswarm.runtime.atomic import atomic_path, write_atomically
from jaxswarm.world.graph import Graph
from jaxswarm.world.lattice import OPPOSITE
from jaxswarm.world.paths import Solution, as_node, trim

MASKED_COLOR = "0.6"
"""Neutral grey for obstacles and non-finite values in :func:`draw_field`."""
ENDPOINT_STYLE = {"start": {"marker": "o", "color": "tab:green", "markersize": 11},
                  "goal": {"marker": "*", "color": "tab:red", "markersize": 16}}
"""Marker style of the start and goal."""
WALL_GID = "walls"
"""``gid`` of the LineCollection of thin walls drawn on grid maps."""
EDGE_GID = "edges"
"""``gid`` of the LineCollection of edges drawn for general graphs."""


def draw_map(ax: Axes, graph: Graph, *, start=None, goal=None, title=None) -> Axes:
    """Draw a map: obstacles and thin walls of a grid, or nodes and edges of a general graph.

    Args:
      ax: the axes to draw into.
      graph: the map (N nodes; grid if ``graph.shape`` is ``(H, W)``).
      start, goal: optional node index or (x, y) cell/coordinates, drawn as markers labelled
        "start" and "goal" (blocked nodes are accepted: the plot shows what is there).
      title: optional axes title.

    Returns:
      ``ax``.
    """
    if graph.is_grid:
        _draw_obstacles(ax, graph)
        _draw_walls(ax, graph)
    else:
        _draw_graph(ax, graph)
    _draw_endpoints(ax, graph, start, goal)
    if title is not None:
        ax.set_title(title)
    return ax


def draw_paths(ax: Axes, graph: Graph, paths, labels=None, *, colors=None,
               linewidth: float = 2) -> list[Line2D]:
    """Draw padded paths as polylines through node centres.

    Args:
      ax: the axes to draw into.
      graph: the map the paths live on (N nodes).
      paths: a sequence of P paths, each a :class:`~jaxswarm.world.paths.Solution` or an i32[L]
        node array with -1 padding (an i32[P, L] array works too).
      labels: optional P legend labels.
      colors: optional P matplotlib colours (default: the axes' colour cycle).
      linewidth: line width in points.

    Returns:
      P Line2D, in the order of ``paths``; an empty path gives an empty line, so indices match.

    Raises:
      ValueError: ``labels`` or ``colors`` of the wrong length, or a node index >= N.
    """
    paths = list(paths)
    for name, given in (("labels", labels), ("colors", colors)):
        if given is not None and len(given) != len(paths):
            raise ValueError(f"{name} has {len(given)} entries for {len(paths)} paths")
    xy = np.asarray(graph.xy)
    lines = []
    for i, path in enumerate(paths):
        nodes = trim(path.path if isinstance(path, Solution) else path)
        if nodes.size and nodes.max() >= graph.num_nodes:
            raise ValueError(f"path {i} visits node {nodes.max()}, but the map has "
                             f"{graph.num_nodes} nodes")
        style = {} if colors is None else {"color": colors[i]}
        (line,) = ax.plot(xy[nodes, 0], xy[nodes, 1], linewidth=linewidth, zorder=3,
                          solid_capstyle="round", solid_joinstyle="round",
                          label=None if labels is None else labels[i], **style)
        lines.append(line)
    return lines


def draw_field(ax: Axes, graph: Graph, values, *, cmap="viridis", label=None,
               log: bool = False) -> AxesImage:
    """Draw a per-node field as a heat map of a grid, with a colorbar.

    Obstacle cells and non-finite values (e.g. the inf of unreachable cells) are masked and shown
    in a neutral grey (``MASKED_COLOR``); with ``log=True`` non-positive values are masked too.

    Args:
      ax: the axes to draw into.
      graph: a grid map (``graph.shape == (H, W)``, N = H * W nodes).
      values: f[N] one value per node.
      cmap: colormap name or Colormap.
      label: colorbar label.
      log: logarithmic colour scale.

    Returns:
      The AxesImage; its array is the masked f[H, W] field (masked where hidden).

    Raises:
      ValueError: ``graph`` is a general graph, or ``values`` does not hold one value per node.
    """
    if not graph.is_grid:
        raise ValueError("draw_field needs a grid map (graph.shape is None: a general graph)")
    values = np.asarray(values, dtype=np.float64)
    if values.shape != (graph.num_nodes,):
        raise ValueError(f"values must have shape ({graph.num_nodes},), one per node, "
                         f"got {values.shape}")
    hidden = ~np.asarray(graph.free) | ~np.isfinite(values)
    norm = None
    if log:
        hidden |= values <= 0
        # LogNorm cannot autoscale to an all-masked field: give it any valid range then.
        norm = LogNorm(1, 10) if hidden.all() else LogNorm()
    field = np.ma.masked_array(values, mask=hidden).reshape(graph.shape)
    colormap = matplotlib.colormaps.get_cmap(cmap).with_extremes(bad=MASKED_COLOR)
    image = ax.imshow(field, cmap=colormap, norm=norm, interpolation="nearest",
                      **_grid_image_args(graph))
    ax.figure.colorbar(image, ax=ax, label=label)
    return image


def plot_solutions(graph: Graph, solutions: Mapping[str, Solution], *, start, goal, field=None,
                   title=None, path=None, field_label=None) -> Figure:
    """One figure of a map (or a field heat map) with labelled paths and their costs.

    Args:
      graph: the map (N nodes).
      solutions: name -> Solution; each path is labelled "name (cost)" in the legend, or
        "name (no path)" when not found.
      start, goal: node indices or (x, y).
      field: optional f[N] per-node field drawn as a heat map under the paths (grids only; see
        :func:`draw_field`), instead of the obstacle image.
      title: optional axes title.
      path: optional file path; the figure is saved there as a PNG (see :func:`save_png`).
      field_label: colorbar label of ``field``.

    Returns:
      The figure (managed by pyplot: close it with ``plt.close(fig)``).
    """
    fig, ax = plt.subplots(figsize=(7, 6))
    if field is None:
        draw_map(ax, graph, title=title)
    else:
        draw_field(ax, graph, field, label=field_label)
        _draw_walls(ax, graph)
        if title is not None:
            ax.set_title(title)
    labels = [f"{name} ({float(sol.cost):.2f})" if bool(sol.found) else f"{name} (no path)"
              for name, sol in solutions.items()]
    draw_paths(ax, graph, list(solutions.values()), labels)
    _draw_endpoints(ax, graph, start, goal)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncols=3, frameon=False)
    if path is not None:
        save_png(fig, path)
    return fig


def draw_trace(ax: Axes, trace, *, optimum=None, label=None) -> list[Line2D]:
    """Draw a swarm run's convergence: best cost so far per iteration (solid), each iteration's
    best (dots), the optimum as a dashed line, and the share of agents that arrived (right axis).

    Args:
      ax: the axes to draw into.
      trace: a :class:`jaxswarm.swarm.Trace` of one run (arrays f32[T]; NaN after the stop).
      optimum: the exact optimum (e.g. Dijkstra's cost), drawn as a horizontal line if given.
      label: legend label of the best-so-far line (default "best so far").

    Returns:
      The lines drawn on ``ax``: best so far, iteration best, and the optimum if given.
    """
    best = np.asarray(trace.best_cost, dtype=np.float64)
    ran = int(trace.iterations)
    iterations = np.arange(1, ran + 1)
    (best_line,) = ax.plot(iterations, _nan_if_inf(best[:ran]), lw=2,
                           label=label or "best so far")
    (each_line,) = ax.plot(iterations, _nan_if_inf(np.asarray(trace.iteration_cost)[:ran]), ".",
                           ms=4, alpha=0.6, label="iteration best")
    lines = [best_line, each_line]
    if optimum is not None:
        lines.append(ax.axhline(float(optimum), ls="--", color="k", lw=1, label="optimum"))
    ax.set_xlabel("iteration")
    ax.set_ylabel("path length")
    share = ax.twinx()
    share.fill_between(iterations, np.asarray(trace.arrived)[:ran], step="mid", alpha=0.15,
                       color="tab:green")
    share.set_ylim(0, 1)
    share.set_ylabel("share of agents that arrived", color="tab:green")
    ax.legend(loc="upper right", frameon=False)
    return lines


def plot_swarm_run(graph: Graph, field, solution: Solution, trace, *, start, goal, optimum=None,
                   field_label=None, title=None, path=None) -> Figure:
    """Two panels of one swarm run: its memory (altitude or pheromone per node, f[N]) as a heat
    map with the best path over it, and its convergence trace (see :func:`draw_trace`).

    Args:
      graph: a grid map.
      field: f[N] the swarm's per-node memory at the end of the run.
      solution: the run's best Solution.
      trace: the run's :class:`jaxswarm.swarm.Trace`.
      start, goal: node indices or (x, y).
      optimum: the exact optimum, drawn on the trace.
      field_label: colorbar label (e.g. "altitude").
      title: figure title.
      path: optional PNG file to write (atomically, see :func:`save_png`).

    Returns:
      The figure (close it with ``plt.close(fig)``).
    """
    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 5.5), layout="constrained")
    draw_field(left, graph, field, label=field_label)
    _draw_walls(left, graph)
    label = f"best ({float(solution.cost):.2f})" if bool(solution.found) else "best (no path)"
    draw_paths(left, graph, [solution], [label], colors=["tab:red"])
    _draw_endpoints(left, graph, start, goal)
    left.legend(loc="upper center", bbox_to_anchor=(0.5, -0.07), ncols=3, frameon=False)
    draw_trace(right, trace, optimum=optimum)
    if title is not None:
        fig.suptitle(title)
    if path is not None:
        save_png(fig, path)
    return fig


def animate_field(graph: Graph, frames, path, *, start=None, goal=None, label=None,
                  title=None, interval_ms: int = 200, log: bool = False) -> None:
    """Write a GIF of a per-node field changing over time (one frame per row of ``frames``),
    e.g. a swarm's altitude or pheromone re-forming after the map changed, atomically.

    Args:
      graph: a grid map (N nodes).
      frames: f[T, N] the field at T moments.
      path: the GIF to write (parent directories are created).
      start, goal: markers, as :func:`draw_map`'s.
      label: colorbar label; title: axes title, formatted with ``frame`` (e.g. "iteration
        {frame}").
      interval_ms: time between frames.
      log: logarithmic colour scale.

    Raises:
      ValueError: as :func:`draw_field`, or ``frames`` not [T, N].
    """
    frames = np.asarray(frames, dtype=np.float64)
    if frames.ndim != 2 or frames.shape[1] != graph.num_nodes:
        raise ValueError(f"frames must be [T, {graph.num_nodes}], got {frames.shape}")
    fig, ax = plt.subplots(figsize=(6, 6), layout="constrained")
    image = draw_field(ax, graph, frames[0], label=label, log=log)
    _draw_endpoints(ax, graph, start, goal)
    finite = frames[np.isfinite(frames)]
    if finite.size and not log:
        image.set_clim(finite.min(), finite.max())
    hidden = np.ma.getmaskarray(image.get_array())

    def show(t):
        image.set_data(np.ma.masked_array(frames[t].reshape(graph.shape),
                                          mask=hidden | ~np.isfinite(frames[t]).reshape(
                                              graph.shape)))
        if title is not None:
            ax.set_title(title.format(frame=t))
        return (image,)

    save_gif(FuncAnimation(fig, show, frames=frames.shape[0], interval=interval_ms, blit=False),
             path, interval_ms)
    plt.close(fig)


def save_gif(animation: FuncAnimation, path, interval_ms: int) -> None:
    """Write ``animation`` as a GIF (Pillow), ``interval_ms`` between frames, atomically."""
    # Pillow picks the format from the file name, so the GIF is made under its own name in a
    # scratch folder, then moved into place whole.
    with tempfile.TemporaryDirectory() as scratch:
        made = Path(scratch) / "animation.gif"
        animation.save(made, writer=PillowWriter(fps=max(1, round(1000 / interval_ms))))
        write_atomically(path, made.read_bytes())


def save_png(fig: Figure, path) -> None:
    """Save ``fig`` as a PNG (dpi 120, tight bounding box), atomically.

    Parent directories are created. The image is written to a temporary file in the same
    directory and moved into place with ``os.replace``, so an interrupted save never leaves a
    half-written file at ``path`` (an existing file stays intact until the new one is complete).
    """
    with atomic_path(path) as temporary, open(temporary, "wb") as file:
        fig.savefig(file, format="png", dpi=120, bbox_inches="tight")


def _nan_if_inf(values: np.ndarray) -> np.ndarray:
    """Costs to plot: inf (nothing arrived) becomes a gap."""
    return np.where(np.isfinite(values), values, np.nan)


def _grid_image_args(graph: Graph) -> dict:
    """imshow arguments that centre cell (x, y) on (x, y) with y growing downwards."""
    height, width = graph.shape
    return {"origin": "upper", "extent": (-0.5, width - 0.5, height - 0.5, -0.5)}


def _draw_obstacles(ax: Axes, graph: Graph) -> AxesImage:
    """bool[H, W] free cells as an image: free white, blocked black."""
    free = np.asarray(graph.free).reshape(graph.shape)
    return ax.imshow(free, cmap="gray", vmin=0, vmax=1, interpolation="nearest",
                     **_grid_image_args(graph))


def _draw_walls(ax: Axes, graph: Graph) -> LineCollection:
    """Closed orthogonal lattice edges as segments on the cell border; one per wall.

    A wall is counted once per pair of cells (from the E and S slots) and is drawn if the edge is
    closed in either direction. The segment is the edge rotated by 90 degrees about its midpoint:
    between (x, y) and (x + 1, y) it runs from (x + 0.5, y - 0.5) to (x + 0.5, y + 0.5).
    """
    nbr = np.asarray(graph.nbr)
    is_open = np.asarray(graph.open)
    xy = np.asarray(graph.xy)
    segments = []
    for k in (0, 1):  # E and S: each orthogonal neighbour pair once
        rows = np.nonzero(nbr[:, k] >= 0)[0]
        heads = nbr[rows, k]
        closed = ~is_open[rows, k] | ~is_open[heads, OPPOSITE[k]]
        tail_xy, head_xy = xy[rows[closed]], xy[heads[closed]]
        middle = (tail_xy + head_xy) / 2
        half = (head_xy - tail_xy)[:, ::-1] * np.array([-0.5, 0.5])
        segments.append(np.stack([middle - half, middle + half], axis=1))
    walls = LineCollection(np.concatenate(segments), colors="black", linewidths=2.5,
                           capstyle="round", zorder=2, gid=WALL_GID)
    ax.add_collection(walls)
    return walls


def _draw_graph(ax: Axes, graph: Graph) -> LineCollection:
    """Nodes of a general graph as dots (blocked in grey) and valid edges as thin lines.

    An edge usable in both directions is drawn once.
    """
    xy = np.asarray(graph.xy)
    rows, slots = np.nonzero(np.asarray(graph.valid_edges()))
    pairs = np.unique(np.sort(np.stack([rows, np.asarray(graph.nbr)[rows, slots]], axis=1),
                              axis=1), axis=0)
    edges = LineCollection(xy[pairs], colors="0.5", linewidths=0.8, zorder=1, gid=EDGE_GID)
    ax.add_collection(edges)
    free = np.asarray(graph.free)
    ax.scatter(xy[:, 0], xy[:, 1], s=12, c=np.where(free, "black", "0.75"), zorder=2)
    ax.set_aspect("equal")
    ax.autoscale_view()
    return edges


def _draw_endpoints(ax: Axes, graph: Graph, start, goal) -> None:
    """Start (green circle) and goal (red star) markers, labelled for the legend."""
    xy = np.asarray(graph.xy)
    for point, name in ((start, "start"), (goal, "goal")):
        if point is not None:
            x, y = xy[as_node(graph, point, name=name, require_free=False)]
            ax.plot([x], [y], linestyle="none", markeredgecolor="white", label=name, zorder=5,
                    **ENDPOINT_STYLE[name])
