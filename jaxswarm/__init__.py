"""jaxswarm: swarm path planners (RFD, RFD*, the ant colonies, water drops, bees) as vectorised
JAX, beside exact planners, on maps stored as dense padded adjacency tensors or as planes of
rectangles.

The names a first plan needs are here::

    import jax
    import jaxswarm

    maze = jaxswarm.paper_map("maze20")
    graph = maze.graph()
    task = jaxswarm.make_task(graph, maze.start, maze.goal)
    swarm = jaxswarm.make("rfd", num_agents=64)
    state, trace = jaxswarm.run(swarm, jax.random.key(0), graph, task, swarm.default_params,
                                iterations=20)
    print(swarm.best(state).cost, jaxswarm.optimal_length(graph, maze.start, maze.goal))

Everything else lives in one room per concern; imports only go down this list (the import
contract in ``pyproject.toml``, checked by the tests):

* :mod:`jaxswarm.runtime`: how jaxswarm runs: arithmetic that does not depend on the batch,
  XLA:CPU devices and threads (:func:`jaxswarm.runtime.cpu.configure`, called before JAX
  starts), compiled programs kept on disk and let go, files written whole or not at all, one
  writer per folder, a vmap rule for loops of differing trip counts, the evolution strategies'
  gradient estimate.
* :mod:`jaxswarm.world`: what a swarm plans in: the :class:`Graph` (dense padded adjacency
  tensors) with its lattice, shape-preserving edits, padded paths, the min-plus relaxation and
  its edges as CSR arrays for the host's planners; the :class:`Plane` of rectangles and its
  geometry.
* :mod:`jaxswarm.maps`: where worlds come from: the RFD paper's maps (:func:`paper_map`), seeded
  random grids and path maps (:func:`random_grid`), Moving AI ``.map``/``.scen`` files
  (:func:`load_map`), the IWD_PG experiments' maps and the bees' planes (:func:`paper_plane`).
* :mod:`jaxswarm.exact`: exact planners: :func:`dijkstra`, :func:`astar`,
  :func:`bidirectional_astar`, D* Lite (:func:`replanner`), batched queries, the optimum as the
  swarms measure it (:func:`optimal_length`), the JAX distance field, the plane's visibility graph.
* :mod:`jaxswarm.swarm`: the swarm protocol and run loop (:func:`make_task`), the shared
  walker, the algorithms (RFD, ACO, IWD on graphs; the bees on planes), the registry of names
  (:func:`make`, :func:`registered`), the executor that runs them (:func:`run`, batches,
  devices) and the conformance suite every swarm passes.
* :mod:`jaxswarm.dynamic`: worlds that change during a run: events and each swarm's change rule
  (what its memory does on them), a robot that re-plans.
* :mod:`jaxswarm.multiagent`: many agents on one map: the A* report's two-robot scheme,
  prioritised space-time A*, Conflict-Based Search and its improvements, ECBS and EECBS, PIBT and
  LaCAM, one plan format and one validator.
* :mod:`jaxswarm.sweep`: parameter sweeps: specs as TOML data, a swarm's runs as compiled
  batches over the devices, the resumable runner, the Parquet results store, replaying a row.
* :mod:`jaxswarm.plot`: figures and animations, one module per world or subject, and how each
  swarm's memory is drawn.
* :mod:`jaxswarm.tune`: tuning a swarm's open constants: search spaces, iterated racing, random
  search, the grid and evolution strategies, rescoring on held-out instances.
* :mod:`jaxswarm.studies`: what the table scripts of ``sweeps/`` share (provenance, timed runs,
  success, arguments, figures) and the RFD paper's tables they reproduce (Table 1's rows, the
  dynamic scenarios of Tables 2-5).
* :mod:`jaxswarm.cli`: the ``jaxswarm`` command.

Importing the package does not start JAX's backend, so :func:`jaxswarm.runtime.cpu.configure` can
still be called after it. On x86-64 it caps XLA:CPU's instruction set at AVX, so that one key
gives one result in any batch (:mod:`jaxswarm.runtime.arithmetic`); import it before JAX's first
computation. When ``JAXSWARM_CACHE`` names a folder, importing it keeps compiled programs there
(:mod:`jaxswarm.runtime.cache`).
"""
import importlib.metadata

from jaxswarm.runtime import arithmetic, cache

arithmetic.require_fixed_arithmetic()  # before JAX starts: XLA reads its flags then
cache.from_environment()  # before jaxswarm.exact imports numba, which reads its cache folder then

from jaxswarm.exact import astar, bidirectional_astar, dijkstra, optimal_length, replanner
from jaxswarm.maps.movingai import load_map
from jaxswarm.maps.paper import paper_map
from jaxswarm.maps.planes import paper_plane
from jaxswarm.maps.random import random_grid
from jaxswarm.swarm import Task, make, make_task, registered, run
from jaxswarm.world.graph import Graph
from jaxswarm.world.plane import Plane

try:
    __version__ = importlib.metadata.version("jaxswarm")
    """The installed distribution's version (``0+unknown`` when run from an uninstalled tree)."""
except importlib.metadata.PackageNotFoundError:  # pragma: no cover - a source tree on sys.path
    __version__ = "0+unknown"

__all__ = ["Graph", "Plane", "Task", "__version__", "astar", "bidirectional_astar", "dijkstra",
           "load_map", "make", "make_task", "optimal_length", "paper_map", "paper_plane",
           "random_grid", "registered", "replanner", "run"]
