"""Every registered swarm replays its golden records (``tests/golden/swarms.json``) bit for bit:
the digest of every leaf of its state and trace, its best cost and the iterations it ran."""
import json

import pytest
from golden.swarms import GOLDEN, cases, replay

RECORDS = json.loads(GOLDEN.read_text())


def test_every_registered_swarm_has_its_records():
    described = [{k: v for k, v in r.items() if k not in ("digests", "best_cost", "ran")}
                 for r in RECORDS]
    assert described == cases()


@pytest.mark.parametrize("record", RECORDS,
                         ids=lambda r: f"{r['swarm']}-{r['world']}-seed{r['seed']}")
def test_a_swarm_replays_its_golden_record(record):
    again = replay(record)
    assert again["ran"] == record["ran"]
    assert again["best_cost"] == record["best_cost"]
    changed = sorted(leaf for leaf, digest in record["digests"].items()
                     if again["digests"].get(leaf) != digest)
    assert not changed, f"{record['swarm']}: these leaves changed: {changed}"
