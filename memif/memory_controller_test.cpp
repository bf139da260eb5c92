// Memory controller and SRAM banks (docs/memif.md; decisions D21, D23): exact timing with a
// mock client, bank parallelism, the switch penalty and the reordering, writes, bandwidth
// counting, bad requests and bad configurations.
#include "memif/memory_controller.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <random>

namespace saarcor::memif {
namespace {

class FnModule : public hw::Module {
 public:
  FnModule(hw::Kernel& k, std::string name, std::function<int()> f)
      : hw::Module(k, std::move(name)), f_(std::move(f)) {}
  int evaluate() override { return f_(); }

 private:
  std::function<int()> f_;
};

MemoryImage numbered_image() {
  MemoryImage img(ff::kFp24, 4096);
  for (int b = 0; b < kNumBanks; ++b) {
    for (std::uint32_t o = 0; o < 4096; ++o)
      img.set_word(b, o, (static_cast<std::uint32_t>(b) << 24) | o);
  }
  return img;
}

MemRequest read(std::uint16_t client, std::uint32_t tag, int bank, std::uint32_t offset,
                int words) {
  MemRequest r;
  r.client = client;
  r.tag = tag;
  r.bank = static_cast<std::uint8_t>(bank);
  r.offset = offset;
  r.words = static_cast<std::uint8_t>(words);
  return r;
}

// A client that sends a scripted list of (cycle, request) and records (cycle, response).
struct ScriptedClient {
  ScriptedClient(hw::Kernel& k, MemoryController::Port& port,
                 std::vector<std::pair<std::uint64_t, MemRequest>> script)
      : script_(std::move(script)), mod_(k, "client." + port.name, [this, &k, &port] {
          int p = 0;
          if (next_ < script_.size() && script_[next_].first <= k.now() &&
              port.requests.can_push()) {
            port.requests.push(script_[next_++].second);
            ++p;
          }
          if (port.responses.can_pop()) {
            got.emplace_back(k.now(), port.responses.pop());
            ++p;
          }
          return p;
        }) {}
  std::vector<std::pair<std::uint64_t, MemRequest>> script_;
  std::size_t next_ = 0;
  std::vector<std::pair<std::uint64_t, MemResponse>> got;
  FnModule mod_;
};

TEST(MemoryController, OneReadTakesTheDocumentedCyclesAndReturnsTheImageWords) {
  for (int words : {1, 2, 3}) {
    MemoryImage img = numbered_image();
    hw::Kernel k;
    MemoryController mc(k, "ctrl", img);
    MemoryController::Port& port = mc.add_port("p");
    const std::uint16_t c = mc.add_client("c");
    ScriptedClient client(k, port, {{0, read(c, 77, 4, 100, words)}});
    k.run_to_completion([&] { return client.got.size() == 1; }, 100);
    // push 0 -> accepted into the bank queue at 1 -> started at 2 -> last word read at
    // 2 + words - 1 -> data + latency 4 -> handed to the port -> poppable one cycle later.
    EXPECT_EQ(client.got[0].first, static_cast<std::uint64_t>(2 + words - 1 + 4 + 1));
    const MemResponse& r = client.got[0].second;
    EXPECT_EQ(r.tag, 77u);
    EXPECT_EQ(r.client, c);
    ASSERT_EQ(r.count, words);
    for (int i = 0; i < words; ++i)
      EXPECT_EQ(r.words[i], (4u << 24) | (100u + i));
    EXPECT_EQ(mc.client_bytes(c), 4u * words);
  }
}

TEST(MemoryController, OneBankDeliversOneWordPerCycle) {
  MemoryImage img = numbered_image();
  hw::Kernel k;
  MemoryController mc(k, "ctrl", img);
  MemoryController::Port& port = mc.add_port("p");
  const std::uint16_t c = mc.add_client("c");
  std::vector<std::pair<std::uint64_t, MemRequest>> script;
  for (int i = 0; i < 30; ++i)
    script.push_back({0, read(c, i, 3, 3 * i, 3)});
  ScriptedClient client(k, port, script);
  k.run_to_completion([&] { return client.got.size() == 30; }, 1000);
  // Back-to-back on one bank: starts at 2, 5, 8, ...; the last at 2 + 29*3 = 89.
  EXPECT_EQ(client.got.back().first, 89u + 2 + 4 + 1);
  EXPECT_EQ(k.stats().value("ctrl.bank3.busy_cycles"), 90.0);
  EXPECT_EQ(mc.bank_switches(), 0u);
}

TEST(MemoryController, SharedPathPaysThePenaltyWhenSwitchingBanksAndBanksOverlap) {
  MemoryImage img = numbered_image();
  for (int penalty : {0, 1, 3}) {
    hw::Kernel k;
    MemoryControllerConfig cfg;
    cfg.switch_penalty = penalty;
    MemoryController mc(k, "ctrl", img, cfg);
    MemoryController::Port& port = mc.add_port("p");
    const std::uint16_t c = mc.add_client("c");
    // Three 3-word reads to banks 3, 4, 5, pushed at 0, 1, 2: accepted at 1, 2, 3.
    ScriptedClient client(
        k, port, {{0, read(c, 0, 3, 0, 3)}, {0, read(c, 1, 4, 0, 3)}, {0, read(c, 2, 5, 0, 3)}});
    k.run_to_completion([&] { return client.got.size() == 3; }, 100);
    // Starts: bank3 at 2; bank4 accepted at 2, path free at 3, switch: 3 + penalty; bank5
    // accepted at 3, path free at 4 + penalty, switch: 4 + 2*penalty.
    const std::uint64_t s[3] = {2, 3u + penalty, 4u + 2u * penalty};
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(client.got[i].first, s[i] + 2 + 4 + 1) << "penalty " << penalty << " read " << i;
    }
    EXPECT_EQ(mc.bank_switches(), 2u);
  }
}

TEST(MemoryController, ThreeSceneBanksWithoutSwitchPenaltyDeliverThreeWordsPerCycle) {
  MemoryImage img = numbered_image();
  hw::Kernel k;
  MemoryControllerConfig cfg;
  cfg.switch_penalty = 0;
  MemoryController mc(k, "ctrl", img, cfg);
  MemoryController::Port& port = mc.add_port("p");
  const std::uint16_t c = mc.add_client("c");
  std::vector<std::pair<std::uint64_t, MemRequest>> script;
  for (int i = 0; i < 90; ++i)
    script.push_back({0, read(c, i, 3 + i % 3, 3 * (i / 3), 3)});
  ScriptedClient client(k, port, script);
  const std::uint64_t cycles = k.run_to_completion([&] { return client.got.size() == 90; }, 1000);
  // One request enters per cycle (pushed 0..89, queued 1..90, started 2..91); the last is
  // answered at 91 + 2 + 4 and popped a cycle later: 270 words in 99 cycles.
  EXPECT_EQ(client.got.back().first, 98u);
  EXPECT_EQ(cycles, 99u);
  for (int b = 3; b < 6; ++b) {
    EXPECT_EQ(k.stats().value("ctrl.bank" + std::to_string(b) + ".busy_cycles"), 90.0);
  }
}

TEST(MemoryController, ReorderingCutsBankSwitchesOnRandomTraffic) {
  // Several clients, random scene-bank reads; the same request stream with and without the
  // open-bank preference. Every response must carry the right words either way.
  auto run = [](bool reorder, std::uint64_t* cycles) {
    MemoryImage img = numbered_image();
    hw::Kernel k;
    MemoryControllerConfig cfg;
    cfg.reorder = reorder;
    MemoryController mc(k, "ctrl", img, cfg);
    std::vector<std::unique_ptr<ScriptedClient>> clients;
    std::mt19937 rng(3);
    std::map<std::pair<int, std::uint32_t>, MemRequest> sent;
    for (int p = 0; p < 3; ++p) {
      MemoryController::Port& port = mc.add_port("p" + std::to_string(p));
      const std::uint16_t c = mc.add_client("c" + std::to_string(p));
      std::vector<std::pair<std::uint64_t, MemRequest>> script;
      for (std::uint32_t i = 0; i < 300; ++i) {
        MemRequest r = read(c, i, 3 + static_cast<int>(rng() % 3), rng() % 4000,
                            2 + static_cast<int>(rng() % 2));
        sent[{p, i}] = r;
        script.push_back({0, r});
      }
      clients.push_back(std::make_unique<ScriptedClient>(k, port, script));
    }
    *cycles = k.run_to_completion(
        [&] {
          for (auto& c : clients) {
            if (c->got.size() != 300) return false;
          }
          return true;
        },
        100000);
    for (int p = 0; p < 3; ++p) {
      for (const auto& [t, r] : clients[p]->got) {
        const MemRequest& q = sent.at({p, r.tag});
        EXPECT_EQ(r.count, q.words);
        for (int w = 0; w < q.words; ++w) {
          EXPECT_EQ(r.words[w], img.word(q.bank, q.offset + w));
        }
      }
    }
    return mc.bank_switches();
  };
  std::uint64_t cycles_fifo = 0, cycles_reorder = 0;
  const std::uint64_t fifo = run(false, &cycles_fifo);
  const std::uint64_t reorder = run(true, &cycles_reorder);
  EXPECT_LT(reorder, fifo);
  EXPECT_LT(cycles_reorder, cycles_fifo);
  std::printf("bank switches: in order %llu (%llu cycles), reordered %llu (%llu cycles)\n",
              static_cast<unsigned long long>(fifo), static_cast<unsigned long long>(cycles_fifo),
              static_cast<unsigned long long>(reorder),
              static_cast<unsigned long long>(cycles_reorder));
}

// A port's response channel is as wide as its client takes (the routing's broadcast width,
// routing.responses): two reads due in the same cycle reach a 2-wide port together, a 1-wide
// port one cycle apart.
TEST(MemoryController, AWideResponsePortTakesSeveralReadsPerCycle) {
  for (int width : {1, 2}) {
    MemoryImage img = numbered_image();
    hw::Kernel k;
    MemoryControllerConfig cfg;
    cfg.bank_path = {0, 1, 2, 3, 4, 5};
    MemoryController mc(k, "ctrl", img, cfg);
    MemoryController::Port& port = mc.add_port("p", width);
    const std::uint16_t c = mc.add_client("c");
    // A 2-word read of bank 3 started at 2 and a 1-word read of bank 4 started at 3: both due at 7.
    const std::vector<std::pair<std::uint64_t, MemRequest>> script = {{0, read(c, 1, 3, 10, 2)},
                                                                      {1, read(c, 2, 4, 20, 1)}};
    std::size_t next = 0;
    std::vector<std::uint64_t> got;
    FnModule client(k, "client", [&] {
      int p = 0;
      if (next < script.size() && script[next].first <= k.now() && port.requests.can_push()) {
        port.requests.push(script[next++].second);
        ++p;
      }
      while (port.responses.can_pop()) {
        port.responses.pop();
        got.push_back(k.now());
        ++p;
      }
      return p;
    });
    k.run_to_completion([&] { return got.size() == 2; }, 100);
    EXPECT_EQ(got,
              (width == 1 ? std::vector<std::uint64_t>{8, 9} : std::vector<std::uint64_t>{8, 8}))
        << width;
    EXPECT_EQ(port.responses.width(), width);
    EXPECT_EQ(port.responses.capacity(), 4);  // max(port_capacity 4, 2 x width)
    EXPECT_THROW(mc.add_port("bad", 0), std::runtime_error);
  }
}

// Three ports want one bank more often than it serves (one-word reads, a word a cycle): once its
// queue is full, a place frees each cycle and the bank's round-robin pointer gives it to each port
// in turn (D55). Taken in port order, the third port's reads would all wait for the first two's.
// Three ports p0..p2 with clients c0..c2, each pushing `reads` one-word reads of bank 3 from cycle
// 0 (read i of port p at word 100 p + i, tag i), run until every client has all its answers.
std::vector<std::unique_ptr<ScriptedClient>> three_reading_ports(hw::Kernel& k,
                                                                 MemoryController& mc, int reads) {
  std::vector<std::unique_ptr<ScriptedClient>> clients;
  for (int p = 0; p < 3; ++p) {
    MemoryController::Port& port = mc.add_port("p" + std::to_string(p));
    const std::uint16_t c = mc.add_client("c" + std::to_string(p));
    std::vector<std::pair<std::uint64_t, MemRequest>> script;
    for (int i = 0; i < reads; ++i)
      script.push_back({0, read(c, static_cast<std::uint32_t>(i), 3,
                                static_cast<std::uint32_t>(100 * p + i), 1)});
    clients.push_back(std::make_unique<ScriptedClient>(k, port, script));
  }
  k.run_to_completion(
      [&] {
        for (const auto& c : clients)
          if (c->got.size() < static_cast<std::size_t>(reads)) return false;
        return true;
      },
      1000);
  return clients;
}

TEST(MemoryController, PortsWaitingForAFullBankQueueTakeTurns) {
  MemoryImage img = numbered_image();
  hw::Kernel k;
  MemoryController mc(k, "ctrl", img);
  const auto clients = three_reading_ports(k, mc, 20);
  // Each port's i-th read is answered within four cycles of the others' (the bank's 60 reads end
  // at cycle 66, one answer a cycle from cycle 7).
  for (std::size_t i = 0; i < 20; ++i) {
    std::uint64_t lo = ~std::uint64_t{0}, hi = 0;
    for (const auto& c : clients) {
      lo = std::min(lo, c->got[i].first);
      hi = std::max(hi, c->got[i].first);
    }
    EXPECT_LE(hi - lo, 4u) << "read " << i;
  }
  // The round robin's last turn is in port order, one answer a cycle.
  EXPECT_EQ(clients[0]->got.back().first, 64u);
  EXPECT_EQ(clients[1]->got.back().first, 65u);
  EXPECT_EQ(clients[2]->got.back().first, 66u);
}

TEST(MemoryController, AContendedBankWithRoomForTwoTakesTheNextTwoPortsOnce) {
  // Queues of 2 and three ports whose first reads reach an empty bank in the same cycle: more
  // want it than it has room for, so the round robin decides. From the pointer at port 0 it takes
  // ports 0 and 1, each once, and holds port 2. Moving the loop's start with the pointer visited
  // port 2 twice and took its request twice.
  MemoryImage img = numbered_image();
  hw::Kernel k;
  MemoryControllerConfig config;
  config.queue_depth = 2;
  MemoryController mc(k, "ctrl", img, config);
  const auto clients = three_reading_ports(k, mc, 1);
  // One read a cycle leaves the bank in the order taken in: ports 0 and 1 first, port 2 last.
  EXPECT_LT(clients[0]->got[0].first, clients[2]->got[0].first);
  EXPECT_LT(clients[1]->got[0].first, clients[2]->got[0].first);
  EXPECT_EQ(clients[2]->got[0].second.words[0], img.word(3, 200));
}

TEST(MemoryController, WritesLandInTheImageAndLaterReadsSeeThem) {
  MemoryImage img = numbered_image();
  hw::Kernel k;
  MemoryController mc(k, "ctrl", img);
  MemoryController::Port& port = mc.add_port("p");
  const std::uint16_t c = mc.add_client("frame");
  MemRequest w = read(c, 0, 0, 10, 2);
  w.write = true;
  w.data = {0xAABBCCu, 0x112233u, 0, 0};
  w.counted_bytes = 6;  // 3 bytes per pixel (D36)
  ScriptedClient client(k, port, {{0, w}, {0, read(c, 5, 0, 10, 2)}});
  k.run_to_completion([&] { return client.got.size() == 1; }, 100);
  EXPECT_EQ(img.word(0, 10), 0xAABBCCu);
  EXPECT_EQ(img.word(0, 11), 0x112233u);
  EXPECT_EQ(client.got[0].second.words[0], 0xAABBCCu);
  EXPECT_EQ(client.got[0].second.tag, 5u);
  EXPECT_EQ(mc.client_bytes(c), 6u + 8u);
  EXPECT_EQ(k.stats().value("ctrl.bank0.writes"), 1.0);
}

TEST(MemoryController, BandwidthIsReportedInMegabytesPerSecondAtTheModelledClock) {
  MemoryImage img = numbered_image();
  hw::Kernel k;
  MemoryController mc(k, "ctrl", img);
  MemoryController::Port& port = mc.add_port("p");
  const std::uint16_t c = mc.add_client("dynrtp0.node_cache");
  std::vector<std::pair<std::uint64_t, MemRequest>> script;
  for (int i = 0; i < 100; ++i)
    script.push_back({0, read(c, i, 3, 2 * i, 2)});
  ScriptedClient client(k, port, script);
  const std::uint64_t cycles = k.run_to_completion([&] { return client.got.size() == 100; }, 10000);
  EXPECT_EQ(mc.client_bytes(c), 800u);
  // 800 bytes in `cycles` cycles at 90 MHz, MB = 2^20 bytes.
  const double expect = 800.0 * 90e6 / static_cast<double>(cycles) / 1048576.0;
  EXPECT_DOUBLE_EQ(mc.client_mb_per_s(c, cycles), expect);
  EXPECT_DOUBLE_EQ(k.stats().value("dynrtp0.node_cache.mem_mb_per_s"), expect);
  // Sanity on the scale: one bank flat out is 4 B * 90 MHz = 343.3 MB/s.
  EXPECT_GT(expect, 250.0);
  EXPECT_LT(expect, 343.33);
}

TEST(MemoryController, RequestsOutsideMemoryAndBadConfigurationsAreRefused) {
  MemoryImage img = numbered_image();
  {
    hw::Kernel k;
    MemoryController mc(k, "ctrl", img);
    MemoryController::Port& port = mc.add_port("p");
    const std::uint16_t c = mc.add_client("c");
    ScriptedClient client(k, port, {{0, read(c, 0, 3, 4095, 2)}});
    EXPECT_THROW(k.run([] { return false; }, 10), std::runtime_error);
  }
  {
    hw::Kernel k;
    MemoryController mc(k, "ctrl", img);
    MemoryController::Port& port = mc.add_port("p");
    const std::uint16_t c = mc.add_client("c");
    ScriptedClient client(k, port, {{0, read(c, 0, 6, 0, 1)}});
    EXPECT_THROW(k.run([] { return false; }, 10), std::runtime_error);
  }
  hw::Kernel k;
  auto make = [&](auto edit) {  // the same kernel every time: a refusal leaves nothing behind
    MemoryControllerConfig cfg;
    edit(cfg);
    MemoryController mc(k, "bad", img, cfg);
  };
  EXPECT_THROW(make([](auto& c) { c.queue_depth = 0; }), std::runtime_error);
  EXPECT_THROW(make([](auto& c) { c.latency = 0; }), std::runtime_error);
  EXPECT_THROW(make([](auto& c) { c.bank_path = {0, 1}; }), std::runtime_error);
  EXPECT_THROW(make([](auto& c) { c.switch_penalty = -1; }), std::runtime_error);
  EXPECT_THROW(make([](auto& c) { c.clock_hz = 0; }), std::runtime_error);
}

// Lanes (docs/memif.md "Lanes"): a shading-like port reading one bank and a frame-like port
// writing another, served in closed form, give the same cycles, responses, stored words and
// statistics (the controller's busy and stall cycles, the banks', the clients', the channels')
// as the same ports through their channels, beside a third port stepped through the controller
// (its own busy and stall cycles overlap the lanes'). Shallow queues and small ports make the
// lanes stall and wait for room; gaps let the kernel skip idle cycles.
}  // namespace
struct LaneRun {
  std::uint64_t cycles = 0;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> shading, other;  // (cycle, tag) received
  std::vector<std::uint32_t> frame_words;
  std::string stats;
};

using Script = std::vector<std::pair<std::uint64_t, MemRequest>>;

// The three ports' requests: shading-like reads of bank 2, frame-like writes of bank 0 and other
// reads of the shared banks, in bursts that fill the queues and gaps to skip.
struct LaneScripts {
  Script reads, writes, others;
};
LaneScripts lane_scripts(std::uint16_t cs, std::uint16_t cf, std::uint16_t co, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  auto script = [&](int n, auto make) {
    Script s;
    std::uint64_t at = 0;
    for (int i = 0; i < n; ++i) {
      at += rng() % 8 == 0 ? rng() % 60 : 0;  // bursts that fill the queues, gaps to skip
      s.emplace_back(at, make(i));
    }
    return s;
  };
  LaneScripts out;
  out.reads = script(300, [&](int i) {
    return read(cs, static_cast<std::uint32_t>(i), 2, static_cast<std::uint32_t>(rng() % 4000),
                1 + static_cast<int>(rng() % 4));
  });
  out.writes = script(200, [&](int i) {
    MemRequest w = read(cf, 0, 0, static_cast<std::uint32_t>(i), 1);
    w.write = true;
    w.counted_bytes = 3;
    w.data[0] = 0xABC000u + static_cast<std::uint32_t>(i);
    return w;
  });
  out.others = script(150, [&](int i) {
    return read(co, static_cast<std::uint32_t>(i), 3 + static_cast<int>(rng() % 3),
                static_cast<std::uint32_t>(rng() % 4000), 1 + static_cast<int>(rng() % 3));
  });
  return out;
}

// The next due request of `list` into `port`, through its lane when it has one (the RGS's way
// with its ports: one request per cycle when the port takes it).
int push_due(std::uint64_t now, MemoryController::Port& port, const Script& list,
             std::size_t& next) {
  if (next >= list.size() || list[next].first > now) {
    return 0;
  }
  if (!(port.lane != nullptr ? port.lane->can_push() : port.requests.can_push())) {
    return 0;
  }
  if (port.lane != nullptr) {
    port.lane->push(list[next++].second);
  } else {
    port.requests.push(list[next++].second);
  }
  return 1;
}

LaneRun run_lanes(bool lanes, MemoryControllerConfig cfg, std::uint64_t seed) {
  MemoryImage img = numbered_image();
  hw::Kernel k;
  cfg.bank_path = {0, 1, 2, 3, 3, 3};
  MemoryController mc(k, "ctrl", img, cfg);
  MemoryController::Port& other = mc.add_port("other");
  MemoryController::Port& shading = mc.add_port("shading");
  MemoryController::Port& frame = mc.add_port("frame");
  const std::uint16_t co = mc.add_client("other"), cs = mc.add_client("shading"),
                      cf = mc.add_client("frame");
  if (lanes) {
    mc.add_lane(shading, true);
    mc.add_lane(frame, false);
  }
  const LaneScripts s = lane_scripts(cs, cf, co, seed);
  LaneRun out;
  std::size_t next_read = 0, next_write = 0, next_other = 0;
  // Every response is taken the cycle it becomes visible.
  FnModule client(k, "client", [&] {
    int p = push_due(k.now(), shading, s.reads, next_read) +
            push_due(k.now(), frame, s.writes, next_write) +
            push_due(k.now(), other, s.others, next_other);
    if (shading.lane != nullptr ? shading.lane->can_pop() : shading.responses.can_pop()) {
      out.shading.emplace_back(
          k.now(), shading.lane != nullptr ? shading.lane->pop() : shading.responses.pop().tag);
      ++p;
    }
    if (other.responses.can_pop()) {
      out.other.emplace_back(k.now(), other.responses.pop().tag);
      ++p;
    }
    return p;
  });
  out.cycles = k.run_to_completion(
      [&] {
        return out.shading.size() == s.reads.size() && out.other.size() == s.others.size() &&
               next_write == s.writes.size() && mc.port_idle(frame) && mc.idle();
      },
      1000000);
  for (std::uint32_t o = 0; o < 200; ++o)
    out.frame_words.push_back(img.bank(0)[o]);
  // The lanes ran (they would have left their ports to the channels if they could not).
  EXPECT_EQ(lanes, shading.lane != nullptr);
  EXPECT_EQ(lanes, frame.lane != nullptr);
  out.stats = k.stats().json();
  return out;
}

namespace {
TEST(MemoryController, LanesGiveTheSteppedCyclesAndStatistics) {
  std::vector<MemoryControllerConfig> configs(3);
  configs[1].queue_depth = 1;
  configs[1].port_capacity = 2;
  configs[1].latency = 1;
  configs[2].queue_depth = 2;
  configs[2].port_capacity = 3;
  configs[2].latency = 17;
  for (std::size_t c = 0; c < configs.size(); ++c) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
      const LaneRun stepped = run_lanes(false, configs[c], seed);
      const LaneRun lane = run_lanes(true, configs[c], seed);
      EXPECT_EQ(stepped.cycles, lane.cycles) << c << " " << seed;
      EXPECT_EQ(stepped.shading, lane.shading) << c << " " << seed;
      EXPECT_EQ(stepped.other, lane.other) << c << " " << seed;
      EXPECT_EQ(stepped.frame_words, lane.frame_words) << c << " " << seed;
      EXPECT_EQ(stepped.stats, lane.stats) << c << " " << seed;
    }
  }
}

// A lane runs only where nothing else reaches its bank: another port's request to it is a model
// error, and a bank sharing its issue path leaves the port on its channels.
TEST(MemoryController, LanesKeepTheirBanksToThemselves) {
  MemoryImage img = numbered_image();
  hw::Kernel k;
  MemoryController mc(k, "ctrl", img);
  MemoryController::Port& lane_port = mc.add_port("lane");
  MemoryController::Port& shared = mc.add_port("shared");
  MemoryController::Port& other = mc.add_port("other");
  const std::uint16_t c = mc.add_client("c");
  mc.add_lane(lane_port, true);
  mc.add_lane(shared, true);
  FnModule client(k, "client", [&] {
    if (k.now() == 0) {
      lane_port.lane->push(read(c, 1, 2, 0, 1));
      shared.lane->push(read(c, 2, 3, 0, 1));  // bank 3 shares its path with 4 and 5
      return 1;
    }
    if (k.now() == 1) other.requests.push(read(c, 3, 2, 0, 1));
    return k.now() == 1 ? 1 : 0;
  });
  EXPECT_THROW(k.run_to_completion([] { return false; }, 10), std::logic_error);
  EXPECT_EQ(shared.lane, nullptr);
  EXPECT_NE(lane_port.lane, nullptr);
}

}  // namespace
}  // namespace saarcor::memif
