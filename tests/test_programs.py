"""Compiled programs let go when a process holds too many memory mappings
(:mod:`jaxswarm.runtime.programs`)."""
import sys

import jax
import pytest
import sizes
from conformance import maze  # noqa: F401 (fixture)

from jaxswarm.runtime import programs
from jaxswarm.swarm import make, run

linux = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux's /proc only")


@linux
def test_a_compiled_program_holds_mappings_that_a_release_gives_back(maze):
    graph, task, _ = maze
    before = programs.mapped_regions()
    # A swarm's run at the shared size: compiled, or loaded from the persistent cache, it is
    # new to this process (the compile ledger forgets programs between test files).
    swarm = make("aco_star", **sizes.CONFIG)
    jax.block_until_ready(run(swarm, jax.random.key(0), graph, task, swarm.default_params,
                              iterations=sizes.ITERATIONS))
    held = programs.mapped_regions()
    added = held - before
    assert added > 200  # hundreds a program (threads and allocators move a few dozen)
    assert not programs.release_if_crowded(share=1.0)  # far from the limit: nothing goes
    assert programs.release_if_crowded(share=0.0)
    assert programs.mapped_regions() < held - added // 2


@linux
def test_the_limit_is_the_systems():
    assert programs.region_limit() == int(open("/proc/sys/vm/max_map_count").read())


def test_without_the_systems_figures_nothing_is_released(monkeypatch, tmp_path):
    monkeypatch.setattr(programs, "MAPS", tmp_path / "missing")
    assert programs.mapped_regions() is None
    assert not programs.release_if_crowded(share=0.0)


@pytest.mark.parametrize("share", [-0.1, 1.5])
def test_a_share_outside_0_1_is_refused(share):
    with pytest.raises(ValueError, match="share"):
        programs.release_if_crowded(share=share)
