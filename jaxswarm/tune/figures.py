"""The race drawn: each setting's life over the instances of every race of an iterated race."""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd


def race_figure(race: pd.DataFrame, path, *, title: str = "") -> Path:
    """Draw ``race`` (the log :func:`jaxswarm.tune.race.iterated_race` returns) to ``path``:
    one panel per iteration, a setting per row, a bar over the instances it ran on, ended by a
    cross where a test dropped it (and a dot where it survived the race); returns ``path``."""
    path = Path(path)
    iterations = sorted(race["iteration"].unique())
    figure, axes = plt.subplots(1, len(iterations), figsize=(3.2 * len(iterations), 4.2),
                                squeeze=False, sharey=False)
    for ax, iteration in zip(axes[0], iterations):
        rows = race[race["iteration"] == iteration]
        order = rows.groupby("setting")["step"].max().sort_values(kind="stable")
        for y, (setting, last) in enumerate(order.items()):
            mine = rows[rows["setting"] == setting]
            dropped = (mine["dropped"] != "").any()
            ax.plot([mine["step"].min() - 0.5, last + 0.5], [y, y],
                    color="tab:red" if dropped else "tab:blue", linewidth=2)
            ax.plot(last + 0.5, y, "x" if dropped else "o",
                    color="tab:red" if dropped else "tab:blue", markersize=4)
        ax.set_title(f"iteration {iteration}: {len(order)} settings", fontsize=9)
        ax.set_xlabel("instance of the race")
        ax.set_yticks(range(len(order)), [str(s) for s in order.index], fontsize=6)
    axes[0][0].set_ylabel("setting (dropped: red, survived: blue)")
    figure.suptitle(title, fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=120)
    plt.close(figure)
    return path
