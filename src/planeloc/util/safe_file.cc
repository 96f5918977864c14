#include "planeloc/util/safe_file.h"

#include <fmt/format.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "planeloc/util/error.h"

namespace planeloc {
namespace fs = std::filesystem;
namespace {

// A fix for the user from the system's reason.
std::string FixFor(int error_number) {
  switch (error_number) {
    case ENOSPC:
    case EDQUOT:
      return "free disk space (or lift the quota) and run again, or write to another disk";
    case EFBIG:
      return "the file exceeds the file-size limit (ulimit -f) or the file system's maximum; "
             "raise the limit or write elsewhere";
    case EACCES:
    case EPERM:
    case EROFS:
      return "choose a writable output folder, or fix its permissions";
    default:
      return "check the output folder and the disk, or choose another output path";
  }
}

InputError WriteError(const fs::path& path, const std::string& action, int error_number) {
  return InputError(path.string(), 0,
                    fmt::format("cannot {}: {}", action, std::strerror(error_number)),
                    FixFor(error_number));
}

// Existing and not a regular file (a device, a FIFO): written in place, never renamed over.
bool IsSpecialFile(const fs::path& path) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  return !error && fs::exists(status) && !fs::is_regular_file(status) && !fs::is_directory(status);
}

fs::path FolderOf(const fs::path& path) {
  return path.has_parent_path() ? path.parent_path() : fs::path(".");
}

void CheckFolder(const fs::path& path, const std::string& flag) {
  const fs::path folder = FolderOf(path);
  const std::string via =
      flag.empty() ? "" : fmt::format(" (the folder of {} {})", flag, path.string());
  std::error_code error;
  CheckInput(
      fs::exists(folder, error), folder.string(), 0,
      fmt::format("the output folder does not exist{}", via),
      fmt::format("create it first (mkdir -p {}) or choose another output path", folder.string()));
  CheckInput(fs::is_directory(folder, error), folder.string(), 0,
             fmt::format("is not a folder{}", via), "choose an output path inside a folder");
  CheckInput(::access(folder.c_str(), W_OK | X_OK) == 0, folder.string(), 0,
             fmt::format("the output folder is not writable{}: {}", via, std::strerror(errno)),
             "choose a writable output folder, or fix its permissions");
}

// Identity of a path for comparisons: the canonical form of what exists, lexically normal rest.
fs::path Identity(const fs::path& path) {
  std::error_code error;
  const fs::path canonical = fs::weakly_canonical(path, error);
  return error ? fs::absolute(path).lexically_normal() : canonical;
}

}  // namespace

OutputFile::OutputFile(fs::path path, Mode mode) : path_(std::move(path)), mode_(mode) {
  if (!IsSpecialFile(path_)) CheckFolder(path_, "");
  written_ = mode_ == Mode::kWhole ? TemporaryPathFor(path_) : path_;
  file_ = std::fopen(written_.c_str(), "wb");
  if (file_ == nullptr) {
    const int error_number = errno;
    throw WriteError(path_, "create the file", error_number);
  }
}

OutputFile::~OutputFile() { Discard(); }

void OutputFile::Discard() {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
    if (written_ != path_) {
      std::error_code ignored;
      fs::remove(written_, ignored);
    }
  }
}

void OutputFile::Fail(const std::string& action, int error_number) {
  Discard();
  throw WriteError(path_, action, error_number);
}

void OutputFile::Write(std::string_view bytes) {
  if (file_ == nullptr) throw std::logic_error("OutputFile::Write after Commit: " + path_.string());
  errno = 0;
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    Fail("write the file", errno != 0 ? errno : EIO);
  }
  if (mode_ == Mode::kIncremental && std::fflush(file_) != 0) {
    Fail("write the file", errno != 0 ? errno : EIO);
  }
}

void OutputFile::Commit() {
  if (file_ == nullptr) throw std::logic_error("OutputFile::Commit twice: " + path_.string());
  errno = 0;
  if (std::fflush(file_) != 0) Fail("write the file", errno != 0 ? errno : EIO);
  std::FILE* file = file_;
  file_ = nullptr;
  if (std::fclose(file) != 0) {
    const int error_number = errno != 0 ? errno : EIO;
    if (written_ != path_) {
      std::error_code ignored;
      fs::remove(written_, ignored);
    }
    throw WriteError(path_, "write the file", error_number);
  }
  CommitTemporary(written_, path_);
}

void WriteFileWhole(const fs::path& path, std::string_view content) {
  OutputFile file(path, OutputFile::Mode::kWhole);
  file.Write(content);
  file.Commit();
}

fs::path TemporaryPathFor(const fs::path& path) {
  if (IsSpecialFile(path)) return path;
  fs::path temporary = path;
  temporary += fmt::format(".tmp.{}{}", ::getpid(), path.extension().string());
  return temporary;
}

void CommitTemporary(const fs::path& temporary, const fs::path& path) {
  if (temporary == path) return;
  if (std::rename(temporary.c_str(), path.c_str()) != 0) {
    const int error_number = errno;
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw WriteError(path, fmt::format("rename {} onto the file", temporary.string()),
                     error_number);
  }
}

void CheckOutputPaths(const std::vector<FlagPath>& outputs, const std::vector<FlagPath>& inputs) {
  std::vector<std::pair<const FlagPath*, fs::path>> seen;
  for (const FlagPath& output : outputs) {
    if (output.path.empty()) continue;
    if (!IsSpecialFile(output.path)) CheckFolder(output.path, output.flag);
    std::error_code error;
    CheckInput(!fs::is_directory(output.path, error), output.path.string(), 0,
               fmt::format("{} names a folder, not a file", output.flag),
               fmt::format("give {} a file path inside the folder", output.flag));
    const fs::path identity = Identity(output.path);
    for (const auto& [other, other_identity] : seen) {
      CheckInput(identity != other_identity, output.path.string(), 0,
                 fmt::format("{} and {} name the same file", other->flag, output.flag),
                 "give each output its own path");
    }
    for (const FlagPath& input : inputs) {
      if (input.path.empty() || IsSpecialFile(output.path)) continue;
      CheckInput(identity != Identity(input.path), output.path.string(), 0,
                 fmt::format("the output {} is the input {}: it would be overwritten", output.flag,
                             input.flag),
                 fmt::format("give {} another path", output.flag));
    }
    // Devices (/dev/null) may take several outputs.
    if (!IsSpecialFile(output.path)) seen.emplace_back(&output, identity);
  }
}

}  // namespace planeloc
