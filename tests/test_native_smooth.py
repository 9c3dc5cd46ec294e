"""IWD_PG's smooth operator natively (jaxswarm.swarm.iwd.native_smooth, smooth.cc) against the
XLA passes: the same paths bit for bit on random walks (detours to smooth, revisits, padding
rows, rows not selected, repeated rows) on the shared maze, on mosaic50 and on a general graph;
under vmap (one kernel call for the batch) the paths smoothed alone; whole IWD_PG runs, every
leaf of state and trace; the switch and the kernel's checks."""
import functools
import os
import shutil

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import sizes
from graphs import geometric_graph

from jaxswarm.maps.paper import paper_map
from jaxswarm.runtime import native
from jaxswarm.swarm import make, run
from jaxswarm.swarm.iwd.native_smooth import smooth_rows
from jaxswarm.swarm.iwd.smooth import IMPROVEMENT, smooth_paths
from jaxswarm.swarm.testing import differing_leaves
from jaxswarm.swarm.walking import WalkerOptions
from jaxswarm.swarm.walking import native as native_walk

pytestmark = pytest.mark.skipif(
    not os.environ.get("CXX") and not any(shutil.which(c) for c in native.COMPILERS),
    reason="no C++ compiler")

PATHS, LENGTH = 24, 200
"""Paths of a batch and their length (walks of up to 199 moves: both widths of the cut, 128 and
200)."""
BATCHES = 3
"""Path sets per map (calls of one program) and members of the vmapped batch."""


@jax.jit
def both(graph, paths, which):
    """``(XLA's, native)`` :func:`smooth_paths` of one batch, in one program."""
    return (smooth_paths(graph, paths, which, implementation="lanes"),
            smooth_paths(graph, paths, which, implementation="native"))


def random_paths(graph, seed: int):
    """``(paths i32[PATHS, LENGTH], which bool[PATHS])``: random walks on the valid edges from
    random nodes (a wander has detours to smooth, and revisits), two of them padding only, one
    twice (once not selected), a quarter not selected."""
    rng = np.random.default_rng(seed)
    nbr, free, corner = (np.asarray(x) for x in (graph.nbr, graph.free, graph.corner))
    # graph.valid_edges() on the host (a program of its own per map otherwise).
    valid = ((nbr >= 0) & np.asarray(graph.open) & free[:, None] & free[np.maximum(nbr, 0)]
             & np.all((corner < 0) | free[np.maximum(corner, 0)], axis=-1))
    starts = np.flatnonzero(valid.any(axis=1))
    paths = np.full((PATHS, LENGTH), -1, np.int32)
    for row in paths[2:]:
        node = rng.choice(starts)
        for t in range(rng.integers(3, LENGTH)):
            row[t] = node
            node = nbr[node, rng.choice(np.flatnonzero(valid[node]))]
    paths[-1] = paths[-2]
    which = rng.random(PATHS) < 0.75
    which[-2:] = [False, True]
    return paths, which


def same_native(graph) -> np.ndarray:
    """Both implementations on :data:`BATCHES` random path sets of ``graph``; the paths they
    changed, per set."""
    changed = []
    for seed in range(BATCHES):
        paths, which = random_paths(graph, seed)
        lanes, natively = (np.asarray(out) for out in both(graph, paths, which))
        assert lanes.tobytes() == natively.tobytes(), f"seed {seed}"
        changed.append(np.any(lanes != paths, axis=1))
        assert not changed[-1][~which].any()
    return np.array(changed)


@pytest.mark.parametrize("where", ["maze", "mosaic50", "graph"])
def test_native_smoothing_equals_xla(where):
    if where == "maze":
        graph = sizes.maze()[0]
    elif where == "mosaic50":
        graph = paper_map("mosaic50").graph()
    else:
        graph = geometric_graph(np.random.default_rng(3), 60, radius=3.0, density=0.7,
                                stretch=(1.0, 1.5))
    changed = same_native(graph)
    assert changed.sum(axis=1).min() >= PATHS // 2  # most selected walks got shorter


def test_a_vmap_of_path_sets_is_one_call_and_equals_each_set_alone():
    graph = sizes.maze()[0]
    sets = [random_paths(graph, seed) for seed in range(BATCHES)]
    paths, which = (np.stack(column) for column in zip(*sets))
    batched = jax.jit(jax.vmap(functools.partial(smooth_paths, graph, implementation="native")))
    assert batched.lower(paths, which).as_text().count(
        f"custom_call @{native.SMOOTH_TARGET}(") == 2  # one per width of the cut
    together = np.asarray(batched(paths, which))
    for i, (alone_paths, alone_which) in enumerate(sets):
        alone = np.asarray(both(graph, alone_paths, alone_which)[1])
        assert alone.tobytes() == together[i].tobytes(), f"set {i}"


def calls_the_kernel(swarm) -> bool:
    """Whether ``swarm``'s step on the maze, as traced now, calls the native smoothing."""
    graph, task = sizes.maze()
    args = (graph, task, swarm.default_params)
    state = jax.eval_shape(swarm.init, jax.random.key(0), *args)
    return native.SMOOTH_TARGET in str(jax.make_jaxpr(swarm.step)(state, *args))


def test_iwd_pg_runs_the_same_with_either_smoothing():
    """IWD_PG's shared-size run on the maze, keys 0 and 1, walker and smoothing both on the
    lanes or both native (the smoothing follows the swarm's walker options), every leaf of
    state and trace equal."""
    results = {}
    for name in ("lanes", "native"):
        swarm = make("iwd_pg", **sizes.CONFIG, walker=WalkerOptions(implementation=name))
        assert calls_the_kernel(swarm) == (name == "native")
        graph, task = sizes.maze()
        results[name] = [run(swarm, jax.random.key(key), graph, task, swarm.default_params,
                             iterations=sizes.ITERATIONS) for key in (0, 1)]
    for key, (reference, other) in enumerate(zip(results["lanes"], results["native"])):
        assert not differing_leaves(reference, other), f"key {key}"
        assert np.isfinite(np.asarray(reference[0].best_cost))


def test_the_switch_is_the_walkers(monkeypatch):
    """``implementation`` first, then the walker's variable (then the platform: native on
    CPU)."""
    graph = sizes.maze()[0]
    paths, which = jnp.zeros((2, 8), jnp.int32), jnp.ones(2, bool)

    def traced(implementation=None) -> bool:
        program = jax.make_jaxpr(functools.partial(smooth_paths, graph,
                                                   implementation=implementation))
        return native.SMOOTH_TARGET in str(program(paths, which))

    monkeypatch.setenv(native_walk.VARIABLE, "native")
    assert traced() and not traced("lanes")
    monkeypatch.setenv(native_walk.VARIABLE, "lanes")
    assert not traced() and traced("native")
    monkeypatch.delenv(native_walk.VARIABLE)
    assert traced() == (jax.default_backend() == "cpu")


def test_the_kernel_refuses_a_node_outside_the_map():
    graph = sizes.maze()[0]
    paths = np.array([[0, 1, graph.num_nodes]], np.int32)
    with pytest.raises(jax.errors.JaxRuntimeError, match="a path names no node"):
        np.asarray(smooth_rows(graph, paths, np.ones(1, bool), IMPROVEMENT))
