// Unit transaction vectors (README.md: an RTL design is checked against the model "unit
// by unit (transaction vectors) and frame by frame"): the operands and results of the traversal,
// transformation and intersection datapaths as a real frame exercises them, captured from the
// functional fp24 model, and the datapath's answer to any vector's operands, so a vector file an
// RTL simulation wrote can be checked (docs/unit-vectors.md).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "memif/image_format.h"
#include "units/functional_model.h"

namespace saarcor::units {

enum class VectorUnit { kTraversal, kTransformation, kIntersection };
inline constexpr int kVectorUnits = 3;
const char* vector_unit_name(VectorUnit u);  // "traversal", "transformation", "intersection"
// Throws "unknown unit 'x' (known: traversal, transformation, intersection)".
VectorUnit parse_vector_unit(const std::string& name);

// The fields of a unit's vector: inputs, then outputs. Values are fp24 encodings, flags 0 or 1.
//   traversal (one ray's lane of an inner kd-node step):
//     split o_axis d_axis tn tf -> go_near go_far near_tf far_tn
//   transformation (one matrix-vector step, row r = m_r0 m_r1 m_r2 t_r):
//     m00 m01 m02 t0 m10 m11 m12 t1 m20 m21 m22 t2 x y z translate -> rx ry rz
//   intersection (one ray in unit-triangle space):
//     ox oy oz dx dy dz -> t u v c inside
const std::vector<std::string>& vector_inputs(VectorUnit u);
const std::vector<std::string>& vector_outputs(VectorUnit u);
// Whether a field is a flag (0/1) rather than an fp24 encoding.
bool vector_field_is_flag(const std::string& field);

struct UnitVector {
  std::uint64_t index = 0;  // the transaction's position in the frame (0 = the unit's first)
  std::vector<std::uint32_t> in, out;
};
struct VectorCapture {
  std::vector<UnitVector> vectors;  // in frame order
  std::uint64_t transactions = 0;   // the unit's transactions in the frame
};

// Runs the functional fp24 model on the image's frame and keeps `count` of `unit`'s transactions,
// a uniform sample (reservoir, seeded: the same seed gives the same vectors), or all of them when
// the frame has fewer. Throws for an image that is not fp24.
VectorCapture capture_unit_vectors(const memif::MemoryImage& image, const FunctionalParams& params,
                                   VectorUnit unit, std::size_t count, std::uint64_t seed);

// What the datapath outputs for `in` (units/datapath.h, fp24, round to nearest even): the
// reference a vector's outputs are checked against. Throws if `in` has the wrong field count or a
// flag is not 0/1.
std::vector<std::uint32_t> expected_outputs(VectorUnit unit, const std::vector<std::uint32_t>& in);

}  // namespace saarcor::units
