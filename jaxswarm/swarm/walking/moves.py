"""Work on a walk's moves cut to the moves made in the whole batch.

Rows of moves are as wide as the step budget (a walk's paths written out, a path's nodes), yet
agents stop long before it: a drop on a 64 x 64 map makes about a hundred moves of a budget of
1,023. :func:`on_moves` applies a function to the first ``W`` move columns of such rows only, and
:func:`on_walk` to a walk's paths and slots written out from its log (:mod:`.log`) to ``W`` columns
only, ``W`` the smallest of :func:`move_widths` that holds every agent's moves, of every run of the
batch (a ``vmap`` of walks, nested or not, shares one ``W``: one branch of a ``lax.switch`` runs,
where a ``W`` per run would make ``vmap`` run every branch). Past an agent's last move every column
is padding; a function that gives padding no weight (a move that was not made takes no soil and
deposits nothing) returns the same bits on ``W`` columns as on all of them, when it reduces the
columns by scans, scatters in column order, or :func:`~jaxswarm.runtime.arithmetic.ordered_sum` and
:func:`~jaxswarm.runtime.arithmetic.ordered_cumsum` (their zero-padded power-of-two trees add the
same terms in the same order on any power-of-two width that holds them, and a running sum's first
``W`` terms do not depend on the length). Agents whose moves the function gives no weight (ants
that did not arrive deposit nothing) may be left out of the width (``used``), so it is set by the
walks that matter: the drops of a swarm's first iterations that wander for the whole step budget
without arriving do not make every agent's row that long.

A rule that takes the agents one after another (IWD's drops that arrived change the soil in agent
order) folds over the used agents only (:func:`fold_agents`): each agent's row is read from the log
when its turn comes, so a walk in which few agents matter costs little after it. A rule that works
backwards along the paths a few columns at a time (rfd_graded's carving) folds over the blocks of
columns the batch's paths reach (:func:`fold_blocks_backwards`), every run of a batch in each step.
"""
from __future__ import annotations

import functools
from typing import Any, Callable

import jax
import jax.numpy as jnp
from jax.custom_batching import custom_vmap

from jaxswarm.runtime.batching import fold_runs, unfold_runs
from jaxswarm.swarm.walking.log import MoveLog, agent_rows, columns, paths

NARROWEST = 128
"""The narrowest width :func:`~jaxswarm.swarm.walking.moves.move_widths` offers."""

GROWTH = 4
"""Each width of :func:`~jaxswarm.swarm.walking.moves.move_widths` is this times the one
before. Every width is a branch to compile, and a narrower one saves the moves' work of an
iteration that needs no more (the trade measured: ``docs/performance.md``)."""


def move_widths(columns: int) -> tuple[int, ...]:
    """The widths (static, ascending) :func:`on_moves` chooses from for ``columns`` move
    columns: :data:`~jaxswarm.swarm.walking.moves.NARROWEST` times the powers of
    :data:`~jaxswarm.swarm.walking.moves.GROWTH` below ``columns``, then ``columns``."""
    widths = []
    width = NARROWEST
    while width < columns:
        widths.append(width)
        width *= GROWTH
    return tuple(widths) + (columns,)


def on_moves(function: Callable, moves: jax.Array, columns: Any, per_run: Any = None,
             shared: Any = None, *, used: jax.Array | None = None):
    """``function(cut, per_run, shared)`` for one run's walk, ``cut`` its move ``columns`` cut to
    the width that holds the moves of every agent of the batch that ``function`` uses.

    Args:
      function: ``(cut, per_run, shared) -> outputs``, ``cut`` the leaves of ``columns`` with
        their axis 1 cut to some width ``W >= max(moves)``; its outputs must not depend on ``W``
        (module docstring), in values or shapes. It takes the traced arrays it needs as
        arguments (``per_run``, ``shared``) rather than closing over them.
      moves: i32[A] the columns each agent's row uses: its moves (its nodes, where the
        columns are a path's nodes).
      columns: a pytree of ``[A, C, ...]`` arrays, one column per move (C the step budget).
      per_run: a pytree of this run's other inputs (batched like the walk).
      shared: a pytree of inputs every run of a batch shares (the map); when a ``vmap`` batches
        one of its leaves, each run of that ``vmap`` picks its own width.
      used: bool[A] the agents whose rows ``function``'s outputs depend on (None: all); the
        others' rows may be cut short, and ``function`` must give them no weight (a drop whose
        soil changes are dropped, an ant that deposits nothing), so that a long walk nothing
        uses does not widen the cut.

    Returns:
      ``function``'s outputs.
    """
    count = jax.tree_util.tree_leaves(columns)[0].shape[1]
    return _apply(function, _cut_columns, move_widths(count), moves, columns, per_run, shared,
                  used)


def on_walk(function: Callable, log: MoveLog, per_run: Any = None, shared: Any = None, *,
            used: jax.Array | None = None):
    """:func:`on_moves` of a walk's moves: ``function((path, slots), per_run, shared)`` with
    ``(path i32[A, W + 1], slots [A, W])`` the walk's paths and slots written out from its
    ``log`` to the width ``W`` that holds the moves of every agent of the batch that
    ``function`` uses (:func:`.log.paths`); arguments and outputs as :func:`on_moves`'s."""
    return _apply(function, paths, move_widths(log.max_steps), log.moves, log, per_run, shared,
                  used)


def _cut_columns(columns, width: int):
    """``columns`` (a pytree of ``[A, C, ...]`` arrays) cut to ``width`` columns."""
    return jax.tree_util.tree_map(lambda x: x[:, :width], columns)


def _apply(function: Callable, cut: Callable, widths: tuple[int, ...], moves, columns, per_run,
           shared, used):
    """:func:`on_moves` of one run's ``columns``, cut to a width by ``cut(columns, width)``."""
    if used is not None:
        moves = jnp.where(used, moves, 0)
    apply = _runs_folded(functools.partial(_on_runs, function, cut, widths))
    return _one_run(apply, (moves, columns, per_run), shared)


def _one_run(apply: Callable, per_run: tuple, shared):
    """``apply(*per_run, shared)`` (a :func:`_runs_folded` function) of one run: a run axis of
    one added to ``per_run``'s leaves and taken off the outputs."""
    out = apply(*(jax.tree_util.tree_map(lambda x: jnp.asarray(x)[None], tree)
                  for tree in per_run), shared)
    return jax.tree_util.tree_map(lambda x: x[0], out)


def _runs_folded(on_runs: Callable):
    """``on_runs(*per_run, shared)`` of R runs (a leading axis R on every leaf of ``per_run``)
    with a ``vmap`` rule that folds the mapped axis into R, so that the width and the loops
    inside it are chosen once for the whole batch; when a ``vmap`` batches ``shared``, each of
    its members runs on its own."""

    # Jitted, the traced function keeps its constants (the widths, NumPy arrays the function
    # uses) inside its own program: custom_vmap refuses constants of its own once a vmapped
    # lax.cond has batched them.
    on_runs = jax.jit(on_runs)

    @custom_vmap
    def apply(*args):
        return on_runs(*args)

    @apply.def_vmap
    def batch_rule(axis_size, in_batched, *args):
        if any(jax.tree_util.tree_leaves(in_batched[-1])):
            axes = tuple(jax.tree_util.tree_map(lambda b: 0 if b else None, b)
                         for b in in_batched)
            out = jax.vmap(on_runs, in_axes=axes)(*args)
            return out, jax.tree_util.tree_map(lambda _: True, out)

        fold = functools.partial(fold_runs, axis_size=axis_size)
        folded = (jax.tree_util.tree_map(fold, tree, batched)
                  for tree, batched in zip(args[:-1], in_batched[:-1]))
        out = jax.tree_util.tree_map(lambda x: unfold_runs(x, axis_size),
                                     apply(*folded, args[-1]))
        return out, jax.tree_util.tree_map(lambda _: True, out)

    return apply


def _width_index(widths: tuple[int, ...], moves: jax.Array) -> jax.Array:
    """i32[]: the index in ``widths`` of the narrowest that holds every move of ``moves``."""
    most = jnp.max(moves)
    return jnp.sum(most > jnp.asarray(widths[:-1], most.dtype), dtype=jnp.int32)


def _on_runs(function: Callable, cut: Callable, widths: tuple[int, ...], moves, columns,
             per_run, shared):
    """``function`` of each of R runs on its ``columns`` cut (``cut``) to the narrowest of
    ``widths`` that holds every move of ``moves`` (i32[R, A])."""

    def within(width):
        def run(columns, per_run):
            return jax.vmap(lambda c, p: function(cut(c, width), p, shared))(columns, per_run)
        return run

    return jax.lax.switch(_width_index(widths, moves), [within(width) for width in widths],
                          columns, per_run)


def fold_agents(step: Callable, log: MoveLog, carry: Any, per_run: Any = None,
                shared: Any = None, *, used: jax.Array):
    """``carry`` after ``step`` of every used agent's walk, one agent after another in agent
    order, each agent's path read from ``log`` on its own: the work grows with the used agents
    and their moves, not with every agent's row (where :func:`on_walk` writes out all rows).

    A batch (a ``vmap`` of walks, nested or not) steps its runs together: the ``k``-th call
    takes each run's ``k``-th used agent, for ``k`` up to the most agents one run uses, on rows
    as wide as the narrowest of :func:`move_widths` that holds every used agent's moves.

    Args:
      step: ``(carry, agent, (path, slots), per_run, shared) -> carry``, ``agent`` i32[] and its
        row of :func:`~.log.paths` (``path i32[W + 1]``, ``slots [W]``, ``W`` any width that
        holds its moves; the outputs must not depend on ``W``). It is also called with
        ``agent = A`` (past the last) and a row of no moves, where a run has fewer used agents
        than another: it must then return ``carry`` as it was (a scatter of the agent's moves
        and of ``agent``'s entries with ``mode="drop"`` does).
      log: the walk's log.
      carry: a pytree, this run's state before the first used agent (batched like the walk).
      per_run: a pytree of this run's other inputs (batched like the walk).
      shared: a pytree of inputs every run of a batch shares (the map); when a ``vmap``
        batches one of its leaves, each run of that ``vmap`` is folded on its own.
      used: bool[A] the agents ``step`` takes, in agent order.

    Returns:
      ``carry`` after the last used agent.
    """
    apply = _runs_folded(functools.partial(_fold_runs, step, move_widths(log.max_steps)))
    return _one_run(apply, (log, used, carry, per_run), shared)


def _fold_runs(step: Callable, widths: tuple[int, ...], log: MoveLog, used, carry, per_run,
               shared):
    """:func:`fold_agents` of R runs (a leading axis R on ``log``, ``used``, ``carry`` and
    ``per_run``)."""
    agents = used.shape[1]
    order = jax.vmap(lambda u: jnp.nonzero(u, size=agents, fill_value=agents)[0])(used)
    count = jnp.max(jnp.sum(used, axis=1))
    on_run = jax.vmap(step, in_axes=(0, 0, 0, 0, None))

    def within(width):
        def one_agent(k, carry):
            agent = order[:, k]
            rows = jax.vmap(agent_rows, in_axes=(0, 0, None))(log, agent, width)
            return on_run(carry, agent, rows, per_run, shared)

        return lambda carry: jax.lax.fori_loop(0, count, one_agent, carry)

    return jax.lax.switch(_width_index(widths, jnp.where(used, log.moves, 0)),
                          [within(width) for width in widths], carry)


def fold_blocks_backwards(step: Callable, log: MoveLog, carry: Any, per_run: Any = None,
                          shared: Any = None, *, block: int):
    """``carry`` after ``step`` of every block of ``block`` path columns that holds a node of a
    path, from the last such block to the first (columns ``k * block .. (k + 1) * block - 1``
    for ``k`` down to 0): the work grows with the batch's longest path, not with the budget.

    A batch (a ``vmap`` of walks, nested or not) steps its runs together, in one loop from the
    last block any agent of the batch reached: a run whose paths end earlier first sees blocks
    past them (every node -1), on which ``step`` must return its carry as it was. One loop for
    the batch costs a step of every run for each block of the longest path; a small swarm's
    steps are cheap beside the loop's own cost per step, which the batch then pays once.

    Args:
      step: ``(carry, (nodes i32[A, block], slots [A, block]), per_run, shared) -> carry``, the
        block's columns of every agent's path and slots (:func:`~.log.columns`: -1 past a
        path's end; a path's last node has no move, so its slot reads -1).
      log: the walk's log.
      carry: a pytree, this run's state before the last block (batched like the walk).
      per_run: a pytree of this run's other inputs (batched like the walk).
      shared: a pytree of inputs every run of a batch shares (the map); when a ``vmap``
        batches one of its leaves, each run of that ``vmap`` is folded on its own.
      block: columns per step (static).

    Returns:
      ``carry`` after the first block.
    """
    apply = _runs_folded(functools.partial(_fold_blocks, step, block))
    return _one_run(apply, (log, carry, per_run), shared)


def _fold_blocks(step: Callable, block: int, log: MoveLog, carry, per_run, shared):
    """:func:`fold_blocks_backwards` of R runs (a leading axis R on ``log``, ``carry`` and
    ``per_run``)."""
    blocks = -(-(log.max_steps + 1) // block)
    # A path of m moves holds columns 0 .. m: the blocks up to column max(moves).
    reached = jnp.minimum((jnp.max(log.moves) + block) // block, blocks)
    on_run = jax.vmap(step, in_axes=(0, 0, 0, None))
    read = jax.vmap(columns, in_axes=(0, None))

    def one_block(k, carry):
        first = (reached - 1 - k) * block
        return on_run(carry, read(log, first + jnp.arange(block)), per_run, shared)

    return jax.lax.fori_loop(0, reached, one_block, carry)
