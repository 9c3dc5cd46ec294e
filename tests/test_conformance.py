"""Every registered swarm's promises (:mod:`jaxswarm.swarm.testing`) on its conformance world
(maze20 for the walkers, the 6 x 6 plane for the bees): one key, one result (alone equals the
same key in a batch of 3 runs; in batches of 1 and 64, and of 1,000, in the slow tier),
reproducible per key, valid results never below the optimum, a walker's clean "not found" on a
goal behind a wall (the shared size's run on a map cut out of the maze's shape), a batch over
params compiled once, and its golden records (``tests/golden/swarms.json``) replayed bit for
bit. Sweep rows on other thread and device counts, in processes of their own, are checked in
``test_sweep.py``.

One test class per swarm: under ``--dist loadscope`` (the Makefile's) a class runs on one
worker, which builds the swarm's two programs of the default tier (a run alone and a batch of 3
runs, at the shared size) once for all its checks (the golden records are runs alone at the
shared size), and the swarms spread over the workers, those slowest to compile first. A batch
of 3 runs of 32 agents walks on one lane an agent; the walker's queue, whose lanes take agent
after agent, is checked in the default tier by ``test_walk.py`` (a batch of walks with more
agents than lanes, each as alone) and here in the slow tier (batches of 64 runs)."""
import json

import numpy as np
import pytest
import sizes
from conformance import field, maze, world_of  # noqa: F401 (fixtures)
from golden.swarms import GOLDEN, cases, replay

from jaxswarm import swarm as swarms
from jaxswarm.swarm import make, make_task
from jaxswarm.swarm.testing import (check_batch_invariant, check_compiles_once,
                                     check_reproducible, check_unreachable_goal,
                                     check_valid_results)
from jaxswarm.swarm.walking import WalkerOptions
from jaxswarm.world.graph import Graph

SMALL = sizes.CONFIG
ITERATIONS = sizes.ITERATIONS
KEYS = 4
"""Keys of the one-key checks, each alone and in every width (a batch of 64 holds them and
copies of the last): a width's program is compiled once whatever the count."""
SLOW_WIDTHS = (1, 64)
"""The batch widths of the slow tier's one-key check, beside the default tier's 3."""
FIRST = ("iwd_pg", "cabc")
"""The swarms whose programs take longest to compile, whose classes come first."""
RECORDS = json.loads(GOLDEN.read_text())


class Conformance:
    """The checks of one swarm (``name``), in the order that compiles each program first where
    the later checks reuse it."""

    name: str

    def _world(self, maze, field):
        return world_of(self.name, maze, field)

    def test_a_key_gives_one_result_alone_and_in_a_batch_of_3(self, maze, field):
        world, task, _ = self._world(maze, field)
        check_batch_invariant(make(self.name, **SMALL), world, task, iterations=ITERATIONS,
                              widths=(sizes.RUNS,), keys=KEYS)

    @pytest.mark.slow  # a program for each width (its twin: the batch of 3 above)
    def test_a_key_gives_one_result_alone_and_in_batches_of_1_and_64(self, maze, field):
        world, task, _ = self._world(maze, field)
        check_batch_invariant(make(self.name, **SMALL), world, task, iterations=ITERATIONS,
                              widths=SLOW_WIDTHS, keys=KEYS)

    def test_same_key_is_bit_identical_and_vmap_matches_loop(self, maze, field):
        world, task, _ = self._world(maze, field)
        check_reproducible(make(self.name, **SMALL), world, task, iterations=ITERATIONS,
                           runs=sizes.RUNS)

    def test_results_are_valid_and_never_beat_the_optimum(self, maze, field):
        world, task, optimum = self._world(maze, field)
        check_valid_results(make(self.name, **SMALL), world, task, optimum,
                            iterations=ITERATIONS)

    def test_a_batch_over_params_compiles_once(self, maze, field):
        world, task, _ = self._world(maze, field)
        check_compiles_once(make(self.name, **SMALL), world, task, iterations=ITERATIONS,
                            runs=sizes.RUNS)

    def test_replays_its_golden_records(self):
        assert_replays(self.name)

    @pytest.mark.slow  # 1,000 runs alone, of 2 iterations and 8 agents to fit CI: 20-300 s
    def test_a_thousand_keys_alone_equal_them_in_one_batch_of_a_thousand(self, maze, field):
        world, task, _ = self._world(maze, field)
        check_batch_invariant(make(self.name, num_agents=8), world, task, iterations=2,
                              widths=(1000,))


@pytest.fixture(scope="module")
def walled():
    """``(graph, task)``: a 6 x 6 room of the shared map's shape split by a wall, from the start
    on one side to the goal on the other: the shared size's run program on a goal no walker
    reaches."""
    free = np.ones((6, 6), bool)
    free[:, 3] = False
    graph = sizes.cut_out(free)
    return graph, make_task(graph, (0, 0), (5, 5))


class WalkerConformance(Conformance):
    """The checks of a swarm on a graph: those of every swarm, a goal it cannot reach, and, in
    the slow tier, the golden records and the batch widths on the XLA walker's lanes (the
    reference; the default tier walks natively on CPU, and ``test_native_walk.py`` compares the
    two walk by walk)."""

    def test_an_unreachable_goal_is_a_clean_not_found_result(self, walled):
        graph, task = walled
        check_unreachable_goal(make(self.name, **SMALL), graph, task, iterations=ITERATIONS)

    @pytest.mark.slow  # the lanes' programs, each a few seconds to compile
    def test_on_the_lanes_it_replays_its_golden_records_and_one_key_gives_one_result(self, maze,
                                                                                    field):
        assert_replays(self.name, walker=LANES)
        world, task, _ = self._world(maze, field)
        check_batch_invariant(make(self.name, **SMALL, walker=LANES), world, task,
                              iterations=ITERATIONS, widths=(sizes.RUNS, *SLOW_WIDTHS),
                              keys=KEYS)


LANES = WalkerOptions(implementation="lanes")
"""The walker of the slow tier's reference checks."""


def assert_replays(name: str, **options) -> None:
    """Every golden record of swarm ``name``, run again (its config with ``options``): every
    leaf's digest, the best cost and the iterations it ran, bit for bit."""
    for record in (r for r in RECORDS if r["swarm"] == name):
        again = replay(dict(record, config=dict(record["config"], **options)))
        described = f"{name} on {record['world']}, seed {record['seed']}"
        assert (again["ran"], again["best_cost"]) == (record["ran"], record["best_cost"]), (
            described)
        changed = sorted(leaf for leaf, digest in record["digests"].items()
                         if again["digests"].get(leaf) != digest)
        assert not changed, f"{described}: these leaves changed: {changed}"


for _name in [*FIRST, *(n for n in swarms.registered() if n not in FIRST)]:
    _base = WalkerConformance if make(_name).world is Graph else Conformance
    globals()[f"TestSwarm_{_name}"] = type(f"TestSwarm_{_name}", (_base,), {"name": _name})


def test_every_registered_swarm_has_its_golden_records():
    described = [{k: v for k, v in r.items() if k not in ("digests", "best_cost", "ran")}
                 for r in RECORDS]
    assert described == cases()


def test_every_registered_swarm_has_its_class():
    assert {n for n in globals() if n.startswith("TestSwarm_")} == {
        f"TestSwarm_{n}" for n in swarms.registered()}


@pytest.mark.parametrize("widths", [
    (sizes.RUNS,), pytest.param(SLOW_WIDTHS, marks=pytest.mark.slow)], ids=str)
def test_a_hooked_walk_gives_one_result_alone_and_in_batches(maze, widths):
    # Drops that change the soil as they walk read each other's writes: in a batch, as alone.
    world, task, _ = maze
    check_batch_invariant(make("iwd", local_updates="while_walking", **SMALL), world, task,
                          iterations=ITERATIONS, widths=widths, keys=KEYS)
