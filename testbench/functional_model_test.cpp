// The functional fp24 model on built images (units/functional_model.h): results independent of
// packet width, stack and mailbox sizes; the same closest hits as a brute-force scan with the same
// datapath functions; ray conservation; op counts per unit against the paper's Table 2; bad input.
#include "units/functional_model.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>

#include "host/image_builder.h"
#include "host/scene.h"

namespace saarcor::units {
namespace {

using F = ff::fp24;

host::BuiltImage build(const std::string& spec, int w = 64, int h = 48,
                       ff::Format format = ff::kFp24) {
  const host::Scene scene = host::load_scene(spec);
  host::ImageParams ip;
  ip.width = w;
  ip.height = h;
  ip.format = format;
  return host::build_image(scene, ip);
}

std::string shared(const std::string& rel) {
  return std::string(SAARCOR_SHARED_SCENES) + "/" + rel;
}

bool same_record(const FrameSink::Pixel& a, const FrameSink::Pixel& b) {
  return a.t == b.t && a.u == b.u && a.v == b.v && a.cos == b.cos && a.instance == b.instance &&
         a.triangle == b.triangle && a.o == b.o && a.d == b.d;
}

void expect_same_frames(const FunctionalFrame& a, const FunctionalFrame& b, bool counters,
                        const std::string& what) {
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  int bad = 0;
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const bool same = same_record(a.pixels[i], b.pixels[i]) &&
                      (!counters || a.pixels[i].counters == b.pixels[i].counters);
    if (!same && ++bad <= 3)
      ADD_FAILURE() << what << ": pixel " << i % static_cast<std::size_t>(a.width) << ","
                    << i / static_cast<std::size_t>(a.width) << " differs (replay: --pixel x,y)";
  }
  EXPECT_EQ(bad, 0) << what;
  EXPECT_EQ(a.rgb, b.rgb) << what;
}

// Every instance's every triangle, with the model's own datapath functions and no kd-tree.
HitRecord<F> brute_force(const host::BuiltImage& b, const Ray<F>& world) {
  UnitFp<F> fp;
  HitRecord<F> best;
  const auto& img = b.image;
  for (std::uint32_t i = 0; i < img.registers().instance_count; ++i) {
    if (!b.instances[i].in_top_level) continue;
    const std::uint32_t row = img.registers().instance_row_base + memif::kInstanceRows * i;
    const Mat34<F> m = read_matrix<F>(img, row);
    const Ray<F> obj{transform_step(fp, m, world.o, true), transform_step(fp, m, world.d, false)};
    const memif::InstanceHeader h = img.instance_header(i);
    const host::ObjectInfo& o = b.objects[b.instances[i].object];
    for (std::uint32_t k = 0; k < o.triangles; ++k) {
      if (!o.t_delta[k]) continue;
      const Mat34<F> t = read_matrix<F>(img, h.triangle_row_base + memif::kTriangleRows * k);
      const Ray<F> tri{transform_step(fp, t, obj.o, true), transform_step(fp, t, obj.d, false)};
      const Candidate<F> c = intersect_unit_triangle(fp, tri);
      if (!accepts(c, i, k, best)) continue;
      best.t = c.t;
      best.u = c.u;
      best.v = c.v;
      best.c = c.c;
      best.instance = i;
      best.triangle = k;
    }
  }
  return best;
}

// Pixels whose kd-tree hit differs from the brute-force hit.
int brute_force_mismatches(const host::BuiltImage& b, const FunctionalFrame& fr,
                           int* hits = nullptr) {
  int bad = 0, n = 0;
  for (int y = 0; y < fr.height; ++y)
    for (int x = 0; x < fr.width; ++x) {
      const auto& px = fr.at(x, y);
      Ray<F> r;
      for (int k = 0; k < 3; ++k) {
        r.o[k] = F::from_bits(px.o[static_cast<std::size_t>(k)]);
        r.d[k] = F::from_bits(px.d[static_cast<std::size_t>(k)]);
      }
      const HitRecord<F> h = brute_force(b, r);
      const std::uint32_t t = h.hit() ? h.t.bits : F::infinity().bits;
      if (h.hit()) ++n;
      if (h.instance != px.instance || h.triangle != px.triangle || t != px.t) {
        if (++bad <= 3)
          ADD_FAILURE() << "pixel " << x << "," << y << ": kd-tree hit " << px.instance << "/"
                        << px.triangle << " t=" << F::from_bits(px.t).to_double()
                        << ", brute force " << h.instance << "/" << h.triangle
                        << " t=" << h.t.to_double() << " (replay: --pixel " << x << "," << y << ")";
      }
    }
  if (hits) *hits = n;
  return bad;
}

#ifdef SAARCOR_SANITIZED
constexpr int kW = 32, kH = 24;  // the sanitizer run is ~20x slower
#else
constexpr int kW = 64, kH = 48;
#endif

TEST(FunctionalModel, PrimaryRaysComeFromTinit) {
  const host::BuiltImage b = build("builtin:room", 16, 12);
  const FunctionalFrame fr = run_functional<F>(b.image, FunctionalParams{});
  const auto& regs = b.image.registers();
  Mat34<F> t{};
  for (int r = 0; r < 3; ++r)
    t[r] = {F::from_bits(regs.cam_r[r]), F::from_bits(regs.cam_u[r]), F::from_bits(regs.cam_d[r]),
            F::from_bits(regs.cam_p[r])};
  UnitFp<F> fp;
  for (auto [x, y] : {std::pair{0, 0}, std::pair{5, 3}, std::pair{15, 11}}) {
    const Vec3<F> o = transform_step(fp, t, Vec3<F>{F::zero(), F::zero(), F::zero()}, true);
    const Vec3<F> d =
        transform_step(fp, t, Vec3<F>{F::from_int(x), F::from_int(y), F::one()}, false);
    for (int k = 0; k < 3; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      EXPECT_EQ(fr.at(x, y).o[kk], o[k].bits);
      EXPECT_EQ(fr.at(x, y).o[kk], regs.cam_p[kk]) << "origin = Cp exactly";
      EXPECT_EQ(fr.at(x, y).d[kk], d[k].bits);
    }
  }
}

TEST(FunctionalModel, PacketWidthNeverChangesResults) {
  const host::BuiltImage b = build("builtin:room", kW, kH);
  FunctionalParams p;
  p.packet = 1;
  // The triangle mailbox holds 8 triangles per packet: a wider packet evicts sooner, so its rays
  // test some triangles again (results equal, per-ray counters not).
  p.triangle_mailbox = 0;
  const FunctionalFrame f1 = run_functional<F>(b.image, p);
  for (int packet : {2, 4, 16, 64}) {
    p.packet = packet;
    expect_same_frames(f1, run_functional<F>(b.image, p), true, "packet " + std::to_string(packet));
  }
}

TEST(FunctionalModel, StackAndMailboxSizesNeverChangeResults) {
  const host::BuiltImage b = build("builtin:room", kW, kH);
  FunctionalParams p;
  const FunctionalFrame ref = run_functional<F>(b.image, p);
  for (int mb : {0, 1, 32}) {
    FunctionalParams q = p;
    q.mailbox = mb;
    q.triangle_mailbox = mb;
    expect_same_frames(ref, run_functional<F>(b.image, q), false, "mailbox " + std::to_string(mb));
  }
  FunctionalParams q = p;
  q.stack_depth = 200;
  q.shared_origin = false;
  expect_same_frames(ref, run_functional<F>(b.image, q), true, "stack 200, no shared origin");
  // The mailbox only saves work: without it the rays fetch at least as many list entries.
  q = p;
  q.mailbox = 0;
  q.triangle_mailbox = 0;
  const FunctionalFrame no_mb = run_functional<F>(b.image, q);
  EXPECT_EQ(no_mb.by_kind[0].mailbox_skips, 0u);
  EXPECT_GE(no_mb.by_kind[0].transformations, ref.by_kind[0].transformations);
}

// Empty children flagged in their parent (memif::KdNode) are never stepped into: the same hits
// and image, and the steps saved are at least the empty-leaf steps the frame took without it.
TEST(FunctionalModel, SkippingEmptyChildrenSavesTheirStepsOnly) {
  for (const char* spec : {"builtin:room", "builtin:dynamic"}) {
    const host::BuiltImage b = build(spec, kW, kH);
    FunctionalParams on;
    FunctionalParams off = on;
    off.skip_empty = false;
    const FunctionalFrame a = run_functional<F>(b.image, on);
    const FunctionalFrame c = run_functional<F>(b.image, off);
    expect_same_frames(c, a, false, std::string(spec) + " skip_empty");
    EXPECT_EQ(a.units.empty_leaf_steps, 0u) << spec;  // roots are never empty here
    EXPECT_GT(c.units.empty_leaf_steps, 0u) << spec;
    EXPECT_GE(c.units.traversal_steps - a.units.traversal_steps, c.units.empty_leaf_steps) << spec;
    EXPECT_EQ(c.units.inner_steps, a.units.inner_steps) << spec;
    EXPECT_EQ(c.units.transformation_steps, a.units.transformation_steps) << spec;
  }
}

// A traversal unit with k dividers per ray clips k faces per step: ceil(6 / k) steps for a whole
// box, ceil(3 / k) for the exit faces; the same divisions in all, the same results.
TEST(FunctionalModel, ClipFacesPerStepSetsTheClipSteps) {
  const host::BuiltImage b = build("builtin:room", kW, kH);
  const FunctionalFrame one = run_functional<F>(b.image, FunctionalParams{});
  for (int k : {2, 3, 6}) {
    FunctionalParams p;
    p.clip_faces_per_step = k;
    const FunctionalFrame f = run_functional<F>(b.image, p);
    expect_same_frames(one, f, false, "clip faces per step " + std::to_string(k));
    const std::uint64_t full = f.units.clips - f.units.exit_only_clips;
    const auto steps = [&](int faces) { return static_cast<std::uint64_t>((faces + k - 1) / k); };
    EXPECT_EQ(f.units.clip_steps, full * steps(6) + f.units.exit_only_clips * steps(3)) << k;
    EXPECT_EQ(f.units.traversal_ops.div, one.units.traversal_ops.div) << k;
    EXPECT_EQ(f.units.traversal_ops.cmp, one.units.traversal_ops.cmp) << k;
    EXPECT_EQ(one.units.traversal_steps, f.units.traversal_steps) << k;  // node steps alike
  }
  FunctionalParams bad;
  bad.clip_faces_per_step = 7;
  EXPECT_THROW(run_functional<F>(b.image, bad), std::runtime_error);
}

class BruteForce : public ::testing::TestWithParam<std::string> {};

TEST_P(BruteForce, KdTreeHitsWhatTheScanHits) {
  const std::string spec = GetParam().rfind("builtin:", 0) == 0 ? GetParam() : shared(GetParam());
#ifdef SAARCOR_SANITIZED
  const int w = 24, h = 18;  // the scan is quadratic; keep the sanitizer run short
#else
  const int w = 48, h = 36;
#endif
  const host::BuiltImage b = build(spec, w, h);
  const FunctionalFrame fr = run_functional<F>(b.image, FunctionalParams{});
  int hits = 0;
  EXPECT_EQ(brute_force_mismatches(b, fr, &hits), 0);
  EXPECT_GT(hits, w * h / 20) << "the camera should see the scene";
  std::printf("[ scene    ] %s: %d of %d pixels hit\n", GetParam().c_str(), hits, w * h);
}

INSTANTIATE_TEST_SUITE_P(Scenes, BruteForce,
                         ::testing::Values("builtin:room", "builtin:cube", "Box/Box.gltf",
                                           "Duck/Duck.gltf", "SimpleMeshes/SimpleMeshes.gltf",
                                           "BoxTextured/BoxTextured.gltf"),
                         [](const auto& info) {
                           std::string n = info.param.substr(0, info.param.find('/'));
                           for (char& c : n)
                             if (c == ':') c = '_';
                           return n;
                         });

TEST(FunctionalModel, EveryRayReturnsExactlyOnce) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  FunctionalParams p;
  p.shadows = true;
  p.secondary = true;
  const FunctionalFrame fr = run_functional<F>(b.image, p);
  EXPECT_EQ(fr.rays_issued[0], 32u * 24u);
  for (int k = 0; k < kRayKinds; ++k)
    EXPECT_EQ(fr.rays_issued[static_cast<std::size_t>(k)],
              fr.rays_returned[static_cast<std::size_t>(k)])
        << ray_kind_name(static_cast<RayKind>(k));
  EXPECT_GT(fr.rays_issued[1], 0u) << "room has lights: shadow rays";
}

TEST(FunctionalModel, OpCountsPerUnitFollowTable2) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  FunctionalParams p;
  p.shade = false;  // shading adds dot products on the transformation unit
  const FunctionalFrame fr = run_functional<F>(b.image, p);
  const UnitStats& u = fr.units;
  const std::uint64_t P = 4;
  // Traversal: per inner step P add, P div, 3P cmp; leaf/empty steps P cmp (the termination
  // check); box-face clip steps P add, P div, P cmp, plus P cmp on each box's last face and 2P
  // (origin against the box) on the first step of an exit-only clip; P cmp per stack entry
  // dropped at the pop (its rays' termination test).
  EXPECT_EQ(u.traversal_ops.add, P * (u.inner_steps + u.clip_steps));
  EXPECT_EQ(u.traversal_ops.div, P * (u.inner_steps + u.clip_steps));
  EXPECT_EQ(u.traversal_ops.cmp, 3 * P * u.inner_steps + P * (u.traversal_steps - u.inner_steps) +
                                     P * u.clip_steps + P * u.clips + 2 * P * u.exit_only_clips +
                                     P * u.stack_drops);
  // Clip steps: 6 per box, 3 when every ray starts inside it.
  EXPECT_EQ(u.clip_steps, 6 * u.clips - 3 * u.exit_only_clips);
  EXPECT_GT(u.exit_only_clips, 0u) << "the room's camera is inside the scene box";
  EXPECT_GT(u.stack_drops, 0u);
  EXPECT_EQ(u.traversal_ops.mul, 0u);
  // Transformation: 9 mul, 9 add per step.
  EXPECT_EQ(u.transformation_ops.mul, 9 * u.transformation_steps);
  EXPECT_EQ(u.transformation_ops.add, 9 * u.transformation_steps);
  // Intersection: 3 add, 2 mul, 1 div per ray, P rays per packet, no comparator.
  EXPECT_EQ(u.intersection_ops.add, 3 * P * u.intersection_packets);
  EXPECT_EQ(u.intersection_ops.mul, 2 * P * u.intersection_packets);
  EXPECT_EQ(u.intersection_ops.div, P * u.intersection_packets);
  EXPECT_EQ(u.intersection_ops.cmp, 0u);
  EXPECT_EQ(u.rgs_ops.total(), 0u);
  EXPECT_GT(u.inner_steps, 0u);
  std::printf("[ table 2  ] per inner step: %.2f add %.2f div %.2f cmp (paper 4/4/13)\n",
              1.0 * u.traversal_ops.add / static_cast<double>(u.inner_steps + u.clip_steps),
              1.0 * u.traversal_ops.div / static_cast<double>(u.inner_steps + u.clip_steps),
              3.0 * P);
}

TEST(FunctionalModel, ShadingColoursHitsAndBackground) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  FunctionalParams p;
  const FunctionalFrame plain = run_functional<F>(b.image, p);
  const std::uint32_t bg = b.image.registers().background_rgb;
  int lit = 0;
  for (std::size_t i = 0; i < plain.pixels.size(); ++i) {
    const std::uint8_t* c = &plain.rgb[3 * i];
    if (plain.pixels[i].instance == memif::kNone) {
      EXPECT_EQ(c[0] | (c[1] << 8) | (c[2] << 16), static_cast<int>(bg & 0xFFFFFF));
    } else if (c[0] + c[1] + c[2] > 0) {
      ++lit;
    }
  }
  EXPECT_GT(lit, 0);
  p.shadows = true;
  const FunctionalFrame shadowed = run_functional<F>(b.image, p);
  // Shadows only take light away.
  std::uint64_t sum_plain = 0, sum_shadow = 0;
  for (std::size_t i = 0; i < plain.rgb.size(); ++i) {
    EXPECT_LE(shadowed.rgb[i], plain.rgb[i]);
    sum_plain += plain.rgb[i];
    sum_shadow += shadowed.rgb[i];
  }
  EXPECT_LT(sum_shadow, sum_plain) << "the room casts some shadow";
}

TEST(FunctionalModel, PrecisionFormatsRun) {
  const host::BuiltImage b16 = build("builtin:room", 32, 24);
  const FunctionalFrame f16 = run_functional<F>(b16.image, FunctionalParams{});
  for (int m : {10, 23}) {
    const host::BuiltImage b = build("builtin:room", 32, 24, ff::Format{7, m});
    const FunctionalFrame fr = run_functional(b.image, FunctionalParams{});
    EXPECT_EQ(fr.format, (ff::Format{7, m}));
    int same = 0;
    for (std::size_t i = 0; i < fr.pixels.size(); ++i)
      same += fr.pixels[i].instance == f16.pixels[i].instance &&
              fr.pixels[i].triangle == f16.pixels[i].triangle;
    EXPECT_GT(same, static_cast<int>(fr.pixels.size()) * 8 / 10) << "m = " << m;
  }
}

TEST(FunctionalModel, TracePixelReplaysOnePixel) {
  const host::BuiltImage b = build("builtin:room", 32, 24);
  const FunctionalFrame fr = run_functional<F>(b.image, FunctionalParams{});
  const PixelTrace t = trace_pixel(b.image, FunctionalParams{}, 13, 7);
  EXPECT_TRUE(same_record(t.pixel, fr.at(13, 7)));
  EXPECT_EQ(t.rgb[0], fr.rgb[3 * (7 * 32 + 13)]);
  ASSERT_FALSE(t.log.empty());
  EXPECT_NE(t.log.front().find("generate"), std::string::npos);
}

TEST(FunctionalModel, BadInputThrowsOneLine) {
  const host::BuiltImage b = build("builtin:room", 16, 12);
  using F12 = ff::Float<7, 12>;
  EXPECT_THROW(run_functional<F12>(b.image, FunctionalParams{}), std::runtime_error);
  FunctionalParams p;
  p.packet = 3;
  EXPECT_THROW(run_functional<F>(b.image, p), std::runtime_error);
  p.packet = 128;
  EXPECT_THROW(run_functional<F>(b.image, p), std::runtime_error);
  p = {};
  p.stack_depth = 1;
  EXPECT_THROW(run_functional<F>(b.image, p), std::runtime_error);
  p.stack_depth = 0;
  EXPECT_THROW(run_functional<F>(b.image, p), std::runtime_error);
  EXPECT_THROW(trace_pixel(b.image, FunctionalParams{}, 16, 0), std::runtime_error);
  memif::MemoryImage wrong(ff::Format{5, 10}, 16);
  wrong.registers().width = 4;
  wrong.registers().height = 4;
  EXPECT_THROW(run_functional(wrong, FunctionalParams{}), std::runtime_error);
  try {
    run_functional<F12>(b.image, FunctionalParams{});
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("e7m16"), std::string::npos);
  }
}

}  // namespace
}  // namespace saarcor::units
