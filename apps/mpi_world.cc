#include "mpi_world.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <string>

#include "planeloc/util/error.h"

#ifdef PLANELOC_WITH_MPI
#include <mpi.h>

#include <climits>
#include <cstdint>
#endif

namespace planeloc::cli {
namespace {

// The number of processes the launcher started (1 when not launched by one).
int LauncherSize() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"}) {
    if (const char* value = std::getenv(name)) return std::max(1, std::atoi(value));
  }
  return std::getenv("PMIX_RANK") != nullptr ? 2 : 1;  // PMIx without a size: assume several
}

}  // namespace

#ifdef PLANELOC_WITH_MPI

MpiWorld::MpiWorld() {
  if (LauncherSize() <= 1 && std::getenv("PMIX_RANK") == nullptr) return;
  int already = 0;
  MPI_Initialized(&already);
  if (!already) MPI_Init(nullptr, nullptr);
  initialized_ = !already;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiWorld::~MpiWorld() {
  if (initialized_) MPI_Finalize();
}

void MpiWorld::Abort(int code) const {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::abort();  // MPI_Abort does not return
}

std::vector<std::string> MpiWorld::GatherToRoot(const std::string& mine) const {
  if (size_ == 1) return {mine};
  // Point-to-point in chunks below INT_MAX bytes: a rank's results may exceed MPI's int counts.
  constexpr std::size_t kChunk = std::size_t{1} << 30;
  std::vector<std::string> all;
  if (rank_ != 0) {
    const std::uint64_t bytes = mine.size();
    MPI_Send(&bytes, 1, MPI_UINT64_T, 0, 0, MPI_COMM_WORLD);
    for (std::size_t off = 0; off < mine.size(); off += kChunk) {
      const int n = static_cast<int>(std::min(kChunk, mine.size() - off));
      MPI_Send(mine.data() + off, n, MPI_BYTE, 0, 1, MPI_COMM_WORLD);
    }
    return all;
  }
  all.push_back(mine);
  for (int r = 1; r < size_; ++r) {
    std::uint64_t bytes = 0;
    MPI_Recv(&bytes, 1, MPI_UINT64_T, r, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    std::string theirs(bytes, '\0');
    for (std::size_t off = 0; off < theirs.size(); off += kChunk) {
      const int n = static_cast<int>(std::min<std::size_t>(kChunk, theirs.size() - off));
      MPI_Recv(theirs.data() + off, n, MPI_BYTE, r, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    }
    all.push_back(std::move(theirs));
  }
  return all;
}

#else

MpiWorld::MpiWorld() {
  const int launched = LauncherSize();
  CheckInput(launched <= 1, "", 0,
             fmt::format("started by an MPI launcher with {} processes, but this planeloc was "
                         "built without MPI",
                         launched),
             "rebuild with `cmake -DPLANELOC_WITH_MPI=ON` (Debian: libopenmpi-dev), or run "
             "without mpirun (the tiles are then processed one after another)");
}

MpiWorld::~MpiWorld() = default;

void MpiWorld::Abort(int code) const { std::exit(code); }

std::vector<std::string> MpiWorld::GatherToRoot(const std::string& mine) const { return {mine}; }

#endif

}  // namespace planeloc::cli
