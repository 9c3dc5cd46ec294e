"""Table rows that can be run again alone (:mod:`jaxswarm.sweep.run_record`): the run record
reads back to the same swarm, params, key and map, and a row that cannot be replayed is named."""
import json

import jax
import numpy as np
import pytest

from jaxswarm.maps.named import named_map
from jaxswarm.studies.problems import movingai_folder, named_problem, scenario_problem
from jaxswarm.sweep.run_record import read_run_record, run_record
from jaxswarm.swarm import make
from jaxswarm.maps.entry import check, resolve
from jaxswarm.sweep.replay import replay_row


def test_a_record_reads_back_to_the_same_swarm_params_key_and_stop_rules():
    swarm = make("iwd", num_agents=12, local_updates="while_walking")
    params = swarm.default_params._replace(rho_n=np.float32(0.7))
    key = jax.random.fold_in(jax.random.split(jax.random.key(5), 3)[2], 9)
    text = run_record(swarm, params, "maze20", key, iterations=7, patience=3)
    record = read_run_record(text, source="test")
    assert record.swarm == swarm
    assert record.params == params
    assert np.array_equal(jax.random.key_data(record.key), jax.random.key_data(key))
    assert (record.entry, record.iterations, record.patience) == ("maze20", 7, 3)


def test_a_run_without_a_map_entry_has_no_record_and_says_so():
    swarm = make("aco_star", num_agents=4)
    assert run_record(swarm, swarm.default_params, None, jax.random.key(0), iterations=2,
                      patience=None) == ""
    with pytest.raises(ValueError, match="row 3: no run record"):
        read_run_record("", source="row 3")


@pytest.mark.parametrize("change, message", [
    (lambda r: r.pop("key"), "lacks key"),
    (lambda r: r.update(map="nowhere20"), "unknown map 'nowhere20'"),
    (lambda r: r.update(algorithm="nothing"), "unknown swarm 'nothing'"),
])
def test_a_broken_record_is_named(change, message):
    swarm = make("aco_star", num_agents=4)
    record = json.loads(run_record(swarm, swarm.default_params, "maze20", jax.random.key(0),
                                   iterations=2, patience=None))
    change(record)
    with pytest.raises(ValueError, match=message):
        read_run_record(json.dumps(record), source="runs.csv row 0")
    with pytest.raises(ValueError, match="not JSON"):
        read_run_record("{", source="runs.csv row 0")


def test_a_seeded_path_map_is_a_map_entry_of_its_own():
    problem = named_problem("pathmap12x8", seed=4)
    assert problem.entry == {"pathmap": "12x8", "seed": 4}
    resolved = resolve(problem.entry)
    walls = named_map("pathmap12x8", seed=4).graph
    assert resolved.label == "pathmap12x8-s4"
    assert np.array_equal(np.asarray(resolved.world.open), np.asarray(walls.open))
    assert (resolved.start, resolved.goal) == ((0, 0), (11, 7))
    assert named_problem("maze20").entry == "maze20"
    assert "size must be 'WxH'" in check({"pathmap": "12", "seed": 0})
    assert "non-negative integer seed" in check({"pathmap": "12x8"})
    assert "unknown keys ['walls']" in check({"pathmap": "12x8", "seed": 0,
                                                         "walls": 3})


def test_a_moving_ai_problem_names_the_scenario_row_it_took(movingai_dir):
    problem = scenario_problem(movingai_folder(), "random-32-32-10")
    entry = problem.entry
    assert entry["movingai"] == "mapf/random-32-32-10.map"
    assert entry["scenario_file"] == "random-32-32-10-even-1.scen"
    resolved = resolve(entry)
    assert (resolved.start, resolved.goal) == (problem.start, problem.goal)


def test_a_table_without_run_records_or_a_row_out_of_range_is_named(tmp_path):
    (tmp_path / "runs.csv").write_text("map,cost\nmaze20,1.0\n")
    with pytest.raises(ValueError, match="no run_record, fingerprint column"):
        replay_row(tmp_path, 0)
    (tmp_path / "runs.csv").write_text("map,cost,run_record,fingerprint\nmaze20,1.0,,\n")
    with pytest.raises(ValueError, match="rows 0 to 0, not row 4"):
        replay_row(tmp_path, 4)
    with pytest.raises(ValueError, match="row 0: no run record"):
        replay_row(tmp_path, 0)
    with pytest.raises(ValueError, match="nor a results folder"):
        replay_row(tmp_path / "missing", 0)
