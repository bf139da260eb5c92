// The DPI-C reference's float operators and unit datapaths (rtl/dpi/saarcor_dpi.h): the runtime
// format operators of fixedfloat/format.h (what `saarcor float-calc` and the MPFR tests use) and
// the datapath functions of units/datapath.h on fp24 (what the functional and cycle models and
// `saarcor vectors --check` use).
#include "rtl/dpi/saarcor_dpi.h"

#include <cstdio>
#include <cstring>
#include <string>
#include <string_view>

#include "fixedfloat/float.h"
#include "rtl/dpi/dpi_calls.h"
#include "units/datapath.h"
#include "units/unit_fp.h"

namespace saarcor::dpi {
namespace {

using F = ff::fp24;

std::string& last_error() {
  static std::string message;
  return message;
}

std::string text(const char* s) {
  return s == nullptr ? std::string("(null)") : std::string(s);
}

// The modes by name (fixedfloat's parse_mode, as saarcor float-calc takes them).
ff::Mode mode(const char* round, const char* subnormals) {
  return ff::parse_mode(text(round), text(subnormals));
}

ff::Format format(int exp_bits, int man_bits) {
  const ff::Format f{exp_bits, man_bits};
  if (!f.valid())
    throw std::invalid_argument("format e" + std::to_string(exp_bits) + "m" +
                                std::to_string(man_bits) + " is outside 2 <= E <= 8, 1 <= M <= 23");
  return f;
}

std::uint32_t binary_op(std::string_view op, std::uint32_t a, std::uint32_t b, const ff::Format& f,
                        const ff::Mode& m) {
  if (op == "add") return ff::op_add(a, b, f, m);
  if (op == "sub") return ff::op_sub(a, b, f, m);
  if (op == "mul") return ff::op_mul(a, b, f, m);
  if (op == "div") return ff::op_div(a, b, f, m);
  if (op == "sqrt") return ff::op_sqrt(a, f, m);
  if (op == "min") return ff::op_min(a, b, f, m);
  if (op == "max") return ff::op_max(a, b, f, m);
  if (op == "lt") return ff::op_lt(a, b, f, m) ? 1u : 0u;
  if (op == "le") return ff::op_le(a, b, f, m) ? 1u : 0u;
  if (op == "eq") return ff::op_eq(a, b, f, m) ? 1u : 0u;
  throw std::invalid_argument("unknown op '" + std::string(op) +
                              "' (known: add sub mul div sqrt min max lt le eq)");
}

F fp24(unsigned int bits, const char* name) {
  return F::from_bits(operand(bits, ff::kFp24, name));
}

}  // namespace

void set_last_error(const std::string& message) {
  last_error() = message;
}

std::uint32_t operand(unsigned int bits, const ff::Format& f, const char* name) {
  if ((bits & ~f.bits_mask()) != 0) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%x", bits);
    throw std::invalid_argument(std::string("operand ") + name + " = " + hex + " does not fit " +
                                ff::format_name(f) + " (" + std::to_string(f.bits()) + " bits)");
  }
  return bits;
}

}  // namespace saarcor::dpi

using saarcor::dpi::fp24;
using saarcor::dpi::guarded;
using saarcor::dpi::out;
namespace ff = saarcor::ff;
namespace units = saarcor::units;

extern "C" const char* saarcor_dpi_last_error(void) {
  return saarcor::dpi::last_error().c_str();
}

extern "C" int saarcor_dpi_version(void) {
  return 1;
}

extern "C" int saarcor_dpi_fp_op(const char* op, int exp_bits, int man_bits, const char* round,
                                 const char* subnormals, unsigned int a, unsigned int b,
                                 unsigned int* result) {
  return guarded("saarcor_dpi_fp_op", [&] {
    const ff::Format f = saarcor::dpi::format(exp_bits, man_bits);
    const ff::Mode m = saarcor::dpi::mode(round, subnormals);
    const std::uint32_t x = saarcor::dpi::operand(a, f, "a");
    const std::uint32_t y = saarcor::dpi::operand(b, f, "b");
    const std::uint32_t r = saarcor::dpi::binary_op(saarcor::dpi::text(op), x, y, f, m);
    out(result, "result") = r;
  });
}

extern "C" int saarcor_dpi_fp_from_real(double value, int exp_bits, int man_bits, const char* round,
                                        const char* subnormals, unsigned int* bits) {
  return guarded("saarcor_dpi_fp_from_real", [&] {
    const ff::Format f = saarcor::dpi::format(exp_bits, man_bits);
    const ff::Mode m = saarcor::dpi::mode(round, subnormals);
    out(bits, "bits") = ff::from_double(value, f, m);
  });
}

extern "C" int saarcor_dpi_fp_to_real(unsigned int bits, int exp_bits, int man_bits,
                                      const char* subnormals, double* value) {
  return guarded("saarcor_dpi_fp_to_real", [&] {
    const ff::Format f = saarcor::dpi::format(exp_bits, man_bits);
    const ff::Mode m = saarcor::dpi::mode("rne", subnormals);
    out(value, "value") = ff::decode(saarcor::dpi::operand(bits, f, "bits"), f, m.subnormals);
  });
}

extern "C" int saarcor_dpi_traversal_lane(const char* round, const char* subnormals,
                                          unsigned int split, unsigned int o_axis,
                                          unsigned int d_axis, unsigned int tn, unsigned int tf,
                                          int* go_near, int* go_far, unsigned int* near_tf,
                                          unsigned int* far_tn) {
  return guarded("saarcor_dpi_traversal_lane", [&] {
    const units::UnitFp<ff::fp24> fp(saarcor::dpi::mode(round, subnormals));
    const units::TraversalLane<ff::fp24> r =
        units::traversal_lane(fp, fp24(split, "split"), fp24(o_axis, "o_axis"),
                              fp24(d_axis, "d_axis"), fp24(tn, "tn"), fp24(tf, "tf"));
    out(go_near, "go_near") = r.go_near ? 1 : 0;
    out(go_far, "go_far") = r.go_far ? 1 : 0;
    out(near_tf, "near_tf") = r.near_tf.bits;
    out(far_tn, "far_tn") = r.far_tn.bits;
  });
}

extern "C" int saarcor_dpi_transform_step(const char* round, const char* subnormals,
                                          unsigned int m00, unsigned int m01, unsigned int m02,
                                          unsigned int t0, unsigned int m10, unsigned int m11,
                                          unsigned int m12, unsigned int t1, unsigned int m20,
                                          unsigned int m21, unsigned int m22, unsigned int t2,
                                          unsigned int x, unsigned int y, unsigned int z,
                                          int translate, unsigned int* rx, unsigned int* ry,
                                          unsigned int* rz) {
  return guarded("saarcor_dpi_transform_step", [&] {
    const units::UnitFp<ff::fp24> fp(saarcor::dpi::mode(round, subnormals));
    const units::Mat34<ff::fp24> m{
        {{fp24(m00, "m00"), fp24(m01, "m01"), fp24(m02, "m02"), fp24(t0, "t0")},
         {fp24(m10, "m10"), fp24(m11, "m11"), fp24(m12, "m12"), fp24(t1, "t1")},
         {fp24(m20, "m20"), fp24(m21, "m21"), fp24(m22, "m22"), fp24(t2, "t2")}}};
    const units::Vec3<ff::fp24> v{fp24(x, "x"), fp24(y, "y"), fp24(z, "z")};
    if (translate != 0 && translate != 1) throw std::invalid_argument("translate is not 0 or 1");
    const units::Vec3<ff::fp24> r = units::transform_step(fp, m, v, translate == 1);
    out(rx, "rx") = r[0].bits;
    out(ry, "ry") = r[1].bits;
    out(rz, "rz") = r[2].bits;
  });
}

extern "C" int saarcor_dpi_intersect(const char* round, const char* subnormals, unsigned int ox,
                                     unsigned int oy, unsigned int oz, unsigned int dx,
                                     unsigned int dy, unsigned int dz, unsigned int instance_id,
                                     unsigned int triangle_id, unsigned int best_t,
                                     unsigned int best_instance, unsigned int best_triangle,
                                     unsigned int* t, unsigned int* u, unsigned int* v,
                                     unsigned int* c, int* inside, int* accept) {
  return guarded("saarcor_dpi_intersect", [&] {
    const units::UnitFp<ff::fp24> fp(saarcor::dpi::mode(round, subnormals));
    const units::Ray<ff::fp24> ray{{fp24(ox, "ox"), fp24(oy, "oy"), fp24(oz, "oz")},
                                   {fp24(dx, "dx"), fp24(dy, "dy"), fp24(dz, "dz")}};
    units::HitRecord<ff::fp24> best;
    best.t = fp24(best_t, "best_t");
    best.instance = best_instance;
    best.triangle = best_triangle;
    const units::Candidate<ff::fp24> k = units::intersect_unit_triangle(fp, ray);
    const bool acc = units::accepts(k, instance_id, triangle_id, best);
    out(t, "t") = k.t.bits;
    out(u, "u") = k.u.bits;
    out(v, "v") = k.v.bits;
    out(c, "c") = k.c.bits;
    out(inside, "inside") = k.inside ? 1 : 0;
    out(accept, "accept") = acc ? 1 : 0;
  });
}
