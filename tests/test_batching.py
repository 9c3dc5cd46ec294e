"""one_at_a_time: the same results as vmap, each batch member running its own loop."""
import jax
import jax.numpy as jnp
import numpy as np

from jaxswarm.runtime.batching import one_at_a_time


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
