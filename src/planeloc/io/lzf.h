// LZF decompression (Marc Lehmann's liblzf format), as used by PCL's `binary_compressed` .pcd.
#pragma once

#include <cstddef>
#include <cstdint>

namespace planeloc {

// Decompresses `in` into exactly `out_size` bytes at `out`. Returns false when the stream is
// malformed: a back reference before the start of the output, a run past the end of either
// buffer, or a stream that ends before `out_size` bytes were produced.
//
// Format: a control byte c < 32 is followed by c + 1 literal bytes; otherwise the run length is
// (c >> 5) + 2 (when c >> 5 == 7 the next byte is added to it) and the back reference is
// ((c & 31) << 8) + next byte + 1 bytes behind the output position.
bool LzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out,
                   std::size_t out_size);

}  // namespace planeloc
