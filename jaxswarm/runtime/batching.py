"""Batching rules for loops whose trip count differs from one batch member to the next.

Under ``vmap`` a ``lax.while_loop`` runs until its last member is done, and every iteration
works on the whole batch: a relaxation that needs 1 sweep in most runs of a sweep and 30 in a
few costs 30 sweeps for each. :func:`one_at_a_time` gives such a function a batching rule that
maps it over the batch one member at a time instead, so each member pays for its own loop.
:func:`fold_runs` and :func:`unfold_runs` serve the other kind of rule, which folds a
``vmap``'s axis into a function's own leading run axis (the walker's, and the work after it)
so that the whole batch runs as one; :func:`runs_folded` gives a function written for a leading
run axis that rule.
"""
from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
from jax.custom_batching import custom_vmap
from jax.extend.core import jaxpr_as_fun


def one_at_a_time(fun):
    """``fun`` (positional array or pytree arguments, pytree result) with a vmap rule that
    applies it to the batch members one after the other (``lax.map``) rather than to all of
    them at once. Results are the same as ``vmap``'s; pays where members' loops run for very
    different numbers of iterations and one member's iteration already fills the machine.
    Arguments not batched are shared by every member, not copied. ``fun`` is jitted and traced
    once per argument signature, whether it runs alone or as a member inside the rule."""
    member = _traced_once(fun)

    @custom_vmap
    @functools.wraps(fun)
    def mapped(*args):
        return member(*args)

    @mapped.def_vmap
    def rule(axis_size, in_batched, *args):
        del axis_size
        leaves, treedef = jax.tree_util.tree_flatten(args)
        batched = jax.tree_util.tree_leaves(in_batched)
        # Batched leaves are the scanned input; the others are shared by every member.
        xs = [leaf for leaf, b in zip(leaves, batched) if b]

        def one(member):
            members = iter(member)
            return mapped(*jax.tree_util.tree_unflatten(
                treedef, [next(members) if b else leaf for leaf, b in zip(leaves, batched)]))

        out = jax.lax.map(one, xs)
        return out, jax.tree_util.tree_map(lambda _: True, out)

    return mapped


def _traced_once(fun):
    """``fun``, jitted, and traced once per argument signature (pytree structure and each
    leaf's shape, dtype and weak type) wherever it is called. JAX keys its tracing caches on
    the context of a call too, and a ``vmap`` rule runs in ``vmap``'s axis context: a member
    traced there would be traced again at every batch (seconds for a run loop). Each call
    stages the kept jaxpr, a ``jit`` call of ``fun``."""
    jitted = jax.jit(fun)
    jaxprs = {}

    @functools.wraps(fun)
    def call(*args):
        leaves, treedef = jax.tree_util.tree_flatten(args)
        signature = (treedef, tuple(jax.typeof(leaf) for leaf in leaves))
        if signature not in jaxprs:
            jaxpr, shapes = jax.make_jaxpr(jitted, return_shape=True)(*args)
            jaxprs[signature] = jaxpr, jax.tree_util.tree_structure(shapes)
        jaxpr, out_tree = jaxprs[signature]
        return jax.tree_util.tree_unflatten(out_tree, jaxpr_as_fun(jaxpr)(*leaves))

    return call


def runs_folded(fun):
    """``fun`` (positional array or pytree arguments, each leaf with a leading run axis R; a
    pytree result likewise) with a vmap rule that folds the mapped axis into R: a batch is one
    call of ``fun`` over all its runs, so a loop inside it runs as often as its longest run needs
    and the loop's predicate is never batched (a batched one makes every iteration select every
    leaf of the carry). Arguments not batched are broadcast to every member."""

    @custom_vmap
    @functools.wraps(fun)
    def folded(*args):
        return fun(*args)

    @folded.def_vmap
    def rule(axis_size, in_batched, *args):
        fold = functools.partial(fold_runs, axis_size=axis_size)
        out = folded(*(jax.tree_util.tree_map(fold, arg, batched)
                       for arg, batched in zip(args, in_batched)))
        out = jax.tree_util.tree_map(lambda x: unfold_runs(x, axis_size), out)
        return out, jax.tree_util.tree_map(lambda _: True, out)

    return folded


def fold_runs(x: jax.Array, batched: bool, axis_size: int) -> jax.Array:
    """``[axis_size * R, ...]``: a vmapped ``x`` (``[axis_size, R, ...]``, or ``[R, ...]`` when
    not ``batched``, then the same for every member) with the mapped axis folded into its leading
    run axis R."""
    if not batched:
        x = jnp.broadcast_to(x, (axis_size,) + x.shape)
    return x.reshape((x.shape[0] * x.shape[1],) + x.shape[2:])


def unfold_runs(x: jax.Array, axis_size: int) -> jax.Array:
    """``[axis_size, R, ...]``: :func:`fold_runs` undone on a result ``x`` (``[axis_size * R,
    ...]``)."""
    return x.reshape((axis_size, x.shape[0] // axis_size) + x.shape[1:])
