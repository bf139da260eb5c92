// Mock neighbours for the DynRTP units' exact-cycle tests (units/unit_timing_test.cpp,
// units/pass_through_unit_test.cpp): a thread table whose threads run fixed request scripts.
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "hw/kernel.h"
#include "units/cycle_unit.h"

namespace saarcor::units::testing {

inline const Request kDone{};  // unit kNone: the thread is finished (the RGS frees it)

// A thread table whose threads run fixed request scripts: execute() moves a thread to its
// script's next request and logs the cycle (the unit's issue cycle); start_primary() starts the
// `primary` script. What the units time is only the requests' unit, phase, item and steps.
class ScriptedThreads final : public ThreadTable {
 public:
  struct Issue {
    std::uint64_t cycle;
    std::uint32_t thread;
    Request request;
  };
  struct Start {
    std::uint64_t cycle;
    std::uint32_t thread;
    int packet;
  };

  ScriptedThreads(hw::Kernel& k, std::vector<std::vector<Request>> scripts,
                  std::vector<Request> primary = {}, int packets = 0)
      : k_(k), scripts_(std::move(scripts)), primary_(std::move(primary)), packets_(packets) {
    requests_.resize(scripts_.size());
    pos_.assign(scripts_.size(), 0);
    for (std::size_t t = 0; t < scripts_.size(); ++t)
      requests_[t] = scripts_[t].empty() ? kDone : scripts_[t][0];
  }
  void execute(std::uint32_t t) override {
    issues.push_back({k_.now(), t, requests_[t]});
    ++pos_[t];
    requests_[t] = pos_[t] < scripts_[t].size() ? scripts_[t][pos_[t]] : kDone;
  }
  void start_primary(std::uint32_t t, int packet) override {
    starts.push_back({k_.now(), t, packet});
    set_script(t, primary_);
  }
  int packets() const override { return packets_; }
  const std::vector<RgsAccess>& rgs_memory(std::uint32_t t) const override {
    const auto it = memory_.find(t);
    return it == memory_.end() ? ThreadTable::rgs_memory(t) : it->second;
  }
  // Test hook: the memory accesses thread t's RGS requests make.
  void set_memory(std::uint32_t t, std::vector<RgsAccess> access) {
    memory_[t] = std::move(access);
  }
  // Test hook: thread t continues with `script` (between runs only).
  void set_script(std::uint32_t t, std::vector<Request> script) {
    scripts_[t] = std::move(script);
    pos_[t] = 0;
    requests_[t] = scripts_[t].empty() ? kDone : scripts_[t][0];
  }
  // The cycle thread t issued its k-th request (0-based).
  std::uint64_t issued_at(std::uint32_t t, int k = 0) const {
    for (const Issue& i : issues)
      if (i.thread == t && k-- == 0) return i.cycle;
    ADD_FAILURE() << "thread " << t << " issued fewer requests";
    return hw::kNever;
  }

  std::vector<Issue> issues;
  std::vector<Start> starts;

 private:
  hw::Kernel& k_;
  std::vector<std::vector<Request>> scripts_;
  std::vector<std::size_t> pos_;
  std::vector<Request> primary_;
  int packets_;
  std::map<std::uint32_t, std::vector<RgsAccess>> memory_;
};

}  // namespace saarcor::units::testing
