"""The constrained ABC local planner (``cabc``): a vehicle in a plane of rectangles that sees a
square window around itself and, at every step, moves to the point a bee colony picks in it (the
bees paper, sections III-IV).

One ``run`` iteration is one vehicle step: the colony (:mod:`.colony`) starts afresh in the sensor
window (the square of side ``window`` centred on the vehicle, clipped to the plane), runs
``inner_iterations`` cycles on the guided function (:mod:`.guided`) and returns its best point by
Deb's rules. A feasible best point is the vehicle's next position; when no candidate is feasible the
vehicle stays. The vehicle has arrived when it is within ``tolerance`` of the goal; the goal is then
appended to its trajectory, so the path length is the length of a trajectory from start to goal
(never below the optimum of :func:`jaxswarm.exact.visibility.shortest_path`). It moves at most
``max_steps`` times (the paper's M = 200). Sizes the paper leaves open are ours: N = 20 sources; a
window of side 2, so that a move shifts each coordinate by at most 1, less than the thinnest wall of
our maps (2): the vehicle cannot hop over an obstacle, only clip a corner (the paper's vehicle
checks only where it lands, and its map #2 traps it, which a vehicle that hops over walls would not
notice); a tolerance of 0.5. f3 measures the turn in degrees by default (``turn_unit``; why:
:mod:`.guided`).

The module holds cABC's config, params and state, the vehicle's arrival test, the colony's pick
in the sensor window, and the swarm's init, step and change rule, which :func:`build_cabc` binds
to a config.
"""
from __future__ import annotations

import dataclasses
import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.swarm.bees.colony import Best, search
from jaxswarm.swarm.bees.guided import check_turn_unit, constraint_violations, guided, revisits
from jaxswarm.swarm.core import (ParamError, StepInfo, Swarm, SwarmConfig, Task, check_positive,
                                 default_params, shown)
from jaxswarm.world.paths import Solution
from jaxswarm.world.plane import Plane, crossings, trajectory_length


@dataclasses.dataclass(frozen=True)
class CABCConfig(SwarmConfig):
    """Static sizes and switches of cABC.

    Attributes:
      num_agents: N, the colony's food sources (and onlookers) per step (>= 2).
      max_steps: M, the most moves of the vehicle (its trajectory holds M + 2 points).
      forbid_crossing: a move that passes through a rectangle violates it too (off in the paper,
        whose vehicle only checks where it lands: a move may then clip an obstacle's corner).
      remember: the vehicle remembers the windows it has seen and adds ``w4 f4`` to Phi
        (:func:`~jaxswarm.swarm.bees.guided.revisits`; the paper's future work, off).
      turn_unit: f3's unit, one of :data:`~jaxswarm.swarm.bees.guided.TURN_UNITS` (the text
        lost it; see :mod:`.guided` for the choice).
    """

    num_agents: int = 20
    max_steps: int = 200
    forbid_crossing: bool = False
    remember: bool = False
    turn_unit: str = "degrees"

    def __post_init__(self):
        super().__post_init__()
        check_turn_unit(self.turn_unit)
        if self.num_agents < 2:
            raise ValueError(f"cabc needs num_agents >= 2 (a bee moves relative to another), "
                             f"got {self.num_agents}")
        if self.max_steps is None:
            raise ValueError("cabc needs max_steps (the paper's M)")


class CABCParams(NamedTuple):
    """Numbers of cABC (f32 scalars, traced; defaults in brackets).

    Attributes:
      w1, w2, w3: eq. 4's weights of the goal distance, the pushback and the smoothness
        (1.0, 0.2, 0.03: the paper's best on map #1, Table 4; with our f2 and f3 they reach
        the goal in 3 of 20 runs there, see ``results/bees_tables``, where w3 = 0 reaches it
        in all).
      inner_iterations: I, colony cycles per vehicle step, a whole number (8, the paper's
        Tables 1-5).
      window: the side of the sensor window (2).
      limit: trials before a source goes to a scout (40, the paper's 2N for N = 20).
      tolerance: the distance to the goal that counts as arrived (0.5).
      w4: the weight of the revisit penalty, with ``remember`` (0.2: after about seven visits a
        window costs what one step towards the goal gains).
    """

    w1: jax.Array
    w2: jax.Array
    w3: jax.Array
    inner_iterations: jax.Array
    window: jax.Array
    limit: jax.Array
    tolerance: jax.Array
    w4: jax.Array


@dataclasses.dataclass(frozen=True)
class CABCState:
    """The vehicle between steps (a pytree).

    Attributes:
      key: PRNG key.
      waypoints: f32[M + 2, 2] the trajectory so far, start first, NaN padded.
      count: i32[] the points in ``waypoints`` (the vehicle stands at ``waypoints[count - 1]``).
      reached: bool[] the vehicle arrived (the goal is the last waypoint).
    """

    key: jax.Array
    waypoints: jax.Array
    count: jax.Array
    reached: jax.Array


jax.tree_util.register_dataclass(
    CABCState, data_fields=["key", "waypoints", "count", "reached"], meta_fields=[])

WAYPOINTS_LABEL = "trajectory (x, y)"


def cabc_defaults(num_agents: int = 20) -> CABCParams:
    """The default :class:`CABCParams` for a colony of ``num_agents`` sources (limit 2N)."""
    return default_params(CABCParams, w1=1.0, w2=0.2, w3=0.03, inner_iterations=8, window=2.0,
                          limit=2 * num_agents, tolerance=0.5, w4=0.2)


def check_cabc(params: CABCParams) -> None:
    """Host-side check: weights non-negative, I and limit whole numbers (I >= 0, limit >= 1),
    window and tolerance positive.

    Raises:
      ParamError: naming the param.
    """
    for name in ("w1", "w2", "w3", "w4"):
        check_positive(name, getattr(params, name), allow_zero=True)
    for name in ("window", "tolerance"):
        check_positive(name, getattr(params, name))
    for name, low in (("inner_iterations", 0), ("limit", 1)):
        value = np.asarray(getattr(params, name), np.float64)
        if not np.all(np.isfinite(value) & (value == np.round(value)) & (value >= low)):
            raise ParamError(name, f"must be a whole number >= {low}, got {shown(value)}")


def trajectory(state: CABCState) -> Solution:
    """The vehicle's answer: ``path`` f32[M + 2, 2] (NaN padded), ``cost`` its length (inf until
    it arrived), ``found`` whether it arrived."""
    return Solution(path=state.waypoints,
                    cost=jnp.where(state.reached, trajectory_length(state.waypoints), jnp.inf),
                    found=state.reached)


def arrive(state: CABCState, plane: Plane, goal: jax.Array, tolerance: jax.Array, *,
           forbid_crossing: bool) -> CABCState:
    """Mark the vehicle arrived when it stands within ``tolerance`` (f32[]) of ``goal`` (f32[2])
    (and, with ``forbid_crossing``, sees it past no obstacle), and end its trajectory at the
    goal: the goal becomes the last waypoint unless the vehicle stands on it already."""
    here = state.waypoints[state.count - 1]
    gap = jnp.linalg.norm(goal - here)
    arrives = ~state.reached & (gap <= tolerance)
    if forbid_crossing:
        arrives &= crossings(plane, here, goal) == 0
    extra = arrives & (gap > 0)
    waypoints = state.waypoints.at[state.count].set(
        jnp.where(extra, goal, state.waypoints[state.count]))
    return dataclasses.replace(state, waypoints=waypoints,
                               count=state.count + extra.astype(jnp.int32),
                               reached=state.reached | arrives)


def colony_pick(config: CABCConfig, key: jax.Array, state: CABCState, plane: Plane,
                goal: jax.Array, params: CABCParams) -> Best:
    """The point a fresh colony of ``num_agents`` sources picks in the sensor window around the
    vehicle (``inner_iterations`` cycles on the guided function, best by Deb's rules).

    Args:
      key: PRNG key of the colony's search.
      goal: f32[2] the goal.

    Returns:
      :class:`~.colony.Best`: ``point`` f32[2], its ``phi`` f32[] and ``violations`` i32[],
      and the search's guided-function ``evaluations`` i32[].
    """
    here = state.waypoints[state.count - 1]
    previous = state.waypoints[jnp.maximum(state.count - 2, 0)]
    half = params.window / 2
    lower = jnp.clip(here - half, 0.0, plane.extent)
    upper = jnp.clip(here + half, 0.0, plane.extent)
    weights = jnp.stack([params.w1, params.w2, params.w3])

    def evaluate(candidates):
        """``(phi f32[C], violations i32[C])`` of the candidate points f32[C, 2]."""
        phi = guided(candidates, weights, plane, goal, here, previous,
                     state.count >= 2, lower, upper, half, turn_unit=config.turn_unit)
        if config.remember:
            phi = phi + params.w4 * revisits(candidates, state.waypoints, state.count, half)
        return phi, constraint_violations(candidates, plane, here,
                                          forbid_crossing=config.forbid_crossing)

    return search(key, evaluate, lower, upper, num_sources=config.num_agents,
                  cycles=params.inner_iterations.astype(jnp.int32),
                  limit=params.limit.astype(jnp.int32))


def _init(config: CABCConfig, key: jax.Array, plane: Plane, task: Task,
          params: CABCParams) -> CABCState:
    """The vehicle at ``task.start`` (f32[2]), arrived already if the goal is within
    ``tolerance``; ``waypoints`` f32[M + 2, 2]."""
    waypoints = jnp.full((config.max_steps + 2, 2), jnp.nan, jnp.float32).at[0].set(task.start)
    state = CABCState(key=key, waypoints=waypoints, count=jnp.int32(1),
                      reached=jnp.array(False))
    return arrive(state, plane, task.goal, params.tolerance,
                  forbid_crossing=config.forbid_crossing)


def _step(config: CABCConfig, state: CABCState, plane: Plane, task: Task,
          params: CABCParams) -> tuple[CABCState, StepInfo]:
    """One vehicle step: the colony picks a point in the sensor window and the vehicle moves
    there when the point is feasible, it has not arrived and it has moves left (``max_steps``);
    else it stays. Returns the state and the :class:`~jaxswarm.swarm.core.StepInfo` (f32[] cost
    of a trajectory completed by this step, else inf; i32[] moves, 0 or 1; i32[] the colony's
    guided-function evaluations as lane steps and evaluations)."""
    key, search_key = jax.random.split(state.key)
    best = colony_pick(config, search_key, state, plane, task.goal, params)
    moves = (~state.reached & (best.violations == 0)
             & (state.count <= config.max_steps))
    moved = CABCState(key=key, waypoints=state.waypoints.at[state.count].set(best.point),
                      count=state.count + 1, reached=state.reached)
    moved = arrive(moved, plane, task.goal, params.tolerance,
                   forbid_crossing=config.forbid_crossing)
    after = jax.tree_util.tree_map(lambda new, old: jnp.where(moves, new, old), moved,
                                   dataclasses.replace(state, key=key))
    arrived = after.reached & ~state.reached
    info = StepInfo(iteration_cost=jnp.where(arrived, trajectory(after).cost, jnp.inf),
                    arrived=after.reached.astype(jnp.float32), converged=after.reached,
                    moves=moves.astype(jnp.int32), lane_steps=best.evaluations,
                    evaluations=best.evaluations)
    return after, info


def change_rule(config: CABCConfig, state: CABCState, before: Plane, after: Plane,
                old_task: Task, new_task: Task, params: CABCParams) -> CABCState:
    """cABC's rule for a change of the plane or the goal: the vehicle remembers nothing of the
    plane, so it goes on from where it stands, towards the (possibly new) goal; a new goal
    makes an arrived vehicle set out again."""
    if_new_goal = dataclasses.replace(state, reached=jnp.array(False))
    restart = jnp.any(new_task.goal != old_task.goal)
    state = jax.tree_util.tree_map(lambda a, b: jnp.where(restart, a, b), if_new_goal, state)
    return arrive(state, after, new_task.goal, params.tolerance,
                  forbid_crossing=config.forbid_crossing)


def build_cabc(config: CABCConfig) -> Swarm:
    """cABC on a :class:`~jaxswarm.world.plane.Plane` (see the module docstring): its init, step
    and change rule with ``config`` bound."""
    return Swarm(name="cabc", config=config, init=jax.jit(functools.partial(_init, config)),
                 step=jax.jit(functools.partial(_step, config)), best=trajectory,
                 default_params=cabc_defaults(config.num_agents), check_params=check_cabc,
                 world=Plane)
