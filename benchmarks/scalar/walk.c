/* A scalar reference of jaxswarm's walk on grids: one agent at a time, the same transition
 * rule (inverse CDF over exp(log-weight - max) of the admissible slots), visited sets as bits,
 * the same counter-based uniforms (jaxswarm.swarm.walking.streams.uniforms), so it walks the
 * same paths. It writes what the walker returns (jaxswarm.swarm.walking.Walk), in the same
 * layout, so that the two do the same work: the log of moves (jaxswarm.swarm.walking.log:
 * blocks of 16 moves, each agent's blocks in order, agent after agent, -1 after an agent's
 * last move and in the blocks no agent owns), each agent's first block, visited set, moves,
 * length, position, and whether it arrived or got stuck. As the walker, it writes the blocks to
 * a journal as agents finish (its lanes write them as they are made) and lays them out agent by
 * agent once every agent is done (each agent's place depends on the moves of those before
 * it). Build it without floating-point contraction (-ffp-contract=off): the walker's
 * arithmetic has none.
 * Built and timed by benchmarks/walk.py; agents are shared out over threads with OpenMP. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#define ORTHOGONAL_SLOTS 4
#define BLOCK 16

/* Threads for the next walk_all (OpenMP; one when built without it). */
void set_threads(int32_t threads) {
#ifdef _OPENMP
  omp_set_num_threads(threads);
#else
  (void)threads;
#endif
}

static inline uint32_t finalise(uint32_t x) {
  x ^= x >> 16; x *= 0x85EBCA6Bu; x ^= x >> 13; x *= 0xC2B2AE35u; x ^= x >> 16;
  return x;
}

static inline float uniform(uint32_t s0, uint32_t s1, uint32_t agent, uint32_t move) {
  uint32_t counter = (agent * 0x9E3779B1u) ^ move;
  return (float)(finalise(finalise(counter ^ s0) ^ s1) >> 8) * 0x1p-24f;
}

/* What walk_all writes (the caller fills visited with zeros), and its journal. */
typedef struct {
  int32_t *nodes;    /* i32[capacity, BLOCK]: the log's nodes */
  int8_t *slots;     /* i8[capacity, BLOCK]: the log's slots */
  int32_t *offset;   /* i32[agents]: each agent's first block in the log */
  uint32_t *visited; /* u32[agents, ceil(num_nodes / 32)] */
  int32_t *moves;    /* i32[agents] */
  float *length;     /* f32[agents]: orthogonal moves + diagonal moves * sqrt(2) in float32 */
  int32_t *position; /* i32[agents] */
  int8_t *arrived;   /* bool[agents] */
  int8_t *stuck;     /* bool[agents] */
  int32_t *journal_nodes; /* i32[capacity, BLOCK]: the blocks as agents finish (scratch) */
  int8_t *journal_slots;  /* i8[capacity, BLOCK] (scratch) */
  int32_t *journaled;     /* i32[agents]: each agent's first block in the journal (scratch) */
} Outputs;

/* Walks agents 0..agents-1 from start, writes their Outputs and returns the total number of
 * moves, or -1 when their blocks do not fit the log's capacity (blocks). */
int64_t walk_all(const float *log_weights, int32_t num_nodes, int32_t degree,
                 const int32_t *offsets, int32_t start, int32_t goal, int32_t agents,
                 int32_t max_steps, uint32_t s0, uint32_t s1, int64_t capacity, Outputs out) {
  int32_t words = (num_nodes + 31) / 32;
  int64_t total = 0, claimed = 0;
#pragma omp parallel reduction(+ : total)
  {
    float weight[64];
    int32_t neighbour[64];
    int32_t *nodes = malloc(sizeof(int32_t) * (size_t)(max_steps + BLOCK));
    int8_t *slots = malloc((size_t)(max_steps + BLOCK));
#pragma omp for schedule(dynamic, 16)
    for (int32_t a = 0; a < agents; a++) {
      uint32_t *visited = out.visited + (int64_t)a * words;
      int32_t here = start, moves = 0, diagonal = 0, stuck = 0;
      visited[here >> 5] |= 1u << (here & 31);
      while (here != goal && moves < max_steps) {
        const float *row = log_weights + (int64_t)here * degree;
        float top = -INFINITY;
        for (int32_t k = 0; k < degree; k++) {
          int32_t nb = here + offsets[k];
          nb = nb < 0 ? 0 : (nb >= num_nodes ? num_nodes - 1 : nb);
          neighbour[k] = nb;
          int seen = (visited[nb >> 5] >> (nb & 31)) & 1u;
          weight[k] = (row[k] > -INFINITY && !seen) ? row[k] : -INFINITY;
          if (weight[k] > top) top = weight[k];
        }
        if (!isfinite(top)) { stuck = 1; break; }
        float sum = 0.0f;
        for (int32_t k = 0; k < degree; k++) {
          weight[k] = expf(weight[k] - top);
          sum += weight[k];
        }
        float u = uniform(s0, s1, (uint32_t)a, (uint32_t)moves) * sum, running = 0.0f;
        int32_t below_u = 0, below_total = 0;
        for (int32_t k = 0; k < degree; k++) {
          running += weight[k];
          below_u += running <= u;
          below_total += running < sum;
        }
        int32_t choice = below_u < below_total ? below_u : below_total;
        here = neighbour[choice];
        visited[here >> 5] |= 1u << (here & 31);
        slots[moves] = (int8_t)choice;
        diagonal += choice >= ORTHOGONAL_SLOTS;
        nodes[moves++] = here;
      }
      int64_t blocks = (moves + BLOCK - 1) / BLOCK, first;
#pragma omp atomic capture
      { first = claimed; claimed += blocks; }
      out.journaled[a] = (int32_t)first;
      if (first + blocks <= capacity) {
        for (int32_t m = moves; m < blocks * BLOCK; m++) { nodes[m] = -1; slots[m] = -1; }
        memcpy(out.journal_nodes + first * BLOCK, nodes, sizeof(int32_t) * blocks * BLOCK);
        memcpy(out.journal_slots + first * BLOCK, slots, (size_t)(blocks * BLOCK));
      }
      out.moves[a] = moves;
      out.length[a] = (float)(moves - diagonal) + (float)diagonal * (float)M_SQRT2;
      out.position[a] = here;
      out.arrived[a] = here == goal;
      out.stuck[a] = (int8_t)stuck;
      total += moves;
    }
    free(nodes);
    free(slots);
  }
  if (claimed > capacity) return -1;
  int64_t place = 0;
  for (int32_t a = 0; a < agents; a++) {
    out.offset[a] = (int32_t)place;
    place += (out.moves[a] + BLOCK - 1) / BLOCK;
  }
#pragma omp parallel for schedule(dynamic, 64)
  for (int32_t a = 0; a < agents; a++) {
    int64_t blocks = (out.moves[a] + BLOCK - 1) / BLOCK;
    memcpy(out.nodes + (int64_t)out.offset[a] * BLOCK,
           out.journal_nodes + (int64_t)out.journaled[a] * BLOCK, sizeof(int32_t) * blocks * BLOCK);
    memcpy(out.slots + (int64_t)out.offset[a] * BLOCK,
           out.journal_slots + (int64_t)out.journaled[a] * BLOCK, (size_t)(blocks * BLOCK));
  }
  memset(out.nodes + place * BLOCK, 0xff, sizeof(int32_t) * (capacity - place) * BLOCK);
  memset(out.slots + place * BLOCK, 0xff, (size_t)((capacity - place) * BLOCK));
  return total;
}
