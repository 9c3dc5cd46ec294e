"""Running swarms: the one place that compiles and caches run programs per (swarm, world shape,
batch form), sizes the walker's logs and makes a run again with room when a walk overflowed, and
shares runs out over devices.

:func:`run` (one run), :func:`run_batch` (a ``vmap`` of runs), :func:`steps` (a run stepped with
a record of each iteration) and :func:`retried` (a program of one's own that runs a swarm) are in
:mod:`.runs`; :class:`ShardedRuns` (calls of many runs over the devices, what sweeps and tuners
use) in :mod:`.sharded`. Which swarms' batches run one member at a time is
:data:`ONE_AT_A_TIME`.
"""
from jaxswarm.swarm.executor.runs import (ONE_AT_A_TIME, retried, run, run_batch, run_program,
                                          steps, with_room)
from jaxswarm.swarm.executor.sharded import ShardedRuns, group_size

__all__ = ["ONE_AT_A_TIME", "ShardedRuns", "group_size", "retried", "run", "run_batch",
           "run_program", "steps", "with_room"]
