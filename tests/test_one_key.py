"""One key, one result: every registered swarm's run alone equals the same key in batches of
1, 3 and 64 runs (1,000 in the slow suite), every leaf bit for bit
(:func:`jaxswarm.swarm.testing.check_batch_invariant`). Sweep rows on other thread and device
counts, in processes of their own, are checked in ``test_sweep.py``. A file of its own, so that
its compiles run beside ``test_swarm.py``'s on another worker."""
import pytest
import sizes
from conformance import field, maze, world_of  # noqa: F401 (fixtures)

from jaxswarm import swarm as swarms
from jaxswarm.swarm import make
from jaxswarm.swarm.testing import check_batch_invariant

SMALL = sizes.CONFIG
ITERATIONS = sizes.ITERATIONS
KEYS = 4
"""Keys of the default checks, each alone and in every width (the width 64 batch holds them and
copies of the last): a width's program is compiled once whatever the count, its runs are not."""


@pytest.mark.parametrize("name", swarms.registered())
def test_a_key_gives_one_result_alone_and_in_batches_of_1_3_and_64(name, maze, field):
    world, task, _ = world_of(name, maze, field)
    check_batch_invariant(make(name, **SMALL), world, task, iterations=ITERATIONS, keys=KEYS)


@pytest.mark.slow  # 1,000 runs alone per swarm, of 2 iterations to fit CI: minutes in all
@pytest.mark.parametrize("name", swarms.registered())
def test_a_thousand_keys_alone_equal_them_in_one_batch_of_a_thousand(name, maze, field):
    world, task, _ = world_of(name, maze, field)
    check_batch_invariant(make(name, **SMALL), world, task, iterations=2, widths=(1000,))


def test_a_hooked_walk_gives_one_result_alone_and_in_batches(maze):
    # Drops that change the soil as they walk read each other's writes: in a batch, as alone.
    world, task, _ = maze
    check_batch_invariant(make("iwd", local_updates="while_walking", **SMALL), world, task,
                          iterations=ITERATIONS, keys=KEYS)
