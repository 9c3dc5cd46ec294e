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
