"""Every transition rule and every memory update against a hand computation.

The maps are 3 x 3 grids (nodes ``y * 3 + x``, 8-connected, diagonals sqrt 2, no corner
cutting; slot order E S W N SE SW NW NE) or small variants with obstacles, and for rfd_graded's
step, which starts from fresh memory, a corridor cut out of the shared map's shape: one
iteration of the run its conformance checks compile (``tests/sizes.py``). Expected numbers are
computed here from the papers' formulas with ``math`` (see tests/hand.py for the geometry,
written out independently of the library), never by calling the code under test.

RFD paper (000_eee128c5dbb1fda2): eq. 1-3 (RFD transition), eq. 4-5 (erosion, sediment), eq. 6
(RFD*), eq. 7-9 (Ant System). Max-Min ACO paper (001_5617ee2aab5d0bc9): eq. 1 and Algorithm 1.
"""
from __future__ import annotations

import dataclasses
import functools
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
import sizes
from graphs import wandering_walk
from hand import (E, N, NE, NW, R2, S, SE, SW, W, check_lattice, distance, fake_walk, moves,
                  node, probabilities, slot, step_length, xy)
from jitted import (ant_system_update, deposit, erode_banks, graded_transition, settle,
                    transition_rule)

from jaxswarm.exact import dijkstra
from jaxswarm.maps.random import random_path_map
from jaxswarm.runtime.arithmetic import ordered_sum
from jaxswarm.swarm import aco, make, make_task, rfd, run
from jaxswarm.swarm.aco.bug2 import first_ant_path
from jaxswarm.swarm.rfd import (DEFAULT_GRADED, RFDParams, RFDStarConfig, RFDStarParams,
                                add_compensated, paper, river)
from jaxswarm.swarm.walking import FORCED
from jaxswarm.world.graph import grid_graph, path_map_graph

REL = 1e-5
NONE = -math.inf

# The functions under test, jitted: each is one program per map shape (and static option), where
# outside jit each of its operations would be lowered and run as a program of its own. Maps,
# tables and walks are passed as arguments, never closed over.
rfd_transition = jax.jit(rfd.rfd_transition)
rfd_star_transition = jax.jit(rfd.rfd_star_transition, static_argnums=0)  # the config
erosion_change = jax.jit(rfd.erosion_change)
sediment_where_stuck = jax.jit(river.sediment_where_stuck, static_argnums=0)  # the node count
carve = jax.jit(rfd.carve)
blind_alleys = jax.jit(rfd.blind_alleys)


def approx(expected):
    """rel 1e-5; exact zeros are allowed float32 dust of 1e-6."""
    return pytest.approx(expected, rel=REL, abs=1e-6)


def grid(width=3, height=3, blocked=()):
    """A grid graph with the given nodes blocked, checked against the hand-written lattice."""
    obstacles = np.zeros((height, width), bool)
    for v in blocked:
        obstacles[v // width, v % width] = True
    graph = grid_graph(obstacles)
    check_lattice(graph, width, height, blocked)
    return graph


def row(table, i):
    """{slot: log-weight} of node i, -inf entries included."""
    return {k: float(v) for k, v in enumerate(np.asarray(table)[i])}


def expect_row(table, i, expected: dict):
    """Row i of a log-weight table is ``expected`` on its slots and -inf everywhere else."""
    got = row(table, i)
    for k in range(len(got)):
        want = expected.get(k, NONE)
        if want == NONE:
            assert got[k] == NONE, (i, k, got[k])
        elif want >= FORCED:
            assert got[k] >= FORCED * (1 - 1e-6), (i, k, got[k])
        else:
            assert got[k] == approx(want), (i, k)


def f32(**values):
    return {name: np.float32(value) for name, value in values.items()}


_JITTED = {}


def step(swarm, state, graph, task, params):
    """One jitted step (one compiled step per swarm and map shape)."""
    if swarm not in _JITTED:
        _JITTED[swarm] = jax.jit(swarm.step)
    return _JITTED[swarm](state, graph, task, params)


# ------------------------------------------------------------------------------------------------
# RFD, eqs. 1-3


ALT1 = [3.0, 1.0, 2.0,
        2.0, 2.0, 0.5,
        4.0, 2.0, 0.0]


def test_rfd_eq1_downhill_uphill_and_flat_weights():
    """Eq. 2: gradient = (alt(i) - alt(j)) / distance. Eq. 1: weight gradient (downhill),
    omega / |gradient| (uphill), delta (flat); eq. 3: P = weight / total.

    Node 4 (alt 2): E->5 (0.5) g 1.5; S->7, W->3, NE->2 (all 2) flat: delta; N->1 (1) g 1;
    SE->8 (0) g 2/sqrt2 = sqrt2; SW->6 (4) g -sqrt2: omega/sqrt2; NW->0 (3) g -1/sqrt2:
    omega*sqrt2. Corner 0 (alt 3): E->1 g 2, S->3 g 1, SE->4 g 1/sqrt2, nothing else.
    Goal 8 (alt 0): W->7 g -2: omega/2; N->5 g -0.5: omega/0.5; NW->4 g -sqrt2: omega/sqrt2.
    """
    graph = grid()
    task = make_task(graph, 0, 8)
    omega, delta = 0.3, 0.2
    params = RFDParams(**f32(initial_height=1.0, erosion=1.0, sediment=0.1, omega=omega,
                             delta=delta))
    table = rfd_transition(graph, task, np.array(ALT1, np.float32), params)
    centre = {E: 1.5, S: delta, W: delta, N: 1.0, SE: R2, SW: omega / R2, NW: omega * R2,
              NE: delta}
    expect_row(table, 4, {k: math.log(w) for k, w in centre.items()})
    total = sum(centre.values())
    assert probabilities(np.asarray(table)[4]) == approx({k: w / total for k, w in centre.items()})
    corner = {E: 2.0, S: 1.0, SE: 1 / R2}
    expect_row(table, 0, {k: math.log(w) for k, w in corner.items()})
    total = sum(corner.values())
    assert probabilities(np.asarray(table)[0]) == approx({k: w / total for k, w in corner.items()})
    expect_row(table, 8, {W: math.log(omega / 2), N: math.log(omega / 0.5),
                          NW: math.log(omega / R2)})


# ------------------------------------------------------------------------------------------------
# RFD*, eq. 6


ALT6 = [2.0, 1.5, 1.0,
        2.5, 1.0, 0.5,
        1.0, 0.5, 0.0]


@pytest.mark.parametrize("max_climb", [None, 0.5])
def test_rfd_star_eq6_weights_forced_goal_and_max_climb(max_climb):
    """Eq. 6: P ~ p_base ** gradient / d_j ** alpha, d_j the straight line from j to the goal
    (2, 2). p_base 3, alpha 2. The goal is forced whenever adjacent (d_goal = 0).

    Node 0 (2.0): E->1 (1.5) g 0.5, d sqrt5; S->3 (2.5) g -0.5, d sqrt5; SE->4 (1.0)
    g 1/sqrt2, d sqrt2. Node 4 (1.0): SE is the goal: forced; E->5 g .5 d 1; S->7 g .5 d 1;
    W->3 g -1.5 d sqrt5; N->1 g -.5 d sqrt5; SW->6 g 0 d 2; NW->0 g -1/sqrt2 d sqrt8; NE->2 g 0
    d 2. max_climb 0.5 bans g < -0.5: W and NW of node 4 (N, g = -0.5 exactly, stays).
    """
    graph = grid()
    task = make_task(graph, 0, 8)
    p_base, alpha = 3.0, 2.0
    params = RFDStarParams(**f32(p_base=p_base, alpha=alpha, initial_height=1.0, erosion=1.0,
                                 sediment=0.1))
    config = RFDStarConfig(num_agents=1, max_climb=max_climb)
    table = rfd_star_transition(config, graph, task, np.array(ALT6, np.float32), params)

    def logw(g, d):
        if max_climb is not None and g < -max_climb - 1e-12:
            return NONE
        return g * math.log(p_base) - alpha * math.log(d)

    node0 = {E: logw(0.5, math.sqrt(5)), S: logw(-0.5, math.sqrt(5)),
             SE: logw(1 / R2, R2)}
    expect_row(table, 0, node0)
    weights = {k: math.exp(v) for k, v in node0.items()}
    total = sum(weights.values())
    assert probabilities(np.asarray(table)[0]) == approx({k: w / total
                                                          for k, w in weights.items()})
    expect_row(table, 4, {E: logw(0.5, 1), S: logw(0.5, 1), W: logw(-1.5, math.sqrt(5)),
                          N: logw(-0.5, math.sqrt(5)), SE: FORCED, SW: logw(0.0, 2),
                          NW: logw(-1 / R2, math.sqrt(8)), NE: logw(0.0, 2)})
    assert probabilities(np.asarray(table)[4])[SE] == approx(1.0)
    # Node 5 (0.5) next to the goal: S forced; N->2 (1.0) g -0.5, W->4 g -0.5 (d 2 and sqrt2).
    expect_row(table, 5, {S: FORCED, N: logw(-0.5, 2), W: logw(-0.5, R2),
                          SW: logw(0.0, 1), NW: logw(-1 / R2, math.sqrt(5))})
    if max_climb is not None:
        assert row(table, 4)[W] == NONE and row(table, 4)[NW] == NONE


# ------------------------------------------------------------------------------------------------
# RFD, eqs. 4-5 and the stuck drop


ALT4 = [3.0, 2.0, 2.5,
        2.8, 1.5, 1.0,
        3.0, 2.0, 0.0]


# The three drops of the hand tests on ALT4: A 0->4->8 and B 0->1->2->5->8 arrived, C 0->3->6
# got stuck. Each move is (node, gradient, altitude of the node it goes to).
THREE_DROPS = [[0, 4, 8], [0, 1, 2, 5, 8], [0, 3, 6]]
MOVES_A_B = [(0, 1.5 / R2, 1.5), (4, 1.5 / R2, 0.0),
             (0, 1.0, 2.0), (1, -0.5, 2.5), (2, 1.5, 1.0), (5, 1.0, 0.0)]
MOVES_C = [(0, 0.2, 2.8), (3, -0.2, 3.0)]


def three_drops():
    return fake_walk(THREE_DROPS, 9, arrived=[True, True, False], stuck=[False, False, True],
                     budget=8)


@pytest.mark.parametrize("law", ["linear", "exponential"])
@pytest.mark.parametrize("travelled", [False, True])
def test_erosion_eq4_eq5_by_hand_with_three_drops(law, travelled):
    """Eq. 4: each move i->j of an eroding drop lowers i by E / ((N-1) D) * gradient (linear,
    negative gradients erode nothing) or * p_base ** gradient (exponential, then at most down to
    the lowest node i's eroding moves go to); eq. 5: every node gains the eroded total / (N - 1).
    N = 9, D = 3 (every drop counts in D), E = 2.4: E / ((N-1) D) = 0.1, p_base = 2.

    Arrived only, C erodes nothing; all travelled paths, C's moves 0->3 (gradient 0.2) and 3->6
    (-0.2) erode too. Exponential: node 1 (only an uphill move, to 2.5) and node 3 (only an
    uphill move, to 3.0) are below every node they go to: they erode nothing; every other node
    asks for less than its drop to its lowest head (node 0: 0.1 (2 ** 1.06 + 2 + 2 ** 0.2) =
    0.52 < 3 - 1.5)."""
    graph = grid()
    c, p_base = 2.4 / (8 * 3), 2.0
    shape = (lambda g: max(g, 0.0)) if law == "linear" else (lambda g: p_base ** g)
    moves_made = MOVES_A_B + (MOVES_C if travelled else [])
    asked, outlet = [0.0] * 9, [math.inf] * 9
    for i, g, head in moves_made:
        asked[i] += c * shape(g)
        outlet[i] = min(outlet[i], head)
    eroded = asked if law == "linear" else [min(asked[i], max(ALT4[i] - outlet[i], 0.0))
                                            for i in range(9)]
    total = sum(eroded)
    expected = [ALT4[i] - eroded[i] + total / 8 for i in range(9)]
    drops = three_drops()
    eroding = np.array([True, True, travelled])
    change = erosion_change(graph, np.array(ALT4, np.float32), drops, eroding,
                            np.float32(2.4), None if law == "linear" else np.float32(p_base))
    assert (np.asarray(ALT4) + np.asarray(change)).tolist() == approx(expected)
    assert eroded[1] == 0.0 and expected[1] == approx(2.0 + total / 8)


def test_exponential_erosion_stops_at_the_lowest_node_a_node_drains_to():
    """Exponential law, E = 24 (E / ((N-1) D) = 1), p_base = 2, drops A and B of ALT4 arrived:
    every node asks for more than its drop to its lowest head, and gives exactly that drop.
    Node 0 asks 2 ** (1.5 / sqrt2) + 2 ** 1 = 4.09 and goes to 4 (1.5) and 1 (2.0): gives 1.5.
    Node 4 asks 2.09, drains to the goal (0): gives 1.5. Node 1 asks 2 ** -0.5 = 0.71 but its
    only move climbs to 2.5: gives 0. Node 2 asks 2 ** 1.5 = 2.83, drains to 5 (1.0): gives 1.5.
    Node 5 asks 2, drains to the goal: gives 1.0. Total 5.5: every node gains 5.5 / 8 = 0.6875.
    After the erosion (before eq. 5) node 0 is at 1.5, the altitude of node 4: not below it."""
    graph = grid()
    drops = three_drops()
    change = erosion_change(graph, np.array(ALT4, np.float32), drops, drops.arrived,
                            np.float32(24.0), np.float32(2.0))
    eroded = {0: 1.5, 4: 1.5, 1: 0.0, 2: 1.5, 5: 1.0}
    expected = [ALT4[i] - eroded.get(i, 0.0) + 5.5 / 8 for i in range(9)]
    assert (np.asarray(ALT4) + np.asarray(change)).tolist() == approx(expected)
    # Unbounded, node 0 would give 4.09 and end 2.6 below node 4.
    assert 2.0 ** (1.5 / R2) + 2.0 > ALT4[0] - ALT4[4] + 2.5


@jax.jit
def whole_rows_erosion(graph, altitude, drops, erosion, p_base):
    """Eqs. 4 and 5 as :func:`erosion_change` before the cut: over every drop's whole row (the
    step budget's columns), the arrived drops eroding."""
    eroded = paper._eroded((drops.path, drops.slots), (altitude, drops.arrived, erosion, p_base),
                           graph)
    return ordered_sum(eroded) / (graph.num_nodes - 1) - eroded


@pytest.mark.parametrize("p_base", [None, 2.0])
def test_drops_that_do_not_erode_leave_the_erosion_as_their_whole_rows_would(p_base):
    # Only arrived drops erode; some stuck drops walk longer than the arrived ones' width.
    graph, drops = wandering_walk()
    altitude = jax.random.uniform(jax.random.key(1), (graph.num_nodes,), minval=0.5, maxval=1.5)
    p_base = None if p_base is None else np.float32(p_base)
    got = erosion_change(graph, altitude, drops, drops.arrived, np.float32(3.0), p_base)
    # Every drop's whole row (the step budget's columns), as before the cut: the same bits.
    want = whole_rows_erosion(graph, altitude, drops, np.float32(3.0), p_base)
    np.testing.assert_array_equal(np.asarray(got), np.asarray(want))


# The step tests of rfd and rfd_star share one map shape, a row of 4 nodes, and 3 drops: one
# compiled step per swarm. N = 4 counts the blocked node.
DROPS = 3


def forced_corridor():
    """Start 0, goal 2, node 3 blocked: every drop walks 0 -> 1 -> 2."""
    graph = grid(4, 1, blocked=[3])
    return graph, make_task(graph, 0, 2)


def dead_end():
    """[start, ., #, goal]: every drop walks 0 -> 1 and is stuck (0 visited, 2 blocked)."""
    graph = grid(4, 1, blocked=[2])
    return graph, make_task(graph, 0, 3)


CORRIDOR = [1.0, 1.5, 0.0, 1.0]  # the altitudes of the forced corridor's step


@pytest.mark.parametrize("name, config, erosion, p_base, expected", [
    # c = E / ((N-1) D) = E / 9. Linear: node 0 (g -0.5) erodes nothing, node 1 (g 1.5) loses
    # 3 drops * c * 1.5; every node gains the total / 3, the blocked one too; the goal is reset
    # to 0.
    ("rfd", {}, 0.9, None, [1.0 + 0.15, 1.5 - 0.45 + 0.15, 0.0, 1.0 + 0.15]),
    ("rfd_star", {}, 0.9, 2.0, [1.0 + 0.15, 1.5 - 0.45 + 0.15, 0.0, 1.0 + 0.15]),
    # Exponential, p_base 9: node 0 asks 3 * 0.1 * 9 ** -0.5 = 0.1 but its move climbs (to
    # 1.5): it gives 0; node 1 asks 3 * 0.1 * 9 ** 1.5 = 8.1 and drains to the goal (0): it gives
    # 1.5. Every node gains 1.5 / 3. (Unbounded: [3.63, -3.87 clamped to 0, 0, 3.73].)
    ("rfd_star", {"erosion_law": "exponential"}, 0.9, 9.0,
     [1.0 + 0.5, 1.5 - 1.5 + 0.5, 0.0, 1.0 + 0.5]),
    # E = 9 (c = 1): node 1 loses 4.5 and gains 1.5: -1.5, clamped at 0; node 0 gains 1.5.
    ("rfd", {}, 9.0, None, [2.5, 0.0, 0.0, 2.5]),
])
def test_one_step_on_a_forced_corridor_erodes_by_eq4_eq5_then_clamps(name, config, erosion,
                                                                      p_base, expected):
    graph, task = forced_corridor()
    swarm = make(name, num_agents=DROPS, **config)
    values = dict(erosion=erosion, initial_height=1.0, sediment=0.3)
    if p_base is not None:
        values.update(p_base=p_base, alpha=1.0)
    params = swarm.default_params._replace(**f32(**values))
    state = swarm.init(jax.random.key(0), graph, task, params)
    state = dataclasses.replace(state, altitude=np.array(CORRIDOR, np.float32))
    state, info = step(swarm, state, graph, task, params)
    assert float(info.arrived) == 1.0
    assert np.asarray(state.altitude).tolist() == approx(expected)
    assert float(state.best_cost) == approx(2.0)
    residual = np.asarray(state.residual)
    assert residual[2] == 0.0 and (expected[1] > 0.0 or residual[1] == 0.0)  # goal, clamped


@pytest.mark.parametrize("name", ["rfd", "rfd_star"])
def test_erosion_steps_of_1e9_add_up_over_1000_iterations(name):
    """The forced corridor 0 -> 1 -> goal 2 at altitudes 1, 1, 0 (the blocked node 3 at 1), three
    drops, E = 9e-9, no sediment: c = E / ((N-1) D) = 1e-9. Each iteration node 1 (gradient 1 to
    the goal) loses 3 c = 3e-9, node 0 (gradient about 0 to node 1) about nothing, and eq. 5
    gives every node 3e-9 / 3 = 1e-9: node 0 rises by 1e-9 and node 1 sinks by 2e-9 an
    iteration. Both steps are far below half the float32 spacing at 1 (3e-8 below it, 6e-8
    above), so without the residual neither altitude would ever move; with it, after 1000
    iterations node 0 is 1 + 1e-6 and node 1 is 1 - 2e-6, to within a float32 spacing (1.2e-7
    above 1, 6e-8 below)."""
    graph, task = forced_corridor()
    swarm = make(name, num_agents=DROPS)
    params = swarm.default_params._replace(**f32(erosion=9e-9, initial_height=1.0,
                                                 sediment=0.0))
    state = swarm.init(jax.random.key(0), graph, task, params)
    for _ in range(1000):
        state, _ = step(swarm, state, graph, task, params)
    altitude, residual = np.asarray(state.altitude), np.asarray(state.residual)
    assert altitude[0] - 1.0 == pytest.approx(1e-6, abs=1.2e-7)
    assert 1.0 - altitude[1] == pytest.approx(2e-6, abs=6e-8)
    # What the altitudes do not show yet is in the residual.
    assert (altitude[:2].astype(np.float64) + residual[:2]).tolist() == pytest.approx(
        [1 + 1e-6, 1 - 2e-6], abs=1e-9)
    assert altitude[2] == 0.0 and residual[2] == 0.0


def test_add_compensated_keeps_steps_below_the_float32_spacing():
    """1e-9 added 1000 times to altitude 1.0: a plain float32 sum stays at 1.0 (1 + 1e-9 rounds
    back to 1); the compensated sum reaches 1 + 1e-6 to within one spacing (1.2e-7), and the
    altitude plus its residual is 1 + 1000 * f32(1e-9) = 1 + 9.9999997e-7 almost exactly."""
    tiny = jnp.full((1,), 1e-9, jnp.float32)

    def add(_, carry):
        plain, altitude, residual = carry
        return (plain + tiny, *add_compensated(altitude, residual, tiny))

    one = jnp.ones((1,), jnp.float32)
    plain, altitude, residual = jax.device_get(jax.jit(lambda: jax.lax.fori_loop(
        0, 1000, add, (one, one, jnp.zeros((1,), jnp.float32))))())
    assert float(plain[0]) == 1.0
    assert float(altitude[0]) - 1.0 == pytest.approx(1e-6, abs=1.2e-7)
    assert float(altitude[0]) + float(residual[0]) == pytest.approx(
        1.0 + 1000 * float(np.float32(1e-9)), abs=1e-12)
    # Eager, without XLA's fusion, the same bits.
    eager = (one, one, jnp.zeros((1,), jnp.float32))
    for i in range(1000):
        eager = add(i, eager)
    eager = jax.device_get(eager)
    assert float(eager[1][0]) == float(altitude[0]) and float(eager[2][0]) == float(residual[0])


def test_a_stuck_drop_deposits_sediment_where_it_stands():
    """sediment_where_stuck: each stuck drop adds ``sediment`` on its node. Stuck at 3, 3 and 5:
    node 3 gains 2 * 0.25, node 5 gains 0.25; the drop that ran out of steps at 7 deposits
    nothing."""
    drops = fake_walk([[0, 3], [0, 3], [0, 1, 2, 5], [0, 4, 7]], 9,
                      arrived=[False] * 4, stuck=[True, True, True, False])
    got = sediment_where_stuck(9, drops, np.float32(0.25))
    expected = [0.0] * 9
    expected[3] += 0.5
    expected[5] += 0.25
    assert np.asarray(got).tolist() == approx(expected)


STUCK_SWITCHES = dict(fill_blind_alleys=True, erode="travelled")
"""RFD*'s two switches for drops that do not arrive, in one swarm (one compiled step) for the two
tests below: each test's params leave the other switch nothing to do (the trail it erodes is
flat; the alley it fills gets sediment 0)."""


@pytest.mark.parametrize("name, config, expected_gain", [
    ("rfd", {}, 3 * 0.25),  # three stuck drops, each deposits 0.25 on node 1
    ("rfd_star", {}, 3 * 0.25),
    ("rfd_star", STUCK_SWITCHES, 0.25),  # the alley {1} is filled once
])
def test_one_step_where_every_drop_gets_stuck(name, config, expected_gain):
    """The dead end: every drop walks 0 -> 1 and is stuck. No drop arrived and the trail 0 -> 1
    is flat: no erosion, eq. 5 adds 0; node 1 gains the sediment; the blocked node keeps its
    initial height 1, the goal 0."""
    graph, task = dead_end()
    swarm = make(name, num_agents=DROPS, **config)
    params = swarm.default_params._replace(**f32(sediment=0.25, initial_height=1.0,
                                                 erosion=1.0))
    state = swarm.init(jax.random.key(1), graph, task, params)
    state, info = step(swarm, state, graph, task, params)
    assert float(info.arrived) == 0.0
    assert np.asarray(state.altitude).tolist() == approx([1.0, 1.0 + expected_gain, 1.0, 0.0])


@pytest.mark.parametrize("config, expected", [
    # No drop arrived: nothing erodes, eq. 5 adds 0.
    pytest.param({}, [1.0, 0.5, 1.0, 0.0], id="arrived"),
    # Every drop's trail 0 -> 1 (gradient 0.5) erodes: node 0 loses 3 drops * 0.1 * 0.5 = 0.15,
    # every node gains 0.15 / 3 = 0.05 (the blocked node too: eq. 5's "all nodes").
    pytest.param(STUCK_SWITCHES, [1.0 - 0.15 + 0.05, 0.5 + 0.05, 1.0 + 0.05, 0.0],
                 id="travelled"),
])
def test_rfd_star_erodes_the_trails_of_stuck_drops_only_when_told(config, expected):
    """The dead end at altitudes 1, 0.5, 1, 0: every drop walks 0 -> 1 and is stuck, no
    sediment. N = 4, D = 3, E = 0.9: E / ((N-1) D) = 0.1."""
    graph, task = dead_end()
    swarm = make("rfd_star", num_agents=DROPS, **config)
    params = swarm.default_params._replace(**f32(sediment=0.0, initial_height=1.0,
                                                 erosion=0.9))
    state = swarm.init(jax.random.key(1), graph, task, params)
    state = dataclasses.replace(state, altitude=np.array([1.0, 0.5, 1.0, 0.0], np.float32))
    state, info = step(swarm, state, graph, task, params)
    assert float(info.arrived) == 0.0
    assert np.asarray(state.altitude).tolist() == approx(expected)


# ------------------------------------------------------------------------------------------------
# Ant System (eq. 7), ACO*, Improved Max-Min transitions


def pheromone_table(scale=1.0):
    """A pheromone table with a different value on every slot: 0.5 + 0.1 k + 0.05 i."""
    i, k = np.meshgrid(np.arange(9), np.arange(8), indexing="ij")
    return (scale * (0.5 + 0.1 * k + 0.05 * i)).astype(np.float32)


def tau(i, k, scale=1.0):
    return scale * (0.5 + 0.1 * k + 0.05 * i)


@pytest.mark.parametrize("alpha, beta", [(1.0, 0.0), (1.0, 1.0), (2.0, 1.0)])
def test_ant_system_eq7_probabilities(alpha, beta):
    """Eq. 7 (alpha 1, beta 0): P(i, j) = tau_ij / sum_l tau_il over the admissible slots; with
    beta > 0, tau ** alpha * (1 / length) ** beta. Node 1 is blocked, so node 4 may go E, S, W,
    SE, SW (N is blocked; NW and NE would cut the corner at node 1)."""
    graph = grid(blocked=[1])
    task = make_task(graph, 0, 8)
    params = aco.DEFAULT_ANT_SYSTEM._replace(**f32(alpha=alpha, beta=beta))
    table = transition_rule(graph, task, pheromone_table(), params)
    admissible = moves(4, blocked=[1])
    assert sorted(admissible) == [E, S, W, SE, SW]
    logw = {k: alpha * math.log(tau(4, k)) - beta * math.log(step_length(4, j))
            for k, j in admissible.items()}
    expect_row(table, 4, logw)
    weights = {k: tau(4, k) ** alpha / step_length(4, j) ** beta for k, j in admissible.items()}
    total = sum(weights.values())
    assert probabilities(np.asarray(table)[4]) == approx({k: w / total
                                                          for k, w in weights.items()})
    if beta == 0.0:  # literally eq. 7
        total = sum(tau(4, k) for k in admissible)
        assert probabilities(np.asarray(table)[4]) == approx({k: tau(4, k) / total
                                                              for k in admissible})
    expect_row(table, 1, {})  # a blocked node has no move


def test_aco_star_weight_divides_by_goal_distance_and_forces_the_goal():
    """ACO*: tau ** alpha * (1/length) ** beta / d_j ** alpha_goal, goal (2, 2) forced when
    adjacent. alpha 1, beta 1, alpha_goal 3. Node 0: E->1 and S->3 at d sqrt5, SE->4 (length
    sqrt2) at d sqrt2. Node 5: S is the goal."""
    graph = grid()
    task = make_task(graph, 0, 8)
    params = aco.DEFAULT_ACO_STAR._replace(**f32(alpha=1.0, beta=1.0, alpha_goal=3.0))
    table = transition_rule(graph, task, pheromone_table(), params, goal_distance=True)
    weights = {E: tau(0, E) / 1.0 / math.sqrt(5) ** 3, S: tau(0, S) / 1.0 / math.sqrt(5) ** 3,
               SE: tau(0, SE) / R2 / R2 ** 3}
    expect_row(table, 0, {k: math.log(w) for k, w in weights.items()})
    total = sum(weights.values())
    assert probabilities(np.asarray(table)[0]) == approx({k: w / total
                                                          for k, w in weights.items()})
    # Node 5 (2, 1): N->2 d 2, W->4 d sqrt2, NW->1 (length sqrt2) d sqrt5, SW->7 (sqrt2) d 1.
    expect_row(table, 5, {S: FORCED,
                          N: math.log(tau(5, N)) - 3 * math.log(2.0),
                          W: math.log(tau(5, W)) - 3 * math.log(R2),
                          NW: math.log(tau(5, NW) / R2) - 3 * math.log(math.sqrt(5)),
                          SW: math.log(tau(5, SW) / R2) - 3 * math.log(1.0)})


def eta_direction(i, j, goal=8):
    """Improved Max-Min's direction desirability (1 + cos) / 2 + 1e-3, cos the angle between the
    move i->j and the line from i to the goal."""
    (xi, yi), (xj, yj), (xg, yg) = xy(i), xy(j), xy(goal)
    move, aim = (xj - xi, yj - yi), (xg - xi, yg - yi)
    cos = (move[0] * aim[0] + move[1] * aim[1]) / (math.hypot(*move) * math.hypot(*aim))
    return (1 + cos) / 2 + 1e-3


@pytest.mark.parametrize("first_ant", [False, True])
def test_improved_transition_uses_the_direction_heuristic(first_ant):
    """Max-Min ACO paper eq. 1: P ~ tau ** alpha * eta ** beta, eta the direction
    desirability. Later ants: beta = 1; the first ant: beta_first = 5 (its hweight).
    Node 1 (1, 0) aims at (1, 2): E cos 1/sqrt5, S 2/sqrt5, W -1/sqrt5, SE 3/sqrt10,
    SW 1/sqrt10. Node 4 aims at (1, 1): NW is straight away (cos -1: eta = the floor 1e-3)."""
    graph = grid()
    task = make_task(graph, 0, 8)
    params = aco.DEFAULT_IMPROVED._replace(**f32(alpha=1.0, beta=1.0, beta_first=5.0))
    beta = 5.0 if first_ant else 1.0
    table = transition_rule(graph, task, pheromone_table(), params, direction=True,
                            beta=params.beta_first if first_ant else None)
    cosines = {E: 1 / math.sqrt(5), S: 2 / math.sqrt(5), W: -1 / math.sqrt(5),
               SE: 3 / math.sqrt(10), SW: 1 / math.sqrt(10)}
    for k, cos in cosines.items():  # the hand cosines agree with eta_direction
        assert eta_direction(1, moves(1)[k]) == approx((1 + cos) / 2 + 1e-3)
    weights = {k: tau(1, k) * ((1 + cos) / 2 + 1e-3) ** beta for k, cos in cosines.items()}
    expect_row(table, 1, {k: math.log(w) for k, w in weights.items()})
    total = sum(weights.values())
    assert probabilities(np.asarray(table)[1]) == approx({k: w / total
                                                          for k, w in weights.items()})
    expect_row(table, 4, {k: math.log(tau(4, k)) + beta * math.log(eta_direction(4, j))
                          for k, j in moves(4).items()})
    assert eta_direction(4, 0) == approx(1e-3)


# ------------------------------------------------------------------------------------------------
# Pheromone updates: eqs. 8-9 and the Max-Min rules


# A 3 x 3 corridor: only 0, 1, 2, 5, 8 are free, so every ant walks 0 E 1 E 2 S 5 S 8 (length 4).
CORRIDOR_BLOCKED = [3, 4, 6, 7]
CORRIDOR_EDGES = [(0, 1), (1, 2), (2, 5), (5, 8)]


def initial_pheromone():
    """A different tau on every slot, between 0.5 and 2.95."""
    i, k = np.meshgrid(np.arange(9), np.arange(8), indexing="ij")
    return (0.5 + 0.25 * i + 0.05 * k).astype(np.float32)


def on_edges(edges, amount):
    """f64[9, 8]: ``amount`` on both directions of each edge (hand slots)."""
    add = np.zeros((9, 8))
    for i, j in edges:
        add[i, slot(i, j)] += amount
        add[j, slot(j, i)] += amount
    return add


@functools.partial(jax.jit, static_argnums=0)
def first_step(swarm, key, graph, task, params, memory):
    """``(state, info)`` of one step of ``swarm`` from fresh memory (``swarm.init``) with the
    fields in ``memory`` (a dict of arrays) replaced: the init and the step in one program per
    swarm, map shape and set of fields."""
    state = dataclasses.replace(swarm.init(key, graph, task, params), **memory)
    return swarm.step(state, graph, task, params)


def best_so_far(graph, path, cost):
    """The ``memory`` of :func:`first_step` that makes ``path`` (node list) of ``cost`` the best
    path so far: -1 padded to N nodes (a walk's N - 1 moves and its start)."""
    padded = np.full(graph.num_nodes, -1, np.int32)
    padded[:len(path)] = path
    return dict(best_path=padded, best_cost=np.float32(cost))


def corridor_step(name, params, best=None, **config):
    """One step of an ant colony on the corridor from ``initial_pheromone``; ``best`` = (path,
    cost) replaces the best path so far first."""
    graph = grid(blocked=CORRIDOR_BLOCKED)
    task = make_task(graph, 0, 8)
    swarm = make(name, **config)
    memory = dict(pheromone=initial_pheromone())
    if best is not None:
        memory.update(best_so_far(graph, *best))
    state, info = first_step(swarm, jax.random.key(2), graph, task, params, memory)
    assert float(info.arrived) == 1.0 and float(info.iteration_cost) == approx(4.0)
    return np.asarray(state.pheromone)


@pytest.mark.parametrize("name", ["ant_system", "aco_star"])
def test_ant_system_eq9_then_eq8_on_a_forced_corridor(name):
    """Eq. 9: tau <- (1 - rho) tau on every slot; eq. 8: each of the 5 arrived ants adds
    Q / f(S) = 2 / 4 on every edge of its path, both directions: 5 * 0.5 = 2.5."""
    params = make(name).default_params._replace(**f32(rho=0.25, q=2.0))
    got = corridor_step(name, params, num_agents=5)
    expected = 0.75 * initial_pheromone().astype(np.float64) + on_edges(CORRIDOR_EDGES, 2.5)
    assert got.ravel().tolist() == approx(expected.ravel().tolist())


def test_ant_system_evaporation_stops_at_the_smallest_normal_float():
    """Eq. 9 in float32, kept at least TAU_FLOOR = 2 ** -126 (about 1.18e-38, the smallest normal
    float32). On the open 3 x 3, tau = 1e-37 everywhere but on node 4's slots (tau = 1), rho =
    0.9: 1e-37 evaporates to 1.0e-38, below 2 ** -126, which XLA flushes to 0 (log 0 = -inf: the
    edge would be impassable); the floor makes it 2 ** -126. Node 4's tau = 1 becomes 1 - 0.9 in
    float32 (0.100000024) exactly, as without a floor. One arrived ant 0 E 1 E 2 S 5 S 8 (f = 4,
    Q = 2) adds 0.5 on its edges, both directions: 0.5 + 2 ** -126 rounds to 0.5. Node 0 then
    weighs E (to 1) 0.5 and S (to 3) and SE (to 4) 2 ** -126 each: log-weights log 0.5 and
    -126 log 2 = -87.34, finite, so the ant may still take them."""
    graph = grid()
    ants = fake_walk([[0, 1, 2, 5, 8]], 9, arrived=[True], stuck=[False])
    params = aco.DEFAULT_ANT_SYSTEM._replace(**f32(rho=0.9, q=2.0))
    start = np.full((9, 8), 1e-37, np.float32)
    start[4] = 1.0
    got = np.asarray(ant_system_update(graph, start, ants, None, None, None, params))
    floor = np.float32(2.0 ** -126)
    assert aco.TAU_FLOOR == floor == np.finfo(np.float32).tiny
    assert np.float32(1e-37) * (np.float32(1.0) - np.float32(0.9)) < floor
    deposited = on_edges(CORRIDOR_EDGES, 0.5) > 0
    expected = np.where(deposited, np.float32(0.5), floor)
    expected[4] = np.float32(1.0) - np.float32(0.9)
    np.testing.assert_array_equal(got, expected)
    table = transition_rule(graph, make_task(graph, 0, 8), got, params)
    expect_row(table, 0, {E: math.log(0.5), S: -126 * math.log(2.0),
                          SE: -126 * math.log(2.0)})


def test_eq8_deposit_of_two_ants_of_different_lengths():
    """Eq. 8 with two paths on the open 3 x 3: A 0->4->8 (f = 2 sqrt2) adds Q / f on 0-4 and 4-8,
    B 0->1->2->5->8 (f = 4) adds Q / 4 on its edges, both directions; Q = 3."""
    graph = grid()
    ants = fake_walk([[0, 4, 8], [0, 1, 2, 5, 8]], 9, arrived=[True, True],
                     stuck=[False, False])
    start = initial_pheromone()
    got = deposit(graph, start, np.asarray(ants.path)[:, :-1], ants.slots, 3.0 / ants.length)
    expected = (start + on_edges([(0, 4), (4, 8)], 3 / (2 * R2))
                + on_edges(CORRIDOR_EDGES, 3 / 4))
    assert np.asarray(got).ravel().tolist() == approx(expected.ravel().tolist())


MAX_MIN = dict(rho=0.5, q=3.0, tau_min=0.6, tau_max=10.0)


@pytest.mark.parametrize("global_best, upper_bound, tau_max", [
    (False, False, 10.0), (True, True, 10.0), (True, True, 1.2)])
def test_max_min_update(global_best, upper_bound, tau_max):
    """Max-Min: tau <- max((1 - rho) tau, tau_min), then Q / f on the best path; with
    upper_bound, min(tau, tau_max). The best path so far is set to 0->1->2 claiming cost 2, so the
    ants (cost 4) do not replace it. Iteration-best: Q / 4 = 0.75 on the corridor, once (not per
    ant). global_best: Q / 2 = 1.5 on 0-1 and 1-2 only. rho 0.5, tau_min 0.6: every initial tau
    below 1.2 is floored. The two switches are on together (one compiled step): a cap of 10
    leaves every tau as it is, a cap of 1.2 lowers more than 5."""
    params = aco.DEFAULT_MAX_MIN._replace(**f32(**dict(MAX_MIN, tau_max=tau_max)))
    got = corridor_step("max_min_aco", params, best=([0, 1, 2], 2.0), num_agents=6,
                        global_best=global_best, upper_bound=upper_bound)
    expected = np.maximum(0.5 * initial_pheromone().astype(np.float64), 0.6)
    assert (expected == 0.6).sum() > 5  # the floor matters here
    if global_best:
        expected = expected + on_edges([(0, 1), (1, 2)], 1.5)
    else:
        expected = expected + on_edges(CORRIDOR_EDGES, 0.75)
    if upper_bound:
        capped = (expected > tau_max).sum()
        assert capped > 5 if tau_max < 10 else capped == 0  # the cap matters at 1.2 only
        expected = np.minimum(expected, tau_max)
    assert got.ravel().tolist() == approx(expected.ravel().tolist())


def test_improved_update_floors_then_adds_q_on_the_best_path_so_far():
    """Algorithm 1: pher <- pher (1 - rho); floored at minpher; + delta on the best path so far.
    On the open 3 x 3 the best path so far is set to the optimum 0->4->8 (2 sqrt2, which no ant
    can beat): rho 0.5, tau_min 0.6, q 0.7 on 0-4 and 4-8, both directions, whatever the ants
    did."""
    graph = grid()
    task = make_task(graph, 0, 8)
    params = aco.DEFAULT_IMPROVED._replace(**f32(rho=0.5, q=0.7, tau_min=0.6))
    swarm = make("improved_max_min_aco", num_agents=16)
    memory = dict(pheromone=initial_pheromone(),
                  **best_so_far(graph, [0, 4, 8], np.float32(2) * np.float32(R2)))
    state, _ = first_step(swarm, jax.random.key(3), graph, task, params, memory)
    expected = (np.maximum(0.5 * initial_pheromone().astype(np.float64), 0.6)
                + on_edges([(0, 4), (4, 8)], 0.7))
    assert np.asarray(state.pheromone).ravel().tolist() == approx(expected.ravel().tolist())
    assert np.asarray(state.best_path)[:3].tolist() == [0, 4, 8]


# ------------------------------------------------------------------------------------------------
# rfd_graded: clipped transition, carve, settle, bank erosion


GRADED = DEFAULT_GRADED._replace(**f32(p_base=2.0, alpha=1.0, initial_height=10.0, erosion=1.0,
                                       climb=0.5, repose=0.5))

ALTG = [10.0, 10.0, 12.0,   # plateau, plateau, filled hill
        10.0, 1.5, 10.3,    # plateau, bed, filled
        2.0, 1.0, 0.0]      # bed, bed, goal


def test_graded_transition_clips_between_bed_and_plateau():
    """Eq. 6 (p_base 2, alpha 1, goal (2, 2) forced when adjacent) over clipped gradients:
    from a bed (alt < 10) an uphill move counts as at most climb = 0.5 steep; from the plateau a
    move into a bed counts as at most erosion = 1 downhill; from the plateau a climb steeper
    than 0.5 is banned; other gradients as they are."""
    graph = grid()
    task = make_task(graph, 0, 8)
    table = graded_transition(graph, task, np.array(ALTG, np.float32), GRADED)
    log2 = math.log(2.0)

    def logw(g, j):
        return g * log2 - math.log(distance(j, 8))

    # Bed 4 (1.5): climbs to 5, 3, 1, 0, 2 are clipped to -0.5; SW->6 (2.0) g -0.5/sqrt2 stays.
    expect_row(table, 4, {E: logw(-0.5, 5), S: logw(0.5, 7), W: logw(-0.5, 3),
                          N: logw(-0.5, 1), SE: FORCED, SW: logw(-0.5 / R2, 6),
                          NW: logw(-0.5, 0), NE: logw(-0.5, 2)})
    # Plateau 3 (10): into the beds 4 (g 8.5), 6 (g 8), 7 (g 9/sqrt2) at most 1; flat to 0, 1.
    expect_row(table, 3, {E: logw(1.0, 4), S: logw(1.0, 6), SE: logw(1.0, 7), N: logw(0.0, 0),
                          NE: logw(0.0, 1)})
    # Plateau 1 (10): E->2 (12) g -2 banned; SE->5 (10.3) g -0.3/sqrt2 allowed as is;
    # S->4 (bed) at most 1; W, SW flat.
    expect_row(table, 1, {SE: logw(-0.3 / R2, 5), S: logw(1.0, 4), W: logw(0.0, 0),
                          SW: logw(0.0, 3)})
    # Filled 2 (12): W->1 g 2 and S->5 g 1.7 are plateau to plateau, not clipped; SW->4 at most 1.
    expect_row(table, 2, {W: logw(2.0, 1), S: logw(1.7, 5), SW: logw(1.0, 4)})
    # Filled 5 (10.3): the goal is forced; N->2 (12) g -1.7 banned.
    assert row(table, 5)[S] >= FORCED * (1 - 1e-6) and row(table, 5)[N] == NONE


def test_carve_lowers_each_path_node_to_erosion_times_its_way_to_water():
    """Carving (E = 2, plateau 10; before: goal 0, node 4 at 1, all else 10): each node of a
    path goes down to min over later water m of alt(m) + E * (length walked from it to m).
    A (arrived): 0 -E-> 1 -SE-> 5 -S-> 8: 5 to 2 * 1, 1 to 2 (1 + sqrt2), 0 to 2 (2 + sqrt2).
    B (did not arrive): 0 -S-> 3 -S-> 6 -E-> 7 -N-> 4: water at 4 (1): 7 to 3, 6 to 5, 3 to 7,
    0 to 9. C (did not arrive): 0 -> 3 -> 4 -> 1 -> 2: 3 to 3, 0 to 5; 1 and 2 lie after the
    water, and 1, carved by A in this same iteration, is not water for C: 2 stays 10.
    Each node keeps the lowest: 0 -> 5, 3 -> 3."""
    graph = grid()
    before = [10.0, 10.0, 10.0, 10.0, 1.0, 10.0, 10.0, 10.0, 0.0]
    # Order A, C, B: at node 0 the lowest (C's 5) comes neither first nor last.
    drops = fake_walk([[0, 1, 5, 8], [0, 3, 4, 1, 2], [0, 3, 6, 7, 4]], 9,
                      arrived=[True, False, False], stuck=[False, False, False], budget=8)
    params = GRADED._replace(**f32(erosion=2.0))
    got = carve(graph, np.array(before, np.float32), drops, params)
    expected = [min(2 * (2 + R2), 9.0, 5.0), 2 * (1 + R2), 10.0,
                min(7.0, 3.0), 1.0, 2.0,
                5.0, 3.0, 0.0]
    assert np.asarray(got).tolist() == approx(expected)


def test_one_graded_step_on_a_forced_corridor_carves_the_bed():
    """rfd_graded at the shared size (one iteration of the run test_conformance.py compiles) on
    a corridor (0, 0) -> (1, 0) -> goal (2, 0) cut out of the shared map's shape, plateau 10,
    E = 1.5: every drop walks 0 -> 1 -> 2 (0 to 1 is flat, 1 to the goal forced) and arrives: no
    alley, no failed trail, nothing settles; carving puts 1 at E * 1 and 0 at E * 2; the banks
    change nothing (0: 1.5 + 1.5 = 3); the blocked cells stay on the plateau."""
    height, width = sizes.maze()[0].shape
    graph = grid(width, height, blocked=range(3, width * height))
    task = make_task(graph, 0, 2)
    swarm = make("rfd_graded", **sizes.CONFIG)
    params = swarm.default_params._replace(**f32(initial_height=10.0, erosion=1.5))
    key = jax.random.key(4)
    fresh, _ = run(swarm, key, graph, task, params, iterations=sizes.ITERATIONS,
                   budget=0)  # no iteration: the memory swarm.init makes
    bed = np.full(graph.num_nodes, 10.0)
    bed[2] = 0.0
    assert np.asarray(fresh.altitude).tolist() == approx(bed.tolist())
    state, trace = run(swarm, key, graph, task, params, iterations=sizes.ITERATIONS, budget=1)
    assert int(trace.iterations) == 1 and np.asarray(trace.arrived)[0] == 1.0
    bed[:2] = 3.0, 1.5
    assert np.asarray(state.altitude).tolist() == approx(bed.tolist())


def test_settle_raises_filled_pits_to_their_lowest_neighbour_plus_repose():
    """Settling (plateau 10, repose 0.5): a filled node (> 10) that lies below min_j alt(j) +
    0.5 length(i, j) rises to it, until no filled node is a pit. Node 4 (10.2) is a pit: its
    lowest way is NW to 0 (10, unfilled, never raised): 10 + 0.5 sqrt2. Then 5 and 7 (11) see
    4 + 0.5 = 10.5 + 0.5 sqrt2 above them and rise to it; 2 and 6 (11) see 4 + 0.5 sqrt2 =
    10 + sqrt2 and rise to it. 1 and 3 (11) have 0 + 0.5 below them; 8 (12) has 4 + 0.5 sqrt2."""
    graph = grid()
    before = [10.0, 11.0, 11.0, 11.0, 10.2, 11.0, 11.0, 11.0, 12.0]
    got = settle(graph, np.array(before, np.float32), GRADED)
    h = 0.5 * R2
    expected = [10.0, 11.0, 10.0 + 2 * h, 11.0, 10.0 + h, 10.5 + h, 10.0 + 2 * h, 10.5 + h, 12.0]
    assert np.asarray(got).tolist() == approx(expected)
    # No filled node is a pit any more (hand check over the hand lattice).
    for i in range(9):
        if expected[i] > 10.0:
            lowest = min(expected[j] + 0.5 * step_length(i, j) for j in moves(i).values())
            assert lowest <= expected[i] * (1 + 1e-6)


@pytest.mark.parametrize("blocked", [(), (5,)])
def test_erode_banks_lowers_visited_carved_nodes_to_the_deeper_bed_beside(blocked):
    """A visited carved node (< 10) goes down to min_j alt(j) + E length(i, j) over its carved
    neighbours j (E = 1, all neighbours read before the update). Visited: 0, 1, 2, 4, 6.
    4 (3): SE to the goal: 0 + sqrt2; with 5 blocked that diagonal cuts a corner: 7 + 1 = 2.5.
    1 (5): 4 + 1 = 4. 0 (9): 4 + sqrt2. 6 (2): 7 + 1 = 2.5, not lower: stays. 2 is plateau: stays.
    7 (1.5) could go to 1 but was not visited."""
    graph = grid(blocked=blocked)
    before = [9.0, 5.0, 10.0, 10.0, 3.0, 10.0, 2.0, 1.5, 0.0]
    visited = np.zeros(9, bool)
    visited[[0, 1, 2, 4, 6]] = True
    got = erode_banks(graph, np.array(before, np.float32), visited, GRADED)
    expected = [3.0 + R2, 4.0, 10.0, 10.0, 2.5 if blocked else R2, 10.0, 2.0, 1.5, 0.0]
    assert np.asarray(got).tolist() == approx(expected)


# ------------------------------------------------------------------------------------------------
# Blind alleys


ALLEY_BLOCKED = [3, 5, 6, 8]  # . . . / # . # / # . #: a dead end 4, 7 hangs below node 1


def alley_table(graph, banned=()):
    """0 on every valid edge, -inf elsewhere and on the ``banned`` (i, j) moves."""
    table = np.where(np.asarray(graph.valid_edges()), 0.0, -np.inf).astype(np.float32)
    for i, j in banned:
        table[i, slot(i, j)] = -np.inf
    return table


@pytest.mark.parametrize("banned, expected", [
    ((), [4, 7]),             # 1 has a way out (E to 2): the alley is 4, 7
    (((1, 2),), [1, 4, 7]),   # 1 -> 2 banned by the table: 1 is in the alley too, the start not
])
def test_blind_alleys_of_a_tiny_dead_end(banned, expected):
    """A drop walked 0 -> 1 -> 4 -> 7 and is stuck at 7 (4 visited). Back along its trail, 4's
    only moves lead back to 1 or into 7 (filled): filled. 1 has E to 2: the alley ends there,
    unless the table bans 1 -> 2. A second drop that arrived 0 -> 1 -> 2 fills nothing, nor do
    the same two walks when the first drop ran out of steps in the alley instead (two drops
    both times: one compiled loop)."""
    graph = grid(blocked=ALLEY_BLOCKED)
    table = alley_table(graph, banned)
    paths = [[0, 1, 4, 7], [0, 1, 2]]
    drops = fake_walk(paths, 9, arrived=[False, True], stuck=[True, False])
    got = np.flatnonzero(np.asarray(blind_alleys(graph, table, drops))).tolist()
    assert got == expected
    not_stuck = fake_walk(paths, 9, arrived=[False, True], stuck=[False, False])
    assert not np.asarray(blind_alleys(graph, table, not_stuck)).any()


# ------------------------------------------------------------------------------------------------
# The Improved Max-Min first ant (depth-first, never revisits)


def in_the_shared_shape(free):
    """``(graph, at)``: the 3 x 3 nodes ``free`` at the same cells in the corner of the shared
    map's shape (``tests/sizes.py``), every other cell blocked, and ``at``, their numbers there:
    the first ants' programs of the 20 x 20 maps below."""
    height, width = sizes.maze()[0].shape
    at = {v: node(*xy(v), width) for v in free}
    graph = grid(width, height, blocked=sorted(set(range(width * height)) - set(at.values())))
    return graph, at


@pytest.mark.parametrize("greedy", [True, False])
def test_first_ant_backs_out_of_a_dead_end(greedy):
    """On the alley map (in the shared map's shape, its 3 x 3 nodes numbered there by ``at``),
    from 0 to 2 with 1 -> 4 made the most likely move: a greedy ant goes 0 1 4 7, is stuck, backs
    out to 4 (nothing new), to 1, and takes E to 2. The only path without revisits is 0 1 2, so
    a weighted ant ends with it too, whatever it drew."""
    graph, at = in_the_shared_shape([v for v in range(9) if v not in ALLEY_BLOCKED])
    table = alley_table(graph)
    table[at[1], slot(at[1], at[4], graph.shape[1])] = 5.0
    for seed in range(4 if not greedy else 1):
        path, cost, found = first_ant_path(jax.random.key(seed), graph, table,
                                           at[0], at[2], greedy=greedy)
        assert bool(found)
        assert np.asarray(path).tolist() == [at[0], at[1], at[2]] + [-1] * (graph.num_nodes - 3)
        assert float(cost) == approx(2.0)


def improved_first_table(graph, task):
    params = aco.DEFAULT_IMPROVED
    return transition_rule(graph, task, np.ones(graph.nbr.shape, np.float32), params,
                           direction=True, beta=params.beta_first)


def check_simple_path(graph, path, start, goal, cost):
    """A path of valid moves from start to goal, never revisiting, of the hand-summed length."""
    width = graph.shape[1]
    nodes = [int(v) for v in np.asarray(path) if v >= 0]
    assert (np.asarray(path)[len(nodes):] == -1).all()
    assert nodes[0] == start and nodes[-1] == goal
    assert len(set(nodes)) == len(nodes)
    valid = np.asarray(graph.valid_edges())
    total = 0.0
    for i, j in zip(nodes, nodes[1:]):
        (xi, yi), (xj, yj) = xy(i, width), xy(j, width)
        assert max(abs(xi - xj), abs(yi - yj)) == 1
        assert valid[i, slot(i, j, width)], (i, j)
        total += step_length(i, j, width)
    assert float(cost) == approx(total)


@pytest.mark.parametrize("width, height", [(10, 10), (20, 20), (40, 25)])
def test_first_ant_reaches_the_goal_without_revisits_on_random_path_maps(width, height):
    """Twelve seeded path maps per size (extra passages 0, 0.15 or 0.3: mazes with many dead
    ends to airy maps), corner to corner and between two seeded cells; a weighted first ant
    (Improved Max-Min's: direction heuristic with beta_first 5, tau 1) with its own key finds
    a path whenever Dijkstra does, and never enters a node twice."""
    for seed in range(12):
        graph = path_map_graph(random_path_map(width, height, seed,
                                               extra=(0.0, 0.15, 0.3)[seed % 3]))
        rng = np.random.default_rng(seed)
        pairs = [(0, graph.num_nodes - 1),
                 tuple(int(v) for v in rng.choice(graph.num_nodes, 2, replace=False))]
        for start, goal in pairs:
            task = make_task(graph, start, goal)
            path, cost, found = first_ant_path(jax.random.key(100 + seed), graph,
                                               improved_first_table(graph, task), start, goal)
            exact = dijkstra(graph, start, goal)
            assert bool(found) == bool(exact.found)
            assert bool(found), (seed, start, goal)
            check_simple_path(graph, path, start, goal, cost)
            assert float(cost) >= float(exact.cost) * (1 - 1e-6)


def test_first_ant_reports_an_unreachable_goal():
    """Goal walled off: found False, path all -1, cost inf, as Dijkstra says. (a) a 20 x 20 path
    map with the 8 edges of the goal closed; (b) a 3 x 3 grid with a wall down column 1, in the
    shared map's shape."""
    goal = 210
    connections = random_path_map(20, 20, 7, extra=0.3)
    connections[goal // 20, goal % 20] = False  # both ways: an edge is open where both ends say so
    graph = path_map_graph(connections)
    walled, at = in_the_shared_shape([0, 2, 3, 5, 6, 8])
    for g, start, end in [(graph, 0, goal), (walled, at[0], at[8])]:
        task = make_task(g, start, end)
        for seed in range(3):
            path, cost, found = first_ant_path(jax.random.key(seed), g,
                                               improved_first_table(g, task), start, end)
            assert not bool(found) and not bool(dijkstra(g, start, end).found)
            assert (np.asarray(path) == -1).all() and math.isinf(float(cost))
