"""Write ``rfd_graded_0.3.0.json``: runs of ``rfd_graded`` that ``tests/test_registry.py``
replays bit for bit, so that a change of any result (a new random stream, another float
order) is seen and made on purpose. Run it from the repository root after such a change::

    python tests/golden/record.py
"""
from __future__ import annotations

import json
from pathlib import Path

import jax
import numpy as np

from jaxswarm.maps.paper import paper_map
from jaxswarm.swarm import make, make_task, run

GOLDEN = Path(__file__).parent / "rfd_graded_0.3.0.json"
CASES = [dict(map="maze20", num_agents=64, iterations=30, patience=10),
         dict(map="alley20", num_agents=32, iterations=25, patience=None),
         dict(map="mosaic50", num_agents=64, iterations=12, patience=None)]
"""Each case is recorded with seeds 0 and 1."""


def record(case: dict, seed: int) -> dict:
    chosen = paper_map(case["map"])
    graph = chosen.graph()
    task = make_task(graph, chosen.start, chosen.goal)
    swarm = make("rfd_graded", num_agents=case["num_agents"])
    state, trace = run(swarm, jax.random.key(seed), graph, task, swarm.default_params,
                       iterations=case["iterations"], patience=case["patience"])
    ran = int(trace.iterations)
    return dict(case, seed=seed, best_cost=float(state.best_cost),
                best_path=np.asarray(state.best_path).tolist(), ran=ran,
                trace_best=np.asarray(trace.best_cost)[:ran].tolist(),
                altitude=np.asarray(state.altitude).tolist())


if __name__ == "__main__":
    GOLDEN.write_text(json.dumps([record(case, seed) for case in CASES for seed in (0, 1)]))
    print(f"wrote {GOLDEN}")
