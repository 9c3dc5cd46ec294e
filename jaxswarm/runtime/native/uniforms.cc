// jaxswarm's native CPU kernels, called from jitted programs through XLA's typed FFI
// (jax.ffi.ffi_call; jaxswarm/runtime/native/__init__.py builds, loads and registers them).
//
// JaxswarmUniforms: the walker's counter-based uniform stream
// (jaxswarm.swarm.walking.streams.uniforms), bit for bit:
//   seed u32[B..., 2], agent i32[B..., A], move i32[B..., A] -> f32[B..., A]
// where B... are leading batch dimensions (those vmap adds with vmap_method="broadcast_all"),
// the same in the three inputs. Each batch member b draws with its own seed row.
//
// Thread safety: the handler keeps no state (no statics, no globals); it reads its inputs and
// writes its own output buffer only, so XLA may run two calls at once (two CPU devices under
// shard_map, or two programs on two threads).
#include <cstddef>
#include <cstdint>

#include "xla/ffi/api/ffi.h"

#include "streams.h"

namespace ffi = xla::ffi;

namespace {

using jaxswarm::Uniform;

ffi::Error UniformsImpl(ffi::Buffer<ffi::U32> seed, ffi::Buffer<ffi::S32> agent,
                        ffi::Buffer<ffi::S32> move, ffi::ResultBuffer<ffi::F32> out) {
  auto seed_dims = seed.dimensions();
  auto agent_dims = agent.dimensions();
  if (seed_dims.size() < 1 || seed_dims.back() != 2) {
    return ffi::Error::InvalidArgument("uniforms: seed must be u32[..., 2]");
  }
  if (agent_dims.size() != seed_dims.size()) {
    return ffi::Error::InvalidArgument("uniforms: agent must be i32[..., A] with seed's batch "
                                       "dimensions");
  }
  for (size_t d = 0; d + 1 < seed_dims.size(); ++d) {
    if (agent_dims[d] != seed_dims[d]) {
      return ffi::Error::InvalidArgument("uniforms: seed and agent batch dimensions differ");
    }
  }
  if (move.element_count() != agent.element_count() ||
      out->element_count() != agent.element_count()) {
    return ffi::Error::InvalidArgument("uniforms: agent, move and out must have one shape");
  }
  const size_t batch = seed.element_count() / 2;
  const size_t width = static_cast<size_t>(agent_dims.back());  // rank >= 1: checked above
  const uint32_t* __restrict s = seed.typed_data();
  for (size_t b = 0; b < batch; ++b) {
    const uint32_t s0 = s[2 * b], s1 = s[2 * b + 1];
    const int32_t* __restrict a = agent.typed_data() + b * width;
    const int32_t* __restrict m = move.typed_data() + b * width;
    float* __restrict u = out->typed_data() + b * width;
    for (size_t i = 0; i < width; ++i) {  // XLA's buffers do not overlap: vectorised
      u[i] = Uniform(s0, s1, static_cast<uint32_t>(a[i]), static_cast<uint32_t>(m[i]));
    }
  }
  return ffi::Error::Success();
}

}  // namespace

XLA_FFI_DEFINE_HANDLER_SYMBOL(JaxswarmUniforms, UniformsImpl,
                              ffi::Ffi::Bind()
                                  .Arg<ffi::Buffer<ffi::U32>>()  // seed
                                  .Arg<ffi::Buffer<ffi::S32>>()  // agent
                                  .Arg<ffi::Buffer<ffi::S32>>()  // move
                                  .Ret<ffi::Buffer<ffi::F32>>()  // out
);
