"""The native depth-first walk (jaxswarm.swarm.walking.native_backtrack, backtrack.cc) against
the XLA one: every leaf bit for bit for the first ant's fixed table (greedy and drawn), IWD's
soil rule and a population cut at a path length, on the shared maze, on a cut-out map whose goal
cannot be reached, and on a general graph; under vmap (one kernel call per walk for the whole
batch); whole runs of IWD with backtracking drops and of improved_max_min_aco's first ant; the
soil rule against IWD's own; the switch and the kernel's checks."""
import functools
import os
import shutil

import jax
import numpy as np
import pytest
import sizes
from graphs import geometric_graph

from jaxswarm.runtime import native
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.iwd.iwd import DEFAULT_IWD, soil_choice
from jaxswarm.swarm.iwd.soil import SOIL_CHOICE, choice_log_weights, goal_log_desirability
from jaxswarm.swarm.registry import REGISTRY
from jaxswarm.swarm.testing import differing_leaves
from jaxswarm.swarm.walking import WalkerOptions, edge_table
from jaxswarm.swarm.walking import native as native_walk
from jaxswarm.swarm.walking import native_backtrack
from jaxswarm.swarm.walking.backtrack import (DepthFirstRule, walks_natively, backtracking_walk,
                                              depth_first_walk, rule_choice)
from jaxswarm.world.graph import grid_graph

pytestmark = pytest.mark.skipif(
    not os.environ.get("CXX") and not any(shutil.which(c) for c in native.COMPILERS),
    reason="no C++ compiler")

KEYS = (0, 1, 2)
"""The keys each program is called with (keys, not compiles: each is one more call)."""
WALKS = 4
"""The depth-first walks of one :func:`walks` program (each one kernel call when native)."""
TARGET = f"custom_call @{native.DEPTH_FIRST_TARGET}("


@functools.partial(jax.jit, static_argnames=("implementation", "cut"))
def walks(key, graph, soil, params, start, goal, *, implementation, cut):
    """Every kind of depth-first walk in one program, over IWD's goal table: the first ant's
    (the table's row) greedy and drawn, 32 IWD drops (the soil rule), and 32 agents on the table
    whose ways may have at most ``cut`` moves."""
    table = edge_table(graph, params.beta * goal_log_desirability(graph, goal))
    fixed = DepthFirstRule(table)
    first_ant = functools.partial(depth_first_walk, key, graph, fixed, start, goal,
                                  max_nodes=graph.num_nodes, implementation=implementation)
    population = functools.partial(backtracking_walk, key, graph, start=start, goal=goal,
                                   num_agents=sizes.AGENTS, implementation=implementation)
    return dict(greedy=first_ant(greedy=True), drawn=first_ant(),
                drops=population(soil_choice(table, soil, params),
                                 max_steps=graph.num_nodes - 1),
                cut=population(fixed, max_steps=cut))


def soil_of(graph, seed=0):
    """f32[N, K] uneven soil, some of it negative (the choice's shift applies)."""
    return np.random.default_rng(seed).uniform(-50.0, 800.0, graph.nbr.shape).astype(np.float32)


def compare(graph, task, cut):
    """Both implementations on every key; returns the XLA walks."""
    out = []
    for key in KEYS:
        args = (jax.random.key(key), graph, soil_of(graph, key), DEFAULT_IWD, task.start,
                task.goal)
        reference = walks(*args, implementation="lanes", cut=cut)
        native_walks = walks(*args, implementation="native", cut=cut)
        assert not differing_leaves(reference, native_walks), f"key {key}"
        out.append(reference)
    return out


MAZE_CUT = 84
"""Moves a cut way may have on the maze: the drops' ways there have 78 to 90."""


def test_the_maze_and_an_unreachable_goal_equal_xla():
    graph, task = sizes.maze()
    walked = compare(graph, task, MAZE_CUT)
    cut = np.concatenate([np.asarray(w["cut"].arrived) for w in walked])
    assert cut.any() and not cut.all()  # some ways were longer than the cut
    assert all(bool(w["greedy"].found) for w in walked)
    assert max(int(w["drawn"].moves) for w in walked) > 90  # it backed out of dead ends
    # A cut-out map of the maze's shape (the same programs): two rooms, the goal in the other.
    walled = sizes.cut_out([[True, True, True, False, True], [True, True, True, False, True]])
    for w in compare(walled, make_task(walled, (0, 0), (4, 1)), MAZE_CUT):
        for name in ("greedy", "drawn"):
            assert not bool(w[name].found) and np.all(np.asarray(w[name].path) == -1)
            assert int(w[name].moves) == 5 + 6  # into the room's 5 other cells, out of all 6
        assert not np.asarray(w["drops"].arrived).any()
        assert np.all(np.asarray(w["drops"].moves) == 5 + 6)


def test_a_general_graph_equals_xla():
    """A random directed graph of 60 nodes; a cut of 4 moves (its ways have 3 to 21)."""
    graph = geometric_graph(np.random.default_rng(3), 60, radius=3.0, density=0.7,
                            stretch=(1.0, 1.5))
    walked = compare(graph, make_task(graph, 0, 59), 4)
    cut = np.concatenate([np.asarray(w["cut"].arrived) for w in walked])
    assert cut.any() and not cut.all()


def test_a_vmap_over_keys_is_one_call_per_walk_and_equals_the_walks_alone():
    graph, task = sizes.maze()
    soil = soil_of(graph)
    batched = jax.jit(jax.vmap(
        functools.partial(walks, implementation="native", cut=MAZE_CUT),
        in_axes=(0, None, None, None, None, None)))
    keys = jax.vmap(jax.random.key)(np.array(KEYS))
    args = (keys, graph, soil, DEFAULT_IWD, task.start, task.goal)
    assert batched.lower(*args).as_text().count(TARGET) == WALKS
    together = batched(*args)
    for i, key in enumerate(KEYS):
        alone = walks(jax.random.key(key), graph, soil, DEFAULT_IWD, task.start, task.goal,
                      implementation="native", cut=MAZE_CUT)
        member = jax.tree_util.tree_map(lambda leaf, i=i: leaf[i], together)
        assert not differing_leaves(alone, member), f"key {key}"


def calls_the_kernel(name, **config) -> bool:
    """Whether ``name``'s first iteration (``init`` and ``step`` of its shared-size run on the
    maze, with ``config``), as traced now, calls the native depth-first walk."""
    swarm = make(name, **sizes.CONFIG, **config)
    graph, task = sizes.maze()
    args = (graph, task, swarm.default_params)
    state = jax.eval_shape(swarm.init, jax.random.key(0), *args)
    traced = [jax.make_jaxpr(swarm.init)(jax.random.key(0), *args),
              jax.make_jaxpr(swarm.step)(state, *args)]
    return any(native.DEPTH_FIRST_TARGET in str(jaxpr) for jaxpr in traced)


def runs_of(name, **config):
    """``name``'s shared-size run on the maze from two keys, with ``config``: a list of
    ``(state, trace)``. The swarm is built anew (``make``'s are kept, and their programs with
    them), so its programs are traced now, under the environment of now."""
    swarm = REGISTRY[name].build(make(name, **sizes.CONFIG, **config).config)
    graph, task = sizes.maze()
    return [run(swarm, jax.random.key(key), graph, task, swarm.default_params,
                iterations=sizes.ITERATIONS) for key in KEYS[:2]]


def test_iwd_with_backtracking_drops_runs_the_same_native():
    chosen = {name: WalkerOptions(implementation=name) for name in ("lanes", "native")}
    traced = [calls_the_kernel("iwd", backtrack=True, walker=chosen[name]) for name in chosen]
    assert traced == [False, True]
    lanes = runs_of("iwd", backtrack=True, walker=chosen["lanes"])
    natives = runs_of("iwd", backtrack=True, walker=chosen["native"])
    for key, (reference, other) in enumerate(zip(lanes, natives)):
        assert not differing_leaves(reference, other), f"key {key}"
    assert np.isfinite(np.asarray(lanes[0][0].best_cost))


def test_improved_max_min_acos_first_ant_runs_the_same_native():
    """The first ant (bug2.first_ant_path) walks as the colony's walker options say."""
    chosen = {name: WalkerOptions(implementation=name) for name in ("lanes", "native")}
    traced = [calls_the_kernel("improved_max_min_aco", walker=chosen[name]) for name in chosen]
    assert traced == [False, True]
    lanes = runs_of("improved_max_min_aco", walker=chosen["lanes"])
    natives = runs_of("improved_max_min_aco", walker=chosen["native"])
    for key, (reference, other) in enumerate(zip(lanes, natives)):
        assert not differing_leaves(reference, other), f"key {key}"


def test_the_soil_rule_is_iwds_choice():
    """The rule's XLA evaluation (a copy of IWD's choice_log_weights: the walking package cannot
    import it) gives IWD's bits, eagerly (no program), at every node of a small room and for
    uneven visited sets."""
    graph = grid_graph(np.zeros((3, 4), bool))
    rng = np.random.default_rng(1)
    table = np.where(graph.nbr >= 0, rng.normal(size=graph.nbr.shape), -np.inf).astype(np.float32)
    soil = rng.uniform(-100.0, 300.0, graph.nbr.shape).astype(np.float32)  # shifts, some
    rule = rule_choice(soil_choice(table, soil, DEFAULT_IWD))
    one_lane = jax.tree_util.tree_map(lambda p: np.asarray(p)[None], DEFAULT_IWD)
    for here in range(graph.num_nodes):
        unvisited = (graph.nbr[here] >= 0) & (rng.random(graph.nbr.shape[1]) < 0.7)
        admissible = unvisited & (table[here] > -np.inf)
        expected = table[here] + choice_log_weights(one_lane, soil[here][None],
                                                    admissible[None])[0]
        assert np.asarray(rule(here, unvisited)).tobytes() == np.asarray(expected).tobytes()


def test_the_switch_is_the_walkers(monkeypatch):
    """The walker's switch (:func:`native.implementation`) picks the depth-first walk's
    implementation too; only the rules the kernel copies walk natively."""
    table = np.zeros((4, 2), np.float32)
    soil_rule = soil_choice(table, table, DEFAULT_IWD)
    monkeypatch.setenv(native_walk.VARIABLE, "native")
    assert walks_natively(DepthFirstRule(table), None) and walks_natively(soil_rule, None)
    assert not walks_natively(DepthFirstRule(table), "lanes")  # the caller's choice first
    assert not walks_natively(lambda here, unvisited: table[here], None)  # Python
    assert not walks_natively(soil_rule._replace(hook=SOIL_CHOICE._replace(native=None)), None)
    monkeypatch.setenv(native_walk.VARIABLE, "lanes")
    assert not walks_natively(soil_rule, None)


def test_the_kernel_refuses_inputs_it_cannot_take():
    """Eager calls (no program): a start outside the map, a neighbour table of another shape."""
    keys = np.zeros((2, 2), np.uint32)
    table = np.zeros((4, 2), np.float32)
    nbr = np.array([[1, -1], [2, 0], [3, 1], [-1, 2]], np.int32)
    call = functools.partial(native_backtrack.depth_first_walks, keys, soil=None, alpha=None,
                             eps_s=None, goal=3, max_nodes=4, greedy=True)
    with pytest.raises(jax.errors.JaxRuntimeError, match="start or goal outside the map"):
        np.asarray(call(nbr, table, start=4)[0])
    with pytest.raises(jax.errors.JaxRuntimeError, match="nbr must be"):
        np.asarray(call(nbr[:, :1], table, start=0)[0])
    path, found, moves = call(nbr, table, start=0)
    assert np.asarray(path).tolist() == [[0, 1, 2, 3]] * 2 and np.asarray(found).all()
    assert np.asarray(moves).tolist() == [3, 3]
