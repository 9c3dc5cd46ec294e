"""Swarm planners on the graph tensors: the protocol and run loop (``core``), the lockstep walker
(``walk``) and the algorithms, each registered by name (``make(name, **config)``)."""
from jaxswarm.swarm import rfd  # noqa: F401  (registers "rfd" and "rfd_star")
from jaxswarm.swarm.core import Swarm, Task, Trace, make, make_task, registered, run

__all__ = ["Swarm", "Task", "Trace", "make", "make_task", "registered", "run"]
