// `saarcor vectors`: write or check unit transaction vectors (testbench/vectors_cmd.h).
#include "testbench/vectors_cmd.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "testbench/image_io.h"
#include "testbench/render_cmd.h"

namespace saarcor {
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
