// `saarcor cost` and `saarcor paper --table 1|2` (docs/cost.md).
#include "testbench/cost_cmd.h"

#include <cstdio>
#include <stdexcept>

#include "testbench/image_io.h"
#include "testbench/report.h"

namespace saarcor {
namespace {

using units::ConfigurationCost;
using units::CostParams;
using units::FpUnits;
using units::UnitCost;

double ratio(double model, double paper) {
  return paper == 0.0 ? 0.0 : model / paper;
}

std::string fp_cell(int v) {
  return v == 0 ? "-" : std::to_string(v);
}

// A model line has its area estimate (LUTs, block RAMs); the paper's line has none.
std::string unit_line(const std::string& label, const FpUnits& f, double kb,
                      const units::AreaEstimate* area = nullptr) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "%-34s %5s %5s %5s %5s %5s %10.2f", label.c_str(),
                fp_cell(f.add).c_str(), fp_cell(f.mul).c_str(), fp_cell(f.div).c_str(),
                fp_cell(f.cmp).c_str(), fp_cell(f.sqrt).c_str(), kb);
  std::string s = buf;
  if (area != nullptr) {
    std::snprintf(buf, sizeof buf, " %8s %5s", fp_cell(static_cast<int>(area->luts)).c_str(),
                  fp_cell(area->block_rams).c_str());
    s += buf;
  }
  return s + "\n";
}

std::string ratio_cell(double model, double paper) {
  char buf[32];
  if (paper == 0.0)
    std::snprintf(buf, sizeof buf, "%s", model == 0.0 ? "-" : "new");
  else
    std::snprintf(buf, sizeof buf, "%.2f", model / paper);
  return buf;
}

// Table 2's paper line and the ratio line under a model line.
std::string paper_lines(const std::string& key, const FpUnits& f, double kb) {
  const auto& p = units::paper_table2_row(key);
  std::string s = unit_line("  paper", {p.add, p.mul, p.div, p.cmp, 0}, p.memory_kb);
  char buf[200];
  std::snprintf(buf, sizeof buf, "%-34s %5s %5s %5s %5s %5s %10s\n", "  ratio model/paper",
                ratio_cell(f.add, p.add).c_str(), ratio_cell(f.mul, p.mul).c_str(),
                ratio_cell(f.div, p.div).c_str(), ratio_cell(f.cmp, p.cmp).c_str(), "",
                ratio_cell(kb, p.memory_kb).c_str());
  return s + buf;
}

std::string heading(const CostParams& p) {
  const auto& c = p.cycle;
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%d DynRTP%s, %d threads, %d-ray packets, stack %d, mailboxes %d/%d, caches "
                "%d/%d/%d items (%d/%d/%d ways), %d lights, %.0f MHz\n",
                c.pipelines, c.pipelines == 1 ? "" : "s", c.threads, c.packet, c.stack, c.mailbox,
                c.triangle_mailbox, c.cache[0].items, c.cache[1].items, c.cache[2].items,
                c.cache[0].ways, c.cache[1].ways, c.cache[2].ways, p.lights, c.clock_mhz);
  return buf;
}

std::string column_heads(const char* first) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%-34s %5s %5s %5s %5s %5s %10s %8s %5s\n", first, "add", "mul",
                "div", "cmp", "sqrt", "memory KB", "LUTs", "BRAM");
  return buf;
}

std::string memory_lines(const UnitCost& u) {
  std::string s;
  char buf[400];
  for (const auto& m : u.memory) {
    std::snprintf(buf, sizeof buf, "    %9.3f KB  %-13s %s: %lld bits x %lld%s\n",
                  static_cast<double>(m.bits()) / 8192.0, m.kind.c_str(), m.what.c_str(),
                  static_cast<long long>(m.bits_each), static_cast<long long>(m.count),
                  m.ports == 2 ? ", dual-ported (x2)" : "");
    s += buf;
  }
  return s;
}

std::string total_lines(const ConfigurationCost& c, bool table2) {
  const double kb1 = static_cast<double>(c.memory_bits_per_pipeline) / 8192.0;
  std::string s = unit_line("Total (one DynRTP)", c.fp_per_pipeline, kb1, &c.area_per_pipeline);
  if (table2) s += paper_lines("total", c.fp_per_pipeline, kb1);
  if (c.pipelines > 1)
    s += unit_line("Total (" + std::to_string(c.pipelines) + " DynRTPs)", c.fp_total,
                   c.memory_kb_total(), &c.area_total);
  char buf[400];
  std::snprintf(buf, sizeof buf, "FLOPs: %.3g (%d FP units x %.0f MHz; paper: 4 billion)\n",
                c.flops, c.fp_total.total(), c.clock_mhz);
  s += buf;
  const auto pct = [](double v, double of) { return 100.0 * v / of; };
  std::snprintf(
      buf, sizeof buf,
      "XC2V6000 (Virtex-II, the prototype's): %lld LUTs (%.1f %%), %d MULT18X18 (%.1f %%), "
      "at least %d block RAMs (%.1f %%); LUTs of the FP operators only (docs/cost.md)\n",
      static_cast<long long>(c.area_total.luts),
      pct(static_cast<double>(c.area_total.luts), units::kXc2v6000Luts), c.area_total.mult18x18,
      pct(c.area_total.mult18x18, units::kXc2v6000Mult18x18), c.area_total.block_rams,
      pct(c.area_total.block_rams, units::kXc2v6000BlockRams));
  return s + buf;
}

}  // namespace

CostParams cost_params(const std::string& preset, const std::vector<std::string>& set) {
  CostParams p = units::cost_preset(preset);
  for (const std::string& kv : set)
    units::apply_cost_setting(p, kv);
  units::check_cost_params(p);
  return p;
}

std::string cost_text(const CostParams& params, bool table2) {
  const ConfigurationCost c = units::configuration_cost(params);
  std::string s = heading(params) + column_heads("unit (one DynRTP)");
  for (const UnitCost& u : c.units) {
    s += unit_line(u.name, u.fp, u.memory_kb(), &u.area);
    if (table2) s += paper_lines(u.key, u.fp, u.memory_kb());
    s += memory_lines(u);
  }
  return s + total_lines(c, table2);
}

std::string table2_text(const CostParams& params) {
  const ConfigurationCost c = units::configuration_cost(params);
  std::string s = "Table 2 (paper: one DynRTP, 32 threads, 512-item caches, 8 lights; model: " +
                  heading(params).substr(0, heading(params).size() - 1) + ")\n" +
                  column_heads("unit");
  for (const UnitCost& u : c.units)
    s += unit_line(u.name, u.fp, u.memory_kb(), &u.area) + paper_lines(u.key, u.fp, u.memory_kb());
  return s + total_lines(c, true) + "the memory items and each difference: saarcor cost --preset " +
         "table2, docs/cost.md\n";
}

std::string table1_text(const CostParams& params) {
  const units::Table1 t = units::table1(params);
  std::string s =
      "Table 1 (FP units = add + mul + div + cmp, one per operation of a fully pipelined datapath; "
      "K = this configuration's traversal unit, " +
      std::to_string(t.traversal.total()) + " units; docs/cost.md)\n";
  char buf[200];
  std::snprintf(buf, sizeof buf, "%-12s %-18s %18s %12s\n", "design", "parts", "without traversal",
                "full design");
  s += buf;
  for (const auto& d : t.designs) {
    std::snprintf(buf, sizeof buf, "%-12s %-18s %18d %12d\n", d.name.c_str(), d.parts.c_str(),
                  d.without_traversal.total(), d.full.total());
    s += buf;
  }
  std::snprintf(buf, sizeof buf, "%-34s %18s %12s\n", "FP cost ratio", "without traversal",
                "full design");
  s += buf;
  for (const auto& r : t.ratios) {
    std::snprintf(buf, sizeof buf, "%-34s %17.0f%% %11.0f%%\n", r.name.c_str(),
                  100 * r.paper_without_traversal, 100 * r.paper_full);
    s += buf;
    std::snprintf(buf, sizeof buf, "%-34s %17.1f%% %11.1f%%\n", "  model",
                  100 * r.without_traversal, 100 * r.full);
    s += buf;
    std::snprintf(buf, sizeof buf, "%-34s %18.2f %12.2f\n", "  ratio model/paper",
                  ratio(r.without_traversal, r.paper_without_traversal),
                  ratio(r.full, r.paper_full));
    s += buf;
  }
  return s;
}

int run_cost(const CostOptions& opts) {
  if (!opts.json.empty() && !opts.json.ends_with(".json"))
    throw std::runtime_error("bad --json '" + opts.json + "': expected a .json file name");
  const CostParams p = cost_params(opts.preset, opts.set);
  const bool table2 = opts.preset == "table2";
  const std::string text = cost_text(p, table2);  // computed before any file is written
  if (!opts.json.empty()) write_text_file(opts.json, cost_report_json(p, table2).dump(2) + "\n");
  std::printf("%s", text.c_str());
  if (!opts.json.empty()) std::printf("  json: %s\n", opts.json.c_str());
  return 0;
}

int run_paper_cost_table(int table, const std::vector<std::string>& set, const std::string& json,
                         const std::string& csv) {
  if (!csv.empty())
    throw std::runtime_error("bad --csv with --table " + std::to_string(table) +
                             ": the CSV is Tables 3 and 4's; --json writes Tables 1 and 2");
  if (!json.empty() && !json.ends_with(".json"))
    throw std::runtime_error("bad --json '" + json + "': expected a .json file name");
  const CostParams p = cost_params(table == 2 ? "table2" : "prototype", set);
  const std::string text = table == 1 ? table1_text(p) : table2_text(p);
  if (!json.empty()) write_text_file(json, cost_report_json(p, table == 2).dump(2) + "\n");
  std::printf("%s", text.c_str());
  if (!json.empty()) std::printf("  json: %s\n", json.c_str());
  return 0;
}

}  // namespace saarcor
