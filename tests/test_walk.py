import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxswarm.swarm.walking import (FEWEST_LANES, FORCED, LANES, STEPS_PER_REFILL, edge_table,
                                    lanes_for, sample_masked, visited_nodes, walk)
from jaxswarm.world.graph import dense_graph, grid_graph
from jaxswarm.world.lattice import straight_line
from jaxswarm.world.paths import is_valid_path, path_length


def _fields(walk) -> dict:
    """A walk's arrays by name (its log's too, and its paths and slots written out), but for
    its ``lane_steps`` (the loop's work), as NumPy arrays."""
    leaves = jax.tree_util.tree_leaves_with_path(walk._replace(lane_steps=None))
    return jax.device_get(dict({jax.tree_util.keystr(key): value for key, value in leaves},
                               path=walk.path, slots=walk.slots))


def _uniform(seed, mask):
    """f32[A]: one seeded uniform per row of a bool[A, K] mask."""
    return jax.random.uniform(jax.random.key(seed), mask.shape[:1])


sample = jax.jit(sample_masked)
"""The sampler under test, one program per shape of its arguments (applied outside ``jit``,
each of its operations would be a program of its own)."""


def test_sampler_follows_weights_and_never_picks_masked_slots():
    log_weights = jnp.log(jnp.array([[1.0, 2.0, 0.0, 5.0]] * 20000))
    mask = np.array([[True, True, True, False]] * 20000)  # slot 3 is heavy but masked
    choice, has = jax.device_get(sample(_uniform(0, mask), log_weights, mask))
    assert has.all()
    counts = np.bincount(np.asarray(choice), minlength=4)
    assert counts[2] == 0 and counts[3] == 0  # zero weight and masked
    np.testing.assert_allclose(counts[:2] / 20000, [1 / 3, 2 / 3], atol=0.015)


def test_sampler_reports_no_choice_instead_of_slot_zero():
    log_weights = np.array([[0.0, 0.0], [np.nan, np.nan], [-np.inf, -np.inf], [0.0, 1.0]],
                           np.float32)
    mask = np.array([[False, False], [True, True], [True, True], [True, True]])
    choice, has = jax.device_get(sample(_uniform(1, mask), log_weights, mask))
    np.testing.assert_array_equal(has, [False, False, False, True])
    np.testing.assert_array_equal(choice[:3], [-1, -1, -1])


def test_forced_slot_always_wins():
    log_weights = np.array([[3.0, FORCED, 50.0]] * 1000, np.float32)
    choice, _ = sample(jax.random.uniform(jax.random.key(2), (1000,)), log_weights,
                       np.ones((1000, 3), bool))
    assert (np.asarray(choice) == 1).all()


def test_greedy_rows_take_the_most_likely_slot_and_draw_among_ties():
    log_weights = jnp.log(jnp.array([[1.0, 3.0, 2.0, 3.0, 9.0]] * 4000))
    mask = np.array([[True, True, True, True, False]] * 4000)  # slot 4 is heaviest but masked
    greedy = np.arange(4000) < 2000
    choice, has = jax.device_get(sample(_uniform(5, mask), log_weights, mask, greedy))
    assert has.all()
    greedy_counts = np.bincount(choice[:2000], minlength=5)
    assert greedy_counts[[0, 2, 4]].sum() == 0  # only the tied best slots 1 and 3
    assert 900 < greedy_counts[1] < 1100
    drawn = np.bincount(choice[2000:], minlength=5)
    assert drawn[0] > 0 and drawn[2] > 0  # the other rows still draw


def uniform(graph):
    return edge_table(graph, np.zeros(graph.nbr.shape, np.float32))


@jax.jit
def towards(graph, goal, strength):
    """A table whose log-weight of a move is ``-strength`` times its head's distance to goal
    (one program for the grids of a shape)."""
    closer = -strength * straight_line(graph, goal)
    return edge_table(graph, jnp.broadcast_to(closer[jnp.maximum(graph.nbr, 0)],
                                              graph.nbr.shape))


SIDE = 16
"""The side of the grids walked on: :func:`walk` is one program for all maps of a shape and all
tables, so these walks build one program per set of walk options."""
AGENTS = 64
"""The agents of a walk: at most the walker's fewest lanes, so a run alone walks a lane an agent,
and more than a quarter of them, so a batch of 4 runs outnumbers its lanes."""
STEPS = SIDE * SIDE - 1
"""A walk's step budget (the longest walk without revisits)."""


def grid(blocked=0.0, seed=0, free=()):
    """A SIDE x SIDE grid, each cell blocked with probability ``blocked`` but the nodes ``free``."""
    obstacles = np.random.default_rng(seed).random((SIDE, SIDE)) < blocked
    obstacles.flat[list(free)] = False
    return grid_graph(obstacles)


def grid_walk(key, graph, table, start, goal, **options):
    """:func:`walk` of AGENTS agents for STEPS steps, ``start`` and ``goal`` as i32[] (Python
    ints are weakly typed: a program of their own)."""
    return walk(key, graph, table, jnp.int32(start), jnp.int32(goal), num_agents=AGENTS,
                max_steps=STEPS, **options)


def batch_of_walks(keys, graph, table, starts, goal):
    """:func:`grid_walk` under ``vmap``, a run a key and start: their agents share one queue."""
    return jax.vmap(lambda key, start: grid_walk(key, graph, table, start, goal))(keys, starts)


def test_walks_are_valid_self_avoiding_and_measured():
    goal = SIDE * SIDE - 1
    graph = grid(0.25, free=(0, goal))
    result = jax.device_get(grid_walk(jax.random.key(3), graph, uniform(graph), 0, goal))
    path = np.asarray(result.path)
    for a in range(AGENTS):
        nodes = path[a][path[a] >= 0]
        assert len(set(nodes.tolist())) == len(nodes)  # no revisits
        assert bool(is_valid_path(graph, path[a], start=0))
        assert float(path_length(graph, path[a])) == pytest.approx(float(result.length[a]))
        if result.arrived[a]:
            assert nodes[-1] == goal and not result.stuck[a]
        assert nodes[-1] == int(result.position[a])
    # Stuck agents really have no unvisited free neighbour left.
    valid, nbr = np.asarray(graph.valid_edges()), np.asarray(graph.nbr)
    for a in np.nonzero(result.stuck)[0]:
        nodes = set(path[a][path[a] >= 0].tolist())
        here = int(result.position[a])
        assert all(nbr[here, k] in nodes for k in range(8) if valid[here, k])
    moves = result.moves
    assert moves.max() <= STEPS and (moves == (path >= 0).sum(axis=1) - 1).all()
    assert moves.sum() <= int(result.lane_steps) <= AGENTS * (STEPS + STEPS_PER_REFILL)
    np.testing.assert_array_equal(np.asarray(result.slots) >= 0, path[:, 1:] >= 0)


def unpacked(bits, num_nodes):
    """bool[A, N] from packed u32[A, W] bit sets (numpy, bit n % 32 of word n // 32)."""
    bits = np.asarray(bits)
    return ((bits[:, :, None] >> np.arange(32, dtype=np.uint32)) & 1).reshape(
        len(bits), -1)[:, :num_nodes].astype(bool)


def test_walks_on_a_general_graph_are_valid_and_record_their_nodes():
    rng = np.random.default_rng(5)
    weights = np.where(rng.random((30, 30)) < 0.15, rng.uniform(0.5, 3.0, (30, 30)), np.inf)
    graph = dense_graph(weights)
    result = jax.device_get(walk(jax.random.key(1), graph, uniform(graph), 0, 29, num_agents=32,
                                 max_steps=29))
    path, visited = np.asarray(result.path), unpacked(result.visited, 30)
    for a in range(32):
        nodes = path[a][path[a] >= 0]
        assert len(set(nodes.tolist())) == len(nodes)
        assert bool(is_valid_path(graph, path[a], start=0))
        assert sum(weights[u, v] for u, v in zip(nodes[:-1], nodes[1:])) == pytest.approx(
            float(result.length[a]), rel=1e-6)
        assert set(np.flatnonzero(visited[a])) == set(nodes.tolist())
    assert result.arrived.any() and result.stuck.any()


def test_visited_nodes_is_the_union_of_the_selected_paths():
    nodes, centre = SIDE * SIDE, SIDE * SIDE // 2 + SIDE // 2
    graph = grid(0.2, seed=2, free=(centre, nodes - 1))
    result = jax.device_get(grid_walk(jax.random.key(2), graph, uniform(graph), centre,
                                      nodes - 1))
    path = np.asarray(result.path)
    np.testing.assert_array_equal(unpacked(result.visited, nodes).any(axis=0),
                                  np.asarray(visited_nodes(result, nodes)))
    which = result.arrived
    expected = np.zeros(nodes, bool)
    expected[path[~which][path[~which] >= 0]] = True
    np.testing.assert_array_equal(np.asarray(visited_nodes(result, nodes, ~which)), expected)
    assert expected.any() and not expected.all()


def test_walk_into_a_dead_end_gets_stuck_and_start_at_goal_arrives():
    obstacles = np.ones((SIDE, SIDE), bool)
    obstacles[1, :4] = False  # a corridor (0,1)..(3,1) closed at the east end
    graph = grid_graph(obstacles)
    west, east, goal = SIDE, SIDE + 3, 2 * SIDE + 4  # the goal (4,2) is blocked
    result = jax.device_get(grid_walk(jax.random.key(0), graph, uniform(graph), west, goal))
    assert result.stuck.all() and not result.arrived.any()
    np.testing.assert_array_equal(result.position, [east] * AGENTS)
    np.testing.assert_array_equal(np.asarray(result.path)[:, :5],
                                  [[*range(west, east + 1), -1]] * AGENTS)
    # One block of a lane per agent: all are stuck after three moves, so the loop ends there.
    assert int(result.lane_steps) == AGENTS * STEPS_PER_REFILL
    at_goal = jax.device_get(grid_walk(jax.random.key(0), graph, uniform(graph), west + 1,
                                       west + 1))
    assert at_goal.arrived.all() and int(at_goal.lane_steps) == 0


def test_greedy_agents_descend_deterministically_and_the_others_do_not():
    graph = grid()
    goal = SIDE * SIDE - 1
    logw = towards(graph, goal, 1.0)  # prefer moves towards the goal
    walks = [jax.device_get(grid_walk(jax.random.key(k), graph, logw, 0, goal, greedy_agents=2))
             for k in range(3)]
    paths = np.stack([np.asarray(result.path) for result in walks])
    diagonal = list(range(0, goal + 1, SIDE + 1))
    for result, path in zip(walks, paths):
        np.testing.assert_array_equal(path[0], diagonal + [-1] * (STEPS + 1 - len(diagonal)))
        np.testing.assert_array_equal(path[1], path[0])
        assert float(result.length[0]) == pytest.approx((SIDE - 1) * np.sqrt(2), rel=1e-6)
    drawn = paths[:, 2:]
    assert (drawn != drawn[0]).any()  # drawing agents vary with the key


def test_excluded_and_invalid_edges_are_never_taken():
    graph = grid()
    logw = np.zeros(graph.nbr.shape, np.float32)
    logw[:, 4:] = -np.inf  # the algorithm forbids diagonals
    result = grid_walk(jax.random.key(4), graph, edge_table(graph, logw), 0, 4 * SIDE + 4)
    slots = np.asarray(result.slots)
    assert slots.max() <= 3 and (slots[slots >= 0] >= 0).all()
    assert np.asarray(result.arrived).any()


@pytest.fixture
def walker_constants(monkeypatch):
    """``set(**values)`` sets constants of the walker's module for the rest of the test; the
    jitted :func:`walk` traces again with them, and again with the originals after the test."""
    import jaxswarm.swarm.walking.loop as walk_module

    def set_constants(**values):
        for name, value in values.items():
            monkeypatch.setattr(walk_module, name, value)
        walk.clear_cache()

    yield set_constants
    monkeypatch.undo()
    walk.clear_cache()


@pytest.mark.parametrize("lanes, compact, smallest", [
    (64, 10 ** 9, 16), (5, 2, 16), (64, 2, 2),
    # A walk program each: a queue narrowing to 2 lanes in the slow tier, its twin (5, 2, 16).
    pytest.param(8, 4, 16, marks=pytest.mark.slow)])
def test_how_agents_share_the_lanes_changes_no_walk(walker_constants, lanes, compact, smallest):
    graph = grid()
    goal = SIDE * SIDE - 1
    logw = towards(graph, goal, 0.6)  # most agents arrive early, a few wander on

    def walks():
        return grid_walk(jax.random.key(0), graph, logw, 0, goal, greedy_agents=2)

    default = walks()
    moves = np.asarray(default.moves)
    # The case under test: agents of very different lengths, so lanes are refilled unevenly.
    assert moves.max() - moves.min() > 4 * STEPS_PER_REFILL
    # (64, 2, 2): five narrowings
    walker_constants(LANES=lanes, COMPACT_SHARE=compact, SMALLEST_COMPACTION=smallest)
    shared = walks()
    assert int(shared.lane_steps) != int(default.lane_steps)  # another schedule ...
    for (name, value), other in zip(_fields(default).items(), _fields(shared).values()):
        np.testing.assert_array_equal(value, other, err_msg=name)  # ... the same walks


def test_a_loop_steps_about_one_lane_per_eight_agents_within_bounds():
    assert [lanes_for(n) for n in (1, 100, 128, 1024, 2048, 4096, 8192, 16384, 10 ** 6)] == [
        1, 100, 128, 128, 256, 512, 1024, 1024, 1024]
    assert FEWEST_LANES <= LANES


def test_a_small_walk_keeps_most_lanes_busy(walker_constants):
    """1,024 agents (4 runs of 256, a few of which wander long after the others arrived) on
    ``lanes_for``'s 128 lanes: more of the lane-steps move an agent than with a lane per agent,
    for the same walks."""
    goal = SIDE * SIDE - 1
    graph = grid(0.1, seed=4, free=(0, goal))
    logw = towards(graph, goal, 0.7)
    keys = jax.random.split(jax.random.key(2), 4)

    def walks():
        return jax.vmap(lambda key: walk(key, graph, logw, jnp.int32(0), jnp.int32(goal),
                                         num_agents=256, max_steps=STEPS))(keys)

    queued = jax.device_get(walks())
    walker_constants(FEWEST_LANES=1024)  # a lane for every agent
    one_each = jax.device_get(walks())
    busy = [int(w.moves.sum()) / int(w.lane_steps[0]) for w in (queued, one_each)]
    assert busy[0] > 0.7 and busy[0] > busy[1] + 0.05, busy
    np.testing.assert_array_equal(queued.moves, one_each.moves)
    np.testing.assert_array_equal(queued.log.nodes, one_each.log.nodes)


def test_a_batch_of_walks_shares_one_queue_and_walks_as_each_alone():
    """A batch whose agents outnumber the walker's lanes: 4 runs of 64 agents step 128 lanes,
    which take agent after agent from one queue, while a run alone walks a lane an agent; every
    run walks as it does alone. The default tier's twin of the conformance checks' batches of 64
    runs (slow tier)."""
    goal = SIDE * SIDE - 1
    graph = grid(0.2, seed=3, free=(0, SIDE + 1, goal))
    logw = towards(graph, goal, 0.3)
    keys = jax.random.split(jax.random.key(7), 4)
    starts = np.array([0, SIDE + 1, goal, 0], np.int32)  # the third run is already at its goal
    assert lanes_for(4 * AGENTS) < 4 * AGENTS and lanes_for(AGENTS) == AGENTS

    batch = jax.device_get(batch_of_walks(keys, graph, logw, starts, goal))
    fields = _fields(batch)
    for i in range(4):
        alone = grid_walk(keys[i], graph, logw, starts[i], goal)
        for (name, value), other in zip(_fields(alone).items(), fields.values()):
            np.testing.assert_array_equal(value, other[i], err_msg=name)
    assert batch.moves.sum() <= batch.lane_steps[0]  # one loop's count for all
    assert int(grid_walk(keys[2], graph, logw, goal, goal).lane_steps) == 0
    assert batch.arrived[2].all()
