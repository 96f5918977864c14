#include "planeloc/io/lzf.h"

namespace planeloc {

bool LzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out,
                   std::size_t out_size) {
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    const unsigned control = in[ip++];
    if (control < 32) {  // literal run
      const std::size_t length = control + 1;
      if (ip + length > in_size || op + length > out_size) return false;
      for (std::size_t k = 0; k < length; ++k) out[op++] = in[ip++];
      continue;
    }
    std::size_t length = control >> 5;
    if (length == 7) {
      if (ip >= in_size) return false;
      length += in[ip++];
    }
    length += 2;
    if (ip >= in_size) return false;
    const std::size_t back = ((control & 0x1fu) << 8) + in[ip++] + 1;
    if (back > op || op + length > out_size) return false;
    // Byte by byte: the source may overlap the bytes being written (a repeated pattern).
    for (std::size_t k = 0; k < length; ++k, ++op) out[op] = out[op - back];
  }
  return op == out_size;
}

}  // namespace planeloc
