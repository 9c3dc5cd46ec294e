"""Swarm planners on the graph tensors: the protocol and run loop (``core``), the lockstep walker
(``walk``), the algorithms (``rfd``, ``aco``) and the registry of names (``registry``:
``make(name, **config)``)."""
from jaxswarm.swarm.core import Swarm, Task, Trace, make_task, run
from jaxswarm.swarm.registry import config_options, definition, make, registered

__all__ = ["Swarm", "Task", "Trace", "config_options", "definition", "make", "make_task",
           "registered", "run"]
