"""The one validator of multi-agent solutions.

A solution (:mod:`jaxswarm.multiagent.plan`) is valid when every row starts at its agent's start,
every step is a wait on a free node or a move along a valid edge of the graph given (load the
MAPF maps 4-connected), no two agents share a node at a step (vertex conflict) or exchange nodes
in a step (swap conflict, :mod:`jaxswarm.multiagent.conflicts`), and every agent ends at its goal
and, from its length on, stays there.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from jaxswarm.multiagent.agents import agent_nodes
from jaxswarm.multiagent.conflicts import find_conflicts
from jaxswarm.world.graph import Graph


@dataclasses.dataclass(frozen=True)
class Violation:
    """One broken rule.

    Attributes:
      kind: "shape", "start", "node", "move", "goal", "vertex" or "swap".
      agents: the agents concerned.
      step: the time step (for a move or a swap, the step it leaves from), or None.
      message: the whole story, e.g. "vertex conflict at step 4: agents 0 and 2 on node 17".
    """

    kind: str
    agents: tuple[int, ...]
    step: int | None
    message: str

    def __str__(self) -> str:
        return self.message


def validate(graph: Graph, paths, starts, goals, lengths=None) -> list[Violation]:
    """The violations of a multi-agent solution (empty when it is valid).

    Args:
      graph: the map; its valid edges are the allowed moves.
      paths: i32[A, T] node indices, padded by repeating the goal.
      starts, goals: (x, y) cells or node indices, one per agent (checked as the planners check
        them: ValueError for a bad instance).
      lengths: optional i32[A] arrival steps; each agent must then be at its goal from its
        length to the end.

    Returns:
      A list of :class:`Violation`, in the order shape, start, node, move, goal, vertex, swap.
    """
    start_nodes, goal_nodes = agent_nodes(graph, starts, goals)
    paths = np.asarray(paths)
    agents = len(start_nodes)
    if paths.ndim != 2 or paths.shape[0] != agents or paths.shape[1] == 0:
        return [Violation("shape", (), None, f"paths must be [{agents} agents, steps], "
                                             f"got shape {paths.shape}")]
    if lengths is not None and np.shape(lengths) != (agents,):
        return [Violation("shape", (), None, f"lengths must be [{agents}], "
                                             f"got shape {np.shape(lengths)}")]
    problems = [Violation("start", (a,), 0, f"agent {a} starts at node {paths[a, 0]}, "
                                            f"not at its start {start_nodes[a]}")
                for a in np.nonzero(paths[:, 0] != start_nodes)[0].tolist()]
    off_map = (paths < 0) | (paths >= graph.num_nodes)
    for a in np.nonzero(off_map.any(axis=1))[0].tolist():
        step = int(np.argmax(off_map[a]))
        problems.append(Violation("node", (a,), step, f"agent {a} is on node {paths[a, step]} "
                                                      f"at step {step}: not a node of the map"))
    if problems and problems[-1].kind == "node":
        return problems  # the remaining checks index the map by these nodes
    problems += _bad_moves(graph, paths)
    problems += _goal_violations(paths, goal_nodes, lengths)
    problems += _conflict_violations(paths, graph.num_nodes)
    return problems


def _bad_moves(graph: Graph, paths: np.ndarray) -> list[Violation]:
    here, there = paths[:, :-1], paths[:, 1:]
    nbr = np.asarray(graph.nbr)
    edge = ((nbr[here] == there[..., None]) & np.asarray(graph.valid_edges())[here]).any(-1)
    free = np.asarray(graph.free)
    ok = np.where(here == there, free[here], edge)
    problems = [Violation("node", (a,), 0, f"agent {a} starts on blocked node {paths[a, 0]}")
                for a in np.nonzero(~free[paths[:, 0]])[0].tolist()]
    for a, step in zip(*np.nonzero(~ok)):
        u, v = int(here[a, step]), int(there[a, step])
        what = f"waits on blocked node {u}" if u == v else f"jumps from node {u} to {v} (no edge)"
        problems.append(Violation("move", (int(a),), int(step),
                                  f"agent {a} {what} at step {step}"))
    return problems


def _goal_violations(paths, goal_nodes, lengths) -> list[Violation]:
    problems = []
    for a in range(paths.shape[0]):
        goal = goal_nodes[a]
        if paths[a, -1] != goal:
            problems.append(Violation("goal", (a,), paths.shape[1] - 1,
                                      f"agent {a} ends on node {paths[a, -1]}, not at its "
                                      f"goal {goal}"))
        elif lengths is not None:
            length = int(lengths[a])
            away = np.nonzero(paths[a, max(length, 0):] != goal)[0]
            if length < 0 or away.size:
                step = max(length, 0) + int(away[0]) if away.size else 0
                problems.append(Violation("goal", (a,), step,
                                          f"agent {a} is away from its goal {goal} at step "
                                          f"{step}, after its length {length}"))
    return problems


def _conflict_violations(paths: np.ndarray, num_nodes: int) -> list[Violation]:
    found = find_conflicts(paths, num_nodes)
    problems = []
    for step in np.nonzero(found.vertex.any(axis=1))[0].tolist():
        crowded = np.nonzero(found.vertex[step])[0]
        nodes = paths[crowded, step]
        for node in np.unique(nodes).tolist():
            agents = tuple(crowded[nodes == node].tolist())
            problems.append(Violation("vertex", agents, step, f"vertex conflict at step {step}: "
                                      f"agents {_names(agents)} on node {node}"))
    for step, a in zip(*np.nonzero(found.swap >= 0)):
        b = int(found.swap[step, a])
        if a < b or found.swap[step, b] != a:  # each swap once
            problems.append(Violation("swap", (int(a), b), int(step),
                                      f"swap conflict between steps {step} and {step + 1}: "
                                      f"agents {a} and {b} exchange nodes {paths[a, step]} and "
                                      f"{paths[b, step]}"))
    return problems


def _names(agents: tuple[int, ...]) -> str:
    return ", ".join(map(str, agents[:-1])) + f" and {agents[-1]}"
