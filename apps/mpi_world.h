// The MPI side of `planeloc map planes --tiles` (issue 15), behind one small class so that the
// rest of the program never includes <mpi.h>, and the build without MPI (PLANELOC_WITH_MPI=OFF,
// the default) still runs tiles one after another in one process.
//
// MPI is initialized only when the process was started by an MPI launcher (mpirun / mpiexec /
// srun set OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK): a plain `planeloc map planes --tiles`
// never starts MPI. A build without MPI started by a launcher with more than one process is an
// InputError (every rank would write the same output).
#pragma once

#include <string>
#include <vector>

namespace planeloc::cli {

class MpiWorld {
 public:
  MpiWorld();   // MPI_Init when launched by an MPI launcher (and built with MPI)
  ~MpiWorld();  // MPI_Finalize when initialized
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }

  // Ends every rank with `code` (MPI_Abort; the launcher reports it). Only when size() > 1.
  [[noreturn]] void Abort(int code) const;

  // Every rank's `mine`, in rank order, on rank 0 (empty on the others). Collective.
  std::vector<std::string> GatherToRoot(const std::string& mine) const;

 private:
  bool initialized_ = false;
  int rank_ = 0;
  int size_ = 1;
};

}  // namespace planeloc::cli
