"""The bees: the guided function's parts and the rays against hand computations, Deb's rules on
each pair case, eqs. 9-10, the colony's search, and the vehicle (never inside an obstacle, its
trajectory checked by shapely, its length beside the visibility-graph optimum)."""
import functools
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxswarm.dynamic.rules import change_rule
from jaxswarm.exact.visibility import shortest_path
from jaxswarm.maps.planes import PLANE_CAPACITY, paper_plane
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.bees import colony
from jaxswarm.swarm.bees import guided as guided_function
from jaxswarm.swarm.bees.colony import search
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.plane import make_plane, violations

shapely = pytest.importorskip("shapely")
STEPS = 200
"""Every run here has the paper's budget and a plane of PLANE_CAPACITY slots (in the default
tier through :func:`drive`: one compiled run)."""
SOURCES = 20
"""Food sources of every colony search here."""
ROWS = 8
"""Searches in one batch of :func:`searches`."""
NO_WALL = (0.0, 0.0, 0.0, 0.0)
"""An empty box: no point lies strictly inside it."""


def f32(values):
    return np.asarray(values, np.float32)


# The guided function's parts and Deb's rules under test, each called from the tests through one
# jitted wrapper: one program per shape and option, where called outside jit each of their JAX
# operations is a program of its own.
goal_distance = jax.jit(guided_function.goal_distance)
pushback = jax.jit(guided_function.pushback)
turn_angle = jax.jit(guided_function.turn_angle, static_argnames="turn_unit")
revisits = jax.jit(guided_function.revisits)
guided = jax.jit(guided_function.guided, static_argnames="turn_unit")
constraint_violations = jax.jit(guided_function.constraint_violations,
                                static_argnames="forbid_crossing")
fitness = jax.jit(colony.fitness)
deb_better = jax.jit(colony.deb_better)
deb_best = jax.jit(colony.deb_best)
onlooker_probabilities = jax.jit(colony.onlooker_probabilities)


def test_f1_is_the_distance_to_the_goal():
    assert goal_distance(f32([[0, 0], [3, 4]]), f32([3, 0])).tolist() == [3.0, 4.0]


def test_f2_pushes_back_from_what_the_four_rays_meet_inside_the_window():
    # A wall x in [3, 4] crosses the window [0, 3.5] x [3, 7] (side 4 round (1.5, 5), reach 2);
    # a second one, x in [6, 7], lies outside it and is not seen.
    plane = make_plane([(3, 0, 4, 10), (6, 0, 7, 10)], (10, 10))
    lower, upper, reach = f32([0, 3]), f32([3.5, 7]), np.float32(2)
    points = f32([[2, 5], [2.5, 5], [0.5, 5], [3.2, 5], [2, 2]])
    # (2, 5): the +x ray meets the wall at 1, so 2 - 1; (2.5, 5): 2 - 0.5; (0.5, 5): 2.5 away,
    # beyond reach; (3.2, 5): inside, every ray meets it at 0, so 4 x 2; (2, 2) is below the
    # window, where the sensor sees nothing of the wall.
    assert pushback(points, plane, lower, upper, reach).tolist() == pytest.approx(
        [1.0, 1.5, 0.0, 8.0, 0.0])


def test_f2_sees_along_both_axes_and_takes_the_nearest():
    plane = make_plane([(0, 4, 10, 5), (5.5, 0, 6, 10)], (10, 10))
    # From (5, 3.5): up to the wall y >= 4 at 0.5, right to x >= 5.5 at 0.5; reach 1.
    value = pushback(f32([[5, 3.5]]), plane, f32([4, 2.5]), f32([6, 4.5]), np.float32(1))
    assert float(value[0]) == pytest.approx(0.5 + 0.5)


@pytest.mark.parametrize("turn_unit, scale", [("degrees", 1.0), ("radians", math.pi / 180)])
def test_f3_is_the_turn_in_the_declared_unit(turn_unit, scale):
    # The last move is (0, 0) -> (1, 0), along +x. Going on to (2, 0) turns by 0; to (2, 1), by
    # 45 degrees (pi / 4); to (1, 1), 90 (pi / 2); back to (0, 0), 180 (pi); staying at (1, 0)
    # is no move and no turn. Under the other unit the 90 degree turn would read 1.5708 or 5157.
    previous, here = f32([0, 0]), f32([1, 0])
    points = f32([[2, 0], [2, 1], [1, 1], [0, 0], [1, 0]])
    turns = turn_angle(points, here, previous, np.array(True), turn_unit=turn_unit)
    assert turns.tolist() == pytest.approx([0.0, 45.0 * scale, 90.0 * scale, 180.0 * scale, 0.0])
    assert turn_angle(points, here, previous, np.array(False),
                      turn_unit=turn_unit).tolist() == [0.0] * 5


def test_a_swarm_of_either_unit_scores_a_turn_in_it():
    # From (1, 0), having come from (0, 0), with w = (0, 0, 0.03): a 90 degree turn to (1, 1)
    # costs 0.03 x 90 = 2.7 in degrees and 0.03 x pi / 2 = 0.0471 in radians.
    plane = make_plane([(3, 0, 4, 10)], (10, 10))
    args = (plane, f32([9, 9]), f32([1, 0]), f32([0, 0]), np.array(True), f32([0, -1]),
            f32([2, 1]), np.float32(1))
    weights = f32([0.0, 0.0, 0.03])
    assert float(guided(f32([[1, 1]]), weights, *args, turn_unit="degrees")[0]) == (
        pytest.approx(2.7))
    assert float(guided(f32([[1, 1]]), weights, *args, turn_unit="radians")[0]) == (
        pytest.approx(0.03 * math.pi / 2))


@pytest.mark.parametrize("build", [
    lambda: make("cabc", turn_unit="grads"),
    lambda: turn_angle(f32([[1, 1]]), f32([1, 0]), f32([0, 0]), np.array(True),
                       turn_unit="grads"),
])
def test_an_unknown_turn_unit_is_named(build):
    with pytest.raises(ValueError, match="unknown turn_unit 'grads'; choose one of degrees, "
                                         "radians"):
        build()


def test_phi_is_the_weighted_sum_of_eq_4():
    plane = make_plane([(3, 0, 4, 10)], (10, 10))
    points = f32([[2, 5], [2, 6]])
    args = (plane, f32([2, 9]), f32([1, 5]), f32([0, 5]), np.array(True), f32([0, 3]),
            f32([3.5, 7]), np.float32(2))
    phi = guided(points, f32([0.5, 2.0, 0.1]), *args, turn_unit="degrees")
    f1 = np.hypot([0, 0], [4, 3])
    f3 = np.asarray([0.0, 45.0])
    assert phi.tolist() == pytest.approx(0.5 * f1 + 2.0 * 1.0 + 0.1 * f3)


def test_violations_count_rectangles_and_optionally_the_crossed_ones():
    plane = make_plane([(1, 0, 2, 10), (3, 0, 4, 10)], (10, 10))
    here, points = f32([0, 5]), f32([[1.5, 5], [5, 5], [0.5, 5]])
    assert constraint_violations(points, plane, here, forbid_crossing=False).tolist() == [1, 0, 0]
    assert constraint_violations(points, plane, here, forbid_crossing=True).tolist() == [2, 2, 0]


def test_fitness_is_eq_9():
    assert fitness(f32([3, 0, -2])).tolist() == [0.25, 1.0, 3.0]


@pytest.mark.parametrize("a, b, wins", [
    ((5.0, 0), (1.0, 2), True),  # feasible beats infeasible, however good
    ((1.0, 2), (5.0, 0), False),
    ((1.0, 0), (2.0, 0), True),  # both feasible: the fitter
    ((2.0, 0), (1.0, 0), False),
    ((1.0, 0), (1.0, 0), False),  # a tie does not beat
    ((9.0, 1), (1.0, 3), True),  # both infeasible: fewer violations, whatever phi
    ((1.0, 3), (9.0, 1), False),
    ((1.0, 2), (9.0, 2), False),
])
def test_debs_rules_on_each_pair_case(a, b, wins):
    assert bool(deb_better(f32(a[0]), np.int32(a[1]), f32(b[0]), np.int32(b[1]))) is wins


def test_the_deb_best_of_a_population():
    assert int(deb_best(f32([0.5, 3.0, 2.0, 0.1]), np.int32([1, 0, 0, 2]))) == 2
    assert int(deb_best(f32([0.5, 3.0]), np.int32([2, 1]))) == 1


def test_onlooker_probabilities_are_eq_10():
    # fit = [0.5, 0.25, 0.5], summed over all sources: 1.25; violations sum to 2.
    p = onlooker_probabilities(f32([1, 3, 1]), np.int32([0, 0, 2]))
    assert p.tolist() == pytest.approx([0.5 + 0.5 * 0.5 / 1.25, 0.5 + 0.5 * 0.25 / 1.25, 0.0])
    p = onlooker_probabilities(f32([1, 1, 1]), np.int32([1, 1, 2]))
    assert p.tolist() == pytest.approx([0.375, 0.375, 0.25])


def _bowl(target, wall):
    """The distance to ``target``; points strictly inside the box ``wall`` violate it."""
    def evaluate(points):
        phi = jnp.linalg.norm(points - target, axis=-1)
        inside = jnp.all((points > wall[:2]) & (points < wall[2:]), axis=-1)
        return phi, inside.astype(jnp.int32)
    return evaluate


@jax.jit
@functools.partial(jax.vmap, in_axes=(0, 0, None, None, None))
def _searches(key, cycles, limit, target, wall):
    return search(key, _bowl(target, wall), f32([0, 0]), f32([4, 4]), num_sources=SOURCES,
                  cycles=cycles, limit=limit)


def searches(keys, cycles, *, limit, target, wall=NO_WALL):
    """:data:`ROWS` colony searches of :data:`SOURCES` sources in the box [0, 4] x [0, 4] for the
    bowl round ``target`` (points inside ``wall`` violate it), a row for each key and cycle count
    (each given per row or once for all). The target, the wall and the limit are arguments, so
    every test's searches share one compiled program."""
    return _searches(jnp.broadcast_to(keys, (ROWS,)),
                     np.broadcast_to(np.asarray(cycles, np.int32), (ROWS,)),
                     np.int32(limit), f32(target), f32(wall))


def test_cycles_bring_the_colony_to_the_minimum_and_are_counted():
    target = f32([1.0, 3.0])
    cycles = np.asarray([0, 1, 2, 4, 6, 10, 15, 20])
    best = searches(jax.random.key(1), cycles, limit=40, target=target)
    gaps = np.asarray(best.phi)
    assert gaps == pytest.approx(np.linalg.norm(np.asarray(best.point) - target, axis=-1))
    # N at the start, then per cycle N employed tries, at most N onlookers, scouts.
    evaluations = np.asarray(best.evaluations)
    assert (SOURCES * (1 + cycles) <= evaluations).all()
    assert (evaluations <= SOURCES * (1 + 3 * cycles)).all()
    # One key: each row's cycles begin with the shorter rows', and the best is remembered.
    assert (np.diff(gaps) <= 0).all() and gaps[-1] < gaps[2] and gaps[-1] < 0.05


def test_the_search_keeps_to_the_box_and_prefers_feasible_points():
    wall = (0.5, 2.5, 1.5, 3.5)  # covers the unconstrained minimum (1, 3)
    best = searches(jax.random.split(jax.random.key(0), ROWS), 6, limit=4, target=(1.0, 3.0),
                    wall=wall)
    points = np.asarray(best.point)
    assert (np.asarray(best.violations) == 0).all()
    assert (points >= 0).all() and (points <= 4).all()
    assert not ((points > [0.5, 2.5]) & (points < [1.5, 3.5])).all(axis=1).any()


def test_zero_cycles_is_the_greedy_pick_of_the_first_sources():
    key = jax.random.key(3)
    best = searches(key, 0, limit=20, target=(2.0, 2.0))
    uniform = jax.random.uniform(jax.random.split(key)[0], (SOURCES, 2))
    first = np.asarray(uniform) * 4  # eq. 7 in the box
    distances = np.linalg.norm(first - 2.0, axis=1)
    assert np.allclose(best.point, first[np.argmin(distances)])
    assert (np.asarray(best.evaluations) == SOURCES).all()


def shapely_collisions(plane, waypoints) -> int:
    """Segments of a trajectory that enter an obstacle's interior, counted by shapely."""
    points = waypoints[~np.isnan(waypoints).any(axis=1)]
    boxes = [shapely.box(*b).buffer(-1e-5, join_style="mitre") for b in plane.obstacles()]
    return sum(any(box.intersects(shapely.LineString([a, b])) for box in boxes)
               for a, b in zip(points[:-1], points[1:]) if not np.array_equal(a, b))


@pytest.fixture(scope="module")
def map2_runs():
    """Ten runs of each variant on map #2 (weights of the paper's Table 5 best)."""
    chosen = paper_plane("map2")
    task = make_task(chosen.plane, chosen.start, chosen.goal)
    runs = {}
    for forbid in (False, True):
        swarm = make("cabc", forbid_crossing=forbid)
        params = swarm.default_params._replace(w1=np.float32(0.8), w2=np.float32(0.1))
        runs[forbid] = swarm, jax.vmap(lambda k: run(swarm, k, chosen.plane, task, params,
                                                     iterations=STEPS))(
            jax.random.split(jax.random.key(0), 10))
    return chosen, task, runs


@pytest.mark.slow  # the fixture compiles two variants' batched runs: about 25 s
def test_the_vehicle_never_stands_inside_an_obstacle(map2_runs):
    chosen, _, runs = map2_runs
    for swarm, (state, trace) in runs.values():
        waypoints = np.asarray(state.waypoints)
        held = ~np.isnan(waypoints).any(axis=-1)
        assert int(np.asarray(violations(chosen.plane, jnp.asarray(waypoints[held]))).sum()) == 0
        assert (held.sum(axis=1) == np.asarray(state.count)).all()
        assert (np.asarray(trace.moves).sum(axis=1) <= 200).all()


@pytest.mark.slow
def test_with_forbid_crossing_every_trajectory_is_collision_free(map2_runs):
    chosen, task, runs = map2_runs
    swarm, (state, _) = runs[True]
    assert sum(shapely_collisions(chosen.plane, w) for w in np.asarray(state.waypoints)) == 0
    # The paper's vehicle checks only where it lands, and clips corners.
    paper_swarm, (paper_state, _) = runs[False]
    assert sum(shapely_collisions(chosen.plane, w)
               for w in np.asarray(paper_state.waypoints)) > 0


@pytest.mark.slow
def test_an_arrived_trajectory_ends_at_the_goal_and_is_never_shorter_than_the_optimum(map2_runs):
    chosen, task, runs = map2_runs
    optimum, _ = shortest_path(chosen.plane, chosen.start, chosen.goal)
    arrived = 0
    for swarm, (state, trace) in runs.values():
        solution = jax.vmap(swarm.best)(state)
        for found, cost, waypoints, count in zip(np.asarray(solution.found),
                                                 np.asarray(solution.cost),
                                                 np.asarray(solution.path),
                                                 np.asarray(state.count)):
            if not found:
                assert math.isinf(cost)
                continue
            arrived += 1
            assert np.array_equal(waypoints[count - 1], np.asarray(chosen.goal, np.float32))
            assert cost >= optimum
            length = np.sum(np.linalg.norm(np.diff(waypoints[:count], axis=0), axis=1))
            assert cost == pytest.approx(length, rel=1e-5)
    assert arrived > 0


def drive(swarm, key, plane, task, params, state=None):
    """``run`` for :data:`STEPS` iterations from ``state``, by default the vehicle at the task's
    start (``swarm.init``'s state, as a run from no state begins). A run that continues a state
    and one from none are programs of their own; so every run of the default tier here continues
    one, and all share the program of the run that goes on after a new goal."""
    if state is None:
        state = swarm.init(key, plane, task, params)
    return run(swarm, key, plane, task, params, iterations=STEPS, state=state)


@functools.partial(jax.jit, static_argnames="swarm")
def best_of(swarm, state):
    """``swarm.best(state)``, the vehicle's trajectory, in one program."""
    return swarm.best(state)


@functools.partial(jax.jit, static_argnames="swarm")
def adapt(swarm, state, before, after, old_task, new_task, params):
    """The swarm's change rule (:func:`jaxswarm.dynamic.rules.change_rule`), in one program."""
    return change_rule(swarm)(state, before, after, old_task, new_task, params)


def test_a_vehicle_with_no_feasible_candidate_stays():
    # Four squares meet where the vehicle stands: all its window but two lines is blocked.
    plane = make_plane([(3, 3, 5, 5), (5, 3, 7, 5), (3, 5, 5, 7), (5, 5, 7, 7)], (10, 10),
                       capacity=PLANE_CAPACITY)
    swarm = make("cabc")
    task = make_task(plane, (5, 5), (9, 9))
    state, trace = drive(swarm, jax.random.key(0), plane, task, swarm.default_params)
    assert int(state.count) == 1 and int(np.asarray(trace.moves).sum()) == 0
    assert int(trace.iterations) == STEPS and not bool(best_of(swarm, state).found)


@pytest.mark.slow  # a config of its own: one more compile
def test_the_vehicle_moves_at_most_max_steps_times():
    chosen = paper_plane("map1")
    swarm = make("cabc", max_steps=5)
    task = make_task(chosen.plane, chosen.start, chosen.goal)
    state, trace = run(swarm, jax.random.key(0), chosen.plane, task, swarm.default_params,
                       iterations=STEPS)
    assert int(np.asarray(trace.moves).sum()) == 5 and int(state.count) == 6
    assert state.waypoints.shape == (7, 2)


def test_a_vehicle_started_at_the_goal_has_arrived():
    chosen = paper_plane("map1")
    swarm = make("cabc")
    task = make_task(chosen.plane, chosen.goal, (47.2, 47.0))
    state, trace = drive(swarm, jax.random.key(0), chosen.plane, task, swarm.default_params)
    solution = best_of(swarm, state)
    assert int(trace.iterations) == 1 and bool(solution.found)
    assert float(solution.cost) == pytest.approx(0.2, abs=1e-5)


def test_after_a_new_goal_the_vehicle_goes_on_from_where_it_stands():
    chosen = paper_plane("map1")
    swarm = make("cabc")
    params = swarm.default_params._replace(w2=np.float32(0), w3=np.float32(0))
    task = make_task(chosen.plane, (3.0, 3.0), (6.0, 3.0))
    state, _ = drive(swarm, jax.random.key(0), chosen.plane, task, params)
    assert bool(state.reached)
    new_task = make_task(chosen.plane, (3.0, 3.0), (3.0, 6.5))
    adapted = adapt(swarm, state, chosen.plane, chosen.plane, task, new_task, params)
    assert not bool(adapted.reached) and int(adapted.count) == int(state.count)
    after, _ = drive(swarm, jax.random.key(1), chosen.plane, new_task, params, state=adapted)
    assert bool(after.reached) and int(after.count) > int(state.count)
    count = int(state.count)
    assert np.array_equal(np.asarray(after.waypoints)[:count], np.asarray(state.waypoints)[:count])


def test_bees_and_walkers_refuse_each_others_worlds():
    chosen = paper_plane("map1")
    graph = grid_graph(np.zeros((4, 4), bool))
    bees, drops = make("cabc"), make("rfd_star", num_agents=8)
    with pytest.raises(ValueError, match="cabc plans on a Plane, got a Graph"):
        run(bees, jax.random.key(0), graph, make_task(graph, (0, 0), (3, 3)),
            bees.default_params)
    with pytest.raises(ValueError, match="rfd_star plans on a Graph, got a Plane"):
        run(drops, jax.random.key(0), chosen.plane,
            make_task(chosen.plane, chosen.start, chosen.goal), drops.default_params)


@pytest.mark.parametrize("field, value, message", [
    ("w2", -0.1, "w2 must be non-negative"),
    ("inner_iterations", 2.5, "inner_iterations must be a whole number >= 0"),
    ("limit", 0, "limit must be a whole number >= 1"),
    ("window", 0, "window must be positive"),
    ("tolerance", np.nan, "tolerance must be finite"),
    ("w4", -1, "w4 must be non-negative"),
])
def test_bad_params_are_named(field, value, message):
    swarm = make("cabc")
    with pytest.raises(ValueError, match=message):
        swarm.check_params(swarm.default_params._replace(**{field: np.float32(value)}))


def test_bad_sizes_are_named():
    with pytest.raises(ValueError, match="cabc needs num_agents >= 2"):
        make("cabc", num_agents=1)
    with pytest.raises(TypeError, match="max_steps of cabc must be an integer, got None"):
        make("cabc", max_steps=None)


def test_f4_counts_the_earlier_windows_that_hold_a_point():
    waypoints = f32([[0, 0], [1, 0], [2, 0], [np.nan, np.nan]])
    points = f32([[0.5, 0.5], [1.8, 0], [2.5, 0], [-2, 0]])
    # (0.5, 0.5) lies in the windows round (0, 0) and (1, 0); (1.8, 0) in (1, 0)'s; (2.5, 0)
    # only in the current position's, which does not count.
    assert revisits(points, waypoints, np.int32(3), np.float32(1)).tolist() == [2, 1, 0, 0]
    assert revisits(points, waypoints, np.int32(1), np.float32(1)).tolist() == [0, 0, 0, 0]


@pytest.mark.slow  # a config of its own: one more compile
def test_a_vehicle_that_remembers_pays_for_going_back():
    chosen = paper_plane("map2")
    plain, remembering = make("cabc"), make("cabc", remember=True)
    task = make_task(chosen.plane, chosen.start, chosen.goal)
    params = plain.default_params._replace(w4=np.float32(0))
    a, _ = run(plain, jax.random.key(0), chosen.plane, task, params, iterations=STEPS)
    b, _ = run(remembering, jax.random.key(0), chosen.plane, task, params, iterations=STEPS)
    assert np.array_equal(a.waypoints, b.waypoints, equal_nan=True)  # w4 = 0: no memory
    c, _ = run(remembering, jax.random.key(0), chosen.plane, task, remembering.default_params,
               iterations=STEPS)
    assert not np.array_equal(a.waypoints, c.waypoints, equal_nan=True)
