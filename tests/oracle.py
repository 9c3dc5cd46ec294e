"""Independent reference implementations for the tests (plain, readable, slow).

Nothing here imports jaxswarm: the grid rules are written out again from the Moving AI convention
so that a bug in jaxswarm's tensors cannot hide in both places.
"""
import heapq
import math

SQRT2 = math.sqrt(2.0)


def grid_adjacency(obstacles, *, connectivity=8, corner_cutting=False):
    """{(x, y): [((x2, y2), length), ...]} for an occupancy grid (True = blocked, [y, x])."""
    height, width = len(obstacles), len(obstacles[0])

    def free(x, y):
        return 0 <= x < width and 0 <= y < height and not obstacles[y][x]

    moves = [(1, 0), (-1, 0), (0, 1), (0, -1)]
    if connectivity == 8:
        moves += [(1, 1), (1, -1), (-1, 1), (-1, -1)]
    adjacency = {}
    for y in range(height):
        for x in range(width):
            if not free(x, y):
                continue
            edges = []
            for dx, dy in moves:
                if not free(x + dx, y + dy):
                    continue
                if dx and dy and not corner_cutting and not (free(x + dx, y) and free(x, y + dy)):
                    continue
                edges.append(((x + dx, y + dy), SQRT2 if dx and dy else 1.0))
            adjacency[(x, y)] = edges
    return adjacency


def matrix_adjacency(weights):
    """{i: [(j, w), ...]} for a dense matrix where 0 / inf off the diagonal mean no edge."""
    n = len(weights)
    return {i: [(j, float(weights[i][j])) for j in range(n)
                if i != j and 0 < weights[i][j] < math.inf] for i in range(n)}


def dijkstra(adjacency, source, target):
    """Shortest distance from source to target (inf if unreachable)."""
    dist = {source: 0.0}
    heap = [(0.0, source)]
    done = set()
    while heap:
        d, u = heapq.heappop(heap)
        if u in done:
            continue
        if u == target:
            return d
        done.add(u)
        for v, w in adjacency.get(u, ()):
            if d + w < dist.get(v, math.inf):
                dist[v] = d + w
                heapq.heappush(heap, (d + w, v))
    return math.inf


def mapf_optimum(adjacency, starts, goals):
    """The least sum of costs of a multi-agent instance by Dijkstra over joint states, or None.

    Every agent waits or moves along an edge of ``adjacency`` (cells, as from
    :func:`grid_adjacency`) per step; no two agents on one cell, no two exchanging cells. An agent
    costs one per step until it commits to its goal and stays there ("done"), so the sum of costs
    counts each agent's steps up to its last arrival. Exponential: tiny instances only.
    """
    start = (tuple(starts), (False,) * len(starts))
    best = {start: 0}
    queue = [(0, start)]
    while queue:
        cost, state = heapq.heappop(queue)
        if cost > best[state]:
            continue
        positions, done = state
        if all(done):
            return cost
        options = []
        for agent, (cell, finished) in enumerate(zip(positions, done)):
            if finished:
                options.append([(cell, True, 0)])
                continue
            moves = [(cell, False, 1)] + [(nxt, False, 1) for nxt, _ in adjacency[cell]]
            if cell == goals[agent]:
                moves.append((cell, True, 0))
            options.append(moves)
        for combo in _product(options):
            cells = tuple(c for c, _, _ in combo)
            if len(set(cells)) < len(cells):
                continue
            if any(cells[a] == positions[b] and cells[b] == positions[a] and a != b
                   for a in range(len(cells)) for b in range(a + 1, len(cells))):
                continue
            nxt = (cells, tuple(f for _, f, _ in combo))
            new_cost = cost + sum(c for _, _, c in combo)
            if new_cost < best.get(nxt, math.inf):
                best[nxt] = new_cost
                heapq.heappush(queue, (new_cost, nxt))
    return None


def _product(options):
    if not options:
        yield ()
        return
    for first in options[0]:
        for rest in _product(options[1:]):
            yield (first,) + rest


def pairwise_conflicts(paths):
    """(vertex set of (step, agent), swap set of (step, agent, other)) of padded paths (lists of
    equal-length node lists), by testing every pair of agents at every step."""
    vertex, swap = set(), set()
    steps = len(paths[0])
    for a, mine in enumerate(paths):
        for b, theirs in enumerate(paths):
            if a == b:
                continue
            for t in range(steps):
                if mine[t] == theirs[t]:
                    vertex.add((t, a))
                if (t + 1 < steps and mine[t] != mine[t + 1] and mine[t] == theirs[t + 1]
                        and mine[t + 1] == theirs[t]):
                    swap.add((t, a, b))
    return vertex, swap


def spacetime_steps(adjacency, start, goal, others):
    """Fewest steps for one agent from ``start`` to ``goal`` (cells) that it can keep, avoiding
    ``others`` (lists of cells per step; each other agent stays on its last cell for good): no
    shared cell at a step, no exchange of cells in a step. Breadth-first over (cell, step) up to
    the step after which nothing moves plus the number of cells; None if there is no way."""
    horizon = max((len(path) for path in others), default=0)

    def at(path, t):
        return path[min(t, len(path) - 1)]

    def last_visit(cell):
        return max([t for path in others for t in range(len(path)) if path[t] == cell]
                   + [horizon if any(path[-1] == cell for path in others) else -1])

    keep_from = last_visit(goal) + 1
    frontier = [start]
    seen = {(start, 0)}
    for t in range(horizon + len(adjacency) + 1):
        if goal in frontier and t >= keep_from:
            return t
        following = []
        for cell in frontier:
            for nxt in [cell] + [n for n, _ in adjacency[cell]]:
                if (nxt, t + 1) in seen or any(at(p, t + 1) == nxt for p in others):
                    continue
                if nxt != cell and any(at(p, t) == nxt and at(p, t + 1) == cell
                                       for p in others):
                    continue
                seen.add((nxt, t + 1))
                following.append(nxt)
        frontier = following
    return None
