// Binary scalar fields of point-cloud files (.pcd and .ply): type, size, and decoding from bytes
// in either byte order. Shared by pcd_reader.cc and ply_reader.cc.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace planeloc {

enum class ScalarKind : std::uint8_t { kInt, kUint, kFloat };

struct ScalarType {
  ScalarKind kind = ScalarKind::kFloat;
  int size = 4;  // bytes: 1, 2, 4 or 8 (floats 4 or 8)

  // True for the combinations a file may hold (int/uint 1, 2, 4, 8 bytes; float 4, 8 bytes).
  bool Valid() const;
};

// The value of the scalar at `bytes`, stored little-endian unless `big_endian`. `type` must be
// Valid().
double DecodeScalar(const unsigned char* bytes, ScalarType type, bool big_endian);

// The 32 bits at `bytes` (little-endian unless `big_endian`), e.g. PCL's packed rgb.
std::uint32_t DecodeBits32(const unsigned char* bytes, bool big_endian);

}  // namespace planeloc
