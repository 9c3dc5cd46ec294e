"""The walker against the scalar C loop of ``benchmarks/scalar/walk.c``: one agent at a time,
the same rule and uniforms, written in plain C. Every output of every agent must be the same."""
import shutil
import tempfile

import jax
import numpy as np
import pytest
from repo_scripts import load_script
from sizes import AGENTS, MAP

from jaxswarm.swarm import make
from jaxswarm.swarm.walking import step_budget

walk_bench = load_script("benchmarks/walk.py")
TABLES = {name: jax.jit(rule) for name, (rule, _) in walk_bench.TRANSITION_RULES.items()}
"""Each swarm's transition table of its memory, jitted: one program instead of each of its
operations applied on its own."""


@pytest.fixture(scope="module")
def scalar():
    if shutil.which("cc") is None:
        pytest.skip("no C compiler (cc) to build the reference")
    with tempfile.TemporaryDirectory() as directory:
        yield walk_bench.build_scalar(directory)


@pytest.mark.parametrize("swarm_name", ["rfd_graded", "aco_star"])
def test_walker_writes_what_the_scalar_loop_writes(scalar, swarm_name):
    graph, task = walk_bench.load_problem(MAP)
    seeds = 2
    swarm = make(swarm_name, num_agents=AGENTS)
    _, memory = walk_bench.TRANSITION_RULES[swarm_name]
    state = swarm.init(jax.random.key(0), graph, task, swarm.default_params)
    table = TABLES[swarm_name](graph, task, memory(state), swarm.default_params)
    steps = step_budget(graph, None)
    keys = jax.random.split(jax.random.key(3), seeds)
    ours = jax.device_get(walk_bench.batched_walks(AGENTS, steps)(keys, table, graph, task))
    out = walk_bench.scalar_outputs(graph, seeds, AGENTS, steps)
    moves = walk_bench.scalar_walks(scalar, graph, task, np.asarray(table, np.float32),
                                    walk_bench.seed_words(keys), out, AGENTS, steps)
    # The comparison covers agents that arrived and agents that got stuck.
    assert out["arrived"].any() and out["stuck"].any()
    assert moves == ours.moves.sum()
    assert walk_bench.same_agents(ours, out) == seeds * AGENTS
    # The whole logs, the blocks no agent owns included, are the same arrays.
    np.testing.assert_array_equal(np.asarray(ours.log.nodes), out["nodes"])
    np.testing.assert_array_equal(np.asarray(ours.log.slots), out["slots"])
