#include "planeloc/pipeline/ba_job.h"

#include <chrono>
#include <exception>

namespace planeloc {

void SolveBaJob(const StereoCamera& camera, const WindowBaOptions& options, BaJob& job) {
  const auto start = std::chrono::steady_clock::now();
  try {
    job.result = SolveWindowBa(camera, job.problem, options);
  } catch (const std::exception&) {
    job.result = WindowBaResult{};  // usable = false: the tracker keeps the map as it is
  }
  job.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace planeloc
