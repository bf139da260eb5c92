// The memory controller and the SRAM banks (paper section 3: "Mem-Ctrl ... uses a simple
// reordering algorithm that ... avoid[s] unnecessary switching of memory-banks";
// docs/memif.md; decisions D21, D23, D39).
//
// Model:
//   * Ports: each client group (the simple routing of the caches, a shading unit, a frame-buffer
//     writer, the host bus) talks to the controller through one Port: a request channel and a
//     response channel (latency 1 each: the routing cycle each way of D21). The response channel
//     is `response_width` responses per cycle wide (add_port; 1 but for the routing's port, which
//     is as wide as its broadcast) and holds max(port_capacity, 2 x width) responses.
//   * Intake: per port and cycle at most one request moves into the per-bank queue of its bank
//     (depth `queue_depth`); a full queue holds the port (head-of-line, back-pressure). Where
//     more ports want a bank than its queue has room for, a round-robin pointer per bank decides
//     (D55): each waits at most one turn of the others.
//   * Banks: six 32-bit SRAM banks reading the MemoryImage. A request of w words occupies its
//     bank for w cycles from its start cycle s; its response (all w words) is handed to the port
//     in cycle s + w - 1 + latency.
//   * Issue paths: banks on the same path (default: the three scene banks 3-5, which the DynRTC
//     shares) are started by one shared issue stage, at most one start per cycle; starting a
//     bank other than the path's open (last) bank costs `switch_penalty` cycles (D21). With
//     `reorder` on, a path keeps issuing to its open bank while that bank has work and is free
//     (at most `max_burst` in a row while other banks wait), else it switches to the free bank
//     with the oldest request; with `reorder` off it always serves the path's oldest request.
//   * Writes (frame buffer, host) store into the image at their start cycle; no response.
//   * Bytes are counted per client at the start cycle (4 per word, or MemRequest::counted_bytes)
//     and reported as MB/s at the modelled clock (MB = 2^20 bytes, D39).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "hw/cycle_marks.h"
#include "hw/kernel.h"
#include "hw/ring.h"
#include "memif/config.h"
#include "memif/image_format.h"
#include "memif/request.h"

namespace saarcor::memif {

// What a traced run observes of a port (the lockstep's memory boundary, units/boundary_cache.h):
// a response pushed into the port's response channel. Null in a run that traces nothing.
class PortObserver {
 public:
  virtual ~PortObserver() = default;
  virtual void responded(std::uint64_t cycle, const MemResponse& r) = 0;
};

class MemoryController : public hw::Module {
 public:
  class Lane;
  struct Port {
    std::string name;
    hw::Channel<MemRequest> requests;    // client pushes, controller pops
    hw::Channel<MemResponse> responses;  // controller pushes, client pops
    // Set while the port is served as a lane (add_lane): its client uses the lane's calls instead
    // of the two channels.
    Lane* lane = nullptr;
    PortObserver* observer = nullptr;  // every response pushed (null: none)
    Port(hw::Kernel& k, const std::string& n, int capacity, int response_width = 1)
        : name(n),
          requests(k, n + ".req", capacity, 1),
          responses(k, n + ".resp", std::max(capacity, 2 * response_width), 1, response_width) {}
  };

  // Throws std::runtime_error for a bad configuration (one line naming the parameter).
  MemoryController(hw::Kernel& kernel, std::string name, MemoryImage& image,
                   MemoryControllerConfig config = {});

  // Throws std::runtime_error (one line) if the configuration is refused; returns the name.
  static std::string check(std::string name, const MemoryControllerConfig& config);

  // Set-up (before the first cycle). A port is a pair of channels; a client is a name bandwidth
  // is counted under (several clients may share one port, e.g. all caches behind the routing).
  // `response_width`: responses the port's client can take per cycle (>= 1; the routing's
  // broadcast width).
  Port& add_port(const std::string& name, int response_width = 1);
  std::uint16_t add_client(const std::string& name);
  // Serves `port` as a lane (below; docs/memif.md "Lanes"): reads only (`reads`) or writes only,
  // all into one bank that nothing else uses. Before the first cycle; the lane decides at its
  // first request whether it can run (otherwise the port works through its channels).
  Lane& add_lane(Port& port, bool reads);
  // Cycles in a lane's window (a client planning ahead keeps its own marks in as many).
  std::uint64_t lane_window() const { return lane_busy_.window(); }
  // Returns every lane's port to its channels (a host upload is about to write into the banks).
  // Throws std::logic_error once a lane has served a request.
  void close_lanes();

  int evaluate() override;
  std::string dump_state() const override;
  std::uint64_t next_wakeup(std::uint64_t now) const override;
  void skipped(std::uint64_t cycles) override;
  std::uint64_t skip_bound(std::uint64_t now) const override;

  // Bandwidth per client: bytes so far, and MB/s over `cycles` cycles at the modelled clock.
  std::uint64_t client_bytes(std::uint16_t client) const;
  // The client's bytes as the registry's counter (<client>.mem_bytes).
  const hw::Counter& client_counter(std::uint16_t client) const {
    return *clients_.at(client).bytes;
  }
  double client_mb_per_s(std::uint16_t client, std::uint64_t cycles) const;
  const std::string& client_name(std::uint16_t client) const;
  int clients() const { return static_cast<int>(clients_.size()); }
  std::uint64_t bank_switches() const;
  bool idle() const;  // nothing queued, in flight, or in a port channel
  // Nothing of `port`'s is in its channels, queued or in flight (a client's requests all served:
  // the RGS's last frame-buffer write stored while a host upload still runs).
  bool port_idle(const Port& port) const;
  const MemoryControllerConfig& config() const { return config_; }
  const MemoryImage& image() const { return image_; }

 private:
  struct Queued {
    MemRequest req;
    int port = 0;
    std::uint64_t seq = 0;  // arrival order, for oldest-first
  };
  struct InFlight {
    std::uint64_t due = 0;
    int port = 0;
    MemResponse resp;
  };
  // A bank's queue holds at most queue_depth requests and its reads in flight at most
  // inflight_limit_ (a bank starts no read beyond it), so both are fixed rings; an entry is
  // written where it waits.
  struct Bank {
    hw::Ring<Queued> queue;
    hw::Ring<InFlight> inflight;  // reads, in start order (due cycles increase)
    hw::Counter* reads = nullptr;
    hw::Counter* writes = nullptr;
    hw::Counter* words = nullptr;
    hw::Counter* max_queue = nullptr;
  };
  struct Path {
    unsigned banks = 0;  // bit b: bank b is on this path
    int open = -1;
    int burst = 0;
    std::uint64_t free_at = 0;
    hw::Counter* switches = nullptr;
  };
  struct Client {
    std::string name;
    hw::Counter* bytes = nullptr;
  };

  // The cycle, as a script.
  int retire_responses();
  int issue();
  int choose(const Path& path, unsigned waiting) const;  // the bank a path starts, or -1
  int accept_requests();
  const MemRequest* front(std::size_t port) const;
  void enqueue(std::size_t port, Bank& bank, int b);
  void start(int bank, std::uint64_t when);

  MemoryImage& image_;
  MemoryControllerConfig config_;
  std::vector<std::unique_ptr<Port>> ports_;
  std::vector<Bank> banks_;
  std::vector<Path> paths_;
  std::vector<Client> clients_;
  std::uint64_t seq_ = 0;
  int inflight_limit_;
  // What the per-cycle stages scan, kept beside the banks so a cycle reads a few words: bit b of
  // queued_ / inflight_ says bank b has a queued request / a read in flight, and then oldest_[b]
  // is its front request's arrival number and due_[b] its front read's due cycle.
  unsigned queued_ = 0, inflight_ = 0;
  std::array<std::uint64_t, kNumBanks> oldest_{}, due_{};
  // Per bank: the port first in line when more ports want the bank than its queue has room for.
  std::array<std::size_t, kNumBanks> intake_next_{};
  std::vector<const MemRequest*> fronts_;  // accept_requests' scratch: each port's front request
  std::array<std::uint64_t, kNumBanks> free_at_{};  // first cycle a bank can start another request
  // The earliest due_ (kNever with nothing in flight): before it no read can leave, and the
  // retire stage is not entered (most cycles with reads in flight have none due).
  std::uint64_t next_due_ = hw::kNever;
  // Per bank: bit p = its issue path p; the issue stage visits only the paths of queued banks.
  std::array<unsigned, kNumBanks> path_bit_{};
  // Per port: its request channel (the intake polls every port every cycle it runs).
  std::vector<hw::Channel<MemRequest>*> intake_;

  // Lanes. Their requests' cycles in which the controller makes progress (intake, start,
  // retire) and in which it stalls (a lane's request visible but its bank queue full), marked in
  // a window of cycles from lane_from_ on; counted into the controller's busy and stall cycles as
  // the cycles pass (account_lanes).
  void account_lanes(std::uint64_t to, bool busy_counted, bool stall_counted);
  void mark_lane_stalls(std::uint64_t from, std::uint64_t to);
  std::uint64_t lane_horizon() const;
  std::vector<std::unique_ptr<Lane>> lanes_;
  unsigned lane_banks_ = 0;  // bit b: bank b is a lane's
  int open_lanes_ = 0;       // lanes serving requests
  hw::CycleMarks lane_busy_, lane_stall_;
  std::uint64_t lane_reach_ = 0;  // lane_horizon(), computed once
  std::uint64_t lane_from_ = 0;   // the first cycle not yet counted
};

// A lane: a port whose requests all go to one bank that nothing else uses, on an issue path of
// its own, served in closed form. The stepped model moves a request through the port's request
// channel, the controller's intake, the bank's queue, its start and (for a read) its return
// buffer and response channel, a module evaluation each; with nothing else on the bank or its
// path, the cycle of every one of these steps follows from the request's push cycle and the
// cycles of the requests before it (docs/memif.md "Lanes" derives them), so the lane computes
// them when the request is pushed. The controller's busy and stall cycles are counted as the
// kernel's time passes them (cycle marks); the channels', bank's and client's statistics are sums
// over requests, booked at the push. The client must take every response in the cycle it
// becomes visible (the RGS does: it pops one per cycle and the bank returns at most one).
class MemoryController::Lane {
 public:
  // The port's request channel would take a push in this cycle / from which cycle on it will.
  bool can_push() const;
  std::uint64_t push_ready_cycle() const;
  void push(const MemRequest& r) { (void)push_at(r, mc_.now()); }
  // Planning ahead (the client knows what it will push in which cycle, as the RGS does for a
  // wave of reads going out back to back): the first cycle from `from` on in which the port would
  // take a push after those pushed so far; whether a push in `cycle` stays within the lane's
  // window; a push in a cycle from now on (in cycle order, each where the port takes it).
  // push_at returns the cycle a read's response becomes visible (0 for a write).
  std::uint64_t next_push_cycle(std::uint64_t from) const;
  bool plannable(std::uint64_t cycle) const;
  std::uint64_t push_at(const MemRequest& r, std::uint64_t cycle);
  // Takes the next `count` responses, the last of which becomes visible in this cycle (the ones
  // before it were visible in earlier cycles: taken then, booked as such); returns its tag.
  std::uint32_t pop_through(std::uint64_t count);
  // A response visible in this cycle; the cycle the next one becomes visible (kNever: none).
  bool can_pop() const { return response_cycle() <= mc_.now(); }
  std::uint64_t response_cycle() const {
    return popped_ < pushed_ ? item(popped_).retire + 1 : hw::kNever;
  }
  // Takes the visible response; returns its tag.
  std::uint32_t pop();
  // Nothing of the lane's queued, in flight or unanswered in the current cycle.
  bool idle() const;
  bool open() const { return state_ == State::kOpen; }

 private:
  friend class MemoryController;
  Lane(MemoryController& mc, Port& port, int port_index, bool reads);
  // A read waiting for its response to be taken (the client pops in the cycle it is visible).
  struct Item {
    std::uint64_t retire = 0;
    std::uint32_t tag = 0;
  };
  enum class State { kUnbound, kOpen, kClosed };
  Item& item(std::uint64_t k) { return items_[k & item_mask_]; }
  const Item& item(std::uint64_t k) const { return items_[k & item_mask_]; }
  bool bind(const MemRequest& r);  // at the first request: can the lane run?
  std::uint64_t push_unusual(const MemRequest& r, std::uint64_t t);
  void book_beyond_window(std::uint64_t last);
  void settle();  // hands the statistics booked so far to their counters

  MemoryController& mc_;
  Port& port_;
  int port_index_;
  bool reads_;
  State state_ = State::kUnbound;
  int bank_ = -1;
  std::uint64_t bank_words_ = 0;
  std::vector<Item> items_;  // reads, by request number
  std::uint64_t item_mask_ = 0;
  // Requests pushed; the first read whose response the client has not taken.
  std::uint64_t pushed_ = 0, popped_ = 0;
  // The controller's parameters the recurrences read (port capacity, queue depth, reads in
  // flight, latency) and its clients when the lane opened.
  std::uint64_t cap_, depth_, limit_, latency_, client_count_ = 0;
  // The cycles the recurrences read: the first cycle after the last push, the last request's
  // intake, the cycle its bank is free, its words; per request the intake, start and (reads)
  // retire cycles of the last few (ring by request number).
  std::uint64_t next_push_ = 0, last_accept_ = 0, bank_free_ = 0;
  std::uint8_t last_words_ = 0;
  struct Steps {
    std::uint64_t accept = 0, start = 0, retire = 0;
  };
  std::vector<Steps> hist_;
  std::uint64_t hist_mask_ = 0;
  // push_at's steps: the closed form's precondition, the request's statistics, the controller's
  // busy and stall cycles.
  bool usual(const MemRequest& r, std::uint64_t t) const;
  void book(const MemRequest& r, std::uint64_t t, const Steps& s);
  void mark(const Steps& s, std::uint64_t visible);
  // The first request taken in after the last push cycle (the port's request channel holds it
  // and those after it at the end of that cycle).
  std::uint64_t channel_front_ = 0;
  // Statistics of the requests pushed since the last settle(): every cycle of a request is known
  // when it is pushed, so it is booked then (sums of cycles for the channels' occupancies).
  struct Booked {
    std::uint64_t requests = 0, push_cycles = 0, accept_cycles = 0, retire_cycles = 0, words = 0;
    std::uint64_t most_in_channel = 0, most_queued = 0;
  } booked_;
  std::uint64_t queue_front_ = 0;  // the first request not yet started at the last intake
};

// ---- The lane's hot path, inline: its client pushes a request in most of the cycles it acts in.

// The port takes one request per cycle, and only while its channel has room: the cap-th newest
// request must have been taken in before the cycle.
inline bool MemoryController::Lane::can_push() const {
  return push_ready_cycle() <= mc_.now();
}

inline std::uint64_t MemoryController::Lane::push_ready_cycle() const {
  return next_push_cycle(0);
}

inline std::uint64_t MemoryController::Lane::next_push_cycle(std::uint64_t from) const {
  std::uint64_t c = std::max(from, next_push_);
  if (pushed_ >= cap_) {
    c = std::max(c, hist_[(pushed_ - cap_) & hist_mask_].accept + 1);
  }
  return c;
}

inline bool MemoryController::Lane::plannable(std::uint64_t cycle) const {
  return state_ == State::kOpen &&
         cycle + mc_.lane_reach_ - mc_.lane_from_ < (mc_.lane_busy_.window() - 1) / 2;
}

// A request the closed form covers: the lane open, the request one of its kind into its bank and
// within it, from a known client, pushed in cycle order, and (a read) with room among the
// responses not yet taken.
inline bool MemoryController::Lane::usual(const MemRequest& r, std::uint64_t t) const {
  return state_ == State::kOpen && r.words >= 1 && r.words <= kMaxRequestWords && r.bank == bank_ &&
         static_cast<std::uint64_t>(r.offset) + r.words <= bank_words_ &&
         r.client < client_count_ && r.write != reads_ && t >= mc_.now() && t >= next_push_ &&
         !(reads_ && pushed_ - popped_ > item_mask_);
}

// The request's cycles, from the stepped model's rules (memory_controller.h): visible at the
// intake a cycle after its push, one intake per port and cycle, into a bank queue with room after
// that cycle's start (the depth-th request before it has started); started a cycle after its
// intake at the earliest, when the bank is free and (reads) fewer than the limit of reads are in
// flight after that cycle's retire; a read retires at its due cycle (its port's response channel
// always has room: the client takes each response the cycle it becomes visible).
inline std::uint64_t MemoryController::Lane::push_at(const MemRequest& r, std::uint64_t t) {
  if (!usual(r, t)) [[unlikely]] {
    return push_unusual(r, t);
  }
  const std::uint64_t k = pushed_;
  const std::uint64_t visible = std::max(t + 1, k == 0 ? 0 : last_accept_ + 1);
  const Steps* const hist = hist_.data();
  Steps s{visible, 0, 0};
  if (k >= depth_) {
    s.accept = std::max(s.accept, hist[(k - depth_) & hist_mask_].start);
  }
  s.start = std::max(s.accept + 1, bank_free_);
  if (reads_ && k >= limit_) {
    s.start = std::max(s.start, hist[(k - limit_) & hist_mask_].retire);
  }
  s.retire = reads_ ? s.start + r.words - 1 + latency_ : 0;
  book(r, t, s);
  mark(s, visible);
  next_push_ = t + 1;
  last_accept_ = s.accept;
  last_words_ = r.words;
  bank_free_ = s.start + r.words;
  ++pushed_;
  return reads_ ? s.retire + 1 : 0;
}

// The statistics of every step of request pushed_, pushed in cycle t (the stepped model books
// them in the cycles the request takes each step; the sums are the same, and nothing reads them
// before the run ends: a lane runs only without time series and traces); a read's response
// waits among the items, a write is stored.
inline void MemoryController::Lane::book(const MemRequest& r, std::uint64_t t, const Steps& s) {
  const std::uint64_t k = pushed_;
  const Steps* const hist = hist_.data();
  // The bank queue after the intake: the requests from the first not started by then on.
  while (queue_front_ < k && hist[queue_front_ & hist_mask_].start <= s.accept) {
    ++queue_front_;
  }
  // The port's request channel at the end of this cycle: this request and those taken in later.
  // Intake cycles increase with the request number and push cycles with each push, so the first
  // of them only moves forward (the history holds the last hist_mask_ + 1 requests).
  channel_front_ = std::max(channel_front_, k > hist_mask_ ? k - hist_mask_ : 0);
  while (channel_front_ < k && hist[channel_front_ & hist_mask_].accept <= t) {
    ++channel_front_;
  }
  const std::uint64_t occupancy = k - channel_front_ + 1;
  hist_[k & hist_mask_] = s;
  ++booked_.requests;
  booked_.push_cycles += t;
  booked_.accept_cycles += s.accept;
  booked_.words += r.words;
  booked_.most_in_channel = std::max(booked_.most_in_channel, occupancy);
  booked_.most_queued = std::max(booked_.most_queued, k - queue_front_ + 1);
  *mc_.clients_[r.client].bytes += r.counted_bytes ? r.counted_bytes : 4u * r.words;
  if (reads_) {
    booked_.retire_cycles += s.retire;
    Item& it = item(k);
    it.retire = s.retire;
    it.tag = r.tag;
  } else {
    // Stored at its start in the stepped model; nothing reads a lane's bank before then.
    std::copy_n(r.data.begin(), r.words, mc_.image_.bank(bank_).data() + r.offset);
  }
}

// The controller's cycles: progress at the intake, the start and the retire; a stall while the
// request is visible and its bank queue full. (Cycles beyond the window: book the past first.)
inline void MemoryController::Lane::mark(const Steps& s, std::uint64_t visible) {
  if (std::max(s.start, s.retire) - mc_.lane_from_ >= mc_.lane_busy_.window()) [[unlikely]] {
    book_beyond_window(std::max(s.start, s.retire));
  }
  mc_.lane_busy_.mark(s.accept);
  mc_.lane_busy_.mark(s.start);
  if (reads_) {
    mc_.lane_busy_.mark(s.retire);
  }
  if (s.accept > visible) {
    mc_.mark_lane_stalls(visible, s.accept);
  }
}

}  // namespace saarcor::memif
