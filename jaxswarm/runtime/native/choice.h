// The pieces of a move's choice that the walk kernels share, operation for operation as the
// XLA walker computes them.
#ifndef JAXSWARM_RUNTIME_NATIVE_CHOICE_H_
#define JAXSWARM_RUNTIME_NATIVE_CHOICE_H_

#include <cstdint>
#include <limits>

#include "arithmetic.h"

namespace jaxswarm {

// IWD's soil term of one admissible slot (jaxswarm.swarm.iwd.soil.choice_log_weights):
// alpha * -log(eps_s + g), g = soil - shift (shift: the least admissible soil when negative,
// else 0).
inline float SoilTerm(float alpha, float eps_s, float soil, float shift) {
  return alpha * -Log(eps_s + (soil - shift));
}

// jaxswarm.swarm.walking.sampler.sample_masked's draw from K weights: their total summed in
// slot order, and the first slot whose running sum exceeds uniform * total (capped at the last
// slot of positive weight).
inline int32_t DrawFromWeights(const float* weight, int32_t K, float uniform) {
  float total = weight[0];
  for (int32_t k = 1; k < K; ++k) total = total + weight[k];
  const float u = uniform * total;
  float running = 0.0f;
  int32_t choice = 0;
  for (int32_t k = 0; k < K; ++k) {
    running = running + weight[k];
    choice += (running <= u) & (running < total);
  }
  return choice;
}

// sample_masked's draw of one row whose largest log-weight `top` is finite: the weights
// exp(masked - top) into `weight` (K floats), then DrawFromWeights. Two weights need no Exp:
// a masked-out slot's (exp(-inf) is 0: below the smallest normal float, flushed as XLA
// flushes it) and the top's (exp(0) is 1 exactly).
inline int32_t InverseCdf(const float* masked, int32_t K, float top, float uniform,
                          float* weight) {
  const float inf = std::numeric_limits<float>::infinity();
  for (int32_t k = 0; k < K; ++k) {
    weight[k] = masked[k] == -inf ? 0.0f : masked[k] == top ? 1.0f : Exp(masked[k] - top);
  }
  return DrawFromWeights(weight, K, uniform);
}

}  // namespace jaxswarm

#endif  // JAXSWARM_RUNTIME_NATIVE_CHOICE_H_
