"""The bees paper's inverse problem (section VI, eq. 11): brute force against optax, on maps #1
and #2, and the vehicle that remembers where it has been.

For each map, with the paper's settings (``--seeds`` K = 30 runs per weight setting, I = 3
colony cycles a step, M = 200 steps):

1. **Brute force** (the paper's method): every setting of a ``--grid`` of weights (default
   6 x 6 x 6: w1 in [0.6, 1.2], w2 in [0, 0.3], w3 in [0, 0.1]) scored by eq. 11 in one vmapped
   program (:func:`jaxswarm.swarm.bees.inverse.grid_search`); its landscape as a heat map.
2. **Evolution strategies with optax** (:func:`~jaxswarm.swarm.bees.inverse.es_search`) from the
   grid's middle, with as many direct-problem runs as the grid (``--pairs`` antithetic pairs a
   step, as many steps as the budget allows), on the same K seeds.
3. **Fresh seeds**: the best setting of each search and the paper's answer, scored again on K
   new seeds (K to 2K - 1), so that no method wins by the seeds it was chosen on; each also with
   the vehicle that remembers the windows it has seen (``remember``, the paper's future work).

Written to ``--out`` (default ``out/bees_inverse``; ``make reproduce`` uses
``results/bees_inverse``), each file atomically: ``landscape.csv`` (every grid setting),
``search.csv`` (every setting the optax search scored), ``fresh.csv``, ``table.md``,
``provenance.json`` and ``<map>.png`` (the landscape with the search's path over it).

Run from the repository root (about 15 minutes on 2 cores)::

    python sweeps/bees_inverse.py
    python sweeps/bees_inverse.py --maps map1 --seeds 4 --grid 2x2x2 --pairs 2
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import jax
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from jaxswarm.exact.visibility import shortest_path  # noqa: E402
from jaxswarm.maps.planes import PAPER_PLANES, paper_plane  # noqa: E402
from jaxswarm.runtime.atomic import write_csv  # noqa: E402
from jaxswarm.studies import provenance  # noqa: E402
from jaxswarm.studies.arguments import add_out_argument, check_counts, names_argument  # noqa: E402
from jaxswarm.studies.figures import write_png  # noqa: E402
from jaxswarm.swarm import definition, make, make_task  # noqa: E402
from jaxswarm.swarm.bees.inverse import (es_search, grid_search, make_scorer,  # noqa: E402
                                         weight_grid)


CYCLES = 3
"""The paper's colony cycles a step for the inverse problem."""
RANGES = ((0.6, 1.2), (0.0, 0.3), (0.0, 0.1))
"""The grid's range of w1, w2, w3 (ends included)."""
PAPER_ANSWER = {
    "map1": ((1.05, 0.2, 0.03), 30, 108.0, 28.0),
    "map2": ((0.73, 0.09, 0.03), 22, 147.0, 53.0),
}
"""The paper's weights per map and what it measured with them: target of 30, avgP, stdP."""

TITLE = "The bees paper's inverse problem: brute force, optax, fresh seeds"
ABOUT = ("Eq. 11, `avgP / (1 + target)` over K runs (`jaxswarm.swarm.bees.inverse`), minimised "
         "over the weights of `cabc` by the paper's brute force over a grid and by evolution "
         "strategies stepped with optax's Adam, with the same number of direct-problem runs. "
         "A setting whose vehicle never arrives scores the longest trajectory a vehicle can "
         "make. `remember` (the paper's future work, ours) adds a penalty for windows the "
         "vehicle has already seen.")

LANDSCAPE_COLUMNS = ["map", "w1", "w2", "w3", "target", "avg_length", "objective"]
SEARCH_COLUMNS = ["map", "step", "w1", "w2", "w3", "target", "avg_length", "objective"]
FRESH_COLUMNS = ["map", "setting", "remember", "w1", "w2", "w3", "seeds", "target",
                 "avg_length", "objective"]


def study(name: str, args) -> tuple[list[dict], list[dict], list[dict], dict]:
    """One map: the grid, the optax search and the fresh-seed scores; the rows of the three
    CSV files and what the figure needs."""
    chosen = paper_plane(name)
    task = make_task(chosen.plane, chosen.start, chosen.goal)
    seeds = np.arange(args.seeds)
    fresh = np.arange(args.seeds, 2 * args.seeds)
    swarms = {False: make("cabc"), True: make("cabc", remember=True)}
    params = swarms[False].default_params._replace(inner_iterations=np.float32(CYCLES))
    score = make_scorer(swarms[False], chosen.plane, task, params, seeds)
    grid = grid_search(score, weight_grid(RANGES, args.grid), args.seeds)
    steps = grid.runs // (2 * args.pairs * args.seeds)
    middle = np.asarray([(low + high) / 2 for low, high in RANGES], np.float32)
    search = es_search(jax.random.key(args.search_seed), score, middle, args.seeds,
                       steps=max(steps, 1), pairs=args.pairs, sigma=args.sigma,
                       learning_rate=args.learning_rate)
    landscape = [dict(map=name, w1=w[0], w2=w[1], w3=w[2], target=int(t), avg_length=a,
                      objective=o)
                 for w, a, t, o in zip(grid.weights, *grid.score)]
    tried = [dict(map=name, step=int(s), w1=w[0], w2=w[1], w3=w[2], target=int(t),
                  avg_length=a, objective=o)
             for s, w, a, t, o in zip(search.step, search.weights, *search.score)]
    settings = {"grid best": grid.best(), "optax best": search.best(),
                "paper": np.asarray(PAPER_ANSWER[name][0], np.float32)}
    rows = []
    for remember, swarm in swarms.items():
        on_fresh = make_scorer(swarm, chosen.plane, task, params, fresh)(
            np.stack(list(settings.values())))
        for (setting, w), a, t, o in zip(settings.items(), *jax.device_get(on_fresh)):
            rows.append(dict(map=name, setting=setting, remember=remember, w1=w[0], w2=w[1],
                             w3=w[2], seeds=len(fresh), target=int(t), avg_length=a,
                             objective=o))
    optimum, _ = shortest_path(chosen.plane, chosen.start, chosen.goal)
    figure = dict(grid=grid, search=search, optimum=optimum)
    return landscape, tried, rows, figure


def landscape_figure(path: Path, name: str, figure: dict) -> None:
    """Eq. 11 over (w1, w2), the best over w3 at each, with the grid's best (star), the optax
    search's mean step by step (line) and its best (diamond)."""
    grid, search = figure["grid"], figure["search"]
    w1, w2 = np.unique(grid.weights[:, 0]), np.unique(grid.weights[:, 1])
    values = np.asarray(grid.score.objective).reshape(len(w1), len(w2), -1).min(axis=-1)
    fig, ax = plt.subplots(figsize=(6.4, 5))
    image = ax.pcolormesh(w2, w1, values, shading="nearest", cmap="viridis_r")
    fig.colorbar(image, ax=ax, label="avgP / (1 + target), best over w3 (lower is better)")
    best = grid.best()
    ax.plot(best[1], best[0], "*", color="white", markersize=14, markeredgecolor="k",
            label=f"grid best {_weights(best)}")
    ax.plot(search.path[:, 1], search.path[:, 0], ".-", color="tab:red", label="optax mean")
    found = search.best()
    ax.plot(found[1], found[0], "D", color="tab:red", markeredgecolor="k",
            label=f"optax best {_weights(found)}")
    ax.set_xlabel("w2 (pushback)")
    ax.set_ylabel("w1 (goal distance)")
    ax.set_title(f"{name}: eq. 11 over the weights (shortest path {figure['optimum']:.1f})")
    ax.legend(loc="lower right", fontsize=7)
    write_png(fig, path)


def _weights(w) -> str:
    """Weights f32[3] as text, three significant digits each."""
    return "(" + ", ".join(f"{float(v):.3g}" for v in w) + ")"


def markdown(fresh: list[dict], landscape: list[dict], tried: list[dict], args) -> str:
    """The tables: per map, each setting on fresh seeds (with and without memory) beside the
    paper's figures, and the budgets."""
    lines = [f"K = {args.seeds} runs per setting, I = {CYCLES} cycles a step, M = 200 steps; "
             f"the grid: {'x'.join(map(str, args.grid))} settings; optax: Adam on evolution-"
             f"strategies gradients, {args.pairs} antithetic pairs a step, sigma {args.sigma}, "
             f"learning rate {args.learning_rate}, the same number of runs.", ""]
    for name in args.maps:
        grid_runs = sum(r["map"] == name for r in landscape) * args.seeds
        search_runs = sum(r["map"] == name for r in tried) * args.seeds
        paper = PAPER_ANSWER[name]
        lines += [f"### Map #{name[-1]}", "",
                  f"Budgets: grid {grid_runs} runs, optax {search_runs} runs. The paper: "
                  f"w = {paper[0]}, target {paper[1]}/30, avgP {paper[2]:g}, stdP {paper[3]:g} "
                  f"(objective {paper[2] / (1 + paper[1]):.2f}).", "",
                  "| setting | remember | w1 | w2 | w3 | target | avgP | objective |",
                  "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
        mine = [r for r in fresh if r["map"] == name]
        for r in mine:
            avg = "-" if np.isnan(r["avg_length"]) else f"{r['avg_length']:.1f}"
            lines.append(f"| {r['setting']} | {'yes' if r['remember'] else 'no'} | "
                         f"{r['w1']:.3f} | {r['w2']:.3f} | {r['w3']:.3f} | "
                         f"{r['target']}/{r['seeds']} | {avg} | {r['objective']:.2f} |")
        lines += ["", verdict(mine), ""]
    return "\n".join(lines)


def verdict(rows: list[dict]) -> str:
    """Plain words on a map's fresh seeds: is optax's best at least as good as the grid's, and
    does the memory raise the target rate?"""
    score = {(r["setting"], r["remember"]): r for r in rows}
    grid, optax = score["grid best", False], score["optax best", False]
    words = ("at least as good as" if optax["objective"] <= grid["objective"]
             else "worse than")
    memory = ", ".join(f"{setting} {score[setting, False]['target']} -> "
                       f"{score[setting, True]['target']}"
                       for setting in ("grid best", "optax best", "paper"))
    return (f"On fresh seeds the optax search's best ({optax['objective']:.3f}) is {words} "
            f"the grid's best ({grid['objective']:.3f}). Arrivals without and with the "
            f"memory of visited windows: {memory}.")


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=names_argument(PAPER_PLANES), default="all",
                        help=f"comma-separated, from {', '.join(PAPER_PLANES)} (default all)")
    parser.add_argument("--seeds", type=int, default=30, help="K, runs per weight setting")
    parser.add_argument("--grid", default="6x6x6", help="values of w1 x w2 x w3")
    parser.add_argument("--pairs", type=int, default=6, help="antithetic pairs per optax step")
    parser.add_argument("--sigma", type=float, default=0.05)
    parser.add_argument("--learning-rate", type=float, default=0.03)
    parser.add_argument("--search-seed", type=int, default=0)
    add_out_argument(parser, "bees_inverse")
    args = parser.parse_args(argv)
    try:
        args.grid = tuple(int(v) for v in args.grid.split("x"))
    except ValueError:
        parser.error(f"--grid must be AxBxC, got {args.grid!r}")
    if len(args.grid) != 3 or min(args.grid) < 1:
        parser.error(f"--grid must be three counts >= 1, got {args.grid!r}")
    check_counts(parser, args, "seeds", "pairs")
    record = provenance.begin(__file__, argv)
    landscape, tried, fresh = [], [], []
    for name in args.maps:
        began = time.perf_counter()
        mine = study(name, args)
        landscape += mine[0]
        tried += mine[1]
        fresh += mine[2]
        landscape_figure(args.out / f"{name}.png", name, mine[3])
        print(f"{name}: {time.perf_counter() - began:.0f} s", flush=True)
    record.finish(title=TITLE, about=ABOUT, arguments={**vars(args), "out": str(args.out)},
                  swarm=definition(make("cabc")))
    write_csv(args.out / "landscape.csv", landscape, LANDSCAPE_COLUMNS)
    write_csv(args.out / "search.csv", tried, SEARCH_COLUMNS)
    write_csv(args.out / "fresh.csv", fresh, FRESH_COLUMNS)
    print("\n" + record.publish(args.out, markdown(fresh, landscape, tried, args)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
