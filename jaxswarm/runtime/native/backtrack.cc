// JaxswarmDepthFirst: the walker's depth-first walk (jaxswarm.swarm.walking.backtrack's
// depth_first_walk, the walk of an agent that backs out of dead ends), walk after walk, bit for
// bit the XLA implementation's walks (jaxswarm/swarm/walking/native_backtrack.py calls it;
// docs/native.md says what matches).
//
//   keys u32[B..., W, 2] (each walk's key data), table f32[B..., N, K], soil f32[B..., N, K]
//   (IWD's soil rule) or an empty f32[B..., 0, K] (the table's row alone), alpha f32[B...],
//   eps_s f32[B...] (the soil rule's numbers), nbr i32[B..., N, K], start i32[B...],
//   goal i32[B...]; attributes greedy (take the most likely move, the first of equals) and
//   partitionable (jax_threefry_partitionable: how a uniform's bits come from the hash)
//   -> path i32[B..., W, max_nodes] (the way without its dead ends, -1 padded; all -1 when
//      the goal was not reached), found pred[B..., W], moves i32[B..., W]
//
// B... are the batch axes a vmap adds (vmap_method "broadcast_all": every input has them): each
// of their runs is a map, a rule, a start and a goal, and W walks over them with their own keys.
//
// A walk's m-th move draws jax.random.uniform(jax.random.fold_in(key, m), (1,)): threefry2x32
// (20 rounds) folds m into the key, hashes the counter (0, 0) with the folded key, and turns the
// bits into a float in [0, 1) as jax.random.uniform does. The rest is the XLA walk's arithmetic
// operation for operation: the choice rule (the table's row; or IWD's choice_log_weights: the
// smallest admissible soil as a chain of minima in slot order, g = soil - min(smallest, 0),
// log_f = -Log(eps_s + g), the row plus alpha * log_f), and the masked sampler of walk.cc
// (Exp(masked - top), sums in slot order, the prefix count), with no contraction
// (-ffp-contract=off), no fast-math and subnormals flushed (FlushDenormals) for the call.
//
// Thread safety: no statics, no globals; the handler reads its inputs and writes its own outputs
// (its scratch is per call), so XLA may run calls at once.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "xla/ffi/api/ffi.h"

#include "arithmetic.h"
#include "choice.h"

namespace ffi = xla::ffi;

namespace {

constexpr int32_t kNoNode = -1;  // jaxswarm.world.graph.NO_NODE

// threefry2x32's rotations, the first four for the even groups of rounds, the others for the odd.
constexpr int kRotations[2][4] = {{13, 15, 26, 6}, {17, 29, 16, 24}};
constexpr uint32_t kParity = 0x1BD11BDAu;  // threefry's key schedule constant

using jaxswarm::Exp;
using jaxswarm::FlushDenormals;
using jaxswarm::InverseCdf;
using jaxswarm::SoilTerm;

struct Words {
  uint32_t first, second;
};

// threefry2x32 of the counter pair (x0, x1) under the key (k0, k1), as JAX's
// _threefry2x32_lowering: 5 groups of 4 rounds, the key schedule injected after each.
Words Threefry2x32(uint32_t k0, uint32_t k1, uint32_t x0, uint32_t x1) {
  const uint32_t schedule[3] = {k0, k1, k0 ^ k1 ^ kParity};
  x0 += schedule[0];
  x1 += schedule[1];
  for (uint32_t group = 0; group < 5; ++group) {
    for (int rotation : kRotations[group % 2]) {
      x0 += x1;
      x1 = (x1 << rotation) | (x1 >> (32 - rotation));
      x1 ^= x0;
    }
    x0 += schedule[(group + 1) % 3];
    x1 += schedule[(group + 2) % 3] + group + 1;
  }
  return {x0, x1};
}

// jax.random.uniform(jax.random.fold_in(key, move), (1,))[0] for the key data (k0, k1).
float Draw(uint32_t k0, uint32_t k1, uint32_t move, bool partitionable) {
  // fold_in: the hash of the counter threefry_seed(move) = (0, move).
  const Words folded = Threefry2x32(k0, k1, 0u, move);
  // random_bits of one 32-bit word: the hash of the counter (0, 0); partitionable, the xor of
  // both output words, else the first.
  const Words hashed = Threefry2x32(folded.first, folded.second, 0u, 0u);
  const uint32_t bits = partitionable ? hashed.first ^ hashed.second : hashed.first;
  // The 23 high bits as the mantissa of a float in [1, 2), less 1 (exact): [0, 1).
  const uint32_t mantissa = (bits >> 9) | 0x3F800000u;
  float one_to_two;
  std::memcpy(&one_to_two, &mantissa, sizeof one_to_two);
  return one_to_two - 1.0f;
}

// XLA's minimum and maximum: a NaN operand gives NaN.
float Minimum(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::numeric_limits<float>::quiet_NaN();
  return b < a ? b : a;
}

float Maximum(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::numeric_limits<float>::quiet_NaN();
  return b > a ? b : a;
}

// One run's map and rule: rows of N x K.
struct Run {
  const float* table;
  const float* soil;  // null: the table's row is the rule
  float alpha, eps_s;
  const int32_t* nbr;
  int32_t start, goal;
};

// What every walk of a call shares: its sizes, attributes and scratch.
struct Walker {
  int32_t num_nodes, degree, max_nodes;
  bool greedy, partitionable;
  std::vector<char> visited;            // [N]
  std::vector<int32_t> heads;           // [K] each slot's neighbour (0 for an empty slot)
  std::vector<char> unvisited;          // [K] the slot leads to a node not yet entered
  std::vector<float> options, weights;  // [K]
};

// The options out of `here` (depth_first_walk's `options`): the rule's log-weights where the slot
// leads to an unvisited node, -inf elsewhere; fills the walker's heads and unvisited too.
void Options(const Run& run, int32_t here, Walker& w) {
  const int32_t K = w.degree;
  const int64_t at = static_cast<int64_t>(here) * K;
  const float* row = run.table + at;
  const float inf = std::numeric_limits<float>::infinity();
  for (int32_t k = 0; k < K; ++k) {
    const int32_t nb = run.nbr[at + k];
    w.heads[k] = nb >= 0 ? nb : 0;
    w.unvisited[k] = nb >= 0 && !w.visited[w.heads[k]];
  }
  if (run.soil == nullptr) {  // bug2's first ant: the table's row
    for (int32_t k = 0; k < K; ++k) w.options[k] = w.unvisited[k] ? row[k] : -inf;
    return;
  }
  // IWD's soil_choice: the row plus choice_log_weights over the admissible slots.
  const float* soil = run.soil + at;
  float smallest = inf;
  for (int32_t k = 0; k < K; ++k) {
    const bool admissible = w.unvisited[k] && row[k] > -inf;
    const float choice = admissible ? soil[k] : inf;
    smallest = k == 0 ? choice : Minimum(smallest, choice);
  }
  const float shift = Minimum(smallest, 0.0f);  // shifted only when negative
  for (int32_t k = 0; k < K; ++k) {
    const bool admissible = w.unvisited[k] && row[k] > -inf;
    const float value = row[k] + (admissible ? SoilTerm(run.alpha, run.eps_s, soil[k], shift)
                                             : 0.0f);
    w.options[k] = w.unvisited[k] ? value : -inf;
  }
}

// jnp.argmax of the options (the first of equals; the first NaN if any): its slot, and whether
// it may be taken (its option > -inf, so not NaN).
int32_t Greediest(const Walker& w, bool* can_move) {
  int32_t best = 0;
  for (int32_t k = 1; k < w.degree && !std::isnan(w.options[best]); ++k) {
    if (std::isnan(w.options[k]) || w.options[k] > w.options[best]) best = k;
  }
  *can_move = w.options[best] > -std::numeric_limits<float>::infinity();
  return best;
}

// sample_masked over the options with every slot masked in, for the uniform `u`: the slot drawn
// (0 when none can be), and whether one can (the largest option finite, no NaN).
int32_t Drawn(Walker& w, float u, bool* can_move) {
  const int32_t K = w.degree;
  float top = w.options[0];
  for (int32_t k = 1; k < K; ++k) top = Maximum(top, w.options[k]);
  *can_move = std::isfinite(top);
  if (!*can_move) return 0;
  return InverseCdf(w.options.data(), K, top, u, w.weights.data());
}

// One depth-first walk from run.start with the key data (k0, k1): its stack is `path`
// (max_nodes entries; all -1 when the goal was not reached). Returns the moves made.
int32_t WalkOne(const Run& run, uint32_t k0, uint32_t k1, Walker& w, int32_t* path,
                bool* found) {
  std::fill(path, path + w.max_nodes, kNoNode);
  std::fill(w.visited.begin(), w.visited.end(), 0);
  path[0] = run.start;
  w.visited[run.start] = 1;
  int32_t depth = 1, move = 0;
  while (depth > 0 && path[depth - 1] != run.goal) {
    Options(run, path[depth - 1], w);
    bool can_move;
    const int32_t best = w.greedy ? Greediest(w, &can_move)
                                  : Drawn(w, Draw(k0, k1, static_cast<uint32_t>(move),
                                                  w.partitionable), &can_move);
    if (can_move && depth < w.max_nodes) {  // forward into the chosen neighbour
      path[depth++] = w.heads[best];
      w.visited[w.heads[best]] = 1;
    } else {  // back out of a dead end (or of a way that would be too long)
      path[--depth] = kNoNode;
    }
    ++move;
  }
  *found = depth > 0;  // the stack holds the way; it is empty (all -1) otherwise
  return move;
}

// Whether `dims` has rank batch.size() + extra and starts with the batch axes.
bool Batched(ffi::Span<const int64_t> dims, ffi::Span<const int64_t> batch, size_t extra) {
  if (dims.size() != batch.size() + extra) return false;
  return std::equal(batch.begin(), batch.end(), dims.begin());
}

// The inputs' shapes (see the top of the file), or the first thing wrong with them.
ffi::Error CheckShapes(ffi::Span<const int64_t> batch, ffi::Span<const int64_t> keys,
                       ffi::Span<const int64_t> table, ffi::Span<const int64_t> soil,
                       ffi::Span<const int64_t> nbr, size_t goals, size_t alphas, size_t epss,
                       size_t runs) {
  if (!Batched(keys, batch, 2) || keys.back() != 2) {
    return ffi::Error::InvalidArgument("depth_first: keys must be u32[B..., W, 2]");
  }
  if (!Batched(table, batch, 2) || table[batch.size()] < 1 || table.back() < 1) {
    return ffi::Error::InvalidArgument("depth_first: table must be f32[B..., N, K], N, K >= 1");
  }
  if (!(nbr == table)) {
    return ffi::Error::InvalidArgument("depth_first: nbr must be i32[B..., N, K] as table");
  }
  const bool empty = Batched(soil, batch, 2) && (soil[batch.size()] == 0 || soil.back() == 0);
  if (!empty && !(soil == table)) {
    return ffi::Error::InvalidArgument("depth_first: soil must be f32[B..., N, K] or empty");
  }
  if (goals != runs || alphas != runs || epss != runs) {
    return ffi::Error::InvalidArgument("depth_first: goal, alpha and eps_s must be [B...] as "
                                       "start");
  }
  return ffi::Error::Success();
}

// Start, goal and every neighbour within the map (the walk reads nodes by them).
ffi::Error CheckNodes(const int32_t* start, const int32_t* goal, const int32_t* nbr, int64_t runs,
                      int64_t N, int64_t K) {
  for (int64_t r = 0; r < runs; ++r) {
    if (start[r] < 0 || start[r] >= N || goal[r] < 0 || goal[r] >= N) {
      return ffi::Error::InvalidArgument("depth_first: start or goal outside the map");
    }
  }
  for (int64_t i = 0; i < runs * N * K; ++i) {
    if (nbr[i] >= N) return ffi::Error::InvalidArgument("depth_first: nbr names no node");
  }
  return ffi::Error::Success();
}

ffi::Error DepthFirstImpl(ffi::Buffer<ffi::U32> keys, ffi::Buffer<ffi::F32> table,
                          ffi::Buffer<ffi::F32> soil, ffi::Buffer<ffi::F32> alpha,
                          ffi::Buffer<ffi::F32> eps_s, ffi::Buffer<ffi::S32> nbr,
                          ffi::Buffer<ffi::S32> start, ffi::Buffer<ffi::S32> goal, int32_t greedy,
                          int32_t partitionable, ffi::ResultBuffer<ffi::S32> path,
                          ffi::ResultBuffer<ffi::PRED> found, ffi::ResultBuffer<ffi::S32> moves) {
  const auto batch = start.dimensions();
  const int64_t runs = static_cast<int64_t>(start.element_count());
  if (ffi::Error error = CheckShapes(batch, keys.dimensions(), table.dimensions(),
                                     soil.dimensions(), nbr.dimensions(), goal.element_count(),
                                     alpha.element_count(), eps_s.element_count(), runs);
      error.failure()) {
    return error;
  }
  const int64_t W = keys.dimensions()[batch.size()];
  const int64_t N = table.dimensions()[batch.size()], K = table.dimensions().back();
  const auto path_dims = path->dimensions();
  if (!Batched(path_dims, batch, 2) || path_dims[batch.size()] != W || path_dims.back() < 1 ||
      found->element_count() != static_cast<size_t>(runs * W) ||
      moves->element_count() != static_cast<size_t>(runs * W)) {
    return ffi::Error::InvalidArgument("depth_first: path must be i32[B..., W, max_nodes >= 1], "
                                       "found and moves [B..., W]");
  }
  if (ffi::Error error = CheckNodes(start.typed_data(), goal.typed_data(), nbr.typed_data(), runs,
                                    N, K);
      error.failure()) {
    return error;
  }
  FlushDenormals flush;
  const int64_t max_nodes = path_dims.back();
  Walker walker{static_cast<int32_t>(N), static_cast<int32_t>(K), static_cast<int32_t>(max_nodes),
                greedy != 0, partitionable != 0, std::vector<char>(N), std::vector<int32_t>(K),
                std::vector<char>(K), std::vector<float>(K), std::vector<float>(K)};
  const bool soil_rule = soil.element_count() > 0;
  for (int64_t r = 0; r < runs; ++r) {
    const Run run{table.typed_data() + r * N * K,
                  soil_rule ? soil.typed_data() + r * N * K : nullptr,
                  alpha.typed_data()[r], eps_s.typed_data()[r], nbr.typed_data() + r * N * K,
                  start.typed_data()[r], goal.typed_data()[r]};
    for (int64_t w = 0; w < W; ++w) {
      const int64_t walk = r * W + w;
      const uint32_t* key = keys.typed_data() + 2 * walk;
      moves->typed_data()[walk] = WalkOne(run, key[0], key[1], walker,
                                          path->typed_data() + walk * max_nodes,
                                          found->typed_data() + walk);
    }
  }
  return ffi::Error::Success();
}

}  // namespace

XLA_FFI_DEFINE_HANDLER_SYMBOL(JaxswarmDepthFirst, DepthFirstImpl,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::U32>>()  // keys
                                  .Arg<ffi::Buffer<ffi::F32>>()  // table
                                  .Arg<ffi::Buffer<ffi::F32>>()  // soil
                                  .Arg<ffi::Buffer<ffi::F32>>()  // alpha
                                  .Arg<ffi::Buffer<ffi::F32>>()  // eps_s
                                  .Arg<ffi::Buffer<ffi::S32>>()  // nbr
                                  .Arg<ffi::Buffer<ffi::S32>>()  // start
                                  .Arg<ffi::Buffer<ffi::S32>>()  // goal
                                  .Attr<int32_t>("greedy")
                                  .Attr<int32_t>("partitionable")
                                  .Ret<ffi::Buffer<ffi::S32>>()   // path
                                  .Ret<ffi::Buffer<ffi::PRED>>()  // found
                                  .Ret<ffi::Buffer<ffi::S32>>()   // moves
);
