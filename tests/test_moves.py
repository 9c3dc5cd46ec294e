"""Work on a walk's moves cut to the moves the whole batch made (jaxswarm.swarm.walking.moves)."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxswarm.runtime.arithmetic import ordered_cumsum, ordered_sum
from jaxswarm.swarm.walking.moves import move_widths, on_moves


def width_and_sum(moves, run, shared):
    """The width it was given (a test of the mechanism: real functions must not depend on it),
    and an ordered sum and running sum of the moves' values scaled by ``run`` and ``shared``."""
    (values,) = moves
    return (jnp.int32(values.shape[1]), ordered_sum(values * run * shared, axis=1),
            ordered_cumsum(values, axis=1)[:, -1])


def walk_columns(moves, columns=1023, agents=4, seed=0):
    """f32[agents, columns] values, zero past each agent's ``moves``."""
    values = np.random.default_rng(seed).random((agents, columns)).astype(np.float32)
    values[np.arange(columns)[None, :] >= np.asarray(moves)[:, None]] = 0.0
    return values


def test_widths_are_powers_of_four_times_128_then_the_whole():
    assert move_widths(1023) == (128, 512, 1023)
    assert move_widths(128) == (128,)
    assert move_widths(129) == (128, 129)
    assert move_widths(10) == (10,)


def test_one_walk_gets_the_narrowest_width_that_holds_its_moves_and_the_same_bits():
    moves = jnp.array([3, 70, 0, 12], jnp.int32)
    values = walk_columns(moves)
    width, total, running = jax.jit(lambda m, v: on_moves(
        width_and_sum, m, (v,), jnp.float32(2.0), jnp.float32(3.0)))(moves, values)
    assert int(width) == 128
    full = width_and_sum((values,), np.float32(2.0), np.float32(3.0))
    np.testing.assert_array_equal(total, full[1])
    np.testing.assert_array_equal(running, full[2])


def test_agents_not_used_do_not_widen_the_cut():
    moves = jnp.array([3, 700, 0, 12], jnp.int32)
    used = jnp.array([True, False, True, True])
    values = walk_columns(moves)
    values[1] = 0.0  # the function gives the unused agent no weight

    def width(m, v, used):
        return on_moves(width_and_sum, m, (v,), jnp.float32(1.0), jnp.float32(1.0), used=used)

    assert int(jax.jit(width)(moves, values, used)[0]) == 128
    assert int(jax.jit(width)(moves, values, None)[0]) == 1023


def test_a_batch_shares_one_width_at_any_nesting():
    moves = jnp.array([[3, 5, 0, 1], [3, 300, 2, 1], [1, 1, 1, 1]], jnp.int32)
    values = np.stack([walk_columns(m, seed=i) for i, m in enumerate(np.asarray(moves))])

    def one(m, v, run):
        return on_moves(width_and_sum, m, (v,), run, jnp.float32(1.0))

    width, total, _ = jax.jit(jax.vmap(one))(moves, values, jnp.arange(3.0))
    np.testing.assert_array_equal(width, [512, 512, 512])
    alone = [one(m, v, jnp.float32(r)) for r, (m, v) in enumerate(zip(moves, values))]
    assert [int(a[0]) for a in alone] == [128, 512, 128]
    np.testing.assert_array_equal(total, np.stack([a[1] for a in alone]))
    nested = jax.jit(jax.vmap(jax.vmap(one, in_axes=(0, 0, None)), in_axes=(0, 0, 0)))(
        moves.reshape(3, 1, 4), values.reshape(3, 1, 4, -1), jnp.arange(3.0))
    np.testing.assert_array_equal(nested[0], np.full((3, 1), 512))
    np.testing.assert_array_equal(nested[1][:, 0], total)


def test_a_batched_shared_input_lets_each_run_pick_its_own_width():
    moves = jnp.array([[3, 5, 0, 1], [3, 300, 2, 1]], jnp.int32)
    values = np.stack([walk_columns(m, seed=i) for i, m in enumerate(np.asarray(moves))])
    width, total, _ = jax.vmap(lambda m, v, s: on_moves(width_and_sum, m, (v,), 1.0, s))(
        moves, values, jnp.array([1.0, 2.0]))
    np.testing.assert_array_equal(width, [128, 512])
    np.testing.assert_allclose(total[1], 2 * values[1].astype(np.float64).sum(1), rtol=1e-5)


@pytest.mark.parametrize("moves", [[0, 0], [1023, 5]])
def test_no_moves_and_a_whole_budget(moves):
    values = walk_columns(moves, agents=2)
    width, total, _ = on_moves(width_and_sum, jnp.array(moves, jnp.int32), (values,),
                               jnp.float32(1.0), jnp.float32(1.0))
    assert int(width) == (128 if max(moves) == 0 else 1023)
    np.testing.assert_array_equal(total, ordered_sum(values, axis=1))


def weighted_sum(moves, run, shared):
    """Each row's sum of its moves' values weighted by their column (a NumPy constant)."""
    (values,) = moves
    return jnp.sum(values * np.arange(values.shape[1], dtype=np.float32), axis=1) * run * shared


def test_it_runs_inside_a_vmapped_cond_with_constants():
    # A vmapped lax.cond with a batched predicate batches every constant of its branches.
    def branch(values):
        moves = jnp.sum(values > 0, axis=1, dtype=jnp.int32)
        return (on_moves(width_and_sum, moves, (values,), jnp.float32(1.0), jnp.float32(2.0))[1]
                + on_moves(weighted_sum, moves, (values,), jnp.float32(1.0), jnp.float32(2.0)))

    values = np.stack([walk_columns([3, 9], agents=2, seed=i) for i in range(3)])
    got = jax.vmap(lambda v, p: jax.lax.cond(p, branch, lambda v: jnp.zeros(2), v))(
        values, jnp.array([True, False, True]))
    np.testing.assert_array_equal(got[1], [0.0, 0.0])
    np.testing.assert_array_equal(got[2], branch(values[2]))
