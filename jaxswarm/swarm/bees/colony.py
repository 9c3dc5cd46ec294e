"""Constrained artificial bee colony (cABC, Karaboga and Akay; the bees paper, section IV) over a
box, all bees in lockstep.

``N`` food sources (candidate points) start uniform in the box (eq. 7). Each of ``I`` cycles
runs three phases:

* **employed**: every source ``i`` tries ``v = x_i`` with one coordinate ``j`` moved by
  ``phi (x_ij - x_kj)``, ``phi ~ U[-1, 1]``, ``k != i`` (eq. 8), clipped to the box, and keeps
  the better of the two by Deb's rules (:func:`deb_better`); a source that is not improved
  counts one more trial.
* **onlooker**: each source gets the probability of eq. 10 (:func:`onlooker_probabilities`);
  going round the sources in order, an onlooker is sent to source ``i`` when ``U[0, 1] < p_i``
  until ``N`` onlookers are out (at most :data:`ONLOOKER_ROUNDS` rounds). Each makes an eq. 8 try
  from its source.
* **scout**: a source whose trials reached ``limit`` is replaced by a new uniform point.

Lockstep, not one bee after another: the employed bees all start from the sources as the phase
found them, and so do the onlookers; a source that sent several onlookers takes the best of their
tries (when it beats the source; otherwise each failed try counts a trial). The best source ever
seen is remembered across the cycles (scouts may drop it), and the search returns it.
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp

from jaxswarm.runtime.arithmetic import ordered_sum

ONLOOKER_ROUNDS = 8
"""Rounds over the sources in which onlookers are sent (eq. 10 gives a feasible source p >= 0.5,
so N onlookers need about two; a colony whose sources are all infeasible with equal violations has
p = 0.5 (1 - 1/N) each, and eight rounds send N onlookers except with tiny probability)."""


class Sources(NamedTuple):
    """The colony's food sources.

    Attributes:
      points: f32[N, 2].
      phi: f32[N] the guided function at each.
      violations: i32[N] constraints each violates (0: feasible).
      trials: i32[N] tries since the source last improved.
    """

    points: jax.Array
    phi: jax.Array
    violations: jax.Array
    trials: jax.Array


class Best(NamedTuple):
    """A search's answer: ``point`` f32[2], ``phi`` f32[], ``violations`` i32[], and
    ``evaluations`` i32[] (guided-function calls the search made)."""

    point: jax.Array
    phi: jax.Array
    violations: jax.Array
    evaluations: jax.Array


Evaluate = Callable[[jax.Array], tuple[jax.Array, jax.Array]]
"""``points f32[N, 2] -> (phi f32[N], violations i32[N])``."""


def fitness(phi: jax.Array) -> jax.Array:
    """Eq. 9: ``1 / (1 + phi)`` where ``phi >= 0``, ``1 + |phi|`` elsewhere (f32[...])."""
    return jnp.where(phi >= 0, 1.0 / (1.0 + jnp.abs(phi)), 1.0 + jnp.abs(phi))


def deb_better(phi_a, violations_a, phi_b, violations_b) -> jax.Array:
    """bool[...]: whether ``a`` beats ``b`` by Deb's rules: a feasible point beats an infeasible
    one; of two feasible points the fitter (eq. 9) wins; of two infeasible points the one with
    fewer violations wins. Ties do not beat."""
    feasible_a, feasible_b = violations_a == 0, violations_b == 0
    return jnp.where(feasible_a & feasible_b, fitness(phi_a) > fitness(phi_b),
                     jnp.where(feasible_a | feasible_b, feasible_a,
                               violations_a < violations_b))


def deb_best(phi: jax.Array, violations: jax.Array) -> jax.Array:
    """i32[]: the index of the best of N points (f32[N], i32[N]) by Deb's rules: fewest
    violations, then the greatest fitness; the first of equals."""
    fewest = violations == jnp.min(violations)
    return jnp.argmax(jnp.where(fewest, fitness(phi), -jnp.inf)).astype(jnp.int32)


def onlooker_probabilities(phi: jax.Array, violations: jax.Array) -> jax.Array:
    """Eq. 10: f32[N], ``0.5 + 0.5 fit_i / sum_j fit_j`` for a feasible source,
    ``0.5 (1 - viol_i / sum_j viol_j)`` for an infeasible one."""
    fit = fitness(phi)
    total_violations = jnp.maximum(jnp.sum(violations), 1).astype(jnp.float32)
    return jnp.where(violations == 0, 0.5 + 0.5 * fit / ordered_sum(fit),
                     0.5 * (1.0 - violations / total_violations))


def uniform_in_box(key: jax.Array, lower: jax.Array, upper: jax.Array, count: int) -> jax.Array:
    """Eq. 7: f32[count, 2] points uniform in the box ``[lower, upper]`` (f32[2] each)."""
    return lower + jax.random.uniform(key, (count, 2)) * (upper - lower)


def neighbour_tries(key: jax.Array, points: jax.Array, sources: jax.Array, lower: jax.Array,
                    upper: jax.Array) -> jax.Array:
    """Eq. 8: f32[M, 2], one try from each of ``sources`` (i32[M] indices into points f32[N, 2]):
    one random coordinate moved by ``phi (x_ij - x_kj)`` towards or away from a random other
    source ``k``, clipped to the box."""
    n = points.shape[0]
    partner_key, axis_key, step_key = jax.random.split(key, 3)
    count = sources.shape[0]
    partner = (sources + jax.random.randint(partner_key, (count,), 1, n)) % n
    axis = jax.random.randint(axis_key, (count,), 0, 2)
    step = jax.random.uniform(step_key, (count,), minval=-1.0, maxval=1.0)
    here = points[sources]
    moved = here + (jax.nn.one_hot(axis, 2) * (step * (here - points[partner])[
        jnp.arange(count), axis])[:, None])
    return jnp.clip(moved, lower, upper)


def search(key: jax.Array, evaluate: Evaluate, lower: jax.Array, upper: jax.Array, *,
           num_sources: int, cycles: jax.Array, limit: jax.Array) -> Best:
    """cABC in the box ``[lower, upper]``: the best point found in ``cycles`` cycles.

    Args:
      key: PRNG key.
      evaluate: the guided function and the constraints (see :data:`Evaluate`).
      lower, upper: f32[2] the box.
      num_sources: N (static, >= 2).
      cycles: i32[] I, the employed-onlooker-scout cycles (traced; 0 keeps the best of the
        initial sources).
      limit: i32[] trials after which a source is abandoned to a scout.

    Returns:
      :class:`Best`.
    """
    init_key, loop_key = jax.random.split(key)
    points = uniform_in_box(init_key, lower, upper, num_sources)
    phi, violations = evaluate(points)
    sources = Sources(points, phi, violations, jnp.zeros(num_sources, jnp.int32))
    first = deb_best(phi, violations)
    best = Best(points[first], phi[first], violations[first], jnp.int32(num_sources))

    def cycle(_, carry):
        key, sources, best = carry
        key, employed_key, onlooker_key, scout_key = jax.random.split(key, 4)
        sources, employed = _employed(employed_key, sources, evaluate, lower, upper)
        sources, onlookers = _onlookers(onlooker_key, sources, evaluate, lower, upper)
        best = _remember(best, sources)
        sources, scouts = _scouts(scout_key, sources, evaluate, lower, upper, limit)
        best = _remember(best, sources)
        return key, sources, best._replace(
            evaluations=best.evaluations + employed + onlookers + scouts)

    _, _, best = jax.lax.fori_loop(0, cycles, cycle, (loop_key, sources, best))
    return best


def _employed(key, sources: Sources, evaluate: Evaluate, lower, upper):
    n = sources.points.shape[0]
    tries = neighbour_tries(key, sources.points, jnp.arange(n), lower, upper)
    phi, violations = evaluate(tries)
    better = deb_better(phi, violations, sources.phi, sources.violations)
    return _replace_where(sources, better, tries, phi, violations,
                          jnp.where(better, 0, sources.trials + 1)), jnp.int32(n)


def _onlookers(key, sources: Sources, evaluate: Evaluate, lower, upper):
    n = sources.points.shape[0]
    choose_key, try_key = jax.random.split(key)
    probability = onlooker_probabilities(sources.phi, sources.violations)
    draws = jax.random.uniform(choose_key, (ONLOOKER_ROUNDS, n))
    sent = (draws < probability).reshape(-1)  # round-major: sources in order, round after round
    (order,) = jnp.nonzero(sent, size=n, fill_value=-1)
    out = order >= 0
    source = jnp.where(out, order % n, 0).astype(jnp.int32)
    tries = neighbour_tries(try_key, sources.points, source, lower, upper)
    phi, violations = evaluate(tries)
    # Each source's best try by Deb's rules: fewest violations, then the greatest fitness, then
    # the first onlooker.
    segment = jnp.where(out, source, n)
    fewest = jax.ops.segment_min(violations, segment, num_segments=n + 1)[segment]
    fit = jnp.where(violations == fewest, fitness(phi), -jnp.inf)
    fittest = jax.ops.segment_max(fit, segment, num_segments=n + 1)[segment]
    first = jax.ops.segment_min(jnp.where(fit == fittest, jnp.arange(n), n), segment,
                                num_segments=n + 1)[:n]
    has_try = first < n
    winner = jnp.minimum(first, n - 1)
    better = has_try & deb_better(phi[winner], violations[winner], sources.phi,
                                  sources.violations)
    failed = jnp.zeros(n, jnp.int32).at[segment].add(1, mode="drop")
    sources = _replace_where(sources, better, tries[winner], phi[winner], violations[winner],
                             jnp.where(better, 0, sources.trials + failed))
    return sources, jnp.sum(out, dtype=jnp.int32)


def _scouts(key, sources: Sources, evaluate: Evaluate, lower, upper, limit):
    abandoned = sources.trials >= limit

    def send(sources):
        fresh = uniform_in_box(key, lower, upper, sources.points.shape[0])
        phi, violations = evaluate(fresh)
        return _replace_where(sources, abandoned, fresh, phi, violations,
                              jnp.where(abandoned, 0, sources.trials))

    # Few cycles rarely reach the limit: a run on its own skips the evaluations.
    sources = jax.lax.cond(jnp.any(abandoned), send, lambda sources: sources, sources)
    return sources, jnp.sum(abandoned, dtype=jnp.int32)


def _remember(best: Best, sources: Sources) -> Best:
    i = deb_best(sources.phi, sources.violations)
    better = deb_better(sources.phi[i], sources.violations[i], best.phi, best.violations)
    return best._replace(point=jnp.where(better, sources.points[i], best.point),
                         phi=jnp.where(better, sources.phi[i], best.phi),
                         violations=jnp.where(better, sources.violations[i], best.violations))


def _replace_where(sources: Sources, where, points, phi, violations, trials) -> Sources:
    return Sources(points=jnp.where(where[:, None], points, sources.points),
                   phi=jnp.where(where, phi, sources.phi),
                   violations=jnp.where(where, violations, sources.violations), trials=trials)
