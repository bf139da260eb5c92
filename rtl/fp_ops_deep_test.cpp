// Deep runs of the SystemVerilog float operators against fixedfloat (label "deep"; ctest --preset
// deep): 10M TestFloat-style fp24 pairs per mode, every op (rtl/fp_ops_test.cpp runs 200K).
#include <gtest/gtest.h>

#include "Vfp_ops_e7m16_rne_flush.h"
#include "Vfp_ops_e7m16_rne_keep.h"
#include "Vfp_ops_e7m16_rtz_flush.h"
#include "Vfp_ops_e7m16_rtz_keep.h"
#include "rtl/fp_ops_rig.h"

namespace saarcor::rtl::testing {
namespace {

using ff::fp24;
constexpr std::uint64_t kCount = 10'000'000;

TEST(RtlFp24Deep, NearestEvenFlush) {
  OpsRig<Vfp_ops_e7m16_rne_flush, fp24> rig({ff::Rounding::kNearestEven, ff::Subnormals::kFlush},
                                            "fp24 rne flush");
  run_fp24(rig, kCount, 101);
}
TEST(RtlFp24Deep, NearestEvenKeep) {
  OpsRig<Vfp_ops_e7m16_rne_keep, fp24> rig({ff::Rounding::kNearestEven, ff::Subnormals::kKeep},
                                           "fp24 rne keep");
  run_fp24(rig, kCount, 102);
}
TEST(RtlFp24Deep, TowardZeroFlush) {
  OpsRig<Vfp_ops_e7m16_rtz_flush, fp24> rig({ff::Rounding::kTowardZero, ff::Subnormals::kFlush},
                                            "fp24 rtz flush");
  run_fp24(rig, kCount, 103);
}
TEST(RtlFp24Deep, TowardZeroKeep) {
  OpsRig<Vfp_ops_e7m16_rtz_keep, fp24> rig({ff::Rounding::kTowardZero, ff::Subnormals::kKeep},
                                           "fp24 rtz keep");
  run_fp24(rig, kCount, 104);
}

}  // namespace
}  // namespace saarcor::rtl::testing
