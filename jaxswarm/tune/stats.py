"""The statistics of iterated racing: which settings survive the instances seen so far.

A race evaluates S candidate settings on the same instances, one instance (a block) after the
other, and drops the settings that are significantly worse than the best. This module is the test
irace applies after each instance (López-Ibáñez et al., "The irace package: Iterated racing for
automatic algorithm configuration", Operations Research Perspectives 3, 2016): rank the settings
within each instance, run the Friedman test on the ranks and, only when it rejects "all settings
are equal", Conover's post-hoc test of every setting against the best.

It follows irace's ``aux2_friedman`` (``R/race.R``, lines 140-179 of irace at commit 3f2fd71e;
the same formulas as ``aux2.friedman`` of earlier versions) with three deliberate differences:

* irace switches to a paired Wilcoxon signed-rank test when only two settings are alive; here two
  settings get the same Friedman test (for S = 2 it is the sign test's chi-square,
  ``(wins - losses)^2 / (wins + losses)``) and the same post-hoc.
* When every instance ties all settings, irace's statistic is 0 / 0 (NaN) and nothing is dropped;
  here the statistic is 0 and the p-value 1, with the same outcome.
* irace only says which settings survive; here every setting also gets the p-value of its
  comparison with the best.

Results are numbers to minimise (a cost, a gap to the optimum), one row per instance and one
column per setting; a race that maximises passes the negated results.
"""
from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
from scipy import stats

DecidingTest = Literal["friedman", "conover"]
"""Which test decided a :class:`PostHoc`: the omnibus Friedman test or Conover's post-hoc."""


class FriedmanResult(NamedTuple):
    """The Friedman test of S settings on I instances (blocks)."""

    statistic: float  # chi-square with S - 1 degrees of freedom, corrected for ties
    p_value: float  # upper tail of that chi-square at the statistic
    rank_sums: np.ndarray  # f64[S]: each setting's ranks summed over the instances


class PostHoc(NamedTuple):
    """Which settings survive a test against the best setting."""

    best: int  # the setting with the lowest rank sum (of equal sums, the lowest index)
    p_values: np.ndarray  # f64[S]: the deciding test's p-value per setting (see race_step); best 1
    keep: np.ndarray  # bool[S]: not significantly worse than the best
    test: DecidingTest  # which test decided keep


def ranks(results: np.ndarray) -> np.ndarray:
    """Rank the settings within each instance, 1 for the lowest result.

    Args:
      results: f64[I, S] (any real dtype), the result of setting s on instance i; lower is
        better. +inf ranks last and -inf first; NaN is refused.

    Returns:
      f64[I, S], each row ranked 1..S; tied results share the average of their ranks, as
      ``scipy.stats.rankdata(row, method="average")`` and R's ``rank`` give them.

    Raises:
      ValueError: ``results`` is not 2-D or holds NaN.
    """
    return stats.rankdata(_as_table(results), method="average", axis=1)


def friedman(results: np.ndarray) -> FriedmanResult:
    """The Friedman test that all settings perform alike, with the correction for ties.

    The statistic is Conover's T1 (Practical Nonparametric Statistics, 3rd ed., 1999): with r
    the ranks of :func:`ranks`, R_j = sum_i r_ij, A = sum_ij r_ij^2 and C = I S (S + 1)^2 / 4,
    ``T1 = (S - 1) sum_j (R_j - I (S + 1) / 2)^2 / (A - C)``, the same number as irace's formula
    and ``scipy.stats.friedmanchisquare`` (which needs S >= 3; this works for S >= 2). Its
    p-value is the upper tail of chi-square with S - 1 degrees of freedom. When every instance
    ties all settings (A = C), the statistic is 0 and the p-value 1.

    Args:
      results: f64[I, S] (any real dtype), lower is better; I >= 1 instances, S >= 2 settings.

    Returns:
      :class:`FriedmanResult` with ``statistic`` and ``p_value`` (Python floats) and
      ``rank_sums`` f64[S].

    Raises:
      ValueError: ``results`` is not 2-D, holds NaN, has no instance or fewer than 2 settings.
    """
    rank_table = ranks(results)
    instances, settings = _require_size(rank_table, min_instances=1)
    rank_sums = rank_table.sum(axis=0)
    # A - C: the ranks' squared deviations from their row mean (S + 1) / 2 (exact: the ranks are
    # multiples of 1/2); 0 only when every instance ties all settings.
    rank_spread = np.sum(rank_table**2) - instances * settings * (settings + 1) ** 2 / 4
    if rank_spread == 0:
        return FriedmanResult(0.0, 1.0, rank_sums)
    deviation = np.sum((rank_sums - instances * (settings + 1) / 2) ** 2)
    statistic = float((settings - 1) * deviation / rank_spread)
    return FriedmanResult(statistic, float(stats.chi2.sf(statistic, settings - 1)), rank_sums)


def conover_against_best(results: np.ndarray, alpha: float) -> PostHoc:
    """Conover's post-hoc test of each setting against the best, as irace runs it.

    With the notation of :func:`friedman` and ``df = (I - 1)(S - 1)``, two settings differ at
    level alpha when ``|R_j - R_best| > t_{1 - alpha/2, df} * scale`` with
    ``scale = sqrt(2 (I A - sum_j R_j^2) / df)`` (Conover 1999, pp. 369-371; irace's
    ``aux2_friedman``, which drops every setting whose difference exceeds that critical value).
    ``I A - sum_j R_j^2`` equals the book's ``I (A - C)(1 - T1 / (I (S - 1)))``. The p-value of
    setting j is the two-sided tail of Student's t with df degrees of freedom at
    ``|R_j - R_best| / scale``, so it is below alpha when j is dropped (but for rounding at the
    boundary, where ``keep`` follows irace's comparison).

    ``scale`` is 0 when every setting has the same rank on every instance (every instance all
    tied, or every instance ranking the settings the same way); then a setting is kept (p = 1)
    when its rank sum equals the best's and dropped (p = 0) otherwise, as irace's critical
    value 0 does.

    Args:
      results: f64[I, S] (any real dtype), lower is better; I >= 2 instances, S >= 2 settings.
      alpha: the significance level, in (0, 1).

    Returns:
      :class:`PostHoc` with ``test == "conover"``.

    Raises:
      ValueError: ``results`` is not 2-D, holds NaN, has fewer than 2 instances or settings, or
        ``alpha`` is outside (0, 1).
    """
    _require_level(alpha)
    rank_table = ranks(results)
    instances, settings = _require_size(rank_table, min_instances=2)
    rank_sums = rank_table.sum(axis=0)
    best = _best(rank_sums)
    df = (instances - 1) * (settings - 1)
    scale = np.sqrt(2 * (instances * np.sum(rank_table**2) - np.sum(rank_sums**2)) / df)
    difference = np.abs(rank_sums - rank_sums[best])
    keep = difference <= stats.t.ppf(1 - alpha / 2, df) * scale
    if scale == 0:
        p_values = np.where(difference == 0, 1.0, 0.0)
    else:
        p_values = 2 * stats.t.sf(difference / scale, df)
    return PostHoc(best, p_values, keep, "conover")


def race_step(results: np.ndarray, alpha: float, first_test: int) -> PostHoc | None:
    """The test irace runs after an instance: which settings stay in the race.

    No test before ``first_test`` instances or with fewer than 2 settings (``None``). Otherwise
    the Friedman test; when its p-value is at least alpha every setting stays (``test ==
    "friedman"``, and each setting's p-value is the Friedman p-value), else
    :func:`conover_against_best` decides (``test == "conover"``; it may still keep everyone).
    irace tests only every ``eachTest`` instances from ``firstTest`` on (``R/race.R``, line 1113
    at commit 3f2fd71e); the caller decides when to call.

    Args:
      results: f64[I, S] (any real dtype), the alive settings' results on the instances seen so
        far, lower is better.
      alpha: the significance level, in (0, 1) (irace's ``1 - confidence``, 0.05 by default).
      first_test: the number of instances of the first test, at least 2 (irace's ``firstTest``,
        5 by default).

    Returns:
      :class:`PostHoc`, or ``None`` when no test is due.

    Raises:
      ValueError: ``results`` is not 2-D or holds NaN, ``alpha`` is outside (0, 1), or
        ``first_test`` is below 2 (the post-hoc test needs 2 instances).
    """
    _require_level(alpha)
    if first_test < 2:
        raise ValueError(f"first_test must be at least 2 instances, got {first_test}")
    instances, settings = _as_table(results).shape
    if instances < first_test or settings < 2:
        return None
    omnibus = friedman(results)
    if omnibus.p_value < alpha:
        return conover_against_best(results, alpha)
    best = _best(omnibus.rank_sums)
    p_values = np.full(settings, omnibus.p_value)
    p_values[best] = 1.0
    return PostHoc(best, p_values, np.ones(settings, dtype=bool), "friedman")


def _as_table(results: np.ndarray) -> np.ndarray:
    """``results`` as f64[I, S], refused unless 2-D and free of NaN."""
    table = np.asarray(results, dtype=np.float64)
    if table.ndim != 2:
        raise ValueError(f"results must be a table [instances, settings], got shape {table.shape}")
    if np.isnan(table).any():
        raise ValueError("results hold NaN; a race needs a result for every setting on every "
                         "instance")
    return table


def _require_size(table: np.ndarray, *, min_instances: int) -> tuple[int, int]:
    """The (instances, settings) of ``table``, refused below the sizes a test needs."""
    instances, settings = table.shape
    if instances < min_instances or settings < 2:
        raise ValueError(f"the test needs at least {min_instances} instance(s) and 2 settings, "
                         f"got {instances} and {settings}")
    return instances, settings


def _require_level(alpha: float) -> None:
    """Refuse a significance level outside (0, 1)."""
    if not 0 < alpha < 1:
        raise ValueError(f"alpha must lie in (0, 1), got {alpha}")


def _best(rank_sums: np.ndarray) -> int:
    """The setting with the lowest rank sum; of equal sums, the lowest index (R's ``order``)."""
    return int(np.argmin(rank_sums))
