// The memory interface assembled (paper Fig. 2, section 3; docs/memif.md).
#include "memif/memory_system.h"

#include <cstdio>
#include <stdexcept>

namespace saarcor::memif {

MemorySystem::MemorySystem(hw::Kernel& kernel, MemoryImage& image, const MemorySystemConfig& config)
    : config_(config) {
  // Everything is checked before anything registers with the kernel: a refused configuration
  // leaves the kernel untouched.
  if (config.pipelines < 1) throw std::runtime_error("memory system: pipelines must be >= 1");
  MemoryController::check("mi.ctrl", config.controller);
  SimpleRouting::check("mi.routing", config.responses_per_cycle);
  HostBus::check("mi.host", config.host);
  for (int p = 0; p < config.pipelines; ++p) {
    for (int t = 0; t < kItemTypes; ++t) {
      const auto type = static_cast<ItemType>(t);
      const CacheConfig& c = t == 0   ? config.node_cache
                             : t == 1 ? config.list_cache
                                      : config.row_cache;
      Cache::check("dynrtp" + std::to_string(p) + "." + item_type_name(type) + "_cache", c,
                   image.item_words(type));
    }
  }
  controller_ = std::make_unique<MemoryController>(kernel, "mi.ctrl", image, config.controller);
  // The caches' port answers as many responses per cycle as the routing broadcasts.
  MemoryController::Port& cache_port =
      controller_->add_port("mi.ctrl.caches", config.responses_per_cycle);
  routing_ =
      std::make_unique<SimpleRouting>(kernel, "mi.routing", cache_port, config.responses_per_cycle);
  pipes_.resize(static_cast<std::size_t>(config.pipelines));
  const CacheConfig* cfg[kItemTypes] = {&config.node_cache, &config.list_cache, &config.row_cache};
  for (int p = 0; p < config.pipelines; ++p) {
    Pipeline& pipe = pipes_[static_cast<std::size_t>(p)];
    const std::string prefix = "dynrtp" + std::to_string(p) + ".";
    for (int t = 0; t < kItemTypes; ++t) {
      const auto type = static_cast<ItemType>(t);
      const std::string name = prefix + item_type_name(type) + "_cache";
      const std::uint16_t client = controller_->add_client(name);
      if (client != cache_client(p, type))
        throw std::logic_error("memory system: " + name + " is client " + std::to_string(client) +
                               ", not " + std::to_string(cache_client(p, type)));
      pipe.caches[t] = std::make_unique<Cache>(kernel, name, type, image, client, *cfg[t]);
      routing_->add_client(client, pipe.caches[t]->memory_requests(), pipe.caches[t]->fills());
    }
    pipe.shading_client = controller_->add_client(prefix + "shading");
    pipe.shading = &controller_->add_port(prefix + "shading");
    pipe.frame_client = controller_->add_client(prefix + "frame");
    pipe.frame = &controller_->add_port(prefix + "frame");
  }
  host_ = std::make_unique<HostBus>(kernel, "mi.host", *controller_, config.host);
}

const MemorySystem::Pipeline& MemorySystem::at(int p) const {
  if (p < 0 || p >= config_.pipelines) {
    throw std::out_of_range("memory system: no pipeline " + std::to_string(p));
  }
  return pipes_[static_cast<std::size_t>(p)];
}

Cache& MemorySystem::cache(int pipeline, ItemType type) {
  return *at(pipeline).caches[static_cast<int>(type)];
}
MemoryController::Port& MemorySystem::shading_port(int pipeline) {
  return *at(pipeline).shading;
}
MemoryController::Port& MemorySystem::frame_port(int pipeline) {
  return *at(pipeline).frame;
}
std::uint16_t MemorySystem::shading_client(int pipeline) const {
  return at(pipeline).shading_client;
}
std::uint16_t MemorySystem::frame_client(int pipeline) const {
  return at(pipeline).frame_client;
}

void MemorySystem::add_lanes(int pipeline) {
  if (config_.pipelines != 1) {
    throw std::logic_error("memory system: lanes need the shading and frame banks to one DynRTP");
  }
  controller_->add_lane(shading_port(pipeline), true);
  controller_->add_lane(frame_port(pipeline), false);
}

bool MemorySystem::idle() const {
  if (!controller_->idle() || !host_->idle()) return false;
  for (const Pipeline& p : pipes_) {
    for (const auto& c : p.caches) {
      if (!c->idle()) return false;
    }
  }
  return true;
}

bool MemorySystem::frame_writes_stored() const {
  for (const Pipeline& p : pipes_)
    if (!controller_->port_idle(*p.frame)) return false;
  return true;
}

void MemorySystem::invalidate_caches() {
  for (Pipeline& p : pipes_) {
    for (auto& c : p.caches)
      c->invalidate();
  }
}

std::string MemorySystem::bandwidth_report(std::uint64_t cycles) const {
  std::string out;
  for (int c = 0; c < controller_->clients(); ++c) {
    const auto id = static_cast<std::uint16_t>(c);
    char line[160];
    std::snprintf(line, sizeof line, "%-24s %12llu B %10.3f MB/s\n",
                  controller_->client_name(id).c_str(),
                  static_cast<unsigned long long>(controller_->client_bytes(id)),
                  controller_->client_mb_per_s(id, cycles));
    out += line;
  }
  return out;
}

}  // namespace saarcor::memif
