// Simple routing: request multiplexer and labelled response broadcast (paper section 3,
// docs/memif.md, decision D23).
#include "memif/routing.h"

#include <stdexcept>

namespace saarcor::memif {

std::string SimpleRouting::check(std::string name, int responses_per_cycle) {
  if (responses_per_cycle < 1) {
    throw std::runtime_error("routing '" + name + "': responses_per_cycle must be >= 1");
  }
  return name;
}

SimpleRouting::SimpleRouting(hw::Kernel& kernel, std::string name, MemoryController::Port& port,
                             int responses_per_cycle)
    : hw::Module(kernel, check(std::move(name), responses_per_cycle)),
      port_(port),
      responses_per_cycle_(responses_per_cycle) {
  sleep_when_idle();  // depends only on its channels and its register
  produces(port.requests);
  consumes(port.responses);
  forwarded_ = &stats().counter(this->name() + ".requests", "requests",
                                "requests forwarded to the memory controller");
}

void SimpleRouting::add_client(std::uint16_t client, hw::Channel<MemRequest>& requests,
                               hw::Channel<MemResponse>& fills) {
  if (by_id_.size() <= client) by_id_.resize(client + 1u, -1);
  if (by_id_[client] >= 0) {
    throw std::runtime_error("routing '" + name() + "': client " + std::to_string(client) +
                             " added twice");
  }
  consumes(requests);
  produces(fills);
  by_id_[client] = static_cast<int>(clients_.size());
  clients_.push_back({client, &requests, &fills});
}

int SimpleRouting::evaluate() {
  return broadcast() + arbitrate();
}

int SimpleRouting::broadcast() {
  int moved = 0;
  while (moved < responses_per_cycle_ && port_.responses.can_pop()) {
    const MemResponse& r = port_.responses.peek();
    if (r.client >= by_id_.size() || by_id_[r.client] < 0) {
      throw std::runtime_error("routing '" + name() + "': response labelled for client " +
                               std::to_string(r.client) + ", which is not connected");
    }
    hw::Channel<MemResponse>& fills = *clients_[static_cast<std::size_t>(by_id_[r.client])].fills;
    if (!fills.can_push()) {
      stall();
      break;
    }
    if (observer_ != nullptr) [[unlikely]]
      observer_->delivered(now(), r);
    fills.push(port_.responses.pop());  // last: `r` refers to the channel's slot
    ++moved;
  }
  return moved;
}

int SimpleRouting::arbitrate() {
  const int n = static_cast<int>(clients_.size());
  for (int k = 0; k < n; ++k) {
    const int c = (rr_.get() + k) % n;
    hw::Channel<MemRequest>& in = *clients_[static_cast<std::size_t>(c)].requests;
    if (!in.can_pop()) continue;
    if (!port_.requests.can_push()) {
      if (observer_ != nullptr) [[unlikely]]
        observer_->blocked(now());
      stall();
      return 0;
    }
    MemRequest r = in.pop();
    r.client = clients_[static_cast<std::size_t>(c)].id;  // the label is the routing's to set
    port_.requests.push(r);
    if (observer_ != nullptr) [[unlikely]]
      observer_->forwarded(now(), r);
    rr_.set((c + 1) % n);
    ++*forwarded_;
    return 1;
  }
  return 0;
}

std::string SimpleRouting::dump_state() const {
  return "next client " + std::to_string(rr_.get()) + " of " + std::to_string(clients_.size());
}

}  // namespace saarcor::memif
