"""The one masked sampler every agent's move goes through."""
from __future__ import annotations

import functools
import operator

import jax
import jax.numpy as jnp

from jaxswarm.runtime.arithmetic import exp
from jaxswarm.world.graph import NO_NODE

FORCED = 1e30
"""A log-weight that wins every draw: use it for moves that must be taken (e.g. into the goal)."""


def sample_masked(uniform: jax.Array, log_weights: jax.Array, mask: jax.Array,
                  greedy: jax.Array | None = None):
    """Draw one slot per row among the masked-in slots, by inverse CDF.

    Args:
      uniform: f32[A] one uniform draw in [0, 1) per row (e.g. ``jax.random.uniform``).
      log_weights: f32[A, K] unnormalised log-probabilities; ``-inf`` means probability 0 and
        ``FORCED`` makes a slot certain.
      mask: bool[A, K] slots that may be chosen.
      greedy: optional bool[A]; a greedy row takes its most likely slot (ties drawn uniformly).

    Returns:
      ``(choice i32[A], has_choice bool[A])``. Rows with no admissible slot of positive weight get
      ``has_choice = False`` and ``choice = -1``; they must not move (``jax.random.categorical``
      would silently return slot 0 there).
    """
    masked = jnp.where(mask, log_weights, -jnp.inf)
    top = jnp.max(masked, axis=-1, keepdims=True)
    has_choice = jnp.isfinite(top[..., 0])  # False for no slot, all -inf, or NaN weights
    weights = exp(masked - jnp.where(has_choice[..., None], top, 0.0))
    if greedy is not None:
        weights = jnp.where(greedy[..., None], (masked == top).astype(weights.dtype), weights)
    # The first slot whose cumulative weight exceeds u (a slot of positive weight), capped at the
    # last slot of positive weight in case rounding made u reach the total: the cumulative sums
    # never decrease, so both "at most u" and "below the total" hold on a prefix of the slots,
    # and the slot is the length of the shorter prefix. The sums are unrolled over the (small,
    # static) slots and the prefix counted by one reduction: one kernel, cheaper than a cumsum
    # (a reduce-window) and argmax (a variadic reduce), whose result XLA keeps (an elementwise
    # count would be computed again in each of the step's consumers of the slot).
    columns = [weights[..., k] for k in range(weights.shape[-1])]
    total = functools.reduce(operator.add, columns)
    u = uniform * total
    running, prefix = jnp.zeros_like(total), []
    for column in columns:
        running = running + column
        prefix.append((running <= u) & (running < total))
    choice = jnp.sum(jnp.stack(prefix, axis=-1), axis=-1, dtype=jnp.int32)
    return jnp.where(has_choice, choice, NO_NODE).astype(jnp.int32), has_choice
