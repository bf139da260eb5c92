// The memory controller and SRAM banks (paper section 3, docs/memif.md, decisions D21/D23).
#include "memif/memory_controller.h"

#include <algorithm>
#include <bit>
#include <sstream>
#include <stdexcept>

namespace saarcor::memif {

// Checked before the module registers with the kernel, so a refused configuration leaves no
// half-built module behind.
std::string MemoryController::check(std::string name, const MemoryControllerConfig& c) {
  auto bad = [&](const std::string& what) {
    throw std::runtime_error("memory controller '" + name + "': " + what);
  };
  if (c.queue_depth < 1) bad("queue_depth must be >= 1");
  if (c.latency < 1) bad("latency must be >= 1");
  if (c.switch_penalty < 0) bad("switch_penalty must be >= 0");
  if (c.max_burst < 1) bad("max_burst must be >= 1");
  if (c.port_capacity < 2) bad("port_capacity must be >= 2");
  if (!(c.clock_hz > 0)) bad("clock_hz must be > 0");
  if (static_cast<int>(c.bank_path.size()) != kNumBanks) {
    bad("bank_path needs one entry per bank (" + std::to_string(kNumBanks) + ")");
  }
  for (int p : c.bank_path) {
    if (p < 0 || p >= kNumBanks)
      bad("bank_path entries must be 0.." + std::to_string(kNumBanks - 1));
  }
  return name;
}

MemoryController::MemoryController(hw::Kernel& kernel, std::string name, MemoryImage& image,
                                   MemoryControllerConfig config)
    : hw::Module(kernel, check(std::move(name), config)),
      image_(image),
      config_(std::move(config)),
      banks_(kNumBanks),
      inflight_limit_(config_.latency + 2) {
  due_.fill(hw::kNever);
  sleep_when_idle();  // its timers are in next_wakeup, its inputs are its ports
  hw::Stats& s = stats();
  const std::string& n = this->name();
  for (int b = 0; b < kNumBanks; ++b) {
    const int p = config_.bank_path[static_cast<std::size_t>(b)];
    if (static_cast<int>(paths_.size()) <= p) paths_.resize(static_cast<std::size_t>(p) + 1);
    paths_[static_cast<std::size_t>(p)].banks |= 1u << b;
    path_bit_[static_cast<std::size_t>(b)] = 1u << p;
    const std::string bn = n + ".bank" + std::to_string(b);
    Bank& bank = banks_[static_cast<std::size_t>(b)];
    bank.queue = hw::Ring<Queued>(config_.queue_depth);
    bank.inflight = hw::Ring<InFlight>(inflight_limit_);
    bank.reads = &s.counter(bn + ".reads", "requests", "read requests started");
    bank.writes = &s.counter(bn + ".writes", "requests", "write requests started");
    bank.words = &s.counter(bn + ".busy_cycles", "cycles", "cycles transferring a word");
    bank.max_queue = &s.counter(bn + ".max_queue", "requests", "largest bank queue occupancy");
  }
  for (std::size_t p = 0; p < paths_.size(); ++p) {
    if (paths_[p].banks == 0) continue;
    paths_[p].switches = &s.counter(n + ".path" + std::to_string(p) + ".bank_switches", "events",
                                    "starts on a bank other than the path's open bank");
  }
}

// ---- Lanes (docs/memif.md "Lanes") ----------------------------------------------------------

// How far ahead of its push cycle a lane request's last step can lie: behind it at most the
// port's other entries, a full bank queue and the reads in flight, each starting at most a
// latency and a few cycles after the one before; then its own latency.
std::uint64_t MemoryController::lane_horizon() const {
  const auto lat = static_cast<std::uint64_t>(config_.latency);
  const std::uint64_t ahead = static_cast<std::uint64_t>(config_.port_capacity) +
                              static_cast<std::uint64_t>(config_.queue_depth) +
                              static_cast<std::uint64_t>(inflight_limit_) + 2;
  return ahead * (lat + 6) + lat + 8;
}

MemoryController::Lane& MemoryController::add_lane(Port& port, bool reads) {
  int index = -1;
  for (std::size_t p = 0; p < ports_.size(); ++p) {
    if (ports_[p].get() == &port) {
      index = static_cast<int>(p);
    }
  }
  if (index < 0 || port.lane != nullptr) {
    throw std::logic_error("memory controller '" + name() + "': no lane for port " + port.name);
  }
  lanes_.push_back(std::unique_ptr<Lane>(new Lane(*this, port, index, reads)));
  port.lane = lanes_.back().get();
  bound_idle_skip();
  lane_reach_ = lane_horizon();
  if (lane_busy_.empty()) {
    // Wide enough that a lane's pushes rarely have to book the past first (the controller's
    // own evaluations book it as they go).
    std::uint64_t window = 4096;
    while (window < 4 * lane_horizon()) {
      window *= 2;
    }
    lane_busy_ = hw::CycleMarks(window);
    lane_stall_ = hw::CycleMarks(window);
  }
  return *port.lane;
}

void MemoryController::close_lanes() {
  for (auto& l : lanes_) {
    if (l->state_ == Lane::State::kOpen) {
      throw std::logic_error("memory controller '" + name() + "': lane " + l->port_.name +
                             " closed after it served requests");
    }
    l->state_ = Lane::State::kClosed;
    l->port_.lane = nullptr;
  }
}

MemoryController::Lane::Lane(MemoryController& mc, Port& port, int port_index, bool reads)
    : mc_(mc),
      port_(port),
      port_index_(port_index),
      reads_(reads),
      cap_(static_cast<std::uint64_t>(mc.config_.port_capacity)),
      depth_(static_cast<std::uint64_t>(mc.config_.queue_depth)),
      limit_(static_cast<std::uint64_t>(mc.inflight_limit_)),
      latency_(static_cast<std::uint64_t>(mc.config_.latency)) {
  const MemoryControllerConfig& c = mc.config_;
  std::uint64_t n = 1;
  while (n < 4 * (static_cast<std::uint64_t>(c.port_capacity) +
                  static_cast<std::uint64_t>(c.queue_depth) +
                  static_cast<std::uint64_t>(mc.inflight_limit_) + 8)) {
    n *= 2;
  }
  items_.resize(n);
  item_mask_ = n - 1;
  std::uint64_t h = 1;
  while (h < static_cast<std::uint64_t>(
                 std::max({c.port_capacity, c.queue_depth, mc.inflight_limit_}) + 2)) {
    h *= 2;
  }
  hist_.resize(h);
  hist_mask_ = h - 1;
}

// The lane runs only where its closed form is the stepped model's: its bank alone on its issue
// path and idle, no other lane on it, the kernel skipping idle work (the reference evaluates
// every cycle), no VCD trace (it samples the channels every cycle), and a watchdog that no
// stretch of lane-only progress can reach (the kernel sees no progress in those cycles; a client
// planning ahead, as the RGS does up to 16 requests, stretches it to about as many horizons).
bool MemoryController::Lane::bind(const MemRequest& r) {
  hw::Kernel& k = mc_.kernel();
  const int b = r.bank;
  const std::uint64_t wd = k.config().watchdog_cycles;
  bool ok = b < kNumBanks && r.write != reads_ && k.config().idle_skip && !k.tracing() &&
            k.config().time_series_period == 0 && (wd == 0 || wd > 32 * mc_.lane_horizon());
  if (ok) {
    const Path& path =
        mc_.paths_[static_cast<std::size_t>(mc_.config_.bank_path[static_cast<std::size_t>(b)])];
    const Bank& bank = mc_.banks_[static_cast<std::size_t>(b)];
    ok = path.banks == (1u << b) && (mc_.lane_banks_ >> b & 1u) == 0 && bank.queue.empty() &&
         bank.inflight.empty() && port_.requests.empty() && port_.responses.empty();
  }
  if (!ok) {
    state_ = State::kClosed;
    port_.lane = nullptr;
    return false;
  }
  state_ = State::kOpen;
  bank_ = b;
  bank_words_ = mc_.image_.bank(b).size();
  client_count_ = mc_.clients_.size();
  mc_.lane_banks_ |= 1u << b;
  ++mc_.open_lanes_;
  mc_.intake_[static_cast<std::size_t>(port_index_)] = nullptr;
  bank_free_ = std::max(
      mc_.free_at_[static_cast<std::size_t>(b)],
      mc_.paths_[static_cast<std::size_t>(mc_.config_.bank_path[static_cast<std::size_t>(b)])]
          .free_at);
  return true;
}

// The unusual pushes: the lane's first (can it run?), and requests the lane cannot take (model
// errors), or whose cycles lie beyond its window (book the past first).
std::uint64_t MemoryController::Lane::push_unusual(const MemRequest& r, std::uint64_t t) {
  if (state_ == State::kUnbound) {
    if (!bind(r)) {
      port_.requests.push(r);
      return 0;
    }
    return push_at(r, t);
  }
  if (state_ != State::kOpen || r.words < 1 || r.words > kMaxRequestWords || r.bank != bank_ ||
      static_cast<std::uint64_t>(r.offset) + r.words > bank_words_ || r.client >= client_count_ ||
      r.write == reads_) {
    throw std::runtime_error("memory controller '" + mc_.name() + "': port " + port_.name +
                             " sent a request outside memory or its lane (bank " +
                             std::to_string(r.bank) + ", offset " + std::to_string(r.offset) +
                             ", " + std::to_string(r.words) + " words, client " +
                             std::to_string(r.client) + ")");
  }
  if (t < mc_.now() || t < next_push_) {
    throw std::logic_error("memory controller: lane " + port_.name + " pushed out of order");
  }
  if (reads_ && pushed_ - popped_ > item_mask_) {
    throw std::logic_error("memory controller: lane " + port_.name + " holds too many requests");
  }
  throw std::logic_error("memory controller: lane " + port_.name + " refused a request it takes");
}

void MemoryController::Lane::book_beyond_window(std::uint64_t last) {
  mc_.account_now();
  if (last - mc_.lane_from_ >= mc_.lane_busy_.window()) {
    throw std::logic_error("memory controller: lane " + port_.name + "'s cycle " +
                           std::to_string(last) + " beyond its window");
  }
}

// (Booked with the lane's other steps: the response is taken in the cycle after its retire.)
std::uint32_t MemoryController::Lane::pop() {
  return pop_through(1);
}

std::uint32_t MemoryController::Lane::pop_through(std::uint64_t count) {
  if (count == 0 || popped_ + count > pushed_ ||
      item(popped_ + count - 1).retire + 1 != mc_.now()) {
    throw std::logic_error("memory controller: lane " + port_.name +
                           "'s response not taken in the cycle it became visible");
  }
  popped_ += count;
  return item(popped_ - 1).tag;
}

bool MemoryController::Lane::idle() const {
  if (reads_) {
    return popped_ == pushed_;
  }
  return pushed_ == 0 || bank_free_ - last_words_ < mc_.now();
}

void MemoryController::Lane::settle() {
  const Booked b = booked_;
  if (b.requests == 0) {
    return;
  }
  booked_ = {};
  port_.requests.book_pushes(b.requests, b.push_cycles, b.most_in_channel);
  port_.requests.book_pops(b.requests, b.accept_cycles);
  Bank& bank = mc_.banks_[static_cast<std::size_t>(bank_)];
  bank.max_queue->set_max(b.most_queued);
  *bank.words += b.words;
  *(reads_ ? bank.reads : bank.writes) += b.requests;
  if (reads_) {
    port_.responses.book_pushes(b.requests, b.retire_cycles, 1);
    port_.responses.book_pops(b.requests, b.retire_cycles + b.requests);
  }
}

void MemoryController::mark_lane_stalls(std::uint64_t from, std::uint64_t to) {
  if (to - 1 - lane_from_ >= lane_stall_.window()) {
    throw std::logic_error("memory controller '" + name() + "': a lane's cycle " +
                           std::to_string(to - 1) + " beyond its window");
  }
  lane_stall_.mark(from, to);
}

// The lanes' steps in cycles [lane_from_, to) booked; the controller's busy and stall cycles
// among them counted, but those the kernel counts already (the evaluated cycle's own progress or
// stall, the repeats of a stalled evaluation).
void MemoryController::account_lanes(std::uint64_t to, bool busy_counted, bool stall_counted) {
  for (auto& l : lanes_) {
    if (l->state_ == Lane::State::kOpen) {
      l->settle();
    }
  }
  if (open_lanes_ != 0 && to > lane_from_) {
    const std::uint64_t busy = lane_busy_.take(lane_from_, to);
    const std::uint64_t stalls = lane_stall_.take(lane_from_, to);
    count_cycles(busy_counted ? 0 : busy, stall_counted ? 0 : stalls);
  }
  lane_from_ = to;
}

void MemoryController::skipped(std::uint64_t) {
  if (!lanes_.empty()) {
    account_lanes(now(), false, stalled());
  }
}

// The cycle after the lanes' next step: there the frame buffer's last write may have been
// stored (the run's end) without any module evaluated.
std::uint64_t MemoryController::skip_bound(std::uint64_t now) const {
  if (open_lanes_ == 0) {
    return hw::kNever;
  }
  const std::uint64_t c =
      lane_busy_.next(std::max(now, lane_from_), lane_from_ + lane_busy_.window());
  return c == hw::kNever ? hw::kNever : c + 1;
}

MemoryController::Port& MemoryController::add_port(const std::string& name, int response_width) {
  if (response_width < 1)
    throw std::runtime_error("memory controller '" + this->name() + "': port " + name +
                             " needs a response width >= 1");
  ports_.push_back(std::make_unique<Port>(kernel(), name, config_.port_capacity, response_width));
  consumes(ports_.back()->requests);
  intake_.push_back(&ports_.back()->requests);
  produces(ports_.back()->responses);
  return *ports_.back();
}

std::uint16_t MemoryController::add_client(const std::string& name) {
  if (clients_.size() >= 0xFFFF) throw std::runtime_error("memory controller: too many clients");
  const auto id = static_cast<std::uint16_t>(clients_.size());
  Client c;
  c.name = name;
  c.bytes = &stats().counter(name + ".mem_bytes", "bytes",
                             "external memory traffic of this client (reads and writes)");
  const double clock = config_.clock_hz;
  const hw::Counter* bytes = c.bytes;
  hw::Kernel* k = &kernel();
  stats().formula(name + ".mem_mb_per_s", "MB/s", "external memory bandwidth at the modelled clock",
                  [bytes, clock, k] { return hw::mb_per_s(bytes->value, k->now(), clock); });
  clients_.push_back(std::move(c));
  return id;
}

std::uint64_t MemoryController::client_bytes(std::uint16_t client) const {
  return clients_.at(client).bytes->value;
}

double MemoryController::client_mb_per_s(std::uint16_t client, std::uint64_t cycles) const {
  return hw::mb_per_s(client_bytes(client), cycles, config_.clock_hz);
}

const std::string& MemoryController::client_name(std::uint16_t client) const {
  return clients_.at(client).name;
}

std::uint64_t MemoryController::bank_switches() const {
  std::uint64_t n = 0;
  for (const Path& p : paths_) {
    if (p.switches) n += p.switches->value;
  }
  return n;
}

bool MemoryController::idle() const {
  if (queued_ != 0 || inflight_ != 0) return false;
  for (const auto& l : lanes_) {
    if (l->open() && !l->idle()) {
      return false;
    }
  }
  // (A lane's channels hold its booked steps only: its own idle() answers for its port.)
  for (const auto& p : ports_) {
    if (p->lane != nullptr && p->lane->open()) {
      continue;
    }
    if (!p->requests.empty() || !p->responses.empty()) return false;
  }
  return true;
}

bool MemoryController::port_idle(const Port& port) const {
  if (port.lane != nullptr && port.lane->open()) {
    return port.lane->idle();
  }
  if (!port.requests.empty() || !port.responses.empty()) return false;
  int index = -1;
  for (std::size_t p = 0; p < ports_.size(); ++p)
    if (ports_[p].get() == &port) index = static_cast<int>(p);
  for (const Bank& b : banks_) {
    for (std::size_t i = 0; i < b.queue.size(); ++i)
      if (b.queue[i].port == index) return false;
    for (std::size_t i = 0; i < b.inflight.size(); ++i)
      if (b.inflight[i].port == index) return false;
  }
  return true;
}

int MemoryController::evaluate() {
  // Back to front, like pipeline stages: each stage reads what the later one left last cycle.
  int progress = next_due_ <= now() ? retire_responses() : 0;
  progress += issue();
  progress += accept_requests();
  if (!lanes_.empty()) {
    account_lanes(now() + 1, progress > 0, stalled());
  }
  return progress;
}

// Completed reads leave towards their port, oldest due first; per port and cycle as many as its
// response channel is wide (one but for the routing's port with a wider broadcast).
int MemoryController::retire_responses() {
  int moved = 0;
  for (;;) {
    int best = -1;
    for (unsigned bits = inflight_; bits != 0; bits &= bits - 1) {
      const int b = std::countr_zero(bits);
      if (due_[static_cast<std::size_t>(b)] > now()) continue;
      const int port = banks_[static_cast<std::size_t>(b)].inflight.front().port;
      if (!ports_[static_cast<std::size_t>(port)]->responses.can_push()) continue;
      if (best < 0 || due_[static_cast<std::size_t>(b)] < due_[static_cast<std::size_t>(best)])
        best = b;
    }
    if (best < 0) break;
    Bank& bank = banks_[static_cast<std::size_t>(best)];
    Port& port = *ports_[static_cast<std::size_t>(bank.inflight.front().port)];
    port.responses.push_slot() = bank.inflight.front().resp;
    if (port.observer != nullptr) [[unlikely]]
      port.observer->responded(now(), bank.inflight.front().resp);
    bank.inflight.pop_front();
    if (bank.inflight.empty()) {
      inflight_ &= ~(1u << best);
      due_[static_cast<std::size_t>(best)] = hw::kNever;
    } else {
      due_[static_cast<std::size_t>(best)] = bank.inflight.front().due;
    }
    ++moved;
  }
  next_due_ = hw::kNever;
  for (unsigned bits = inflight_; bits != 0; bits &= bits - 1) {
    const std::uint64_t due = due_[static_cast<std::size_t>(std::countr_zero(bits))];
    next_due_ = std::min(next_due_, due);
    if (due <= now()) stall();  // port full
  }
  return moved;
}

void MemoryController::start(int b, std::uint64_t when) {
  Bank& bank = banks_[static_cast<std::size_t>(b)];
  const Queued& q = bank.queue.front();  // leaves the queue last: read in place
  const MemRequest& r = q.req;
  free_at_[static_cast<std::size_t>(b)] = when + r.words;
  *bank.words += r.words;
  *clients_[r.client].bytes += r.counted_bytes ? r.counted_bytes : 4u * r.words;
  // accept_requests checked the words are inside the bank.
  std::uint32_t* const mem = image_.bank(b).data() + r.offset;
  if (r.write) {
    ++*bank.writes;
    for (int i = 0; i < r.words; ++i)
      mem[i] = r.data[static_cast<std::size_t>(i)];
  } else {
    ++*bank.reads;
    const std::uint64_t due = when + r.words - 1 + static_cast<std::uint64_t>(config_.latency);
    if (bank.inflight.empty()) {
      inflight_ |= 1u << b;
      due_[static_cast<std::size_t>(b)] = due;
      next_due_ = std::min(next_due_, due);
    }
    // The read's words go into its return buffer entry as the bank delivers them; the entry's
    // words beyond the request are zero, as the response promises.
    InFlight& f = bank.inflight.push_slot();
    f.due = due;
    f.port = q.port;
    f.resp.client = r.client;
    f.resp.tag = r.tag;
    f.resp.count = r.words;
    for (int i = 0; i < kMaxRequestWords; ++i)
      f.resp.words[static_cast<std::size_t>(i)] = i < r.words ? mem[i] : 0u;
  }
  bank.queue.pop_front();
  if (bank.queue.empty())
    queued_ &= ~(1u << b);
  else
    oldest_[static_cast<std::size_t>(b)] = bank.queue.front().seq;
}

int MemoryController::issue() {
  if (queued_ == 0) return 0;
  // A path starts only a bank that has work and is free: the paths without one are not visited
  // (their cycle would choose nothing and change nothing).
  unsigned active = 0;  // the paths with a free queued bank, visited in path order
  for (unsigned bits = queued_; bits != 0; bits &= bits - 1) {
    const int b = std::countr_zero(bits);
    if (free_at_[static_cast<std::size_t>(b)] <= now())
      active |= path_bit_[static_cast<std::size_t>(b)];
  }
  int started = 0;
  for (; active != 0; active &= active - 1) {
    Path& path = paths_[static_cast<std::size_t>(std::countr_zero(active))];
    const unsigned waiting = path.banks & queued_;
    if (waiting == 0 || path.free_at > now()) continue;
    const int chosen = choose(path, waiting);
    if (chosen < 0) continue;
    std::uint64_t when = now();
    if (chosen != path.open) {
      if (path.open >= 0) {
        when += static_cast<std::uint64_t>(config_.switch_penalty);
        ++*path.switches;
      }
      path.open = chosen;
      path.burst = 0;
    }
    ++path.burst;
    path.free_at = when + 1;
    start(chosen, when);
    ++started;
  }
  return started;
}

// The bank a path with queued banks `waiting` starts this cycle, or -1 (the bank reordering of
// D23): with reorder, the open bank while it has work and the burst allows, else the free bank
// with the oldest request; without, the path's oldest request when its bank is free.
int MemoryController::choose(const Path& path, unsigned waiting) const {
  auto startable = [&](int b) {
    const Bank& bank = banks_[static_cast<std::size_t>(b)];
    return (queued_ >> b & 1u) != 0 && free_at_[static_cast<std::size_t>(b)] <= now() &&
           static_cast<int>(bank.inflight.size()) < inflight_limit_;
  };
  auto older = [&](int b, int than) {
    return than < 0 ||
           oldest_[static_cast<std::size_t>(b)] < oldest_[static_cast<std::size_t>(than)];
  };
  int oldest_any = -1, oldest_startable = -1, others_waiting = 0;
  for (unsigned bits = waiting; bits != 0; bits &= bits - 1) {
    const int b = std::countr_zero(bits);
    if (b != path.open) ++others_waiting;
    if (older(b, oldest_any)) oldest_any = b;
    if (startable(b) && older(b, oldest_startable)) oldest_startable = b;
  }
  if (!config_.reorder) return oldest_any >= 0 && startable(oldest_any) ? oldest_any : -1;
  // Stay on the open bank while it has work and the burst limit allows, waiting for it when it
  // becomes free no later than a switch would let another bank start: such a switch would be
  // needless. Otherwise switch to the free bank with the oldest request.
  const bool open_wanted = path.open >= 0 && (queued_ >> path.open & 1u) != 0 &&
                           (path.burst < config_.max_burst || others_waiting == 0);
  if (open_wanted && startable(path.open)) return path.open;
  if (open_wanted && free_at_[static_cast<std::size_t>(path.open)] <=
                         now() + static_cast<std::uint64_t>(config_.switch_penalty))
    return -1;  // wait for the open bank
  return oldest_startable;
}

// The port's front request, checked; null when the port has none (or is a lane's).
const MemRequest* MemoryController::front(std::size_t p) const {
  if (intake_[p] == nullptr || !intake_[p]->can_pop()) return nullptr;
  const MemRequest& r = intake_[p]->peek();
  if (r.bank >= kNumBanks || r.words < 1 || r.words > kMaxRequestWords ||
      static_cast<std::uint64_t>(r.offset) + r.words > image_.bank(r.bank).size() ||
      r.client >= clients_.size()) {
    throw std::runtime_error("memory controller '" + name() + "': port " + ports_[p]->name +
                             " sent a request outside memory (bank " + std::to_string(r.bank) +
                             ", offset " + std::to_string(r.offset) + ", " +
                             std::to_string(r.words) + " words, client " +
                             std::to_string(r.client) + ")");
  }
  if ((lane_banks_ >> r.bank & 1u) != 0) {
    throw std::logic_error("memory controller '" + name() + "': port " + ports_[p]->name +
                           " sent a request to bank " + std::to_string(r.bank) + ", a lane's own");
  }
  return &r;
}

// Moves port p's front request into its bank's queue (which has room).
void MemoryController::enqueue(std::size_t p, Bank& bank, int b) {
  hw::Channel<MemRequest>& in = *intake_[p];
  if (bank.queue.empty()) {
    queued_ |= 1u << b;
    oldest_[static_cast<std::size_t>(b)] = seq_;
  }
  Queued& q = bank.queue.push_slot();  // the request is written into its queue entry
  q.req = in.peek();
  q.port = static_cast<int>(p);
  q.seq = seq_++;
  in.drop();  // last: the request lived in the channel's slot
  bank.max_queue->set_max(bank.queue.size());
}

int MemoryController::accept_requests() {
  // Ports whose banks have room for every port that wants them move in, in port order. Where more
  // ports want a bank than its queue has room for, the bank's round-robin pointer decides: the
  // first from it take the places and the pointer moves past the last that did, so each waits at
  // most one turn of the others (D55). Taken in port order every time, three DynRTPs' frame-buffer
  // writers starved the third for 230,000 cycles of a 1.2 M-cycle frame while the other two kept
  // the frame bank's queue full.
  const std::size_t n = intake_.size();
  fronts_.resize(n);  // each port's front request, checked once a cycle
  std::array<int, kNumBanks> want{};
  for (std::size_t p = 0; p < n; ++p)
    if ((fronts_[p] = front(p)) != nullptr) ++want[fronts_[p]->bank];
  unsigned contended = 0;
  for (int b = 0; b < kNumBanks; ++b)
    if (want[static_cast<std::size_t>(b)] >
        config_.queue_depth - static_cast<int>(banks_[static_cast<std::size_t>(b)].queue.size()))
      contended |= 1u << b;
  int accepted = 0;
  for (std::size_t p = 0; p < n; ++p) {
    const MemRequest* r = fronts_[p];
    if (r == nullptr || (contended >> r->bank & 1u) != 0) continue;
    const int b = r->bank;
    Bank& bank = banks_[static_cast<std::size_t>(b)];
    enqueue(p, bank, b);
    fronts_[p] = nullptr;  // one request per port and cycle
    ++accepted;
  }
  for (unsigned bits = contended; bits != 0; bits &= bits - 1) {
    const int b = std::countr_zero(bits);
    Bank& bank = banks_[static_cast<std::size_t>(b)];
    // Each port once, from where the pointer stood at the cycle's start (moving the start with
    // the pointer would visit a port twice and skip another).
    std::size_t& next = intake_next_[static_cast<std::size_t>(b)];
    const std::size_t first = next;
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t p = (first + k) % n;
      const MemRequest* r = fronts_[p];
      if (r == nullptr || r->bank != b) continue;
      if (static_cast<int>(bank.queue.size()) >= config_.queue_depth) {
        stall();  // held: the queue is full (back-pressure)
        continue;
      }
      enqueue(p, bank, b);
      fronts_[p] = nullptr;
      ++accepted;
      next = (p + 1) % n;
    }
  }
  return accepted;
}

std::uint64_t MemoryController::next_wakeup(std::uint64_t now) const {
  std::uint64_t t = hw::kNever;
  for (unsigned bits = inflight_; bits != 0; bits &= bits - 1) {
    const std::uint64_t due = due_[static_cast<std::size_t>(std::countr_zero(bits))];
    if (due > now) t = std::min(t, due);
  }
  for (unsigned bits = queued_; bits != 0; bits &= bits - 1) {
    const int b = std::countr_zero(bits);
    const Path& path =
        paths_[static_cast<std::size_t>(config_.bank_path[static_cast<std::size_t>(b)])];
    const std::uint64_t ready = std::max(free_at_[static_cast<std::size_t>(b)], path.free_at);
    if (ready > now) t = std::min(t, ready);
  }
  return t;
}

std::string MemoryController::dump_state() const {
  std::ostringstream os;
  for (int b = 0; b < kNumBanks; ++b) {
    const Bank& bank = banks_[static_cast<std::size_t>(b)];
    os << "bank" << b << " queue " << bank.queue.size() << " in flight " << bank.inflight.size()
       << " free at " << free_at_[static_cast<std::size_t>(b)] << (b + 1 < kNumBanks ? "; " : "");
  }
  return os.str();
}

}  // namespace saarcor::memif
