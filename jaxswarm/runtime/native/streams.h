// The walker's counter-based uniform stream (jaxswarm.swarm.walking.streams.uniforms), bit for
// bit: agent `agent`'s `move`-th draw from the walk's seed (s0, s1), shared by the kernels.
#ifndef JAXSWARM_RUNTIME_NATIVE_STREAMS_H_
#define JAXSWARM_RUNTIME_NATIVE_STREAMS_H_

#include <cstdint>

namespace jaxswarm {

inline uint32_t Fmix32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x85EBCA6Bu;
  x ^= x >> 13;
  x *= 0xC2B2AE35u;
  x ^= x >> 16;
  return x;
}

inline float Uniform(uint32_t s0, uint32_t s1, uint32_t agent, uint32_t move) {
  uint32_t counter = (agent * 0x9E3779B1u) ^ move;
  uint32_t mixed = Fmix32(Fmix32(counter ^ s0) ^ s1);
  // (mixed >> 8) < 2**24 is exact in f32, and the product by 2**-24 is exact: no rounding.
  return static_cast<float>(mixed >> 8) * 0x1p-24f;
}

}  // namespace jaxswarm

#endif  // JAXSWARM_RUNTIME_NATIVE_STREAMS_H_
