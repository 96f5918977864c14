// Output files that are complete or absent, and write failures that are never silent.
//
// A whole file (a map, planes.json, a JSON report, settings) is written to `<path>.tmp.<pid>`
// beside the target and renamed onto it once every write, the flush and the close succeeded, so
// a reader never sees half a file and a failed run leaves no file (or the old one). A target that
// exists and is not a regular file (/dev/null, /dev/full, /dev/stdout, a FIFO) is written in
// place. A record-per-frame file (trajectory, stats) is written in place and flushed after every
// record, so a killed run keeps each finished record; each write, flush and the final close are
// checked. Every failure is an InputError naming the path and the system's reason (strerror),
// e.g. "out/map.pcd: cannot write the file: No space left on device".
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace planeloc {

class OutputFile {
 public:
  enum class Mode {
    kWhole,        // temporary file renamed onto the path by Commit(); none left on failure
    kIncremental,  // in place, flushed after every Write(); Commit() checks the close
  };

  // Opens the file (kWhole: the temporary). Throws InputError naming the folder when it does not
  // exist, or the path and strerror when the file cannot be created.
  OutputFile(std::filesystem::path path, Mode mode);
  // Without a successful Commit(): closes and removes the temporary file (kWhole).
  ~OutputFile();
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  // Appends `bytes`; kIncremental also flushes. Throws InputError(path, strerror) on failure.
  void Write(std::string_view bytes);
  // Flushes and closes (and renames, kWhole); throws InputError(path, strerror) on failure.
  void Commit();

  const std::filesystem::path& path() const { return path_; }

 private:
  [[noreturn]] void Fail(const std::string& action, int error_number);
  void Discard();

  std::filesystem::path path_;
  std::filesystem::path written_;  // the temporary file, or path_ when written in place
  Mode mode_;
  std::FILE* file_ = nullptr;
};

// Writes `content` as a whole file (OutputFile::Mode::kWhole).
void WriteFileWhole(const std::filesystem::path& path, std::string_view content);

// For outputs written by another program (e.g. matplotlib for `eval --plot`): the temporary path
// to hand it (`<path>.tmp.<pid><extension>`: the extension kept, tools choose the format by it),
// or `path` itself when it exists and is not a regular file.
std::filesystem::path TemporaryPathFor(const std::filesystem::path& path);
// Renames `temporary` onto `path` (nothing when they are equal); throws InputError with strerror
// and removes the temporary file on failure.
void CommitTemporary(const std::filesystem::path& temporary, const std::filesystem::path& path);

// A path given on the command line, with the flag that gave it ("--out").
struct FlagPath {
  std::string flag;
  std::filesystem::path path;
};

// Checks the outputs of a command before any work: every output's folder exists and is a
// writable folder (the error names the folder and the flag), no output is a folder, and no two
// outputs, nor an output and an input, are the same file. Empty paths are ignored. Throws
// InputError naming the flags and paths.
void CheckOutputPaths(const std::vector<FlagPath>& outputs,
                      const std::vector<FlagPath>& inputs = {});

}  // namespace planeloc
