"""The native walk (jaxswarm.swarm.walking.native, walk.cc) against the XLA walker's lanes:
every leaf of the Walk bit for bit, on ACO*'s and rfd_graded's tables of the shared maze and of
mosaic50, alone and in batches (the walker's vmap rule folds the runs into one kernel call),
with a greedy agent, a run that starts at its goal, a walk whose lanes narrow twice, overflowed
logs, and a general graph; and IWD's drops under its two soil hooks. The default tier compares
them once at the shared size; the rest is in the slow tier."""
import os
import shutil

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import sizes
from graphs import geometric_graph

from jaxswarm.maps.paper import paper_map
from jaxswarm.runtime import native
from jaxswarm.swarm import aco, make, make_task, rfd
from jaxswarm.swarm.executor import with_room
from jaxswarm.swarm.iwd.soil import SOIL, SOIL_CHOICE, goal_log_desirability
from jaxswarm.swarm.testing import differing_leaves
from jaxswarm.swarm.walking import WalkerOptions, loop, walk
from jaxswarm.swarm.walking import native as native_walk
from jaxswarm.swarm.walking.tables import edge_table, step_budget

pytestmark = pytest.mark.skipif(
    not os.environ.get("CXX") and not any(shutil.which(c) for c in native.COMPILERS),
    reason="no C++ compiler")

KEYS = (0, 1, 2)
"""The keys each program is called with (keys, not compiles: each is one more call)."""


def tables(graph, task) -> list:
    """ACO*'s and rfd_graded's transition tables of their first memory and of a memory with
    noise (uneven weights, so the draws are not near-uniform)."""
    out = []
    noise = jax.random.uniform(jax.random.key(5), (graph.num_nodes,), minval=-1.0, maxval=1.0)
    for name in ("aco_star", "rfd_graded"):
        swarm = make(name, num_agents=sizes.AGENTS)
        params = swarm.default_params
        state = swarm.init(jax.random.key(0), graph, task, params)
        if name == "aco_star":
            rule = lambda memory: aco.transition_rule(graph, task, memory, params,  # noqa: E731
                                                      goal_distance=True)
            memories = (state.pheromone, state.pheromone * jnp.exp(noise)[:, None])
        else:
            rule = lambda memory: rfd.graded_transition(graph, task, memory, params)  # noqa: E731
            memories = (state.altitude, state.altitude + noise * 0.5)
        out += [rule(memory) for memory in memories]
    return out


def walks(implementation, monkeypatch, graph, *, agents, steps, greedy=0, walker=WalkerOptions(),
          runs=None, hook=None):
    """The jitted walk ``(key(s), table, start, goal(s), memory, hook params) -> Walk`` as
    ``walk`` traces it with ``JAXSWARM_WALKER=implementation``: alone (``runs`` None) or under
    ``vmap`` over ``runs`` keys, goals and memories (one folded batch). Returns ``(call,
    lower)``, each setting the variable before the program is traced."""
    traced = walk.__wrapped__  # traced afresh by this jit, so the variable is read then

    def one(key, table, start, goal, memory, params):
        return traced(key, graph, table, start, goal, num_agents=agents, max_steps=steps,
                      greedy_agents=greedy, hook=hook, memory=memory, hook_params=params,
                      walker=walker)

    axes = (0, None, None, 0, None if hook is None else 0, None)
    program = jax.jit(one if runs is None else jax.vmap(one, in_axes=axes))

    def call(*args):
        monkeypatch.setenv(native_walk.VARIABLE, implementation)
        return program(*args)

    def lower(*args):
        monkeypatch.setenv(native_walk.VARIABLE, implementation)
        return program.lower(*args)

    return call, lower


def compare(monkeypatch, graph, task, table_list, *, agents=sizes.AGENTS, greedy=0,
            walker=WalkerOptions(), runs=None, goals=None, hook=None, soil=None, params=None):
    """Both implementations on every table and key (with ``hook``: over ``soil``, f32[N, K],
    and a run ``r`` of a batch over ``soil + r``, with IWD ``params``); returns the lanes'
    walks."""
    steps = step_budget(graph, None)
    shared = dict(agents=agents, steps=steps, greedy=greedy, walker=walker, runs=runs,
                  hook=hook)
    lanes, lower_lanes = walks("lanes", monkeypatch, graph, **shared)
    natives, lower_natives = walks("native", monkeypatch, graph, **shared)
    memory = (soil, params)
    example = arguments(task, table_list[0], 0, runs, goals, memory)
    target = f"custom_call @{native.WALK_TARGET if hook is None else native.HOOKED_WALK_TARGET}("
    assert lower_natives(*example).as_text().count(target) == 1  # the batch in one call
    assert target not in lower_lanes(*example).as_text()
    out = []
    for t, table in enumerate(table_list):
        for key in KEYS:
            args = arguments(task, table, key, runs, goals, memory)
            reference = lanes(*args)
            assert not differing_leaves(reference, natives(*args)), f"table {t}, key {key}"
            out.append(reference)
    return out


def arguments(task, table, key, runs, goals, memory=(None, None)):
    soil, params = memory
    if runs is None:
        return jax.random.key(key), table, task.start, task.goal, soil, params
    keys = jax.random.split(jax.random.key(key), runs)
    goal = jnp.full((runs,), task.goal, jnp.int32) if goals is None else jnp.asarray(goals)
    soils = None if soil is None else soil + jnp.arange(runs, dtype=jnp.float32)[:, None, None]
    return keys, table, task.start, goal, soils, params


@pytest.fixture(scope="module")
def maze():
    graph, task = sizes.maze()
    return graph, task, tables(graph, task)


@pytest.fixture(scope="module")
def mosaic():
    chosen = paper_map("mosaic50")
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    return graph, task, tables(graph, task)


WORLDS = ["maze", pytest.param("mosaic", marks=pytest.mark.slow)]
"""The shared maze in the default tier (the lanes' conformance once, at the shared size);
mosaic50 in the slow tier."""


@pytest.mark.parametrize("world", WORLDS)
def test_one_run_equals_the_lanes(world, request, monkeypatch):
    graph, task, table_list = request.getfixturevalue(world)
    walked = compare(monkeypatch, graph, task, table_list)
    assert any(int(w.arrived.sum()) for w in walked) and any(int(w.stuck.sum()) for w in walked)


@pytest.mark.parametrize("world", WORLDS)
def test_a_batch_of_three_with_a_greedy_agent_equals_the_lanes(world, request, monkeypatch):
    """Three runs under vmap, folded into one kernel call; one greedy agent per run; the third
    run starts at its goal (its agents do not walk)."""
    graph, task, table_list = request.getfixturevalue(world)
    goals = [task.goal, task.goal, task.start]
    walked = compare(monkeypatch, graph, task, table_list, greedy=1, runs=3, goals=goals)
    for w in walked:
        assert bool(np.all(w.arrived[2])) and not np.any(w.moves[2])


@pytest.mark.slow  # 3 x 1,024 agents on the lanes
def test_narrowing_lanes_and_a_shared_count_equal_the_lanes(maze, monkeypatch):
    """3 x 1,024 agents: 384 lanes, narrowed to 96 and then 24 as agents stop (lane_steps
    depends on that schedule, which the kernel replays)."""
    graph, task, table_list = maze
    assert loop.lanes_for(3 * 1024) // loop.COMPACT_SHARE ** 2 >= loop.SMALLEST_COMPACTION
    compare(monkeypatch, graph, task, table_list[:2], agents=1024, runs=3)


@pytest.mark.parametrize("runs", [None, pytest.param(3, marks=pytest.mark.slow)])
def test_an_overflowed_log_equals_the_lanes(maze, monkeypatch, runs):
    """Room for 16 moves an agent: the logs overflow, and the blocks the lanes' journal lost
    (the last in the lanes' schedule) are the kernel's too."""
    graph, task, table_list = maze
    walked = compare(monkeypatch, graph, task, table_list, walker=WalkerOptions(log_moves=16),
                     runs=runs)
    overflowed = [bool(np.all(w.log.overflowed)) for w in walked]  # all runs: the journal did
    assert sum(overflowed) >= len(KEYS), overflowed


def test_a_general_graph_equals_the_lanes(monkeypatch):
    """A random directed graph (its nbr table, its lengths summed from the log)."""
    graph = geometric_graph(np.random.default_rng(3), 60, radius=3.0, density=0.7,
                            stretch=(1.0, 1.5))
    task = make_task(graph, 0, 59)
    table = edge_table(graph, jax.random.normal(jax.random.key(2), graph.nbr.shape))
    compare(monkeypatch, graph, task, [table], runs=3)


def drops(graph, task):
    """IWD's goal table, a soil with noise (some of it negative, so the choice's shift by the
    smallest soil matters) and IWD's default params."""
    params = make("iwd", num_agents=sizes.AGENTS).default_params
    table = edge_table(graph, params.beta * goal_log_desirability(graph, task.goal))
    soil = jax.random.uniform(jax.random.key(7), graph.nbr.shape, minval=-20.0, maxval=200.0)
    return table, soil, params


@pytest.mark.parametrize("hook", [SOIL, SOIL_CHOICE], ids=["soil", "soil_choice"])
def test_the_soil_hooks_equal_the_lanes(maze, monkeypatch, hook):
    """IWD's drops with the soil rule (the soil written as they walk; several drops cross one
    edge in one step) and with the soil choice (read only): alone and in a batch of three with
    a run that starts at its goal, the memory and the drops' states included."""
    graph, task, _ = maze
    table, soil, params = drops(graph, task)
    walked = compare(monkeypatch, graph, task, [table], hook=hook, soil=soil, params=params)
    assert any(int(w.arrived.sum()) for w in walked)
    if hook.writes:
        assert not np.array_equal(walked[0].memory, soil)
    compare(monkeypatch, graph, task, [table], hook=hook, soil=soil, params=params, runs=3,
            goals=[task.goal, task.start, task.goal])


@pytest.mark.slow
def test_the_soil_rule_on_a_general_graph_with_an_overflowed_log_equals_the_lanes(monkeypatch):
    """The soil rule on a random directed graph (each edge's own length in eq. 4), its logs
    overflowed."""
    graph = geometric_graph(np.random.default_rng(3), 60, radius=3.0, density=0.7,
                            stretch=(1.0, 1.5))
    task = make_task(graph, 0, 59)
    table, soil, params = drops(graph, task)
    walked = compare(monkeypatch, graph, task, [table], hook=SOIL, soil=soil, params=params,
                     runs=3, walker=WalkerOptions(log_moves=16))
    assert any(bool(np.all(w.log.overflowed)) for w in walked)


def test_the_switch(monkeypatch):
    monkeypatch.setenv(native_walk.VARIABLE, "native")
    assert native_walk.implementation() == "native"
    assert native_walk.implementation(hook=SOIL) == "native"
    assert native_walk.implementation(hook=SOIL._replace(native=None)) == "lanes"
    monkeypatch.delenv(native_walk.VARIABLE)
    assert native_walk.implementation() == native_walk.platform_default() == "native"  # CPU
    monkeypatch.setenv(native_walk.VARIABLE, "fast")
    with pytest.raises(ValueError, match="JAXSWARM_WALKER"):
        native_walk.implementation()


def test_a_swarm_picks_its_implementation_with_its_walker_options(monkeypatch):
    monkeypatch.setenv(native_walk.VARIABLE, "lanes")
    assert native_walk.implementation(requested="native") == "native"  # before the variable
    with pytest.raises(ValueError, match="implementation must be one of lanes, native"):
        WalkerOptions(implementation="fast")
    chosen = WalkerOptions(log_moves=16, implementation="native")
    assert chosen.with_room() == WalkerOptions(log_moves=2 ** 31 - 1, implementation="native")
    swarm = make("aco_star", **sizes.CONFIG, walker=chosen)
    assert with_room(swarm).config.walker.implementation == "native"
    graph, task = sizes.maze()
    lowered = jax.jit(swarm.step).lower(
        swarm.init(jax.random.key(0), graph, task, swarm.default_params), graph, task,
        swarm.default_params).as_text()
    assert native.WALK_TARGET in lowered
