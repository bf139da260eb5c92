// Per-type item cache (paper section 3, Table 2; docs/memif.md; decision D20).
#include "memif/cache.h"

#include <algorithm>
#include <bit>
#include <sstream>
#include <stdexcept>

namespace saarcor::memif {

// Checked before the module registers with the kernel (a refused configuration leaves nothing
// behind).
std::string Cache::check(std::string name, const CacheConfig& config, int words) {
  auto bad = [&](const std::string& what) {
    throw std::runtime_error("cache '" + name + "': " + what);
  };
  if (config.items < 1) bad("items must be >= 1");
  if (config.ways < 1 || config.items % config.ways != 0) {
    bad("ways must divide items (" + std::to_string(config.items) + " items, " +
        std::to_string(config.ways) + " ways)");
  }
  if (config.hit_latency < 2) bad("hit_latency must be >= 2 (one cycle in, one out)");
  if (config.max_misses < 1) bad("max_misses must be >= 1");
  if (config.max_targets < 1) bad("max_targets must be >= 1");
  if (config.request_capacity < 1) bad("request_capacity must be >= 1");
  if (config.memory_capacity < 1) bad("memory_capacity must be >= 1");
  if (config.ports < 1) bad("ports must be >= 1");
  if (words > kMaxRequestWords) {
    bad("items wider than " + std::to_string(kMaxRequestWords) + " words");
  }
  return name;
}

Cache::Cache(hw::Kernel& kernel, std::string name, ItemType type, const MemoryImage& image,
             std::uint16_t client, CacheConfig config)
    : hw::Module(kernel, check(std::move(name), config, image.item_words(type))),
      request0_(nullptr),
      one_port_(config.ports == 1),
      ways_(config.ways),
      sets_(config.ways > 0 ? config.items / config.ways : 0),
      words_(image.item_words(type)),
      filled_(config.max_misses),
      fills_(kernel, this->name() + ".fill", std::max(1, config.memory_capacity), 1),
      type_(type),
      image_(image),
      client_(client),
      config_(config),
      mem_requests_(kernel, this->name() + ".mem_req", std::max(1, config.memory_capacity), 1) {
  for (int p = 0; p < config.ports; ++p) {
    const std::string suffix = config.ports == 1 ? "" : std::to_string(p);
    requests_.push_back(std::make_unique<hw::Channel<CacheRequest>>(
        kernel, this->name() + ".req" + suffix, config.request_capacity, 1));
    responses_.push_back(std::make_unique<hw::Channel<CacheResponse>>(
        kernel, this->name() + ".resp" + suffix, config.hit_latency + 2, config.hit_latency - 1));
  }
  request0_ = requests_[0].get();
  // Event scheduling: the cache depends only on its channels (it has no timers).
  sleep_when_idle();
  for (int p = 0; p < config.ports; ++p) {
    consumes(*requests_[static_cast<std::size_t>(p)]);
    produces(*responses_[static_cast<std::size_t>(p)]);
  }
  produces(mem_requests_);
  consumes(fills_);
  if ((sets_ & (sets_ - 1)) == 0) set_mask_ = static_cast<std::uint32_t>(sets_ - 1);
  lines_.resize(static_cast<std::size_t>(config.items));
  if (ways_ > 1) lru_.resize(static_cast<std::size_t>(config.items));
  mshrs_.resize(static_cast<std::size_t>(config.max_misses));
  for (Mshr& m : mshrs_)
    m.targets = hw::Ring<Mshr::Target>(config.max_targets);
  free_mshrs_.assign((mshrs_.size() + 63) / 64, 0);
  for (std::size_t i = 0; i < mshrs_.size(); ++i)
    free_mshrs_[i / 64] |= std::uint64_t{1} << (i % 64);
  hw::Stats& s = stats();
  const std::string& n = this->name();
  requests_stat_ = &s.counter(n + ".requests", "requests", "item requests accepted");
  hits_ = &s.counter(n + ".hits", "requests", "requests served from a present line");
  misses_ = &s.counter(n + ".misses", "requests", "requests that allocated a line and fetched it");
  merges_ = &s.counter(n + ".merges", "requests",
                       "requests merged into an outstanding miss of the same item");
  const hw::Counter *req = requests_stat_, *hit = hits_, *merge = merges_;
  s.formula(n + ".hit_rate", "ratio", "hits / requests",
            [req, hit] { return hw::ratio(hit->value, req->value); });
  s.formula(n + ".hit_rate_with_merges", "ratio",
            "(hits + merges) / requests: the hit rate of a blocking cache",
            [req, hit, merge] { return hw::ratio(hit->value + merge->value, req->value); });
}

void Cache::invalidate() {
  for (Line& l : lines_) {
    if (l.state >= 0) mshrs_[static_cast<std::size_t>(l.state)].line = -1;
    l = Line{};
  }
  std::fill(lru_.begin(), lru_.end(), 0);
}

bool Cache::idle() const {
  if (!mem_requests_.empty() || !fills_.empty()) return false;
  for (std::size_t p = 0; p < requests_.size(); ++p) {
    if (!requests_[p]->empty() || !responses_[p]->empty()) return false;
  }
  for (const Mshr& m : mshrs_) {
    if (m.busy) return false;
  }
  return true;
}

int Cache::evaluate() {
  // A fill is written into its line and may answer its first waiting request in the same cycle
  // (bypass); that delivery takes the response port, so a hit waits a cycle.
  // (Each stage is entered only when it has something to do.)
  int progress = fills_.can_pop() ? accept_fill() : 0;
  const int delivered = filled_.empty() ? 0 : deliver();
  progress += delivered;
  progress += lookup(delivered == 0);
  return progress;
}

int Cache::deliver() {
  if (filled_.empty()) return 0;
  const int id = filled_.front();
  Mshr& m = mshrs_[static_cast<std::size_t>(id)];
  const Mshr::Target& t = m.targets.front();
  hw::Channel<CacheResponse>& out = *responses_[static_cast<std::size_t>(t.port)];
  if (!out.can_push()) {
    stall();
    return 0;
  }
  CacheResponse& r = out.push_slot();
  r.index = m.item;
  r.label = t.label;
  r.words = m.words;
  r.count = words_;
  m.targets.pop_front();
  if (m.targets.empty()) {
    m.busy = false;
    free_mshrs_[static_cast<std::size_t>(id) / 64] |= std::uint64_t{1} << (id % 64);
    filled_.pop_front();
  }
  return 1;
}

// The lookup stage as a script: pick a request (round robin among ports), find its item in its
// set, then hit, merge into the pending fill, or miss; an accepted request leaves its channel.
int Cache::lookup(bool port_free) {
  const int port = one_port_ ? (request0_->can_pop() ? 0 : -1) : next_request_port();
  if (port < 0) return 0;
  hw::Channel<CacheRequest>& in =
      one_port_ ? *request0_ : *requests_[static_cast<std::size_t>(port)];
  const CacheRequest& req = in.peek();
  const std::uint32_t index = req.index;
  const std::size_t set =
      set_mask_ != 0 || sets_ == 1 ? index & set_mask_ : index % static_cast<std::uint32_t>(sets_);
  const std::size_t first = set * static_cast<std::size_t>(ways_);
  const std::size_t end = first + static_cast<std::size_t>(ways_);
  std::size_t li = first;
  while (li < end && (lines_[li].item != index || lines_[li].state == kEmpty))
    ++li;
  int done;
  if (li == end) {
    done = miss(req, port, first);
  } else if (lines_[li].state == kValid) {
    done = hit(req, port, li, port_free);
  } else {
    done = merge(req, port, li);
  }
  if (done == 0) {
    stall();
    return 0;
  }
  if (accept_log_) accept_log_->push_back(index);
  ++*requests_stat_;
  if (!one_port_) next_port_ = port + 1 == static_cast<int>(requests_.size()) ? 0 : port + 1;
  in.drop();  // last: `req` refers to the channel's slot
  return 1;
}

// The first port from next_port_ on with a request, or -1.
int Cache::next_request_port() const {
  const int ports = static_cast<int>(requests_.size());
  for (int k = 0; k < ports; ++k) {
    const int p = (next_port_ + k) % ports;
    if (requests_[static_cast<std::size_t>(p)]->can_pop()) return p;
  }
  return -1;
}

// A present line answers through the port's response channel, if the port is free this cycle.
int Cache::hit(const CacheRequest& req, int port, std::size_t li, bool port_free) {
  hw::Channel<CacheResponse>& out = *responses_[static_cast<std::size_t>(port)];
  if (!port_free || !out.can_push()) return 0;
  CacheResponse& r = out.push_slot();
  r.index = req.index;
  r.label = req.label;
  r.words = lines_[li].words;
  r.count = words_;
  if (ways_ > 1) lru_[li] = ++use_clock_;
  ++*hits_;
  if (observer_ != nullptr) [[unlikely]]
    observer_->hit(now(), *this, req);
  return 1;
}

// A secondary miss waits with the MSHR whose fill is on its way (a full MSHR holds the cache).
int Cache::merge(const CacheRequest& req, int port, std::size_t li) {
  Mshr& m = mshrs_[static_cast<std::size_t>(lines_[li].state)];
  if (static_cast<int>(m.targets.size()) >= config_.max_targets) return 0;
  Mshr::Target& target = m.targets.push_slot();
  target.label = req.label;
  target.port = port;
  if (ways_ > 1) lru_[li] = ++use_clock_;
  ++*merges_;
  if (observer_ != nullptr) [[unlikely]]
    observer_->merged(now(), *this, req, lines_[li].state);
  return 1;
}

// A miss needs a free MSHR (the lowest numbered) and room towards memory; it allocates a victim
// line of the set and sends one memory request for the item.
int Cache::miss(const CacheRequest& req, int port, std::size_t first) {
  int id = -1;
  for (std::size_t w = 0; w < free_mshrs_.size(); ++w) {
    if (free_mshrs_[w] != 0) {
      id = static_cast<int>(w * 64) + std::countr_zero(free_mshrs_[w]);
      break;
    }
  }
  if (id < 0 || !mem_requests_.can_push()) return 0;
  const std::size_t victim = allocate(first, req.index, id);
  Mshr& m = mshrs_[static_cast<std::size_t>(id)];
  m.busy = true;
  m.filled = false;
  m.item = req.index;
  m.line = static_cast<int>(victim);
  m.targets.clear();
  Mshr::Target& target = m.targets.push_slot();
  target.label = req.label;
  target.port = port;
  free_mshrs_[static_cast<std::size_t>(id) / 64] &= ~(std::uint64_t{1} << (id % 64));
  const WordLocation loc = image_.locate(type_, req.index, 0);
  MemRequest& mr = mem_requests_.push_slot();  // the cache's own channel: written in place
  mr.client = client_;
  mr.tag = static_cast<std::uint32_t>(id);
  mr.bank = static_cast<std::uint8_t>(loc.bank);
  mr.words = static_cast<std::uint8_t>(words_);
  mr.write = false;
  mr.counted_bytes = 0;
  mr.offset = loc.offset;
  ++*misses_;
  if (observer_ != nullptr) [[unlikely]]
    observer_->miss(now(), *this, req.index, id, req.label);
  return 1;
}

// The victim of the set starting at `first`: the first empty way, else the least recently used
// one (one way: that one). It now waits for MSHR `id`'s fill of `item`; a fill still on its way
// into it is no longer kept.
std::size_t Cache::allocate(std::size_t first, std::uint32_t item, int id) {
  std::size_t victim = first;
  if (ways_ > 1) {
    const std::size_t end = first + static_cast<std::size_t>(ways_);
    for (std::size_t w = first; w < end; ++w) {
      if (lines_[w].state == kEmpty) {
        victim = w;
        break;
      }
      if (lru_[w] < lru_[victim]) victim = w;
    }
    lru_[victim] = ++use_clock_;
  }
  Line& l = lines_[victim];
  if (l.state >= 0) mshrs_[static_cast<std::size_t>(l.state)].line = -1;
  l.item = item;
  l.state = id;
  return victim;
}

int Cache::accept_fill() {
  if (!fills_.can_pop()) return 0;
  const MemResponse& f = fills_.peek();
  if (f.tag >= mshrs_.size() || !mshrs_[f.tag].busy || mshrs_[f.tag].filled || f.count != words_) {
    throw std::logic_error("cache '" + name() + "': fill for MSHR " + std::to_string(f.tag) +
                           " that is not waiting for one");
  }
  Mshr& m = mshrs_[f.tag];
  m.filled = true;
  m.words = f.words;
  if (m.line >= 0) {
    const auto line = static_cast<std::size_t>(m.line);
    lines_[line].state = kValid;
    lines_[line].words = f.words;
  }
  filled_.push_back(static_cast<int>(f.tag));
  if (observer_ != nullptr) [[unlikely]]
    observer_->filled(now(), *this, static_cast<int>(f.tag));
  fills_.drop();  // last: `f` refers to the channel's slot
  return 1;
}

std::string Cache::dump_state() const {
  std::ostringstream os;
  int busy = 0;
  for (const Mshr& m : mshrs_)
    busy += m.busy;
  os << item_type_name(type_) << " cache: " << busy << "/" << mshrs_.size()
     << " misses outstanding, " << filled_.size() << " filled awaiting delivery";
  for (std::size_t i = 0; i < mshrs_.size(); ++i) {
    const Mshr& m = mshrs_[i];
    if (!m.busy) continue;
    os << "; mshr" << i << " item " << m.item << (m.filled ? " filled" : " waiting for memory")
       << ", " << m.targets.size() << " requests (first tag " << m.targets.front().label.tag << ")";
  }
  return os.str();
}

}  // namespace saarcor::memif
