// libsaarcor_dpi.so through its C ABI (rtl/dpi/saarcor_dpi.h), as a simulator calls it: the float
// operators against fixedfloat/format.h's (checked against MPFR in fixedfloat/), the datapaths
// against the values `saarcor vectors --check` recomputes, and the core's traced pixels and unit
// predictions against the functional model's frame of the same scene, built in this process.
#include "rtl/dpi/saarcor_dpi.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "fixedfloat/format.h"
#include "host/image_builder.h"
#include "host/scene.h"
#include "units/functional_model.h"
#include "units/unit_vectors.h"

namespace saarcor {
namespace {

constexpr unsigned kOne = 0x3f0000u;  // fp24 1.0: exponent field 63 (the bias), mantissa 0
constexpr unsigned kInf = 0x7f0000u;

TEST(DpiFloat, HandValuesInFp24) {
  unsigned r = 0;
  ASSERT_EQ(saarcor_dpi_fp_op("add", 7, 16, "rne", "flush", kOne, kOne, &r), SAARCOR_DPI_OK);
  EXPECT_EQ(r, 0x400000u);  // 2.0: exponent field 64
  ASSERT_EQ(saarcor_dpi_fp_op("div", 7, 16, "rne", "flush", kOne, 0, &r), SAARCOR_DPI_OK);
  EXPECT_EQ(r, kInf);
  ASSERT_EQ(saarcor_dpi_fp_op("sqrt", 7, 16, "rne", "flush", 0x410000u, 0, &r), SAARCOR_DPI_OK);
  EXPECT_EQ(r, 0x400000u);  // sqrt(4) = 2
  ASSERT_EQ(saarcor_dpi_fp_op("lt", 7, 16, "rne", "flush", kOne, 0x400000u, &r), SAARCOR_DPI_OK);
  EXPECT_EQ(r, 1u);
  // 1 + 2^-17 in e7m16: halfway between 1 and 1 + 2^-16; nearest even keeps 1.0, and so does
  // toward zero; 1 + 3 * 2^-17 rounds up to 1 + 2^-15 with rne, down to 1 + 2^-16 with rtz.
  double v = 0.0;
  ASSERT_EQ(saarcor_dpi_fp_from_real(1.0 + 3.0 / 131072.0, 7, 16, "rne", "flush", &r),
            SAARCOR_DPI_OK);
  EXPECT_EQ(r, kOne + 2u);
  ASSERT_EQ(saarcor_dpi_fp_from_real(1.0 + 3.0 / 131072.0, 7, 16, "rtz", "flush", &r),
            SAARCOR_DPI_OK);
  EXPECT_EQ(r, kOne + 1u);
  ASSERT_EQ(saarcor_dpi_fp_to_real(0x3e8000u, 7, 16, "flush", &v), SAARCOR_DPI_OK);
  EXPECT_EQ(v, 0.75);  // exponent 62 (2^-1), mantissa 0x8000 (1.5)
}

// Every op in four formats and all four modes, against the runtime-format operators.
TEST(DpiFloat, EveryOpFormatAndModeEqualsFixedfloat) {
  const char* ops[] = {"add", "sub", "mul", "div", "sqrt", "min", "max", "lt", "le", "eq"};
  const ff::Format formats[] = {{7, 16}, {4, 5}, {8, 23}, {5, 10}};
  std::mt19937 rng(7);
  int checked = 0;
  for (const ff::Format& f : formats)
    for (const char* round : {"rne", "rtz"})
      for (const char* sub : {"flush", "keep"}) {
        ff::Mode m;
        m.rounding = round[1] == 'n' ? ff::Rounding::kNearestEven : ff::Rounding::kTowardZero;
        m.subnormals = sub[0] == 'f' ? ff::Subnormals::kFlush : ff::Subnormals::kKeep;
        for (int i = 0; i < 200; ++i) {
          const auto a = static_cast<unsigned>(rng() & f.bits_mask());
          const auto b = static_cast<unsigned>(rng() & f.bits_mask());
          for (const char* op : ops) {
            unsigned got = 0;
            ASSERT_EQ(saarcor_dpi_fp_op(op, f.exp_bits, f.man_bits, round, sub, a, b, &got), 0);
            const std::string o = op;
            const unsigned want = o == "add"    ? ff::op_add(a, b, f, m)
                                  : o == "sub"  ? ff::op_sub(a, b, f, m)
                                  : o == "mul"  ? ff::op_mul(a, b, f, m)
                                  : o == "div"  ? ff::op_div(a, b, f, m)
                                  : o == "sqrt" ? ff::op_sqrt(a, f, m)
                                  : o == "min"  ? ff::op_min(a, b, f, m)
                                  : o == "max"  ? ff::op_max(a, b, f, m)
                                  : o == "lt"   ? unsigned{ff::op_lt(a, b, f, m)}
                                  : o == "le"   ? unsigned{ff::op_le(a, b, f, m)}
                                                : unsigned{ff::op_eq(a, b, f, m)};
            ASSERT_EQ(got, want) << op << " " << ff::format_name(f) << " " << round << " " << sub
                                 << " a=" << std::hex << a << " b=" << b;
            ++checked;
          }
        }
      }
  EXPECT_EQ(checked, 4 * 4 * 200 * 10);
}

TEST(DpiFloat, BadInputIsMinusOneAndOneLine) {
  unsigned r = 12345;
  EXPECT_EQ(saarcor_dpi_fp_op("fma", 7, 16, "rne", "flush", 0, 0, &r), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(
      saarcor_dpi_last_error(),
      "saarcor_dpi_fp_op: unknown op 'fma' (known: add sub mul div sqrt min max lt le eq)");
  EXPECT_EQ(saarcor_dpi_fp_op("add", 9, 16, "rne", "flush", 0, 0, &r), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(),
               "saarcor_dpi_fp_op: format e9m16 is outside 2 <= E <= 8, 1 <= M <= 23");
  EXPECT_EQ(saarcor_dpi_fp_op("add", 7, 16, "rne", "flush", 0x1000000u, 0, &r), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(),
               "saarcor_dpi_fp_op: operand a = 0x1000000 does not fit e7m16 (24 bits)");
  EXPECT_EQ(saarcor_dpi_fp_op("add", 7, 16, "up", "flush", 0, 0, &r), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(),
               "saarcor_dpi_fp_op: unknown rounding mode 'up' (expected rne or rtz)");
  EXPECT_EQ(saarcor_dpi_fp_op("add", 7, 16, "rne", "flush", 0, 0, nullptr), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(), "saarcor_dpi_fp_op: output 'result' is null");
  EXPECT_EQ(r, 12345u);  // untouched by the failed calls
}

// A ray in unit-triangle space straight down onto (0.25, 0.25): t = 1, u = v = 0.25 (0x3d0000:
// exponent 61 = 2^-2), c = D'z = 1; accepted against no hit, refused against an equal t whose
// record has the same instance and a smaller triangle (the tie rule).
TEST(DpiDatapath, IntersectionByHand) {
  unsigned t, u, v, c;
  int inside, accept;
  ASSERT_EQ(saarcor_dpi_intersect("rne", "flush", 0x3d0000u, 0x3d0000u, 0xbf0000u, 0, 0, kOne, 0, 1,
                                  kInf, 0xffffffffu, 0xffffffffu, &t, &u, &v, &c, &inside, &accept),
            SAARCOR_DPI_OK);
  EXPECT_EQ(t, kOne);
  EXPECT_EQ(u, 0x3d0000u);
  EXPECT_EQ(v, 0x3d0000u);
  EXPECT_EQ(c, kOne);
  EXPECT_EQ(inside, 1);
  EXPECT_EQ(accept, 1);
  ASSERT_EQ(saarcor_dpi_intersect("rne", "flush", 0x3d0000u, 0x3d0000u, 0xbf0000u, 0, 0, kOne, 0, 1,
                                  kOne, 0, 0, &t, &u, &v, &c, &inside, &accept),
            SAARCOR_DPI_OK);
  EXPECT_EQ(inside, 1);
  EXPECT_EQ(accept, 0);
}

// Random vectors of each unit against units::expected_outputs, what `saarcor vectors --check`
// holds an RTL run's outputs against.
TEST(DpiDatapath, RandomVectorsEqualTheVectorCheck) {
  std::mt19937 rng(11);
  auto bits = [&] { return static_cast<unsigned>(rng() & 0xffffffu); };
  for (int i = 0; i < 2000; ++i) {
    const unsigned s = bits(), o = bits(), d = bits(), tn = bits(), tf = bits();
    int gn, gf;
    unsigned ntf, ftn;
    ASSERT_EQ(saarcor_dpi_traversal_lane("rne", "flush", s, o, d, tn, tf, &gn, &gf, &ntf, &ftn), 0);
    const auto want = units::expected_outputs(units::VectorUnit::kTraversal, {s, o, d, tn, tf});
    EXPECT_EQ((std::vector<std::uint32_t>{unsigned(gn), unsigned(gf), ntf, ftn}), want);

    std::vector<std::uint32_t> in(16);
    for (int k = 0; k < 15; ++k)
      in[static_cast<std::size_t>(k)] = bits();
    in[15] = rng() & 1u;
    unsigned r[3];
    ASSERT_EQ(saarcor_dpi_transform_step("rne", "flush", in[0], in[1], in[2], in[3], in[4], in[5],
                                         in[6], in[7], in[8], in[9], in[10], in[11], in[12], in[13],
                                         in[14], int(in[15]), &r[0], &r[1], &r[2]),
              0);
    EXPECT_EQ((std::vector<std::uint32_t>{r[0], r[1], r[2]}),
              units::expected_outputs(units::VectorUnit::kTransformation, in));

    const std::vector<std::uint32_t> ray{bits(), bits(), bits(), bits(), bits(), bits()};
    unsigned t, u, v, c;
    int inside, accept;
    ASSERT_EQ(
        saarcor_dpi_intersect("rne", "flush", ray[0], ray[1], ray[2], ray[3], ray[4], ray[5], 0, 0,
                              kInf, 0xffffffffu, 0xffffffffu, &t, &u, &v, &c, &inside, &accept),
        0);
    EXPECT_EQ((std::vector<std::uint32_t>{t, u, v, c, unsigned(inside)}),
              units::expected_outputs(units::VectorUnit::kIntersection, ray));
    EXPECT_EQ(accept, inside);  // against no hit every candidate inside is accepted
  }
}

// ---- the core ----------------------------------------------------------------------------------

std::string run(const std::string& args) {
  const std::string cmd = std::string(SAARCOR_BIN_DIR) + "/saarcor " + args + " > /dev/null 2>&1";
  return std::system(cmd.c_str()) == 0 ? "" : "failed: " + cmd;
}

// Per process: CTest runs each test as its own process, two at a time.
std::string temp_path(const std::string& name) {
  return testing::TempDir() + "dpi_" + std::to_string(::getpid()) + "_" + name;
}

TEST(DpiCore, CallsWithoutAnImageFailWithOneLine) {
  saarcor_dpi_unload_image();
  unsigned inst = 7, tri, t, u, v;
  EXPECT_EQ(saarcor_dpi_trace_pixel(0, 0, 4, &inst, &tri, &t, &u, &v), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(),
               "saarcor_dpi_trace_pixel: no memory image loaded (saarcor_dpi_load_image first)");
  EXPECT_EQ(inst, 7u);
  EXPECT_EQ(saarcor_dpi_core_transform(0, 1, 0, 0, 0, &t, &u, &v), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(),
               "saarcor_dpi_core_transform: no memory image loaded (saarcor_dpi_load_image first)");
}

TEST(DpiCore, ForeignAndCorruptFilesFailWithOneLine) {
  const std::string foreign = temp_path("foreign.img");
  std::ofstream(foreign) << "P6 2 2 255 not an image file";
  EXPECT_EQ(saarcor_dpi_load_image(foreign.c_str()), SAARCOR_DPI_ERROR);
  EXPECT_EQ(std::string(saarcor_dpi_last_error()),
            "saarcor_dpi_load_image: memory image file " + foreign +
                ": not a saarcor memory image (no SAARCORI magic)");
  EXPECT_EQ(saarcor_dpi_load_image("/nonexistent.img"), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(),
               "saarcor_dpi_load_image: memory image file /nonexistent.img: cannot open");
  int w = 0, h, e, m, n;
  EXPECT_EQ(saarcor_dpi_image_info(&w, &h, &e, &m, &n), SAARCOR_DPI_ERROR);
  std::remove(foreign.c_str());
}

// The room as `saarcor scene --write-image` writes it, traced through the library, against the
// functional model's frame of the room built here: every 1009th pixel's hit record (195 pixels;
// a call replays the pixel's packet, about 8 ms at 512x384), bit for bit.
// Then the hit of the centre pixel predicted again unit by unit: its world ray moved into the
// instance's object space (core_transform) and intersected with its triangle (core_intersect)
// gives the same t, u and v.
class DpiRoom : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    path_ = new std::string(temp_path("room.img"));
    ASSERT_EQ(run("scene builtin:room --write-image " + *path_), "");
    built_ = new host::BuiltImage(host::build_image(host::load_scene("builtin:room")));
    frame_ = new units::FunctionalFrame(units::run_functional(built_->image, {}));
  }
  static void TearDownTestSuite() {
    std::remove(path_->c_str());
    delete frame_;
    delete built_;
    delete path_;
  }
  static std::string* path_;
  static host::BuiltImage* built_;
  static units::FunctionalFrame* frame_;
};
std::string* DpiRoom::path_ = nullptr;
host::BuiltImage* DpiRoom::built_ = nullptr;
units::FunctionalFrame* DpiRoom::frame_ = nullptr;

TEST_F(DpiRoom, TracedPixelsEqualTheFunctionalFrame) {
  ASSERT_EQ(saarcor_dpi_load_image(path_->c_str()), SAARCOR_DPI_OK) << saarcor_dpi_last_error();
  int w, h, e, m, n;
  ASSERT_EQ(saarcor_dpi_image_info(&w, &h, &e, &m, &n), SAARCOR_DPI_OK);
  EXPECT_EQ(w, 512);
  EXPECT_EQ(h, 384);
  EXPECT_EQ(e * 100 + m, 716);
  EXPECT_EQ(n, static_cast<int>(built_->image.registers().instance_count));
  int hits = 0;
  for (int i = 0; i < w * h; i += 1009) {
    const int x = i % w, y = i / w;
    unsigned inst, tri, t, u, v;
    ASSERT_EQ(saarcor_dpi_trace_pixel(x, y, 4, &inst, &tri, &t, &u, &v), SAARCOR_DPI_OK);
    const auto& p = frame_->at(x, y);
    ASSERT_EQ(inst, p.instance) << x << "," << y;
    ASSERT_EQ(tri, p.triangle) << x << "," << y;
    ASSERT_EQ(t, p.t) << x << "," << y;
    ASSERT_EQ(u, p.u) << x << "," << y;
    ASSERT_EQ(v, p.v) << x << "," << y;
    hits += inst != 0xffffffffu ? 1 : 0;
  }
  EXPECT_GT(hits, 180);  // the room is closed: nearly all of the 195 pixels hit
  unsigned inst, tri, t, u, v;
  EXPECT_EQ(saarcor_dpi_trace_pixel(512, 0, 4, &inst, &tri, &t, &u, &v), SAARCOR_DPI_ERROR);
  EXPECT_STREQ(saarcor_dpi_last_error(),
               "saarcor_dpi_trace_pixel: functional model: pixel 512,0 lies outside the 512x384 "
               "frame");
}

TEST_F(DpiRoom, UnitPredictionsReproduceTheCentreHit) {
  ASSERT_EQ(saarcor_dpi_load_image(path_->c_str()), SAARCOR_DPI_OK) << saarcor_dpi_last_error();
  const auto& p = frame_->at(256, 192);
  ASSERT_NE(p.instance, 0xffffffffu);
  const unsigned row = built_->image.registers().instance_row_base + 6 * p.instance;
  unsigned o[3], d[3];
  ASSERT_EQ(saarcor_dpi_core_transform(row, 1, p.o[0], p.o[1], p.o[2], &o[0], &o[1], &o[2]), 0);
  ASSERT_EQ(saarcor_dpi_core_transform(row, 0, p.d[0], p.d[1], p.d[2], &d[0], &d[1], &d[2]), 0);
  unsigned t, u, v, c;
  int inside, accept;
  ASSERT_EQ(
      saarcor_dpi_core_intersect(p.instance, p.triangle, o[0], o[1], o[2], d[0], d[1], d[2], kInf,
                                 0xffffffffu, 0xffffffffu, &t, &u, &v, &c, &inside, &accept),
      SAARCOR_DPI_OK)
      << saarcor_dpi_last_error();
  EXPECT_EQ(inside, 1);
  EXPECT_EQ(accept, 1);
  EXPECT_EQ(t, p.t);
  EXPECT_EQ(u, p.u);
  EXPECT_EQ(v, p.v);
  EXPECT_EQ(
      saarcor_dpi_core_intersect(p.instance, 0x7fffffffu, o[0], o[1], o[2], d[0], d[1], d[2], kInf,
                                 0xffffffffu, 0xffffffffu, &t, &u, &v, &c, &inside, &accept),
      SAARCOR_DPI_ERROR);
}

// The traversal unit on the root of the room's object tree (the top level is a single leaf: one
// instance) with the centre pixel's ray in object space over [0, inf): the node's axis and split
// from the image (read here through memif), the lane as saarcor_dpi_traversal_lane computes it; a
// leaf and a node beyond the image are errors.
TEST_F(DpiRoom, CoreTraversalStepsTheObjectRootWithItsSplit) {
  ASSERT_EQ(saarcor_dpi_load_image(path_->c_str()), SAARCOR_DPI_OK) << saarcor_dpi_last_error();
  const auto& p = frame_->at(256, 192);
  const memif::MemoryImage& im = built_->image;
  ASSERT_TRUE(im.node(im.registers().top_root).leaf);
  const std::uint32_t root = im.instance_header(p.instance).root;
  const memif::KdNode n = im.node(root);
  ASSERT_FALSE(n.leaf);
  const unsigned row = im.registers().instance_row_base + 6 * p.instance;
  unsigned o[3], d[3];
  ASSERT_EQ(saarcor_dpi_core_transform(row, 1, p.o[0], p.o[1], p.o[2], &o[0], &o[1], &o[2]), 0);
  ASSERT_EQ(saarcor_dpi_core_transform(row, 0, p.d[0], p.d[1], p.d[2], &d[0], &d[1], &d[2]), 0);
  int axis, gn, gf, want_gn, want_gf;
  unsigned ntf, ftn, want_ntf, want_ftn;
  ASSERT_EQ(saarcor_dpi_core_traversal(root, o[0], o[1], o[2], d[0], d[1], d[2], 0, kInf, &axis,
                                       &gn, &gf, &ntf, &ftn),
            SAARCOR_DPI_OK)
      << saarcor_dpi_last_error();
  EXPECT_EQ(axis, static_cast<int>(n.axis));
  ASSERT_EQ(saarcor_dpi_traversal_lane("rne", "flush", n.split, o[n.axis], d[n.axis], 0, kInf,
                                       &want_gn, &want_gf, &want_ntf, &want_ftn),
            SAARCOR_DPI_OK);
  EXPECT_EQ(gn, want_gn);
  EXPECT_EQ(gf, want_gf);
  EXPECT_EQ(ntf, want_ntf);
  EXPECT_EQ(ftn, want_ftn);
  EXPECT_EQ(gn + gf >= 1, true);  // a ray from inside the room's box needs at least one child
  std::uint32_t leaf = 0;
  while (!im.node(leaf).leaf)
    ++leaf;
  EXPECT_EQ(
      saarcor_dpi_core_traversal(leaf, 0, 0, 0, 0, 0, 0, 0, kInf, &axis, &gn, &gf, &ntf, &ftn),
      SAARCOR_DPI_ERROR);
  EXPECT_EQ(std::string(saarcor_dpi_last_error()),
            "saarcor_dpi_core_traversal: node " + std::to_string(leaf) + " is a leaf");
  const std::uint32_t nodes = im.regions().count[0];
  EXPECT_EQ(
      saarcor_dpi_core_traversal(nodes, 0, 0, 0, 0, 0, 0, 0, kInf, &axis, &gn, &gf, &ntf, &ftn),
      SAARCOR_DPI_ERROR);
  EXPECT_EQ(
      std::string(saarcor_dpi_last_error()),
      "saarcor_dpi_core_traversal: node " + std::to_string(nodes) + " of " + std::to_string(nodes));
}

}  // namespace
}  // namespace saarcor
