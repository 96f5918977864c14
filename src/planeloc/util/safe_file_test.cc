#include "planeloc/util/safe_file.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <fstream>
#include <iterator>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

namespace fs = std::filesystem;

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::size_t FilesIn(const fs::path& folder) {
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(folder), fs::directory_iterator()));
}

// Runs `body` with the file-size limit at `bytes` (SIGXFSZ ignored, so write() fails with EFBIG
// as on a full disk) and restores the limit.
template <typename Body>
void WithFileSizeLimit(rlim_t bytes, Body body) {
  rlimit old{};
  ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = old;
  limited.rlim_cur = bytes;
  ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &limited), 0);
  body();
  setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
}

TEST(SafeFileTest, WholeFileAppearsOnlyOnCommit) {
  TempDir dir;
  const fs::path path = dir.path() / "out.json";
  {
    OutputFile file(path, OutputFile::Mode::kWhole);
    file.Write("{\"a\": ");
    EXPECT_FALSE(fs::exists(path));  // still the temporary file
    file.Write("1}\n");
    file.Commit();
  }
  EXPECT_EQ(ReadAll(path), "{\"a\": 1}\n");
  EXPECT_EQ(FilesIn(dir.path()), 1u);  // no temporary left
}

TEST(SafeFileTest, AbandonedWholeFileLeavesNothing) {
  TempDir dir;
  { OutputFile(dir.path() / "out.txt", OutputFile::Mode::kWhole).Write("half"); }
  EXPECT_EQ(FilesIn(dir.path()), 0u);
}

TEST(SafeFileTest, IncrementalFileHoldsEveryWriteBeforeCommit) {
  TempDir dir;
  const fs::path path = dir.path() / "traj.txt";
  OutputFile file(path, OutputFile::Mode::kIncremental);
  file.Write("line 1\n");
  EXPECT_EQ(ReadAll(path), "line 1\n");  // flushed: a killed run keeps it
  file.Write("line 2\n");
  file.Commit();
  EXPECT_EQ(ReadAll(path), "line 1\nline 2\n");
}

TEST(SafeFileTest, FullDeviceIsAnErrorWithTheReason) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  for (const auto mode : {OutputFile::Mode::kWhole, OutputFile::Mode::kIncremental}) {
    try {
      OutputFile file("/dev/full", mode);
      file.Write("x\n");
      file.Commit();
      ADD_FAILURE() << "no error writing /dev/full";
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), "/dev/full");
      EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_THROW(WriteFileWhole("/dev/full", "{}"), InputError);
}

TEST(SafeFileTest, FailedWholeWriteKeepsTheOldFileAndNoTemporary) {
  TempDir dir;
  const fs::path path = dir.path() / "map.pcd";
  WriteFileWhole(path, "old");
  WithFileSizeLimit(1000, [&] {
    try {
      WriteFileWhole(path, std::string(100000, 'x'));
      ADD_FAILURE() << "no error beyond the file-size limit";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("File too large"), std::string::npos) << e.what();
    }
  });
  EXPECT_EQ(ReadAll(path), "old");
  EXPECT_EQ(FilesIn(dir.path()), 1u);
}

TEST(SafeFileTest, FailedIncrementalWriteIsReportedAtThatWrite) {
  TempDir dir;
  const fs::path path = dir.path() / "traj.txt";
  WithFileSizeLimit(10, [&] {
    OutputFile file(path, OutputFile::Mode::kIncremental);
    file.Write("12345\n");  // within the limit
    EXPECT_THROW(file.Write("67890\n"), InputError);
  });
  EXPECT_EQ(ReadAll(path).substr(0, 6), "12345\n");
}

TEST(SafeFileTest, MissingFolderIsNamed) {
  TempDir dir;
  const fs::path missing = dir.path() / "no" / "such";
  try {
    CheckOutputPaths({{"--out", missing / "traj.txt"}});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), missing.string());
    EXPECT_NE(std::string(e.what()).find("--out"), std::string::npos) << e.what();
  }
  EXPECT_THROW(OutputFile(missing / "x.txt", OutputFile::Mode::kWhole), InputError);
}

TEST(SafeFileTest, SameFileForTwoOutputsOrAnInputIsRefused) {
  TempDir dir;
  const fs::path a = dir.path() / "a.txt";
  EXPECT_THROW(CheckOutputPaths({{"--out", a}, {"--stats", dir.path() / "." / "a.txt"}}),
               InputError);
  WriteFileWhole(dir.path() / "gt.txt", "1\n");
  EXPECT_THROW(
      CheckOutputPaths({{"--out", dir.path() / "gt.txt"}}, {{"--gt", dir.path() / "gt.txt"}}),
      InputError);
  EXPECT_THROW(CheckOutputPaths({{"--out", dir.path()}}), InputError);  // a folder
  EXPECT_NO_THROW(CheckOutputPaths({{"--out", a}, {"--stats", dir.path() / "b.txt"}, {"--x", ""}},
                                   {{"--gt", dir.path() / "gt.txt"}}));
  EXPECT_NO_THROW(CheckOutputPaths({{"--json", "/dev/null"}, {"--plot", "/dev/null"}}));
}

}  // namespace
}  // namespace planeloc
