"""Multi-agent planning: prioritised planning on a MAPF benchmark instance, the batched JAX
conflict check beside a pure-Python one on the same solutions, PIBT's step, LaCAM's solve
times, LaCAM*'s refinement over time and CBSH-RTC's constraint-tree nodes per second.

What is measured
----------------
1. Prioritised planning. :func:`jaxswarm.multiagent.prioritized` on the first ``--agents`` rows
   (default 100) of ``random-32-32-10-random-1.scen`` (:func:`~jaxswarm.multiagent.load_instance`:
   the map loaded 4-connected), once per order of ``--orders`` (default given, distance, random).
   Per order: one warm-up call, timed apart (``warm-up s``: the first one compiles the numba
   space-time search, or loads it from numba's on-disk cache, and JAX compiles the batched hop
   fields for the map's shape), then ``--repeats`` calls (default 10); ``median ms`` is the
   median wall time (``time.perf_counter`` around the call as users make it: hop fields,
   reservation table and packing included). ``expanded`` is the plan's ``stats["expanded"]``,
   the space-time states expanded (the useful work; the planner is deterministic, and every
   call must expand as many), ``k exp/s`` that count over the median time. ``SoC`` is the sum of
   costs, ``bound`` :func:`~jaxswarm.multiagent.lower_bound` (each agent's own fewest steps,
   summed), ``SoC/bound`` their ratio, ``valid`` whether :func:`~jaxswarm.multiagent.validate`
   found no violation in the plan (starts, moves, goals, vertex and swap conflicts).

2. Conflict check. ``--check-agents`` agents (default 1,000) for ``--check-steps`` time steps
   (default 1,000) on ``--check-map`` (default ``random-64-64-10``, loaded 4-connected), from
   distinct free cells drawn with ``--seed``; each step every agent picks one of its 4 direction
   slots or a wait, uniformly (a slot without a valid edge is a wait). Two solutions of the same
   starts and picks:

   * ``random walks``: every pick is carried out; the agents ignore each other, so at this
     density (1,000 agents on 3,687 free cells) about a quarter of the agent-steps are vertex
     conflicts and some are swaps;
   * ``conflict-free walks``: a move goes ahead only onto a cell no agent occupies at that step
     and no other agent picks, otherwise the agent waits, so there is no conflict at all (the
     script checks it with ``validate``, the first and last cells as starts and goals), as in a
     planner's solution.

   :func:`~jaxswarm.multiagent.find_conflicts` ``(paths, num_nodes)`` is called as users call
   it, on the i32[A, T] numpy array: transpose, host -> device, the compiled check, and
   ``np.asarray`` of both results are timed. Beside it, :func:`python_conflicts`, a per-time-step
   hash check in pure Python (no numpy inside; ``paths.T.tolist()`` is timed with it): per step
   a dict node -> lowest agent id there (built by ``dict(zip(...))`` from the highest id down), a
   vertex flag for every agent on a node that holds 2+ agents (skipped when the dict has one
   entry per agent), and for each agent that moves u -> w the agent found on w at t as its swap
   partner if that agent is on u at t + 1 (the semantics of ``find_conflicts``). It returns
   per-step lists of A flags and A partners (converting them to numpy is not timed). Of a few
   variants tried (``setdefault`` in a loop, a ``Counter``, an explicit loop over the movers)
   this was the fastest. Both results must be equal (every vertex flag and swap partner) before
   any timing is printed; the script exits 1 otherwise.

   Per solution and check: the median of ``--check-repeats`` calls (default 7) after a warm-up
   call (``warm-up s``; JAX compiles the check for the shape in the first one), the two checks
   called in turn within each repeat (a busy spell of a shared machine hits both), agent-steps
   (A x T) per second, and, on the ``find_conflicts`` row, the speed-up (Python's median over
   its own) and the goal "the batched check at least 20x faster than the pure-Python one".

   Why ``random-64-64-10``: it has a few thousand free cells (3,687) yet is crowded at 1,000
   agents (27 % of them occupied), so a quarter of the random walks' agent-steps are vertex
   conflicts and the Python check runs its slow path (on ``Berlin_1_256``, 1,000 random walkers
   rarely meet: 2 % of the agent-steps); and its 4,096 nodes keep ``find_conflicts``' occupancy
   tables (one entry per node per time step, 128 steps per chunk here) small beside the agents,
   where Berlin's 65,536 nodes give 8 steps per chunk (``--check-map Berlin_1_256``).

3. PIBT and LaCAM. PIBT's step for the first ``--pibt-agents`` rows (default 400) of
   ``random-32-32-20-random-1.scen``: :func:`jaxswarm.multiagent.pibt.configuration` timed alone,
   one call per step, over ``--pibt-steps`` steps (default 200) from the starts with the
   priorities PIBT updates; the distance fields and the first (compiling) step are left out.
   ``median us`` is the median step, ``steps/s`` its inverse, the goal a step under 1 ms. Then
   :func:`jaxswarm.multiagent.lacam` on ``--lacam`` (default: random-32-32-20 and both 64 x 64
   maps, 400 agents each, ``random-1`` scenarios), as LaCAM and with LaCAM*'s swap generator
   (``lacam_star``): one warm-up call on 2 agents (it loads the kernels), then one timed call:
   ``fields s`` the distance fields (one batched JAX call), ``search s`` the search,
   ``total s`` the call as users make it; the goal is the total within 10 s on one core.
   ``configurations`` counts LaCAM's high-level nodes, the useful work.

4. LaCAM*'s refinement. :func:`jaxswarm.multiagent.lacam` with ``swap`` and ``refine`` =
   ``--refine`` seconds (default 10; 0 leaves this part out) on ``--refine-instances`` (default
   100, 200 and 400 agents of random-32-32-20 and of room-64-64-8, ``random-1`` scenarios): one
   warm-up call on 2 agents, then one call each. Printed: the first solution's sum of costs and
   sum of loss (LaCAM*'s objective: agents not resting at their goals, summed over the steps),
   then both for the best solution known 1, 2, 5 and 10 s after the first (from
   ``stats["improvements"]``), and the configurations explored. Then the issue's check: five
   100-agent instances of random-32-32-20 (rows 0-99, 100-199, 200-299 and 300-399 of
   ``random-1``, the 100 rows of ``even-1``), each refined for ``--refine`` seconds; the goal is a
   sum of loss below the first solution's on at least 4 of the 5. The search stops at a time,
   not at a count of configurations, so these figures depend on the machine and its load.

5. CBSH-RTC. ``cbs`` with every switch (``"cbsh_rtc"`` in :mod:`jaxswarm.multiagent.registry`)
   on the first 20 rows of ``--cbs`` (default ``room-32-32-4-even-1``, ``maze-32-32-2-even-1``
   and ``maze-32-32-4-random-1``, the 32 x 32 files hardest for CBS), stopped after
   ``--cbs-nodes`` constraint-tree nodes (default 2,000): one warm-up call on 3 agents, then
   ``--cbs-repeats`` calls (default 3). The search is deterministic, so every call must split
   as many nodes and expand as many space-time states (the useful work), and a plan it solves
   must pass ``validate`` (the script exits 1 otherwise); ``median s`` is the median call,
   ``nodes/s`` the nodes over it, ``k states/s`` the low-level states over it, ``pairs`` the
   two-agent problems its heuristic solved.

XLA:CPU runs on ``--threads`` intra-op threads (default 1, as in ``benchmarks/rfd.py``: the
Python check runs on one core too; see :mod:`jaxswarm.runtime.cpu`).

How to run
----------
From the repository root (defaults take about 3 minutes on 2 cores, 2 of them LaCAM*'s
refinement; ``--refine 0`` leaves it out)::

    python benchmarks/multiagent.py
    python benchmarks/multiagent.py --quick
    python benchmarks/multiagent.py --check-map Berlin_1_256 --check-repeats 3

``--data`` is the ``shared`` directory holding ``benchdata/movingai/mapf`` (default: ``../shared``
next to the repository root).
"""
from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import jax
import numba
import numpy as np

from jaxswarm.maps.movingai import read_map
from jaxswarm.multiagent import (ORDERS, find_conflicts, hop_fields, lacam, load_instance,
                                 lower_bound, prioritized, registry, validate)
from jaxswarm.multiagent.agents import agent_nodes
from jaxswarm.multiagent.pibt import (Moves, Workspace, by_priority, configuration,
                                      initial_priorities, next_priorities)
from jaxswarm.runtime.cpu import configure, cpu_model
from jaxswarm.world.graph import grid_graph

REPO = Path(__file__).resolve().parents[1]
MAPF_DIR = Path("benchdata", "movingai", "mapf")
PLAN_MAP = "random-32-32-10"
GOAL_SPEEDUP = 20.0
PIBT_MAP = "random-32-32-20"
LACAM_INSTANCES = "random-32-32-20:400,random-64-64-10:400,room-64-64-8:400"
REFINE_INSTANCES = ("random-32-32-20:100,random-32-32-20:200,random-32-32-20:400,"
                    "room-64-64-8:100,room-64-64-8:200,room-64-64-8:400")
REFINE_CHECKPOINTS = (1.0, 2.0, 5.0, 10.0)
REFINE_CHECK = (("random-1", 0), ("random-1", 100), ("random-1", 200), ("random-1", 300),
                ("even-1", 0))
"""The refinement check's instances: 100 rows of a ``random-32-32-20`` scenario file from a row."""
GOAL_REFINED = 4
GOAL_STEP_MS = 1.0
GOAL_LACAM_S = 10.0
CBS_FILES = "room-32-32-4-even-1,maze-32-32-2-even-1,maze-32-32-4-random-1"
CBS_AGENTS = 20


def machine() -> str:
    """Where the figures come from: platform, CPU model, cores, python, jax, numba, numpy."""
    return (f"{platform.platform()} | {cpu_model()} | {os.cpu_count()} CPUs | python "
            f"{platform.python_version()} | jax {jax.__version__} ({jax.default_backend()}) | "
            f"numba {numba.__version__} | numpy {np.__version__}")


def timed(call, repeats: int) -> tuple[float, float, object]:
    """``(warm-up seconds, median seconds of repeats calls, last result)`` of ``call()``."""
    began = time.perf_counter()
    result = call()
    warm_up = time.perf_counter() - began
    times = []
    for _ in range(repeats):
        began = time.perf_counter()
        result = call()
        times.append(time.perf_counter() - began)
    return warm_up, statistics.median(times), result


def interleaved(calls, repeats: int) -> list[tuple[float, float, object]]:
    """``timed`` of several calls, each warmed up once, then called in turn within each of
    ``repeats`` passes (so a busy spell of a shared machine hits them alike)."""
    warm_ups, results = [], []
    for call in calls:
        began = time.perf_counter()
        results.append(call())
        warm_ups.append(time.perf_counter() - began)
    times = [[] for _ in calls]
    for _ in range(repeats):
        for i, call in enumerate(calls):
            began = time.perf_counter()
            results[i] = call()
            times[i].append(time.perf_counter() - began)
    return [(warm_up, statistics.median(spent), result)
            for warm_up, spent, result in zip(warm_ups, times, results)]


def markdown(header: tuple[str, ...], rows: list[tuple], right: str) -> str:
    """A Markdown table with padded columns; ``right[i]`` is "r" for a right-aligned column."""
    cells = [tuple(header)] + [tuple(str(v) for v in row) for row in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(len(header))]

    def line(row):
        return "| " + " | ".join(v.rjust(w) if a == "r" else v.ljust(w)
                                 for v, w, a in zip(row, widths, right)) + " |"

    rule = "| " + " | ".join("-" * (w - 1) + (":" if a == "r" else "-")
                             for w, a in zip(widths, right)) + " |"
    return "\n".join([line(cells[0]), rule] + [line(row) for row in cells[1:]])


# --- 1. prioritised planning ------------------------------------------------------------------


def bench_prioritized(mapf: Path, agents: int, orders: list[str], repeats: int):
    """Part 1: (table rows, whether every solved plan is valid and every call deterministic)."""
    instance = load_instance(mapf / f"{PLAN_MAP}.map", mapf / f"{PLAN_MAP}-random-1.scen", agents)
    graph, starts, goals = instance.graph, instance.starts, instance.goals
    rows, ok, bound = [], True, None
    for order in orders:
        expanded = []

        def call():
            plan = prioritized(graph, starts, goals, order=order)
            expanded.append(plan.stats["expanded"])
            return plan

        warm_up, wall, plan = timed(call, repeats)
        if bound is None:  # after the first warm-up, which compiles the hop fields it needs
            bound = lower_bound(graph, starts, goals)
        same = len(set(expanded)) == 1
        problems = validate(graph, plan.paths, starts, goals, plan.lengths) if plan.solved else []
        valid = ("yes" if not problems else f"NO: {problems[0]}") if plan.solved else \
            f"not solved: {plan.reason}"
        ok &= same and not problems
        rows.append((order, agents, f"{warm_up:.2f}", f"{1e3 * wall:.1f}",
                     f"{expanded[-1]:,}" + ("" if same else " (DIFFERS)"),
                     f"{expanded[-1] / wall / 1e3:,.0f}", f"{plan.sum_of_costs:,}", f"{bound:,}",
                     f"{plan.sum_of_costs / bound:.3f}", plan.makespan, valid))
    return instance.name, rows, ok


# --- 2. conflict check ------------------------------------------------------------------------


def walks(graph, agents: int, steps: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``(random walks, conflict-free walks)``, both i32[agents, steps], of the same starts
    (distinct free cells) and the same picks (a direction slot or a wait per agent and step)."""
    nbr = np.asarray(graph.nbr)
    valid = np.asarray(graph.valid_edges())
    free = np.nonzero(np.asarray(graph.free))[0]
    if agents > free.size:
        raise ValueError(f"{agents} agents but only {free.size} free cells")
    rng = np.random.default_rng(seed)
    starts = rng.choice(free, agents, replace=False).astype(np.int32)
    slots = nbr.shape[1]
    picks = rng.integers(0, slots + 1, size=(steps - 1, agents))  # slot == slots: a wait
    ids = np.arange(agents)
    result = []
    for avoid in (False, True):
        paths = np.empty((agents, steps), np.int32)
        paths[:, 0] = here = starts
        for t, pick in enumerate(picks, start=1):
            slot = np.minimum(pick, slots - 1)
            moves = (pick < slots) & valid[here, slot]
            there = np.where(moves, nbr[here, slot], here)
            if avoid:
                occupied = np.zeros(graph.num_nodes, bool)
                occupied[here] = True
                picked = np.bincount(there[moves], minlength=graph.num_nodes)
                moves &= ~occupied[there] & (picked[there] == 1)
                there = np.where(moves, there, here)
            paths[ids, t] = here = there
        result.append(paths)
    return result[0], result[1]


def python_conflicts(paths: np.ndarray) -> tuple[list[list[bool]], list[list[int]]]:
    """``find_conflicts``'s results by a per-time-step hash check in pure Python: per step, A
    vertex flags and A swap partners (-1 where none), as lists."""
    rows = paths.T.tolist()
    agents = len(rows[0])
    ids = range(agents)
    downward = range(agents - 1, -1, -1)
    no_conflict = [False] * agents
    last = len(rows) - 1
    vertex, swap = [], []
    for t, here in enumerate(rows):
        after = rows[t + 1] if t < last else here
        lowest = dict(zip(reversed(here), downward))  # node -> lowest agent id on it
        if len(lowest) == agents:
            vertex.append(no_conflict)
        else:
            crowded = {v for a, v in zip(ids, here) if lowest[v] != a}
            vertex.append([v in crowded for v in here])
        get = lowest.get
        swap.append([o if u != w and (o := get(w, -1)) >= 0 and after[o] == u else -1
                     for u, w in zip(here, after)])
    return vertex, swap


def first_difference(ours, theirs) -> str:
    """Where two (vertex, swap) results differ first, in words ("" if they are equal)."""
    for name, mine, other in (("vertex", ours.vertex, theirs[0]), ("swap", ours.swap, theirs[1])):
        other = np.asarray(other, mine.dtype)
        if other.shape != mine.shape:
            return f"{name} shapes {mine.shape} and {other.shape}"
        wrong = np.argwhere(mine != other)
        if wrong.size:
            t, a = wrong[0]
            return (f"{name} at step {t}, agent {a}: find_conflicts {mine[t, a]}, Python "
                    f"{other[t, a]} ({len(wrong)} entries differ)")
    return ""


def bench_conflicts(graph, solutions: dict[str, np.ndarray], repeats: int):
    """Part 2: (table rows, speed-ups by solution); exits 1 if the two checks disagree."""
    rows, speedups = [], {}
    for name, paths in solutions.items():
        agent_steps = paths.size
        (py_warm, py_wall, theirs), (jax_warm, jax_wall, ours) = interleaved(
            (lambda: python_conflicts(paths), lambda: find_conflicts(paths, graph.num_nodes)),
            repeats)
        differs = first_difference(ours, theirs)
        if differs:
            sys.exit(f"{name}: find_conflicts and the Python check differ: {differs}")
        speedups[name] = py_wall / jax_wall
        flagged = (f"{int(ours.vertex.sum()):,}", f"{int((ours.swap >= 0).sum()):,}")
        shape = f"{paths.shape[0]:,} x {paths.shape[1]:,}"
        rows.append((name, "Python hash check", shape, *flagged, f"{py_warm:.2f}",
                     f"{1e3 * py_wall:.1f}", f"{agent_steps / py_wall / 1e6:.2f}", "", ""))
        rows.append((name, "find_conflicts", shape, *flagged, f"{jax_warm:.2f}",
                     f"{1e3 * jax_wall:.1f}", f"{agent_steps / jax_wall / 1e6:.2f}",
                     f"{speedups[name]:.1f}x",
                     "met" if speedups[name] >= GOAL_SPEEDUP else "NOT met"))
    return rows, speedups


# --- 3. PIBT and LaCAM ------------------------------------------------------------------------


def bench_pibt(mapf: Path, agents: int, steps: int) -> tuple[str, float, int]:
    """Part 3a: ``(instance, median seconds of one PIBT step, agents at their goals after the
    steps)``; the distance fields and the first step (which loads the kernel) untimed."""
    instance = load_instance(mapf / f"{PIBT_MAP}.map", mapf / f"{PIBT_MAP}-random-1.scen", agents)
    starts, goals = agent_nodes(instance.graph, instance.starts, instance.goals)
    moves = Moves.build(instance.graph, goals, hop_fields(instance.graph, goals))
    work = Workspace(moves)
    current, priorities = starts, initial_priorities(moves, starts)
    nothing = np.zeros(0, np.int32)
    times = []
    for _ in range(steps + 1):
        order = by_priority(priorities)
        following = np.empty_like(current)
        began = time.perf_counter()
        configuration(moves, work, current, order, nothing, nothing, following)
        times.append(time.perf_counter() - began)
        next_priorities(priorities, following, goals, priorities)
        current = following
    return instance.name, statistics.median(times[1:]), int((current == goals).sum())


def bench_lacam(mapf: Path, instances: list[tuple[str, int]]) -> tuple[list[tuple], bool]:
    """Part 3b: (table rows, whether every instance was solved with a valid plan)."""
    rows, ok = [], True
    for name, agents in instances:
        instance = load_instance(mapf / f"{name}.map", mapf / f"{name}-random-1.scen", agents)
        graph, starts, goals = instance.graph, instance.starts, instance.goals
        bound = lower_bound(graph, starts, goals)
        for swap in (False, True):
            lacam(graph, starts[:2], goals[:2], swap=swap)  # load the kernels
            began = time.perf_counter()
            plan = lacam(graph, starts, goals, swap=swap)
            total = time.perf_counter() - began
            valid = plan.solved and not validate(graph, plan.paths, starts, goals, plan.lengths)
            ok &= valid
            rows.append(_lacam_row(name, agents, plan, valid, total, bound))
    return rows, ok


def _lacam_row(name: str, agents: int, plan, valid: bool, total: float, bound: int) -> tuple:
    """One row of part 3b's table."""
    return (name, agents, plan.planner, "yes" if valid else f"NO: {plan.reason}",
            f"{plan.stats['field_seconds']:.2f}", f"{plan.stats['seconds']:.2f}",
            f"{total:.2f}", f"{plan.stats['configurations']:,}",
            f"{plan.sum_of_costs / bound:.2f}" if plan.solved else "-",
            "met" if valid and total <= GOAL_LACAM_S else "NOT met")


# --- 4. LaCAM*'s refinement ---------------------------------------------------------------------


def refined_at(plan, seconds: float) -> tuple[int, int]:
    """``(sum of costs, sum of loss)`` of the best solution LaCAM* knew ``seconds`` after its
    first (``plan.stats`` of a call with ``refine``)."""
    best = (plan.stats["first_soc"], plan.stats["first_sum_of_loss"])
    for at, loss, soc in plan.stats["improvements"]:
        if at <= seconds:
            best = (soc, loss)
    return best


def bench_refinement(mapf: Path, instances: list[tuple[str, int]],
                     refine: float) -> list[tuple]:
    """Part 4, the table over time: one row per instance."""
    rows = []
    for name, agents in instances:
        instance = load_instance(mapf / f"{name}.map", mapf / f"{name}-random-1.scen", agents)
        graph, starts, goals = instance.graph, instance.starts, instance.goals
        lacam(graph, starts[:2], goals[:2], swap=True, refine=0.01)  # load the kernels
        plan = lacam(graph, starts, goals, swap=True, refine=refine)
        if not plan.solved:
            rows.append((name, agents, f"NO: {plan.reason}") + ("-",) * 6)
            continue
        checkpoints = [refined_at(plan, at) for at in REFINE_CHECKPOINTS if at <= refine]
        rows.append((name, agents, f"{plan.stats['first_soc']:,} / "
                                   f"{plan.stats['first_sum_of_loss']:,}")
                    + tuple(f"{soc:,} / {loss:,}" for soc, loss in checkpoints)
                    + ("-",) * (len(REFINE_CHECKPOINTS) - len(checkpoints))
                    + (f"{plan.stats['configurations']:,}",
                       "yes" if plan.stats["optimal"] else "no"))
    return rows


def bench_refinement_check(mapf: Path, refine: float) -> tuple[list[tuple], int]:
    """Part 4, the check: (rows, how many of the five instances improved their sum of loss)."""
    name, agents = "random-32-32-20", 100
    rows, improved = [], 0
    for scenario, first_row in REFINE_CHECK:
        instance = load_instance(mapf / f"{name}.map", mapf / f"{name}-{scenario}.scen",
                                 first_row + agents)
        graph = instance.graph
        starts, goals = instance.starts[first_row:], instance.goals[first_row:]
        plan = lacam(graph, starts, goals, swap=True, refine=refine)
        if not plan.solved:
            rows.append((f"{scenario} rows {first_row}-{first_row + agents - 1}",
                         f"NO: {plan.reason}", "-", "-", "-"))
            continue
        first, loss = plan.stats["first_sum_of_loss"], plan.stats["sum_of_loss"]
        improved += loss < first
        rows.append((f"{scenario} rows {first_row}-{first_row + agents - 1}", f"{first:,}",
                     f"{loss:,}", f"{plan.stats['configurations']:,}",
                     "yes" if loss < first else "no"))
    return rows, improved


def bench_cbs(mapf: Path, files: list[str], nodes: int, repeats: int) -> tuple[list[tuple],
                                                                              bool]:
    """Part 5: (table rows, whether every call of a file did the same work and every solved
    plan is valid)."""
    rows, same = [], True
    for scenario in files:
        name = scenario.rsplit("-", 2)[0]  # the map's name: without "-even-1" or "-random-1"
        instance = load_instance(mapf / f"{name}.map", mapf / f"{scenario}.scen", CBS_AGENTS)
        graph, starts, goals = instance.graph, instance.starts, instance.goals
        registry.plan("cbsh_rtc", graph, starts[:3], goals[:3])  # load the kernels
        times, work = [], set()
        for _ in range(repeats):
            began = time.perf_counter()
            plan = registry.plan("cbsh_rtc", graph, starts, goals, max_nodes=nodes, time_limit=600)
            times.append(time.perf_counter() - began)
            work.add((plan.stats["nodes"], plan.stats["expanded"], plan.stats["pairs"]))
        same &= len(work) == 1 and (not plan.solved or not validate(graph, plan.paths, starts,
                                                                    goals, plan.lengths))
        split, states, pairs = work.pop()
        median = statistics.median(times)
        rows.append((scenario, CBS_AGENTS, f"{split:,}", f"{median:.2f}", f"{split / median:,.0f}",
                     f"{states / median / 1e3:,.0f}", f"{pairs:,}",
                     "yes" if plan.solved else f"no ({plan.stats['lower_bound']} bound)"))
    return rows, same


def instance_list(parser: argparse.ArgumentParser, option: str,
                  text: str) -> list[tuple[str, int]]:
    """``[(map, agents), ...]`` of ``"MAP:AGENTS,..."``; the parser's error naming ``option``
    otherwise."""
    try:
        return [(name, int(count)) for name, count in
                (entry.split(":") for entry in text.split(","))]
    except ValueError:
        parser.error(f"{option}: expected MAP:AGENTS,..., got {text!r}")


def main(argv: list[str] | None = None) -> int:
    """Parse the options, run both parts, print the tables; 1 if a result is wrong."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--agents", type=int, default=100,
                        help=f"agents of part 1: the first rows of {PLAN_MAP}-random-1.scen")
    parser.add_argument("--orders", default="given,distance,random",
                        help=f"comma-separated priority orders, from {', '.join(ORDERS)}")
    parser.add_argument("--repeats", type=int, default=10, help="timed calls per order")
    parser.add_argument("--check-map", default="random-64-64-10",
                        help="the Moving AI MAPF map of part 2 (loaded 4-connected)")
    parser.add_argument("--check-agents", type=int, default=1000, help="agents of part 2")
    parser.add_argument("--check-steps", type=int, default=1000, help="time steps of part 2")
    parser.add_argument("--check-repeats", type=int, default=7,
                        help="timed calls of each check per solution")
    parser.add_argument("--seed", type=int, default=0, help="seed of part 2's walks")
    parser.add_argument("--pibt-agents", type=int, default=400,
                        help=f"agents of PIBT's step: the first rows of {PIBT_MAP}-random-1.scen")
    parser.add_argument("--pibt-steps", type=int, default=200, help="PIBT steps timed")
    parser.add_argument("--lacam", default=LACAM_INSTANCES,
                        help="LaCAM's instances, MAP:AGENTS comma-separated (random-1 scenarios)")
    parser.add_argument("--refine", type=float, default=10.0,
                        help="seconds of LaCAM*'s refinement per instance in part 4 (0: skip)")
    parser.add_argument("--refine-instances", default=REFINE_INSTANCES,
                        help="part 4's instances, MAP:AGENTS comma-separated (random-1 "
                             "scenarios)")
    parser.add_argument("--cbs", default=CBS_FILES,
                        help="CBSH-RTC's scenario files, comma-separated (first 20 rows each)")
    parser.add_argument("--cbs-nodes", type=int, default=2000,
                        help="constraint-tree nodes after which each CBSH-RTC call stops")
    parser.add_argument("--cbs-repeats", type=int, default=3, help="timed CBSH-RTC calls")
    parser.add_argument("--threads", type=int, default=1,
                        help="XLA:CPU intra-op threads (jaxswarm.runtime.cpu.configure)")
    parser.add_argument("--data", type=Path, default=REPO.parent / "shared",
                        help="the shared directory holding benchdata/movingai/mapf "
                             "(default: ../shared next to the repository)")
    parser.add_argument("--quick", action="store_true",
                        help="a smoke test: 2 repeats of each part, 200 agents x 200 steps in "
                             "part 2")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeats, args.check_repeats, args.check_agents, args.check_steps = 2, 2, 200, 200
        args.pibt_steps, args.lacam = 20, "random-32-32-20:100"
        args.refine, args.refine_instances = 1.0, "random-32-32-20:100"
        args.cbs_nodes, args.cbs_repeats = 200, 2
    for name in ("agents", "repeats", "check_agents", "check_repeats", "threads", "pibt_agents",
                 "pibt_steps", "cbs_nodes", "cbs_repeats"):
        if getattr(args, name) < 1:
            parser.error(f"--{name.replace('_', '-')} must be at least 1")
    if not args.refine >= 0:
        parser.error(f"--refine must be at least 0, got {args.refine}")
    if args.check_steps < 2:
        parser.error("--check-steps must be at least 2")
    orders = args.orders.split(",")
    unknown = [order for order in orders if order not in ORDERS]
    if unknown:
        parser.error(f"--orders: unknown {', '.join(unknown)}; known: {', '.join(ORDERS)}")
    mapf = args.data / MAPF_DIR
    check_map = mapf / f"{args.check_map}.map"
    if not check_map.is_file():
        parser.error(f"no {check_map} (use --data or --check-map)")
    for scenario in args.cbs.split(","):
        for path in (mapf / f"{scenario.rsplit('-', 2)[0]}.map", mapf / f"{scenario}.scen"):
            if not path.is_file():
                parser.error(f"--cbs: no {path} (a scenario file's name, as "
                             f"room-32-32-4-even-1)")
    configure(threads=args.threads)  # before JAX's first computation

    began = time.perf_counter()
    print(f"machine: {machine()}, {args.threads} XLA thread(s)")
    name, rows, plans_ok = bench_prioritized(mapf, args.agents, orders, args.repeats)
    print(f"\nPrioritised planning on {name}: median of {args.repeats} calls after a warm-up\n")
    print(markdown(("order", "agents", "warm-up s", "median ms", "expanded", "k exp/s", "SoC",
                    "bound", "SoC/bound", "makespan", "valid"), rows, "lrrrrrrrrrl"))

    graph = grid_graph(read_map(check_map), connectivity=4)
    random_walks, free_walks = walks(graph, args.check_agents, args.check_steps, args.seed)
    solutions = {"random walks": random_walks, "conflict-free walks": free_walks}
    rows, speedups = bench_conflicts(graph, solutions, args.check_repeats)
    # After the timings: validate calls find_conflicts, which would warm it up for the shape.
    problems = validate(graph, free_walks, free_walks[:, 0], free_walks[:, -1])
    if problems:
        sys.exit(f"the conflict-free walks are not valid: {problems[0]}")
    print(f"\nConflict check on {args.check_map} ({int(np.asarray(graph.free).sum()):,} free cells"
          f", {graph.num_nodes:,} nodes; seed {args.seed}): median of {args.check_repeats} calls "
          f"after a warm-up; equal results (vertex flags and swap partners) on every solution\n")
    print(markdown(("solution", "check", "agents x steps", "vertex flags", "swaps", "warm-up s",
                    "median ms", "M agent-steps/s", "speed-up", f"{GOAL_SPEEDUP:.0f}x goal"),
                   rows, "lllrrrrrrl"))
    met = [name for name, ratio in speedups.items() if ratio >= GOAL_SPEEDUP]
    print(f"\nvertex flags, swaps: agent-steps flagged (find_conflicts and the Python check agree)."
          f" Goal: the batched check at least {GOAL_SPEEDUP:.0f}x faster than the Python one: "
          f"met on {len(met)} of {len(speedups)} solutions"
          f"{' (' + ', '.join(met) + ')' if met and len(met) < len(speedups) else ''}.")
    name, step, arrived = bench_pibt(mapf, args.pibt_agents, args.pibt_steps)
    print(f"\nPIBT on {name}: median of {args.pibt_steps} steps after the first, distance fields "
          f"excluded\n")
    print(markdown(("agents", "median us", "steps/s", "at goals after",
                    f"{GOAL_STEP_MS:g} ms goal"),
                   [(args.pibt_agents, f"{1e6 * step:.0f}", f"{1 / step:,.0f}",
                     f"{arrived} of {args.pibt_agents}",
                     "met" if 1e3 * step < GOAL_STEP_MS else "NOT met")], "rrrrl"))
    instances = instance_list(parser, "--lacam", args.lacam)
    refine_instances = instance_list(parser, "--refine-instances", args.refine_instances)
    rows, lacam_ok = bench_lacam(mapf, instances)
    print(f"\nLaCAM, one call per instance after a warm-up on 2 agents, {args.threads} XLA "
          f"thread(s)\n")
    print(markdown(("map", "agents", "planner", "valid", "fields s", "search s", "total s",
                    "configurations", "SoC/bound", f"{GOAL_LACAM_S:g} s goal"), rows,
                   "lrllrrrrrl"))
    plans_ok &= lacam_ok
    if args.refine > 0:
        rows = bench_refinement(mapf, refine_instances, args.refine)
        print(f"\nLaCAM* (swap) refining for {args.refine:g} s after its first solution: sum of "
              f"costs / sum of loss over time, one call per instance\n")
        print(markdown(("map", "agents", "first solution") + tuple(
            f"after {at:g} s" for at in REFINE_CHECKPOINTS) + ("configurations", "optimal"),
            rows, "lrrrrrrrl"))
        rows, improved = bench_refinement_check(mapf, args.refine)
        print(f"\nLaCAM* (swap) on five 100-agent instances of random-32-32-20, {args.refine:g} s "
              f"of refinement each: sum of loss\n")
        print(markdown(("instance", "first", "refined", "configurations", "lower"), rows,
                       "lrrrl"))
        print(f"\nGoal: below the first solution's sum of loss on at least {GOAL_REFINED} of "
              f"{len(REFINE_CHECK)}: {'met' if improved >= GOAL_REFINED else 'NOT met'} "
              f"({improved} of {len(REFINE_CHECK)}).")
    rows, cbs_ok = bench_cbs(mapf, args.cbs.split(","), args.cbs_nodes, args.cbs_repeats)
    print(f"\nCBSH-RTC, stopped after {args.cbs_nodes:,} nodes: median of {args.cbs_repeats} "
          f"calls after a warm-up on 3 agents\n")
    print(markdown(("scenario", "agents", "nodes", "median s", "nodes/s", "k states/s", "pairs",
                    "solved"), rows, "lrrrrrrl"))
    plans_ok &= cbs_ok
    verdict = "every plan valid" if plans_ok else "A PLAN IS INVALID OR DIFFERS (see above)"
    print(f"plans: {verdict} | benchmark took {time.perf_counter() - began:.0f} s")
    return 0 if plans_ok else 1


if __name__ == "__main__":
    sys.exit(main())
