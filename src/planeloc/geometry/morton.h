// 3-D Morton (Z-order) keys of integer cell coordinates: cells close in space get close keys, so
// sorting points by key gives cache-friendly neighbour searches and voxel runs.
#pragma once

#include <cstdint>

namespace planeloc {

// Spreads the low 21 bits of x so that there are two zero bits between consecutive bits.
inline std::uint64_t SpreadBits3(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

// Interleaves the low 21 bits of each coordinate (x lowest).
inline std::uint64_t MortonKey3(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
  return SpreadBits3(x) | SpreadBits3(y) << 1 | SpreadBits3(z) << 2;
}

}  // namespace planeloc
