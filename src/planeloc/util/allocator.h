// Process-wide allocator settings for the long-running commands (`planeloc run`, the ROS node).
#pragma once

namespace planeloc {

// glibc: keeps freed blocks of up to 32 MB in the heap for reuse instead of handing each back to
// the kernel (mmap threshold), and trims the heap top above 256 MB only. The tracker frees and
// reallocates the same image-sized buffers every frame (pyramids, ORB's bordered copies, LSD's
// buffers, decoded PNGs); with the glibc defaults each is a fresh mapping whose pages fault in
// again until glibc's dynamic threshold has risen past its size. Measured on kitti07-like
// (docs/bench-tracking.md): the first 300 frames 10 % less CPU (user + sys 15.8 / 15.5 s ->
// 14.0 / 14.1 s), the whole 1 101 frames threaded 3 % less (63.4 / 63.0 s -> 61.7 / 60.5 s,
// 21.0 / 20.9 -> 21.3 / 21.7 fps), peak RSS unchanged (205-207 MB).
// Call once, before the work starts; a no-op where the C library is not glibc. The map commands
// do not call it: their large buffers (GBs) should go back to the kernel when freed.
void KeepFreedMemoryForReuse();

}  // namespace planeloc
