// A one-line progress bar with rate, drawn on stderr only when stderr is a terminal (so logs and
// CI output stay clean). Not thread-safe: call Update() from one thread.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace planeloc {

class ProgressBar {
 public:
  // `total` = number of work items; `unit` names them in the rate ("frames", "scans").
  ProgressBar(std::string label, std::size_t total, std::string unit = "it");
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

  // Sets the number of finished items; redraws at most every 100 ms.
  void Update(std::size_t done);
  void Finish();

 private:
  void Draw();

  std::string label_;
  std::size_t total_;
  std::string unit_;
  std::size_t done_ = 0;
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace planeloc
