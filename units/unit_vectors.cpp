// Unit transaction vectors: capture from the functional fp24 model, and the datapath reference
// (units/unit_vectors.h, docs/unit-vectors.md).
#include "units/unit_vectors.h"

#include <algorithm>
#include <random>
#include <stdexcept>

#include "units/datapath.h"

namespace saarcor::units {
namespace {

using F = ff::fp24;

// Keeps a uniform sample of `count` transactions of one unit (Algorithm R, seeded), each as its
// encodings and flags.
class SamplingTap final : public UnitTap<F> {
 public:
  SamplingTap(VectorUnit unit, std::size_t count, std::uint64_t seed)
      : unit_(unit), count_(count), rng_(seed) {
    kept_.reserve(count);
  }

  void traversal(int /*lane*/, F split, F o_axis, F d_axis, F tn, F tf, bool go_near, bool go_far,
                 F near_tf, F far_tn) override {
    if (unit_ != VectorUnit::kTraversal || !take()) {
      return;
    }
    keep({split.bits, o_axis.bits, d_axis.bits, tn.bits, tf.bits},
         {go_near ? 1u : 0u, go_far ? 1u : 0u, near_tf.bits, far_tn.bits});
  }
  void transformation(int /*lane*/, const Mat34<F>& m, const Vec3<F>& in, bool translate,
                      const Vec3<F>& out) override {
    if (unit_ != VectorUnit::kTransformation || !take()) {
      return;
    }
    std::vector<std::uint32_t> v;
    for (const auto& row : m) {
      for (const F x : row) {
        v.push_back(x.bits);
      }
    }
    for (const F x : in) {
      v.push_back(x.bits);
    }
    v.push_back(translate ? 1u : 0u);
    keep(std::move(v), {out[0].bits, out[1].bits, out[2].bits});
  }
  void intersection(int /*lane*/, const Ray<F>& ray, const Candidate<F>& c) override {
    if (unit_ != VectorUnit::kIntersection || !take()) {
      return;
    }
    keep({ray.o[0].bits, ray.o[1].bits, ray.o[2].bits, ray.d[0].bits, ray.d[1].bits, ray.d[2].bits},
         {c.t.bits, c.u.bits, c.v.bits, c.c.bits, c.inside ? 1u : 0u});
  }

  VectorCapture result() && {
    std::sort(kept_.begin(), kept_.end(),
              [](const UnitVector& a, const UnitVector& b) { return a.index < b.index; });
    return {std::move(kept_), seen_};
  }

 private:
  // Whether transaction number seen_ enters the sample; slot_ is where it goes.
  bool take() {
    const std::uint64_t i = seen_++;
    if (kept_.size() < count_) {
      slot_ = kept_.size();
      kept_.emplace_back();
      return true;
    }
    const std::uint64_t j = std::uniform_int_distribution<std::uint64_t>(0, i)(rng_);
    if (j >= count_) {
      return false;
    }
    slot_ = static_cast<std::size_t>(j);
    return true;
  }
  void keep(std::vector<std::uint32_t> in, std::vector<std::uint32_t> out) {
    UnitVector& v = kept_[slot_];
    v.index = seen_ - 1;
    v.in = std::move(in);
    v.out = std::move(out);
  }

  VectorUnit unit_;
  std::size_t count_;
  std::mt19937_64 rng_;
  std::vector<UnitVector> kept_;
  std::size_t slot_ = 0;
  std::uint64_t seen_ = 0;
};

F enc(std::uint32_t bits) {
  if ((bits & ~F::kFormat.bits_mask()) != 0) {
    throw std::runtime_error("unit vector: " + std::to_string(bits) +
                             " is not a 24-bit fp24 encoding");
  }
  return F::from_bits(bits);
}
bool flag(std::uint32_t v) {
  if (v > 1) {
    throw std::runtime_error("unit vector: a flag is 0 or 1, not " + std::to_string(v));
  }
  return v == 1;
}

}  // namespace

const char* vector_unit_name(VectorUnit u) {
  switch (u) {
    case VectorUnit::kTraversal:
      return "traversal";
    case VectorUnit::kTransformation:
      return "transformation";
    case VectorUnit::kIntersection:
      return "intersection";
  }
  return "?";
}

VectorUnit parse_vector_unit(const std::string& name) {
  for (int i = 0; i < kVectorUnits; ++i) {
    if (name == vector_unit_name(static_cast<VectorUnit>(i))) {
      return static_cast<VectorUnit>(i);
    }
  }
  throw std::runtime_error("unknown unit '" + name +
                           "' (known: traversal, transformation, intersection)");
}

const std::vector<std::string>& vector_inputs(VectorUnit u) {
  static const std::vector<std::string> fields[kVectorUnits] = {
      {"split", "o_axis", "d_axis", "tn", "tf"},
      {"m00", "m01", "m02", "t0", "m10", "m11", "m12", "t1", "m20", "m21", "m22", "t2", "x", "y",
       "z", "translate"},
      {"ox", "oy", "oz", "dx", "dy", "dz"}};
  return fields[static_cast<int>(u)];
}

const std::vector<std::string>& vector_outputs(VectorUnit u) {
  static const std::vector<std::string> fields[kVectorUnits] = {
      {"go_near", "go_far", "near_tf", "far_tn"},
      {"rx", "ry", "rz"},
      {"t", "u", "v", "c", "inside"}};
  return fields[static_cast<int>(u)];
}

bool vector_field_is_flag(const std::string& field) {
  return field == "go_near" || field == "go_far" || field == "translate" || field == "inside";
}

VectorCapture capture_unit_vectors(const memif::MemoryImage& image, const FunctionalParams& params,
                                   VectorUnit unit, std::size_t count, std::uint64_t seed) {
  if (!(image.format() == F::kFormat)) {
    throw std::runtime_error("unit vectors: the image is in " + ff::format_name(image.format()) +
                             "; the vectors are the fp24 hardware's (e7m16)");
  }
  SamplingTap tap(unit, count, seed);
  run_functional<F>(image, params, {}, &tap);
  return std::move(tap).result();
}

std::vector<std::uint32_t> expected_outputs(VectorUnit unit, const std::vector<std::uint32_t>& in) {
  if (in.size() != vector_inputs(unit).size()) {
    throw std::runtime_error("unit vector: " + std::string(vector_unit_name(unit)) + " takes " +
                             std::to_string(vector_inputs(unit).size()) + " inputs, not " +
                             std::to_string(in.size()));
  }
  const UnitFp<F> fp;  // fp24, round to nearest even, subnormals flushed: the prototype's units
  switch (unit) {
    case VectorUnit::kTraversal: {
      const TraversalLane<F> r =
          traversal_lane(fp, enc(in[0]), enc(in[1]), enc(in[2]), enc(in[3]), enc(in[4]));
      return {r.go_near ? 1u : 0u, r.go_far ? 1u : 0u, r.near_tf.bits, r.far_tn.bits};
    }
    case VectorUnit::kTransformation: {
      Mat34<F> m;
      for (std::size_t k = 0; k < 12; ++k) {
        m[k / 4][k % 4] = enc(in[k]);
      }
      const Vec3<F> v{enc(in[12]), enc(in[13]), enc(in[14])};
      const Vec3<F> r = transform_step(fp, m, v, flag(in[15]));
      return {r[0].bits, r[1].bits, r[2].bits};
    }
    case VectorUnit::kIntersection: {
      Ray<F> ray;
      for (std::size_t k = 0; k < 3; ++k) {
        ray.o[k] = enc(in[k]);
        ray.d[k] = enc(in[3 + k]);
      }
      const Candidate<F> c = intersect_unit_triangle(fp, ray);
      return {c.t.bits, c.u.bits, c.v.bits, c.c.bits, c.inside ? 1u : 0u};
    }
  }
  return {};
}

}  // namespace saarcor::units
