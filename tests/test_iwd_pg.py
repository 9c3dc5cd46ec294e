"""IWD_PG's parts: the smooth operator, the memory and its path surgery, the intersection
operators, the fuzzy section scores (against a hand computation), local search, and the swarm
with each stage switched off."""
import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxswarm.exact import dijkstra
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.iwd import fuzzy
from jaxswarm.swarm.iwd.iwd import STANDARD_IWD, IWDConfig, build_iwd
from jaxswarm.swarm.iwd.intersect import (closest_inner_pair, first_intersection,
                                          second_intersection)
from jaxswarm.swarm.iwd.local import connect
from jaxswarm.swarm.iwd.memory import empty_memory, join, remember, reverse, splice
from jaxswarm.swarm.iwd.smooth import smooth_path
from jaxswarm.swarm.walking import WalkerOptions, edge_table, walk
from jaxswarm.world.graph import grid_graph
from jaxswarm.world.paths import is_valid_path, pad, path_length, trim

L = 40


def open_grid(height=6, width=6, blocked=()):
    grid = np.zeros((height, width), bool)
    for x, y in blocked:
        grid[y, x] = True
    return grid_graph(grid)


def nodes(cells, width=6):
    return [y * width + x for x, y in cells]


# The operators under test and the walks' edge table, each called from the tests through one
# jitted wrapper: one program per shape, where called outside jit each of their JAX operations
# is a program of its own.
smooth = jax.jit(smooth_path)
smooth_each = jax.jit(jax.vmap(smooth_path, in_axes=(None, 0)))
remember_paths = jax.jit(remember)
intersect_first = jax.jit(first_intersection)
score = jax.jit(fuzzy.fuzzy_score)
valid_table = jax.jit(edge_table)


@jax.jit
def intersect_second(graph, a, b, connection):
    """:func:`closest_inner_pair` ``(i, j)`` of ``a`` and ``b``, and the children of
    :func:`second_intersection` joined there by ``connection``."""
    i, j = closest_inner_pair(graph, a, b)
    return (i, j), second_intersection(graph, a, b, i, j, connection)


@jax.jit
def surgery(a, b, middle):
    """:func:`join` of ``a``'s first 2 nodes and ``b`` from position 1, :func:`splice` of
    ``middle`` into ``a`` from position 1 to 3, and :func:`reverse` of ``a``."""
    return join(a, 2, b, 1), splice(a, 1, 3, middle), reverse(a)


@jax.jit
def sections(graph, paths):
    """The lengths of each of ``paths`` in 4 sections along x (:func:`fuzzy.section_lengths`)
    and their scores (:func:`fuzzy.section_scores`, every path present)."""
    lengths = jax.vmap(lambda path: fuzzy.section_lengths(graph, path, 0, 4))(paths)
    return lengths, fuzzy.section_scores(lengths, jnp.ones(paths.shape[0], bool))


def test_smoothing_shortens_a_staircase_into_a_diagonal():
    graph = open_grid()
    stairs = nodes([(0, 0), (1, 0), (1, 1), (2, 1), (2, 2), (3, 2), (3, 3)])
    smoothed = trim(smooth(graph, pad(stairs, L)))
    assert smoothed.tolist() == nodes([(0, 0), (1, 1), (2, 2), (3, 3)])


def test_smoothing_never_cuts_a_corner_or_crosses_a_block():
    graph = open_grid(blocked=[(1, 0)])
    # Around the block (1, 0): the diagonal (0, 0) -> (1, 1) would squeeze past it.
    around = nodes([(0, 0), (0, 1), (1, 1), (2, 1), (2, 0)])
    smoothed = smooth(graph, pad(around, L))
    assert bool(is_valid_path(graph, smoothed, around[0], around[-1]))
    assert float(path_length(graph, smoothed)) <= float(path_length(graph, pad(around, L)))
    assert 1 not in trim(smoothed).tolist()


def test_smoothing_takes_two_straight_moves_for_two_diagonals():
    graph = open_grid()
    bump = nodes([(0, 2), (1, 1), (2, 2)])  # NE then SE: 2.83; E, E is 2
    smoothed = trim(smooth(graph, pad(bump, L)))
    assert smoothed.tolist() == nodes([(0, 2), (1, 2), (2, 2)])


def test_smoothed_drop_paths_stay_valid_and_never_get_longer():
    # Random walks from a corner of a 16 x 16 grid with a quarter of its cells blocked, ending
    # wherever they stopped: the sizes of test_walk.py's and test_log.py's walks (64 agents,
    # 255 steps, start and goal as i32[]), one program for the three files.
    side = 16
    goal = side * side - 1
    obstacles = np.random.default_rng(0).random((side, side)) < 0.25
    obstacles.flat[[0, goal]] = False
    graph = grid_graph(obstacles)
    table = valid_table(graph, np.zeros(graph.nbr.shape, np.float32))
    walks = walk(jax.random.key(1), graph, table, np.int32(0), np.int32(goal), num_agents=64,
                 max_steps=goal)
    smoothed = smooth_each(graph, walks.path)
    shortened = 0
    for before, after in zip(np.asarray(walks.path), np.asarray(smoothed)):
        ends = trim(before)[[0, -1]]
        assert bool(is_valid_path(graph, after, ends[0], ends[1]))
        length, walked = float(path_length(graph, after)), float(path_length(graph, before))
        assert length <= walked + 1e-4
        assert len(set(trim(after).tolist())) == len(trim(after))  # still simple
        shortened += length < walked - 1e-4
    assert shortened  # the case under test: walks with detours to cut


@pytest.mark.parametrize("swarm_run", ["iwd"], indirect=True)
def test_iwd_keeps_soil_on_every_edge(swarm_run):
    """IWD's memory holds an amount of soil per edge slot of the map (the shared run's state)."""
    assert swarm_run.state.soil.shape == swarm_run.world.nbr.shape


def test_memory_keeps_the_shortest_distinct_paths_best_first():
    memory = empty_memory(3, 6)
    paths = np.asarray([pad([0, 1, 2], 6), pad([0, 3, 2], 6), pad([0, 1, 2], 6),
                        pad([0, 4, 5, 2], 6)])
    memory = remember_paths(memory, paths, np.float32([2.0, 2.5, 2.0, 3.0]))
    assert np.asarray(memory.costs).tolist() == [2.0, 2.5, 3.0]
    assert [trim(p).tolist() for p in np.asarray(memory.paths)] == [[0, 1, 2], [0, 3, 2],
                                                                    [0, 4, 5, 2]]
    memory = remember_paths(memory, paths[:1], np.float32([2.0]))  # already remembered
    assert np.asarray(memory.costs).tolist() == [2.0, 2.5, 3.0]
    memory = remember_paths(memory, np.asarray([pad([0, 2], 6)]), np.float32([1.0]))
    assert np.asarray(memory.costs).tolist() == [1.0, 2.0, 2.5]


def test_join_splice_and_reverse_by_hand():
    a, b, middle = pad([1, 2, 3, 4], 8), pad([7, 3, 8, 9], 8), pad([2, 5, 6, 4], 8)
    joined, spliced, backwards = surgery(a, b, middle)
    assert trim(joined).tolist() == [1, 2, 3, 8, 9]
    assert trim(spliced).tolist() == [1, 2, 5, 6, 4]
    assert trim(backwards).tolist() == [4, 3, 2, 1]


def test_first_intersection_exchanges_tails_at_the_best_shared_node():
    graph = open_grid()
    a = pad(nodes([(0, 0), (1, 0), (2, 0), (3, 1), (4, 2), (5, 3)]), L)  # long way round
    b = pad(nodes([(0, 0), (0, 1), (1, 2), (2, 1), (3, 1), (4, 1), (5, 2), (5, 3)]), L)
    kids = jax.device_get(intersect_first(graph, a, b))
    for child, cost in zip(kids.paths, kids.costs):
        assert bool(is_valid_path(graph, child, 0, nodes([(5, 3)])[0]))
        assert cost == pytest.approx(float(path_length(graph, child)))
    # a's head to (3, 1), then b's tail; b's head to (3, 1), then a's tail.
    assert trim(kids.paths[0]).tolist() == nodes([(0, 0), (1, 0), (2, 0), (3, 1), (4, 1),
                                                  (5, 2), (5, 3)])
    assert trim(kids.paths[1]).tolist() == nodes([(0, 0), (0, 1), (1, 2), (2, 1), (3, 1),
                                                  (4, 2), (5, 3)])
    apart = pad(nodes([(0, 0), (0, 1), (0, 2), (1, 3), (2, 4), (3, 4), (4, 4), (5, 3)]), L)
    assert not np.isfinite(np.asarray(intersect_first(graph, a, apart).costs)).any()


def test_second_intersection_joins_the_closest_inner_nodes():
    graph = open_grid()
    a = pad(nodes([(0, 0), (1, 0), (2, 0), (3, 0), (4, 1), (5, 2)]), L)
    b = pad(nodes([(0, 0), (0, 1), (1, 2), (2, 2), (3, 2), (4, 3), (5, 2)]), L)
    connection = pad(nodes([(1, 0), (0, 1)]), L)
    (i, j), kids = jax.device_get(intersect_second(graph, a, b, connection))
    assert (int(i), int(j)) == (1, 1)  # (1, 0) and (0, 1), one diagonal apart (first in order)
    assert trim(kids.paths[0]).tolist() == nodes([(0, 0), (1, 0), (0, 1), (1, 2), (2, 2), (3, 2),
                                                  (4, 3), (5, 2)])
    assert trim(kids.paths[1]).tolist() == nodes([(0, 0), (0, 1), (1, 0), (2, 0), (3, 0), (4, 1),
                                                  (5, 2)])
    for child, cost in zip(kids.paths, kids.costs):
        assert bool(is_valid_path(graph, child, 0, nodes([(5, 2)])[0]))
        assert cost == pytest.approx(float(path_length(graph, child)))
    _, nothing = intersect_second(graph, a, b, np.full((L,), -1, np.int32))
    assert not np.isfinite(np.asarray(nothing.costs)).any()


def hand_membership(x):
    """Low, medium, high of x in [0, 1], written out piecewise."""
    low = 1.0 if x <= 0.25 else (0.0 if x >= 0.5 else (0.5 - x) / 0.25)
    medium = 0.0 if x <= 0.25 or x >= 0.75 else (
        (x - 0.25) / 0.25 if x <= 0.5 else (0.75 - x) / 0.25)
    high = 0.0 if x <= 0.5 else (1.0 if x >= 0.75 else (x - 0.5) / 0.25)
    return [low, medium, high]


def test_fuzzy_score_of_a_fixed_example_by_hand():
    spl, ospl = 0.3, 0.6
    m_spl, m_ospl = hand_membership(spl), hand_membership(ospl)  # [0.8, 0.2, 0], [0, 0.6, 0.4]
    table = [["high", "high", "medium"], ["medium", "medium", "low"],
             ["medium", "low", "low"]]
    strength = {"low": 0.0, "medium": 0.0, "high": 0.0}
    for r in range(3):
        for c in range(3):
            strength[table[r][c]] = max(strength[table[r][c]], min(m_spl[r], m_ospl[c]))
    assert strength == pytest.approx({"low": 0.2, "medium": 0.4, "high": 0.6})
    points = np.linspace(0, 1, 101)
    shape = [max(min(strength[name], hand_membership(p)[k])
                 for k, name in enumerate(("low", "medium", "high"))) for p in points]
    want = float(np.dot(shape, points) / np.sum(shape))
    assert float(score(np.float32(spl), np.float32(ospl))) == pytest.approx(want, rel=1e-5)


def test_section_lengths_and_scores_of_three_paths():
    graph = open_grid()
    straight = pad(nodes([(x, 0) for x in range(6)]), L)  # along row 0: moves in every section
    paths = np.asarray([straight,
                        pad(nodes([(0, 0), (1, 1), (2, 2), (3, 1), (4, 1), (5, 0)]), L),
                        pad(nodes([(0, 0), (0, 1), (0, 2), (0, 3), (1, 3), (2, 3), (3, 3),
                                   (4, 3), (5, 3), (5, 2), (5, 1), (5, 0)]), L)])
    lengths, scores = jax.device_get(sections(graph, paths))
    assert lengths[0].sum() == pytest.approx(5.0) and (lengths[0] > 0).all()
    assert ((scores >= 0) & (scores <= 1)).all()
    # The straight path is shortest everywhere: best in every section; the long detour worst.
    assert (scores[0] >= scores[1] - 1e-6).all() and (scores[1] >= scores[2] - 1e-6).all()
    assert (scores[0] > scores[2]).all()


def hooked_map():
    """8 x 8 with an L-shaped wall between the start (0, 7) and the goal (7, 0): IWD's drops
    find long ways round it (17-24 for seeds 0-3), the optimum is 11.66."""
    blocked = [(3, y) for y in range(3, 7)] + [(x, 3) for x in range(4, 6)]
    graph = open_grid(8, 8, blocked=blocked)
    return graph, make_task(graph, (0, 7), (7, 0))


def check_iwd_pg(options, seeds):
    graph, task = hooked_map()
    optimum = float(dijkstra(graph, task.start, task.goal).cost)
    swarm = make("iwd_pg", num_agents=10, local_agents=4, local_iterations=3, **options)
    for seed in seeds:
        state, trace = run(swarm, jax.random.key(seed), graph, task, swarm.default_params,
                           iterations=15)
        best = swarm.best(state)
        assert bool(is_valid_path(graph, best.path, task.start, task.goal)), options
        assert float(best.cost) == pytest.approx(float(path_length(graph, best.path)))
        assert float(best.cost) == pytest.approx(optimum, rel=1e-5), (options, seed)
        drops = np.nansum(np.asarray(trace.arrived)) * 10
        assert int(trace.evaluations.sum()) > drops  # the operators' calls count too


@pytest.mark.slow  # its own sizes, about 30 s to compile; its twin: its conformance checks
def test_iwd_pg_reaches_the_optimum_where_iwd_does_not():
    check_iwd_pg({}, seeds=(0, 2))


@pytest.mark.slow
@pytest.mark.parametrize("options", [{"smooth": False}, {"fuzzy": False},
                                     {"first_intersection": False, "second_intersection": False}])
def test_iwd_pg_without_one_stage_still_runs(options):
    graph, task = hooked_map()
    swarm = make("iwd_pg", num_agents=10, local_agents=4, local_iterations=3, **options)
    state, trace = run(swarm, jax.random.key(1), graph, task, swarm.default_params,
                       iterations=10)
    best = swarm.best(state)
    assert bool(is_valid_path(graph, best.path, task.start, task.goal)), options
    assert float(best.cost) == pytest.approx(float(path_length(graph, best.path)))


def test_bad_iwd_pg_options_are_named():
    with pytest.raises(ValueError, match="memory_size"):
        make("iwd_pg", memory_size=1)
    with pytest.raises(ValueError, match="sections"):
        make("iwd_pg", sections=0)


def test_a_local_search_whose_walk_overflowed_says_so():
    # Corner to corner of an open 32 x 32 grid every arrived drop makes at least 31 moves: a log
    # with room for 16 moves a drop cannot hold them, and the search says so (IWD_PG's step
    # then reports it, and the executor makes the run again with room).
    graph = grid_graph(np.zeros((32, 32), bool))
    cramped = build_iwd(IWDConfig(num_agents=8, walker=WalkerOptions(log_moves=16)))
    search = jax.jit(functools.partial(connect, swarm=cramped, iterations=2))
    *_, overflowed = search(jax.random.key(0), graph, jnp.int32(0), jnp.int32(32 * 32 - 1),
                            STANDARD_IWD)
    assert bool(overflowed)
