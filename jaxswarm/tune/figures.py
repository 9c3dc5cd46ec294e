"""The race drawn: each setting's life over the instances of every race of an iterated race."""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd


LABELLED = 40
"""A panel names its settings on the axis when it has at most this many."""


def race_figure(race: pd.DataFrame, path, *, title: str = "") -> Path:
    """Draw ``race`` (the log :func:`jaxswarm.tune.race.iterated_race` returns) to ``path``:
    one panel per iteration, a setting per row (by the instance it reached), a bar over the
    instances it ran on, red where a test dropped it and blue where it survived the race (with a
    cross or a dot, and its number on the axis, when the panel has at most :data:`LABELLED`
    settings); returns ``path``."""
    path = Path(path)
    iterations = sorted(race["iteration"].unique())
    figure, axes = plt.subplots(1, len(iterations), figsize=(3.2 * len(iterations), 4.2),
                                squeeze=False, sharey=False)
    for ax, iteration in zip(axes[0], iterations):
        rows = race[race["iteration"] == iteration]
        order = rows.groupby("setting")["step"].max().sort_values(kind="stable")
        crowded = len(order) > LABELLED
        for y, (setting, last) in enumerate(order.items()):
            mine = rows[rows["setting"] == setting]
            dropped = (mine["dropped"] != "").any()
            color = "tab:red" if dropped else "tab:blue"
            ax.plot([mine["step"].min() - 0.5, last + 0.5], [y, y], color=color,
                    linewidth=0.6 if crowded else 2)
            if not crowded:
                ax.plot(last + 0.5, y, "x" if dropped else "o", color=color, markersize=4)
        ax.set_title(f"iteration {iteration}: {len(order)} settings", fontsize=9)
        ax.set_xlabel("instance of the race")
        if crowded:
            ax.set_yticks([])
        else:
            ax.set_yticks(range(len(order)), [str(s) for s in order.index], fontsize=6)
    axes[0][0].set_ylabel("setting (dropped: red, survived: blue)")
    figure.suptitle(title, fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path
