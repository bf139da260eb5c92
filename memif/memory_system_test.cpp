// The memory interface under constrained-random traffic (docs/memif.md): several
// requesters on the caches of two DynRTPs plus uncached shading reads, frame-buffer writes and a
// host upload, all through one controller. A scoreboard checks that every request is answered
// exactly once with the words of a reference image, and the caches' hit/miss counts equal those
// of a plain reference cache simulation on the same request sequence. Also: the same figures
// with idle skipping and in random evaluation orders, and the host bus bandwidth.
#include "memif/memory_system.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "memif/reference_cache.h"
#include "memif/test_traffic.h"

namespace saarcor::memif {
namespace {

using testing::Requester;
using testing::RequesterConfig;

// Uncached shading reads of random 1..4-word records in the shading bank, checked on arrival.
class ShadingReader : public hw::Module {
 public:
  ShadingReader(hw::Kernel& k, MemorySystem& mi, const MemoryImage& ref, int reads)
      : hw::Module(k, "test.shading"),
        port_(mi.shading_port(0)),
        client_(mi.shading_client(0)),
        ref_(ref),
        reads_(reads) {}
  int evaluate() override {
    int p = 0;
    if (port_.responses.can_pop()) {
      const MemResponse r = port_.responses.pop();
      const auto it = sent_.find(r.tag);
      EXPECT_NE(it, sent_.end());
      if (it != sent_.end()) {
        EXPECT_EQ(r.count, it->second.words);
        for (int w = 0; w < r.count; ++w) {
          EXPECT_EQ(r.words[w], ref_.word(kShadingBank, it->second.offset + w));
        }
        sent_.erase(it);
      }
      ++p;
    }
    if (tag_ < static_cast<std::uint32_t>(reads_) && port_.requests.can_push()) {
      MemRequest q;
      q.client = client_;
      q.tag = tag_;
      q.bank = kShadingBank;
      q.words = static_cast<std::uint8_t>(1 + rng_() % 4);
      q.offset = rng_() % 8000;
      sent_[tag_++] = q;
      port_.requests.push(q);
      ++p;
    }
    return p;
  }
  std::uint64_t next_wakeup(std::uint64_t) const override { return hw::kNever; }
  bool done() const { return tag_ == static_cast<std::uint32_t>(reads_) && sent_.empty(); }
  std::uint64_t words_read = 0;

 private:
  MemoryController::Port& port_;
  std::uint16_t client_;
  const MemoryImage& ref_;
  int reads_;
  std::uint32_t tag_ = 0;
  std::map<std::uint32_t, MemRequest> sent_;
  std::mt19937 rng_{11};
};

// Frame-buffer writes: one word per pixel, 3 bytes counted (D36).
class FrameWriter : public hw::Module {
 public:
  FrameWriter(hw::Kernel& k, MemorySystem& mi, int pixels)
      : hw::Module(k, "test.frame"),
        port_(mi.frame_port(0)),
        client_(mi.frame_client(0)),
        pixels_(pixels) {}
  int evaluate() override {
    if (next_ == pixels_ || !port_.requests.can_push()) return 0;
    MemRequest q;
    q.client = client_;
    q.bank = kFrameBank0;
    q.write = true;
    q.words = 1;
    q.counted_bytes = 3;
    q.offset = static_cast<std::uint32_t>(next_);
    q.data[0] = 0xC0FFEEu ^ static_cast<std::uint32_t>(next_);
    port_.requests.push(q);
    ++next_;
    return 1;
  }
  std::uint64_t next_wakeup(std::uint64_t) const override { return hw::kNever; }
  bool done() const { return next_ == pixels_; }

 private:
  MemoryController::Port& port_;
  std::uint16_t client_;
  int pixels_;
  int next_ = 0;
};

struct Scenario {
  ff::Format format = ff::kFp24;
  MemorySystemConfig mi;  // a cache with n ports gets n requesters, one per port
  RequesterConfig req;
};

struct Result {
  std::uint64_t cycles;
  std::string stats;
};

Result run_scenario(const Scenario& sc, hw::KernelConfig kc, unsigned seed) {
  MemoryImage img = testing::random_scene_image(sc.format, seed);
  const MemoryImage ref = img;
  hw::Kernel k(kc);
  MemorySystem mi(k, img, sc.mi);
  std::vector<std::unique_ptr<Requester>> reqs;
  std::vector<std::vector<std::uint32_t>> accepted(
      static_cast<std::size_t>(mi.pipelines() * kItemTypes));
  for (int p = 0; p < mi.pipelines(); ++p) {
    for (int t = 0; t < kItemTypes; ++t) {
      const auto type = static_cast<ItemType>(t);
      Cache& cache = mi.cache(p, type);
      cache.set_accept_log(&accepted[static_cast<std::size_t>(p * kItemTypes + t)]);
      RequesterConfig rc = sc.req;
      rc.items = ref.regions().count[static_cast<std::size_t>(t)];
      for (int port = 0; port < cache.config().ports; ++port) {
        reqs.push_back(std::make_unique<Requester>(
            k, "test.req" + std::to_string(p) + "." + item_type_name(type) + std::to_string(port),
            cache, ref, static_cast<std::uint16_t>(100 * p + 10 * t + port), rc,
            seed * 100 + static_cast<unsigned>(reqs.size()), port));
      }
    }
  }
  ShadingReader shading(k, mi, ref, 300);
  FrameWriter frame(k, mi, 400);
  std::vector<std::uint32_t> upload(1000);
  for (std::size_t i = 0; i < upload.size(); ++i)
    upload[i] = 0xB0000000u + static_cast<std::uint32_t>(i);
  mi.host().upload(kFrameBank1, 100, upload);
  const std::uint64_t cycles = k.run_to_completion(
      [&] {
        for (auto& r : reqs) {
          if (!r->done()) return false;
        }
        return shading.done() && frame.done() && mi.idle();
      },
      2000000);
  // Scoreboard: every request answered exactly once (duplicates and inventions fail inside).
  for (auto& r : reqs)
    EXPECT_EQ(r->answered, sc.req.requests) << r->name();
  // Hit rates against the reference simulation on the accepted request sequence.
  for (int p = 0; p < mi.pipelines(); ++p) {
    for (int t = 0; t < kItemTypes; ++t) {
      const auto type = static_cast<ItemType>(t);
      const Cache& c = mi.cache(p, type);
      testing::ReferenceCache model(c.config().items, c.config().ways);
      const auto& seq = accepted[static_cast<std::size_t>(p * kItemTypes + t)];
      EXPECT_EQ(seq.size(), c.requests_count());
      EXPECT_EQ(seq.size(), static_cast<std::size_t>(sc.req.requests * c.config().ports));
      for (std::uint32_t index : seq)
        model.access(index);
      std::printf(
          "%s: %llu requests, %llu hits, %llu merges, %llu misses (reference: %llu hits)\n",
          c.name().c_str(), static_cast<unsigned long long>(c.requests_count()),
          static_cast<unsigned long long>(c.hits()), static_cast<unsigned long long>(c.merges()),
          static_cast<unsigned long long>(c.misses()), static_cast<unsigned long long>(model.hits));
      EXPECT_EQ(c.hits() + c.merges(), model.hits) << c.name();
      EXPECT_EQ(c.misses(), model.misses) << c.name();
      EXPECT_GT(c.hits(), 0u) << c.name();
      EXPECT_GT(c.misses(), 0u) << c.name();
      // Bytes: every miss fetched its item once.
      EXPECT_EQ(mi.controller().client_bytes(c.client()),
                c.misses() * 4u * static_cast<unsigned>(ref.item_words(type)))
          << c.name();
    }
  }
  // Frame-buffer and host writes arrived; scene banks untouched.
  for (int i = 0; i < 400; ++i) {
    EXPECT_EQ(img.word(kFrameBank0, static_cast<std::uint32_t>(i)),
              0xC0FFEEu ^ static_cast<std::uint32_t>(i));
  }
  for (std::size_t i = 0; i < upload.size(); ++i) {
    EXPECT_EQ(img.word(kFrameBank1, 100 + static_cast<std::uint32_t>(i)), upload[i]);
  }
  for (int b = kFirstSceneBank; b < kNumBanks; ++b)
    EXPECT_EQ(img.bank(b), ref.bank(b));
  EXPECT_EQ(mi.controller().client_bytes(mi.frame_client(0)), 400u * 3u);
  EXPECT_EQ(mi.controller().client_bytes(mi.host().client()), 4000u);
  return {cycles, k.stats().json()};
}

TEST(MemorySystem, ScoreboardAndReferenceHitRatesWithDefaultCaches) {
  Scenario sc;
  sc.mi.pipelines = 2;
  sc.req.requests = 600;
  run_scenario(sc, {}, 1);
}

TEST(MemorySystem, ScoreboardAndReferenceHitRatesWithSmallAssociativeCachesUnderPressure) {
  Scenario sc;
  sc.mi.pipelines = 2;
  for (CacheConfig* c : {&sc.mi.node_cache, &sc.mi.list_cache, &sc.mi.row_cache}) {
    c->items = 64;
    c->ways = 4;
    c->max_misses = 2;
    c->max_targets = 2;
    c->hit_latency = 3;
  }
  sc.req.requests = 600;
  sc.req.conflict_stride = 16;
  sc.req.max_gap = 0;
  run_scenario(sc, {}, 2);
}

TEST(MemorySystem, ScoreboardWithTinyDirectMappedCachesWideRowsAndNoReordering) {
  Scenario sc;
  sc.format = ff::kFp32;  // 4-word rows
  sc.mi.pipelines = 1;
  for (CacheConfig* c : {&sc.mi.node_cache, &sc.mi.list_cache, &sc.mi.row_cache}) {
    c->items = 8;
    c->max_misses = 1;
  }
  sc.mi.controller.reorder = false;
  sc.mi.controller.switch_penalty = 0;
  sc.mi.responses_per_cycle = 2;
  sc.req.requests = 400;
  sc.req.conflict_stride = 8;
  run_scenario(sc, {}, 3);
}

TEST(MemorySystem, ScoreboardWithSeveralUnitsSharingOneCacheThroughPorts) {
  Scenario sc;
  sc.mi.pipelines = 1;
  sc.mi.row_cache.ports = 3;  // e.g. transformation, traversal (bounds) and shading helpers
  sc.mi.node_cache.ports = 2;
  sc.req.requests = 300;
  run_scenario(sc, {}, 5);
}

TEST(MemorySystem, IdleSkipAndEvaluationOrderChangeNoFigure) {
  Scenario sc;
  sc.mi.pipelines = 2;
  sc.req.requests = 200;
  sc.req.max_gap = 40;  // sparse traffic: many idle cycles to skip
  const Result step = run_scenario(sc, {.idle_skip = false}, 4);
  const Result skip = run_scenario(sc, {.idle_skip = true}, 4);
  EXPECT_EQ(skip.cycles, step.cycles);
  EXPECT_EQ(skip.stats, step.stats);
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const Result shuffled = run_scenario(sc, {.idle_skip = seed % 2 == 0, .shuffle_seed = seed}, 4);
    EXPECT_EQ(shuffled.cycles, step.cycles) << "seed " << seed;
    EXPECT_EQ(shuffled.stats, step.stats) << "seed " << seed;
  }
}

TEST(HostBus, UploadsAtTheConfiguredBandwidth) {
  for (double mbps : {132.0, 33.0}) {
    MemoryImage img(ff::kFp24, 65536);
    hw::Kernel k;
    MemorySystemConfig cfg;
    cfg.host.mb_per_s = mbps;
    MemorySystem mi(k, img, cfg);
    std::vector<std::uint32_t> words(16384);  // 64 KB
    for (std::size_t i = 0; i < words.size(); ++i)
      words[i] = static_cast<std::uint32_t>(i * 2654435761u);
    mi.host().upload(kShadingBank, 0, words);
    const std::uint64_t cycles = k.run_to_completion([&] { return mi.idle(); }, 10000000);
    EXPECT_TRUE(std::equal(words.begin(), words.end(), img.bank(kShadingBank).begin()));
    EXPECT_EQ(img.word(kShadingBank, 16384), 0u);
    EXPECT_EQ(mi.host().bytes_sent(), 65536u);
    // The last 16-byte burst leaves when the credit covers all 65536 bytes: cycle
    // ceil(65536 * 90e6 / B) - 1; the controller queues it a cycle later and writes it the
    // cycle after; the run sees everything idle at the start of the next cycle.
    const double bytes_per_s = std::round(mbps * 1048576.0);
    const auto last = static_cast<std::uint64_t>(std::ceil(65536.0 * 90e6 / bytes_per_s)) - 1;
    EXPECT_EQ(cycles, last + 3) << mbps;
    EXPECT_NEAR(mi.controller().client_mb_per_s(mi.host().client(), cycles), mbps, mbps * 0.001);
    EXPECT_GT(k.skipped_cycles(), cycles / 2);  // waiting for credit is skipped, not stepped
  }
  MemoryImage img(ff::kFp24, 1024);
  hw::Kernel k;
  MemorySystem mi(k, img);
  EXPECT_THROW(mi.host().upload(kShadingBank, 1000, std::vector<std::uint32_t>(100)),
               std::runtime_error);
  EXPECT_THROW(mi.host().upload(7, 0, {1}), std::runtime_error);
  hw::Kernel k2;
  MemorySystemConfig bad;
  bad.host.mb_per_s = 0;
  EXPECT_THROW(MemorySystem(k2, img, bad), std::runtime_error);
}

// Frame sequences (docs/frames.md): the next frame's registers share the bus's bandwidth but go
// to no bank; stored() holds once every SRAM word is in its bank; an upload into words the frame
// in flight reads is refused with one line naming the range, and nothing of it is queued.
TEST(HostBus, RegistersShareTheBandwidthAndProtectedWordsAreRefused) {
  MemoryImage img(ff::kFp24, 4096);
  hw::Kernel k;
  MemorySystem mi(k, img);  // 132 MB/s, 4-word bursts
  HostUpload u;
  u.runs.push_back({kFirstSceneBank, 100, std::vector<std::uint32_t>(64, 0xA5u)});
  u.register_words = 32;
  u.frame_reads = {{kFirstSceneBank, 0, 100, "the top-level tree"},
                   {kFirstSceneBank, 164, 4096, "the bottom-level trees"}};
  EXPECT_EQ(u.sram_bytes(), 256u);
  EXPECT_EQ(u.bytes(), 384u);
  mi.host().upload(u);
  EXPECT_FALSE(mi.host().stored());
  const std::uint64_t cycles = k.run_to_completion([&] { return mi.host().stored(); }, 1000000);
  EXPECT_EQ(mi.host().bytes_sent(), 384u);
  EXPECT_EQ(mi.host().register_bytes_sent(), 128u);
  EXPECT_EQ(mi.controller().client_bytes(mi.host().client()), 256u);
  EXPECT_EQ(img.word(kFirstSceneBank, 163), 0xA5u);
  EXPECT_EQ(img.word(kFirstSceneBank, 164), 0u);
  // The registers come last: the whole 384 bytes' credit, ceil(384 * 90e6 / (132 * 2^20)) =
  // 250 cycles, then the SRAM words' last write was already stored.
  const auto credit =
      static_cast<std::uint64_t>(std::ceil(384.0 * 90e6 / std::round(132.0 * 1048576.0)));
  EXPECT_EQ(cycles, credit);
  // One word into the protected range: refused, nothing queued.
  HostUpload bad;
  bad.runs.push_back({kFirstSceneBank, 0, {1, 2}});
  bad.runs.push_back({kFirstSceneBank, 99, {7}});
  bad.frame_reads = u.frame_reads;
  try {
    mi.host().upload(bad);
    FAIL() << "an upload into the top-level tree in flight was accepted";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find("bank 3 words 0..1 overlaps the top-level tree (bank 3 words 0..99), which "
                     "the frame in flight reads"),
              std::string::npos)
        << m;
  }
  EXPECT_TRUE(mi.host().idle());
  EXPECT_THROW(mi.host().upload(kFirstSceneBank, 4000, {1}), std::runtime_error);
  EXPECT_NO_THROW(mi.host().upload(kFirstSceneBank, 100, {1}));  // between the ranges
  mi.host().protect({});
  EXPECT_NO_THROW(mi.host().upload(kFirstSceneBank, 0, {1}));
}

TEST(MemorySystem, BandwidthReportNamesEveryClient) {
  MemoryImage img = testing::random_scene_image(ff::kFp24, 9);
  hw::Kernel k;
  MemorySystem mi(k, img);
  const std::string r = mi.bandwidth_report(1000);
  for (const char* n : {"dynrtp0.node_cache", "dynrtp0.list_cache", "dynrtp0.row_cache",
                        "dynrtp0.shading", "dynrtp0.frame", "mi.host"}) {
    EXPECT_NE(r.find(n), std::string::npos) << n;
  }
  EXPECT_THROW(mi.cache(1, ItemType::kNode), std::out_of_range);
}

TEST(MemorySystem, BadConfigurationsAreRefused) {
  MemoryImage img = testing::random_scene_image(ff::kFp24, 10);
  hw::Kernel k;  // one kernel throughout: a refused configuration must leave it untouched
  auto refused = [&](auto edit) {
    MemorySystemConfig cfg;
    edit(cfg);
    try {
      MemorySystem mi(k, img, cfg);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refused([](MemorySystemConfig& c) { c.pipelines = 0; }),
            "memory system: pipelines must be >= 1");
  EXPECT_EQ(refused([](MemorySystemConfig& c) { c.responses_per_cycle = 0; }),
            "routing 'mi.routing': responses_per_cycle must be >= 1");
  EXPECT_EQ(refused([](MemorySystemConfig& c) { c.row_cache.ports = 0; }),
            "cache 'dynrtp0.row_cache': ports must be >= 1");
  EXPECT_EQ(refused([](MemorySystemConfig& c) { c.controller.queue_depth = 0; }),
            "memory controller 'mi.ctrl': queue_depth must be >= 1");
  EXPECT_EQ(refused([](MemorySystemConfig& c) { c.host.burst_words = 5; }),
            "host bus 'mi.host': burst_words must be 1..4");
  EXPECT_TRUE(k.modules().empty());
  EXPECT_TRUE(k.channels().empty());
}

}  // namespace
}  // namespace saarcor::memif
