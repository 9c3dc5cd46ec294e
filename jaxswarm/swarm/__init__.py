"""Swarm planners on the graph tensors and on planes: the protocol and run loop (``core``), the
walker (``walking``), the algorithms (``rfd``, ``aco``, ``iwd`` on graphs; ``bees`` on planes),
the registry of names (``registry``: ``make(name, **config)``), what runs them (``executor``:
``run``, batches, devices) and the conformance suite every swarm passes (``testing``)."""
from jaxswarm.swarm.core import Swarm, Task, Trace, make_task
from jaxswarm.swarm.executor import run
from jaxswarm.swarm.registry import config_options, definition, make, registered

__all__ = ["Swarm", "Task", "Trace", "config_options", "definition", "make", "make_task",
           "registered", "run"]
