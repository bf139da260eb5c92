// Driving the Verilated unit datapaths (rtl/rtl_units.h).
#include "rtl/rtl_units.h"

#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include "Vintersection_unit.h"
#include "Vtransform_unit.h"
#include "Vtraversal_unit.h"
#include "verilated.h"

namespace saarcor::rtl {
namespace {

template <class V>
void tick(V& top) {
  top.clk = 0;
  top.eval();
  top.clk = 1;
  top.eval();
}

// One transaction per cycle (or a random idle cycle), outputs collected in order. `set_in` puts a
// transaction (or, for an idle cycle, random junk) on the input ports; `get_out` reads the
// outputs. A transaction issued before clock edge k (cycle k) whose output is valid after edge
// k + n - 1 (in cycle k + n) has latency n.
template <class V, class SetIn, class GetOut>
RtlRun drive(std::size_t count, std::size_t in_fields, const RunOptions& opt, SetIn set_in,
             GetOut get_out) {
  auto top = std::make_unique<V>();
  RtlRun run;
  run.outputs.resize(count);
  std::vector<std::uint64_t> issued_at(count);
  std::mt19937_64 rng(opt.seed);
  std::vector<std::uint32_t> junk(in_fields);

  top->rst = 1;
  top->in_valid = 0;
  for (int i = 0; i < 3; ++i)
    tick(*top);
  top->rst = 0;

  std::uint64_t cycle = 0;
  std::size_t next_in = 0;
  std::size_t next_out = 0;
  std::uint64_t quiet = 0;  // cycles without an output while some are due
  bool first = true;
  while (next_out < count) {
    const bool idle =
        opt.bubble_one_in > 0 && rng() % static_cast<unsigned>(opt.bubble_one_in) == 0;
    if (next_in < count && !idle) {
      top->in_valid = 1;
      set_in(*top, next_in);
      issued_at[next_in++] = cycle;
    } else {
      top->in_valid = 0;
      for (auto& j : junk)
        j = static_cast<std::uint32_t>(rng());
      set_in.junk(*top, junk);
    }
    tick(*top);
    ++cycle;
    if (top->out_valid) {
      quiet = 0;
      if (next_out >= next_in) {
        ++run.stray_outputs;
        continue;
      }
      const int lat = static_cast<int>(cycle - issued_at[next_out]);
      if (first || lat < run.latency_min) run.latency_min = lat;
      if (first || lat > run.latency_max) run.latency_max = lat;
      first = false;
      run.outputs[next_out++] = get_out(*top);
    } else if (next_out < next_in && ++quiet > 1000) {
      throw std::runtime_error("rtl: the pipeline stopped delivering outputs");
    }
  }
  // Idle cycles after the last output: nothing may come out any more.
  top->in_valid = 0;
  for (int i = 0; i < 64; ++i) {
    tick(*top);
    ++cycle;
    if (top->out_valid) ++run.stray_outputs;
  }
  run.cycles = cycle;
  top->final();
  return run;
}

void check_fields(const std::vector<std::vector<std::uint32_t>>& inputs, std::size_t n,
                  units::VectorUnit unit) {
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    if (inputs[i].size() != n) {
      throw std::runtime_error(std::string("rtl: ") + units::vector_unit_name(unit) +
                               " transaction " + std::to_string(i) + " has " +
                               std::to_string(inputs[i].size()) + " inputs, expected " +
                               std::to_string(n));
    }
  }
}

constexpr std::uint32_t kFp24Mask = 0xFFFFFF;

struct IntersectionIn {
  const std::vector<std::vector<std::uint32_t>>& in;
  const std::vector<AcceptInputs>& acc;
  void put(Vintersection_unit& t, const std::uint32_t* v, const AcceptInputs& a) const {
    t.ox = v[0] & kFp24Mask;
    t.oy = v[1] & kFp24Mask;
    t.oz = v[2] & kFp24Mask;
    t.dx = v[3] & kFp24Mask;
    t.dy = v[4] & kFp24Mask;
    t.dz = v[5] & kFp24Mask;
    t.instance_id = a.instance;
    t.triangle_id = a.triangle;
    t.best_t = a.best_t & kFp24Mask;
    t.best_instance = a.best_instance;
    t.best_triangle = a.best_triangle;
  }
  void operator()(Vintersection_unit& t, std::size_t i) const {
    put(t, in[i].data(), acc.empty() ? AcceptInputs{} : acc[i]);
  }
  void junk(Vintersection_unit& t, const std::vector<std::uint32_t>& j) const {
    put(t, j.data(), AcceptInputs{j[0], j[1], j[2], j[3], j[4]});
  }
};

struct TransformationIn {
  const std::vector<std::vector<std::uint32_t>>& in;
  static void put(Vtransform_unit& t, const std::uint32_t* v) {
    t.m00 = v[0] & kFp24Mask;
    t.m01 = v[1] & kFp24Mask;
    t.m02 = v[2] & kFp24Mask;
    t.t0 = v[3] & kFp24Mask;
    t.m10 = v[4] & kFp24Mask;
    t.m11 = v[5] & kFp24Mask;
    t.m12 = v[6] & kFp24Mask;
    t.t1 = v[7] & kFp24Mask;
    t.m20 = v[8] & kFp24Mask;
    t.m21 = v[9] & kFp24Mask;
    t.m22 = v[10] & kFp24Mask;
    t.t2 = v[11] & kFp24Mask;
    t.x = v[12] & kFp24Mask;
    t.y = v[13] & kFp24Mask;
    t.z = v[14] & kFp24Mask;
    t.translate = v[15] & 1u;
  }
  void operator()(Vtransform_unit& t, std::size_t i) const { put(t, in[i].data()); }
  void junk(Vtransform_unit& t, const std::vector<std::uint32_t>& j) const { put(t, j.data()); }
};

struct TraversalIn {
  const std::vector<std::vector<std::uint32_t>>& in;
  static void put(Vtraversal_unit& t, const std::uint32_t* v) {
    t.split = v[0] & kFp24Mask;
    t.o_axis = v[1] & kFp24Mask;
    t.d_axis = v[2] & kFp24Mask;
    t.tn = v[3] & kFp24Mask;
    t.tf = v[4] & kFp24Mask;
  }
  void operator()(Vtraversal_unit& t, std::size_t i) const { put(t, in[i].data()); }
  void junk(Vtraversal_unit& t, const std::vector<std::uint32_t>& j) const { put(t, j.data()); }
};

}  // namespace

RtlRun run_unit(units::VectorUnit unit, const std::vector<std::vector<std::uint32_t>>& inputs,
                const RunOptions& options, const std::vector<AcceptInputs>& accept) {
  const std::size_t n = units::vector_inputs(unit).size();
  check_fields(inputs, n, unit);
  switch (unit) {
    case units::VectorUnit::kIntersection:
      if (!accept.empty() && accept.size() != inputs.size())
        throw std::runtime_error("rtl: one set of acceptance inputs per transaction expected");
      return drive<Vintersection_unit>(
          inputs.size(), n, options, IntersectionIn{inputs, accept},
          [](const Vintersection_unit& t) -> std::vector<std::uint32_t> {
            return {t.t, t.u, t.v, t.c, t.hit_inside, t.accept};
          });
    case units::VectorUnit::kTransformation:
      return drive<Vtransform_unit>(inputs.size(), n, options, TransformationIn{inputs},
                                    [](const Vtransform_unit& t) -> std::vector<std::uint32_t> {
                                      return {t.rx, t.ry, t.rz};
                                    });
    case units::VectorUnit::kTraversal:
      return drive<Vtraversal_unit>(inputs.size(), n, options, TraversalIn{inputs},
                                    [](const Vtraversal_unit& t) -> std::vector<std::uint32_t> {
                                      return {t.go_near, t.go_far, t.near_tf, t.far_tn};
                                    });
  }
  throw std::runtime_error("rtl: unknown unit");
}

}  // namespace saarcor::rtl
