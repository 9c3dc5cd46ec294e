// JaxswarmWalk: the walker's plain walk (jaxswarm.swarm.walking.loop._walk_runs without a hook),
// agent after agent, bit for bit the walks of the XLA walker's lanes (jaxswarm/swarm/walking/
// native.py calls it; docs/native.md says what matches and what does not).
//
//   seed u32[R, 2], log_weights f32[R or 1, N, K], start i32[R], goal i32[R],
//   neighbours i32[K] (a grid or path map's slot offsets) or i32[N, K] (a graph's nbr table)
//   attributes num_agents, max_steps, greedy_agents, blocks (each run's log's room), and the
//   lanes' schedule: lanes (loop.lanes_for of R * A, or R * A when the hook writes),
//   refill_share, compact_share, smallest_compaction (loop.REFILL_SHARE, COMPACT_SHARE,
//   SMALLEST_COMPACTION)
//   -> nodes i32[R, blocks, 16], slots i8 or i16[R, blocks, 16], offset i32[R, A],
//      moves i32[R, A], overflowed pred[R], length f32[R, A] (grids; 0 on graphs, whose
//      lengths the caller sums from the log), arrived pred[R, A], stuck pred[R, A],
//      position i32[R, A], visited u32[R, A, ceil(N / 32)], lane_steps i32[R]
//
// JaxswarmHookedWalk: the walk with a hook that has a native twin (IWD's soil rules,
// jaxswarm.swarm.walking.native.HOOK_RULES), the same inputs and outputs and
//   memory f32[R, N, K], params f32[R or 1, P] (the rule's numbers), lengths f32[K] (by slot,
//   grids) or f32[N, K] (each edge's length), attribute rule (1: the soil choice, which reads
//   the soil; 2: the soil rule, which writes it)
//   -> memory f32[R, N, K] after the walk (f32[0] under the soil choice, which does not write
//      it), state f32[R, A, E] (E = 0, or 2: velocity, carried)
// Under the soil choice the agents walk in turn, as without a hook; under the soil rule the
// drops of a run walk step by step together, as the lanes walk them (WalkTogether).
//
// The walks do not depend on the lanes' schedule, but two outputs do: the lane-steps the
// lanes' loop executes, and, when the batch's agents own more blocks of moves than the batch's
// logs hold together, which blocks the lanes' journal loses. Once every agent has walked, the
// handler replays the loop's schedule (jaxswarm.swarm.walking.loop._walk_agents: the queue, the
// refills, the narrowings) from each agent's step count alone, at one operation per lane and
// block, and takes both from it.
//
// The arithmetic is the walker's operation for operation: jaxswarm.runtime.arithmetic's exp,
// log and integer_power (arithmetic.h: the same float32 constants, the same order), the masked
// sampler's sums in slot order (jaxswarm.swarm.walking.sampler.sample_masked), the soil rule's
// sums in agent order, no contraction (-ffp-contract=off), no fast-math, and subnormals
// flushed as XLA:CPU flushes them (FTZ and DAZ set for the call and restored after it).
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
#include <type_traits>
#include <utility>
#include <vector>

#include "xla/ffi/api/ffi.h"

#include "arithmetic.h"
#include "choice.h"
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
using jaxswarm::DrawFromWeights;
using jaxswarm::IntegerPower;
using jaxswarm::InverseCdf;
using jaxswarm::SoilTerm;
using jaxswarm::Uniform;  // jaxswarm.swarm.walking.streams.uniforms

// What one call reads.
struct Map {
  const float* log_weights;  // f32[R or 1, N, K]
  int64_t table_runs;        // 1: one table for every run
  const int32_t* neighbours; // offsets i32[K] (grid) or nbr i32[N, K]
  bool grid;
  int32_t num_nodes, degree, words;
};

// The hooks with a native twin (jaxswarm.swarm.walking.native.HOOK_RULES).
enum Rule : int32_t { kPlain = 0, kSoilChoice = 1, kSoil = 2 };

// IWD's numbers, one run's, in the order jaxswarm.swarm.walking.native.HOOK_RULES lists them.
struct SoilParams {
  float alpha, eps_s, a_v, b_v, c_v, a_s, b_s, c_s, hud_scale, eps_v, rho_n, initial_velocity;
};
constexpr int32_t kSoilChoiceParams = 2;  // alpha, eps_s
constexpr int32_t kSoilParams = 12;

// What a hooked walk reads besides the map: the memory (soil f32[R, N, K], written in place by
// the soil rule), each run's numbers and each edge's length (f32[K] by slot on grids, f32[N, K]).
struct Hook {
  Rule rule;
  const float* memory;       // f32[R, N, K] as the walk starts (the soil choice reads it)
  float* written;            // f32[R, N, K] the soil rule's memory, a copy it writes, or null
  const float* params;       // f32[R or 1, P]
  int64_t params_runs;
  int32_t params_width;
  const float* lengths;      // f32[K] or f32[N, K]
};

SoilParams ParamsOf(const Hook& hook, int64_t run) {
  SoilParams p{};
  float* fields = &p.alpha;
  const float* row = hook.params + (hook.params_runs > 1 ? run : 0) * hook.params_width;
  std::copy(row, row + hook.params_width, fields);
  return p;
}

// One agent's choice at `here` (jaxswarm.swarm.walking.lanes.choose_slots): the admissible
// slots (a finite log-weight, a neighbour not visited), the soil rule's log-weights added
// (jaxswarm.swarm.iwd.soil.choice_log_weights) when `soil_row` is given, one slot drawn by
// inverse CDF from `uniform` (jaxswarm.swarm.walking.sampler.sample_masked) or, greedy, the
// most likely one. Writes the slots' neighbours into `neighbour` (i32[K]); returns the slot,
// -1 when none is admissible. `masked` and `weight` are scratch of K floats.
int32_t Choose(const Map& map, const float* row, const float* soil_row, const SoilParams& p,
               const uint32_t* visited, int32_t here, bool greedy, float uniform,
               int32_t* neighbour, bool* admissible, float* masked, float* weight) {
  const int32_t K = map.degree, N = map.num_nodes;
  const float inf = std::numeric_limits<float>::infinity();
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
    admissible[k] = row[k] > -inf && !seen;
  }
  if (soil_row != nullptr) {
    // The smallest admissible soil, a chain of minima in slot order; the soil shifted by it
    // only when it is negative.
    float smallest = inf;
    for (int32_t k = 0; k < K; ++k) {
      const float choice = admissible[k] ? soil_row[k] : inf;
      smallest = choice < smallest ? choice : smallest;
    }
    const float shift = smallest < 0.0f ? smallest : 0.0f;
    for (int32_t k = 0; k < K; ++k) {
      const float added = admissible[k] ? SoilTerm(p.alpha, p.eps_s, soil_row[k], shift) : 0.0f;
      masked[k] = admissible[k] ? row[k] + added : -inf;
    }
  } else {
    for (int32_t k = 0; k < K; ++k) masked[k] = admissible[k] ? row[k] : -inf;
  }
  float top = -inf;
  for (int32_t k = 0; k < K; ++k) top = masked[k] > top ? masked[k] : top;
  if (!std::isfinite(top)) return -1;
  if (!greedy) return InverseCdf(masked, K, top, uniform, weight);
  for (int32_t k = 0; k < K; ++k) weight[k] = masked[k] == top ? 1.0f : 0.0f;  // ties drawn
  return DrawFromWeights(weight, K, uniform);
}

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

// Where a call writes (see the file's comment for the shapes).
template <typename Slot>
struct Out {
  int32_t* nodes;
  Slot* slots;
  int32_t* offset;
  int32_t* moves;
  bool* overflowed;
  float* length;
  bool* arrived;
  bool* stuck;
  int32_t* position;
  uint32_t* visited;
  int32_t* lane_steps;
  float* state;          // f32[R, A, E], or null
  int32_t state_width;   // E
};

// What a call walks.
struct Call {
  Map map;
  Schedule schedule;
  const uint32_t* seed;
  const int32_t* start;
  const int32_t* goal;
  int64_t runs;
  int32_t agents, max_steps, greedy_agents;
  int64_t blocks;
};

// One agent as it walks.
struct Agent {
  int32_t here = 0, moves = 0, diagonal = 0;
  bool walking = false, arrived = false, stuck = false;
  float velocity = 0.0f, carried = 0.0f;  // the soil rule's state
};

// Scratch of one call, K floats or flags each.
struct Scratch {
  explicit Scratch(int32_t K) : neighbour(K), admissible(K), masked(K), weight(K) {}
  std::vector<int32_t> neighbour;
  std::vector<char> admissible;
  std::vector<float> masked, weight;
};

inline void Mark(uint32_t* visited, int32_t node) { visited[node >> 5] |= 1u << (node & 31); }

// Mark for a start outside the map (a run that starts at its goal, e.g. padding): the lanes
// index the words as jnp does, a negative word counted from the end, one past the end dropped.
inline void MarkStart(uint32_t* visited, int32_t node, int32_t words) {
  int32_t word = node >> 5;
  if (word < 0) word += words;
  if (word >= 0 && word < words) visited[word] |= 1u << (node & 31);
}

// Agent `a` of run `r` draws and takes one move from `agent.here` (`soil` null: no soil rule);
// returns the slot, -1 when it had none (the agent is then stuck).
int32_t Step(const Call& c, const float* soil, const SoilParams& p, int64_t r, int32_t a,
             Agent& agent, uint32_t* visited, Scratch& scratch) {
  const Map& map = c.map;
  const int64_t K = map.degree;
  const float* table = map.log_weights + (map.table_runs > 1 ? r : 0) * map.num_nodes * K;
  const int32_t here = agent.here;
  const float uniform = Uniform(c.seed[2 * r], c.seed[2 * r + 1], static_cast<uint32_t>(a),
                                static_cast<uint32_t>(agent.moves));
  const int32_t choice = Choose(
      map, table + here * K, soil == nullptr ? nullptr : soil + here * K, p, visited, here,
      a < c.greedy_agents, uniform, scratch.neighbour.data(),
      reinterpret_cast<bool*>(scratch.admissible.data()), scratch.masked.data(),
      scratch.weight.data());
  if (choice < 0) {
    agent.stuck = true;
    agent.walking = false;
    return choice;
  }
  agent.here = scratch.neighbour[choice];
  Mark(visited, agent.here);
  agent.diagonal += choice >= kOrthogonalSlots;
  ++agent.moves;
  agent.arrived = agent.here == c.goal[r];
  agent.walking = !agent.arrived && agent.moves < c.max_steps;
  return choice;
}

// Move `move` of the agent whose log starts at block `first` of run `r`'s log, when within the
// run's room.
template <typename Slot>
void Log(const Call& c, const Out<Slot>& out, int64_t r, int64_t first, int32_t move,
         int32_t node, int32_t slot) {
  const int64_t block = first + move / kBlock;
  if (block >= c.blocks) return;
  const int64_t at = (r * c.blocks + block) * kBlock + move % kBlock;
  out.nodes[at] = node;
  out.slots[at] = static_cast<Slot>(slot);
}

// Writes what agent `a` of run `r` did; returns the blocks of its moves.
template <typename Slot>
int64_t Finish(const Call& c, const Out<Slot>& out, int64_t r, int32_t a, const Agent& agent,
               int64_t first) {
  const int64_t row = r * c.agents + a;
  out.offset[row] = static_cast<int32_t>(first);
  out.moves[row] = agent.moves;
  out.position[row] = agent.here;
  out.arrived[row] = agent.arrived;
  out.stuck[row] = agent.stuck;
  out.length[row] = c.map.grid ? static_cast<float>(agent.moves - agent.diagonal)
                                     + static_cast<float>(agent.diagonal) * kSqrt2
                               : 0.0f;
  if (out.state_width == 2) {
    out.state[2 * row] = agent.velocity;
    out.state[2 * row + 1] = agent.carried;
  }
  return (agent.moves + kBlock - 1) / kBlock;
}

Agent Started(const Call& c, int64_t r, const SoilParams& p, uint32_t* visited) {
  Agent agent;
  agent.here = c.start[r];
  agent.arrived = agent.here == c.goal[r];
  agent.walking = !agent.arrived;
  agent.velocity = p.initial_velocity;
  MarkStart(visited, agent.here, c.map.words);
  return agent;
}

// Run `r`'s agents one after another (no hook, or a hook that only reads its memory): each
// walks to its end, its moves written straight into the log. Returns the run's blocks.
template <typename Slot>
int64_t WalkInTurn(const Call& c, const Hook& hook, int64_t r, const Out<Slot>& out,
                   Scratch& scratch) {
  const SoilParams p = hook.rule == kPlain ? SoilParams{} : ParamsOf(hook, r);
  const float* soil = hook.rule == kSoilChoice
      ? hook.memory + r * static_cast<int64_t>(c.map.num_nodes) * c.map.degree : nullptr;
  int64_t owned = 0;
  for (int32_t a = 0; a < c.agents; ++a) {
    uint32_t* visited = out.visited + (r * c.agents + a) * c.map.words;
    Agent agent = Started(c, r, p, visited);
    while (agent.walking) {
      const int32_t slot = Step(c, soil, p, r, a, agent, visited, scratch);
      if (slot >= 0) Log(c, out, r, owned, agent.moves - 1, agent.here, slot);
    }
    owned += Finish(c, out, r, a, agent, owned);
  }
  return owned;
}

// Run `r`'s drops under the soil rule (jaxswarm.swarm.iwd.soil.SOIL), all together, step by
// step as the lanes walk them: every drop chooses from the soil as it is at the start of the
// step, then the drops that cross one edge (a group, in agent order) each gain velocity from
// the edge's soil, take soil (eq. 4) and leave the edge with
// soil * keep^count - sum of rho_n keep^(count - 1 - rank) taken (eqs. 5, 6; summed in agent
// order, as jaxswarm.swarm.walking.hooks.EdgeGroups.group_sum). Returns the run's blocks.
template <typename Slot>
int64_t WalkTogether(const Call& c, const Hook& hook, int64_t r, const Out<Slot>& out,
                     Scratch& scratch, std::vector<int32_t>& group_of_edge) {
  const int32_t A = c.agents, K = c.map.degree;
  const SoilParams p = ParamsOf(hook, r);
  float* soil = hook.written + r * static_cast<int64_t>(c.map.num_nodes) * K;
  const float keep = 1.0f - p.rho_n;
  std::vector<Agent> agents(A);
  std::vector<std::vector<std::pair<int32_t, int32_t>>> moved(A);  // (node, slot) per move
  std::vector<int32_t> from(A), slot(A), group(A), rank(A);
  struct Group {
    int64_t edge;
    int32_t count;
    float before, removed;
  };
  std::vector<Group> groups;
  bool walking = false;
  for (int32_t a = 0; a < A; ++a) {
    agents[a] = Started(c, r, p, out.visited + (r * A + a) * c.map.words);
    walking |= agents[a].walking;
  }
  while (walking) {
    for (int32_t a = 0; a < A; ++a) {
      slot[a] = -1;
      if (!agents[a].walking) continue;
      from[a] = agents[a].here;
      slot[a] = Step(c, soil, p, r, a, agents[a], out.visited + (r * A + a) * c.map.words,
                     scratch);
    }
    for (int32_t a = 0; a < A; ++a) {  // the groups, in agent order
      if (slot[a] < 0) continue;
      const int64_t edge = static_cast<int64_t>(from[a]) * K + slot[a];
      if (group_of_edge[edge] < 0) {
        group_of_edge[edge] = static_cast<int32_t>(groups.size());
        groups.push_back({edge, 0, soil[edge], 0.0f});
      }
      group[a] = group_of_edge[edge];
      rank[a] = groups[group[a]].count++;
    }
    for (int32_t a = 0; a < A; ++a) {
      if (slot[a] < 0) continue;
      Group& g = groups[group[a]];
      Agent& agent = agents[a];
      const float velocity = agent.velocity + p.a_v / (p.b_v + p.c_v * (g.before * g.before));
      const float length = c.map.grid ? hook.lengths[slot[a]] : hook.lengths[g.edge];
      const float time = p.hud_scale * length / std::max(p.eps_v, velocity);
      const float taken = p.a_s / (p.b_s + p.c_s * (time * time));
      g.removed = g.removed + p.rho_n * IntegerPower(keep, g.count - 1 - rank[a]) * taken;
      agent.velocity = velocity;
      agent.carried = agent.carried + taken;
      moved[a].emplace_back(agent.here, slot[a]);
    }
    for (const Group& g : groups) {
      soil[g.edge] = g.before * IntegerPower(keep, g.count) - g.removed;
      group_of_edge[g.edge] = -1;
    }
    groups.clear();
    walking = false;
    for (const Agent& agent : agents) walking |= agent.walking;
  }
  int64_t owned = 0;
  for (int32_t a = 0; a < A; ++a) {
    for (int32_t m = 0; m < static_cast<int32_t>(moved[a].size()); ++m) {
      Log(c, out, r, owned, m, moved[a][m].first, moved[a][m].second);
    }
    owned += Finish(c, out, r, a, agents[a], owned);
  }
  return owned;
}

template <typename Slot>
ffi::Error WalkAll(const Call& c, const Hook& hook, const Out<Slot>& out) {
  const int64_t entries = c.runs * c.blocks * kBlock;
  std::fill(out.nodes, out.nodes + entries, kNoNode);
  std::fill(out.slots, out.slots + entries, static_cast<Slot>(-1));
  std::fill(out.visited, out.visited + c.runs * c.agents * c.map.words, 0u);
  Scratch scratch(c.map.degree);
  std::vector<int32_t> group_of_edge;
  if (hook.rule == kSoil) {
    group_of_edge.assign(static_cast<size_t>(c.map.num_nodes) * c.map.degree, -1);
  }
  int64_t owned_total = 0;
  for (int64_t r = 0; r < c.runs; ++r) {
    const int64_t owned = hook.rule == kSoil
        ? WalkTogether(c, hook, r, out, scratch, group_of_edge)
        : WalkInTurn(c, hook, r, out, scratch);
    out.overflowed[r] = owned > c.blocks;
    owned_total += owned;
  }
  // The XLA walker's journal has room for the batch's blocks together: when the batch's agents
  // own more, every run says it overflowed (jaxswarm.swarm.walking.journal.ordered_logs).
  if (owned_total > c.runs * c.blocks) std::fill(out.overflowed, out.overflowed + c.runs, true);
  const int32_t lane_steps = Replay(c.schedule, out.moves, out.stuck, c.start, c.goal, c.runs,
                                    c.agents, c.blocks, out.offset, out.nodes, out.slots);
  std::fill(out.lane_steps, out.lane_steps + c.runs, lane_steps);
  return ffi::Error::Success();
}

// The checks and the call shared by both handlers.
ffi::Error Walk(ffi::Buffer<ffi::U32> seed, ffi::Buffer<ffi::F32> log_weights,
                ffi::Buffer<ffi::S32> start, ffi::Buffer<ffi::S32> goal,
                ffi::Buffer<ffi::S32> neighbours, Hook hook, int32_t num_agents,
                int32_t max_steps, int32_t greedy_agents, int32_t blocks, Schedule schedule,
                ffi::ResultBuffer<ffi::S32> nodes, ffi::Result<ffi::AnyBuffer> slots,
                ffi::ResultBuffer<ffi::S32> offset, ffi::ResultBuffer<ffi::S32> moves,
                ffi::ResultBuffer<ffi::PRED> overflowed, ffi::ResultBuffer<ffi::F32> length,
                ffi::ResultBuffer<ffi::PRED> arrived, ffi::ResultBuffer<ffi::PRED> stuck,
                ffi::ResultBuffer<ffi::S32> position, ffi::ResultBuffer<ffi::U32> visited,
                ffi::ResultBuffer<ffi::S32> lane_steps, float* state, int64_t state_entries,
                int32_t state_width) {
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
  if (schedule.lanes < 1 || schedule.refill_share < 1 || schedule.compact_share < 2 ||
      schedule.smallest_compaction < 1) {
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
      lane_steps->element_count() != static_cast<size_t>(runs) ||
      state_entries != static_cast<int64_t>(per_agent) * state_width) {
    return ffi::Error::InvalidArgument("walk: an output's shape does not match the inputs");
  }
  const int32_t* starts = start.typed_data();
  const int32_t* goals = goal.typed_data();
  for (int64_t r = 0; r < runs; ++r) {  // a run whose start is its goal does not walk
    if (starts[r] != goals[r] && (starts[r] < 0 || starts[r] >= N || goals[r] < 0 ||
                                  goals[r] >= N)) {
      return ffi::Error::InvalidArgument("walk: start or goal outside the map");
    }
  }
  FlushDenormals flush;
  const Call call{{log_weights.typed_data(), table_dims[0], neighbours.typed_data(), grid,
                   static_cast<int32_t>(N), static_cast<int32_t>(K), static_cast<int32_t>(words)},
                  schedule, seed.typed_data(), starts, goals, runs, num_agents, max_steps,
                  greedy_agents, blocks};
  auto run = [&](auto* slot_data) {
    using Slot = std::remove_pointer_t<decltype(slot_data)>;
    const Out<Slot> out{nodes->typed_data(), slot_data, offset->typed_data(),
                        moves->typed_data(), overflowed->typed_data(), length->typed_data(),
                        arrived->typed_data(), stuck->typed_data(), position->typed_data(),
                        visited->typed_data(), lane_steps->typed_data(), state, state_width};
    return WalkAll(call, hook, out);
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
  const Hook plain{kPlain, nullptr, nullptr, nullptr, 0, 0, nullptr};
  return Walk(seed, log_weights, start, goal, neighbours, plain, num_agents, max_steps,
              greedy_agents, blocks, {lanes, refill_share, compact_share, smallest_compaction},
              nodes, slots, offset, moves, overflowed, length, arrived, stuck, position, visited,
              lane_steps, nullptr, 0, 0);
}

ffi::Error HookedWalkImpl(
    ffi::Buffer<ffi::U32> seed, ffi::Buffer<ffi::F32> log_weights, ffi::Buffer<ffi::S32> start,
    ffi::Buffer<ffi::S32> goal, ffi::Buffer<ffi::S32> neighbours, ffi::Buffer<ffi::F32> memory,
    ffi::Buffer<ffi::F32> params, ffi::Buffer<ffi::F32> lengths, int32_t rule,
    int32_t num_agents, int32_t max_steps, int32_t greedy_agents, int32_t blocks, int32_t lanes,
    int32_t refill_share, int32_t compact_share, int32_t smallest_compaction,
    ffi::ResultBuffer<ffi::S32> nodes, ffi::Result<ffi::AnyBuffer> slots,
    ffi::ResultBuffer<ffi::S32> offset, ffi::ResultBuffer<ffi::S32> moves,
    ffi::ResultBuffer<ffi::PRED> overflowed, ffi::ResultBuffer<ffi::F32> length,
    ffi::ResultBuffer<ffi::PRED> arrived, ffi::ResultBuffer<ffi::PRED> stuck,
    ffi::ResultBuffer<ffi::S32> position, ffi::ResultBuffer<ffi::U32> visited,
    ffi::ResultBuffer<ffi::S32> lane_steps, ffi::ResultBuffer<ffi::F32> memory_after,
    ffi::ResultBuffer<ffi::F32> state) {
  if (rule != kSoilChoice && rule != kSoil) {
    return ffi::Error::InvalidArgument("hooked walk: unknown rule");
  }
  const int64_t runs = seed.dimensions().size() == 2 ? seed.dimensions()[0] : 0;
  auto table_dims = log_weights.dimensions();
  if (table_dims.size() != 3) {
    return ffi::Error::InvalidArgument("hooked walk: log_weights must be f32[R or 1, N, K]");
  }
  const int64_t cells = table_dims[1] * table_dims[2];
  const int32_t width = rule == kSoil ? kSoilParams : kSoilChoiceParams;
  auto params_dims = params.dimensions();
  // The soil choice reads the memory in place and writes none (an empty memory_after).
  const size_t written = rule == kSoil ? static_cast<size_t>(runs * cells) : 0;
  if (memory.element_count() != static_cast<size_t>(runs * cells) ||
      memory_after->element_count() != written) {
    return ffi::Error::InvalidArgument("hooked walk: memory must be f32[R, N, K], and the "
                                       "memory after f32[R, N, K] (the soil rule) or f32[0]");
  }
  if (params_dims.size() != 2 || params_dims[1] != width ||
      (params_dims[0] != 1 && params_dims[0] != runs)) {
    return ffi::Error::InvalidArgument("hooked walk: params must be f32[R or 1, P], P the "
                                       "rule's numbers");
  }
  if (lengths.element_count() != static_cast<size_t>(table_dims[2]) &&
      lengths.element_count() != static_cast<size_t>(cells)) {
    return ffi::Error::InvalidArgument("hooked walk: lengths must be f32[K] or f32[N, K]");
  }
  const int32_t state_width = rule == kSoil ? 2 : 0;
  std::copy(memory.typed_data(), memory.typed_data() + written, memory_after->typed_data());
  const Hook hook{static_cast<Rule>(rule), memory.typed_data(),
                  rule == kSoil ? memory_after->typed_data() : nullptr, params.typed_data(),
                  params_dims[0], width, lengths.typed_data()};
  return Walk(seed, log_weights, start, goal, neighbours, hook, num_agents, max_steps,
              greedy_agents, blocks, {lanes, refill_share, compact_share, smallest_compaction},
              nodes, slots, offset, moves, overflowed, length, arrived, stuck, position, visited,
              lane_steps, state->typed_data(), static_cast<int64_t>(state->element_count()),
              state_width);
}

// The bindings both handlers share, in their order: the walk's inputs, its sizes and the lanes'
// schedule, its outputs (a Binding's methods take it as an rvalue).
template <typename Binding>
auto WalkInputs(Binding binding) {
  return std::move(binding).template Arg<ffi::Buffer<ffi::U32>>()  // seed
      .template Arg<ffi::Buffer<ffi::F32>>()                    // log_weights
      .template Arg<ffi::Buffer<ffi::S32>>()                    // start
      .template Arg<ffi::Buffer<ffi::S32>>()                    // goal
      .template Arg<ffi::Buffer<ffi::S32>>();                   // neighbours
}

template <typename Binding>
auto WalkAttributes(Binding binding) {
  return std::move(binding).template Attr<int32_t>("num_agents")
      .template Attr<int32_t>("max_steps")
      .template Attr<int32_t>("greedy_agents")
      .template Attr<int32_t>("blocks")
      .template Attr<int32_t>("lanes")
      .template Attr<int32_t>("refill_share")
      .template Attr<int32_t>("compact_share")
      .template Attr<int32_t>("smallest_compaction");
}

template <typename Binding>
auto WalkOutputs(Binding binding) {
  return std::move(binding).template Ret<ffi::Buffer<ffi::S32>>()  // nodes
      .template Ret<ffi::AnyBuffer>()                           // slots
      .template Ret<ffi::Buffer<ffi::S32>>()                    // offset
      .template Ret<ffi::Buffer<ffi::S32>>()                    // moves
      .template Ret<ffi::Buffer<ffi::PRED>>()                   // overflowed
      .template Ret<ffi::Buffer<ffi::F32>>()                    // length
      .template Ret<ffi::Buffer<ffi::PRED>>()                   // arrived
      .template Ret<ffi::Buffer<ffi::PRED>>()                   // stuck
      .template Ret<ffi::Buffer<ffi::S32>>()                    // position
      .template Ret<ffi::Buffer<ffi::U32>>()                    // visited
      .template Ret<ffi::Buffer<ffi::S32>>();                   // lane_steps
}

}  // namespace

XLA_FFI_DEFINE_HANDLER_SYMBOL(JaxswarmWalk, WalkImpl,
                              WalkOutputs(WalkAttributes(WalkInputs(ffi::Ffi::Bind()))));

XLA_FFI_DEFINE_HANDLER_SYMBOL(
    JaxswarmHookedWalk, HookedWalkImpl,
    WalkOutputs(WalkAttributes(WalkInputs(ffi::Ffi::Bind())
                                   .Arg<ffi::Buffer<ffi::F32>>()  // memory
                                   .Arg<ffi::Buffer<ffi::F32>>()  // params
                                   .Arg<ffi::Buffer<ffi::F32>>()  // lengths
                                   .Attr<int32_t>("rule")))
        .Ret<ffi::Buffer<ffi::F32>>()   // memory after the walk
        .Ret<ffi::Buffer<ffi::F32>>());  // state
