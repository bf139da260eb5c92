// The memory controller and SRAM banks (paper section 3, DESIGN.md section 6, DIGEST D21/D23).
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
                  [bytes, clock, k] {
                    return k->now() == 0 ? 0.0
                                         : static_cast<double>(bytes->value) * clock /
                                               static_cast<double>(k->now()) / 1048576.0;
                  });
  clients_.push_back(std::move(c));
  return id;
}

std::uint64_t MemoryController::client_bytes(std::uint16_t client) const {
  return clients_.at(client).bytes->value;
}

double MemoryController::client_mb_per_s(std::uint16_t client, std::uint64_t cycles) const {
  if (cycles == 0) return 0.0;
  return static_cast<double>(client_bytes(client)) * config_.clock_hz /
         static_cast<double>(cycles) / 1048576.0;
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
  for (const auto& p : ports_) {
    if (!p->requests.empty() || !p->responses.empty()) return false;
  }
  return true;
}

bool MemoryController::port_idle(const Port& port) const {
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
    ports_[static_cast<std::size_t>(bank.inflight.front().port)]->responses.push_slot() =
        bank.inflight.front().resp;
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
    int chosen = -1;
    if (config_.reorder) {
      // Stay on the open bank while it has work and the burst limit allows, waiting for it when
      // it becomes free no later than a switch would let another bank start: such a switch
      // would be needless. Otherwise switch to the free bank with the oldest request.
      const bool open_wanted = path.open >= 0 && (queued_ >> path.open & 1u) != 0 &&
                               (path.burst < config_.max_burst || others_waiting == 0);
      if (open_wanted && startable(path.open)) {
        chosen = path.open;
      } else if (open_wanted && free_at_[static_cast<std::size_t>(path.open)] <=
                                    now() + static_cast<std::uint64_t>(config_.switch_penalty)) {
        chosen = -1;  // wait for the open bank
      } else {
        chosen = oldest_startable;
      }
    } else if (oldest_any >= 0 && startable(oldest_any)) {
      chosen = oldest_any;
    }
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

int MemoryController::accept_requests() {
  int accepted = 0;
  for (std::size_t p = 0; p < intake_.size(); ++p) {
    hw::Channel<MemRequest>& in = *intake_[p];
    if (!in.can_pop()) continue;
    const MemRequest& r = in.peek();
    if (r.bank >= kNumBanks || r.words < 1 || r.words > kMaxRequestWords ||
        static_cast<std::uint64_t>(r.offset) + r.words > image_.bank(r.bank).size() ||
        r.client >= clients_.size()) {
      throw std::runtime_error("memory controller '" + name() + "': port " + ports_[p]->name +
                               " sent a request outside memory (bank " + std::to_string(r.bank) +
                               ", offset " + std::to_string(r.offset) + ", " +
                               std::to_string(r.words) + " words, client " +
                               std::to_string(r.client) + ")");
    }
    Bank& bank = banks_[r.bank];
    if (static_cast<int>(bank.queue.size()) >= config_.queue_depth) {
      stall();
      continue;
    }
    if (bank.queue.empty()) {
      queued_ |= 1u << r.bank;
      oldest_[r.bank] = seq_;
    }
    Queued& q = bank.queue.push_slot();  // the request is written into its queue entry
    q.req = r;
    q.port = static_cast<int>(p);
    q.seq = seq_++;
    in.drop();  // last: `r` refers to the channel's slot
    bank.max_queue->set_max(bank.queue.size());
    ++accepted;
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
