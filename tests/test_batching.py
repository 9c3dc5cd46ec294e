"""one_at_a_time: the same results as vmap, each batch member running its own loop."""
import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.batching import fold_runs, one_at_a_time, unfold_runs


def halvings(x, floor):
    """(x halved until below floor, halvings): a loop whose trip count depends on x."""
    def body(carry):
        value, count = carry
        return value / 2, count + 1
    return jax.lax.while_loop(lambda carry: carry[0] >= floor, body, (x, jnp.int32(0)))


def test_vmap_gives_what_plain_vmap_gives_with_shared_and_batched_arguments():
    xs = jnp.array([1.0, 3.0, 1000.0, 7.5], jnp.float32)
    sequential = jax.jit(jax.vmap(one_at_a_time(halvings), in_axes=(0, None)))(xs, 2.0)
    plain = jax.vmap(halvings, in_axes=(0, None))(xs, 2.0)
    np.testing.assert_array_equal(sequential[0], plain[0])
    np.testing.assert_array_equal(sequential[1], [0, 1, 9, 2])
    # One loop per member, mapped over the batch, rather than one loop over the whole batch.
    program = str(jax.make_jaxpr(jax.vmap(one_at_a_time(halvings), in_axes=(0, None)))(xs, 2.0))
    assert "scan" in program and "scan" not in str(
        jax.make_jaxpr(jax.vmap(halvings, in_axes=(0, None)))(xs, 2.0))


def test_nested_vmap_and_pytree_arguments():
    def scaled(pair, floor):
        value, count = halvings(pair["x"] * pair["scale"], floor)
        return {"value": value, "count": count}

    xs = jnp.arange(1.0, 7.0).reshape(2, 3)
    floors = jnp.array([1.0, 4.0])
    pair = {"x": xs, "scale": jnp.float32(10.0)}  # the scale is shared by every member
    inner = (({"x": 0, "scale": None}, None))
    outer = (({"x": 0, "scale": None}, 0))
    got = jax.vmap(jax.vmap(one_at_a_time(scaled), in_axes=inner), in_axes=outer)(pair, floors)
    want = jax.vmap(jax.vmap(scaled, in_axes=inner), in_axes=outer)(pair, floors)
    np.testing.assert_array_equal(got["value"], want["value"])
    np.testing.assert_array_equal(got["count"], want["count"])
    assert got["count"].shape == (2, 3)


def test_unbatched_call_is_the_function_itself():
    value, count = one_at_a_time(halvings)(jnp.float32(40.0), 2.0)
    assert float(value) == 1.25 and int(count) == 5


def test_fold_runs_puts_the_mapped_axis_before_the_runs_and_unfold_runs_undoes_it():
    x = np.arange(2 * 3 * 4).reshape(2, 3, 4)
    folded = fold_runs(x, True, 2)
    np.testing.assert_array_equal(folded, x.reshape(6, 4))
    np.testing.assert_array_equal(unfold_runs(folded, 2), x)
    shared = fold_runs(x[0], False, 2)  # not batched: every member the same
    np.testing.assert_array_equal(shared, np.concatenate([x[0], x[0]]))
