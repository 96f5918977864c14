#include "planeloc/util/allocator.h"

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace planeloc {

void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  // Setting either value explicitly also turns off glibc's dynamic mmap threshold, which only
  // rises after a mapped block has been freed (too late for the first frames of every size).
  mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 256 * 1024 * 1024);
#endif
}

}  // namespace planeloc
