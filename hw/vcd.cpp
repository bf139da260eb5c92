// VCD tracer (docs/hw.md; IEEE 1364-2005 section 18.2 grammar).
#include "hw/vcd.h"

#include <map>
#include <ostream>

#include "hw/channel.h"
#include "hw/module.h"

namespace saarcor::hw {

std::string vcd_identifier(std::size_t k) {
  std::string id;
  do {
    id += static_cast<char>(33 + k % 94);
    k /= 94;
  } while (k != 0);
  return id;
}

namespace {

// VCD references are identifiers: keep letters, digits and '_', map the rest to '_'.
std::string sanitize(const std::string& s) {
  std::string out = s.empty() ? std::string("_") : s;
  for (char& c : out) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
    if (!ok) c = '_';
  }
  return out;
}

int bits_for(int max_value) {
  int b = 1;
  while ((1LL << b) <= max_value)
    ++b;
  return b;
}

struct ScopeNode {
  std::map<std::string, ScopeNode> children;
  std::vector<std::size_t> signals;
};

}  // namespace

VcdTracer::VcdTracer(std::ostream& out, std::uint64_t from, std::uint64_t to)
    : out_(out), from_(from), to_(to) {}

void VcdTracer::header(const std::vector<Module*>& modules,
                       const std::vector<ChannelBase*>& channels) {
  for (const Module* m : modules) {
    signals_.push_back({m->name(), "busy", 1, {}, 0});
    signals_.push_back({m->name(), "stall", 1, {}, 0});
  }
  for (const ChannelBase* c : channels) {
    signals_.push_back({c->name(), "valid", 1, {}, 0});
    signals_.push_back({c->name(), "ready", 1, {}, 0});
    signals_.push_back({c->name(), "occupancy", bits_for(c->capacity()), {}, 0});
  }
  ScopeNode root;
  for (std::size_t i = 0; i < signals_.size(); ++i) {
    signals_[i].id = vcd_identifier(i);
    ScopeNode* node = &root;
    const std::string& scope = signals_[i].scope;
    std::size_t pos = 0;
    for (;;) {
      const std::size_t dot = scope.find('.', pos);
      node = &node->children[sanitize(scope.substr(pos, dot - pos))];
      if (dot == std::string::npos) break;
      pos = dot + 1;
    }
    node->signals.push_back(i);
  }
  out_ << "$version saarcor hw kernel $end\n"
       << "$comment one time unit = one clock cycle $end\n"
       << "$timescale 1 ns $end\n"
       << "$scope module top $end\n";
  auto emit = [&](auto&& self, const ScopeNode& n) -> void {
    for (std::size_t i : n.signals) {
      const Signal& s = signals_[i];
      out_ << "$var wire " << s.width << " " << s.id << " " << s.name;
      if (s.width > 1) out_ << " [" << s.width - 1 << ":0]";
      out_ << " $end\n";
    }
    for (const auto& [name, child] : n.children) {
      out_ << "$scope module " << name << " $end\n";
      self(self, child);
      out_ << "$upscope $end\n";
    }
  };
  emit(emit, root);
  out_ << "$upscope $end\n$enddefinitions $end\n";
}

void VcdTracer::value_change(Signal& s, std::uint64_t v, bool force) {
  if (!force && v == s.last) return;
  s.last = v;
  if (s.width == 1) {
    out_ << (v ? '1' : '0') << s.id << "\n";
    return;
  }
  std::string bits;
  for (int b = s.width - 1; b >= 0; --b)
    bits += ((v >> b) & 1u) ? '1' : '0';
  const std::size_t first = bits.find('1');  // leading zeros may be dropped (18.2.1)
  out_ << "b" << (first == std::string::npos ? std::string("0") : bits.substr(first)) << " " << s.id
       << "\n";
}

void VcdTracer::sample(std::uint64_t cycle, const std::vector<Module*>& modules,
                       const std::vector<ChannelBase*>& channels) {
  if (cycle < from_ || cycle > to_ || finished_) return;
  const bool first = !started_;
  if (first) {
    header(modules, channels);
    started_ = true;
  }
  // Values in signal order (as laid out by header()).
  std::vector<std::uint64_t> v;
  v.reserve(signals_.size());
  for (const Module* m : modules) {
    v.push_back(m->busy());
    v.push_back(m->stalled());
  }
  for (const ChannelBase* c : channels) {
    v.push_back(c->valid());
    v.push_back(c->ready());
    v.push_back(static_cast<std::uint64_t>(c->occupancy()));
  }
  if (first) {
    out_ << "#" << cycle << "\n$dumpvars\n";
    for (std::size_t i = 0; i < signals_.size(); ++i)
      value_change(signals_[i], v[i], true);
    out_ << "$end\n";
    last_time_ = cycle;
    return;
  }
  bool stamped = false;
  for (std::size_t i = 0; i < signals_.size(); ++i) {
    if (v[i] == signals_[i].last) continue;
    if (!stamped) {
      out_ << "#" << cycle << "\n";
      stamped = true;
      last_time_ = cycle;
    }
    value_change(signals_[i], v[i], false);
  }
}

void VcdTracer::finish(std::uint64_t cycle) {
  if (!started_ || finished_) return;
  finished_ = true;
  std::uint64_t end = cycle < to_ + 1 ? cycle : to_ + 1;
  if (end <= last_time_) end = last_time_ + 1;
  out_ << "#" << end << "\n";
  out_.flush();
}

}  // namespace saarcor::hw
