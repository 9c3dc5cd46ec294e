"""The rows of the RFD paper's Table 1 (static environment) as this project runs them.

Shared by the scripts that reproduce the table (``sweeps/rfd_paper_static.py``), re-run its
three RFD rows (``sweeps/rfd_static.py``) and continue every row after the paper's map changes
(``sweeps/rfd_paper_dynamic.py``): the rows and their swarms and params, the seeded timed runs of
a row, the cells the tables share and each row's best path in a figure.
"""
from __future__ import annotations

import statistics
from collections.abc import Mapping
from typing import NamedTuple

import numpy as np
from matplotlib.axes import Axes

from jaxswarm.exact import astar, dijkstra
from jaxswarm.plot.graph import draw_paths
from jaxswarm.studies.problems import Problem
from jaxswarm.studies.success import reaches_optimum
from jaxswarm.studies.timing import TimedRun, median_milliseconds, seed_keys, timed_runs
from jaxswarm.swarm import Swarm, definition, make
from jaxswarm.world.graph import Graph
from jaxswarm.world.paths import Solution


class Row(NamedTuple):
    """One row of our Table 1: an exact planner (``swarm`` None) or a registered swarm."""

    label: str
    """The row's label in our table."""
    paper: str | None
    """The paper's Table 1 row it reproduces (a key of ``PAPER_TABLE1_LENGTH``), None if none."""
    swarm: str | None = None
    """The registered swarm; None for an exact planner (``PLANNERS[label]``)."""
    params: tuple[tuple[str, float], ...] = ()
    """(name, value) of the swarm params that replace its defaults."""
    config: tuple[tuple[str, object], ...] = ()
    """(name, value) of the swarm's static options that replace its defaults."""

    def planner(self) -> str:
        """What runs: the planner, or the registered swarm with the options and params it
        replaces."""
        if self.swarm is None:
            return PLANNERS[self.label].__name__
        return " ".join([self.swarm, *(f"{name}={value}" for name, value in self.config),
                         *(f"{name}={value:g}" for name, value in self.params)])


PLANNERS = {"Dijkstra": dijkstra, "A*": astar}
"""Exact planners: Table 1 row label -> planner."""
ROWS = (
    Row("Dijkstra", "Dijkstra"),
    Row("A*", "A*"),
    Row("ACO (paper, eq. 7)", "ACO", "ant_system"),
    Row("ACO with eta (beta=1)", "ACO", "ant_system", (("beta", 1.0),)),
    Row("ACO*", "ACO*", "aco_star"),
    Row("RFD", "RFD", "rfd"),
    Row("RFD* (paper)", "RFD*", "rfd_star"),
    Row("RFD* (paper, all travelled paths)", "RFD*", "rfd_star", config=(("erode", "travelled"),)),
    Row("RFD graded (ours)", "RFD*", "rfd_graded"),
)
"""The rows, in the paper's order, each variant after the one the paper writes."""
BY_LABEL = {row.label: row for row in ROWS}
"""Row label -> Row."""
BY_SWARM = {row.swarm: row for row in ROWS
            if row.swarm is not None and not row.params and not row.config}
"""Registered swarm -> the row that runs it with its default options and params."""
ALGORITHMS = tuple(BY_LABEL)
"""Row labels, in table order."""
COLORS = dict(zip(ALGORITHMS, ("tab:blue", "tab:cyan", "tab:orange", "tab:brown", "tab:red",
                               "tab:purple", "tab:olive", "tab:pink", "tab:green")))
"""Path colour of each row in the figures."""
ABOUT = (
    "Rows: Dijkstra and A* (exact); \"ACO (paper, eq. 7)\" is the RFD paper's Ant System "
    "(`ant_system`, pheromone only, beta = 0) and \"ACO with eta (beta=1)\" the same with the "
    "edge-length heuristic weighted by beta = 1; ACO* (`aco_star`) and RFD (`rfd`) are the "
    "paper's; \"RFD* (paper)\" is the paper's RFD* as written (`rfd_star`: eq. 6 with the "
    "erosion of eqs. 4-5) on the paths of the drops that reached the goal, Algorithm 1's "
    "\"complete paths\", and \"RFD* (paper, all travelled paths)\" the same with every drop's "
    "path eroded, the text's \"an erosion process is executed on all travelled paths\" "
    "(`rfd_star erode=travelled`). \"RFD graded (ours)\" (`rfd_graded`) is not the paper's "
    "algorithm but this project's law (RFD*'s transitions over a graded river bed). Arithmetic: "
    "the ant colonies keep pheromone at least the smallest normal float32, and RFD and RFD* add "
    "their erosion and sediment by compensated summation. Under each row, the paper's values of "
    "the row it reproduces: both ACO rows the paper's ACO, both RFD* rows and the graded one "
    "the paper's RFD*.")
"""What the rows are (the paragraph under the provenance of a table of all rows)."""


def row_swarm(row: Row, agents: int) -> tuple[Swarm, tuple]:
    """The swarm of ``row`` with ``agents`` drops or ants and the row's options, and its params:
    the defaults with the row's replacements (float32 scalars)."""
    swarm = make(row.swarm, num_agents=agents, **dict(row.config))
    params = swarm.default_params._replace(
        **{name: np.float32(value) for name, value in row.params})
    return swarm, params


def run_swarm_row(row: Row, problem: Problem, seeds: int, *, iterations: int, agents: int,
                  patience: int | None = None) -> tuple[Swarm, list[TimedRun]]:
    """Run the swarm of ``row`` on ``problem`` once per seed (keys split from key 0), compiled
    first, each run timed alone.

    Returns:
      (the swarm, one :class:`~jaxswarm.studies.timing.TimedRun` per seed).
    """
    swarm, params = row_swarm(row, agents)
    runs = timed_runs(swarm, seed_keys(seeds), problem.graph, problem.task, params,
                      iterations=iterations, patience=patience, entry=problem.entry)
    return swarm, runs


def run_planner_row(row: Row, problem: Problem, seeds: int) -> list[Solution]:
    """Run the exact planner of ``row`` on ``problem`` ``seeds`` times, as repeats: every
    Solution (path i32[N], -1 padded) is the same, each timed by the planner itself
    (``stats.wall_time``)."""
    planner = PLANNERS[row.label]
    return [planner(problem.graph, problem.start, problem.goal) for _ in range(seeds)]


def row_definitions(agents: int) -> dict[str, dict]:
    """Row label -> what ran: the paper row it reproduces, and for a swarm its name, config and
    the params used (JSON-ready)."""
    definitions = {}
    for row in ROWS:
        entry = dict(paper=row.paper, planner=row.planner())
        if row.swarm is not None:
            swarm, params = row_swarm(row, agents)
            entry.update(config=definition(swarm)["config"],
                         params={k: float(v) for k, v in params._asdict().items()})
        definitions[row.label] = entry
    return definitions


def length_cell(runs: list[dict]) -> str:
    """Mean cost over the runs that found a path ("n/a" if none did) and the found count."""
    found = [r["cost"] for r in runs if r["found"]]
    mean = f"{statistics.mean(found):.2f}" if found else "n/a"
    return f"{mean} ({len(found)}/{len(runs)})"


def optimal_cell(runs: list[dict]) -> str:
    """How many of the runs reach the optimum (their ``gap``: see
    :func:`~jaxswarm.studies.success.reaches_optimum`)."""
    return f"{sum(reaches_optimum(r['gap']) for r in runs)}/{len(runs)}"


def time_cell(runs: list[dict]) -> str:
    """Median wall time of one run, in ms."""
    return f"{median_milliseconds(r['seconds'] for r in runs):.2f}"


def draw_best_paths(ax: Axes, graph: Graph, best: Mapping[str, Solution], *,
                    thinning: float) -> None:
    """Draw each row's best path on ``ax``, labelled with its cost, and the legend under it.

    Args:
      best: row label -> Solution (path i32[L], -1 padded; empty if not found), in table order.
      thinning: how much thinner each path is than the one before it (from 5 points), so that
        paths that coincide (Dijkstra and A*, or an optimal swarm) all show.
    """
    for thinner, (label, solution) in enumerate(best.items()):
        cost = f"{float(solution.cost):.2f}" if bool(solution.found) else "no path"
        draw_paths(ax, graph, [solution], [f"{label} ({cost})"],
                   colors=[COLORS.get(label, "black")], linewidth=5 - thinning * thinner)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.03), ncols=2, frameon=False,
              fontsize="small")
