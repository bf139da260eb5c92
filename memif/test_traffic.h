// Traffic generators and a scoreboard for the memif tests (docs/memif.md): a requester
// that drives one cache with constrained-random item requests and checks every response against
// a reference MemoryImage, and a scene image filled with random words. Test-only header.
#pragma once

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <string>
#include <vector>

#include "hw/kernel.h"
#include "memif/cache.h"
#include "memif/image_format.h"

namespace saarcor::memif::testing {

// An image whose scene regions hold random words; item counts fit a small bank.
inline MemoryImage random_scene_image(ff::Format format, unsigned seed) {
  MemoryImage img(format, 8192);
  std::mt19937 rng(seed);
  for (int b = 0; b < kNumBanks; ++b) {
    for (auto& w : img.bank(b))
      w = static_cast<std::uint32_t>(rng());
  }
  img.regions().base = {0, 2000, 3000};
  img.regions().count = {1500, 2400, 1500};
  return img;
}

struct RequesterConfig {
  std::uint32_t items = 1000;  // index range
  int requests = 500;
  int max_gap = 3;          // cycles between requests: 0..max_gap
  int pop_stall_per_4 = 1;  // out of 4 cycles with a response, this many refuse it
  std::uint32_t conflict_stride = 512;
};

// Drives one cache: a mix of a sliding hot window (locality), uniform indices and conflicting
// indices (same set); records the accepted trace; checks each response against the reference.
class Requester : public hw::Module {
 public:
  Requester(hw::Kernel& k, std::string name, Cache& cache, const MemoryImage& reference,
            std::uint16_t id, RequesterConfig cfg, unsigned seed, int port = 0)
      : hw::Module(k, std::move(name)),
        cache_(cache),
        ref_(reference),
        id_(id),
        cfg_(cfg),
        rng_(seed),
        port_(port) {}

  int evaluate() override {
    int p = 0;
    hw::Channel<CacheResponse>& resp = cache_.responses(port_);
    if (resp.can_pop()) {
      ++p;  // the draw below changes the generator: progress, so idle skip stays exact
      if (static_cast<int>(rng_() % 4) >= cfg_.pop_stall_per_4) check(resp.pop());
    }
    if (sent_ < cfg_.requests && now() >= next_issue_ && cache_.requests(port_).can_push()) {
      const std::uint32_t index = pick();
      const std::uint32_t tag = static_cast<std::uint32_t>(sent_++);
      cache_.requests(port_).push({index, {id_, tag}});
      outstanding_[tag] = index;
      trace.push_back(index);
      next_issue_ = now() + 1 + rng_() % static_cast<unsigned>(cfg_.max_gap + 1);
      ++p;
    }
    return p;
  }
  std::uint64_t next_wakeup(std::uint64_t now) const override {
    return sent_ < cfg_.requests && next_issue_ > now ? next_issue_ : hw::kNever;
  }
  std::string dump_state() const override {
    return std::to_string(sent_) + " sent, " + std::to_string(outstanding_.size()) + " outstanding";
  }
  bool done() const { return sent_ == cfg_.requests && outstanding_.empty(); }

  std::vector<std::uint32_t> trace;  // indices in the order this requester sent them
  int answered = 0;

 private:
  std::uint32_t pick() {
    const unsigned kind = rng_() % 10;
    if (kind < 5) {  // hot window that drifts
      if (rng_() % 64 == 0) hot_ = static_cast<std::uint32_t>(rng_() % cfg_.items);
      return (hot_ + rng_() % 32) % cfg_.items;
    }
    if (kind < 8) return static_cast<std::uint32_t>(rng_() % cfg_.items);
    const std::uint32_t base = trace.empty() ? 0 : trace.back();
    return (base + cfg_.conflict_stride * (1 + rng_() % 2)) % cfg_.items;
  }
  void check(const CacheResponse& r) {
    auto it = outstanding_.find(r.label.tag);
    ASSERT_EQ(r.label.requester, id_) << name();
    ASSERT_NE(it, outstanding_.end()) << name() << ": response for tag " << r.label.tag
                                      << " that is not outstanding (duplicate or invented)";
    ASSERT_EQ(r.index, it->second) << name();
    ASSERT_EQ(r.count, ref_.item_words(cache_.type())) << name();
    for (int w = 0; w < r.count; ++w) {
      ASSERT_EQ(r.words[w], ref_.item_word(cache_.type(), r.index, w))
          << name() << ": item " << r.index << " word " << w;
    }
    for (int w = r.count; w < kMaxRequestWords; ++w)
      ASSERT_EQ(r.words[w], 0u);
    outstanding_.erase(it);
    ++answered;
  }

  Cache& cache_;
  const MemoryImage& ref_;
  std::uint16_t id_;
  RequesterConfig cfg_;
  std::mt19937 rng_;
  int port_;
  int sent_ = 0;
  std::uint64_t next_issue_ = 0;
  std::uint32_t hot_ = 0;
  std::map<std::uint32_t, std::uint32_t> outstanding_;  // tag -> index
};

}  // namespace saarcor::memif::testing
