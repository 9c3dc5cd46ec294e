"""The bees' inverse problem (eq. 11): the objective against hand computations, the scorer
against direct runs, and the two searches and their budgets."""
import jax
import numpy as np
import pytest

from jaxswarm.maps.planes import paper_plane
from jaxswarm.swarm import make, make_task, run
from jaxswarm.swarm.bees.inverse import (Score, es_search, grid_search, make_scorer, objective,
                                         worst_objective)

eq_11 = jax.jit(objective)
""":func:`objective` under test, one program per shape of its runs (applied outside ``jit``, each
of its operations would be a program of its own)."""


def test_eq_11_is_the_mean_length_of_the_arrived_over_one_plus_their_count():
    inf = np.inf
    lengths = np.asarray([[10.0, inf, 20.0], [inf, inf, inf], [108.0, 108.0, 108.0]], np.float32)
    reached = np.isfinite(lengths)
    score = eq_11(lengths, reached, worst=300.0)
    assert score.target.tolist() == [2, 0, 3]
    assert np.allclose(score.avg_length, [15.0, np.nan, 108.0], equal_nan=True)
    assert score.objective.tolist() == pytest.approx([15 / 3, 300.0, 108 / 4])
    # The paper's map #1 answer: target 30 of 30, avgP 108.
    assert float(eq_11(np.full(30, 108.0, np.float32), np.ones(30, bool), 300.0).objective) == (
        pytest.approx(108 / 31))


def test_a_setting_that_never_arrives_scores_worse_than_any_that_does():
    swarm = make("cabc")
    worst = worst_objective(swarm, swarm.default_params)
    assert worst == pytest.approx(201 * 2 / np.sqrt(2))  # 200 moves, and the last one home


@pytest.mark.slow  # compiles the scorer and a run: about 15 s
def test_the_scorer_equals_direct_runs():
    chosen = paper_plane("map1")
    swarm = make("cabc", max_steps=30)
    task = make_task(chosen.plane, chosen.start, chosen.goal)
    params = swarm.default_params._replace(inner_iterations=np.float32(3))
    weights = np.asarray([[1.0, 0.0, 0.0], [0.9, 0.1, 0.05]], np.float32)
    score = make_scorer(swarm, chosen.plane, task, params, [0, 1], iterations=30)(weights)
    for w, target in zip(weights, np.asarray(score.target)):
        chosen_params = params._replace(w1=w[0], w2=w[1], w3=w[2])
        found = [bool(swarm.best(run(swarm, jax.random.key(s), chosen.plane, task,
                                     chosen_params, iterations=30)[0]).found) for s in (0, 1)]
        assert sum(found) == target


def _bowl(weights):
    """A stand-in scorer: the objective is the squared distance to (1, 0.2, 0.05)."""
    distance = np.sum((np.asarray(weights) - np.asarray([1.0, 0.2, 0.05], np.float32)) ** 2,
                      axis=-1)
    return Score(avg_length=distance, target=np.ones(len(weights), np.int32), objective=distance)


def test_es_walks_down_the_objective_and_counts_its_runs():
    search = es_search(jax.random.key(0), _bowl, [0.5, 0.5, 0.5], seeds=30, steps=40, pairs=4,
                       sigma=0.05, learning_rate=0.05)
    assert search.runs == 40 * 8 * 30 and search.weights.shape == (320, 3)
    first, last = search.score.objective[:8].mean(), search.score.objective[-8:].mean()
    assert last < first / 4
    assert (search.weights >= 0).all() and set(np.unique(search.step)) == set(range(1, 41))


def test_grid_search_scores_every_setting_once():
    grid = np.stack(np.meshgrid([0.8, 1.0], [0.0, 0.2], [0.05], indexing="ij"), -1).reshape(-1, 3)
    search = grid_search(_bowl, grid, seeds=30)
    assert search.runs == 4 * 30 and np.allclose(search.best(), [1.0, 0.2, 0.05])
