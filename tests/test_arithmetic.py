"""Arithmetic whose result does not depend on the program (jaxswarm.runtime.arithmetic), and the
fingerprint of a run (jaxswarm.swarm.fingerprint)."""
import os
import platform

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxswarm.runtime.arithmetic import (ISA_FLAG, exp, fixed_arithmetic_flags, integer_power,
                                         log, ordered_cumsum,
                                         ordered_sum)
from jaxswarm.swarm.fingerprint import fingerprint, hex_fingerprint

X86 = platform.machine().lower() in ("x86_64", "amd64")


def in_rows(function, x, width):
    """``function`` jitted and applied to ``x`` in rows of ``width`` (the last one shorter)."""
    compiled = jax.jit(function)
    return np.concatenate([np.asarray(compiled(x[i:i + width]))
                           for i in range(0, len(x), width)])


@pytest.mark.skipif(not X86, reason="the instruction set cap is x86-64's")
def test_importing_jaxswarm_caps_xla_so_that_nothing_is_fused_into_one_rounding():
    assert ISA_FLAG in os.environ["XLA_FLAGS"]
    rng = np.random.default_rng(0)
    a, b = rng.random(4096, np.float32), rng.random(4096, np.float32)
    c = -(a.astype(np.float64) * b).astype(np.float32)
    # a * b rounded, then + c: the rounding error of the product (an FMA would give it exactly).
    np.testing.assert_array_equal(jax.jit(lambda a, b, c: a * b + c)(a, b, c), a * b + c)


def test_the_flag_is_added_once_and_a_users_choice_stands():
    environ = {}
    assert fixed_arithmetic_flags(environ, "x86_64") and environ["XLA_FLAGS"] == ISA_FLAG
    assert not fixed_arithmetic_flags(environ, "x86_64") and environ["XLA_FLAGS"] == ISA_FLAG
    mine = {"XLA_FLAGS": "--xla_cpu_max_isa=AVX2 --xla_force_host_platform_device_count=2"}
    assert not fixed_arithmetic_flags(mine, "AMD64")
    assert mine["XLA_FLAGS"] == "--xla_cpu_max_isa=AVX2 --xla_force_host_platform_device_count=2"
    arm = {}
    assert not fixed_arithmetic_flags(arm, "aarch64") and arm == {}


def test_exp_is_within_one_ulp_and_the_same_bits_on_every_width():
    rng = np.random.default_rng(1)
    x = (rng.random(30_000) * 175 - 87).astype(np.float32)  # results in the normal range
    # Near overflow 2^n is 2^63 * 2^64: kept apart, its halves are normal floats.
    x = np.concatenate([x, np.linspace(87.5, 88.72, 1000, dtype=np.float32)])
    got = np.asarray(jax.jit(exp)(x))
    want = np.exp(x.astype(np.float64)).astype(np.float32)
    ulps = np.abs(got.view(np.int32).astype(np.int64) - want.view(np.int32).astype(np.int64))
    assert ulps.max() <= 1
    for width in (1, 3, 7, 64):
        np.testing.assert_array_equal(in_rows(exp, x[:700], width), got[:700])
    special = np.array([-np.inf, -200.0, 0.0, 89.0, np.inf, np.nan], np.float32)
    np.testing.assert_array_equal(jax.jit(exp)(special), [0.0, 0.0, 1.0, np.inf, np.inf, np.nan])


def test_log_is_within_one_ulp_and_the_same_bits_on_every_width():
    rng = np.random.default_rng(2)
    x = np.concatenate([rng.random(20_000) * 2, np.exp(rng.random(20_000) * 170 - 85),
                        np.float32(2.0) ** np.arange(-126, 128)]).astype(np.float32)
    got = np.asarray(jax.jit(log)(x))
    want = np.log(x.astype(np.float64)).astype(np.float32)
    ulps = np.abs(got.view(np.int32).astype(np.int64) - want.view(np.int32).astype(np.int64))
    assert ulps.max() <= 1
    for width in (1, 3, 7, 64):
        np.testing.assert_array_equal(in_rows(log, x[:700], width), got[:700])
    special = np.array([0.0, 1e-40, -1.0, 1.0, np.inf, np.nan], np.float32)
    np.testing.assert_array_equal(jax.jit(log)(special),
                                  [-np.inf, -np.inf, np.nan, 0.0, np.inf, np.nan])


def test_integer_power_multiplies_the_squares_of_the_exponents_bits():
    x = np.float32(0.9)
    n = np.arange(0, 41, dtype=np.int32)
    got = np.asarray(jax.jit(integer_power, static_argnums=2)(x, n, 40))
    # By hand: the squares x, x^2, x^4, ... multiplied in, lowest bit first, in float32.
    squares = [x]
    for _ in range(5):
        squares.append(np.float32(squares[-1] * squares[-1]))
    for k in n:
        want = np.float32(1.0)
        for bit, square in enumerate(squares):
            if (k >> bit) & 1:
                want = np.float32(want * square)
        assert got[k] == want, k
    assert got[0] == 1.0


def test_ordered_sum_adds_halves_pairwise_whatever_the_batch():
    # Pairwise: (1e8 + -1e8) + (1 + 1) = 2; left to right in float32, 1e8 + 1 rounds to 1e8.
    x = np.array([1e8, 1.0, -1e8, 1.0], np.float32)
    assert float(ordered_sum(x)) == 2.0
    assert float(ordered_sum(x[:3])) == 1.0  # (1e8 + -1e8) + (1 + 0)
    assert float(ordered_sum(np.zeros(0, np.float32))) == 0.0
    rows = np.random.default_rng(2).random((64, 37)).astype(np.float32)
    batch = np.asarray(jax.jit(lambda r: ordered_sum(r, axis=1))(rows))
    np.testing.assert_array_equal(batch, [np.asarray(jax.jit(ordered_sum)(r)) for r in rows])
    np.testing.assert_allclose(batch, rows.astype(np.float64).sum(axis=1), rtol=1e-6)
    np.testing.assert_array_equal(ordered_sum(rows.T, axis=0), batch)


def test_ordered_cumsum_is_the_running_sum_whatever_the_batch():
    rows = np.random.default_rng(3).random((64, 50)).astype(np.float32)
    batch, backwards = jax.device_get(jax.jit(lambda r: (
        ordered_cumsum(r, axis=1), ordered_cumsum(r, axis=1, reverse=True)))(rows))
    np.testing.assert_array_equal(batch, [np.asarray(jax.jit(ordered_cumsum)(r)) for r in rows])
    np.testing.assert_allclose(batch, np.cumsum(rows.astype(np.float64), axis=1), rtol=1e-6)
    np.testing.assert_allclose(backwards[:, 0], rows.astype(np.float64).sum(axis=1), rtol=1e-6)
    np.testing.assert_allclose(backwards[:, -1], rows[:, -1])


def test_a_fingerprint_sees_every_bit_and_is_the_same_in_a_batch():
    # Alone outside jit (as a replayed run is fingerprinted), in a batch jitted (as a sweep's).
    tree = {"cost": np.arange(5, dtype=np.float32), "key": jax.random.key(0),
            "found": np.array([True, False]), "slots": np.array([1, -1], np.int8)}
    base = hex_fingerprint(fingerprint(tree))
    assert len(base) == 16
    one_ulp = dict(tree, cost=tree["cost"].copy())
    one_ulp["cost"][3] = np.nextafter(np.float32(3), np.float32(4))
    flipped = dict(tree, found=np.array([False, False]))
    other_key = dict(tree, key=jax.random.key(1))
    swapped = dict(tree, cost=tree["cost"][::-1])
    changed = {hex_fingerprint(fingerprint(t)) for t in (one_ulp, flipped, other_key, swapped)}
    assert base not in changed and len(changed) == 4
    stacked = jax.tree_util.tree_map(lambda x: jnp.stack([x, x, x]), tree)
    batch = np.asarray(jax.jit(jax.vmap(fingerprint))(stacked))
    assert {hex_fingerprint(f) for f in batch} == {base}
