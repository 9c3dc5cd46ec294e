"""Golden records of every registered swarm: small runs replayed bit for bit by
``tests/test_conformance.py``, so that "behaviour unchanged" means the same bits for every swarm.

Each record names its swarm, world, config, iterations, patience and seed, and holds the
SHA-256 of every leaf of what the run returned (state and trace, PRNG keys as their data) but
the trace's ``lane_steps`` (:data:`SCHEDULE`), beside a few readable figures (best cost,
iterations run) that say what changed when a digest does. Write them again only after a change
that is meant to change results (and say why in the CHANGELOG), from ``tests/``::

    python -m golden.swarms

Both write and replay with the instruction set jaxswarm caps XLA at when it is imported
(:mod:`jaxswarm.runtime.arithmetic`), so the records hold on any x86-64 machine.
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path

import jax
import numpy as np

import sizes
from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import make, make_task, registered, run
from jaxswarm.swarm.testing import key_data

GOLDEN = Path(__file__).parent / "swarms.json"
SIZE = dict(config=sizes.CONFIG, iterations=sizes.ITERATIONS, patience=None)
"""The tests' shared size (``tests/sizes.py``): a record replays the program the conformance
checks compile for their single runs."""
GRAPH_CASES = [dict(world=world, **SIZE) for world in (sizes.MAP, "alley20")]
"""Two 20 x 20 maps: one compiled program per swarm."""
PLANE_CASES = [dict(world="plane6", **SIZE)]
SEEDS = (0, 3)
SCHEDULE = "[1].lane_steps"
"""The leaf a record leaves out: the lane-steps the walker's loop ran, which depend on how it
schedules agents over lanes (:mod:`jaxswarm.swarm.walking.loop`), not on what any agent did."""


def world(name: str):
    """``(world, task)`` of a record: a paper map by name, or ``plane6``, the bees' shared
    6 x 6 plane (:func:`sizes.plane`)."""
    if name == "plane6":
        plane, start, goal = sizes.plane()
        return plane, make_task(plane, start, goal)
    chosen = paper_map(name)
    graph = chosen.graph()
    return graph, make_task(graph, chosen.start, chosen.goal)


def replay(record: dict) -> dict:
    """The run a record describes, as the record's ``digests``, ``best_cost`` and ``ran``."""
    graph, task = world(record["world"])
    swarm = make(record["swarm"], **record["config"])
    state, trace = run(swarm, jax.random.key(record["seed"]), graph, task, swarm.default_params,
                       iterations=record["iterations"], patience=record["patience"])
    leaves = jax.tree_util.tree_leaves_with_path(key_data((state, trace)))
    digests = {jax.tree_util.keystr(where): hashlib.sha256(
        np.ascontiguousarray(np.asarray(leaf)).tobytes()).hexdigest()[:16]
        for where, leaf in leaves if jax.tree_util.keystr(where) != SCHEDULE}
    return dict(digests=digests, best_cost=float(swarm.best(state).cost),
                ran=int(trace.iterations))


def cases() -> list[dict]:
    """Every record's description: each registered swarm on its kind of world, two seeds."""
    out = []
    for name in registered():
        on_plane = make(name).world.__name__ == "Plane"
        for case in PLANE_CASES if on_plane else GRAPH_CASES:
            out += [dict(swarm=name, seed=seed, **case) for seed in SEEDS]
    return out


if __name__ == "__main__":
    GOLDEN.write_text(json.dumps([dict(case, **replay(case)) for case in cases()], indent=1) + "\n")
    print(f"wrote {GOLDEN}")
