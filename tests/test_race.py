"""Iterated racing, rule by rule, as irace runs it (jaxswarm.tune.race): the instances each race
takes, elites that keep their results and their protection, the budget spent, the models passed
down an elite's lineage, soft restarts and integers drawn uniformly; on a planted objective, no
swarm run."""
import collections

import numpy as np
import pytest

from jaxswarm.tune import tune_spec_from_dict
from jaxswarm.tune.evaluate import Setting
from jaxswarm.tune.race import (Model, PROBABILITY_CAP, _Race, _restart, _update_models,
                                iterated_race)
from jaxswarm.tune.space import (Choice, Integer, Real, Space, cell_unit, from_cell_unit)


class Planted:
    """Scores ``(x - 1.3)^2`` (``x`` the setting's alpha, plus ``0.05`` where its erosion is not
    2) plus noise keyed by the instance, counting runs and every (setting, instance)
    it ran."""

    def __init__(self, spec):
        self.spec = spec
        self.runs_spent = 0
        self.batches = []
        self.ran = collections.Counter()

    def score(self, settings, instances, *, phase="training", iteration=0):
        self.runs_spent += len(settings) * len(instances)
        self.batches.append(len(settings) * len(instances))
        self.ran.update((s.number, i) for s in settings for i in instances)
        noise = np.array([np.random.default_rng(1000 + 7 * m + s).normal(0, 0.05)
                          for m, s in instances])
        return np.array([[(s.values["alpha"] - 1.3) ** 2 + n
                          + 0.05 * (s.values.get("erosion", 2.0) != 2.0) for n in noise]
                         for s in settings])


def planted_race(budget=600, seeds=40, race=None, params=None, seed=0):
    spec = tune_spec_from_dict({
        "tune": {"name": "planted", "algorithm": "rfd_star", "method": "race", "budget": budget,
                 "objective": "gap", "training": {"maps": ["maze20"], "seeds": seeds},
                 "held_out": {"maps": ["alley20"], "seeds": [100]}, "race": race or {}},
        "params": params or {"alpha": {"low": 0.5, "high": 4.0}, "erosion": 1.0,
                             "p_base": 50.0}})
    evaluator = Planted(spec)
    baseline = {"alpha": 1} | ({"erosion": 1.0} if "erosion" in spec.space.free else {})
    return spec, evaluator, iterated_race(evaluator, spec.space, baseline,
                                          np.random.default_rng(seed))


def test_each_race_after_the_first_starts_with_an_instance_no_earlier_race_saw():
    _, _, result = planted_race(seeds=200)
    log = result.log
    assert log["iteration"].max() >= 4
    gave_up = False
    for j in range(2, log["iteration"].max() + 1):
        earlier = set(log.loc[log["iteration"] < j, "instance"])
        order = log[log["iteration"] == j].drop_duplicates("step")["instance"].tolist()
        if order[0] in earlier:
            # irace gives its new instances up, for good, once the budget cannot pay for them
            gave_up = True
        assert (order[0] in earlier) == gave_up
        if not gave_up:  # a new instance, then every instance seen before, then new ones
            assert set(order[1:1 + len(earlier)]) == earlier
        else:
            assert set(order) <= earlier


def test_the_budget_is_spent_to_within_one_batch_and_no_known_run_is_made_again():
    spec, evaluator, result = planted_race(budget=600)
    assert spec.budget - max(evaluator.batches) < evaluator.runs_spent <= spec.budget
    assert max(evaluator.ran.values()) == 1
    # Without the extra iterations irace makes, the last third of the budget would be left.
    spec, lean, _ = planted_race(budget=600, race={"spend_remaining": False})
    assert lean.runs_spent <= evaluator.runs_spent


def test_an_elite_is_not_dropped_before_the_race_passed_the_instances_it_knows():
    _, _, result = planted_race(budget=900, seeds=60)
    log = result.log
    for _, rows in log.groupby(["iteration", "setting"]):
        known, dropped = rows[~rows["ran"]], rows[rows["dropped"] != ""]
        if len(known) and len(dropped):
            assert dropped["step"].iloc[0] >= known["step"].max()
    assert (~log["ran"]).any()  # elites came with results
    assert result.elites[0].values["alpha"] == pytest.approx(1.3, abs=0.15)


def test_an_elites_model_follows_its_lineage_with_the_cap():
    space = Space({"alpha": Real(0.5, 4.0), "c": Choice(("a", "b", "c"))})
    state = _Race(order=[])
    state.models = {0: Model({"alpha": 0.5}, {"c": np.full(3, 1 / 3)})}
    state.parents = {0: None, 5: 0}
    elites = [Setting(0, {"alpha": 1.0, "c": "b"}), Setting(5, {"alpha": 1.2, "c": "c"})]
    probabilities = {0: np.full(3, 1 / 3), 5: np.full(3, 1 / 3)}
    deviation = {0: 0.5, 5: 0.5}
    iterations, fresh, d = 4, 4, 2
    for j in (2, 3, 4):
        _update_models(space, state, elites, j, iterations, fresh, d)
        for elite in elites:
            shift = (j - 1) / iterations
            p = probabilities[elite.number] * (1 - shift) + shift * np.array(
                [v == elite.values["c"] for v in ("a", "b", "c")])
            p = np.minimum(p / p.sum(), PROBABILITY_CAP ** (1 / d))
            probabilities[elite.number] = p / p.sum()
            deviation[elite.number] *= (1 / fresh) ** (1 / d)
            model = state.models[elite.number]
            np.testing.assert_allclose(model.probabilities["c"], probabilities[elite.number])
            assert model.deviation["alpha"] == pytest.approx(deviation[elite.number])
    # Without the cap the favoured value would have gone further.
    uncapped = np.full(3, 1 / 3)
    for j in (2, 3, 4):
        uncapped = uncapped * (1 - (j - 1) / iterations) + (j - 1) / iterations * np.array(
            [0.0, 1.0, 0.0])
    assert state.models[0].probabilities["c"][1] < uncapped[1] / uncapped.sum() - 0.05


def test_a_soft_restart_widens_the_model_and_fires_when_settings_collapse():
    space = Space({"alpha": Integer(1, 3), "c": Choice(("a", "b"))})
    model = Model({"alpha": 0.01}, {"c": np.array([0.9, 0.1])})
    restarted = _restart(space, model, fresh=4, dimension=2)
    np.testing.assert_allclose(restarted.probabilities["c"],
                               np.array([0.9, 0.18]) / 1.08)
    first = 0.5 * 2 / 3  # half the range of the cells [1, 4)
    assert restarted.deviation["alpha"] == pytest.approx(min(0.01 * 4, first * 0.5))
    # Three integer values and two choices: new settings soon repeat an elite.
    _, _, result = planted_race(budget=900, params={
        "alpha": {"low": 1, "high": 3, "integer": True}, "erosion": {"choices": [1.0, 2.0]},
        "p_base": 50.0})
    assert result.restarts


def test_integers_are_drawn_uniformly_over_their_range():
    for domain in (Integer(1, 4), Integer(1, 16, log=True)):
        space = Space({"n": domain})
        counts = collections.Counter(s["n"] for s in space.uniform(np.random.default_rng(0),
                                                                   40_000))
        assert set(counts) == set(range(domain.low, domain.high + 1))
        if not domain.log:
            shares = np.array([counts[v] for v in range(1, 5)]) / 40_000
            np.testing.assert_allclose(shares, 0.25, atol=0.01)  # the ends as often as the rest
        assert from_cell_unit(domain, 1.0) == domain.high
        assert from_cell_unit(domain, cell_unit(domain, 3)) == 3


def test_the_switches_are_checked_in_the_spec():
    with pytest.raises(ValueError, match="tune.race.elitist: must be true or false"):
        planted_race(race={"elitist": "yes"})
    with pytest.raises(ValueError, match="tune.race.new_instances"):
        planted_race(race={"new_instances": -1})
    # Without elitism every race runs its settings on instances no race saw: nothing is known.
    _, evaluator, result = planted_race(race={"elitist": False, "soft_restart": False})
    assert result.log["ran"].all() and result.log["iteration"].max() >= 2
    assert evaluator.runs_spent <= 600 and not result.restarts
