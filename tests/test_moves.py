"""Work on a walk's moves cut to the moves the whole batch made, and folds over the used agents'
walks (jaxswarm.swarm.walking.moves)."""
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jitted import rows_log

from jaxswarm.runtime.arithmetic import ordered_cumsum, ordered_sum
from jaxswarm.swarm.walking.moves import (fold_agents, fold_blocks_backwards, move_widths,
                                          on_moves)


def width_and_sum(moves, run, shared):
    """The width it was given (a test of the mechanism: real functions must not depend on it),
    and an ordered sum and running sum of the moves' values scaled by ``run`` and ``shared``."""
    (values,) = moves
    return (jnp.int32(values.shape[1]), ordered_sum(values * run * shared, axis=1),
            ordered_cumsum(values, axis=1)[:, -1])


whole = jax.jit(width_and_sum)
"""width_and_sum on a run's whole columns in one program: the bits a cut must give (applied
outside jit, ordered_sum and ordered_cumsum are dozens of operations of a program each)."""


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


def cut_sum(moves, values, run, shared, used=None):
    """:func:`width_and_sum` on one run's ``values`` (f32[4, 1023]) cut by :func:`on_moves`.
    Applied outside ``jit``, every test's run alone is one program: on_moves's own."""
    return on_moves(width_and_sum, moves, (values,), run, shared, used=used)


@jax.jit
def batches(moves, values, runs, shared):
    """:func:`cut_sum` of R runs (``moves`` i32[R, 4], ``values`` f32[R, 4, 1023]) batched
    three ways, one program for the tests of batches: with their own run inputs ``runs``
    (f32[R]) and the shared input 1, by a ``vmap`` and by a ``vmap`` of ``vmap`` (R x 1); with
    the run input 1 and their own shared inputs ``shared`` (f32[R]), by a ``vmap``."""
    one = jnp.float32(1.0)
    flat = jax.vmap(cut_sum, in_axes=(0, 0, 0, None))(moves, values, runs, one)
    nested = jax.vmap(jax.vmap(cut_sum, in_axes=(0, 0, None, None)), in_axes=(0, 0, 0, None))(
        moves[:, None], values[:, None], runs, one)
    own = jax.vmap(cut_sum, in_axes=(0, 0, None, 0))(moves, values, one, shared)
    return flat, nested, own


def test_one_walk_gets_the_narrowest_width_that_holds_its_moves_and_the_same_bits():
    moves = jnp.array([3, 70, 0, 12], jnp.int32)
    values = walk_columns(moves)
    width, total, running = cut_sum(moves, values, jnp.float32(2.0), jnp.float32(3.0))
    assert int(width) == 128
    full = whole((values,), np.float32(2.0), np.float32(3.0))
    np.testing.assert_array_equal(total, full[1])
    np.testing.assert_array_equal(running, full[2])


def test_agents_not_used_do_not_widen_the_cut():
    moves = jnp.array([3, 700, 0, 12], jnp.int32)
    used = jnp.array([True, False, True, True])
    values = walk_columns(moves)
    values[1] = 0.0  # the function gives the unused agent no weight

    def width(used):
        return int(cut_sum(moves, values, jnp.float32(1.0), jnp.float32(1.0), used=used)[0])

    assert width(used) == 128
    assert width(None) == 1023


def test_a_batch_shares_one_width_at_any_nesting():
    moves = np.array([[3, 5, 0, 1], [3, 300, 2, 1], [1, 1, 1, 1]], np.int32)
    values = np.stack([walk_columns(m, seed=i) for i, m in enumerate(moves)])
    runs = np.array([1.0, 2.0, 3.0], np.float32)
    (width, total, _), nested, _ = jax.device_get(batches(moves, values, runs,
                                                          np.ones(3, np.float32)))
    np.testing.assert_array_equal(width, [512, 512, 512])
    alone = [cut_sum(m, v, r, np.float32(1.0)) for m, v, r in zip(moves, values, runs)]
    assert [int(a[0]) for a in alone] == [128, 512, 128]
    np.testing.assert_array_equal(total, np.stack([a[1] for a in alone]))
    np.testing.assert_array_equal(nested[0], np.full((3, 1), 512))
    np.testing.assert_array_equal(nested[1][:, 0], total)


def test_a_batched_shared_input_lets_each_run_pick_its_own_width():
    moves = np.array([[3, 5, 0, 1], [3, 300, 2, 1], [700, 1, 0, 1]], np.int32)
    values = np.stack([walk_columns(m, seed=i) for i, m in enumerate(moves)])
    shared = np.array([1.0, 2.0, 3.0], np.float32)
    width, total, _ = batches(moves, values, np.ones(3, np.float32), shared)[2]
    np.testing.assert_array_equal(width, [128, 512, 1023])
    want = shared[:, None] * values.astype(np.float64).sum(2)
    np.testing.assert_allclose(total, want, rtol=1e-5)


@pytest.mark.parametrize("moves", [[0, 0, 0, 0], [1023, 5, 0, 3]])
def test_no_moves_and_a_whole_budget(moves):
    values = walk_columns(moves)
    width, total, _ = cut_sum(jnp.array(moves, jnp.int32), values, jnp.float32(1.0),
                              jnp.float32(1.0))
    assert int(width) == (128 if max(moves) == 0 else 1023)
    np.testing.assert_array_equal(total, whole((values,), np.float32(1.0), np.float32(1.0))[1])


def weighted_sum(moves, run, shared):
    """Each row's sum of its moves' values weighted by their column (a NumPy constant)."""
    (values,) = moves
    return jnp.sum(values * np.arange(values.shape[1], dtype=np.float32), axis=1) * run * shared


def test_it_runs_inside_a_vmapped_cond_with_constants():
    # A vmapped lax.cond with a batched predicate batches every constant of its branches
    # (jitted, the batch is one program; applied outside jit, each on_moves of it is one).
    def branch(values):
        moves = jnp.sum(values > 0, axis=1, dtype=jnp.int32)
        return (on_moves(width_and_sum, moves, (values,), jnp.float32(1.0), jnp.float32(2.0))[1]
                + on_moves(weighted_sum, moves, (values,), jnp.float32(1.0), jnp.float32(2.0)))

    values = np.stack([walk_columns([3, 9, 0, 1], seed=i) for i in range(3)])
    batched = jax.jit(jax.vmap(lambda v, p: jax.lax.cond(p, branch, lambda v: jnp.zeros(4), v)))
    got = np.asarray(batched(values, np.array([True, False, True])))
    np.testing.assert_array_equal(got[1], np.zeros(4))
    np.testing.assert_array_equal(got[2], branch(values[2]))


def random_log(moves, max_steps=1023, nodes=50, seed=0):
    """A MoveLog of agents that made ``moves`` moves each (random nodes and slots), and its rows
    ``(path, slots)`` padded to the budget, as NumPy arrays."""
    rng = np.random.default_rng(seed)
    agents, width = len(moves), max_steps
    made = np.arange(width)[None, :] < np.asarray(moves)[:, None]
    slots = np.where(made, rng.integers(0, 8, (agents, width)), -1).astype(np.int8)
    path = np.concatenate([np.full((agents, 1), 7), np.where(
        made, rng.integers(0, nodes, (agents, width)), -1)], axis=1).astype(np.int32)
    log = rows_log(path, slots, np.asarray(moves, np.int32), np.int32(7), max_steps)
    return log, path, slots


def record(carry, agent, row, run, shared):
    """Each used agent's turn, its row's weighted sums and the widest row seen; nothing for an
    agent past the last."""
    turns, turn, sums, widest = carry
    path, slots = row
    column = jnp.arange(1, path.shape[0] + 1)
    total = (jnp.sum(jnp.where(path >= 0, path * column, 0))
             + jnp.sum(jnp.where(slots >= 0, slots * column[:-1], 0))) * run + shared
    real = agent < turn.shape[0]
    return (turns + real, turn.at[agent].set(turns, mode="drop"),
            sums.at[agent].set(total, mode="drop"),
            jnp.where(real, jnp.maximum(widest, slots.shape[0]), widest))


def expected_record(path, slots, used, run=1, shared=0):
    """:func:`record`'s turns and sums by a loop over the used agents in agent order."""
    turn, sums = np.full(len(used), -1), np.zeros(len(used), np.int64)
    for order, agent in enumerate(np.flatnonzero(used)):
        column = np.arange(1, path.shape[1] + 1)
        turn[agent] = order
        sums[agent] = ((np.where(path[agent] >= 0, path[agent] * column, 0).sum()
                        + np.where(slots[agent] >= 0, slots[agent] * column[:-1], 0).sum())
                       * run + shared)
    return turn, sums


def empty_record(agents):
    return (jnp.int32(0), jnp.full(agents, -1, jnp.int32), jnp.zeros(agents, jnp.int32),
            jnp.int32(0))


def fold(log, used, run, shared):
    """:func:`record` folded over one run's ``used`` agents of 5 (:func:`random_log`'s budget).
    Applied outside ``jit``, every test's run alone is one program: fold_agents's own."""
    return fold_agents(record, log, empty_record(5), run, shared, used=used)


def test_fold_agents_takes_the_used_agents_in_agent_order_on_their_own_rows():
    moves = [3, 700, 0, 12, 40]
    used = np.array([True, False, True, True, True])
    log, path, slots = random_log(moves)
    turns, turn, sums, widest = fold(log, used, jnp.int32(1), jnp.int32(0))
    want_turn, want_sums = expected_record(path, slots, used)
    assert int(turns) == 4
    np.testing.assert_array_equal(turn, want_turn)
    np.testing.assert_array_equal(sums, want_sums)
    assert int(widest) == 128  # the unused agent's 700 moves do not widen the rows
    everyone = fold(log, np.ones(5, bool), jnp.int32(1), jnp.int32(0))
    assert int(everyone[3]) == 1023
    np.testing.assert_array_equal(everyone[2], expected_record(path, slots, np.ones(5, bool))[1])


def test_a_batch_of_folds_equals_each_run_alone_at_any_nesting():
    # Runs with 3, 0 and 5 used agents: the batch steps to the most, the others unchanged.
    moves = [[3, 5, 0, 1, 9], [3, 300, 2, 1, 4], [1, 1, 600, 1, 2]]
    logs = [random_log(m, seed=i) for i, m in enumerate(moves)]
    log = jax.tree_util.tree_map(lambda *x: np.stack(x), *[entry[0] for entry in logs])
    used = np.array([[1, 0, 1, 0, 1], [0] * 5, [1, 1, 0, 1, 1]], bool)
    runs = np.array([1, 2, 3], np.int32)

    @jax.jit
    def fold_batches(log, used, runs):
        """The runs folded by a ``vmap``, by a ``vmap`` of ``vmap`` (R x 1), and by a ``vmap``
        that batches the shared input too: one program."""
        four = jnp.int32(4)
        flat = jax.vmap(fold, in_axes=(0, 0, 0, None))(log, used, runs, four)
        nested = jax.vmap(jax.vmap(fold, in_axes=(0, 0, None, None)), in_axes=(0, 0, 0, None))(
            jax.tree_util.tree_map(lambda x: x[:, None], log), used[:, None], runs, four)
        return flat, nested, jax.vmap(fold)(log, used, runs, jnp.full(3, four))

    batch, nested, shared = jax.device_get(fold_batches(log, used, runs))
    for r, (_, path, slots) in enumerate(logs):
        alone = fold(jax.tree_util.tree_map(lambda x: x[r], log), used[r], runs[r], jnp.int32(4))
        for got, want in zip(batch, alone):
            np.testing.assert_array_equal(got[r], want)
        want_turn, want_sums = expected_record(path, slots, used[r], r + 1, 4)
        np.testing.assert_array_equal(batch[1][r], want_turn)
        np.testing.assert_array_equal(batch[2][r], want_sums)
    np.testing.assert_array_equal(batch[3], [128, 0, 128])  # no run's used agent made 600 moves
    for got, want in zip(nested, batch):
        np.testing.assert_array_equal(got[:, 0], want)
    # A batched shared input: each run folds on its own, to the same result.
    for got, want in zip(shared, batch):
        np.testing.assert_array_equal(got, want)


def hash_block(carry, block, run, shared):
    """A hash of the blocks' columns in the order they come (``run`` and ``shared`` weigh the
    nodes and the slots), left as it was by a block past every path's end, and the steps taken
    (which a block past the end does count)."""
    steps, digest = carry
    nodes, slots = block
    real = jnp.any(nodes >= 0)
    column = jnp.arange(1, nodes.shape[1] + 1)
    value = jnp.sum(jnp.where(nodes >= 0, nodes * column, 0)) * run + jnp.sum(
        jnp.where(slots >= 0, slots + 1, 0)) * shared
    return steps + 1, jnp.where(real, digest * 31 + value, digest)


def expected_hash(path, slots, block, run=1, shared=1):
    """:func:`hash_block`'s steps and digest by a loop over one run's blocks, last first."""
    moves_made = (path >= 0).sum(axis=1) - 1
    blocks = (moves_made.max() + block) // block
    padded = -np.ones((path.shape[0], path.shape[1] + block), np.int64)
    padded[:, :path.shape[1]] = path
    slot_rows = -np.ones_like(padded)
    slot_rows[:, :slots.shape[1]] = slots
    digest, column = 0, np.arange(1, block + 1)
    for k in reversed(range(blocks)):
        nodes = padded[:, k * block:(k + 1) * block]
        taken = slot_rows[:, k * block:(k + 1) * block]
        value = (np.where(nodes >= 0, nodes * column, 0).sum() * run
                 + np.where(taken >= 0, taken + 1, 0).sum() * shared)
        digest = (digest * 31 + value) % 2 ** 32
    return blocks, np.array([digest], np.uint64).astype(np.uint32).view(np.int32)[0]


def fold_back(log, run, shared):
    """:func:`hash_block` folded backwards over one run's blocks of 8 columns."""
    return fold_blocks_backwards(hash_block, log, (jnp.int32(0), jnp.int32(0)), run, shared,
                                 block=8)


def test_fold_blocks_backwards_takes_the_walked_blocks_last_first():
    moves = [3, 37, 0, 12]
    log, path, slots = random_log(moves, max_steps=64)
    steps, digest = jax.jit(fold_back)(log, jnp.int32(2), jnp.int32(5))
    want_steps, want_digest = expected_hash(path, slots, 8, run=2, shared=5)
    assert int(steps) == want_steps == 5  # columns 0 .. 37 of the longest path
    assert int(digest) == want_digest


def test_a_batch_of_backward_folds_steps_to_its_longest_path_with_each_run_as_alone():
    moves = [[3, 5, 0, 1], [2, 60, 2, 1], [0, 0, 0, 0]]
    logs = [random_log(m, max_steps=64, seed=i) for i, m in enumerate(moves)]
    log = jax.tree_util.tree_map(lambda *x: np.stack(x), *[entry[0] for entry in logs])
    runs = np.array([1, 2, 3], np.int32)

    @jax.jit
    def fold_batches(log, runs):
        flat = jax.vmap(fold_back, in_axes=(0, 0, None))(log, runs, jnp.int32(4))
        nested = jax.vmap(jax.vmap(fold_back, in_axes=(0, None, None)), in_axes=(0, 0, None))(
            jax.tree_util.tree_map(lambda x: x[:, None], log), runs, jnp.int32(4))
        return flat, nested, jax.vmap(fold_back)(log, runs, jnp.full(3, 4, jnp.int32))

    (steps, digest), nested, shared = jax.device_get(fold_batches(log, runs))
    np.testing.assert_array_equal(steps, [8, 8, 8])  # the batch steps to 60 moves' blocks
    for r, (_, path, slots) in enumerate(logs):
        assert int(digest[r]) == expected_hash(path, slots, 8, run=r + 1, shared=4)[1]
    np.testing.assert_array_equal(nested[1][:, 0], digest)
    # A batched shared input: each run folds on its own, over its own blocks.
    np.testing.assert_array_equal(shared[1], digest)
    np.testing.assert_array_equal(shared[0], [1, 8, 1])
