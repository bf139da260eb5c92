// The memory interface (MI) assembled (paper Fig. 2 and section 3; docs/memif.md;
// decisions D23, D44): per DynRTP three caches (kd-nodes, lists, matrix rows) behind one simple
// routing shared by all DynRTPs; per DynRTP an uncached shading port and a frame-buffer port;
// one host bus; one memory controller over the six SRAM banks of a MemoryImage.
//
// This is what the DynRTC cycle model instantiates. A unit uses only its cache's two channels:
//   Cache& c = mi.cache(p, ItemType::kNode);
//   if (c.requests().can_push()) c.requests().push({index, {unit_id, thread}});
//   if (c.responses().can_pop()) { CacheResponse r = c.responses().pop(); ... r.label.tag ... }
// The RGS uses shading_port(p) / frame_port(p) directly with MemRequests labelled by
// shading_client(p) / frame_client(p) (reads answered on the port's response channel in the
// order issued per bank; writes unanswered).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "memif/cache.h"
#include "memif/config.h"
#include "memif/host_bus.h"
#include "memif/memory_controller.h"
#include "memif/routing.h"

namespace saarcor::memif {

class MemorySystem {
 public:
  // Names: "mi.ctrl", "mi.routing", "mi.host", "dynrtp<p>.<type>_cache", "dynrtp<p>.shading",
  // "dynrtp<p>.frame". Throws std::runtime_error for a bad configuration.
  MemorySystem(hw::Kernel& kernel, MemoryImage& image, const MemorySystemConfig& config = {});

  Cache& cache(int pipeline, ItemType type);
  // The controller client id of a pipeline's cache: each pipeline adds its three caches, its
  // shading and its frame client in that order (the routing's labels; an RTL routing is
  // configured with them).
  static std::uint16_t cache_client(int pipeline, ItemType type) {
    return static_cast<std::uint16_t>(pipeline * (kItemTypes + 2) + static_cast<int>(type));
  }
  MemoryController::Port& shading_port(int pipeline);
  MemoryController::Port& frame_port(int pipeline);
  std::uint16_t shading_client(int pipeline) const;
  std::uint16_t frame_client(int pipeline) const;
  // Serves the pipeline's shading port (reads of the shading bank) and frame port (writes of the
  // frame-buffer bank) as the controller's lanes (docs/memif.md "Lanes"): only where no other
  // port reaches those banks, i.e. with one DynRTP (several share the shading bank).
  void add_lanes(int pipeline);
  MemoryController& controller() { return *controller_; }
  SimpleRouting& routing() { return *routing_; }
  HostBus& host() { return *host_; }
  int pipelines() const { return config_.pipelines; }

  // No miss outstanding, nothing queued in the controller or in any memif channel (responses
  // included: a response the unit has not popped yet counts as work), nothing left to upload.
  bool idle() const;
  // Every DynRTP's frame-buffer writes stored (the end of a frame; a host upload may go on).
  bool frame_writes_stored() const;
  // Invalidates every cache (frame start, after an upload; D20).
  void invalidate_caches();
  // Bandwidth report: one line per client, "name bytes MB/s", at the modelled clock over
  // `cycles` cycles.
  std::string bandwidth_report(std::uint64_t cycles) const;

 private:
  struct Pipeline {
    std::unique_ptr<Cache> caches[kItemTypes];
    MemoryController::Port* shading = nullptr;
    MemoryController::Port* frame = nullptr;
    std::uint16_t shading_client = 0, frame_client = 0;
  };
  const Pipeline& at(int p) const;

  MemorySystemConfig config_;
  std::unique_ptr<MemoryController> controller_;
  std::unique_ptr<SimpleRouting> routing_;
  std::unique_ptr<HostBus> host_;
  std::vector<Pipeline> pipes_;
};

}  // namespace saarcor::memif
