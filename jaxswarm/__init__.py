"""jaxswarm: swarm path planners (RFD, RFD*, the ant colonies, water drops, bees) as vectorised
JAX, beside exact planners, on maps stored as dense padded adjacency tensors or as planes of
rectangles.

Where things are:

* :mod:`jaxswarm.world.graph` (maps as tensors), :mod:`jaxswarm.world.edits` (shape-preserving map changes),
  :mod:`jaxswarm.world.paths` (padded paths and their lengths);
* :mod:`jaxswarm.maps` (the RFD paper's maps, seeded random maps, Moving AI files, planes of
  rectangles for the bees);
* :mod:`jaxswarm.exact` (Dijkstra, A*, bidirectional A* and the batched distance field);
* :mod:`jaxswarm.swarm` (the swarm protocol, the walker and the algorithms, by name);
* :mod:`jaxswarm.sweep` (parameter studies: specs, the sharded runner, the results store);
* :mod:`jaxswarm.plot.graph`, :mod:`jaxswarm.plot.plane` (figures), :mod:`jaxswarm.runtime.cpu` (XLA:CPU devices and threads, set before
  JAX starts), :mod:`jaxswarm.cli` (the ``jaxswarm`` command).

Importing the package does not start JAX's backend, so :func:`jaxswarm.runtime.cpu.configure` can still
be called after it.
"""
