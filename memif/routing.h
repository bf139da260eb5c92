// Simple routing (paper section 3: "acts like a multiplexer for memory requests and uses a
// labeled broadcast for memory responses" [SWS02]; docs/memif.md; decision D23).
//
// Requests: one per cycle from the clients (every cache of every DynRTP) to the controller port,
// chosen round-robin among the clients that have one (fair: a client waits at most one turn of
// the others). Responses: up to `responses_per_cycle` per cycle from the controller port (whose
// response channel MemorySystem makes as wide), each delivered to the client named by its label
// (MemResponse::client); a client whose fill channel is full or already took a fill this cycle
// holds the broadcast (head-of-line), as a shared bus would.
// Latency: one cycle each way in the routing's channels (the client's request channel and its
// fill channel, both latency 1), plus one each way in the controller's port channels.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "memif/memory_controller.h"
#include "memif/request.h"

namespace saarcor::memif {

// What a traced run observes of the routing (the lockstep's cache record, units/boundary_cache.h):
// a client's request taken towards the controller, and a response pushed to its client's fill
// channel. Null in a run that traces nothing (one pointer test per request and per response).
class RoutingObserver {
 public:
  virtual ~RoutingObserver() = default;
  virtual void forwarded(std::uint64_t cycle, const MemRequest& r) = 0;  // r.client set
  virtual void delivered(std::uint64_t cycle, const MemResponse& r) = 0;
  // A client had a request and the controller port's request channel was full.
  virtual void blocked(std::uint64_t /*cycle*/) {}
};

class SimpleRouting : public hw::Module {
 public:
  SimpleRouting(hw::Kernel& kernel, std::string name, MemoryController::Port& port,
                int responses_per_cycle = 1);

  // Throws std::runtime_error (one line) if responses_per_cycle < 1; returns the name.
  static std::string check(std::string name, int responses_per_cycle);

  // Set-up: a client (named by its controller client id) whose requests the routing takes from
  // `requests` and whose responses it pushes into `fills`.
  void add_client(std::uint16_t client, hw::Channel<MemRequest>& requests,
                  hw::Channel<MemResponse>& fills);

  // Every forwarded request and delivered response reports to `o` (null: none, the default).
  void set_observer(RoutingObserver* o) { observer_ = o; }
  MemoryController::Port& port() { return port_; }

  int evaluate() override;
  void commit() override { rr_.commit(); }
  std::uint64_t next_wakeup(std::uint64_t) const override { return hw::kNever; }
  std::string dump_state() const override;

 private:
  struct Client {
    std::uint16_t id;
    hw::Channel<MemRequest>* requests;
    hw::Channel<MemResponse>* fills;
  };
  int broadcast();
  int arbitrate();

  MemoryController::Port& port_;
  int responses_per_cycle_;
  std::vector<Client> clients_;
  std::vector<int> by_id_;  // controller client id -> index in clients_, -1 if not ours
  hw::Reg<int> rr_{0};      // next client to be offered the request bus
  hw::Counter* forwarded_;
  RoutingObserver* observer_ = nullptr;
};

}  // namespace saarcor::memif
