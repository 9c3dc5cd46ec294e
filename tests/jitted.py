"""Library functions the tests call on concrete arrays, each through one jitted wrapper: one
program per shape and static option, where applied outside ``jit`` each of its operations would
be lowered, looked up and run as a program of its own (``docs/testing.md``). Maps, tables and
walks are passed as arguments, never closed over. A wrapper used by one test file only lives in
that file."""
import jax

from jaxswarm.dynamic import events
from jaxswarm.swarm import aco, rfd
from jaxswarm.swarm.aco import ant_system, bug2
from jaxswarm.swarm.walking.log import from_rows

apply_event = jax.jit(events.apply_event)
change = jax.jit(events.change, static_argnums=0)  # the swarm
rows_log = jax.jit(from_rows, static_argnames="max_steps")
ant_system_update = jax.jit(ant_system.ant_system_update)
deposit = jax.jit(aco.deposit)
transition_rule = jax.jit(aco.transition_rule, static_argnames=("direction", "goal_distance"))
bug2_path = jax.jit(bug2.bug2_path)
graded_transition = jax.jit(rfd.graded_transition)
settle = jax.jit(rfd.settle)
erode_banks = jax.jit(rfd.erode_banks)
