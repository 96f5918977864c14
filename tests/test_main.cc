// The main() of every planeloc_<module>_test binary: GoogleTest's, plus one step at the end.
//
// oneTBB leaves its worker threads running when main returns, and they wind down while the
// process exits. Under AddressSanitizer, LeakSanitizer stops every thread at exit to scan for
// leaks; a worker that is half torn down at that instant crashes its tracer ("Tracer caught
// signal 11 ... LeakSanitizer has encountered a fatal error"), which fails a test binary whose
// tests all passed (CI, 2026-12-04: the sim suite, 21/21 passed). Joining the workers before
// returning leaves no thread in that state (docs/reliability.md, "Sanitizers").
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <new>

int main(int argc, char** argv) {
  tbb::task_scheduler_handle tbb_workers{tbb::attach{}};
  testing::InitGoogleTest(&argc, argv);
  const int result = RUN_ALL_TESTS();
  // Blocking finalize joins the workers; it declines (false) while another handle or a
  // global_control is alive, which leaves the exit as it was.
  [[maybe_unused]] const bool joined = tbb::finalize(tbb_workers, std::nothrow);
  return result;
}
