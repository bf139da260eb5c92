// `saarcor sample-check` (docs/sampling.md): the sampled simulation (testbench/sampling.h) against
// full runs of the same frames, scene by scene under the covering design's eight configurations
// (testbench/covering_design.h), at each resolution asked for. Per figure it tabulates the mean
// and the largest error of the estimates, how often the full value lay inside the 95 % interval,
// and the host time of the full runs over the sampled runs', both timed in this process one after
// the other. Every sampled run's simulated packets are checked bit for bit against the functional
// model (outside the timing, as a full run's check would be).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "testbench/sampling.h"

namespace saarcor {

struct SampleCheckOptions {
  // Scenes (builtin:NAME or glTF files); empty: every built-in and `models` reference models.
  std::vector<std::string> scenes;
  std::string references = "../shared/scenes";
  int models = 10;
  std::vector<std::string> res = {"512x384", "1024x768"};
  std::vector<std::string> configs;  // covering-design names; empty: all eight
  std::string sample_spec;           // "" = the default
  std::string json;                  // write the cases and the summary
  bool quiet = false;                // no line per case
};

// One frame run whole and sampled.
struct SampleCase {
  std::string scene, config, res;
  double full_seconds = 0, sampled_seconds = 0;
  double covariate_seconds = 0;  // the part of sampled_seconds the packets' covariate took
  std::uint64_t packets = 0, packets_simulated = 0;
  int windows = 0;
  bool trusted = true;  // the sample gave an interval (otherwise `defeated` says why)
  std::string defeated;
  // Per checked figure (sample_check_figures()): the full value, the estimate, the interval.
  std::vector<double> full, estimate;
  std::vector<SampleInterval> ci;
};

// The figures the check compares: cycles, fps and the report's Table 4 figures (kFigures).
const std::vector<std::string>& sample_check_figures();
// Whether a figure's error is relative (%, cycles, fps, bandwidths) or in points (usage, hit %).
bool sample_check_relative(const std::string& figure);

// The image's frame under covering-design configuration `config` (a name), whole and sampled
// (scene and res are left for the caller to fill in).
SampleCase run_sample_case(const memif::MemoryImage& image, const std::string& config,
                           const SampleSpec& spec);
// The image of `scene` at `res` (WxH) as the cases run it (4 MB banks; 32 for builtin:terrain, 8
// for the two largest reference models, as the bit-exactness tests use).
memif::MemoryImage sample_check_image(const std::string& scene, const std::string& res);
// The scenes of a run without --scene: every built-in, then the first `models` reference models
// found under `references` (the glTF models the bit-exactness tests use, largest first).
std::vector<std::string> sample_check_scenes(const std::string& references, int models);

// Per figure over the cases: mean and max error, coverage of the trusted cases; per resolution the
// host-time ratio (sum of full seconds over sum of sampled seconds) and its smallest case.
nlohmann::json sample_check_summary(const std::vector<SampleCase>& cases);
std::string sample_check_text(const nlohmann::json& summary);

// The command: every case, a line each, then the summary. Returns 0.
int run_sample_check(const SampleCheckOptions& opts);

}  // namespace saarcor
