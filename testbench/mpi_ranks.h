// The ranks of an MPI launch (`mpirun -np N saarcor sweep ...`): the sweep splits its points over
// them and rank 0 gathers the rows and writes the one CSV a single process writes. MPI is
// optional: the MPI calls are compiled in only when CMake finds MPI (SAARCOR_HAVE_MPI); without
// it a launch of more than one rank is refused, so N processes never race to write one file.
#pragma once

#include <string>
#include <vector>

namespace saarcor {

// True when built with MPI.
bool mpi_available();
// True when this process was started by an MPI launcher (mpirun, mpiexec, srun --mpi): the
// launcher's environment (OMPI_COMM_WORLD_SIZE, PMI_SIZE, PMIX_RANK) says so. A plain run never
// initialises MPI, so it pays nothing for it.
bool mpi_launched();

// MPI_Init on construction when launched (MPI_Finalize on destruction); otherwise rank 0 of 1.
// Throws when launched with more than one rank but built without MPI. Only the constructing
// thread calls MPI (MPI_THREAD_FUNNELED); the sweep's worker threads never do.
class MpiRanks {
 public:
  MpiRanks();
  MpiRanks(const MpiRanks&) = delete;
  MpiRanks& operator=(const MpiRanks&) = delete;
  ~MpiRanks();

  int rank() const { return rank_; }
  int size() const { return size_; }
  // Ranks on this rank's host (they share its cores).
  int local_size() const { return local_size_; }
  // Every rank's text, in rank order, on rank 0; an empty list on the others. Collective: every
  // rank must call it.
  std::vector<std::string> gather(const std::string& mine) const;

 private:
  bool initialised_ = false;
  int rank_ = 0;
  int size_ = 1;
  int local_size_ = 1;
};

}  // namespace saarcor
