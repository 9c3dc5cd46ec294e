"""The one solution format of the multi-agent planners.

A solution is ``paths`` i32[A, T], the node of every agent at every time step 0..T-1, each row
padded to T by repeating its last node, with ``lengths`` i32[A]: the step from which the agent
is at its goal for good (its cost; waits before that count, waits at the goal after it do not).
The sum of costs is ``lengths.sum()``, the makespan ``lengths.max()``.
"""
from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np


@dataclasses.dataclass(frozen=True)
class Plan:
    """A multi-agent planner's answer.

    Attributes:
      paths: i32[A, T] node indices, padded by repeating each row's last node. When ``solved``
        is False these are what the planner had when it stopped (unplanned agents wait at their
        starts), not a solution.
      lengths: i32[A] each agent's arrival step (see the module docstring).
      solved: whether ``paths`` is a solution.
      planner: the planner's name.
      reason: why it is not solved, naming the agent ("" when solved).
      agent: the agent that could not be planned, or None.
      stats: planner statistics (``expanded`` low-level states, ``nodes`` CBS nodes, ``seconds``).
      log: the planner's messages, in order (the report's scheme prints its decisions).
    """

    paths: np.ndarray
    lengths: np.ndarray
    solved: bool
    planner: str
    reason: str = ""
    agent: int | None = None
    stats: dict = dataclasses.field(default_factory=dict)
    log: tuple[str, ...] = ()

    @property
    def sum_of_costs(self) -> int:
        """Sum of the agents' arrival steps."""
        return int(self.lengths.sum())

    @property
    def makespan(self) -> int:
        """The latest arrival step."""
        return int(self.lengths.max())


def pack(paths: Sequence[Sequence[int]], goals=None) -> tuple[np.ndarray, np.ndarray]:
    """Padded ``(paths i32[A, T], lengths i32[A])`` of per-agent node sequences.

    Args:
      paths: A non-empty node sequences.
      goals: optional i32[A]; an agent's length is then its arrival step at its goal for good
        (the whole path's last step if it does not end there), else each path's last step.
    """
    rows = [np.asarray(path, np.int32).reshape(-1) for path in paths]
    if any(row.size == 0 for row in rows):
        raise ValueError("every agent's path needs at least its start")
    steps = max(row.size for row in rows)
    padded = np.empty((len(rows), steps), np.int32)
    for agent, row in enumerate(rows):
        padded[agent, :row.size] = row
        padded[agent, row.size:] = row[-1]
    if goals is None:
        return padded, np.array([row.size - 1 for row in rows], np.int32)
    return padded, arrival_steps(padded, goals)


def arrival_steps(paths: np.ndarray, goals) -> np.ndarray:
    """i32[A]: for each row of ``paths`` (i32[A, T]), the first step from which it stays at its
    goal to the end; T - 1 where it does not end at its goal."""
    paths = np.asarray(paths)
    away = paths != np.asarray(goals, np.int32)[:, None]
    steps = paths.shape[1]
    last_away = steps - 1 - np.argmax(away[:, ::-1], axis=1)
    return np.where(away.any(axis=1), np.minimum(last_away + 1, steps - 1), 0).astype(np.int32)

