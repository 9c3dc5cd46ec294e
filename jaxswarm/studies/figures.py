"""The figures of the tables: one panel per map in a grid, written as PNG files."""
from __future__ import annotations

import math
from pathlib import Path

from matplotlib import pyplot as plt
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from jaxswarm.plot.graph import save_png


def panel_grid(count: int, *, columns: int, width: float,
               height: float) -> tuple[Figure, list[Axes]]:
    """A figure of ``count`` panels, at most ``columns`` a row, each ``width`` x ``height``
    inches; the grid's unused panels are hidden.

    Returns:
      (the figure, its ``count`` panels in reading order).
    """
    rows, columns = math.ceil(count / columns), min(count, columns)
    fig, axes = plt.subplots(rows, columns, figsize=(width * columns, height * rows),
                             squeeze=False, layout="constrained")
    for ax in axes.flat[count:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:count])


def write_png(fig: Figure, path: Path) -> None:
    """Save ``fig`` as a PNG at ``path``, atomically (:func:`jaxswarm.plot.graph.save_png`), then
    close it."""
    save_png(fig, path)
    plt.close(fig)
