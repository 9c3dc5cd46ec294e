"""The RFD paper's nine maps as jaxswarm builds them, with their optima.

Prints, for each map of :mod:`jaxswarm.maps.paper`, its size, obstacle share, start and goal,
the optimum found by Dijkstra, A* and bidirectional A* (they must agree), the paper's published
Dijkstra length for its own (unpublished) map, and the ratio; ``--ascii`` also prints the maps
('#' blocked, '.' free, 'S' start, 'G' goal). Writes a 3 x 3 figure of the maps with their
optimal paths (``--out``, default ``out/paper_maps.png``).

Run from the repository root::

    python sweeps/paper_maps.py --ascii
"""
from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
from matplotlib import pyplot as plt

from jaxswarm.exact import astar, bidirectional_astar, dijkstra
from jaxswarm.maps.paper import PAPER_MAPS, PAPER_OPTIMA, paper_map
from jaxswarm.plot.graph import draw_map, draw_paths, save_png


def ascii_map(chosen) -> str:
    """The map as text: '#' blocked, '.' free, 'S' start, 'G' goal."""
    rows = [["#" if cell else "." for cell in row] for row in chosen.obstacles]
    for (x, y), mark in ((chosen.start, "S"), (chosen.goal, "G")):
        rows[y][x] = mark
    return "\n".join("".join(row) for row in rows)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--ascii", action="store_true", help="print the maps as text")
    parser.add_argument("--out", type=Path, default=Path("out/paper_maps.png"))
    args = parser.parse_args(argv)
    fig, axes = plt.subplots(3, 3, figsize=(13, 13))
    print(f"{'map':10} {'size':>8} {'blocked':>8} {'start':>9} {'goal':>9} "
          f"{'optimum':>8} {'paper':>8} {'ratio':>6}")
    for name, ax in zip(PAPER_MAPS, axes.flat):
        chosen = paper_map(name)
        graph = chosen.graph()
        costs = {planner(graph, chosen.start, chosen.goal).cost
                 for planner in (dijkstra, astar, bidirectional_astar)}
        if max(costs) - min(costs) > 1e-9 * max(costs):
            raise AssertionError(f"{name}: exact planners disagree: {sorted(costs)}")
        best = dijkstra(graph, chosen.start, chosen.goal)
        height, width = chosen.obstacles.shape
        print(f"{name:10} {width:>4}x{height:<3} {chosen.obstacles.mean():>8.1%} "
              f"{str(chosen.start):>9} {str(chosen.goal):>9} {best.cost:>8.2f} "
              f"{PAPER_OPTIMA[name]:>8.2f} {best.cost / PAPER_OPTIMA[name]:>6.3f}")
        if args.ascii:
            print(ascii_map(chosen) + "\n")
        draw_map(ax, graph, start=chosen.start, goal=chosen.goal,
                 title=f"{name}: {best.cost:.2f} (paper {PAPER_OPTIMA[name]:.2f})")
        draw_paths(ax, graph, [best], ["Dijkstra"])
        ax.get_legend() and ax.get_legend().remove()
    save_png(fig, args.out)
    plt.close(fig)
    print(f"figure written to {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
