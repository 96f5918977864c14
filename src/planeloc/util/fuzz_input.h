// Helpers for the libFuzzer targets (*_fuzz.cc, scripts/fuzz.sh). The readers take paths (they
// name the file in their errors and some stat it), so each input is written to a file first.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace planeloc {

// Writes `data` to `<tmp>/planeloc-fuzz-<pid>/input<extension>` (one file per process, reused for
// every input, removed at exit) and returns its path.
inline std::filesystem::path WriteFuzzInput(const std::uint8_t* data, std::size_t size,
                                            const std::string& extension) {
  struct Dir {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("planeloc-fuzz-" + std::to_string(::getpid()));
    Dir() { std::filesystem::create_directories(path); }
    ~Dir() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  const std::filesystem::path path = dir.path / ("input" + extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace planeloc
