// The DynRTP assembled for the cycle model (paper section 3.1, Figure 2 paths a-g;
// docs/cycle-model.md and docs/memif.md; docs/cycle-model.md): Figure 2's units with their input
// priorities, the paths between every two units, and the memory system's parameters.
// testbench/chip.cpp instantiates the chip from it and clocks it.
#include "units/dynrtp.h"

#include <stdexcept>
#include <string>

#include "hw/kernel.h"
#include "memif/memory_system.h"
#include "units/dynrtc_units.h"

namespace saarcor::units {
namespace {

// The paths of Figure 2 by (from, to); the other hand-overs of the thread program (a unit's own
// loop, list -> traversal when a leaf's list ends, ...) get descriptive names.
std::string path_name(UnitId from, UnitId to) {
  struct P {
    UnitId from, to;
    const char* name;
  };
  static constexpr P kPaths[] = {{UnitId::kRgs, UnitId::kTransformation, "path_a"},
                                 {UnitId::kTransformation, UnitId::kTraversal, "path_b"},
                                 {UnitId::kTraversal, UnitId::kList, "path_c"},
                                 {UnitId::kList, UnitId::kTransformation, "path_d"},
                                 {UnitId::kTransformation, UnitId::kIntersection, "path_e"},
                                 {UnitId::kIntersection, UnitId::kTraversal, "path_f"},
                                 {UnitId::kTraversal, UnitId::kRgs, "path_g"}};
  for (const P& p : kPaths)
    if (p.from == from && p.to == to) return p.name;
  if (from == to) return std::string(unit_name(from)) + "_loop";
  return std::string(unit_name(from)) + "_to_" + unit_name(to);
}

}  // namespace

FunctionalParams functional_params(const CycleParams& p, FunctionalParams shading) {
  shading.packet = p.packet;
  shading.stack_depth = p.stack;
  shading.mailbox = p.mailbox;
  shading.triangle_mailbox = p.triangle_mailbox;
  shading.clip_exit_only = p.clip_exit_only;
  shading.skip_empty = p.skip_empty;
  shading.clip_faces_per_step = p.clip_faces_per_step;
  shading.shared_origin = p.shared_origin;
  return shading;
}

namespace {

// Figure 2's units, each over its pipeline's cache (the RGS over its memory ports).
CycleUnit& make_rgs(const UnitContext& c) {
  const int pipe = c.pipeline;
  // With one DynRTP its RGS alone reads the shading bank and writes the frame buffer: its ports
  // are the controller's lanes, served in closed form (docs/memif.md "Lanes"; same cycles and
  // statistics as through the channels).
  if (c.params.pipelines == 1) {
    c.memory.add_lanes(pipe);
  }
  const RgsPorts ports{&c.memory.shading_port(pipe), &c.memory.frame_port(pipe),
                       c.memory.shading_client(pipe), c.memory.frame_client(pipe),
                       c.params.pipelines == 1 ? c.memory.controller().lane_window() : 0};
  return c.kernel.make<RaySource>(c.name, c.threads, c.params.rgs_depth, c.rgc, pipe,
                                  static_cast<ThreadToken>(pipe * c.params.threads),
                                  c.params.threads, ports);
}
CycleUnit& make_traversal(const UnitContext& c) {
  return c.kernel.make<TraversalUnit>(c.name, c.threads, c.params.traversal_depth(),
                                      c.memory.cache(c.pipeline, memif::ItemType::kNode));
}
CycleUnit& make_list(const UnitContext& c) {
  return c.kernel.make<ListUnit>(c.name, c.threads, c.params.list_depth(),
                                 c.memory.cache(c.pipeline, memif::ItemType::kList));
}
CycleUnit& make_transformation(const UnitContext& c) {
  return c.kernel.make<TransformationUnit>(c.name, c.threads, c.params.transformation_depth(),
                                           c.memory.cache(c.pipeline, memif::ItemType::kRow));
}
CycleUnit& make_intersection(const UnitContext& c) {
  return c.kernel.make<IntersectionUnit>(c.name, c.threads, c.params.intersection_depth());
}

}  // namespace

// Input priorities (D25): in-flight work before new rays; a unit's own loop first. Only the
// hand-overs the thread program can make are listed.
std::vector<UnitSpec> dynrtc_units() {
  using U = UnitId;
  return {
      // The RGS: g, the end of a list or an intersection, shadow-ray generation.
      {U::kRgs, {U::kTraversal, U::kList, U::kIntersection, U::kTransformation, U::kRgs}, make_rgs},
      // Traversal: loop (next node, pop), f, end of a leaf's list, shadow rays, b.
      {U::kTraversal,
       {U::kTraversal, U::kIntersection, U::kList, U::kRgs, U::kTransformation},
       make_traversal},
      // List: loop (mailbox skip), after an intersection, c.
      {U::kList, {U::kList, U::kIntersection, U::kTraversal}, make_list},
      // Transformation: d before a (D25).
      {U::kTransformation, {U::kList, U::kRgs}, make_transformation},
      // Intersection: e.
      {U::kIntersection, {U::kTransformation}, make_intersection},
  };
}

// The units in the order given, then the paths between every two (by unit id), then each unit's
// inputs in its priority order. Thread-id queues hold every thread of the pipeline: a full path can
// never hold a unit (deadlock freedom by construction); the priorities decide only the order.
DynRtp::DynRtp(hw::Kernel& k, memif::MemorySystem& mi, const CycleParams& p, ThreadTable& threads,
               RayGenerationController& rgc, int pipeline, const std::vector<UnitSpec>& units) {
  const std::string pre = "dynrtp" + std::to_string(pipeline) + ".";
  std::array<const UnitSpec*, kMaxUnits> spec{};
  for (const UnitSpec& s : units) {
    const auto i = static_cast<std::size_t>(unit_index(s.id));
    if (s.id == UnitId::kNone || i >= spec.size() || spec[i] != nullptr)
      throw std::logic_error("DynRTP: unit id " + std::to_string(i) + " is kNone or given twice");
    spec[i] = &s;
    units_[i] = &s.make({k, mi, p, threads, rgc, pipeline, pre + unit_name(s.id)});
  }
  rgs_ = dynamic_cast<RaySource*>(units_[static_cast<std::size_t>(unit_index(UnitId::kRgs))]);
  if (rgs_ == nullptr) throw std::logic_error("DynRTP: no ray source (UnitId::kRgs)");
  const int capacity = p.threads + 1;
  for (std::size_t from = 0; from < spec.size(); ++from)
    for (std::size_t to = 0; to < spec.size(); ++to) {
      if (spec[from] == nullptr || spec[to] == nullptr) continue;
      const UnitId f = spec[from]->id, t = spec[to]->id;
      paths_[from][to] = &k.make_channel<ThreadToken>(pre + path_name(f, t), capacity, 1);
      units_[from]->set_output(t, paths_[from][to]);
    }
  for (std::size_t to = 0; to < spec.size(); ++to)
    if (spec[to] != nullptr)
      for (UnitId from : spec[to]->inputs)
        units_[to]->add_input(paths_[static_cast<std::size_t>(unit_index(from))][to]);
}

// The CycleParams as the memory system's parameters (every memif knob of the table).
memif::MemorySystemConfig memory_system_config(const CycleParams& p) {
  memif::MemorySystemConfig mc;
  mc.pipelines = p.pipelines;
  memif::CacheConfig* caches[kCacheUnits] = {&mc.node_cache, &mc.list_cache, &mc.row_cache};
  for (int c = 0; c < kCacheUnits; ++c) {
    memif::CacheConfig& cc = *caches[c];
    cc.items = p.cache[c].items;
    cc.ways = p.cache[c].ways;
    cc.hit_latency = p.cache_hit_latency;
    cc.max_misses = p.cache_misses;
    cc.max_targets = p.cache_merge_targets;
    cc.request_capacity = p.cache_request_queue;
    cc.memory_capacity = p.cache_memory_queue;
  }
  mc.controller.queue_depth = p.mem_queue_depth;
  mc.controller.latency = p.mem_latency;
  mc.controller.switch_penalty = p.mem_switch_penalty;
  mc.controller.max_burst = p.mem_max_burst;
  mc.controller.reorder = p.mem_reorder;
  if (p.mem_scene_paths == 3) mc.controller.bank_path = {0, 1, 2, 3, 4, 5};
  mc.controller.port_capacity = p.mem_port_capacity;
  mc.controller.clock_hz = p.clock_mhz * 1e6;
  mc.responses_per_cycle = p.routing_responses;
  mc.host.mb_per_s = p.hostbus_mb_s;
  mc.host.burst_words = p.hostbus_burst_words;
  mc.host.clock_hz = p.clock_mhz * 1e6;
  return mc;
}

const char* program_mode_name(ProgramMode m) {
  switch (m) {
    case ProgramMode::kPerStep:
      return "per-step";
    case ProgramMode::kPacketFirst:
      return "packet-first";
    case ProgramMode::kAhead:
      return "ahead";
  }
  return "?";
}

}  // namespace saarcor::units
