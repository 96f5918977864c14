// A scratch directory removed on destruction, for tests and tools.
#pragma once

#include <filesystem>
#include <random>
#include <string>

namespace planeloc {

class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "planeloc") {
    std::random_device device;
    path_ = std::filesystem::temp_directory_path() /
            (prefix + "-" + std::to_string(device()) + std::to_string(device()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace planeloc
