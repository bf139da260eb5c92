// The intersection unit (rtl/intersection_threads.sv) in lockstep with the cycle model: the
// injected fault "accepts on u + v < 1" (intersection_unit.sv FAULT_STRICT_UV) is caught at its
// first wrong event, which the test finds in the healthy run's events: the first thread leaving
// with a closest hit the step accepted exactly on the triangle's edge u + v = 1.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "fixedfloat/float.h"
#include "rtl/builds_testing.h"
#include "rtl/lockstep.h"
#include "units/boundary_intersection.h"
#include "units/cycle_params.h"
#include "units/datapath.h"
#include "units/dynrtp.h"
#include "units/unit_fp.h"

namespace saarcor::rtl {
namespace {

using units::BoundaryEvent;
using units::BoundaryPort;
using F = ff::Float<7, 16>;

// The steps of one thread at the intersection unit: its triangle's rays and ids, from its input.
struct Triangle {
  std::uint64_t mask = 0;
  std::uint32_t instance = 0, triangle = 0;
  std::vector<std::uint32_t> rays;
};

// Whether the output `e` of the step on `in` carries a hit accepted on the edge u + v = 1: a
// lane of the entry whose closest hit is now this triangle's candidate, with u + v rounding to 1.
bool edge_hit(const units::RawFp<F>& fp, const Triangle& in, const BoundaryEvent& e) {
  for (std::size_t i = 0; i * units::kIntersectionRayWords < in.rays.size(); ++i) {
    if (((in.mask >> i) & 1u) == 0) continue;
    const std::uint32_t* w = &in.rays[i * units::kIntersectionRayWords];
    units::Ray<F> r;
    for (std::size_t a = 0; a < 3; ++a) {
      r.o[a] = F{w[a]};
      r.d[a] = F{w[3 + a]};
    }
    const units::Candidate<F> c = units::intersect_unit_triangle(fp, r);
    const std::uint32_t* h = &e.wide[i * units::kIntersectionHitWords];
    const bool now_best = h[0] == c.t.bits && h[4] == in.instance && h[5] == in.triangle;
    if (c.inside && now_best && units::magnitude_key(fp.add(c.u, c.v)) == F::one().bits)
      return true;
  }
  return false;
}

TEST(IntersectionLockstep, StrictUvIsCaughtAtTheFirstEdgeHit) {
  SAARCOR_REQUIRE_VARIANT_BUILDS();
  LockstepOptions o;
  o.units = {"intersection"};
  o.scene = "builtin:room";
  o.width = 64;  // (at 24 x 18 no ray of the room hits an edge exactly)
  o.height = 48;
  const units::RawFp<F> fp(units::functional_params(units::prototype_params(), {}).mode);
  std::map<std::uint32_t, Triangle> in;
  std::uint64_t first = 0, outputs = 0;
  o.model_events = [&](const BoundaryEvent& e) {
    if (e.unit != units::UnitId::kIntersection) return;
    if (e.port == BoundaryPort::kInput)
      in[e.thread] = {e.field[0], static_cast<std::uint32_t>(e.field[3]),
                      static_cast<std::uint32_t>(e.field[4]), e.wide};
    if (e.port != BoundaryPort::kOutput) return;
    ++outputs;
    if (first == 0 && edge_hit(fp, in[e.thread], e)) first = e.cycle;
  };
  const LockstepResult healthy = run_lockstep(o);
  ASSERT_FALSE(healthy.diverged) << healthy.screen;
  EXPECT_EQ(healthy.unit("intersection").event(BoundaryPort::kOutput), outputs);
  ASSERT_NE(first, 0u) << "no ray of the room hits a triangle's edge u + v = 1";

  o.model_events = nullptr;
  o.fault = "strict-uv";
  const LockstepResult r = run_lockstep(o);
  ASSERT_TRUE(r.diverged);
  EXPECT_EQ(r.divergence.cycle, first) << r.screen;
  EXPECT_EQ(r.divergence.unit, "intersection");
  EXPECT_EQ(r.divergence.port, "output");
  EXPECT_EQ(r.divergence.kind, "payload");
  EXPECT_EQ(r.divergence.field.rfind("wide[", 0), 0u) << r.divergence.field;  // a hit record
}

}  // namespace
}  // namespace saarcor::rtl
