// jaxswarm.runtime.arithmetic's exp, log and integer_power, operation for operation, as the
// kernels use them: the same float32 constants in the same order, so that with no contraction
// (-ffp-contract=off) and subnormals flushed (FlushDenormals) they give the bits the XLA
// programs give.
#ifndef JAXSWARM_RUNTIME_NATIVE_ARITHMETIC_H_
#define JAXSWARM_RUNTIME_NATIVE_ARITHMETIC_H_

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#define JAXSWARM_HAVE_MXCSR 1
#endif

namespace jaxswarm {

// Saves the thread's MXCSR, sets flush-to-zero and denormals-are-zero (as XLA:CPU runs its
// kernels), and restores it when the call ends.
class FlushDenormals {
 public:
#ifdef JAXSWARM_HAVE_MXCSR
  FlushDenormals() : saved_(_mm_getcsr()) { _mm_setcsr(saved_ | 0x8040u); }
  ~FlushDenormals() { _mm_setcsr(saved_); }

 private:
  unsigned int saved_;
#endif
};

constexpr float kLog2e = 1.44269504088896341f;
constexpr float kLn2High = 0.693359375f;
constexpr float kLn2Low = -2.12194440e-4f;
constexpr float kExpPoly[6] = {1.9875691500e-4f, 1.3981999507e-3f, 8.3334519073e-3f,
                               4.1665795894e-2f, 1.6666665459e-1f, 5.0000001201e-1f};
constexpr float kExpMax = 88.72283935546875f;
constexpr float kExpMin = -103.972084045410f;
constexpr float kSqrtHalf = 0.707106781186547524f;
constexpr float kLogPoly[9] = {7.0376836292e-2f,  -1.1514610310e-1f, 1.1676998740e-1f,
                               -1.2420140846e-1f, 1.4249322787e-1f,  -1.6668057665e-1f,
                               2.0000714765e-1f,  -2.4999993993e-1f, 3.3333331174e-1f};

inline float PowerOfTwo(int32_t n) {  // 2^n for n in [-126, 127], from its exponent bits
  uint32_t bits = static_cast<uint32_t>(n + 127) << 23;
  float out;
  std::memcpy(&out, &bits, sizeof out);
  return out;
}

// jaxswarm.runtime.arithmetic.exp.
inline float Exp(float x) {
  // jnp.clip: maximum with the lower bound, then minimum with the upper.
  float clipped = x > kExpMin ? x : kExpMin;
  clipped = clipped < kExpMax ? clipped : kExpMax;
  float n = std::floor(clipped * kLog2e + 0.5f);
  float r = (clipped - n * kLn2High) - n * kLn2Low;
  float p = kExpPoly[0];
  for (int i = 1; i < 6; ++i) p = p * r + kExpPoly[i];
  float y = p * (r * r) + r + 1.0f;
  int32_t half = static_cast<int32_t>(std::floor(n * 0.5f));
  int32_t rest = static_cast<int32_t>(n) - half;
  float value = y * PowerOfTwo(half) / PowerOfTwo(-rest);
  if (x > kExpMax) value = std::numeric_limits<float>::infinity();
  return std::isnan(x) ? x : value;
}

// jaxswarm.runtime.arithmetic.log.
inline float Log(float x) {
  if (std::isnan(x)) return x;
  if (x == std::numeric_limits<float>::infinity()) return x;
  if (x < 0.0f) return std::numeric_limits<float>::quiet_NaN();
  if (x < std::numeric_limits<float>::min()) return -std::numeric_limits<float>::infinity();
  uint32_t word;
  std::memcpy(&word, &x, sizeof word);
  int32_t exponent = static_cast<int32_t>(word >> 23) - 126;
  uint32_t mantissa = (word & 0x007FFFFFu) | 0x3F000000u;
  float m;
  std::memcpy(&m, &mantissa, sizeof m);
  const bool below = m < kSqrtHalf;
  const float e = static_cast<float>(below ? exponent - 1 : exponent);
  const float f = below ? (m + m) - 1.0f : m - 1.0f;
  const float z = f * f;
  float p = kLogPoly[0];
  for (int i = 1; i < 9; ++i) p = p * f + kLogPoly[i];
  float y = p * f * z;
  y = y + kLn2Low * e;
  y = y - 0.5f * z;
  return (f + y) + kLn2High * e;
}

// jaxswarm.runtime.arithmetic.integer_power: x^n (n >= 0) as the product of the squares
// x^(2^b) over the set bits b of n, lowest first.
inline float IntegerPower(float x, int32_t n) {
  float result = 1.0f, square = x;
  for (uint32_t bits = static_cast<uint32_t>(n); bits; bits >>= 1) {
    if (bits & 1u) result = result * square;
    square = square * square;
  }
  return result;
}

}  // namespace jaxswarm

#endif  // JAXSWARM_RUNTIME_NATIVE_ARITHMETIC_H_
