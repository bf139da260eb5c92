// MPI ranks for the sweep (testbench/mpi_ranks.h). The MPI calls exist only in a build that found
// MPI; the launch detection and the refusal exist in every build.
#include "testbench/mpi_ranks.h"

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#ifndef SAARCOR_HAVE_MPI  // CMake defines it to 1 when it found MPI
#define SAARCOR_HAVE_MPI 0
#endif
#if SAARCOR_HAVE_MPI
#include <mpi.h>
#endif

namespace saarcor {
namespace {

// The launcher's world size, 0 when not launched by one.
int launcher_size() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    if (const char* v = std::getenv(var)) return std::max(1, std::atoi(v));
  }
  return std::getenv("PMIX_RANK") != nullptr ? 1 : 0;
}

}  // namespace

bool mpi_available() {
  return SAARCOR_HAVE_MPI != 0;
}

bool mpi_launched() {
  return launcher_size() > 0;
}

#if SAARCOR_HAVE_MPI

MpiRanks::MpiRanks() {
  if (!mpi_launched()) return;
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  initialised_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm local;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &local);
  MPI_Comm_size(local, &local_size_);
  MPI_Comm_free(&local);
}

MpiRanks::~MpiRanks() {
  if (initialised_) MPI_Finalize();
}

std::vector<std::string> MpiRanks::gather(const std::string& mine) const {
  if (size_ == 1) return {mine};
  // Lengths first, then the texts themselves into one buffer at rank 0.
  int length = static_cast<int>(mine.size());
  std::vector<int> lengths(static_cast<std::size_t>(size_));
  MPI_Gather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
  std::vector<int> offsets(static_cast<std::size_t>(size_), 0);
  int total = 0;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = total;
    total += lengths[r];
  }
  std::string all(rank_ == 0 ? static_cast<std::size_t>(total) : 0, '\0');
  MPI_Gatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
              0, MPI_COMM_WORLD);
  if (rank_ != 0) return {};
  std::vector<std::string> texts;
  for (std::size_t r = 0; r < lengths.size(); ++r)
    texts.push_back(
        all.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(lengths[r])));
  return texts;
}

#else

MpiRanks::MpiRanks() {
  const int n = launcher_size();
  if (n > 1)
    throw std::runtime_error("started by an MPI launcher with " + std::to_string(n) +
                             " ranks, but this saarcor was built without MPI (install "
                             "libopenmpi-dev and rebuild), or run one process (--jobs, --shard)");
}

MpiRanks::~MpiRanks() = default;

std::vector<std::string> MpiRanks::gather(const std::string& mine) const {
  return {mine};
}

#endif

}  // namespace saarcor
