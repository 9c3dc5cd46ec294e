"""The robot that finds hidden blocks as it walks and re-plans: what it sees, where it stops,
that it never walks through a block, reaches the goal, never beats the full-knowledge optimum,
batches under vmap, and names bad worlds."""
import jax
import numpy as np
import pytest
from jitted import change

from jaxswarm.dynamic.events import apply_event, check_events, make_event
from jaxswarm.dynamic.robot import (check_world, dstar_robot, hidden_blocks, swarm_robot, walk_plan)
from jaxswarm.exact import astar
from jaxswarm.maps.paper import paper_map
from jaxswarm.maps.random import random_path_map
from jaxswarm.swarm import make, make_task
from jaxswarm.swarm.core import Task
from jaxswarm.world.graph import grid_graph, path_map_graph
from jaxswarm.world.paths import is_valid_path, pad, path_length, trim

SQRT2 = float(np.sqrt(2))
SIDE = 5
"""The side of the maps walked here: the detour world's, so that every walk of a plan (a plan of
``SIDE ** 2`` nodes, as D* Lite's) is one program."""


def free_grid(height, width):
    return grid_graph(np.zeros((height, width), bool))


def plan(*nodes):
    """i32[SIDE ** 2]: a plan through ``nodes``, -1 padded."""
    return pad(nodes, SIDE ** 2)


def top_row_path_map():
    """A SIDE x SIDE thin-wall path map whose only passages join its top row's cells (nodes 0,
    1, ..., SIDE - 1) east and west: a corridor."""
    connections = np.zeros((SIDE, SIDE, 8), bool)
    connections[0, :-1, 0] = True  # east moves 0 -> 1 -> ... -> SIDE - 1
    connections[0, 1:, 2] = True  # and back west
    return path_map_graph(connections)


def test_the_robot_stops_before_a_hidden_cell_and_sees_it():
    graph = free_grid(SIDE, SIDE)  # the robot walks the top row 0-1-2-3-4
    hidden = make_event(graph, block=[3])
    world = apply_event(hidden, graph, make_task(graph, 0, 4))[0]
    leg = walk_plan(world, graph, plan(0, 1, 2, 3, 4))
    assert int(leg.stop) == 2 and not bool(leg.reached)
    assert float(leg.length) == pytest.approx(2.0)
    assert int(leg.seen.start) == 2
    assert sorted(np.asarray(leg.seen.block).tolist()) == [-1, -1, 3]
    assert np.all(np.asarray(leg.seen.close) == -1)
    clear = walk_plan(graph, graph, plan(0, 1, 2, 3, 4))
    assert bool(clear.reached) and int(clear.stop) == 4 and int(clear.seen.start) == -1
    nothing = walk_plan(graph, graph, plan())
    assert not bool(nothing.reached) and float(nothing.length) == 0.0


def test_a_diagonal_squeezing_past_a_hidden_cell_reveals_that_cell():
    graph = free_grid(SIDE, SIDE)  # 0 1 / 5 6: the diagonal 0 -> 6 needs 1 and 5 free
    world = apply_event(make_event(graph, block=[(1, 0)]), graph, make_task(graph, 0, 6))[0]
    leg = walk_plan(world, graph, plan(0, 6))
    assert int(leg.stop) == 0 and float(leg.length) == 0.0
    assert sorted(np.asarray(leg.seen.block).tolist()) == [-1, -1, 1]


def test_a_hidden_thin_wall_is_seen_as_a_closed_passage():
    graph = top_row_path_map()
    hidden = make_event(graph, close=[((1, 0), (2, 0))])
    task = make_task(graph, 0, 2)
    world = apply_event(hidden, graph, task)[0]
    assert np.asarray(graph.valid_edges())[1, 0] and not np.asarray(world.valid_edges())[1, 0]
    leg = walk_plan(world, graph, plan(0, 1, 2))
    assert int(leg.stop) == 1 and np.asarray(leg.seen.close).tolist() == [[1, 0]]
    assert np.all(np.asarray(leg.seen.block) == -1)
    # Closing is both directions, and opening undoes it.
    reopened = apply_event(make_event(graph, open=[(2, 1)]), world, task)[0]
    np.testing.assert_array_equal(np.asarray(reopened.open), np.asarray(graph.open))


def detour_world():
    """A 5 x 5 free grid with a wall across column 2 except row 4; the robot knows only the
    wall's top part, the hidden cell (2, 3) closes the short gap it plans through."""
    obstacles = np.zeros((5, 5), bool)
    obstacles[0:3, 2] = True
    known = grid_graph(obstacles)
    return known, (0, 0), (4, 0), make_event(known, block=[(2, 3)])


def robot_invariants(known, start, goal, hidden, walk):
    """The robot never walks through a block, its trajectory is what it travelled, and it
    travelled no less than the optimum with full knowledge."""
    task = make_task(known, start, goal)
    world = apply_event(hidden, known, task)[0]
    # The padded trajectory (-1 after the last node stood on): one program whatever the route.
    assert bool(is_valid_path(world, walk.trajectory, task.start, task.goal))
    assert float(path_length(world, walk.trajectory)) == pytest.approx(
        float(walk.travelled), rel=1e-5)
    assert float(walk.travelled) >= check_world(known, start, goal, hidden) - 1e-4


def test_dstar_robot_takes_the_detour_a_hand_count_gives():
    known, start, goal, hidden = detour_world()
    walk, seconds = dstar_robot(known, start, goal, hidden)
    assert bool(walk.reached) and int(walk.plans) == 2 and seconds > 0
    robot_invariants(known, start, goal, hidden, walk)
    # Every shortest plan enters the gap (2, 3) from (1, 3) (from (1, 2) the corner (2, 2) is
    # blocked), reached after 2 + sqrt 2; there it sees (2, 3). From (1, 3) the way round is
    # (1, 4) (2, 4) (3, 4) (its diagonals squeeze past (2, 3)), then to (4, 0): 3 + sqrt 2.
    assert float(walk.travelled) == pytest.approx(2 + SQRT2 + 3 + 3 + SQRT2, rel=1e-5)
    assert int(walk.seen.start[0]) == 16 and 17 in np.asarray(walk.seen.block[0]).tolist()


@pytest.mark.parametrize("name, memory", [
    ("improved_max_min_aco", "keep"),
    pytest.param("improved_max_min_aco", "wipe", marks=pytest.mark.slow),
    pytest.param("rfd_star", "keep", marks=pytest.mark.slow), ("rfd_graded", "keep")])
def test_swarm_robot_reaches_the_goal_without_crossing_a_block(name, memory):
    known, start, goal, hidden = detour_world()
    swarm = make(name, num_agents=32)
    walk = swarm_robot(swarm, jax.random.key(1), known, make_task(known, start, goal), hidden,
                       swarm.default_params, iterations=40, patience=10, memory=memory)
    walk = jax.device_get(walk)  # read on the host
    assert bool(walk.reached) and int(walk.plans) >= 2
    robot_invariants(known, start, goal, hidden, walk)
    assert int(walk.iterations) > 0 and int(walk.moves) > 0
    # Wherever its first plan went, it stopped where it saw a block, and stood there.
    assert int(walk.seen.start[0]) in trim(walk.trajectory).tolist()
    assert np.any(np.asarray(walk.seen.block[0]) >= 0)


@pytest.mark.slow
def test_robot_reaches_the_goal_on_a_paper_map_and_a_path_map():
    for known, start, goal in ((paper_map("maze20").graph(), (0, 0), (19, 19)),
                               (path_map_graph(random_path_map(10, 10, 3)), (0, 0), (9, 9))):
        hidden = hidden_blocks(known, start, goal, count=2, seed=4)
        swarm = make("improved_max_min_aco")
        walk = swarm_robot(swarm, jax.random.key(0), known, make_task(known, start, goal),
                           hidden, swarm.default_params, iterations=30, patience=10)
        assert bool(walk.reached)
        robot_invariants(known, start, goal, hidden, walk)
        exact, _ = dstar_robot(known, start, goal, hidden)
        robot_invariants(known, start, goal, hidden, exact)


def test_improved_first_ant_walks_again_from_the_new_start():
    known, start, goal, _ = detour_world()
    swarm = make("improved_max_min_aco", num_agents=8)
    task = make_task(known, start, goal)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), known, task, params)
    state = state.__class__(key=state.key, pheromone=np.asarray(state.pheromone) * 3.0,
                            best_path=state.best_path, best_cost=state.best_cost)
    moved = make_event(known, start=(1, 2), block=[(2, 3)])
    after_state, after, new_task = change(swarm, state, moved, known, task, params)
    assert bool(is_valid_path(after, after_state.best_path, new_task.start, new_task.goal))
    assert np.isfinite(float(after_state.best_cost))
    kept = np.asarray(after.valid_edges())
    np.testing.assert_allclose(np.asarray(after_state.pheromone)[kept],
                               np.asarray(state.pheromone)[kept])


@pytest.mark.slow  # two compiles of the robot program, about 25 s
def test_vmap_over_keys_maps_and_hidden_blocks_equals_a_loop():
    worlds = []
    for seed in range(3):
        known = path_map_graph(random_path_map(6, 6, seed))
        worlds.append((known, make_task(known, 0, 35),
                       hidden_blocks(known, 0, 35, count=2, seed=seed)))
    swarm = make("improved_max_min_aco", num_agents=8)
    keys = jax.random.split(jax.random.key(5), 3)

    def one(key, known, task, hidden):
        return swarm_robot(swarm, key, known, task, hidden, swarm.default_params,
                           iterations=10, patience=5, max_plans=4)

    stacked = jax.tree_util.tree_map(lambda *x: np.stack(x), *worlds)
    batch = jax.device_get(jax.vmap(one)(keys, *stacked))  # read on the host
    for i, (known, task, hidden) in enumerate(worlds):
        single = one(keys[i], known, task, hidden)
        for got, want in zip(jax.tree_util.tree_leaves(batch), jax.tree_util.tree_leaves(single)):
            np.testing.assert_allclose(np.asarray(got[i]), np.asarray(want), rtol=1e-6)


def test_hidden_blocks_lie_on_the_way_and_keep_the_goal_reachable():
    known = paper_map("mosaic20").graph()
    start, goal = paper_map("mosaic20").start, paper_map("mosaic20").goal
    hidden = hidden_blocks(known, start, goal, count=3, seed=7)
    cells = [int(c) for c in np.asarray(hidden.block)]
    assert len(set(cells)) == 3 and np.all(np.asarray(known.free)[cells])
    first = set(astar(known, start, goal).nodes().tolist())
    assert cells[0] in first  # the first block is on the way the robot plans first
    check_world(known, start, goal, hidden)
    with pytest.raises(ValueError, match="only 0 of 1 hidden blocks keep the goal reachable"):
        hidden_blocks(top_row_path_map(), 0, 4, count=1, seed=0)


def test_bad_worlds_are_named():
    known, start, goal, _ = detour_world()
    with pytest.raises(ValueError, match="a hidden block is on the goal"):
        check_world(known, start, goal, make_event(known, block=[(4, 0)]))
    with pytest.raises(ValueError, match="a hidden block is on the start"):
        check_world(known, start, goal, make_event(known, block=[(0, 0)]))
    with pytest.raises(ValueError, match="unreachable: no path"):
        check_world(known, start, goal, make_event(known, block=[(2, 3), (2, 4)]))
    with pytest.raises(ValueError, match="may only block cells and close passages"):
        check_world(known, start, goal, make_event(known, unblock=[(2, 0)]))
    with pytest.raises(ValueError, match="made for a map of 4 nodes"):
        check_world(known, start, goal, make_event(free_grid(2, 2), block=[1]))
    with pytest.raises(ValueError, match=r"world: start \(2, 0\) is blocked"):
        check_world(known, (2, 0), goal, make_event(known))
    swarm = make("rfd_star", num_agents=4)
    with pytest.raises(ValueError, match="unknown memory 'forget'"):
        swarm_robot(swarm, jax.random.key(0), known, make_task(known, start, goal),
                    make_event(known), swarm.default_params, memory="forget")


def test_passage_events_are_checked():
    graph = free_grid(3, 3)
    task = Task(start=np.int32(0), goal=np.int32(8))
    with pytest.raises(ValueError, match=r"close: cells \(0, 0\) and \(2, 2\) are not neighbours"):
        make_event(graph, close=[((0, 0), (2, 2))])
    assert np.asarray(graph.nbr)[0, 7] == -1  # no neighbour up-left of the corner cell
    bad = make_event(graph, close=[(0, 1)])._replace(close=np.array([[0, 7]], np.int32))
    with pytest.raises(ValueError, match=r"close passage \(node 0, slot 7\) is not an edge"):
        check_events(graph, task, bad)
