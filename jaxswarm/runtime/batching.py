"""Batching rules for loops whose trip count differs from one batch member to the next.

Under ``vmap`` a ``lax.while_loop`` runs until its last member is done, and every iteration
works on the whole batch: a relaxation that needs 1 sweep in most runs of a sweep and 30 in a
few costs 30 sweeps for each. :func:`one_at_a_time` gives such a function a batching rule that
maps it over the batch one member at a time instead, so each member pays for its own loop.
"""
from __future__ import annotations

import functools

import jax
from jax.custom_batching import custom_vmap


def one_at_a_time(fun):
    """``fun`` (positional array or pytree arguments, pytree result) with a vmap rule that
    applies it to the batch members one after the other (``lax.map``) rather than to all of
    them at once. Results are the same as ``vmap``'s; pays where members' loops run for very
    different numbers of iterations and one member's iteration already fills the machine.
    Arguments not batched are shared by every member, not copied."""

    @custom_vmap
    @functools.wraps(fun)
    def mapped(*args):
        return fun(*args)

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
