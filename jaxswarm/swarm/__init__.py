"""Swarm planners on the graph tensors: the protocol and run loop (``core``), the lockstep walker
(``walk``) and the algorithms, each registered by name (``make(name, **config)``)."""
from jaxswarm.swarm import aco, rfd  # noqa: F401  (register the algorithms)
from jaxswarm.swarm.core import Swarm, Task, Trace, make, make_task, registered, run

__all__ = ["Swarm", "Task", "Trace", "make", "make_task", "registered", "run"]
