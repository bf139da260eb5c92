// MPI ranks: a plain process is rank 0 of 1 and never initialises MPI; `mpirun -np 2 saarcor
// sweep` writes the very CSV one process writes (built where CMake found MPI: SAARCOR_MPIEXEC).
#include "testbench/mpi_ranks.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "testbench/testing.h"

namespace saarcor {
namespace {

namespace fs = std::filesystem;

TEST(MpiRanks, APlainProcessIsRankZeroOfOne) {
  if (mpi_launched()) GTEST_SKIP() << "the tests themselves run under an MPI launcher";
  const MpiRanks ranks;
  EXPECT_EQ(ranks.rank(), 0);
  EXPECT_EQ(ranks.size(), 1);
  EXPECT_EQ(ranks.local_size(), 1);
  EXPECT_EQ(ranks.gather("rows"), std::vector<std::string>{"rows"});
}

#ifdef SAARCOR_MPIEXEC
std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(MpiRanks, TwoRanksWriteTheOneProcessCsv) {
  ASSERT_TRUE(mpi_available());
  const fs::path d = test_support::scratch_dir("mpi");
  fs::remove_all(d);
  fs::create_directories(d);
  const std::string sweep =
      " sweep builtin:room --res 32x24 --vary threads=2,8,32 --vary packet=4,16 --jobs 1 --csv ";
  const std::string bin = std::string(SAARCOR_BIN_DIR) + "/saarcor";
  const std::string one = (d / "one.csv").string(), two = (d / "two.csv").string();
  ASSERT_EQ(std::system((bin + sweep + one + " >/dev/null 2>&1").c_str()), 0);
  // As root (CI containers) OpenMPI wants --allow-run-as-root; --oversubscribe lets two ranks
  // start on a host with fewer free slots.
  const std::string log = (d / "mpirun.log").string();
  const std::string cmd = std::string(SAARCOR_MPIEXEC) +
                          " --allow-run-as-root --oversubscribe -np 2 " + bin + sweep + two + " >" +
                          log + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(log);
  const std::string a = slurp(one), b = slurp(two);
  EXPECT_EQ(std::count(a.begin(), a.end(), '\n'), 7);  // header and six points
  EXPECT_EQ(b, a);
  // Rank 0 alone prints the table: the summary line once.
  const std::string out = slurp(log);
  EXPECT_EQ(out.find("saarcor sweep: builtin:room"), out.rfind("saarcor sweep: builtin:room"))
      << out;
  EXPECT_NE(out.find("6 points, every one bit-identical"), std::string::npos) << out;
}
#endif

}  // namespace
}  // namespace saarcor
