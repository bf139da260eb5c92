// `saarcor vectors`: write or check unit transaction vectors (testbench/vectors_cmd.h).
#include "testbench/vectors_cmd.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "testbench/image_io.h"
#include "testbench/render_cmd.h"

namespace saarcor {
namespace {

constexpr const char* kMagic = "# saarcor unit vectors 1";

std::string field_text(const std::string& field, std::uint32_t v) {
  char buf[16];
  if (units::vector_field_is_flag(field)) {
    std::snprintf(buf, sizeof buf, "%u", v);
  } else {
    std::snprintf(buf, sizeof buf, "%06x", v);
  }
  return buf;
}

}  // namespace

std::string format_vector_file(units::VectorUnit unit, const units::VectorCapture& capture,
                               const std::string& source) {
  const auto& ins = units::vector_inputs(unit);
  const auto& outs = units::vector_outputs(unit);
  std::string s = std::string(kMagic) + "\n";
  s += std::string("# unit: ") + units::vector_unit_name(unit) + "\n";
  s += "# format: fp24 (e7m16, bias 63), round to nearest even, subnormals flushed; encodings as "
       "6 hex digits, flags 0/1\n";
  s += "# inputs: " + join_words(ins) + "\n";
  s += "# outputs: " + join_words(outs) + "\n";
  s += "# source: " + source + ", " + std::to_string(capture.vectors.size()) + " of " +
       std::to_string(capture.transactions) + " transactions\n";
  for (const units::UnitVector& v : capture.vectors) {
    std::string line;
    for (std::size_t k = 0; k < v.in.size(); ++k) {
      line += (k == 0 ? "" : " ") + field_text(ins[k], v.in[k]);
    }
    for (std::size_t k = 0; k < v.out.size(); ++k) {
      line += " " + field_text(outs[k], v.out[k]);
    }
    s += line + "\n";
  }
  return s;
}

VectorCheck check_vector_text(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  std::size_t number = 0;
  bool have_unit = false;
  VectorCheck r;
  auto bad = [&](const std::string& why) {
    return std::runtime_error("vector file line " + std::to_string(number) + ": " + why);
  };
  while (std::getline(in, line)) {
    ++number;
    if (number == 1 && line != kMagic) {
      throw bad("expected '" + std::string(kMagic) + "'");
    }
    if (line.empty()) {
      continue;
    }
    if (line[0] == '#') {
      if (line.rfind("# unit: ", 0) == 0) {
        r.unit = units::parse_vector_unit(line.substr(8));
        have_unit = true;
      }
      continue;
    }
    if (!have_unit) {
      throw bad("a vector before the '# unit: ' line");
    }
    const auto& ins = units::vector_inputs(r.unit);
    const auto& outs = units::vector_outputs(r.unit);
    std::istringstream fields(line);
    std::vector<std::uint32_t> values;
    std::string tok;
    while (fields >> tok) {
      const std::size_t k = values.size();
      const std::string& name = k < ins.size()                 ? ins[k]
                                : k - ins.size() < outs.size() ? outs[k - ins.size()]
                                                               : std::string("(extra)");
      std::size_t used = 0;
      unsigned long v = 0;
      try {
        v = std::stoul(tok, &used, units::vector_field_is_flag(name) ? 10 : 16);
      } catch (const std::exception&) {
        used = 0;
      }
      const unsigned long limit = units::vector_field_is_flag(name) ? 1u : 0xffffffu;
      if (used != tok.size() || v > limit) {
        std::string why = "field ";
        why += name;
        why += " '";
        why += tok;
        why += "' is not ";
        why += units::vector_field_is_flag(name) ? "0 or 1" : "a hex fp24 encoding";
        throw bad(why);
      }
      values.push_back(static_cast<std::uint32_t>(v));
    }
    if (values.size() != ins.size() + outs.size()) {
      throw bad(std::to_string(values.size()) + " fields, a " + units::vector_unit_name(r.unit) +
                " vector has " + std::to_string(ins.size() + outs.size()));
    }
    const std::vector<std::uint32_t> input(values.begin(),
                                           values.begin() + static_cast<long>(ins.size()));
    std::vector<std::uint32_t> expected;
    try {
      expected = units::expected_outputs(r.unit, input);
    } catch (const std::runtime_error& e) {
      throw bad(e.what());
    }
    ++r.vectors;
    bool differs = false;
    for (std::size_t k = 0; k < outs.size(); ++k) {
      const std::uint32_t got = values[ins.size() + k];
      if (got == expected[k]) {
        continue;
      }
      differs = true;
      if (r.first_differences.size() < 5) {
        r.first_differences.push_back("line " + std::to_string(number) + ": " + outs[k] + " is " +
                                      field_text(outs[k], got) + ", the datapath gives " +
                                      field_text(outs[k], expected[k]));
      }
    }
    r.differing += differs ? 1 : 0;
  }
  if (number == 0) {
    throw bad("empty file");
  }
  if (!have_unit) {
    throw bad("no '# unit: ' line");
  }
  return r;
}

int run_vectors(const VectorsOptions& opts) {
  if (!opts.check.empty()) {
    if (!opts.scene.empty() || !opts.out.empty()) {
      throw std::runtime_error("--check reads a vector file: no SCENE or --out with it");
    }
    std::ifstream f(opts.check, std::ios::binary);
    if (!f) {
      throw std::runtime_error("cannot read vector file '" + opts.check + "'");
    }
    std::stringstream ss;
    ss << f.rdbuf();
    const VectorCheck r = check_vector_text(ss.str());
    std::printf("saarcor vectors --check %s: %s unit, %zu vectors, %zu differ from the datapath\n",
                opts.check.c_str(), units::vector_unit_name(r.unit), r.vectors, r.differing);
    for (const std::string& d : r.first_differences) {
      std::printf("  %s\n", d.c_str());
    }
    return r.differing == 0 ? 0 : 2;
  }
  if (opts.scene.empty()) {
    throw std::runtime_error("vectors needs a SCENE (or --check FILE)");
  }
  const units::VectorUnit unit = units::parse_vector_unit(opts.unit);
  if (opts.count == 0) {
    throw std::runtime_error("bad --count 0: at least one vector");
  }
  if (opts.out.empty()) {
    throw std::runtime_error("vectors needs --out FILE");
  }
  const RenderSettings settings =
      frame_settings(opts.res, opts.time, opts.shadows, opts.depth, opts.bank_mb);
  const PreparedScene prep = prepare_scene(opts.scene, settings);
  progress("capturing " + std::string(units::vector_unit_name(unit)) + " transactions");
  const units::VectorCapture cap = units::capture_unit_vectors(
      prep.built.image, functional_params(settings), unit, opts.count, opts.seed);
  const std::string source =
      opts.scene + " " + std::to_string(settings.res.width) + "x" +
      std::to_string(settings.res.height) + (opts.shadows ? " with shadows" : "") +
      (opts.depth > 0 ? ", depth " + std::to_string(opts.depth) : "") +
      ", functional fp24 model, uniform sample with seed " + std::to_string(opts.seed);
  write_text_file(opts.out, format_vector_file(unit, cap, source));
  std::printf("saarcor vectors: %s unit, %zu of %llu transactions of %s -> %s\n",
              units::vector_unit_name(unit), cap.vectors.size(),
              static_cast<unsigned long long>(cap.transactions), opts.scene.c_str(),
              opts.out.c_str());
  return 0;
}

}  // namespace saarcor
