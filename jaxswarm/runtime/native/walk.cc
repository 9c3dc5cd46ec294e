// JaxswarmWalk: the walker's plain walk (jaxswarm.swarm.walking.loop._walk_runs without a hook),
// agent after agent, bit for bit the walks of the XLA walker's lanes (jaxswarm/swarm/walking/
// native.py calls it; docs/native.md says what matches and what does not).
//
//   seed u32[R, 2], log_weights f32[R or 1, N, K], start i32[R], goal i32[R],
//   neighbours i32[K] (a grid or path map's slot offsets) or i32[N, K] (a graph's nbr table)
//   attributes num_agents, max_steps, greedy_agents, blocks (each run's log's room), and the
//   lanes' schedule: lanes (loop.lanes_for of R * A), refill_share, compact_share,
//   smallest_compaction (loop.REFILL_SHARE, COMPACT_SHARE, SMALLEST_COMPACTION)
//   -> nodes i32[R, blocks, 16], slots i8 or i16[R, blocks, 16], offset i32[R, A],
//      moves i32[R, A], overflowed pred[R], length f32[R, A] (grids; 0 on graphs, whose
//      lengths the caller sums from the log), arrived pred[R, A], stuck pred[R, A],
//      position i32[R, A], visited u32[R, A, ceil(N / 32)], lane_steps i32[R]
//
// The walks do not depend on the lanes' schedule, but two outputs do: the lane-steps the
// lanes' loop executes, and, when the batch's agents own more blocks of moves than the batch's
// logs hold together, which blocks the lanes' journal loses. Once every agent has walked, the
// handler replays the loop's schedule (jaxswarm.swarm.walking.loop._walk_agents: the queue, the
// refills, the narrowings) from each agent's step count alone, at one operation per lane and
// block, and takes both from it.
//
// The arithmetic is the walker's operation for operation: jaxswarm.runtime.arithmetic.exp
// (Cephes' polynomial, the same float32 constants, the same order), the masked sampler's sums
// in slot order (jaxswarm.swarm.walking.sampler.sample_masked), no contraction
// (-ffp-contract=off), no fast-math, and subnormals flushed as XLA:CPU flushes them (FTZ and
// DAZ set for the call and restored after it).
//
// Thread safety: no statics, no globals; the handler reads its inputs and writes its own
// outputs (the MXCSR it sets is the calling thread's own register), so XLA may run calls at
// once (two CPU devices under shard_map).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "xla/ffi/api/ffi.h"

#include "arithmetic.h"
#include "streams.h"

namespace ffi = xla::ffi;

namespace {

constexpr int32_t kBlock = 16;            // jaxswarm.swarm.walking.log.BLOCK
constexpr int32_t kOrthogonalSlots = 4;   // jaxswarm.world.lattice.ORTHOGONAL_SLOTS
constexpr int32_t kNoNode = -1;           // jaxswarm.world.graph.NO_NODE

// jaxswarm.world.lattice.SQRT2: float32(sqrt(2)).
constexpr float kSqrt2 = 1.41421356237309515f;

using jaxswarm::Exp;
using jaxswarm::FlushDenormals;
using jaxswarm::Uniform;  // jaxswarm.swarm.walking.streams.uniforms

// What one call reads.
struct Map {
  const float* log_weights;  // f32[R or 1, N, K]
  int64_t table_runs;        // 1: one table for every run
  const int32_t* neighbours; // offsets i32[K] (grid) or nbr i32[N, K]
  bool grid;
  int32_t num_nodes, degree, words;
};

// The lanes' loop's schedule (jaxswarm.swarm.walking.loop).
struct Schedule {
  int32_t lanes, refill_share, compact_share, smallest_compaction;
};

// Replays jaxswarm.swarm.walking.loop._walk_agents's schedule for agents that made moves[f]
// moves and stopped stuck (stuck[f]) or not, row f = agent f % agents of run f / agents: the
// queue (the rows of runs that do not start at their goal, in row order), the lanes taking
// them, blocks of kBlock lockstep steps, refills of at most lanes / refill_share stopped lanes,
// and the narrowings. Each block whose agent moved in it is appended to the journal in lane
// order; the blocks past the journal's room (runs * blocks) are lost: their places in the logs
// (laid out in agent order, offset[f] + the block's index, when within the run's room) are
// emptied, as jaxswarm.swarm.walking.journal.ordered_logs leaves them. Returns the lane-steps
// (int32, wrapping as XLA's sum does).
template <typename Slot>
int32_t Replay(const Schedule& schedule, const int32_t* moves, const bool* stuck,
               const int32_t* start, const int32_t* goal, int64_t runs, int32_t agents,
               int64_t blocks, const int32_t* offset, int32_t* nodes, Slot* slots) {
  const int64_t count = runs * agents, none = count, room = runs * blocks;
  std::vector<int64_t> order;
  for (int64_t f = 0; f < count; ++f) {
    if (start[f / agents] != goal[f / agents]) order.push_back(f);
  }
  const int64_t live = static_cast<int64_t>(order.size());
  auto steps_of = [&](int64_t f) { return static_cast<int64_t>(moves[f]) + (stuck[f] ? 1 : 0); };
  int64_t width = schedule.lanes;
  std::vector<int64_t> agent(width, none), done(width, 0);
  std::vector<char> walking(width, 0);
  for (int64_t l = 0; l < width && l < live; ++l) {
    agent[l] = order[l];
    walking[l] = 1;
  }
  int64_t next = std::min(width, live), written = 0;
  uint32_t lane_steps = 0;
  auto walking_count = [&]() {
    int64_t n = 0;
    for (int64_t l = 0; l < width; ++l) n += walking[l];
    return n;
  };
  auto block = [&]() {
    for (int64_t l = 0; l < width; ++l) {
      if (agent[l] == none || !walking[l]) continue;
      const int64_t f = agent[l], j = done[l];
      if (moves[f] > j * kBlock) {  // the agent moved in this block: the lane appends it
        if (written >= room) {     // lost: its place in the log stays empty
          const int64_t place = offset[f] + j;
          if (place < blocks) {
            const int64_t at = ((f / agents) * blocks + place) * kBlock;
            std::fill(nodes + at, nodes + at + kBlock, kNoNode);
            std::fill(slots + at, slots + at + kBlock, static_cast<Slot>(-1));
          }
        }
        ++written;
      }
      done[l] = j + 1;
      walking[l] = steps_of(f) > (j + 1) * kBlock;
    }
    lane_steps += static_cast<uint32_t>(width) * static_cast<uint32_t>(kBlock);
  };
  auto flush = [&]() {
    for (int64_t l = 0; l < width; ++l) {
      if (agent[l] != none && !walking[l]) agent[l] = none;
    }
  };
  int64_t few = width / schedule.compact_share;
  while (next < live || walking_count() > few) {
    block();
    const int64_t cap = std::max<int64_t>(width / schedule.refill_share, 1);
    int64_t taken = 0;
    for (int64_t l = 0; l < width && taken < cap; ++l) {
      if (agent[l] == none || walking[l]) continue;
      const int64_t queued = next + taken++;
      agent[l] = queued < live ? order[queued] : none;
      walking[l] = queued < live;
      done[l] = 0;
    }
    next = std::min(next + taken, live);
  }
  flush();
  while (few) {
    int64_t fewer = few / schedule.compact_share;
    if (fewer < schedule.smallest_compaction) fewer = 0;
    std::vector<int64_t> kept_agent(few, none), kept_done(few, 0);
    std::vector<char> kept_walking(few, 0);
    for (int64_t l = 0, k = 0; l < width && k < few; ++l) {
      if (!walking[l]) continue;
      kept_agent[k] = agent[l];
      kept_done[k] = done[l];
      kept_walking[k++] = 1;
    }
    agent.swap(kept_agent);
    done.swap(kept_done);
    walking.swap(kept_walking);
    width = few;
    while (walking_count() > fewer) block();
    flush();
    few = fewer;
  }
  return static_cast<int32_t>(lane_steps);
}

template <typename Slot>
ffi::Error WalkAll(const Map& map, const Schedule& schedule, const uint32_t* seed,
                   const int32_t* start, const int32_t* goal, int64_t runs, int32_t agents,
                   int32_t max_steps, int32_t greedy_agents, int64_t blocks, int32_t* nodes, Slot* slots,
                   int32_t* offset, int32_t* moves_out, bool* overflowed, float* length,
                   bool* arrived_out, bool* stuck_out, int32_t* position, uint32_t* visited_out,
                   int32_t* steps_out) {
  const int32_t K = map.degree, N = map.num_nodes, W = map.words;
  std::vector<float> masked(K), weight(K);
  std::vector<int32_t> neighbour(K);
  std::fill(nodes, nodes + runs * blocks * kBlock, kNoNode);
  std::fill(slots, slots + runs * blocks * kBlock, static_cast<Slot>(-1));
  std::fill(visited_out, visited_out + runs * agents * W, 0u);
  const float inf = std::numeric_limits<float>::infinity();
  int64_t owned_total = 0;
  for (int64_t r = 0; r < runs; ++r) {
    const float* table = map.log_weights + (map.table_runs > 1 ? r : 0) * N * K;
    const uint32_t s0 = seed[2 * r], s1 = seed[2 * r + 1];
    const int32_t goal_r = goal[r];
    int32_t* run_nodes = nodes + r * blocks * kBlock;
    Slot* run_slots = slots + r * blocks * kBlock;
    int64_t owned = 0;  // blocks owned by the run's agents so far: the next agent's offset
    for (int32_t a = 0; a < agents; ++a) {
      const int64_t row_index = r * agents + a;
      uint32_t* visited = visited_out + row_index * W;
      int32_t here = start[r], moves = 0, diagonal = 0;
      bool stuck = false, arrived = here == goal_r;
      const bool greedy = a < greedy_agents;
      visited[here >> 5] |= 1u << (here & 31);
      const int64_t first = owned;
      bool walking = !arrived;
      while (walking) {
        const float* row = table + static_cast<int64_t>(here) * K;
        float top = -inf;
        for (int32_t k = 0; k < K; ++k) {
          int32_t nb;
          if (map.grid) {
            nb = here + map.neighbours[k];
            nb = nb < 0 ? 0 : (nb > N - 1 ? N - 1 : nb);
          } else {
            nb = map.neighbours[static_cast<int64_t>(here) * K + k];
            nb = nb > 0 ? nb : 0;
          }
          neighbour[k] = nb;
          const bool seen = (visited[nb >> 5] >> (nb & 31)) & 1u;
          masked[k] = (row[k] > -inf && !seen) ? row[k] : -inf;
          top = masked[k] > top ? masked[k] : top;  // no NaN: row[k] > -inf excludes it
        }
        const bool has_choice = std::isfinite(top);
        if (!has_choice) {
          stuck = true;
          break;
        }
        for (int32_t k = 0; k < K; ++k) {
          weight[k] = greedy ? (masked[k] == top ? 1.0f : 0.0f) : Exp(masked[k] - top);
        }
        float total = weight[0];
        for (int32_t k = 1; k < K; ++k) total = total + weight[k];
        const float u = Uniform(s0, s1, static_cast<uint32_t>(a), static_cast<uint32_t>(moves))
                        * total;
        float running = 0.0f;
        int32_t choice = 0;
        for (int32_t k = 0; k < K; ++k) {
          running = running + weight[k];
          choice += (running <= u) & (running < total);
        }
        here = neighbour[choice];
        visited[here >> 5] |= 1u << (here & 31);
        const int64_t block = first + moves / kBlock;
        if (block < blocks) {
          run_nodes[block * kBlock + moves % kBlock] = here;
          run_slots[block * kBlock + moves % kBlock] = static_cast<Slot>(choice);
        }
        diagonal += choice >= kOrthogonalSlots;
        ++moves;
        arrived = here == goal_r;
        walking = !arrived && moves < max_steps;
      }
      owned += (moves + kBlock - 1) / kBlock;
      offset[row_index] = static_cast<int32_t>(first);
      moves_out[row_index] = moves;
      position[row_index] = here;
      arrived_out[row_index] = arrived;
      stuck_out[row_index] = stuck;
      length[row_index] = map.grid ? static_cast<float>(moves - diagonal)
                                         + static_cast<float>(diagonal) * kSqrt2
                                   : 0.0f;
    }
    overflowed[r] = owned > blocks;
    owned_total += owned;
  }
  // The XLA walker's journal has room for the batch's blocks together: when the batch's agents
  // own more, every run says it overflowed (jaxswarm.swarm.walking.journal.ordered_logs).
  if (owned_total > runs * blocks) std::fill(overflowed, overflowed + runs, true);
  const int32_t lane_steps = Replay(schedule, moves_out, stuck_out, start, goal, runs, agents,
                                    blocks, offset, nodes, slots);
  std::fill(steps_out, steps_out + runs, lane_steps);
  return ffi::Error::Success();
}

ffi::Error WalkImpl(ffi::Buffer<ffi::U32> seed, ffi::Buffer<ffi::F32> log_weights,
                    ffi::Buffer<ffi::S32> start, ffi::Buffer<ffi::S32> goal,
                    ffi::Buffer<ffi::S32> neighbours, int32_t num_agents, int32_t max_steps,
                    int32_t greedy_agents, int32_t blocks, int32_t lanes,
                    int32_t refill_share, int32_t compact_share, int32_t smallest_compaction,
                    ffi::ResultBuffer<ffi::S32> nodes, ffi::Result<ffi::AnyBuffer> slots,
                    ffi::ResultBuffer<ffi::S32> offset, ffi::ResultBuffer<ffi::S32> moves,
                    ffi::ResultBuffer<ffi::PRED> overflowed, ffi::ResultBuffer<ffi::F32> length,
                    ffi::ResultBuffer<ffi::PRED> arrived, ffi::ResultBuffer<ffi::PRED> stuck,
                    ffi::ResultBuffer<ffi::S32> position, ffi::ResultBuffer<ffi::U32> visited,
                    ffi::ResultBuffer<ffi::S32> lane_steps) {
  auto seed_dims = seed.dimensions();
  auto table_dims = log_weights.dimensions();
  auto neighbour_dims = neighbours.dimensions();
  if (seed_dims.size() != 2 || seed_dims[1] != 2) {
    return ffi::Error::InvalidArgument("walk: seed must be u32[R, 2]");
  }
  const int64_t runs = seed_dims[0];
  if (table_dims.size() != 3 || (table_dims[0] != 1 && table_dims[0] != runs)) {
    return ffi::Error::InvalidArgument("walk: log_weights must be f32[R or 1, N, K]");
  }
  const int64_t N = table_dims[1], K = table_dims[2];
  if (start.element_count() != static_cast<size_t>(runs) ||
      goal.element_count() != static_cast<size_t>(runs)) {
    return ffi::Error::InvalidArgument("walk: start and goal must be i32[R]");
  }
  const bool grid = neighbour_dims.size() == 1;
  if (!(grid && neighbour_dims[0] == K) &&
      !(neighbour_dims.size() == 2 && neighbour_dims[0] == N && neighbour_dims[1] == K)) {
    return ffi::Error::InvalidArgument("walk: neighbours must be i32[K] offsets or i32[N, K]");
  }
  if (N < 1 || K < 1 || num_agents < 1 || blocks < 0) {
    return ffi::Error::InvalidArgument("walk: empty map, no agents or negative room");
  }
  if (lanes < 1 || refill_share < 1 || compact_share < 2 || smallest_compaction < 1) {
    return ffi::Error::InvalidArgument("walk: the lanes' schedule needs lanes >= 1, "
                                       "refill_share >= 1, compact_share >= 2");
  }
  const int64_t words = (N + 31) / 32;
  const size_t per_agent = static_cast<size_t>(runs) * num_agents;
  const size_t log_entries = static_cast<size_t>(runs) * blocks * kBlock;
  if (nodes->element_count() != log_entries || slots->element_count() != log_entries ||
      offset->element_count() != per_agent || moves->element_count() != per_agent ||
      overflowed->element_count() != static_cast<size_t>(runs) ||
      length->element_count() != per_agent || arrived->element_count() != per_agent ||
      stuck->element_count() != per_agent || position->element_count() != per_agent ||
      visited->element_count() != per_agent * words ||
      lane_steps->element_count() != static_cast<size_t>(runs)) {
    return ffi::Error::InvalidArgument("walk: an output's shape does not match the inputs");
  }
  const int32_t* starts = start.typed_data();
  const int32_t* goals = goal.typed_data();
  for (int64_t r = 0; r < runs; ++r) {
    if (starts[r] < 0 || starts[r] >= N || goals[r] < 0 || goals[r] >= N) {
      return ffi::Error::InvalidArgument("walk: start or goal outside the map");
    }
  }
  FlushDenormals flush;
  const Map map{log_weights.typed_data(), table_dims[0], neighbours.typed_data(), grid,
                static_cast<int32_t>(N), static_cast<int32_t>(K), static_cast<int32_t>(words)};
  const Schedule schedule{lanes, refill_share, compact_share, smallest_compaction};
  auto run = [&](auto* slot_data) {
    return WalkAll(map, schedule, seed.typed_data(), starts, goals, runs, num_agents, max_steps,
                   greedy_agents, blocks, nodes->typed_data(), slot_data, offset->typed_data(),
                   moves->typed_data(), overflowed->typed_data(), length->typed_data(),
                   arrived->typed_data(), stuck->typed_data(), position->typed_data(),
                   visited->typed_data(), lane_steps->typed_data());
  };
  switch (slots->element_type()) {
    case ffi::DataType::S8:
      return run(reinterpret_cast<int8_t*>(slots->untyped_data()));
    case ffi::DataType::S16:
      return run(reinterpret_cast<int16_t*>(slots->untyped_data()));
    case ffi::DataType::S32:
      return run(reinterpret_cast<int32_t*>(slots->untyped_data()));
    default:
      return ffi::Error::InvalidArgument("walk: slots must be i8, i16 or i32");
  }
}

}  // namespace

XLA_FFI_DEFINE_HANDLER_SYMBOL(JaxswarmWalk, WalkImpl,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::U32>>()  // seed
                                  .Arg<ffi::Buffer<ffi::F32>>()  // log_weights
                                  .Arg<ffi::Buffer<ffi::S32>>()  // start
                                  .Arg<ffi::Buffer<ffi::S32>>()  // goal
                                  .Arg<ffi::Buffer<ffi::S32>>()  // neighbours
                                  .Attr<int32_t>("num_agents")
                                  .Attr<int32_t>("max_steps")
                                  .Attr<int32_t>("greedy_agents")
                                  .Attr<int32_t>("blocks")
                                  .Attr<int32_t>("lanes")
                                  .Attr<int32_t>("refill_share")
                                  .Attr<int32_t>("compact_share")
                                  .Attr<int32_t>("smallest_compaction")
                                  .Ret<ffi::Buffer<ffi::S32>>()   // nodes
                                  .Ret<ffi::AnyBuffer>()          // slots
                                  .Ret<ffi::Buffer<ffi::S32>>()   // offset
                                  .Ret<ffi::Buffer<ffi::S32>>()   // moves
                                  .Ret<ffi::Buffer<ffi::PRED>>()  // overflowed
                                  .Ret<ffi::Buffer<ffi::F32>>()   // length
                                  .Ret<ffi::Buffer<ffi::PRED>>()  // arrived
                                  .Ret<ffi::Buffer<ffi::PRED>>()  // stuck
                                  .Ret<ffi::Buffer<ffi::S32>>()   // position
                                  .Ret<ffi::Buffer<ffi::U32>>()   // visited
                                  .Ret<ffi::Buffer<ffi::S32>>()   // lane_steps
);
