"""Multi-agent path finding at the benchmark's scale: the A* report's scheme, prioritised planning,
CBS (plain, improved, bounded), PIBT and LaCAM on every Moving AI MAPF map, with ``pymapf`` as an
independent baseline where it is installed.

On each map of ``--maps`` (default: every ``*.map`` of ``--data`` with both scenario files), each
scenario file of ``--scenarios`` (default ``random`` and ``even``: ``<map>-random-1.scen``,
``<map>-even-1.scen``) and each count k of ``--agents`` (default 10, 20, 50, 100, 200, 400, 700,
1,000) that the file has rows for, the instance is the file's first k rows
(:func:`jaxswarm.multiagent.load_instance`). Rows, the planners of
:mod:`jaxswarm.multiagent.registry` (their labels and figure styles too), each planner with an
``order`` option once per order, every other but CBSH (:data:`LEFT_OUT`) once:

* ``report``: :func:`~jaxswarm.multiagent.report_scheme`, the A* report's scheme (A* per robot,
  then side-steps, waits and "one robot moves first" at collisions; the report has two robots,
  the pairwise extension to more is jaxswarm's choice);
* ``prioritized (given)``, ``prioritized (distance)``, ``prioritized (random)``:
  :func:`~jaxswarm.multiagent.prioritized` in the file's order, farthest first, and a random
  order once per seed 0 .. ``--seeds`` - 1;
* ``cbs``: :func:`~jaxswarm.multiagent.cbs` (optimal sum of costs); ``icbs``: the same with
  prioritised collisions and bypassing (optimal too); ``cbsh_tc``: ICBS with the weighted
  dependency graph heuristic and target and corridor reasoning (optimal); ``cbsh_rtc``: with
  rectangle reasoning too (optimal); ``ecbs`` and
  ``eecbs``: :func:`~jaxswarm.multiagent.ecbs` and :func:`~jaxswarm.multiagent.eecbs` with w =
  ``--w`` (1.2);
* ``pibt``: :func:`~jaxswarm.multiagent.pibt` (1,000 steps at most); ``lacam``:
  :func:`~jaxswarm.multiagent.lacam` (its first solution); ``lacam_star``: the same with LaCAM*'s
  successor generator (PIBT with the swap operation), its first solution;
* ``pymapf lacam``, ``pymapf cbs``: ``pymapf.solve`` with its ``lacam`` and ``cbs`` solvers (the
  peer a Python user would try first), their paths validated and costed as ours.

Every planner has ``--time-limit`` seconds an instance (default 30): prioritised planning, the
CBS family, LaCAM and pymapf's solvers stop there; a run of the report's scheme or PIBT that
takes longer counts as not solved. A planner is run up to its
``MAX_AGENTS`` (the report's scheme, CBS and pymapf's solvers stop early: tens to hundreds of
agents are their scale), and, on one map and scenario file, not again above a count it did not
solve (recorded as not solved, "not run").

Conventions (the MAPF benchmark's): the maps are 4-connected, every move or wait takes one step,
and an agent's cost is the step from which it stays at its goal for good (waits before that
count, waits at the goal afterwards do not); the sum of costs adds them, the makespan is the
largest. The lower bound is the sum of each agent's own shortest 4-connected distance to its
goal (:func:`~jaxswarm.multiagent.lower_bound`), ignoring the others; the ``.scen`` files' last
column is an 8-connected optimum and is **not** used. Every solved plan is checked by
:func:`~jaxswarm.multiagent.validate` (an invalid one raises :class:`InvalidPlan`: a planner bug),
its sum of costs must be at least the lower bound, no planner may beat a solved optimal one (CBS,
ICBS, CBSH-TC, CBSH-RTC) on the same instance, and ECBS and EECBS must stay within w of their
proven bound (else :class:`InvalidPlan` too). A planner that raises is recorded as not solved,
with the exception as its reason and ``error`` set; the study goes on, writes its files and exits
with status 1.

Per run (map, scenario, agents, planner, seed) ``runs.csv`` holds: solved, sum of costs, lower
bound, their ratio, makespan (blank when not solved), time (s, wall time of the planner call,
after a warm-up that leaves out numba's and JAX's one-off compilation), of which ``field_seconds``
the agents' distance fields (PIBT and LaCAM report them apart), the reason when not solved, the
planner's counters (low-level expansions, CBS nodes, LaCAM configurations), and the commit the
run came from.

A study at the benchmark's scale takes hours, so it runs in parts: ``--planners`` picks the
rows to run, ``runs.csv`` is rewritten after each map and scenario file, and ``--resume
[FOLDER ...]`` keeps the runs of earlier parts (by default ``--out``'s own) and runs only the
others, the files covering them all. Parts may run side by side into separate folders (say, half
of the maps each) and be joined by a last one that resumes from both. ``table.md`` counts the
runs of each commit.

Outputs (in ``--out``, default ``out/mapf_study/``, each written atomically):

* ``runs.csv``: one row per run;
* ``summary.csv``: per planner and agent count over all instances (``map`` = ``all``), then per
  map (and scenario), agent count and planner: runs, solved, success rate, mean SoC / lower
  bound and mean makespan over the solved runs, median time over all runs, runs that raised;
* ``table.md``: the provenance (:mod:`jaxswarm.studies.provenance`), the published LaCAM figures
  beside ours, then both summaries as Markdown tables;
* ``mapf_study.png``: success rate (the MAPF literature's plot), mean SoC / lower bound and
  median time against the number of agents, one line per planner (over all instances);
* ``provenance.json``: the provenance and the arguments.

``make reproduce`` writes them to ``results/mapf_study/``; ``make reproduce-quick`` runs a tiny
version in seconds.

The maps are read from ``--data`` (default: ``$JAXSWARM_MOVINGAI/mapf`` if that variable is set,
else ``../shared/benchdata/movingai/mapf`` beside the repository). Run from the repository root::

    python sweeps/mapf_study.py
    python sweeps/mapf_study.py --maps room-32-32-4,maze-32-32-2 --scenarios random \\
        --agents 5,10 --seeds 1 --time-limit 2 --out out/mapf_quick
"""
from __future__ import annotations

import argparse
import csv
import importlib.util
import math
import statistics
import sys
import time
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np
from matplotlib.figure import Figure

from jaxswarm.multiagent import (ORDERS, Instance, Plan, cbs, lacam, load_instance, lower_bound,
                                 pack, pibt, prioritized, report_scheme, validate)
from jaxswarm.multiagent import registry
from jaxswarm.multiagent.registry import Style
from jaxswarm.multiagent.agents import agent_nodes
from jaxswarm.runtime.atomic import atomic_path, write_csv
from jaxswarm.studies import provenance
from jaxswarm.studies.arguments import add_out_argument, check_counts, names_argument
from jaxswarm.studies.problems import movingai_folder


SCENARIOS = ("random", "even")
"""The scenario files of a map: ``<map>-<name>-1.scen``."""
AGENTS = (10, 20, 50, 100, 200, 400, 700, 1000)
"""The default agent counts (each map runs those its scenario files have rows for)."""
LEFT_OUT = ("cbsh",)
"""Registered planners the study does not run: CBSH, whose heuristic CBSH-TC runs with more
reasoning."""
ORDER_STYLES = {"given": Style("s", "-"), "distance": Style("D", "--"), "random": Style("^", ":")}
"""The figure's style of a planner's row per priority order."""
PYMAPF = {"pymapf lacam": ("pymapf LaCAM", Style("H", "-")),
          "pymapf cbs": ("pymapf CBS", Style("8", "--"))}
"""The rows of pymapf's solvers (left out when pymapf is not installed): their labels and
styles."""


class Row(NamedTuple):
    """One row of the study: a registered ``planner`` (None: pymapf's) with ``options`` (its
    priority order), its ``label`` in the tables and its ``style`` in the figure."""

    planner: str | None
    options: dict
    label: str
    style: Style


def study_rows() -> dict[str, Row]:
    """Row name -> :class:`Row`, in the order they run on every instance: the registered
    planners but :data:`LEFT_OUT` in the registry's order (one with an ``order`` option once per
    order of ``ORDERS``, as ``"NAME (ORDER)"``), then pymapf's solvers."""
    rows = {}
    for name in registry.registered():
        entry = registry.entry(name)
        if name in LEFT_OUT:
            continue
        if "order" not in registry.options(name):
            rows[name] = Row(name, {}, entry.label, entry.style)
            continue
        for order in ORDERS:
            rows[f"{name} ({order})"] = Row(name, {"order": order}, f"{entry.label} ({order})",
                                            ORDER_STYLES[order])
    rows.update((name, Row(None, {}, label, style)) for name, (label, style) in PYMAPF.items())
    return rows


ROWS = study_rows()
"""The rows (see :func:`study_rows`), as the registry holds them when the script is loaded."""
PLANNERS = tuple(ROWS)
"""The rows' names, in the order they run on every instance."""
LABELS = {name: row.label for name, row in ROWS.items()}
"""Each row's name in tables and figures."""
MARKERS, STYLES = ("".join(row.style.marker for row in ROWS.values()),
                   tuple(row.style.linestyle for row in ROWS.values()))
"""The figure's marker and line style of each row of :data:`PLANNERS`, in order."""
MAX_AGENTS = {"report": 100, "cbs": 100, "icbs": 100, "cbsh_tc": 100, "cbsh_rtc": 100,
              "ecbs": 400, "eecbs": 400, "pymapf lacam": 200, "pymapf cbs": 50}
"""The most agents a row is run with (the others: every count)."""
OPTIMAL = tuple(name for name, row in ROWS.items()
                if row.planner and registry.entry(row.planner).guarantee == "optimal")
"""The rows whose solved plans have the least sum of costs."""
BOUNDED = tuple(name for name, row in ROWS.items()
                if row.planner and registry.entry(row.planner).guarantee == "bounded")
"""The rows whose solved plans are within w of the bound they prove."""
RANDOM = next(name for name, row in ROWS.items() if row.options.get("order") == "random")
"""The row run once per seed."""
RUN_COLUMNS = ("map", "scenario", "agents", "planner", "seed", "solved", "sum_of_costs",
               "lower_bound", "ratio", "makespan", "seconds", "field_seconds", "reason", "error",
               "expanded", "nodes", "configurations", "repairs", "commit")
INTEGER_COLUMNS = ("agents", "sum_of_costs", "lower_bound", "makespan", "expanded", "nodes",
                   "configurations", "repairs")
FLOAT_COLUMNS = ("ratio", "seconds", "field_seconds")
"""The typed columns of ``runs.csv`` (blank cells stay blank); ``solved`` and ``error`` are
booleans, ``seed`` an integer or blank, the others text."""
SUMMARY_COLUMNS = ("map", "agents", "planner", "runs", "solved", "success_rate", "mean_ratio",
                   "mean_makespan", "median_seconds", "errors")
ALL_MAPS = "all"
"""The ``map`` of summary rows over every instance."""
TITLE = "Multi-agent path finding on the Moving AI MAPF benchmark"
"""Title of table.md."""
ABOUT = (
    "Rows: the A* report's two-robot scheme (`report_scheme`; its pairwise extension to more "
    "robots is jaxswarm's choice), prioritised planning with space-time A* (Silver 2005; "
    "`prioritized`) in the scenario's order, farthest-first and seeded random orders, "
    "Conflict-Based Search (Sharon et al. 2015; `cbs`, optimal), CBS with prioritised "
    "collisions and bypassing (Boyarski et al. 2015; `icbs`, optimal), ICBS with the weighted "
    "dependency graph heuristic (Li et al. 2019) and target and corridor reasoning (Li et al. "
    "2020; `cbsh_tc`, optimal) and with rectangle reasoning too (Li et al. 2019, its barriers "
    "timed by static distances; `cbsh_rtc`, optimal), Enhanced CBS (Barer et al. 2014; "
    "`ecbs`) and Explicit Estimation CBS (Li et al. 2021, without the CBS improvements of its "
    "paper; `eecbs`), both "
    "within w of the optimum, PIBT (Okumura et al. 2022), LaCAM (Okumura, "
    "AAAI 2023; its first solution) and with LaCAM*'s successor generator (Okumura, IJCAI "
    "2023: PIBT with the swap operation; its first solution), and pymapf's LaCAM and CBS where "
    "pymapf is installed. "
    "Instances: the first k rows of each map's `-random-1.scen` and `-even-1.scen`, "
    "4-connected, unit moves; an agent's cost is the step from which it stays at its goal. A run "
    "counts as solved only within the time limit; a planner is not run above its agent cap, nor "
    "above a count it did not solve on the same map and scenario (those runs count as not "
    "solved). SoC / LB is the sum of costs over the sum of the agents' own 4-connected "
    "distances; it and the makespan are means over the solved runs only. Every solved plan "
    "passed `validate`.")
"""What the rows are (the paragraph under the provenance)."""
PUBLISHED = (
    ("LaCAM* (Okumura, IJCAI 2023): its code's README, Kei18/lacam2, first solution on random "
     "starts and goals", "random-32-32-20", 400, "about 0.031 s"),
    ("LaCAM* (Okumura, IJCAI 2023, arXiv 2305.03632)", "the MAPF benchmark", "up to 1,000",
     "99 % of instances solved within 10 s"),
)
"""Published LaCAM* figures on the same benchmark (C++ implementations, their machines), set
beside our ``lacam_star`` (LaCAM*'s swap generator, its first solution)."""


class InvalidPlan(RuntimeError):
    """A planner's solved plan breaks a rule (validate, the lower bound, an optimum, a bound)."""


def parse_maps(text: str) -> list[str] | None:
    """``"all"`` (None: every map of the data folder) or a comma list of map names."""
    if text.strip() == "all":
        return None
    maps = [name.strip() for name in text.split(",") if name.strip()]
    if not maps:
        raise argparse.ArgumentTypeError(f"expected map names or 'all', got {text!r}")
    return maps


def parse_agents(text: str) -> list[int]:
    """A comma list of agent counts (each at least 1), e.g. ``"5,10,20"``."""
    try:
        counts = [int(part) for part in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a comma list of integers, got {text!r}")
    if not counts or min(counts) < 1:
        raise argparse.ArgumentTypeError(f"agent counts must be at least 1, got {text!r}")
    return sorted(set(counts))


def parse_scenarios(text: str) -> list[str]:
    """A comma list of scenario names from :data:`SCENARIOS`."""
    names = [name.strip() for name in text.split(",") if name.strip()]
    unknown = [name for name in names if name not in SCENARIOS]
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"scenarios are {', '.join(SCENARIOS)}; got {text!r}")
    return names


def read_runs(path: Path) -> list[dict]:
    """The rows of a study's ``runs.csv``, typed as :func:`run_study` makes them.

    Raises:
      ValueError: the file's columns are not :data:`RUN_COLUMNS` (naming the file).
    """
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.DictReader(f)
        if tuple(reader.fieldnames or ()) != RUN_COLUMNS:
            raise ValueError(f"{path}: columns {reader.fieldnames} are not this study's "
                             f"{list(RUN_COLUMNS)}")
        rows = list(reader)
    for line, row in enumerate(rows, start=2):
        try:
            row.update({key: int(row[key]) for key in (*INTEGER_COLUMNS, "seed")
                        if row[key] != ""})
            row.update({key: float(row[key]) for key in FLOAT_COLUMNS if row[key] != ""})
        except ValueError as exc:
            raise ValueError(f"{path}, line {line}: {exc}") from None
        row.update(solved=row["solved"] == "True", error=row["error"] == "True")
    return rows


def run_key(row: dict) -> tuple:
    """What identifies a run: its map, scenario, agents, planner and seed."""
    return row["map"], row["scenario"], row["agents"], row["planner"], row["seed"]


def scenario_path(data: Path, map_name: str, scenario: str) -> Path:
    """The scenario file of ``map_name``."""
    return data / f"{map_name}-{scenario}-1.scen"


def scenario_rows(path: Path) -> int:
    """The agents a scenario file has rows for."""
    with open(path, encoding="utf-8") as file:
        return sum(1 for line in file if line.strip()) - 1


def pymapf_installed() -> bool:
    """Whether the pymapf package can be imported."""
    return importlib.util.find_spec("pymapf") is not None


def pymapf_planner(solver: str, time_limit: float) -> Callable:
    """``call(graph, starts, goals) -> Plan`` of pymapf's ``solver`` on a grid map: pymapf's
    cells are (row, column); its paths come back as our node lists, packed and costed as ours
    (the validator judges them)."""
    import pymapf

    def call(graph, starts, goals) -> Plan:
        began = time.perf_counter()
        start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
        height, width = graph.shape
        blocked = ~np.asarray(graph.free).reshape(height, width)
        cell = {node: (int(node) // width, int(node) % width) for node in
                (*start_nodes.tolist(), *goal_nodes.tolist())}
        problem = pymapf.MAPFProblem(pymapf.GridMap(blocked.tolist()), [
            pymapf.Agent(str(a), cell[s], cell[g])
            for a, (s, g) in enumerate(zip(start_nodes.tolist(), goal_nodes.tolist()))])
        solution = pymapf.solve(problem, solver, time_limit=time_limit)
        seconds = time.perf_counter() - began
        name = f"pymapf {solver}"
        if solution is None:
            return Plan(start_nodes[:, None], np.zeros(len(start_nodes), np.int32), False, name,
                        reason=f"pymapf's {solver} returned no solution",
                        stats={"seconds": seconds})
        paths = [[r * width + c for r, c in solution.paths[str(a)]]
                 for a in range(len(start_nodes))]
        return Plan(*pack(paths, goal_nodes), solved=True, planner=name,
                    stats={"seconds": seconds})

    return call


def planner_calls(seeds: int, time_limit: float, w: float, with_pymapf: bool,
                  planners=PLANNERS) -> list[tuple[str, int | None, Callable]]:
    """``(planner, seed or None, call(graph, starts, goals) -> Plan)`` in the order they run,
    for the rows of ``planners`` (pymapf's only ``with_pymapf``): each registered planner with
    its row's options and, where it takes them, ``time_limit`` and ``w``; the random order
    once per seed 0 .. ``seeds`` - 1."""
    calls = []
    for name, row in ROWS.items():
        if row.planner is None:
            if with_pymapf:
                calls.append((name, None, pymapf_planner(name.split()[1], time_limit)))
            continue
        taken = registry.options(row.planner)
        options = dict(row.options, **{option: value for option, value in
                                       (("time_limit", time_limit), ("w", w))
                                       if option in taken})
        for seed in (range(seeds) if row.options.get("order") == "random" else [None]):
            seeded = {} if seed is None else {"seed": seed}
            calls.append((name, seed, registry.make_planner(row.planner, **options, **seeded)))
    return [call for call in calls if call[0] in planners]


def warm_up(instance: Instance) -> None:
    """Leave the one-off compilation out of the timings: numba's kernels (loaded from its cache
    once per process) on two agents, and the JAX programs compiled per map and agent count
    (the hop fields, the report's distance fields: a report run that stops before any repair)."""
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    lower_bound(graph, starts, goals)
    report_scheme(graph, starts, goals, max_repairs=0)
    for planner in (prioritized, cbs, pibt, lacam):
        planner(graph, starts[:2], goals[:2])


def run_instance(instance: Instance, where: dict, calls: list, time_limit: float, *,
                 skip: dict | None = None, earlier: list[dict] = (),
                 commit: str = "") -> list[dict]:
    """Every planner of ``calls`` on one instance (``where``: its ``map``, ``scenario``,
    ``agents``); one row per run. ``skip``: planner -> why it is not run here; ``earlier``:
    the instance's rows of an earlier run (an optimum there binds these runs too); ``commit``:
    the source the rows come from.

    Raises:
      InvalidPlan: a solved plan fails ``validate``, is below the lower bound, beats an optimal
        planner, or ECBS's or EECBS's is above its bound.
    """
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    bound = lower_bound(graph, starts, goals)
    calls = within_caps(calls, where["agents"])
    if any(planner not in (skip or {}) for planner, _, _ in calls):
        warm_up(instance)
    rows = []
    for planner, seed, call in calls:
        row = dict(where, planner=planner, seed="" if seed is None else seed, solved=False,
                   sum_of_costs="", lower_bound=bound, ratio="", makespan="", seconds=0.0,
                   field_seconds="", reason="", error=False, expanded="", nodes="",
                   configurations="", repairs="", commit=commit)
        if skip and planner in skip:
            rows.append(dict(row, reason=skip[planner], seconds=""))
            continue
        began = time.perf_counter()
        try:
            plan, error = call(graph, starts, goals), None
        except Exception as exc:  # noqa: BLE001 - a crash is recorded, the study goes on
            plan, error = None, f"raised {type(exc).__name__}: {exc}"
        row.update(seconds=time.perf_counter() - began, error=error is not None,
                   reason=error or (plan.reason if plan else ""))
        if plan is not None:
            for key in ("expanded", "nodes", "configurations", "repairs", "field_seconds"):
                row[key] = plan.stats.get(key, "")
            row["solved"] = plan.solved
            if plan.solved and row["seconds"] > time_limit:
                row.update(solved=False, reason=f"solved in {row['seconds']:.1f} s, over the "
                                                f"{time_limit:g} s limit")
        if row["solved"]:
            _check(instance, row, plan, bound, seed)
        rows.append(row)
    check_optimal([*earlier, *rows], instance.name)
    return rows


def within_caps(calls: list, agents: int) -> list:
    """The planner calls whose :data:`MAX_AGENTS` allows ``agents`` (the others have no row)."""
    return [call for call in calls if agents <= MAX_AGENTS.get(call[0], agents)]


def _check(instance: Instance, row: dict, plan: Plan, bound: int, seed) -> None:
    """Validate a solved run and record its costs; :class:`InvalidPlan` if it breaks a rule."""
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    where = f"{row['planner']} on {instance.name}" + ("" if seed is None else f", seed {seed}")
    violations = validate(graph, plan.paths, starts, goals, plan.lengths)
    if violations:
        shown = "; ".join(map(str, violations[:5]))
        raise InvalidPlan(f"{where}: a solved plan with {len(violations)} violations: {shown}")
    if plan.sum_of_costs < bound:
        raise InvalidPlan(f"{where}: sum of costs {plan.sum_of_costs} below the lower bound "
                          f"{bound}")
    proven = plan.stats.get("lower_bound")
    if row["planner"] in BOUNDED and plan.sum_of_costs > plan.stats["w"] * proven:
        raise InvalidPlan(f"{where}: sum of costs {plan.sum_of_costs} above w times its "
                          f"bound {proven}")
    row.update(sum_of_costs=plan.sum_of_costs, makespan=plan.makespan,
               ratio=plan.sum_of_costs / bound if bound > 0 else math.nan)


def check_optimal(rows: list[dict], name: str) -> None:
    """Raise :class:`InvalidPlan` if a solved run of one instance has a smaller sum of costs
    than a solved optimal one (those of :data:`OPTIMAL` are the least), or if two of those
    differ."""
    optima = {row["sum_of_costs"] for row in rows if row["planner"] in OPTIMAL and row["solved"]}
    if len(optima) > 1:
        raise InvalidPlan(f"the optimal planners on {name}: different optima {sorted(optima)}")
    if not optima:
        return
    optimum = optima.pop()
    for row in rows:
        if row["solved"] and row["sum_of_costs"] < optimum:
            raise InvalidPlan(f"{row['planner']} on {name} (seed {row['seed']}): sum of costs "
                              f"{row['sum_of_costs']} below the optimum {optimum}")


def run_study(instances: list[tuple[str, str]], agent_counts, calls: list, time_limit: float,
              data: Path, *, kept: list[dict] = (), commit: str = "",
              save: Callable[[list[dict]], None] | None = None,
              log: Callable[[str], None] | None = print) -> list[dict]:
    """Run every planner on every (map, scenario) at every count its file has rows for; the
    tidy rows. A planner not solving at a count is not run at larger ones on the same file.

    Args:
      instances: ``(map, scenario)`` pairs (files ``data / MAP.map`` and their scenario).
      agent_counts: numbers of agents (the first rows of the scenario file).
      calls: :func:`planner_calls`.
      time_limit: seconds an instance, per planner.
      data: the folder of the maps.
      kept: rows of earlier runs (:func:`read_runs`): a run among them is not run again, and
        its failures stop its planner at larger counts as new ones do. All of them are in the
        result, those of this grid in its order (each instance's rows in planner order), the
        others after.
      commit: the source the new rows come from (their ``commit``).
      save: called with the rows so far after each (map, scenario), so that an interrupted
        study loses little (None: not called).
      log: called with one progress line per instance (None: silent).
    """
    earlier: dict[tuple, list[dict]] = {}
    for row in kept:
        earlier.setdefault(run_key(row)[:3], []).append(row)
    rows = []
    began = time.perf_counter()
    for map_name, scenario in instances:
        scen = scenario_path(data, map_name, scenario)
        failed: dict[str, str] = {}
        for agents in [k for k in agent_counts if k <= scenario_rows(scen)]:
            where = dict(map=map_name, scenario=scenario, agents=agents)
            old = earlier.pop((map_name, scenario, agents), [])
            done = {run_key(row) for row in old}
            todo = [call for call in within_caps(calls, agents) if (
                map_name, scenario, agents, call[0], "" if call[1] is None else call[1])
                not in done]
            instance_began = time.perf_counter()
            new = [] if not todo else run_instance(
                load_instance(data / f"{map_name}.map", scen, agents), where, todo, time_limit,
                skip=failed, earlier=old, commit=commit)
            ran = sorted(old + new, key=lambda row: (PLANNERS.index(row["planner"]),
                                                     -1 if row["seed"] == "" else row["seed"]))
            rows += ran
            for row in ran:
                if not row["solved"] and row["planner"] not in failed and row["planner"] != RANDOM:
                    failed[row["planner"]] = f"not run: not solved at {agents} agents"
            if log is not None and new:
                log(_progress(where, new, time.perf_counter() - instance_began,
                              time.perf_counter() - began))
        if save is not None:
            save([*rows, *(row for group in earlier.values() for row in group)])
    return [*rows, *(row for group in earlier.values() for row in group)]


def _progress(where: dict, new: list[dict], seconds: float, elapsed: float) -> str:
    """One log line: the instance, its time, and each planner's solved runs."""
    solved = {}
    for row in new:
        done, runs = solved.get(row["planner"], (0, 0))
        solved[row["planner"]] = (done + row["solved"], runs + 1)
    return (f"{where['map']:>22} {where['scenario']:>6} {where['agents']:>4}: {seconds:6.1f} s "
            f"(elapsed {elapsed:6.0f} s) | "
            + ", ".join(f"{LABELS[p]} {d}/{n}" for p, (d, n) in solved.items()))


def _group(rows: list[dict], key: tuple) -> dict:
    entry = {"map": key[0], "agents": key[1], "planner": key[2], "runs": len(rows)}
    solved = [row for row in rows if row["solved"]]
    entry["solved"] = len(solved)
    entry["success_rate"] = len(solved) / len(rows)
    entry["mean_ratio"] = (float(np.mean([row["ratio"] for row in solved])) if solved
                           else math.nan)
    entry["mean_makespan"] = (float(np.mean([row["makespan"] for row in solved])) if solved
                              else math.nan)
    ran = [row["seconds"] for row in rows if row["seconds"] != ""]
    entry["median_seconds"] = float(statistics.median(ran)) if ran else math.nan
    entry["errors"] = sum(bool(row["error"]) for row in rows)
    return entry


def instance_set(row: dict) -> str:
    """The instances a run belongs to in the summaries: its map and scenario file."""
    return f"{row['map']} ({row['scenario']})"


def summarise(rows: list[dict]) -> list[dict]:
    """Per (agents, planner) over all maps (``map`` = :data:`ALL_MAPS`), then per (map and
    scenario, agents, planner): runs, solved, success rate, mean ratio and makespan over the
    solved runs, median seconds over all runs, errors. Sorted by map (all first), agents, then
    planner order."""
    order = {name: i for i, name in enumerate(PLANNERS)}
    maps = list(dict.fromkeys(instance_set(row) for row in rows))
    overall: dict[tuple, list[dict]] = {}
    each: dict[tuple, list[dict]] = {}
    for row in rows:
        overall.setdefault((ALL_MAPS, row["agents"], row["planner"]), []).append(row)
        each.setdefault((instance_set(row), row["agents"], row["planner"]), []).append(row)

    def sort_key(item):
        (map_name, agents, planner), _ = item
        return (-1 if map_name == ALL_MAPS else maps.index(map_name), agents,
                order.get(planner, 99))

    return [_group(group, key) for key, group in sorted([*overall.items(), *each.items()],
                                                        key=sort_key)]


def _number(value: float, digits: int) -> str:
    return "-" if value is None or (isinstance(value, float) and math.isnan(value)) \
        else f"{value:.{digits}f}"


def summary_markdown(summary: list[dict], rows: list[dict]) -> str:
    """Both summaries as Markdown tables: over all maps, then per map (with the reason of the
    first run not solved)."""
    head = ("| agents | planner | solved | success | SoC / LB | makespan | median time s |",
            "| ---: | --- | ---: | ---: | ---: | ---: | ---: |")

    def cells(e):
        return (f"{e['solved']}/{e['runs']} | {100 * e['success_rate']:.0f}% | "
                f"{_number(e['mean_ratio'], 3)} | {_number(e['mean_makespan'], 1)} | "
                f"{_number(e['median_seconds'], 3)}")

    overall = [*head] + [f"| {e['agents']} | {LABELS[e['planner']]} | {cells(e)} |"
                         for e in summary if e["map"] == ALL_MAPS]
    reasons = {}
    for row in rows:
        if not row["solved"]:
            reasons.setdefault((instance_set(row), row["agents"], row["planner"]),
                               row["reason"])
    per_map = ["| map | agents | planner | solved | success | SoC / LB | makespan | "
               "median time s | first reason not solved |",
               "| --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | --- |"]
    for e in summary:
        if e["map"] == ALL_MAPS:
            continue
        reason = reasons.get((e["map"], e["agents"], e["planner"]), "").replace("|", "\\|")
        per_map.append(f"| {e['map']} | {e['agents']} | {LABELS[e['planner']]} | {cells(e)} | "
                       f"{reason} |")
    errors = sum(e["errors"] for e in summary if e["map"] == ALL_MAPS)
    commits: dict[str, int] = {}
    for row in rows:
        commits[row["commit"]] = commits.get(row["commit"], 0) + 1
    sources = ["| commit | runs |", "| --- | ---: |"] + [
        f"| {commit or 'unknown'} | {runs} |" for commit, runs in commits.items()]
    sections = [("Published LaCAM figures beside ours", published_markdown(rows)),
                ("Over all maps", overall), ("Per map", per_map),
                ("The source of the runs (a resumed study's parts)", sources)]
    if errors:
        sections.append(("Runs that raised", [
            f"{errors} runs raised an exception (recorded as not solved; the `error` column of "
            "`runs.csv`, the reason says which)."]))
    return provenance.join_sections(sections)


def published_markdown(rows: list[dict]) -> list[str]:
    """The published LaCAM* figures (:data:`PUBLISHED`) beside our ``lacam_star`` on the same
    maps (on random-32-32-20, the 400 agents of its random scenario file)."""
    ours = [row for row in rows if row["planner"] == "lacam_star"]
    dense = [row for row in ours if (row["map"], row["scenario"], row["agents"])
             == ("random-32-32-20", "random", 400)]
    first = "-" if not dense else (f"{dense[0]['seconds']:.2f} s"
                                   + ("" if dense[0]["solved"] else " (not solved)"))
    quick = sum(bool(row["solved"]) and row["seconds"] <= 10.0 for row in ours)
    second = f"{quick} of {len(ours)} runs solved within 10 s" if ours else "-"
    return ["| published | instances | agents | published figure | ours (jaxswarm's "
            "lacam_star, this run) |", "| --- | --- | --- | --- | --- |"] + [
        f"| {who} | {where} | {agents} | {figure} | {value} |"
        for (who, where, agents, figure), value in zip(PUBLISHED, (first, second))]


def format_summary(summary: list[dict]) -> str:
    """The over-all-maps summary as a fixed-width text table."""
    fmt = "{:>6} {:<24} {:>8} {:>8} {:>9} {:>9} {:>10}"
    lines = [fmt.format("agents", "planner", "solved", "success", "SoC/LB", "makespan",
                        "median s")]
    for e in summary:
        if e["map"] == ALL_MAPS:
            lines.append(fmt.format(e["agents"], LABELS[e["planner"]],
                                    f"{e['solved']}/{e['runs']}",
                                    f"{100 * e['success_rate']:.0f}%",
                                    _number(e["mean_ratio"], 3),
                                    _number(e["mean_makespan"], 1),
                                    _number(e["median_seconds"], 3)))
    return "\n".join(lines)


def plot_summary(summary: list[dict], path) -> None:
    """Three panels against the number of agents, one line per planner, over all maps: success
    rate, mean SoC / lower bound over the solved runs, median time. Saved as PNG, atomically."""
    panels = (("success_rate", "success rate"), ("mean_ratio", "mean SoC / lower bound (solved)"),
              ("median_seconds", "median time (s)"))
    overall = [e for e in summary if e["map"] == ALL_MAPS]
    counts = sorted({e["agents"] for e in overall})
    fig = Figure(figsize=(17, 4.5), layout="constrained")
    axes = fig.subplots(1, len(panels))
    for ax, (metric, title) in zip(axes, panels):
        for planner, marker, style in zip(PLANNERS, MARKERS, STYLES):
            entries = sorted((e for e in overall if e["planner"] == planner),
                             key=lambda e: e["agents"])
            if entries:  # markers and dashes tell apart the lines that coincide
                ax.plot([e["agents"] for e in entries], [e[metric] for e in entries],
                        marker=marker, markersize=5, linestyle=style, label=LABELS[planner],
                        alpha=0.85)
        ax.set_xscale("log")
        ax.set_xticks(counts, [str(c) for c in counts], rotation=45)
        ax.minorticks_off()
        ax.set_title(title)
        ax.set_xlabel("agents")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylim(-0.05, 1.05)
    axes[2].set_yscale("log")
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside right center")
    sets = [e["map"] for e in summary if e["map"] != ALL_MAPS]
    maps = sorted({name.split(" (")[0] for name in sets})
    fig.suptitle(f"MAPF planners on {len(maps)} Moving AI map{'s' * (len(maps) > 1)}, "
                 f"{len(set(sets))} scenario files: success rate against agents (over all)")
    with atomic_path(path) as temporary:
        fig.savefig(temporary, format="png", dpi=120)


def main(argv: list[str] | None = None) -> int:
    """Command line entry point (see the module docstring); returns the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    check_counts(parser, args, "seeds")
    if args.time_limit <= 0 or args.w < 1:
        parser.error("--time-limit must be positive and --w at least 1")
    maps = args.maps or sorted(path.stem for path in args.data.glob("*.map")
                               if all(scenario_path(args.data, path.stem, s).is_file()
                                      for s in args.scenarios))
    instances = [(name, scenario) for name in maps for scenario in args.scenarios]
    for name, scenario in instances:
        for path in (args.data / f"{name}.map", scenario_path(args.data, name, scenario)):
            if not path.is_file():
                parser.error(f"no {path} (see --data)")
    kept = resumed_rows(parser, [args.out] if args.resume == [] else args.resume or [])
    with_pymapf = pymapf_installed() and not args.no_pymapf
    record = provenance.begin(__file__, argv)
    commit = (record.commit or "unknown")[:12] + ("+dirty" if record.dirty_files else "")
    print(f"MAPF study: {len(maps)} maps x {len(args.scenarios)} scenario files, agents "
          f"{args.agents}, {args.seeds} random orders, {args.time_limit:g} s a planner and "
          f"instance, pymapf {'on' if with_pymapf else 'off'}, {len(kept)} runs kept "
          f"-> {args.out}")
    began = time.perf_counter()
    calls = planner_calls(args.seeds, args.time_limit, args.w, with_pymapf, args.planners)
    rows = run_study(instances, args.agents, calls, args.time_limit, args.data, kept=kept,
                     commit=commit,
                     save=lambda rows: write_csv(args.out / "runs.csv", rows, RUN_COLUMNS))
    summary = summarise(rows)
    record.finish(title=TITLE, about=ABOUT, arguments=vars(args), pymapf=with_pymapf)
    write_csv(args.out / "runs.csv", rows, RUN_COLUMNS)
    write_csv(args.out / "summary.csv", summary, SUMMARY_COLUMNS)
    plot_summary(summary, args.out / "mapf_study.png")
    record.publish(args.out, summary_markdown(summary, rows))
    print("\n" + format_summary(summary))
    print(f"\n{len(rows)} runs ({len(rows) - len(kept)} new) in "
          f"{time.perf_counter() - began:.0f} s; every solved plan passed validate. Wrote "
          f"{args.out / 'runs.csv'}, {args.out / 'summary.csv'}, "
          f"{args.out / 'mapf_study.png'}, {args.out / 'table.md'}")
    errors = sum(bool(row["error"]) for row in rows)
    if errors:  # a planner that raises is a bug: the files are written, the run fails
        print(f"\nERROR: {errors} runs raised an exception (see the error and reason columns "
              "of runs.csv)", file=sys.stderr)
        return 1
    return 0


def resumed_rows(parser: argparse.ArgumentParser, folders: list[Path]) -> list[dict]:
    """The rows of every ``folder / runs.csv`` (:func:`read_runs`); the parser's error if one
    is missing or unreadable, or if two hold the same run."""
    rows, seen = [], {}
    for folder in folders:
        path = folder / "runs.csv"
        if not path.is_file():
            parser.error(f"--resume: no {path}")
        try:
            part = read_runs(path)
        except (ValueError, KeyError) as exc:
            parser.error(f"--resume: {exc}")
        for row in part:
            if run_key(row) in seen:
                parser.error(f"--resume: run {run_key(row)} is in both {seen[run_key(row)]} "
                             f"and {path}")
            seen[run_key(row)] = path
        rows += part
    return rows


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--maps", type=parse_maps, default=None,
                        help="comma list of MAPF map names, or 'all' (default: every map of "
                             "--data with its scenario files)")
    parser.add_argument("--scenarios", type=parse_scenarios, default=list(SCENARIOS),
                        help="comma list of scenario files: random, even (default both)")
    parser.add_argument("--agents", type=parse_agents, default=list(AGENTS),
                        help="comma list of agent counts (default 10,20,50,100,200,400,700,"
                             "1000; each map runs those its scenario files have rows for)")
    parser.add_argument("--seeds", type=int, default=3,
                        help="runs of the random priority order, seeds 0.. (default 3)")
    parser.add_argument("--time-limit", type=float, default=30.0,
                        help="seconds a planner has per instance (default 30)")
    parser.add_argument("--w", type=float, default=1.2, help="ECBS's bound (default 1.2)")
    parser.add_argument("--planners", type=names_argument(PLANNERS), default=PLANNERS,
                        help="comma list of the rows to run, or 'all' (default)")
    parser.add_argument("--resume", type=Path, nargs="*", default=None, metavar="FOLDER",
                        help="keep the runs of these folders' runs.csv (none named: --out's) "
                             "and run only the others; the files cover them all")
    parser.add_argument("--no-pymapf", action="store_true",
                        help="leave out pymapf's solvers even where pymapf is installed")
    parser.add_argument("--data", type=Path, default=movingai_folder(),
                        help="the folder of the MAPF .map and .scen files (default "
                             "$JAXSWARM_MOVINGAI/mapf, else ../shared/benchdata/movingai/mapf)")
    add_out_argument(parser, "mapf_study")
    return parser


if __name__ == "__main__":
    sys.exit(main())
