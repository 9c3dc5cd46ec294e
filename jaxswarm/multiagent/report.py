"""The A* report's multi-robot scheme (``shared/papers/004``, section 5), as it describes it.

1. Each robot gets its own A* path (:func:`jaxswarm.exact.astar`, the map's edge lengths).
2. The paths are checked for a collision: two robots on one cell at one step, or two robots
   exchanging cells in one step. The collision step ``t`` is the step they arrive at.
3. At a collision between robot 1 and robot 2, the possible moves of robot 2 are the free
   neighbours of the cell it occupied before the collision, except robot 1's cells at ``t - 1``
   and ``t``, nearest to robot 2's goal first. Robot 2 side-steps to the first whose plan has no
   collision with robot 1's: robot 2 keeps its path to ``t - 1``, steps aside at ``t`` and
   re-plans A* from there, while robot 1 waits one step (the report's first printed example:
   robot 1's path gains a repeated cell, robot 2's the side-step).
4. If no possible move gives a plan without collision, the robots cannot move at the same time:
   robot 2 moves first (re-planned around robot 1's start, where robot 1 waits) and robot 1
   starts when robot 2 has reached its goal (re-planned around that goal, where robot 2 then
   stays). This is the report's second example. If either re-plan fails, there is no plan.

For more than two robots (the report has two) the scheme is applied pairwise in priority order
(this module's choice): the pair ``(i, j)``, ``i < j``, that comes first in lexicographic order
among those that collide is repaired with ``i`` as robot 1 and ``j`` as robot 2, and the check
starts again, until no pair collides or ``max_repairs`` repairs were made.

The report's figures (its two 10 x 10 maps) are not in its text; :data:`REPORT_EXAMPLES` holds
the smallest obstacle sets under which the printed candidate moves and paths come out (see the
tests). Its grids are 8-connected with corner cutting ("the diagonal box is a valid move").
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from jaxswarm.exact import astar
from jaxswarm.multiagent.agents import agent_nodes, distance_fields
from jaxswarm.multiagent.conflicts import pair_collisions
from jaxswarm.multiagent.limits import check_count
from jaxswarm.multiagent.plan import Plan, pack
from jaxswarm.world.edges import edge_arrays
from jaxswarm.world.edits import block_cells
from jaxswarm.world.graph import Graph, grid_graph

REPORT_EXAMPLES = {
    # map 1: the diagonal crosses a cluster of obstacles around (5, 5), leaving robot 2 the
    # printed possible moves [(4, 5), (6, 6)]; (3, 4) makes its re-plan from (4, 5) unique.
    "map1": {"obstacles": ((3, 4), (4, 6), (5, 4), (5, 6), (6, 4), (6, 5)),
             "starts": ((0, 0), (9, 9)), "goals": ((9, 9), (0, 0))},
    # map 2: two open rows joined by a one-cell corridor in column 5.
    "map2": {"obstacles": tuple((x, y) for y in range(1, 9) for x in range(10) if x != 5),
             "starts": ((4, 0), (6, 9)), "goals": ((4, 9), (6, 0))},
}
"""The report's two examples: obstacle cells (x, y) of a 10 x 10 grid, the robots' starts and
goals."""


def report_example(name: str) -> tuple[Graph, tuple, tuple]:
    """``(graph, starts, goals)`` of a report example ("map1" or "map2"): a 10 x 10 grid,
    8-connected with corner cutting, as the report plans."""
    example = REPORT_EXAMPLES[name]
    blocked = np.zeros((10, 10), bool)
    for x, y in example["obstacles"]:
        blocked[y, x] = True
    graph = grid_graph(blocked, connectivity=8, corner_cutting=True)
    return graph, example["starts"], example["goals"]


@dataclasses.dataclass(frozen=True)
class ReportConfig:
    """The options of :func:`report_scheme`, checked when made.

    Attributes:
      max_repairs: give up after this many repairs (at least 0; None: 20 per robot).

    Raises:
      TypeError, ValueError: a ``max_repairs`` that is not None or a whole number of at least 0.
    """

    max_repairs: int | None = None

    def __post_init__(self):
        if self.max_repairs is not None:
            check_count("max_repairs", self.max_repairs, least=0)


def report_scheme(graph: Graph, starts, goals, **options) -> Plan:
    """The A* report's scheme: A* per robot, then side-steps, waits and "one robot moves first"
    at collisions (see the module docstring).

    Args:
      graph: the map; A* plans with its edge lengths, every move takes one step.
      starts, goals: (x, y) cells (or node indices), one per robot, all distinct.
      **options: those of :class:`~jaxswarm.multiagent.report.ReportConfig` (``max_repairs``).

    Returns:
      A :class:`~jaxswarm.multiagent.plan.Plan` (``planner="report"``) whose ``log`` has the
      report's messages; not solved, naming the robots, when a robot has no A* path, both fallback
      re-plans fail, or the repairs run out.

    Raises:
      TypeError, ValueError: a bad option (see :class:`~jaxswarm.multiagent.report.ReportConfig`),
        naming it.
      ValueError: a bad instance (see :func:`jaxswarm.multiagent.agents.agent_nodes`).
    """
    config = ReportConfig(**options)
    began = time.perf_counter()
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    robots = len(start_nodes)
    limit = 20 * robots if config.max_repairs is None else config.max_repairs
    scheme = _Scheme(goal_nodes, np.asarray(graph.xy).astype(int), began)
    paths = []
    for r in range(robots):
        path = _astar(graph, start_nodes[r], goal_nodes[r])
        if path is None:
            paths.append([int(start_nodes[r])])
            return scheme.finish(paths + [[int(s)] for s in start_nodes[r + 1:]], False,
                                 f"agent {r} has no path to its goal", r)
        paths.append(path)
        scheme.log.append(f"robot{r + 1} initialized path : {scheme.cells(path)}")
    return _repair_collisions(scheme, graph, paths, distance_fields(graph, goal_nodes), limit)


@dataclasses.dataclass
class _Scheme:
    """One run of the scheme: where the robots go, what it has logged and how many repairs it
    made.

    Attributes:
      goal_nodes: i32[R] the robots' goals.
      xy: int[N, 2] every node's cell (x, y), for the log.
      began: ``time.perf_counter()`` when the run began.
      log: the report's messages so far.
      repairs: the repairs made so far.
    """

    goal_nodes: np.ndarray
    xy: np.ndarray
    began: float
    log: list[str] = dataclasses.field(default_factory=list)
    repairs: int = 0

    def cells(self, path) -> str:
        """The nodes of ``path`` as the report prints them: ``[(x, y), ...]``."""
        return "[" + ", ".join(f"({self.xy[v][0]}, {self.xy[v][1]})" for v in path) + "]"

    def finish(self, paths, solved: bool, reason: str = "", agent=None) -> Plan:
        """The scheme's :class:`~jaxswarm.multiagent.plan.Plan` of ``paths`` (one node list
        per robot)."""
        return Plan(*pack(paths, self.goal_nodes), solved=solved, planner="report",
                    reason=reason, agent=agent,
                    stats={"repairs": self.repairs, "seconds": time.perf_counter() - self.began},
                    log=tuple(self.log))


def _repair_collisions(scheme: _Scheme, graph: Graph, paths: list, to_goal: np.ndarray,
                       limit: int) -> Plan:
    """Repair the first colliding pair of ``paths`` (one node list per robot) until none
    collides (solved), a pair cannot be repaired or ``limit`` repairs were made (not solved).
    ``to_goal``: f32[R, N] every node's distance to each robot's goal."""
    first = pair_collisions(pack(paths)[0])
    while True:
        colliding = np.argwhere(np.triu(first >= 0))
        if colliding.size == 0:
            return scheme.finish(paths, True)
        if scheme.repairs == limit:
            i, j = colliding[0]
            return scheme.finish(paths, False, f"agents {i} and {j} still collide after {limit} "
                                               "repairs", int(j))
        i, j = (int(v) for v in colliding[0])
        scheme.repairs += 1
        repaired = _repair(graph, paths[i], paths[j], int(first[i, j]), to_goal[j], scheme.log,
                           scheme.cells, (i + 1, j + 1))
        if repaired is None:
            return scheme.finish(paths, False, f"agents {i} and {j} cannot pass each other: no "
                                               "side-step and no plan with one moving first", j)
        paths[i], paths[j] = repaired
        # Only the two repaired robots' collisions change (the others, padded with their goals
        # if the new paths are longer, gain none).
        changed = pair_collisions(pack(paths)[0], [i, j])
        first[[i, j], :] = changed
        first[:, [i, j]] = changed.T


def _repair(graph, first, second, step, to_goal, log, cells, names):
    """New paths of robots 1 and 2 (``first``, ``second``: node lists) after their collision
    arriving at ``step``, or None."""
    one, two = names
    padded = pack([first, second])[0]
    log.append(f"collision state at {step}")
    log.append(f"before collision states of robot are robot{two}_state:"
               f"{cells([padded[1, step]])[1:-1]}, robot{one}_state = "
               f"{cells([padded[0, step]])[1:-1]}")
    before = int(padded[1, step - 1])
    taken = {int(padded[0, step - 1]), int(padded[0, step])}
    moves = [v for v in _neighbours(graph, before) if v not in taken]
    moves.sort(key=lambda v: (to_goal[v], v))
    if moves:
        log.append(f"found possible move for robot{two} state : {cells(moves)}")
    for move in moves:
        rest = _astar(graph, move, second[-1])
        if rest is None:
            continue
        held = padded[0].tolist()  # robot 1 may already be at its goal at ``step``
        waiting = held[:step] + [held[step - 1]] + held[step:]
        stepping = padded[1, :step].tolist() + rest
        if (pair_collisions(pack([waiting, stepping])[0])[0, 1] < 0):
            log.append("no collision found")
            return waiting, stepping
    ahead = _astar(block_cells(graph, first[0]), second[0], second[-1])
    after = _astar(block_cells(graph, second[-1]), first[0], first[-1])
    if ahead is None or after is None:
        return None
    log.append(f"robot{one}_path_possible")
    log.append(f"can not synchronize, robot {two} move first")
    log.append(f"robot{two} path planning:{cells(ahead)}")
    return [first[0]] * (len(ahead) - 1) + after, ahead


def _neighbours(graph: Graph, node: int) -> list[int]:
    """The heads of ``node``'s valid edges, from the map's cached CSR arrays."""
    arrays = edge_arrays(graph)
    return arrays.heads[arrays.indptr[node]:arrays.indptr[node + 1]].tolist()


def _astar(graph: Graph, start, goal) -> list[int] | None:
    """A*'s node list, or None where there is no path or an end is blocked."""
    free = np.asarray(graph.free)
    if not (free[start] and free[goal]):
        return None
    solution = astar(graph, int(start), int(goal))
    return solution.nodes().tolist() if bool(solution.found) else None
