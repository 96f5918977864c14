// exp(-x) in single precision, written so that GCC/Clang vectorize loops that call it (no table,
// no library call, no branch). The tensor-voting kernels evaluate two decays per vote; with
// std::exp they would not vectorize and the exp would dominate the run time.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>

namespace planeloc {

// exp(-x) for x >= 0 (x < 0 is treated as 0); relative error < 1e-5 (the rounding of x * log2(e)
// to float dominates for large x; < 2e-6 for x < 20), and exactly 0 from
// x = 87 (where the float result would become denormal).
inline float FastNegExp(float x) {
  x = std::max(x, 0.0f);
  const float keep = x < 87.0f ? 1.0f : 0.0f;
  x = std::min(x, 87.0f);
  // exp(-x) = 2^t with t = -x log2(e) = n + f, n integer <= 0, f in [0, 1).
  const float t = -x * 1.44269504088896341f;
  std::int32_t n = static_cast<std::int32_t>(t);  // rounds towards zero, i.e. up for t < 0
  n -= static_cast<float>(n) > t ? 1 : 0;
  const float f = (t - static_cast<float>(n)) * 0.693147180559945309f;  // f ln 2 in [0, ln 2)
  // e^f by its Taylor series to degree 7 (remainder < 0.7^8 / 8! < 2e-6 relative).
  float p = 1.0f / 5040.0f;
  p = p * f + 1.0f / 720.0f;
  p = p * f + 1.0f / 120.0f;
  p = p * f + 1.0f / 24.0f;
  p = p * f + 1.0f / 6.0f;
  p = p * f + 0.5f;
  p = p * f + 1.0f;
  p = p * f + 1.0f;
  // 2^n as the float with biased exponent n + 127 (n >= -126 here, so it is a normal number).
  const float scale = std::bit_cast<float>((n + 127) << 23);
  return keep * p * scale;
}

}  // namespace planeloc
