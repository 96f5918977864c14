#include "planeloc/io/scalar_field.h"

#include <algorithm>
#include <array>
#include <cstring>

namespace planeloc {
namespace {

// The native little-endian bytes of a scalar stored in the given order (x86/ARM hosts are
// little-endian; the static_assert below keeps it that way).
template <typename T>
T Load(const unsigned char* bytes, bool big_endian) {
  std::array<unsigned char, sizeof(T)> buffer;
  std::memcpy(buffer.data(), bytes, sizeof(T));
  if (big_endian) std::reverse(buffer.begin(), buffer.end());
  T value;
  std::memcpy(&value, buffer.data(), sizeof(T));
  return value;
}

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "planeloc assumes a little-endian host");

}  // namespace

bool ScalarType::Valid() const {
  if (kind == ScalarKind::kFloat) return size == 4 || size == 8;
  return size == 1 || size == 2 || size == 4 || size == 8;
}

double DecodeScalar(const unsigned char* bytes, ScalarType type, bool big_endian) {
  switch (type.kind) {
    case ScalarKind::kFloat:
      return type.size == 4 ? Load<float>(bytes, big_endian) : Load<double>(bytes, big_endian);
    case ScalarKind::kInt:
      switch (type.size) {
        case 1:
          return Load<std::int8_t>(bytes, big_endian);
        case 2:
          return Load<std::int16_t>(bytes, big_endian);
        case 4:
          return Load<std::int32_t>(bytes, big_endian);
        default:
          return static_cast<double>(Load<std::int64_t>(bytes, big_endian));
      }
    case ScalarKind::kUint:
      switch (type.size) {
        case 1:
          return Load<std::uint8_t>(bytes, big_endian);
        case 2:
          return Load<std::uint16_t>(bytes, big_endian);
        case 4:
          return Load<std::uint32_t>(bytes, big_endian);
        default:
          return static_cast<double>(Load<std::uint64_t>(bytes, big_endian));
      }
  }
  return 0.0;
}

std::uint32_t DecodeBits32(const unsigned char* bytes, bool big_endian) {
  return Load<std::uint32_t>(bytes, big_endian);
}

}  // namespace planeloc
