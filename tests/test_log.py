"""A walk's log of moves: what it holds, reading it, and the room it has (overflow and retry)."""
import dataclasses

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import sizes
from jitted import rows_log

from jaxswarm.dynamic.robot import hidden_blocks, swarm_robot
from jaxswarm.plot.memory import memory_frames
from jaxswarm.swarm import make, run
from jaxswarm.swarm.executor import run_batch, with_room
from jaxswarm.swarm.executor.runs import _run_batch
from jaxswarm.swarm.testing import batched_params, outcome
from jaxswarm.swarm.walking import step_budget, walk
from jaxswarm.swarm.walking import EVERY_MOVE, WalkerOptions
from jaxswarm.swarm.walking.log import (BLOCK, ROOM_FOR_EVERY_MOVE, agent_path, all_same, columns, default_log_moves,
                                        log_blocks, paths, room_blocks)
from jaxswarm.world.graph import grid_graph

SIDE = 16
OPEN = grid_graph(np.zeros((SIDE, SIDE), bool))
"""An open grid: uniform walkers wander far before they reach a cell near the start."""
AGENTS, STEPS = 64, SIDE * SIDE - 1
"""The walkers of the tests' walks and logs, and their step budget: the sizes of
``test_walk.py``'s walks, so that a walk with the default room is one program for both files."""
WIDTHS = (BLOCK - 1, 40, STEPS)
"""The moves :func:`read` cuts a log's paths to: within one block, across blocks, the budget."""


def _walk(log_moves):
    """AGENTS uniform walkers on OPEN for STEPS steps, their log with room for ``log_moves``
    moves an agent (one program a room); start and goal as i32[] (Python ints are weakly typed:
    a program of their own), the table as f32 (two Python floats would make it weakly typed)."""
    table = np.where(np.asarray(OPEN.nbr) >= 0, np.float32(0.0), np.float32(-np.inf))
    return walk(jax.random.key(0), OPEN, table, np.int32(0), np.int32(5 * SIDE + 5),
                num_agents=AGENTS, max_steps=STEPS,
                walker=WalkerOptions(log_moves=log_moves))


# all_same in one program, shared by the tests: applied outside jit, each of its operations is
# a program of its own (a dozen).
same_moves = jax.jit(all_same)


@jax.jit
def read(log, picked, agents):
    """``(cuts, (nodes, slots), agent_paths)``: :func:`paths` of ``log`` cut to each of
    WIDTHS, its :func:`columns` ``picked`` (i32[AGENTS, k]) and the whole :func:`agent_path` of
    each of ``agents`` (i32[n])."""
    cuts = [paths(log, width) for width in WIDTHS]
    return cuts, columns(log, picked), [agent_path(log, a, STEPS + 1) for a in agents]


def test_a_log_without_room_says_so_and_its_size_changes_no_move():
    tight, default, roomy = (_walk(m) for m in (BLOCK, None, ROOM_FOR_EVERY_MOVE))
    moves = np.asarray(roomy.moves)
    assert moves.mean() > 2 * BLOCK  # the case under test: one block an agent is too few
    assert bool(tight.log.overflowed) and not bool(default.log.overflowed)
    assert not bool(roomy.log.overflowed)
    for name in ("moves", "length", "arrived", "stuck", "position", "visited"):
        for other in (tight, default):
            np.testing.assert_array_equal(getattr(other, name), getattr(roomy, name), name)
    np.testing.assert_array_equal(default.path, roomy.path)
    np.testing.assert_array_equal(default.slots, roomy.slots)
    assert default.log.nodes.shape[0] == roomy.log.nodes.shape[0]  # a small walk: every move
    with pytest.raises(ValueError, match="no room for all its moves"):
        tight.path  # noqa: B018 (a property that checks)


def test_reading_the_log_gives_the_padded_rows_it_was_made_of():
    walked = _walk(ROOM_FOR_EVERY_MOVE)
    path, slots = np.asarray(walked.path), np.asarray(walked.slots)
    moves = np.asarray(walked.moves)
    # Written out, each row holds its moves, then -1; the path starts at the start.
    for a in range(AGENTS):
        assert (path[a, :moves[a] + 1] >= 0).all() and (path[a, moves[a] + 1:] == -1).all()
        assert (slots[a, :moves[a]] >= 0).all() and (slots[a, moves[a]:] == -1).all()
    assert (path[:, 0] == 0).all()
    # The same rows through from_rows (another layout: a fixed stride per agent).
    strided = rows_log(path, slots, moves, np.int32(0), STEPS)
    picked = np.random.default_rng(0).integers(-2, STEPS + 4, (AGENTS, 7)).astype(np.int32)
    agents = np.array([0, 5, 11, AGENTS - 1], np.int32)
    for log in (walked.log, strided):
        cuts, (nodes, slot), agent_paths = jax.device_get(read(log, picked, agents))
        for width, (cut_path, cut_slots) in zip(WIDTHS, cuts):
            np.testing.assert_array_equal(cut_path, path[:, :width + 1])
            np.testing.assert_array_equal(cut_slots, slots[:, :width])
        padded_path = np.pad(path, ((0, 0), (0, 10)), constant_values=-1)
        padded_slots = np.pad(slots, ((0, 0), (0, 10)), constant_values=-1)
        inside = picked >= 0
        np.testing.assert_array_equal(nodes[inside],
                                      np.take_along_axis(padded_path, picked, 1)[inside])
        np.testing.assert_array_equal(slot[inside],
                                      np.take_along_axis(padded_slots, picked, 1)[inside])
        assert (nodes[~inside] == -1).all()
        for a, agent_row in zip(agents, agent_paths):
            np.testing.assert_array_equal(agent_row, path[a])
        assert not bool(same_moves(log))


def test_all_same_sees_one_different_move_anywhere():
    row = np.arange(1, 41, dtype=np.int32)
    path = np.tile(np.concatenate([[0], row, [-1] * (STEPS - 40)]), (AGENTS, 1))
    slots = np.tile(np.concatenate([row % 8, [-1] * (STEPS - 40)]), (AGENTS, 1)).astype(np.int8)
    moves = np.full(AGENTS, 40, np.int32)

    def same(path, slots, moves):
        return bool(same_moves(rows_log(path, slots, moves, np.int32(0), STEPS)))

    assert same(path, slots, moves)
    for agent, move in [(0, 0), (3, 17), (4, 39), (AGENTS - 1, 39)]:
        changed = slots.copy()
        changed[agent, move] = (changed[agent, move] + 1) % 8
        assert not same(path, changed, moves)
    shorter = moves.copy()
    shorter[2] = 39
    cut = slots.copy()
    cut[2, 39] = -1
    assert not same(path, cut, shorter)


def test_a_large_walks_log_does_not_grow_with_a_longer_possible_path():
    graph = grid_graph(np.zeros((32, 32), bool))
    table = jnp.where(graph.nbr >= 0, 0.0, -jnp.inf)
    budget = step_budget(graph, None)
    assert default_log_moves(600, budget) == 256  # room set by the map
    # 4,096 agents need more than WHOLE_ROOM_BYTES for every move; 8 do not.
    assert room_blocks(4096, 300, None, budget) == log_blocks(4096, 300, 256)
    assert room_blocks(4096, 600, None, budget) == log_blocks(4096, 600, 256)
    assert room_blocks(8, 600, None, budget) == log_blocks(8, 600, 600)
    assert room_blocks(8, 600, BLOCK, budget) == 8  # a room asked for is the room given

    def own_bytes(max_steps):
        compiled = walk.lower(jax.random.key(0), graph, table, np.int32(0), np.int32(1023),
                              num_agents=4096, max_steps=max_steps).compile()
        analysis = compiled.memory_analysis()
        return analysis.output_size_in_bytes + analysis.temp_size_in_bytes

    assert own_bytes(300) == own_bytes(600)


@pytest.fixture(scope="module")
def cramped():
    """ACO* at the shared size on the shared maze (:mod:`sizes`) with one block of room per ant:
    its ants walk far before they reach the goal, so its walks overflow. With room (at this size
    the default room holds every move) it is the conformance checks' ACO*, whose programs its
    runs share."""
    graph, task = sizes.maze()
    return make("aco_star", **sizes.CONFIG, walker=WalkerOptions(log_moves=BLOCK)), graph, task


def test_run_makes_a_run_whose_walk_overflowed_again_with_room(cramped):
    swarm, graph, task = cramped
    params = swarm.default_params
    roomy = make("aco_star", **sizes.CONFIG)
    keys = jax.random.split(jax.random.key(2), sizes.RUNS)
    grid = batched_params(params, sizes.RUNS)
    # _run_batch is run_batch without its retry: jit of vmap of run, a caller who maps run and
    # so sees the flag (the same program as run_batch's first try below).
    mapped = _run_batch(swarm, keys, graph, task, grid, iterations=sizes.ITERATIONS,
                        patience=None)
    assert bool(np.asarray(mapped[1].overflowed).any())
    for key in keys:
        alone = run(swarm, key, graph, task, params, iterations=sizes.ITERATIONS)
        assert not bool(alone[1].overflowed)
        want = run(roomy, key, graph, task, params, iterations=sizes.ITERATIONS)
        assert jax.tree_util.tree_all(jax.tree_util.tree_map(
            lambda x, y: bool(np.array_equal(x, y, equal_nan=True)),
            outcome(alone), outcome(want)))
    batch = run_batch(swarm, keys, graph, task, grid, iterations=sizes.ITERATIONS)
    want = run_batch(roomy, keys, graph, task, grid, iterations=sizes.ITERATIONS)
    assert not bool(np.asarray(batch[1].overflowed).any())
    np.testing.assert_array_equal(batch[0].best_cost, want[0].best_cost)
    assert with_room(swarm).config.walker == EVERY_MOVE


def test_a_bad_log_room_is_refused():
    with pytest.raises(ValueError, match="log_moves must be at least 1"):
        WalkerOptions(log_moves=0)
    with pytest.raises(TypeError, match="walker must be WalkerOptions"):
        make("aco_star", walker=16)


def test_room_is_for_swarms_of_the_registry_that_walk():
    with pytest.raises(ValueError, match="does not walk"):
        with_room(make("cabc"))
    by_hand = dataclasses.replace(make("aco_star", **sizes.CONFIG), name="my_colony")
    with pytest.raises(ValueError, match="'my_colony' was not built by the registry"):
        with_room(by_hand)


@pytest.mark.slow  # the frames' and the robot's programs, cramped and roomy: about 45 s cold
def test_memory_frames_and_the_robot_walk_again_with_room(cramped):
    """Twin in the default tier: test_run_makes_a_run_whose_walk_overflowed_again_with_room (the
    retry these callers share)."""
    swarm, graph, task = cramped
    roomy = make("aco_star", **sizes.CONFIG)
    params = swarm.default_params
    state = swarm.init(jax.random.key(0), graph, task, params)
    assert bool(swarm.step(state, graph, task, params)[1].overflowed)  # the case under test
    got = memory_frames(swarm, state, graph, task, params, 3)
    want = memory_frames(roomy, state, graph, task, params, 3)
    np.testing.assert_array_equal(got[1], want[1])
    hidden = hidden_blocks(graph, int(task.start), int(task.goal), count=2, seed=0)
    got, want = (swarm_robot(s, jax.random.key(1), graph, task, hidden, params, iterations=3,
                             patience=None, max_plans=2) for s in (swarm, roomy))
    assert not bool(got.overflowed)
    np.testing.assert_array_equal(got.trajectory, want.trajectory)
    np.testing.assert_array_equal(got.plan_paths, want.plan_paths)
