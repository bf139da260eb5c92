// The DPI-C reference's transaction-level core (rtl/dpi/saarcor_dpi.h): a memory image file
// (memif/image_file.h) loaded once, then pixels traced through the functional model
// (units::trace_pixel, what `saarcor render --pixel` runs) and single unit steps predicted on the
// image's matrices with the datapath functions of units/datapath.h.
#include <memory>
#include <stdexcept>
#include <string>

#include "memif/image_file.h"
#include "rtl/dpi/dpi_calls.h"
#include "rtl/dpi/saarcor_dpi.h"
#include "units/datapath.h"
#include "units/functional_model.h"
#include "units/unit_fp.h"

namespace saarcor::dpi {
namespace {

using F = ff::fp24;

std::unique_ptr<memif::MemoryImage>& loaded() {
  static std::unique_ptr<memif::MemoryImage> image;
  return image;
}

const memif::MemoryImage& image() {
  if (!loaded()) throw std::runtime_error("no memory image loaded (saarcor_dpi_load_image first)");
  return *loaded();
}

// The unit steps below run the prototype's fp24 operators on the image's words.
const memif::MemoryImage& fp24_image() {
  const memif::MemoryImage& im = image();
  if (!(im.format() == ff::kFp24))
    throw std::runtime_error("the loaded image is " + ff::format_name(im.format()) +
                             "; the unit steps take fp24 images");
  return im;
}

void check_rows(const memif::MemoryImage& im, std::uint64_t row, const char* what) {
  const std::uint32_t rows = im.regions().count[static_cast<int>(memif::ItemType::kRow)];
  if (row + 3 > rows)
    throw std::out_of_range(std::string(what) + " rows " + std::to_string(row) + ".." +
                            std::to_string(row + 2) + " lie beyond the image's " +
                            std::to_string(rows) + " matrix rows");
}

F enc(unsigned int bits, const char* name) {
  return F::from_bits(operand(bits, ff::kFp24, name));
}

}  // namespace
}  // namespace saarcor::dpi

using saarcor::dpi::enc;
using saarcor::dpi::guarded;
using saarcor::dpi::out;
namespace ff = saarcor::ff;
namespace memif = saarcor::memif;
namespace units = saarcor::units;

extern "C" int saarcor_dpi_load_image(const char* path) {
  return guarded("saarcor_dpi_load_image", [&] {
    if (path == nullptr) throw std::invalid_argument("path is null");
    auto image = std::make_unique<memif::MemoryImage>(memif::read_image_file(std::string(path)));
    saarcor::dpi::loaded() = std::move(image);
  });
}

extern "C" int saarcor_dpi_unload_image(void) {
  return guarded("saarcor_dpi_unload_image", [&] {
    saarcor::dpi::image();
    saarcor::dpi::loaded().reset();
  });
}

extern "C" int saarcor_dpi_image_info(int* width, int* height, int* exp_bits, int* man_bits,
                                      int* instances) {
  return guarded("saarcor_dpi_image_info", [&] {
    const memif::MemoryImage& im = saarcor::dpi::image();
    out(width, "width") = static_cast<int>(im.registers().width);
    out(height, "height") = static_cast<int>(im.registers().height);
    out(exp_bits, "exp_bits") = im.format().exp_bits;
    out(man_bits, "man_bits") = im.format().man_bits;
    out(instances, "instances") = static_cast<int>(im.registers().instance_count);
  });
}

extern "C" int saarcor_dpi_trace_pixel(int x, int y, int packet, unsigned int* instance,
                                       unsigned int* triangle, unsigned int* t, unsigned int* u,
                                       unsigned int* v) {
  return guarded("saarcor_dpi_trace_pixel", [&] {
    units::FunctionalParams params;  // the prototype's (units/program_types.h)
    params.packet = packet;
    const units::PixelTrace trace = units::trace_pixel(saarcor::dpi::image(), params, x, y);
    out(instance, "instance") = trace.pixel.instance;
    out(triangle, "triangle") = trace.pixel.triangle;
    out(t, "t") = trace.pixel.t;
    out(u, "u") = trace.pixel.u;
    out(v, "v") = trace.pixel.v;
  });
}

extern "C" int saarcor_dpi_core_transform(unsigned int row, int translate, unsigned int x,
                                          unsigned int y, unsigned int z, unsigned int* rx,
                                          unsigned int* ry, unsigned int* rz) {
  return guarded("saarcor_dpi_core_transform", [&] {
    const memif::MemoryImage& im = saarcor::dpi::fp24_image();
    saarcor::dpi::check_rows(im, row, "matrix");
    if (translate != 0 && translate != 1) throw std::invalid_argument("translate is not 0 or 1");
    const units::UnitFp<ff::fp24> fp;  // the prototype's mode: nearest even, subnormals flushed
    const units::Vec3<ff::fp24> r =
        units::transform_step(fp, units::read_matrix<ff::fp24>(im, row),
                              {enc(x, "x"), enc(y, "y"), enc(z, "z")}, translate == 1);
    out(rx, "rx") = r[0].bits;
    out(ry, "ry") = r[1].bits;
    out(rz, "rz") = r[2].bits;
  });
}

extern "C" int saarcor_dpi_core_traversal(unsigned int node, unsigned int ox, unsigned int oy,
                                          unsigned int oz, unsigned int dx, unsigned int dy,
                                          unsigned int dz, unsigned int tn, unsigned int tf,
                                          int* axis, int* go_near, int* go_far,
                                          unsigned int* near_tf, unsigned int* far_tn) {
  return guarded("saarcor_dpi_core_traversal", [&] {
    const memif::MemoryImage& im = saarcor::dpi::fp24_image();
    const std::uint32_t nodes = im.regions().count[static_cast<int>(memif::ItemType::kNode)];
    if (node >= nodes)
      throw std::out_of_range("node " + std::to_string(node) + " of " + std::to_string(nodes));
    const memif::KdNode n = im.node(node);
    if (n.leaf) throw std::invalid_argument("node " + std::to_string(node) + " is a leaf");
    const ff::fp24 o[3] = {enc(ox, "ox"), enc(oy, "oy"), enc(oz, "oz")};
    const ff::fp24 d[3] = {enc(dx, "dx"), enc(dy, "dy"), enc(dz, "dz")};
    const units::UnitFp<ff::fp24> fp;  // the prototype's mode: nearest even, subnormals flushed
    const units::TraversalLane<ff::fp24> r = units::traversal_lane(
        fp, ff::fp24::from_bits(n.split), o[n.axis], d[n.axis], enc(tn, "tn"), enc(tf, "tf"));
    out(axis, "axis") = static_cast<int>(n.axis);
    out(go_near, "go_near") = r.go_near ? 1 : 0;
    out(go_far, "go_far") = r.go_far ? 1 : 0;
    out(near_tf, "near_tf") = r.near_tf.bits;
    out(far_tn, "far_tn") = r.far_tn.bits;
  });
}

extern "C" int saarcor_dpi_core_intersect(unsigned int instance, unsigned int triangle,
                                          unsigned int ox, unsigned int oy, unsigned int oz,
                                          unsigned int dx, unsigned int dy, unsigned int dz,
                                          unsigned int best_t, unsigned int best_instance,
                                          unsigned int best_triangle, unsigned int* t,
                                          unsigned int* u, unsigned int* v, unsigned int* c,
                                          int* inside, int* accept) {
  return guarded("saarcor_dpi_core_intersect", [&] {
    const memif::MemoryImage& im = saarcor::dpi::fp24_image();
    if (instance >= im.registers().instance_count)
      throw std::out_of_range("instance " + std::to_string(instance) + " of " +
                              std::to_string(im.registers().instance_count));
    const std::uint64_t row = std::uint64_t{im.instance_header(instance).triangle_row_base} +
                              std::uint64_t{memif::kTriangleRows} * triangle;
    saarcor::dpi::check_rows(im, row, "triangle");
    const units::UnitFp<ff::fp24> fp;
    const units::Mat34<ff::fp24> m =
        units::read_matrix<ff::fp24>(im, static_cast<std::uint32_t>(row));
    const units::Ray<ff::fp24> ray{
        units::transform_step(fp, m, {enc(ox, "ox"), enc(oy, "oy"), enc(oz, "oz")}, true),
        units::transform_step(fp, m, {enc(dx, "dx"), enc(dy, "dy"), enc(dz, "dz")}, false)};
    units::HitRecord<ff::fp24> best;
    best.t = enc(best_t, "best_t");
    best.instance = best_instance;
    best.triangle = best_triangle;
    const units::Candidate<ff::fp24> k = units::intersect_unit_triangle(fp, ray);
    out(t, "t") = k.t.bits;
    out(u, "u") = k.u.bits;
    out(v, "v") = k.v.bits;
    out(c, "c") = k.c.bits;
    out(inside, "inside") = k.inside ? 1 : 0;
    out(accept, "accept") = units::accepts(k, instance, triangle, best) ? 1 : 0;
  });
}
