"""What a swarm plans in: a graph (:mod:`~jaxswarm.world.graph`, dense padded adjacency
tensors; :mod:`~jaxswarm.world.lattice`, the grid's directions, slots and move lengths) and
what is done with it (:mod:`~jaxswarm.world.edits`, shape-preserving edits;
:mod:`~jaxswarm.world.paths`, padded paths and their lengths; :mod:`~jaxswarm.world.relax`,
the min-plus fixpoint behind distance fields; :mod:`~jaxswarm.world.edges`, its edges as CSR
arrays for the planners that run on the host), or a plane of rectangles
(:mod:`~jaxswarm.world.plane`, with its geometry)."""
