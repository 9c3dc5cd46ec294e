// JaxswarmSmooth: IWD_PG's global smooth operator (jaxswarm.swarm.iwd.smooth's smooth_paths),
// every selected path of a call smoothed by passes until one changes nothing, bit for bit the
// XLA implementation's paths (jaxswarm/swarm/iwd/native_smooth.py calls it; docs/native.md).
//
//   paths i32[B..., A, W] (walks on the map, -1 padded), which pred[B..., A] (the paths to
//   smooth), valid pred[B..., N, K] (the map's valid edges), nbr i32[B..., N, K] (a general
//   graph's neighbours; an empty i32[B..., 0, K] on a lattice), cost f32[B..., N, K] (a general
//   graph's edge lengths) or f32[B..., 1, K] (a lattice's slot lengths, slot_lengths);
//   attributes width (a grid's or path map's width, node i the cell (i % width, i / width);
//   0: a general graph) and improvement (smooth.IMPROVEMENT as float32)
//   -> smoothed i32[B..., A, W] (the paths of `which` smoothed, the others as they were)
//
// B... are the batch axes a vmap adds (vmap_method "broadcast_all": every input has them).
//
// A pass is smooth._smooth_pass operation for operation: the lengths of lattice_costs (a move's
// edge from the cells' coordinates and the node's mask of valid moves) on lattices, of
// graph_costs (the edge searched among the node's slots, the least length of the slots that
// reach it) on general graphs; the windows' sums m0 + m1 and (m0 + m1) + m2 in that order; the
// thresholds `direct < window - improvement` and `via < min(window, direct) - improvement` with
// XLA's NaN-propagating minimum; the direct shortcuts taken where no candidate starts one or two
// positions before; else the first window a middle node shortens, through the first slot among
// equals. A pass that takes a direct shortcut does not need the middle nodes (its result is the
// shortened path), so the legs are computed only when there is none, and only up to the first
// window they shorten. Every path of `which` is smoothed (the XLA code smooths each distinct one
// once: the same function of each path), a path equal to an earlier selected one copied from it.
// No contraction (-ffp-contract=off), no fast-math, subnormals flushed (FlushDenormals).
//
// Thread safety: no statics, no globals; scratch is per call.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "xla/ffi/api/ffi.h"

#include "arithmetic.h"

namespace ffi = xla::ffi;

namespace {

constexpr int32_t kNoNode = -1;  // jaxswarm.world.graph.NO_NODE
// jaxswarm.world.lattice.DIRECTIONS: each slot's (dx, dy).
constexpr int32_t kDirections[8][2] = {{1, 0},  {0, 1},   {-1, 0}, {0, -1},
                                       {1, 1},  {-1, 1},  {-1, -1}, {1, -1}};
constexpr int32_t kOrthogonalSlots = 4;  // jaxswarm.world.lattice.ORTHOGONAL_SLOTS
constexpr float kInf = std::numeric_limits<float>::infinity();

using jaxswarm::FlushDenormals;

// XLA's minimum: a NaN operand gives NaN.
float Minimum(float a, float b) {
  if (std::isnan(a) || std::isnan(b)) return std::numeric_limits<float>::quiet_NaN();
  return b < a ? b : a;
}

// One batch member's map, and the lattice's tables (width > 0).
struct Map {
  int32_t num_nodes, degree, width;
  const bool* valid;    // [N, K]
  const int32_t* nbr;   // [N, K], general graphs
  const float* cost;    // [N, K] on general graphs, [K] slot lengths on lattices
  float straight, diagonal;   // lattice_costs' lengths of an odd and an even code
  int32_t codes[8], offsets[8];
  std::vector<int32_t> masks;  // [N] each node's valid moves, a bit per code; -1: not yet made
};

// lattice_costs' `moves[node]`: the bits 3 (dy + 1) + dx + 1 of the node's valid slots.
int32_t Mask(Map& map, int32_t node) {
  int32_t& mask = map.masks[node];
  if (mask < 0) {
    mask = 0;
    for (int32_t k = 0; k < map.degree; ++k) {
      if (map.valid[static_cast<int64_t>(node) * map.degree + k]) mask |= 1 << map.codes[k];
    }
  }
  return mask;
}

// lattice_costs' `step`: the length of the move of cell offset (dx, dy) set in `mask`, else inf.
float Step(const Map& map, int32_t dx, int32_t dy, int32_t mask) {
  const int32_t code = std::clamp((dy + 1) * 3 + dx + 1, 0, 8);
  const bool near = std::abs(dx) <= 1 && std::abs(dy) <= 1 && ((mask >> code) & 1) == 1;
  return near ? (code % 2 == 1 ? map.straight : map.diagonal) : kInf;
}

// graph_costs' edge_cost: the least length of the valid slots of `here` that reach `there`;
// inf where there is none or either is padding.
float EdgeCost(const Map& map, int32_t here, int32_t there) {
  if (here < 0 || there < 0) return kInf;
  const int64_t row = static_cast<int64_t>(here) * map.degree;
  float least = kInf;
  for (int32_t k = 0; k < map.degree; ++k) {
    const bool hit = map.nbr[row + k] == there && map.valid[row + k];
    least = Minimum(least, hit ? map.cost[row + k] : kInf);
  }
  return least;
}

// The nodes at positions t .. t + 3 of a path (-1 past its end: costs' `ahead`), and on a
// lattice their cells (where they are nodes).
struct Window {
  int32_t node[4], x[4], y[4];
};

// The length of the edge from the window's i-th node to its j-th (lattice_costs' `edge`, or
// graph_costs' edge_cost).
float Edge(Map& map, const Window& a, int i, int j) {
  if (map.width == 0) return EdgeCost(map, a.node[i], a.node[j]);
  if (a.node[i] < 0 || a.node[j] < 0) return kInf;
  return Step(map, a.x[j] - a.x[i], a.y[j] - a.y[i], Mask(map, a.node[i]));
}

// The lengths a pass compares at one position: moves[i] = p[t + i] -> p[t + i + 1], direct[w - 2]
// = p[t] -> p[t + w], window[w - 2] = the moves' sum.
struct Lengths {
  float moves[3], direct[2], window[2];
};

Lengths LengthsAt(Map& map, const Window& a) {
  Lengths out;
  for (int i = 0; i < 3; ++i) out.moves[i] = Edge(map, a, i, i + 1);
  out.direct[0] = Edge(map, a, 0, 2);
  out.direct[1] = Edge(map, a, 0, 3);
  out.window[0] = out.moves[0] + out.moves[1];
  out.window[1] = out.moves[0] + out.moves[1] + out.moves[2];
  return out;
}

// The legs p[t] -> m -> p[t + w] of slot k (m the slot's neighbour, inf when m is on the path):
// legs[w - 2]; returns m.
int32_t Legs(Map& map, const Window& a, const char* on_path, int32_t k, float legs[2]) {
  const int32_t K = map.degree, N = map.num_nodes;
  const int32_t node = std::max(a.node[0], 0);
  const int64_t slot = static_cast<int64_t>(node) * K + k;
  if (map.width == 0) {  // graph_costs
    const int32_t middle = map.nbr[slot];
    const float first =
        map.valid[slot] && !on_path[std::max(middle, 0)] ? map.cost[slot] : kInf;
    for (int w = 2; w <= 3; ++w) legs[w - 2] = first + EdgeCost(map, middle, a.node[w]);
    return middle;
  }
  const int32_t middle = std::clamp(node + map.offsets[k], 0, N - 1);  // lattice_costs
  const bool slot_valid = ((Mask(map, node) >> map.codes[k]) & 1) == 1;
  const float first = slot_valid && !on_path[middle] ? map.cost[k] : kInf;
  const int32_t reach = map.valid[slot] ? Mask(map, middle) : 0;
  for (int w = 2; w <= 3; ++w) {
    const float second = a.node[0] >= 0 && a.node[w] >= 0
                             ? Step(map, (a.x[w] - a.x[0]) - kDirections[k][0],
                                    (a.y[w] - a.y[0]) - kDirections[k][1], reach)
                             : kInf;
    legs[w - 2] = first + second;
  }
  return middle;
}

// What a pass shares: the map, the threshold and scratch of W and N.
struct Smoother {
  Map map;
  float improvement;
  int64_t W, extent;              // the paths' width; the current path's last node + 1
  std::vector<char> on_path;     // [N]
  std::vector<int32_t> next;     // [W] the path after the pass
  std::vector<Lengths> lengths;  // [W]
  std::vector<int32_t> xs, ys;   // [W] on a lattice, the cells of the path's nodes
};

// The window at position t of `path` (s.xs and s.ys its cells on a lattice).
Window Ahead(const Smoother& s, const int32_t* path, int64_t t) {
  Window out{};
  for (int64_t i = 0; i < 4; ++i) {
    const bool inside = t + i < s.W;
    out.node[i] = inside ? path[t + i] : kNoNode;
    if (s.map.width > 0 && inside) {
      out.x[i] = s.xs[t + i];
      out.y[i] = s.ys[t + i];
    }
  }
  return out;
}

// The direct shortcuts of a pass (its `taken` windows) cut out of `path` into s.next; whether
// there was one. s.lengths must hold each position's lengths.
bool Shortcuts(Smoother& s, const int32_t* path) {
  bool before1 = false, before2 = false, any = false;  // candidates one and two back
  int64_t latest = -1, latest_width = 0, out = 0;
  for (int64_t t = 0; t < s.extent; ++t) {
    const Lengths& l = s.lengths[t];
    const bool short2 = l.direct[0] < l.window[0] - s.improvement;
    const bool short3 = l.direct[1] < l.window[1] - s.improvement;
    const bool candidate = short2 || short3;
    if (candidate && !(before1 || before2)) {
      latest = t;
      latest_width = short2 ? 2 : 3;
      any = true;
    }
    const bool inside = latest >= 0 && t > latest && t < latest + latest_width;
    if (!inside) s.next[out++] = path[t];
    before2 = before1;
    before1 = candidate;
  }
  std::fill(s.next.begin() + out, s.next.end(), kNoNode);
  return any;
}

// The first window a middle node shortens, rerouted through it into s.next; whether there was
// one.
bool Reroute(Smoother& s, const int32_t* path) {
  const int32_t K = s.map.degree;
  for (int64_t t = 0; t < s.extent; ++t) {
    const Window a = Ahead(s, path, t);
    // No end node (nor, on a lattice, a start): every leg is inf (or NaN), so no `better`.
    if ((a.node[2] < 0 && a.node[3] < 0) || (s.map.width > 0 && a.node[0] < 0)) continue;
    const Lengths& l = s.lengths[t];
    float via[2] = {kInf, kInf}, best[2] = {kInf, kInf};
    int32_t through[2] = {0, 0};
    for (int32_t k = 0; k < K; ++k) {
      float legs[2];
      const int32_t middle = Legs(s.map, a, s.on_path.data(), k, legs);
      for (int i = 0; i < 2; ++i) {
        via[i] = k == 0 ? legs[i] : Minimum(via[i], legs[i]);
        if (k == 0 || legs[i] < best[i]) {  // jnp.argmin: the first slot among equals
          best[i] = legs[i];
          through[i] = middle;
        }
      }
    }
    const bool better2 = via[0] < Minimum(l.window[0], l.direct[0]) - s.improvement;
    const bool better3 = via[1] < Minimum(l.window[1], l.direct[1]) - s.improvement;
    if (!(better2 || better3)) continue;
    std::copy(path, path + s.W, s.next.begin());
    if (t + 1 < s.W) s.next[t + 1] = better2 ? through[0] : through[1];
    if (!better2) {  // a window of three moves loses its node at t + 2
      for (int64_t p = t + 2; p < s.W; ++p) s.next[p] = p + 1 < s.W ? s.next[p + 1] : kNoNode;
    }
    return true;
  }
  return false;
}

// One pass over `path` (W nodes), written back into it; whether it changed anything. Past the
// path's last node every position is padding, where a pass finds nothing (no candidate, no leg
// that is not inf) and keeps the padding: the positions up to it are enough.
bool Pass(Smoother& s, int32_t* path) {
  s.extent = 0;
  for (int64_t t = 0; t < s.W; ++t) {
    if (path[t] < 0) continue;
    s.extent = t + 1;
    s.on_path[path[t]] = 1;
    if (s.map.width > 0) {
      s.xs[t] = path[t] % s.map.width;
      s.ys[t] = path[t] / s.map.width;
    }
  }
  for (int64_t t = 0; t < s.extent; ++t) s.lengths[t] = LengthsAt(s.map, Ahead(s, path, t));
  const bool changed = Shortcuts(s, path) || Reroute(s, path);
  for (int64_t t = 0; t < s.W; ++t) {
    if (path[t] >= 0) s.on_path[path[t]] = 0;
  }
  if (changed) std::copy(s.next.begin(), s.next.end(), path);
  return changed;
}

// Whether `dims` is the batch axes followed by `extra` more.
bool Batched(ffi::Span<const int64_t> dims, ffi::Span<const int64_t> batch, size_t extra) {
  if (dims.size() != batch.size() + extra) return false;
  return std::equal(batch.begin(), batch.end(), dims.begin());
}

// The inputs' shapes (see the top of the file), or the first thing wrong with them.
ffi::Error CheckShapes(ffi::Span<const int64_t> batch, ffi::Span<const int64_t> paths,
                       ffi::Span<const int64_t> valid, ffi::Span<const int64_t> nbr,
                       ffi::Span<const int64_t> cost, ffi::Span<const int64_t> out,
                       int32_t width) {
  if (!Batched(paths, batch, 2) || !(out == paths)) {
    return ffi::Error::InvalidArgument("smooth: paths and the result must be i32[B..., A, W]");
  }
  if (!Batched(valid, batch, 2) || valid[batch.size()] < 1 || valid.back() < 1) {
    return ffi::Error::InvalidArgument("smooth: valid must be pred[B..., N, K], N, K >= 1");
  }
  const int64_t N = valid[batch.size()], K = valid.back();
  const bool rows_ok = Batched(nbr, batch, 2) && Batched(cost, batch, 2) &&
                       nbr.back() == K && cost.back() == K;
  if (width < 0 || !rows_ok) {
    return ffi::Error::InvalidArgument("smooth: nbr and cost must be [B..., *, K], width >= 0");
  }
  if (width == 0 && (nbr[batch.size()] != N || cost[batch.size()] != N)) {
    return ffi::Error::InvalidArgument("smooth: on a graph, nbr and cost must be [B..., N, K]");
  }
  if (width > 0 && (nbr[batch.size()] != 0 || cost[batch.size()] != 1 || K > 8)) {
    return ffi::Error::InvalidArgument("smooth: on a lattice, nbr must be [B..., 0, K] and cost "
                                       "[B..., 1, K], K <= 8");
  }
  return ffi::Error::Success();
}

// Every node of the paths (and of a graph's nbr) below N.
ffi::Error CheckNodes(const int32_t* paths, int64_t count, const int32_t* nbr, int64_t slots,
                      int64_t N) {
  for (int64_t i = 0; i < count; ++i) {
    if (paths[i] >= N) return ffi::Error::InvalidArgument("smooth: a path names no node");
  }
  for (int64_t i = 0; i < slots; ++i) {
    if (nbr[i] >= N) return ffi::Error::InvalidArgument("smooth: nbr names no node");
  }
  return ffi::Error::Success();
}

// Batch member r's map (its lattice tables made from `width` and the slot lengths).
Map MapOf(const bool* valid, const int32_t* nbr, const float* cost, int64_t r, int32_t N,
          int32_t K, int32_t width) {
  const int64_t table = static_cast<int64_t>(N) * K;
  Map map{N, K, width, valid + r * table, nullptr, nullptr, 0.0f, 0.0f, {}, {},
          std::vector<int32_t>()};
  if (width == 0) {
    map.nbr = nbr + r * table;
    map.cost = cost + r * table;
    return map;
  }
  map.cost = cost + r * K;
  map.straight = map.cost[0];
  map.diagonal = map.cost[std::min(kOrthogonalSlots, K - 1)];
  for (int32_t k = 0; k < K; ++k) {
    map.codes[k] = (kDirections[k][1] + 1) * 3 + kDirections[k][0] + 1;
    map.offsets[k] = kDirections[k][0] + kDirections[k][1] * width;
  }
  map.masks.assign(N, -1);
  return map;
}

// Batch member r's paths (A of W) into `out`: each of `which` smoothed (or copied from an equal
// earlier one), the others as they were.
void SmoothMember(Smoother& s, const int32_t* paths, const bool* which, int64_t A,
                  int32_t* out) {
  const int64_t W = s.W;
  std::copy(paths, paths + A * W, out);
  for (int64_t a = 0; a < A; ++a) {
    if (!which[a]) continue;
    int64_t same = 0;
    while (same < a && !(which[same] && std::equal(paths + same * W, paths + (same + 1) * W,
                                                   paths + a * W))) {
      ++same;
    }
    if (same < a) {
      std::copy(out + same * W, out + (same + 1) * W, out + a * W);
      continue;
    }
    while (Pass(s, out + a * W)) {
    }
  }
}

ffi::Error SmoothImpl(ffi::Buffer<ffi::S32> paths, ffi::Buffer<ffi::PRED> which,
                      ffi::Buffer<ffi::PRED> valid, ffi::Buffer<ffi::S32> nbr,
                      ffi::Buffer<ffi::F32> cost, int32_t width, float improvement,
                      ffi::ResultBuffer<ffi::S32> smoothed) {
  const auto rows = which.dimensions();
  if (rows.size() < 1) return ffi::Error::InvalidArgument("smooth: which must be pred[B..., A]");
  const auto batch = rows.first(rows.size() - 1);
  if (ffi::Error error = CheckShapes(batch, paths.dimensions(), valid.dimensions(),
                                     nbr.dimensions(), cost.dimensions(), smoothed->dimensions(),
                                     width);
      error.failure()) {
    return error;
  }
  const int64_t A = rows.back(), W = paths.dimensions().back();
  const int64_t N = valid.dimensions()[batch.size()], K = valid.dimensions().back();
  const int64_t members = A > 0 ? static_cast<int64_t>(which.element_count()) / A : 0;
  if (ffi::Error error = CheckNodes(paths.typed_data(), paths.element_count(), nbr.typed_data(),
                                    nbr.element_count(), N);
      error.failure()) {
    return error;
  }
  FlushDenormals flush;
  for (int64_t r = 0; r < members; ++r) {
    Smoother s{MapOf(valid.typed_data(), nbr.typed_data(), cost.typed_data(), r,
                     static_cast<int32_t>(N), static_cast<int32_t>(K), width),
               improvement, W, 0, std::vector<char>(N), std::vector<int32_t>(W),
               std::vector<Lengths>(W), std::vector<int32_t>(W), std::vector<int32_t>(W)};
    SmoothMember(s, paths.typed_data() + r * A * W, which.typed_data() + r * A, A,
                 smoothed->typed_data() + r * A * W);
  }
  return ffi::Error::Success();
}

}  // namespace

XLA_FFI_DEFINE_HANDLER_SYMBOL(JaxswarmSmooth, SmoothImpl,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::S32>>()   // paths
                                  .Arg<ffi::Buffer<ffi::PRED>>()  // which
                                  .Arg<ffi::Buffer<ffi::PRED>>()  // valid
                                  .Arg<ffi::Buffer<ffi::S32>>()   // nbr
                                  .Arg<ffi::Buffer<ffi::F32>>()   // cost
                                  .Attr<int32_t>("width")
                                  .Attr<float>("improvement")
                                  .Ret<ffi::Buffer<ffi::S32>>()  // smoothed
);
