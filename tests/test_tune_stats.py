"""The racing statistics (jaxswarm.tune.stats) against scipy and against Conover's book."""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import stats as scipy_stats

from jaxswarm.tune.stats import conover_against_best, friedman, race_step, ranks

# A hand-ranked table: 4 instances (rows), 3 settings (columns), no ties.
HAND = np.array([[1.0, 2.0, 3.0],
                 [1.0, 3.0, 2.0],
                 [1.0, 2.0, 3.0],
                 [2.0, 1.0, 3.0]])


def _random_tables():
    """Result tables of 3..8 settings on 5..30 instances: continuous, integer (many ties), and
    continuous with some instances tying all settings."""
    rng = np.random.default_rng(20160101)
    tables = []
    for _ in range(6):
        instances, settings = int(rng.integers(5, 31)), int(rng.integers(3, 9))
        tables.append(rng.normal(size=(instances, settings)) + rng.normal(size=settings))
        tables.append(rng.integers(0, 3, size=(instances, settings)).astype(float))
        partly_tied = rng.normal(size=(instances, settings))
        partly_tied[::3] = 7.0
        tables.append(partly_tied)
    return tables


def _book_conover_p_values(rank_table, best):
    """Conover's pairwise test (Practical Nonparametric Statistics, 1999, pp. 369-371) written
    with loops and the book's T1 form of the variance: settings i and j differ when
    |R_j - R_i| / sqrt(2 b (A1 - C1) (1 - T1 / (b (k - 1))) / ((b - 1)(k - 1))) exceeds a quantile
    of Student's t with (b - 1)(k - 1) degrees of freedom (b blocks, k treatments)."""
    b, k = rank_table.shape
    column_sums = [sum(rank_table[i][j] for i in range(b)) for j in range(k)]
    a1 = sum(rank_table[i][j] ** 2 for i in range(b) for j in range(k))
    c1 = b * k * (k + 1) ** 2 / 4
    t1 = (k - 1) * sum((column_sums[j] - b * (k + 1) / 2) ** 2 for j in range(k)) / (a1 - c1)
    degrees = (b - 1) * (k - 1)
    variance = 2 * b * (a1 - c1) * (1 - t1 / (b * (k - 1))) / degrees
    p_values = []
    for j in range(k):
        t_value = abs(column_sums[j] - column_sums[best]) / math.sqrt(variance)
        p_values.append(2 * (1 - scipy_stats.t.cdf(t_value, degrees)))
    return np.array(p_values)


def test_ranks_equal_scipy_rankdata_row_by_row():
    for table in _random_tables():
        expected = np.array([scipy_stats.rankdata(row) for row in table])
        np.testing.assert_array_equal(ranks(table), expected)


def test_ranks_average_ties_and_put_the_lowest_result_first():
    np.testing.assert_array_equal(ranks([[3.0, 1.0, 3.0, 2.0], [5.0, 5.0, 5.0, 5.0]]),
                                  [[3.5, 1.0, 3.5, 2.0], [2.5, 2.5, 2.5, 2.5]])


def test_friedman_equals_scipy_friedmanchisquare():
    for table in _random_tables():
        expected = scipy_stats.friedmanchisquare(*table.T)
        result = friedman(table)
        np.testing.assert_allclose(result.statistic, expected.statistic, rtol=1e-12)
        np.testing.assert_allclose(result.p_value, expected.pvalue, rtol=1e-12)
        np.testing.assert_array_equal(result.rank_sums, ranks(table).sum(axis=0))


def test_friedman_of_two_settings_is_the_sign_test_chi_square():
    rng = np.random.default_rng(7)
    table = rng.integers(0, 4, size=(25, 2)).astype(float)
    wins = int(np.sum(table[:, 0] < table[:, 1]))
    losses = int(np.sum(table[:, 0] > table[:, 1]))
    result = friedman(table)
    np.testing.assert_allclose(result.statistic, (wins - losses) ** 2 / (wins + losses),
                               rtol=1e-12)
    np.testing.assert_allclose(result.p_value, scipy_stats.chi2.sf(result.statistic, 1),
                               rtol=1e-12)


def test_conover_p_values_equal_the_book_formula():
    for table in _random_tables():
        rank_table = scipy_stats.rankdata(table, axis=1)
        result = conover_against_best(table, 0.05)
        rank_sums = rank_table.sum(axis=0)
        expected_best = next(j for j, total in enumerate(rank_sums) if total == rank_sums.min())
        assert result.best == expected_best
        np.testing.assert_allclose(result.p_values, _book_conover_p_values(rank_table, result.best),
                                   rtol=1e-9, atol=1e-14)
        np.testing.assert_array_equal(result.keep, result.p_values >= 0.05)
        assert result.test == "conover"


def test_hand_computed_example():
    # Rank sums R = (5, 8, 11); A = 4 * (1 + 4 + 9) = 56; C = 4 * 3 * 16 / 4 = 48.
    # Friedman: T1 = 2 * ((5-8)^2 + 0 + (11-8)^2) / (56 - 48) = 4.5; chi-square with 2 df:
    # p = exp(-4.5 / 2) = 0.105399.
    # Conover: df = 3 * 2 = 6; I A - sum R^2 = 224 - 210 = 14; scale = sqrt(2 * 14 / 6) = 2.160247.
    # Setting 1: t = 3 / 2.160247 = 1.388730, two-sided p = 0.214271.
    # Setting 2: t = 6 / 2.160247 = 2.777460; t^2 = 54 / 7, and for 6 df the two-sided tail is
    # 1 - s (1 + c/2 + 3 c^2 / 8) with c = 6 / (6 + t^2) = 7/16, s = sqrt(1 - c) = 3/4:
    # p = 263 / 8192 = 0.0321045.
    # Critical differences: t_{0.975, 6} * scale = 2.446912 * 2.160247 = 5.285934 (alpha 0.05),
    # t_{0.9, 6} * scale = 1.439756 * 2.160247 = 3.110228 (alpha 0.2).
    omnibus = friedman(HAND)
    assert omnibus.statistic == pytest.approx(4.5, rel=1e-12)
    assert omnibus.p_value == pytest.approx(math.exp(-2.25), rel=1e-12)
    post_hoc = conover_against_best(HAND, 0.05)
    assert post_hoc.best == 0
    np.testing.assert_allclose(post_hoc.p_values, [1.0, 0.214271, 263 / 8192], rtol=1e-5)
    np.testing.assert_array_equal(post_hoc.keep, [True, True, False])
    # At alpha 0.05 the Friedman test does not reject (0.105 >= 0.05): everyone stays.
    at_5 = race_step(HAND, 0.05, first_test=4)
    assert at_5.test == "friedman" and at_5.best == 0 and at_5.keep.all()
    np.testing.assert_allclose(at_5.p_values, [1.0, math.exp(-2.25), math.exp(-2.25)])
    # At alpha 0.2 it rejects; 3 <= 3.110 keeps setting 1, 6 > 3.110 drops setting 2.
    at_20 = race_step(HAND, 0.2, first_test=4)
    assert at_20.test == "conover" and at_20.best == 0
    np.testing.assert_array_equal(at_20.keep, [True, True, False])


def test_best_of_equal_rank_sums_is_the_lowest_index():
    table = np.array([[2.0, 1.0, 3.0], [1.0, 2.0, 3.0]] * 3)
    assert conover_against_best(table, 0.05).best == 0


def test_race_drops_a_planted_worse_setting_and_keeps_equal_ones():
    # Four equal settings take the places 0..3 in turn (a rotation), so their rank sums stay
    # within 3 of each other; a fifth is setting 0 plus a margin of 1.5 on every instance. The
    # instances' difficulties dwarf both, as in a real race: only the ranks within an instance
    # count.
    instances, first_test = 30, 5
    difficulty = np.random.default_rng(5).normal(scale=10.0, size=(instances, 1))
    equal = difficulty + (np.arange(instances)[:, None] + np.arange(4)) % 4
    worse = equal[:, :1] + 1.5
    table = np.concatenate([equal[:, :2], worse, equal[:, 2:]], axis=1)
    verdicts = [race_step(table[:seen], 0.05, first_test) for seen in range(1, instances + 1)]
    assert all(verdict is None for verdict in verdicts[:first_test - 1])
    tested = verdicts[first_test - 1:]
    assert all(verdict.keep[[0, 1, 3, 4]].all() for verdict in tested)
    dropped = [not verdict.keep[2] for verdict in tested]
    first_drop = dropped.index(True)
    assert first_drop > 0 and all(dropped[first_drop:])  # not at the first test, then for good
    assert [verdict.test for verdict in tested] == (
        ["friedman"] * first_drop + ["conover"] * (len(tested) - first_drop))


def test_no_test_with_one_setting():
    assert race_step(np.ones((10, 1)), 0.05, first_test=5) is None


def test_all_tied_tables_keep_everything_without_warnings():
    for table in (np.full((10, 4), 3.0), np.full((6, 2), -1.0)):
        with warnings.catch_warnings(), np.errstate(all="raise"):
            warnings.simplefilter("error")
            omnibus = friedman(table)
            post_hoc = conover_against_best(table, 0.05)
            verdict = race_step(table, 0.05, first_test=5)
        assert (omnibus.statistic, omnibus.p_value) == (0.0, 1.0)
        assert post_hoc.keep.all() and (post_hoc.p_values == 1.0).all()
        assert verdict.test == "friedman" and verdict.keep.all() and verdict.best == 0


def test_identical_rankings_on_every_instance_drop_all_but_the_best():
    # Every instance ranks the settings 1, 2, 3: the post-hoc variance is 0 and irace's critical
    # difference is 0, so any setting whose rank sum differs from the best's goes.
    table = np.tile([1.0, 2.0, 3.0], (6, 1))
    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        verdict = race_step(table, 0.05, first_test=5)
    assert friedman(table).statistic == pytest.approx(12.0)  # I (S - 1), its largest value
    assert verdict.test == "conover"
    np.testing.assert_array_equal(verdict.keep, [True, False, False])
    np.testing.assert_array_equal(verdict.p_values, [1.0, 0.0, 0.0])


@pytest.mark.parametrize("call, message", [
    (lambda: ranks(np.ones(4)), "table"),
    (lambda: friedman([[1.0, np.nan], [2.0, 1.0]]), "NaN"),
    (lambda: friedman(np.ones((3, 1))), "2 settings"),
    (lambda: conover_against_best(np.ones((1, 3)), 0.05), "2 instance"),
    (lambda: conover_against_best(HAND, 1.0), "alpha"),
    (lambda: race_step(HAND, 0.05, first_test=1), "first_test"),
])
def test_bad_input_is_named(call, message):
    with pytest.raises(ValueError, match=message):
        call()
